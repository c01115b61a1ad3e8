"""The transcription: knots at fixed fractions of the duration, a constant path jerk on each
interval, and the states at the knots by the exact integration (:class:`Mesh`); a motion's
states (:class:`Motion`)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..._arrays import Array


@dataclass(frozen=True)
class Mesh:
    """Knots at fractions ``f`` (M + 1,) of the duration, and the knots pinned to the path's
    joints (``pins``: knot indices, ``pin_s`` their arc lengths)."""

    f: Array
    pins: Array
    pin_s: Array

    @property
    def M(self) -> int:
        """The number of intervals."""
        return len(self.f) - 1

    @cached_property
    def h(self) -> Array:
        """The intervals' lengths (fractions of the duration), (M,)."""
        return np.diff(self.f)

    def states(self, J: Array) -> tuple[Array, Array, Array]:
        """``alpha, w, sigma`` at the knots (M + 1,) from the normalised jerks ``J`` (M,):
        the exact integration of a piecewise-constant jerk from rest, knot to knot."""
        h = self.h
        hJ = h * J
        alpha = np.concatenate([[0.0], np.cumsum(hJ)])
        a0 = alpha[:-1]
        w = np.concatenate([[0.0], np.cumsum(h * (a0 + hJ / 2))])
        sigma = np.concatenate([[0.0], np.cumsum(h * (w[:-1] + h * (a0 / 2 + hJ / 6)))])
        return alpha, w, sigma

    def rows_at(self, p: Array) -> tuple[Array, Array, Array]:
        """The rows of the linear maps from the jerks to ``alpha, w, sigma`` at the knots
        ``p`` (n,): three arrays (n, M)."""
        f, h = self.f, self.h
        after = np.maximum(f[np.asarray(p, int)][:, None] - f[None, 1:], 0.0)
        inside = np.where(f[np.asarray(p, int)][:, None] >= f[None, 1:], h[None, :], 0.0)
        return (inside, inside * (inside / 2 + after),
                inside * (inside * inside / 6 + inside * after / 2 + after * after / 2))


def make_mesh(f: Array, pin_f: Array, pin_s: Array) -> Mesh:
    """The mesh of knots ``f`` with the knots at fractions ``pin_f`` pinned to ``pin_s``."""
    f = np.asarray(f, float)
    return Mesh(f, np.searchsorted(f, pin_f), np.asarray(pin_s, float))


@dataclass(frozen=True)
class Motion:
    """The states at the knots (M + 1,) of normalised jerks ``J`` (M,): arc length ``sigma``,
    speed ``w``, acceleration ``alpha``; and ``T``."""

    J: Array
    T: float
    sigma: Array
    w: Array
    alpha: Array

    def at(self, mesh: Mesh, k: Array, theta: Array) -> tuple[Array, Array, Array]:
        """``sigma, w, alpha`` at offsets ``theta`` (n,) into the intervals ``k`` (n,)."""
        J = self.J[k]
        a, w, s = self.alpha[k], self.w[k], self.sigma[k]
        sigma = s + theta * (w + theta * (a / 2 + theta * J / 6))
        # at an interval's end, exactly its end knot's (a pinned knot is on its joint)
        end = theta >= mesh.h[k]
        sigma[end] = self.sigma[k[end] + 1]
        return sigma, w + theta * (a + theta * J / 2), a + theta * J


def motion(mesh: Mesh, J: Array, T: float, length: float) -> Motion:
    """The motion of the normalised jerks ``J`` and duration ``T``: the knots' states, exactly
    ``0`` and ``length`` at the ends and the pinned arc lengths at the pinned knots."""
    alpha, w, sigma = mesh.states(J)
    sigma = np.clip(sigma, 0.0, length)
    sigma[mesh.pins] = mesh.pin_s
    sigma[0], sigma[-1] = 0.0, length
    alpha[-1] = 0.0
    return Motion(np.asarray(J, float), float(T), sigma, w, alpha)


def ends(mesh: Mesh, length: float) -> tuple[Array, Array]:
    """The end conditions and the pinned knots as equalities ``E J = e`` on the jerks:
    ``alpha_M = 0``, ``w_M = 0``, ``sigma_M = S`` and ``sigma = s_j`` at the pinned
    knots."""
    Ea, Ev, Es = mesh.rows_at(np.concatenate([[mesh.M], mesh.pins]))
    E = np.vstack([Ea[:1], Ev[:1], Es])
    return E, np.concatenate([[0.0, 0.0, length], mesh.pin_s])
