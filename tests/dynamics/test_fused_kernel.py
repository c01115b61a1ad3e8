"""The fused torque kernel (inverse_dynamics, bias_forces, gravity_torques), compiled and in
numpy, against a straightforward evaluation of Kane's equations, body by body, written here
independently of the kernel's identities (equimomental rods, the legs side by side, det and
u . e in closed form), and the two kernels against each other."""

import numpy as np
import pytest

from dextar.dynamics import (
    Inertia,
    Model,
    Rod,
    bias_forces,
    exact,
    gravity_torques,
    inverse_dynamics,
)
from dextar.dynamics.exact import _torques
from dextar.errors import ParameterError, SingularityError
from dextar.geometry import FiveBar

from ..compiled import skip_without_a_compiler
from .conftest import ROBOT

ASYMMETRIC = FiveBar(l1=0.8, l2=0.95, L1=1.1, L2=0.9, d=0.6)


def inertia(**kw):
    return Inertia(
        proximal=(Rod(0.08, 0.3, 0.004), Rod(0.11, 0.45, 0.006)),
        distal=(Rod(0.1, 0.55, 0.009), Rod(0.07, 0.4, 0.005)),
        effector_mass=1.0, payload=0.2, rotor=(0.01, 0.015), **kw)


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def perp(a):
    return np.stack([-a[..., 1], a[..., 0]], axis=-1)


def pose(model, q):
    """Motor directions, proximal rods, elbows B and C, P and the distal rods, per sample."""
    r = model.robot
    sign = 1.0 if model.assembly in ("up", 1) else -1.0
    base = np.array([[r.d / 2, 0.0], [-r.d / 2, 0.0]])
    dirs = np.stack([np.cos(q), np.sin(q)], axis=-1)  # (n, 2 legs, 2)
    arm = np.array([r.l1, r.l2])[None, :, None] * dirs
    E = base[None] + arm  # elbows B, C
    v = E[:, 0] - E[:, 1]
    del2 = np.sum(v * v, -1)
    k = 0.5 * (del2 + r.L2**2 - r.L1**2)
    h = sign * np.sqrt(r.L2**2 * del2 - k * k)
    P = E[:, 1] + (k[:, None] * v + h[:, None] * perp(v)) / del2[:, None]
    return dirs, arm, E, P, P[:, None] - E


def reference(model, q, dq, ddq, *, gravity=True, friction=True):
    """tau = sum over the bodies of J_i^T m_i (a_Gi - g) + J_omega_i^T I_i alpha_i, with the
    Jacobians from A Pdot = diag(b) qdot, solved per sample by np.linalg.solve."""
    r, ine = model.robot, model.inertia
    g = np.array(ine.gravity if gravity else (0.0, 0.0))
    Ls = np.array([r.L1, r.L2])
    dirs, arm, E, P, U = pose(model, q)  # U: distal rods, (n, 2 legs, 2)
    dE_dq = perp(arm)  # dE_i / dq_i
    A = U  # rows u, e
    b = np.sum(U * dE_dq, -1)  # U_i . dE_i/dq_i
    JP = np.linalg.solve(A, b[:, :, None] * np.eye(2)[None])  # dP/dq, (n, 2 xy, 2 q)
    dE = dE_dq * dq[..., None]
    ddE = dE_dq * ddq[..., None] - arm * (dq**2)[..., None]
    dP = np.einsum("nij,nj->ni", JP, dq)
    rel = dP[:, None] - dE
    rhs = np.sum(U * ddE, -1) - np.sum(rel * rel, -1)
    ddP = np.linalg.solve(A, rhs[..., None])[..., 0]
    tau = np.zeros_like(q)
    for i in range(2):
        prox, dist = ine.proximal[i], ine.distal[i]
        JE = np.zeros((len(q), 2, 2))  # dE_i/dq, (n, 2 xy, 2 q)
        JE[:, :, i] = dE_dq[:, i]
        # the proximal rod about its fixed axis, its rotor, its gravity
        tau[:, i] += (prox.about_joint + ine.rotor[i]) * ddq[:, i]
        tau[:, i] -= prox.mass * prox.com * cross(dirs[:, i], np.broadcast_to(g, (len(q), 2)))
        # the distal rod: centre G = E + lam U, rotation omega = U x (Pdot - Edot) / L^2
        lam = dist.com / Ls[i]
        JG = JE + lam * (JP - JE)
        aG = ddE[:, i] + lam * (ddP - ddE[:, i])
        JU = JP - JE  # dU_i/dq
        Jw = (U[:, i, 0, None] * JU[:, 1] - U[:, i, 1, None] * JU[:, 0]) / Ls[i] ** 2
        alpha = cross(U[:, i], ddP - ddE[:, i]) / Ls[i] ** 2
        tau += np.einsum("nxq,nx->nq", JG, dist.mass * (aG - g))
        tau += Jw * (dist.inertia * alpha)[:, None]
    tau += np.einsum("nxq,nx->nq", JP, ine.point_mass * (ddP - g))
    if friction:
        tau += ine.viscous * dq + ine.coulomb * np.tanh(dq / ine.coulomb_speed)
    return tau


def states(robot, n, seed):
    """Random states near the paper's pose, kept away from parallel singularities."""
    rng = np.random.default_rng(seed)
    q = np.radians([60.5, 119.5]) + rng.uniform(-0.35, 0.35, (n, 2))
    dq = rng.normal(0.0, 2.0, (n, 2))
    ddq = rng.normal(0.0, 10.0, (n, 2))
    return q, dq, ddq


@pytest.mark.parametrize("robot", [ROBOT, ASYMMETRIC], ids=["dextar", "asymmetric"])
@pytest.mark.parametrize("assembly", ["up", "down"])
def test_fused_kernel_equals_straightforward_kane(robot, assembly, kernel):
    """Measured: relative differences 7e-15 to 1.2e-14 (bound 1e-12; a distal inertia 1e-6
    larger shows 5e-9), over gravity with both
    components, viscous and Coulomb friction, rotors and non-uniform rods."""
    model = Model(robot, inertia(gravity=(0.3, -0.9), viscous=(0.02, 0.05),
                                 coulomb=(0.01, 0.03), coulomb_speed=0.5),
                  assembly=assembly, tol=0.0)
    q, dq, ddq = states(robot, 3000, 7)
    ref = reference(model, q, dq, ddq)
    keep = np.isfinite(ref).all(axis=1)
    assert keep.mean() > 0.9
    q, dq, ddq, ref = q[keep], dq[keep], ddq[keep], ref[keep]
    scale = np.abs(ref).max()
    tau = inverse_dynamics(model, q, dq, ddq)
    assert np.abs(tau - ref).max() <= 1e-12 * scale
    z = np.zeros_like(q)
    c = bias_forces(model, q, dq)
    np.testing.assert_allclose(c, reference(model, q, dq, z, gravity=False, friction=False),
                               rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(gravity_torques(model, q),
                               reference(model, q, z, z, friction=False),
                               rtol=0, atol=1e-12 * scale)
    # and the comparison can fail: a distal inertia 1e-6 larger is seen
    heavier = Model(robot, inertia(gravity=(0.3, -0.9), viscous=(0.02, 0.05),
                                   coulomb=(0.01, 0.03), coulomb_speed=0.5).with_(
        distal=(Rod(0.1, 0.55, 0.009 * (1 + 1e-6)), Rod(0.07, 0.4, 0.005))),
        assembly=assembly, tol=0.0)
    assert np.abs(inverse_dynamics(heavier, q, dq, ddq) - ref).max() > 1e-10 * scale


@pytest.mark.parametrize("block", [1, 7, 64, 1000])
def test_blocks_and_shapes_do_not_change_the_torques(block, kernel):
    """Any block size (a last block shorter than the others, blocks of one sample) and any
    leading shape give the same torques."""
    model = Model(ROBOT, inertia(gravity=(0.0, -1.0)))
    q, dq, ddq = states(ROBOT, 1500, 3)
    whole = _torques(model, q, dq, ddq, gravity=True, friction=True)
    blocked = _torques(model, q, dq, ddq, gravity=True, friction=True, block=block)
    np.testing.assert_allclose(blocked, whole, rtol=0, atol=1e-13 * np.abs(whole).max())
    shaped = inverse_dynamics(model, q.reshape(30, 50, 2), dq.reshape(30, 50, 2),
                              ddq.reshape(30, 50, 2))
    assert shaped.shape == (30, 50, 2)
    np.testing.assert_allclose(shaped.reshape(-1, 2), whole, rtol=0, atol=0)
    one = inverse_dynamics(model, q[5], dq[5], ddq[5])
    assert one.shape == (2,)
    np.testing.assert_allclose(one, whole[5], rtol=0, atol=1e-13 * np.abs(whole).max())
    assert inverse_dynamics(model, q[:0], dq[:0], ddq[:0]).shape == (0, 2)


def test_singular_sample_in_a_late_block_is_named(kernel):
    """The block's extremes catch a sample too near a parallel singularity anywhere (here the
    nearest of 300, in whichever block it falls) and the error names it and its time like the
    per-sample check does; a tolerance below every sample raises nothing."""
    q, dq, ddq = states(ROBOT, 300, 5)
    t = np.linspace(0.0, 3.0, 300)
    model = Model(ROBOT, inertia())
    _, _, _, _, U = pose(model, q)
    dist = np.abs(cross(U[:, 0], U[:, 1])) / (ROBOT.L1 * ROBOT.L2)
    order = np.argsort(dist)
    worst = int(order[0])
    loose = Model(ROBOT, inertia(), tol=0.5 * (dist[order[0]] + dist[order[1]]))
    with pytest.raises(SingularityError, match=rf"at t = {t[worst]:.6g} \(sample {worst}\)"):
        _torques(loose, q, dq, ddq, gravity=True, friction=True, t=t, block=64)
    _torques(Model(ROBOT, inertia(), tol=0.5 * dist.min()), q, dq, ddq, gravity=True,
             friction=True, t=t, block=64)


def test_the_compiled_kernel_is_built_where_a_compiler_is():
    """pip builds the kernel where a C compiler is (as on CI): a failed build would otherwise
    pass unseen, every test then running the numpy kernel."""
    skip_without_a_compiler()
    assert exact._compiled is not None, (
        "dextar.dynamics._kernel was not built: reinstall (pip install -e .) and read the "
        "compiler's output")
    assert exact.USE_COMPILED


@pytest.mark.parametrize("robot", [ROBOT, ASYMMETRIC], ids=["dextar", "asymmetric"])
@pytest.mark.parametrize("assembly", ["up", "down"])
@pytest.mark.parametrize("friction", [False, True])
def test_compiled_and_numpy_kernels_agree(robot, assembly, friction, monkeypatch):
    """The two kernels on the same states, in every quadrant of the angles (their cos and sin
    differ: a polynomial against tan(q/2)), a whole number of turns away, at the quarter
    turns and beyond the polynomial's reduction (libm there). Measured: 4e-15 to 8e-15 of the
    largest torque (bound 1e-13); a rotor inertia 1e-8 larger shows 1.1e-11 to 3.4e-11
    (bound 1e-12)."""
    if exact._compiled is None:
        pytest.skip("the compiled kernel was not built (no C compiler at install)")
    ine = inertia(gravity=(0.3, -0.9), **({"viscous": (0.02, 0.05), "coulomb": (0.01, 0.03),
                                           "coulomb_speed": 0.5} if friction else {}))
    model = Model(robot, ine, assembly=assembly, tol=0.0)
    q, dq, ddq = states(robot, 4000, 11)
    turns = np.random.default_rng(2).integers(-3, 4, (4000, 2)) * 2 * np.pi
    q = q + turns
    q[:8] = np.radians([[90.0, 90.0], [0.0, 90.0], [-90.0, 270.0], [45.0, 135.0],
                        [90.0, 120.0], [60.0, 90.0], [180.0, 180.0], [60.0, 150.0]])
    q[8:16] += 2 * np.pi * 2e5  # beyond 2^19 pi/2: libm's cos and sin
    monkeypatch.setattr(exact, "USE_COMPILED", True)
    compiled = inverse_dynamics(model, q, dq, ddq)
    monkeypatch.setattr(exact, "USE_COMPILED", False)
    plain = inverse_dynamics(model, q, dq, ddq)
    scale = np.abs(plain).max()
    assert np.isfinite(compiled).all()
    assert np.abs(compiled - plain).max() <= 1e-13 * scale
    other = Model(robot, ine.with_(rotor=(0.01 * (1 + 1e-8), 0.015)), assembly=assembly, tol=0.0)
    monkeypatch.setattr(exact, "USE_COMPILED", True)
    assert np.abs(inverse_dynamics(other, q, dq, ddq) - plain).max() > 1e-12 * scale


@pytest.mark.parametrize("bad", ["q", "dq", "ddq"])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_a_value_that_is_not_finite_is_named_by_input_and_index(bad, value, kernel):
    """The compiled kernel checks its inputs as it reads them; the error names the input and
    the sample's index in the caller's shape, as the numpy kernel's check does."""
    model = Model(ROBOT, inertia(gravity=(0.0, -1.0)))
    q, dq, ddq = states(ROBOT, 600, 9)
    args = {"q": q.reshape(20, 30, 2), "dq": dq.reshape(20, 30, 2), "ddq": ddq.reshape(20, 30, 2)}
    args[bad] = args[bad].copy()
    args[bad][17, 4, 1] = value
    with pytest.raises(ParameterError, match=rf"^{bad} has a non-finite value at index \(17, 4, 1\)"):
        inverse_dynamics(model, args["q"], args["dq"], args["ddq"])


def test_an_old_build_of_the_compiled_kernel_is_not_used():
    """A build of another interface version (an edit of _kernel.c whose build failed leaves
    the old one in place) is set aside at import: the numpy kernel runs, no crash."""
    from types import SimpleNamespace

    from dextar._compiled import usable

    version = exact.KERNEL_VERSION
    assert not usable(None, version)
    assert not usable(SimpleNamespace(torques=None), version)  # a build before versions
    assert not usable(SimpleNamespace(VERSION=version - 1), version)
    assert usable(SimpleNamespace(VERSION=version), version)
    if exact._compiled is not None:
        assert usable(exact._compiled, version)
