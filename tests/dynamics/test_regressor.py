"""The regressor reproduces the exact inverse dynamics for any parameters, and the base
parameters lump exactly what the mechanism's kinematics say they must."""

import numpy as np
import pytest

from dextar.dynamics import Inertia, Model, Rod, inverse_dynamics
from dextar.dynamics.regressor import INDEX, NAMES, regressor, standard_parameters
from dextar.geometry import DEXTAR_MM, FiveBar
from dextar.identification.base import base_parameters, random_states

ROBOTS = [DEXTAR_MM.scaled(1e-3), FiveBar(l1=0.1, l2=0.08, L1=0.13, L2=0.11, d=0.05)]


def random_inertia(rng, gravity=(0.3, -9.81)):
    def rod():
        return Rod(rng.uniform(0.05, 0.5), rng.uniform(-0.02, 0.1), rng.uniform(1e-5, 1e-3))

    return Inertia((rod(), rod()), (rod(), rod()), effector_mass=rng.uniform(0.05, 1),
                   payload=rng.uniform(0, 0.2), rotor=tuple(rng.uniform(0, 1e-3, 2)),
                   viscous=tuple(rng.uniform(0, 0.1, 2)), coulomb=tuple(rng.uniform(0, 0.1, 2)),
                   gravity=gravity, coulomb_speed=0.05)


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("assembly", ["up", "down"])
def test_regressor_times_parameters_is_the_inverse_dynamics(robot, assembly):
    rng = np.random.default_rng(3)
    for _ in range(3):
        model = Model(robot, random_inertia(rng), assembly)
        q, dq, ddq = random_states(model, 300, rng)
        dq, ddq = 3 * dq, 30 * ddq
        tau = inverse_dynamics(model, q, dq, ddq)
        Y = regressor(model, q, dq, ddq)
        assert Y.shape == (300, 2, 15)
        err = np.abs(Y @ standard_parameters(model.inertia) - tau).max()
        assert err < 1e-12 * np.abs(tau).max()


@pytest.mark.parametrize("robot", ROBOTS)
def test_base_parameters_explain_every_parameter_set(robot):
    rng = np.random.default_rng(5)
    model = Model(robot, random_inertia(rng))
    base = base_parameters(model)
    q, dq, ddq = random_states(model, 200, np.random.default_rng(99))  # states not used above
    Y = regressor(model, q, dq, ddq)
    for _ in range(5):
        theta = rng.normal(size=15)  # any values, not only physical ones
        full = Y @ theta
        assert np.abs(base.columns(Y) @ base.of(theta) - full).max() < 1e-10 * np.abs(full).max()


def test_base_parameters_lump_what_the_kinematics_say():
    """A distal rod's mass moves with its elbow (the proximal rod's tip, at l from the
    motor) and its first moment h is equivalent to a mass h / L at P, where the point mass
    rides on either rod; so m_BP enters J_A' as l1^2 m_BP and h_BP enters m_P' as h_BP / L1."""
    robot = ROBOTS[1]
    model = Model(robot, random_inertia(np.random.default_rng(1)))
    base = base_parameters(model)
    assert base.size == 11 and not base.unidentifiable
    row = dict(zip(base.names, base.K, strict=True))
    assert row["J_A'"][INDEX["m_BP"]] == pytest.approx(robot.l1**2, rel=1e-9)
    assert row["h_AB'"][INDEX["m_BP"]] == pytest.approx(robot.l1, rel=1e-9)
    assert row["J_D'"][INDEX["m_CP"]] == pytest.approx(robot.l2**2, rel=1e-9)
    assert row["m_P'"][INDEX["h_BP"]] == pytest.approx(1 / robot.L1, rel=1e-9)
    assert row["m_P'"][INDEX["h_CP"]] == pytest.approx(1 / robot.L2, rel=1e-9)
    assert row["J_BP'"][INDEX["h_BP"]] == pytest.approx(-robot.L1, rel=1e-9)
    # friction is never lumped
    for name in ("fv_A", "fc_A", "fv_D", "fc_D"):
        assert np.count_nonzero(row[name]) == 1


def test_without_gravity_the_first_moments_of_the_proximal_rods_leave_no_trace():
    model = Model(ROBOTS[0], random_inertia(np.random.default_rng(2), gravity=(0.0, 0.0)))
    base = base_parameters(model)
    assert {NAMES[j] for j in base.unidentifiable} == {"h_AB", "h_DC"}
    assert base.size == 9
