"""Excitation that excites at every seed (issue 28, item 2): 20 seeds of `dextar excite
--duration 15` on two robots, each design checked against its coverage floors (and designed
again from new deterministic starts when it misses them), tracked by MuJoCo, identified, and
the identified model's prediction error on a line and an arc it never saw.

* **gravity**: issue 28's robot (l1 = 80, l2 = 75, L1 = 95, L2 = 92, d = 58 mm, a 0.28 kg
  effector, gravity tilted by 9.4 deg, friction 0.02 N m + 0.005 N m s/rad, 1.5 N m motors of
  30 rad/s);
* **dry friction**: issue 28's user robot lying flat (l1 = l2 = 120, L1 = L2 = 180, d = 100
  mm, a 0.1 kg effector with a 0.3 kg payload, no gravity, dry friction 0.03 N m + 0.005 N m
  s/rad, 1.5 N m motors of 30 rad/s).

MuJoCo's robot has other masses and rotors than the config's (tests/identification/
mujoco_harness.py, a 100 Hz PD loop at 10 kHz); angles through a 17-bit encoder and 50 mN m
of torque noise (3 % of the motors' peak: a current sensor's), so that what the excitation
does not excite shows. For each seed the first design (the seed's own starts: the former
`excite`) and the design kept after the floors are printed with their coverage (each
motor's range, speed and acceleration as % of their references), condition number, the
identification's status and the worst prediction error on the line and the arc (RMS,
% of the RMS torque, motor A / D); then the worst of each robot.

With ``--scales``: whether missing a floor makes a worse model. The gravity robot's designs
at seeds 0-2 shrunk about their rest pose (1, 0.6, 0.4, 0.25, 0.15 of their size), each
one's coverage (% of the references, motor A / D, and whether a floor is missed), then
tracked, identified with 50 mN m of noise, and their prediction error on the line and arc
and on the other seeds' full-size designs (against the true model). The floors are advisory
because the error grows gradually as the motion shrinks, whatever the floors say
(src/dextar/identification/excite.py's doc).

Run: python benchmarks/bench_excite_seeds.py [SEEDS]   (needs mujoco; about 25 minutes)
     python benchmarks/bench_excite_seeds.py --scales  (about 10 minutes)
"""

from __future__ import annotations

import importlib.util
import math
import sys
import time
from pathlib import Path

import numpy as np

from dextar.config.scenario import scenario_from_dict
from dextar.dynamics import Model
from dextar.errors import DextarError
from dextar.identification import excite as design
from dextar.identification.base import base_parameters
from dextar.identification.data import MotionData
from dextar.identification.fit import identify, validate
from dextar.program import plan_program

ROOT = Path(__file__).resolve().parents[1]
COUNT = 2 * np.pi / 2**17
NOISE = 0.05
TILT = math.radians(9.4)

ROBOTS = {
    "gravity": (
        {"robot": {"l1": 80.0, "l2": 75.0, "L1": 95.0, "L2": 92.0, "d": 58.0,
                   "working_mode": "+-"},
         "inertia": {"effector_mass": 0.28, "proximal_mass": 0.095, "distal_mass": 0.06},
         "friction": {"coulomb": 0.02, "viscous": 0.005},
         "gravity": {"vector": [9810.0 * math.sin(TILT), -9810.0 * math.cos(TILT)]},
         "motors": {"peak_torque": 1.5, "max_speed_rpm": 286.0}},
        {"program": {"start": [-40.0, 110.0], "law": "min-jerk"},
         "move": [{"type": "line", "to": [20.0, 100.0], "duration": 1.0},
                  {"type": "arc", "via": [-10.0, 145.0], "to": [-40.0, 110.0],
                   "duration": 1.5}]},
        (0.02, 0.005)),
    "dry friction": (
        {"robot": {"l1": 120.0, "l2": 120.0, "L1": 180.0, "L2": 180.0, "d": 100.0,
                   "working_mode": "+-"},
         "inertia": {"effector_mass": 0.1, "payload": 0.3, "proximal_mass": 0.1,
                     "distal_mass": 0.08},
         "friction": {"coulomb": 0.03, "viscous": 0.005},
         "motors": {"peak_torque": 1.5, "max_speed_rpm": 286.0}},
        {"program": {"start": [-60.0, 200.0], "law": "min-jerk"},
         "move": [{"type": "line", "to": [60.0, 180.0], "duration": 1.0},
                  {"type": "arc", "via": [0.0, 250.0], "to": [-60.0, 200.0],
                   "duration": 1.5}]},
        (0.03, 0.005)),
}


def harness():
    spec = importlib.util.spec_from_file_location(
        "mujoco_harness", ROOT / "tests" / "identification" / "mujoco_harness.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["mujoco_harness"] = mod
    spec.loader.exec_module(mod)
    return mod


def sampled(t, q, dq, ddq):
    def motion(tt):
        i = np.clip(np.round((tt - t[0]) / (t[1] - t[0])).astype(int), 0, len(t) - 1)
        return q[i], dq[i], ddq[i]
    return motion


def measured(run, rng=None):
    tau = run.tau if rng is None else run.tau + rng.normal(scale=NOISE, size=run.tau.shape)
    return MotionData(run.t, np.round(run.q / COUNT) * COUNT, tau)


def unseen(H, sc, task_doc, true):
    model = sc.si_model
    task = scenario_from_dict({**sc.doc, **task_doc})
    pp = plan_program(model.robot, model.inertia, task.moves, start=task.program_start,
                      working_mode=sc.mode, motors=sc.si_motors, servo_rate_hz=10000.0)
    cut = int(np.searchsorted(pp.t, 1.0))
    out = {}
    for name, sl in (("line", slice(0, cut + 1)), ("arc", slice(cut, None))):
        t = pp.t[sl] - pp.t[sl][0]
        run = H.track(true, model, sampled(t, pp.q[sl], pp.dq[sl], pp.ddq[sl]), float(t[-1]))
        out[name] = measured(run)
    return out


def fractions(ex) -> str:
    c = ex.coverage
    return " ".join(f"{100 * c.fractions[k][0]:3.0f}/{100 * c.fractions[k][1]:<3.0f}"
                    for k in ("range", "speed", "acceleration"))


def evaluate(H, true, model, mode, ex, val, base, seed):
    run = H.track(true, model, ex.trajectory.evaluate, ex.duration)
    if run.type2_sign_changes or run.tracking_error_deg > 1.0:
        return "lost tracking", np.full(2, np.inf)
    try:
        res = identify(measured(run, np.random.default_rng(seed)), model, mode=mode, base=base)
    except DextarError as exc:
        return f"refused: {str(exc)[:60]}", np.full(2, np.inf)
    err = np.maximum(*(validate(res, d, model, mode=mode).error for d in val.values()))
    return res.status_text, err


def scales(H) -> None:
    """The coverage and the prediction error of designs shrunk about their rest pose."""
    from dextar.dynamics import inverse_dynamics
    from dextar.dynamics.regressor import regressor

    doc, task_doc, (fc, fv) = ROBOTS["gravity"]
    sc = scenario_from_dict({**doc, "output": {"servo_rate_hz": 1000.0}})
    model, motors = sc.si_model, sc.si_motors
    t0 = H.true_robot(model)
    true = Model(t0.robot, t0.inertia.with_(viscous=(fv, fv), coulomb=(fc, fc)), t0.assembly)
    val = unseen(H, sc, task_doc, true)
    base = base_parameters(model)
    designs = {s: design.design_excitation(model, sc.mode, duration=15.0, motors=motors,
                                           seed=s, base=base) for s in range(3)}
    tt = np.arange(0.0, 5.0, 0.002)
    others = {s: ex.trajectory.evaluate(tt) for s, ex in designs.items()}
    truth = {s: inverse_dynamics(true, *m) for s, m in others.items()}
    rng = np.random.default_rng(11)
    print("seed scale | range/speed/acc % of the references A/D, floors | status, error line/arc "
          "A/D %, error on the other seeds' designs A/D %")
    for seed, ex in designs.items():
        ref = design.coverage_reference(model, ex.trajectory.q0, 5, 0.2, motors, None)
        for f in (1.0, 0.6, 0.4, 0.25, 0.15):
            tr = design.FourierTrajectory(ex.trajectory.q0, f * ex.trajectory.a,
                                          f * ex.trajectory.b, ex.trajectory.base_hz)
            sv = design._singular_values(model, base, *tr.evaluate(tt[::10]))
            cond = math.inf if sv is None else float(sv[0] / sv[-1])
            cov = design.check_coverage(tr, ref, cond)
            fr = " ".join(f"{100 * cov.fractions[k][0]:3.0f}/{100 * cov.fractions[k][1]:<3.0f}"
                          for k in ("range", "speed", "acceleration"))
            run = H.track(true, model, tr.evaluate, ex.duration)
            try:
                res = identify(measured(run, rng), model, mode=sc.mode, base=base)
            except DextarError as exc:
                print(f"{seed:4d} {f:5.2f} | {fr} | refused: {str(exc)[:60]}")
                continue
            err = np.maximum(*(validate(res, d, model, mode=sc.mode).error
                               for d in val.values()))
            oth = np.max([np.sqrt(((regressor(model, *others[s]) @ res.theta - truth[s]) ** 2
                                   ).mean(axis=0)) / np.sqrt((truth[s] ** 2).mean(axis=0))
                          for s in others if s != seed], axis=0)
            print(f"{seed:4d} {f:5.2f} | {fr} {'met   ' if cov.met else 'missed'} | "
                  f"{res.status_text:<17} {100 * err[0]:5.2f} / {100 * err[1]:5.2f} | "
                  f"{100 * oth[0]:5.2f} / {100 * oth[1]:5.2f}", flush=True)


def main() -> None:
    if sys.argv[1:] == ["--scales"]:
        scales(harness())
        return
    seeds = [int(s) for s in sys.argv[1:]] or list(range(20))
    H = harness()
    print(f"advisory floors: range {100 * design.RANGE_FLOOR:g} %, speed "
          f"{100 * design.SPEED_FLOOR:g} %, acceleration {100 * design.ACCELERATION_FLOOR:g} % "
          "of the references (identification.excite.coverage_reference), condition "
          f"number at most {design.COND_CEILING:g}; up to {design.ATTEMPTS} designs")
    for name, (doc, task_doc, (fc, fv)) in ROBOTS.items():
        sc = scenario_from_dict({**doc, "output": {"servo_rate_hz": 1000.0}})
        model, motors = sc.si_model, sc.si_motors
        t0 = H.true_robot(model)
        true = Model(t0.robot, t0.inertia.with_(viscous=(fv, fv), coulomb=(fc, fc)),
                     t0.assembly)
        val = unseen(H, sc, task_doc, true)
        base = base_parameters(model)
        print(f"\n{name}: seed | first design: range/speed/acc % A/D, cond, status, error "
              "A/D % | kept design (attempts): the same")
        worst_first, worst_kept = np.zeros(2), np.zeros(2)
        for seed in seeds:
            attempts = design.ATTEMPTS
            try:
                design.ATTEMPTS = 1
                first = design.design_excitation(model, sc.mode, duration=15.0, motors=motors,
                                            seed=seed, base=base)
            finally:
                design.ATTEMPTS = attempts
            t = time.perf_counter()
            kept = design.design_excitation(model, sc.mode, duration=15.0, motors=motors,
                                       seed=seed, base=base)
            dt = time.perf_counter() - t
            s1, e1 = evaluate(H, true, model, sc.mode, first, val, base, seed)
            line = (f"{seed:4d} | {fractions(first)} {first.condition_number:5.2f} {s1:<17} "
                    f"{100 * e1[0]:6.3f} / {100 * e1[1]:6.3f} | ")
            worst_first = np.maximum(worst_first, e1)
            if kept.attempts == 1:
                e2 = e1
                line += f"the same ({dt:.0f} s)"
            else:
                s2, e2 = evaluate(H, true, model, sc.mode, kept, val, base, seed)
                line += (f"{fractions(kept)} {kept.condition_number:5.2f} {s2:<17} "
                         f"{100 * e2[0]:6.3f} / {100 * e2[1]:6.3f} ({kept.attempts}, "
                         f"{dt:.0f} s){'' if kept.coverage.met else ' floors missed'}")
            worst_kept = np.maximum(worst_kept, e2)
            print(line, flush=True)
        print(f"{name}: worst prediction error over {len(seeds)} seeds: first designs "
              f"{100 * worst_first[0]:.3g} / {100 * worst_first[1]:.3g} %, designs kept "
              f"{100 * worst_kept[0]:.3g} / {100 * worst_kept[1]:.3g} %")


if __name__ == "__main__":
    main()
