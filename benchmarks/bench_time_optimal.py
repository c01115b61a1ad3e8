"""Our time-optimal law against toppra 0.6.10 on the same path, dynamics and grid, in one run.

Run: python benchmarks/bench_time_optimal.py   (toppra: pip install -e '.[bench]')

Both solve the same problem: the paper's semicircle in SI (0.1 kg end-effector, rods,
rotors, gravity along -y), motor torque limits 0.5 N m, the interpolation discretisation on
400 and 2000 segments. toppra gets the path dynamics as arrays (the coefficients ``a, b, c``
of ``tau = a u + b x + c`` that ours computes, through a ``LinearConstraint``), so its time is
its solver's; ours is timed end to end (coefficients, solve, and the output check that ours
adds). Prints both times and both durations (floor: ours no slower than toppra, durations
within 1e-4 relative).
"""

from __future__ import annotations

import time

import numpy as np

from dextar.config import scenario_from_dict
from dextar.dynamics import RobotAlongPath
from dextar.laws import solve_time_optimal_law

DOC = {"path": {"type": "arc", "radius": 120.0},
       "inertia": {"effector_mass": 0.1, "proximal_mass": 0.03, "distal_mass": 0.02,
                   "rotor_inertia": 2.0},
       "gravity": {"vector": [0.0, -9810.0]},
       "law": {"type": "time-optimal", "torque_limit": 0.5}, "output": {"units": "si"}}
LIMIT = np.array([0.5, 0.5])


def best(fn, repeat: int = 15) -> tuple[float, object]:
    out, t_best = None, np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        t_best = min(t_best, time.perf_counter() - t0)
    return t_best, out


def toppra_duration(along: RobotAlongPath, n: int) -> tuple[float, float]:
    import toppra as ta
    from toppra.constraint.linear_constraint import (
        DiscretizationType,
        LinearConstraint,
        canlinear_colloc_to_interpolate,
    )

    co = along.coefficients(np.linspace(0.0, along.length, n + 1))

    class Torque(LinearConstraint):
        def __init__(self) -> None:
            super().__init__()
            self.discretization_type = DiscretizationType.Interpolation
            self.identical = True

        def compute_constraint_params(self, path, gridpoints, *args, **kwargs):
            F = np.vstack([np.eye(2), -np.eye(2)])
            g = np.concatenate([LIMIT, LIMIT])
            return canlinear_colloc_to_interpolate(co.a, co.b, co.g, F, g, None, None,
                                                   gridpoints, identical=True)

    class JointPath(ta.interpolator.AbstractGeometricPath):
        dof = 2
        path_interval = np.array([0.0, float(co.s[-1])])

        def __call__(self, s, order=0):  # only the grid is used by the parameterisation
            return np.zeros((np.size(s), 2))

    grid = co.s

    def solve() -> np.ndarray:
        inst = ta.algorithm.TOPPRA([Torque()], JointPath(), gridpoints=grid,
                                   solver_wrapper="seidel")
        _, sd, _ = inst.compute_parameterization(0, 0)  # (sdd, sd, v)
        return np.asarray(sd)

    t, sd = best(solve)
    sd = np.asarray(sd)
    duration = float(np.sum(2 * np.diff(grid) / (sd[:-1] + sd[1:])))
    return t, duration


def main() -> None:
    sc = scenario_from_dict(DOC)
    along = RobotAlongPath(sc.model(), sc.path, sc.mode, sc.units)
    for n in (400, 2000):
        t_ours, law = best(lambda n=n: solve_time_optimal_law(along, torque_limit=tuple(LIMIT),
                                                               grid=n))
        line = f"grid {n:5d}: ours {t_ours * 1e3:7.1f} ms, duration {law.duration:.8f} s"
        try:
            t_tp, d_tp = toppra_duration(along, n)
        except ImportError:
            print(line + "; toppra not installed (pip install -e '.[bench]')")
            continue
        rel = abs(law.duration - d_tp) / d_tp
        print(f"{line} | toppra {t_tp * 1e3:7.1f} ms, duration {d_tp:.8f} s | durations "
              f"differ by {rel:.1e} relative; ours/toppra time {t_ours / t_tp:.2f}")
    print("floor: ours no slower than toppra at both grids, durations within 1e-4")


if __name__ == "__main__":
    main()
