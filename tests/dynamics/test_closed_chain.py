"""The closed chain in full coordinates (dextar.dynamics.closed_chain): the same torques as the
exact kernel away from a parallel singularity, task-space dynamics that stay regular through
one (M positive definite and bounded, E of rank 1 there)."""

import numpy as np
import pytest

from dextar.dynamics import Inertia, Model, Rod, inverse_dynamics
from dextar.dynamics.closed_chain import (
    chain_forces,
    chain_torques,
    degeneracy_residual,
    task_dynamics,
)
from dextar.geometry import FiveBar
from dextar.kinematics import inverse_kinematics, joint_rates, parallel_indicator

from ..crossing_cases import CASES

ROBOT = FiveBar(0.070, 0.080, 0.095, 0.085, 0.060)
INERTIA = Inertia(proximal=(Rod(0.08, 0.03, 4e-5), Rod(0.11, 0.04, 6e-5)),
                  distal=(Rod(0.1, 0.05, 9e-5), Rod(0.07, 0.035, 5e-5)), effector_mass=0.3,
                  payload=0.1, rotor=(1e-4, 2e-4), gravity=(0.5, -9.8), viscous=(0.01, 0.02),
                  coulomb=(0.02, 0.01), coulomb_speed=0.01)


def _motion(rng, n, robot=ROBOT):
    P = np.stack([rng.uniform(-0.03, 0.03, n), rng.uniform(0.08, 0.13, n)], -1)
    q = inverse_kinematics(robot, P, "+-")
    dP, ddP = rng.normal(size=(n, 2)) * 0.3, rng.normal(size=(n, 2)) * 3.0
    dq, ddq = joint_rates(robot, q, P, dP, ddP)
    return q, dq, ddq, P, dP, ddP


def test_chain_torques_are_the_exact_kernels():
    q, dq, ddq, P, dP, ddP = _motion(np.random.default_rng(3), 200)
    model = Model(ROBOT, INERTIA)
    tau = inverse_dynamics(model, q, dq, ddq)
    got = chain_torques(model, q, dq, ddq, P, dP, ddP)
    assert np.abs(got - tau).max() <= 1e-12 * np.abs(tau).max()
    # the check can fail: a payload it does not know
    other = chain_torques(Model(ROBOT, INERTIA.with_(payload=0.11)), q, dq, ddq, P, dP, ddP)
    assert np.abs(other - tau).max() > 1e-4 * np.abs(tau).max()


def test_task_dynamics_balance_the_exact_torques():
    q, dq, ddq, P, dP, ddP = _motion(np.random.default_rng(4), 50)
    model = Model(ROBOT, INERTIA)
    tau = inverse_dynamics(model, q, dq, ddq)
    td = task_dynamics(model, "+-", P, dP)
    assert np.abs(td.acceleration(tau) - ddP).max() <= 1e-10 * np.abs(ddP).max()
    assert np.allclose(td.M, np.swapaxes(td.M, -1, -2), rtol=0, atol=1e-14)
    assert (np.linalg.eigvalsh(td.M)[:, 0] > 0).all()
    assert np.abs(td.dq - dq).max() <= 1e-12 * np.abs(dq).max()


@pytest.mark.parametrize("name", sorted(CASES))
def test_task_dynamics_regular_through_the_crossing(name):
    """At the crossing (B, C, P aligned) M stays positive definite and of the size it has
    away from it, E loses rank (the motors cannot push P along the rods' normal) but stays
    bounded; 5 mm away E has full rank."""
    case = CASES[name]
    c = case.crossings[0]
    away = case.path.position(np.array([max(c.p - 0.1, 0.0)]))[0]
    dP = np.array([0.3, -0.4])
    at = task_dynamics(case.model, "+-", c.P, dP)
    off = task_dynamics(case.model, "+-", away, dP)
    sv_at, sv_off = np.linalg.svd(at.E, compute_uv=False), np.linalg.svd(off.E, compute_uv=False)
    assert sv_at[1] <= 1e-9 * sv_at[0]  # rank 1: its normal direction lost
    assert sv_off[1] >= 1e-2 * sv_off[0]
    assert np.isfinite(at.E).all() and sv_at[0] < 10 * sv_off[0]
    eig_at, eig_off = np.linalg.eigvalsh(at.M), np.linalg.eigvalsh(off.M)
    assert eig_at[0] > 0 and 0.1 < eig_at[1] / eig_off[1] < 10
    # E's range at the crossing is the rods' direction: normal to the crossing's normal
    assert abs(c.normal @ at.E[:, 0]) <= 1e-9 * np.abs(at.E).max()
    assert abs(parallel_indicator(case.robot, at.q, c.P)) < 1e-12


def test_degeneracy_residual_is_the_normal_force():
    """At rest at the crossing under gravity alone, the residual is the weight's normal
    component (not zero: a robot cannot be held there); without gravity it is zero."""
    case = CASES["dextar"]
    c = case.crossings[0]
    z = np.zeros(2)
    f = chain_forces(case.model, c.q, z, z, c.P, z, z)
    weight = case.inertia.point_mass + sum(r.mass * r.com / L for r, L in zip(
        case.inertia.distal, (case.robot.L1, case.robot.L2), strict=True))
    expected = -weight * (c.normal @ np.array(case.inertia.gravity))
    res = float(degeneracy_residual(f))
    assert res == pytest.approx(expected, rel=1e-9) and abs(res) > 0.1
    f0 = chain_forces(Model(case.robot, case.inertia.with_(gravity=(0.0, 0.0))), c.q, z, z,
                      c.P, z, z)
    assert abs(float(degeneracy_residual(f0))) < 1e-15


def test_task_state_on_floats_is_task_dynamics():
    """The integrators' one-state evaluation gives the vectorised one's numbers."""
    from dextar.dynamics.closed_chain import task_state

    _, _, _, P, dP, _ = _motion(np.random.default_rng(5), 5)
    model = Model(ROBOT, INERTIA)
    td = task_dynamics(model, "+-", P, dP)
    for i in range(len(P)):
        st = task_state(model, (1, -1), P[i], dP[i])
        assert st is not None
        M, h, E, q, dq = st
        for got, ref in ((M, td.M[i]), (h, td.h[i]), (E, td.E[i]), (dq, td.dq[i])):
            assert np.abs(got - ref).max() <= 1e-12 * np.abs(ref).max()
        assert np.abs(np.angle(np.exp(1j * (q - td.q[i])))).max() < 1e-12
    assert task_state(model, (1, -1), np.array([0.0, 0.5]), np.zeros(2)) is None  # out of reach
