"""IK and FK throughput on 1e6 points, one core (floor: 60 ns/point each).

Run: python benchmarks/bench_kinematics.py
"""

from __future__ import annotations

import time

import numpy as np

import dextar as dx


def best_of(fn, repeat: int = 5) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    n = 1_000_000
    rng = np.random.default_rng(0)
    robot = dx.DEXTAR_MM
    # points on and around the paper's semicircle, all reachable in "+-"
    ang = rng.uniform(0.0, np.pi, n)
    rad = rng.uniform(80.0, 125.0, n)
    P = np.stack([rad * np.cos(ang), rad * np.sin(ang)], axis=-1)
    q = dx.inverse_kinematics(robot, P, "+-")
    t_ik = best_of(lambda: dx.inverse_kinematics(robot, P, "+-"))
    t_fk = best_of(lambda: dx.direct_kinematics(robot, q, "up"))
    err = np.abs(dx.direct_kinematics(robot, q, "up") - P).max()
    print(f"IK: {t_ik / n * 1e9:7.1f} ns/point  ({n:.0e} points, floor 60)")
    print(f"FK: {t_fk / n * 1e9:7.1f} ns/point  ({n:.0e} points, floor 60)")
    print(f"max |fk(ik(P)) - P| = {err:.2e} mm")


if __name__ == "__main__":
    main()
