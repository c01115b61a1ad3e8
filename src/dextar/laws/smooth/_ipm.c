/* The jerk-limited law's linear programmes compiled: the primal-dual interior point of
 * dextar.laws.smooth.banded.solve_staged (Mehrotra's predictor-corrector on the inequality
 * form with slacks, a Newton system that is a band of half-width 8 bordered by one column)
 * in one call, the same method, start, steps and stopping rules; the band factorised by
 * Gaussian elimination with partial pivoting within the band (as LAPACK's dgbtf2 does), so
 * the iterates agree with the Python solver's to rounding (not to the last bit: the sums
 * are taken in another order).
 *
 * Built by `pip install` when a C compiler is there (an optional extension: without one,
 * dextar runs the Python solver, which gives the same solutions to the programmes'
 * tolerances).
 *
 * solve(c, rk, ra, rg, rb, E, e, lo, hi, rq, x0, x, tol, dual_tol, gap_tol,
 *       maxiter) -> (status, iterations)
 *   The programme of banded.StagedLP with one border variable: c, lo, hi, x0 and the
 *   writable x hold nx = 4 (M + 1) + 1 float64 values (the knots' states sigma, w, alpha,
 *   T, knot by knot, then the border); rk (int64) the R rows' intervals, ra their 6
 *   coefficients on sigma_k, w_k, alpha_k, T_k, alpha_k+1, T_k+1 (R x 6), rg (R) on the
 *   border, rb (R) their right-hand sides, rq (R) their proximal weights (the objective's
 *   quadratic term sum rq (g . (x - x0))^2 / 2, 0 for none); E (M x 3 x 8) and e (M x 3)
 *   the equalities of each interval on the states of its two knots. The solution is
 *   written into x; status 0 (converged, or the best iterate within a hundred times the
 *   tolerances), 1 (the iteration limit) or 2 (a singular Newton matrix). A signal's Python handler runs
 *   between iterations (an exception it raises ends the solve).
 *
 * Compiled without contraction into fused multiply-adds (-ffp-contract=off).
 */

#include "../../_buffers.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif
/* A buffer of 4 MiB or more asked to be on huge pages (Linux: aligned to 2 MiB, the x86-64
 * huge page, and advised MADV_HUGEPAGE, which transparent huge pages in "madvise" mode wait
 * for; in "always" mode they come anyway, and elsewhere it is plain malloc; a failed aligned
 * allocation falls back to malloc). The interior point's band and rows are tens of
 * megabytes at 16k knots, swept several times an iteration, and 4 KiB pages miss the TLB on
 * every sweep. Measured on the scaling benchmark's line at 16k knots (five runs each,
 * interleaved): 1.14-1.22 s of CPU time against 1.22-1.35 s (medians 1.17 and 1.24), minor
 * page faults 34-37k against 62k; at 4k knots the same time; the same solutions. Freed by
 * free(). */
static void *big_alloc(size_t size)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t huge = (size_t)2 << 20;
    if (size >= 2 * huge) {
        void *p = NULL;
        if (posix_memalign(&p, huge, size) == 0) {
            madvise(p, size, MADV_HUGEPAGE);
            return p;
        }
    }
#endif
    return malloc(size);
}

#if (defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0) || defined(__FAST_MATH__)
#error "dextar's compiled interior point needs double evaluation without -ffast-math"
#endif

/* The interface version: banded.py uses a build of this version only. */
#define IPM_VERSION 4

/* States per knot, equalities per interval, band positions per knot, the band's
 * half-widths and its storage's width with the fill-in of the pivoting (banded.py's D, Q,
 * BLOCK, KL, KU). */
#define D 4
#define Q 3
#define BLOCK 7
#define KL 8
#define KU 8
#define W (2 * KL + KU + 1)
#define REG 1e-14
#define ETA 0.99
#define MU0 1e-3
/* the corrector's target at least this fraction of the mean complementarity the gap's
 * tolerance allows, or the mean where it is below (TARGET_FLOOR in banded.py) */
#define TARGET_FLOOR 0.1
/* the start's slacks at least this much: of 1 + |rb| for a row, of the width for a bound
 * (SLACK_FLOOR, BOUND_FLOOR in banded.py) */
#define SLACK_FLOOR 1e-3
#define BOUND_FLOOR 1e-4

/* a row's variables relative to its interval's first knot (as x indices, band positions),
 * each state's band position in its knot's block, an equality's band positions */
static const int ROW_X[6] = {0, 1, 2, 3, D + 2, D + 3};
static const int ROW_POS[6] = {2, 3, 0, 1, BLOCK + 0, BLOCK + 1};
static const int PERM[4] = {2, 3, 0, 1};
static const int EQ_POS[8] = {2, 3, 0, 1, BLOCK + 2, BLOCK + 3, BLOCK + 0, BLOCK + 1};

/* A(i, j) of the band, row by row with room for the pivoting's fill-in: j - i in
 * [-KL, KU + KL] */
#define AT(L, i, j) ((L)[(i) * W + (j) - (i) + KL])

typedef struct {
    Py_ssize_t M, nk, nx, nb, R, nu, nl, m;
    const double *c, *ra, *rg, *rb, *E, *e, *lo, *hi, *rq;
    double *rc;  /* the rows' values at the start: the proximal term's centres */
    const long long *rk;
    const unsigned char *fixed;
    const Py_ssize_t *iu, *il;
} Prog;

/* every inequality's right-hand side h[i]: the rows', then x <= hi, then -x <= -lo */
static double h_of(const Prog *p, Py_ssize_t i)
{
    if (i < p->R)
        return p->rb[i];
    if (i < p->R + p->nu)
        return p->hi[p->iu[i - p->R]];
    return -p->lo[p->il[i - p->R - p->nu]];
}

/* every inequality's g . x */
static void G(const Prog *p, const double *x, double *out)
{
    const double xb = x[p->nk];
    for (Py_ssize_t r = 0; r < p->R; r++) {
        const double *a = p->ra + 6 * r;
        const double *xs = x + D * p->rk[r];
        double s = p->rg[r] * xb;
        for (int j = 0; j < 6; j++)
            s += a[j] * xs[ROW_X[j]];
        out[r] = s;
    }
    for (Py_ssize_t i = 0; i < p->nu; i++)
        out[p->R + i] = x[p->iu[i]];
    for (Py_ssize_t i = 0; i < p->nl; i++)
        out[p->R + p->nu + i] = -x[p->il[i]];
}

/* the larger of two, NaN when either is (as Python's max of NumPy's maxima here) */
static double nan_max(double a, double b)
{
    return (isnan(a) || isnan(b)) ? NAN : (a > b ? a : b);
}

/* The residuals at the iterate in one pass over the rows and the bounds: rp = G x + s - h
 * and rd = G^T z plus the proximal term's gradient (the fixed variables' entries zero; c
 * and E^T y are added after); returns
 * the gap s . z and the largest |rp| in *maxrp. In the same pass, the predictor's part of
 * the step's right-hand side: the barrier terms Dz = z / s, the targets cc = s z,
 * t = rp - cc / z into ds, Dz t into dz and G^T dz into rhs (work of no use when the
 * iterate has converged, in one iteration of a solve's). Each sum in the order of G, GT
 * and dot: the same bits as those passes one after another. */
static double residuals(const Prog *p, const double *x, const double *sl, const double *z,
                        double *rp, double *rd, double *maxrp, double *Dz, double *cc,
                        double *ds, double *dz, double *rhs)
{
    const Py_ssize_t R = p->R, nu = p->nu, nl = p->nl, nk = p->nk;
    memset(rd, 0, p->nx * sizeof(double));
    memset(rhs, 0, p->nx * sizeof(double));
    const double xb = x[nk];
    double b = 0.0, bt = 0.0, gap = 0.0, mx = 0.0;
#define PREDICTOR(i, res)                       \
    const double d_ = z[i] / sl[i];             \
    const double c_ = sl[i] * z[i];             \
    const double t_ = (res) - c_ / z[i];        \
    const double e_ = d_ * t_;                  \
    Dz[i] = d_;                                 \
    cc[i] = c_;                                 \
    ds[i] = t_;                                 \
    dz[i] = e_;
    for (Py_ssize_t r = 0; r < R; r++) {
        const double *a = p->ra + 6 * r;
        const Py_ssize_t o = D * p->rk[r];
        const double *xs = x + o;
        double *os = rd + o, *ts = rhs + o;
        double g = p->rg[r] * xb;
        for (int j = 0; j < 6; j++)
            g += a[j] * xs[ROW_X[j]];
        const double zr = p->rq[r] != 0.0 ? z[r] + p->rq[r] * (g - p->rc[r]) : z[r];
        for (int j = 0; j < 6; j++)
            os[ROW_X[j]] += a[j] * zr;
        b += p->rg[r] * zr;
        const double res = g + (sl[r] - p->rb[r]);
        rp[r] = res;
        gap += sl[r] * z[r];
        mx = nan_max(mx, fabs(res));
        PREDICTOR(r, res)
        for (int j = 0; j < 6; j++)
            ts[ROW_X[j]] += a[j] * e_;
        bt += p->rg[r] * e_;
    }
    rd[nk] += b;
    rhs[nk] += bt;
    for (Py_ssize_t k = 0; k < nu; k++) {
        const Py_ssize_t i = R + k, v = p->iu[k];
        rd[v] += z[i];
        const double res = x[v] + (sl[i] - p->hi[v]);
        rp[i] = res;
        gap += sl[i] * z[i];
        mx = nan_max(mx, fabs(res));
        PREDICTOR(i, res)
        rhs[v] += e_;
    }
    for (Py_ssize_t k = 0; k < nl; k++) {
        const Py_ssize_t i = R + nu + k, v = p->il[k];
        rd[v] -= z[i];
        const double res = -x[v] + (sl[i] - -p->lo[v]);
        rp[i] = res;
        gap += sl[i] * z[i];
        mx = nan_max(mx, fabs(res));
        PREDICTOR(i, res)
        rhs[v] -= e_;
    }
#undef PREDICTOR
    for (Py_ssize_t i = 0; i < p->nx; i++)
        if (p->fixed[i]) {
            rd[i] = 0.0;
            rhs[i] = 0.0;
        }
    *maxrp = mx;
    return gap;
}

/* the equalities' residuals E x - e (3 M) */
static void Ex(const Prog *p, const double *x, double *out)
{
    for (Py_ssize_t k = 0; k < p->M; k++)
        for (int q = 0; q < Q; q++) {
            const double *Ek = p->E + (k * Q + q) * 2 * D;
            double s = 0.0;
            for (int j = 0; j < 2 * D; j++)
                s += Ek[j] * x[D * k + j];
            out[k * Q + q] = s - p->e[k * Q + q];
        }
}

/* E^T y added into out (the fixed variables' entries zero) */
static void ETy_add(const Prog *p, const double *y, double *out)
{
    for (Py_ssize_t k = 0; k < p->M; k++)
        for (int q = 0; q < Q; q++) {
            const double *Ek = p->E + (k * Q + q) * 2 * D;
            const double yk = y[k * Q + q];
            for (int j = 0; j < 2 * D; j++)
                out[D * k + j] += Ek[j] * yk;
        }
    for (Py_ssize_t i = 0; i < p->nx; i++)
        if (p->fixed[i])
            out[i] = 0.0;
}

static Py_ssize_t xband(Py_ssize_t v) { return BLOCK * (v / D) + PERM[v % D]; }

/* LU factorisation with partial pivoting within the band (rows j .. j + KL at column j),
 * of the columns j0 .. j1 - 1 (ju_io: the reach of the updates so far), in place: the
 * multipliers below the diagonal, the pivots' rows in piv, the last column of each row of
 * U in ext (as LAPACK's dgbtf2, the updates stop at the last column the pivots so far can
 * have filled: without a row exchange, the band's own KU); along with it, the forward
 * substitution of the right-hand sides b and bb (L^-1 P b, rows up to j1 - 1 + KL made);
 * -1 when a pivot is zero */
static int band_lu(double *L, Py_ssize_t n, Py_ssize_t *piv, Py_ssize_t *ext,
                   Py_ssize_t j0, Py_ssize_t j1, Py_ssize_t *ju_io, double *b, double *bb)
{
    Py_ssize_t ju = *ju_io;
    for (Py_ssize_t j = j0; j < j1; j++) {
        Py_ssize_t last = j + KL < n - 1 ? j + KL : n - 1;
        Py_ssize_t p = j;
        double best = fabs(AT(L, j, j));
        for (Py_ssize_t i = j + 1; i <= last; i++)
            if (fabs(AT(L, i, j)) > best) {
                best = fabs(AT(L, i, j));
                p = i;
            }
        piv[j] = p;
        if (best == 0.0 || !isfinite(best))
            return -1;
        Py_ssize_t reach = p + KU < n - 1 ? p + KU : n - 1;
        if (reach > ju)
            ju = reach;
        ext[j] = ju;
        if (p != j)
            for (Py_ssize_t c = j; c <= ju; c++) {
                double t = AT(L, j, c);
                AT(L, j, c) = AT(L, p, c);
                AT(L, p, c) = t;
            }
        if (p != j) {
            double t = b[j];
            b[j] = b[p];
            b[p] = t;
            t = bb[j];
            bb[j] = bb[p];
            bb[p] = t;
        }
        const double inv = 1.0 / AT(L, j, j), bj = b[j], bbj = bb[j];
        for (Py_ssize_t i = j + 1; i <= last; i++) {
            double l = AT(L, i, j) * inv;
            AT(L, i, j) = l;
            /* the forward substitution of b and bb, in band_solve2's operations and order */
            b[i] -= l * bj;
            bb[i] -= l * bbj;
            if (l != 0.0)
                for (Py_ssize_t c = j + 1; c <= ju; c++)
                    AT(L, i, c) -= l * AT(L, j, c);
        }
    }
    *ju_io = ju;
    return 0;
}

/* b := A^-1 b from band_lu's factors */
static void band_solve(const double *L, Py_ssize_t n, const Py_ssize_t *piv,
                       const Py_ssize_t *ext, double *b)
{
    for (Py_ssize_t j = 0; j < n; j++) {
        Py_ssize_t p = piv[j];
        if (p != j) {
            double t = b[j];
            b[j] = b[p];
            b[p] = t;
        }
        const double bj = b[j];
        Py_ssize_t last = j + KL < n - 1 ? j + KL : n - 1;
        if (bj != 0.0)
            for (Py_ssize_t i = j + 1; i <= last; i++)
                b[i] -= AT(L, i, j) * bj;
    }
    for (Py_ssize_t j = n - 1; j >= 0; j--) {
        /* four partial sums: the row's products are not a chain of dependent additions */
        double s0 = b[j], s1 = 0.0, s2 = 0.0, s3 = 0.0;
        const double *row = L + j * W - j + KL;  /* row[c] = A(j, c) */
        Py_ssize_t c = j + 1, e = ext[j];
        for (; c + 3 <= e; c += 4) {
            s0 -= row[c] * b[c];
            s1 -= row[c + 1] * b[c + 1];
            s2 -= row[c + 2] * b[c + 2];
            s3 -= row[c + 3] * b[c + 3];
        }
        for (; c <= e; c++)
            s0 -= row[c] * b[c];
        b[j] = ((s0 + s1) + (s2 + s3)) / row[j];
    }
}

/* b := U^-1 b and c := U^-1 c in one sweep over the factors (the back substitution of
 * band_solve, twice: band_lu made the forward one) */
static void band_back2(const double *L, Py_ssize_t n, const Py_ssize_t *ext, double *b,
                       double *c)
{
    for (Py_ssize_t j = n - 1; j >= 0; j--) {
        double s0 = b[j], s1 = 0.0, t0 = c[j], t1 = 0.0;
        const double *row = L + j * W - j + KL;
        Py_ssize_t k = j + 1, e = ext[j];
        for (; k + 1 <= e; k += 2) {
            s0 -= row[k] * b[k];
            s1 -= row[k + 1] * b[k + 1];
            t0 -= row[k] * c[k];
            t1 -= row[k + 1] * c[k + 1];
        }
        for (; k <= e; k++) {
            s0 -= row[k] * b[k];
            t0 -= row[k] * c[k];
        }
        b[j] = (s0 + s1) / row[j];
        c[j] = (t0 + t1) / row[j];
    }
}

static double max_abs(const double *v, Py_ssize_t n)
{
    double m = 0.0;
    for (Py_ssize_t i = 0; i < n; i++)
        m = nan_max(m, fabs(v[i]));
    return m;
}

static double dot(const double *a, const double *b, Py_ssize_t n)
{
    double s = 0.0;
    for (Py_ssize_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* One iteration's factorised Newton system and what a step needs. */
typedef struct {
    double *L, *U, *BU, *full, *rhs, *dx, *dy;
    Py_ssize_t *piv, *ext;
    double corner, schur;
} Newton;

/* The corrector's part of the step's right-hand side from the rows and the bounds, in one
 * pass: for every inequality i its target cc[i] = s z + ds dz - target (from the
 * predictor's ds and dz), t = rp - cc / z into ds, Dz t into dz, and rhs = G^T dz (the
 * fixed variables' entries zero); each sum in the order of GT, the same bits as the loops
 * over the inequalities one after another, without their traffic over the arrays. */
static void targets(const Prog *p, const double *Dz, const double *rp, const double *sl,
                    const double *z, double target, double *cc, double *dz, double *ds,
                    double *rhs)
{
    const Py_ssize_t R = p->R, nu = p->nu, nl = p->nl, nk = p->nk;
    memset(rhs, 0, p->nx * sizeof(double));
    double b = 0.0;
#define TARGET(i)                                                                 \
    const double c_ = sl[i] * z[i] + ds[i] * dz[i] - target;                     \
    const double t_ = rp[i] - c_ / z[i], d_ = Dz[i] * t_;                        \
    cc[i] = c_;                                                                   \
    ds[i] = t_;                                                                   \
    dz[i] = d_;
    for (Py_ssize_t r = 0; r < R; r++) {
        TARGET(r)
        const double *a = p->ra + 6 * r;
        double *o = rhs + D * p->rk[r];
        for (int j = 0; j < 6; j++)
            o[ROW_X[j]] += a[j] * d_;
        b += p->rg[r] * d_;
    }
    rhs[nk] += b;
    for (Py_ssize_t k = 0; k < nu; k++) {
        const Py_ssize_t i = R + k;
        TARGET(i)
        rhs[p->iu[k]] += d_;
    }
    for (Py_ssize_t k = 0; k < nl; k++) {
        const Py_ssize_t i = R + nu + k;
        TARGET(i)
        rhs[p->il[k]] -= d_;
    }
#undef TARGET
    for (Py_ssize_t i = 0; i < p->nx; i++)
        if (p->fixed[i])
            rhs[i] = 0.0;
}

/* The step (dx, dy, dz, ds) for the complementarity targets s z + ds z + s dz = -cc of
 * every inequality (banded._Newton.step), in two halves around the band's solve:
 * step_rhs makes its right-hand side in nw->full from the G^T dz in nw->rhs (residuals'
 * for the predictor, targets' for the corrector; ds holds t = rp - cc / z on the way),
 * step_end takes the band's solution there to the step and gives the largest steps to the
 * bounds of s and of z (s + a ds >= 0, z + a dz >= 0; inf when none), in the same pass. */
static void step_rhs(const Prog *p, Newton *nw, const double *rd, const double *re)
{
    const Py_ssize_t nk = p->nk;
    for (Py_ssize_t v = 0; v < p->nx; v++)
        nw->rhs[v] = -rd[v] - nw->rhs[v];
    for (Py_ssize_t v = 0; v < nk; v++)
        nw->full[xband(v)] = nw->rhs[v];
    for (Py_ssize_t k = 0; k < p->M; k++)
        for (int q = 0; q < Q; q++)
            nw->full[BLOCK * k + D + q] = -re[k * Q + q];
}

static void step_end(const Prog *p, Newton *nw, const double *Dz, const double *z,
                     const double *s, const double *cc, double *dz, double *ds,
                     double *to_s, double *to_z)
{
    const Py_ssize_t nk = p->nk, nb = p->nb, R = p->R, nu = p->nu, nl = p->nl;
    double r = nw->rhs[nk] - dot(nw->U, nw->full, nb);
    double dp = r / nw->schur;
    for (Py_ssize_t i = 0; i < nb; i++)
        nw->full[i] -= nw->BU[i] * dp;
    const double *dx = nw->dx;
    for (Py_ssize_t v = 0; v < nk; v++)
        nw->dx[v] = p->fixed[v] ? 0.0 : nw->full[xband(v)];
    nw->dx[nk] = p->fixed[nk] ? 0.0 : dp;
    for (Py_ssize_t k = 0; k < p->M; k++)
        for (int q = 0; q < Q; q++)
            nw->dy[k * Q + q] = nw->full[BLOCK * k + D + q];
    /* G dx inequality by inequality (G's sums), then dz, ds and the bounds' ratios */
    double as = INFINITY, az = INFINITY;
#define STEP_END(i, g)                                      \
    {                                                       \
        const double d_ = Dz[i] * ((g) + ds[i]);            \
        const double e_ = -(s[i] * d_ + cc[i]) / z[i];      \
        dz[i] = d_;                                         \
        ds[i] = e_;                                         \
        if (e_ < 0) {                                       \
            const double t_ = -s[i] / e_;                   \
            if (t_ < as)                                    \
                as = t_;                                    \
        }                                                   \
        if (d_ < 0) {                                       \
            const double t_ = -z[i] / d_;                   \
            if (t_ < az)                                    \
                az = t_;                                    \
        }                                                   \
    }
    const double xb = dx[nk];
    for (Py_ssize_t i = 0; i < R; i++) {
        const double *a = p->ra + 6 * i;
        const double *xs = dx + D * p->rk[i];
        double g = p->rg[i] * xb;
        for (int j = 0; j < 6; j++)
            g += a[j] * xs[ROW_X[j]];
        STEP_END(i, g)
    }
    for (Py_ssize_t k = 0; k < nu; k++)
        STEP_END(R + k, dx[p->iu[k]])
    for (Py_ssize_t k = 0; k < nl; k++)
        STEP_END(R + nu + k, -dx[p->il[k]])
#undef STEP_END
    *to_s = as;
    *to_z = az;
}

/* Assemble and factorise the Newton matrix at the barrier terms Dz (the border's column in
 * U, its corner in corner); -1 when singular. */
static int newton_matrix(const Prog *p, Newton *nw, const double *Dz, double *diag)
{
    const Py_ssize_t nb = p->nb, nk = p->nk, R = p->R;
    double *L = nw->L, *U = nw->U;
    for (Py_ssize_t v = 0; v < p->nx; v++)
        diag[v] = REG;
    for (Py_ssize_t i = 0; i < p->nu; i++)
        diag[p->iu[i]] += Dz[R + i];
    for (Py_ssize_t i = 0; i < p->nl; i++)
        diag[p->il[i]] += Dz[R + p->nu + i];
    for (Py_ssize_t v = 0; v < p->nx; v++)
        if (p->fixed[v])
            diag[v] = 1.0;
    /* block by block (knot k's states and interval k's equalities: band rows 7k ..), each
     * block's rows made whole while they are in cache (no pass over the band per kind of
     * term): the sums of d a a^T of the rows of intervals k - 1 and k (the rows sorted by
     * interval, see solve), the equalities of both intervals, the diagonal, the fixed
     * variables' rows */
    double corner = 0.0;
    Py_ssize_t done = 0, ju = 0;  /* the band's columns factorised, band_lu's reach */
    double Hp[6][6] = {{0.0}}, up[6] = {0.0};  /* interval k - 1's sums */
    Py_ssize_t r = 0;
    for (Py_ssize_t k = 0; k <= p->M; k++) {
        double Hc[6][6] = {{0.0}}, uc[6] = {0.0};
        for (; r < R && p->rk[r] == k; r++) {
            const double *a = p->ra + 6 * r;
            const double d = Dz[r] + p->rq[r];
            for (int i = 0; i < 6; i++) {
                if (a[i] == 0.0)
                    continue;
                const double da = d * a[i];
                for (int j = i; j < 6; j++)  /* (the upper triangle: H is symmetric) */
                    Hc[i][j] += da * a[j];
                uc[i] += da * p->rg[r];
            }
            corner += d * p->rg[r] * p->rg[r];
        }
        const Py_ssize_t b0 = BLOCK * k, bp = b0 - BLOCK;
        const Py_ssize_t here = k < p->M ? BLOCK : D;
        memset(L + b0 * W, 0, (size_t)here * W * sizeof(double));
        memset(U + b0, 0, (size_t)here * sizeof(double));
        for (int i = 0; i < 6; i++) {  /* interval k's rows on knot k's states */
            if (ROW_POS[i] >= BLOCK)
                continue;
            const Py_ssize_t pi = b0 + ROW_POS[i];
            for (int j = 0; j < 6; j++)
                AT(L, pi, b0 + ROW_POS[j]) += j >= i ? Hc[i][j] : Hc[j][i];
            U[pi] += uc[i];
        }
        if (k > 0)
            for (int i = 0; i < 6; i++) {  /* interval k - 1's rows on knot k's states */
                if (ROW_POS[i] < BLOCK)
                    continue;
                const Py_ssize_t pi = bp + ROW_POS[i];
                for (int j = 0; j < 6; j++)
                    AT(L, pi, bp + ROW_POS[j]) += j >= i ? Hp[i][j] : Hp[j][i];
                U[pi] += up[i];
            }
        if (k < p->M)  /* interval k's equalities, and their columns on knot k's states */
            for (int q = 0; q < Q; q++) {
                const Py_ssize_t i = b0 + D + q;
                const double *Ek = p->E + (k * Q + q) * 2 * D;
                for (int a = 0; a < 2 * D; a++) {
                    if (p->fixed[D * k + a])
                        continue;
                    const Py_ssize_t j = b0 + EQ_POS[a];
                    AT(L, i, j) += Ek[a];
                    if (EQ_POS[a] < BLOCK)
                        AT(L, j, i) += Ek[a];
                }
                AT(L, i, i) -= REG;
            }
        if (k > 0)  /* interval k - 1's equalities' columns on knot k's states */
            for (int q = 0; q < Q; q++) {
                const Py_ssize_t i = bp + D + q;
                const double *Ek = p->E + ((k - 1) * Q + q) * 2 * D;
                for (int a = D; a < 2 * D; a++) {
                    if (p->fixed[D * (k - 1) + a])
                        continue;
                    AT(L, bp + EQ_POS[a], i) += Ek[a];
                }
            }
        for (int st = 0; st < D; st++) {  /* knot k's states: the diagonal, fixed rows */
            const Py_ssize_t v = D * k + st, pos = b0 + PERM[st];
            if (p->fixed[v]) {  /* the fixed variable's row: the identity's */
                Py_ssize_t c0 = pos - KL > 0 ? pos - KL : 0;
                Py_ssize_t c1 = pos + KU < nb - 1 ? pos + KU : nb - 1;
                for (Py_ssize_t c = c0; c <= c1; c++)
                    AT(L, pos, c) = 0.0;
                U[pos] = 0.0;
            }
            AT(L, pos, pos) += diag[v];
        }
        memcpy(Hp, Hc, sizeof Hp);
        memcpy(up, uc, sizeof up);
        /* the columns whose rows (to KL below the diagonal) are all made: factorised now,
         * while the block is in cache (no second pass over the band), with the forward
         * substitution of the border's column (BU, a copy of U) and of the predictor's
         * right-hand side (full) */
        memcpy(nw->BU + b0, U + b0, (size_t)here * sizeof(double));
        const Py_ssize_t ready = b0 + here - KL;
        if (ready > done) {
            if (band_lu(L, nb, nw->piv, nw->ext, done, ready, &ju, nw->BU, nw->full) < 0)
                return -1;
            done = ready;
        }
    }
    nw->corner = corner + diag[nk];
    return band_lu(L, nb, nw->piv, nw->ext, done, nb, &ju, nw->BU, nw->full);
}

/* The solve (see the file's doc); -1 (a Python error set) when interrupted or out of
 * memory. */
static int ipm(Prog *p, const double *x0, double *x, double tol, double dual_tol,
               double gap_tol, long maxiter, long *nit)
{
    const Py_ssize_t nx = p->nx, m = p->m, nb = p->nb, nE = Q * p->M, R = p->R;
    int status = 1;
    long it = 0;
    /* m-sized: sl, z, Dz, rp, cc, dz, ds; nx-sized: rd, diag, best, rhs, dx; nE: y, re, dy;
     * nb: U, BU, full; the band; R: the rows at the start (the proximal term's centres) */
    double *work = big_alloc(((size_t)7 * m + 5 * nx + 3 * nE + 3 * nb + (size_t)nb * W
                              + (size_t)R) * sizeof(double));
    Py_ssize_t *piv = malloc((size_t)2 * nb * sizeof(Py_ssize_t));
    if (work == NULL || piv == NULL) {
        free(work);
        free(piv);
        PyErr_NoMemory();
        return -1;
    }
    double *sl = work, *z = sl + m, *Dz = z + m, *rp = Dz + m, *cc = rp + m, *dz = cc + m,
           *ds = dz + m;
    double *rd = ds + m, *diag = rd + nx, *best = diag + nx;
    double *y = best + nx, *re = y + nE;
    Newton nw;
    nw.rhs = re + nE;
    nw.dx = nw.rhs + nx;
    nw.dy = nw.dx + nx;
    nw.U = nw.dy + nE;
    nw.BU = nw.U + nb;
    nw.full = nw.BU + nb;
    nw.L = nw.full + nb;
    p->rc = nw.L + (size_t)nb * W;
    nw.piv = piv;
    nw.ext = piv + nb;

    /* the start: x0 (fixed variables at their values), the slacks at least a small margin,
     * the multipliers on the central path of MU0 */
    for (Py_ssize_t v = 0; v < nx; v++)
        x[v] = p->fixed[v] ? p->lo[v] : x0[v];
    G(p, x, sl);
    memcpy(p->rc, sl, (size_t)R * sizeof(double));
    for (Py_ssize_t i = 0; i < m; i++) {
        double floor;
        if (i < R)
            floor = SLACK_FLOOR * (1.0 + fabs(p->rb[i]));
        else {
            Py_ssize_t v = i < R + p->nu ? p->iu[i - R] : p->il[i - R - p->nu];
            double width = (isfinite(p->hi[v]) && isfinite(p->lo[v])) ? p->hi[v] - p->lo[v]
                                                                      : fabs(x[v]) + 1.0;
            floor = BOUND_FLOOR * width;
        }
        double s = h_of(p, i) - sl[i];
        sl[i] = s > floor ? s : floor;
        z[i] = MU0 / sl[i];
    }
    memset(y, 0, (size_t)nE * sizeof(double));
    double scale_p = 1.0 + max_abs(p->rb, R), scale_d = 1.0 + max_abs(p->c, nx);
    double best_miss = INFINITY;
    memcpy(best, x, (size_t)nx * sizeof(double));
    for (it = 0; it <= maxiter; it++) {
        if (PyErr_CheckSignals() < 0) {
            free(work);
            free(piv);
            return -1;
        }
        int singular = 0, done = 0;
        Py_BEGIN_ALLOW_THREADS
        double maxrp;
        double gap = residuals(p, x, sl, z, rp, rd, &maxrp, Dz, cc, ds, dz, nw.rhs);
        for (Py_ssize_t v = 0; v < nx; v++)
            rd[v] += p->c[v];
        ETy_add(p, y, rd);
        Ex(p, x, re);
        double cx = fabs(dot(p->c, x, nx));
        double prim = nan_max(maxrp, max_abs(re, nE)) / (tol * scale_p);
        double miss = nan_max(nan_max(prim, max_abs(rd, nx) / (dual_tol * scale_d)),
                              gap / (gap_tol * (1.0 + cx)));
        if (miss < best_miss) {
            best_miss = miss;
            memcpy(best, x, (size_t)nx * sizeof(double));
        }
        if (miss <= 1.0) {
            status = 0;
            done = 1;
        } else if (it == maxiter || gap <= 1e-6 * gap_tol * (1.0 + cx)) {
            done = 1;
        } else {
            double mu = gap / (double)m, to_s, to_z;
            /* the predictor's (affine) right-hand side first (residuals made its rows'
             * part, targets s z): the factorisation substitutes it and the border's column
             * forward as it goes */
            step_rhs(p, &nw, rd, re);
            if (newton_matrix(p, &nw, Dz, diag) < 0) {
                status = 2;
                singular = 1;
            } else {
                /* the border's solve and the predictor's in one sweep back, then the Schur
                 * complement of the border, then the corrector's targets */
                band_back2(nw.L, nb, nw.ext, nw.BU, nw.full);
                nw.schur = nw.corner - dot(nw.U, nw.BU, nb);
                step_end(p, &nw, Dz, z, sl, cc, dz, ds, &to_s, &to_z);
                double ap = fmin(1.0, to_s);
                double ad = fmin(1.0, to_z);
                double mu_aff = 0.0;
                for (Py_ssize_t i = 0; i < m; i++)
                    mu_aff += (sl[i] + ap * ds[i]) * (z[i] + ad * dz[i]);
                mu_aff /= (double)m;
                double sigma = mu_aff / mu;
                double target = fmax(sigma * sigma * sigma * mu,
                                     fmin(mu, TARGET_FLOOR * gap_tol * (1.0 + cx) / (double)m));
                targets(p, Dz, rp, sl, z, target, cc, dz, ds, nw.rhs);
                step_rhs(p, &nw, rd, re);
                band_solve(nw.L, nb, nw.piv, nw.ext, nw.full);
                step_end(p, &nw, Dz, z, sl, cc, dz, ds, &to_s, &to_z);
                ap = fmin(1.0, ETA * to_s);
                ad = fmin(1.0, ETA * to_z);
                for (Py_ssize_t v = 0; v < nx; v++)
                    x[v] += ap * nw.dx[v];
                for (Py_ssize_t i = 0; i < m; i++) {
                    sl[i] += ap * ds[i];
                    z[i] += ad * dz[i];
                }
                for (Py_ssize_t i = 0; i < nE; i++)
                    y[i] += ad * nw.dy[i];
            }
        }
        Py_END_ALLOW_THREADS
        if (done || singular)
            break;
    }
    if (it > maxiter)
        it = maxiter;
    if (status != 0 && best_miss <= 100.0) {
        status = 0;
        memcpy(x, best, (size_t)nx * sizeof(double));
    }
    free(work);
    free(piv);
    *nit = it;
    return status;
}

static int get_int64(PyObject *obj, Py_buffer *view, const char *name)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        return -1;
    if (view->itemsize != 8 || view->format == NULL
            || (strcmp(view->format, "q") != 0 && strcmp(view->format, "l") != 0)) {
        PyErr_Format(PyExc_TypeError, "%s must hold int64 values", name);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

static PyObject *solve(PyObject *self, PyObject *args)
{
    /* float64 buffers: c, ra, rg, rb, E, e, lo, hi, rq, x0, then x (writable) */
    PyObject *objs[11], *rk_obj;
    static const char *names[11] = {"c", "ra", "rg", "rb", "E", "e", "lo", "hi", "rq", "x0",
                                    "x"};
    Py_buffer views[11], rk_view;
    double tol, dual_tol, gap_tol;
    long maxiter;
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOdddl", &objs[0], &rk_obj, &objs[1], &objs[2],
                          &objs[3], &objs[4], &objs[5], &objs[6], &objs[7], &objs[8],
                          &objs[9], &objs[10], &tol, &dual_tol, &gap_tol, &maxiter))
        return NULL;
    if (get_int64(rk_obj, &rk_view, "rk") < 0)
        return NULL;
    if (get_buffers(objs, views, 11, 10, names) < 0) {
        PyBuffer_Release(&rk_view);
        return NULL;
    }
    unsigned char *fixed = NULL;
    Py_ssize_t *bnd = NULL;
    double *sorted_rows = NULL;
    {
        Py_ssize_t nx = views[0].len / 8, R = rk_view.len / 8;
        Py_ssize_t K = (nx - 1) / D, M = K - 1;
        if (nx < 1 + 2 * D || (nx - 1) % D != 0 || views[1].len != 6 * R * 8
                || views[2].len != R * 8 || views[3].len != R * 8
                || views[4].len != M * Q * 2 * D * 8 || views[5].len != M * Q * 8
                || views[6].len != nx * 8 || views[7].len != nx * 8
                || views[8].len != R * 8 || views[9].len != nx * 8
                || views[10].len != nx * 8 || maxiter < 0) {
            PyErr_SetString(PyExc_ValueError,
                            "c, lo, hi, x0, x must hold 4 (M + 1) + 1 values, ra 6 R, rg, "
                            "rb and rq R (rk's length), E 24 M and e 3 M");
            goto done;
        }
        const long long *rk = rk_view.buf;
        for (Py_ssize_t r = 0; r < R; r++)
            if (rk[r] < 0 || rk[r] >= M) {
                PyErr_SetString(PyExc_ValueError, "rk must hold intervals in [0, M)");
                goto done;
            }
        const double *lo = views[6].buf, *hi = views[7].buf;
        fixed = malloc((size_t)nx);
        bnd = malloc((size_t)2 * nx * sizeof(Py_ssize_t));
        if (fixed == NULL || bnd == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        Py_ssize_t nu = 0, nl = 0;
        for (Py_ssize_t v = 0; v < nx; v++) {
            fixed[v] = lo[v] == hi[v];
            if (!fixed[v] && isfinite(hi[v]))
                bnd[nu++] = v;
        }
        for (Py_ssize_t v = 0; v < nx; v++)
            if (!fixed[v] && isfinite(lo[v]))
                bnd[nu + nl++] = v;
        /* the rows sorted by interval (a counting sort, stable): the solve's passes over
         * them then read the knots' states and write the band in order (on a long path,
         * rows in the order of their kinds swept the band once per kind, out of cache) */
        sorted_rows = big_alloc((size_t)R * 10 * sizeof(double)
                                + (size_t)R * sizeof(long long)
                                + (size_t)(M + 1) * sizeof(Py_ssize_t));
        if (sorted_rows == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        double *ra_s = sorted_rows, *rg_s = ra_s + 6 * R, *rb_s = rg_s + R, *rq_s = rb_s + R;
        long long *rk_s = (long long *)(rq_s + R);
        Py_ssize_t *start = (Py_ssize_t *)(rk_s + R);
        const double *ra = views[1].buf, *rg = views[2].buf, *rb = views[3].buf,
                     *rq = views[8].buf;
        memset(start, 0, (size_t)(M + 1) * sizeof(Py_ssize_t));
        for (Py_ssize_t r = 0; r < R; r++)
            start[rk[r] + 1]++;
        for (Py_ssize_t k = 0; k < M; k++)
            start[k + 1] += start[k];
        for (Py_ssize_t r = 0; r < R; r++) {
            Py_ssize_t i = start[rk[r]]++;
            memcpy(ra_s + 6 * i, ra + 6 * r, 6 * sizeof(double));
            rg_s[i] = rg[r];
            rb_s[i] = rb[r];
            rq_s[i] = rq[r];
            rk_s[i] = rk[r];
        }
        Prog p = {M, D * K, nx, BLOCK * M + D, R, nu, nl, R + nu + nl,
                  views[0].buf, ra_s, rg_s, rb_s, views[4].buf,
                  views[5].buf, lo, hi, rq_s, NULL, rk_s, fixed, bnd, bnd + nu};
        long nit = 0;
        int status = ipm(&p, views[9].buf, views[10].buf, tol, dual_tol, gap_tol, maxiter,
                         &nit);
        if (status >= 0)
            result = Py_BuildValue("il", status, nit);
    }
done:
    free(fixed);
    free(bnd);
    free(sorted_rows);
    PyBuffer_Release(&rk_view);
    release_buffers(views, 11);
    return result;
}

static PyMethodDef methods[] = {
    {"solve", solve, METH_VARARGS,
     "solve(c, rk, ra, rg, rb, E, e, lo, hi, rq, x0, x, tol, dual_tol, gap_tol, maxiter) -> "
     "(status, iterations): the programme's solution into x."},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_ipm",
    "The jerk-limited law's banded interior point, compiled.", -1, methods,
    NULL, NULL, NULL, NULL
};

PyMODINIT_FUNC PyInit__ipm(void)
{
    PyObject *mod = PyModule_Create(&module);
    if (mod == NULL)
        return NULL;
    if (PyModule_AddIntConstant(mod, "VERSION", IPM_VERSION) < 0) {
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
