"""IK and FK throughput on 1e6 points, one core (floor: 60 ns/point each): the best of 7 runs,
the median and the worst shown.

Run: python benchmarks/bench_kinematics.py
"""

from __future__ import annotations

import time

import numpy as np

import dextar as dx


def times_of(fn, repeat: int = 7) -> np.ndarray:
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return np.array(out)


def line(name: str, t: np.ndarray, n: int) -> str:
    ns = t / n * 1e9
    return (f"{name}: {ns.min():7.1f} ns/point best (median {np.median(ns):.1f}, worst "
            f"{ns.max():.1f}; {n:.0e} points, floor 60: "
            f"{'met' if ns.min() <= 60 else 'NOT met'})")


def main() -> None:
    n = 1_000_000
    rng = np.random.default_rng(0)
    robot = dx.DEXTAR_MM
    # points on and around the paper's semicircle, all reachable in "+-"
    ang = rng.uniform(0.0, np.pi, n)
    rad = rng.uniform(80.0, 125.0, n)
    P = np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=-1)
    q = dx.inverse_kinematics(robot, P, "+-")
    t_ik = times_of(lambda: dx.inverse_kinematics(robot, P, "+-"))
    t_fk = times_of(lambda: dx.direct_kinematics(robot, q, "up"))
    err = np.abs(dx.direct_kinematics(robot, q, "up") - P).max()
    print(line("IK", t_ik, n))
    print(line("FK", t_fk, n))
    print(f"max |fk(ik(P)) - P| = {err:.2e} mm")


if __name__ == "__main__":
    main()
