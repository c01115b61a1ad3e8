"""The path's coefficients on the grid of arc lengths, with their slopes along the path: what
the transcription's rows interpolate (:class:`Table`), and the robot's dynamics answered from
it at the grid's own points (:class:`CachedDynamics`, for the second-order start law)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..._arrays import Array
from ..base import Law
from ..constraints import JointSamples, PathCoefficients, PathDynamics
from ..time_optimal import split_segments

#: The table's columns (2 each): q', q'', q''' and a, b, g, a', b', g'.
Q1, Q2, Q3, A, B, G, DA, DB, DG = (slice(2 * i, 2 * i + 2) for i in range(9))


@dataclass(frozen=True)
class Table:
    """The path coefficients on the grid (``co``) and, stacked for one interpolation, the
    path derivatives of the joints ``q', q'', q'''`` and the dynamics' ``a, b, g`` with
    their derivatives ``a', b', g'`` (columns, 2 each), at both ends of every segment
    (``lo``, ``hi``, each (N, 18): a derivative may jump at a grid point, ``joints``)."""

    co: PathCoefficients
    lo: Array
    hi: Array
    joints: Array  # arc lengths of the grid points where a derivative jumps

    @property
    def s(self) -> Array:
        """The grid's arc lengths."""
        return self.co.s

    def at(self, s: Array, before: bool | Array = False) -> tuple[Array, Array]:
        """The columns at arc lengths ``s`` (n,) and their slopes, (n, 18) each; at a grid
        point, those of the segment after it (``before``: the one before it; an array (n,):
        for each point)."""
        return segments(self.co.s, self.lo, self.hi, s, before)

    @cached_property
    def moving(self) -> PathCoefficients:
        """The coefficients with the first and last points doubled (N + 3 points): the
        constraint objects' rows leave friction out at a path's two ends (the rest points of
        a second-order law's grid), but the rows here are interpolated between the grid's
        points, and friction is there as soon as the motion leaves rest."""
        co = self.co

        def ends(v: Array) -> Array:
            return np.concatenate([v[:1], v, v[-1:]])

        return PathCoefficients(ends(co.s), ends(co.P), ends(co.a), ends(co.b), ends(co.g),
                                ends(co.dq_ds), co.coulomb, co.viscous, ends(co.ddq_ds),
                                co.coulomb_speed)


#: The table's grid is refined until every column's linear interpolation is within this
#: fraction of the column's largest value at the segments' middles (estimated from both
#: ends, :func:`middle_miss`; the rows' coefficients, and so the limits' use, to about this
#: much), in at most :data:`TABLE_ROUNDS` rounds.
TABLE_TOL = 2e-4
TABLE_ROUNDS = 4
#: A segment shorter than this fraction of the path's length is not refined: its
#: interpolation's miss (the square of its length times the columns' curvature) is below
#: rounding, and :func:`middle_miss`'s slope form divides the rounding of its ends' values
#: by its length (a grid given with two points 1e-13 of the path apart had been split into
#: thousands of points, some of them equal).
SHORT = 1e-9
#: The step of the derivatives along the path (a fraction of the path's length): a central
#: difference of the dynamics' own coefficients, or one-sided at a joint (truncation about
#: the step times the next derivative, far below the interpolation's).
DERIVATIVE_STEP = 1e-7
#: A grid point is a joint (pieces of a path meet there, the curvature's derivative jumps)
#: where a column's one-sided derivatives differ by more than this fraction of its largest.
JOINT_JUMP = 1e-3


def make_table(dynamics: PathDynamics, s: Array) -> Table:
    """The table of the dynamics' coefficients from the grid ``s`` (N + 1,) of arc lengths,
    refined where a column's linear interpolation misses its value at a segment's middle by
    more than :data:`TABLE_TOL` of its largest (a blend's dynamics change over a fraction of
    a millimetre; the miss estimated from both ends, :func:`middle_miss`). The derivatives
    along the path (of ``q''``, ``a``, ``b``, ``g``) are differences of the dynamics'
    coefficients a short step apart, one-sided at the joints (both sides kept: the segment
    before a joint ends with its left derivative, the one after starts with its right
    one)."""
    s = np.asarray(s, float)
    length = float(s[-1])
    for _ in range(TABLE_ROUNDS):
        co, lo, hi, joint = _columns(s, *_coefficients(dynamics, s, length))
        scale = np.abs(np.concatenate([lo, hi])).max(axis=0) + 1e-300
        h = np.diff(s)
        err = (np.abs(middle_miss(h, lo, hi)) / scale).max(axis=1)
        # (a segment shorter than SHORT of the path misses by the square of its length: its
        # estimate is the rounding of its ends' values over its length)
        bad = (err > TABLE_TOL) & (h > SHORT * length)
        if not bad.any():
            break
        pieces = np.where(bad, np.clip(np.ceil(np.sqrt(err / TABLE_TOL)), 2, 8), 1)
        s = split_segments(s, pieces.astype(int))
    else:
        co, lo, hi, joint = _columns(s, *_coefficients(dynamics, s, length))
    return Table(co, lo, hi, co.s[joint])


def middle_miss(h: Array, lo: Array, hi: Array) -> Array:
    """How far each column's linear interpolation misses its value at the segments' middles
    (N, 18), from the columns at both ends alone (the segments ``h`` (N,) long): every
    column's derivative along the path is a column too, so for a value ``f`` with slope
    ``d`` the miss is the cubic's through both ends' values and slopes, ``h (d0 - d1) / 8``,
    and for a slope ``d`` of ``f`` the quartic's (with the middle's value, which drops out),
    ``3 ((f1 - f0) - h (d0 + d1) / 2) / (2 h)``: both to order ``h^4``. Measured on 80
    blended corners against the dynamics at the segments' quarters and middles: the
    table's largest miss 2.01e-4 of a column's largest (2.00e-4 from the middles' own
    values, which cost twice the model's evaluations), the same number of points. Over a
    very short segment (below :data:`SHORT` of the path) the slope form is rounding: not
    used (:func:`make_table`)."""
    hh = h[:, None]
    out = np.empty_like(lo)
    out[:, _VALUES] = hh * (lo[:, _THEIR_SLOPES] - hi[:, _THEIR_SLOPES]) / 8
    out[:, _SLOPES] = 1.5 * ((hi[:, _OF] - lo[:, _OF])
                             - hh * (lo[:, _SLOPES] + hi[:, _SLOPES]) / 2) / hh
    return out


def _columns_of(*parts: slice) -> Array:
    return np.concatenate([np.arange(p.start, p.stop) for p in parts])


# (for middle_miss: the value columns and their slopes' columns; the slope columns and the
# columns they are the slopes of; q'' is both, its miss the value's)
_VALUES, _THEIR_SLOPES = _columns_of(Q1, Q2, A, B, G), _columns_of(Q2, Q3, DA, DB, DG)
_SLOPES, _OF = _columns_of(Q3, DA, DB, DG), _columns_of(Q2, A, B, G)


def _coefficients(dynamics: PathDynamics, s: Array, length: float
                  ) -> tuple[PathCoefficients, Array, Array, Array]:
    """The coefficients at the arc lengths ``s``, and the columns with derivatives (``q''``,
    ``a``, ``b``, ``g``; (3 n, 8)) there and a short step (:data:`DERIVATIVE_STEP`) before
    and after them (within the path), and those points, from one evaluation of the dynamics
    (its cost is mostly per call)."""
    step = DERIVATIVE_STEP * length
    left, right = np.maximum(s - step, 0.0), np.minimum(s + step, length)
    co = dynamics.coefficients(np.concatenate([s, left, right]))
    base = np.concatenate([co.ddq_ds, co.a, co.b, co.g], axis=1)
    return _rows_of(co, slice(0, len(s))), base, left, right


def _rows_of(co: PathCoefficients, rows: slice) -> PathCoefficients:
    """The coefficients of the points ``rows``."""
    return PathCoefficients(co.s[rows], co.P[rows], co.a[rows], co.b[rows], co.g[rows],
                            co.dq_ds[rows], co.coulomb, co.viscous,
                            None if co.d2q_ds2 is None else co.d2q_ds2[rows], co.coulomb_speed)


def _columns(s: Array, co: PathCoefficients, base: Array, left: Array, right: Array
             ) -> tuple[PathCoefficients, Array, Array, Array]:
    """From the coefficients at ``s`` (N + 1,) and the columns with derivatives there and a
    step ``left`` and ``right`` of them (:func:`_coefficients`), the table's columns (see
    :class:`Table`) at the starts and the ends of the segments (two arrays (N, 18)) and the
    joints (indices)."""
    n = len(s)
    f0, fl, fr = base[:n], base[n:2 * n], base[2 * n:]
    with np.errstate(invalid="ignore", divide="ignore"):
        dl = np.where((s > left)[:, None], (f0 - fl) / (s - left)[:, None], np.nan)
        dr = np.where((right > s)[:, None], (fr - f0) / (right - s)[:, None], np.nan)
    dl = np.where(np.isnan(dl), dr, dl)  # (at the path's ends, the one side there is)
    dr = np.where(np.isnan(dr), dl, dr)
    central = 0.5 * (dl + dr)

    def table(d: Array) -> Array:
        return np.concatenate([co.dq_ds, co.ddq_ds, d[:, :2], co.a, co.b, co.g, d[:, 2:]],
                              axis=1)

    scale = np.abs(central).max(axis=0) + 1e-300
    joint = (np.abs(dr - dl) > JOINT_JUMP * scale).any(axis=1)
    joint[[0, -1]] = False
    after = np.where(joint[:, None], dr, central)
    before = np.where(joint[:, None], dl, central)
    return co, table(after)[:-1], table(before)[1:], np.flatnonzero(joint)


def interp(grid: Array, values: Array, s: Array) -> tuple[Array, Array]:
    """The piecewise-linear interpolant of ``values`` (N + 1, p) on ``grid`` at ``s`` (n,)
    and its slope: two arrays (n, p)."""
    return segments(grid, values[:-1], values[1:], s)


def values_at(grid: Array, lo: Array, hi: Array, s: Array) -> Array:
    """:func:`segments`' values alone (n, p) (at a grid point the segment after it): the
    same arithmetic, without the slopes."""
    k = np.clip(np.searchsorted(grid, s, side="right") - 1, 0, len(grid) - 2)
    ds = grid[k + 1] - grid[k]
    w = ((np.clip(s, grid[0], grid[-1]) - grid[k]) / ds)[:, None]
    a = np.ascontiguousarray(lo)[k]  # (rows gathered from a contiguous table: faster)
    out = np.ascontiguousarray(hi)[k]
    out -= a  # a + (b - a) w, in place
    out *= w
    out += a
    return np.asarray(out)


def segments(grid: Array, lo: Array, hi: Array, s: Array, before: bool | Array = False
             ) -> tuple[Array, Array]:
    """Linear on each segment from ``lo`` to ``hi`` (N, p): the values at ``s`` (n,) and the
    slopes, two arrays (n, p) (at a grid point the segment after it, or ``before`` it; an
    array (n,): for each point)."""
    if np.ndim(before):
        k = np.where(before, np.searchsorted(grid, s, side="left"),
                     np.searchsorted(grid, s, side="right")) - 1
    else:
        k = np.searchsorted(grid, s, side="left" if before else "right") - 1
    k = np.clip(k, 0, len(grid) - 2)
    ds = grid[k + 1] - grid[k]
    w = ((np.clip(s, grid[0], grid[-1]) - grid[k]) / ds)[:, None]
    a, b = lo[k], hi[k]
    return a + (b - a) * w, (b - a) / ds[:, None]


class CachedDynamics:
    """The dynamics with the table's coefficients for the grid's own points (the start's
    second-order law asks for a subset of them)."""

    def __init__(self, dynamics: PathDynamics, table: Table) -> None:
        self._d, self._t = dynamics, table

    @property
    def length(self) -> float:
        """The path's length."""
        return float(self._d.length)

    def coefficients(self, s: Array) -> PathCoefficients:
        """The coefficients at ``s``: the table's rows where ``s`` are grid points, else the
        dynamics'."""
        grid = self._t.s
        k = np.clip(np.searchsorted(grid, s), 0, len(grid) - 1)
        if not np.allclose(grid[k], s, rtol=0.0, atol=1e-12 * grid[-1]):
            return self._d.coefficients(s)
        co = self._t.co
        return PathCoefficients(co.s[k], co.P[k], co.a[k], co.b[k], co.g[k], co.dq_ds[k],
                                co.coulomb, co.viscous, co.ddq_ds[k], co.coulomb_speed)

    def samples(self, law: Law, times: Array) -> JointSamples:
        """The dynamics' samples."""
        return self._d.samples(law, times)
