"""Identification of the base parameters from measured motion.

Steps of :func:`identify` (each a small function below):

1. **Filter and differentiate** the angles: zero-phase 4th-order Butterworth low-pass
   (``scipy.signal.sosfiltfilt``) at the cut-off ``fc``, then central differences for the
   rates and accelerations (measured rates and accelerations, when given, are filtered the
   same way instead of differentiated).
2. **Parallel filtering** (Gautier): the regressor's columns and the measured torques go
   through the same low-pass, so ``Y theta = tau`` still holds after it for every part of
   the model (friction steps included), then both are decimated to about ``2.5 fc`` so that
   the residuals are close to white; the ends (the filter's settling, ``fs / fc`` samples
   each) are dropped.
3. **Base regressor** (:mod:`dextar.identification.base`) and its conditioning in these data
   (columns scaled to unit norm); a rank-deficient regressor is refused, naming the
   parameter combinations the data cannot tell apart.
4. **Weighted least squares**: ordinary least squares, each motor's residual variance, then
   the rows of each motor weighted by the inverse of its residual standard deviation; the
   standard deviations of the estimates from ``(Y_w^T Y_w)^{-1}``.
5. **Physical consistency**: a set of standard parameters (masses, inertias and friction not
   negative, every rod's inertia about its centre not negative) with exactly these base
   parameters is sought closest to the prior; when none exists the fit is redone as a
   least-squares problem constrained to physical parameters (``method = "constrained"``).

The default cut-off is derived from the data: ``fc = min(max(5 f_b, 10 / T), fs / 5)``
where ``f_b`` holds 99.9 % of the energy of the angles' spectrum (trend removed), ``T``
the duration and ``fs`` the sample rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, signal

from .._arrays import Array
from ..dynamics.exact import Model
from ..dynamics.inertia import Inertia, Rod
from ..dynamics.regressor import INDEX, STANDARD, regressor, standard_parameters
from ..errors import NumericalError, ParameterError
from ..geometry import parse_working_mode
from ..kinematics import direct_kinematics, working_mode
from .base import BaseParameters, base_parameters
from .data import MotionData

#: Condition number above which the summary warns that the data excite badly.
COND_WARNING = 1e3
#: Samples (after decimation) needed per base parameter.
SAMPLES_PER_PARAMETER = 5
#: Lags (decimated samples) of the autocorrelation-consistent covariance.
HAC_LAGS = 4
#: A motor's samples slower than this fraction of its peak speed are left out of its
#: equations (static friction).
LOW_SPEED = 0.05


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
    """

    t: Array
    q: Array
    dq: Array
    ddq: Array
    Y: Array
    tau: Array
    cutoff_hz: float


@dataclass(frozen=True)
class IdentificationResult:
    """What :func:`identify` found.

    Attributes
    ----------
    base : BaseParameters
    beta, std : ndarray, shape (n_base,)
        Identified base parameters and their standard deviations.
    theta : ndarray, shape (15,)
        A physically consistent set of standard parameters with ``base.of(theta) = beta``
        (to rounding when ``consistent``).
    inertia : Inertia
        The same as an :class:`Inertia` (friction and gravity included).
    method : str
        ``"weighted least squares"`` or ``"constrained"`` (see the module doc).
    condition_number : float
        Of the weighted base regressor, columns scaled to unit norm.
    rms_residual : ndarray, shape (2,)
        RMS of each motor's residual (N m), on the filtered torques.
    sigma : ndarray, shape (2,)
        Each motor's residual standard deviation used as weight.
    n_samples, n_used : int
        Samples read and kept after decimation.
    cutoff_hz : float
    consistent : bool
        True when ``inertia`` reproduces ``beta`` to 1e-9 relative.
    status : int
        0 success, 1 poorly conditioned (``condition_number`` above 1e3), 2 the physical set
        does not reproduce the base parameters exactly.
    message : str
    warnings : list of str
    conditioned : Conditioned, optional
        The filtered, decimated data the fit used (for plots and residuals).
    """

    base: BaseParameters
    beta: Array
    std: Array
    theta: Array
    inertia: Inertia
    method: str
    condition_number: float
    rms_residual: Array
    sigma: Array
    n_samples: int
    n_used: int
    cutoff_hz: float
    consistent: bool
    status: int
    message: str
    warnings: list[str] = field(default_factory=list)
    conditioned: Conditioned | None = None

    @property
    def success(self) -> bool:
        """True when the status is 0."""
        return self.status == 0


def default_cutoff(t: Array, q: Array) -> float:
    """The default low-pass cut-off (Hz) of data ``q`` (n, 2) sampled at ``t`` (n,)."""
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


def _lowpass(x: Array, fc: float, fs: float) -> Array:
    sos = signal.butter(4, fc, fs=fs, output="sos")
    return np.asarray(signal.sosfiltfilt(sos, x, axis=0))


def condition(data: MotionData, model: Model, *, cutoff_hz: float | None = None
              ) -> Conditioned:
    """Steps 1 and 2 of the module doc: filter, differentiate, regress, parallel-filter and
    decimate ``data`` for ``model``.

    Raises
    ------
    ParameterError
        A cut-off that is not below the Nyquist frequency, or too few samples left.
    """
    fs = data.rate_hz
    fc = default_cutoff(data.t, data.q) if cutoff_hz is None else float(cutoff_hz)
    if not (0.0 < fc < 0.5 * fs):
        raise ParameterError(f"cut-off {fc:g} Hz must be positive and below the Nyquist "
                             f"frequency {0.5 * fs:g} Hz of {data.source}")
    dt = 1.0 / fs
    q = _lowpass(data.q, fc, fs)
    if data.dq is not None:
        dq = _lowpass(data.dq, fc, fs)
    else:
        dq = np.gradient(q, dt, axis=0)
    if data.ddq is not None:
        ddq = _lowpass(data.ddq, fc, fs)
    else:
        ddq = np.gradient(dq, dt, axis=0)
    Y = regressor(model, q, dq, ddq, t=data.t)
    n = len(data.t)
    Yf = _lowpass(Y.reshape(n, -1), fc, fs).reshape(Y.shape)
    tau = _lowpass(data.tau, fc, fs)
    for name, arr in (("the regressor", Yf), ("the torques", tau)):
        if not np.isfinite(arr).all():
            raise NumericalError(f"{data.source}: {name} overflow after filtering (values "
                                 "too large for double precision)")
    edge = min(int(math.ceil(fs / fc)), n // 10)
    step = max(1, int(fs / (2.5 * fc)))
    keep = np.arange(edge, n - edge, step)
    return Conditioned(data.t[keep], q[keep], dq[keep], ddq[keep], Yf[keep], tau[keep], fc)


def check_working_mode(data: MotionData, model: Model, mode: str) -> None:
    """Raise :class:`ParameterError` at the first sample whose pose is not in the working
    mode ``mode`` (the assembly mode is the model's)."""
    want = np.array(parse_working_mode(mode))
    P = direct_kinematics(model.robot, data.q, model.assembly)
    got = working_mode(model.robot, data.q, P)
    bad = ~(got == want).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        sgn = "".join("+" if s > 0 else "-" if s < 0 else "0" for s in got[i])
        raise ParameterError(
            f"{data.source}: row {i + 2} (t = {data.t[i]:.6g} s) is in working mode {sgn}, not "
            f"{mode}: phi = {math.degrees(data.q[i, 0]):.6g} deg, psi = "
            f"{math.degrees(data.q[i, 1]):.6g} deg, P = ({1e3 * P[i, 0]:.6g}, "
            f"{1e3 * P[i, 1]:.6g}) mm")


def _stack(Yb: Array, tau: Array, sigma: Array, keep: Array) -> tuple[Array, Array]:
    """The kept rows of motor A then of motor D, each weighted by ``1 / sigma_k``:
    (n_A + n_D, p) and (n_A + n_D,)."""
    A = np.concatenate([Yb[keep[:, k], k, :] / sigma[k] for k in range(2)])
    b = np.concatenate([tau[keep[:, k], k] / sigma[k] for k in range(2)])
    return A, b


def _rank_check(A: Array, base: BaseParameters, source: str) -> float:
    """Condition number of ``A`` with unit-norm columns; raise for a rank-deficient ``A``
    naming the base-parameter combinations the data cannot identify."""
    if not np.isfinite(A).all():
        raise NumericalError(f"{source}: the weighted regressor is not finite (values too "
                             "large or too small for double precision)")
    norms = np.linalg.norm(A, axis=0)
    names = base.names
    if (norms == 0).any():
        j = int(np.flatnonzero(norms == 0)[0])
        raise ParameterError(f"{source}: the data do not excite base parameter {names[j]} "
                             f"({base.meanings[j]}): it cannot be identified")
    _, s, vt = np.linalg.svd(A / norms, full_matrices=False)
    cond = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
    if not cond < 1e10:
        v = vt[-1]
        big = np.argsort(-np.abs(v))[:3]
        combo = " + ".join(f"{v[j]:.3g} {names[j]}" for j in big if abs(v[j]) > 0.05)
        raise ParameterError(f"{source}: the data do not excite every base parameter "
                             f"(condition number {cond:.3g}): the combination "
                             f"{combo.replace('+ -', '- ')} cannot be identified; excite "
                             "both motors over a richer motion (dextar excite)")
    return cond


def identify(data: MotionData, model: Model, *, mode: str, cutoff_hz: float | None = None,
             base: BaseParameters | None = None) -> IdentificationResult:
    """Identify the base parameters of ``model``'s robot from ``data``.

    Parameters
    ----------
    data : MotionData
        Measured angles and torques (SI).
    model : Model
        The prior: geometry, assembly mode, gravity, Coulomb regularisation speed, and the
        masses that the physical set stays closest to.
    mode : str
        The working mode the data must stay in.
    cutoff_hz : float, optional
        Low-pass cut-off (default: :func:`default_cutoff`).
    base : BaseParameters, optional
        Precomputed base parameters of ``model``.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    ParameterError
        Data outside the working mode, too few samples, or a rank-deficient regressor.
    """
    check_working_mode(data, model, mode)
    base = base or base_parameters(model)
    c = condition(data, model, cutoff_hz=cutoff_hz)
    m = len(c.t)
    need = SAMPLES_PER_PARAMETER * base.size
    if m < need:
        raise ParameterError(
            f"{data.source}: {m} samples after filtering at {c.cutoff_hz:.3g} Hz and "
            f"decimating ({len(data.t)} read), fewer than {need} ({SAMPLES_PER_PARAMETER} per "
            f"base parameter, {base.size} of them): record longer")
    Yb = base.columns(c.Y)
    # a motor's rows near rest carry its static friction, which no model of the motion
    # predicts (the motor sticks): they are left out of its equations
    keep = np.abs(c.dq) > LOW_SPEED * np.abs(c.dq).max(axis=0)
    sizes = (int(keep[:, 0].sum()), int(keep[:, 1].sum()))
    A, b = _stack(Yb, c.tau, np.ones(2), keep)
    _rank_check(A, base, data.source)
    beta0, *_ = np.linalg.lstsq(A, b, rcond=None)
    r0 = (Yb @ beta0) - c.tau
    sigma = np.array([np.sqrt((r0[keep[:, k], k] ** 2).sum()
                              / max(sizes[k] - base.size / 2.0, 1.0)) for k in range(2)])
    if not (sigma > 0).all():  # an exact fit of a motor: weigh both alike
        sigma = np.ones(2)
    Aw, bw = _stack(Yb, c.tau, sigma, keep)
    cond = _rank_check(Aw, base, data.source)
    beta, *_ = np.linalg.lstsq(Aw, bw, rcond=None)
    std = _hac_std(Aw, Aw @ beta - bw, sizes)
    prior = standard_parameters(model.inertia)
    method = "weighted least squares"
    theta, ok = physical_set(beta, base, prior, model.inertia)
    if not ok:
        method = "constrained"
        theta = _constrained_fit(Aw, bw, base, prior, model.inertia)
        beta = base.of(theta)
        std = _hac_std(Aw, Aw @ beta - bw, sizes)  # the spread about the constrained fit
    inertia = realise(theta, model.inertia)
    back = base.of(standard_parameters(inertia))
    consistent = bool(np.all(np.abs(back - beta) <= 1e-9 * np.maximum(np.abs(beta), 1e-12)
                             + 1e-12 * np.abs(beta).max()))
    res = Yb @ beta - c.tau
    rms = np.array([np.sqrt((res[keep[:, k], k] ** 2).mean()) for k in range(2)])
    warnings = []
    status, message = 0, "identified"
    if cond > COND_WARNING:
        status = 1
        message = (f"condition number {cond:.3g} above {COND_WARNING:g}: the data excite "
                   "poorly, the estimates are uncertain (dextar excite designs a better motion)")
        warnings.append(message)
    if not consistent:
        status = 2
        message = "the physical parameter set does not reproduce the base parameters exactly"
        warnings.append(message)
    if method == "constrained":
        warnings.append("the least-squares solution is not physical (a negative mass, "
                        "inertia or friction): the fit was constrained to physical parameters")
    return IdentificationResult(base, beta, std, theta, inertia, method, cond, rms, sigma,
                                len(data.t), m, c.cutoff_hz, consistent, status, message,
                                warnings, c)


def _hac_std(A: Array, r: Array, sizes: tuple[int, int]) -> Array:
    """Standard deviations of least-squares estimates whose residuals ``r`` are correlated
    in time (the low-pass leaves neighbouring samples related): the heteroskedasticity and
    autocorrelation consistent (Newey-West, Bartlett weights) covariance
    ``(A^T A)^-1 S (A^T A)^-1``, lags within each motor's rows (``sizes`` of them), scaled
    by ``n / (n - p)``."""
    n, p = A.shape
    g = A * r[:, None]
    S = g.T @ g
    starts = (0, sizes[0])
    for lag in range(1, HAC_LAGS + 1):
        w = 1.0 - lag / (HAC_LAGS + 1.0)
        G = np.zeros((p, p))
        for k in range(2):
            blk = g[starts[k]:starts[k] + sizes[k]]
            if len(blk) > lag:
                G += blk[lag:].T @ blk[:-lag]
        S += w * (G + G.T)
    inv = np.linalg.inv(A.T @ A)
    cov = inv @ S @ inv * (n / max(n - p, 1))
    return np.asarray(np.sqrt(np.clip(np.diag(cov), 0.0, None)))


# ----------------------------------------------------------------------- physical parameters
def _scales(prior: Array) -> Array:
    """A scale per standard parameter: its prior magnitude, floored per unit."""
    s = np.abs(prior).astype(float)
    units = np.array([p.unit for p in STANDARD])
    for u in set(units.tolist()):
        sel = units == u
        s[sel] = np.maximum(s[sel], 1e-3 * max(float(s[sel].max()), 1e-12))
    return np.asarray(np.maximum(s, 1e-12))


def _scaled_bounds(prior_inertia: Inertia, s: Array) -> list[tuple[float | None, None]]:
    """Lower bounds of the scaled standard parameters ``theta / s``: masses, inertias and
    friction not negative, the point mass not below the payload."""
    lo: list[float | None] = [0.0 if p.nonnegative else None for p in STANDARD]
    lo[INDEX["m_P"]] = prior_inertia.payload
    return [(None if v is None else v / s[i], None) for i, v in enumerate(lo)]


_RODS = ((INDEX["J_BP"], INDEX["h_BP"], INDEX["m_BP"]), (INDEX["J_CP"], INDEX["h_CP"], INDEX["m_CP"]))


def _rod_slack(x: Array, s: Array) -> Array:
    """``J m - h^2`` of each distal rod (>= 0 when its inertia about its centre is not
    negative), for scaled parameters ``x = theta / s``, in scaled units, shape (2,)."""
    th = x * s
    return np.array([(th[J] * th[m] - th[h] ** 2) / (s[J] * s[m]) for J, h, m in _RODS])


def physical_set(beta: Array, base: BaseParameters, prior: Array, prior_inertia: Inertia,
                 ) -> tuple[Array, bool]:
    """Standard parameters ``theta`` (15,) closest to ``prior`` (scaled) with
    ``base.of(theta) = beta`` and physical values; ``ok`` is False when none exists."""
    s = _scales(prior)
    K = base.K * s
    x0 = prior / s
    sb = _scaled_bounds(prior_inertia, s)

    def rods(x: Array) -> Array:
        return _rod_slack(x, s)

    bscale = np.maximum(np.abs(beta), 1e-300)
    cons = [{"type": "eq", "fun": lambda x: (K @ x - beta) / bscale,
             "jac": lambda x: K / bscale[:, None]},
            {"type": "ineq", "fun": rods}]
    # start from the prior moved onto the affine set K theta = beta (least-norm correction)
    x_start = x0 + np.linalg.lstsq(K, beta - K @ x0, rcond=None)[0]
    r = optimize.minimize(lambda x: float(((x - x0) ** 2).sum()), x_start,
                          jac=lambda x: 2 * (x - x0), bounds=sb, constraints=cons,
                          method="SLSQP", options={"maxiter": 500, "ftol": 1e-14})
    theta = r.x * s
    ok = bool(np.all(np.abs(base.of(theta) - beta) <= 1e-9 * bscale + 1e-12 * np.abs(beta).max())
              and np.all(rods(r.x) >= -1e-9)
              and all(lo is None or r.x[i] >= lo - 1e-12 for i, (lo, _hi) in enumerate(sb)))
    if ok:  # land exactly on the constraints (SLSQP stops within its tolerance)
        theta = _polish(theta, base, beta)
    return theta, ok


def _polish(theta: Array, base: BaseParameters, beta: Array) -> Array:
    """Move ``theta`` onto ``K theta = beta`` exactly along the independent parameters."""
    idx = list(base.independent)
    out = theta.copy()
    out[idx] += beta - base.of(theta)
    return out


def _constrained_fit(Aw: Array, bw: Array, base: BaseParameters, prior: Array,
                     prior_inertia: Inertia) -> Array:
    """Least squares over physical standard parameters (a tiny pull to the prior fixes the
    directions the torques do not see)."""
    s = _scales(prior)
    M = Aw @ (base.K * s)
    G = M.T @ M
    g = M.T @ bw
    x0 = prior / s
    eps = 1e-9 * float(np.trace(G)) / len(x0)
    sb = _scaled_bounds(prior_inertia, s)

    def rods(x: Array) -> Array:
        return _rod_slack(x, s)

    def f(x: Array) -> float:
        return float(x @ G @ x - 2 * g @ x + eps * ((x - x0) ** 2).sum())

    def df(x: Array) -> Array:
        return np.asarray(2 * (G @ x - g) + 2 * eps * (x - x0))

    x_start = np.clip(x0, [lo if lo is not None else -np.inf for lo, _ in sb], None)
    r = optimize.minimize(f, x_start, jac=df, bounds=sb,
                          constraints=[{"type": "ineq", "fun": rods}], method="SLSQP",
                          options={"maxiter": 1000, "ftol": 1e-15})
    return np.asarray(r.x * s)


def realise(theta: Array, template: Inertia) -> Inertia:
    """An :class:`Inertia` with the standard parameters ``theta`` (physical), gravity and
    Coulomb regularisation of ``template``; each proximal rod keeps the template's mass (or
    the smallest mass its first moment allows) and inertia where they fit, the rest of its
    ``J`` going to the rotor; the payload stays the template's."""
    th = np.asarray(theta, float)
    distal = []
    for J, h, m in ((th[INDEX["J_BP"]], th[INDEX["h_BP"]], th[INDEX["m_BP"]]),
                    (th[INDEX["J_CP"]], th[INDEX["h_CP"]], th[INDEX["m_CP"]])):
        m = max(m, 0.0)
        c = h / m if m > 0 else 0.0
        distal.append(Rod(m, c, max(J - m * c * c, 0.0) if m > 0 else 0.0))
    prox, rotor = [], []
    for k, (J, h) in enumerate(((th[INDEX["J_A"]], th[INDEX["h_AB"]]),
                                (th[INDEX["J_D"]], th[INDEX["h_DC"]]))):
        p = template.proximal[k]
        J = max(J, 0.0)
        m = p.mass
        if h != 0 and (m <= 0 or m * J < h * h):
            m = h * h / J if J > 0 else abs(h) / 1e-12
        c = h / m if m > 0 else 0.0
        rest = max(J - m * c * c, 0.0)
        inert = min(p.inertia, rest) if m > 0 else 0.0
        prox.append(Rod(m, c, inert))
        rotor.append(rest - inert)
    mP = th[INDEX["m_P"]]
    payload = template.payload if mP - template.payload > 1e-12 * max(mP, 1.0) else 0.0
    return template.with_(proximal=(prox[0], prox[1]), distal=(distal[0], distal[1]),
                          effector_mass=max(mP - payload, 1e-300), payload=payload,
                          rotor=(rotor[0], rotor[1]),
                          viscous=(max(th[INDEX["fv_A"]], 0.0), max(th[INDEX["fv_D"]], 0.0)),
                          coulomb=(max(th[INDEX["fc_A"]], 0.0), max(th[INDEX["fc_D"]], 0.0)))
