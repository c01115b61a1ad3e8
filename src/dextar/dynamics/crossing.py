"""The robot along a path that crosses the parallel (type 2) singularity curve: the path
dynamics with the degeneracy condition at each crossing, and torques that stay bounded
through it.

At a crossing (:class:`dextar.trajectory.Crossing`, arc length ``s*``) the distal rods are
aligned and the motors cannot push the end-effector along their normal ``n``. In the closed
chain's full coordinates (:mod:`dextar.dynamics.closed_chain`) the torques are
``tau = F_q + B A^-T F_P``; along the path ``F_P = aP u + bP x + gP`` is affine in the path
acceleration ``u = sddot`` and squared speed ``x = sdot^2``, so the **degeneracy condition**
``n . F_P = 0`` (Briot & Arakelian, IJRR 27(8), 2008) is one linear equality on ``(u, x)`` at
``s*`` (:class:`~dextar.laws.constraints.ConditionRow`), which the time-optimal law imposes
(:class:`~dextar.laws.constraints.DegeneracyCondition`): this is how the law gets the
freedom the crossing needs, chosen here among the time-optimal motions (TOPP-RA, Pham & Pham,
IEEE T-RO 2018) rather than by a polynomial of high enough degree as Briot & Arakelian do.

Where the condition holds the torque is the limit of ``B A^-T F_P``, a ratio of two quantities
that vanish together, never a division by the vanishing determinant here:

* the torque rows of the grid point ``s*`` are the finite part of the rows around it: the
  torques of a motion of constant ``u`` through ``s*`` at the four points ``s* + (-2, -1, 1,
  2) h`` combined with the weights of the cubic through them at ``s*`` (``-1/6, 2/3, 2/3,
  -1/6``). Those weights are symmetric, so the ``1 / (s - s*)`` part of the rows cancels
  exactly, the combination is the limit to ``O(h^4)``, and ``h`` puts the nodes at a
  normalised distance :data:`CROSSING_WINDOW` from the singularity (rounding amplified by
  1e3 at most);
* the torques of a planned law within ``h`` of the crossing (the output check, the setpoints)
  are the same cubic through the exact torques at the nodes' times, where the law is smooth
  (the time-optimal law's acceleration is the same on both sides of ``s*``: the condition
  fixes it).

The robot cannot be held still near a crossing (the torque that holds it against gravity grows
as the inverse of the distance to the singularity: 1.4 N m at a normalised distance 0.05 on
the DexTAR's line, against the 0.5 N m its crossing is planned within), so the time-optimal
law checks gravity alone against the motors only at the path's ends, where the motion rests
(:attr:`~dextar.laws.constraints.PathCoefficients.holdable`), and its passes decide the rest.

Where the condition does not hold (a law that ignores it) nothing is smoothed: the exact torques grow as
``1 / |s - s*|`` (:func:`crossing_margins` measures the residual, the tests the growth).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .._arrays import Array
from ..errors import ParameterError, SingularityError
from ..kinematics import inverse_kinematics, joint_rates
from ..laws import Law, UniformLaw
from ..laws.constraints import ConditionRow, JointSamples, PathCoefficients
from ..paths import Path
from ..trajectory import Crossing, path_motion
from ..units import Units
from .closed_chain import ChainForces, chain_forces, rods_normal
from .exact import Model

#: The normalised distance to the singularity of the nodes of the limit (see the module
#: doc): the rounding of the torques there is amplified by ``1 / CROSSING_WINDOW``, the
#: cubic's error is ``O((h / reach)^4)``, 1e-12 on the DexTAR's lines.
CROSSING_WINDOW = 1e-3
#: The normalised distance within which a crossing's torque peak is reported
#: (:func:`crossing_margins`): 2.4 mm on either side of the DexTAR's crossings.
NEIGHBOURHOOD = 0.05
#: The degeneracy condition holds when its residual ``n . F_P`` is at most this fraction of
#: the terms that cancel in it (``|n . aP u| + |n . bP x| + |n . gP|``). Measured
#: (``benchmarks/bench_crossing.py``): the time-optimal laws across the DexTAR's and an
#: unequal robot's curves at 100 to 1600 segments leave 2e-16 to 5e-14; the same laws on a
#: robot carrying 1 g more payload (0.8 % of the point mass) 2.4e-4 and 3.1e-4 (the
#: condition is homogeneous in the masses: all of them 10 % heavier leave it at 5e-15); the
#: same paths at laws that ignore it (min-jerk, uniform) 1.
CONDITION_RTOL = 1e-8

_NODES = np.array([-2.0, -1.0, 1.0, 2.0])


def _lagrange(x: Array) -> Array:
    """Weights (n, 4) of the cubic through :data:`_NODES` at ``x`` (n,)."""
    x = np.asarray(x, float)[:, None]
    w = np.ones((x.shape[0], 4))
    for j, xj in enumerate(_NODES):
        for m, xm in enumerate(_NODES):
            if m != j:
                w[:, j] *= (x[:, 0] - xm) / (xj - xm)
    return w


#: The cubic's weights at 0: ``(-1/6, 2/3, 2/3, -1/6)``.
_CENTRE = _lagrange(np.zeros(1))[0]


def crossing_time(law: Law, s: float) -> float:
    """The time at which ``law`` reaches arc length ``s`` (bisection on its motion, which
    increases from rest to rest)."""
    t = law.times(4097)
    sv = law.evaluate(t)[0]
    k = int(np.clip(np.searchsorted(sv, s), 1, len(t) - 1))
    lo, hi = float(t[k - 1]), float(t[k])
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if float(law.evaluate(np.array([mid]))[0, 0]) < s:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@dataclass(frozen=True)
class RobotAcrossPath:
    """A robot model following ``path`` in working mode ``mode`` across the parallel
    singularity curve at ``crossings`` (each one changes the assembly mode); implements
    :class:`~dextar.laws.constraints.PathDynamics` with the degeneracy condition of each
    crossing among its coefficients, and ``adjust_grid`` that puts a grid point on each
    crossing. Every torque comes from the closed chain's full coordinates
    (:func:`~dextar.dynamics.closed_chain.chain_forces`: no direct kinematics, so no
    assembly mode to choose). ``units`` only serves the words of an error.
    """

    model: Model
    path: Path
    mode: str
    crossings: tuple[Crossing, ...]
    units: Units | None = None

    @property
    def length(self) -> float:
        """The path's arc length."""
        return float(self.path.length)

    def adjust_grid(self, s: Array) -> Array:
        """The grid ``s`` (N + 1,) with its point nearest each crossing moved onto it."""
        s = np.array(s, float)
        for c in self.crossings:
            k = int(np.argmin(np.abs(s - c.s)))
            if k in (0, len(s) - 1):
                raise ParameterError(f"the path crosses the parallel singularity curve at "
                                     f"its end (arc length {c.s:.6g}): a motion cannot start "
                                     "or stop there")
            s[k] = c.s
        if not np.all(np.diff(s) > 0):
            raise ParameterError("two crossings of the parallel singularity curve fall in one "
                                 "segment of the time-optimal grid: refine the grid")
        return s

    # ------------------------------------------------------------------ the path's terms
    def _terms(self, s: Array) -> tuple[Array, ...]:
        """``P, P', P'', q, q', q''`` (n, 2) at arc lengths ``s`` (derivatives in ``s``)."""
        S = self.path.length
        _, _, _, _, _, _, P, d1, d2 = path_motion(self.path, UniformLaw(S, S),
                                                  np.clip(np.asarray(s, float), 0.0, S))
        q = inverse_kinematics(self.model.robot, P, self.mode, unwrap=True)
        q1, q2 = joint_rates(self.model.robot, q, P, d1, d2, tol=0.0)
        return P, d1, d2, q, q1, q2

    def _forces(self, s: Array) -> tuple[ChainForces, ChainForces, ChainForces]:
        """The chain's forces of ``u = 1``, of ``x = 1`` (no gravity) and of gravity alone
        (friction aside) at arc lengths ``s``."""
        P, d1, d2, q, q1, q2 = self._terms(s)
        z, m = np.zeros_like(P), self.model
        return (chain_forces(m, q, z, q1, P, z, d1, gravity=False, friction=False),
                chain_forces(m, q, q1, q2, P, d1, d2, gravity=False, friction=False),
                chain_forces(m, q, z, z, P, z, z, gravity=True, friction=False))

    def _step(self, c: Crossing, near: float) -> float:
        """The nodes' step ``h`` of a crossing: at the normalised distance
        :data:`CROSSING_WINDOW`, within a quarter of ``near`` (the distance to the nearest
        point where the law's acceleration may jump)."""
        return min(c.window(CROSSING_WINDOW), 0.25 * near)

    def coefficients(self, s: Array) -> PathCoefficients:
        """The path dynamics at the arc lengths ``s`` (N + 1,) (every crossing a grid point,
        :meth:`adjust_grid`), with the degeneracy condition at each crossing's point and the
        limit of the torque rows there."""
        s = np.asarray(s, float)
        P, _, _, _, q1, q2 = self._terms(s)
        fa, fb, fg = self._forces(s)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            a, b, g = fa.torques(), fb.torques(), fg.torques()
        conditions = []
        for c in self.crossings:
            hit = np.flatnonzero(s == c.s)
            if hit.size != 1 or hit[0] in (0, len(s) - 1):
                raise ParameterError(f"the crossing at arc length {c.s:.6g} is not an inner "
                                     "grid point (the grid was not adjusted)")
            k = int(hit[0])
            h = self._step(c, min(s[k] - s[k - 1], s[k + 1] - s[k]))
            delta = h * _NODES
            na, nb, ng = (f.torques() for f in self._forces(c.s + delta))
            a[k] = _CENTRE @ (na + 2.0 * delta[:, None] * nb)
            b[k], g[k] = _CENTRE @ nb, _CENTRE @ ng
            n = rods_normal(fa.A[k])
            conditions.append(ConditionRow(k, float(n @ fa.P[k]), float(n @ fb.P[k]),
                                           float(n @ fg.P[k])))
        bad = ~(np.isfinite(a) & np.isfinite(b) & np.isfinite(g))
        if bad.any():
            k = int(np.flatnonzero(bad.any(axis=1))[0])
            raise SingularityError(f"the path dynamics are unbounded at arc length "
                                   f"{s[k]:.6g}: a parallel singularity that is not one of "
                                   "the path's crossings")
        ine = self.model.inertia
        holdable = np.zeros(len(s), bool)  # at rest only at its ends (module doc)
        holdable[[0, -1]] = True
        return PathCoefficients(s, P, a, b, g, q1, np.array(ine.coulomb, float),
                                np.array(ine.viscous, float), q2, ine.coulomb_speed,
                                tuple(conditions), holdable)

    # ------------------------------------------------------------------ a law's torques
    def _exact(self, law: Law, t: Array) -> tuple[Array, Array, Array, Array, Array]:
        """Arc length, joint rates and accelerations, torques and the chain's forces of
        ``law`` at times ``t`` (exact: unbounded at a crossing that misses the condition)."""
        s, _, _, _, _, _, P, dP, ddP = path_motion(self.path, law, t)
        q = inverse_kinematics(self.model.robot, P, self.mode)
        dq, ddq = joint_rates(self.model.robot, q, P, dP, ddP, tol=0.0)
        f = chain_forces(self.model, q, dq, ddq, P, dP, ddP)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            tau = f.torques()
        return s, dq, ddq, tau, f.P

    def condition(self, law: Law, c: Crossing) -> tuple[float, float, float, float]:
        """The degeneracy condition along ``law`` at crossing ``c``: its time, the path
        speed there, the residual ``n . F_P`` (force unit) and its ratio to the terms that
        cancel in it (see :data:`CONDITION_RTOL`)."""
        tc = crossing_time(law, c.s)
        _, v, u, _ = law.evaluate(np.array([tc]))[:, 0]
        fa, fb, fg = self._forces(np.array([c.s]))
        n = rods_normal(fa.A[0])
        terms = np.array([n @ fa.P[0] * u, n @ fb.P[0] * v * v, n @ fg.P[0]])
        res = float(terms.sum())
        scale = float(np.abs(terms).sum())
        return tc, float(v), res, (abs(res) / scale if scale > 0 else 0.0)

    def samples(self, law: Law, times: Array) -> JointSamples:
        """``law`` at ``times`` through the closed chain's exact model; within ``h`` of a
        crossing where the condition holds, the cubic through the exact torques at the
        nodes' times (module doc)."""
        t = np.asarray(times, float)
        _, dq, ddq, tau, _ = self._exact(law, t)
        return JointSamples(PlannedTorques(self, law).smooth(t, tau), dq, ddq, t)

    def windows(self, law: Law) -> tuple[tuple[float, float | None], ...]:
        """Per crossing, its time along ``law`` and the nodes' step in time (None where the
        condition does not hold: nothing is smoothed there)."""
        out: list[tuple[float, float | None]] = []
        bp = law.breakpoints()
        s_bp = law.evaluate(bp)[0] if bp.size else np.empty(0)
        for c in self.crossings:
            tc, v, _, ratio = self.condition(law, c)
            if not (ratio <= CONDITION_RTOL) or not v > 0:
                out.append((tc, None))
                continue
            far = np.abs(s_bp - c.s)
            far = far[far > 1e-9 * self.length]
            near = float(far.min()) if far.size else self.length
            near = min(near, c.s, self.length - c.s)
            out.append((tc, self._step(c, near) / v))
        return tuple(out)


@dataclass(frozen=True)
class PlannedTorques:
    """The torques of ``law`` along ``dynamics`` as a function of time, its crossings'
    windows found once (a feedforward for a controller, a torque function for the forward
    dynamics): :meth:`RobotAcrossPath.samples`'s torques, one call per time."""

    dynamics: RobotAcrossPath
    law: Law

    @cached_property
    def _windows(self) -> tuple[tuple[float, float | None], ...]:
        return self.dynamics.windows(self.law)

    def smooth(self, t: Array, tau: Array) -> Array:
        """``tau`` (n, 2), the exact torques at times ``t`` (n,), with the samples within a
        crossing's window replaced by the cubic through its nodes."""
        tau = np.array(tau, float)
        for tc, h_t in self._windows:
            if h_t is None:
                continue
            near = np.abs(t - tc) < h_t
            if near.any():
                tau_n = self.dynamics._exact(self.law, tc + h_t * _NODES)[3]
                tau[near] = _lagrange((t[near] - tc) / h_t) @ tau_n
        return tau

    def __call__(self, t: object) -> Array:
        """The torques (..., 2) at times ``t`` (...,), clipped to the law's duration."""
        ta = np.asarray(t, float)
        tt = np.clip(np.atleast_1d(ta), 0.0, self.law.duration)
        tau = self.smooth(tt, self.dynamics._exact(self.law, tt)[3])
        return tau.reshape(ta.shape + (2,))


@dataclass(frozen=True)
class CrossingMargin:
    """How a planned law crosses the parallel singularity curve at one crossing (run units).

    Attributes
    ----------
    crossing : Crossing
    t : float
        The crossing's time.
    speed : float
        The path speed there (``sdot``).
    residual, residual_ratio : float
        The degeneracy condition's residual ``n . F_P`` (force unit) and its ratio to the
        terms that cancel in it.
    holds : bool
        ``residual_ratio <= CONDITION_RTOL``.
    torque_peak : ndarray, shape (2,)
        The largest ``|tau_i|`` within the crossing's neighbourhood (where the normalised
        distance to the singularity is below :data:`NEIGHBOURHOOD`; infinite where the
        condition does not hold).
    span : (float, float)
        The neighbourhood's times.
    """

    crossing: Crossing
    t: float
    speed: float
    residual: float
    residual_ratio: float
    holds: bool
    torque_peak: Array
    span: tuple[float, float]


def crossing_margins(dynamics: RobotAcrossPath, law: Law, samples: int = 401
                     ) -> tuple[CrossingMargin, ...]:
    """Each crossing's :class:`CrossingMargin` along ``law``: the condition at its time, and
    the torques on ``samples`` times across its neighbourhood."""
    out = []
    S = dynamics.length
    for c in dynamics.crossings:
        tc, v, res, ratio = dynamics.condition(law, c)
        w = c.window(NEIGHBOURHOOD)
        t0 = crossing_time(law, max(c.s - w, 0.0))
        t1 = crossing_time(law, min(c.s + w, S))
        holds = bool(ratio <= CONDITION_RTOL)
        if holds:
            js = dynamics.samples(law, np.linspace(t0, t1, samples))
            peak = np.abs(js.tau).max(axis=0)
        else:
            peak = np.full(2, np.inf)
        out.append(CrossingMargin(c, tc, v, res, ratio, holds, peak, (t0, t1)))
    return tuple(out)
