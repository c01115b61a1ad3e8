"""The jerk-limited time-optimal law: against Ruckig on joint moves, its convergence to the
second-order law as the jerk limit grows, and its planning time per pick-and-place move
against today's (second-order) time-optimal law, in one process.

Run: taskset -c 0 python benchmarks/bench_smooth.py   (ruckig: pip install -e '.[bench]')

Floors: joint moves within 1 % of Ruckig's duration and never below; within 1 % of the
second-order duration at 100 times the binding jerk; a pick-and-place move within 3x "today's
time-optimal planning time" (issue 22): the second-order law as issue 22 measured it, with
no compiled part (its passes in Python, the numpy torque kernel: the same time as that day's
code, measured side by side), timed in the same rounds. The second-order law as it runs now
(compiled passes and kernels, about 3x faster since issue 23) is timed beside them and the
ratio to it printed too (no floor).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from dextar.config import load_scenario
from dextar.dynamics import Model, RobotAlongJointLine, RobotAlongPath, exact
from dextar.laws import solve_jerk_limited_law, solve_time_optimal_law, time_optimal
from dextar.motors import MotorLimits
from dextar.paths import Line
from dextar.trajectory import JointLine

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pick_place.toml"
JOINT_MOVES = [((2.2, 0.9), (1.6, 0.5), (3.0, 2.5), (40.0, 30.0), (800.0, 600.0)),
               ((2.2, 0.9), (1.2, 1.4), (3.0, 3.0), (20.0, 30.0), (100.0, 600.0)),
               ((2.0, 0.7), (2.05, 0.72), (3.0, 3.0), (40.0, 40.0), (400.0, 400.0)),
               ((1.0, 1.5), (2.5, 0.2), (2.0, 4.0), (10.0, 50.0), (200.0, 300.0))]


def best(fn, repeat: int = 5) -> tuple[float, float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), max(times), out


def ruckig_duration(q0, q1, V, A, J) -> float:
    import ruckig

    inp = ruckig.InputParameter(2)
    inp.current_position, inp.target_position = list(q0), list(q1)
    inp.current_velocity = inp.current_acceleration = [0.0, 0.0]
    inp.target_velocity = inp.target_acceleration = [0.0, 0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = list(V), list(A), list(J)
    inp.synchronization = ruckig.Synchronization.Phase
    traj = ruckig.Trajectory(2)
    ruckig.Ruckig(2).calculate(inp, traj)
    return float(traj.duration)


def main() -> None:
    sc = load_scenario(EXAMPLE)
    m = sc.si_model
    model = Model(m.robot, m.inertia, "up")
    print("joint moves against Ruckig (phase-synchronised, rest to rest, same limits):")
    for q0, q1, V, A, J in JOINT_MOVES:
        law = solve_jerk_limited_law(RobotAlongJointLine(model, JointLine(q0, q1)),
                                     motors=MotorLimits((50.0, 50.0), V, None, A, J))
        try:
            ref = ruckig_duration(q0, q1, V, A, J)
        except ImportError:
            print(f"  {q0} -> {q1}: ours {law.duration:.6f} s; ruckig not installed")
            continue
        print(f"  {q0} -> {q1}: ours {law.duration:.6f} s, Ruckig {ref:.6f} s, "
              f"{law.duration / ref - 1:+.2e} relative ({law.solves} programmes)")
    path = Line((-0.04, 0.09), (0.04, 0.12))
    along = RobotAlongPath(model, path, "+-")
    second = solve_time_optimal_law(along, torque_limit=(0.3, 0.3))
    tr = along.samples(second, np.linspace(0, second.duration, 2001))
    J0 = 4 * np.abs(tr.ddq).max() / second.duration
    print(f"convergence on a torque-limited line (second-order {second.duration:.6f} s, "
          f"binding jerk J0 = 4 a / T = {J0:.4g} rad/s^3):")
    for k in (1, 3, 10, 30, 100, 300):
        law = solve_jerk_limited_law(along, motors=MotorLimits((0.3, 0.3),
                                                               max_jerk=(k * J0, k * J0)))
        print(f"  {k:4d} J0: {law.duration:.6f} s, {law.duration / second.duration - 1:+.3%}")
    print("planning time per pick-and-place move (the law alone; 15 interleaved rounds, best "
          "[median]):")
    limits = sc.si_motors
    assert limits is not None
    jerky = MotorLimits(limits.peak_torque, limits.max_speed, limits.knee_speed,
                        (60.0, 60.0), (3000.0, 3000.0))
    compiled = exact.USE_COMPILED, time_optimal.USE_COMPILED
    for a, b in (((-0.04, 0.11), (-0.04, 0.09)), ((0.04, 0.09), (0.04, 0.11))):
        mv = RobotAlongPath(sc.si_model, Line(a, b), sc.mode)
        t2s, t22, t3s = [], [], []
        for _ in range(15):  # a round each: the machine's load falls on all alike
            t0 = time.perf_counter()
            l2 = solve_time_optimal_law(mv, motors=limits, grid=400)
            t1 = time.perf_counter()
            exact.USE_COMPILED = time_optimal.USE_COMPILED = False  # (issue 22's law)
            ref = solve_time_optimal_law(mv, motors=limits, grid=400)
            exact.USE_COMPILED, time_optimal.USE_COMPILED = compiled
            t2 = time.perf_counter()
            l3 = solve_jerk_limited_law(mv, motors=jerky, grid=400)
            t2s.append(t1 - t0)
            t22.append(t2 - t1)
            t3s.append(time.perf_counter() - t2)
        assert abs(ref.duration - l2.duration) <= 1e-9 * l2.duration
        ratio = float(np.median(np.array(t3s) / np.array(t22)))
        now = float(np.median(np.array(t3s) / np.array(t2s)))
        print(f"  line {a} -> {b} m: jerk-limited {min(t3s) * 1e3:.1f} ms "
              f"[{np.median(t3s) * 1e3:.1f}] ({l3.duration:.4f} s, {l3.solves} programmes); "
              f"second order as issue 22 measured it {min(t22) * 1e3:.1f} ms "
              f"[{np.median(t22) * 1e3:.1f}] ({ref.duration:.4f} s): {ratio:.2f}x median of "
              f"the rounds' ratios (floor 3x: {'met' if ratio <= 3 else 'NOT met'}); second "
              f"order now {min(t2s) * 1e3:.1f} ms [{np.median(t2s) * 1e3:.1f}]: {now:.2f}x")

if __name__ == "__main__":
    main()
