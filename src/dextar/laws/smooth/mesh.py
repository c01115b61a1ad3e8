"""The transcription: knots at fixed fractions of a stretch's duration, a constant path jerk on
each interval, and the states at the knots by the exact integration (:class:`Mesh`); a
motion's states (:class:`Motion`).

The knots pinned to the path's joints (where its curvature's derivative jumps, so that the
jerk may jump there) divide the motion into stretches, each with its own duration: interval
``k`` lasts ``h_k T_k``, ``T_k`` the same within a stretch, so a pinned knot moves in time
as the stretches before and after it grow or shrink. In each interval the states are
normalised by its own ``T_k``: ``w = T_k sdot``, ``alpha = T_k^2 sddot``,
``J = T_k^3 sdddot``, the arc length ``sigma`` as it is.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..._arrays import Array


@dataclass(frozen=True)
class Mesh:
    """Knots at fractions ``f`` (M + 1,) of the duration (of the start: each interval's
    share of its stretch's duration is fixed), and the knots pinned to the path's joints
    (``pins``: knot indices, increasing; ``pin_s`` their arc lengths)."""

    f: Array
    pins: Array
    pin_s: Array

    @property
    def M(self) -> int:
        """The number of intervals."""
        return len(self.f) - 1

    @cached_property
    def h(self) -> Array:
        """The intervals' lengths (fractions), (M,)."""
        return np.diff(self.f)

    @cached_property
    def stretch(self) -> Array:
        """Each interval's stretch (M,): 0 before the first pinned knot, 1 after it, ..."""
        return np.searchsorted(self.pins, np.arange(self.M), side="right")

    @cached_property
    def pinned(self) -> Array:
        """Whether each knot (M + 1,) is pinned."""
        out = np.zeros(self.M + 1, bool)
        out[self.pins] = True
        return out


def make_mesh(f: Array, pin_f: Array, pin_s: Array) -> Mesh:
    """The mesh of knots ``f`` with the knots at fractions ``pin_f`` pinned to ``pin_s``."""
    f = np.asarray(f, float)
    pins = np.searchsorted(f, pin_f)
    order = np.argsort(pins)
    return Mesh(f, pins[order], np.asarray(pin_s, float)[order])


def integrate(dt: Array, j: Array) -> tuple[Array, Array, Array]:
    """``a, v, s`` at the knots (M + 1,) of piecewise-constant jerks ``j`` (M,) over the
    intervals ``dt`` (M,), from rest: the exact integration, knot to knot."""
    dj = dt * j
    a = np.concatenate([[0.0], np.cumsum(dj)])
    a0 = a[:-1]
    v = np.concatenate([[0.0], np.cumsum(dt * (a0 + dj / 2))])
    s = np.concatenate([[0.0], np.cumsum(dt * (v[:-1] + dt * (a0 / 2 + dj / 6)))])
    return a, v, s


def knot_rows(dt: Array, p: Array) -> tuple[Array, Array, Array]:
    """The rows of the linear maps from the jerks (M,) to ``a, v, s`` at the knots ``p``
    (n,) over the intervals ``dt`` (M,): three arrays (n, M) (dense: for a few knots)."""
    t = np.concatenate([[0.0], np.cumsum(dt)])
    tp = t[np.asarray(p, int)][:, None]
    after = np.maximum(tp - t[None, 1:], 0.0)
    inside = np.where(tp >= t[None, 1:], dt[None, :], 0.0)
    return (inside, inside * (inside / 2 + after),
            inside * (inside * inside / 6 + inside * after / 2 + after * after / 2))


@dataclass(frozen=True)
class Motion:
    """A motion on a mesh: each interval's normalised jerk ``J`` and duration ``T_k`` (M,),
    and the states at the knots (M + 1,) in the normalisation of the interval that starts
    there (the last knot: of the last interval), ``sigma, w, alpha``, and at each
    interval's end in its own, ``w_end, alpha_end`` (M,)."""

    J: Array
    Tk: Array
    sigma: Array
    w: Array
    alpha: Array
    w_end: Array
    alpha_end: Array
    T: float  # the duration

    def at(self, mesh: Mesh, k: Array, theta: Array) -> tuple[Array, Array, Array]:
        """``sigma, w, alpha`` at offsets ``theta`` (n,) into the intervals ``k`` (n,), in
        their normalisation."""
        J = self.J[k]
        a, w, s = self.alpha[k], self.w[k], self.sigma[k]
        sigma = s + theta * (w + theta * (a / 2 + theta * J / 6))
        # at an interval's end, exactly its end knot's (a pinned knot is on its joint)
        end = theta >= mesh.h[k]
        sigma[end] = self.sigma[k[end] + 1]
        return sigma, w + theta * (a + theta * J / 2), a + theta * J


def knot_T(Tk: Array) -> Array:
    """Each knot's normalisation (M + 1,): the interval's that starts there, the last
    interval's at the end."""
    return np.concatenate([Tk, Tk[-1:]])


def motion(mesh: Mesh, J: Array, Tk: Array, length: float) -> Motion:
    """The motion of the normalised jerks ``J`` and durations ``Tk`` (M,): the knots' states,
    exactly ``0`` and ``length`` at the ends and the pinned arc lengths at the pinned
    knots."""
    Tk = np.asarray(Tk, float)
    J = np.asarray(J, float)
    a, v, s = integrate(mesh.h * Tk, J / Tk**3)
    s = np.clip(s, 0.0, length)
    s[mesh.pins] = mesh.pin_s
    s[0], s[-1] = 0.0, length
    a[-1] = 0.0
    Tn = knot_T(Tk)
    return Motion(J, Tk, s, v * Tn, a * Tn * Tn, v[1:] * Tk, a[1:] * Tk * Tk,
                  float(np.sum(mesh.h * Tk)))


#: The most end and pinned-knot rows solved dense by :func:`projected`, by their normal
#: equations (a few rows, their products by the einsum's own loop: LAPACK's least squares
#: and numpy's matrix products ran on OpenBLAS's threads from a few thousand knots, which
#: then spin on the other core: a 16k-knot line's CPU time 1.3 times its wall time).
#: Measured at 400 to 16000 intervals with 0 to 29 pinned knots: 0.05 to 14 ms, 2 to 50
#: times less than the banded system; on 240 random meshes of 200 to 4000 intervals with
#: 2 to 29 pinned knots the ends and the pinned knots met to 9.5e-10 of the length.
DENSE_ROWS = 32
#: The largest miss of :func:`projected`'s pinned knots and end (of the length), and of its
#: last acceleration and speed (of their largest, or on the dense path of their terms'
#: size), accepted before it falls back to least squares on the dense rows (pinned knots
#: too close to be met: the best it can, never a made-up motion).
PROJECTION_TOL = 1e-9


def projected(mesh: Mesh, j: Array, Tk: Array, length: float) -> Array:
    """The physical jerks ``j`` changed the least (in the sum of squares) to meet the end
    conditions ``a_M = 0``, ``v_M = 0``, ``s_M = S`` and the pinned knots' arc lengths
    exactly (over the intervals' durations ``h T_k``).

    In time normalised by the duration (the jerks scale as its cube, the states are of one
    size). Where the ends' and the pinned knots' rows are few (at most
    :data:`DENSE_ROWS`) by their normal equations, refined at most twice while an arc length
    misses by more than 1e-12 of the length; else with the states at
    the knots as unknowns and the exact integration as equalities: a banded system (8
    unknowns a knot, 7 either side of the diagonal) solved by LAPACK's banded LU, in time
    and memory linear in M. (Dense rows of every pinned knot are P x M and their normal
    equations P^2 M: a 224-line blended chain of 3481 intervals and 450 pinned knots spent
    55 of its 88 s of wall time under the profiler there, and their least-squares solve had
    left the pinned knots up to 1e-4 of the length off.) Where the result misses its rows
    by more than :data:`PROJECTION_TOL` (pinned knots that leave too few intervals between
    them), least squares on the dense rows: their least miss."""
    dt = mesh.h * np.asarray(Tk, float)
    M, T = len(dt), float(np.sum(dt))
    u = dt / T
    jn = np.asarray(j, float) * T**3
    pk = np.asarray(mesh.pins, int)
    e = np.concatenate([[0.0, 0.0, length], mesh.pin_s])
    well = pk.size == 0 or (pk[0] >= 1 and pk[-1] < M and bool(np.all(np.diff(pk) >= 1)))
    if len(pk) + 3 <= DENSE_ROWS or not well:
        E = _rows(u, pk)
        G = np.einsum("ik,jk->ij", E, E)
        x, r = jn, e - np.einsum("ij,j->i", E, jn)
        try:
            for tol in (1e-12, 1e-12, PROJECTION_TOL):  # (the solve, refined where it misses)
                x = x + np.einsum("i,ij->j", np.linalg.solve(G, r), E)
                r = e - np.einsum("ij,j->i", E, x)
                if _small(r, E, x, e, tol):
                    return np.asarray(x / T**3)
        except np.linalg.LinAlgError:
            pass
    else:
        x = jn + _banded(u, jn, pk, e)
        if _meets(u, x, pk, e):
            return np.asarray(x / T**3)
        E = _rows(u, pk)
    # (pinned knots too close to be met: the least miss)
    x = jn + np.linalg.lstsq(E, e - E @ jn, rcond=None)[0]
    return np.asarray(x / T**3)


def _rows(u: Array, pk: Array) -> Array:
    """The dense rows of the last knot's ``a, v, s`` and the pinned knots' ``s``."""
    Ea, Ev, Es = knot_rows(u, np.concatenate([[len(u)], pk]))
    return np.vstack([Ea[:1], Ev[:1], Es])


def _small(r: Array, E: Array, x: Array, e: Array, tol: float) -> bool:
    """Whether the dense rows' misses ``r = e - E x`` are within ``tol``: the arc lengths'
    of the length, the last knot's acceleration and speed of their terms' size (the sums
    of the jerks' contributions)."""
    if not np.all(np.isfinite(r)):
        return False
    size = np.einsum("ij,j->i", np.abs(E[:2]), np.abs(x))
    return bool(np.abs(r[2:]).max() <= tol * abs(e[2]) and np.all(np.abs(r[:2]) <= tol * size))


def _meets(u: Array, x: Array, pk: Array, e: Array) -> bool:
    """Whether the jerks ``x`` meet the rows ``e`` (:func:`projected`) to
    :data:`PROJECTION_TOL`."""
    if not np.all(np.isfinite(x)):
        return False
    a, v, s = integrate(u, x)
    tol = PROJECTION_TOL
    return bool(abs(a[-1]) <= tol * np.abs(a).max() and abs(v[-1]) <= tol * np.abs(v).max()
                and np.abs(np.concatenate([s[pk], s[-1:]]) - e[np.r_[3:len(e), 2]]).max()
                <= tol * abs(e[2]))


def _banded(u: Array, jn: Array, pk: Array, e: Array) -> Array:
    """The least change of the jerks ``jn`` (normalised) that meets the rows ``e``
    (:func:`projected`), pinned knots ``pk`` inside and apart, by the banded system."""
    from scipy.linalg import solve_banded  # (not on the command line's start)

    M = len(u)
    a, v, s = integrate(u, jn)
    # the unknowns of interval k: its jerk's change d_k, the multipliers nu_k of its three
    # equalities y_k+1 - A_k y_k - b_k d_k = 0, the change y_k+1 of the states (a, v, s)
    # at its end, a pinned knot's multiplier mu_k+1 (0 where not pinned); then the
    # multipliers of the last knot's three equalities. Each row is the stationarity of
    # its own unknown (or that unknown's equality): the matrix is symmetric.
    k = np.arange(M)
    d, nu, y, mu = 8 * k, 8 * k[:, None] + 1 + np.arange(3), 8 * k[:, None] + 4 + np.arange(3), \
        8 * k + 7
    rho = 8 * M + np.arange(3)
    b = np.stack([u, u * u / 2, u**3 / 6], 1)
    pinned = np.zeros(M, bool)
    pinned[pk - 1] = True  # (mu_k+1 of the knot k + 1)
    up = u[1:]
    ones = np.ones(M - 1)
    # A_k = [[1, 0, 0], [u_k, 1, 0], [u_k^2 / 2, u_k, 1]] on y_k (k >= 1: y[k - 1])
    a_terms = [(0, 0, ones), (1, 0, up), (1, 1, ones), (2, 0, up * up / 2), (2, 1, up),
               (2, 2, ones)]
    pairs = [(d, d, np.ones(M)), (nu.ravel(), y.ravel(), np.ones(3 * M)),
             (nu.ravel(), np.repeat(d, 3), -b.ravel()), (rho, y[-1], np.ones(3)),
             (mu[pinned], y[pinned, 2], np.ones(int(pinned.sum())))]
    pairs += [(nu[1:, r], y[:-1, c], -x) for r, c, x in a_terms]
    rows = np.concatenate([p[0] for p in pairs])
    cols = np.concatenate([p[1] for p in pairs])
    vals = np.concatenate([p[2] for p in pairs])
    n = 8 * M + 3
    ab = np.zeros((15, n))
    ab[7 + rows - cols, cols] = vals  # (the symmetric half: each pair both ways)
    ab[7 + cols - rows, rows] = vals
    ab[7, mu[~pinned]] = 1.0  # (mu = 0 where not pinned)
    rhs = np.zeros(n)
    rhs[mu[pinned]] = e[3:] - s[pk]
    rhs[rho] = [-a[-1], -v[-1], e[2] - s[-1]]
    try:
        z = solve_banded((7, 7), ab, rhs, check_finite=False)
    except (np.linalg.LinAlgError, ValueError):  # (singular: the caller's fallback)
        return np.full(M, np.nan)
    return np.asarray(z[d])
