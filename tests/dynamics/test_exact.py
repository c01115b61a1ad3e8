import numpy as np
import pytest

import dextar as dx
from dextar.dynamics import (
    Inertia,
    Model,
    Rod,
    accelerations,
    bias_forces,
    gravity_torques,
    inverse_dynamics,
    joint_reactions,
    kinetic_energy,
    mass_matrix,
)
from dextar.trajectory import sample_trajectory

from .conftest import ROBOT, SEMI, random_joint_motion

# central differences of order 8 on 9 points
FD8 = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])


def general_inertia(**kw):
    return Inertia(
        proximal=(Rod(0.08, 0.3, 0.004), Rod(0.11, 0.45, 0.006)),
        distal=(Rod(0.1, 0.55, 0.009), Rod(0.07, 0.4, 0.005)),
        effector_mass=1.0, payload=0.2, rotor=(0.01, 0.015), **kw)


def energy_rate(model, qfun, t, h=1e-3):
    """dT/dt by an 8th-order central difference of the exact energy along q(t)."""
    rate = np.zeros_like(t)
    for k, c in enumerate(FD8):
        if c:
            q, dq, _ = qfun(t + (k - 4) * h)
            rate += c * kinetic_energy(model, q, dq)
    return rate / h


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_power_balance_random_joint_motions(seed):
    model = Model(ROBOT, general_inertia())
    rng = np.random.default_rng(seed)
    motion = lambda tt: random_joint_motion(np.random.default_rng(seed), tt)  # noqa: E731
    rng.random()
    t = np.linspace(0.0, 1.0, 201)
    q, dq, ddq = motion(t)
    tau = inverse_dynamics(model, q, dq, ddq)
    power = np.sum(tau * dq, axis=-1)
    rate = energy_rate(model, motion, t)
    assert np.abs(power - rate).max() <= 1e-8 * np.abs(power).max()


def test_power_balance_paper_trajectory(paper_traj, paper_model, law):
    t = paper_traj.t[5:-5]

    def motion(tt):
        tr = sample_trajectory(ROBOT, SEMI, law, times=tt)
        return tr.q, tr.dq, tr.ddq

    q, dq, ddq = motion(t)
    power = np.sum(inverse_dynamics(paper_model, q, dq, ddq) * dq, axis=-1)
    rate = energy_rate(paper_model, motion, t)
    assert np.abs(power - rate).max() <= 1e-8 * np.abs(power).max()


def test_energy_of_point_mass_only():
    model = Model(ROBOT, Inertia.uniform(ROBOT, proximal_mass=0, distal_mass=0, effector_mass=2.0))
    q, dq, _ = random_joint_motion(np.random.default_rng(4), np.linspace(0, 1, 50))
    P = dx.direct_kinematics(ROBOT, q)
    dP = dx.task_velocity(ROBOT, q, P, dq)
    np.testing.assert_allclose(kinetic_energy(model, q, dq), np.sum(dP**2, -1), rtol=1e-12)


def test_lumped_limit(paper_traj):
    """Massless rods: tau = J^T m a_P + rotor terms."""
    ine = Inertia.uniform(ROBOT, proximal_mass=0, distal_mass=0, effector_mass=1.3,
                          rotor=(0.02, 0.03))
    tr = paper_traj
    tau = inverse_dynamics(Model(ROBOT, ine), tr.q, tr.dq, tr.ddq)
    J = dx.jacobian(ROBOT, tr.q, tr.P)
    expect = np.einsum("nji,nj->ni", J, 1.3 * tr.ddP) + np.array([0.02, 0.03]) * tr.ddq
    np.testing.assert_allclose(tau, expect, atol=1e-12 * np.abs(expect).max())


def test_symmetry_of_paper_case(paper_traj, paper_model):
    tau = inverse_dynamics(paper_model, paper_traj.q, paper_traj.dq, paper_traj.ddq)
    np.testing.assert_allclose(tau[:, 0], -tau[::-1, 1], atol=1e-10 * np.abs(tau).max())


def test_decomposition_and_mass_matrix():
    model = Model(ROBOT, general_inertia(gravity=(0.3, -2.0), viscous=(0.01, 0.02)))
    q, dq, ddq = random_joint_motion(np.random.default_rng(5), np.linspace(0, 1, 40))
    M = mass_matrix(model, q)
    assert np.allclose(M, np.swapaxes(M, -1, -2), atol=1e-14)
    assert (np.linalg.eigvalsh(M) > 0).all()
    tau = inverse_dynamics(model, q, dq, ddq)
    rebuilt = (np.einsum("nij,nj->ni", M, ddq) + bias_forces(model, q, dq)
               + gravity_torques(model, q) + np.array([0.01, 0.02]) * dq)
    np.testing.assert_allclose(tau, rebuilt, atol=1e-12 * np.abs(tau).max())
    # kinetic energy is (1/2) qdot^T M qdot
    np.testing.assert_allclose(kinetic_energy(model, q, dq),
                               0.5 * np.einsum("ni,nij,nj->n", dq, M, dq), rtol=1e-12)


def test_accelerations_invert_the_inverse_dynamics(kernel):
    """Review 28 finding 11: the replay's windows and the forward dynamics share one
    vectorised ``accelerations`` (M from mass_matrix, h from one inverse_dynamics pass) where
    the replay had rebuilt M and h from three inverse-dynamics calls. Against the inverse
    dynamics with gravity, viscous and Coulomb friction and rotors (forward(inverse) =
    identity), and M against state_dynamics, the scalar model the integrators call."""
    from dextar.dynamics import state_dynamics

    model = Model(ROBOT, general_inertia(gravity=(0.3, -2.0), viscous=(0.01, 0.02),
                                         coulomb=(0.05, 0.03)))
    q, dq, ddq = random_joint_motion(np.random.default_rng(7), np.linspace(0, 1, 60))
    tau = inverse_dynamics(model, q, dq, ddq)
    acc = accelerations(model, q, dq, tau)
    np.testing.assert_allclose(acc, ddq, rtol=0, atol=1e-10 * np.abs(ddq).max())
    assert accelerations(model, q[3], dq[3], tau[3]).shape == (2,)  # one state
    M = mass_matrix(model, q)
    for i in (0, 17, 59):
        Mi, hi = state_dynamics(model, q[i], dq[i])
        np.testing.assert_allclose(M[i], Mi, rtol=0, atol=1e-13 * np.abs(Mi).max())
    # the torques of other accelerations are not these accelerations' (the check can fail)
    assert np.abs(accelerations(model, q, dq, tau + 1e-3) - ddq).max() > 1e-3


def test_accelerations_name_the_state_they_cannot_take():
    """The replay gives up a window by this error (one state at a time, named)."""
    model = Model(ROBOT, general_inertia())
    q = np.radians([[60.5, 119.5], [0.0, 180.0]])  # the second: rods 2.3 L apart
    with pytest.raises(dx.AssemblyError, match=r"cannot meet at sample 1: q = \(0, 180\) deg"):
        accelerations(model, q, np.zeros((2, 2)), np.zeros((2, 2)))


def test_gravity_is_potential_gradient():
    g = (0.4, -3.0)
    model = Model(ROBOT, general_inertia(gravity=g))
    q = np.radians([[60.0, 120.0], [40.0, 100.0], [80.0, 150.0]])

    def potential(qq):
        ine = model.inertia
        B, C = dx.elbows(ROBOT, qq)
        P = dx.direct_kinematics(ROBOT, qq)
        A, D = ROBOT.A, ROBOT.D
        pts = [
            (ine.proximal[0].mass, A + ine.proximal[0].com / ROBOT.l1 * (B - A)),
            (ine.proximal[1].mass, D + ine.proximal[1].com / ROBOT.l2 * (C - D)),
            (ine.distal[0].mass, B + ine.distal[0].com / ROBOT.L1 * (P - B)),
            (ine.distal[1].mass, C + ine.distal[1].com / ROBOT.L2 * (P - C)),
            (ine.point_mass, P),
        ]
        return -sum(m * (x @ np.array(g)) for m, x in pts)

    h = 1e-6
    grad = np.stack([(potential(q + h * e) - potential(q - h * e)) / (2 * h) for e in np.eye(2)],
                    -1)
    np.testing.assert_allclose(gravity_torques(model, q), grad, rtol=1e-7, atol=1e-9)


def test_reactions_reproduce_torques_by_newton_euler():
    g = (0.5, -2.0)
    model = Model(ROBOT, general_inertia(gravity=g))
    q, dq, ddq = random_joint_motion(np.random.default_rng(6), np.linspace(0, 1, 60))
    tau = inverse_dynamics(model, q, dq, ddq)
    R = joint_reactions(model, q, dq, ddq)
    ine = model.inertia
    # rod AB about A: tau1 = J_A phiddot + (B - A) x R_B - (G1 - A) x m1 g
    for k, (Rk, l, pivot_rod) in enumerate(((R.B, ROBOT.l1, ine.proximal[0]),
                                            (R.C, ROBOT.l2, ine.proximal[1]))):
        c, s = np.cos(q[:, k]), np.sin(q[:, k])
        Jk = ine.rotor[k] + pivot_rod.about_joint
        rebuilt = (Jk * ddq[:, k] + l * (c * Rk[:, 1] - s * Rk[:, 0])
                   - pivot_rod.mass * pivot_rod.com * (c * g[1] - s * g[0]))
        np.testing.assert_allclose(rebuilt, tau[:, k], atol=1e-10 * np.abs(tau).max())
    # the end-effector: P1 + P2 + m g = m a_P
    P = dx.direct_kinematics(ROBOT, q)
    _, ddP = dx.task_acceleration(ROBOT, q, P, dq, ddq)
    np.testing.assert_allclose(R.P1 + R.P2 + ine.point_mass * np.array(g),
                               ine.point_mass * ddP, atol=1e-10)


def test_singularity_raises_with_time():
    model = Model(ROBOT, general_inertia())
    # a configuration at the type-2 singularity: B, P, C aligned
    from scipy.optimize import brentq

    B = np.array([ROBOT.d / 2 + ROBOT.l1, 0.0])

    def gap(psi):
        C = np.array([-ROBOT.d / 2 + ROBOT.l2 * np.cos(psi), ROBOT.l2 * np.sin(psi)])
        return np.linalg.norm(B - C) - 2 * ROBOT.L1

    psi = brentq(gap, np.pi / 2, np.pi)
    q = np.array([[0.0, psi - 0.2], [0.0, psi]])
    with pytest.raises(dx.SingularityError, match=r"t = 0\.5 \(sample 1\)"):
        inverse_dynamics(model, q, np.zeros_like(q), np.zeros_like(q), t=[0.0, 0.5])


def test_invalid_inertia_named():
    with pytest.raises(dx.ParameterError, match="distal rod BP mass"):
        Inertia(proximal=(Rod(1, 0.5, 0.1),) * 2, distal=(Rod(-1, 0.5, 0.1), Rod(1, 0.5, 0.1)))
    with pytest.raises(dx.ParameterError, match="proximal rod DC inertia"):
        Inertia(proximal=(Rod(1, 0.5, 0.1), Rod(1, 0.5, -0.1)), distal=(Rod(1, 0.5, 0.1),) * 2)
    with pytest.raises(dx.ParameterError, match="payload"):
        Inertia.uniform(ROBOT, proximal_mass=1, distal_mass=1, payload=float("nan"))
    with pytest.raises(dx.ParameterError, match="massless"):
        Inertia(proximal=(Rod(0.0, 0.5, 0.1),) * 2, distal=(Rod(1, 0.5, 0.1),) * 2)


@pytest.mark.parametrize("seed", [3, 4])
def test_path_dynamics_is_the_inverse_dynamics_along_a_path(seed):
    """``tau = a sddot + b sdot^2 + g`` for the joint motion ``q(s(t))``: the one-pass
    coefficients against the general inverse dynamics at random speeds and accelerations."""
    from dextar.dynamics.exact import path_dynamics

    model = Model(ROBOT, general_inertia(gravity=(0.3, -9.81)))
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, 301)
    q, dq_ds, ddq_ds = random_joint_motion(np.random.default_rng(seed), s)
    a, b, g = path_dynamics(model, q, dq_ds, ddq_ds)
    sdot, sddot = rng.uniform(-2.0, 2.0, len(s)), rng.uniform(-5.0, 5.0, len(s))
    dq = dq_ds * sdot[:, None]
    ddq = dq_ds * sddot[:, None] + ddq_ds * (sdot**2)[:, None]
    tau = inverse_dynamics(model, q, dq, ddq)
    pred = a * sddot[:, None] + b * (sdot**2)[:, None] + g
    np.testing.assert_allclose(pred, tau, rtol=0, atol=1e-11 * np.abs(tau).max())
    np.testing.assert_allclose(g, gravity_torques(model, q), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(a, np.einsum("nij,nj->ni", mass_matrix(model, q), dq_ds),
                               rtol=0, atol=1e-12 * np.abs(a).max())
