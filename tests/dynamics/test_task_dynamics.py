"""task_inverse_dynamics: the joint rates and torques of an end-effector motion in one pass
of the compiled kernel, against the stages it fuses (inverse kinematics, joint_rates,
inverse_dynamics) in every working and assembly mode, and its errors: those of the stages,
naming the same sample."""

import numpy as np
import pytest

from dextar.dynamics import Inertia, Model, Rod, exact, inverse_dynamics
from dextar.dynamics.exact import task_inverse_dynamics
from dextar.errors import ParameterError, ReachError, SingularityError
from dextar.geometry import FiveBar
from dextar.kinematics import (
    assembly_mode,
    inverse_kinematics,
    joint_rates,
    singularity_distances,
    task_acceleration,
)

from .conftest import ROBOT

ASYMMETRIC = FiveBar(l1=0.8, l2=0.95, L1=1.1, L2=0.9, d=0.6)
MODES = ["++", "+-", "-+", "--"]


def inertia():
    return Inertia(
        proximal=(Rod(0.08, 0.3, 0.004), Rod(0.11, 0.45, 0.006)),
        distal=(Rod(0.1, 0.55, 0.009), Rod(0.07, 0.4, 0.005)),
        effector_mass=1.0, payload=0.2, rotor=(0.01, 0.015), gravity=(0.3, -0.9),
        viscous=(0.02, 0.05), coulomb=(0.01, 0.03), coulomb_speed=0.5)


def motion(robot, mode, n, seed):
    """End-effector states in working mode ``mode``, well clear of both singularity types (torques grow as 1 / det^2 near a
    parallel one: rounding with them), from
    random joint rates (exact: Pdot and Pddot from the velocity relations), and the
    assembly mode of most of them."""
    rng = np.random.default_rng(seed)
    reach = robot.l1 + robot.L1
    P = np.stack([rng.uniform(-0.6, 0.6, 20 * n), rng.uniform(0.2, 1.0, 20 * n)], -1) * reach
    # within both legs' annuli (a point within 1e-9 of an annulus' edge is a stretched or
    # folded leg, which the serial-singularity distance below leaves out anyway)
    ok = np.ones(len(P), bool)
    for leg, pivot in ((1, robot.A), (2, robot.D)):
        rin, rout = robot.reach(leg)
        r = np.hypot(P[:, 0] - pivot[0], P[:, 1] - pivot[1])
        ok &= (r > rin + 1e-9 * rout) & (r < rout * (1 - 1e-9))
    P = P[ok]
    q = inverse_kinematics(robot, P, mode)
    t1, t2 = singularity_distances(robot, q, P)
    keep = (t1 > 0.1) & (t2 > 0.2)
    P, q = P[keep][:n], q[keep][:n]
    assert len(P) == n
    sig = assembly_mode(robot, q, P)
    dq = rng.normal(0.0, 2.0, (n, 2))
    ddq = rng.normal(0.0, 10.0, (n, 2))
    dP, ddP = task_acceleration(robot, q, P, dq, ddq, tol=0.0)
    assembly = "up" if (sig > 0).mean() >= 0.5 else "down"
    same = sig == (1 if assembly == "up" else -1)
    return P[same], dP[same], ddP[same], q[same], dq[same], ddq[same], assembly


compiled_only = pytest.mark.skipif(exact._compiled is None, reason="the compiled kernel was "
                                   "not built (no C compiler at install)")


@compiled_only
@pytest.mark.parametrize("robot", [ROBOT, ASYMMETRIC], ids=["dextar", "asymmetric"])
@pytest.mark.parametrize("mode", MODES)
def test_the_fused_pass_equals_the_stages_in_turn(robot, mode, monkeypatch):
    """Measured over these 8 cases: rates within 1.5e-15, accelerations 1.9e-14 of the
    stages' and of the joint rates the motion was made from, torques within 8.4e-14 of the
    largest (the stages take the motor angles' cosines from an angle, the fused pass from
    the elbows: rounding, grown by 1 / det near a parallel singularity); bound 1e-12 each. A
    rotor inertia 1e-6 larger shows 5e-11 to 4e-10 (that check's bound 1e-11)."""
    P, dP, ddP, q0, dq0, ddq0, assembly = motion(robot, mode, 400, 5)
    model = Model(robot, inertia(), assembly=assembly, tol=1e-3)
    monkeypatch.setattr(exact, "USE_COMPILED", True)
    dq, ddq, tau = task_inverse_dynamics(model, mode, P, dP, ddP)
    q = inverse_kinematics(robot, P, mode)
    rdq, rddq = joint_rates(robot, q, P, dP, ddP, tol=0.0)
    rtau = inverse_dynamics(model, q, rdq, rddq)
    for got, want in ((dq, rdq), (ddq, rddq), (tau, rtau), (dq, dq0), (ddq, ddq0)):
        assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()
    other = Model(robot, inertia().with_(rotor=(0.01 * (1 + 1e-6), 0.015)),
                  assembly=assembly, tol=1e-3)
    assert np.abs(task_inverse_dynamics(other, mode, P, dP, ddP)[2] - rtau).max() \
        > 1e-11 * np.abs(rtau).max()


@pytest.mark.parametrize("mode", MODES)
def test_the_rates_are_those_the_motion_was_made_from_and_shapes_are_kept(mode, kernel):
    """Either build: the joint rates the end-effector motion was made from (measured 1.5e-15
    and 1.9e-14 of the largest; bound 1e-12), for samples of any leading shape."""
    P, dP, ddP, q0, dq0, ddq0, assembly = motion(ROBOT, mode, 120, 8)
    model = Model(ROBOT, inertia(), assembly=assembly, tol=1e-3)
    shape = (len(P) // 6, 6, 2)
    n = shape[0] * 6
    dq, ddq, tau = task_inverse_dynamics(model, mode, *(x[:n].reshape(shape)
                                                        for x in (P, dP, ddP)))
    assert dq.shape == ddq.shape == tau.shape == shape
    for got, want in ((dq, dq0[:n]), (ddq, ddq0[:n])):
        assert np.abs(got.reshape(-1, 2) - want).max() <= 1e-12 * np.abs(want).max()
    one = task_inverse_dynamics(model, mode, P[3], dP[3], ddP[3])
    assert [x.shape for x in one] == [(2,)] * 3
    assert np.abs(one[2] - tau.reshape(-1, 2)[3]).max() <= 1e-12 * np.abs(tau).max()
    with pytest.raises(ParameterError, match="the same shape"):
        task_inverse_dynamics(model, mode, P, dP[:1], ddP)


@compiled_only
def test_on_a_stretched_leg_both_builds_agree_on_an_error(monkeypatch):
    """Points on leg 1's outer boundary (within the inverse kinematics' reach tolerance),
    where the joint rate is unbounded: the compiled pass hands a rate of rounding noise over
    to the stages, so that both builds raise the same error or give the same (huge) rates,
    never one an error and the other a number. Measured: 261 errors and 170 numbers of 431
    points, each alike."""
    import warnings

    from dextar.dynamics import paper_inertia

    model = Model(ROBOT, paper_inertia(ROBOT))
    ang = np.linspace(0.3, 2.8, 431)
    P = np.array([ROBOT.d / 2, 0.0]) + (ROBOT.l1 + ROBOT.L1) * np.stack([np.cos(ang),
                                                                        np.sin(ang)], -1)

    def outcome(compiled, p):
        monkeypatch.setattr(exact, "USE_COMPILED", compiled)
        try:
            return task_inverse_dynamics(model, "+-", p[None], np.array([[0.1, 0.2]]),
                                         np.zeros((1, 2)))
        except (ParameterError, ReachError, SingularityError) as e:
            return f"{type(e).__name__}: {e}"

    kinds = set()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the stages divide by zero there
        for p in P:
            a, b = outcome(True, p), outcome(False, p)
            assert isinstance(a, str) == isinstance(b, str)
            if isinstance(a, str):
                assert a == b
            kinds.add(isinstance(a, str))
    assert kinds == {True, False}  # both kinds occur


def test_a_point_out_of_reach_is_named_as_the_inverse_kinematics_names_it(kernel):
    P, dP, ddP, *_, assembly = motion(ROBOT, "+-", 50, 3)
    model = Model(ROBOT, inertia(), assembly=assembly)
    P = P.copy()
    P[37] = (0.0, 5.0)
    with pytest.raises(ReachError) as fused:
        task_inverse_dynamics(model, "+-", P, dP, ddP)
    with pytest.raises(ReachError) as stages:
        inverse_kinematics(ROBOT, P, "+-")
    assert str(fused.value) == str(stages.value)
    assert "at index 37 is out of reach of leg 1" in str(fused.value)


@pytest.mark.parametrize("name", ["points", "dpoints", "ddpoints"])
def test_a_value_that_is_not_finite_is_named_by_input_and_index(name, kernel):
    P, dP, ddP, *_, assembly = motion(ROBOT, "+-", 50, 4)
    model = Model(ROBOT, inertia(), assembly=assembly)
    args = {"points": P.copy(), "dpoints": dP.copy(), "ddpoints": ddP.copy()}
    args[name][21, 1] = np.nan
    with pytest.raises(ParameterError, match=rf"^{name} has a non-finite value at index "
                                             r"\(21, 1\)"):
        task_inverse_dynamics(model, "+-", args["points"], args["dpoints"], args["ddpoints"])


def test_a_sample_near_a_parallel_singularity_is_named(kernel):
    """The samples' largest 1 / |det| against the model's tolerance: the stages name the
    sample nearest; a tolerance below every sample's distance passes them all."""
    P, dP, ddP, q, *_, assembly = motion(ROBOT, "+-", 80, 6)
    dist = singularity_distances(ROBOT, q, P)[1]
    worst = int(np.argmin(dist))
    tight = Model(ROBOT, inertia(), assembly=assembly, tol=dist.min() * 1.01)
    with pytest.raises(SingularityError, match=rf"singularity at sample {worst}: q = "):
        task_inverse_dynamics(tight, "+-", P, dP, ddP)
    loose = Model(ROBOT, inertia(), assembly=assembly, tol=dist.min() * 0.99)
    assert np.isfinite(task_inverse_dynamics(loose, "+-", P, dP, ddP)[2]).all()
