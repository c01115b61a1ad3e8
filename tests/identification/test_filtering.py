"""The conditioning's filters follow the data (sample rate, encoder noise), the speed noise it
predicts is the one it has, the rows near reversals are left out, the region check tells a
motion outside the identification's, and the data file is read fast with the same errors."""

import csv
import math

import numpy as np
import pytest

from dextar.errors import ConfigError, ParameterError
from dextar.identification.coverage import JointRegion, coverage
from dextar.identification.data import MotionData, read_motion_csv
from dextar.identification.filtering import (
    CREEP_FRACTION,
    PARALLEL_RATIO,
    SIGN_SIGMAS,
    choose_filters,
    condition,
)
from dextar.identification.fit import identify, validate

from .conftest import synthetic
from .excitations import EXCITATIONS


def _angles(tr, rate, seconds=10.0, bits=None):
    t = np.arange(int(round(seconds * rate)) + 1) / rate
    q, dq, _ = tr.evaluate(t)
    if bits:
        c = 2 * np.pi / 2**bits
        q = np.round(q / c) * c
    return t, q, dq


def test_the_state_filter_follows_the_encoder_and_the_sample_rate(excitation):
    """Exact angles: fs / 10. The spectrum of a 17-bit encoder's angles meets its noise floor
    at 25-31 Hz (measured on 20 MuJoCo runs and the stored excitations): f_s = 3 f_n = 75-94
    Hz; 14 bits (8x the noise): f_n 14-15 Hz, f_s 41-44 Hz here. The parallel filter at
    f_s / 2.5."""
    t, q, _ = _angles(excitation, 1000.0)
    f = choose_filters(t, q)
    assert f.state_hz == pytest.approx(100.0) and f.parallel_hz == pytest.approx(40.0)
    t, q, _ = _angles(excitation, 500.0)
    assert choose_filters(t, q).state_hz == pytest.approx(50.0)
    t, q17, _ = _angles(excitation, 1000.0, bits=17)
    t, q14, _ = _angles(excitation, 1000.0, bits=14)
    f17, f14 = choose_filters(t, q17), choose_filters(t, q14)
    assert 15 < f17.noise_hz < 40 and 45 < f17.state_hz <= 100, f17
    assert 20 < f14.state_hz < 0.8 * f17.state_hz, (f14, f17)
    for f in (f17, f14):
        assert f.parallel_hz == pytest.approx(f.state_hz / PARALLEL_RATIO)
    # given cut-offs are kept
    g = choose_filters(t, q14, state_hz=30.0)
    assert g.state_hz == 30.0 and g.parallel_hz == pytest.approx(12.0)
    assert choose_filters(t, q14, state_hz=30.0, parallel_hz=5.0).parallel_hz == 5.0


def test_the_speed_noise_predicted_is_the_one_the_filtered_speed_has(prior, excitation):
    """14-bit angles: the filtered speed's error against the true speed has the standard
    deviation the conditioning predicts from the angles' noise floor (ratio 1.00-1.20
    measured on both motors of the three stored excitations; bounds 0.7-1.4); the rows are
    left out below 3 of them."""
    model = prior[0]
    t, q, dq = _angles(excitation, 1000.0, bits=14)
    d = MotionData(t, q, np.zeros_like(q))
    c = condition(d, model)
    err = c.dq - dq[c.rows]
    # away from the reversals, where the smear of the filter adds to the noise
    calm = np.abs(dq[c.rows]) > 0.2
    ratio = np.array([err[calm[:, k], k].std() for k in range(2)]) / c.speed_noise
    assert ((ratio > 0.7) & (ratio < 1.4)).all(), ratio
    rms = np.sqrt((dq ** 2).mean(axis=0))
    assert np.allclose(c.min_speed, np.maximum(SIGN_SIGMAS * c.speed_noise,
                                               CREEP_FRACTION * rms), rtol=0.05)


def test_rows_near_reversals_are_left_out_on_the_parallel_filters_support(prior, excitation):
    """A decimated row is used only when no sample within 2 / f_p of it changes sign or is
    slower than the speed floor; every reversal of the motion is covered (to within the few
    samples by which the filtered speed's reversal may move)."""
    model = prior[0]
    t, q, dq = _angles(excitation, 1000.0)
    c = condition(MotionData(t, q, np.zeros_like(q)), model)
    guard = math.ceil(2.0 * 1000.0 / c.parallel_hz)
    for k in range(2):
        rev = np.flatnonzero(np.sign(dq[1:, k]) != np.sign(dq[:-1, k]))
        assert len(rev) >= 4
        dist = np.abs(c.rows[:, None] - rev[None, :]).min(axis=1)
        assert not c.told[dist <= guard - 5, k].any()
        far = (dist > guard + 50) & (np.abs(c.dq[:, k]) > 0.1)
        assert c.told[far, k].all()


def test_validation_predicts_our_own_model_and_reports_the_region(prior, excitation, base):
    model, mode, _ = prior
    res = identify(synthetic(model, excitation, 10.0, seed=21), model, mode=mode, base=base)
    # the same motion again (another noise draw): inside the region, predicted to the noise
    v = validate(res, synthetic(model, excitation, 10.0, seed=22), model, mode=mode)
    assert v.coverage.fraction == 1.0 and v.warnings == []
    assert (v.error < 0.05).all() and (v.error_prior < 0.05).all()
    assert (v.rows_used > 0.5 * len(v.conditioned.t)).all()
    # another stored excitation, twice as fast: faster than the identification moved
    tr = EXCITATIONS[1]
    fast = type(tr)(tr.q0, 2 * tr.a, 2 * tr.b, 2 * tr.base_hz)
    v2 = validate(res, synthetic(model, fast, 2.5, seed=23), model, mode=mode)
    assert v2.coverage.fast.any() and v2.coverage.fraction < 0.9
    msg = v2.warnings[0]
    assert "lie outside the region the identification excited" in msg and "faster" in msg
    assert "rows " in msg and "t = " in msg


def test_the_region_of_poses_and_speeds(excitation):
    t, q, dq = _angles(excitation, 100.0)
    region = JointRegion.from_samples(q, dq)
    near, slow = region.contains(q, dq)
    assert near.all() and slow.all()
    far = q + np.radians(30.0)
    near, _ = region.contains(far, dq)
    assert not near.all()
    _, slow = region.contains(q, 1.2 * dq)
    assert not slow.all()
    assert (region.distance(q) <= 0.25 * region.radius).all()


def test_coverage_names_the_rows_outside(prior, excitation):
    model = prior[0]
    d = synthetic(model, excitation, 10.0, seed=24)
    c = condition(d, model)
    half = JointRegion.from_samples(c.q[: len(c.q) // 4], c.dq[: len(c.q) // 4])
    cov = coverage(half, c)
    assert 0 < cov.fraction < 1
    assert (cov.rows == c.rows[~cov.inside] + 2).all()
    assert cov.message("v.csv").startswith("v.csv: ")


# ------------------------------------------------------------------ reading the data file
COLS = ["t_s", "phi_rad", "psi_rad", "dphi_rad_s", "tau1_Nm", "tau2_Nm", "dpsi_rad_s"]


def _write(path, rows, head=COLS, newline="\n"):
    with open(path, "w", newline="") as fh:
        csv.writer(fh, lineterminator=newline).writerows([head, *rows])
    return path


def _rows(n=50):
    t = np.arange(n) / 1000.0
    return [[repr(float(v)) for v in (ti, 1.0 + ti, 2.0 - ti, 1.0, 0.1, -0.1, -1.0)]
            for ti in t]


def test_plain_and_quoted_files_read_alike(tmp_path):
    rows = _rows()
    a = read_motion_csv(_write(tmp_path / "a.csv", rows))
    b = read_motion_csv(_write(tmp_path / "b.csv", rows, newline="\r\n"))
    with open(tmp_path / "c.csv", "w", newline="") as fh:  # every field quoted: the slow path
        csv.writer(fh, quoting=csv.QUOTE_ALL).writerows([COLS, *rows])
    c = read_motion_csv(tmp_path / "c.csv")
    for x in (b, c):
        for name in ("t", "q", "tau", "dq"):
            assert np.array_equal(getattr(a, name), getattr(x, name))
    assert a.ddq is None and a.dq is not None
    assert np.array_equal(a.q[:, 0], [float(r[1]) for r in rows])
    assert np.array_equal(a.dq[:, 1], [float(r[6]) for r in rows])


@pytest.mark.parametrize("edit, error, message", [
    (lambda r: r[:10] + [[]] + r[10:], ParameterError, "row 12 has 0 fields, the header 7"),
    (lambda r: r[:10] + [r[10][:6]] + r[11:], ParameterError, "row 12 has 6 fields"),
    (lambda r: r[:10] + [r[10] + ["9"]] + r[11:], ParameterError, "row 12 has 8 fields"),
    (lambda r: r[:7] + [[*r[7][:4], "x", *r[7][5:]]] + r[8:], ParameterError,
     "row 9, column tau1_Nm: 'x' is not a number"),
    (lambda r: r[:7] + [[*r[7][:2], "", *r[7][3:]]] + r[8:], ParameterError,
     "row 9, column psi_rad: '' is not a number"),
    (lambda r: r + [[]], ParameterError, "row 52 has 0 fields"),
])
def test_bad_rows_are_named(tmp_path, edit, error, message):
    path = _write(tmp_path / "bad.csv", edit(_rows()))
    with pytest.raises(error, match=message):
        read_motion_csv(path)


def test_bad_files_are_named(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    with pytest.raises(ConfigError, match="is empty"):
        read_motion_csv(empty)
    binary = tmp_path / "bin.csv"
    binary.write_bytes(b"\xff\xfe\x00t_s")
    with pytest.raises(ConfigError, match="is not a text"):
        read_motion_csv(binary)
    with pytest.raises(ConfigError, match="lacks the column tau2_Nm"):
        read_motion_csv(_write(tmp_path / "m.csv", [r[:5] for r in _rows()], head=COLS[:5]))
    head_only = _write(tmp_path / "h.csv", [])
    with pytest.raises(ParameterError, match="0 samples"):
        read_motion_csv(head_only)
