"""Identification you can trust, on data no part of dextar's dynamics produced: for 20
excitation seeds of ``design_excitation`` (the pick-and-place robot, 10 s at 1 kHz), MuJoCo's
robot (tests/identification/mujoco_harness.py: other masses, rotors, friction; a 100 Hz PD
loop at 10 kHz with the prior's feedforward) tracks the excitation; we identify from its
angles (a 17-bit encoder) and applied torques, and predict MuJoCo's torques of two motions the
fit never saw: the paper's semicircle and the pick-and-place program (time-optimal, at the
motors' limits). Every prediction must be within 0.5 % RMS per motor. Then the verdicts on
data the prior does not describe (status 3, "poor fit").

Run: python benchmarks/bench_identify_mujoco.py   (needs mujoco, a test dependency)
"""

from __future__ import annotations

import dataclasses
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

from dextar.config import load_scenario, load_toml
from dextar.config.scenario import scenario_from_dict
from dextar.dynamics import Model, inverse_dynamics
from dextar.errors import DextarError
from dextar.identification.base import base_parameters
from dextar.identification.data import MotionData
from dextar.identification.excite import design_excitation
from dextar.identification.fit import identify, validate
from dextar.program import plan_program

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "pick_place.toml"
COUNT = 2 * np.pi / 2**17
BOUND = 0.005


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


def measured(run):
    return MotionData(run.t, np.round(run.q / COUNT) * COUNT, run.tau)


def main() -> None:
    H = harness()
    sc = load_scenario(EXAMPLE)
    model, motors = sc.si_model, sc.si_motors
    true = H.true_robot(model)
    base = base_parameters(model)
    doc = {k: v for k, v in load_toml(EXAMPLE).items()
           if k in ("robot", "inertia", "friction", "gravity")}
    doc.update({"law": {"type": "optimal", "duration": 1.0}, "output": {"units": "si"}})
    semi = scenario_from_dict(doc).trajectory(samples=10001)
    pp = plan_program(model.robot, model.inertia, sc.moves, start=sc.program_start,
                      working_mode=sc.mode, motors=motors, servo_rate_hz=10000.0)
    unseen = {}
    for name, (t, q, dq, ddq) in (("semicircle", (semi.t, semi.q, semi.dq, semi.ddq)),
                                  ("program", (pp.t, pp.q, pp.dq, pp.ddq))):
        run = H.track(true, model, sampled(t, q, dq, ddq), float(t[-1]))
        unseen[name] = measured(run)
        print(f"{name}: {float(t[-1]):.3g} s tracked within {run.tracking_error_deg:.3g} deg")
    print("seed  cond  headroom A/D  design s | track deg | fit quality A/D % | "
          "semicircle A/D %  (prior)   | program A/D %  (prior)   | region")
    worst = np.zeros(2)
    datas = []
    for seed in range(20):
        t0 = time.perf_counter()
        ex = design_excitation(model, sc.mode, duration=10.0, motors=motors, seed=seed,
                               base=base)
        dt = time.perf_counter() - t0
        run = H.track(true, model, ex.trajectory.evaluate, ex.duration)
        assert run.type2_sign_changes == 0 and run.assembly_gap_mm < 1e-3
        data = measured(run)
        datas.append(data)
        res = identify(data, model, mode=sc.mode, base=base)
        v = {n: validate(res, d, model, mode=sc.mode) for n, d in unseen.items()}
        for x in v.values():
            worst = np.maximum(worst, x.error)
        s, p = v["semicircle"], v["program"]
        print(f"{seed:4d} {ex.condition_number:5.2f}  {ex.headroom[0]:.2f} / {ex.headroom[1]:.2f}"
              f"  {dt:6.1f}   | {run.tracking_error_deg:.4f}    | "
              f"{100 * res.fit_quality[0]:.3f} / {100 * res.fit_quality[1]:.3f}   | "
              f"{100 * s.error[0]:.3f} / {100 * s.error[1]:.3f} ({100 * s.error_prior[0]:.1f} / "
              f"{100 * s.error_prior[1]:.1f}) | {100 * p.error[0]:.3f} / {100 * p.error[1]:.3f} "
              f"({100 * p.error_prior[0]:.1f} / {100 * p.error_prior[1]:.1f}) | "
              f"{100 * s.coverage.fraction:.0f} % / {100 * p.coverage.fraction:.0f} %"
              + ("" if res.status == 0 else f"  status {res.status}"), flush=True)
    verdict = "all within" if (worst <= BOUND).all() else "NOT all within"
    print(f"worst prediction error over 20 seeds and both motions: {100 * worst[0]:.3f} / "
          f"{100 * worst[1]:.3f} % ({verdict} {100 * BOUND:g} %)")

    print("\nverdicts on data the prior does not describe (the 20 MuJoCo runs above):")
    default = load_scenario(None).si_model
    flat = Model(model.robot, model.inertia.with_(gravity=(0.0, 0.0)), model.assembly)
    big_sc = scenario_from_dict({
        "robot": {"l1": 100.0, "l2": 100.0, "L1": 140.0, "L2": 140.0, "d": 60.0,
                  "working_mode": "+-"},
        "inertia": {"effector_mass": 0.08, "payload": 0.05, "proximal_mass": 0.04,
                    "distal_mass": 0.03},
        "friction": {"coulomb": 0.02, "viscous": 0.01},
        "gravity": {"vector": [0.0, -9810.0]}, "output": {"units": "si"}})
    big = big_sc.si_model
    cases = [
        ("gravity left out of the prior", datas, flat),
        ("the default prior (the paper's DexTAR: no gravity, no friction)", datas, default),
        ("torques in mN m", [dataclasses.replace(d, tau=1e3 * d.tau) for d in datas], model),
        ("torques of the other sign", [dataclasses.replace(d, tau=-d.tau) for d in datas], model),
        ("motors swapped", [dataclasses.replace(d, tau=d.tau[:, ::-1].copy()) for d in datas],
         model),
        ("identified as a 100/140 mm five-bar", datas, big),
    ]
    rng = np.random.default_rng(0)
    bigdata = []
    for seed in range(3):
        ex = design_excitation(big, "+-", duration=10.0, motors=motors, seed=seed)
        t = np.arange(10001) / 1000.0
        q, dq, ddq = ex.trajectory.evaluate(t)
        tau = inverse_dynamics(big, q, dq, ddq) + rng.normal(scale=0.005, size=q.shape)
        bigdata.append(MotionData(t, np.round(q / COUNT) * COUNT, tau))
    big_flat = Model(big.robot, big.inertia.with_(gravity=(0.0, 0.0)), big.assembly)
    cases += [("a 100/140 mm five-bar with its own model (a good fit)", bigdata, big),
              ("a 100/140 mm five-bar, gravity left out", bigdata, big_flat),
              ("a 100/140 mm five-bar as the default DexTAR", bigdata, default)]
    for name, ds, prior in cases:
        fq, st, msg = [], [], ""
        for d in ds:
            try:
                r = identify(d, prior, mode="+-")
            except DextarError as exc:
                st.append("refused")
                msg = str(exc)
                continue
            fq.append(r.fit_quality)
            st.append(r.status)
            msg = msg or r.message
        counts = {s: st.count(s) for s in dict.fromkeys(st)}
        line = f"  {name}: statuses {counts}"
        if fq:
            f = 100 * np.array(fq)
            line += (f", fit quality {f[:, 0].min():.3g}-{f[:, 0].max():.3g} / "
                     f"{f[:, 1].min():.3g}-{f[:, 1].max():.3g} %")
        print(line)
        print(f"      {msg[:160]}{'...' if len(msg) > 160 else ''}")


if __name__ == "__main__":
    main()
