"""Identification of the base parameters from measured motion, with a verdict on the fit.

Steps of :func:`identify` (each a small function below):

1. **Checks** (:mod:`dextar.identification.modes`): every row in the working mode and the
   model's assembly mode, the rods able to meet; a plausible time base
   (:func:`~dextar.identification.verdict.check_time_base`: "time in milliseconds?").
2. **Conditioning** (:mod:`dextar.identification.filtering`): a state filter for the angles
   and their derivatives, a parallel filter and decimation for the regressor and the
   torques, both chosen from the sample rate and the measured motion; the rows of each motor
   whose friction sign the data cannot tell are left out.
3. **Base regressor** (:mod:`dextar.identification.base`) and its conditioning in these data
   (columns scaled to unit norm); a rank-deficient regressor is refused, naming the
   parameter combinations the data cannot tell apart.
4. **Weighted least squares**: ordinary least squares, each motor's residual variance, then
   the rows of each motor weighted by the inverse of its residual standard deviation; the
   standard deviations of the estimates from an autocorrelation-consistent covariance.
5. **Physical consistency** in the full sense (:func:`physical_set`): a set of standard
   parameters with exactly these base parameters is sought closest to the prior, with every
   rod's mass not negative and at most :data:`MASS_BOUND` times the prior's heaviest body,
   its centre of mass within its length of its joint, its inertia at least ``m c^2``
   (pseudo-inertia positive semi-definite; the proximal rods' masses, which the torques do
   not see, are variables), friction not negative, the point mass at least the payload;
   when none exists the fit is redone as least squares constrained to physical parameters
   (``method = "constrained"``), and the least-squares estimate's Mahalanobis distance to
   it, ``unphysical_distance``, tells whether the data contradict physics or scatter about
   it.
6. **Verdict from what the model is for** (:mod:`dextar.identification.verdict` computes the
   figures): status 0 "identified" only when

   a. the **predicted-torque uncertainty** (the parameter covariance propagated to a
      reference motion: the task given, else the recorded motion itself, so that the verdict
      covers motions like it; RMS standard deviation over RMS torque) is at most
      :data:`UNCERTAINTY_LIMIT` on both motors, and the condition number at most
      :data:`COND_WARNING`; else 1 "poorly determined";
   b. the **residual is what noise and filters explain**: ``fit_quality`` (RMS residual /
      RMS torque) at most :data:`RESIDUAL_FACTOR` times ``explained_quality``, the torque
      noise after the parallel filter (from the torques' spectrum floor) over the RMS
      torque, combined with :data:`RESIDUAL_FLOOR`; and the identified torques within
      :data:`TORQUE_SCALE` of the prior's; else 3 "poor fit" (above :data:`POOR_FIT` the
      likely causes named are another robot's);
   c. the model is **physical**: a physical set reproduces the base parameters, and the
      least-squares estimate lies within :data:`PHYSICAL_SIGMAS` standard deviations of
      one; else 2 "not physically consistent".

   Every reason is named (``reasons``; the message has the worst first); base parameters
   whose relative standard deviation exceeds :data:`REL_STD_FLAG` are listed in
   ``poorly_determined``.

How the thresholds were chosen (``benchmarks/bench_identify_verdicts.py``: issue 28's
80/75/95/92/58 mm robot with gravity tilted 9.4 deg and dry friction, MuJoCo's robot under a
100 Hz PD loop, 15 s excitations at seeds 0-4, 17-bit angles unless said; the errors are the
identified model's on an unseen min-jerk line and arc, % of their RMS torque):

* :data:`RESIDUAL_FLOOR` 1 % and :data:`RESIDUAL_FACTOR` 2 (2 % without torque noise):
  good fits without torque noise reach 0.07-0.28 % (14-bit angles 0.08-0.31 %; the
  pick-and-place robot's 20 MuJoCo runs 0.12 %; a flat 120/180 mm robot with dry friction
  and no gravity 0.7-1.3 %, benchmarks/bench_excite_seeds.py's); with 10-150 mN m of noise
  the fit quality is 0.93-1.07 times what is explained. Model errors below the former 20 %
  limit: the config's gravity vertical (the robot's tilted 9.4 deg) 5.4-12 % on the worse
  motor, its predictions 7-16 % wrong (on the issue's own seed-1 motion, 20 deg on motor
  D: 2.97 % / 0.65 %, 6-10 % wrong, "identified" before: the gentlest case, 1.5x the
  limit); l1 1 mm long 6.3-22 % (4.6-20 % wrong); both poor fits now. Torques 2 ms late
  (0.3-0.8 %, 0.2-0.4 % wrong) pass: their predictions stay within 0.5 %.
* :data:`UNCERTAINTY_LIMIT` 2 %: the uncertainty is a 1-sigma figure (a Monte Carlo over 12
  noise draws of the pick-and-place robot matched it to 4-7 %). Along the line and arc
  (``--task``) it follows their error: 0.25-0.43 % for 0.2-0.7 % wrong (50 mN m of noise),
  0.84-1.2 % for 0.76-1.5 % (150 mN m), 2.5 / 2.7 % for 2.6 / 2.2 % (an excitation at a
  quarter of its size, 50 mN m: "identified" before). The default reference is the
  recorded motion (the rows the fit used): over 80 cases of MuJoCo's data the model's error
  along it was 0.46-1.51 times the figure, 0.22-0.48 % with 50 mN m of noise. The former
  default, the excitation's envelope (every visited pose with each motor's speed and
  acceleration drawn up to their peaks), read 1.0-4.6 % there (errors 0.2-0.7 %) and called
  good fits "poorly determined". Neither sees a task outside the excitation (the quarter-size
  motion: 0.4-0.6 % along itself): give ``--task`` for the motion the model is for.
* :data:`PHYSICAL_SIGMAS` 5: good fits are physical or within 2.9 sigma of a physical set;
  the wrong gravity 2.7-10, l1 1 mm long 34-72, the time stretched 30x (the tests' data)
  26-63 sigma.

The former :data:`POOR_FIT` (``benchmarks/bench_identify_mujoco.py``): wrong priors leave
64 % and more (gravity left out 71 % / 72 %, the default DexTAR 81 % / 84 %, torques of the
other sign 80 % / 64 %, motors swapped 17-52 %); it now only picks the likely causes named.
Torques in mN m fit as well as in N m by least squares, but 1060 to 1090 times the prior's
torques (good fits: 1.05 to 1.10): status 3 through :data:`TORQUE_SCALE`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics.exact import Model
from ..dynamics.inertia import Inertia, Rod
from ..dynamics.regressor import INDEX, STANDARD, standard_parameters
from ..errors import NumericalError, ParameterError
from ..geometry import FiveBar
from .base import BaseParameters, base_parameters
from .coverage import Coverage, coverage
from .data import MotionData
from .filtering import Conditioned, Filters, condition, default_cutoff
from .modes import check_modes
from .verdict import (
    check_time_base,
    describe_motion,
    prediction_uncertainty,
    recorded_motion,
    torque_noise,
)

optimize = lazy_module("scipy.optimize")

__all__ = ["COND_WARNING", "Conditioned", "Filters", "IdentificationResult", "POOR_FIT",
           "STATUS", "Validation", "check_modes", "condition", "default_cutoff", "identify",
           "physical_set", "realise", "validate"]

#: Condition number above which the summary warns that the data excite badly.
COND_WARNING = 1e3
#: Samples (after decimation) needed per base parameter.
SAMPLES_PER_PARAMETER = 5
#: Lags (decimated samples) of the autocorrelation-consistent covariance.
HAC_LAGS = 4
#: Fit quality (RMS residual over RMS torque) above which an unexplained residual is taken
#: for another robot's (the likely causes named).
POOR_FIT = 0.2
#: Largest ratio between the identified and the prior's RMS torques along the data.
TORQUE_SCALE = 10.0
#: Relative standard deviation above which a base parameter is flagged.
REL_STD_FLAG = 0.5
#: Predicted-torque uncertainty (RMS std over RMS torque along the reference motion) above
#: which the model is poorly determined for its use.
UNCERTAINTY_LIMIT = 0.02
#: Fit quality that good fits of noise-free data reach (encoder quantisation, the filters,
#: the friction's regularisation): the part of the residual no torque noise explains.
RESIDUAL_FLOOR = 0.01
#: Largest ratio of the fit quality to the one noise and filters explain.
RESIDUAL_FACTOR = 2.0
#: Distance (standard deviations, Mahalanobis) beyond which a least-squares estimate that is
#: not physical contradicts physics rather than scatters about it.
PHYSICAL_SIGMAS = 5.0
#: The status codes of :class:`IdentificationResult` and their names (as summaries print them).
STATUS = {0: "identified", 1: "poorly determined", 2: "not physically consistent",
          3: "poor fit"}


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
        RMS of each motor's residual (N m), on the filtered torques of the rows used.
    sigma : ndarray, shape (2,)
        Each motor's residual standard deviation used as weight.
    n_samples, n_used : int
        Samples read and kept after decimation.
    cutoff_hz : float
        The state filter's cut-off (Hz).
    consistent : bool
        True when ``inertia`` reproduces ``beta`` to 1e-9 relative.
    status : int
        0 identified; 1 poorly determined (``uncertainty`` above :data:`UNCERTAINTY_LIMIT`
        on a motor, or ``condition_number`` above :data:`COND_WARNING`); 2 not physically
        consistent (no physical set of standard parameters has these base parameters, see
        :func:`physical_set`); 3 poor fit (``fit_quality`` above :data:`POOR_FIT` or above
        :data:`RESIDUAL_FACTOR` times ``explained_quality`` on a motor, or the torques'
        scale unlike the prior's); the estimates are computed whatever the status.
        :data:`STATUS` names them.
    message : str
    warnings : list of str
    conditioned : Conditioned, optional
        The filtered, decimated data the fit used (for plots and residuals).
    fit_quality : ndarray, shape (2,)
        ``rms_residual`` over each motor's RMS filtered torque on the same rows.
    rel_std : ndarray, shape (n_base,)
        ``std / |beta|`` (``inf`` where ``beta`` is 0).
    poorly_determined : tuple of str
        Names of the base parameters whose ``rel_std`` exceeds :data:`REL_STD_FLAG`.
    torque_scale : ndarray, shape (2,)
        RMS of the identified model's torques over the prior's, along the rows used.
    parallel_hz : float
        The parallel filter's cut-off (Hz).
    rows_used : ndarray of int, shape (2,)
        Rows of each motor in the fit (the others carry a friction sign the data cannot
        tell).
    covariance : ndarray, shape (n_base, n_base)
        Of ``beta`` (autocorrelation consistent).
    uncertainty : ndarray, shape (2,)
        Each motor's predicted-torque uncertainty along ``reference``: the RMS standard
        deviation of the predicted torques over their RMS (:func:`~dextar.identification.
        verdict.prediction_uncertainty`).
    reference : str
        The motion ``uncertainty`` is measured on: the task given, or the recorded motion
        (:func:`~dextar.identification.verdict.recorded_motion`), its poses and speeds
        named.
    torque_noise : ndarray, shape (2,)
        Standard deviation of each motor's torque noise after the parallel filter (N m).
    explained_quality : ndarray, shape (2,)
        The fit quality noise and filters explain: ``sqrt((torque_noise / RMS torque)^2 +``
        :data:`RESIDUAL_FLOOR` ``^2)``.
    reasons : tuple of str
        Every reason the status is not 0, the worst last.
    unphysical_distance : float
        How far the least-squares estimate lies from the physical set fitted instead, in
        standard deviations (the Mahalanobis distance under ``covariance``); 0 when the
        least-squares estimate is physical.
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
    fit_quality: Array = field(default_factory=lambda: np.zeros(2))
    rel_std: Array = field(default_factory=lambda: np.zeros(0))
    poorly_determined: tuple[str, ...] = ()
    torque_scale: Array = field(default_factory=lambda: np.ones(2))
    parallel_hz: float = math.nan
    rows_used: Array = field(default_factory=lambda: np.zeros(2, int))
    covariance: Array = field(default_factory=lambda: np.zeros((0, 0)))
    uncertainty: Array = field(default_factory=lambda: np.zeros(2))
    reference: str = "the recorded motion"
    torque_noise: Array = field(default_factory=lambda: np.zeros(2))
    explained_quality: Array = field(default_factory=lambda: np.zeros(2))
    reasons: tuple[str, ...] = ()
    unphysical_distance: float = 0.0

    @property
    def success(self) -> bool:
        """True when the status is 0."""
        return self.status == 0

    @property
    def status_text(self) -> str:
        """The status's name (:data:`STATUS`)."""
        return STATUS[self.status]


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
             parallel_hz: float | None = None, base: BaseParameters | None = None,
             reference: tuple[Array, Array, Array] | None = None,
             reference_name: str = "the task") -> IdentificationResult:
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
        The state filter's cut-off (default: chosen from the data, see
        :mod:`dextar.identification.filtering`).
    parallel_hz : float, optional
        The parallel filter's cut-off (default: ``cutoff_hz / 2.5``).
    base : BaseParameters, optional
        Precomputed base parameters of ``model``.
    reference : (q, dq, ddq), optional
        The motion the model is for (each (n, 2), SI): the predicted-torque uncertainty is
        measured along it (default: the recorded motion, the rows the fit used: the verdict
        then covers motions like it).
    reference_name : str
        How messages name ``reference``.

    Returns
    -------
    IdentificationResult
        Every status still carries every estimate.

    Raises
    ------
    ParameterError
        Data outside the working or assembly mode, a time column not in seconds, too few
        samples, or a rank-deficient regressor.
    """
    check_time_base(data)
    check_modes(data, model, mode)
    base = base or base_parameters(model)
    c = condition(data, model, cutoff_hz=cutoff_hz, parallel_hz=parallel_hz)
    keep = c.used
    sizes = (int(keep[:, 0].sum()), int(keep[:, 1].sum()))
    need = SAMPLES_PER_PARAMETER * base.size
    if sum(sizes) < need:
        raise ParameterError(
            f"{data.source}: {sum(sizes)} samples after filtering at {c.cutoff_hz:.3g} / "
            f"{c.parallel_hz:.3g} Hz, decimating and leaving out the rows near rest "
            f"({len(data.t)} read), fewer than {need} ({SAMPLES_PER_PARAMETER} per base "
            f"parameter, {base.size} of them): record longer, or move more")
    Yb = base.columns(c.Y)
    beta, cov, sigma, cond, Aw, bw = _weighted_fit(Yb, c.tau, keep, sizes, base, data.source)
    prior = standard_parameters(model.inertia)
    method = "weighted least squares"
    theta, ok = physical_set(beta, base, prior, model.inertia, model.robot)
    consistent = True
    distance = 0.0
    ls_pred = Yb @ beta  # the torques' scale is the least-squares fit's (a fit in another
    if not ok:           # unit is not physical: the constrained fit would hide the unit)
        method = "constrained"
        theta = _constrained_fit(Aw, bw, base, prior, model.inertia, model.robot)
        distance = _mahalanobis(beta - base.of(theta), cov)
        beta = base.of(theta)
        cov = _hac_cov(Aw, Aw @ beta - bw, sizes)  # the spread about the constrained fit
        consistent = _physical(theta, prior, model.inertia, model.robot)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    inertia = realise(theta, model.inertia, model.robot)
    if method == "constrained":  # the model written is the fit (realise may move it by
        theta = standard_parameters(inertia)  # rounding where a constraint is active)
        beta = base.of(theta)
    back = base.of(standard_parameters(inertia))
    consistent = consistent and bool(np.all(
        np.abs(back - beta) <= 1e-9 * np.maximum(np.abs(beta), 1e-12)
        + 1e-12 * np.abs(beta).max()))
    pred = Yb @ beta
    rms, quality, _ = _fit_figures(pred, c.tau, c.Y @ prior, keep)
    scale = _fit_figures(ls_pred, c.tau, c.Y @ prior, keep)[2]
    noise = torque_noise(data, c.parallel_hz)
    rms_tau = np.where(quality > 0, rms / np.where(quality > 0, quality, 1.0), math.inf)
    explained = np.sqrt((noise / np.where(rms_tau > 0, rms_tau, math.inf)) ** 2
                        + RESIDUAL_FLOOR ** 2)
    if reference is None:
        ref = recorded_motion(c)
        ref_name = f"the recorded motion ({describe_motion(ref[0], ref[1])})"
    else:
        ref, ref_name = reference, reference_name
    u_std, u_rms = prediction_uncertainty(model, base, beta, cov, *ref)
    uncertainty = np.where(u_rms > 0, u_std / np.where(u_rms > 0, u_rms, 1.0), math.inf)
    with np.errstate(divide="ignore"):
        rel = np.where(beta != 0, std / np.abs(beta), math.inf)
    flagged = tuple(n for n, r in zip(base.names, rel, strict=True) if r > REL_STD_FLAG)
    status, message, warnings, reasons = _status(
        _Findings(cond, consistent, method, flagged, quality, scale, explained, uncertainty,
                  ref_name, u_std, distance))
    consistent = consistent and distance <= PHYSICAL_SIGMAS
    return IdentificationResult(base, beta, std, theta, inertia, method, cond, rms, sigma,
                                len(data.t), len(c.t), c.cutoff_hz, consistent, status, message,
                                warnings, c, quality, rel, flagged, scale, c.parallel_hz,
                                np.array(sizes), cov, uncertainty, ref_name, noise, explained,
                                reasons, distance)


def _weighted_fit(Yb: Array, tau: Array, keep: Array, sizes: tuple[int, int],
                  base: BaseParameters, source: str
                  ) -> tuple[Array, Array, Array, float, Array, Array]:
    """Ordinary least squares, each motor's residual standard deviation, then the rows of
    each motor weighted by its inverse: the estimates, their covariance, the weights, the
    condition number and the weighted system ``(Aw, bw)``."""
    A, b = _stack(Yb, tau, np.ones(2), keep)
    _rank_check(A, base, source)
    beta0, *_ = np.linalg.lstsq(A, b, rcond=None)
    r0 = (Yb @ beta0) - tau
    sigma = np.array([np.sqrt((r0[keep[:, k], k] ** 2).sum()
                              / max(sizes[k] - base.size / 2.0, 1.0)) for k in range(2)])
    if not (sigma > 0).all():  # an exact fit of a motor: weigh both alike
        sigma = np.ones(2)
    Aw, bw = _stack(Yb, tau, sigma, keep)
    cond = _rank_check(Aw, base, source)
    beta, *_ = np.linalg.lstsq(Aw, bw, rcond=None)
    return beta, _hac_cov(Aw, Aw @ beta - bw, sizes), sigma, cond, Aw, bw


def _fit_figures(pred: Array, tau: Array, prior_pred: Array, keep: Array
                 ) -> tuple[Array, Array, Array]:
    """Per motor over the rows used: the RMS residual, the fit quality (RMS residual / RMS
    torque) and the identified torques' scale against the prior's."""
    res = pred - tau
    rms = np.array([_rms(res[keep[:, k], k]) for k in range(2)])
    rms_tau = np.array([_rms(tau[keep[:, k], k]) for k in range(2)])
    quality = np.where(rms_tau > 0, rms / np.where(rms_tau > 0, rms_tau, 1.0), math.inf)
    prior_rms = np.array([_rms(prior_pred[keep[:, k], k]) for k in range(2)])
    pred_rms = np.array([_rms(pred[keep[:, k], k]) for k in range(2)])
    scale = np.where(prior_rms > 0, pred_rms / np.where(prior_rms > 0, prior_rms, 1.0), math.inf)
    return rms, quality, scale


@dataclass(frozen=True)
class _Findings:
    """The figures a verdict is made of (see :func:`_status`)."""

    cond: float
    consistent: bool
    method: str
    flagged: tuple[str, ...]
    quality: Array
    scale: Array
    explained: Array
    uncertainty: Array
    reference: str
    uncertainty_nm: Array
    distance: float


def _status(f: _Findings) -> tuple[int, str, list[str], tuple[str, ...]]:
    """The result's status, message (every reason, the worst first), warnings and reasons."""
    warnings: list[str] = []
    reasons: list[tuple[int, str]] = []
    if f.cond > COND_WARNING:
        reasons.append((1, f"condition number {f.cond:.3g} above {COND_WARNING:g}: the data "
                           "excite poorly (dextar excite designs a better motion)"))
    if (f.uncertainty > UNCERTAINTY_LIMIT).any():
        worst = ""
        if f.flagged:
            worst = (f"; the data hardly determine {', '.join(f.flagged)} (relative std "
                     f"above {100 * REL_STD_FLAG:g} %)")
        reasons.append((1, f"poorly determined: the parameters' uncertainty makes the torques "
                           f"predicted along {f.reference} uncertain by "
                           f"{100 * f.uncertainty[0]:.3g} % / {100 * f.uncertainty[1]:.3g} % "
                           f"of their RMS ({f.uncertainty_nm[0]:.3g} / "
                           f"{f.uncertainty_nm[1]:.3g} N m, motor A / D; limit "
                           f"{100 * UNCERTAINTY_LIMIT:g} %){worst}: record longer or excite "
                           "more (dextar excite, --task for the motion the model is for)"))
    if not f.consistent:
        reasons.append((2, "not physically consistent: the physical parameter set does not "
                           "reproduce the base parameters exactly"))
    elif f.distance > PHYSICAL_SIGMAS:
        reasons.append((2, f"not physically consistent: the least-squares estimate lies "
                           f"{f.distance:.3g} standard deviations from the nearest physical "
                           f"parameters (limit {PHYSICAL_SIGMAS:g}): no set of rods with "
                           "masses not negative, centres of mass within their rods' length "
                           "of their joints and inertias of at least m c^2, with friction not "
                           "negative, explains the torques; the model written is the closest "
                           "physical fit. Likely causes: a time column or torques in another "
                           "unit, the config's geometry or gravity off, or data from another "
                           "robot"))
    if f.method == "constrained":
        warnings.append("the least-squares solution is not physical (a negative mass, "
                        "inertia or friction, or a centre of mass beyond its rod): the fit "
                        "was constrained to physical parameters")
    if f.flagged:
        warnings.append(f"base parameter{'s' if len(f.flagged) > 1 else ''} "
                        f"{', '.join(f.flagged)} {'have' if len(f.flagged) > 1 else 'has'} a "
                        f"relative standard deviation above {100 * REL_STD_FLAG:g} %: the data "
                        "hardly determine them")
    poor = _verdict(f.quality, f.scale, f.explained)
    if poor:
        reasons.append((3, poor))
    if not reasons:
        return 0, "identified", warnings, ()
    reasons.sort(key=lambda r: r[0])
    status = reasons[-1][0]
    texts = tuple(r[1] for r in reasons)
    warnings.extend(texts)
    return status, "; ".join(reversed(texts)), warnings, texts


@dataclass(frozen=True)
class Validation:
    """How an identified model predicts the torques of another motion.

    Attributes
    ----------
    rms_error, rms_error_prior : ndarray, shape (2,)
        RMS prediction error (N m) of the identified and of the prior model per motor, over
        the rows whose friction sign the data tell (at rest and at reversals static friction
        holds any torque within its Coulomb bound, which no model predicts).
    rms_torque : ndarray, shape (2,)
        RMS of the filtered torques over the same rows (N m).
    error, error_prior : ndarray, shape (2,)
        The errors relative to ``rms_torque``.
    rows_used : ndarray of int, shape (2,)
        Rows of each motor compared (of ``len(conditioned.t)``).
    coverage : Coverage
        Which validation rows lie outside the region the identification excited.
    conditioned : Conditioned
        The validation data, conditioned with the identification's filters.
    warnings : list of str
        The coverage's warning, when some rows extrapolate.
    """

    rms_error: Array
    rms_error_prior: Array
    rms_torque: Array
    error: Array
    error_prior: Array
    rows_used: Array
    coverage: Coverage
    conditioned: Conditioned
    warnings: list[str] = field(default_factory=list)


def validate(result: IdentificationResult, data: MotionData, model: Model, *, mode: str
             ) -> Validation:
    """Predict the torques of ``data`` (another motion) with ``result``'s model and with the
    prior ``model``, the data conditioned with the identification's filters.

    Parameters
    ----------
    result : IdentificationResult
    data : MotionData
        The validation motion (SI).
    model : Model
        The prior (the one :func:`identify` was given).
    mode : str
        The working mode the data must stay in.

    Returns
    -------
    Validation

    Raises
    ------
    ParameterError
        Data outside the working or assembly mode, or sampled too slowly for the
        identification's filters.
    """
    check_modes(data, model, mode)
    vc = condition(data, model, filters=Filters(result.cutoff_hz, result.parallel_hz))
    keep = vc.used
    pred = vc.Y @ result.theta
    prior = vc.Y @ standard_parameters(model.inertia)
    err = np.array([_rms((pred - vc.tau)[keep[:, k], k]) for k in range(2)])
    errp = np.array([_rms((prior - vc.tau)[keep[:, k], k]) for k in range(2)])
    rms = np.array([_rms(vc.tau[keep[:, k], k]) for k in range(2)])
    safe = np.where(rms > 0, rms, 1.0)
    cov = coverage(result.conditioned, vc) if result.conditioned is not None else coverage(vc, vc)
    warn = cov.message(data.source)
    return Validation(err, errp, rms, np.where(rms > 0, err / safe, math.inf),
                      np.where(rms > 0, errp / safe, math.inf),
                      keep.sum(axis=0), cov, vc, [warn] if warn else [])


def _rms(x: Array) -> float:
    return float(np.sqrt((x ** 2).mean())) if len(x) else 0.0


def _verdict(quality: Array, scale: Array, explained: Array) -> str:
    """The poor-fit message, or "" for a fit the model explains: the torques' scale unlike
    the prior's, or a residual above :data:`RESIDUAL_FACTOR` times what noise and filters
    explain (the likely causes by its size: above :data:`POOR_FIT`, another robot)."""
    if ((scale > TORQUE_SCALE) | (scale < 1.0 / TORQUE_SCALE)).any():
        return (f"poor fit: the identified torques are {scale[0]:.3g} / {scale[1]:.3g} times "
                f"the prior model's for motor A / D (beyond a factor {TORQUE_SCALE:g}). "
                "Likely causes: torques in another unit (mN m, A, a motor-side torque before "
                "the gear), or a config for another robot")
    unexplained = quality > RESIDUAL_FACTOR * explained
    what = (f"poor fit: the model leaves {100 * quality[0]:.3g} % / {100 * quality[1]:.3g} % "
            f"of the RMS torque of motor A / D unexplained where the torques' noise and the "
            f"filters explain {100 * explained[0]:.3g} % / {100 * explained[1]:.3g} % "
            f"(limit {RESIDUAL_FACTOR:g}x that). ")
    if (unexplained & (quality > POOR_FIT)).any():
        return (what + "Likely causes: another robot's geometry or assembly mode in the "
                "config (or no config: the DexTAR's defaults assumed), gravity left out or in "
                "another direction, data from another machine, torques of another sign or "
                "motor order, or effects the model lacks (backlash, a cable, a spring)")
    if unexplained.any():
        return (what + "Likely causes: the config's geometry or gravity direction a little "
                "off, torques and angles out of step, or effects the model lacks (backlash, "
                "a cable, a spring, friction beyond Coulomb and viscous)")
    return ""


def _mahalanobis(d: Array, cov: Array) -> float:
    """``sqrt(d^T cov^-1 d)`` (the pseudo-inverse where ``cov`` is singular)."""
    return float(math.sqrt(max(float(d @ np.linalg.pinv(cov, hermitian=True) @ d), 0.0)))


def _hac_std(A: Array, r: Array, sizes: tuple[int, int]) -> Array:
    """Standard deviations of :func:`_hac_cov`."""
    return np.asarray(np.sqrt(np.clip(np.diag(_hac_cov(A, r, sizes)), 0.0, None)))


def _hac_cov(A: Array, r: Array, sizes: tuple[int, int]) -> Array:
    """Covariance of least-squares estimates whose residuals ``r`` are correlated in time
    (the low-pass leaves neighbouring samples related): the heteroskedasticity and
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
    return np.asarray(0.5 * (cov + cov.T))


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


#: (J, h, m) of each rod: the proximal rods' masses are variables 15 and 16 (not in the
#: torques), the distal rods' are standard parameters.
_RODS = ((INDEX["J_A"], INDEX["h_AB"], 15), (INDEX["J_D"], INDEX["h_DC"], 16),
         (INDEX["J_BP"], INDEX["h_BP"], INDEX["m_BP"]),
         (INDEX["J_CP"], INDEX["h_CP"], INDEX["m_CP"]))
#: A rod heavier than this many times the prior's heaviest body is not physical here (the
#: proximal rods' masses are not in the torques: without a bound any first moment would fit
#: with a mass that tends to infinity and a centre of mass at the joint).
MASS_BOUND = 10.0


class _Physics:
    """The physical region of the standard parameters, in scaled variables ``x`` (17,):
    ``theta / s`` then the proximal rods' masses over their scale (see
    :func:`physical_set`)."""

    def __init__(self, prior: Array, prior_inertia: Inertia, robot: FiveBar | None) -> None:
        s = _scales(prior)
        masses = [r.mass for r in (*prior_inertia.proximal, *prior_inertia.distal)]
        heaviest = max([*masses, prior_inertia.point_mass, float(s[INDEX["m_P"]])])
        sm = np.maximum(np.array([r.mass for r in prior_inertia.proximal], float),
                        1e-3 * heaviest)
        self.s = np.concatenate([s, sm])
        self.prior = np.concatenate([prior, sm])
        lo = _scaled_bounds(prior_inertia, s)
        top = MASS_BOUND * heaviest
        mass_hi = [None if i not in (INDEX["m_BP"], INDEX["m_CP"], INDEX["m_P"]) else
                   top / s[i] for i in range(len(s))]
        self.bounds: list[tuple[float | None, float | None]] = [
            (lo_, hi) for (lo_, _), hi in zip(lo, mass_hi, strict=True)]
        self.bounds += [(0.0, top / sm[0]), (0.0, top / sm[1])]
        self.lengths = (np.full(4, 1e300) if robot is None
                        else np.array([robot.l1, robot.l2, robot.L1, robot.L2], float))

    def K(self, base: BaseParameters) -> Array:
        """``base.K`` in the scaled variables (the proximal masses do not enter)."""
        return np.concatenate([base.K * self.s[:15], np.zeros((base.size, 2))], axis=1)

    def slack(self, x: Array) -> Array:
        """>= 0 where physical, in scaled units, shape (12,): per rod ``J m - h^2`` (its
        inertia about its centre not negative), ``L m - h`` and ``L m + h`` (its centre of
        mass within its length ``L`` of its joint)."""
        s = self.s
        th = x * s
        out = []
        for (J, h, m), L in zip(_RODS, self.lengths, strict=True):
            scale = max(L * s[m], s[h])
            out += [(th[J] * th[m] - th[h] ** 2) / (s[J] * s[m]),
                    (L * th[m] - th[h]) / scale, (L * th[m] + th[h]) / scale]
        return np.array(out)

    def physical(self, x: Array, tol: float = 1e-9) -> bool:
        """Every constraint and bound met at ``x`` (within ``tol``, scaled)."""
        return bool(np.all(self.slack(x) >= -tol) and all(
            (lo is None or x[i] >= lo - tol) and (hi is None or x[i] <= hi * (1 + tol))
            for i, (lo, hi) in enumerate(self.bounds)))


def _physical(theta: Array, prior: Array, prior_inertia: Inertia, robot: FiveBar | None
              ) -> bool:
    """True when the standard parameters ``theta`` are physical (see :func:`physical_set`)
    with some proximal masses (the smallest each rod allows)."""
    ph = _Physics(prior, prior_inertia, robot)
    x = np.concatenate([theta, np.zeros(2)]) / ph.s
    for k, (J, h, _m) in enumerate(_RODS[:2]):
        need = max(theta[h] ** 2 / theta[J] if theta[J] > 0 else math.inf,
                   abs(theta[h]) / ph.lengths[k]) if theta[h] != 0 else 0.0
        x[15 + k] = need / ph.s[15 + k]
    return ph.physical(x)


def physical_set(beta: Array, base: BaseParameters, prior: Array, prior_inertia: Inertia,
                 robot: FiveBar | None = None) -> tuple[Array, bool]:
    """Standard parameters ``theta`` (15,) closest to ``prior`` (scaled) with
    ``base.of(theta) = beta`` and physical values; ``ok`` is False when none exists.

    Physical in the full sense where the base parameters allow the check: inertias about the
    joints and friction not negative, the point mass at least the payload and every rod's
    mass not negative (at most :data:`MASS_BOUND` times the prior's heaviest body), every
    rod's inertia at least ``m c^2`` (``J m >= h^2``: its pseudo-inertia positive
    semi-definite) and, with ``robot``, its centre of mass within its length of its joint
    (``|h| <= l m``). A proximal rod's mass is not in the torques: it is a variable here,
    and :func:`realise` picks the smallest that fits."""
    ph = _Physics(prior, prior_inertia, robot)
    K = ph.K(base)
    x0 = ph.prior / ph.s
    bscale = np.maximum(np.abs(beta), 1e-300)
    cons = [{"type": "eq", "fun": lambda x: (K @ x - beta) / bscale,
             "jac": lambda x: K / bscale[:, None]},
            {"type": "ineq", "fun": ph.slack}]
    # start from the prior moved onto the affine set K theta = beta (least-norm correction);
    # a feasible set is found in 10-20 iterations (measured), an infeasible one would run
    # to any limit (500 took 30 s): 100, then the constrained fit decides
    x_start = x0 + np.linalg.lstsq(K, beta - K @ x0, rcond=None)[0]
    r = optimize.minimize(lambda x: float(((x - x0) ** 2).sum()), x_start,
                          jac=lambda x: 2 * (x - x0), bounds=ph.bounds, constraints=cons,
                          method="SLSQP", options={"maxiter": 100, "ftol": 1e-14})
    theta = r.x[:15] * ph.s[:15]
    ok = bool(np.all(np.abs(base.of(theta) - beta) <= 1e-9 * bscale + 1e-12 * np.abs(beta).max())
              and ph.physical(r.x))
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
                     prior_inertia: Inertia, robot: FiveBar | None = None) -> Array:
    """Least squares over physical standard parameters (a tiny pull to the prior fixes the
    directions the torques do not see)."""
    ph = _Physics(prior, prior_inertia, robot)
    M = Aw @ ph.K(base)
    norm = max(float(bw @ bw), 1e-300)  # the cost in units of the data's (SLSQP's ftol is
    G = M.T @ M / norm                   # absolute)
    g = M.T @ bw / norm
    x0 = ph.prior / ph.s
    eps = 1e-9 * float(np.trace(G)) / len(x0)

    def f(x: Array) -> float:
        return float(x @ G @ x - 2 * g @ x + eps * ((x - x0) ** 2).sum())

    def df(x: Array) -> Array:
        return np.asarray(2 * (G @ x - g) + 2 * eps * (x - x0))

    x_start = np.clip(x0, [lo if lo is not None else -np.inf for lo, _ in ph.bounds],
                      [hi if hi is not None else np.inf for _, hi in ph.bounds])
    r = optimize.minimize(f, x_start, jac=df, bounds=ph.bounds,
                          constraints=[{"type": "ineq", "fun": ph.slack}], method="SLSQP",
                          options={"maxiter": 1000, "ftol": 1e-13})
    return np.asarray(r.x[:15] * ph.s[:15])


def realise(theta: Array, template: Inertia, robot: FiveBar | None = None) -> Inertia:
    """An :class:`Inertia` with the standard parameters ``theta`` (physical), gravity and
    Coulomb regularisation of ``template``; each proximal rod keeps the template's mass (or
    the smallest mass its first moment allows: ``J >= m c^2`` and, with ``robot``, its centre
    within its length of its joint) and inertia where they fit, the rest of its ``J`` going
    to the rotor; the payload stays the template's."""
    th = np.asarray(theta, float)
    distal: list[Rod] = []
    for J, h, m in ((th[INDEX["J_BP"]], th[INDEX["h_BP"]], th[INDEX["m_BP"]]),
                    (th[INDEX["J_CP"]], th[INDEX["h_CP"]], th[INDEX["m_CP"]])):
        m = max(m, 0.0)
        c = h / m if m > 0 else 0.0
        if robot is not None:  # within its length (to the constraints' tolerance)
            L = (robot.L1, robot.L2)[len(distal)]
            c = min(max(c, -L), L)
        distal.append(Rod(m, c, max(J - m * c * c, 0.0) if m > 0 else 0.0))
    prox, rotor = [], []
    for k, (J, h) in enumerate(((th[INDEX["J_A"]], th[INDEX["h_AB"]]),
                                (th[INDEX["J_D"]], th[INDEX["h_DC"]]))):
        p = template.proximal[k]
        J = max(J, 0.0)
        m = p.mass
        reach = math.inf if robot is None else (robot.l1, robot.l2)[k]
        if h != 0 and (m <= 0 or m * J < h * h or abs(h) > reach * m):
            m = max(h * h / J if J > 0 else abs(h) / 1e-12, abs(h) / reach)
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
