"""A crossing of the parallel (type 2) singularity curve, measured (issue 31): a line across the
DexTAR's curve and one across an unequal robot's (70/80/95/85/60 mm), standing vertically,
the pick-and-place's masses, 0.5 N m motors.

Run: python benchmarks/bench_crossing.py [--no-mujoco]

Prints, per robot:

* the time-optimal law under the degeneracy condition at 100, 400 and 1600 segments: its
  duration and planning time, the crossing's time and speed, the condition's residual (N and
  its ratio to the terms that cancel in it) and the torque peak near the crossing against the
  limit;
* the bounded torque at the crossing against the exact model's at 1e-5 to 1e-7 s from it;
* the condition's residual ratio of laws that ignore it (min-jerk, uniform) and of the
  planned law on robots whose masses differ (all 10 % heavier: the condition is the same, it
  is homogeneous in the masses; 1 g and 10 g more payload); the exact torque of the min-jerk law at
  1e-3 to 1e-6 s from the crossing (it grows as the inverse of the distance);
* the forward dynamics in the end-effector's coordinates under the planned torques held at
  10 kHz (open loop) against the plan;
* the singularity-robust tracking with masses 20 % off and an unknown payload (10 Hz), and
  the torque peak of the plain inverse of E instead;
* MuJoCo driven by the planned torques and the loop (30 Hz, 2 kHz), on its model of ours and
  with 20 g of payload the controller does not know, and open loop.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

import dextar as dx
from dextar.dynamics import Inertia, Model, gravity_torques
from dextar.dynamics.closed_chain import task_state
from dextar.dynamics.crossing import (
    PlannedTorques,
    RobotAcrossPath,
    crossing_margins,
    crossing_time,
)
from dextar.dynamics.forward import forward_task_dynamics
from dextar.geometry import FiveBar
from dextar.laws import MinimumJerkLaw, UniformLaw
from dextar.laws.time_optimal import solve_time_optimal_law
from dextar.motors import MotorLimits
from dextar.paths import Line
from dextar.simulation.crossing import simulate_crossing, sr_inverse
from dextar.trajectory import find_crossings, path_motion, sample_trajectory

PEAK = 0.5
CASES = {
    "DexTAR 72/72/87/87/60 mm": (dx.DEXTAR_MM.scaled(1e-3), (-0.015, 0.075), (0.010, 0.020)),
    "unequal 70/80/95/85/60 mm": (FiveBar(0.070, 0.080, 0.095, 0.085, 0.060), (-0.020, 0.080),
                                  (0.0, 0.020)),
}


def inertia(robot: FiveBar) -> Inertia:
    return Inertia.uniform(robot, proximal_mass=0.03, distal_mass=0.02, effector_mass=0.08,
                           payload=0.05, gravity=(0.0, -9.81), coulomb=(0.02, 0.02),
                           viscous=(0.01, 0.01), coulomb_speed=np.radians(0.01))


def mujoco_drive(mujoco, dyn, law, truth, *, feedback, hz=30.0, every=5, hold=0.02):
    from dextar.kinematics import assembly_mode
    from dextar.output.mjcf import to_mjcf

    tr = sample_trajectory(dyn.model.robot, dyn.path, law, mode="+-", samples=3,
                           crossings=dyn.crossings)
    m = mujoco.MjModel.from_xml_string(to_mjcf(truth, start=(tr.q[0], tr.dq[0])))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("start").id)
    mujoco.mj_forward(m, d)
    dt = m.opt.timestep
    n = int(np.ceil((law.duration + hold) / dt))
    ticks = np.arange(0, n + every, every) * dt
    mid = ticks + 0.5 * every * dt
    ff = PlannedTorques(dyn, law)(np.minimum(mid, law.duration))
    ff[mid > law.duration] = gravity_torques(replace(dyn.model, assembly="down"), tr.q[-1])
    Pd, dPd = path_motion(dyn.path, law, np.minimum(ticks, law.duration))[6:8]
    dPd[ticks > law.duration] = 0.0
    s1, s2 = m.site("tip1").id, m.site("tip2").id
    j1, j2 = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    w = 2 * np.pi * hz
    err = []
    for k in range(n):
        if k % every == 0:
            j = k // every
            P = 0.5 * (d.site_xpos[s1][:2] + d.site_xpos[s2][:2])
            mujoco.mj_jacSite(m, d, j1, None, s1)
            mujoco.mj_jacSite(m, d, j2, None, s2)
            dP = 0.5 * ((j1 + j2) @ d.qvel)[:2]
            M, _, E, _, _ = task_state(dyn.model, (1, -1), P, dP)
            tau = ff[j]
            if feedback:
                tau = tau + sr_inverse(E) @ (M @ (w * w * (Pd[j] - P) + 2 * w * (dPd[j] - dP)))
            d.ctrl[:] = tau
            err.append(float(np.linalg.norm(P - Pd[j])))
        mujoco.mj_step(m, d)
    P = 0.5 * (d.site_xpos[s1][:2] + d.site_xpos[s2][:2])
    return max(err), assembly_mode(dyn.model.robot, d.qpos[[0, 2]], P)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-mujoco", action="store_true")
    args = ap.parse_args()
    mujoco = None
    if not args.no_mujoco:
        try:
            import mujoco  # type: ignore[no-redef]
        except ImportError:
            print("(MuJoCo not installed: its part is skipped)")
    motors = MotorLimits((PEAK, PEAK))
    for name, (robot, a, b) in CASES.items():
        ine = inertia(robot)
        path = Line(a, b)
        crossings = find_crossings(robot, path, mode="+-")
        (c,) = crossings
        model = Model(robot, ine, "up", tol=0.0)
        dyn = RobotAcrossPath(model, path, "+-", crossings)
        print(f"\n== {name}: line ({1e3 * a[0]:g}, {1e3 * a[1]:g}) -> ({1e3 * b[0]:g}, "
              f"{1e3 * b[1]:g}) mm, crossing at ({1e3 * c.P[0]:.4g}, {1e3 * c.P[1]:.4g}) mm, "
              f"slope {c.slope:.4g} /m, up -> down")
        law = None
        for grid in (100, 400, 1600):
            t0 = time.perf_counter()
            lw = solve_time_optimal_law(dyn, motors=motors, grid=grid)
            dt = time.perf_counter() - t0
            (mg,) = crossing_margins(dyn, lw)
            print(f"  grid {grid:5d}: {1e3 * lw.duration:.4f} ms (status {lw.status}), planned "
                  f"in {1e3 * dt:.0f} ms; crossing at {1e3 * mg.t:.3f} ms, {mg.speed:.4f} m/s; "
                  f"residual {mg.residual:.2e} N ({mg.residual_ratio:.1e} of its terms); "
                  f"torque peak near it {mg.torque_peak[0]:.5f}, {mg.torque_peak[1]:.5f} N m "
                  f"({max(mg.torque_peak) / PEAK:.5f} of the limit)")
            if grid == 400:
                law = lw
        assert law is not None
        tc = crossing_time(law, c.s)
        at = dyn.samples(law, np.array([tc])).tau[0]
        for d in (1e-4, 1e-5, 1e-6, 1e-7):
            ex = dyn._exact(law, np.array([tc - d, tc + d]))[3].mean(axis=0)
            print(f"  bounded torque at the crossing vs the mean of the exact model's at "
                  f"+-{d:.0e} s: {np.abs(ex - at).max():.2e} N m")
        for label, other in (("min-jerk 200 ms", MinimumJerkLaw(path.length, 0.2)),
                             ("min-jerk 350 ms", MinimumJerkLaw(path.length, 0.35)),
                             ("uniform 100 ms", UniformLaw(path.length, 0.1))):
            print(f"  {label}: residual ratio {dyn.condition(other, c)[3]:.3g}")
        for label, other_ine in (("every mass 10 % heavier", ine.scaled_masses(1.1)),
                                 ("1 g more payload", ine.with_(payload=ine.payload + 1e-3)),
                                 ("10 g more payload", ine.with_(payload=ine.payload + 1e-2))):
            off = RobotAcrossPath(Model(robot, other_ine, "up", tol=0.0), path, "+-",
                                  crossings)
            print(f"  the planned law on a robot with {label}: residual ratio "
                  f"{off.condition(law, c)[3]:.3g}")
        mj = MinimumJerkLaw(path.length, 0.2)
        tm = crossing_time(mj, c.s)
        grow = [np.abs(dyn._exact(mj, np.array([tm - d, tm + d]))[3]).max()
                for d in (1e-3, 1e-4, 1e-5, 1e-6)]
        print("  min-jerk 200 ms: exact |tau| at 1e-3, 1e-4, 1e-5, 1e-6 s from the crossing: "
              + ", ".join(f"{v:.4g}" for v in grow) + " N m")
        # open loop forward dynamics
        dt = 1e-4
        t = np.arange(0.0, law.duration, dt)
        tau = PlannedTorques(dyn, law)(t[:-1] + 0.5 * dt)
        P, dP = path_motion(path, law, t)[6:8]
        t0 = time.perf_counter()
        fw = forward_task_dynamics(model, "+-",
                                   lambda tt, q, dq, tau=tau, dt=dt: tau[int(tt // dt)], P[0],
                                   dP[0], t, substeps=2)
        err = np.linalg.norm(fw.P - P, axis=-1)
        print(f"  forward dynamics (end-effector coordinates), planned torques held at 10 kHz: "
              f"largest error {1e3 * err.max():.4f} mm, at the end {1e3 * err[-1]:.4f} mm "
              f"({time.perf_counter() - t0:.2f} s)")
        # tracking
        tr = sample_trajectory(robot, path, law, mode="+-", samples=1001, crossings=crossings)
        plant = ine.scaled_masses(1.2)
        plant_m = Model(robot, plant.with_(payload=plant.payload + 0.1 * ine.effector_mass),
                        "up", tol=0.0)
        for label, damping in (("singularity-robust", None), ("plain inverse of E", 0.0)):
            t0 = time.perf_counter()
            kw = {} if damping is None else {"sr_damping": damping}
            res = simulate_crossing(tr, model, plant_m, natural_frequency=2 * np.pi * 10,
                                    time_s=1.0, length_mm=1e3, **kw)
            print(f"  tracking, masses +20 %, payload +8 g, 10 Hz, {label}: status "
                  f"{res.status}, largest error {1e3 * res.task_error.max():.4f} mm, torque "
                  f"peak {np.abs(res.tau).max():.4g} N m ({time.perf_counter() - t0:.2f} s)")
        if mujoco is not None:
            for label, extra, fb in (("its model of ours, loop", 0.0, True),
                                     ("20 g unknown payload, loop", 0.02, True),
                                     ("20 g unknown payload, open loop", 0.02, False)):
                truth = Model(robot, ine.with_(payload=ine.payload + extra), "up", tol=0.0)
                worst, end = mujoco_drive(mujoco, dyn, law, truth, feedback=fb)
                print(f"  MuJoCo, {label}: largest error {1e3 * worst:.4f} mm, ends in "
                      f"assembly {'up' if end > 0 else 'down'}")


if __name__ == "__main__":
    main()
