"""Our time-optimal law against toppra 0.6.10 on the same path, dynamics and grid, in one run,
and where our time goes.

Run: python benchmarks/bench_time_optimal.py [--rounds N]  (toppra: pip install -e '.[bench]')

Both solve the same problem: the paper's semicircle in SI (0.1 kg end-effector, rods,
rotors, gravity along -y), motor torque limits 0.5 N m, the interpolation discretisation on
100, 400 and 2000 segments. toppra gets the path dynamics as arrays (the coefficients
``a, b, c`` of ``tau = a u + b x + c`` that ours computes, through a ``LinearConstraint``), so
its time is its solver's alone (the seidel solver wrapper, its fastest). Ours is timed end to
end (``solve_time_optimal_law``: the coefficients, the solve and the output check, which
toppra does not do) and in parts:

* coefficients: the path dynamics on the grid (kinematics, the path's checks, the exact
  model);
* rows: the constraints' rows of every stage (NumPy);
* passes: the stages' elimination and the backward and forward passes (compiled where the
  extension was built, ``dextar.laws.time_optimal.USE_COMPILED``; else Python);
* check: the law sampled nine times a segment through the exact model (the inverse dynamics
  of ``dextar.dynamics.exact`` on 9 N samples) and the ratios to the limits;
* other: the rest (the grid, the law from the squared speeds, its words).

"solver" is rows + passes + the law. Ours with the Python passes (what an install without a
C compiler runs) is timed in the same rounds. The rounds interleave ours and toppra's (ratios
taken round by round: the machine's speed drifts); best of the rounds, the median and the
worst shown. Floor (issue 23): ours end to end at or under 0.3x toppra's solver time at 400
and 2000 segments and no slower than it at 100, as the median of the rounds' ratios;
durations within 1e-4.
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

import numpy as np

import dextar.laws.time_optimal as to
from dextar.config import scenario_from_dict
from dextar.dynamics import RobotAlongPath

DOC = {"path": {"type": "arc", "radius": 120.0},
       "inertia": {"effector_mass": 0.1, "proximal_mass": 0.03, "distal_mass": 0.02,
                   "rotor_inertia": 2.0},
       "gravity": {"vector": [0.0, -9810.0]},
       "law": {"type": "time-optimal", "torque_limit": 0.5}, "output": {"units": "si"}}
LIMIT = np.array([0.5, 0.5])
GRIDS = (100, 400, 2000)

#: The solver's parts, by the module functions that do them (outermost call only).
PARTS = {"_rows": "rows", "_passes": "passes", "_law": "law", "ratios_by_kind": "check"}


class Timed:
    """The robot along the path, its coefficients and check samples timed."""

    def __init__(self, along: RobotAlongPath, acc: dict[str, float]) -> None:
        self.along, self.acc = along, acc

    @property
    def length(self) -> float:
        return self.along.length

    def coefficients(self, s):
        t = time.perf_counter()
        out = self.along.coefficients(s)
        self.acc["coefficients"] += time.perf_counter() - t
        return out

    def samples(self, law, times):
        t = time.perf_counter()
        out = self.along.samples(law, times)
        self.acc["check"] += time.perf_counter() - t
        return out


def instrument(acc: dict[str, float]) -> None:
    """Time the solver's module functions into ``acc`` (outermost call only)."""
    depth = [0]
    for name, part in PARTS.items():
        fn = getattr(to, name)

        def timed(*a, _fn=fn, _part=part, **k):
            depth[0] += 1
            t = time.perf_counter()
            try:
                return _fn(*a, **k)
            finally:
                depth[0] -= 1
                if depth[0] == 0:
                    acc[_part] += time.perf_counter() - t

        setattr(to, name, timed)


def toppra_solver(along: RobotAlongPath, n: int):
    """toppra's solve on our coefficients: (callable returning the duration)."""
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

    def solve() -> float:
        inst = ta.algorithm.TOPPRA([Torque()], JointPath(), gridpoints=grid,
                                   solver_wrapper="seidel")
        _, sd, _ = inst.compute_parameterization(0, 0)  # (sdd, sd, v)
        sd = np.asarray(sd)
        return float(np.sum(2 * np.diff(grid) / (sd[:-1] + sd[1:])))

    return solve


def spread(v: list[float], scale: float = 1e3) -> str:
    return (f"best {min(v) * scale:7.2f} median {np.median(v) * scale:7.2f} worst "
            f"{max(v) * scale:7.2f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=15)
    args = ap.parse_args()
    sc = scenario_from_dict(DOC)
    along = RobotAlongPath(sc.model(), sc.path, sc.mode, sc.units)
    acc: dict[str, float] = defaultdict(float)
    instrument(acc)
    timed = Timed(along, acc)
    compiled = to.USE_COMPILED
    print(f"passes compiled: {compiled}")
    verdicts = []
    for n in GRIDS:
        try:
            theirs = toppra_solver(along, n)
        except ImportError:
            theirs = None
        ours_t, py_t, tp_t, parts = [], [], [], defaultdict(list)
        law = py_law = None
        for _ in range(args.rounds):
            acc.clear()
            to.USE_COMPILED = compiled
            t0 = time.perf_counter()
            law = to.solve_time_optimal_law(timed, torque_limit=tuple(LIMIT), grid=n)
            ours_t.append(time.perf_counter() - t0)
            for k, v in acc.items():
                parts[k].append(v)
            parts["other"].append(ours_t[-1] - sum(acc.values()))
            to.USE_COMPILED = False
            t0 = time.perf_counter()
            py_law = to.solve_time_optimal_law(along, torque_limit=tuple(LIMIT), grid=n)
            py_t.append(time.perf_counter() - t0)
            to.USE_COMPILED = compiled
            if theirs is not None:
                t0 = time.perf_counter()
                d_tp = theirs()
                tp_t.append(time.perf_counter() - t0)
        assert law is not None and py_law is not None
        solver = [sum(parts[p][i] for p in ("rows", "passes", "law"))
                  for i in range(args.rounds)]
        print(f"grid {n:5d}: duration {law.duration:.10f} s, {law.solves} solve(s); the Python "
              f"passes' law {'the same to the last bit' if np.array_equal(law.knots_v, py_law.knots_v) else 'DIFFERS'}")
        print(f"  ours end to end   {spread(ours_t)} ms")
        for p in ("coefficients", "rows", "passes", "law", "check", "other"):
            print(f"    {p:22s}  {spread(parts[p])} ms")
        print(f"  ours solver       {spread(solver)} ms (rows, passes, law)")
        print(f"  ours, Python passes, end to end {spread(py_t)} ms")
        if theirs is None:
            print("  toppra not installed (pip install -e '.[bench]')")
            continue
        rel = abs(law.duration - d_tp) / d_tp
        r_all = np.array(ours_t) / np.array(tp_t)
        r_solver = np.array(solver) / np.array(tp_t)
        r_py = np.array(py_t) / np.array(tp_t)
        print(f"  toppra solver     {spread(tp_t)} ms, duration {d_tp:.10f} s (differs by "
              f"{rel:.1e})")
        print(f"  ours/toppra: end to end {min(ours_t) / min(tp_t):.2f} best/best, "
              f"{np.median(r_all):.2f} median of the rounds' ratios; solver "
              f"{min(solver) / min(tp_t):.2f} best/best, {np.median(r_solver):.2f} median; "
              f"end to end with the Python passes {np.median(r_py):.2f} median")
        bound = 1.0 if n < 400 else 0.3
        ok = np.median(r_all) <= bound and rel <= 1e-4
        verdicts.append(f"{n} segments {np.median(r_all):.2f}x (<= {bound:g}x: "
                        f"{'met' if ok else 'NOT met'})")
    print("floor: ours end to end / toppra's solver (median of the rounds' ratios), durations "
          "within 1e-4: " + "; ".join(verdicts))


if __name__ == "__main__":
    main()
