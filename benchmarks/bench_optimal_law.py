"""Optimal-law solve time on the paper's semicircle (floor: 20 ms for eta = 0.1 with an ODE
residual of 1e-8) and convergence across eta in {1e-5, 1e-3, 0.1, 10, 1e3, 1e5}.

Run: python benchmarks/bench_optimal_law.py
"""

from __future__ import annotations

import time

import numpy as np

from dextar.laws import solve_optimal_law
from dextar.paths import Arc, ExpressionPath, Spline

SEMI = Arc(120 / 87, 0.0, np.pi)


def ode_residual(law, eta: float) -> float:
    """max |p'''' - (6 pdot^2 + gamma^2) pddot| / (1 + max |p''''|) on 4001 times."""
    R = SEMI.radius
    t = np.linspace(0, 1, 4001)
    _, ds, dds, _ = law.evaluate(t)
    p4 = law.fourth_derivative(t) / R
    rhs = (6 * (ds / R) ** 2 + 1 / eta) * dds / R
    return float(np.abs(p4 - rhs).max() / (1 + np.abs(p4).max()))


def best_of(fn, repeat: int) -> tuple[float, object]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    print("semicircle R = 120/87 L, T = 1, m = 1 (paper units)")
    for eta in (1e-5, 1e-3, 0.1, 10.0, 1e3, 1e5):
        dt, law = best_of(lambda e=eta: solve_optimal_law(SEMI, eta=e), 7)
        print(f"  eta = {eta:<7g} solve {dt * 1e3:7.2f} ms  nodes {law.nodes:4d}  "
              f"ODE residual {ode_residual(law, eta):.1e}  cost {law.cost:.10g}")
    print("floor: 20 ms for eta = 0.1; every eta converges")
    print("other paths (eta = 0.01, varying curvature, solve_bvp with curvature continuation)")
    for name, path in (
            ("spline", Spline(((0.0, 1.0), (0.3, 1.2), (0.6, 1.0), (1.0, 1.3)))),
            ("expression", ExpressionPath("0.3*cos(p)", "1.2 + 0.2*sin(2*p)", 0.0, 3.0))):
        dt, law = best_of(lambda p=path: solve_optimal_law(p, eta=0.01), 3)
        print(f"  {name:<10} solve {dt * 1e3:7.1f} ms  {law.message}")


if __name__ == "__main__":
    main()
