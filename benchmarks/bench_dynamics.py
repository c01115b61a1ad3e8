"""Exact inverse-dynamics cost per sample on 1e6 samples, one core (floor: 150 ns/sample),
and, in the same run, the cost of the MuJoCo cross-check per sample (mj_forward on the same
states with our torques), with the ratio.

Run: python benchmarks/bench_dynamics.py
"""

from __future__ import annotations

import time

import numpy as np

from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.geometry import DEXTAR_MM
from dextar.laws import solve_optimal_law
from dextar.output.mjcf import mujoco_state, to_mjcf
from dextar.paths import Arc
from dextar.trajectory import sample_trajectory


def main() -> None:
    robot = DEXTAR_MM.scaled(1 / 87)
    path = Arc(120 / 87, 0.0, np.pi)
    tr = sample_trajectory(robot, path, solve_optimal_law(path, eta=0.1), samples=10001)
    model = Model(robot, paper_inertia(robot).with_(rotor=(0.01, 0.01), gravity=(0.0, -1.0)))
    n = 1_000_000
    idx = np.random.default_rng(0).integers(0, tr.t.size, n)
    q, dq, ddq = tr.q[idx], tr.dq[idx], tr.ddq[idx]
    inverse_dynamics(model, q[:1000], dq[:1000], ddq[:1000])
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        tau = inverse_dynamics(model, q, dq, ddq)
        best = min(best, time.perf_counter() - t0)
    ours = best / n * 1e9
    print(f"exact inverse dynamics: {ours:7.1f} ns/sample on {n:.0e} samples (floor 150)")
    try:
        import mujoco
    except ImportError:
        print("mujoco not installed: no comparison")
        return
    m = mujoco.MjModel.from_xml_string(to_mjcf(model))
    d = mujoco.MjData(m)
    k = 20000
    qpos, qvel = mujoco_state(model, q[:k], dq[:k])
    acc = np.empty((k, 2))
    t0 = time.perf_counter()
    for i in range(k):
        d.qpos[:] = qpos[i]
        d.qvel[:] = qvel[i]
        d.ctrl[:] = tau[i]
        mujoco.mj_forward(m, d)
        acc[i] = d.qacc[[0, 2]]
    mj = (time.perf_counter() - t0) / k * 1e9
    rel = np.abs(acc - ddq[:k]).max() / np.abs(ddq[:k]).max()
    print(f"MuJoCo mj_forward:      {mj:7.1f} ns/sample on {k:.0e} samples (Python loop)")
    print(f"ratio MuJoCo / dextar:  {mj / ours:7.1f}")
    print(f"MuJoCo accelerations vs ours: max relative difference {rel:.1e}")


if __name__ == "__main__":
    main()
