import re

import numpy as np
import pytest

import dextar as dx
from dextar.laws import MinimumJerkLaw, UniformLaw, solve_optimal_law
from dextar.paths import Arc, Line, Spline
from dextar.trajectory import sample_trajectory

ROBOT = dx.DEXTAR_MM.scaled(1 / 87)  # paper units: L = 1
SEMI = Arc(120 / 87, 0.0, np.pi)


@pytest.fixture(scope="session")
def paper():
    return sample_trajectory(ROBOT, SEMI, solve_optimal_law(SEMI, eta=0.1), samples=4001)


def test_joint_rates_against_finite_differences(paper):
    h = paper.t[1] - paper.t[0]
    fd1 = (paper.q[2:] - paper.q[:-2]) / (2 * h)
    fd2 = (paper.q[2:] - 2 * paper.q[1:-1] + paper.q[:-2]) / h**2
    assert np.abs(fd1 - paper.dq[1:-1]).max() < 1e-5 * np.abs(paper.dq).max()
    assert np.abs(fd2 - paper.ddq[1:-1]).max() < 1e-4 * np.abs(paper.ddq).max()
    # task-space quantities as well
    fdP = (paper.P[2:] - paper.P[:-2]) / (2 * h)
    assert np.abs(fdP - paper.dP[1:-1]).max() < 1e-5 * np.abs(paper.dP).max()


def test_paper_motion_shape(paper):
    assert paper.mode == "+-" and paper.assembly == "up"
    np.testing.assert_allclose(paper.P[0], [120 / 87, 0.0], atol=1e-12)
    np.testing.assert_allclose(paper.P[-1], [-120 / 87, 0.0], atol=1e-9)
    mid = len(paper.t) // 2
    np.testing.assert_allclose(np.degrees(paper.q[mid]), [60.5118, 119.4882], atol=1e-4)
    # rest to rest
    assert np.abs(paper.dq[[0, -1]]).max() < 1e-8
    # symmetry of the robot and the law: phi(t) + psi(T - t) = pi
    np.testing.assert_allclose(paper.q[:, 0] + paper.q[::-1, 1], np.pi, atol=1e-9)


def test_forward_kinematics_reproduces_path(paper):
    P = dx.direct_kinematics(ROBOT, paper.q, paper.assembly)
    np.testing.assert_allclose(P, paper.P, atol=1e-12)


def test_leaves_workspace_names_time_and_point():
    big = Arc(170 / 87, 0.0, np.pi)
    with pytest.raises(dx.ReachError, match=r"leaves the workspace at t = [\d.]+ \(sample \d+\): point \("):
        sample_trajectory(ROBOT, big, UniformLaw(big.length, 1.0))


def test_singularity_names_time_and_point():
    # a straight line through the type-2 curve of mode "+-" (near the base, y ~ 0.5 L)
    line = Line((0.0, 1.4), (0.0, 0.3))
    with pytest.raises(dx.SingularityError, match=r"at t = [\d.]+ \(sample \d+\): the motion meets a parallel \(type 2\)"):
        sample_trajectory(ROBOT, line, MinimumJerkLaw(line.length, 1.0))


def test_mismatched_law_refused():
    with pytest.raises(dx.ParameterError, match="distance"):
        sample_trajectory(ROBOT, SEMI, UniformLaw(1.0, 1.0))


def test_spline_path_trajectory():
    sp = Spline(((0.6, 1.0), (0.2, 1.3), (-0.3, 1.1), (-0.6, 1.4)))
    tr = sample_trajectory(ROBOT, sp, MinimumJerkLaw(sp.length, 2.0), samples=801)
    h = tr.t[1] - tr.t[0]
    fd = (tr.q[2:] - tr.q[:-2]) / (2 * h)
    assert np.abs(fd - tr.dq[1:-1]).max() < 1e-4 * np.abs(tr.dq).max()


def test_a_path_across_the_parallel_singularity_curve_passes_only_where_planned():
    """The geometry checker refuses a crossing of the parallel singularity curve unless it is
    one of the path's crossings the caller plans (find_crossings), and only there."""
    from dextar.errors import SingularityError
    from dextar.trajectory import check_path, find_crossings

    from .crossing_cases import CASES

    case = CASES["dextar"]
    with pytest.raises(SingularityError, match="parallel"):
        check_path(case.robot, case.path, mode="+-")
    crossings = find_crossings(case.robot, case.path, mode="+-")
    checked = check_path(case.robot, case.path, mode="+-", crossings=crossings)
    assert checked.distances.type2.min() < 1e-3  # it passed the singularity itself
    # a crossing excused elsewhere on the path does not excuse this one
    from dataclasses import replace
    moved = replace(crossings[0], s=crossings[0].s * 0.5)
    with pytest.raises(SingularityError, match="parallel"):
        check_path(case.robot, case.path, mode="+-", crossings=(moved,))


def test_a_paths_dynamics_names_the_place_by_its_arc_length():
    """The path's dynamics sample it with a unit-speed law, whose times are arc lengths: an
    error there said "at t = 0.0972 (sample 216)" for a place 97.2 mm along the path (a new
    user's trial); it names the arc length (in mm with SI words)."""
    from dextar.dynamics import RobotAlongPath, paper_inertia
    from dextar.dynamics.exact import Model
    from dextar.geometry import DEXTAR_MM
    from dextar.units import SI

    robot = DEXTAR_MM.scaled(1e-3)
    line = Line((0.0, 0.12), (0.0, 0.20))  # out of the DexTAR's reach at y = 0.1563 m
    model = Model(robot, paper_inertia(robot))
    for units, words in ((SI, r"at (3[\d.]+) mm along the path \(from the start of the "
                               r"motion\): point \(0, 156\.\d+\) mm"),
                         (None, r"at s = (0\.03[\d]+) along the path: point \(0, 0\.156")):
        with pytest.raises(dx.ReachError, match=words) as err:
            RobotAlongPath(model, line, "+-", units).coefficients(np.linspace(0, 0.08, 801))
        assert "t =" not in str(err.value)
        # the first sample out of reach: 36.3 mm along (y = 0.1563 m), the samples 0.1 mm
        # apart
        at = float(re.search(words, str(err.value)).group(1))
        assert at * (1e-3 if units is SI else 1.0) == pytest.approx(0.0363, abs=2e-4)
