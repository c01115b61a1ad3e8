"""The start of the search: the second-order time-optimal law passed through a moving-average
filter, and the knots placed where the rows change fast along it.

The filter's width ``rho`` is the time the steepest acceleration switch of the second-order
law needs at the jerk (or torque-rate) limits: the filtered law's acceleration ramps over
``rho`` wherever the second-order law's jumps, it keeps rest and zero acceleration at both
ends, and its duration is ``T2 + rho``. On a single axis with the acceleration limit reached
this is Ruckig's profile, so the programmes start near the answer (Biagiotti & Melchiorri,
*Trajectory Planning for Automatic Machines and Robots*, Springer 2008, sec. 4.4, FIR
filters for jerk-limited profiles)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._arrays import Array
from ..._lazy import lazy_module
from ..base import Law
from ..constraints import (
    Constraint,
    JerkLimit,
    JointSamples,
    PathCoefficients,
    TorqueRateLimit,
)
from .law import JerkLimitedLaw
from .mesh import Mesh, make_mesh, projected
from .rows import compiled_monitor
from .table import DB, DG, Q1, Q2, Q3, A, B, Table, values_at

ndimage = lazy_module("scipy.ndimage")


def jumps(base: Any) -> tuple[Array, Array]:
    """The second-order law's acceleration jumps (with the jumps from rest and to rest at
    the ends): arc lengths (N + 1,) and sizes."""
    u = np.concatenate([[0.0], np.asarray(base.accel, float), [0.0]])
    return np.asarray(base.knots_s, float), np.diff(u)


def ramp(base: Any, table: Table, third: Sequence[Constraint]) -> float:
    """The time the steepest of the second-order law's acceleration jumps takes at the
    third-order limits (the joint jerk ``q' du / rho``, the torque rate ``a du / rho``)."""
    s, jump = jumps(base)
    v = table.at(s)[0]
    q1, a = np.abs(v[:, Q1]), np.abs(v[:, A])
    rho = 0.0
    for c in third:
        if isinstance(c, JerkLimit):
            rho = max(rho, float((np.abs(jump)[:, None] * q1 / np.asarray(c.max_jerk)).max()))
        elif isinstance(c, TorqueRateLimit):
            rho = max(rho, float((np.abs(jump)[:, None] * a
                                  / np.asarray(c.max_torque_rate)).max()))
    return rho


#: The share of a third-order limit the start's speed cap leaves to the path's terms alone
#: (the joint jerk ``q''' sdot^3``, the torque rate ``b' sdot^3`` and ``g' sdot``): the rest
#: is for the motion's acceleration and jerk.
CAP_SHARE = 0.5


def third_order_cap(table: Table, third: Sequence[Constraint]) -> Array:
    """The squared path speed (N + 1,) at which the path's own terms of a third-order limit
    (those without the motion's acceleration or jerk: ``q''' sdot^3`` of the joint jerk;
    ``b' sdot^3`` and ``g' sdot`` of the torque rate) use :data:`CAP_SHARE` of it, at the
    table's points (``inf`` where none)."""
    v = np.concatenate([np.abs(table.lo[:1]), np.maximum(np.abs(table.lo[1:]),
                                                         np.abs(table.hi[:-1])),
                        np.abs(table.hi[-1:])])
    cap = np.full(len(v), np.inf)
    with np.errstate(divide="ignore"):
        for c in third:
            if isinstance(c, JerkLimit):
                lim = CAP_SHARE * np.asarray(c.max_jerk, float)
                cap = np.minimum(cap, ((lim / v[:, Q3]) ** (2 / 3)).min(axis=1))
            elif isinstance(c, TorqueRateLimit):
                lim = CAP_SHARE * np.asarray(c.max_torque_rate, float)
                cap = np.minimum(cap, ((lim / v[:, DB]) ** (2 / 3)).min(axis=1))
                cap = np.minimum(cap, ((lim / v[:, DG]) ** 2).min(axis=1))
    return cap


@dataclass(frozen=True, eq=False)
class CapConstraint(Constraint):
    """A cap on the squared path speed, given on a grid of arc lengths (the start's
    third-order cap for the second-order law; never measured: its ratio is 0)."""

    s: Array
    cap: Array
    kind: str = "start cap"

    def speed_cap(self, co: PathCoefficients) -> Array:
        """The cap at the points ``co.s`` (linear between the grid's)."""
        return np.asarray(np.interp(co.s, self.s, self.cap))

    def sample_ratios(self, js: JointSamples) -> Array:
        """Nothing is measured: zeros."""
        return np.zeros(len(js.tau))

    def scaled(self, scales: Mapping[str, float]) -> CapConstraint:
        """Unchanged."""
        return self


@dataclass(frozen=True)
class Start:
    """The second-order law filtered by a moving average of width ``rho`` on a fine time
    grid ``t`` (n,) from 0 to ``T = T2 + rho``: arc length, speed, acceleration; ``width``
    the filter's ``rho`` (0 for a start made otherwise)."""

    t: Array
    s: Array
    v: Array
    a: Array
    width: float = 0.0

    @property
    def T(self) -> float:
        """The duration."""
        return float(self.t[-1])


def filtered(base: Any, rho: float, length: float, n: int = 4001) -> Start:
    """``a(t) = (v2(t) - v2(t - rho)) / rho``, ``v(t) = (s2(t) - s2(t - rho)) / rho`` and
    ``s`` its integral (``v2, s2`` the second-order law's speed and arc length)."""
    T2 = float(base.duration)
    t = np.linspace(0.0, T2 + rho, n)
    s2, v2 = base.evaluate(np.clip(t, 0.0, T2))[:2]
    s2 = np.where(t > T2, length, s2)
    v2 = np.where(t > T2, 0.0, v2)
    sb = np.interp(t - rho, t, s2, left=0.0)
    vb = np.interp(t - rho, t, v2, left=0.0)
    v = (s2 - sb) / rho
    a = (v2 - vb) / rho
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    return Start(t, s * (length / s[-1]), v, a, rho)


def slowed_to_cap(start: Start, grid: Array, ok: Array, slack: float) -> Start:
    """The start slowed where its speed passes ``ok`` (a speed cap at the arc lengths
    ``grid``) by more than ``slack``: its time stretched by a factor that is at least the
    speed's excess over the cap wherever it passes it (the excess's largest within half the
    start's filter's width of each time, averaged over that width, so that the slowing is as
    smooth as the start), then sampled again on as many equal times. The moving average of
    the filter passes a short slow stretch (a blend's end, where the path's third derivative
    jumps) far above its cap."""
    t, s, v = start.t, start.s, start.v
    with np.errstate(divide="ignore", invalid="ignore"):
        over = np.where(v > 0, v / np.interp(s, grid, ok), 0.0)
    if not over.max(initial=0.0) > 1.0 + slack:  # (also NaN: the start as it is)
        return start
    phi = np.maximum(np.nan_to_num(over, nan=0.0, posinf=0.0), 1.0)
    dt = float(t[1] - t[0])
    size = 2 * max(1, int(round(start.width / (2 * dt)))) + 1
    phi = ndimage.uniform_filter1d(ndimage.maximum_filter1d(phi, size, mode="nearest"), size,
                                   mode="nearest")
    tw = np.concatenate([[0.0], np.cumsum(0.5 * (phi[1:] + phi[:-1]) * dt)])
    tu = np.linspace(0.0, float(tw[-1]), len(t))
    vu = np.interp(tu, tw, v / phi)
    au = np.gradient(vu, tu)
    au[0] = au[-1] = 0.0
    return Start(tu, np.interp(tu, tw, s), vu, au, start.width)


#: The fewest intervals between two of the path's joints (each a pinned knot, where the
#: jerk may jump): a stretch's jerks must meet its end's arc length and carry on its speed
#: and acceleration. (A long chain's start slowed 12.7 times was placed with 752 knots for
#: 450 joints: its jerks projected onto them were 24 to 60 times too slow for its limits.)
STRETCH_INTERVALS = 4


def joints_passed(start: Start, joints: Array) -> tuple[Array, Array]:
    """The path's ``joints`` (arc lengths) the start passes inside its ends, and when."""
    s = start.s
    inner = joints[(joints > 0) & (joints < s[-1])]
    return inner, np.interp(inner, s, start.t)


def fractions(start: Start, table: Table, cons: Sequence[Constraint], segments: int,
               tol: float = 2e-3) -> Array:
    """The knots' fractions of the duration (M + 1,): at least ``segments`` per duration,
    and where the rows change fast along the start motion as many as keep the rows between
    the knots and the middles within about ``tol`` of their values there (the second-order
    rows near their limits are at the quarters too: within about a quarter of it).

    The monitor is the second time derivative ``c`` of the motion's joint accelerations,
    torques (without friction) and joint jerks from the path's curvature (``q'' v^2``,
    ``b v^2``, ``3 q'' v a + q''' v^3``) over their limits: a function exceeds its values at
    points ``h / 2`` apart by up to ``c h^2 / 32`` between them, so the density is
    ``sqrt(c / (32 tol))`` intervals per unit time."""
    t, s, v, a = start.t, start.s, start.v, start.a
    kinds: list[float] = []  # 0 acceleration, 1 torque, 2 jerk, 3 speed (see _monitor)
    lims: list[Array] = []
    seen: set[tuple[str, tuple[float, ...]]] = set()  # (a part twice changes no maximum)
    for c in cons:
        lim = getattr(c, "max_acceleration", None)
        if lim is not None and ("acceleration", tuple(lim)) not in seen:
            seen.add(("acceleration", tuple(lim)))
            kinds.append(0.0)
            lims.append(np.asarray(lim, float))
        lim = c.torque_limit
        if lim is not None and ("torque", tuple(lim)) not in seen:
            seen.add(("torque", tuple(lim)))
            kinds.append(1.0)
            lims.append(np.asarray(lim, float))
        if isinstance(c, JerkLimit):
            kinds.append(2.0)
            lims.append(np.asarray(c.max_jerk, float))
        wmax = getattr(c, "max_speed", None)
        if wmax is not None:  # near the speed limit, the envelope's torque falls steeply
            knee = getattr(c, "knee", None)
            kinds.append(3.0)
            lims.append(np.asarray(wmax, float) - (0.0 if knee is None else np.asarray(knee)))
    dt = t[1] - t[0]
    c2 = _monitor(table, s, v, a, kinds, lims, dt)
    density = np.maximum(np.sqrt(c2 / (32 * tol)), segments / start.T)
    # between two of the path's joints (pinned knots) at least STRETCH_INTERVALS (a span
    # shorter than two samples as two samples: the density is sampled, and bounded)
    tj = joints_passed(start, table.joints)[1]
    if tj.size:
        edges = np.concatenate([[0.0], tj, [t[-1]]])
        span = np.maximum(np.diff(edges), 2 * dt)
        density = np.maximum(density, STRETCH_INTERVALS / span[
            np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(span) - 1)])
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * dt)])
    M = max(segments, int(np.ceil(cdf[-1])))
    f = np.interp(np.linspace(0.0, cdf[-1], M + 1), cdf, t / start.T)
    f[0], f[-1] = 0.0, 1.0
    return np.asarray(f)


def _monitor(table: Table, s: Array, v: Array, a: Array, kinds: list[float],
             lims: list[Array], dt: float) -> Array:
    """The monitor of :func:`fractions` at the samples ``s, v, a`` (n,): the largest second
    time difference of its parts (``kinds``: 0 the joint accelerations ``q' a + q'' v^2``,
    1 the torques without friction ``a_ a + b v^2``, 2 the joint jerks from the path's
    curvature ``3 q'' v a + q''' v^3``, 3 the joint speeds ``q' v``) over their limits
    ``lims`` (2, each); compiled where built (_rows.c: the same arithmetic)."""
    out = compiled_monitor(table.s, table.lo, table.hi, s, v, a, kinds, lims, dt)
    if out is not None:
        return out
    used = max(c.stop for c in (Q1, Q2, Q3, A, B))  # (the columns it needs, first)
    vals = values_at(table.s, table.lo[:, :used], table.hi[:, :used], s)
    q1, q2, q3 = vals[:, Q1], vals[:, Q2], vals[:, Q3]
    vv, aa = v[:, None], a[:, None]
    torque: Array | None = None
    parts: list[Array] = []
    for kind, lim in zip(kinds, lims, strict=True):
        if kind == 0.0:
            parts.append((q1 * aa + q2 * vv * vv) / lim)
        elif kind == 1.0:
            if torque is None:
                torque = vals[:, A] * aa + vals[:, B] * vv * vv
            parts.append(torque / lim)
        elif kind == 2.0:
            parts.append((3 * q2 * vv * aa + q3 * vv**3) / lim)
        else:
            parts.append(q1 * vv / lim)
    # every part's columns side by side: one pair of differences (the same per column)
    return (np.abs(_gradient(_gradient(np.concatenate(parts, axis=1), dt), dt))
            .max(axis=1, initial=0.0) if parts else np.zeros_like(s))


def _gradient(f: Array, dx: float) -> Array:
    """``np.gradient(f, dx, axis=0)`` (central differences inside, one-sided at the ends:
    the same operations, so the same bits) without its temporaries."""
    out = np.empty_like(f)
    np.subtract(f[2:], f[:-2], out=out[1:-1])
    out[1:-1] /= 2.0 * dx
    out[0] = (f[1] - f[0]) / dx
    out[-1] = (f[-1] - f[-2]) / dx
    return out


def pinned(f: Array, start: Start, joints: Array) -> Mesh:
    """The mesh of the knots ``f`` with, for each of the path's ``joints`` (arc lengths) the
    start motion passes, the nearest inner knot moved to where it passes it and pinned there
    (the path's curvature's derivative jumps at a joint: the jerk may jump at a knot)."""
    f = np.array(f, float)
    M = len(f) - 1
    pin_f: list[float] = []
    pin_s: list[float] = []
    taken: set[int] = set()
    inner, tj = joints_passed(start, joints)
    for sj, fj in zip(inner.tolist(), (tj / start.T).tolist(), strict=True):
        # the nearest knot (the first of two as near; the knots stay increasing as each
        # pinned one stays between its neighbours), by bisection: a long chain has
        # hundreds of joints and thousands of knots
        i = int(np.searchsorted(f, fj))
        k = i - 1 if i > M or (i > 0 and fj - f[i - 1] <= f[i] - fj) else i
        if 0 < k < M and k not in taken and f[k - 1] < fj < f[k + 1]:
            f[k] = fj
            taken.add(k)
            pin_f.append(fj)
            pin_s.append(sj)
    return make_mesh(f, np.asarray(pin_f, float), np.asarray(pin_s, float))


def start_jerks(start: Start, mesh: Mesh, length: float) -> Array:
    """The normalised jerks (M,) whose knot accelerations are the start motion's, changed
    the least to meet the end conditions and the pinned knots exactly (every interval's
    duration normalised by the start's)."""
    T, f = start.T, mesh.f
    # the start's acceleration at rest at both ends: its samples' last one is a difference
    # of speeds interpolated between samples, not quite zero, and knots finer than the
    # samples near the end took that slope and then jumped to zero in the last interval (a
    # jerk growing with the knots: 61 % over at 16k knots, the start 17 % slower)
    a = start.a.copy()
    a[0] = a[-1] = 0.0
    ak = np.interp(f * T, start.t, a)
    ak[0] = ak[-1] = 0.0
    Tk = np.full(mesh.M, T)
    j = projected(mesh, np.diff(ak) / (mesh.h * T), Tk, length)
    return np.asarray(j * T**3)


#: A motion is idle where its speed and acceleration stay below these fractions of their
#: largest (it barely moves: a stop before a pinned knot the motion reached early, a wait at
#: the end) for at least :data:`IDLE_SPAN` of the duration; the re-timing removes that time.
IDLE_SPEED = 0.02
IDLE_ACCEL = 0.05
IDLE_SPAN = 0.03


def without_idle(law: Law, n: int = 4001, always: bool = False) -> Start | None:
    """The law sampled on ``n`` times with its idle spans cut out (the motion before and
    after each span joined: the states there differ by the little it moves while idle), as
    a start motion; None when it has no idle span (unless ``always``: then the law
    sampled)."""
    T = float(law.duration)
    t = np.linspace(0.0, T, n)
    # (a jerk-limited law's arc length only for a start: its speed and acceleration alone)
    lazy = law if not always and isinstance(law, JerkLimitedLaw) else None
    if lazy is not None:
        v, a = lazy.speed_and_acceleration(t)
    else:
        s, v, a = law.evaluate(t)[:3]
    still = (np.abs(v) <= IDLE_SPEED * np.abs(v).max()) & \
        (np.abs(a) <= IDLE_ACCEL * np.abs(a).max())
    # runs of still samples, long enough
    edges = np.diff(np.concatenate([[0], still.astype(int), [0]]))
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    long = (t[last] - t[first]) >= IDLE_SPAN * T
    if not long.any():
        return Start(t, s, v, a) if always else None
    if lazy is not None:
        s = lazy.evaluate(t)[0]
    cut = np.zeros(n - 1, bool)  # the sample pairs whose time is removed
    for i0, i1 in zip(first[long], last[long], strict=True):
        cut[i0:i1] = True
    dt = np.where(cut, 0.0, np.diff(t))
    keep = np.concatenate([[True], ~cut])
    tn = np.concatenate([[0.0], np.cumsum(dt)])[keep]
    return Start(tn, s[keep], v[keep], a[keep])
