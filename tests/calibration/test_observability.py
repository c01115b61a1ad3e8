"""Identifiability is computed: exact dependencies are found and named, data in the robot
frame identify the robot's seven parameters, a single pose identifies almost nothing."""

import numpy as np

from dextar.calibration import NAMES, identifiability
from dextar.calibration.model import closure, jacobian
from dextar.calibration.observability import correlation, multiple_correlation

from .conftest import NOMINAL


def test_a_column_that_is_a_combination_of_earlier_ones_is_named(four_modes):
    J = jacobian(NOMINAL, closure(NOMINAL, four_modes.readings, 1))
    full = identifiability(J, NAMES)
    assert full.identifiable == NAMES and full.not_identifiable == ()
    J2 = J.copy()
    J2[:, :, 9] = -2.0 * J[:, :, 5] + 0.5 * J[:, :, 7]    # theta0 = -2 phi_offset + 0.5 x0
    ident = identifiability(J2, NAMES)
    assert ident.not_identifiable == ("theta0",)
    assert ident.combinations["theta0"] == "theta0 = -2 phi_offset + 0.5 x0"


def test_one_pose_repeated_identifies_two_parameters(four_modes):
    r = np.repeat(four_modes.readings[:1], 30, axis=0)
    J = jacobian(NOMINAL, closure(NOMINAL, r, 1))
    ident = identifiability(J, NAMES)
    assert len(ident.identifiable) == 2     # a point moves in two directions
    assert len(ident.not_identifiable) == 8


def test_robot_frame_and_multiple_correlation(four_modes):
    J = jacobian(NOMINAL, closure(NOMINAL, four_modes.readings, 1))
    ident = identifiability(J, NAMES[:7])
    assert ident.identifiable == NAMES[:7]
    cov = np.linalg.inv(np.einsum("nki,nkj->ij", J, J))
    corr = correlation(cov)
    assert np.allclose(np.diag(corr), 1.0) and np.abs(corr).max() <= 1.0
    # a parameter exactly a combination of two others has multiple correlation 1, pairwise
    # correlations of 1/sqrt(2) only
    c = np.array([[1.0, 0.0, 0.7071], [0.0, 1.0, 0.7071], [0.7071, 0.7071, 1.0]])
    assert multiple_correlation(c)[2] > 0.9999
