"""Limits of a law planned on the robot's dynamics along a path, one object per limit.

Along the path (arc length ``s``) the joint motion is ``qdot = q' sdot`` and
``qddot = q' sddot + q'' sdot^2``, so with ``x = sdot^2`` and ``u = sddot`` the exact inverse
dynamics are affine in ``(x, u)`` up to friction:

    tau(s) = a(s) u + b(s) x + g(s) + f(s, sdot),
    a = M q',  b = M q'' + c(q, q'),  g = gravity,  f = friction (viscous + Coulomb).

A constraint turns this into linear rows ``pu u + px x <= ph`` at every grid point
(:meth:`Constraint.rows`) or a cap on the squared speed (:meth:`Constraint.speed_cap`), and
measures how far a planned law goes against it on check samples (:meth:`Constraint.ratio`).
A caller composes them (:func:`motor_constraints` for the motors' limits); the time-optimal
solver (:mod:`dextar.laws.time_optimal`) takes any sequence of them. The kinds:

* :class:`TorqueLimit`: ``|tau_i| <= peak_i`` with friction bounded, not linearised: the
  regularised Coulomb torque always lies between 0 and ``coulomb * sign(q')`` and the viscous
  torque ``viscous q' sqrt(x)`` between 0 and its tangent upper bound at a tangent point
  ``x0`` (the previous iterate's speeds), so the limits hold for every friction value in the
  interval; where a joint reverses the interval is ``[-coulomb, coulomb]``; at the two rest
  points friction is zero.
* :class:`SpeedLimit`: ``|qdot_i| <= max_speed_i``, a cap ``x <= (max_speed / |q'|)^2``.
* :class:`TorqueSpeedEnvelope`: full torque up to the knee speed, then linearly down to zero
  at the maximum speed: ``|tau| + sigma |q'| sqrt(x) <= T + sigma knee``
  (``sigma = T / (max_speed - knee)``), ``sqrt(x)`` bounded above by its tangent at
  ``max(x0, x_knee)``: conservative, and exact at the tangent point.
* :class:`AccelerationLimit`: ``|qddot_i| = |q'_i u + q''_i x| <= max_acceleration_i``, linear
  in ``(u, x)`` like the torque rows.
* :class:`DegeneracyCondition`: at a crossing of the parallel (type 2) singularity curve,
  the equality ``cu u + cx x + cg = 0`` that the path dynamics carry for that grid point
  (:attr:`PathCoefficients.conditions`): the end-effector's force has no component normal to
  the aligned distal rods (Briot & Arakelian, IJRR 2008), so the torques stay bounded there;
  the torque rows at that point are the limit of the torques along a motion that meets it
  (:mod:`dextar.dynamics.crossing`).
* :class:`JerkLimit` and :class:`TorqueRateLimit`: third order, ``|qdddot_i|`` and
  ``|d tau_i / dt|`` bounded. They have no rows in ``(u, x)`` (the jerk involves ``sdddot``):
  the jerk-limited law (:mod:`dextar.laws.smooth`) linearises them in its own variables, and
  they measure their ratio by finite differences of the sampled accelerations or torques
  (samples in increasing time, e.g. at a servo rate).

Each constraint has a ``kind`` (the quantity it limits: ``"torque"``, ``"speed"``); when the
check finds an excess of a kind, the solver tightens every constraint of that kind by it
(:meth:`Constraint.scaled`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Protocol

import numpy as np

from .._arrays import Array
from ..motors import MotorLimits
from ..registry import Registry
from .base import Law


@dataclass(frozen=True)
class ConditionRow:
    """An equality ``cu u + cx x + cg = 0`` on the path's acceleration ``u = sddot`` and squared
    speed ``x = sdot^2`` at grid point ``index`` (a degeneracy condition: the normal component
    of the end-effector's force at a crossing of the parallel singularity curve, in force
    units)."""

    index: int
    cu: float
    cx: float
    cg: float


@dataclass(frozen=True)
class PathCoefficients:
    """The path dynamics on a grid of arc lengths: ``tau = a u + b x + g + f``.

    Attributes
    ----------
    s : ndarray, shape (N + 1,)
        Arc lengths of the grid, increasing from 0 to the path's length.
    P : ndarray, shape (N + 1, 2)
        End-effector positions (for the words of an error).
    a, b, g : ndarray, shape (N + 1, 2)
        ``M q'``, ``M q'' + c(q, q')`` and the gravity torques.
    dq_ds : ndarray, shape (N + 1, 2)
        ``q'``, the joint rates per unit arc length.
    coulomb, viscous : ndarray, shape (2,)
        The motors' friction coefficients.
    d2q_ds2 : ndarray, shape (N + 1, 2), optional
        ``q''`` (for the joint accelerations; None: zero, a straight line in joint space).
    coulomb_speed : float
        The regularisation speed of the Coulomb friction (``tanh(qdot / coulomb_speed)``).
    conditions : tuple of ConditionRow
        Equalities the motion must meet at some grid points (the degeneracy conditions of
        crossings of the parallel singularity curve); :class:`DegeneracyCondition` imposes
        them.
    holdable : ndarray of bool, shape (N + 1,), optional
        The grid points where holding the robot still is a meaningful check (None: all);
        near a crossing of the parallel singularity curve no finite torque holds it there,
        and the motion passes.
    """

    s: Array
    P: Array
    a: Array
    b: Array
    g: Array
    dq_ds: Array
    coulomb: Array
    viscous: Array
    d2q_ds2: Array | None = None
    coulomb_speed: float = 1.0
    conditions: tuple[ConditionRow, ...] = ()
    holdable: Array | None = None

    @property
    def ddq_ds(self) -> Array:
        """``q''`` (N + 1, 2), zeros when not given."""
        return np.zeros_like(self.dq_ds) if self.d2q_ds2 is None else self.d2q_ds2

    @cached_property
    def friction_sides(self) -> tuple[Array, Array]:
        """Where each joint's friction may push up (forward motion, or a reversal near) and
        down: two arrays (N + 1, 2) of 1.0 and 0.0, both 0 at the two rest points (where
        friction is exactly zero)."""
        sg = np.sign(self.dq_ds)
        steady = (sg == np.roll(sg, 1, axis=0)) & (sg == np.roll(sg, -1, axis=0)) & (sg != 0)
        steady[[0, -1]] = (sg[[0, -1]] == sg[[1, -2]]) & (sg[[0, -1]] != 0)
        up = ((steady & (sg > 0)) | ~steady).astype(float)
        down = ((steady & (sg < 0)) | ~steady).astype(float)
        up[[0, -1]] = down[[0, -1]] = 0.0
        return up, down


@dataclass(frozen=True)
class JointSamples:
    """A law's motion sampled through the exact model: the torques and the joint rates (and
    the joint accelerations and the times, for the limits on them and on their rates).

    Attributes
    ----------
    tau, dq : ndarray, shape (n, 2)
    ddq : ndarray, shape (n, 2), optional
    t : ndarray, shape (n,), optional
        The sample times.
    """

    tau: Array
    dq: Array
    ddq: Array | None = None
    t: Array | None = None


class PathDynamics(Protocol):
    """The robot along a path, as the laws planned on its dynamics need it."""

    @property
    def length(self) -> float:
        """The path's length."""
        ...

    def coefficients(self, s: Array) -> PathCoefficients:
        """The coefficients at the arc lengths ``s`` (N + 1,), from 0 to the length."""
        ...

    def samples(self, law: Law, times: Array) -> JointSamples:
        """``law`` at ``times`` through the exact model (gravity and friction included)."""
        ...


@dataclass(frozen=True)
class PointRows:
    """Rows ``pu u + px x <= ph`` at every grid point, each array (N + 1, m)."""

    pu: Array
    px: Array
    ph: Array


@dataclass(frozen=True)
class Tangent:
    """The grid's coefficients with the tangent point ``x0`` (N + 1,) of the speed-dependent
    bounds (None before there is one), shared by the constraints of one solve."""

    co: PathCoefficients
    x0: Array | None

    @cached_property
    def friction(self) -> tuple[Array, Array, Array, Array]:
        """Friction ``f`` in ``[phi_lo + psi_lo x, phi_hi + psi_hi x]`` at each grid point,
        arrays (N + 1, 2)."""
        co, x0 = self.co, self.x0
        up, down = co.friction_sides
        if x0 is None:
            far_phi, far_psi = np.broadcast_to(co.coulomb, up.shape), np.zeros(up.shape)
        else:  # viscous |f| <= w sqrt(x) <= w (x + x0) / (2 sqrt(x0)), tangent at x0
            r = np.sqrt(np.maximum(x0, 1e-9 * max(float(x0.max()), 1e-300)))[:, None]
            w = co.viscous * np.abs(co.dq_ds)
            far_phi, far_psi = co.coulomb + 0.5 * w * r, 0.5 * w / r
        return -down * far_phi, -down * far_psi, up * far_phi, up * far_psi


class Constraint(ABC):
    """One limit of a law along a path (see the module doc)."""

    #: The quantity limited; the check's excess of a kind tightens every constraint of it.
    kind: str = ""

    def rows(self, tangent: Tangent) -> PointRows | None:
        """Rows at every grid point (None: this constraint has none)."""
        return None

    def speed_cap(self, co: PathCoefficients) -> Array | None:
        """The largest squared path speed (N + 1,) it allows (None: no cap)."""
        return None

    def needs_tangent(self, co: PathCoefficients) -> bool:
        """True when its rows bound a ``sqrt(x)`` by a tangent (speed-dependent bounds)."""
        return False

    @abstractmethod
    def sample_ratios(self, js: JointSamples) -> Array:
        """The ratio of the limited quantity to its limit at each sample (n,), or for a limit
        on a rate between each two consecutive samples (n - 1,)."""

    def ratio(self, js: JointSamples) -> float:
        """Largest ratio of the limited quantity to its limit on the samples."""
        return float(self.sample_ratios(js).max(initial=0.0))

    @abstractmethod
    def scaled(self, scales: Mapping[str, float]) -> Constraint:
        """The constraint with its limits multiplied by ``scales[kind]`` (tightened)."""

    #: 2 for a limit on the state and the acceleration (rows in ``(u, x)``), 3 for a limit on
    #: the jerk or the torque rate.
    order: int = 2

    @property
    def torque_limit(self) -> tuple[float, float] | None:
        """The peak torques it imposes, for the words of an error (None: not a torque)."""
        return None

    @property
    def speed_limit(self) -> tuple[float, float] | None:
        """The joint speeds it imposes (None: not a speed limit)."""
        return None


def _pair(v: Array) -> tuple[float, float]:
    return float(v[0]), float(v[1])


@dataclass(frozen=True)
class TorqueLimit(Constraint):
    """``|tau_i| <= peak_i`` at every point, friction bounded (see the module doc)."""

    peak: tuple[float, float]
    kind: str = "torque"

    def rows(self, tangent: Tangent) -> PointRows:
        """``a u + b x + g + f <= T`` and ``-(a u + b x + g + f) <= T`` at every point."""
        co, tmax = tangent.co, np.asarray(self.peak, float)
        phi_lo, psi_lo, phi_hi, psi_hi = tangent.friction
        return PointRows(np.concatenate([co.a, -co.a], axis=1),
                         np.concatenate([co.b + psi_hi, -(co.b + psi_lo)], axis=1),
                         np.concatenate([tmax - co.g - phi_hi, tmax + co.g + phi_lo], axis=1))

    def needs_tangent(self, co: PathCoefficients) -> bool:
        """A viscous friction's bound is a tangent."""
        return bool(np.any(co.viscous > 0))

    def sample_ratios(self, js: JointSamples) -> Array:
        """``max_i |tau_i| / peak_i`` at each sample."""
        return _torque_ratios(MotorLimits(self.peak), js)

    def scaled(self, scales: Mapping[str, float]) -> TorqueLimit:
        """The peak torques tightened by ``scales["torque"]``."""
        return replace(self, peak=_pair(np.asarray(self.peak, float) * scales.get("torque", 1.0)))

    @property
    def torque_limit(self) -> tuple[float, float]:
        """The peak torques."""
        return self.peak


@dataclass(frozen=True)
class SpeedLimit(Constraint):
    """``|qdot_i| <= max_speed_i``: a cap on the squared path speed."""

    max_speed: tuple[float, float]
    kind: str = "speed"

    def speed_cap(self, co: PathCoefficients) -> Array:
        """``min_i (max_speed_i / |q'_i|)^2`` (``inf`` where neither joint moves)."""
        wmax = np.asarray(self.max_speed, float)
        with np.errstate(divide="ignore"):
            return np.asarray(np.min(np.where(co.dq_ds != 0, (wmax / np.abs(co.dq_ds)) ** 2,
                                              np.inf), axis=1))

    def sample_ratios(self, js: JointSamples) -> Array:
        """``max_i |qdot_i| / max_speed_i`` at each sample."""
        return np.asarray((np.abs(js.dq) / np.asarray(self.max_speed, float)).max(axis=1))

    def scaled(self, scales: Mapping[str, float]) -> SpeedLimit:
        """The speeds tightened by ``scales["speed"]``."""
        return replace(self, max_speed=_pair(np.asarray(self.max_speed, float)
                                             * scales.get("speed", 1.0)))

    @property
    def speed_limit(self) -> tuple[float, float]:
        """The maximum speeds."""
        return self.max_speed


@dataclass(frozen=True)
class TorqueSpeedEnvelope(Constraint):
    """Full torque up to ``knee``, then linearly down to zero at ``max_speed``: a torque
    limit whose tightening scales the peak by ``scales["torque"]`` and the speeds by
    ``scales["speed"]``."""

    peak: tuple[float, float]
    max_speed: tuple[float, float]
    knee: tuple[float, float]
    kind: str = "torque"

    def rows(self, tangent: Tangent) -> PointRows | None:
        """``|tau| + sigma |q'| sqrt(x) <= T + sigma knee`` with ``sqrt(x)`` bounded by its
        tangent at ``max(x0, x_knee)`` (none before the first tangent point)."""
        co, x0 = tangent.co, tangent.x0
        if x0 is None:
            return None
        tmax, wmax = np.asarray(self.peak, float), np.asarray(self.max_speed, float)
        knee = np.asarray(self.knee, float)
        phi_lo, psi_lo, phi_hi, psi_hi = tangent.friction
        sigma = tmax / (wmax - knee)
        qabs = np.abs(co.dq_ds)
        with np.errstate(divide="ignore"):
            xk = np.where(qabs > 0, (knee / qabs) ** 2, np.inf)
        r = np.sqrt(np.minimum(np.maximum(x0[:, None], xk), 1e300))
        slope = np.where(qabs > 0, sigma * qabs / (2 * r), 0.0)
        offset = np.where(qabs > 0, sigma * qabs * r / 2, 0.0)
        cap = tmax + sigma * knee - offset
        return PointRows(np.concatenate([co.a, -co.a], axis=1),
                         np.concatenate([co.b + psi_hi + slope, -(co.b + psi_lo) + slope],
                                        axis=1),
                         np.concatenate([cap - co.g - phi_hi, cap + co.g + phi_lo], axis=1))

    def needs_tangent(self, co: PathCoefficients) -> bool:
        """The envelope's ``sqrt(x)`` is bounded by a tangent."""
        return True

    def sample_ratios(self, js: JointSamples) -> Array:
        """``max_i |tau_i|`` over the torque available at the sample's speed."""
        return _torque_ratios(MotorLimits(self.peak, self.max_speed, self.knee), js)

    def scaled(self, scales: Mapping[str, float]) -> TorqueSpeedEnvelope:
        """Peak tightened by ``scales["torque"]``, speeds by ``scales["speed"]``."""
        t, w = scales.get("torque", 1.0), scales.get("speed", 1.0)
        return replace(self, peak=_pair(np.asarray(self.peak, float) * t),
                       max_speed=_pair(np.asarray(self.max_speed, float) * w),
                       knee=_pair(np.asarray(self.knee, float) * w))

    @property
    def torque_limit(self) -> tuple[float, float]:
        """The peak torques."""
        return self.peak


@dataclass(frozen=True)
class AccelerationLimit(Constraint):
    """``|qddot_i| = |q'_i u + q''_i x| <= max_acceleration_i``: rows linear in ``(u, x)``."""

    max_acceleration: tuple[float, float]
    kind: str = "acceleration"

    def rows(self, tangent: Tangent) -> PointRows:
        """``+-(q' u + q'' x) <= max_acceleration`` at every point."""
        co = tangent.co
        amax = np.broadcast_to(np.asarray(self.max_acceleration, float), co.dq_ds.shape)
        d1, d2 = co.dq_ds, co.ddq_ds
        return PointRows(np.concatenate([d1, -d1], axis=1), np.concatenate([d2, -d2], axis=1),
                         np.concatenate([amax, amax], axis=1))

    def sample_ratios(self, js: JointSamples) -> Array:
        """``max_i |qddot_i| / max_acceleration_i`` at each sample (0 without
        accelerations)."""
        if js.ddq is None:
            return np.zeros(len(js.tau))
        return np.asarray((np.abs(js.ddq) / np.asarray(self.max_acceleration, float))
                          .max(axis=1))

    def scaled(self, scales: Mapping[str, float]) -> AccelerationLimit:
        """The accelerations tightened by the scale of its kind (``scales["acceleration"]``;
        a cap of another kind by its own)."""
        return replace(self, max_acceleration=_pair(np.asarray(self.max_acceleration, float)
                                                    * scales.get(self.kind, 1.0)))


@dataclass(frozen=True)
class DegeneracyCondition(Constraint):
    """The equalities of :attr:`PathCoefficients.conditions` (the degeneracy conditions of the
    path's crossings of the parallel singularity curve), as two opposite rows at their grid
    points (none elsewhere). Its ratio is 0: the condition holds to rounding at its grid
    point by construction, and its residual along the planned law is measured by
    :func:`dextar.dynamics.crossing.crossing_margins`."""

    kind: str = "degeneracy"

    def rows(self, tangent: Tangent) -> PointRows | None:
        """``cu u + cx x <= -cg`` and ``-(cu u + cx x) <= cg`` at each condition's point,
        scaled to unit size (rows of zeros elsewhere)."""
        co = tangent.co
        if not co.conditions:
            return None
        n = len(co.s)
        pu, px, ph = np.zeros((n, 2)), np.zeros((n, 2)), np.zeros((n, 2))
        for c in co.conditions:
            scale = max(abs(c.cu), abs(c.cx), abs(c.cg), 1e-300)
            row = np.array([c.cu, c.cx, -c.cg]) / scale
            pu[c.index], px[c.index], ph[c.index] = (np.array([row[0], -row[0]]),
                                                     np.array([row[1], -row[1]]),
                                                     np.array([row[2], -row[2]]))
        return PointRows(pu, px, ph)

    def sample_ratios(self, js: JointSamples) -> Array:
        """0 at every sample (see the class doc)."""
        return np.zeros(len(js.dq))

    def ratio(self, js: JointSamples) -> float:
        """0 (see the class doc)."""
        return 0.0

    def scaled(self, scales: Mapping[str, float]) -> DegeneracyCondition:
        """Itself: an equality is not tightened."""
        return self


def _torque_ratios(motors: MotorLimits, js: JointSamples) -> Array:
    """``max_i |tau_i| / available torque_i`` at each sample (``inf`` where a torque is asked
    of a motor that has none left)."""
    avail = motors.available_torque(js.dq)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(avail > 0, np.abs(js.tau) / avail,
                     np.where(np.abs(js.tau) > 0, np.inf, 0.0))
    return np.asarray(r.max(axis=1))


def _rate(values: Array | None, t: Array | None) -> Array | None:
    """Finite differences ``d values / dt`` between consecutive samples (n - 1, 2)."""
    if values is None or t is None or len(t) < 2:
        return None
    dt = np.diff(t)
    return np.asarray(np.diff(values, axis=0) / np.where(dt > 0, dt, np.inf)[:, None])


@dataclass(frozen=True)
class JerkLimit(Constraint):
    """``|qdddot_i| <= max_jerk_i`` (third order); its ratio is measured by finite differences
    of the sampled joint accelerations (samples in increasing time)."""

    max_jerk: tuple[float, float]
    kind: str = "jerk"
    order: int = 3

    def sample_ratios(self, js: JointSamples) -> Array:
        """``max_i |d qddot_i / dt| / max_jerk_i`` between consecutive samples."""
        r = _rate(js.ddq, js.t)
        return np.zeros(0) if r is None else np.asarray(
            (np.abs(r) / np.asarray(self.max_jerk, float)).max(axis=1))

    def scaled(self, scales: Mapping[str, float]) -> JerkLimit:
        """The jerks tightened by ``scales["jerk"]``."""
        return replace(self, max_jerk=_pair(np.asarray(self.max_jerk, float)
                                            * scales.get("jerk", 1.0)))


@dataclass(frozen=True)
class TorqueRateLimit(Constraint):
    """``|d tau_i / dt| <= max_torque_rate_i`` (third order); its ratio is measured by finite
    differences of the sampled torques (samples in increasing time)."""

    max_torque_rate: tuple[float, float]
    kind: str = "torque_rate"
    order: int = 3

    def sample_ratios(self, js: JointSamples) -> Array:
        """``max_i |d tau_i / dt| / max_torque_rate_i`` between consecutive samples."""
        r = _rate(js.tau, js.t)
        return np.zeros(0) if r is None else np.asarray(
            (np.abs(r) / np.asarray(self.max_torque_rate, float)).max(axis=1))

    def scaled(self, scales: Mapping[str, float]) -> TorqueRateLimit:
        """The rates tightened by ``scales["torque_rate"]``."""
        return replace(self, max_torque_rate=_pair(np.asarray(self.max_torque_rate, float)
                                                   * scales.get("torque_rate", 1.0)))


@dataclass(frozen=True)
class ConstraintType:
    """A kind of limit the laws honour, built from the motors' limits.

    Attributes
    ----------
    name : str
        Its name in :data:`CONSTRAINT_TYPES` (and in the docs).
    build : callable
        ``build(motors)``: the constraint for these limits, or None where they do not set it
        (a speed limit without ``max_speed``).
    help : str
        One line for the docs.
    """

    name: str
    build: Callable[[MotorLimits], Constraint | None]
    help: str = ""


#: The limits every time-optimal law (second and third order) plans within, in the order
#: they are built. A new limit is a :class:`Constraint` and one ``register`` call; an
#: installed package adds one through the entry-point group ``dextar.constraints``.
CONSTRAINT_TYPES: Registry[ConstraintType] = Registry("constraint", "constraint",
                                                      group="dextar.constraints")


def _finite_speed(m: MotorLimits) -> Constraint | None:
    return (SpeedLimit(m.max_speed) if np.isfinite(np.asarray(m.max_speed, float)).any()
            else None)


for _kind in (
        ConstraintType("torque", lambda m: TorqueLimit(m.peak_torque),
                       "each motor's peak torque (with friction)"),
        ConstraintType("speed", _finite_speed, "each motor's speed limit, when finite"),
        ConstraintType("envelope", lambda m: None if m.knee_speed is None else
                       TorqueSpeedEnvelope(m.peak_torque, m.max_speed, m.knee_speed),
                       "the torque-speed envelope, when it has a knee"),
        ConstraintType("acceleration", lambda m: None if m.max_acceleration is None else
                       AccelerationLimit(m.max_acceleration),
                       "each joint's acceleration limit, when given"),
        ConstraintType("jerk", lambda m: None if m.max_jerk is None else
                       JerkLimit(m.max_jerk), "each joint's jerk limit, when given"),
        ConstraintType("torque_rate", lambda m: None if m.max_torque_rate is None else
                       TorqueRateLimit(m.max_torque_rate),
                       "each motor's torque rate limit, when given")):
    CONSTRAINT_TYPES.register(_kind)


def motor_constraints(motors: MotorLimits) -> tuple[Constraint, ...]:
    """The motors' limits as constraints, one per registered :class:`ConstraintType` that
    the limits set (:data:`CONSTRAINT_TYPES`: the peak torque, the speed limit when finite,
    the torque-speed envelope when it has a knee, and the acceleration, jerk and torque-rate
    limits when given)."""
    return tuple(c for kind in CONSTRAINT_TYPES.values() if (c := kind.build(motors)) is not None)


def point_rows(constraints: Sequence[Constraint], tangent: Tangent) -> PointRows:
    """Every constraint's rows at every point, side by side (N + 1, m)."""
    rows = [r for c in constraints if (r := c.rows(tangent)) is not None]
    return PointRows(*(np.concatenate([getattr(r, k) for r in rows], axis=1)
                       for k in ("pu", "px", "ph")))


def speed_cap(constraints: Sequence[Constraint], co: PathCoefficients) -> Array:
    """The squared-speed cap (N + 1,) of all constraints (``inf`` where none caps it)."""
    cap = np.full(len(co.s), np.inf)
    for c in constraints:
        x = c.speed_cap(co)
        if x is not None:
            cap = np.minimum(cap, x)
    return cap


def ratios_by_kind(constraints: Sequence[Constraint], js: JointSamples) -> dict[str, float]:
    """The largest ratio of each kind of constraint on the samples."""
    out: dict[str, float] = {}
    for c in constraints:
        r = c.ratio(js)
        out[c.kind] = max(out.get(c.kind, 0.0), r)
    return out
