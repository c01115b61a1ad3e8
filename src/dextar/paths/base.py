"""Plane paths ``r(p)`` with exact derivatives, arc length and curvature.

Every path has a parameter interval ``[p0, p1]`` (``p1 > p0``) and gives, vectorised over ``p``,
``r, r', r'', r'''`` (derivatives with respect to ``p``). From them: speed ``|r'|``, signed
curvature ``kappa = (r' x r'') / |r'|^3`` and its derivative along the arc ``dkappa/ds``; the
arc length ``s(p)`` and its inverse ``p(s)`` (closed forms where they exist, else Gauss-Legendre
quadrature on a fine table with Hermite interpolation and a Newton polish).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from .._arrays import Array
from .._lazy import lazy_module
from ..errors import ParameterError
from .expression import Expression

# scipy.interpolate is imported where a spline is first built (Spline): it costs a third of a
# second to import (half a second with what it brings), and lines, arcs, expressions and the
# blends of a program (closed forms and HermiteTable) never need it.
interpolate = lazy_module("scipy.interpolate")


class HermiteTable:
    """The piecewise cubic Hermite interpolant of values ``y`` and slopes ``dydx`` at rising
    knots ``x`` (each (n,), n >= 2), evaluated at any points (a value beyond the ends from the
    end piece's cubic).

    ``scipy.interpolate.CubicHermiteSpline(x, y, dydx)`` with the same coefficients and the
    same sum of powers (the same values to the last bit); written here for
    the half second scipy.interpolate takes to import, which a program's path paid for two
    lookups.
    """

    def __init__(self, x: Array, y: Array, dydx: Array) -> None:
        """The table of values ``y`` and slopes ``dydx`` at the knots ``x``."""
        self.x = np.asarray(x, dtype=float)
        y, m = np.asarray(y, dtype=float), np.asarray(dydx, dtype=float)
        h = np.diff(self.x)
        if not (len(self.x) >= 2 and (h > 0).all() and y.shape == m.shape == self.x.shape):
            raise ParameterError("a Hermite table needs rising knots (at least two) and a value "
                                 "and a slope at each")
        slope = np.diff(y) / h
        t = (m[:-1] + m[1:] - 2.0 * slope) / h
        # per piece: y + m dx + c2 dx^2 + c3 dx^3, dx from the piece's left knot
        self.c = np.stack([t / h, (slope - m[:-1]) / h - t, m[:-1], y[:-1]])

    def __call__(self, xi: object) -> Array:
        """The interpolant at ``xi`` (any shape)."""
        xi = np.asarray(xi, dtype=float)
        i = np.clip(np.searchsorted(self.x, xi, side="right") - 1, 0, len(self.x) - 2)
        dx = xi - self.x[i]
        c3, c2, c1, c0 = self.c[:, i]
        dx2 = dx * dx
        return np.asarray(((c0 + c1 * dx) + c2 * dx2) + c3 * (dx2 * dx))


def _cross(a: Array, b: Array) -> Array:
    return np.asarray(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])


class Path(ABC):
    """A plane path ``r(p)``, ``p`` in ``[p0, p1]``; subclasses give :meth:`derivatives`."""

    p0: float
    p1: float
    #: Curvature when it is the same everywhere (lines, arcs), else None.
    constant_curvature: float | None = None

    @abstractmethod
    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """``r, r', r'', r'''`` at ``p`` (shape (...,)), each of shape (..., 2)."""

    def _check_parameter(self, p: object) -> Array:
        p = np.asarray(p, dtype=float)
        span = self.p1 - self.p0
        lo, hi = self.p0 - 1e-9 * span, self.p1 + 1e-9 * span
        # the extremes first (a NaN among the values makes them NaN: not within)
        if p.size and not (p.min() >= lo and p.max() <= hi):
            bad = ~np.isfinite(p) | (p < lo) | (p > hi)
            v = p.reshape(-1)[np.flatnonzero(bad.reshape(-1))[0]]
            raise ParameterError(f"path parameter p = {v:.6g} outside [{self.p0:.6g}, "
                                 f"{self.p1:.6g}]")
        return p

    def position(self, p: object) -> Array:
        """The points ``r(p)``, shape (..., 2)."""
        return self.derivatives(p)[0]

    def speed(self, p: object) -> Array:
        """``ds/dp = |r'(p)|``."""
        return np.asarray(np.linalg.norm(self.derivatives(p)[1], axis=-1))

    def curvature(self, p: object) -> tuple[Array, Array]:
        """Signed curvature ``kappa`` and ``dkappa/ds`` at ``p``."""
        _, r1, r2, r3 = self.derivatives(p)
        v2 = np.sum(r1 * r1, axis=-1)
        v = np.sqrt(v2)
        c12 = _cross(r1, r2)
        kappa = c12 / (v2 * v)
        dkappa_dp = _cross(r1, r3) / (v2 * v) - 3.0 * c12 * np.sum(r1 * r2, axis=-1) / (v2 * v2 * v)
        return kappa, dkappa_dp / v

    # ---------------------------------------------------------------- arc length
    @cached_property
    def _table(self) -> tuple[Array, Array, Array]:
        """Parameter nodes, arc length at the nodes and speed at the nodes."""
        n = 4096
        nodes = np.linspace(self.p0, self.p1, n + 1)
        x, w = np.polynomial.legendre.leggauss(6)
        h = np.diff(nodes)
        mid = 0.5 * (nodes[:-1] + nodes[1:])
        pts = mid[:, None] + 0.5 * h[:, None] * x[None, :]
        seg = 0.5 * h * (self.speed(pts) @ w)
        s = np.concatenate([[0.0], np.cumsum(seg)])
        v = self.speed(nodes)
        if (v <= 1e-12 * max(1.0, float(v.max()))).any():
            i = int(np.flatnonzero(v <= 1e-12 * max(1.0, float(v.max())))[0])
            raise ParameterError(f"path is not regular: |r'(p)| = 0 at p = {nodes[i]:.6g}")
        return nodes, s, v

    @property
    def length(self) -> float:
        """Total arc length."""
        return float(self._table[1][-1])

    def arc_length(self, p: object) -> Array:
        """Arc length ``s(p)`` from ``p0``."""
        return np.asarray(self._forward(self._check_parameter(p)))

    @cached_property
    def _forward(self) -> HermiteTable:
        nodes, s, v = self._table
        return HermiteTable(nodes, s, v)

    @cached_property
    def _inverse(self) -> HermiteTable:
        nodes, s, v = self._table
        return HermiteTable(s, nodes, 1.0 / v)

    def parameter_at(self, s: object) -> Array:
        """The parameter ``p(s)`` at arc length ``s`` (inverse of :meth:`arc_length`)."""
        s = np.asarray(s, dtype=float)
        total = self.length
        if (~np.isfinite(s) | (s < -1e-9 * total) | (s > total * (1 + 1e-9))).any():
            raise ParameterError(f"arc length outside [0, {total:.6g}]")
        p = np.clip(self._inverse(np.clip(s, 0.0, total)), self.p0, self.p1)
        # one Newton step on s(p) - s = 0 (the spline's inverse is within ~1e-12 already)
        p = np.clip(p - (self.arc_length(p) - s) / self.speed(p), self.p0, self.p1)
        return np.asarray(p)

    def sample(self, n: int = 400) -> Array:
        """``n`` points along the path, shape (n, 2)."""
        return self.position(np.linspace(self.p0, self.p1, n))


@dataclass(frozen=True)
class Arc(Path):
    """Circular arc about ``center``: polar angle ``p`` from ``p0`` to ``p1`` counter-clockwise,
    ``r(p) = c + R (cos p, sin p)``; with ``clockwise`` the polar angle is ``-p`` (so ``p`` still
    increases along the motion).

    The paper's semicircle is ``Arc(center=(0, 0), radius=R, p0=0, p1=pi)``.
    """

    radius: float
    p0: float = 0.0
    p1: float = math.pi
    center: tuple[float, float] = (0.0, 0.0)
    clockwise: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ParameterError(f"arc radius {self.radius!r} must be positive and finite")
        if not (math.isfinite(self.p0) and math.isfinite(self.p1) and self.p1 > self.p0):
            raise ParameterError(f"arc angles must satisfy start < end, got {self.p0!r}, "
                                 f"{self.p1!r}")
        c = np.asarray(self.center, dtype=float)
        if c.shape != (2,) or not np.isfinite(c).all():
            raise ParameterError(f"arc centre {self.center!r} must be a finite point (x, y)")

    @property
    def constant_curvature(self) -> float:  # type: ignore[override]  # a property, not a field
        """Signed curvature ``+-1 / radius``."""
        return (-1.0 if self.clockwise else 1.0) / self.radius

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """The position and its first three derivatives at ``p``, each of shape (..., 2)."""
        p = self._check_parameter(p)
        R, sg = self.radius, (-1.0 if self.clockwise else 1.0)
        c, s = np.cos(sg * p), np.sin(sg * p)
        Rc, Rs = R * c, R * s
        # the position and its derivatives written in place (each its own array)
        r, r1, r2, r3 = (np.empty((*p.shape, 2)) for _ in range(4))
        np.add(self.center[0], Rc, out=r[..., 0])
        np.add(self.center[1], Rs, out=r[..., 1])
        np.multiply(-sg * R, s, out=r1[..., 0])
        np.multiply(sg * R, c, out=r1[..., 1])
        np.negative(Rc, out=r2[..., 0])
        np.negative(Rs, out=r2[..., 1])
        np.multiply(sg * R, s, out=r3[..., 0])
        np.multiply(-sg * R, c, out=r3[..., 1])
        return r, r1, r2, r3

    @property
    def length(self) -> float:
        """``R (p1 - p0)``."""
        return self.radius * (self.p1 - self.p0)

    def arc_length(self, p: object) -> Array:
        """``R (p - p0)``."""
        return self.radius * (self._check_parameter(p) - self.p0)

    def parameter_at(self, s: object) -> Array:
        """``p0 + s / R``."""
        p = self.p0 + np.asarray(s, dtype=float) / self.radius
        return np.clip(p, self.p0, self.p1)


#: A line shorter than this fraction of its coordinates is refused (2.2 um at 0.22 m, as
#: NumPy's allclose refused it before): a jerk-limited law along a shorter one took tens of
#: seconds (a 1 um line at 0.12 m: 35 s; 10 um: 0.5 s).
SHORT_LINE = 1e-5


@dataclass(frozen=True)
class Line(Path):
    """Straight segment ``r(p) = a + p (b - a)``, ``p`` in ``[0, 1]``."""

    start: tuple[float, float]
    end: tuple[float, float]
    p0: float = field(default=0.0, init=False)
    p1: float = field(default=1.0, init=False)
    constant_curvature: float = field(default=0.0, init=False)

    def __post_init__(self) -> None:
        a, b = np.asarray(self.start, float), np.asarray(self.end, float)
        if a.shape != (2,) or b.shape != (2,) or not (np.isfinite(a).all() and np.isfinite(b).all()):
            raise ParameterError("line start and end must be two finite points (x, y)")
        length = float(np.hypot(*(b - a)))
        if length == 0.0:
            raise ParameterError("line start and end must differ")
        size = max(float(np.abs(a).max()), float(np.abs(b).max()))
        if not length > SHORT_LINE * size:
            raise ParameterError(
                f"the line is {length:.3g} long, under {SHORT_LINE:g} of the size of its "
                f"coordinates ({size:.3g}): too short to plan a motion along it (leave it out "
                "or make it longer)")

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """``r, r', r'', r'''`` at ``p`` (shape (...,)), each of shape (..., 2)."""
        p = self._check_parameter(p)
        a, b = np.asarray(self.start), np.asarray(self.end)
        r = a + p[..., None] * (b - a)
        d = np.broadcast_to(b - a, r.shape).copy()
        z = np.zeros_like(r)
        return r, d, z, z.copy()

    @property
    def length(self) -> float:
        """``|end - start|``."""
        return float(np.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1]))

    def arc_length(self, p: object) -> Array:
        """``p |end - start|``."""
        return self.length * self._check_parameter(p)

    def parameter_at(self, s: object) -> Array:
        """``s / |end - start|``."""
        return np.clip(np.asarray(s, dtype=float) / self.length, 0.0, 1.0)


@dataclass(frozen=True)
class Spline(Path):
    """Quintic (C4) interpolating spline through waypoints, parametrised by chord length.

    The end conditions set the third and fourth derivatives to zero ("natural" quintic).
    Through two waypoints the spline is the straight segment between them.
    """

    waypoints: tuple[tuple[float, float], ...]
    p0: float = field(default=0.0, init=False)

    def __post_init__(self) -> None:
        w = np.asarray(self.waypoints, dtype=float)
        if w.ndim != 2 or w.shape[1] != 2 or len(w) < 2:
            raise ParameterError("spline waypoints must be at least two points (x, y)")
        if not np.isfinite(w).all():
            raise ParameterError("spline waypoints must be finite")
        chord = np.linalg.norm(np.diff(w, axis=0), axis=1)
        tiny = chord <= 1e-6 * chord.sum()  # a kink of unbounded curvature, not a path
        if tiny.any():
            i = int(np.flatnonzero(tiny)[0])
            raise ParameterError(f"spline waypoints {i} and {i + 1} coincide (they are "
                                 f"{chord[i]:.3g} apart, under 1e-6 of the path's length)")

    @cached_property
    def _knots(self) -> Array:
        """Cumulative chord length at the waypoints (the parameter)."""
        w = np.asarray(self.waypoints, dtype=float)
        return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(w, axis=0), axis=1))])

    @property
    def p1(self) -> float:  # type: ignore[override]  # derived from the waypoints
        """The total chord length."""
        return float(self._knots[-1])

    @cached_property
    def _spl(self) -> Any:
        w = np.asarray(self.waypoints, dtype=float)
        if len(w) == 2:  # the straight segment (a quintic would overshoot it)
            return interpolate.make_interp_spline(self._knots, w, k=1)
        bc = [(3, np.zeros(2)), (4, np.zeros(2))]
        return interpolate.make_interp_spline(self._knots, w, k=5, bc_type=(bc, bc))

    @property
    def constant_curvature(self) -> float | None:  # type: ignore[override]  # a property here
        """0 for the straight two-waypoint spline, else None (varying curvature)."""
        return 0.0 if len(self.waypoints) == 2 else None

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """``r, r', r'', r'''`` of the spline at ``p``, each of shape (..., 2)."""
        p = self._check_parameter(p)
        spl = self._spl
        vals = [spl(p, nu=k) if k <= spl.k else np.zeros(p.shape + (2,)) for k in range(4)]
        return vals[0], vals[1], vals[2], vals[3]


@dataclass(frozen=True)
class ExpressionPath(Path):
    """A path given as text, ``x(p)`` and ``y(p)``, differentiated symbolically.

    ``scale`` multiplies the values (a config's expressions give mm; the run may compute in
    other length units), so that every error quotes the expressions as typed.

    >>> path = ExpressionPath("0.3*cos(p)", "1.2 + 0.2*sin(2*p)", 0.0, 3.0)
    """

    x: str
    y: str
    p0: float = 0.0
    p1: float = 1.0
    scale: float = 1.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.p0) and math.isfinite(self.p1) and self.p1 > self.p0):
            raise ParameterError(f"expression path needs p0 < p1, got {self.p0!r}, {self.p1!r}")
        if not (math.isfinite(self.scale) and self.scale > 0):
            raise ParameterError(f"expression path scale {self.scale!r} must be positive")
        _ = (self._ex, self._ey)  # parse now: a bad expression fails at construction

    @cached_property
    def _ex(self) -> Expression:
        return Expression.parse(self.x)

    @cached_property
    def _ey(self) -> Expression:
        return Expression.parse(self.y)

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """``r, r', r'', r'''`` of the expressions at ``p``, each of shape (..., 2)."""
        p = self._check_parameter(p)
        xs = self._ex(p)
        ys = self._ey(p)
        r = [self.scale * np.stack([a, b], -1) for a, b in zip(xs, ys, strict=True)]
        return r[0], r[1], r[2], r[3]
