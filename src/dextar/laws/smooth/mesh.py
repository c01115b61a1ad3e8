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
    (n,) over the intervals ``dt`` (M,): three arrays (n, M)."""
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


def ends(mesh: Mesh, Tk: Array, length: float) -> tuple[Array, Array]:
    """The end conditions and the pinned knots as equalities ``E j = e`` on the physical
    jerks ``j = J / T_k^3``: ``a_M = 0``, ``v_M = 0``, ``s_M = S`` and ``s = s_j`` at the
    pinned knots."""
    Ea, Ev, Es = knot_rows(mesh.h * Tk, np.concatenate([[mesh.M], mesh.pins]))
    E = np.vstack([Ea[:1], Ev[:1], Es])
    return E, np.concatenate([[0.0, 0.0, length], mesh.pin_s])


def projected(mesh: Mesh, j: Array, Tk: Array, length: float) -> Array:
    """The physical jerks ``j`` changed the least to meet the end conditions and the pinned
    knots exactly (over the intervals' durations ``h T_k``)."""
    E, e = ends(mesh, Tk, length)
    miss = E @ j - e
    # E E^T by einsum's own loop, not BLAS: OpenBLAS runs that product on its threads from
    # a few thousand knots, and they then spin on the other cores for a while
    EEt = np.einsum("ij,kj->ik", E, E)
    return np.asarray(j - E.T @ np.linalg.lstsq(EEt, miss, rcond=None)[0])
