"""The paper's optimal law: solve times beside scipy's solve_bvp, with the accuracy of both.

Run: python benchmarks/bench_optimal_law.py   (pin it: taskset -c 0 python ...)

1. The semicircle (R = 120/87 L, T = 1, m = 1, the paper's units) for every eta in
   {1e-5, 1e-3, 0.1, 10, 1e3, 1e5}, each from a cold start: best of 7 warm solves (the
   operators cached, a new solve each time) with the spread, the ODE residual (15) checked on
   4001 times independently of the solver, and the cost beside solve_bvp at tol 1e-9
   (floor: eta = 0.1 under 2 ms).
2. Varying curvature: the benchmark's unit spline (eta = 0.01), the spline of
   examples/spline_si.toml (SI) and a curve given by expressions: best of 5 solves, beside the
   solver the law used before (solve_bvp at tol 1e-8 with continuation in the curvature) and
   a solve_bvp reference at tol 1e-9 (its floor: at 1e-10 it runs out of nodes), with the Euler-Lagrange residual on 2001 times (from
   the path's own curvature, not the solver's), the largest difference of s, sdot, sddot
   from the reference (relative to their ranges) and the costs (floor: the spline under
   20 ms).
"""

from __future__ import annotations

import math
import time
from pathlib import Path as FilePath

import numpy as np
from scipy.integrate import simpson, solve_bvp

from dextar.config import load_scenario
from dextar.laws import OptimalLaw, law_cost, solve_optimal_law
from dextar.laws.optimal import _solve_local, line_solution
from dextar.paths import Arc, ExpressionPath, Path, Spline

SEMI = Arc(120 / 87, 0.0, np.pi)
EXAMPLE = FilePath(__file__).resolve().parents[1] / "examples" / "spline_si.toml"


def timed(fn, repeat: int) -> tuple[np.ndarray, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return np.array(times), out


def spread(times: np.ndarray) -> str:
    return f"{times.min() * 1e3:8.2f} ms (median {np.median(times) * 1e3:.2f}, " \
           f"max {times.max() * 1e3:.2f})"


def semicircle_residual(law: OptimalLaw, eta: float) -> float:
    """max |p'''' - (6 pdot^2 + gamma^2) pddot| / (1 + max |p''''|) on 4001 times."""
    R = SEMI.radius
    t = np.linspace(0, 1, 4001)
    _, ds, dds, _ = law.evaluate(t)
    p4 = law.fourth_derivative(t) / R
    rhs = (6 * (ds / R) ** 2 + 1 / eta) * dds / R
    return float(np.abs(p4 - rhs).max() / (1 + np.abs(p4).max()))


def semicircle_bvp_cost(eta: float) -> tuple[float, float]:
    """The cost by solve_bvp at the tightest tolerance it reaches of 1e-9 and 1e-8 (at 1e-10
    it runs out of mesh nodes on its rounding floor), and that tolerance (the paper's ODE (15)
    in p = s / R)."""
    R, G2 = SEMI.radius, 1.0 / eta
    x = np.linspace(0, 1, 201)
    if G2 > 400:
        layer = np.geomspace(0.05, 12.0, 24) / math.sqrt(G2)
        layer = layer[layer < 0.5]
        x = np.unique(np.concatenate([x, layer, 1 - layer]))
    y0 = line_solution(math.sqrt(G2), x) * np.pi

    def fun(_t, y):
        return np.vstack([y[1], y[2], y[3], (6 * y[1] ** 2 + G2) * y[2]])

    def bc(a, b):
        return np.array([a[0], a[1], b[0] - np.pi, b[1]])

    for tol in (1e-9, 1e-8):
        res = solve_bvp(fun, bc, x, y0, tol=tol, max_nodes=200_000)
        if res.success:
            break
    t = np.linspace(0, 1, 200_001)
    y = res.sol(t)
    kin = 0.5 * simpson((R * y[1]) ** 2, x=t)
    inert = 0.5 * eta * simpson(R**2 * (y[2] ** 2 + y[1] ** 4), x=t)  # kappa = 1 / R
    return (float(kin + inert) if res.success else float("nan")), tol


def el_residual(path: Path, law: OptimalLaw) -> float:
    """The Euler-Lagrange equation s'''' = (1/(eta m) + 6 kappa^2 sdot^2) sddot
    + 3 kappa kappa' sdot^4 on 2001 times, relative to 1 + max |s''''|, with the path's own
    curvature at s(t)."""
    t = np.linspace(0.0, law.duration, 2001)
    s, ds, dds, _ = law.evaluate(t)
    kappa, dkappa = path.curvature(path.parameter_at(s))
    g2 = 1.0 / (law.eta * law.mass)
    rhs = (g2 + 6 * kappa**2 * ds**2) * dds + 3 * kappa * dkappa * ds**4
    s4 = law.fourth_derivative(t)
    return float(np.abs(s4 - rhs).max() / (1 + np.abs(s4).max()))


def bvp_law(path: Path, T: float, eta: float, m: float, tol: float) -> OptimalLaw:
    """The law by solve_bvp with continuation in the curvature (the solver used before), at
    ``tol`` or, when solve_bvp cannot reach it, at 10 tol."""
    S = path.length
    sol = _solve_local(path, S, T / math.sqrt(eta * m), tol)
    if sol.sigma is None:
        sol = _solve_local(path, S, T / math.sqrt(eta * m), 10 * tol)
    law = OptimalLaw(distance=S, duration=T, eta=eta, mass=m, sigma=sol.sigma,
                     residual=sol.residual, nodes=sol.nodes)
    kin, inert = law_cost(law, path, m, eta, nodes=max(64, 2 * sol.nodes))
    return OptimalLaw(distance=S, duration=T, eta=eta, mass=m, sigma=sol.sigma,
                      residual=sol.residual, nodes=sol.nodes, kinetic=kin, inertial=inert)


def difference(a: OptimalLaw, b: OptimalLaw) -> float:
    t = np.linspace(0.0, a.duration, 2001)
    ya, yb = a.evaluate(t)[:3], b.evaluate(t)[:3]
    return float(max(np.abs(ya[k] - yb[k]).max() / np.ptp(yb[k]) for k in range(3)))


def main() -> None:
    print("1. semicircle R = 120/87 L, T = 1, m = 1 (paper units), each eta from a cold start")
    for eta in (1e-5, 1e-3, 0.1, 10.0, 1e3, 1e5):
        solve_optimal_law(SEMI, eta=eta)  # the operators built once
        times, law = timed(lambda e=eta: solve_optimal_law(SEMI, eta=e), 7)
        ref, rtol = semicircle_bvp_cost(eta)
        print(f"  eta = {eta:<7g} solve {spread(times)}  nodes {law.nodes:4d}  ODE residual "
              f"{semicircle_residual(law, eta):.1e}  cost {law.cost:.12g} (solve_bvp at "
              f"{rtol:g}: {ref:.12g}, rel. diff. {abs(law.cost - ref) / ref:.1e})")
    print("  floor: eta = 0.1 under 2 ms, every eta converges")

    sc = load_scenario(EXAMPLE)
    cases = [
        ("unit spline, eta = 0.01", Spline(((0.0, 1.0), (0.3, 1.2), (0.6, 1.0), (1.0, 1.3))),
         1.0, 0.01, 1.0),
        ("examples/spline_si.toml", sc.path, sc.law_table.duration_s, 0.002, sc.effector_mass),
        ("expression, eta = 0.01", ExpressionPath("0.3*cos(p)", "1.2 + 0.2*sin(2*p)", 0.0, 3.0),
         1.0, 0.01, 1.0),
    ]
    print("2. varying curvature: ours, the solver used before (solve_bvp 1e-8) and a solve_bvp "
          "reference at 1e-9")
    for name, path, T, eta, m in cases:
        times, law = timed(lambda p=path, T=T, e=eta, m=m: solve_optimal_law(
            p, duration=T, eta=e, mass=m), 5)
        old_times, old = timed(lambda p=path, T=T, e=eta, m=m: bvp_law(p, T, e, m, 1e-8), 3)
        ref = bvp_law(path, T, eta, m, 1e-9)
        print(f"  {name}  (m = {m:g}, T = {T:g})")
        print(f"    ours          {spread(times)}  {law.message}")
        print(f"    before        {spread(old_times)}  solve_bvp, {old.nodes} nodes")
        print(f"    speed-up      {np.median(old_times) / np.median(times):.1f}x (medians)")
        for label, x in (("ours", law), ("before", old), ("reference", ref)):
            print(f"    {label:<10}  Euler-Lagrange residual {el_residual(path, x):.1e}  cost "
                  f"{x.cost:.12g} (rel. to the reference {abs(x.cost - ref.cost) / ref.cost:.1e})"
                  f"  s, sdot, sddot from the reference {difference(x, ref):.1e}")
    print("  floor: the spline under 20 ms")


if __name__ == "__main__":
    main()
