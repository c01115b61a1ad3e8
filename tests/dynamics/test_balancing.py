"""Counterweights and balancing: a counterweight folded into its rod is exact (its own torque
added to the bare rod's, MuJoCo with it as a body of its own, power balance), the shaking
force and moment are the rates of the centre of mass and of the angular momentum, and the
closed-form force balance fixes the centre of mass to rounding."""

import numpy as np
import pytest

import dextar as dx
from dextar.dynamics import (
    Counterweight,
    Inertia,
    Model,
    Rod,
    gravity_torques,
    inverse_dynamics,
    kinetic_energy,
    paper_inertia,
)
from dextar.dynamics.balancing import (
    angular_momentum,
    balance_force,
    distal_counterweights,
    mass_center,
    moving_mass,
    residual_mass,
    shaking,
)
from dextar.dynamics.regressor import INDEX, regressor, standard_parameters
from dextar.errors import ParameterError
from dextar.geometry import FiveBar

from .conftest import random_joint_motion

ROBOT = dx.DEXTAR_MM.scaled(1e-3)  # m
GENERAL = FiveBar(l1=0.08, l2=0.09, L1=0.11, L2=0.10, d=0.06)


def general_inertia(**changes):
    return Inertia(proximal=(Rod(0.08, 0.03, 4e-5), Rod(0.11, 0.05, 6e-5)),
                   distal=(Rod(0.1, 0.06, 9e-5), Rod(0.07, 0.035, 5e-5)), effector_mass=0.3,
                   payload=0.05, rotor=(1e-5, 2e-5), **changes)


CW = (Counterweight(0.4, 0.025, 3e-5), Counterweight(0.25, 0.04))


def motion(n=2001, seed=3):
    t = np.linspace(0.0, 1.0, n)
    q, dq, ddq = random_joint_motion(np.random.default_rng(seed), t)
    return t, q, dq, ddq


def test_folding_round_trips_and_replaces():
    ine = general_inertia().with_counterweights(CW)
    assert ine.has_counterweights and ine.counterweights == CW
    # the folded rod: mass, first moment and inertia about the joint add up
    bare = general_inertia().proximal
    for rod, b, cw in zip(ine.proximal, bare, CW, strict=True):
        assert rod.mass == pytest.approx(b.mass + cw.mass, rel=1e-14)
        assert rod.first_moment == pytest.approx(b.first_moment - cw.mass * cw.distance,
                                                 rel=1e-13)
        assert rod.about_joint == pytest.approx(b.about_joint + cw.about_joint, rel=1e-13)
    for a, b in zip(ine.bare_proximal, bare, strict=True):
        assert (a.mass, a.com, a.inertia) == pytest.approx((b.mass, b.com, b.inertia), rel=1e-9)
    # new counterweights replace the old ones; none gives the bare rods back
    again = ine.with_counterweights((Counterweight(), Counterweight()))
    assert not again.has_counterweights
    for a, b in zip(again.proximal, bare, strict=True):
        assert (a.mass, a.com, a.inertia) == pytest.approx((b.mass, b.com, b.inertia), rel=1e-9)
    # scaling the masses scales the counterweights with the rods
    s = ine.scaled_masses(2.0)
    assert s.counterweights[0].mass == 0.8 and s.bare_proximal[0].mass == pytest.approx(0.16)
    # a rod that does not hold its record is named
    lighter = ine.with_(proximal=bare)
    with pytest.raises(ParameterError, match="does not hold a counterweight"):
        _ = lighter.bare_proximal
    with pytest.raises(ParameterError, match="counterweight of rod AB mass"):
        general_inertia().with_counterweights((Counterweight(-1.0, 0.1), Counterweight()))


def test_a_counterweight_adds_its_own_torque(kernel):
    """The folded model's torques are the bare rods' plus each counterweight's own, derived
    apart: ``(I_c + m_c r^2) qddot_k`` and its weight at ``-r e_k``, ``m_c r (c_k g_y -
    s_k g_x)``; with gravity, friction and rotors, on both kernels."""
    g = (0.7, -9.81)
    bare = general_inertia(gravity=g, viscous=(0.01, 0.02), coulomb=(0.03, 0.01))
    _, q, dq, ddq = motion(200)
    tau0 = inverse_dynamics(Model(GENERAL, bare), q, dq, ddq)
    tau = inverse_dynamics(Model(GENERAL, bare.with_counterweights(CW)), q, dq, ddq)
    own = np.stack([(cw.inertia + cw.mass * cw.distance**2) * ddq[:, k]
                    + cw.mass * cw.distance * (np.cos(q[:, k]) * g[1] - np.sin(q[:, k]) * g[0])
                    for k, cw in enumerate(CW)], -1)
    assert np.abs(tau - tau0 - own).max() < 1e-12 * np.abs(tau).max()
    assert np.abs(own).max() > 0.1 * np.abs(tau).max()  # the counterweights matter here


def test_power_balance_with_counterweights(kernel):
    """``tau . qdot = dT/dt`` with T the bare mechanism's energy plus the counterweights'
    ``(I_c + m_c r^2) qdot^2 / 2``, computed apart (no gravity, no friction)."""
    t, q, dq, ddq = motion()
    bare = general_inertia()
    model = Model(GENERAL, bare.with_counterweights(CW))
    tau = inverse_dynamics(model, q, dq, ddq)
    T = kinetic_energy(Model(GENERAL, bare), q, dq) + sum(
        0.5 * cw.about_joint * dq[:, k] ** 2 for k, cw in enumerate(CW))
    assert np.abs(T - kinetic_energy(model, q, dq)).max() < 1e-13 * T.max()
    power = np.sum(tau * dq, axis=1)
    dT = np.gradient(T, t)
    assert np.abs(power - dT)[5:-5].max() < 1e-4 * np.abs(power).max()


@pytest.mark.slow
def test_mujoco_sees_the_counterweight_as_a_body():
    mujoco = pytest.importorskip("mujoco")
    from dextar.output.mjcf import mujoco_state, to_mjcf

    ine = general_inertia(gravity=(0.5, -9.81)).with_counterweights(CW)
    model = Model(GENERAL, ine)
    t, q, dq, ddq = motion(25)
    xml = to_mjcf(model)
    assert xml.count('<body name="counterweight') == 2
    mm = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(mm)
    qpos, qvel = mujoco_state(model, q, dq)
    for forgotten, ok in ((False, True), (True, False)):
        m = Model(GENERAL, ine.with_(proximal=ine.bare_proximal)) if forgotten else model
        tau = inverse_dynamics(m, q, dq, ddq)
        got = np.empty_like(ddq)
        for i in range(len(t)):
            data.qpos[:], data.qvel[:], data.ctrl[:] = qpos[i], qvel[i], tau[i]
            mujoco.mj_forward(mm, data)
            got[i] = data.qacc[[0, 2]]
        rel = np.abs(got - ddq).max() / np.abs(ddq).max()
        assert (rel < 1e-3) == ok, rel  # measured 2.6e-4 (MuJoCo's soft loop); 5e-2 without


def test_regressor_takes_counterweighted_rods():
    ine = general_inertia(gravity=(0.0, -9.81)).with_counterweights(CW)
    model = Model(GENERAL, ine)
    _, q, dq, ddq = motion(50)
    theta = standard_parameters(ine)
    tau = inverse_dynamics(model, q, dq, ddq)
    assert np.abs(regressor(model, q, dq, ddq) @ theta - tau).max() < 1e-12 * np.abs(tau).max()
    bare = standard_parameters(general_inertia())
    assert theta[INDEX["J_A"]] - bare[INDEX["J_A"]] == pytest.approx(CW[0].about_joint)
    assert theta[INDEX["h_DC"]] - bare[INDEX["h_DC"]] == pytest.approx(-0.25 * 0.04)


def test_shaking_force_and_moment_are_rates():
    """``F = -M G''`` and ``N = -H'`` by finite differences of the centre of mass and of the
    angular momentum (rotors spinning, counterweights on)."""
    t, q, dq, ddq = motion()
    model = Model(GENERAL, general_inertia().with_counterweights(CW))
    sh = shaking(model, q, dq, ddq, spin=(0.003, -0.002))
    dt = t[1] - t[0]
    G = mass_center(model, q)
    aG = np.gradient(np.gradient(G, dt, axis=0), dt, axis=0)
    M = moving_mass(model.inertia)
    assert M == pytest.approx(0.08 + 0.11 + 0.1 + 0.07 + 0.3 + 0.05 + 0.4 + 0.25)
    # finite differences of 5e-4 s: measured 2.8e-5 and 9e-6 of the peaks
    assert np.abs(sh.force + M * aG)[5:-5].max() < 2e-4 * np.abs(sh.force).max()
    H = angular_momentum(model, q, dq, spin=(0.003, -0.002))
    assert np.abs(sh.moment + np.gradient(H, dt))[5:-5].max() < 2e-4 * np.abs(sh.moment).max()
    # the rotors' spin is in the moment: a wrong spin is seen
    other = shaking(model, q, dq, ddq, spin=(0.0, 0.0))
    assert np.abs(other.moment - sh.moment).max() > 1e-2 * np.abs(sh.moment).max()
    s = sh.summary(t)
    assert s["shaking_force"] == pytest.approx(sh.force_magnitude.max())
    assert 0 < s["rms_shaking_force"] < s["shaking_force"]


def balanced_inertia(robot, base):
    """Distal counterweights (condition (b)), then proximal ones (condition (a))."""
    redistributed, dcw = distal_counterweights(robot, base, 0.03, share=0.4)
    return balance_force(robot, redistributed, (0.04, 0.05), counterweight_inertia=2e-5), dcw


@pytest.mark.parametrize("robot, base", [
    (ROBOT, paper_inertia(ROBOT, effector_mass=0.2).with_(payload=0.05)),
    (GENERAL, general_inertia()),
])
def test_force_balance_fixes_the_centre_of_mass(robot, base):
    """The closed form on a DexTAR and on an asymmetric five-bar with non-uniform rods: the
    centre of mass fixed to rounding over a motion, the shaking force zero, the weight holds
    no torque, and the torques (with the counterweights) pass power balance."""
    t, q, dq, ddq = motion()
    fb, dcw = balanced_inertia(robot, base)
    assert fb.full and residual_mass(robot, fb.inertia) == pytest.approx(0.0, abs=1e-15)
    assert all(cw.mass > 0 for cw in (*fb.counterweights, *dcw))
    model = Model(robot, fb.inertia)
    G = mass_center(model, q)
    reach = robot.l1 + robot.L1
    assert np.ptp(G, axis=0).max() < 1e-14 * reach  # measured 1e-17 m on 0.16 m
    unbalanced = Model(robot, base)
    F0 = shaking(unbalanced, q, dq, ddq).force_magnitude.max()
    F = shaking(model, q, dq, ddq).force_magnitude.max()
    assert F < 1e-12 * F0
    with_g = Model(robot, fb.inertia.with_(gravity=(0.0, -9.81)))
    assert np.abs(gravity_torques(with_g, q)).max() < 1e-12 * 9.81 * fb.mass * reach
    # power balance of the balanced robot's torques
    tau = inverse_dynamics(model, q, dq, ddq)
    power, dT = np.sum(tau * dq, axis=1), np.gradient(kinetic_energy(model, q, dq), t)
    assert np.abs(power - dT)[5:-5].max() < 1e-4 * np.abs(power).max()
    # the counterweights raise the torques (the price of balance)
    tau0 = inverse_dynamics(unbalanced, q, dq, ddq)
    assert np.abs(tau).max() > 2 * np.abs(tau0).max()


def test_proximal_counterweights_alone_leave_the_mass_at_p():
    """Condition (a) without (b): the centre of mass moves as ``m_P' P / M`` and the force is
    ``-m_P' a_P`` exactly; it is not fixed (the check can fail)."""
    from dextar.kinematics import direct_kinematics, task_acceleration

    t, q, dq, ddq = motion()
    base = general_inertia()
    fb = balance_force(GENERAL, base, 0.03)
    assert not fb.full and fb.residual_mass == pytest.approx(
        0.35 + 0.1 * 0.06 / 0.11 + 0.07 * 0.035 / 0.10, rel=1e-12)
    model = Model(GENERAL, fb.inertia)
    P = direct_kinematics(GENERAL, q)
    G = mass_center(model, q)
    drift = G - fb.residual_mass * P / fb.mass
    assert np.ptp(drift, axis=0).max() < 1e-14
    assert np.ptp(G, axis=0).max() > 1e-3  # the centre of mass moves by millimetres
    _, ddP = task_acceleration(GENERAL, q, P, dq, ddq)
    F = shaking(model, q, dq, ddq).force
    assert np.abs(F + fb.residual_mass * ddP).max() < 1e-12 * np.abs(F).max()


def test_balance_refuses_what_it_cannot_do():
    with pytest.raises(ParameterError, match="must be positive"):
        balance_force(GENERAL, general_inertia(), 0.0)
    behind = general_inertia().with_(proximal=(Rod(0.5, -0.05, 1e-4), Rod(0.1, 0.04, 1e-5)))
    with pytest.raises(ParameterError, match="leg 1: rod AB is already past balance"):
        balance_force(GENERAL, behind, 0.03)
    with pytest.raises(ParameterError, match="share"):
        distal_counterweights(GENERAL, general_inertia(), 0.03, share=1.5)
