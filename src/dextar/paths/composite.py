"""Paths made of pieces, and corner blends of continuous curvature.

:class:`Quintic` is a quintic Hermite curve; :func:`blend_corner` builds the one that replaces
a corner between two pieces: it leaves the incoming piece ``radius`` before the corner and
joins the outgoing one ``radius`` after it, matching position, tangent and curvature at both
ends (so the path is G2: the curvature is continuous, and a law along it never stops at the
corner). :class:`Composite` chains pieces; its parameter runs over ``[0, n]``, piece ``k``
covering ``[k, k + 1]``, and its arc length is the sum of the pieces' own.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from .base import Arc, Line, Path

# quintic Hermite basis (rows: p0, v0, a0, a1, v1, p1) as power-series coefficients in u
_H = np.array([
    [1, 0, 0, -10, 15, -6],
    [0, 1, 0, -6, 8, -3],
    [0, 0, 0.5, -1.5, 1.5, -0.5],
    [0, 0, 0, 0.5, -1, 0.5],
    [0, 0, 0, -4, 7, -3],
    [0, 0, 0, 10, -15, 6],
], dtype=float)


@dataclass(frozen=True)
class Quintic(Path):
    """The quintic Hermite curve with the given end positions, first and second derivatives
    (with respect to its parameter ``u`` in [0, 1]), each a point (x, y)."""

    p0_: tuple[float, float]
    v0: tuple[float, float]
    a0: tuple[float, float]
    p1_: tuple[float, float]
    v1: tuple[float, float]
    a1: tuple[float, float]
    p0: float = field(default=0.0, init=False)
    p1: float = field(default=1.0, init=False)

    @cached_property
    def _coef(self) -> Array:
        """Power-series coefficients, shape (6, 2) (constant term first)."""
        rows = np.array([self.p0_, self.v0, self.a0, self.a1, self.v1, self.p1_], float)
        return np.asarray(_H.T @ rows)

    @cached_property
    def _derivative_coefs(self) -> tuple[Array, ...]:
        """The coefficients of ``r`` and its first three derivatives, each (6 - k, 2)."""
        c = self._coef
        return tuple(np.polynomial.polynomial.polyder(c, k) if k else c for k in range(4))

    def _horner(self, order: int, u: Array) -> Array:
        """The ``order``-th derivative at ``u`` (..., 1), shape (..., 2)."""
        ck = self._derivative_coefs[order]
        acc = ck[-1] * u + ck[-2]
        for row in ck[-3::-1]:
            acc = acc * u + row
        return np.asarray(acc)

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """The position and its first three derivatives at ``p``, each of shape (..., 2)."""
        u = self._check_parameter(p)[..., None]
        return self._horner(0, u), self._horner(1, u), self._horner(2, u), self._horner(3, u)

    def speed(self, p: object) -> Array:
        """``ds/dp = |r'(p)|`` (only the first derivative is evaluated)."""
        r1 = self._horner(1, self._check_parameter(p)[..., None])
        return np.asarray(np.hypot(r1[..., 0], r1[..., 1]))


def _end_state(piece: Path, at_end: bool) -> tuple[Array, Array, float]:
    """Position, unit tangent and signed curvature at an end of a piece."""
    p = piece.p1 if at_end else piece.p0
    r, r1, _, _ = piece.derivatives(np.array([p]))
    t = r1[0] / np.linalg.norm(r1[0])
    kappa = float(piece.curvature(np.array([p]))[0][0])
    return r[0], t, kappa


def trim(piece: Path, start: float, end: float) -> Path:
    """``piece`` without ``start`` of arc length at its start and ``end`` at its end."""
    if start + end >= piece.length:
        raise ParameterError(f"blends of {start:.6g} and {end:.6g} do not fit a piece of "
                             f"length {piece.length:.6g}")
    if isinstance(piece, Line):
        a, b = np.asarray(piece.start, float), np.asarray(piece.end, float)
        u = (b - a) / piece.length
        return Line(tuple(a + start * u), tuple(b - end * u))
    if isinstance(piece, Arc):
        return Arc(piece.radius, piece.p0 + start / piece.radius, piece.p1 - end / piece.radius,
                   center=piece.center, clockwise=piece.clockwise)
    raise ParameterError(f"cannot trim a {type(piece).__name__}")


def blend_corner(incoming: Path, outgoing: Path, radius: float) -> tuple[Path, Path, Quintic]:
    """Replace the corner between ``incoming`` (ending at it) and ``outgoing`` (starting at it)
    by a G2 quintic that leaves ``incoming`` ``radius`` before the corner and joins
    ``outgoing`` ``radius`` after it.

    Returns the trimmed incoming piece, the trimmed outgoing piece and the blend.

    Raises
    ------
    ParameterError
        For a reversal (the path turns back on itself) or a blend longer than a piece.
    """
    if not (math.isfinite(radius) and radius > 0):
        raise ParameterError(f"blend {radius!r} must be positive")
    _, t_in, _ = _end_state(incoming, True)
    _, t_out, _ = _end_state(outgoing, False)
    turn = math.degrees(math.acos(float(np.clip(t_in @ t_out, -1.0, 1.0))))
    if turn > 170.0:
        raise ParameterError(f"the path turns back by {turn:.1f} deg at the corner: a blend "
                             "cannot round a reversal (use blend = 0)")
    inc = trim(incoming, 0.0, radius)
    out = trim(outgoing, radius, 0.0)
    P0, T0, k0 = _end_state(inc, True)
    P1, T1, k1 = _end_state(out, False)
    lam = float(np.linalg.norm(P1 - P0))
    n0, n1 = np.array([-T0[1], T0[0]]), np.array([-T1[1], T1[0]])
    q = Quintic(tuple(P0), tuple(lam * T0), tuple(lam * lam * k0 * n0), tuple(P1),
                tuple(lam * T1), tuple(lam * lam * k1 * n1))
    return inc, out, q


#: Two pieces meet when the end of one and the start of the next are within this fraction
#: of their size (the longer piece's length or an arc's radius): an arc about a centre
#: takes its end point to 1e-6 of its radius off the circle, and ends on the circle, where
#: the next move starts at the point (the pieces of lines and blends meet to 1e-16).
JOIN_TOL = 2e-6


def check_joined(pieces: Sequence[Path]) -> None:
    """Each piece starting where the previous ends (within :data:`JOIN_TOL` of their size),
    or a :class:`ParameterError` naming the two pieces, the points and the gap (a gap would
    be crossed in no time: a jump of the end-effector)."""
    for k in range(len(pieces) - 1):
        a, b = pieces[k], pieces[k + 1]
        end = np.asarray(a.position(np.array([a.p1])), float).reshape(-1)
        start = np.asarray(b.position(np.array([b.p0])), float).reshape(-1)
        gap = float(np.hypot(*(start - end)))
        size = max(a.length, b.length, getattr(a, "radius", 0.0), getattr(b, "radius", 0.0))
        if not gap <= JOIN_TOL * size:
            raise ParameterError(
                f"pieces {k} and {k + 1} do not meet: piece {k} ends at ({end[0]:.9g}, "
                f"{end[1]:.9g}), piece {k + 1} starts at ({start[0]:.9g}, {start[1]:.9g}), "
                f"{gap:.3g} apart ({gap / size:.3g} of the pieces' size)")


@dataclass(frozen=True)
class Composite(Path):
    """Pieces joined end to end; parameter ``k + f`` is the fraction ``f`` of piece ``k``."""

    pieces: tuple[Path, ...]
    p0: float = field(default=0.0, init=False)

    def __post_init__(self) -> None:
        if not self.pieces:
            raise ParameterError("a composite path needs pieces")
        check_joined(self.pieces)

    @property
    def p1(self) -> float:  # type: ignore[override]  # derived from the pieces
        """The number of pieces."""
        return float(len(self.pieces))

    @cached_property
    def _lengths(self) -> Array:
        return np.array([p.length for p in self.pieces])

    @cached_property
    def _starts(self) -> Array:
        """Arc length at the start of each piece, shape (n + 1,)."""
        return np.concatenate([[0.0], np.cumsum(self._lengths)])

    @property
    def starts(self) -> Array:
        """Arc length at the start of each piece and the total length, shape (n + 1,)."""
        return self._starts.copy()

    @property
    def length(self) -> float:
        """Sum of the pieces' lengths."""
        return float(self._starts[-1])

    def _split(self, p: Array) -> tuple[Array, Array]:
        k = np.clip(np.floor(p).astype(int), 0, len(self.pieces) - 1)
        return k, p - k

    def _runs(self, k: Array) -> tuple[Array | None, list[tuple[int, slice]]]:
        """The samples of each piece as runs: ``order`` (None when the piece indices ``k`` do
        not decrease, the usual case along a motion) sorts them, and piece ``j`` then holds
        the samples in its slice."""
        order = None if bool(np.all(k[1:] >= k[:-1])) else np.argsort(k, kind="stable")
        ks = k if order is None else k[order]
        edges = np.searchsorted(ks, np.arange(len(self.pieces) + 1)).tolist()
        return order, [(j, slice(edges[j], edges[j + 1])) for j in range(len(self.pieces))
                       if edges[j + 1] > edges[j]]

    def derivatives(self, p: object) -> tuple[Array, Array, Array, Array]:
        """The position and its first three derivatives at ``p``, each of shape (..., 2)."""
        p = np.asarray(self._check_parameter(p), float)
        flat = p.reshape(-1)
        k, f = self._split(flat)
        order, runs = self._runs(k)
        fs = f if order is None else f[order]
        out = [np.empty((flat.size, 2)) for _ in range(4)]
        for j, run in runs:
            piece = self.pieces[j]
            span = piece.p1 - piece.p0
            vals = piece.derivatives(piece.p0 + fs[run] * span)
            for k_ in range(4):
                out[k_][run] = vals[k_] * span**k_
        if order is not None:
            for k_ in range(4):
                out[k_][order] = out[k_].copy()
        shape = p.shape + (2,)
        return (out[0].reshape(shape), out[1].reshape(shape), out[2].reshape(shape),
                out[3].reshape(shape))

    def arc_length(self, p: object) -> Array:
        """Arc length from the start: the pieces before plus the part of this one."""
        p = np.asarray(self._check_parameter(p), float)
        flat = p.reshape(-1)
        k, f = self._split(flat)
        order, runs = self._runs(k)
        fs = f if order is None else f[order]
        s = np.empty(flat.size)
        for j, run in runs:
            piece = self.pieces[j]
            s[run] = self._starts[j] + piece.arc_length(piece.p0 + fs[run] * (piece.p1
                                                                              - piece.p0))
        if order is not None:
            s[order] = s.copy()
        return s.reshape(p.shape)

    def parameter_at(self, s: object) -> Array:
        """The parameter at arc length ``s``."""
        sv = np.clip(np.asarray(s, float), 0.0, self.length)
        flat = sv.reshape(-1)
        k = np.clip(np.searchsorted(self._starts, flat, side="right") - 1, 0,
                    len(self.pieces) - 1)
        order, runs = self._runs(k)
        fs = flat if order is None else flat[order]
        p = np.empty(flat.size)
        for j, run in runs:
            piece = self.pieces[j]
            local = piece.parameter_at(fs[run] - self._starts[j])
            p[run] = j + (local - piece.p0) / (piece.p1 - piece.p0)
        if order is not None:
            p[order] = p.copy()
        return p.reshape(sv.shape)

    def piece_at(self, s: Array) -> Array:
        """Index of the piece at each arc length ``s``."""
        return np.clip(np.searchsorted(self._starts, np.asarray(s, float), side="right") - 1,
                       0, len(self.pieces) - 1)


def blended(pieces: Sequence[Path], blends: Sequence[float]) -> tuple[Composite, list[int]]:
    """Chain ``pieces`` (each ending where the next starts), rounding corner ``k`` (between
    pieces ``k`` and ``k + 1``) with a blend of radius ``blends[k]``.

    Returns the composite path and, for each of its pieces, the index of the input piece it
    belongs to (a blend belongs to the piece it leaves). A corner that cannot be blended
    raises :class:`ParameterError` with its index ``k`` as ``corner``.
    """
    if len(blends) != len(pieces) - 1:
        raise ParameterError("one blend per corner")
    check_joined(pieces)
    cur = list(pieces)
    out: list[Path] = []
    owner: list[int] = []
    for k in range(len(cur) - 1):
        try:
            inc, nxt, q = blend_corner(cur[k], cur[k + 1], blends[k])
        except ParameterError as exc:
            exc.corner = k  # type: ignore[attr-defined]  # (which corner, for the caller's words)
            raise
        out += [inc, q]
        owner += [k, k]
        cur[k + 1] = nxt
    out.append(cur[-1])
    owner.append(len(cur) - 1)
    return Composite(tuple(out)), owner
