"""Kinematic calibration: the parameters that make the model's predicted points meet the
measured ones, with their uncertainty.

Steps of :func:`calibrate`:

1. **Assembly modes and the instrument frame.** Rows without an assembly mode take the one
   whose nominal prediction is nearer the measured point. Measured points in the
   instrument's frame are first registered: the rigid motion that best maps the nominal
   predictions onto them (closed form), alternating with the assembly choice until it
   settles. The nominal robot in that frame is the model *before* calibration (its errors
   are the "before" figures: the robot's own errors, not the frame's).
2. **Weights.** With a stated point noise (``sigma_mm`` per row or ``point_std``) each row
   is whitened by its covariance ``sigma^2 I + s_r^2 J_q J_q^T`` (``s_r`` the encoders'
   reading noise, ``J_q`` the point's sensitivity to the readings); otherwise rows are
   weighed alike.
3. **Identifiability** (:mod:`dextar.calibration.observability`): the parameters to fit
   are those of the free ones the poses identify; the others stay nominal.
4. **Nonlinear least squares**, :func:`scipy.optimize.least_squares`: Levenberg-Marquardt
   (MINPACK) with the analytic Jacobian, on variables scaled so that one unit moves the
   end-effector about 1 mm. With a robust loss (``"soft_l1"``, ``"huber"``, ``"cauchy"``,
   ``"arctan"``; trust-region reflective) the rows farther than :data:`OUTLIER_FACTOR`
   residual scales from their prediction are rejected (listed) and the kept rows refitted
   by plain least squares.
5. **Checks**: every row assembles with the fitted parameters and is in its stated working
   mode; every measured point is within reach of both legs of the nominal or the fitted
   robot; without a robust loss, no row is an outlier; poses of a single working mode do
   not leave parameters coupled (correlation above :data:`COUPLING_LIMIT`).
6. **Uncertainty**: covariance ``s^2 (J^T J)^-1`` from the Jacobian at the solution and the
   residual variance ``s^2 = RSS / (2 n - p)``; the correlation matrix; with a stated noise,
   a chi-square test of the residuals (a model that misses something, e.g. frozen
   offsets, shows as residuals far above the noise: ``status`` 2).

Errors are distances ``|measured - predicted|``; an RMS error is ``sqrt(mean(|e|^2))``, so
isotropic noise of ``sigma`` per axis gives an RMS error of ``sqrt(2) sigma``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import AssemblyError, DextarError, ParameterError, ReachError
from ..geometry import parse_working_mode
from ..params import number_words
from .data import PoseData, rows_text
from .errors import CouplingError, OutlierError, OutOfReachError
from .model import (
    INDEX,
    LENGTHS,
    NAMES,
    ROBOT,
    Closure,
    KinematicModel,
    characteristic_scales,
    closure_of,
    jacobian_of,
    predict_of,
    rotation,
    to_file_units,
    wrap,
)
from .observability import (
    Identifiability,
    Observability,
    correlation,
    identifiability,
    multiple_correlation,
    observability,
)

optimize = lazy_module("scipy.optimize")
stats = lazy_module("scipy.stats")

#: A row farther from its prediction than this many residual scales is an outlier (the
#: scale is the per-axis standard deviation estimated from the median error; for Gaussian
#: noise a row is beyond 5 scales with probability exp(-12.5) = 4e-6).
OUTLIER_FACTOR = 5.0
#: A parameter whose multiple correlation with the others reaches this is coupled to them
#: (variance inflation 500; poses of all four modes of the DexTAR stay below 0.97).
COUPLING_LIMIT = 0.999
#: Significance of the chi-square test of the residuals against a stated noise.
CHI2_ALPHA = 1e-6
#: Robust losses of scipy.optimize.least_squares accepted.
ROBUST_LOSSES = ("soft_l1", "huber", "cauchy", "arctan")
#: Rayleigh median: the median distance of isotropic 2-D noise is this times sigma.
RAYLEIGH_MEDIAN = math.sqrt(2.0 * math.log(2.0))
#: Measured points whose spread about their centre is more than this factor off the nominal
#: robot's predictions at the same readings are not millimetres of this robot (a rigid motion
#: keeps the spread). Measured on 40 random robots (lengths 50-600 mm, 24 poses, 0.2 %
#: length errors): good data 0.991-1.011; every row in the other assembly 0.98-1.44 (the
#: check takes the nearer of both); a robot 1.5 times the nominal 0.63-0.72. Millimetres
#: written as metres are 1e-3, as centimetres 0.1, as inches 0.039.
SCALE_FACTOR = 2.0
#: The units a scale names: (ratio of the spreads, the unit the points look written in).
SCALE_UNITS = ((1e-3, "metres"), (0.1, "centimetres"), (1.0 / 25.4, "inches"),
               (1e3, "micrometres"))


@dataclass(frozen=True)
class Parameter:
    """One calibration parameter (SI: m or rad).

    Attributes
    ----------
    name : str
    unit : str
        ``"m"`` or ``"rad"``.
    nominal, value : float
    std : float or None
        Standard deviation; None when not identifiable (``value`` is then ``nominal``).
    identifiable : bool
    """

    name: str
    unit: str
    nominal: float
    value: float
    std: float | None
    identifiable: bool

    def in_file_units(self) -> tuple[str, float, float, float | None]:
        """``(unit, nominal, value, std)`` in mm or deg."""
        return ("mm" if self.name in LENGTHS else "deg", to_file_units(self.name, self.nominal),
                to_file_units(self.name, self.value),
                None if self.std is None else to_file_units(self.name, self.std))


@dataclass(frozen=True)
class Errors:
    """Errors of a model on poses, before and after calibration (SI, m).

    Attributes
    ----------
    residuals_before, residuals_after : ndarray, shape (n, 2)
        ``measured - predicted`` (m) in the frame of the measured points.
    rms_before, rms_after, max_before, max_after : float
        RMS and largest distance ``|measured - predicted|`` (m).
    rows : ndarray of int, shape (n,)
        Row numbers of the poses.
    """

    residuals_before: Array
    residuals_after: Array
    rms_before: float
    rms_after: float
    max_before: float
    max_after: float
    rows: Array

    @classmethod
    def of(cls, before: Array, after: Array, rows: Array) -> Errors:
        """Errors from the residual vectors (n, 2) before and after."""
        eb, ea = np.hypot(*before.T), np.hypot(*after.T)
        return cls(before, after, _rms(eb), _rms(ea), float(eb.max(initial=0.0)),
                   float(ea.max(initial=0.0)), rows)

    def as_dict(self) -> dict[str, float | int]:
        """The four figures in mm, JSON-ready."""
        return {"n_poses": len(self.rows), "rms_error_before_mm": 1e3 * self.rms_before,
                "rms_error_after_mm": 1e3 * self.rms_after,
                "max_error_before_mm": 1e3 * self.max_before,
                "max_error_after_mm": 1e3 * self.max_after}


def _rms(e: Array) -> float:
    return float(np.sqrt(np.mean(e * e))) if e.size else 0.0


@dataclass(frozen=True)
class CalibrationResult:
    """What :func:`calibrate` found (SI: m, rad).

    Attributes
    ----------
    status : int
        0 calibrated; 1 the least-squares solver did not converge (``message`` says why);
        2 the residuals are far above the stated noise (chi-square test at
        :data:`CHI2_ALPHA`): the model misses something.
    message : str
    nominal : KinematicModel
        The model given (in the registered instrument frame: :attr:`before`).
    before : KinematicModel
        The nominal robot in the registered instrument frame: the model before calibration.
    calibrated : KinematicModel
        The identified parameters (the others nominal).
    frame : str
        ``"instrument"`` or ``"robot"`` (the frame of the measured points).
    parameters : tuple of Parameter
        The model's parameters (10, or 7 in the robot frame) in the order of ``NAMES``.
    identifiable, not_identifiable : tuple of str
        Of the free parameters; a parameter not free is in neither.
    combinations : dict
        For each parameter not identifiable, the combination its column equals.
    covariance, correlation : ndarray, shape (k, k)
        Of the identifiable parameters (in the order of ``identifiable``), SI.
    observability : Observability
        Of the identifiable parameters over the kept poses, at the solution.
    data : PoseData
        The poses with their assembly modes resolved.
    kept : ndarray of bool, shape (n,)
        Poses used in the final fit (the others rejected by the robust loss).
    rejected : tuple of int
        Row numbers of the rejected poses.
    errors : Errors
        On the kept poses.
    validation : Errors or None
        On held-out poses.
    residual_std : float
        Per-axis standard deviation of the residuals (m; of the whitened residuals, which
        are then dimensionless, when the fit is weighted).
    chi2 : float or None
        Reduced chi-square of a weighted fit (1 when the noise is as stated).
    nfev : int
        Residual evaluations of the final fit.
    warnings : tuple of str
    """

    status: int
    message: str
    nominal: KinematicModel
    before: KinematicModel
    calibrated: KinematicModel
    frame: str
    parameters: tuple[Parameter, ...]
    identifiable: tuple[str, ...]
    not_identifiable: tuple[str, ...]
    combinations: dict[str, str]
    covariance: Array
    correlation: Array
    observability: Observability
    data: PoseData
    kept: Array
    rejected: tuple[int, ...]
    errors: Errors
    validation: Errors | None
    residual_std: float
    chi2: float | None
    nfev: int
    warnings: tuple[str, ...] = field(default_factory=tuple)

    @property
    def success(self) -> bool:
        """True when ``status`` is 0."""
        return self.status == 0

    @property
    def residuals_before(self) -> Array:
        """``measured - predicted`` (n_kept, 2) of the nominal robot (m)."""
        return self.errors.residuals_before

    @property
    def residuals_after(self) -> Array:
        """``measured - predicted`` (n_kept, 2) of the calibrated model (m)."""
        return self.errors.residuals_after

    @property
    def rms_error_before(self) -> float:
        """RMS distance of the nominal robot's predictions (m)."""
        return self.errors.rms_before

    @property
    def rms_error_after(self) -> float:
        """RMS distance of the calibrated predictions (m)."""
        return self.errors.rms_after

    @property
    def max_error_before(self) -> float:
        """Largest distance of the nominal robot's predictions (m)."""
        return self.errors.max_before

    @property
    def max_error_after(self) -> float:
        """Largest distance of the calibrated predictions (m)."""
        return self.errors.max_after

    def parameter(self, name: str) -> Parameter:
        """The parameter ``name``."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise ParameterError(f"no calibration parameter {name!r}; known: "
                             f"{', '.join(p.name for p in self.parameters)}")

    def robot_covariance(self) -> tuple[tuple[str, ...], Array]:
        """The identifiable robot parameters (no frame) and their covariance (SI)."""
        idx = [i for i, n in enumerate(self.identifiable) if n in ROBOT]
        return (tuple(self.identifiable[i] for i in idx),
                self.covariance[np.ix_(idx, idx)])


# ------------------------------------------------------------------------------ helpers
def register(P: Array, M: Array, weights: Array | None = None) -> tuple[float, float, float]:
    """The rigid motion ``M ~ R(theta) P + t`` that best maps points ``P`` (n, 2) onto
    ``M`` (n, 2) in least squares (closed form), as ``(x0, y0, theta0)``."""
    w = np.ones(len(P)) if weights is None else np.asarray(weights, float)
    w = w / w.sum()
    pc, mc = w @ P, w @ M
    a, b = P - pc, M - mc
    H = (a * w[:, None]).T @ b
    theta = math.atan2(H[0, 1] - H[1, 0], H[0, 0] + H[1, 1])
    t = mc - rotation(theta) @ pc
    return float(t[0]), float(t[1]), theta


def _whitening(sigma: Array | None, reading_std: float | None, Jq: Array) -> Array | None:
    """Per-row whitening matrices (n, 2, 2): ``L^-1`` of the Cholesky factor of
    ``sigma^2 I + s_r^2 J_q J_q^T``; None when no noise is stated."""
    if sigma is None:
        return None
    n = len(sigma)
    S = np.zeros((n, 2, 2))
    S[:, 0, 0] = S[:, 1, 1] = sigma * sigma
    if reading_std:
        S += reading_std ** 2 * np.einsum("nik,njk->nij", Jq, Jq)
    l00 = np.sqrt(S[:, 0, 0])
    l10 = S[:, 1, 0] / l00
    l11 = np.sqrt(np.maximum(S[:, 1, 1] - l10 * l10, 1e-300))
    W = np.zeros((n, 2, 2))
    W[:, 0, 0] = 1.0 / l00
    W[:, 1, 0] = -l10 / (l00 * l11)
    W[:, 1, 1] = 1.0 / l11
    return W


def _apply(W: Array | None, e: Array) -> Array:
    """Whitened residual vectors (n, 2) (residuals in mm when unweighted)."""
    if W is None:
        return 1e3 * e
    return np.asarray(np.einsum("nij,nj->ni", W, e))


def _apply_jac(W: Array | None, J: Array) -> Array:
    if W is None:
        return 1e3 * J
    return np.asarray(np.einsum("nij,njk->nik", W, J))


def _nearer(p: Array, readings: Array, measured: Array) -> tuple[Array, Array]:
    """For each row the assembly (+1/-1) whose prediction with ``p`` is nearer the measured
    point, and the mask of rows whose rods meet."""
    ku, kd = closure_of(p, readings, 1), closure_of(p, readings, -1)
    du = np.hypot(*(predict_of(p, ku) - measured).T)
    dd = np.hypot(*(predict_of(p, kd) - measured).T)
    return np.where(du <= dd, 1, -1), ~ku.open


def _resolve_frame(p: Array, data: PoseData, frame: str, usable: Array) -> tuple[Array, Array]:
    """The registered frame (into ``p``) and the assembly of each row (0 where unusable)."""
    given = data.assembly != 0
    p = p.copy()
    if frame == "robot":
        near, _ = _nearer(p, data.readings, data.points)
        return p, np.where(given, data.assembly, np.where(usable, near, 0))
    rows = np.flatnonzero(usable)
    if len(rows) < 2:
        raise ParameterError(f"{data.source}: fewer than 2 rows the nominal robot can "
                             "assemble: the instrument frame cannot be registered")
    R, M = data.readings[rows], data.points[rows]
    k = {s: closure_of(p, R, s) for s in (1, -1)}

    def fit_frame(a: Array) -> tuple[Array, float]:
        P = np.where(a[:, None] > 0, k[1].P, k[-1].P)
        x0, y0, th = register(P, M)
        q = p.copy()
        q[7:] = (x0, y0, th)
        e = P @ rotation(th).T + q[7:9] - M
        return q, float((e * e).sum())

    g = data.assembly[rows]
    trials = [np.where(g != 0, g, s) for s in (1, -1)]
    fits = [fit_frame(t) for t in trials]
    best = int(np.argmin([f[1] for f in fits]))
    a, p = trials[best], fits[best][0]
    for _ in range(20):  # the nearer assembly in the frame, the frame of the assemblies
        near, _ok = _nearer(p, R, M)
        new = np.where(g != 0, g, near)
        if np.array_equal(new, a):
            break
        a = new
        p = fit_frame(a)[0]
    out = np.zeros(len(data), int)
    out[rows] = a
    return p, out


def _variable_scales(p: Array) -> Array:
    """Scales of the fit's variables (10,): 1 mm for a length, the angle that moves the
    end-effector 1 mm for an angle (SI)."""
    reach = 0.5 * float(p[0] + p[2] + p[1] + p[3])
    return np.array([1e-3 if n in LENGTHS else 1e-3 / reach for n in NAMES])


@dataclass(frozen=True)
class _Fit:
    p: Array
    status: int
    message: str
    nfev: int


def _solve(p0: Array, free: Sequence[int], R: Array, M: Array, a: Array, W: Array | None,
           *, loss: str = "linear", f_scale: float = 1.0, max_nfev: int = 200) -> _Fit:

    S = _variable_scales(p0)[list(free)]
    idx = list(free)

    def params(z: Array) -> Array:
        p = p0.copy()
        p[idx] += S * z
        return p

    def fun(z: Array) -> Array:
        p = params(z)
        k = closure_of(p, R, a)
        return _apply(W, predict_of(p, k) - M).reshape(-1)

    def jac(z: Array) -> Array:
        p = params(z)
        k = closure_of(p, R, a)
        return (_apply_jac(W, jacobian_of(p, k)[:, :, idx]) * S).reshape(-1, len(idx))

    method = "lm" if loss == "linear" else "trf"
    with np.errstate(all="ignore"):
        r = optimize.least_squares(fun, np.zeros(len(idx)), jac=jac, method=method, loss=loss,
                          f_scale=f_scale, xtol=1e-12, ftol=1e-12, gtol=1e-12,
                          max_nfev=max_nfev)
    p = params(r.x)
    ok = r.status > 0 and bool(np.isfinite(r.x).all())
    msg = str(r.message) if ok else f"the least-squares solver stopped: {r.message}"
    return _Fit(p, 0 if ok else 1, msg, int(r.nfev))


def _robust_scale(d: Array) -> float:
    """Per-axis standard deviation of isotropic 2-D residuals from their distances (n,)."""
    return float(np.median(d) / RAYLEIGH_MEDIAN) if d.size else 0.0


def _mm(v: float) -> str:
    return f"{1e3 * v:.4g} mm"


def _spread(P: Array) -> float:
    """RMS distance of points (n, 2) about their centre."""
    return float(np.sqrt(((P - P.mean(axis=0)) ** 2).sum(axis=1).mean()))


def check_scale(data: PoseData, nominal: KinematicModel) -> None:
    """Raise :class:`ParameterError` when the measured points are not millimetres of the
    nominal robot: their spread about their centre (any frame: a rigid motion keeps it)
    against that of the nominal robot's predictions at the same readings, in the rows'
    assembly (those not given up for all, or down for all: the nearer counts), is off by
    more than :data:`SCALE_FACTOR`; the unit the points look written in is named (metres,
    centimetres, inches, micrometres). Fewer than 3 rows the nominal robot assembles are
    not checked here."""
    p = nominal.vector()
    spreads = []  # (assembly of the rows not given, measured spread, predicted spread)
    for s in ((1, -1) if (data.assembly == 0).any() else (1,)):
        k = closure_of(p, data.readings, np.where(data.assembly != 0, data.assembly, s))
        ok = ~k.open
        pred = _spread(k.P[ok]) if ok.sum() >= 3 else 0.0
        if pred > 0.0:
            spreads.append((s, _spread(data.points[ok]), pred))
    if not spreads or min(abs(math.log(max(m, 1e-300) / q)) for _, m, q in spreads
                          ) <= math.log(SCALE_FACTOR):
        return
    _, meas, pred = spreads[0]
    r = meas / pred
    other = "".join(f" ({1e3 * q:.4g} mm with the rows of no assembly down)"
                    for a, _, q in spreads[1:] if abs(q / pred - 1.0) > 0.01)
    unit = next(((f, u) for f, u in SCALE_UNITS if abs(math.log(r / f)) < math.log(1.5)),
                None)
    if unit is not None:
        x, y = (1e3 * v for v in data.points[0])
        f, name = unit
        why = (f"x_mm, y_mm look written in {name} (row {int(data.rows[0])}: {x:.6g}, "
               f"{y:.6g}; in millimetres {x / f:.6g}, {y / f:.6g}): write them in millimetres")
    else:
        why = ("they are not millimetres of this robot: check the units of x_mm, y_mm, that "
               "phi_deg, psi_deg are degrees, and the config's [robot]")
    raise ParameterError(
        f"{data.source}: the measured points spread {1e3 * meas:.4g} mm RMS about their "
        f"centre, the nominal robot's predictions at their readings {1e3 * pred:.4g} mm"
        f"{other}: {r:.3g} times, beyond the factor {SCALE_FACTOR:g} allowed: {why}")


# ----------------------------------------------------------------------------- calibrate
def calibrate(data: PoseData, nominal: KinematicModel, *, frame: str = "instrument",
              fit: Sequence[str] | None = None, robust: str | None = None,
              outlier_factor: float = OUTLIER_FACTOR, point_std: float | None = None,
              reading_std: float | None = None, validation: PoseData | None = None,
              allow_coupled: bool = False, max_nfev: int = 200) -> CalibrationResult:
    """Calibrate ``nominal`` from measured poses (see the module doc for the steps).

    Parameters
    ----------
    data : PoseData
        Encoder readings (rad) and measured points (m) of each pose.
    nominal : KinematicModel
        The nominal robot and encoder offsets (its frame is ignored: registered from the
        data, or zero in the robot frame).
    frame : {"instrument", "robot"}
        The frame of the measured points: the instrument's (anywhere; ``x0, y0, theta0``
        are parameters) or the robot's.
    fit : sequence of str, optional
        The free parameters (default all ten, or the seven of the robot in the robot
        frame); the others stay nominal.
    robust : {"soft_l1", "huber", "cauchy", "arctan"}, optional
        A robust loss: rows beyond ``outlier_factor`` residual scales are rejected, listed
        in ``rejected`` and the rest refitted; without one such rows are an error.
    outlier_factor : float
        The multiple of the per-axis residual scale beyond which a row is an outlier.
    point_std : float, optional
        The instrument's standard deviation per axis (m), for rows without ``sigma``;
        with it (or ``data.sigma``) the fit is weighted and the residuals are tested.
    reading_std : float, optional
        Standard deviation of an encoder reading (rad), e.g. :func:`encoder_std`; used with
        a stated point noise to weight each row by its whole covariance.
    validation : PoseData, optional
        Held-out poses for the errors before and after calibration.
    allow_coupled : bool
        Accept poses of a single working mode that leave parameters coupled (a warning).
    max_nfev : int
        Most residual evaluations of a least-squares solve.

    Returns
    -------
    CalibrationResult

    Raises
    ------
    ParameterError
        An unknown option, fewer poses than twice the identifiable parameters, a row not in
        its stated working mode; :class:`OutlierError` (rows listed) and
        :class:`CouplingError` (parameters named) are ParameterErrors.
    AssemblyError
        A row whose distal rods cannot meet even with the fitted parameters.
    ReachError
        A measured point neither the nominal nor the fitted robot reaches in its mode.
    """
    o = _options(frame, fit, robust, outlier_factor, point_std, reading_std, max_nfev)
    check_scale(data, nominal)
    if validation is not None:
        check_scale(validation, nominal)
    p_nom = nominal.vector()
    if frame == "robot":
        p_nom[7:] = 0.0
    sigma = data.sigma if data.sigma is not None else (
        None if point_std is None else np.full(len(data), float(point_std)))
    # 1. assembly modes and frame (rows the nominal robot cannot assemble wait for the fit)
    _, usable = _nearer(p_nom, data.readings, data.points)
    p_start, assembly = _resolve_frame(p_nom, data, frame, usable)
    try:
        f = _fit(p_start, data, assembly, sigma, o)
        r = _checked_residuals(f, p_nom, o)
    except (AssemblyError, ReachError, ParameterError) as exc:
        _blame(p_start, p_nom, data, assembly, sigma, o, exc)  # the rows at fault, if known
        raise
    if f.fit.status != 0:
        _blame(p_start, p_nom, data, assembly, sigma, o)
    warnings = ([] if f.fit.status == 0 else
                ["reach and outlier checks skipped: the fit did not converge"])
    cov, s2, rss, dof = _covariance(r)
    corr = correlation(cov)
    warnings += _coupling(corr, f.ident, r.d, allow_coupled)
    ident_names = f.ident.identifiable
    obs = observability(r.J, ident_names, characteristic_scales(nominal.robot))
    chi2, status, message = _chi_square(f, rss, dof, s2)
    e_before = r.d.points - predict_of(p_start, closure_of(p_start, r.d.readings,
                                                           r.d.assembly))
    errors = Errors.of(e_before, r.e, r.d.rows)
    if status == 0:
        message = (f"calibrated {len(ident_names)} parameters from {len(r.d)} poses: RMS "
                   f"error {_mm(errors.rms_after)} (nominal robot {_mm(errors.rms_before)})")
    if obs.condition_number > 1e4:
        warnings.append(f"condition number {obs.condition_number:.3g} of the scaled "
                        "identification Jacobian: some parameters are poorly determined")
    p = f.fit.p
    params = _parameters(o.model_names, ident_names, p_start, p,
                         np.sqrt(np.clip(np.diag(cov), 0.0, None)))
    before_model = KinematicModel.from_vector(p_start)
    calibrated = KinematicModel.from_vector(p)
    val = None if validation is None else validation_errors(validation, before_model,
                                                            calibrated)
    not_ident = f.ident.not_identifiable
    return CalibrationResult(
        status, message, nominal, before_model, calibrated, frame, params, ident_names,
        not_ident, {x: f.ident.combinations[x] for x in not_ident}, cov, corr, obs, f.data,
        f.use, f.rejected, errors, val, math.sqrt(s2) * (1.0 if f.W is not None else 1e-3),
        chi2, f.fit.nfev, tuple(warnings))


# ------------------------------------------------------------------ the steps of calibrate
@dataclass(frozen=True)
class _Options:
    """The checked options of :func:`calibrate` (``free``: the free parameters)."""

    model_names: tuple[str, ...]
    free: tuple[str, ...]
    robust: str | None
    outlier_factor: float
    reading_std: float | None
    max_nfev: int


def _options(frame: str, fit: Sequence[str] | None, robust: str | None,
             outlier_factor: float, point_std: float | None, reading_std: float | None,
             max_nfev: int) -> _Options:
    """The options of :func:`calibrate`, checked (:class:`ParameterError` naming the one
    that is wrong)."""
    if frame not in ("instrument", "robot"):
        raise ParameterError(f"frame {frame!r} must be 'instrument' or 'robot'")
    if robust is not None and robust not in ROBUST_LOSSES:
        raise ParameterError(f"robust loss {robust!r} is not one of {', '.join(ROBUST_LOSSES)}")
    if not (math.isfinite(outlier_factor) and outlier_factor > 1.0):
        raise ParameterError(f"outlier factor {number_words(outlier_factor)} must be a number "
                             "above 1")
    for name, v in (("point_std", point_std), ("reading_std", reading_std)):
        if v is not None and not (math.isfinite(v) and v > 0):
            raise ParameterError(f"{name} = {v!r} must be positive and finite")
    model_names = NAMES if frame == "instrument" else ROBOT
    free_names = tuple(model_names if fit is None else fit)
    unknown = [n for n in free_names if n not in model_names]
    if unknown:
        raise ParameterError(f"cannot fit {', '.join(unknown)}: the parameters of the "
                             f"{frame} frame are {', '.join(model_names)}")
    return _Options(model_names, free_names, robust, outlier_factor, reading_std, max_nfev)


@dataclass(frozen=True)
class _Fitted:
    """The final fit (its ``p`` with ``theta0`` wrapped), the whitening of the rows it used
    (``use``: kept and assembled), what they identify, the poses with their assembly
    resolved, the rows the robust loss rejected."""

    fit: _Fit
    W: Array | None
    ident: Identifiability
    data: PoseData
    use: Array
    rejected: tuple[int, ...]

    def kept_rows(self, data: PoseData) -> Array:
        """Rows of ``data`` (n,) bool not rejected by the robust loss."""
        return ~np.isin(data.rows, np.asarray(self.rejected, dtype=int))


def _fit(p: Array, data: PoseData, assembly: Array, sigma: Array | None,
         o: _Options) -> _Fitted:
    """Steps 2 to 4 of the module doc from the start ``p``: with a robust loss its
    rejections first; then rows the start could not assemble (``assembly`` 0) take their
    assembly under the fitted parameters and the fit is repeated once with them."""
    assembly = assembly.copy()
    kept = np.ones(len(data), bool)
    rejected: tuple[int, ...] = ()
    for _round in range(2):
        if o.robust is not None:
            p, kept, rejected = _robust_pass(p, data, assembly, kept, sigma, o, o.robust)
        use = kept & (assembly != 0)
        sol, W, ident = _plain_pass(p, data.subset(use), assembly[use],
                                    None if sigma is None else sigma[use], o, rejected)
        p = sol.p
        waiting = kept & (assembly == 0)
        if not waiting.any():
            break
        assembly[waiting] = _assembly_of_waiting(p, data.subset(waiting))
    if not -math.pi < p[9] <= math.pi:
        p[9] = float(wrap(np.asarray(p[9])))
    resolved = PoseData(data.readings, data.points, data.modes,
                        np.where(assembly != 0, assembly, data.assembly), data.sigma,
                        data.rows, data.source)
    return _Fitted(sol, W, ident, resolved, kept & (assembly != 0), rejected)


def _blame(p: Array, p_nom: Array, data: PoseData, assembly: Array, sigma: Array | None,
           o: _Options, error: DextarError | None = None) -> None:
    """When the fit of every row failed (a row that does not assemble or is not in its mode
    with the fitted parameters, a point out of reach, outliers, no convergence), the rows at
    fault: raise :class:`OutlierError` naming the rows a robust fit (soft_l1, from the start
    ``p``) rejects when the others then calibrate cleanly (converged, every check passed);
    return when there are none (the caller's error stands) or a robust loss was asked for
    already, or the caller's ``error`` is a point out of reach of the very rows at fault
    (it says more). One bad row (an assembly or a point mistyped) drags the plain fit, so
    that a good row may fail its checks first: the error would blame it."""
    if o.robust is not None:
        return
    ro = replace(o, robust="soft_l1")
    try:
        g = _fit(p, data, assembly, sigma, ro)
        r = _checked_residuals(g, p_nom, ro)
    except DextarError:
        return
    if g.fit.status != 0 or not g.rejected:
        return
    q = g.fit.p
    bound = o.outlier_factor * _robust_scale(np.hypot(*r.e.T))
    out = np.array([i for i in np.flatnonzero(~g.kept_rows(data))
                    if _row_distance(q, data, int(i), int(g.data.assembly[i])) > bound], int)
    if not out.size:  # rejected by the robust solves, but the clean fit predicts them
        return
    out = out[np.argsort([-_row_distance(q, data, int(i), int(g.data.assembly[i]))
                          for i in out], kind="stable")]
    if isinstance(error, OutOfReachError) and set(error.rows) == set(data.rows[out]):
        return
    words = [f"{int(data.rows[i])} ({_row_hint(q, data, int(i), int(g.data.assembly[i]), bound)})"
             for i in out[:5]]
    more = f" and {len(out) - 5} more" if len(out) > 5 else ""
    them = "it" if len(out) == 1 else "them"
    # the rows the robust solves set aside too, which the fit of the others predicts within
    # the bound: named, so that the rows counted add up (row 21 named alone beside a fit over
    # 37 rows of 40)
    named = {int(i) for i in out}
    aside = [int(i) for i in np.flatnonzero(~g.kept_rows(data)) if int(i) not in named]
    also = ""
    if aside:
        near = [f"{int(data.rows[i])} ({_mm(_row_distance(q, data, i, int(g.data.assembly[i])))} "
                "from its prediction)" for i in aside[:5]]
        listed = (", ".join(near) + f" and {len(aside) - 5} more" if len(aside) > 5 else
                  " and ".join([", ".join(near[:-1]), near[-1]] if len(near) > 1 else near))
        also = (f"; that fit also left out row{'s' if len(aside) > 1 else ''} {listed}, within "
                "the bound")
    raise OutlierError(
        f"{data.source}: row{'s' if len(out) > 1 else ''} {', '.join(words)}{more} "
        f"disagree{'s' if len(out) == 1 else ''} with the others, which calibrate without "
        f"{them} (RMS error {_mm(_rms(np.hypot(*r.e.T)))} over {len(r.d)} rows, outlier "
        f"bound {_mm(bound)}{also}): correct or remove {them}, or calibrate with a robust "
        "loss", tuple(int(data.rows[i]) for i in out))


def _row_distance(p: Array, data: PoseData, i: int, a: int) -> float:
    """Distance (m) of row ``i``'s measured point from its prediction under ``p`` in
    assembly ``a`` (up when 0); infinite where the rods cannot meet."""
    k = closure_of(p, data.readings[i:i + 1], np.array([a if a != 0 else 1]))
    return math.inf if k.open[0] else float(np.hypot(*(predict_of(p, k) - data.points[i])[0]))


def _row_hint(p: Array, data: PoseData, i: int, a: int, bound: float) -> str:
    """What is wrong with row ``i`` (assembly ``a``) under the parameters ``p``: its distance
    from the prediction and, when its assembly was given and the other one predicts it
    within ``bound`` (m) in its stated working mode, that the assembly given is wrong."""
    dist = _row_distance(p, data, i, a)
    far = ("its rods cannot meet" if math.isinf(dist) else
           f"{_mm(dist)} from its prediction")
    if data.assembly[i] == 0:
        return far
    other = -int(data.assembly[i])
    d_other = _row_distance(p, data, i, other)
    ko = closure_of(p, data.readings[i:i + 1], np.array([other]))
    mode_ok = (ko.working_mode()[0] == np.array(parse_working_mode(data.modes[i]))).all()
    if d_other <= bound and mode_ok:
        given, alt = ("up", "down") if data.assembly[i] > 0 else ("down", "up")
        return (f"assembly {given} as given: {far}; in assembly {alt} {_mm(d_other)}: "
                "its assembly is wrong?")
    return far


def _robust_pass(p: Array, data: PoseData, assembly: Array, kept: Array, sigma: Array | None,
                 o: _Options, loss: str) -> tuple[Array, Array, tuple[int, ...]]:
    """Two robust solves on the kept, assembled rows (the loss's scale from the residuals
    before each); the rows beyond ``o.outlier_factor`` residual scales after them are no
    longer kept: ``(p, kept (n,) bool, rejected row numbers)``."""
    use = kept & (assembly != 0)
    d, a = data.subset(use), assembly[use]
    W = _whitening(None if sigma is None else sigma[use], o.reading_std,
                   jacobian_of(p, closure_of(p, d.readings, a))[:, :, 5:7])
    ident = identifiability(_apply_jac(W, jacobian_of(p, closure_of(p, d.readings, a))),
                            o.free)
    fidx = [INDEX[x] for x in ident.identifiable]
    _enough(len(d), len(fidx), d.source, ())

    def dist(q: Array) -> Array:
        return np.asarray(np.hypot(*_apply(W, predict_of(q, closure_of(q, d.readings, a))
                                          - d.points).T))

    for factor_scale in (3.0, 2.0):
        scale = max(_robust_scale(dist(p)), 1e-12)
        p = _solve(p, fidx, d.readings, d.points, a, W, loss=loss,
                   f_scale=factor_scale * scale, max_nfev=o.max_nfev).p
    e = dist(p)
    kept = kept.copy()
    kept[np.flatnonzero(use)[e > o.outlier_factor * _robust_scale(e)]] = False
    return p, kept, tuple(int(v) for v in data.rows[~kept])


def _plain_pass(p: Array, d: PoseData, a: Array, sigma: Array | None, o: _Options,
                rejected: tuple[int, ...]) -> tuple[_Fit, Array | None, Identifiability]:
    """Whitening, identifiability and the least-squares solve on the poses ``d``."""
    k0 = closure_of(p, d.readings, a)
    J0 = jacobian_of(p, k0)
    W = _whitening(sigma, o.reading_std, J0[:, :, 5:7])
    ident = identifiability(_apply_jac(W, J0), o.free)
    fidx = [INDEX[x] for x in ident.identifiable]
    _enough(len(d), len(fidx), d.source, rejected)
    return _solve(p, fidx, d.readings, d.points, a, W, max_nfev=o.max_nfev), W, ident


def _assembly_of_waiting(p: Array, d: PoseData) -> Array:
    """The assembly (+1/-1) of rows the nominal robot could not assemble, under the fitted
    ``p``: the given one, else the one nearer the measured point; :class:`AssemblyError`
    for the first whose rods still cannot meet."""
    kw = closure_of(p, d.readings, 1)
    if kw.open.any():
        i = int(np.flatnonzero(kw.open)[0])
        raise AssemblyError(
            f"{d.source}: row {int(d.rows[i])}: the distal rods cannot "
            f"meet at readings ({math.degrees(d.readings[i, 0]):.6g}, "
            f"{math.degrees(d.readings[i, 1]):.6g}) deg, with the nominal "
            f"parameters nor with those fitted to the other rows (|B - C| "
            f"{1e3 * kw.gap[i]:.4g} mm outside the rods' range)")
    near, _ = _nearer(p, d.readings, d.points)
    return np.where(d.assembly != 0, d.assembly, near)


@dataclass(frozen=True)
class _Residuals:
    """The poses of the fit at its solution: ``d`` the poses, ``k`` their closures, ``e``
    ``measured - predicted`` (n, 2) (m), ``J`` the Jacobian (n, 2, 10), ``Jw`` the whitened
    Jacobian of the identifiable parameters (2 n, k), ``rw`` the whitened residuals (n, 2)."""

    d: PoseData
    k: Closure
    e: Array
    J: Array
    Jw: Array
    rw: Array


def _checked_residuals(f: _Fitted, p_nom: Array, o: _Options) -> _Residuals:
    """The residuals of the fit ``f``, checked (step 5 of the module doc): every row
    assembles in its stated working mode, and, when the fit converged, every measured point
    is within reach and (without a robust loss) no row is an outlier."""
    p, converged = f.fit.p, f.fit.status == 0
    kd = f.data.subset(f.use)
    k = closure_of(p, kd.readings, kd.assembly)
    k.raise_if_open(kd.rows)
    _check_modes(k, kd)
    e = kd.points - predict_of(p, k)
    if converged:
        _check_reach(p_nom, p, kd, o.outlier_factor * _robust_scale(np.hypot(*e.T)))
    J = jacobian_of(p, k)
    fidx = [INDEX[x] for x in f.ident.identifiable]
    r = _Residuals(kd, k, e, J, _apply_jac(f.W, J[:, :, fidx]).reshape(-1, len(fidx)),
                   _apply(f.W, -e))
    if o.robust is None and converged:
        _check_outliers(r, f.W is None, o.outlier_factor)
    return r


def _check_outliers(r: _Residuals, unweighted: bool, factor: float) -> None:
    """Raise :class:`OutlierError` listing the rows (farthest first) beyond ``factor``
    residual scales of their prediction."""
    dw = np.hypot(*r.rw.T)
    scale = _robust_scale(dw)
    out = dw > factor * scale
    if not out.any():
        return
    order = np.argsort(-dw[out])
    rows_out = r.d.rows[out][order]
    dist = np.hypot(*r.e[out].T)[order]
    listed = ", ".join(f"{int(row)} ({1e3 * v:.3g} mm)" for row, v in
                       zip(rows_out[:5], dist[:5], strict=True))
    more = f" and {len(rows_out) - 5} more" if len(rows_out) > 5 else ""
    scale_text = (f"{scale:.3g} mm" if unweighted else
                  f"{scale:.3g} standard deviations of the stated noise")
    raise OutlierError(
        f"{r.d.source}: row{'s' if len(rows_out) > 1 else ''} {listed}{more} "
        f"measured farther from the prediction than {factor:g} x the "
        f"residual scale ({scale_text}): remove them or calibrate with a robust loss",
        tuple(int(row) for row in rows_out))


def _covariance(r: _Residuals) -> tuple[Array, float, float, int]:
    """Step 6 of the module doc: the covariance ``s^2 (J^T J)^-1`` of the identifiable
    parameters, ``s^2``, the residual sum of squares and the degrees of freedom."""
    dof = max(r.rw.size - r.Jw.shape[1], 1)
    rss = float((r.rw * r.rw).sum())
    s2 = rss / dof
    try:
        JtJ_inv = np.linalg.inv(r.Jw.T @ r.Jw)
    except np.linalg.LinAlgError:
        JtJ_inv = np.linalg.pinv(r.Jw.T @ r.Jw)
    return s2 * JtJ_inv, s2, rss, dof


def _coupling(corr: Array, ident: Identifiability, d: PoseData,
              allow_coupled: bool) -> list[str]:
    """The warning (none or one) of parameters not identifiable or nearly combinations of
    the others (multiple correlation at least :data:`COUPLING_LIMIT`); for poses ``d`` of a
    single working mode a :class:`CouplingError` unless ``allow_coupled``."""
    names, not_ident = ident.identifiable, ident.not_identifiable
    mult = multiple_correlation(corr)
    coupled = [names[i] for i in np.argsort(-mult) if mult[i] >= COUPLING_LIMIT]
    if not (coupled or not_ident):
        return []
    what = "; ".join([*(ident.combinations[x] for x in not_ident),
                      *([", ".join(f"{x} ({mult[names.index(x)]:.5f})" for x in coupled[:4])
                         + (f" and {len(coupled) - 4} more" if len(coupled) > 4 else "")
                         + " nearly combinations of the others (multiple correlation)"]
                        if coupled else [])])
    if len(set(d.modes)) != 1:
        return [f"parameters coupled by these poses: {what}; not identifiable ones kept "
                "nominal"]
    text = (f"{d.source}: poses of the single working mode {d.modes[0]} leave "
            f"parameters coupled: {what}; measure poses in other working modes too "
            "(all four: dextar poses --modes all)")
    if not allow_coupled:
        raise CouplingError(text, tuple(dict.fromkeys([*not_ident, *coupled])))
    return [text]


def _chi_square(f: _Fitted, rss: float, dof: int, s2: float) -> tuple[float | None, int, str]:
    """The reduced chi-square of a weighted fit (None unweighted), and the status and message
    of the fit ``f``: status 2 when it converged but the residuals fail the chi-square test
    at :data:`CHI2_ALPHA`."""
    status, message = f.fit.status, f.fit.message
    if f.W is None:
        return None, status, message

    pval = float(stats.chi2.sf(rss, dof))
    if status == 0 and pval < CHI2_ALPHA:
        return s2, 2, (f"the residuals are {math.sqrt(s2):.3g} times what the stated noise "
                       f"explains (chi-square p = {pval:.2g}): the model misses something (a "
                       "parameter held fixed, a wrong mode or assembly, play in a joint)")
    return s2, status, message


def _parameters(model_names: Sequence[str], ident_names: Sequence[str], p_start: Array,
                p: Array, std: Array) -> tuple[Parameter, ...]:
    """The model's parameters: nominal (``p_start``), fitted (``p``) and, for the
    identifiable ones, the standard deviation ``std`` (in the order of ``ident_names``)."""
    params = []
    for name in model_names:
        i = INDEX[name]
        known = name in ident_names
        params.append(Parameter(name, "m" if name in LENGTHS else "rad", float(p_start[i]),
                                float(p[i]),
                                float(std[ident_names.index(name)]) if known else None,
                                known))
    return tuple(params)


def _enough(m: int, k: int, source: str, rejected: tuple[int, ...]) -> None:
    if m < 2 * k:
        after = (f" left after rejecting row {rows_text(np.asarray(rejected))}"
                 if rejected else "")
        raise ParameterError(f"{source}: {m} poses{after}, fewer than twice the {k} "
                             f"identifiable parameters ({2 * k} needed)")


def _check_modes(k: Closure, d: PoseData) -> None:
    """Raise :class:`ParameterError` for the first row not in its stated working mode."""
    want = np.array([parse_working_mode(m) for m in d.modes]).reshape(-1, 2)
    got = k.working_mode()
    bad = ~(got == want).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        sgn = "".join("+" if s > 0 else "-" if s < 0 else "0" for s in got[i])
        raise ParameterError(
            f"{d.source}: row {int(d.rows[i])}: readings ({math.degrees(d.readings[i, 0]):.6g}, "
            f"{math.degrees(d.readings[i, 1]):.6g}) deg put the calibrated robot in working "
            f"mode {sgn}, not {d.modes[i]}, the working mode given for it")


def _check_reach(p_nom: Array, p: Array, d: PoseData, slack: float) -> None:
    """Raise :class:`ReachError` for the first measured point (in the robot frame of the
    fit) that neither the nominal nor the fitted robot reaches by more than ``slack`` (m;
    a point measured at a stretched leg may fall out of reach by its noise)."""
    Pr = (d.points - p[7:9]) @ rotation(float(p[9]))
    fails = []
    for q in (p_nom, p):
        half = 0.5 * q[4]
        out = np.zeros(len(Pr), bool)
        worst = np.zeros((len(Pr), 2))
        for leg, (cx, l, L) in enumerate(((half, q[0], q[2]), (-half, q[1], q[3]))):
            rho = np.hypot(Pr[:, 0] - cx, Pr[:, 1])
            over = np.maximum(np.maximum(abs(l - L) - rho, rho - (l + L)), 0.0)
            worst[:, leg] = over
            out |= over > slack + 1e-12 * (l + L)
        fails.append((out, worst))
    bad = fails[0][0] & fails[1][0]
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        leg = int(np.argmax(fails[1][1][i])) + 1
        raise OutOfReachError(
            f"{d.source}: row {int(d.rows[i])}: the measured point ({1e3 * Pr[i, 0]:.6g}, "
            f"{1e3 * Pr[i, 1]:.6g}) mm (robot frame) is out of reach of leg {leg} of the "
            f"nominal robot and of the fitted one (by {1e3 * fails[1][1][i, leg - 1]:.4g} mm, "
            f"more than {1e3 * slack:.3g} mm, the outlier bound) in working mode {d.modes[i]}",
            (int(d.rows[i]),))


def validation_errors(data: PoseData, before: KinematicModel,
                      after: KinematicModel) -> Errors:
    """Errors of the models ``before`` and ``after`` calibration on held-out poses (rows
    without an assembly mode take the one nearer under ``before``).

    Raises
    ------
    AssemblyError
        A row either model cannot assemble.
    """
    pb, pa = before.vector(), after.vector()
    near, _ = _nearer(pb, data.readings, data.points)
    a = np.where(data.assembly != 0, data.assembly, near)
    kb, ka = closure_of(pb, data.readings, a), closure_of(pa, data.readings, a)
    for kk in (kb, ka):
        if kk.open.any():
            i = int(np.flatnonzero(kk.open)[0])
            raise AssemblyError(f"{data.source}: row {int(data.rows[i])}: the distal rods "
                                "cannot meet at its readings")
    return Errors.of(data.points - predict_of(pb, kb), data.points - predict_of(pa, ka),
                     data.rows)


def encoder_std(counts: float) -> float:
    """Standard deviation (rad) of a reading quantised to ``counts`` per turn:
    ``2 pi / counts / sqrt(12)``."""
    if not (math.isfinite(counts) and counts > 0):
        raise ParameterError(f"encoder counts {counts!r} must be a positive number")
    return 2.0 * math.pi / counts / math.sqrt(12.0)


@dataclass(frozen=True)
class Diagnosis:
    """A calibration, or the diagnosis of data with outliers.

    Attributes
    ----------
    result : CalibrationResult
        The fit: the calibration asked for or, where outliers stopped it, the fit that keeps
        them (a diagnosis: their distances and arrows, never a calibrated robot).
    outliers : tuple of int
        The outliers' rows as the user counts them (empty for a calibration).
    message : str
        The outliers' error in words (empty for a calibration).
    """

    result: CalibrationResult
    outliers: tuple[int, ...] = ()
    message: str = ""


def calibrate_or_diagnose(data: PoseData, nominal: KinematicModel, *,
                          frame: str = "instrument", robust: str | None = None,
                          outlier_factor: float | None = None,
                          point_std: float | None = None, reading_std: float | None = None,
                          validation: PoseData | None = None) -> Diagnosis:
    """:func:`calibrate`; where it finds outliers (without a robust loss), the fit that keeps
    them with their rows and the error's words instead of the error; where that fit fails
    its own checks (rows that wreck it), the outliers' error, suggesting a robust loss."""
    def fit(factor: float) -> CalibrationResult:
        return calibrate(data, nominal, frame=frame, robust=robust, outlier_factor=factor,
                         point_std=point_std, reading_std=reading_std, validation=validation)

    try:
        return Diagnosis(fit(OUTLIER_FACTOR if outlier_factor is None else outlier_factor))
    except OutlierError as exc:
        try:
            return Diagnosis(fit(1e300), exc.rows, str(exc))
        except DextarError:
            raise OutlierError(f"{exc} (--robust soft_l1)", exc.rows) from None
