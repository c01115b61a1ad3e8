"""The calibration model against the kinematics it builds on and against finite
differences."""

import math

import numpy as np
import pytest

import dextar as dx
from dextar.calibration import NAMES, KinematicModel
from dextar.calibration.model import closure, jacobian, wrap

from .conftest import NOMINAL

MODEL = KinematicModel(dx.FiveBar(0.0712, 0.0725, 0.0868, 0.0879, 0.0607), 0.013, -0.021,
                       0.31, -0.12, 2.4)


def _poses(model, n, assembly, seed=0):
    """Readings of random poses the model assembles, away from both singularities."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        q = rng.uniform(-np.pi, np.pi, (200, 2))
        k = closure(model.with_frame(0, 0, 0), q - model.offsets, assembly)
        t1, t2 = dx.singularity_distances(model.robot, k.q, k.P)
        ok = ~k.open & (t1 > 0.1) & (t2 > 0.1)
        out.extend(q[ok] - model.offsets)
    return np.array(out[:n])


@pytest.mark.parametrize("assembly", [1, -1])
def test_prediction_is_direct_kinematics_in_the_instrument_frame(assembly):
    r = _poses(MODEL, 50, assembly)
    P = dx.direct_kinematics(MODEL.robot, r + MODEL.offsets, assembly)
    c, s = math.cos(MODEL.theta0), math.sin(MODEL.theta0)
    M = np.stack([c * P[:, 0] - s * P[:, 1] + MODEL.x0, s * P[:, 0] + c * P[:, 1] + MODEL.y0],
                 axis=-1)
    np.testing.assert_allclose(MODEL.predict(r, assembly), M, atol=1e-15)
    np.testing.assert_allclose(MODEL.to_robot(M), P, atol=1e-15)


@pytest.mark.parametrize("assembly", [1, -1])
def test_analytic_jacobian_matches_central_differences(assembly):
    r = _poses(MODEL, 40, assembly, seed=1)
    J = jacobian(MODEL, closure(MODEL, r, assembly))
    p0 = MODEL.vector()
    for j, name in enumerate(NAMES):
        h = 1e-6 if name not in ("phi_offset", "psi_offset", "theta0") else 1e-6 / 0.16
        up, dn = p0.copy(), p0.copy()
        up[j] += h
        dn[j] -= h
        fd = (KinematicModel.from_vector(up).predict(r, assembly)
              - KinematicModel.from_vector(dn).predict(r, assembly)) / (2 * h)
        # central differences are exact to O(h^2 |P'''|): measured up to 2e-7 relative near
        # the 0.1 margin; a wrong term would be off by O(1)
        np.testing.assert_allclose(J[:, :, j], fd, rtol=2e-6, atol=1e-8, err_msg=name)


def test_readings_invert_the_prediction_in_every_working_mode():
    rng = np.random.default_rng(2)
    for mode in ("++", "+-", "-+", "--"):
        P = rng.uniform([-0.08, 0.06], [0.08, 0.13], (30, 2))
        try:
            r = MODEL.readings(P, mode)
        except dx.ReachError:
            continue
        sign = dx.assembly_mode(MODEL.robot, r + MODEL.offsets, P)
        for a in (1, -1):
            sel = sign == a
            if sel.any():
                np.testing.assert_allclose(MODEL.to_robot(MODEL.predict(r[sel], a)), P[sel],
                                           atol=1e-12)
        M = MODEL.to_instrument(P)
        np.testing.assert_allclose(MODEL.readings_for_measured(M, mode), r, atol=1e-12)


def test_config_units_and_vector_round_trip():
    m = KinematicModel.from_config_units(dx.DEXTAR_MM, encoder_offset_deg=(0.25, -0.5),
                                         instrument=(100.0, -20.0, 30.0))
    assert m.in_file_units() == {"l1": 72.0, "l2": 72.0, "L1": 87.0, "L2": 87.0, "d": 60.0,
                                 "phi_offset": 0.25, "psi_offset": -0.5, "x0": 100.0,
                                 "y0": -20.0, "theta0": 30.0}
    assert KinematicModel.from_vector(m.vector()) == m
    assert NOMINAL.readings([0.0, 0.12], "+-") == pytest.approx(
        dx.inverse_kinematics(dx.DEXTAR_MM.scaled(1e-3), [0.0, 0.12], "+-"))
    np.testing.assert_allclose(wrap(np.array([3 * np.pi, -np.pi, 0.5])), [np.pi, np.pi, 0.5])


def test_readings_the_rods_cannot_close_are_named():
    with pytest.raises(dx.AssemblyError, match="index 1: the distal rods cannot meet"):
        NOMINAL.predict(np.radians([[60.0, 120.0], [0.0, 180.0]]), 1)
    with pytest.raises(dx.ParameterError, match="theta0"):
        KinematicModel(NOMINAL.robot, theta0=float("nan"))
