import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dextar as dx
from dextar.geometry import WORKING_MODES

ROBOT = dx.DEXTAR_MM


def _curve(t):
    """A smooth curve inside the "+-" workspace with its first two derivatives."""
    x = 30 * np.sin(1.3 * t) + 10 * np.cos(2.1 * t)
    y = 110 + 15 * np.cos(0.7 * t)
    dx_ = 30 * 1.3 * np.cos(1.3 * t) - 10 * 2.1 * np.sin(2.1 * t)
    dy_ = -15 * 0.7 * np.sin(0.7 * t)
    ddx = -30 * 1.69 * np.sin(1.3 * t) - 10 * 4.41 * np.cos(2.1 * t)
    ddy = -15 * 0.49 * np.cos(0.7 * t)
    return (np.stack([x, y], -1), np.stack([dx_, dy_], -1), np.stack([ddx, ddy], -1))


@settings(max_examples=100, deadline=None)
@given(st.floats(-40, 40), st.floats(90, 135), st.sampled_from(WORKING_MODES))
def test_jacobian_against_finite_differences(x, y, mode):
    p = np.array([x, y])
    q = dx.inverse_kinematics(ROBOT, p, mode)
    t1, t2 = dx.singularity_distances(ROBOT, q, p)
    if min(t1, t2) < 0.05:
        return
    sigma = "up" if dx.assembly_mode(ROBOT, q, p) > 0 else "down"
    J = dx.jacobian(ROBOT, q, p)
    h = 1e-6
    fd = np.column_stack(
        [
            (
                dx.direct_kinematics(ROBOT, q + h * e, sigma)
                - dx.direct_kinematics(ROBOT, q - h * e, sigma)
            )
            / (2 * h)
            for e in np.eye(2)
        ]
    )
    np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-6 * np.abs(J).max())


def test_acceleration_relation_against_finite_differences():
    t = np.linspace(0, 2, 2001)
    P, dP, ddP = _curve(t)
    q = dx.inverse_kinematics(ROBOT, P, "+-", unwrap=True)
    dq = dx.joint_velocity(ROBOT, q, P, dP)
    ddq = dx.joint_acceleration(ROBOT, q, P, dq, dP, ddP)
    h = t[1] - t[0]
    np.testing.assert_allclose(dq[1:-1], (q[2:] - q[:-2]) / (2 * h), rtol=0, atol=1e-5)
    np.testing.assert_allclose(ddq[1:-1], (q[2:] - 2 * q[1:-1] + q[:-2]) / h**2, rtol=0, atol=1e-4)
    # and back
    dP2, ddP2 = dx.task_acceleration(ROBOT, q, P, dq, ddq)
    np.testing.assert_allclose(dP2, dP, atol=1e-9)
    np.testing.assert_allclose(ddP2, ddP, atol=1e-8)
    np.testing.assert_allclose(dx.task_velocity(ROBOT, q, P, dq), dP, atol=1e-9)


def test_velocity_matrices_define_jacobian():
    P = np.array([[10.0, 120.0], [-20.0, 100.0]])
    q = dx.inverse_kinematics(ROBOT, P, "+-")
    A, B = dx.velocity_matrices(ROBOT, q, P)
    J = dx.jacobian(ROBOT, q, P)
    np.testing.assert_allclose(A @ J, B, atol=1e-9)
    assert A.shape == B.shape == (2, 2, 2)


def test_type2_singularity_raises_with_configuration():
    # distal rods aligned: |B - C| = L1 + L2 with phi = 0; P is the midpoint of BC
    from scipy.optimize import brentq

    B = np.array([102.0, 0.0])

    def gap(psi):
        C = np.array([-30 + 72 * np.cos(psi), 72 * np.sin(psi)])
        return np.linalg.norm(B - C) - 174.0

    psi = brentq(gap, np.pi / 2, np.pi)
    C = np.array([-30 + 72 * np.cos(psi), 72 * np.sin(psi)])
    q, P = np.array([0.0, psi]), 0.5 * (B + C)
    assert dx.singularity_distances(ROBOT, q, P)[1] < 1e-9
    with pytest.raises(dx.SingularityError, match="parallel") as e:
        dx.jacobian(ROBOT, q, P)
    assert "q = (0, " in str(e.value) and "P = (" in str(e.value)
    # a nearby, regular configuration passes
    q2 = q - [0.0, 0.3]
    dx.jacobian(ROBOT, q2, dx.direct_kinematics(ROBOT, q2, "up"))


def test_type1_singularity_raises():
    # leg 1 stretched: P at distance l1 + L1 from A
    p = np.array([30.0 + 159.0 * np.cos(2.0), 159.0 * np.sin(2.0)])
    q = dx.inverse_kinematics(ROBOT, p, "+-")
    with pytest.raises(dx.SingularityError, match="serial"):
        dx.joint_velocity(ROBOT, q, p, [1.0, 0.0])


def test_workspace_map():
    ws = dx.workspace_map(ROBOT, "+-", resolution=121)
    assert ws.reachable.shape == ws.dexterity.shape == (ws.y.size, ws.x.size)
    assert (
        np.isfinite(ws.dexterity).all() and (ws.dexterity >= 0).all() and (ws.dexterity <= 1).all()
    )
    # reachable set equals the intersection of the two annuli
    X, Y = np.meshgrid(ws.x, ws.y)
    r1, r2 = np.hypot(X - 30, Y), np.hypot(X + 30, Y)
    expect = (r1 >= 15) & (r1 <= 159) & (r2 >= 15) & (r2 <= 159)
    assert (ws.reachable != expect).mean() < 0.01
    # the paper's semicircle lies in the dexterous region of "+-"
    i = np.argmin(np.abs(ws.y - 120)), np.argmin(np.abs(ws.x))
    assert ws.dexterity[i] > 0.3


def test_workspace_plot(tmp_path):
    from dextar.output.figures import plot_workspace
    from dextar.output.files import save_figure

    ws = dx.workspace_map(ROBOT, "+-", resolution=60)
    fig = plot_workspace(ws)
    save_figure(fig, tmp_path / "w.png")
    assert (tmp_path / "w.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
