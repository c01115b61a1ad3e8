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
rows left out cannot be crossed by the programme's solution (checked after each programme).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ..._arrays import Array
from .banded import LPResult, StagedLP, solve_staged
from .mesh import Mesh, Motion, motion
from .rows import Model, Rows

log = logging.getLogger(__name__)

#: The first trust region (a fraction of the largest knot acceleration of the start), and
#: the one after a refinement or a tightening (from a motion near the answer).
START_DELTA = 0.3
RESTART_DELTA = 0.1
#: The trust region's share for ``T``: it moves by at most this times ``delta`` (relative).
T_SHARE = 0.5
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
#: solutions are near vertices), so the next step would be far smaller still.
STEP_TOL = 2e-5
FEAS_TOL = 1e-4


def merit(T: float, T_ref: float, F: Array, ahead: float) -> float:
    """``T`` (relative), the exact penalty on the largest row, the small reward for being
    ahead (:data:`PROGRESS`)."""
    return T / T_ref + PENALTY * max(0.0, float(F.max())) - PROGRESS * ahead


@dataclass(frozen=True)
class Run:
    """What an SLP run found and what it cost: the normalised jerks, the duration, the
    programmes solved, whether they settled, and the largest row at the motion."""

    J: Array
    T: float
    programmes: int
    converged: bool
    worst: float


class Programme:
    """The linear programme's fixed parts on a mesh (see the module doc): the equalities, the
    bounds that do not move, the cost."""

    def __init__(self, mesh: Mesh, length: float) -> None:
        M, h = mesh.M, mesh.h
        self.mesh, self.M, self.length = mesh, M, length
        K = M + 1
        z, one = np.zeros(M), np.ones(M)
        # w_k+1 - w_k = h (alpha_k + alpha_k+1) / 2 and, over h, the arc length's
        self.E = np.stack([np.stack([z, -one, -h / 2, z, one, -h / 2], axis=1),
                           np.stack([-1 / h, -one, -h / 3, 1 / h, z, -h / 6], axis=1)], axis=1)
        lo = np.zeros((K, 3))
        hi = np.stack([np.full(K, length), np.full(K, np.inf), np.zeros(K)], axis=1)
        lo[-1, 0], hi[0, 0] = length, 0.0
        hi[0, 1] = hi[-1, 1] = 0.0
        lo[mesh.pins, 0] = hi[mesh.pins, 0] = mesh.pin_s
        self.lo, self.hi = lo, hi
        self.c = np.zeros(3 * K + 2)
        self.c[3:3 * M:3] = -PROGRESS / ((M - 1) * length)  # the reward for being ahead
        self.c[-1] = PENALTY
        # how far the arc lengths and speeds can move per unit change of the accelerations:
        # their integrals from the nearer end
        g = np.minimum(mesh.f, 1.0 - mesh.f)[:-1]
        self.reach_sw = np.stack([g * g / 2, g], axis=1)

    def ahead(self, mo: Motion) -> float:
        """The mean of the inner knots' arc lengths over the path's length."""
        return float(mo.sigma[1:self.M].sum()) / ((self.M - 1) * self.length)

    def reach(self, rows: Rows, delta: float, scale: float, T: float) -> Array:
        """The largest change of each row's linear model within the trust region."""
        C, k = np.abs(rows.C), rows.k
        d = delta * scale
        return np.asarray(d * (C[:, 0] * self.reach_sw[k, 0] + C[:, 1] * self.reach_sw[k, 1]
                               + C[:, 2] + C[:, 3]) + C[:, 4] * T * T_SHARE * delta)

    def solve(self, rows: Rows, use: Array, mo: Motion, T_ref: float, delta: float,
              scale: float) -> LPResult:
        """The programme on the rows ``use`` (a mask) about the motion ``mo``, within the
        trust region: the accelerations within ``delta * scale`` of the motion's, ``T``
        within ``T_SHARE * delta`` (relative) of it."""
        sel = np.flatnonzero(use)
        k, C = rows.k[sel], rows.C[sel]
        x0 = np.concatenate([np.stack([mo.sigma, mo.w, mo.alpha], axis=1).reshape(-1),
                             [mo.T, 0.0]])
        ra = C[:, :4]
        local = np.stack([mo.sigma[k], mo.w[k], mo.alpha[k], mo.alpha[k + 1]], axis=1)
        rb = np.einsum("ij,ij->i", ra, local) + C[:, 4] * mo.T - rows.F[sel]
        rg = np.stack([C[:, 4], -np.ones(len(sel))], axis=1)
        lo, hi = self.lo.copy(), self.hi.copy()
        inner = slice(1, self.M)
        lo[inner, 2] = mo.alpha[inner] - delta * scale
        hi[inner, 2] = mo.alpha[inner] + delta * scale
        dT = T_SHARE * delta
        c = self.c.copy()
        c[-2] = 1.0 / T_ref
        lp = StagedLP(c, k, ra, rg, rb, self.E,
                      np.concatenate([lo.reshape(-1), [mo.T * (1 - dT), 0.0]]),
                      np.concatenate([hi.reshape(-1), [mo.T * (1 + dT), np.inf]]))
        return solve_staged(lp, x0)

    def states(self, x: Array) -> tuple[Array, Array, Array, float, float]:
        """``sigma, w, alpha`` (M + 1,), ``T`` and the slack of a programme's solution."""
        s = x[:-2].reshape(-1, 3)
        return s[:, 0], s[:, 1], s[:, 2], float(x[-2]), float(x[-1])


def time_scaled(model: Model, J: Array, T: float) -> float:
    """The duration that brings the normalised motion ``J`` just within its rows (a start
    that is slower than the limits allow is sped up, one beyond them slowed down): each
    row's use scales about as ``T^-p`` (:meth:`Rows.powers`); exact where it does, so a few
    rounds, then doubling while a row is still beyond its limit (gravity or friction rows
    that scale more slowly)."""
    for _ in range(40):
        rows = model.rows(motion(model.mesh, J, T, model.length))
        i = int(np.argmax(rows.F))
        worst = float(rows.F[i])
        p = rows.powers()
        use = np.maximum(rows.F + 1.0, 0.0)
        on = p > 0
        factor = float(np.max(use[on] ** (1.0 / p[on]))) if on.any() else 1.0
        if worst <= 0.0 and abs(factor - 1.0) < 1e-3:
            break
        if worst > 0.0:
            if p[i] == 0:
                break  # a row the duration does not change
            factor = max(factor, 1.5)
        T *= factor * (1 + 1e-4)
    return T


def slp(model: Model, J: Array, T: float, budget: int, delta: float) -> Run:
    """Sequential linear programming with a trust region from the motion ``(J, T)``, which
    meets the end conditions (see the module doc)."""
    mesh, S = model.mesh, model.length
    lp = Programme(mesh, S)
    mo = motion(mesh, J, T, S)
    T_ref = T
    rows = model.rows(mo)
    phi = merit(T, T_ref, rows.F, lp.ahead(mo))
    n = 0
    converged = False
    scale = max(float(np.abs(mo.alpha).max()), 1e-300)
    debug = log.isEnabledFor(logging.DEBUG)
    while n < budget:
        use = rows.F + lp.reach(rows, delta, scale, mo.T) > -1e-9
        res = None
        for _ in range(5):  # a row left out and crossed (rounding only) joins
            res = lp.solve(rows, use, mo, T_ref, delta, scale)
            n += 1
            if res.status != 0:
                break
            sig, w, al, Tn, eps = lp.states(res.x)
            lin = rows.linear(sig - mo.sigma, w - mo.w, al - mo.alpha, Tn - mo.T)
            crossed = ~use & (lin > eps + 1e-9)
            if not crossed.any():
                break
            log.debug("      %d rows left out crossed", int(crossed.sum()))
            use |= crossed
        assert res is not None
        if res.status != 0:  # numerical trouble: a smaller step
            log.debug("    programme status %d after %d iterations", res.status, res.nit)
            delta *= 0.25
            if delta < 1e-8:
                break
            continue
        sig, w, an, Tn, eps = lp.states(res.x)
        Jn = np.diff(an) / mesh.h
        pred = phi - res.fun
        mn = motion(mesh, Jn, Tn, S)
        new = model.rows(mn)
        phin = merit(Tn, T_ref, new.F, lp.ahead(mn))
        actual = phi - phin
        ratio = actual / pred if pred > 0 else (1.0 if actual >= 0 else -1.0)
        step = max(float(np.abs(an - mo.alpha).max()) / scale, abs(Tn - T) / (T_SHARE * T))
        if debug:
            i = int(np.argmax(new.F))
            log.debug("    T %.7f eps %.1e max row %.2e (%s) rows %d/%d pred %.1e ratio %.2f "
                      "delta %.2g iterations %d", Tn, eps, new.F.max(), new.kind_of(i),
                      int(use.sum()), len(use), pred, ratio, delta, res.nit)
        if ratio > 0.1:
            T_prev, delta_prev = T, delta
            mo, T, rows, phi = mn, Tn, new, phin
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
    return Run(mo.J, mo.T, n, converged, float(rows.F.max()))
