import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dextar as dx
from dextar.geometry import WORKING_MODES, FiveBar

ROBOT = dx.DEXTAR_MM


def test_paper_vector():
    q = dx.inverse_kinematics(ROBOT, [0.0, 120.0], "+-")
    assert np.degrees(q) == pytest.approx([60.5118, 119.4882], abs=1e-4)


def test_paper_vector_closed_form():
    # symmetric point on the axis: |AP|^2 = 30^2 + 120^2, law of cosines at A
    rho = np.hypot(30.0, 120.0)
    alpha = np.arccos((72**2 + rho**2 - 87**2) / (2 * 72 * rho))
    phi = np.arctan2(120.0, -30.0) - alpha  # "+": elbow to the right of A->P
    q = dx.inverse_kinematics(ROBOT, [0.0, 120.0], "+-")
    assert q[0] == pytest.approx(phi, abs=1e-12)
    assert q[1] == pytest.approx(np.pi - phi, abs=1e-12)


reachable = st.tuples(st.floats(-140, 140), st.floats(-140, 140)).filter(
    lambda p: all(20.0 < np.hypot(p[0] - c, p[1]) < 155.0 for c in (30.0, -30.0))
)


@settings(max_examples=300, deadline=None)
@given(reachable, st.sampled_from(WORKING_MODES))
def test_fk_ik_round_trip(p, mode):
    q = dx.inverse_kinematics(ROBOT, p, mode)
    assert dx.working_mode(ROBOT, q, p).tolist() == [1 if c == "+" else -1 for c in mode]
    if min(dx.singularity_distances(ROBOT, q, p)) < 1e-3:
        return
    sigma = int(dx.assembly_mode(ROBOT, q, p))
    P = dx.direct_kinematics(ROBOT, q, "up" if sigma > 0 else "down")
    np.testing.assert_allclose(P, p, atol=1e-9)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-np.pi, np.pi), st.sampled_from(["up", "down"]))
def test_ik_fk_round_trip(phi, psi, assembly):
    q = np.array([phi, psi])
    try:
        P = dx.direct_kinematics(ROBOT, q, assembly)
    except dx.AssemblyError:
        return
    t1, t2 = dx.singularity_distances(ROBOT, q, P)
    if min(t1, t2) < 1e-6:
        return
    signs = dx.working_mode(ROBOT, q, P)
    mode = "".join("+" if s > 0 else "-" for s in signs)
    assert int(dx.assembly_mode(ROBOT, q, P)) == (1 if assembly == "up" else -1)
    q2 = dx.inverse_kinematics(ROBOT, P, mode)
    np.testing.assert_allclose(np.angle(np.exp(1j * (q2 - q))), 0.0, atol=1e-7)


def test_vectorised_any_shape_and_general_geometry():
    robot = FiveBar(l1=70, l2=80, L1=95, L2=90, d=50)
    rng = np.random.default_rng(1)
    P = np.stack([rng.uniform(-40, 40, (3, 4, 5)), rng.uniform(90, 130, (3, 4, 5))], -1)
    for mode in WORKING_MODES:
        q = dx.inverse_kinematics(robot, P, mode)
        assert q.shape == (3, 4, 5, 2)
        sigma = dx.assembly_mode(robot, q, P)
        for s, name in ((1, "up"), (-1, "down")):
            m = sigma == s
            if m.any():
                np.testing.assert_allclose(dx.direct_kinematics(robot, q[m], name), P[m], atol=1e-9)


def test_unwrap_along_sequence():
    t = np.linspace(0, np.pi, 50)
    P = np.stack([120 * np.cos(t), 120 * np.sin(t)], -1)
    q = dx.inverse_kinematics(ROBOT, P, "+-", unwrap=True)
    assert np.abs(np.diff(q, axis=0)).max() < 0.2


def test_out_of_reach_names_point_leg_distance():
    pts = np.array([[0.0, 120.0], [0.0, 130.0], [200.0, 0.0]])
    with pytest.raises(dx.ReachError) as e:
        dx.inverse_kinematics(ROBOT, pts)
    msg = str(e.value)
    assert "(200, 0)" in msg and "index 2" in msg and "leg 1" in msg and "out by 11" in msg


def test_rods_cannot_meet():
    with pytest.raises(dx.AssemblyError, match="cannot meet"):
        dx.direct_kinematics(ROBOT, [0.0, np.pi])  # elbows 204 apart > 174


def test_no_nan_escapes_on_nan_input():
    with pytest.raises(dx.DextarError, match="non-finite"):
        dx.inverse_kinematics(ROBOT, [np.nan, 1.0])


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"l1": -1, "l2": 72, "L1": 87, "L2": 87, "d": 60}, "l1"),
        ({"l1": 72, "l2": 72, "L1": float("inf"), "L2": 87, "d": 60}, "L1"),
        ({"l1": 10, "l2": 10, "L1": 10, "L2": 10, "d": 100}, "never close"),
        ({"l1": 100, "l2": 5, "L1": 5, "L2": 5, "d": 10}, "leg 1"),
    ],
)
def test_invalid_geometry(kwargs, word):
    with pytest.raises(dx.GeometryError, match=word):
        FiveBar(**kwargs)
