"""Measurement poses: within the margins, in visiting order, more observable than chance,
and more observable in four working modes than in one."""

import numpy as np
import pytest

import dextar as dx
from dextar.calibration import select_poses
from dextar.calibration.model import closure, jacobian
from dextar.calibration.observability import observability
from dextar.calibration.poses import candidates
from dextar.errors import ParameterError

from .conftest import MODES, NOMINAL


def test_poses_are_reachable_away_from_singularities_and_grouped(four_modes):
    s = four_modes
    assert len(s) == 60 and s.success and s.index == "O1"
    assert set(s.modes) == set(MODES)
    changes = sum(a != b for a, b in zip(s.modes, s.modes[1:], strict=False))
    assert changes == len(set(s.modes)) - 1          # each mode visited once
    assert s.modes[0] == "+-"                         # the robot's mode first
    assert s.type1.min() >= 0.2 and s.type2.min() >= 0.2
    # the readings put the nominal robot at the points, in the stated modes and assembly
    k = closure(NOMINAL, s.readings, 1)
    np.testing.assert_allclose(k.P, s.points, atol=1e-12)
    for m in MODES:
        sel = np.array([x == m for x in s.modes])
        np.testing.assert_allclose(dx.inverse_kinematics(NOMINAL.robot, s.points[sel], m),
                                   s.readings[sel], atol=1e-12)
    # poses of a mode keep the spacing (4 % of the legs' mean reach = 6.36 mm)
    for m in MODES:
        P = s.points[[x == m for x in s.modes]]
        d = np.hypot(*(P[:, None] - P[None]).transpose(2, 0, 1))
        assert d[np.triu_indices(len(P), 1)].min() >= 0.02 * 318e-3 - 1e-12


def test_design_beats_random_poses_and_four_modes_beat_one(four_modes, one_mode):
    """O1 of the exchange design against 200 random draws of the same size from the same
    candidates: the design reaches 0.432, the best draw 0.287 (median 0.253); one mode
    0.260. O3: 0.0075 in four modes, 0.0040 in one. Deterministic inputs; the bounds hold
    with margins of 15 % and more."""
    names, cand = candidates(NOMINAL, MODES, 1, margin=0.2, closure_slack=4e-3,
                             resolution=61, rng=np.random.default_rng(0))
    S = np.array([1.0] * 5 + [0.159] * 2 + [1.0] * 2 + [0.159])
    rng = np.random.default_rng(0)
    best = max(observability(cand.J[rng.choice(len(cand.q), 60, replace=False)],
                             four_modes.parameters, S).o1 for _ in range(200))
    assert four_modes.observability.o1 > 1.3 * best
    assert four_modes.observability.o1 > 1.4 * one_mode.observability.o1
    assert four_modes.observability.o3 > 1.4 * one_mode.observability.o3
    # the reported index is that of the poses returned
    J = jacobian(NOMINAL, closure(NOMINAL, four_modes.readings, 1))
    assert observability(J, four_modes.parameters, S).o1 == pytest.approx(
        four_modes.observability.o1, rel=1e-3)


def test_fifty_poses_in_the_robot_frame_and_other_assembly():
    s = select_poses(NOMINAL, 50, frame="robot", assembly="down", seed=3)
    assert len(s) == 50 and s.parameters == ("l1", "l2", "L1", "L2", "d", "phi_offset",
                                             "psi_offset")
    k = closure(NOMINAL, s.readings, -1)
    np.testing.assert_allclose(k.P, s.points, atol=1e-12)


def test_bad_requests_are_refused():
    with pytest.raises(ParameterError, match="needs at least 20"):
        select_poses(NOMINAL, 12)
    with pytest.raises(ParameterError, match="candidate poses .* fewer than the 30"):
        select_poses(NOMINAL, 30, modes=("-+",), margin=0.3)
    with pytest.raises(ParameterError, match="not one of"):
        select_poses(NOMINAL, 30, modes=("+x",))


# ------------------------------------------------------------- every mode, every pose inside
#: The issue's robot: l = 90, L = 120, d = 70 mm. The determinant alone gave its 40 poses in
#: 3 of the 4 working modes (no "-+": its only 4 candidates lie in a 16 x 8 mm patch at
#: y = 21-29 mm) and 16 of them below the motor axis (down to y = -191 mm).
SMALL = dx.calibration.KinematicModel(dx.FiveBar(90.0, 90.0, 120.0, 120.0, 70.0).scaled(1e-3))


@pytest.mark.slow
def test_every_working_mode_asked_for_gets_its_share():
    """At least max(1, 40 // 16) = 2 poses of each mode (all of a mode's candidates when it
    has fewer): 14 / 13 / 2 / 11 here, O1 0.508 against 0.513 for the determinant alone."""
    s = select_poses(SMALL, 40)
    counts = {m: s.modes.count(m) for m in MODES}
    assert min(counts.values()) >= 2, counts
    assert s.missing_modes == () and "in 4 working modes" in s.message
    assert s.observability.o1 > 0.95 * 0.513


#: O1 of the DexTAR's 60-pose design in four modes: 0.432 (seeds 1-3 of the candidate grid:
#: 0.436, 0.430, 0.432); one mode's 0.260.
DEXTAR_O1 = 0.432


def test_the_share_costs_the_dextar_design_nothing(four_modes, one_mode):
    """Every mode gets at least its share, 60 // 16 = 3 poses, and the design keeps the
    determinant's observability: O1 within 5 % of the measured 0.432 (the four seeds
    measured within 1 %). Which poses the greedy exchange takes is the optimiser's: the
    per-mode counts (20, 18, 3, 19 at seed 0) are not asserted (review 28 finding 15). The
    bound can fail: one mode's design reaches 0.260."""
    counts = {m: four_modes.modes.count(m) for m in MODES}
    assert min(counts.values()) >= 60 // 16 and sum(counts.values()) == 60, counts
    assert four_modes.observability.o1 > 0.95 * DEXTAR_O1
    assert one_mode.observability.o1 < 0.95 * DEXTAR_O1


@pytest.mark.slow
def test_every_pose_inside_the_region_and_the_modes_missing_named():
    # above the motor axis, where a tracker beside the robot sees it: every pose inside and
    # the 4 modes (-+ has its 4 candidates at y = 21-29 mm)
    box = (-0.15, 0.15, 0.0, 0.23)
    s = select_poses(SMALL, 40, region=box)
    x, y = s.points.T
    assert ((x >= box[0]) & (x <= box[1]) & (y >= box[2]) & (y <= box[3])).all()
    assert set(s.modes) == set(MODES) and s.missing_modes == () and s.status in (0, 1)
    assert s.region == box and "in the region x -150 to 150 mm, y 0 to 230 mm" in s.message
    # from y = 40 mm up, -+ has no pose: named, the others chosen
    s = select_poses(SMALL, 40, region=(-0.15, 0.15, 0.04, 0.23))
    assert s.missing_modes == ("-+",) and s.status == 2 and set(s.modes) == {"++", "+-", "--"}
    assert "working mode -+ asked for but without a pose in the region" in s.message
    assert (s.points[:, 1] >= 0.04).all()
    # a mode not asked for is not missing
    s = select_poses(SMALL, 20, region=(-0.15, 0.15, 0.04, 0.23), modes=("++", "+-", "--"))
    assert s.missing_modes == () and s.status in (0, 1)


@pytest.mark.parametrize("region, words", [
    ((0.0, 0.1, 0.2), "must be four numbers"),
    ((0.1, 0.0, 0.0, 0.2), "is empty"),
    ((0.0, 0.1, float("nan"), 0.2), "finite"),
    ((1.0, 2.0, 1.0, 2.0), "lies outside the legs' reach"),
    ((0.0, 0.001, 0.1, 0.101), "fewer than the 40 asked for: lower the margin or the count, "
                               "or widen the region"),
])
def test_bad_regions_are_refused(region, words):
    with pytest.raises(ParameterError, match=words):
        select_poses(SMALL, 40, region=region)
