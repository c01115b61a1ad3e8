"""The paper's simplified model (32)-(42) against hand computations and its own physics."""

import math

import numpy as np
import pytest

import dextar as dx
from dextar.dynamics import Inertia, paper_inertia
from dextar.dynamics.paper import (
    PaperModel,
    base_angle,
    effector_energy_const_beta,
    effector_position_23,
    paper_model,
    paper_model_limits,
    torque_error,
)

from .conftest import ROBOT, random_joint_motion


def test_constants_by_hand():
    pm = PaperModel(l=0.8, L=1.0, d=0.7, m=1.0, mL=0.1, Jl=0.02, Je=0.01, lam=0.5,
                    beta0=math.radians(60))
    c2 = (1 + 2 * 0.25 * 0.1) * 1.0 * 0.64 / (4 * 0.25)  # cos 60 = 1/2
    assert pm.C2 == pytest.approx(c2)
    assert pm.C1 == pytest.approx(c2 + 0.75 * 0.1 * 0.64 / 2 + 0.02 + 0.01)
    assert pm.C3 == pytest.approx(0.1 * 0.25 * 0.64 / 0.5)
    assert pm.C4 == pytest.approx(0.1 * 0.25 * 0.64 / 2)


def test_torques_42_are_the_lagrange_equations_of_energy_40():
    """The model is Lagrangian: its torques times the rates are the rate of its own energy."""
    pm = paper_model(ROBOT, paper_inertia(ROBOT).with_(rotor=(0.01, 0.01)), math.radians(55))
    t = np.linspace(0, 1, 4001)
    q, dq, ddq = random_joint_motion(np.random.default_rng(3), t)
    power = np.sum(pm.torques(q, dq, ddq) * dq, axis=-1)
    rate = np.gradient(pm.energy(q, dq), t)
    assert np.abs(power - rate)[5:-5].max() < 1e-4 * np.abs(power).max()


def test_base_angle_and_direct_kinematics_23_by_hand():
    q = np.array([[np.pi / 2, np.pi / 2]])  # B = (d/2, l), C = (-d/2, l): |BC| = d
    beta = base_angle(ROBOT, q)[0]
    assert beta == pytest.approx(math.acos(ROBOT.d / (2 * ROBOT.L1)))
    # P above the middle of BC at height L sin(beta)
    P = effector_position_23(ROBOT, q)[0]
    assert P == pytest.approx([0.0, ROBOT.l1 + ROBOT.L1 * math.sin(beta)])
    # and (23) agrees with the exact direct kinematics on any pose
    qs = np.radians([[60.5, 119.5], [40.0, 100.0], [75.0, 150.0]])
    np.testing.assert_allclose(effector_position_23(ROBOT, qs), dx.direct_kinematics(ROBOT, qs),
                               atol=1e-12)


def test_frozen_beta_energy_is_exact_when_beta_does_not_change():
    """(32) drops only the beta-dot term of (30): at beta = beta0 with rates that keep |BC|
    (so beta-dot = 0) it is the exact end-effector energy m |Pdot|^2 / 2."""
    q = np.radians([[65.0, 125.0], [50.0, 110.0], [80.0, 140.0]])
    B, C = dx.elbows(ROBOT, q)
    v = B - C
    e1 = np.stack([-np.sin(q[:, 0]), np.cos(q[:, 0])], -1)
    e2 = np.stack([-np.sin(q[:, 1]), np.cos(q[:, 1])], -1)
    w1 = np.array([1.0, -0.7, 2.0])
    w2 = w1 * np.sum(v * e1, -1) / np.sum(v * e2, -1)  # (B - C).(Bdot - Cdot) = 0
    dq = np.stack([w1, w2], -1)
    P = dx.direct_kinematics(ROBOT, q)
    dP = dx.task_velocity(ROBOT, q, P, dq)
    for i in range(3):
        beta0 = float(base_angle(ROBOT, q[i:i + 1])[0])
        got = effector_energy_const_beta(ROBOT, 2.0, beta0, q[i:i + 1], dq[i:i + 1])[0]
        assert got == pytest.approx(0.5 * 2.0 * np.sum(dP[i] ** 2), rel=1e-10)


def test_limits_and_errors():
    assert paper_model_limits(ROBOT, paper_inertia(ROBOT)) is None
    asym = dx.FiveBar(0.8, 0.9, 1.0, 1.0, 0.6)
    assert "not symmetric" in paper_model_limits(asym, paper_inertia(asym))
    with pytest.raises(dx.ParameterError, match="does not apply"):
        paper_model(asym, paper_inertia(asym), 0.9)
    none = Inertia.uniform(ROBOT, proximal_mass=0.1, distal_mass=0.1, effector_mass=0.0)
    assert "no mass at P" in paper_model_limits(ROBOT, none)
    err = torque_error(np.array([[1.0, -2.0]]), np.array([[1.5, -2.0]]))
    assert err["max"] == 0.5 and err["peak_exact"] == 2.0 and err["max_relative"] == 0.25
    assert err["rms"] == pytest.approx(math.sqrt(0.125))
