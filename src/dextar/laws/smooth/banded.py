"""The transcription's linear programmes, solved by a primal-dual interior-point method whose
Newton systems are banded: memory and work per iteration linear in the number of knots.

The programme (:class:`StagedLP`) has the structure of a discrete-time control problem: the
variables are the states ``x_k = (sigma_k, w_k, alpha_k, T_k)`` at the knots ``k = 0..M``
(stored knot by knot) and a *border* of ``P = 1`` variable shared by all (the slack of the
penalty); every inequality row couples the states of one interval (knots ``k`` and
``k + 1``) with the border, every equality (``Q = 3`` per interval: the exact integration,
the duration's continuity) the states of one interval. In the Newton system of the
interior-point method, with the variables of each knot followed by the multipliers of its
interval's equalities, the matrix is a band of half-width 8 bordered by
``P`` dense columns: one LU factorisation of the band (LAPACK ``dgbtrf``) and a ``P x P``
Schur complement solve it in ``O(M)``.

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

Compiled (``_ipm.c``, built by pip where a C compiler is; :data:`USE_COMPILED`): the same
method, start, steps and stopping rules in one call, the band factorised by elimination with
partial pivoting within the band (as LAPACK's ``dgbtf2``), a signal's handler run between
iterations; the same solutions to the programmes' tolerances (the sums in another order),
without the numpy calls' overhead that dominates a pick-and-place move's small programmes
(a few hundred rows).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..._arrays import Array
from ..._compiled import usable
from ..._lazy import lazy_module

try:  # the interior point compiled (_ipm.c), built by pip where a C compiler is
    from . import _ipm as _compiled
except ImportError:  # pragma: no cover - installed without a C compiler: the numpy solver
    _compiled = None  # type: ignore[assignment]  # the module or None, as USE_COMPILED says

#: The compiled solver's interface this module calls (``IPM_VERSION`` in _ipm.c): a build
#: of another version (an old one left in place) is not used.
IPM_VERSION = 4
if not usable(_compiled, IPM_VERSION):
    _compiled = None  # type: ignore[assignment]  # an old build: the numpy solver instead

#: Whether the programmes are solved compiled (where it was built): False gives the numpy
#: solver (the same solutions to the tolerances; the tests compare the two).
USE_COMPILED = _compiled is not None

lapack = lazy_module("scipy.linalg.lapack")
sparse = lazy_module("scipy.sparse")

#: States per knot (arc length, speed, acceleration, duration), equalities per interval
#: (the exact integration and the duration's continuity), border variables (the slack).
D, Q, P = 4, 3, 1
#: Band positions per knot (its states, then its interval's equalities).
BLOCK = D + Q
#: Each state's band position in its knot's block (``alpha, T`` first: a row couples the
#: interval's states with the next knot's ``alpha, T``, so the band is narrowest so).
PERM = np.array([2, 3, 0, 1])
#: A row's variables relative to its interval's first knot: sigma_k, w_k, alpha_k, T_k,
#: alpha_k+1 and T_k+1 (the rows of the transcription do not involve sigma_k+1 or w_k+1),
#: as indices of x and as band positions.
ROW_X = np.array([0, 1, 2, 3, D + 2, D + 3])
ROW_POS = np.concatenate([PERM, BLOCK + PERM[2:]])
NR = len(ROW_POS)
#: An equality's band positions: the states of both knots of its interval.
EQ_POS = np.concatenate([PERM, BLOCK + PERM])
#: The band's half-widths (below and above the diagonal): 8.
KL = KU = max(int(ROW_POS.max() - ROW_POS.min()),
              int(np.abs(EQ_POS[:, None] - (D + np.arange(Q))[None, :]).max()))
#: Regularisation of the Newton matrix (primal +, dual -): far below the barrier terms. (It
#: was 1e-11: a Newton direction then missed the equalities by ``REG dy``, at 16k knots
#: about 1e-7, forty times their tolerance, and the steps at the path's ends were cut short;
#: on a 20 mm line 69 iterations, 51 with this.)
REG = 1e-14
#: Fraction of the step to the boundary.
ETA = 0.99
#: The start's multipliers: on the central path of this complementarity.
MU0 = 1e-3
#: The corrector's complementarity target at least this fraction of the mean the gap's
#: tolerance allows (``gap_tol (1 + |c x|)`` over the inequalities), or the mean itself
#: where it is already below (a target is never above the mean): past it the gap is
#: within its tolerance ten times over, and a smaller target only makes the barrier terms
#: span more decades, the Newton directions less accurate, and the residuals still to close
#: grow instead. Without it, on the refined chain at 8000 knots (13 of its programmes):
#: four ran to ``maxiter``, one with the gap closed from 1.2 to 1e-5 of its tolerance in five
#: iterations while the dual residual grew from 0.86 to 3.5e7 of its own; with it those four
#: take 52, 29, 34 and 29 iterations (615 iterations -> 520); the benchmark's line at 4k and
#: 16k knots the same solutions in the same iterations (24 and 31).
TARGET_FLOOR = 0.1
#: The start's slacks at least this much: of ``1 + |rb|`` for a row, of the box's width for
#: a bound. Measured on the pick-and-place line's two programmes (``bench_smooth.py
#: scaling``) at 1k, 2k, 4k, 8k, 16k and 32k knots: with 1e-2 and 1e-3 the second took 15,
#: 16, 19, 20, 28 and 30 iterations, with these 15, 15, 15, 16, 19 and 28 (the first 17, 18,
#: 21, 23, 24, 27 and 17, 17, 22, 26, 24, 25); with 1e-4 and 1e-5 the second 12, 14, 16 at
#: 1k, 4k, 16k, but the durations of 80 random corners 0.29 % longer on average. With these
#: the corners' durations are the same on average (+0.014 % on each of two seeds; each moves
#: by up to about 7 % either way, another path of a local search), their planning 5 % faster.
SLACK_FLOOR = 1e-3
BOUND_FLOOR = 1e-4
#: A programme whose rows' products with their pairs of variables are at most this many
#: keeps them from iteration to iteration, as sparse matrices (memory: about 16 bytes
#: each; a larger programme computes them in every iteration, a pair at a time).
KEEP = 1 << 20


@dataclass(frozen=True)
class StagedLP:
    """``min c x`` subject to ``ra[r] . (sigma_k, w_k, alpha_k, T_k, alpha_k+1, T_k+1) +
    rg[r] . border <= rb[r]`` (``k = rk[r]``), ``E[k] . (x_k, x_k+1) = e[k]`` for every
    interval ``k`` and ``lo <= x <= hi`` (``lo == hi``: fixed).

    Attributes
    ----------
    c, lo, hi : ndarray, shape (4 (M + 1) + 1,)
        The knots' states (``sigma, w, alpha, T`` of knot 0, then of knot 1, ...), then the
        border. ``lo`` may be ``-inf``, ``hi`` ``inf``.
    rk : ndarray of int, shape (R,)
    ra : ndarray, shape (R, 6)
        On ``sigma_k, w_k, alpha_k, T_k, alpha_k+1, T_k+1``.
    rg : ndarray, shape (R, 1)
    rb : ndarray, shape (R,)
    E : ndarray, shape (M, 3, 8)
    e : ndarray, shape (M, 3)
    rq : ndarray, shape (R,), optional
        Proximal weights: ``sum rq[r] (g_r . (x - x0))^2 / 2`` is added to the objective
        (``g_r`` the row's coefficients, ``x0`` the solve's start), so that the solution is
        unique where the rows leave it nearly free (see :func:`solve_staged`).
    """

    c: Array
    rk: Array
    ra: Array
    rg: Array
    rb: Array
    E: Array
    e: Array
    lo: Array
    hi: Array
    rq: Array | None = None


@dataclass(frozen=True)
class LPResult:
    """``x`` and ``fun = c x``; ``status`` 0 (converged), 1 (iteration limit) or 2 (a
    singular Newton matrix); ``nit`` iterations."""

    x: Array
    fun: float
    status: int
    nit: int


def solve_staged(lp: StagedLP, x0: Array, *, tol: float = 1e-9, dual_tol: float = 1e-6,
                 gap_tol: float = 1e-6, maxiter: int = 60) -> LPResult:
    """The programme's solution from ``x0`` (meeting the equalities or near them).

    Converged when the primal residuals are below ``tol`` (relative to the largest
    right-hand side), the dual ones below ``dual_tol`` (relative to the largest cost) and
    the total complementarity (the duality gap) below ``gap_tol (1 + |c x|)`` (the
    sequential programmes need the objective to far fewer digits, their tests a reduction
    of 1e-4 of it; the last digits cost the most iterations: with 1e-8 and :data:`REG`
    1e-11, as before, 80 random blended corners took 7-25 % more programmes and 19-34 %
    more CPU time on three seeds, for durations the same on average: these +0.04 %,
    -0.14 % and +0.34 % against those). Near the end the
    Newton systems lose accuracy (the barrier terms span many decades) and the dual
    residual may stall or grow: the best iterate met is returned, converged when it is
    within a hundred times those tolerances. With proximal weights (``lp.rq``) the
    objective has their quadratic term about ``x0`` (a convex quadratic programme: the
    same method, the term's Hessian in the Newton matrix, its gradient in the dual
    residual); ``fun`` is ``c x`` alone. Compiled where it was built
    (:data:`USE_COMPILED`)."""
    if USE_COMPILED and _compiled is not None and lp.rg.shape[1:] == (P,) and P == 1:
        x = np.empty(len(lp.c))

        def f64(v: Array) -> Array:
            return np.ascontiguousarray(v, float)

        status, nit = _compiled.solve(f64(lp.c), np.ascontiguousarray(lp.rk, np.int64),
                                      f64(lp.ra), f64(lp.rg), f64(lp.rb), f64(lp.E),
                                      f64(lp.e), f64(lp.lo), f64(lp.hi),
                                      f64(np.zeros(len(lp.rk)) if lp.rq is None else lp.rq),
                                      f64(x0), x, tol,
                                      dual_tol, gap_tol, maxiter)
        return LPResult(x, objective(lp.c, x), status, nit)
    c, rk, ra, rg, rb, E, lo, hi = (lp.c, lp.rk, lp.ra, lp.rg, lp.rb, lp.E, lp.lo, lp.hi)
    e = np.asarray(lp.e, float).reshape(-1)
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
    xr = D * rk  # each row's first variable
    exi = (D * k)[:, None] + np.arange(2 * D)[None, :]
    exi_flat = np.repeat(exi[:, None, :], Q, axis=1).reshape(-1)
    base = BLOCK * rk  # each row's first band position
    xband = ((BLOCK * np.arange(K))[:, None] + PERM[None, :]).reshape(-1)
    yband = ((BLOCK * k)[:, None] + D + np.arange(Q)[None, :]).reshape(-1)
    # the matrix's columns of fixed variables are empty (their steps are zero)
    Em = E * free[exi][:, None, :]
    # the fixed variables' rows of the matrix are those of the identity (their steps are
    # zero, so what their columns hold does not matter): the band's entries to clear
    fpos = xband[np.flatnonzero(fixed[:nk])]
    cols = fpos[:, None] + np.arange(-KU, KL + 1)[None, :]
    ok = (cols >= 0) & (cols < nb)
    # band storage for dgbtrf: A[i, j] at ab[KL + KU + i - j, j], ab in Fortran order (so
    # that LAPACK takes it as it is): flat index j * nrow + KL + KU + i - j
    nrow = 2 * KL + KU + 1
    clear = (cols * nrow + KL + KU + fpos[:, None] - cols)[ok]
    # the rows' terms of the matrix, by ordered pairs of their variables (both triangles):
    # the term of row r and pair (a, b) lands at band index base[r] * nrow + offset
    used = [a for a in range(NR) if ra[:, a].any()]
    pa = np.array([a for a in used for b in used], int)
    pb = np.array([b for a in used for b in used], int)
    pair_off = (ROW_POS[pb] * nrow + KL + KU + ROW_POS[pa] - ROW_POS[pb])
    diag_x = xband * nrow + KL + KU
    diag_y = yband * nrow + KL + KU
    pairs = [(a, b) for a in used for b in used if a <= b]  # (the large programmes')

    def eq_band() -> Array:
        """The band with the equalities' part (and the dual regularisation): the same in
        every iteration."""
        ab = np.zeros(nrow * nb)
        abT = ab.reshape(nb, nrow)  # abT[j, KL + KU + i - j] = A[i, j]
        for q in range(Q):  # the equalities and their transposes, interval by interval
            i = D + q
            for a in range(2 * D):
                j = EQ_POS[a]
                abT[j:nb - BLOCK + j + 1:BLOCK, KL + KU + i - j] += Em[:, q, a]
                abT[i:nb - BLOCK + i + 1:BLOCK, KL + KU + j - i] += Em[:, q, a]
        ab[diag_y] -= REG
        return ab

    # a small programme keeps its rows' parts of G, G^T, the band and the border as sparse
    # matrices and the equalities' part of the band, made once; a large one (whose memory
    # they would double) builds them in every iteration, a pair of variables at a time
    kept = _Kept(ra, xr, base, pa, pb, pair_off, nrow, nb) if R * len(pa) <= KEEP else None
    del base  # (a large programme's band makes it again: not kept through its steps)
    ab_eq = eq_band() if kept is not None else None

    iu, il = np.flatnonzero(hasu), np.flatnonzero(hasl)
    nu, nl = len(iu), len(il)
    m_all = R + nu + nl
    # every inequality as g . x <= h: the rows, then x <= hi, then -x <= -lo

    def h_all() -> Array:
        """Every inequality's right-hand side (made when needed: one more array of every
        row's kept through the steps otherwise)."""
        return np.concatenate([rb, hi[iu], -lo[il]])

    bnd = np.concatenate([iu, il])
    sgn = np.concatenate([np.ones(nu), -np.ones(nl)])

    def G(x: Array) -> Array:
        """Every inequality's ``g . x``."""
        if kept is not None:
            out = rg @ x[nk:] + kept.times(x)
        else:
            out = rg @ x[nk:]
            for a in range(NR):
                out += ra[:, a] * x[xr + ROW_X[a]]
        return np.concatenate([out, sgn * x[bnd]])

    def GT(z: Array) -> Array:
        """``sum z g`` over the inequalities (fixed variables' entries zero)."""
        out = np.bincount(bnd, sgn * z[R:], minlength=nx)
        zr = z[:R]
        if kept is not None:
            out[:nk] += kept.transposed(zr, nk)
        else:
            for a in range(NR):
                out[ROW_X[a]:nk] += np.bincount(xr, ra[:, a] * zr,
                                                minlength=nk)[:nk - ROW_X[a]]
        out[nk:] += rg.T @ zr
        out[fixed] = 0.0
        return np.asarray(out)

    def Ex(x: Array) -> Array:
        return np.asarray(np.einsum("kqj,kj->kq", E, x[exi]).reshape(-1) - e)

    def ETy(y: Array) -> Array:
        out = np.zeros(nx)
        out[:nk] = np.bincount(exi_flat, (E * y.reshape(M, Q)[:, :, None]).reshape(-1),
                               minlength=nk)
        out[fixed] = 0.0
        return out

    # the start: x0 as given (fixed variables at their values), the slacks at least a small
    # margin, the multipliers on the central path of MU0
    x = np.where(fixed, lo, np.asarray(x0, float))
    width = np.where(hasu & hasl, hi - lo, np.abs(x) + 1.0)
    floor = np.concatenate([SLACK_FLOOR * (1.0 + np.abs(rb)), BOUND_FLOOR * width[iu],
                            BOUND_FLOOR * width[il]])
    gx = G(x)
    sl = np.maximum(h_all() - gx, floor)
    del floor, width
    # the proximal term's weights and centres (the rows at the start)
    rq = np.zeros(R) if lp.rq is None else np.asarray(lp.rq, float)
    if rq.shape != (R,):
        raise ValueError(f"rq must hold the {R} rows' weights, not {rq.shape}")
    near = np.flatnonzero(rq)
    rc = gx[near]
    del gx
    z = MU0 / sl
    y = np.zeros(Q * M)
    scale_p = 1.0 + float(np.abs(rb).max(initial=0.0))
    scale_d = 1.0 + float(np.abs(c).max(initial=0.0))
    status, it = 1, 0
    best: tuple[float, Array] = (np.inf, x)
    for it in range(maxiter + 1):
        gx = G(x)
        zq = z
        if near.size:  # (the proximal term's gradient with the rows' multipliers)
            zq = z.copy()
            zq[near] += rq[near] * (gx[near] - rc)
        rd = c + GT(zq) + ETy(y)
        del zq
        rd[fixed] = 0.0
        rp = gx + sl - h_all()
        del gx
        re = Ex(x)
        gap = float(sl @ z)
        cx = abs(float(c @ x))
        miss = max(max(float(np.abs(rp).max(initial=0.0)), float(np.abs(re).max(initial=0.0)))
                   / (tol * scale_p), float(np.abs(rd).max()) / (dual_tol * scale_d),
                   gap / (gap_tol * (1.0 + cx)))
        if miss < best[0]:
            best = (miss, x.copy())
        if miss <= 1.0:
            status = 0
            break
        if it == maxiter or gap <= 1e-6 * gap_tol * (1.0 + cx):
            break  # (the gap closed: further steps only lose accuracy)
        mu = gap / m_all
        Dz = z / sl
        diag = np.full(nx, REG) + np.bincount(bnd, Dz[R:], minlength=nx)
        diag[fixed] = 1.0
        Dr = Dz[:R] + rq
        U = np.zeros((nb, P))
        if kept is not None and ab_eq is not None:
            ab = ab_eq.copy()
            kept.band(Dr, ab)
            for p in range(P):
                kept.border(Dr * rg[:, p], U[:, p])
        else:
            ab = eq_band()
            abT = ab.reshape(nb, nrow)
            base = BLOCK * rk
            for a, b in pairs:
                add = np.bincount(base, Dr * ra[:, a] * ra[:, b], minlength=nb)
                i, j = ROW_POS[a], ROW_POS[b]
                abT[j:, KL + KU + i - j] += add[:nb - j]
                if a != b:
                    abT[i:, KL + KU + j - i] += add[:nb - i]
            del add
            for p in range(P):
                drg = Dr * rg[:, p]
                for a in range(NR):
                    U[ROW_POS[a]:, p] += np.bincount(base, drg * ra[:, a],
                                                     minlength=nb)[:nb - ROW_POS[a]]
                del drg
            del base
        abT = ab.reshape(nb, nrow)
        ab[clear] = 0.0
        ab[diag_x] += diag[:nk]
        U[fpos] = 0.0
        corner = (rg * Dr[:, None]).T @ rg + np.diag(diag[nk:])
        lu, piv, info = lapack.dgbtrf(abT.T, KL, KU, overwrite_ab=1)
        if info != 0:
            status = 2
            break
        BU = lapack.dgbtrs(lu, KL, KU, U, piv)[0]
        newton = _Newton(lu, piv, BU, U, corner - U.T @ BU, Dz, rd, rp, re, z, sl, G, GT,
                         fixed, xband, yband, nb, nk)
        _, _, adz, ads = newton.step(sl * z)
        ap = min(1.0, _to_bound(sl, ads))
        ad = min(1.0, _to_bound(z, adz))
        mu_aff = float((sl + ap * ads) @ (z + ad * adz)) / m_all
        target = max((mu_aff / mu) ** 3 * mu,
                     min(mu, TARGET_FLOOR * gap_tol * (1.0 + cx) / m_all))
        cc = sl * z + ads * adz - target
        del adz, ads
        dx, dy, dz, ds = newton.step(cc)
        del cc
        ap = min(1.0, ETA * _to_bound(sl, ds))
        ad = min(1.0, ETA * _to_bound(z, dz))
        x += ap * dx
        sl += ap * ds
        y += ad * dy
        z += ad * dz
        # (the band, its factors and the steps are not kept into the next iteration: at
        # 16k knots each of them is tens of megabytes)
        del newton, lu, ab, abT, dx, dy, dz, ds, Dz, Dr, rp
    if status != 0 and best[0] <= 100.0:
        status, x = 0, best[1]
    return LPResult(x, objective(c, x), status, it)


def objective(c: Array, x: Array) -> float:
    """``c . x`` by numpy's own summation, not BLAS: OpenBLAS runs a dot product of more
    than a few thousand terms on its threads, which then spin on the other cores while the
    next rows are built (a third more CPU time at 4000 knots on 2 cores)."""
    return float(np.multiply(c, x).sum())


@dataclass(frozen=True)
class _Newton:
    """One iteration's Newton system, factorised: the band's LU, the border's solves and
    Schur complement, the barrier terms ``z / s`` and the residuals at the iterate."""

    lu: Array
    piv: Array
    BU: Array
    U: Array
    schur: Array
    Dz: Array
    rd: Array
    rp: Array
    re: Array
    z: Array
    s: Array
    G: Callable[[Array], Array]
    GT: Callable[[Array], Array]
    fixed: Array
    xband: Array
    yband: Array
    nb: int
    nk: int

    def step(self, cc: Array) -> tuple[Array, Array, Array, Array]:
        """The step ``(dx, dy, dz, ds)`` for the complementarity targets
        ``s z + ds z + s dz = -cc`` of every inequality."""
        nk = self.nk
        t = self.rp - cc / self.z
        rhs = -self.rd - self.GT(self.Dz * t)
        full = np.zeros(self.nb)
        full[self.xband] = rhs[:nk]
        full[self.yband] = -self.re
        sb = lapack.dgbtrs(self.lu, KL, KU, full[:, None], self.piv)[0][:, 0]
        r = rhs[nk:] - self.U.T @ sb
        dp = r / self.schur[0, 0] if P == 1 else np.linalg.solve(self.schur, r)
        db = sb - self.BU @ dp
        dx = np.concatenate([db[self.xband], dp])
        dx[self.fixed] = 0.0
        dz = self.Dz * (self.G(dx) + t)
        del t
        ds = self.s * dz  # (-cc - s dz) / z, in place
        ds += cc
        ds /= self.z
        np.negative(ds, out=ds)
        return dx, db[self.yband], dz, ds


class _Kept:
    """A small programme's rows (coefficients ``ra``, first variables ``xr``, first band
    positions ``base``) as sparse matrices made once: their parts of ``G x``, ``G^T z``, the
    band and the border (each row's entries are a row of G and a column of the band's and
    the border's matrices: compressed storage made directly, no sorting)."""

    def __init__(self, ra: Array, xr: Array, base: Array, pa: Array, pb: Array,
                 pair_off: Array, nrow: int, nb: int) -> None:
        n, npair = len(ra), len(pa)
        top = BLOCK + int(ROW_POS.max()) + 1  # past a row's last band position
        self.u0 = int(base.min(initial=0))
        self.u1 = min(int(base.max(initial=0)) + top, nb)
        self.nrow = nrow
        xi = xr[:, None] + ROW_X[None, :]
        bi = ((base - self.u0) * nrow)[:, None] + pair_off[None, :]
        ui = base[:, None] + ROW_POS[None, :] - self.u0
        nx = int(xi.max(initial=0)) + 1
        self.g = sparse.csr_matrix((ra.reshape(-1), xi.reshape(-1),
                                    np.arange(0, NR * n + 1, NR)), shape=(n, nx))
        self.gt = self.g.T
        self.bandm = sparse.csc_matrix(((ra[:, pa] * ra[:, pb]).reshape(-1), bi.reshape(-1),
                                        np.arange(0, npair * n + 1, npair)),
                                       shape=((self.u1 - self.u0) * nrow, n))
        self.borderm = sparse.csc_matrix((ra.reshape(-1), ui.reshape(-1),
                                          np.arange(0, NR * n + 1, NR)),
                                         shape=(self.u1 - self.u0, n))

    def times(self, x: Array) -> Array:
        """The rows' ``ra . x`` (n,)."""
        return np.asarray(self.g @ x[:self.g.shape[1]])

    def transposed(self, z: Array, nk: int) -> Array:
        """``sum z ra`` over the rows, on the knots' states (nk,)."""
        out = np.zeros(nk)
        out[:self.gt.shape[0]] = self.gt @ z
        return out

    def band(self, d: Array, ab: Array) -> None:
        """Add the rows' ``ra^T diag(d) ra`` to the band ``ab`` (flat, LAPACK's storage)."""
        ab[self.u0 * self.nrow:self.u1 * self.nrow] += self.bandm @ d

    def border(self, d: Array, u: Array) -> None:
        """Add the rows' ``ra^T d`` to the band's part ``u`` (nb,) of a border column."""
        u[self.u0:self.u1] += self.borderm @ d


def _to_bound(v: Array, dv: Array) -> float:
    """The largest step ``a`` with ``v + a dv >= 0`` (``inf`` when none is limited)."""
    neg = dv < 0
    return float(np.min(-v[neg] / dv[neg], initial=np.inf))
