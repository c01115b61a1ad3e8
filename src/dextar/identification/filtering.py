"""Conditioning measured motion for the fit: two filters chosen from the data, and the rows
whose friction sign the data can tell.

Steps of :func:`condition`:

1. **State filter**: the angles go through a zero-phase 4th-order Butterworth low-pass
   (``scipy.signal.sosfiltfilt``) at ``f_s`` (:attr:`Filters.state_hz`), then central
   differences give the rates and accelerations (measured rates and accelerations, when
   given, are filtered the same way instead). The regressor is built from these states at
   every sample.
2. **Parallel filter** (Gautier): the regressor's columns and the measured torques go through
   the same low-pass at ``f_p`` (:attr:`Filters.parallel_hz`), so ``Y theta = tau`` still
   holds after it for every part of the model (friction steps included); both are then
   decimated to ``2.5 f_p`` so that the residuals are close to white, and the ends (the
   filter's settling, :data:`GUARD_PERIODS` ``/ f_p`` each) are dropped.
3. **Rows whose friction sign is told**: a motor's raw sample is *uncertain* where the
   filtered speed is below :data:`SIGN_SIGMAS` times its noise (the encoder noise through
   the state filter and the derivative), below :data:`CREEP_FRACTION` of the motor's RMS
   speed (the creep and stick of dry friction near rest, which no Coulomb model predicts), or
   changes sign. A decimated row of that motor is left out of the fit when an uncertain
   sample lies within the parallel filter's support, :data:`GUARD_PERIODS` ``/ f_p`` on
   either side (99.7 % of its impulse response's mass): the stick and the breakaway at a
   reversal would otherwise leak into it.

How the filters are chosen, from the sample rate ``fs`` and the measured motion:

* ``f_s = min(fs / 10, max(3 f_n, f_m))``. ``f_n`` is the highest frequency at which the
  angles' spectrum (Welch, trend removed) is still :data:`NOISE_MARGIN` times above its noise
  floor (the median of the top 40 % of the band); ``f_m = max(5 f_b, 10 / T)`` with ``f_b``
  holding 99.9 % of the angles' energy and ``T`` the duration (the planned motion's band,
  the former default). The measured motion has more than the planned one: at each velocity
  reversal dry friction holds the joint, then it breaks away with accelerations several
  times the planned peak, so ``f_s`` must pass far more than ``f_b``; it stops where the
  spectrum meets the encoder's noise (a 17-bit encoder at 1 kHz: ``f_n`` 25-31 Hz, ``f_s``
  76-94 Hz; a 14-bit one: 32-56 Hz) or at ``fs / 10`` (exact angles, 20-bit and finer).
* ``f_p = f_s / 2.5``: the state filter is flat (within 7e-4) over the parallel filter's
  pass band, so the linear columns (accelerations, gravity) see only the parallel filter,
  while the states that enter non-linearly (the friction sign, the speeds squared) keep the
  state filter's bandwidth.

Measured (``tests/identification/mujoco_harness.py``: MuJoCo's robot under a 100 Hz PD loop,
exact torques, 20 excitation seeds of the pick-and-place robot from the former design, 10 s
at 1 kHz each): the worst prediction error over the seeds on the paper's semicircle and on
the pick-and-place program, motor A / motor D in % of the RMS torque, the validation data
conditioned alike for every row (100 / 40 Hz, the rows whose sign is told); angles exact, or
quantised to 17 or 14 bits:

========================================  ===============  ===============  ===============
identification's filters                  exact            17-bit           14-bit
(semicircle; program)
========================================  ===============  ===============  ===============
the former default (one filter at 5 Hz,    0.25 / 0.29;     0.37 / 0.20;     0.64 / 1.1;
rows below 5 % of the peak speed out)      0.32 / 0.32      0.41 / 0.33      1.3 / 1.2
one filter at 5 Hz, no rows left out       4.8 / 7.2;       8.0 / 8.0;       9.8 / 9.2;
                                           4.1 / 2.8        7.1 / 3.0        8.5 / 3.9
one filter at 100 Hz                       3.8 / 9.0;       3.4 / 7.6;       13 / 21;
                                           3.3 / 3.5        3.4 / 3.5        14 / 9.3
100 / 40 Hz, only sign changes out         3.8 / 8.7;       0.61 / 0.69;     1.5 / 4.1;
                                           3.3 / 3.3        0.55 / 0.55      2.6 / 2.7
100 / 40 Hz, guard, no creep floor         0.30 / 0.68;     0.10 / 0.17;     1.1 / 2.7;
                                           0.26 / 0.41      0.25 / 0.33      2.6 / 3.1
100 / 40 Hz, guard and creep floor         0.004 / 0.020;   0.10 / 0.17;     1.1 / 2.7;
                                           0.18 / 0.29      0.25 / 0.33      2.6 / 3.1
the default (from the data)                0.004 / 0.020;   0.065 / 0.14;    0.50 / 1.0;
                                           0.18 / 0.29      0.22 / 0.31      1.2 / 1.2
the true parameters                        0.005 / 0.018;   0.062 / 0.14;    0.48 / 0.99;
                                           0.18 / 0.29      0.22 / 0.31      1.2 / 1.2
========================================  ===============  ===============  ===============

The default reaches the true parameters' floor (set by the validation's own conditioning:
the program's accelerations jump at the speed limits); the prior misses the semicircle by
4.1 / 8.0 %. A softer loop holds the joints longer at each reversal: under a 10 Hz loop
(0.2 deg of tracking) on six of these excitations, 17-bit angles, the former default errs
by up to 1.2 % on the semicircle (3.4 % under a 5 Hz loop), the default by 0.066 / 0.153 %
at most. The default drops 16 % (exact), 19 % (17-bit) and 36 % (14-bit: ``f_s`` 32-56 Hz)
of the rows; a parallel filter at ``f_s / 5`` instead of ``f_s / 2.5`` gives the same
errors and drops 30 %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics.exact import Model
from ..dynamics.regressor import regressor
from ..errors import NumericalError, ParameterError
from .data import MotionData

ndimage = lazy_module("scipy.ndimage")
signal = lazy_module("scipy.signal")

#: The state filter's cut-off never exceeds this fraction of the sample rate.
STATE_FRACTION = 0.1
#: The spectrum counts as motion while it is this many times above the noise floor.
NOISE_MARGIN = 10.0
#: The state filter's cut-off is this many times the frequency where motion meets noise.
NOISE_BAND_FACTOR = 3.0
#: The state filter's cut-off over the parallel filter's.
PARALLEL_RATIO = 2.5
#: Decimated samples per period of the parallel filter's cut-off.
SAMPLES_PER_PARALLEL_PERIOD = 2.5
#: A filtered speed below this many standard deviations of its noise has no sign.
SIGN_SIGMAS = 3.0
#: A speed below this fraction of the motor's RMS speed is taken as creep or stick.
CREEP_FRACTION = 0.01
#: Half-width of the parallel filter's support, in periods of its cut-off.
GUARD_PERIODS = 2.0
#: Butterworth order of both filters.
ORDER = 4


@dataclass(frozen=True)
class Filters:
    """The two low-pass filters of a conditioning (see the module doc).

    Attributes
    ----------
    state_hz : float
        Cut-off of the angles before differentiation.
    parallel_hz : float
        Cut-off of the regressor and the torques (the parallel filter).
    noise_hz : float
        Highest frequency at which the angles' spectrum is above its noise floor
        (:data:`NOISE_MARGIN` times); ``nan`` when it was not measured (cut-offs given).
    motion_hz : float
        ``max(5 f_b, 10 / T)``: the planned motion's band.
    """

    state_hz: float
    parallel_hz: float
    noise_hz: float = math.nan
    motion_hz: float = math.nan

    def step(self, rate_hz: float) -> int:
        """Decimation step (samples) at the sample rate ``rate_hz``."""
        return max(1, int(round(rate_hz / (SAMPLES_PER_PARALLEL_PERIOD * self.parallel_hz))))

    def guard(self, rate_hz: float) -> int:
        """Half-width (samples) of the parallel filter's support at ``rate_hz``."""
        return int(math.ceil(GUARD_PERIODS * rate_hz / self.parallel_hz))


@dataclass(frozen=True)
class Conditioned:
    """Filtered, differentiated and decimated data ready for the fit.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Times of the kept samples.
    q, dq, ddq : ndarray, shape (m, 2)
        Filtered angles and their derivatives at the kept samples.
    Y : ndarray, shape (m, 2, 15)
        The parallel-filtered regressor.
    tau : ndarray, shape (m, 2)
        The parallel-filtered torques.
    cutoff_hz : float
        The state filter's cut-off.
    parallel_hz : float
        The parallel filter's cut-off.
    told : ndarray of bool, shape (m, 2)
        Rows of each motor whose friction sign the data tell (the rows the fit uses).
    rows : ndarray of int, shape (m,)
        Index of each kept sample in the data (the data file's row is ``rows + 2``).
    speed_noise : ndarray, shape (2,)
        Standard deviation of each filtered speed due to the angles' noise (rad/s).
    min_speed : ndarray, shape (2,)
        Speed below which a sample's friction sign is uncertain (rad/s).
    """

    t: Array
    q: Array
    dq: Array
    ddq: Array
    Y: Array
    tau: Array
    cutoff_hz: float
    parallel_hz: float = math.nan
    told: Array | None = None
    rows: Array | None = None
    speed_noise: Array | None = None
    min_speed: Array | None = None

    @property
    def used(self) -> Array:
        """``told``, or every row when it is not set, shape (m, 2)."""
        return np.ones(self.dq.shape, bool) if self.told is None else self.told


def default_cutoff(t: Array, q: Array) -> float:
    """``max(5 f_b, 10 / T)`` capped at ``fs / 5`` (Hz): the planned motion's band of data
    ``q`` (n, 2) sampled at ``t`` (n,) (the lower bound of the state filter)."""
    n = len(t)
    fs = 1.0 / float(np.median(np.diff(t)))
    duration = float(t[-1] - t[0])
    ramp = np.linspace(0.0, 1.0, n)[:, None]
    x = q - (q[:1] + ramp * (q[-1:] - q[:1]))
    x = x - x.mean(axis=0)
    power = (np.abs(np.fft.rfft(x, axis=0)) ** 2).sum(axis=1)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    cum = np.cumsum(power)
    fb = float(f[int(np.searchsorted(cum, 0.999 * cum[-1]))]) if cum[-1] > 0 else 0.0
    return float(min(max(5.0 * fb, 10.0 / max(duration, 1e-12)), fs / 5.0))


def noise_floor(x: Array, fs: float) -> tuple[Array, Array, Array]:
    """Welch spectrum of the columns of ``x`` (n, k) (about 1 s segments, trends removed) and
    its noise floor: ``(f (nf,), psd (nf, k), floor (k,))``, the floor the median of the
    spectrum over the top 40 % of the band (units of ``x`` squared per Hz)."""
    n = len(x)
    seg = int(min(n, max(64, 2 ** math.ceil(math.log2(max(fs, 2.0))))))
    f, psd = signal.welch(x, fs=fs, nperseg=seg, detrend="linear", axis=0)
    top = f >= 0.3 * fs
    if not top.any():  # pragma: no cover - a Welch spectrum reaches fs / 2
        top = f >= f[-1]
    return f, psd, np.median(psd[top], axis=0)


def _noise_hz(f: Array, psd: Array, floor: Array) -> float:
    """Highest frequency where the spectrum of some column is NOISE_MARGIN above its floor."""
    above = psd > NOISE_MARGIN * floor[None, :]
    hits = np.flatnonzero(above.any(axis=1) & (f > 0))
    return float(f[hits[-1]]) if len(hits) else 0.0


def choose_filters(t: Array, q: Array, *, state_hz: float | None = None,
                   parallel_hz: float | None = None) -> Filters:
    """The filters of data ``q`` (n, 2) sampled at ``t`` (n,), see the module doc; a given
    ``state_hz`` or ``parallel_hz`` is kept (the other follows from it)."""
    fs = 1.0 / float(np.median(np.diff(t)))
    fn, fm = math.nan, math.nan
    if state_hz is None:
        fm = default_cutoff(t, q)
        f, psd, floor = noise_floor(q, fs)
        fn = _noise_hz(f, psd, floor)
        state = min(STATE_FRACTION * fs, max(NOISE_BAND_FACTOR * fn, fm))
        if parallel_hz is not None:
            state = max(state, min(PARALLEL_RATIO * parallel_hz, STATE_FRACTION * fs))
    else:
        state = float(state_hz)
    parallel = state / PARALLEL_RATIO if parallel_hz is None else float(parallel_hz)
    return Filters(float(state), float(parallel), fn, fm)


def _lowpass(x: Array, fc: float, fs: float) -> Array:
    sos = signal.butter(ORDER, fc, fs=fs, output="sos")
    return np.asarray(signal.sosfiltfilt(sos, x, axis=0))


def filtered_noise(floor: Array, fc: float, fs: float, derivative: bool) -> Array:
    """Standard deviation of a white noise of one-sided density ``floor`` (k,) after the
    zero-phase filter at ``fc`` and, with ``derivative``, the central difference."""
    f = np.linspace(0.0, 0.5 * fs, 4097)
    _, h = signal.sosfreqz(signal.butter(ORDER, fc, fs=fs, output="sos"), worN=f, fs=fs)
    gain = np.abs(h) ** 4
    if derivative:
        gain = gain * (fs * np.sin(2 * np.pi * f / fs)) ** 2
    return np.asarray(np.sqrt(floor * float(np.trapezoid(gain, f))))


_speed_noise = filtered_noise


def uncertain_sign(dq: Array, min_speed: Array) -> Array:
    """Samples (n, 2) whose friction sign is uncertain: speed below ``min_speed`` (2,) or a
    sign change to or from the next sample."""
    bad = np.abs(dq) <= min_speed[None, :]
    change = np.sign(dq[1:]) != np.sign(dq[:-1])
    bad[1:] |= change
    bad[:-1] |= change
    return np.asarray(bad)


def condition(data: MotionData, model: Model, *, cutoff_hz: float | None = None,
              parallel_hz: float | None = None, filters: Filters | None = None
              ) -> Conditioned:
    """Filter, differentiate, regress, parallel-filter and decimate ``data`` for ``model``
    (see the module doc).

    Parameters
    ----------
    data : MotionData
    model : Model
        Geometry, assembly mode, gravity and Coulomb regularisation for the regressor.
    cutoff_hz, parallel_hz : float, optional
        The state and parallel filters' cut-offs (Hz); by default chosen from the data by
        :func:`choose_filters`.
    filters : Filters, optional
        Use these filters (those of another data set, e.g. the identification's for
        validation data) instead.

    Returns
    -------
    Conditioned

    Raises
    ------
    ParameterError
        A cut-off that is not below the Nyquist frequency.
    NumericalError
        Values too large for the filters in double precision.
    """
    fs = data.rate_hz
    if filters is None:
        for name, v in (("cut-off", cutoff_hz), ("parallel cut-off", parallel_hz)):
            if v is not None and not (0.0 < v < 0.5 * fs):
                raise ParameterError(f"{name} {v:g} Hz must be positive and below the "
                                     f"Nyquist frequency {0.5 * fs:g} Hz of {data.source}")
        filters = choose_filters(data.t, data.q, state_hz=cutoff_hz, parallel_hz=parallel_hz)
    fc, fp = filters.state_hz, filters.parallel_hz
    for name, v in (("cut-off", fc), ("parallel cut-off", fp)):
        if not (0.0 < v < 0.5 * fs):
            raise ParameterError(f"{name} {v:g} Hz must be positive and below the Nyquist "
                                 f"frequency {0.5 * fs:g} Hz of {data.source}")
    dt = 1.0 / fs
    n = len(data.t)
    q = _lowpass(data.q, fc, fs)
    if data.dq is not None:
        dq = _lowpass(data.dq, fc, fs)
        noise = _speed_noise(noise_floor(data.dq, fs)[2], fc, fs, derivative=False)
    else:
        dq = np.gradient(q, dt, axis=0)
        noise = _speed_noise(noise_floor(data.q, fs)[2], fc, fs, derivative=True)
    if data.ddq is not None:
        ddq = _lowpass(data.ddq, fc, fs)
    else:
        ddq = np.gradient(dq, dt, axis=0)
    Y = regressor(model, q, dq, ddq, t=data.t)
    Yf = _lowpass(Y.reshape(n, -1), fp, fs).reshape(Y.shape)
    tau = _lowpass(data.tau, fp, fs)
    for name, arr in (("the regressor", Yf), ("the torques", tau)):
        if not np.isfinite(arr).all():
            raise NumericalError(f"{data.source}: {name} overflow after filtering (values "
                                 "too large for double precision)")
    guard = filters.guard(fs)
    edge = min(guard, n // 10)
    inner = slice(edge, n - edge) if n - 2 * edge > 0 else slice(0, n)
    rms_speed = np.sqrt((dq[inner] ** 2).mean(axis=0))
    min_speed = np.maximum(SIGN_SIGMAS * noise, CREEP_FRACTION * rms_speed)
    bad = uncertain_sign(dq, min_speed)
    spread = ndimage.maximum_filter1d(bad.astype(np.uint8), size=2 * guard + 1, axis=0,
                                      mode="nearest") > 0
    keep = np.arange(edge, n - edge, filters.step(fs))
    return Conditioned(data.t[keep], q[keep], dq[keep], ddq[keep], Yf[keep], tau[keep], fc,
                       fp, ~spread[keep], keep, noise, min_speed)
