"""The figures behind an identification's verdict: what the model will predict, what the
residual should be, and whether the time base is plausible.

* :func:`prediction_uncertainty`: the parameter covariance propagated to a reference motion,
  ``sqrt(mean_s Y_b(s) C Y_b(s)^T)`` per motor over the RMS torque the model predicts along
  it. The reference is the task the model is for (``dextar identify --task``) or, without
  one, the recorded motion itself (:func:`recorded_motion`: the rows the fit used), so that
  the verdict then covers motions like the recorded one, whose poses and speeds
  :func:`describe_motion` names (a motion elsewhere extrapolates: ``--task`` measures the
  uncertainty along it, ``--validate`` names the samples outside).
* :func:`torque_noise`: the standard deviation of the measured torques' noise after the
  parallel filter, from the torques' spectrum floor (the median density over the top 40 %
  of the band, where no motion is) through the filter's noise gain: the residual a perfect
  model would leave.
* :func:`check_time_base`: a sample rate below :data:`MIN_RATE_HZ` with joint speeds below
  :data:`SLOW_SPEED` (rad/s) is a time column in another unit (milliseconds or microseconds
  read as seconds), refused naming the unit, of :data:`TIME_UNITS`, that brings the rate to
  a drive's (:data:`DRIVE_RATES_HZ`, 100 Hz to 10 kHz) and the rate and speeds it gives, or
  every reading when none does. A time column of 10 ms steps at 1 kHz (``t * 100``) reads as
  milliseconds at 10 kHz: neither its rate nor its speeds tell it from a 10 kHz log, so
  milliseconds are named with those figures, for the user to judge.

The thresholds that turn these figures into a verdict are in :mod:`dextar.identification.fit`
with the cases that justify them.
"""

from __future__ import annotations

import math

import numpy as np

from .._arrays import Array
from ..dynamics.exact import Model
from ..dynamics.regressor import regressor
from ..errors import ParameterError
from .base import BaseParameters
from .data import MotionData
from .filtering import Conditioned, filtered_noise, noise_floor

#: Below this sample rate (Hz) with joints slower than :data:`SLOW_SPEED` the time column is
#: questioned (drives log at 100 Hz to 10 kHz).
MIN_RATE_HZ = 20.0
#: The sample rates (Hz) drives log at: the unit named for a time column not in seconds
#: brings the rate among them.
DRIVE_RATES_HZ = (100.0, 10000.0)
#: The units a time column not in seconds may be in: (seconds per unit, name).
TIME_UNITS = ((1e3, "milliseconds"), (1e6, "microseconds"), (1e9, "nanoseconds"))
#: Peak joint speed (rad/s, 2.9 deg/s) below which data sampled under :data:`MIN_RATE_HZ`
#: are taken for a time column in milliseconds. The excitations measured move at 0.9-2.8
#: rad/s (18x above it); the same data with the time in milliseconds at 0.0009-0.0028 (18x
#: below).
SLOW_SPEED = 0.05


def recorded_motion(c: Conditioned) -> tuple[Array, Array, Array]:
    """The recorded motion as the fit saw it: ``(q, dq, ddq)`` (each (n, 2), SI) of the
    conditioned rows either motor's fit used."""
    keep = c.used.any(axis=1)
    return np.asarray(c.q[keep]), np.asarray(c.dq[keep]), np.asarray(c.ddq[keep])


def describe_motion(q: Array, dq: Array) -> str:
    """A motion's poses and speeds in words: each motor's range (deg) and peak speed."""
    lo, hi = np.degrees(q.min(axis=0)), np.degrees(q.max(axis=0))
    v = np.abs(dq).max(axis=0)
    return (f"motor A {lo[0]:.4g} to {hi[0]:.4g} deg, D {lo[1]:.4g} to {hi[1]:.4g} deg, up "
            f"to {v[0]:.3g} / {v[1]:.3g} rad/s")


def prediction_uncertainty(model: Model, base: BaseParameters, beta: Array, cov: Array,
                           q: Array, dq: Array, ddq: Array) -> tuple[Array, Array]:
    """Per motor, the RMS standard deviation of the torques predicted along ``q, dq, ddq``
    (each (n, 2), SI) by the base parameters ``beta`` of covariance ``cov`` (N m), and the
    RMS of those torques (N m): ``(std (2,), rms (2,))``."""
    Yb = base.columns(regressor(model, q, dq, ddq))  # (n, 2, p)
    var = np.einsum("nkp,pq,nkq->nk", Yb, cov, Yb)
    std = np.sqrt(np.clip(var, 0.0, None).mean(axis=0))
    rms = np.sqrt(((Yb @ beta) ** 2).mean(axis=0))
    return np.asarray(std), np.asarray(rms)


def torque_noise(data: MotionData, parallel_hz: float) -> Array:
    """Standard deviation (N m) of each motor's torque noise after the parallel filter at
    ``parallel_hz`` (white noise of the torques' spectrum floor), shape (2,)."""
    fs = data.rate_hz
    floor = noise_floor(data.tau, fs)[2]
    return np.asarray(filtered_noise(floor, parallel_hz, fs, derivative=False))


def peak_speed(data: MotionData) -> Array:
    """Each motor's 99th-percentile speed (rad/s) from the angles' differences over the time
    column's (the time base in question; measured rates are not used), shape (2,)."""
    v = np.abs(np.diff(data.q, axis=0)) / np.diff(data.t)[:, None]
    return np.asarray(np.percentile(v, 99.0, axis=0))


def time_unit(rate_hz: float) -> tuple[float, str] | None:
    """The power of 1000 (and its unit's name) that brings a sample rate read in seconds
    into a drive's :data:`DRIVE_RATES_HZ`: ``(1000, "milliseconds")`` for data at 1 Hz;
    None when none does."""
    lo, hi = DRIVE_RATES_HZ
    for factor, unit in TIME_UNITS:
        if lo <= float(f"{rate_hz * factor:.6g}") <= hi:
            return factor, unit
    return None


def check_time_base(data: MotionData) -> None:
    """Raise :class:`ParameterError` when the sample rate and the joint speeds together say
    the time column is not in seconds (see the module doc), naming the unit (of
    :data:`TIME_UNITS`) that brings the rate to a drive's, or every reading when none does."""
    rate = data.rate_hz
    v = peak_speed(data)
    if not (rate < MIN_RATE_HZ and float(v.max()) < SLOW_SPEED):
        return
    said = (f"{data.source}: t_s advances {1.0 / rate:.6g} s per sample (a sample rate of "
            f"{rate:.4g} Hz) while the joints move at most {v[0]:.3g} / {v[1]:.3g} rad/s "
            f"({math.degrees(v[0]):.3g} / {math.degrees(v[1]):.3g} deg/s, motor A / D): no "
            f"drive logs this slowly (below {MIN_RATE_HZ:g} Hz with joints below "
            f"{SLOW_SPEED:g} rad/s; drives log at {DRIVE_RATES_HZ[0]:g} Hz to "
            f"{DRIVE_RATES_HZ[1]:g} Hz). ")
    unit = time_unit(rate)
    if unit is not None:
        f, name = unit
        raise ParameterError(
            said + f"Is the time in {name}? Read as {name}, the data run at "
            f"{f * rate:.6g} Hz and {f * v.max():.3g} rad/s; if so, divide t_s by {f:.0f}")
    readings = "; ".join(f"as {name}, {f * rate:.6g} Hz and {f * v.max():.3g} rad/s"
                         for f, name in TIME_UNITS)
    raise ParameterError(said + f"No power of 1000 brings it to a drive's rate ({readings}): "
                         "give t_s in seconds")
