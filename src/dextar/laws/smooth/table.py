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

    def at(self, s: Array, before: bool = False) -> tuple[Array, Array]:
        """The columns at arc lengths ``s`` (n,) and their slopes, (n, 18) each; at a grid
        point, those of the segment after it (``before``: the one before it)."""
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


def make_table(dynamics: PathDynamics, s: Array) -> Table:
    """The table of the dynamics' coefficients at the arc lengths ``s`` (N + 1,)."""
    co = dynamics.coefficients(s)
    values = np.concatenate([co.dq_ds, co.ddq_ds, co.ddq_ds, co.a, co.b, co.g, co.a, co.b,
                             co.g], axis=1)
    lo, hi = values[:-1].copy(), values[1:].copy()
    d = np.r_[4:6, 12:18]  # the columns that are derivatives of others
    dlo, dhi, joints = derivative(co.s, values[:, d])
    lo[:, d], hi[:, d] = dlo, dhi
    return Table(co, lo, hi, co.s[joints])


def derivative(s: Array, v: Array) -> tuple[Array, Array, Array]:
    """The derivative along the path of ``v`` (N + 1, p) at both ends of every segment (two
    arrays (N, p)): central differences at the grid's points, one-sided where the derivative
    jumps (where pieces of a path join, their curvature's derivative jumps: a jump of the
    segments' slopes far above their neighbours'), and those points (indices)."""
    ds = np.diff(s)[:, None]
    slope = np.diff(v, axis=0) / ds  # (N, p), each segment's
    n = len(slope)
    central = np.asarray(np.gradient(v, s, axis=0))
    left, right = central[:-1].copy(), central[1:].copy()  # at each segment's two ends
    if n < 5:
        return left, right, np.zeros(0, int)
    jump = np.abs(np.diff(slope, axis=0))  # (N - 1, p) at the inner points 1..N-1
    scale = np.abs(slope).max(axis=0) + 1e-300
    zero = np.zeros_like(jump[:1])
    near = np.maximum(np.concatenate([zero, jump[:-1]]), np.concatenate([jump[1:], zero]))
    joint = (jump > 4 * near) & (jump > 1e-3 * scale)
    k, c = np.nonzero(joint)
    pk = k + 1  # the grid point
    ok = (pk >= 2) & (pk <= n - 2)  # one-sided slopes need two segments on each side
    pk, c = pk[ok], c[ok]
    left[pk, c] = 1.5 * slope[pk, c] - 0.5 * slope[pk + 1, c]
    right[pk - 1, c] = 1.5 * slope[pk - 1, c] - 0.5 * slope[pk - 2, c]
    return left, right, np.unique(pk)


def interp(grid: Array, values: Array, s: Array) -> tuple[Array, Array]:
    """The piecewise-linear interpolant of ``values`` (N + 1, p) on ``grid`` at ``s`` (n,)
    and its slope: two arrays (n, p)."""
    return segments(grid, values[:-1], values[1:], s)


def segments(grid: Array, lo: Array, hi: Array, s: Array, before: bool = False
              ) -> tuple[Array, Array]:
    """Linear on each segment from ``lo`` to ``hi`` (N, p): the values at ``s`` (n,) and the
    slopes, two arrays (n, p) (at a grid point the segment after it, or ``before`` it)."""
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
