"""Exciting trajectories: periodic joint motions that make the base regressor well conditioned.

Each motor follows a finite Fourier series (Swevers et al., 1997) of ``N`` harmonics of the
base frequency ``f``, ``w = 2 pi f``:

    q_k(t) = q0_k + sum_l [a_kl sin(l w t) - b_kl (cos(l w t) - 1)] / (l w),
    qdot_k = sum_l a_kl cos(l w t) + b_kl sin(l w t),

periodic with period ``1 / f``. With ``sum_l a_kl = 0`` and ``sum_l l b_kl = 0`` (imposed by
the last harmonic's coefficients) it starts and ends each period at rest in ``q0``. The
coefficients minimise the condition number of the stacked base regressor (columns scaled to
unit norm) on a time grid of one period, subject to staying :data:`MARGIN` away from both
singularity types (checked on a grid 4x finer: so in the working and assembly modes of the
start) and, given motors, within :data:`SAFETY` of their torque (at each speed) and of their
maximum speed; the model's torques may be short of the real robot's by that margin. Each of a
few random starts is grown to the largest feasible size, then COBYLA (derivative-free: the
cost has corners) improves it; the best feasible point any start met is kept. Which optimum
is found depends on the last rounding unit (another BLAS, another excitation): test the
result's properties, not the coefficients.

Measured on the pick-and-place robot (5 harmonics, 3 starts, 10 seeds): condition numbers
4.6-5.3, each motor using 69-80 % of its limits; with the pick-and-place program's region,
4.7-5.9, 76-80 %, 86-100 % of the region's poses covered; 1.4-7 s each.

Two more terms in the cost, each zero when met:

* **the motors' headroom**: a motor whose peak use of its limits (``max_t`` of ``|tau| /``
  available torque and ``|qdot| /`` maximum speed) stays below :data:`HEADROOM_TARGET` of
  :data:`SAFETY` is penalised, so the motion uses most of what the motors give (the former
  design used 4-7 % of the available torque and 30-60 % of the speed);
* **a task's region** (:class:`~dextar.identification.coverage.JointRegion`, e.g. a program's
  set-points): region poses farther than its radius from the motion, and peak speeds short of
  the region's (capped at the motors' safe speed), are penalised; the rest pose is the
  region's pose farthest from both singularities (within the radius of its centroid when
  one is).

The result reports the headroom used, the fraction of the region's poses within its radius
of the motion (:mod:`~dextar.identification.coverage`'s rule) and the speeds reached.

**Coverage floors, advisory** (:func:`check_coverage`): each motor's range, peak speed and
peak acceleration against :data:`RANGE_FLOOR`, :data:`SPEED_FLOOR` and
:data:`ACCELERATION_FLOOR` of a reference (:func:`coverage_reference`: the task region's
range, else the motor's free range from the rest pose with the other at rest, which a motion
of both may exceed; the top harmonic sweeping it, capped by the motors), the peak speed also
against the motors' rated speed, and the condition number against :data:`COND_CEILING`. A
design that misses them (a local optimum: the optimiser is chaotic to one rounding unit) is
made again from starts drawn from ``(seed, attempt)``, deterministic, up to :data:`ATTEMPTS`
designs; the one closest to the floors is kept and, still short, its status is 2: a warning
(``dextar excite`` exits 0), not a refusal, because no measured case ties missing a floor to
a worse model, and whether the data suffice is identify's measured verdict (the
predicted-torque uncertainty along the recorded motion or ``--task``):

* Measured (``benchmarks/bench_excite_seeds.py``, 20 seeds, 15 s, 5 harmonics of 0.2 Hz): on
  issue 28's 80/75/95/92/58 mm robot the designs reach a median of about 90 % / 60 % of the
  range, 50 % / 30 % of the speed, 30 % / 20 % of the acceleration (motor A / D); 4 of 20
  first designs miss a floor (seeds 1, 3, 5, 17: 13-20 % of a motor's speed or range, 8-9 %
  of its acceleration), redesigned they reach 16-123 % (a redesign costs 26 s against 8 s).
  Identified from MuJoCo's data with 50 mN m of torque noise, the worst prediction error of
  an unseen line and arc over the 20 seeds: 1.0 / 0.80 % with the first designs, 1.0 / 0.68
  % with the designs kept (seed 1: 0.49 / 0.80 % before, 0.33 / 0.58 % redesigned). On a
  flat 120/180 mm robot with dry friction 1 seed of 20 is redesigned (16 % of motor A's
  range); there the worst error, 3.8 / 4.8 %, is the torque noise on its small torques.
* Designs shrunk about their rest pose (``bench_excite_seeds.py --scales``, seeds 0-2, 50
  mN m): the prediction of the line and arc degrades gradually, not at a floor: 0.21-0.57 %
  at full size, 0.34-0.90 % at 0.6 (a floor missed on two seeds of three), 0.48-1.24 % at
  0.4, 0.42-1.86 % at a quarter (every floor missed), 1.1-2.2 % at 0.15; a design at 0.6
  that meets every floor predicts the other seeds' excitations 2.9 / 2.5 % wrong, one at
  0.25 that misses them 0.68 / 3.0 %. The floors are a guide to a small motion, not a bound
  on the model's error.

The speed reference follows the range (``pi N f R``): a motion can meet it far below the
motors' rating (seed 0 at 1.7 rad/s on 30 rad/s motors), so the summary states each motor's
peak speed against its rating too. On the pick-and-place robot the stored excitations reach
32-90 %, 36-99 % and 13-33 % of the references.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..dynamics.exact import Model, gravity_torques, inverse_dynamics, mass_matrix
from ..dynamics.regressor import regressor
from ..errors import ParameterError
from ..kinematics import direct_kinematics, elbows, inverse_kinematics
from ..kinematics.checker import pose_distances
from ..laws import MotorLimits
from .base import BaseParameters, base_parameters
from .coverage import JointRegion

optimize = lazy_module("scipy.optimize")

#: Smallest normalised distance to either singularity type along an exciting trajectory.
MARGIN = 0.15
#: Time samples per period of the highest harmonic in the optimisation grid.
GRID_PER_HARMONIC = 12
#: Fraction of the motors' torque (at each speed) and speed the design may use.
SAFETY = 0.8
#: Fraction of SAFETY below which a motor's peak use is penalised.
HEADROOM_TARGET = 0.9
#: Weights of the headroom and region penalties against the log condition number.
HEADROOM_WEIGHT = 2.0
REGION_WEIGHT = 5.0
#: Runs of samples over which each constraint holds as one (the optimiser's linear
#: subproblems grow with the number of constraints).
WINDOWS = 12
#: Restarts of the optimiser from its best feasible point when it stops short.
RESTARTS = 1
#: Cost evaluations of one run of the optimiser (COBYLA).
MAX_EVALUATIONS = 500
#: A motion grown towards the motors' headroom may lose this factor of condition number.
GROW_COND = 1.25
#: Advisory coverage floors: each motor's range, peak speed and peak acceleration as
#: fractions of the reference's (:func:`coverage_reference`), and the largest condition
#: number (see the module doc for the measurements behind them and why they are advisory).
RANGE_FLOOR = 0.2
SPEED_FLOOR = 0.2
ACCELERATION_FLOOR = 0.1
COND_CEILING = 20.0
#: Further designs (each from its own deterministic starts) when a design misses a floor.
ATTEMPTS = 4
#: Joint-space grid (points per motor over a turn) of the region the motion may use.
REGION_GRID = 121


@dataclass(frozen=True)
class FourierTrajectory:
    """A periodic joint trajectory (see the module doc).

    Attributes
    ----------
    q0 : ndarray, shape (2,)
        Rest pose (rad).
    a, b : ndarray, shape (2, N)
        Fourier coefficients of the joint rates (rad/s); they satisfy the rest conditions.
    base_hz : float
    """

    q0: Array
    a: Array
    b: Array
    base_hz: float

    @staticmethod
    def from_free(q0: Array, x: Array, harmonics: int, base_hz: float) -> FourierTrajectory:
        """The trajectory of the free coefficients ``x`` (4 (N - 1),): ``a`` and ``b`` of
        harmonics 1 to N-1 per motor; the N-th from the rest conditions."""
        n = harmonics
        x = np.asarray(x, float).reshape(2, 2, n - 1)
        ls = np.arange(1, n + 1)
        a = np.concatenate([x[0], -x[0].sum(axis=1, keepdims=True)], axis=1)
        bl = -(x[1] * ls[:-1]).sum(axis=1, keepdims=True) / n
        b = np.concatenate([x[1], bl], axis=1)
        return FourierTrajectory(np.asarray(q0, float), a, b, float(base_hz))

    @property
    def period(self) -> float:
        """Period (s)."""
        return 1.0 / self.base_hz

    def evaluate(self, t: Array) -> tuple[Array, Array, Array]:
        """``q, qdot, qddot`` (each (n, 2)) at times ``t`` (n,)."""
        t = np.asarray(t, float)
        w = 2 * math.pi * self.base_hz
        lw = w * np.arange(1, self.a.shape[1] + 1)
        arg = t[:, None] * lw[None, :]
        s, c = np.sin(arg), np.cos(arg)
        q = self.q0 + (s / lw) @ self.a.T - ((c - 1.0) / lw) @ self.b.T
        dq = c @ self.a.T + s @ self.b.T
        ddq = (-s * lw) @ self.a.T + (c * lw) @ self.b.T
        return q, dq, ddq


@dataclass(frozen=True)
class ExcitationResult:
    """An optimised exciting trajectory.

    Attributes
    ----------
    trajectory : FourierTrajectory
    condition_number : float
        Of the base regressor over one period (unit-norm columns).
    periods : int
        Whole periods in the requested duration.
    min_type1_distance, min_type2_distance : float
    peak_torque : ndarray, shape (2,)
        Predicted by the model.
    peak_speed : ndarray, shape (2,)
    status : int
        0 success (a start converged, every coverage floor met); 1 no start converged (the
        best feasible point met is kept; every floor met); 2 an advisory coverage floor
        missed after :data:`ATTEMPTS` designs (the design closest to the floors is kept; a
        warning, see the module doc).
    message : str
    headroom : ndarray, shape (2,)
        Each motor's peak use of its limits (``max`` over the motion of ``|tau| /`` available
        torque and ``|qdot| /`` maximum speed); ``nan`` without motors.
    region_coverage : float
        Fraction of the task region's poses within its radius of this motion's poses
        (``nan`` without a region).
    region_speed_ratio : ndarray, shape (2,)
        Each motor's peak speed over the region's (``nan`` without a region); below 1 where
        the motors' safe speed is below the task's.
    coverage : ExcitationCoverage
        Range, speed, acceleration against the advisory floors (:func:`check_coverage`).
    attempts : int
        Designs made (1 when the seed's own met every floor).
    """

    trajectory: FourierTrajectory
    condition_number: float
    periods: int
    min_type1_distance: float
    min_type2_distance: float
    peak_torque: Array
    peak_speed: Array
    status: int
    message: str
    headroom: Array = field(default_factory=lambda: np.full(2, np.nan))
    region_coverage: float = math.nan
    region_speed_ratio: Array = field(default_factory=lambda: np.full(2, np.nan))
    coverage: ExcitationCoverage | None = None
    attempts: int = 1

    @property
    def duration(self) -> float:
        """Duration (s): whole periods."""
        return self.periods * self.trajectory.period


def rest_pose(model: Model, mode: str, resolution: int = 61) -> Array:
    """The pose (2,) of the working mode ``mode`` farthest from both singularity types (on a
    grid of the reachable region)."""
    r = model.robot
    R = max(r.l1 + r.L1, r.l2 + r.L2) + 0.5 * r.d
    xs = np.linspace(-R, R, resolution)
    X, Yg = np.meshgrid(xs, xs)
    P = np.stack([X.ravel(), Yg.ravel()], -1)
    rin1, rout1 = r.reach(1)
    rin2, rout2 = r.reach(2)
    dA = np.hypot(*(P - r.A).T)
    dD = np.hypot(*(P - r.D).T)
    P = P[(dA > rin1) & (dA < rout1) & (dD > rin2) & (dD < rout2)]
    q = inverse_kinematics(r, P, mode)
    d = pose_distances(r, q, P)
    # the pose must assemble in the model's assembly mode
    Pa = direct_kinematics(r, q, model.assembly)
    same = np.hypot(*(Pa - P).T) < 1e-9 * R
    score = np.where(same, np.minimum(d.type1, d.type2), -1.0)
    i = int(np.argmax(score))
    if score[i] <= MARGIN:
        raise ParameterError(f"no pose of working mode {mode} is {MARGIN:g} away from both "
                             "singularity types in this assembly mode: nothing to excite")
    return np.asarray(q[i])


def _feasibility(model: Model, q: Array) -> tuple[Array, Array, Array] | None:
    """Distances (type 1, type 2) of the poses q (n, 2) and the assembly slack; None where
    the rods cannot meet."""
    r = model.robot
    B, C = elbows(r, q)
    d2 = ((B - C) ** 2).sum(axis=1)
    slack = np.minimum((r.L1 + r.L2) ** 2 - d2, d2 - (r.L1 - r.L2) ** 2)
    if (slack <= 0).any():
        return None
    P = direct_kinematics(r, q, model.assembly)
    d = pose_distances(r, q, P)
    return d.type1, d.type2, d.type2_signed


def _use(model: Model, motors: MotorLimits, q: Array, dq: Array, ddq: Array) -> Array:
    """Use of the motors' limits (n, 2): ``max(|tau| / available torque, |qdot| / max speed)``
    (``inf`` where a torque is needed and none is available)."""
    tau = inverse_dynamics(model, q, dq, ddq)
    avail = motors.available_torque(dq)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(avail > 0, np.abs(tau) / avail, np.where(np.abs(tau) > 0, np.inf, 0.0))
    return np.asarray(np.maximum(t, np.abs(dq) / np.asarray(motors.max_speed, float)))


def region_rest_pose(model: Model, region: JointRegion) -> Array | None:
    """The rest pose (2,) for a region: of its poses within its radius of their centroid the
    one farthest from both singularity types, else the farthest of all; None when none is
    :data:`MARGIN` away (the rods may not even meet)."""
    f = _feasibility(model, region.q)
    if f is None:
        B, C = elbows(model.robot, region.q)
        d2 = ((B - C) ** 2).sum(axis=1)
        r = model.robot
        ok = (d2 < (r.L1 + r.L2) ** 2) & (d2 > (r.L1 - r.L2) ** 2)
        if not ok.any():
            return None
        q = region.q[ok]
        f = _feasibility(model, q)
        assert f is not None
    else:
        q = region.q
    score = np.minimum(f[0], f[1])
    near = np.hypot(*(q - q.mean(axis=0)).T) <= region.radius
    pick = score if not (near & (score > MARGIN)).any() else np.where(near, score, -1.0)
    i = int(np.argmax(pick))
    return np.asarray(q[i]) if score[i] > MARGIN else None


def _windows(x: Array) -> Array:
    """The minimum of ``x`` (n,) over each of :data:`WINDOWS` consecutive runs of samples."""
    return np.asarray(x.reshape(WINDOWS, -1).min(axis=1))


def _within(model: Model, motors: MotorLimits, q: Array, dq: Array, ddq: Array,
            safety: float = 1.0) -> bool:
    """True when the motion needs no more than ``safety`` of what the motors give (torque
    at each speed, and speed)."""
    return bool((_use(model, motors, q, dq, ddq) <= safety).all())


def _region_cost(region: JointRegion, q: Array, peak_speed: Array, safe_speed: Array) -> float:
    """Penalty (0 when met) of a motion's poses ``q`` (n, 2) and peak speeds (2,) for the
    region: the mean squared excess of the region poses' distance over the radius (in
    radii), plus each motor's squared relative speed shortfall."""
    d = np.sqrt(((region.q[:, None, :] - q[None, :, :]) ** 2).sum(axis=-1)).min(axis=1)
    far = np.maximum(d / region.radius - 1.0, 0.0)
    want = np.minimum(region.peak_speed, safe_speed)
    with np.errstate(divide="ignore", invalid="ignore"):
        short = np.where(want > 0, np.maximum(1.0 - peak_speed / want, 0.0), 0.0)
    return float((far ** 2).mean() + (short ** 2).sum())


@dataclass(frozen=True)
class CoverageReference:
    """What an excitation's coverage is measured against, per motor (shape (2,) each; see
    :func:`coverage_reference`): references, not limits (a motion of both motors may exceed
    them).

    Attributes
    ----------
    range : ndarray
        The task region's extent, else the motor's free range from the rest pose (rad).
    speed, acceleration : ndarray
        The peak speed (rad/s) and acceleration (rad/s^2) of the top harmonic sweeping that
        range, capped by the motors (their safe speed; what their safe peak torque, less
        gravity, gives the motor's own inertia at rest).
    rated_speed : ndarray
        The motors' maximum speed (rad/s; ``nan`` without motors).
    range_of : str
        What ``range`` is, in words.
    """

    range: Array
    speed: Array
    acceleration: Array
    rated_speed: Array = field(default_factory=lambda: np.full(2, np.nan))
    range_of: str = "the free range from the rest pose, the other motor at rest"


@dataclass(frozen=True)
class ExcitationCoverage:
    """An excitation's coverage against its advisory floors.

    Attributes
    ----------
    range, speed, acceleration : ndarray, shape (2,)
        Each motor's joint range (rad), peak speed (rad/s) and peak acceleration (rad/s^2).
    reference : CoverageReference
    fractions : dict of str to ndarray (2,)
        ``range``, ``speed``, ``acceleration`` over the reference's (may exceed 1).
    rated_fraction : ndarray, shape (2,)
        Peak speed over the motors' maximum speed (``nan`` without motors).
    missed : tuple of str
        The floors missed, in words (empty when every floor is met).
    """

    range: Array
    speed: Array
    acceleration: Array
    reference: CoverageReference
    fractions: dict[str, Array]
    rated_fraction: Array
    missed: tuple[str, ...]

    @property
    def met(self) -> bool:
        """True when every floor is met."""
        return not self.missed


def free_range(model: Model, q0: Array, resolution: int = REGION_GRID) -> Array:
    """Each motor's free range (rad, shape (2,)) from the rest pose ``q0``: the interval of
    its angle, the other motor at rest, that contains ``q0`` and stays :data:`MARGIN` from
    both singularity types (so in its working and assembly modes), on a grid of
    ``6 resolution`` points over a turn (a whole turn at most)."""
    g = np.linspace(-math.pi, math.pi, 6 * resolution + 1)
    mid = len(g) // 2
    out = np.zeros(2)
    r = model.robot
    for k in range(2):
        q = np.repeat(np.asarray(q0, float)[None, :], len(g), axis=0)
        q[:, k] += g
        B, C = elbows(r, q)
        d2 = ((B - C) ** 2).sum(axis=1)
        ok = (d2 < (r.L1 + r.L2) ** 2 * (1 - 1e-9)) & (d2 > (r.L1 - r.L2) ** 2 * (1 + 1e-9))
        f = _feasibility(model, q[ok])
        free = np.zeros(len(g), bool)
        if f is not None:
            free[ok] = (f[0] >= MARGIN) & (f[1] >= MARGIN)
        if not free[mid]:
            continue
        lo = mid - int(np.argmin(free[mid::-1])) if not free[:mid + 1].all() else 0
        hi = mid + int(np.argmin(free[mid:])) if not free[mid:].all() else len(g)
        out[k] = min((hi - lo) * (g[1] - g[0]), 2 * math.pi)
    return out


def coverage_reference(model: Model, q0: Array, harmonics: int, base_hz: float,
                       motors: MotorLimits | None, region: JointRegion | None,
                       safety: float = SAFETY) -> CoverageReference:
    """What the coverage of an excitation of ``harmonics`` harmonics of ``base_hz`` resting at
    ``q0`` is measured against, per motor:

    * range: the task region's extent (``region``), else :func:`free_range` (each motor
      alone from the rest pose: a motion of both may exceed it);
    * speed: the top harmonic sweeping that range, ``pi N f R``, capped at ``safety`` of the
      motor's maximum speed (the rated speed itself is ``rated_speed``);
    * acceleration: the same, ``2 pi^2 (N f)^2 R``, capped at what ``safety`` of the peak
      torque, less the gravity torque at rest, gives the motor's own inertia at ``q0``
      (``M_kk``)."""
    R = (np.asarray(region.upper - region.lower, float) if region is not None
         else free_range(model, q0))
    w = math.pi * harmonics * base_hz
    speed = w * R
    acc = 2.0 * w * w * R
    rated = np.full(2, np.nan)
    if motors is not None:
        rated = np.broadcast_to(np.asarray(motors.max_speed, float), (2,)).copy()
        speed = np.minimum(speed, safety * rated)
        g = np.abs(gravity_torques(model, q0))
        M = np.diag(mass_matrix(model, q0))
        peak = np.asarray(motors.peak_torque, float)
        acc = np.minimum(acc, np.maximum(safety * peak - g, 0.0) / M)
    return CoverageReference(np.asarray(R, float), np.asarray(speed, float),
                             np.asarray(acc, float), rated,
                             "the task's range" if region is not None else
                             "the free range from the rest pose, the other motor at rest")


#: What each coverage figure is measured against, in words.
REFERENCE_WORDS = {"speed": "the top harmonic sweeping that range, capped by the motors",
                   "acceleration": "the top harmonic sweeping that range, capped by what "
                                   "the motors' torque gives at rest"}


def coverage_floors() -> dict[str, float]:
    """The coverage floors by name (``range``, ``speed``, ``acceleration``): the module's
    constants, read when called."""
    return {"range": RANGE_FLOOR, "speed": SPEED_FLOOR, "acceleration": ACCELERATION_FLOOR}


def check_coverage(tr: FourierTrajectory, reference: CoverageReference, cond: float
                   ) -> ExcitationCoverage:
    """The excitation's range, peak speed and acceleration (on a fine grid of a period)
    against :data:`RANGE_FLOOR`, :data:`SPEED_FLOOR`, :data:`ACCELERATION_FLOOR` of the
    reference's (advisory: see the module doc), and its condition number against
    :data:`COND_CEILING`; the peak speed also against the motors' rating."""
    t = np.linspace(0.0, tr.period, 40 * GRID_PER_HARMONIC * tr.a.shape[1], endpoint=False)
    q, dq, ddq = tr.evaluate(t)
    got = {"range": np.ptp(q, axis=0), "speed": np.abs(dq).max(axis=0),
           "acceleration": np.abs(ddq).max(axis=0)}
    ref = {"range": reference.range, "speed": reference.speed,
           "acceleration": reference.acceleration}
    words = {"range": reference.range_of, **REFERENCE_WORDS}
    floors = coverage_floors()
    units = {"range": "deg", "speed": "rad/s", "acceleration": "rad/s^2"}
    rated = got["speed"] / reference.rated_speed
    fractions: dict[str, Array] = {}
    missed: list[str] = []
    for key, v in got.items():
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(ref[key] > 0, v / np.where(ref[key] > 0, ref[key], 1.0), math.inf)
        fractions[key] = np.asarray(frac)
        for k, name in enumerate(("A", "D")):
            if frac[k] < floors[key]:
                scale = math.degrees(1.0) if key == "range" else 1.0
                said = (f"motor {name}'s {'peak ' if key != 'range' else ''}{key} "
                        f"{scale * v[k]:.3g} {units[key]} is {100 * frac[k]:.3g} % of the "
                        f"{scale * ref[key][k]:.3g} {units[key]} of {words[key]} (floor "
                        f"{100 * floors[key]:g} %)")
                if key == "speed" and math.isfinite(rated[k]):
                    said += (f", {100 * rated[k]:.3g} % of its rated "
                             f"{reference.rated_speed[k]:.3g} rad/s")
                missed.append(said)
    if not cond <= COND_CEILING:
        missed.append(f"condition number {cond:.3g} above {COND_CEILING:g}")
    return ExcitationCoverage(got["range"], got["speed"], got["acceleration"], reference,
                              fractions, np.asarray(rated), tuple(missed))


def _score(cov: ExcitationCoverage, cond: float) -> tuple[int, float, float]:
    """Ranks designs: fewer floors missed, then the smallest shortfall, then the condition
    number."""
    short = min(float((cov.fractions[k] / f).min()) for k, f in coverage_floors().items())
    return len(cov.missed), -min(short, 1.0), cond


def design_excitation(model: Model, mode: str, *, harmonics: int = 5, base_hz: float = 0.2,
                      duration: float = 20.0, motors: MotorLimits | None = None,
                      seed: int = 0, starts: int = 3, q0: Array | None = None,
                      base: BaseParameters | None = None, region: JointRegion | None = None,
                      safety: float = SAFETY) -> ExcitationResult:
    """Optimise an exciting trajectory for ``model`` in working mode ``mode``.

    Parameters
    ----------
    model : Model
        The prior model (SI), for the regressor and the predicted torques.
    mode : str
        Working mode to stay in.
    harmonics : int
        Harmonics per motor (at least 2).
    base_hz : float
        Base frequency (Hz); the period is ``1 / base_hz``.
    duration : float
        Requested duration (s), rounded up to whole periods.
    motors : MotorLimits, optional
        Torque-speed envelope and maximum speed (SI): the motion stays within ``safety`` of
        them and aims at using most of that (see the module doc).
    seed : int
        Seed of the random starts.
    starts : int
        Random starts of the optimiser.
    q0 : ndarray, shape (2,), optional
        Rest pose (default: :func:`rest_pose`, or :func:`region_rest_pose` of the region).
    base : BaseParameters, optional
    region : JointRegion, optional
        A task's poses and speeds to cover (e.g. ``JointRegion.from_samples(q, dq)`` of a
        program's set-points, rad and rad/s).
    safety : float
        Fraction of the motors' limits the motion may use, in (0, 1].

    Returns
    -------
    ExcitationResult

    Raises
    ------
    ParameterError
        Bad options, or no feasible motion (the rest pose too close to a singularity, the
        motors too weak to hold it).
    """
    _check_options(harmonics, base_hz, duration, safety)
    base = base or base_parameters(model)
    if q0 is None and region is not None:
        q0 = region_rest_pose(model, region)
    q0 = rest_pose(model, mode) if q0 is None else np.asarray(q0, float)
    problem = _Problem(model, base, np.asarray(q0, float), harmonics, base_hz, motors, safety,
                       region)
    reference = coverage_reference(model, np.asarray(q0, float), harmonics, base_hz, motors,
                                   region, safety)
    chosen = None
    for attempt in range(ATTEMPTS):
        # the first attempt is the seed's own; the others draw their starts from
        # (seed, attempt): deterministic, and each a new set of local optima
        problem.restart()
        best, ok = _optimise(problem, seed if attempt == 0 else (seed, attempt), starts)
        fin = _finalise(problem, best)
        cov = check_coverage(fin[0], reference, fin[5])
        if chosen is None or _score(cov, fin[5]) < _score(chosen[1], chosen[0][5]):
            chosen = (fin, cov, ok, attempt + 1)
        if cov.met:
            break
    assert chosen is not None
    (tr, q, dq, ddq, f, cond), cover, converged, attempts = chosen
    tau = inverse_dynamics(model, q, dq, ddq)
    periods = max(1, int(math.ceil(duration * base_hz - 1e-9)))
    headroom = (np.full(2, np.nan) if motors is None
                else _use(model, motors, q, dq, ddq).max(axis=0))
    covered, speed_ratio = math.nan, np.full(2, np.nan)
    if region is not None:
        mine = JointRegion.from_samples(q, dq, radius=region.radius)
        covered = float((mine.distance(region.q) <= region.radius).mean())
        with np.errstate(divide="ignore", invalid="ignore"):
            speed_ratio = np.where(region.peak_speed > 0, mine.peak_speed / region.peak_speed,
                                   np.inf)
    if not cover.met:
        designs = f"{attempts} design{'s' if attempts > 1 else ''}"
        status, message = 2, (f"the excitation stays below its advisory coverage floors after "
                              f"{designs}: {'; '.join(cover.missed)}. Whether data "
                              "recorded along it fix the model is identify's verdict (the "
                              "predicted-torque uncertainty along the recorded motion or "
                              "--task); a longer --duration, another --base-hz or more "
                              "--harmonics may reach the floors")
    elif converged:
        status, message = 0, "optimised; every coverage floor met"
    else:
        status, message = 1, ("no start of the optimiser converged; the best feasible "
                              "trajectory met is kept (every coverage floor met)")
    return ExcitationResult(tr, cond, periods, float(f[0].min()),
                            float(f[1].min()), np.abs(tau).max(axis=0),
                            np.abs(dq).max(axis=0), status, message, headroom,
                            covered, speed_ratio, cover, attempts)


def _check_options(harmonics: int, base_hz: float, duration: float, safety: float) -> None:
    if not (isinstance(harmonics, int) and 2 <= harmonics <= 20):
        raise ParameterError(f"--harmonics {harmonics!r} must be an integer from 2 to 20")
    if not (math.isfinite(base_hz) and 0 < base_hz <= 10):
        raise ParameterError(f"--base-hz {base_hz!r} must be in (0, 10] Hz")
    if not (math.isfinite(duration) and 0 < duration <= 3600):
        raise ParameterError(f"--duration {duration!r} must be in (0, 3600] s")
    if not (math.isfinite(safety) and 0 < safety <= 1):
        raise ParameterError(f"safety factor {safety!r} must be in (0, 1]")


class _Problem:
    """The optimisation of an exciting trajectory: its cost and constraints on the free
    coefficients, remembered, and the best feasible point evaluated since :meth:`restart`."""

    def __init__(self, model: Model, base: BaseParameters, q0: Array, harmonics: int,
                 base_hz: float, motors: MotorLimits | None, safety: float,
                 region: JointRegion | None) -> None:
        self.model, self.base, self.q0, self.n, self.base_hz = model, base, q0, harmonics, base_hz
        self.motors, self.safety, self.region = motors, safety, region
        m = GRID_PER_HARMONIC * harmonics
        self.m = m
        self.t = np.arange(m) / (m * base_hz)
        self.t_fine = np.arange(4 * m) / (4 * m * base_hz)
        vmax = None if motors is None else np.asarray(motors.max_speed, float)
        self.safe_speed = np.full(2, np.inf) if vmax is None else safety * vmax
        self.nlim = 0 if motors is None else 2 * WINDOWS
        self.cache: dict[bytes, tuple[float, Array]] = {}
        self.seen: list[tuple[float, Array]] = []  # the best feasible point evaluated

    def trajectory(self, x: Array) -> FourierTrajectory:
        """The trajectory of the free coefficients ``x``."""
        return FourierTrajectory.from_free(self.q0, x, self.n, self.base_hz)

    def restart(self) -> None:
        """Forget the best feasible point (a new start)."""
        self.seen.clear()

    def evaluate(self, x: Array) -> tuple[float, Array]:
        """Cost and the constraint values (>= 0 when feasible) of ``x``."""
        key = x.tobytes()
        if key not in self.cache:
            self.cache[key] = self._score(self.trajectory(x))
            cost, cons = self.cache[key]
            if (cons >= 0).all() and (not self.seen or cost < self.seen[0][0]):
                self.seen[:] = [(cost, np.array(x))]
        return self.cache[key]

    def feasible(self, x: Array) -> bool:
        """Every constraint strictly met at ``x``."""
        return bool((self.evaluate(x)[1] > 0).all())

    def _score(self, tr: FourierTrajectory) -> tuple[float, Array]:
        model, motors, nlim = self.model, self.motors, self.nlim
        # the margins on a grid 4x finer than the regressor's (a leg can fold between
        # samples of the coarse one)
        qf, dqf, _ = tr.evaluate(self.t_fine)
        f = _feasibility(model, qf)
        if f is None:  # the rods cannot meet somewhere
            return 1e3, -np.ones(2 * WINDOWS + nlim)
        cons = [_windows(f[0]) - MARGIN, _windows(f[1]) - MARGIN]
        if f[1].min() < 0.1 * MARGIN:  # too near a parallel singularity for the dynamics
            return 1e3, np.concatenate(cons + [-np.ones(nlim)])
        q, dq, ddq = tr.evaluate(self.t)
        cost = _log_condition(model, self.base, q, dq, ddq)
        if motors is not None:
            use = _use(model, motors, q, dq, ddq)
            cons.append(np.minimum(self.safety - np.concatenate(
                [-_windows(-use[:, 0]), -_windows(-use[:, 1])]), 1.0))
            short = np.maximum(1.0 - use.max(axis=0) / (HEADROOM_TARGET * self.safety), 0.0)
            cost += HEADROOM_WEIGHT * float((short ** 2).sum())
        if self.region is not None:
            cost += REGION_WEIGHT * _region_cost(self.region, qf, np.abs(dqf).max(axis=0),
                                                 self.safe_speed)
        return cost, np.concatenate(cons)


def _singular_values(model: Model, base: BaseParameters, q: Array, dq: Array,
                     ddq: Array) -> Array | None:
    """Singular values of the unit-norm base regressor of the motion (None when a column is
    zero)."""
    Yb = base.columns(regressor(model, q, dq, ddq)).reshape(-1, base.size)
    norms = np.linalg.norm(Yb, axis=0)
    if not (norms > 0).all():
        return None
    return np.asarray(np.linalg.svd(Yb / norms, compute_uv=False))


def _log_condition(model: Model, base: BaseParameters, q: Array, dq: Array,
                   ddq: Array) -> float:
    """Log of the condition number of the unit-norm base regressor (1e3 when a column is
    zero): the optimiser's cost."""
    sv = _singular_values(model, base, q, dq, ddq)
    return 1e3 if sv is None else float(np.log(sv[0] / max(sv[-1], 1e-300)))


def _optimise(pb: _Problem, seed: int | tuple[int, int], starts: int) -> tuple[Array, bool]:
    """The best feasible free coefficients over ``starts`` random starts, and whether a start
    converged (the best point found is at least as good)."""
    rng = np.random.default_rng(seed)
    best: tuple[float, Array] | None = None
    converged = False
    for _ in range(max(starts, 1)):
        x = _feasible_start(pb, rng.normal(size=4 * (pb.n - 1)))
        if x is None:
            continue
        pb.restart()
        pb.evaluate(x)
        for _restart in range(RESTARTS + 1):
            # derivative-free (the cost has corners: minima over samples, the rods that
            # cannot meet); a run stopped by its budget restarts from the best feasible point
            r = optimize.minimize(lambda x: pb.evaluate(x)[0], x, method="COBYLA",
                                  constraints=[{"type": "ineq",
                                                "fun": lambda x: pb.evaluate(x)[1]}],
                                  options={"maxiter": MAX_EVALUATIONS,
                                           "rhobeg": 0.1 * float(np.abs(x).max()),
                                           "tol": 1e-3})
            if r.success and (pb.evaluate(r.x)[1] >= 0).all():
                converged = True
                break
            if np.array_equal(pb.seen[0][1], x):  # no feasible progress: a restart repeats it
                break
            x = pb.seen[0][1]
        cost, xs = pb.seen[0] if pb.seen else (pb.evaluate(x)[0], x)
        if best is None or cost < best[0]:
            best = (cost, xs)
    if best is None:
        raise ParameterError("no feasible exciting trajectory: the rest pose is too close to a "
                             "singularity or the motors are too weak to hold it")
    return best[1], converged


def _feasible_start(pb: _Problem, x: Array) -> Array | None:
    """A random start shrunk until it is feasible, then grown to the largest feasible size
    (a start at the limits uses the headroom the cost asks for); None when even a small one
    is not feasible."""
    for _k in range(60):
        if pb.feasible(x):
            break
        x = 0.7 * x
    else:
        return None
    lo, hi = 1.0, 1.0 / 0.7 if _k else 8.0
    while hi / lo > 1.02:
        mid = math.sqrt(lo * hi)
        if pb.feasible(mid * x):
            lo = mid
        else:
            hi = mid
    return lo * x


_Fine = tuple[FourierTrajectory, Array, Array, Array, tuple[Array, Array, Array]]


def _finalise(pb: _Problem, x: Array) -> tuple[FourierTrajectory, Array, Array, Array,
                                                 tuple[Array, Array, Array], float]:
    """The optimiser saw a coarse grid: check a fine one, shrinking the motion about the rest
    pose until every sample is within the margins and the motors; then, where the optimiser
    stopped short of the motors' headroom (its line search can fail), grow it while it stays
    feasible and its condition number within :data:`GROW_COND` of the optimum's. Returns the
    trajectory, its fine samples, their distances to the singularities and the condition
    number."""
    model, motors, safety = pb.model, pb.motors, pb.safety
    tt = np.linspace(0.0, 1.0 / pb.base_hz, 40 * pb.m, endpoint=False)

    def fine(x: Array) -> _Fine | None:
        tr = pb.trajectory(x)
        q, dq, ddq = tr.evaluate(tt)
        f = _feasibility(model, q)
        ok = f is not None and min(f[0].min(), f[1].min()) >= MARGIN and (
            motors is None or _within(model, motors, q, dq, ddq, safety))
        return (tr, q, dq, ddq, f) if ok and f is not None else None

    def cond_of(g: _Fine) -> float:
        sv = _singular_values(model, pb.base, g[1], g[2], g[3])
        return math.inf if sv is None else float(sv[0] / sv[-1])

    for _ in range(200):
        got = fine(x)
        if got is not None:
            break
        x = 0.98 * x
    else:  # pragma: no cover - the rest pose itself is feasible
        raise ParameterError("no exciting trajectory stays within the margins and motors")
    cond = cond_of(got)
    if motors is not None:
        head = _use(model, motors, *got[1:4]).max(axis=0)
        grow = x
        while head.min() < HEADROOM_TARGET * safety:
            g = fine(1.02 * grow)
            if g is None or cond_of(g) > GROW_COND * cond:
                break
            grow = 1.02 * grow
            got = g
            head = _use(model, motors, *got[1:4]).max(axis=0)
        cond = cond_of(got)
    tr, q, dq, ddq, f = got
    return tr, q, dq, ddq, f, cond
