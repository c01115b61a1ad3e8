"""Identification speed: 60 s of data at 1 kHz (120,000 torque samples) identified in
under 2 s (filtering, regressor, parallel filtering, weighted least squares, physical set;
base parameters included); reading the 60,001-row CSV within 1.5x of ``np.loadtxt`` on the
same file (best of 7 each, printed side by side); `dextar excite` (the optimisation of the
exciting trajectory) in under 10 s; `dextar identify` end to end as a user runs it. The
accuracy on MuJoCo's robot is benchmarks/bench_identify_mujoco.py.

Run: python benchmarks/bench_identify.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from dextar.config import load_scenario
from dextar.dynamics import inverse_dynamics
from dextar.dynamics.regressor import standard_parameters
from dextar.identification.base import base_parameters
from dextar.identification.data import MotionData, read_motion_csv
from dextar.identification.excite import design_excitation
from dextar.identification.fit import identify

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"


def main() -> None:
    sc = load_scenario(EXAMPLE)
    model, motors = sc.si_model, sc.si_motors
    times = []
    for seed in range(3):
        t0 = time.perf_counter()
        ex = design_excitation(model, sc.mode, duration=60.0, motors=motors, seed=seed)
        times.append(time.perf_counter() - t0)
    print(f"excite (optimised Fourier trajectory, 3 starts): {min(times):.2f} s best, "
          f"{max(times):.2f} s worst of 3 seeds (floor 10 s); condition number "
          f"{ex.condition_number:.3g}")
    t = np.arange(60001) / 1000.0
    q, dq, ddq = ex.trajectory.evaluate(t)
    tau = inverse_dynamics(model, q, dq, ddq)
    rng = np.random.default_rng(0)
    data = MotionData(t, q, tau + rng.normal(scale=0.005, size=tau.shape))
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        res = identify(data, model, mode=sc.mode)
        best = min(best, time.perf_counter() - t0)
    true = res.base.of(standard_parameters(model.inertia))
    z = np.abs(res.beta - true) / res.std
    print(f"identify 60 s at 1 kHz ({2 * len(t)} torque samples, {res.n_used} kept after "
          f"filtering at {res.cutoff_hz:.3g} Hz): {best * 1e3:.0f} ms best of 3 (floor 2 s), "
          f"base parameters included; max |error| / std = {z.max():.2f}")
    t0 = time.perf_counter()
    base_parameters(model)
    print(f"  of which base parameters: {1e3 * (time.perf_counter() - t0):.0f} ms")
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "data.csv"
        cols = np.column_stack([t, q, tau])
        np.savetxt(csv, cols, delimiter=",", fmt="%.17g",
                   header="t_s,phi_rad,psi_rad,tau1_Nm,tau2_Nm", comments="")
        ours, ref = [], []
        for _ in range(7):
            t0 = time.perf_counter()
            read_motion_csv(csv)
            ours.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            np.loadtxt(csv, delimiter=",", skiprows=1)
            ref.append(time.perf_counter() - t0)
        print(f"reading the 60,001-row CSV: read_motion_csv {1e3 * min(ours):.0f} ms "
              f"(spread {1e3 * min(ours):.0f}-{1e3 * max(ours):.0f}), np.loadtxt "
              f"{1e3 * min(ref):.0f} ms ({1e3 * min(ref):.0f}-{1e3 * max(ref):.0f}): "
              f"{min(ours) / min(ref):.2f}x (floor 1.5x)")
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "dextar", "identify", str(csv), "--config",
                        str(EXAMPLE), "--out", str(Path(tmp) / "out"), "--quiet"], check=True)
        print(f"dextar identify end to end (a new process, CSV, figure and report): "
              f"{time.perf_counter() - t0:.2f} s")


if __name__ == "__main__":
    main()
