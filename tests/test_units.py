"""The same physical scenario computed in the paper's units and in SI gives the same physics."""

import numpy as np
import pytest

from dextar.analysis import analyze
from dextar.config import scenario_from_dict

BASE = {
    "path": {"type": "line", "start": [-60.0, 90.0], "end": [60.0, 115.0]},
    "law": {"type": "optimal", "duration": 0.4, "eta": 0.003},
    "inertia": {"effector_mass": 0.05, "payload": 0.02, "proximal_mass": [0.03, 0.035],
                "distal_mass": 0.02, "distal_com": 40.0, "distal_inertia": 12.0,
                "rotor_inertia": 5.0},
    "friction": {"viscous": [1e-4, 2e-4], "coulomb": 1e-3},
    "gravity": {"vector": [1000.0, -9810.0]},
}


def run(units):
    doc = {**BASE, "output": {"units": units, "samples": 201}}
    sc = scenario_from_dict(doc)
    return sc, analyze(sc.inputs(), sc.law())


def test_paper_and_si_units_agree():
    sc_p, an_p = run("paper")
    sc_s, an_s = run("si")
    assert sc_p.units.length_mm == 87.0 and sc_p.units.time_s == 0.4
    assert sc_p.units.mass_kg == 0.05
    # times, positions, angles
    np.testing.assert_allclose(an_p.trajectory.t * 0.4, an_s.trajectory.t, rtol=1e-12)
    np.testing.assert_allclose(an_p.trajectory.P * 0.087, an_s.trajectory.P, atol=1e-12)
    np.testing.assert_allclose(an_p.trajectory.q, an_s.trajectory.q, atol=1e-9)
    # torques in N m (gravity, friction, rotors, payload all converted)
    tau_p = sc_p.units.torque_in_nm(an_p.tau)
    np.testing.assert_allclose(tau_p, an_s.tau, rtol=1e-7, atol=1e-9 * np.abs(an_s.tau).max())
    # the optimal law's cost in J s
    law_p, law_s = an_p.law, an_s.law
    J_s = 0.05 * 0.087**2 / 0.4  # energy unit x time unit in J s
    assert law_p.cost * J_s == pytest.approx(law_s.cost, rel=1e-7)
