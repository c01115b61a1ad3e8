"""Balancing as design metrics: a DexTAR whose counterweights come from the closed-form
synthesis (distal rods redistributed in [inertia], proximal counterweights in [inertia]) has
a shaking force of zero as a design's metric, the same robot without them does not, and the
design's torques are the exact dynamics' with the counterweights."""

import numpy as np
import pytest

import dextar as dx
from dextar.config import scenario_from_dict
from dextar.design.evaluate import evaluate_design
from dextar.dynamics import Model, inverse_dynamics, paper_inertia
from dextar.dynamics.balancing import balance_force, distal_counterweights, shaking

ROBOT = dx.DEXTAR_MM.scaled(1e-3)
LENGTHS = (72.0, 72.0, 87.0, 87.0, 60.0)


def balanced_doc():
    base = paper_inertia(ROBOT, effector_mass=0.2).with_(payload=0.05)
    redistributed, _ = distal_counterweights(ROBOT, base, 0.03)
    fb = balance_force(ROBOT, redistributed, 0.04)
    assert fb.full
    d = fb.inertia.distal
    c = fb.counterweights
    return {
        "inertia": {"effector_mass": 0.2, "payload": 0.05, "proximal_mass": 0.016,
                    "distal_mass": [r.mass for r in d], "distal_com": [1e3 * r.com for r in d],
                    "distal_inertia": [1e6 * r.inertia for r in d],
                    "counterweight_mass": [w.mass for w in c],
                    "counterweight_distance": [1e3 * w.distance for w in c]},
        "path": {"type": "arc", "radius": 40.0, "center": [0.0, 110.0], "start_deg": 0.0,
                 "end_deg": 180.0},
        "law": {"type": "min-jerk", "duration": 0.3},
        "motors": {"peak_torque": 50.0},
        "output": {"units": "si"},
        "design": {"d": [50.0, 70.0], "samples": 2}}


@pytest.mark.parametrize("balanced", [True, False])
def test_a_balanced_design_does_not_shake_the_frame(balanced):
    doc = balanced_doc()
    if not balanced:  # the same rods without the counterweights of condition (a)
        doc["inertia"].pop("counterweight_mass")
    sc = scenario_from_dict(doc)
    task, _ = sc.design_task()
    row = evaluate_design(task, LENGTHS)
    assert row["feasible"], row["reason"]
    # the design's own model: the counterweights in it, the torques the exact dynamics'
    tr = sc.trajectory(samples=task.samples)
    model = Model(sc.si_model.robot, sc.si_model.inertia)
    assert sc.si_model.inertia.has_counterweights == balanced
    tau = inverse_dynamics(model, tr.q, tr.dq, tr.ddq)
    assert row["peak_torque_A_Nm"] == pytest.approx(np.abs(tau[:, 0]).max(), rel=1e-9)
    reference = shaking(model, tr.q, tr.dq, tr.ddq).force_magnitude.max()
    if balanced:  # zero to rounding: 1e-12 of the effector's own inertia force
        scale = 0.25 * np.abs(np.gradient(np.gradient(tr.P, tr.t, axis=0), tr.t, axis=0)).max()
        assert row["shaking_force_N"] < 1e-12 * scale and reference < 1e-12 * scale
        assert row["rms_shaking_force_N"] < 1e-12 * scale
    else:
        assert row["shaking_force_N"] == pytest.approx(reference, rel=1e-9)
        assert row["shaking_force_N"] > 0.1  # N: measured 13
    assert row["shaking_moment_Nm"] > 0  # balancing the force leaves the moment
