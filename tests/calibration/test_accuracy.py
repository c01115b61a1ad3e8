"""The predicted position uncertainty against Monte Carlo on the full nonlinear model."""

import math

import numpy as np
import pytest

import dextar.calibration as cal
from dextar.calibration.accuracy import accuracy_map, position_covariance
from dextar.calibration.model import ROBOT, KinematicModel
from dextar.errors import ParameterError
from dextar.kinematics import assembly_mode, singularity_distances

from .conftest import COUNT, NOMINAL


@pytest.mark.slow
def test_linearised_covariance_matches_monte_carlo():
    """1500 parameter sets drawn from a covariance (0.01 mm, 0.005 deg, correlated), each
    commanded to the same targets by the readings of the mean model: the sample covariance
    of the positions against the prediction. A standard deviation estimated from 1500
    samples is within 1.8 % (1 sigma) of the truth; bound 8 % (4.4 sigma). Then the
    encoders alone: readings off uniformly by up to half a count."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(7, 7))
    scale = np.array([1e-5] * 5 + [math.radians(0.005)] * 2)
    cov = (A @ A.T / 7 + np.eye(7)) * np.outer(scale, scale) / 2
    targets = np.array([[0.0, 0.12], [-0.05, 0.09], [0.04, 0.13]])
    r = NOMINAL.readings(targets, "+-")
    S, Sp = position_covariance(NOMINAL, targets, "+-", 1, ROBOT, cov, None)
    np.testing.assert_allclose(S, Sp)
    draws = rng.multivariate_normal(np.zeros(7), cov, size=1500)
    P = np.empty((1500, 3, 2))
    for k, dp in enumerate(draws):
        p = NOMINAL.vector()
        p[:7] += dp
        P[k] = KinematicModel.from_vector(p).predict(r, 1)
    for j in range(3):
        emp = np.cov((P[:, j] - targets[j]).T)
        lam_e, lam_p = np.linalg.eigvalsh(emp), np.linalg.eigvalsh(S[j])
        np.testing.assert_allclose(np.sqrt(lam_e), np.sqrt(lam_p), rtol=0.08)
    # encoder resolution: uniform rounding errors of std count / sqrt(12)
    s_r = COUNT / math.sqrt(12)
    S2, Sp2 = position_covariance(NOMINAL, targets, "+-", 1, ROBOT, 0 * cov, s_r)
    assert np.abs(Sp2).max() == 0.0
    dq = rng.uniform(-0.5 * COUNT, 0.5 * COUNT, size=(1500, 1, 2))
    Pq = NOMINAL.predict((r[None] + dq).reshape(-1, 2), 1).reshape(1500, 3, 2)
    for j in range(3):
        emp = np.cov((Pq[:, j] - targets[j]).T)
        np.testing.assert_allclose(np.sqrt(np.linalg.eigvalsh(emp)),
                                   np.sqrt(np.linalg.eigvalsh(S2[j])), rtol=0.08)


def test_the_map_of_a_calibration(four_modes):
    rng = np.random.default_rng(4)
    true = cal.perturbed(NOMINAL, rng)
    data = cal.measure(true, four_modes.readings, 1, rng, point_std=0.02e-3, count=COUNT)
    res = cal.calibrate(data, NOMINAL)
    names, cov = res.robot_covariance()
    assert names == ROBOT and cov.shape == (7, 7)
    m = accuracy_map(res.calibrated, res.identifiable, res.covariance, "+-", resolution=81,
                     reading_std=cal.encoder_std(2**17))
    assert m.std.shape == m.valid.shape == (len(m.y), len(m.x)) and m.valid.any()
    assert (m.std[~m.valid] == 0).all() and (m.std[m.valid] > 0).all()
    assert (m.std >= m.from_parameters).all()
    # a few micrometres in the middle, more near the singularities (measured: median
    # 3.9 um, worst 68 um at 0.02 mm noise)
    assert 1e-6 < m.median < 10e-6 < m.worst
    # the map's points are those of the working mode and assembly, away from singularities
    X, Y = np.meshgrid(m.x, m.y)
    pts = np.stack([X[m.valid], Y[m.valid]], axis=-1)
    q = res.calibrated.readings(pts, "+-") + res.calibrated.offsets
    t1, t2 = singularity_distances(res.calibrated.robot, q, pts)
    assert t1.min() >= 0.05 and t2.min() >= 0.05
    assert (assembly_mode(res.calibrated.robot, q, pts) == 1).all()
    with pytest.raises(ParameterError, match="covariance of shape"):
        accuracy_map(res.calibrated, ("l1",), cov, "+-")
