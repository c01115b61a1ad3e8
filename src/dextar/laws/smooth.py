"""Jerk-limited time-optimal law of motion along a path: the fastest rest-to-rest motion,
starting and ending with zero acceleration, within the limits of the robot's dynamics
(torque with friction, speed, torque-speed envelope, joint acceleration) and within the
third-order limits (joint jerk, torque rate).

Method: direct transcription in normalised time with piecewise-constant jerk, solved by
sequential linear programming (SLP) with a trust region, the duration a variable of every
programme; the start is the second-order time-optimal law passed through a moving-average
filter; the transcription is refined where the output check finds a limit exceeded.

* **Transcription.** The motion is ``M`` intervals of constant path jerk at fixed fractions
  ``f`` of the duration ``T`` (denser at the second-order law's acceleration switches and
  at the ends). In normalised time ``tau = t / T`` the normalised jerks ``J_k = T^3 sdddot``
  give the knots' arc length ``sigma``, speed ``w = T sdot`` and acceleration
  ``alpha = T^2 sddot`` linearly (the exact integration of a piecewise-constant jerk from
  rest), so the ends (``sigma = S``, ``w = alpha = 0``) are linear equalities that do not
  involve ``T``; the motion between the knots is exact.
* **Rows.** Every limit is a row ``r(J, T) <= 0`` at the inner knots and in the middle of
  every interval (and for the third-order limits at both ends and the middle of every
  interval, where the jerk is constant): the second-order constraint objects' rows
  ``pu u + px x <= ph`` (:mod:`dextar.laws.constraints`) become ``pu alpha + px w^2 - ph T^2
  <= 0``, the speed cap ``w <= sqrt(cap) T``, the joint jerk ``q' J + 3 q'' w alpha + q''' w^3
  <= j_max T^3``, the torque rate ``a J + (a' + 2 b) w alpha + b' w^3 + g' w T^2 +
  f_qdot (q' alpha + q'' w^2) T <= r_max T^3``, each normalised by its limit. Each programme
  linearises all of them about the current motion, in every variable: the states (through
  the integration), the arc length at which the coefficients are taken (their slope along
  the path) and ``T``.
* **SLP.** Each linear programme minimises ``T`` plus an exact l-infinity penalty on the
  rows (an elastic slack, so that it is always feasible) within a trust region (a box on
  the jerks and on ``T``); a step is taken when the actual reduction of the merit function
  (``T`` plus the penalty on the true rows) is a fair share of the predicted one, the trust
  region growing or shrinking with their ratio (Fletcher's Sl1QP with a linear model;
  Fletcher, *Practical Methods of Optimization*, 2nd ed., Wiley 1987, ch. 14; Nocedal &
  Wright, *Numerical Optimization*, 2nd ed., Springer 2006, sec. 18.5). Rows far from
  their limits stay out of the programme unless its solution crosses them.
* **Start.** The second-order time-optimal law (:mod:`dextar.laws.time_optimal`, TOPP-RA on
  a coarse grid) filtered by a moving average of width ``rho``, the time the steepest
  acceleration switch needs at the jerk (or torque-rate) limits: its acceleration ramps
  over ``rho`` wherever the second-order law's jumps, it keeps rest and zero acceleration at
  both ends, and its duration is ``T2 + rho``. On a single axis with the acceleration limit
  reached this is Ruckig's profile, so the programmes start near the answer (Biagiotti &
  Melchiorri, *Trajectory Planning for Automatic Machines and Robots*, Springer 2008,
  sec. 4.4, FIR filters for jerk-limited profiles).
* **Check and refinement.** The law is sampled (nine points in every interval) through the
  exact model; an interval in which a limit is exceeded by more than its tolerance
  (``tol``: torque, speed, acceleration; ``rate_tol``: jerk and torque rate, whose ratio is a
  finite difference) is split in two (the same motion, so the programmes go on from it) and
  the SLP runs again; after :data:`MAX_REFINE` rounds a kind still exceeded is tightened by
  its excess.

For the kinematic limits alone (a joint move with speed, acceleration and jerk limits) the
rows are exact at the knots and between them, so the law is never faster than the continuous
optimum (Ruckig's profile, Berscheid & Kroeger, "Jerk-limited real-time trajectory generation
with arbitrary target states", RSS 2021) and within the loss of the fixed knots (below 1e-3
on the tested moves); as the jerk limit grows it tends to the second-order law. The third-order
structure of the problem is as in Pham & Pham, "On the structure of the time-optimal path
parameterization problem with third-order constraints", ICRA 2017; SLP for path following
with nonconvex constraints as in Debrouwere et al., IEEE T-RO 29(6), 2013.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..motors import MotorLimits
from ..units import Units
from .base import Law
from .constraints import (
    Constraint,
    JerkLimit,
    JointSamples,
    PathCoefficients,
    PathDynamics,
    PointRows,
    Tangent,
    TorqueRateLimit,
    motor_constraints,
    point_rows,
    ratios_by_kind,
    speed_cap,
)
from .time_optimal import solve_time_optimal_law

#: Fewest intervals of constant jerk of the first transcription (more where the monitor of
#: :func:`_fractions` asks, and refined where the check needs).
SEGMENTS = 32
#: Segments of the second-order law that starts the search (a coarse grid: it only gives the
#: start motion, which the programmes improve).
START_GRID = 40
#: Greatest number of linear programmes of one SLP run.
MAX_PROGRAMMES = 24
#: The first trust region (a fraction of the largest knot acceleration of the start), and
#: the one after a refinement or a tightening (from a motion near the answer).
START_DELTA = 0.3
RESTART_DELTA = 0.1
#: The trust region's share for ``T``: it moves by at most this times ``delta`` (relative).
T_SHARE = 0.5
#: Rounds of refinement after the output check, then of tightening.
MAX_REFINE = 3
MAX_TIGHTEN = 2
#: A row joins the programme when the current motion uses more than ``1 - ACTIVE`` of its
#: limit (the others join when the programme's solution crosses them).
ACTIVE = 0.3
#: Weight of the l-infinity penalty on the rows (normalised) against ``T / T_start``: above
#: the sum of the rows' multipliers (at most about 1: relaxing every limit by a fraction
#: ``e`` shortens the motion by at most ``e T``), so that the penalty is exact.
PENALTY = 3.0
#: Weight of the reward for progress (the mean of the knots' arc lengths over the path's
#: length) against ``T / T_start``: it costs ``T`` at most this fraction.
PROGRESS = 1e-4
#: Convergence: a step taken after which the largest row (relative to its limit) is below
#: ``FEAS_TOL`` (a tenth of the check's tolerance) and whose predicted reduction of the merit
#: was below ``STEP_TOL``, or which moved ``T`` by less than ``STEP_TOL`` (relative) from
#: inside the trust region. Near the solution the SLP converges fast (the programmes'
#: solutions are vertices), so the next step would be far smaller still.
STEP_TOL = 2e-5
FEAS_TOL = 1e-4
#: Check samples per interval (both ends included).
CHECK_PER_INTERVAL = 9
#: Tolerance of the third-order ratios (finite differences) on the check samples.
RATE_TOL = 1e-2
DEBUG = False  # print the iterations (development)

_RATE_KINDS = ("jerk", "torque_rate")
#: The table's columns (2 each): q', q'', q''' and a, b, g, a', b', g'.
_Q1, _Q2, _Q3, _A, _B, _G, _DA, _DB, _DG = (slice(2 * i, 2 * i + 2) for i in range(9))


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
        The duration of the second-order (unlimited jerk) law on the same limits (on the
        coarse grid of the start).
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


# ------------------------------------------------------------------------------------------
# the path's coefficients on the grid, interpolated with their slopes along the path


@dataclass(frozen=True)
class _Table:
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
        return self.co.s

    def at(self, s: Array, before: bool = False) -> tuple[Array, Array]:
        """The columns at arc lengths ``s`` (n,) and their slopes, (n, 18) each; at a grid
        point, those of the segment after it (``before``: the one before it)."""
        return _segments(self.co.s, self.lo, self.hi, s, before)

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

    @cached_property
    def root_cap(self) -> Array | None:
        """``sqrt`` of the squared-speed cap on the grid (None without one)."""
        return None


def _table(dynamics: PathDynamics, s: Array) -> _Table:
    co = dynamics.coefficients(s)
    values = np.concatenate([co.dq_ds, co.ddq_ds, co.ddq_ds, co.a, co.b, co.g, co.a, co.b,
                             co.g], axis=1)
    lo, hi = values[:-1].copy(), values[1:].copy()
    d = np.r_[4:6, 12:18]  # the columns that are derivatives of others
    dlo, dhi, joints = _derivative(co.s, values[:, d])
    lo[:, d], hi[:, d] = dlo, dhi
    return _Table(co, lo, hi, co.s[joints])


def _derivative(s: Array, v: Array) -> tuple[Array, Array, Array]:
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


def _interp(grid: Array, values: Array, s: Array) -> tuple[Array, Array]:
    """The piecewise-linear interpolant of ``values`` (N + 1, p) on ``grid`` at ``s`` (n,)
    and its slope: two arrays (n, p)."""
    return _segments(grid, values[:-1], values[1:], s)


def _segments(grid: Array, lo: Array, hi: Array, s: Array, before: bool = False
              ) -> tuple[Array, Array]:
    """Linear on each segment from ``lo`` to ``hi`` (N, p): the values at ``s`` (n,) and the
    slopes, two arrays (n, p) (at a grid point the segment after it, or ``before`` it)."""
    k = np.searchsorted(grid, s, side="left" if before else "right") - 1
    k = np.clip(k, 0, len(grid) - 2)
    ds = grid[k + 1] - grid[k]
    w = ((np.clip(s, grid[0], grid[-1]) - grid[k]) / ds)[:, None]
    a, b = lo[k], hi[k]
    return a + (b - a) * w, (b - a) / ds[:, None]


class _Cached:
    """The dynamics with the table's coefficients for the grid's own points (the start's
    second-order law asks for a subset of them)."""

    def __init__(self, dynamics: PathDynamics, table: _Table) -> None:
        self._d, self._t = dynamics, table

    @property
    def length(self) -> float:
        return float(self._d.length)

    def coefficients(self, s: Array) -> PathCoefficients:
        grid = self._t.s
        k = np.clip(np.searchsorted(grid, s), 0, len(grid) - 1)
        if not np.allclose(grid[k], s, rtol=0.0, atol=1e-12 * grid[-1]):
            return self._d.coefficients(s)
        co = self._t.co
        return PathCoefficients(co.s[k], co.P[k], co.a[k], co.b[k], co.g[k], co.dq_ds[k],
                                co.coulomb, co.viscous, co.ddq_ds[k], co.coulomb_speed)

    def samples(self, law: Law, times: Array) -> JointSamples:
        return self._d.samples(law, times)


# ------------------------------------------------------------------------------------------
# the transcription


@dataclass(frozen=True)
class _Mesh:
    """Knots at fractions ``f`` (M + 1,) of the duration, and the knots pinned to the path's
    joints (``pins``: knot indices, ``pin_s`` their arc lengths)."""

    f: Array
    pins: Array
    pin_s: Array

    @property
    def M(self) -> int:
        return len(self.f) - 1

    @cached_property
    def h(self) -> Array:
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


def _mesh(f: Array, pin_f: Array, pin_s: Array) -> _Mesh:
    """The mesh of knots ``f`` with the knots at fractions ``pin_f`` pinned to ``pin_s``."""
    f = np.asarray(f, float)
    return _Mesh(f, np.searchsorted(f, pin_f), np.asarray(pin_s, float))


@dataclass(frozen=True)
class _Motion:
    """The states at the knots (M + 1,) of normalised jerks ``J`` (M,): arc length ``sigma``,
    speed ``w``, acceleration ``alpha``; and ``T``."""

    J: Array
    T: float
    sigma: Array
    w: Array
    alpha: Array

    def at(self, mesh: _Mesh, k: Array, theta: Array) -> tuple[Array, Array, Array]:
        """``sigma, w, alpha`` at offsets ``theta`` (n,) into the intervals ``k`` (n,)."""
        J = self.J[k]
        a, w, s = self.alpha[k], self.w[k], self.sigma[k]
        sigma = s + theta * (w + theta * (a / 2 + theta * J / 6))
        # at an interval's end, exactly its end knot's (a pinned knot is on its joint)
        end = theta >= mesh.h[k]
        sigma[end] = self.sigma[k[end] + 1]
        return sigma, w + theta * (a + theta * J / 2), a + theta * J


def _motion(mesh: _Mesh, J: Array, T: float, length: float) -> _Motion:
    alpha, w, sigma = mesh.states(J)
    sigma = np.clip(sigma, 0.0, length)
    sigma[mesh.pins] = mesh.pin_s
    sigma[0], sigma[-1] = 0.0, length
    alpha[-1] = 0.0
    return _Motion(np.asarray(J, float), float(T), sigma, w, alpha)


@dataclass(frozen=True)
class _Rows:
    """The rows ``F <= 0`` (R,) at a motion, each at a point of an interval ``k`` (R,), and
    their gradients in the LP's variables of that interval: ``C`` (R, 5) in ``sigma_k, w_k,
    alpha_k, alpha_k+1, T`` (the jerk of the interval is ``(alpha_k+1 - alpha_k) / h``)."""

    F: Array
    k: Array
    C: Array
    kinds: tuple[tuple[str, int], ...] = ()  # (what, how many) per block (development)

    def kind_of(self, i: int) -> str:
        for name, n in self.kinds:
            if i < n:
                return name
            i -= n
        return "?"

    def powers(self) -> Array:
        """How each row's use scales with ``1 / T`` for a fixed normalised motion (about:
        the speed cap 1, the torques and accelerations 2, the third-order limits 3; 0 for
        the rows that do not scale)."""
        p = {"second-order": 2.0, "cap": 1.0, "w>=0": 0.0}
        return np.concatenate([np.full(n, p.get(name, 3.0)) for name, n in self.kinds])

    def linear(self, d_sigma: Array, d_w: Array, d_alpha: Array, d_T: float) -> Array:
        """The rows' linear model after a change of the knots' states and of ``T``."""
        k, C = self.k, self.C
        return np.asarray(self.F + C[:, 0] * d_sigma[k] + C[:, 1] * d_w[k]
                          + C[:, 2] * d_alpha[k] + C[:, 3] * d_alpha[k + 1] + C[:, 4] * d_T)


def _local(h: Array, k: Array, theta: Array, gs: Array, gw: Array, ga: Array, gj: Array,
           gT: Array) -> Array:
    """A row's gradient ``C`` (n, 5) from its derivatives in the point's ``sigma, w,
    alpha``, the interval's jerk ``J`` and ``T`` (each (n,)), the point ``theta`` into the
    interval ``k``."""
    cJ = gs * theta**3 / 6 + gw * theta**2 / 2 + ga * theta + gj
    ca = gs * theta**2 / 2 + gw * theta + ga
    hk = h[k]
    return np.stack([gs, gs * theta + gw, ca - cJ / hk, cJ / hk, gT], axis=1)


class _Model:
    """The rows of the transcription at any motion (see the module doc)."""

    def __init__(self, mesh: _Mesh, table: _Table, second: Sequence[Constraint],
                 third: Sequence[Constraint], length: float) -> None:
        self.mesh, self.table, self.length = mesh, table, length
        self.second, self.third = list(second), list(third)
        M, h = mesh.M, mesh.h
        k = np.arange(M)
        # the points of the second-order rows: the inner knots and every interval's middle
        self.k2 = np.concatenate([k[1:], k])
        self.t2 = np.concatenate([np.zeros(M - 1), h / 2])
        # the third-order rows: every interval at its start, middle and end
        self.t3 = (np.zeros(M), h / 2, h)
        cap = speed_cap(second, table.co)
        self.root_cap = (None if not np.isfinite(cap).any()
                         else np.sqrt(np.where(np.isfinite(cap), cap, 1e300)))

    def tangent(self, mo: _Motion) -> Array:
        """The tangent points of the speed-dependent bounds on the grid: the motion's squared
        speeds (floored at 1e-4 of the largest: a tangent above the speed is still an upper
        bound, and near rest the viscous torque it bounds is small)."""
        x = np.maximum(mo.w, 0.0) ** 2 / (mo.T * mo.T)
        x0 = np.interp(self.table.s, mo.sigma, x)
        return np.asarray(np.maximum(x0, 1e-4 * float(x0.max()) + 1e-300))

    def rows(self, mo: _Motion) -> _Rows:
        """All rows at the motion, normalised by their limits (at its ``T``)."""
        mesh, tab, S, T = self.mesh, self.table, self.length, mo.T
        h = mesh.h
        x0 = self.tangent(mo)
        pr = point_rows(self.second, Tangent(tab.moving, np.concatenate([x0[:1], x0,
                                                                           x0[-1:]])))
        pr = PointRows(pr.pu[1:-1], pr.px[1:-1], pr.ph[1:-1])
        m = pr.pu.shape[1]
        k, th = self.k2, self.t2
        sig, w, al = mo.at(mesh, k, th)
        finite = np.isfinite(pr.ph)
        vals, slopes = _interp(tab.s, np.concatenate([pr.pu, pr.px, np.where(finite, pr.ph,
                                                                             0.0)], axis=1),
                               sig)
        pu, px, ph = vals[:, :m], vals[:, m:2 * m], vals[:, 2 * m:]
        dpu, dpx, dph = slopes[:, :m], slopes[:, m:2 * m], slopes[:, 2 * m:]
        keep = (_interp(tab.s, finite.astype(float), sig)[0] > 1 - 1e-12).reshape(-1)
        a_, w_ = al[:, None], w[:, None]
        c = np.maximum(np.abs(ph), 1e-9 * float(np.abs(ph).max()) + 1e-300) * T * T
        F = (pu * a_ + px * w_ * w_ - ph * T * T) / c
        kk, tt = np.repeat(k, m), np.repeat(th, m)
        zero = np.zeros(len(kk))

        def flat(v: Array) -> Array:
            return np.asarray(v.reshape(-1))

        Cs = [_local(h, kk, tt, flat((dpu * a_ + dpx * w_ * w_ - dph * T * T) / c),
                     flat(2 * px * w_ / c), flat(pu / c), zero, flat(-2 * ph * T / c))[keep]]
        Fs, ks, names = [flat(F)[keep]], [kk[keep]], ["second-order"]
        n2 = len(k)
        if self.root_cap is not None:  # w <= sqrt(cap) T
            rv, rs = _interp(tab.s, self.root_cap[:, None], sig)
            rv, rs = rv[:, 0], rs[:, 0]
            c2 = np.maximum(rv, 1e-300) * T
            Fs.append((w - rv * T) / c2)
            Cs.append(_local(h, k, th, -rs * T / c2, 1.0 / c2, np.zeros(n2), np.zeros(n2),
                             -rv / c2))
            ks.append(k)
            names.append("cap")
        Fs.append(-w / S)  # the speed stays >= 0
        Cs.append(_local(h, k, th, np.zeros(n2), np.full(n2, -1.0 / S), np.zeros(n2),
                         np.zeros(n2), np.zeros(n2)))
        ks.append(k)
        names.append("w>=0")
        kM = np.arange(mesh.M)
        for th3, before in zip(self.t3, (False, False, True), strict=True):
            sig, w, al = mo.at(mesh, kM, th3)
            v, d = tab.at(sig, before)
            F3, C3, k3 = self._third_at(mo, kM, th3, v, d, w, al)
            Fs.append(F3)
            Cs.append(C3)
            ks.append(k3)
            names.append("third")
        return _Rows(np.concatenate(Fs), np.concatenate(ks), np.concatenate(Cs),
                     tuple((n, len(f)) for n, f in zip(names, Fs, strict=True)))

    def _third_at(self, mo: _Motion, k: Array, theta: Array, v: Array, d: Array, w: Array,
                  al: Array) -> tuple[Array, Array, Array]:
        """The joint jerk and torque-rate rows, on both sides of each limit, at offsets
        ``theta`` into the intervals ``k`` (n,), with the table's columns ``v`` and slopes
        ``d`` (n, 18) and the states ``w, al`` (n,) there: rows, gradients, intervals."""
        T = mo.T
        h = self.mesh.h
        q1, q2, q3 = v[:, _Q1], v[:, _Q2], v[:, _Q3]
        dq1, dq2, dq3 = d[:, _Q1], d[:, _Q2], d[:, _Q3]
        jj, ww, aa = mo.J[k][:, None], w[:, None], al[:, None]
        Fs: list[Array] = []
        Cs: list[Array] = []
        for c in self.third:
            if isinstance(c, JerkLimit):
                lim = np.asarray(c.max_jerk, float)
                val = q1 * jj + 3 * q2 * ww * aa + q3 * ww**3
                gs = dq1 * jj + 3 * dq2 * ww * aa + dq3 * ww**3
                gw = 3 * q2 * aa + 3 * q3 * ww * ww
                ga = 3 * q2 * ww
                gj = q1
                gT = np.zeros_like(val)
            elif isinstance(c, TorqueRateLimit):
                lim = np.asarray(c.max_torque_rate, float)
                a, b = v[:, _A], v[:, _B]
                da, db, dg = v[:, _DA], v[:, _DB], v[:, _DG]
                co = self.table.co
                vs = co.coulomb_speed
                # the friction's slope in the joint speed at the motion's speed (held in the
                # linearisation: near a reversal the regularised Coulomb torque's is steep)
                cf = co.viscous + co.coulomb / vs / np.cosh(np.clip(q1 * ww / T / vs,
                                                                    -300, 300)) ** 2
                acc = q1 * aa + q2 * ww * ww  # T^2 qddot
                val = (a * jj + (da + 2 * b) * ww * aa + db * ww**3 + dg * ww * T * T
                       + cf * acc * T)
                gs = (d[:, _A] * jj + (d[:, _DA] + 2 * d[:, _B]) * ww * aa
                      + d[:, _DB] * ww**3 + d[:, _DG] * ww * T * T
                      + cf * (dq1 * aa + dq2 * ww * ww) * T)
                gw = (da + 2 * b) * aa + 3 * db * ww * ww + dg * T * T + cf * 2 * q2 * ww * T
                ga = (da + 2 * b) * ww + cf * q1 * T
                gj = a
                gT = 2 * dg * ww * T + cf * acc
            else:
                continue
            scale = lim * T**3
            kk, tt = np.repeat(k, 2), np.repeat(theta, 2)
            for sign in (1.0, -1.0):
                Fs.append(((sign * val - scale) / scale).reshape(-1))
                g_s, g_w, g_a, g_j = ((sign * x / scale).reshape(-1) for x in (gs, gw, ga, gj))
                Cs.append(_local(h, kk, tt, g_s, g_w, g_a, g_j,
                                 ((sign * gT - 3 * lim * T * T) / scale).reshape(-1)))
        if not Fs:
            return np.zeros(0), np.zeros((0, 5)), np.zeros(0, int)
        n = len(Fs)
        return np.concatenate(Fs), np.concatenate(Cs), np.tile(np.repeat(k, 2), n)


def _merit(T: float, T_ref: float, F: Array, ahead: float) -> float:
    """``T`` (relative), the exact penalty on the largest row, the small reward for being
    ahead (:data:`PROGRESS`)."""
    return T / T_ref + PENALTY * max(0.0, float(F.max())) - PROGRESS * ahead


@dataclass
class _Run:
    """What an SLP run found and what it cost."""

    J: Array
    T: float
    programmes: int
    converged: bool


def _ends(mesh: _Mesh, length: float) -> tuple[Array, Array]:
    """The end conditions and the pinned knots as equalities ``E J = e`` on the jerks:
    ``alpha_M = 0``, ``w_M = 0``, ``sigma_M = S`` and ``sigma = s_j`` at the pinned
    knots."""
    Ea, Ev, Es = mesh.rows_at(np.concatenate([[mesh.M], mesh.pins]))
    E = np.vstack([Ea[:1], Ev[:1], Es])
    return E, np.concatenate([[0.0, 0.0, length], mesh.pin_s])


class _Programme:
    """The linear programme's fixed parts on a mesh: the variables are the knots' states
    ``sigma_0..M, w_0..M, alpha_0..M``, ``T`` and the slack ``eps``; the equalities are the
    exact integration of each interval's constant jerk ``(alpha_k+1 - alpha_k) / h_k``."""

    def __init__(self, mesh: _Mesh, length: float) -> None:
        M, h = mesh.M, mesh.h
        self.M, self.length = M, length
        n = 3 * (M + 1) + 2
        self.n = n
        k = np.arange(M)
        iS, iW, iA = k, M + 1 + k, 2 * (M + 1) + k
        rows = np.concatenate([np.repeat(k, 4), np.repeat(M + k, 5)])
        cols = np.concatenate([np.stack([iW + 1, iW, iA, iA + 1], 1).reshape(-1),
                               np.stack([iS + 1, iS, iW, iA, iA + 1], 1).reshape(-1)])
        vals = np.concatenate([np.stack([np.ones(M), -np.ones(M), -h / 2, -h / 2],
                                        1).reshape(-1),
                               np.stack([np.ones(M), -np.ones(M), -h, -h * h / 3, -h * h / 6],
                                        1).reshape(-1)])
        from scipy.sparse import csr_matrix

        self.A_eq = csr_matrix((vals, (rows, cols)), shape=(2 * M, n))
        self.cost = np.zeros(n)
        self.cost[n - 2], self.cost[n - 1] = 1.0, PENALTY
        # the reward for being ahead at every inner knot (see PROGRESS)
        self.cost[1:M] = -PROGRESS / ((M - 1) * length)
        self.pins, self.pin_s = mesh.pins, mesh.pin_s

    def ahead(self, mo: _Motion) -> float:
        return float(mo.sigma[1:self.M].sum()) / ((self.M - 1) * self.length)

    def solve(self, rows: _Rows, use: Array, mo: _Motion, T_ref: float, delta: float,
              scale: float) -> Any:
        """The programme on the rows ``use`` (a mask) about the motion ``mo``, within the
        trust region: the accelerations within ``delta * scale`` of the motion's, ``T``
        within ``delta / 4`` of it."""
        M, n = self.M, self.n
        sel = np.flatnonzero(use)
        R = len(sel)
        k, C = rows.k[sel], rows.C[sel]
        cols = np.stack([k, M + 1 + k, 2 * (M + 1) + k, 2 * (M + 1) + k + 1,
                         np.full(R, n - 2), np.full(R, n - 1)], axis=1)
        vals = np.concatenate([C, -np.ones((R, 1))], axis=1)
        from scipy.optimize import linprog
        from scipy.sparse import csr_matrix

        A = csr_matrix((vals.reshape(-1), (np.repeat(np.arange(R), 6), cols.reshape(-1))),
                       shape=(R, n))
        x0 = np.concatenate([mo.sigma, mo.w, mo.alpha, [mo.T, 0.0]])
        b = A @ x0 - rows.F[sel]
        dT = T_SHARE * delta
        lo = np.concatenate([np.zeros(M + 1), np.zeros(M + 1), mo.alpha - delta * scale,
                             [mo.T * (1 - dT), 0.0]])
        hi = np.concatenate([np.full(M + 1, self.length), np.full(M + 1, np.inf),
                             mo.alpha + delta * scale, [mo.T * (1 + dT), np.inf]])
        for i, v in ((0, 0.0), (M, self.length), (M + 1, 0.0), (2 * M + 1, 0.0),
                     (2 * (M + 1), 0.0), (3 * M + 2, 0.0)):
            lo[i] = hi[i] = v
        lo[self.pins] = hi[self.pins] = self.pin_s
        cost = self.cost.copy()
        cost[n - 2] = 1.0 / T_ref
        return linprog(cost, A_ub=A, b_ub=b, A_eq=self.A_eq, b_eq=np.zeros(2 * M),
                       bounds=np.stack([lo, hi], axis=1), method="highs-ds",
                       options={"presolve": False})


def _time_scaled(model: _Model, J: Array, T: float) -> float:
    """The duration that brings the normalised motion ``J`` just within its rows (a start
    that is slower than the limits allow is sped up, one beyond them slowed down): each
    row's use scales about as ``T^-p`` (:meth:`_Rows.powers`)."""
    for _ in range(3):
        rows = model.rows(_motion(model.mesh, J, T, model.length))
        p = rows.powers()
        use = np.maximum(rows.F + 1.0, 0.0)
        on = p > 0
        factor = float(np.max(use[on] ** (1.0 / p[on]))) if on.any() else 1.0
        if abs(factor - 1.0) < 1e-3 and rows.F.max() <= 0.0:
            break
        T *= factor * (1 + 1e-4)
    return T


def _slp(model: _Model, J: Array, T: float, budget: int, delta: float) -> _Run:
    """Sequential linear programming with a trust region from the motion ``(J, T)``, which
    meets the end conditions (see the module doc)."""
    mesh, S = model.mesh, model.length
    M = mesh.M
    lp = _Programme(mesh, S)
    mo = _motion(mesh, J, T, S)
    T_ref = T
    rows = model.rows(mo)
    phi = _merit(T, T_ref, rows.F, lp.ahead(mo))
    use = rows.F > -ACTIVE
    n = 0
    converged = False
    scale = max(float(np.abs(mo.alpha).max()), 1e-300)
    while n < budget:
        res = None
        for _ in range(30):  # constraint generation: the rows the solution crosses join
            res = lp.solve(rows, use, mo, T_ref, delta, scale)
            n += 1
            if res.status != 0:
                break
            x = res.x
            lin = rows.linear(x[:M + 1] - mo.sigma, x[M + 1:2 * M + 2] - mo.w,
                              x[2 * M + 2:3 * M + 3] - mo.alpha, x[-2] - mo.T)
            crossed = ~use & (lin > x[-1] + 1e-9)
            if DEBUG and crossed.any():
                print("      crossed", int(crossed.sum()), "of", int(use.sum()))
            if not crossed.any():
                break
            use |= crossed | (lin > -ACTIVE)
        assert res is not None
        if res.status != 0:  # numerical trouble: a smaller step
            if DEBUG:
                print("    LP status", res.status, res.message)
            delta *= 0.25
            if delta < 1e-8:
                break
            continue
        x = res.x
        an, Tn, eps = x[2 * M + 2:3 * M + 3], float(x[-2]), float(x[-1])
        Jn = np.diff(an) / mesh.h
        pred = phi - float(res.fun)
        mn = _motion(mesh, Jn, Tn, S)
        new = model.rows(mn)
        phin = _merit(Tn, T_ref, new.F, lp.ahead(mn))
        actual = phi - phin
        ratio = actual / pred if pred > 0 else (1.0 if actual >= 0 else -1.0)
        if DEBUG:
            i = int(np.argmax(new.F))
            print(f"    T {Tn:.7f} eps {eps:.1e} max row {new.F.max():.2e} "
                  f"({new.kind_of(i)}) rows {int(use.sum())}/{len(use)} pred {pred:.1e} "
                  f"ratio {ratio:.2f} delta {delta:.2g} nit {res.nit}")
        step = max(float(np.abs(an - mo.alpha).max()) / scale, abs(Tn - T) / (T_SHARE * T))
        if DEBUG and ratio < -100:
            i = int(np.argmax(new.F))
            kk = int(new.k[i])
            print("      row", i, "interval", kk, "was", rows.F[i], "lin", lin[i], "now", new.F[i],
                  "sigma", mo.sigma[kk:kk + 2], mn.sigma[kk:kk + 2], "w", mo.w[kk:kk + 2],
                  mn.w[kk:kk + 2], "J", mo.J[kk], mn.J[kk], "pins", mesh.pins)
        if ratio > 0.1:
            T_prev, delta_prev = T, delta
            mo, T, rows, phi = mn, Tn, new, phin
            use = use | (rows.F > -ACTIVE)
            if ratio > 0.75 and step > 0.5 * delta:
                delta = min(2 * delta, 2.0)
            elif ratio < 0.25:
                delta = 0.5 * delta
            if float(rows.F.max()) <= FEAS_TOL and (
                    pred <= STEP_TOL or (abs(Tn - T_prev) <= STEP_TOL * T
                                         and step < 0.5 * delta_prev)):
                converged = True  # feasible, and T no longer moves within the region
                break
        else:
            delta = 0.3 * min(delta, step)
        if delta < 1e-9:
            break
    return _Run(mo.J, mo.T, n, converged)


# ------------------------------------------------------------------------------------------
# the start


def _jumps(base: Any) -> tuple[Array, Array]:
    """The second-order law's acceleration jumps (with the jumps from rest and to rest at
    the ends): arc lengths (N + 1,) and sizes."""
    u = np.concatenate([[0.0], np.asarray(base.accel, float), [0.0]])
    return np.asarray(base.knots_s, float), np.diff(u)


def _ramp(base: Any, table: _Table, third: Sequence[Constraint]) -> float:
    """The time the steepest of the second-order law's acceleration jumps takes at the
    third-order limits (the joint jerk ``q' du / rho``, the torque rate ``a du / rho``)."""
    s, jump = _jumps(base)
    v = table.at(s)[0]
    q1, a = np.abs(v[:, _Q1]), np.abs(v[:, _A])
    rho = 0.0
    for c in third:
        if isinstance(c, JerkLimit):
            rho = max(rho, float((np.abs(jump)[:, None] * q1 / np.asarray(c.max_jerk)).max()))
        elif isinstance(c, TorqueRateLimit):
            rho = max(rho, float((np.abs(jump)[:, None] * a
                                  / np.asarray(c.max_torque_rate)).max()))
    return rho


@dataclass(frozen=True)
class _Start:
    """The second-order law filtered by a moving average of width ``rho`` on a fine time
    grid ``t`` (n,) from 0 to ``T = T2 + rho``: arc length, speed, acceleration."""

    t: Array
    s: Array
    v: Array
    a: Array

    @property
    def T(self) -> float:
        return float(self.t[-1])


def _filtered(base: Any, rho: float, length: float, n: int = 4001) -> _Start:
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
    return _Start(t, s * (length / s[-1]), v, a)


def _fractions(start: _Start, table: _Table, cons: Sequence[Constraint], segments: int,
               tol: float = 2e-3) -> tuple[Array, Array, Array]:
    """The knots' fractions of the duration (M + 1,): at least ``segments`` per duration,
    and where the rows change fast along the start motion as many as keep the rows between
    the points they are imposed at (knots and middles) within about ``tol`` of their values
    there; a knot at each of the path's joints the start motion passes (moved there: the
    fractions of those knots and their arc lengths are the second and third results).

    The monitor is the second time derivative ``c`` of the motion's joint accelerations,
    torques (without friction) and joint jerks from the path's curvature (``q'' v^2``,
    ``b v^2``, ``3 q'' v a + q''' v^3``) over their limits: a function exceeds its values at
    points ``h / 2`` apart by up to ``c h^2 / 32`` between them, so the density is
    ``sqrt(c / (32 tol))`` intervals per unit time."""
    t, s, v, a = start.t, start.s, start.v, start.a
    vals = table.at(s)[0]
    q1, q2, q3, b = vals[:, _Q1], vals[:, _Q2], vals[:, _Q3], vals[:, _B]
    vv, aa = v[:, None], a[:, None]
    parts: list[Array] = []
    for c in cons:
        lim = getattr(c, "max_acceleration", None)
        if lim is not None:
            parts.append((q1 * aa + q2 * vv * vv) / np.asarray(lim, float))
        lim = c.torque_limit
        if lim is not None:
            parts.append((vals[:, _A] * aa + b * vv * vv) / np.asarray(lim, float))
        if isinstance(c, JerkLimit):
            parts.append((3 * q2 * vv * aa + q3 * vv**3) / np.asarray(c.max_jerk, float))
        wmax = getattr(c, "max_speed", None)
        if wmax is not None:  # near the speed limit, the envelope's torque falls steeply
            knee = getattr(c, "knee", None)
            span = np.asarray(wmax, float) - (0.0 if knee is None else np.asarray(knee))
            parts.append(q1 * vv / span)
    dt = t[1] - t[0]
    c2 = np.zeros_like(t)
    for p in parts:
        c2 = np.maximum(c2, np.abs(np.gradient(np.gradient(p, dt, axis=0), dt,
                                               axis=0)).max(axis=1))
    density = np.maximum(np.sqrt(c2 / (32 * tol)), segments / start.T)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * dt)])
    M = max(segments, int(np.ceil(cdf[-1])))
    f = np.interp(np.linspace(0.0, cdf[-1], M + 1), cdf, t / start.T)
    f[0], f[-1] = 0.0, 1.0
    # the joints: the nearest inner knot of each moves to where the start passes it
    joints = table.joints[(table.joints > 0) & (table.joints < s[-1])]
    pin_f: list[float] = []
    pin_s: list[float] = []
    for sj in joints:
        fj = float(np.interp(sj, s, t)) / start.T
        k = int(np.argmin(np.abs(f - fj)))
        if 0 < k < M and not any(abs(f[k] - x) < 1e-12 for x in pin_f):
            lo, hi = f[k - 1], f[k + 1]
            if lo < fj < hi:
                f[k] = fj
                pin_f.append(fj)
                pin_s.append(float(sj))
    return np.asarray(f), np.asarray(pin_f, float), np.asarray(pin_s, float)


def _start_jerks(start: _Start, mesh: _Mesh, length: float) -> Array:
    """The normalised jerks (M,) whose knot accelerations are the start motion's, changed
    the least to meet the end conditions and the pinned knots exactly."""
    T, f = start.T, mesh.f
    ak = np.interp(f * T, start.t, start.a) * T * T
    ak[0] = ak[-1] = 0.0
    J = np.diff(ak) / np.diff(f)
    E, e = _ends(mesh, length)
    miss = E @ J - e
    return np.asarray(J - E.T @ np.linalg.lstsq(E @ E.T, miss, rcond=None)[0])


# ------------------------------------------------------------------------------------------
# the check


def _check(dynamics: PathDynamics, cons: Sequence[Constraint], law: JerkLimitedLaw,
           tol: float, rate_tol: float) -> tuple[dict[str, float], Array]:
    """The largest ratio of each kind on the check samples, and for each interval (M,) the
    largest excess of a kind over its limit in units of its tolerance (0 where all are
    within their tolerances)."""
    t = law.knots_t
    M = len(t) - 1
    n = CHECK_PER_INTERVAL
    frac = np.linspace(0.0, 1.0, n)
    times = (t[:-1, None] + np.diff(t)[:, None] * frac[None, :]).reshape(-1)
    js = dynamics.samples(law, times)
    ratio = ratios_by_kind(cons, js)
    excess = np.zeros(M)
    for c in cons:
        kt = rate_tol if c.kind in _RATE_KINDS else tol
        if ratio[c.kind] > 1 + kt:
            r = np.array([c.ratio(_part(js, k * n, (k + 1) * n)) for k in range(M)])
            excess = np.maximum(excess, np.where(r > 1 + kt, (r - 1) / kt, 0.0))
    return ratio, excess


def _part(js: JointSamples, a: int, b: int) -> JointSamples:
    return JointSamples(js.tau[a:b], js.dq[a:b], None if js.ddq is None else js.ddq[a:b],
                        None if js.t is None else js.t[a:b])


def _law(run: _Run, mesh: _Mesh, length: float, base: Any) -> JerkLimitedLaw:
    T = run.T
    a, v, s = mesh.states(run.J)
    v, a = v / T, a / (T * T)
    s[0], v[0], a[0] = 0.0, 0.0, 0.0
    s[-1], v[-1], a[-1] = length, 0.0, 0.0
    return JerkLimitedLaw(length, float(T), mesh.f * T, s, v, a, run.J / T**3,
                          base.torque_limit, base.speed_limit, {}, float(base.duration), 0,
                          "", 0)


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
        torques, one the jerk or the torque rate.
    segments : int
        Fewest intervals of constant jerk of the first transcription (at least 16; more
        where the path's dynamics change fast, refined where the check needs).
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
        No motion within the limits exists (from the second-order law).
    ParameterError
        No limits, no third-order limit, or bad ``segments`` or tolerances.
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
    if not third:
        raise ParameterError("a jerk-limited law needs a jerk or torque-rate limit")
    length = float(dynamics.length)
    pts = (np.linspace(0.0, length, int(grid) + 1) if np.ndim(grid) == 0
           else np.asarray(grid, float))
    table = _table(dynamics, pts)
    step = max(1, int(np.ceil((len(pts) - 1) / START_GRID)))
    coarse = np.unique(np.concatenate([pts[::step], pts[-1:]]))
    base = solve_time_optimal_law(_Cached(dynamics, table), constraints=second,
                                  grid=coarse if len(coarse) > 11 else pts, tol=0.05,
                                  units=units)
    T2 = float(base.duration)
    rho = min(_ramp(base, table, third), 4.0 * T2)
    start = _filtered(base, rho, length)
    f, pin_f, pin_s = _fractions(start, table, cons, int(segments))
    mesh = _mesh(f, pin_f, pin_s)
    if DEBUG:
        print("  joints", table.joints, "pinned", pin_s, "at knots", mesh.pins)
    J, T = _start_jerks(start, mesh, length), start.T
    scales = dict.fromkeys((c.kind for c in cons), 1.0)
    programmes = refined = tightened = 0
    delta = START_DELTA
    while True:
        model = _Model(mesh, table, [c.scaled(scales) for c in second],
                       [c.scaled(scales) for c in third], length)
        if programmes == 0:
            T = _time_scaled(model, J, T)
        run = _slp(model, J, T, MAX_PROGRAMMES, delta)
        delta = RESTART_DELTA
        programmes += run.programmes
        J, T = run.J, run.T
        law = _law(run, mesh, length, base)
        ratio, excess = _check(dynamics, cons, law, tol, rate_tol)
        bad = excess > 0
        if DEBUG:
            print("  check", {k: round(v, 5) for k, v in ratio.items()}, "bad",
                  int(bad.sum()), "intervals", mesh.M, "T", T, "converged", run.converged)
        if not bad.any():
            break
        if refined < MAX_REFINE:
            # split the intervals where a limit is exceeded, into as many pieces as bring
            # an excess that falls with the square of the interval to a quarter of its
            # tolerance (the same motion: each piece keeps its interval's jerk)
            refined += 1
            pieces = np.where(bad, np.clip(np.ceil(np.sqrt(4 * excess)), 2, 8), 1).astype(int)
            h = np.diff(mesh.f)
            inner = [mesh.f[k] + h[k] * np.arange(1, n) / n
                     for k, n in enumerate(pieces) if n > 1]
            mesh = _mesh(np.sort(np.concatenate([mesh.f, *inner])), pin_f, pin_s)
            J = np.repeat(J, pieces)
            continue
        if tightened < MAX_TIGHTEN:
            tightened += 1
            for k, r in ratio.items():
                kt = rate_tol if k in _RATE_KINDS else tol
                if r > 1 + kt:
                    scales[k] *= (1 + 0.25 * kt) / r
            continue
        break
    ok = not bad.any()
    words = ", ".join(f"{k} ratio {r:.5f}" for k, r in ratio.items())
    margin = "" if all(v == 1.0 for v in scales.values()) else (
        "; limits tightened by " + " and ".join(f"{1 - v:.2%} ({k})" for k, v in scales.items()
                                                 if v != 1.0)
        + " so that they hold between the knots")
    how = (f"{mesh.M} intervals of constant jerk"
           + (f" ({refined} refinement(s))" if refined else "")
           + f", {programmes} linear programmes")
    if ok:
        msg = (f"jerk-limited time-optimal within the limits: {words} on the check samples "
               f"({how}; {T / T2 - 1:+.2%} against the second-order law on the start's "
               f"coarse grid){margin}")
    else:
        msg = f"limits exceeded on the check samples ({how}): {words}"
    if not run.converged:
        msg += "; the linear programmes did not settle"
    return replace(law, ratios=ratio, status=0 if ok else 1, message=msg, solves=programmes)


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

