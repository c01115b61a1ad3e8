"""The transcription's linear programmes, solved by a primal-dual interior-point method whose
Newton systems are banded: memory and work per iteration linear in the number of knots.

The programme (:class:`StagedLP`) has the structure of a discrete-time control problem: the
variables are the states ``x_k = (sigma_k, w_k, alpha_k)`` at the knots ``k = 0..M``
(stored knot by knot) and a *border* of ``P = 2`` variables shared by all (the duration and
the slack of the penalty); every inequality row couples the states of one interval (knots
``k`` and ``k + 1``) with the border, every equality (``Q = 2`` per interval, the exact
integration) the states of one interval. In the Newton system of the interior-point method,
with the variables of each knot followed by the multipliers of its interval's equalities,
the matrix is a band of half-width ``2 D + Q - 1 = 7`` bordered by ``P`` dense columns: one
LU factorisation of the band (LAPACK ``dgbtrf``) and a ``P x P`` Schur complement solve it
in ``O(M)``.

Method: Mehrotra's predictor-corrector (Nocedal & Wright, *Numerical Optimization*, 2nd ed.,
Springer 2006, sec. 14.2; Wright, *Primal-Dual Interior-Point Methods*, SIAM 1997, ch. 10) on
the inequality form with slacks, from an infeasible start at the caller's point (the current
motion, which meets the equalities), separate primal and dual step lengths. Fixed variables
(``lo == hi``: the ends, the pinned knots) keep their values and leave the matrix.

Why not HiGHS (``scipy.optimize.linprog``): on these programmes its dual simplex and its
interior point (IPX) grow faster than linearly with the knots (one programme of 1000 knots:
1.5 to 2.8 s, where this solver takes about 0.05 s; ``benchmarks/bench_smooth.py`` prints
the comparison); the border's two dense columns (every row has the duration and the slack)
are what a general sparse solver handles poorly and a bordered band handles exactly. The
loop returns to Python at every iteration (tens of milliseconds at 16k knots), so that an
interrupt acts at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lapack

from ..._arrays import Array

#: States per knot, equalities per interval, border variables.
D, Q, P = 3, 2, 2
#: Band positions per knot (its states, then its interval's equalities).
BLOCK = D + Q
#: A row's band positions relative to its interval's first: sigma_k, w_k, alpha_k and
#: alpha_k+1 (the rows of the transcription do not involve sigma_k+1 or w_k+1).
ROW_POS = np.array([0, 1, 2, BLOCK + 2])
#: An equality's band positions: the states of both knots of its interval.
EQ_POS = np.array([0, 1, 2, BLOCK, BLOCK + 1, BLOCK + 2])
#: The band's half-widths (below and above the diagonal).
KL = KU = 2 * D + Q - 1
#: Regularisation of the Newton matrix (primal +, dual -): far below the barrier terms.
REG = 1e-11
#: Fraction of the step to the boundary.
ETA = 0.99


@dataclass(frozen=True)
class StagedLP:
    """``min c x`` subject to ``ra[r] . (sigma, w, alpha)_k, alpha_k+1 + rg[r] . border <=
    rb[r]`` (``k = rk[r]``), ``E[k] . (x_k, x_k+1) = 0`` for every interval ``k`` and
    ``lo <= x <= hi`` (``lo == hi``: fixed).

    Attributes
    ----------
    c, lo, hi : ndarray, shape (3 (M + 1) + 2,)
        The knots' states (``sigma, w, alpha`` of knot 0, then of knot 1, ...), then the
        border. ``lo`` may be ``-inf``, ``hi`` ``inf``.
    rk : ndarray of int, shape (R,)
    ra : ndarray, shape (R, 4)
    rg : ndarray, shape (R, 2)
    rb : ndarray, shape (R,)
    E : ndarray, shape (M, 2, 6)
    """

    c: Array
    rk: Array
    ra: Array
    rg: Array
    rb: Array
    E: Array
    lo: Array
    hi: Array


@dataclass(frozen=True)
class LPResult:
    """``x`` and ``fun = c x``; ``status`` 0 (converged), 1 (iteration limit) or 2 (a
    singular Newton matrix); ``nit`` iterations."""

    x: Array
    fun: float
    status: int
    nit: int


def solve_staged(lp: StagedLP, x0: Array, *, tol: float = 1e-9,
                 maxiter: int = 60) -> LPResult:
    """The programme's solution from ``x0`` (meeting the equalities or near them).

    Converged when the primal and dual residuals are below ``tol`` (relative to the largest
    right-hand side and cost) and the total complementarity (the duality gap) below
    ``tol (1 + |c x|)``."""
    c, rk, ra, rg, rb, E, lo, hi = (lp.c, lp.rk, lp.ra, lp.rg, lp.rb, lp.E, lp.lo, lp.hi)
    nx = len(c)
    K = (nx - P) // D
    M = K - 1
    nb = BLOCK * M + D  # the band's size
    nk = D * K  # the knots' states
    R = len(rk)
    fixed = lo == hi
    free = ~fixed
    hasu = np.isfinite(hi) & free
    hasl = np.isfinite(lo) & free
    k = np.arange(M)
    # the variables of each row and equality (x numbering), and their band positions
    xi = (D * rk)[:, None] + np.array([0, 1, 2, D + 2])[None, :]
    xi_flat = xi.reshape(-1)
    exi = (D * k)[:, None] + np.arange(2 * D)[None, :]
    exi_flat = np.repeat(exi[:, None, :], Q, axis=1).reshape(-1)
    bpos = (BLOCK * rk)[:, None] + ROW_POS[None, :]
    xband = ((BLOCK * np.arange(K))[:, None] + np.arange(D)[None, :]).reshape(-1)
    yband = ((BLOCK * k)[:, None] + D + np.arange(Q)[None, :]).reshape(-1)
    # the matrix's columns of fixed variables are empty (their steps are zero)
    ram = ra * free[xi]
    rgm = rg * free[None, nk:]
    Em = E * free[exi][:, None, :]
    # band storage for dgbtrf: A[i, j] at ab[KL + KU + i - j, j]
    nrow = 2 * KL + KU + 1
    ii, jj = np.repeat(bpos, 4, axis=1), np.tile(bpos, (1, 4))
    flat_rows = ((KL + KU + ii - jj) * nb + jj).reshape(-1)
    ei = np.repeat(yband.reshape(M, Q)[:, :, None], 2 * D, axis=2)
    ej = np.repeat(((BLOCK * k)[:, None] + EQ_POS[None, :])[:, None, :], Q, axis=1)
    static = np.bincount(np.concatenate([((KL + KU + ei - ej) * nb + ej).reshape(-1),
                                         ((KL + KU + ej - ei) * nb + ei).reshape(-1)]),
                         np.concatenate([Em.reshape(-1), Em.reshape(-1)]),
                         minlength=nrow * nb)
    static[(KL + KU) * nb + yband] -= REG
    diag_x = (KL + KU) * nb + xband

    def Gx(x: Array) -> Array:
        return np.asarray(np.einsum("ij,ij->i", ra, x[xi]) + rg @ x[nk:])

    def GTz(z: Array) -> Array:
        out = np.empty(nx)
        out[:nk] = np.bincount(xi_flat, (ra * z[:, None]).reshape(-1), minlength=nk)
        out[nk:] = rg.T @ z
        return out

    def Ex(x: Array) -> Array:
        return np.asarray(np.einsum("kqj,kj->kq", E, x[exi]).reshape(-1))

    def ETy(y: Array) -> Array:
        out = np.zeros(nx)
        out[:nk] = np.bincount(exi_flat, (E * y.reshape(M, Q)[:, :, None]).reshape(-1),
                               minlength=nk)
        return out

    # the start: x0 as given (fixed variables at their values), the slacks at least a small
    # margin, the multipliers on the central path of MU0
    x = np.where(fixed, lo, np.asarray(x0, float))
    gx = Gx(x)
    width = np.where(hasu & hasl, hi - lo, np.abs(x) + 1.0)
    sr = np.maximum(rb - gx, 1e-2 * (1.0 + np.abs(rb)))
    su = np.maximum(hi - x, 1e-3 * width)[hasu]
    sl = np.maximum(x - lo, 1e-3 * width)[hasl]
    mu0 = 1e-2
    zr, zu, zl = mu0 / sr, mu0 / su, mu0 / sl
    y = np.zeros(Q * M)
    m_all = R + su.size + sl.size
    scale_p = 1.0 + float(np.abs(rb).max(initial=0.0))
    scale_d = 1.0 + float(np.abs(c).max(initial=0.0))
    status, it = 1, 0
    for it in range(maxiter + 1):
        rd = c + GTz(zr) + ETy(y)
        rd[hasu] += zu
        rd[hasl] -= zl
        rd[fixed] = 0.0
        rr = Gx(x) + sr - rb
        re = Ex(x)
        ru = (x - hi)[hasu] + su
        rl = (lo - x)[hasl] + sl
        gap = float(sr @ zr + su @ zu + sl @ zl)
        pres = max(float(np.abs(rr).max(initial=0.0)), float(np.abs(re).max(initial=0.0)),
                   float(np.abs(ru).max(initial=0.0)), float(np.abs(rl).max(initial=0.0)))
        if (pres <= tol * scale_p and float(np.abs(rd).max()) <= tol * scale_d
                and gap <= tol * (1.0 + abs(float(c @ x)))):
            status = 0
            break
        if it == maxiter:
            break
        mu = gap / m_all
        Dr = zr / sr
        du, dl = zu / su, zl / sl
        diag = np.full(nx, REG)
        diag[hasu] += du
        diag[hasl] += dl
        diag[fixed] = 1.0
        w = Dr[:, None] * ram
        ab = static + np.bincount(flat_rows, (w[:, :, None] * ram[:, None, :]).reshape(-1),
                                  minlength=nrow * nb)
        ab[diag_x] += diag[:nk]
        U = np.stack([np.bincount(bpos.reshape(-1), (w * rgm[:, p:p + 1]).reshape(-1),
                                  minlength=nb) for p in range(P)], axis=1)
        corner = (rgm * Dr[:, None]).T @ rgm + np.diag(diag[nk:])
        lu, piv, info = lapack.dgbtrf(ab.reshape(nrow, nb), KL, KU)
        if info != 0:
            status = 2
            break
        BU = lapack.dgbtrs(lu, KL, KU, U, piv)[0]
        schur = corner - U.T @ BU

        sys_ = _Newton(lu, piv, BU, U, schur, Dr, du, dl, rd, rr, re, ru, rl, zr, zu, zl, sr,
                       su, sl, GTz, Gx, hasu, hasl, fixed, xband, yband, nb, nk)
        _, _, azr, azu, azl, asr, asu, asl = sys_.step(sr * zr, su * zu, sl * zl)
        ap = min(1.0, _to_bound(sr, asr), _to_bound(su, asu), _to_bound(sl, asl))
        ad = min(1.0, _to_bound(zr, azr), _to_bound(zu, azu), _to_bound(zl, azl))
        mu_aff = float((sr + ap * asr) @ (zr + ad * azr) + (su + ap * asu) @ (zu + ad * azu)
                       + (sl + ap * asl) @ (zl + ad * azl)) / m_all
        target = (mu_aff / mu) ** 3 * mu
        dx, dy, dzr, dzu, dzl, dsr, dsu, dsl = sys_.step(
            sr * zr + asr * azr - target, su * zu + asu * azu - target,
            sl * zl + asl * azl - target)
        ap = min(1.0, ETA * min(_to_bound(sr, dsr), _to_bound(su, dsu), _to_bound(sl, dsl)))
        ad = min(1.0, ETA * min(_to_bound(zr, dzr), _to_bound(zu, dzu), _to_bound(zl, dzl)))
        x += ap * dx
        sr += ap * dsr
        su += ap * dsu
        sl += ap * dsl
        y += ad * dy
        zr += ad * dzr
        zu += ad * dzu
        zl += ad * dzl
    return LPResult(x, float(c @ x), status, it)


@dataclass(frozen=True)
class _Newton:
    """One iteration's Newton system, factorised: the band's LU, the border's solves and
    Schur complement, the barrier terms and residuals at the iterate."""

    lu: Array
    piv: Array
    BU: Array
    U: Array
    schur: Array
    Dr: Array
    du: Array
    dl: Array
    rd: Array
    rr: Array
    re: Array
    ru: Array
    rl: Array
    zr: Array
    zu: Array
    zl: Array
    sr: Array
    su: Array
    sl: Array
    GTz: Callable[[Array], Array]
    Gx: Callable[[Array], Array]
    hasu: Array
    hasl: Array
    fixed: Array
    xband: Array
    yband: Array
    nb: int
    nk: int

    def step(self, cr: Array, cu: Array, cl: Array) -> tuple[Array, ...]:
        """The step ``(dx, dy, dzr, dzu, dzl, dsr, dsu, dsl)`` for the complementarity
        targets ``s z + ds z + s dz = -c`` of the rows, upper and lower bounds."""
        zr, zu, zl, sr, su, sl = self.zr, self.zu, self.zl, self.sr, self.su, self.sl
        hasu, hasl, fixed, nk = self.hasu, self.hasl, self.fixed, self.nk
        tr, tu, tl = self.rr - cr / zr, self.ru - cu / zu, self.rl - cl / zl
        rhs = -self.rd - self.GTz(self.Dr * tr)
        rhs[hasu] -= self.du * tu
        rhs[hasl] += self.dl * tl
        rhs[fixed] = 0.0
        full = np.zeros(self.nb)
        full[self.xband] = rhs[:nk]
        full[self.yband] = -self.re
        sb = lapack.dgbtrs(self.lu, KL, KU, full[:, None], self.piv)[0][:, 0]
        dp = np.linalg.solve(self.schur, rhs[nk:] - self.U.T @ sb)
        db = sb - self.BU @ dp
        dx = np.concatenate([db[self.xband], dp])
        dx[fixed] = 0.0
        dzr = self.Dr * (self.Gx(dx) + tr)
        dzu = self.du * (dx[hasu] + tu)
        dzl = self.dl * (tl - dx[hasl])
        return (dx, db[self.yband], dzr, dzu, dzl, (-cr - sr * dzr) / zr,
                (-cu - su * dzu) / zu, (-cl - sl * dzl) / zl)


def _to_bound(v: Array, dv: Array) -> float:
    """The largest step ``a`` with ``v + a dv >= 0`` (``inf`` when none is limited)."""
    neg = dv < 0
    return float((-v[neg] / dv[neg]).min(initial=np.inf))
