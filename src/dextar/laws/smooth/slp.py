"""Sequential linear programming with a trust region on the transcription's rows.

Each linear programme minimises ``T`` plus an exact l-infinity penalty on the rows (an elastic
slack, so that it is always feasible) within a trust region (a box on the knots'
accelerations and on ``T``); a step is taken when the actual reduction of the merit function
(``T`` plus the penalty on the true rows) is a fair share of the predicted one, the trust
region growing or shrinking with their ratio (Fletcher's Sl1QP with a linear model; Fletcher,
*Practical Methods of Optimization*, 2nd ed., Wiley 1987, ch. 14; Nocedal & Wright,
*Numerical Optimization*, 2nd ed., Springer 2006, sec. 18.5).

The programme's variables are the states at the knots (``sigma, w, alpha``), ``T`` and the
slack; the equalities are the exact integration of each interval's constant jerk, so the
programme is banded (:mod:`.banded`, linear in the knots). A row joins a programme when the
trust region lets it reach its limit: the box on the accelerations bounds how far the speeds
and arc lengths can move (their integrals from the nearer end, both ends being fixed), so the
rows left out cannot be crossed by the programme's solution, but for rounding and on an
interval into a pinned knot, whose jerk is not boxed (checked after each programme: a row
crossed joins, and the programme is solved again).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..._arrays import Array
from .banded import LPResult, StagedLP, solve_staged
from .mesh import Mesh, Motion, knot_T, motion, projected
from .rows import RowModel, Rows

log = logging.getLogger(__name__)

#: The first trust region (a fraction of the largest knot acceleration of the start), and
#: the one after a refinement or a tightening (from a motion near the answer).
START_DELTA = 0.3
RESTART_DELTA = 0.1
#: The trust region's share for ``T``: it moves by at most this times ``delta`` (relative).
T_SHARE = 0.5
#: The trust region's share for the durations of neighbouring stretches relative to each
#: other (their ratio moves by at most this times ``delta``), at first; where a whole step
#: is turned down and the rows beside a pinned knot at the step are beyond what a good step
#: leaves, that knot's share is cut by ``RHO_CUT``, down to ``RHO_FLOOR``
#: (:func:`cut_shares`). The ratio enters the integration into the pinned knot squared and
#: over that interval's length (the acceleration at its end ``rho^2 alpha``), so its model
#: is worst where that interval is short and the acceleration large. A search keeps the
#: shares from run to run (by the knots' arc lengths). Measured against the fixed share
#: 0.01 before: a long program's stretches must shift their durations against each other
#: by tens of per cent, 0.01 ``delta`` a programme with 0.01 (0.3 % at the first trust
#: region), and the runs ended before: the blended spirals of 28 to 224 lines of
#: ``bench_smooth.py length`` (three starting angles each) came out 2 to 13 % faster
#: (cycles), the 224 lines in 35 % less CPU time; 80 random corners (``bench_smooth.py``'s
#: corners, two seeds, two grids) the same on average (+0.03 %), 2 % more CPU. With a
#: fixed 0.1 the corners, whose pinned knots sit at short intervals, took twice the
#: programmes (steps turned down at their pins); with the shares not kept from run to run
#: 20 % more CPU.
RHO_SHARE = 0.1
RHO_FLOOR = 0.01
RHO_CUT = 0.25
#: The trust region's floor for the speeds, a fraction of the largest.
W_FLOOR = 0.2
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
#: inside the trust region, or (:func:`settled`) after which the motion is on its limits,
#: having moved ``T`` by at most ``sqrt(FEAS_TOL)``, whose reduction the linear model
#: predicted to within ``STEP_TOL``, with the trust region not holding the programme's
#: solution (every box used less than ``REGION_FREE``: the solution a vertex of the rows
#: alone, exact to that along the step, so the next programme finds about the model's error
#: more). Near the solution the SLP converges fast (the programmes' solutions are near
#: vertices), so the next step would be far smaller still. The last rule, measured: on 150
#: random lines with the pick-and-place motors it settled 43 runs a programme early (418
#: programmes for 468), their durations +6e-6 on average, +7.4e-5 at most (some -2e-5); on
#: 160 random corners and 60 random blended chains it never settled a run (the same laws);
#: without its limits' and T's tests (and with the accelerations' box alone) the chains had
#: come out 0.47 % slower on average, up to 7.8 %, and a corner 12.9 % (2.3 % below its
#: limits after T moved 24 %).
STEP_TOL = 1e-4
REGION_FREE = 0.5
#: The largest mesh (intervals) whose rows are all kept while a programme is solved. A
#: longer one (at 8192 intervals a set of rows with their gradients is about 26 MB) keeps
#: then only the rows left out that the programme may cross by more than rounding, those
#: of an interval into a pinned knot (its jerk is not boxed, so :meth:`Programme.reach`
#: does not bound them), and makes the rows again where a step is turned down or a
#: programme fails: one set of gradients alive at a time.
LEAN_ROWS = 8192
#: A programme of at least ``LONG_PROGRAMME`` intervals adds to its objective a proximal
#: term on the jerks' changes, ``PROX / 2 * sum_k h_k ((J_k - J0_k) / jb)^2`` (``h_k`` the
#: intervals' fractions, ``jb`` the trust region's half-width for the jerks), so that its
#: solution is unique where the rows leave the jerks nearly free. The term is at most
#: ``PROX / 2``, half of :data:`STEP_TOL` (every jerk at its box's edge), and so is the
#: rise of the solution's ``c x`` over the linear programme's optimum (which understates
#: the step's predicted reduction by as much); measured on the lines below, 1e-7 to 1e-6.
#: Without it, the interior point walks the edge of a stretch of jerks on their box one to
#: three knots per iteration (at 16k knots on the 20 mm lines of ``bench_smooth.py
#: scaling``: 76 and 69 iterations, 45 and 37 at 4k, the planning time M^1.28 and M^1.32);
#: with it 38 and 35 (36 and 30 at 4k), the durations of the four lines of the scaling the
#: same to 1e-6. Not on shorter programmes: on 80 random blended corners (47 to 80
#: intervals, ``bench_smooth.py blends``' paths, three seeds) the local search came out 0.45
#: to 1.5 % slower on average with it than with the solver before it (-0.14 to +0.34 %
#: without it; each corner moves by a few per cent either way, another path of the
#: search). On long programmes it costs less but not nothing: 48 random corners planned
#: with 2000 intervals (four seeds) came out 0.65 % slower on average with it than without
#: (median 0.22 %, 29 slower and 11 faster by over 0.1 %), the price of the planning
#: time's growth on long paths.
LONG_PROGRAMME = 2000
PROX = 1e-4
FEAS_TOL = 1e-4


def settled(worst: float, pred: float, actual: float, moved: float, still: bool,
            free: bool) -> bool:
    """Whether the SLP has converged after a step taken (see :data:`STEP_TOL`): the largest
    row ``worst`` within ``FEAS_TOL``, and the predicted reduction of the merit ``pred``
    small, or ``still`` (the duration moved little from inside the trust region), or the
    motion on its limits (``worst`` within ``FEAS_TOL`` of 0 from below too) after a step
    that moved the duration by ``moved`` (relative) at most ``sqrt(FEAS_TOL)`` (the rows'
    polynomial form is concave in ``T``: their model overestimates them by about the
    square of that), whose merit the linear model predicted to within ``STEP_TOL``, with
    the trust region not holding the programme's solution (``free``)."""
    return worst <= FEAS_TOL and (
        pred <= STEP_TOL or still
        or (free and worst >= -FEAS_TOL and moved <= FEAS_TOL**0.5
            and abs(actual - pred) <= STEP_TOL))


def cut_shares(shares: Array, beside: Array, pred: float, eps: float) -> Array:
    """The pinned knots' shares of the trust region for the stretches' ratio (see
    :data:`RHO_SHARE`) after a whole step turned down: cut by :data:`RHO_CUT`, down to
    :data:`RHO_FLOOR`, where the largest row beside the knot (``beside``: of the intervals
    into it and out of it, at the step) is above the programme's own slack ``eps`` (its
    model's rows) by more than a quarter of the step's predicted reduction ``pred`` over
    :data:`PENALTY` (a step whose rows stay below that everywhere keeps at least three
    quarters of its prediction). None where the step predicted no reduction."""
    if not pred > 0.0:
        return shares
    hit = beside - max(eps, 0.0) > 0.25 * pred / PENALTY
    return np.where(hit, np.maximum(shares * RHO_CUT, RHO_FLOOR), shares)


def merit(T: float, T_ref: float, F: Array, ahead: float) -> float:
    """``T`` (relative), the exact penalty on the largest row, the small reward for being
    ahead (:data:`PROGRESS`)."""
    return T / T_ref + PENALTY * max(0.0, float(F.max())) - PROGRESS * ahead


@dataclass(frozen=True)
class Run:
    """What an SLP run found and what it cost: the normalised jerks and the intervals'
    durations, the programmes solved, whether they settled, and the largest row at the
    motion."""

    J: Array
    Tk: Array
    programmes: int
    converged: bool
    worst: float
    shares: dict[float, float] = field(default_factory=dict)


class Programme:
    """The linear programme on a mesh (see the module doc): its variables are each knot's
    ``sigma, w, alpha, T`` (``T`` the duration of the knot's stretch) and the slack; its
    equalities each interval's exact integration and, inside a stretch, the duration's
    continuity (at a pinned knot the end states change normalisation, ``w_end = rho w``,
    ``alpha_end = rho^2 alpha`` with ``rho = T_k / T_k+1``: linearised)."""

    def __init__(self, mesh: Mesh, length: float) -> None:
        M, h = mesh.M, mesh.h
        self.mesh, self.M, self.length = mesh, M, length
        K = M + 1
        # w_k+1 - w_k = h (alpha_k + alpha_k+1) / 2, the arc length's over h, T_k = T_k+1,
        # on (sigma, w, alpha, T) of knots k and k + 1
        E = np.zeros((M, 3, 8))
        E[:, 0, 1], E[:, 0, 2], E[:, 0, 5], E[:, 0, 6] = -1.0, -h / 2, 1.0, -h / 2
        E[:, 1, 0], E[:, 1, 1], E[:, 1, 2], E[:, 1, 4], E[:, 1, 6] = (-1 / h, -1.0, -h / 3,
                                                                    1 / h, -h / 6)
        E[:, 2, 3], E[:, 2, 7] = 1.0, -1.0
        self.into_pin = mesh.pinned[1:]  # the intervals that end at a pinned knot
        E[self.into_pin, 2, :] = 0.0
        self.E = E
        lo, hi = np.zeros((K, 4)), np.zeros((K, 4))
        hi[:, 0], hi[:, 1] = length, np.inf
        lo[-1, 0], hi[0, 0] = length, 0.0
        hi[0, 1] = hi[-1, 1] = 0.0
        lo[mesh.pins, 0] = hi[mesh.pins, 0] = mesh.pin_s
        self.lo, self.hi = lo, hi
        self.c = np.zeros(4 * K + 1)
        self.c[4:4 * M:4] = -PROGRESS / ((M - 1) * length)  # the reward for being ahead
        self.c[-1] = PENALTY
        # how far the arc lengths and speeds can move per unit change of the accelerations:
        # their integrals from the nearer end (at any point of the interval)
        g = np.minimum(mesh.f[:-1], 1.0 - mesh.f[1:]) + h
        self.reach_sw = np.stack([g * g / 2, g], axis=1)
        self._terms: tuple[Motion, tuple[Array, Array, Array, Array, Array, Array]] | None = None
        self._x0: tuple[Motion, Array] | None = None
        self._kp, self._kj = np.flatnonzero(self.into_pin), np.flatnonzero(~self.into_pin)
        # (the pinned knots are inner and distinct, as start.pinned and make_mesh make them:
        # the intervals into them are theirs, in order)
        assert np.array_equal(self._kp + 1, mesh.pins)
        #: each pinned knot's share of the trust region for the stretches' ratio (see
        #: :data:`RHO_SHARE`), in the order of ``mesh.pins``
        self.shares = np.full(len(self._kp), RHO_SHARE)

    def shares_from(self, shares: Mapping[float, float]) -> None:
        """The pinned knots' shares an earlier run left (by their arc lengths; a knot not
        among them :data:`RHO_SHARE`)."""
        self.shares = np.array([shares.get(x, RHO_SHARE) for x in self.mesh.pin_s.tolist()])

    def shares_by_arc(self) -> dict[float, float]:
        """The pinned knots' shares by their arc lengths (for the next run)."""
        return dict(zip(self.mesh.pin_s.tolist(), self.shares.tolist(), strict=True))

    def region_use(self, x: Array, mo: Motion, delta: float, scale: float, jscale: float
                   ) -> float:
        """The largest share of its box in the trust region (:meth:`build`) the programme's
        solution ``x`` uses: the inner knots' accelerations and speeds, the jerks inside a
        stretch, the durations and the stretches' durations relative to each other."""
        s = x[:-1].reshape(-1, 4)
        inner = slice(1, self.M)
        Tn = knot_T(mo.Tk)
        rel = s[:, 3] / Tn
        kp, kj, h = self._kp, self._kj, self.mesh.h
        wr = self._speed_box(mo, delta)
        jerk = (s[kj + 1, 2] - s[kj, 2]) / h[kj]
        with np.errstate(divide="ignore", invalid="ignore"):
            uses = (np.abs(s[inner, 2] - mo.alpha[inner]) / (delta * scale),
                    np.where(wr > 0, np.abs(s[inner, 1] - mo.w[inner]) / wr, 0.0),
                    np.abs(jerk - mo.J[kj]) / (delta * jscale),
                    np.abs(rel - 1.0) / (T_SHARE * delta),
                    np.abs(rel[kp] - rel[kp + 1]) / (self.shares * delta))
        return max(float(u.max(initial=0.0)) for u in uses)

    def beside_pins(self, rows: Rows) -> Array:
        """The largest of the rows ``rows`` beside each pinned knot (in the intervals into
        it and out of it), in the order of ``mesh.pins``."""
        top = np.full(self.M, -np.inf)
        np.maximum.at(top, rows.k, rows.F)
        kp = self._kp
        return np.asarray(np.maximum(top[kp], top[np.minimum(kp + 1, self.M - 1)]))

    def _speed_box(self, mo: Motion, delta: float) -> Array:
        """The inner knots' speeds' half-widths in the trust region: ``delta`` of theirs
        (relative, with a floor: the third-order rows grow as their cube, so a slow stretch,
        a blend, moves in proportion)."""
        return np.asarray(delta * (np.abs(mo.w[1:self.M])
                                   + W_FLOOR * float(np.abs(mo.w).max())))

    def ahead(self, mo: Motion) -> float:
        """The mean of the inner knots' arc lengths over the path's length."""
        return float(mo.sigma[1:self.M].sum()) / ((self.M - 1) * self.length)

    def reach(self, rows: Rows, mo: Motion, delta: float, scale: float, jscale: float
              ) -> Array:
        """The largest change of each row's linear model within the trust region: the
        accelerations within ``delta * scale`` (so the speeds and arc lengths within their
        integrals), the jerks within ``delta * jscale``, the durations within
        ``T_SHARE * delta`` (relative; at a pinned knot the end acceleration with them)."""
        G, k = rows.sizes, rows.k
        d, dT = delta * scale, T_SHARE * delta
        return np.asarray(d * (G[:, 0] * self.reach_sw[k, 0] + G[:, 1] * self.reach_sw[k, 1]
                               + G[:, 2]) + delta * jscale * G[:, 3]
                          + dT * (G[:, 4] * mo.Tk[k] + 4 * np.abs(rows.C[:, 3] * mo.alpha_end[k])
                                  * self.into_pin[k]))

    def _end_terms(self, mo: Motion) -> tuple[Array, Array, Array, Array, Array, Array]:
        """The linearised end states of every interval in its own normalisation:
        ``w_end = rw w_k+1 + tw``, ``alpha_end = ra alpha_k+1 + ta`` with ``tw, ta`` linear in
        ``T_k / T0_k - T_k+1 / T0_k+1`` (coefficients ``cw, ca``); (M,) each (those of the
        last motion asked kept: a programme's build and its model ask for the same)."""
        if self._terms is not None and self._terms[0] is mo:
            return self._terms[1]
        Tn = knot_T(mo.Tk)
        rho = Tn[:-1] / Tn[1:]
        pin = self.into_pin
        rho = np.where(pin, rho, 1.0)
        cw = np.where(pin, rho * mo.w[1:], 0.0)
        ca = np.where(pin, 2 * rho * rho * mo.alpha[1:], 0.0)
        self._terms = (mo, (rho, rho * rho, cw, ca, Tn[:-1], Tn[1:]))
        return self._terms[1]

    def _local(self, C: Array, k: Array, mo: Motion, out: Array | None = None) -> Array:
        """The rows' coefficients (n, 6) on ``sigma_k, w_k, alpha_k, T_k, alpha_k+1,
        T_k+1`` from their gradients ``C`` (n, 5) in the interval's own states (into
        ``out`` when given)."""
        _, r2, _, ca, T0, T1 = self._end_terms(mo)
        out = np.empty((len(k), 6)) if out is None else out
        c3 = C[:, 3]
        out[:, :3] = C[:, :3]
        out[:, 3] = C[:, 4] + c3 * (ca / T0)[k]
        out[:, 4] = c3 * r2[k]
        out[:, 5] = -c3 * (ca / T1)[k]
        return out

    def x0(self, mo: Motion) -> Array:
        """The motion as the programme's variables (those of the last motion asked kept;
        not to be written)."""
        if self._x0 is not None and self._x0[0] is mo:
            return self._x0[1]
        x0 = np.concatenate([np.stack([mo.sigma, mo.w, mo.alpha, knot_T(mo.Tk)],
                                      axis=1).reshape(-1), [0.0]])
        x0.flags.writeable = False
        self._x0 = (mo, x0)
        return x0

    def solve(self, rows: Rows, use: Array, mo: Motion, T_ref: float, delta: float,
              scale: float, jscale: float) -> LPResult:
        """The programme on the rows ``use`` (a mask) about the motion ``mo``, within the
        trust region: the accelerations within ``delta * scale`` of the motion's, the
        durations within ``T_SHARE * delta`` (relative) of theirs (:meth:`build`), solved."""
        return solve_staged(*self.build(rows, use, mo, T_ref, delta, scale, jscale))

    def build(self, rows: Rows, use: Array, mo: Motion, T_ref: float, delta: float,
              scale: float, jscale: float) -> tuple[StagedLP, Array]:
        """The programme of :meth:`solve` and its start (the motion's variables)."""
        M, mesh = self.M, self.mesh
        sel = np.flatnonzero(use)
        R = len(sel)
        pin = self.into_pin
        kp, kj = self._kp, self._kj
        n = R + 2 * len(kp) + 2 * len(kj)
        k = np.empty(n, np.int64)
        ra = np.zeros((n, 6))
        rb = np.empty(n)
        rg = np.zeros((n, 1))
        k[:R] = rows.k[sel]
        self._local(rows.C[sel], k[:R], mo, ra[:R])
        x0 = self.x0(mo)
        rb[:R] = -rows.F[sel]
        del sel
        at = 4 * k[:R]
        for j, off in enumerate((0, 1, 2, 3, 6, 7)):
            rb[:R] += ra[:R, j] * x0[at + off]
        del at
        rg[:R] = -1.0
        # the stretches' durations relative to each other change less than the whole: the
        # jerk of the short interval into a pinned knot changes with the square of their
        # ratio over the interval's length
        rho, r2, cw, ca, T0, T1 = self._end_terms(mo)
        i = R + np.arange(len(kp))
        k[i], k[i + len(kp)] = kp, kp
        ra[i, 3], ra[i, 5] = 1.0 / T0[kp], -1.0 / T1[kp]
        ra[i + len(kp)] = -ra[i]
        rb[i], rb[i + len(kp)] = self.shares * delta, self.shares * delta
        # the jerks within delta * jscale of theirs (inside a stretch)
        i = R + 2 * len(kp) + np.arange(len(kj))
        k[i], k[i + len(kj)] = kj, kj
        ra[i, 2], ra[i, 4] = -1.0 / mesh.h[kj], 1.0 / mesh.h[kj]
        ra[i + len(kj)] = -ra[i]
        jb = delta * jscale
        rb[i], rb[i + len(kj)] = mo.J[kj] + jb, jb - mo.J[kj]
        rq = None
        if M >= LONG_PROGRAMME and jb * jb > 0.0:  # (a proximal term: see LONG_PROGRAMME)
            rq = np.zeros(n)
            rq[i] = PROX * mesh.h[kj] / (jb * jb)
        # the integration into a pinned knot, linearised in the durations
        E = self.E.copy()
        h = mesh.h[pin]
        E[pin, 0, 5] = rho[pin]
        E[pin, 0, 6] = -h / 2 * r2[pin]
        E[pin, 1, 6] = -h / 6 * r2[pin]
        dTe = np.stack([cw[pin] - h / 2 * ca[pin], -h / 6 * ca[pin]], axis=1)  # per unit
        E[pin, :2, 3] = dTe / T0[pin, None]
        E[pin, :2, 7] = -dTe / T1[pin, None]
        lo, hi = self.lo.copy(), self.hi.copy()
        inner = slice(1, M)
        lo[inner, 2] = mo.alpha[inner] - delta * scale
        hi[inner, 2] = mo.alpha[inner] + delta * scale
        wr = self._speed_box(mo, delta)
        # (the box holds the motion's own speed where it is below 0: a start's jerks on a
        # new mesh can overshoot; its rows w >= 0 then pull it up)
        lo[inner, 1] = np.minimum(np.maximum(mo.w[inner] - wr, 0.0), mo.w[inner])
        hi[inner, 1] = mo.w[inner] + wr
        Tn = knot_T(mo.Tk)
        lo[:, 3] = Tn * (1 - T_SHARE * delta)
        hi[:, 3] = Tn * (1 + T_SHARE * delta)
        c = self.c.copy()
        c[3:4 * M:4] = mesh.h / T_ref
        return StagedLP(c, k, ra, rg, rb, E, np.zeros((M, 3)),
                        np.concatenate([lo.reshape(-1), [0.0]]),
                        np.concatenate([hi.reshape(-1), [np.inf]]), rq), x0

    def model(self, rows: Rows, x: Array, mo: Motion) -> Array:
        """Every row's linear model at the programme's variables ``x``."""
        _, r2, _, ca, T0, T1 = self._end_terms(mo)
        d = (x[:-1] - self.x0(mo)[:-1]).reshape(-1, 4)
        k, C = rows.k, rows.C
        c3 = C[:, 3]
        return np.asarray(rows.F + C[:, 0] * d[k, 0] + C[:, 1] * d[k, 1] + C[:, 2] * d[k, 2]
                          + (C[:, 4] + c3 * (ca / T0)[k]) * d[k, 3]
                          + c3 * (r2[k] * d[k + 1, 2] - (ca / T1)[k] * d[k + 1, 3]))

    def motion(self, x: Array, length: float) -> Motion:
        """The motion of a programme's solution: its accelerations and durations, the jerks
        between them projected to meet the ends and the pinned knots exactly (the
        linearised normalisation at the pinned knots leaves them a little off)."""
        mesh = self.mesh
        s = x[:-1].reshape(-1, 4)
        Tn = np.maximum(s[:, 3], 1e-300)
        Tk = Tn[:-1]
        a = s[:, 2] / (Tn * Tn)
        a[-1] = 0.0
        j = np.diff(a) / (mesh.h * Tk)
        j = projected(mesh, j, Tk, length)
        return motion(mesh, j * Tk**3, Tk, length)


def time_scaled(model: RowModel, J: Array, Tk: Array, keep: bool = True) -> Array:
    """The durations that bring the normalised motion ``J`` just within its rows (a start
    that is slower than the limits allow is sped up, one beyond them slowed down), all
    scaled alike: each row's use scales about as ``T^-p`` (:meth:`Rows.scaling`); exact
    where it does, so a few rounds, then stretching while a row is still beyond its limit
    (gravity or friction rows that scale more slowly). With ``keep``, the last rows are
    kept (:meth:`.RowModel.rows`) for the SLP that starts from the motion."""
    Tk = np.asarray(Tk, float)
    # the rows of the motion it returns are the first programme's (:func:`slp`): with
    # ``keep``, kept with their gradients when the last factor was near 1 (likely the last
    # round; the same rows without gradients cost nearly as much)
    last = np.inf
    beyond = False  # the last round's scaling left a row beyond its limit
    rows: Rows | None = None
    for _ in range(40):
        near = keep and abs(last - 1.0) < 0.1
        rows = None  # (one set of gradients at a time)
        rows = model.rows(motion(model.mesh, J, Tk, model.length), gradients=near, keep=near)
        worst = float(rows.F.max())
        factor, p_worst = rows.scaling()
        if worst <= 0.0 and abs(factor - 1.0) < 1e-3:
            break
        if worst > 0.0:
            if p_worst == 0:
                break  # a row the duration does not change
            if beyond:  # the powers' factor did not bring it within (gravity, friction)
                factor = max(factor, 1.5)
            beyond = True
        else:
            beyond = False
        Tk = Tk * (factor * (1 + 1e-4))
        last = factor
    return Tk


def slp(model: RowModel, J: Array, Tk: Array, budget: int, delta: float,
        shares: Mapping[float, float] | None = None) -> Run:
    """Sequential linear programming with a trust region from the motion ``(J, Tk)``, which
    meets the end conditions (see the module doc); ``shares`` the pinned knots' shares of
    it for the stretches' ratio an earlier run left (by the knots' arc lengths; see
    :data:`RHO_SHARE`), returned with the run."""
    mesh, S = model.mesh, model.length
    lp = Programme(mesh, S)
    if shares:
        lp.shares_from(shares)
    mo = motion(mesh, J, Tk, S)
    T_ref = mo.T
    first = model.rows(mo)
    phi = merit(mo.T, T_ref, first.F, lp.ahead(mo))
    rows: Rows | None = first
    del first
    n = 0
    converged = False
    scale = max(float(np.abs(mo.alpha).max()), 1e-300)
    jscale = max(float(np.abs(mo.J).max()), 1e-300)
    debug = log.isEnabledFor(logging.DEBUG)
    # a long mesh holds one set of rows' gradients at a time (each is tens of megabytes at
    # 16k knots): while a programme is solved only the rows left out that it may cross
    # by more than rounding (see :data:`LEAN_ROWS`), the rest made again where needed
    lean = mesh.M > LEAN_ROWS
    while n < budget:
        if rows is None:
            rows = model.rows(mo)
        use = rows.F + lp.reach(rows, mo, delta, scale, jscale) > -1e-9
        res = None
        for _ in range(5):  # a row left out and crossed joins
            if rows is None:  # (lean: the rows again, for those that crossed)
                rows = model.rows(mo)
            prog = lp.build(rows, use, mo, T_ref, delta, scale, jscale)
            if lean:
                watch = np.flatnonzero(~use & lp.into_pin[rows.k])
                left = Rows(rows.F[watch], rows.k[watch], rows.C[watch], np.zeros(0),
                            np.zeros((0, 5), np.float32))  # (what a linear model needs)
                rows = None
            res = solve_staged(*prog)
            del prog
            n += 1
            if res.status != 0:
                break
            if rows is None:
                crossed = watch[lp.model(left, res.x, mo) > res.x[-1] + 1e-9]
                del left
            else:
                crossed = np.flatnonzero(~use & (lp.model(rows, res.x, mo)
                                                  > res.x[-1] + 1e-9))
            if not crossed.size:
                break
            log.debug("      %d rows left out crossed", crossed.size)
            use[crossed] = True
        assert res is not None
        if res.status != 0:  # numerical trouble: a smaller step
            log.debug("    programme status %d after %d iterations", res.status, res.nit)
            delta *= 0.25
            if delta < 1e-8:
                break
            continue
        eps = float(res.x[-1])
        pred = phi - res.fun
        free = lp.region_use(res.x, mo, delta, scale, jscale) < REGION_FREE
        mn = lp.motion(res.x, S)
        # the rows at the step, with their gradients (most steps are taken, and then they
        # serve the next programme)
        new = model.rows(mn)
        phin = merit(mn.T, T_ref, new.F, lp.ahead(mn))
        actual = phi - phin
        ratio = actual / pred if pred > 0 else (1.0 if actual >= 0 else -1.0)
        step = max(float(np.abs(mn.alpha - mo.alpha).max()) / scale,
                   float(np.abs(mn.Tk / mo.Tk - 1.0).max()) / T_SHARE)
        if debug:
            i = int(np.argmax(new.F))
            log.debug("    T %.7f eps %.1e max row %.2e (%s) rows %d/%d pred %.1e ratio %.2f "
                      "delta %.2g iterations %d", mn.T, eps, new.F.max(), new.kind_of(i),
                      int(use.sum()), len(use), pred, ratio, delta, res.nit)
        if ratio <= 0.1:  # back along the step: the rows are evaluated, no programme
            if len(lp.shares):  # (first: the pinned knots where the model failed)
                lp.shares = cut_shares(lp.shares, lp.beside_pins(new), pred, eps)
            if rows is None:  # (lean: the rows at the motion again, one set at a time)
                new = Rows(new.F, new.k, np.zeros((0, 5)), new.norm,
                           np.zeros((0, 5), np.float32), new.kinds)
                rows = model.rows(mo)
            x0 = lp.x0(mo)
            lin1 = lp.model(rows, res.x, mo)
            ahead0 = lp.ahead(mo)
            for part in (0.5, 0.25):
                mp = lp.motion(x0 + part * (res.x - x0), S)
                rp = model.rows(mp, gradients=False)
                php = merit(mp.T, T_ref, rp.F, lp.ahead(mp))
                model_p = (mo.T + part * (mn.T - mo.T)) / T_ref + PENALTY * max(
                    0.0, float((rows.F + part * (lin1 - rows.F))[use].max(initial=0.0))) - PROGRESS * (
                    ahead0 + part * (lp.ahead(mn) - ahead0))
                pp = phi - model_p
                rp_ratio = (phi - php) / pp if pp > 0 else -1.0
                log.debug("      back to %.2f of the step: ratio %.2f", part, rp_ratio)
                if rp_ratio > 0.1:
                    mn, new, phin, pred, ratio = mp, rp, php, pp, rp_ratio
                    step *= part
                    free = False  # (the step's model error is not the programme's)
                    break
            del lin1, rp
        if ratio > 0.1:
            T_prev, delta_prev = mo.T, delta
            rows = None
            mo, rows, phi = mn, (new if len(new.C) == len(new.F) else model.rows(mn)), phin
            del new
            if ratio > 0.75 and step > 0.5 * delta:
                delta = min(2 * delta, 2.0)
            elif ratio < 0.25 or step < 0.5 * delta_prev:
                delta = max(0.5 * delta, step)
            if settled(float(rows.F.max()), pred, actual, abs(mo.T - T_prev) / mo.T,
                       abs(mo.T - T_prev) <= STEP_TOL * mo.T and step < 0.5 * delta_prev,
                       free):
                converged = True  # feasible, and T no longer moves within the region
                break
        else:
            delta = 0.3 * min(delta, step)
            del new
        if delta < 1e-9:
            break
    if rows is None:
        rows = model.rows(mo, gradients=False)
    return Run(mo.J, mo.Tk, n, converged, float(rows.F.max()), lp.shares_by_arc())
