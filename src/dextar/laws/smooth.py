"""Jerk-limited time-optimal law of motion along a path: the fastest rest-to-rest motion,
starting and ending with zero acceleration, within the limits of the robot's dynamics
(torque with friction, speed, torque-speed envelope, joint acceleration) and within the
third-order limits (joint jerk, torque rate).

Method: direct transcription in time with piecewise-constant jerk, solved by sequential
linear programming (SLP) with the duration found by a secant search.

* The motion is ``M`` intervals of constant path jerk ``j_k`` (a cubic ``s(t)`` on each), the
  knots at fixed fractions of the duration ``T`` (finer where the second-order law switches
  its acceleration and at the two ends). From rest, the knots' path acceleration, speed and
  arc length are linear in the jerks (the exact integration of a piecewise-constant jerk), so
  the ends (``s = S``, at rest, zero acceleration) are linear equalities, and the motion
  between the knots is exact: the jerk is constant, the acceleration linear.
* The limits are linear rows at the knots, linearised about a reference motion (the
  previous iterate): the second-order constraint objects give their rows ``pu u + px x <=
  ph`` in ``(u, x) = (sddot, sdot^2)`` at the reference's arc lengths (``x`` by its tangent at
  the reference speed), the speed cap bounds ``sdot``; the joint jerk ``q' sdddot + 3 q''
  sdot sddot + q''' sdot^3`` and the torque rate ``d/dt (a u + b x + g + f)`` are linearised
  about the reference (the "convexified jerk rows"), on both sides of every knot.
* For a duration ``T`` one linear programme finds the jerks that minimise the largest relative
  use ``rho`` of the rows' margins; ``rho(T) = 1`` is found by a secant search in ``(log T,
  log rho)`` from the second-order law's duration (a lower bound), each programme linearised
  about the previous one's motion (time-scaled), so that the search and the linearisation
  converge together (sequential linear programming, as in Debrouwere et al., "Time-optimal
  path following for robots with convex-concave constraints using sequential convex
  programming", IEEE T-RO 29(6), 2013, here in the time domain; the third-order structure as
  in Pham & Pham, "On the structure of the time-optimal path parameterization problem with
  third-order constraints", ICRA 2017).
* Output check and margin, like the second-order law: the law is sampled (eight points in
  every interval) through the exact model; a kind of limit exceeded by more than its
  tolerance (``tol``: torque, speed, acceleration; ``rate_tol``: jerk and torque rate, whose
  ratio is a finite difference) is tightened by the excess and the search run again.

For the kinematic limits alone (a joint move with speed, acceleration and jerk limits) the
transcription is exact, so the law is never faster than the continuous optimum (Ruckig's
profile, Berscheid & Kroeger, "Jerk-limited real-time trajectory generation with arbitrary
target states", RSS 2021) and within the discretisation's loss of it (below 1e-3 with the
default 56 intervals); as the jerk limit grows it tends to the second-order law
(:mod:`dextar.laws.time_optimal`, TOPP-RA), which it calls for its start.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy.optimize import linprog

from .._arrays import Array
from ..errors import InfeasibleError, ParameterError
from ..motors import MotorLimits
from ..units import Units
from .base import Law
from .constraints import (
    Constraint,
    JerkLimit,
    PathCoefficients,
    PathDynamics,
    Tangent,
    TorqueRateLimit,
    motor_constraints,
    point_rows,
    ratios_by_kind,
    speed_cap,
)
from .time_optimal import solve_time_optimal_law

#: Intervals of constant jerk (the knots of the transcription).
SEGMENTS = 56
#: Segments of the second-order law that starts the search (a coarse grid: it only gives the
#: duration's lower bound, the first reference motion and where the acceleration switches).
START_GRID = 120
#: Greatest number of linear programmes of one duration search.
MAX_PROGRAMMES = 10
#: Greatest number of tightenings after the output check.
MAX_ROUNDS = 4
#: The search stops when the shortest duration is bracketed to this (relative).
DURATION_TOL = 2e-4
#: A row joins the first programme when the reference uses more than ``1 - ACTIVE`` of its
#: margin (the others join if the solution crosses them).
ACTIVE = 0.5
#: Check samples per interval.
CHECK_PER_INTERVAL = 8
DEBUG = False  # print the search (development)
#: Tolerance of the third-order ratios (finite differences) on the check samples.
RATE_TOL = 1e-2


@dataclass(frozen=True)
class JerkLimitedLaw(Law):
    """Piecewise-constant jerk law found by :func:`solve_jerk_limited_law`.

    Attributes
    ----------
    knots_t, knots_s, knots_v, knots_a : ndarray, shape (M + 1,)
        Time, arc length, speed and acceleration at the knots (zero speed and acceleration at
        both ends); ``jerk`` (M,) on each interval.
    torque_limit, speed_limit : tuple
        The limits of the motors at A and D (speed limit ``inf`` when none).
    ratios : mapping of str to float
        Largest ratio of each kind of limit on the check samples (``torque``, ``speed``,
        ``acceleration``, ``jerk``, ``torque_rate``).
    second_order_duration : float
        The duration of the second-order (unlimited jerk) law on the same limits.
    status : int
        0 when the limits hold within their tolerances on the check samples, 1 otherwise.
    message : str
    solves : int
        Linear programmes solved.
    """

    distance: float
    duration: float
    knots_t: Array = field(repr=False)
    knots_s: Array = field(repr=False)
    knots_v: Array = field(repr=False)
    knots_a: Array = field(repr=False)
    jerk: Array = field(repr=False)
    torque_limit: tuple[float, float] = (np.inf, np.inf)
    speed_limit: tuple[float, float] = (np.inf, np.inf)
    ratios: Mapping[str, float] = field(default_factory=dict)
    second_order_duration: float = 0.0
    status: int = 0
    message: str = ""
    solves: int = 0
    name: str = field(default="time-optimal", init=False)

    @property
    def max_torque_ratio(self) -> float:
        """Largest ``|tau_i| / limit_i`` on the check samples."""
        return float(self.ratios.get("torque", 0.0))

    def report(self, units: Units) -> dict[str, Any]:
        """The torque limits (N m), the order and the largest ratio of each limit."""
        return {"torque_limit_Nm": [float(units.torque_in_nm(v)) for v in self.torque_limit],
                "max_torque_ratio_check_samples": self.max_torque_ratio, "order": 3,
                "max_ratios_check_samples": dict(self.ratios),
                "second_order_duration": self.second_order_duration}

    def _evaluate(self, t: Array) -> Array:
        k = np.clip(np.searchsorted(self.knots_t, t, side="right") - 1, 0, self.jerk.size - 1)
        tau = t - self.knots_t[k]
        j, a, v = self.jerk[k], self.knots_a[k], self.knots_v[k]
        s = self.knots_s[k] + tau * (v + tau * (a / 2 + tau * j / 6))
        return np.stack([s, v + tau * (a + tau * j / 2), a + tau * j, j])


@dataclass(frozen=True)
class _Table:
    """The path coefficients on a fine grid and their derivatives along the path, for the
    rows at any arc length (linear interpolation)."""

    co: PathCoefficients
    d3q: Array  # q''' (N + 1, 2)
    da: Array   # a' (N + 1, 2)
    db: Array
    dg: Array

    def at(self, s: Array) -> tuple[PathCoefficients, Array, Array, Array, Array]:
        """The coefficients at arc lengths ``s`` (n,) and ``q''', a', b', g'`` (n, 2)."""
        grid = self.co.s
        k = np.clip(np.searchsorted(grid, s, side="right") - 1, 0, len(grid) - 2)
        w = ((np.clip(s, grid[0], grid[-1]) - grid[k]) / (grid[k + 1] - grid[k]))[:, None]

        def f(v: Array) -> Array:
            return np.asarray(v[k] * (1 - w) + v[k + 1] * w)

        co = self.co
        out = PathCoefficients(np.clip(s, grid[0], grid[-1]), f(co.P), f(co.a), f(co.b),
                               f(co.g), f(co.dq_ds), co.coulomb, co.viscous, f(co.ddq_ds),
                               co.coulomb_speed)
        return out, f(self.d3q), f(self.da), f(self.db), f(self.dg)


def _table(dynamics: PathDynamics, s: Array) -> _Table:
    co = dynamics.coefficients(s)

    def d(v: Array) -> Array:
        return np.asarray(np.gradient(v, co.s, axis=0))

    return _Table(co, d(co.ddq_ds), d(co.a), d(co.b), d(co.g))


def _fractions(base: Law, segments: int, ramp: float) -> Array:
    """The knots' fractions of the duration (M + 1,): uniform, and denser (up to about 8
    times) within ``ramp`` (a fraction) of the second-order law's large acceleration switches
    and of the two ends."""
    tau = np.linspace(0.0, 1.0, 4001)
    centres = [0.0, 1.0]
    accel = getattr(base, "accel", None)
    knots_t = getattr(base, "knots_t", None)
    if accel is not None and knots_t is not None and accel.size > 1:
        jump = np.abs(np.diff(accel))
        big = np.flatnonzero(jump > 0.3 * np.abs(accel).max())
        big = big[np.argsort(-jump[big])][:8]
        centres += list(knots_t[1:-1][big] / base.duration)
    if ramp >= 1.0 / segments:  # the ramps span intervals: uniform knots
        return np.linspace(0.0, 1.0, segments + 1)
    width = float(max(ramp, 2e-3))
    density = np.ones_like(tau)
    for c in centres:
        density += 6.0 * np.exp(-0.5 * ((tau - c) / width) ** 2)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(tau))])
    f = np.interp(np.linspace(0.0, cdf[-1], segments + 1), cdf, tau)
    f[0], f[-1] = 0.0, 1.0
    return np.asarray(f)


def _integration(t: Array) -> tuple[Array, Array, Array]:
    """Matrices (M + 1, M) giving the knots' acceleration, speed and arc length from the jerks
    of the intervals between the knot times ``t`` (M + 1,), from rest: a unit jerk on interval
    ``i`` adds ``h``, ``h D + h^2/2`` and ``h D^2/2 + h^2 D/2 + h^3/6`` at a later knot, ``D``
    the time since the interval's end."""
    h = np.diff(t)
    D = t[:, None] - t[None, 1:]
    after = D >= -1e-15 * t[-1]
    D = np.maximum(D, 0.0)
    Ma = np.where(after, h, 0.0)
    Mv = np.where(after, h * D + h * h / 2, 0.0)
    Ms = np.where(after, h * D * D / 2 + h * h * D / 2 + h**3 / 6, 0.0)
    return Ma, Mv, Ms


@dataclass(frozen=True)
class _Reference:
    """The motion the rows are linearised about, at the knots' fractions."""

    s: Array
    v: Array
    a: Array
    j: Array | None = None

    def scaled(self, T_from: float, T_to: float) -> _Reference:
        r = T_from / T_to
        return _Reference(self.s, self.v * r, self.a * r * r,
                          None if self.j is None else self.j * r**3)


def _programme(T: float, f: Array, ref: _Reference, table: _Table,
               second: Sequence[Constraint], third: Sequence[Constraint], length: float,
               work: dict[str, Array]) -> tuple[float, Array] | None:
    """The jerks (M,) that go farthest (up to the path's length) in the duration ``T`` and
    come to rest with zero acceleration, and that distance; None when the programme fails.
    ``work`` keeps the rows of the working set from one programme to the next."""
    t = f * T
    Ma, Mv, Ms = _integration(t)
    M = len(f) - 1
    inner = slice(1, M)
    co, d3q, da, db, dg = table.at(ref.s)
    v0, a0 = np.maximum(ref.v, 0.0), ref.a
    blocks: list[Array] = []
    rhs: list[Array] = []

    def add(G: Array, h: Array) -> None:
        keep = np.isfinite(h)
        blocks.append(G[keep])
        rhs.append(h[keep])

    # second-order rows pu u + px x <= ph at the inner knots, x by its tangent at v0
    rows = point_rows(second, Tangent(co, np.maximum(v0 * v0, 1e-12 * (v0 * v0).max() + 1e-300)))
    vv = v0[inner]
    for m in range(rows.pu.shape[1]):
        pu, px, ph = rows.pu[inner, m], rows.px[inner, m], rows.ph[inner, m]
        add(pu[:, None] * Ma[inner] + (2 * px * vv)[:, None] * Mv[inner], ph + px * vv * vv)
    cap = speed_cap(second, co)
    if np.isfinite(cap).any():
        add(Mv[inner], np.sqrt(cap[inner]))
        # and in the middle of every interval (the speed peaks between knots where the
        # acceleration changes sign), against the lower cap of its two knots
        add(_midpoint_speed(t), np.sqrt(np.minimum(cap[:-1], cap[1:])))
    add(-Mv[inner], np.zeros(M - 1))  # sdot >= 0
    G = np.concatenate(blocks)
    h = np.concatenate(rhs)
    lo, hi = _jerk_bounds(co, d3q, da, db, dg, v0, a0, third, M)
    # max s_M:  s_M <= length, v_M = a_M = 0
    A_eq = np.vstack([Ma[-1], Mv[-1]])
    cost = -Ms[-1]
    bounds = np.stack([lo, hi], axis=1)
    # the working set: rows near their limit at the reference, and those of the last
    # programme; the others join when the solution comes near them (constraint generation)
    margin = ACTIVE * np.maximum(np.abs(h), 1e-12)
    use = (h - G @ ref.j) < margin if ref.j is not None else np.ones(len(h), bool)
    last = work.get("use")
    if last is not None and len(last) == len(h):
        use |= last
    for _ in range(12):
        sel = np.flatnonzero(use)
        res = linprog(cost, A_ub=np.vstack([G[sel], Ms[-1]]),
                      b_ub=np.append(h[sel], length), A_eq=A_eq, b_eq=[0.0, 0.0],
                      bounds=bounds, method="highs-ds")
        if res.status != 0:
            if DEBUG:
                print("    LP status", res.status, res.message)
            return None
        jerk = np.asarray(res.x)
        val = G @ jerk
        crossed = ~use & (val > h + 1e-9 * np.abs(h))
        close = val > h - 0.1 * np.abs(h)
        if DEBUG:
            print("    rows", sel.size, "of", len(h), "crossed", int(crossed.sum()))
        if not crossed.any():
            work["use"] = use | close
            return float(Ms[-1] @ jerk), jerk
        use |= crossed | close
    return None


def _jerk_bounds(co: PathCoefficients, d3q: Array, da: Array, db: Array, dg: Array,
                 v0: Array, a0: Array, third: Sequence[Constraint], M: int
                 ) -> tuple[Array, Array]:
    """Bounds (M,) on the path jerk of every interval from the third-order limits at its two
    knots, their terms in the speed and acceleration frozen at the reference: the joint jerk
    ``q1 j + 3 q2 v a + q3 v^3`` (``q1, q2, q3`` the path derivatives of ``q``) and the torque
    rate ``a j + (a' + 2 b) v a + b' v^3 + g' v + f'(v) (q1 a + q2 v^2)``."""
    lo, hi = np.full(M, -np.inf), np.full(M, np.inf)
    q1, q2, q3 = co.dq_ds, co.ddq_ds, d3q
    v, a = v0[:, None], a0[:, None]
    for c in third:
        if isinstance(c, JerkLimit):
            lim = np.asarray(c.max_jerk, float)
            cj, rest = q1, 3 * q2 * v * a + q3 * v**3
        elif isinstance(c, TorqueRateLimit):
            lim = np.asarray(c.max_torque_rate, float)
            vs = co.coulomb_speed
            cf = co.viscous + co.coulomb / vs / np.cosh(np.clip(q1 * v / vs, -300, 300)) ** 2
            cj = co.a
            rest = ((da + 2 * co.b) * v * a + db * v**3 + dg * v
                    + cf * (q1 * a + q2 * v * v))
        else:
            continue
        with np.errstate(divide="ignore", invalid="ignore"):
            b1 = np.where(np.abs(cj) > 0, (lim - rest) / cj, np.inf)
            b2 = np.where(np.abs(cj) > 0, (-lim - rest) / cj, -np.inf)
        up, dn = np.maximum(b1, b2).min(axis=1), np.minimum(b1, b2).max(axis=1)
        hi = np.minimum(hi, np.minimum(up[:-1], up[1:]))
        lo = np.maximum(lo, np.maximum(dn[:-1], dn[1:]))
    # a reference beyond a limit must not exclude standing still
    return np.minimum(lo, 0.0), np.maximum(hi, 0.0)


def _midpoint_speed(t: Array) -> Array:
    """Matrix (M, M) of the speed in the middle of every interval from the jerks."""
    tm = 0.5 * (t[:-1] + t[1:])
    h = np.diff(t)
    D = tm[:, None] - t[None, :-1]  # time since each interval's start
    inside = D >= 0
    Dc = np.minimum(np.maximum(D, 0.0), h[None, :])
    # a unit jerk on interval i: speed gain h (D - h) + h^2/2 after it, D^2/2 inside it
    return np.asarray(np.where(inside, np.where(D >= h[None, :], h * (D - h) + h * h / 2,
                                                Dc * Dc / 2), 0.0))


def _states(t: Array, jerk: Array) -> tuple[Array, Array, Array]:
    Ma, Mv, Ms = _integration(t)
    return Ms @ jerk, Mv @ jerk, Ma @ jerk


def solve_jerk_limited_law(dynamics: PathDynamics, *, motors: MotorLimits | None = None,
                           constraints: Sequence[Constraint] | None = None,
                           segments: int = SEGMENTS, grid: int | Array = 400,
                           tol: float = 1e-3,
                           rate_tol: float = RATE_TOL,
                           units: Units | None = None) -> JerkLimitedLaw:
    """The fastest rest-to-rest law along a path, with zero acceleration at both ends, within
    the motors' limits including jerk and torque rate (see the module doc).

    Parameters
    ----------
    dynamics : PathDynamics
        The robot along the path (gravity and friction included).
    motors : MotorLimits, optional
        The limits (peak torque, speed, envelope, acceleration, jerk, torque rate).
    constraints : sequence of Constraint, optional
        The limits as constraint objects (instead of ``motors``); one of them must limit the
        torques.
    segments : int
        Intervals of constant jerk (at least 16).
    grid : int or ndarray, shape (N + 1,)
        The coefficient table along the path: a number of equal segments or its arc lengths
        (from 0 to the length; the second-order start law takes every few of them).
    tol, rate_tol : float
        Allowed relative excess of a torque, speed or acceleration (``tol``) and of a jerk
        or torque rate (``rate_tol``) over its limit on the check samples.
    units : Units, optional
        Only for the words of an error.

    Returns
    -------
    JerkLimitedLaw
        With ``status`` and ``message``.

    Raises
    ------
    InfeasibleError
        No motion within the limits exists (from the second-order law), or none was found.
    """
    if constraints is not None:
        cons = tuple(constraints)
    elif motors is not None:
        cons = motor_constraints(motors)
    else:
        raise ParameterError("a jerk-limited law needs the motors' limits (or constraints)")
    if int(segments) != segments or segments < 16:
        raise ParameterError(f"segments = {segments!r} must be a whole number of at least 16")
    if not (0 < tol < 1 and 0 < rate_tol < 1):
        raise ParameterError(f"tolerances {tol!r}, {rate_tol!r} must be in (0, 1)")
    second = [c for c in cons if c.order == 2]
    third = [c for c in cons if c.order == 3]
    length = float(dynamics.length)
    pts = (np.linspace(0.0, length, int(grid) + 1) if np.ndim(grid) == 0
           else np.asarray(grid, float))
    step = max(1, int(np.ceil((len(pts) - 1) / START_GRID)))
    coarse = np.unique(np.concatenate([pts[::step], pts[-1:]]))
    base = solve_time_optimal_law(dynamics, constraints=second,
                                  grid=coarse if len(coarse) > 11 else pts, tol=tol,
                                  units=units)
    T2 = float(base.duration)
    table = _table(dynamics, pts)
    # how long a ramp of the second-order law's acceleration takes at the jerk limits
    co_b = table.at(np.asarray(base.knots_s, float))[0]
    qd = np.abs(co_b.dq_ds).max(axis=0) + 1e-300
    peak = float(np.abs(base.accel).max())
    ramp = 0.0
    for c in third:
        if isinstance(c, JerkLimit):
            ramp = max(ramp, float((peak * qd / np.asarray(c.max_jerk, float)).max()))
        elif isinstance(c, TorqueRateLimit):
            tmax = np.asarray(base.torque_limit, float)
            ramp = max(ramp, float((tmax / np.asarray(c.max_torque_rate, float)).max()))
    f = _fractions(base, int(segments), ramp / max(T2, 1e-300))
    tt = f * T2
    s0, v0, a0, _ = base.evaluate(tt)
    ref = _Reference(s0, v0, a0, np.diff(a0) / np.diff(tt))
    scales = dict.fromkeys((c.kind for c in cons), 1.0)
    T = T2  # a lower bound (the search steps up from below)
    ref = ref.scaled(T2, T)
    solves = 0
    law: JerkLimitedLaw | None = None
    ratio: dict[str, float] = {}
    for _round in range(MAX_ROUNDS + 1):
        sec = [c.scaled(scales) for c in second]
        thi = [c.scaled(scales) for c in third]
        found = _search(T, f, ref, table, sec, thi, length, T2)
        solves += found[3]
        if found[1] is None:
            raise InfeasibleError("no jerk-limited motion within the limits was found "
                                  f"(after {solves} linear programmes)")
        T, jerk, ref = found[0], found[1], found[2]
        t = f * T
        s, v, a = _states(t, jerk)
        s[-1], v[-1], a[-1] = length, 0.0, 0.0
        law = JerkLimitedLaw(length, float(T), t, s, v, a, jerk,
                             base.torque_limit, base.speed_limit, {}, T2, 0, "", solves)
        times = np.concatenate([(t[:-1, None] + np.diff(t)[:, None]
                                 * np.linspace(0.0, 1.0, CHECK_PER_INTERVAL + 1)[None, :-1]
                                 ).reshape(-1), [T]])
        ratio = ratios_by_kind(cons, dynamics.samples(law, times))
        over = {k: r for k, r in ratio.items()
                if r > 1 + (rate_tol if k in ("jerk", "torque_rate") else tol)}
        if not over:
            break
        for k, r in over.items():
            kt = rate_tol if k in ("jerk", "torque_rate") else tol
            scales[k] *= (1 + 0.25 * kt) / r
    assert law is not None
    ok = all(r <= 1 + (rate_tol if k in ("jerk", "torque_rate") else tol)
             for k, r in ratio.items())
    words = ", ".join(f"{k} ratio {r:.5f}" for k, r in ratio.items())
    margin = "" if all(v == 1.0 for v in scales.values()) else (
        "; limits tightened by " + " and ".join(f"{1 - v:.2%} ({k})" for k, v in scales.items()
                                                 if v != 1.0)
        + " so that they hold between the knots")
    if ok:
        msg = (f"jerk-limited time-optimal within the limits: {words} on the check samples "
               f"({segments} intervals of constant jerk, {solves} linear programmes; "
               f"{T / T2 - 1:.2%} longer than the second-order law){margin}")
    else:
        msg = (f"limits exceeded on the check samples after {solves} linear programmes: "
               f"{words}; raise the segments")
    return replace(law, ratios=ratio, status=0 if ok else 1, message=msg)


def hist_p(hist: list[tuple[float, float]]) -> float:
    """The exponent of ``distance ~ T^p`` from the last two programmes below the end (3, the
    pure-jerk scaling, before there are two: a step that stays below)."""
    if len(hist) >= 2 and hist[-1][0] != hist[-2][0]:
        (x1, y1), (x2, y2) = hist[-2], hist[-1]
        return float(np.clip((y2 - y1) / (x2 - x1), 0.5, 3.0))
    return 3.0


def _search(T: float, f: Array, ref: _Reference, table: _Table,
            second: Sequence[Constraint], third: Sequence[Constraint], length: float,
            T_low: float) -> tuple[float, Array | None, _Reference, int]:
    """The shortest duration whose farthest motion reaches the path's end: a secant search
    in ``(log T, log distance)`` below it, each programme linearised about the previous one's
    motion (time-scaled), then the law at the first duration that reaches the end. Returns
    the duration, the jerks, the last reference and the number of programmes."""
    work: dict[str, Array] = {}
    hist: list[tuple[float, float]] = []
    best: tuple[float, Array, _Reference] | None = None
    lo, hi = 0.0, np.inf
    n = 0
    while n < MAX_PROGRAMMES:
        n += 1
        out = _programme(T, f, ref, table, second, third, length, work)
        if out is None:
            lo = max(lo, T)
            Tn = 0.5 * (T + hi) if np.isfinite(hi) else T * 1.25
            ref = ref.scaled(T, Tn)
            T = Tn
            continue
        dist, jerk = out
        if DEBUG:
            print("  T", T, "distance", dist / length)
        s, v, a = _states(f * T, jerk)
        new_ref = _Reference(np.clip(s, 0.0, length), np.maximum(v, 0.0), a, jerk)
        if dist >= length * (1 - 1e-9):
            hi = T
            best = (T, jerk, new_ref)
            if lo > 0 and hi <= lo * (1 + DURATION_TOL):
                break
            Tn = 0.5 * (lo + hi) if lo > 0 else T * 0.9
            if len(hist) >= 1 and lo > 0:  # the secant through the last point below
                x2, y2 = hist[-1]
                Tn = float(np.exp(x2 - y2 / hist_p(hist)))
                if Tn >= hi / (1 + DURATION_TOL):  # predicted at the end: try just below
                    Tn = max(hi / (1 + DURATION_TOL), 0.5 * (lo + hi))
                elif Tn <= lo:
                    Tn = 0.5 * (lo + hi)
        else:
            lo = max(lo, T)
            hist.append((float(np.log(T)), float(np.log(max(dist, 1e-300) / length))))
            Tn = float(np.exp(hist[-1][0] - hist[-1][1] / hist_p(hist))) * (
                1 + 0.5 * DURATION_TOL)
            if np.isfinite(hi) and not Tn < hi:
                Tn = 0.5 * (lo + hi)
        ref = new_ref.scaled(T, Tn)
        T = Tn
    if best is None:
        return T, None, ref, n
    return best[0], best[1], best[2], n


def _build(r: Any) -> Law:
    """The registered ``time-optimal`` builder: the second-order law (TOPP-RA) within the
    motors' torque, speed and acceleration limits, or this jerk-limited one when the motors
    have a jerk or torque-rate limit."""
    from ..errors import ConfigError

    p = r.params
    motors = r.motors
    if p.get("torque_limit") is not None:
        own = MotorLimits.of(p["torque_limit"], p.get("speed_limit_deg_s"))
        motors = own if motors is None else replace(
            own, max_acceleration=motors.max_acceleration, max_jerk=motors.max_jerk,
            max_torque_rate=motors.max_torque_rate)
    elif motors is None:
        raise ConfigError("config key [law].torque_limit is required for a time-optimal law "
                          "(or a [motors] table with peak_torque)")
    if motors.third_order:
        return solve_jerk_limited_law(r.dynamics, motors=motors, grid=p["grid"], units=r.units)
    return solve_time_optimal_law(r.dynamics, motors=motors, grid=p["grid"], units=r.units)


def _register() -> None:
    from .registry import LAW_TYPES, LawType, register_law

    second = LAW_TYPES["time-optimal"]
    register_law(LawType(
        "time-optimal", second.params, _build,
        "the fastest rest-to-rest motion within the motors' limits: torque and speed "
        "(TOPP-RA), and with a jerk or torque-rate limit third order (zero acceleration at "
        "both ends; sequential linear programming)", needs_dynamics=True))


_register()
