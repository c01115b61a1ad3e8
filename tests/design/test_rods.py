"""A design's rods without [design].mass_per_length: each rod of the task's robot keeps its
linear density and shape on its new length (the sweep was biased when every geometry carried
the task's rods)."""

import pytest

from dextar.config import scenario_from_dict
from dextar.design.evaluate import inertia_of
from dextar.geometry import FiveBar

TASK = {"robot": {"l1": 100.0, "l2": 100.0, "L1": 140.0, "L2": 140.0, "d": 80.0},
        "inertia": {"effector_mass": 0.1, "proximal_mass": 0.05, "distal_mass": 0.07,
                    "distal_com": 70.0, "rotor_inertia": 2.0},
        "program": {"start": [0.0, 150.0]}, "move": [{"type": "dwell", "time": 0.1}],
        "design": {"L": [100.0, 160.0], "samples": 2}}


def test_rods_keep_their_density_and_shape():
    task, _ = scenario_from_dict(TASK).design_task()
    old = task.template
    new = inertia_of(task, FiveBar(0.1, 0.1, 0.1297, 0.1297, 0.08))
    k = 129.7 / 140.0
    for a, b in zip(old.distal, new.distal, strict=True):
        assert b.mass == pytest.approx(k * a.mass) and b.com == pytest.approx(k * a.com)
        assert b.inertia == pytest.approx(k**3 * a.inertia)
        assert b.com / 0.1297 == pytest.approx(a.com / 0.140)  # the same fraction
    assert new.proximal == old.proximal  # unchanged lengths, unchanged rods
    assert new.rotor == old.rotor and new.effector_mass == old.effector_mass
    # the uniform rod of the task stays a uniform rod: I = m L^2 / 12
    d = new.distal[0]
    assert d.inertia == pytest.approx(d.mass * 0.1297**2 / 12)
