"""The cases behind identification's verdict thresholds (issue 28, item 1): good fits and bad
ones on MuJoCo's robot, with the figures the verdict reads and the error the model then makes
on two motions it never saw.

The robot is issue 28's: l1 = 80, l2 = 75, L1 = 95, L2 = 92, d = 58 mm, a 0.28 kg effector,
gravity tilted by 9.4 deg, dry friction 0.02 N m and viscous 0.005 N m s/rad, 1.5 N m motors
of 30 rad/s. MuJoCo (tests/identification/mujoco_harness.py: other masses and rotors than
the config's, a 100 Hz PD loop at 10 kHz) tracks `dextar excite --duration 15` at seeds 0-4
and a min-jerk line (1 s) and arc (1.5 s) of the config's region; angles through a 17-bit
encoder. Each case prints per motor (A / D, %): the fit quality, the fit quality the noise
and filters explain, the predicted-torque uncertainty along the excitation's envelope and
along the line and arc (``--task``), the Mahalanobis distance of an unphysical least-squares
estimate from the physical one, the status, and the prediction error on the line and arc.

Cases: the right config with 0, 10, 50 and 150 mN m of torque noise, or a 14-bit encoder
(good); an excitation
scaled to a quarter of its size and a 3 s recording (poorly determined); the config's
gravity vertical, its l1 1 mm long, the torques 2 ms late (model errors the 20 % poor-fit
limit cannot see).

Run: python benchmarks/bench_identify_verdicts.py   (needs mujoco, a test dependency; about
3 minutes)
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np

from dextar.config.scenario import scenario_from_dict
from dextar.dynamics import Model
from dextar.errors import DextarError
from dextar.identification.data import MotionData
from dextar.identification.excite import FourierTrajectory, design_excitation
from dextar.identification.fit import identify, validate
from dextar.program import plan_program

ROOT = Path(__file__).resolve().parents[1]
COUNT = 2 * np.pi / 2**17
TILT = math.radians(9.4)

#: issue 28's robot (config units: mm, kg, N m)
ROBOT = {
    "robot": {"l1": 80.0, "l2": 75.0, "L1": 95.0, "L2": 92.0, "d": 58.0, "working_mode": "+-"},
    "inertia": {"effector_mass": 0.28, "proximal_mass": 0.095, "distal_mass": 0.06},
    "friction": {"coulomb": 0.02, "viscous": 0.005},
    "gravity": {"vector": [9810.0 * math.sin(TILT), -9810.0 * math.cos(TILT)]},
    "motors": {"peak_torque": 1.5, "max_speed_rpm": 286.0},
    "output": {"servo_rate_hz": 1000.0},
}
#: the line and the arc the model must predict (min-jerk, from the config's region)
TASK = {"program": {"start": [-40.0, 110.0], "law": "min-jerk"},
        "move": [{"type": "line", "to": [20.0, 100.0], "duration": 1.0},
                 {"type": "arc", "via": [-10.0, 145.0], "to": [-40.0, 110.0],
                  "duration": 1.5}]}


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


def measured(run, seconds=None, bits=17):
    n = len(run.t) if seconds is None else int(round(seconds * 1000)) + 1
    count = 2 * np.pi / 2**bits
    return MotionData(run.t[:n], np.round(run.q[:n] / count) * count, run.tau[:n])


def scenario(**changes):
    doc = {k: dict(v) for k, v in ROBOT.items()}
    for table, values in changes.items():
        doc[table].update(values)
    return scenario_from_dict(doc)


def true_model(H, model: Model) -> Model:
    t0 = H.true_robot(model)
    return Model(t0.robot, t0.inertia.with_(viscous=(0.005, 0.005), coulomb=(0.02, 0.02)),
                 t0.assembly)


def unseen(H, sc, true):
    """The line and the arc, planned on the config's model, tracked by MuJoCo; and the task
    motion (q, dq, ddq) for --task."""
    model = sc.si_model
    task = scenario_from_dict({**ROBOT, **TASK})
    pp = plan_program(model.robot, model.inertia, task.moves, start=task.program_start,
                      working_mode=sc.mode, motors=sc.si_motors, servo_rate_hz=10000.0)
    cut = int(np.searchsorted(pp.t, 1.0))
    out = {}
    for name, sl in (("line", slice(0, cut + 1)), ("arc", slice(cut, None))):
        t = pp.t[sl] - pp.t[sl][0]
        run = H.track(true, model, sampled(t, pp.q[sl], pp.dq[sl], pp.ddq[sl]), float(t[-1]))
        out[name] = measured(run)
    return out, (pp.q[::10], pp.dq[::10], pp.ddq[::10])


def shrink(tr: FourierTrajectory, f: float) -> FourierTrajectory:
    return FourierTrajectory(tr.q0, f * tr.a, f * tr.b, tr.base_hz)


def row(name, res, task_unc, v):
    pct = lambda x: " / ".join(f"{100 * float(e):.3g}" for e in x)  # noqa: E731
    err = np.maximum(v["line"].error, v["arc"].error)
    return (f"{name:<34} {pct(res.fit_quality):>13} {pct(res.explained_quality):>11} "
            f"{pct(res.uncertainty):>13} {pct(task_unc):>13} {res.unphysical_distance:7.1f}  "
            f"{res.status_text:<26} {pct(err):>13}")


def main() -> None:
    H = harness()
    sc = scenario()
    model, motors = sc.si_model, sc.si_motors
    true = true_model(H, model)
    val, task = unseen(H, sc, true)
    print("case                               fit quality   explained   uncertainty  "
          "task uncert.  d(phys)  status                     line/arc error (worst)")
    rng = np.random.default_rng(7)
    runs = {}
    for seed in range(5):
        ex = design_excitation(model, sc.mode, duration=15.0, motors=motors, seed=seed)
        runs[seed] = (ex, H.track(true, model, ex.trajectory.evaluate, ex.duration))
    cases = []
    for seed, (_ex, run) in runs.items():
        for noise in (0.0, 0.01, 0.05, 0.15):
            d = measured(run)
            d = dataclasses.replace(d, tau=d.tau + rng.normal(scale=noise, size=d.tau.shape))
            cases.append((f"seed {seed}, noise {1e3 * noise:g} mN m", d, model))
        cases.append((f"seed {seed}, 14-bit encoder", measured(run, bits=14), model))
    for seed, (ex, _run) in list(runs.items())[:3]:
        small = shrink(ex.trajectory, 0.25)
        r = H.track(true, model, small.evaluate, ex.duration)
        d = measured(r)
        cases.append((f"seed {seed}, 1/4 size", d, model))
        d = dataclasses.replace(d, tau=d.tau + rng.normal(scale=0.05, size=d.tau.shape))
        cases.append((f"seed {seed}, 1/4 size, 50 mN m", d, model))
        cases.append((f"seed {seed}, 3 s", measured(runs[seed][1], 3.0), model))
    vertical = scenario(gravity={"vector": [0.0, -9810.0]}).si_model
    longer = scenario(robot={"l1": 81.0}).si_model
    for seed, (_ex, run) in runs.items():
        d = measured(run)
        cases.append((f"seed {seed}, gravity vertical", d, vertical))
        cases.append((f"seed {seed}, l1 1 mm long", d, longer))
        late = dataclasses.replace(d, tau=np.concatenate([d.tau[:2], d.tau[:-2]]))
        cases.append((f"seed {seed}, torques 2 ms late", late, model))
    for name, d, prior in cases:
        try:
            res = identify(d, prior, mode=sc.mode)
            tres = identify(d, prior, mode=sc.mode, reference=task)
            v = {k: validate(res, x, prior, mode=sc.mode) for k, x in val.items()}
        except DextarError as exc:
            print(f"{name:<34} refused: {exc}")
            continue
        print(row(name, res, tres.uncertainty, v), flush=True)


if __name__ == "__main__":
    main()
