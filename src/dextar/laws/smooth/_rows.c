/* The jerk-limited law's rows compiled: RowModel._block of dextar.laws.smooth.rows (the
 * second-order rows interpolated between the table's points at the knots and the
 * intervals' middles and quarters, the speed cap, w >= 0, and the joint jerk and
 * torque-rate rows at every interval's start, middle and end, with their gradients in the
 * programme's variables) and the second-order rows' columns at the table's points (the
 * built-in constraints' point_rows), each in one call, each value by the same operations
 * in the same order as the numpy code (the same bits where the C library's pow and cosh
 * are numpy's), without its few hundred array operations per call: on a short move those
 * cost more than the arithmetic.
 *
 * Built by `pip install` when a C compiler is there (an optional extension: without one,
 * dextar builds the rows with numpy).
 *
 * block(grid, pcols, tlo, thi, h, J, Tk, sigma, w, alpha, kinds, lims, fric,
 *       F, norm, C, k, sizes, m, has_cap, k0, k1, cfloor, S, neg_inv_S, near, bulge,
 *       grad)
 *     -> (second, cap, w, third)
 *   grid (N + 1) the table's arc lengths; pcols (N + 1) x P the second-order rows'
 *   coefficients pu | px | ph | finite (m columns each) and, with has_cap, the speed cap's
 *   root; tlo, thi (N x 18) the table's columns at its segments' ends; h, J, Tk (M) and
 *   sigma, w, alpha (M + 1) the mesh and the motion; kinds (nc: 0 a jerk limit, 1 a torque
 *   rate limit), lims (2 nc) and fric (viscous 2, Coulomb 2, Coulomb speed) the third-order
 *   limits. The rows of the intervals k0 to k1 (excluded) are written into F, norm, C
 *   (5 per row, with grad), k (int32) and sizes (float32, 5 per row, with grad); the counts
 *   of each kind are returned.
 *
 * columns(pts, x0, kinds, pars, root, cols, m, has_cap) -> phmax
 *   RowModel._columns: pts (n x PTS) the table's a, b, g, q', q'', the friction's sides up
 *   and down, the viscous slope and the Coulomb torque (2 each); x0 (n) the tangent points;
 *   kinds (nc: 0 a torque limit, 1 the torque-speed envelope, 2 an acceleration limit) and
 *   pars (6 per constraint: its limits, 2 each); root (n, with has_cap) the speed cap's root.
 *   Written into cols (n x (4 m + has_cap), m = 4 nc): pu | px | ph (0 where not finite) |
 *   finite | root; the largest finite |ph| returned.
 *
 * monitor(grid, lo, hi, s, v, a, kinds, lims, dt, c2)
 *   start.fractions' monitor: the parts (kinds: 0 a joint acceleration, 1 a torque without
 *   friction, 2 a joint jerk from the path's curvature, 3 a speed over its span; lims 2 per
 *   part) of the start motion's samples s, v, a (n) from the table's first 10 columns (lo,
 *   hi: N x ncols), their second differences in time (step dt, as numpy.gradient twice)
 *   and the largest of their magnitudes at each sample written into c2 (n).
 *
 * Compiled without contraction into fused multiply-adds (-ffp-contract=off).
 */

#include "../../_buffers.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>

#if (defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0) || defined(__FAST_MATH__)
#error "dextar's compiled rows need double evaluation without -ffast-math"
#endif

/* The interface version: rows.py uses a build of this version only. */
#define ROWS_VERSION 5
/* The second-order rows' points: the inner knots, and in every interval its middle, then
 * its first and third quarters (rows.py's RowModel: the same offsets by the same
 * operations; a row at a quarter only where it is near its limit, above -near, and above
 * the chord of its interval's rows on either side of it by more than bulge; at a middle
 * only above the chord of the interval's start and end by more than mid_bulge, but in the
 * first and last intervals always). The speed cap's and w >= 0's rows: at the knots and
 * the middles (the first two passes). */
#define POINTS 4
/* The table's per-point columns columns() takes (2 each): a, b, g, q', q'', the friction's
 * sides up and down, the viscous slope |q'| f_v, the Coulomb torque. */
#define PTS 18
/* The table's columns (2 each): q', q'', q''', a, b, g, a', b', g' (table.py). */
#define NCOL 18
#define Q1 0
#define Q2 2
#define Q3 4
#define CA 6
#define CB 8
#define CDA 12
#define CDB 14
#define CDG 16

/* The offset into an interval of length h of a second-order point's pass (see POINTS). */
static double offset(int pass, double h)
{
    return pass == 0 ? 0.0 : (pass == 1 ? h / 2 : (pass == 2 ? h / 4 : 3 * h / 4));
}

/* numpy's maximum, minimum and clip where a NaN propagates (a tie of signed zeros, which
 * numpy gives as +0, is not met by the callers: a floor above zero, a magnitude against a
 * maximum) */
static double np_max(double a, double b)
{
    return (a >= b || isnan(a)) ? a : b;
}

static double np_min(double a, double b)
{
    return (a <= b || isnan(a)) ? a : b;
}

static double np_clip(double x, double lo, double hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

/* numpy.searchsorted(grid, s, side) - 1 clipped to a segment (side "left" with before) */
static Py_ssize_t segment(const double *g, Py_ssize_t n, double s, int before)
{
    if (isnan(s))
        return n - 2;
    Py_ssize_t lo = 0, hi = n;
    while (lo < hi) {
        Py_ssize_t mid = lo + (hi - lo) / 2;
        if (before ? g[mid] < s : g[mid] <= s)
            lo = mid + 1;
        else
            hi = mid;
    }
    Py_ssize_t k = lo - 1;
    return k < 0 ? 0 : (k > n - 2 ? n - 2 : k);
}

typedef struct {
    const double *h, *J, *Tk, *sigma, *w, *alpha;
} Motion;

/* Motion.at: sigma, w, alpha at the offset th into interval k */
static void state_at(const Motion *mo, Py_ssize_t k, double th, double *sig, double *w,
                     double *al)
{
    double J = mo->J[k], a = mo->alpha[k], ww = mo->w[k], s = mo->sigma[k];
    double sg = s + th * (ww + th * (a / 2 + th * J / 6));
    if (th >= mo->h[k])
        sg = mo->sigma[k + 1];
    *sig = sg;
    *w = ww + th * (a + th * J / 2);
    *al = a + th * J;
}

/* A second-order point: its state, table segment (s, ds, u, the columns a and b at its
 * ends) and its interval's duration */
typedef struct {
    double w, al, ds, u, T;
    const double *a, *b;
} Point;

static Point point_at(const Motion *mo, const double *grid, Py_ssize_t n1, const double *pc,
                      Py_ssize_t P, Py_ssize_t k, double th)
{
    Point pt;
    double sig;
    state_at(mo, k, th, &sig, &pt.w, &pt.al);
    Py_ssize_t s = segment(grid, n1, sig, 0);
    pt.ds = grid[s + 1] - grid[s];
    pt.u = (np_clip(sig, grid[0], grid[n1 - 1]) - grid[s]) / pt.ds;
    pt.a = pc + s * P;
    pt.b = pc + (s + 1) * P;
    pt.T = mo->Tk[k];
    return pt;
}

/* Row j's value at the point (of the m; the columns pu | px | ph), and its pu, px, ph and
 * normalisation c */
static double second_row(const Point *pt, Py_ssize_t m, Py_ssize_t j, double cfloor,
                         double *pu, double *px, double *ph, double *c)
{
    const double *a = pt->a, *b = pt->b;
    double u = pt->u, T = pt->T;
    *pu = a[j] + (b[j] - a[j]) * u;
    *px = a[m + j] + (b[m + j] - a[m + j]) * u;
    *ph = a[2 * m + j] + (b[2 * m + j] - a[2 * m + j]) * u;
    *c = np_max(fabs(*ph), cfloor) * T * T;
    return (*pu * pt->al + *px * pt->w * pt->w - *ph * T * T) / *c;
}

/* Row j's value at the offset th into interval k */
static double row_at(const Motion *mo, const double *grid, Py_ssize_t n1, const double *pc,
                     Py_ssize_t P, Py_ssize_t m, Py_ssize_t k, double th, Py_ssize_t j,
                     double cfloor)
{
    Point pt = point_at(mo, grid, n1, pc, P, k, th);
    double pu, px, ph, c;
    return second_row(&pt, m, j, cfloor, &pu, &px, &ph, &c);
}

/* The middle of the chord a quarter's row is measured against: the row at the interval's
 * start and middle (first quarter, pass 2) or middle and end (third quarter) */
static double chord(const Motion *mo, const double *grid, Py_ssize_t n1, const double *pc,
                    Py_ssize_t P, Py_ssize_t m, Py_ssize_t k, int pass, Py_ssize_t j,
                    double cfloor)
{
    double h = mo->h[k];
    double fa = row_at(mo, grid, n1, pc, P, m, k, pass == 2 ? 0.0 : h / 2, j, cfloor);
    double fb = row_at(mo, grid, n1, pc, P, m, k, pass == 2 ? h / 2 : h, j, cfloor);
    return (fa + fb) / 2;
}

typedef struct {
    double *F, *norm, *C;
    int *k;
    float *sizes;
    Py_ssize_t n;
    int grad;
} Out;

/* one row: its value, normalisation and (rows.local) gradient in its interval's variables */
static void put(Out *o, Py_ssize_t k, double F, double norm, double th, double hk,
                double gs, double gw, double ga, double gj, double gT)
{
    Py_ssize_t i = o->n++;
    o->F[i] = F;
    o->norm[i] = norm;
    o->k[i] = (int)k;
    if (!o->grad)
        return;
    double cJ = gs * pow(th, 3) / 6 + gw * (th * th) / 2 + ga * th + gj;
    double ca = gs * (th * th) / 2 + gw * th + ga;
    double *C = o->C + 5 * i;
    float *z = o->sizes + 5 * i;
    C[0] = gs;
    C[1] = gs * th + gw;
    C[3] = cJ / hk;
    C[2] = ca - C[3];
    C[4] = gT;
    z[0] = (float)fabs(gs);
    z[1] = (float)fabs(gw);
    z[2] = (float)fabs(ga);
    z[3] = (float)fabs(gj);
    z[4] = (float)fabs(gT);
}

/* The third-order rows of one limit, written from row base (both signs, each the intervals'
 * starts, middles, then ends, two joints a point: 4 n3 rows, n3 = 3 nint) with the middles
 * within mid_bulge of their chord left out (the first and last intervals' kept: M the
 * mesh's intervals, k0 the first's), the rows after them moved up in place (rows.py's
 * _third_middles; keep holds 4 n3 flags): the rows kept. */
static Py_ssize_t drop_middles(Out *o, Py_ssize_t base, Py_ssize_t nint, Py_ssize_t k0,
                               Py_ssize_t M, double mid_bulge, unsigned char *keep)
{
    const Py_ssize_t n3 = 3 * nint;
    for (Py_ssize_t i = 0; i < 4 * n3; i++)
        keep[i] = 1;
    for (int sg = 0; sg < 2; sg++)
        for (Py_ssize_t q = 0; q < nint; q++) {
            Py_ssize_t k = k0 + q;
            if (k == 0 || k == M - 1)
                continue;
            for (int j = 0; j < 2; j++) {
                Py_ssize_t at = sg * 2 * n3 + j;
                double fs = o->F[base + at + 2 * q], fm = o->F[base + at + 2 * (nint + q)];
                double fe = o->F[base + at + 2 * (2 * nint + q)];
                keep[at + 2 * (nint + q)] = fm > (fs + fe) / 2 + mid_bulge;
            }
        }
    Py_ssize_t n = 0;
    for (Py_ssize_t i = 0; i < 4 * n3; i++) {
        if (!keep[i])
            continue;
        Py_ssize_t from = base + i, to = base + n++;
        if (from == to)
            continue;
        o->F[to] = o->F[from];
        o->norm[to] = o->norm[from];
        o->k[to] = o->k[from];
        if (o->grad) {
            memcpy(o->C + 5 * to, o->C + 5 * from, 5 * sizeof(double));
            memcpy(o->sizes + 5 * to, o->sizes + 5 * from, 5 * sizeof(float));
        }
    }
    return n;
}

/* a buffer of 4-byte items of the struct code ``code`` ('i' int32, 'f' float32) */
static int get_buffer4(PyObject *obj, Py_buffer *view, char code, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE;
    if (PyObject_GetBuffer(obj, view, flags) < 0)
        return -1;
    size_t n = view->format == NULL ? 0 : strlen(view->format);
    char got = n == 0 ? '\0' : view->format[n - 1];
    /* (a 4-byte C long is numpy's int32 on some platforms) */
    if (view->itemsize != 4 || !(got == code || (code == 'i' && got == 'l'))) {
        PyErr_Format(PyExc_TypeError, "%s must hold %s values", name,
                     code == 'i' ? "int32" : "float32");
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

#define NIN 13
#define NOUT 3

static PyObject *block(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *objs[NIN + NOUT], *kobj, *zobj;
    Py_ssize_t m, k0, k1;
    int has_cap, grad;
    double cfloor, S, neg_inv_S, near, bulge, mid_bulge;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOOOOOOOninndddddd" "p", &objs[0], &objs[1],
                          &objs[2], &objs[3], &objs[4], &objs[5], &objs[6], &objs[7],
                          &objs[8], &objs[9], &objs[10], &objs[11], &objs[12], &objs[13],
                          &objs[14], &objs[15], &kobj, &zobj, &m, &has_cap, &k0, &k1,
                          &cfloor, &S, &neg_inv_S, &near, &bulge, &mid_bulge, &grad))
        return NULL;
    static const char *const names[NIN + NOUT] = {
        "grid", "pcols", "tlo", "thi", "h", "J", "Tk", "sigma", "w", "alpha", "kinds",
        "lims", "fric", "F", "norm", "C"};
    Py_buffer v[NIN + NOUT], kv, zv;
    if (get_buffers(objs, v, NIN + NOUT, NIN, names) < 0)
        return NULL;
    PyObject *result = NULL;
    int held_k = 0, held_z = 0;
    if (get_buffer4(kobj, &kv, 'i', "k") < 0)
        goto done;
    held_k = 1;
    if (get_buffer4(zobj, &zv, 'f', "sizes") < 0)
        goto done;
    held_z = 1;
    {
        Py_ssize_t n1 = v[0].len / 8, M = v[4].len / 8, nc = v[10].len / 8;
        /* the sizes the rows need, bounded before any product (no overflow: m is at most
         * a quarter of pcols' values, the blocks within the mesh, fewer than 1e15 rows) */
        if (n1 < 2 || m < 0 || m > v[1].len / 8 / 4 || k0 < 0 || k1 > M || k1 < k0
            || (double)(POINTS * (k1 - k0)) * (double)(m + 2) + 12.0 * (double)(k1 - k0) * nc
                   > 1e15) {
            PyErr_SetString(PyExc_ValueError, "block: inconsistent array sizes");
            goto done;
        }
        Py_ssize_t P = 4 * m + (has_cap ? 1 : 0);
        Py_ssize_t inner = k1 - (k0 > 1 ? k0 : 1), nint = k1 - k0;
        Py_ssize_t n2 = (inner > 0 ? inner : 0) + nint, n3 = 3 * nint;
        Py_ssize_t rmax = (n2 + (POINTS - 2) * nint) * m + (has_cap ? n2 : 0) + n2
                          + 4 * n3 * nc;
        if (v[1].len / 8 != n1 * P || v[2].len / 8 != (n1 - 1) * NCOL
            || v[3].len / 8 != (n1 - 1) * NCOL || v[5].len / 8 != M || v[6].len / 8 != M
            || v[7].len / 8 != M + 1 || v[8].len / 8 != M + 1 || v[9].len / 8 != M + 1
            || v[11].len / 8 != 2 * nc || v[12].len / 8 != 5 || v[13].len / 8 < rmax || v[14].len / 8 < rmax
            || kv.len / 4 < rmax || (grad && (v[15].len / 8 < 5 * rmax
                                              || zv.len / 4 < 5 * rmax))) {
            PyErr_SetString(PyExc_ValueError, "block: inconsistent array sizes");
            goto done;
        }
        const double *grid = v[0].buf, *pc = v[1].buf, *tlo = v[2].buf, *thi = v[3].buf;
        const double *kinds = v[10].buf, *lims = v[11].buf, *fric = v[12].buf;
        Motion mo = {v[4].buf, v[5].buf, v[6].buf, v[7].buf, v[8].buf, v[9].buf};
        Out o = {v[13].buf, v[14].buf, v[15].buf, kv.buf, zv.buf, 0, grad};
        const double lo_s = grid[0], hi_s = grid[n1 - 1];
        /* the second-order rows at the inner knots, then at the intervals' middles, first
         * quarters and third quarters (POINTS passes) */
        Py_ssize_t first = o.n;
        for (int pass = 0; pass < POINTS; pass++) {
            Py_ssize_t ka = pass == 0 ? (k0 > 1 ? k0 : 1) : k0;
            for (Py_ssize_t k = ka; k < k1; k++) {
                double th = offset(pass, mo.h[k]);
                Point pt = point_at(&mo, grid, n1, pc, P, k, th);
                const double *a = pt.a, *b = pt.b, ds = pt.ds, w = pt.w, al = pt.al, T = pt.T;
                /* a middle's chord: the interval's start and end, once for its rows */
                int mid = pass == 1 && k > 0 && k < M - 1;
                Point p0 = pt, p1 = pt;
                if (mid) {
                    p0 = point_at(&mo, grid, n1, pc, P, k, 0.0);
                    p1 = point_at(&mo, grid, n1, pc, P, k, mo.h[k]);
                }
                for (Py_ssize_t j = 0; j < m; j++) {
                    double fin = a[3 * m + j] + (b[3 * m + j] - a[3 * m + j]) * pt.u;
                    if (!(fin > 1 - 1e-12))
                        continue;
                    double pu, px, ph, c;
                    double F = second_row(&pt, m, j, cfloor, &pu, &px, &ph, &c);
                    double dpu = (b[j] - a[j]) / ds, dpx = (b[m + j] - a[m + j]) / ds;
                    double dph = (b[2 * m + j] - a[2 * m + j]) / ds;
                    if (pass >= 2 && !(F > -near && F > chord(&mo, grid, n1, pc, P, m, k,
                                                               pass, j, cfloor) + bulge))
                        continue;
                    if (mid) {
                        double u0, u1, u2, u3;
                        double f0 = second_row(&p0, m, j, cfloor, &u0, &u1, &u2, &u3);
                        double f1 = second_row(&p1, m, j, cfloor, &u0, &u1, &u2, &u3);
                        if (!(F > (f0 + f1) / 2 + mid_bulge))
                            continue;
                    }
                    put(&o, k, F, c, th, mo.h[k], (dpu * al + dpx * w * w - dph * T * T) / c,
                        2 * px * w / c, pu / c, 0.0, -2 * ph * T / c);
                }
            }
        }
        Py_ssize_t n_second = o.n - first;
        /* the speed cap w <= sqrt(cap) T, then w >= 0, at the same points */
        for (int kind = has_cap ? 0 : 1; kind < 2; kind++) {
            for (int pass = 0; pass < 2; pass++) {
                Py_ssize_t ka = pass == 0 ? (k0 > 1 ? k0 : 1) : k0;
                for (Py_ssize_t k = ka; k < k1; k++) {
                    double th = offset(pass, mo.h[k]);
                    Point pt = point_at(&mo, grid, n1, pc, P, k, th);
                    if (kind == 1) {
                        put(&o, k, -pt.w / S, S, th, mo.h[k], 0.0, neg_inv_S, 0.0, 0.0, 0.0);
                        continue;
                    }
                    double a = pt.a[4 * m], b = pt.b[4 * m], T = pt.T;
                    double rv = a + (b - a) * pt.u, rs = (b - a) / pt.ds;
                    double c2 = np_max(rv, 1e-300) * T;
                    put(&o, k, (pt.w - rv * T) / c2, c2, th, mo.h[k], -rs * T / c2, 1.0 / c2,
                        0.0, 0.0, -rv / c2);
                }
            }
        }
        /* the third-order rows at every interval's start, middle and end (at its end, the
         * table's segment before the point): per limit, both signs, per point, per joint */
        Py_ssize_t n_third = 0;
        unsigned char *keep3 = malloc((size_t)(4 * n3 > 0 ? 4 * n3 : 1));
        if (keep3 == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        for (Py_ssize_t ci = 0; ci < nc; ci++) {
            int torque_rate = kinds[ci] != 0.0;
            Py_ssize_t base = o.n;
            for (Py_ssize_t p = 0; p < n3; p++) {
                Py_ssize_t k = k0 + p % nint;
                int part = (int)(p / nint), end = part == 2;
                double th = part == 0 ? 0.0 : (part == 1 ? mo.h[k] / 2 : mo.h[k]), sig, ww, aa;
                state_at(&mo, k, th, &sig, &ww, &aa);
                Py_ssize_t s = segment(grid, n1, sig, end);
                double ds = grid[s + 1] - grid[s];
                double u = (np_clip(sig, lo_s, hi_s) - grid[s]) / ds;
                const double *ta = tlo + s * NCOL, *tb = thi + s * NCOL;
                double T = mo.Tk[k], jj = mo.J[k];
                for (int j = 0; j < 2; j++) {
#define VAL(c) (ta[(c) + j] + (tb[(c) + j] - ta[(c) + j]) * u)
#define SLOPE(c) ((tb[(c) + j] - ta[(c) + j]) / ds)
                    double q1 = VAL(Q1), q2 = VAL(Q2), val, gs, gw, ga, gj, gT;
                    double lim = lims[2 * ci + j];
                    if (!torque_rate) {
                        double q3 = VAL(Q3);
                        val = q1 * jj + 3 * q2 * ww * aa + q3 * pow(ww, 3);
                        gs = SLOPE(Q1) * jj + 3 * SLOPE(Q2) * ww * aa
                             + SLOPE(Q3) * pow(ww, 3);
                        gw = 3 * q2 * aa + 3 * q3 * ww * ww;
                        ga = 3 * q2 * ww;
                        gj = q1;
                        gT = 0.0;
                    } else {
                        double a = VAL(CA), b = VAL(CB), da = VAL(CDA), db = VAL(CDB);
                        double dg = VAL(CDG), vs = fric[4];
                        double ch = cosh(np_clip(q1 * ww / T / vs, -300, 300));
                        double cf = fric[j] + fric[2 + j] / vs / (ch * ch);
                        double acc = q1 * aa + q2 * ww * ww;
                        val = (a * jj + (da + 2 * b) * ww * aa + db * pow(ww, 3)
                               + dg * ww * T * T + cf * acc * T);
                        gs = (SLOPE(CA) * jj + (SLOPE(CDA) + 2 * SLOPE(CB)) * ww * aa
                              + SLOPE(CDB) * pow(ww, 3) + SLOPE(CDG) * ww * T * T
                              + cf * (SLOPE(Q1) * aa + SLOPE(Q2) * ww * ww) * T);
                        gw = ((da + 2 * b) * aa + 3 * db * ww * ww + dg * T * T
                              + cf * 2 * q2 * ww * T);
                        ga = (da + 2 * b) * ww + cf * q1 * T;
                        gj = a;
                        gT = 2 * dg * ww * T + cf * acc;
                    }
#undef VAL
#undef SLOPE
                    double scale = lim * pow(T, 3);
                    for (int sg = 0; sg < 2; sg++) {
                        double sign = sg == 0 ? 1.0 : -1.0;
                        o.n = base + sg * 2 * n3 + 2 * p + j;
                        put(&o, k, (sign * val - scale) / scale, scale, th, mo.h[k],
                            sign * gs / scale, sign * gw / scale, sign * ga / scale,
                            sign * gj / scale, (sign * gT - 3 * lim * T * T) / scale);
                    }
                }
            }
            Py_ssize_t kept = drop_middles(&o, base, nint, k0, M, mid_bulge, keep3);
            o.n = base + kept;
            n_third += kept;
        }
        free(keep3);
        result = Py_BuildValue("nnnn", n_second, has_cap ? n2 : (Py_ssize_t)0, n2, n_third);
    }
done:
    if (held_k)
        PyBuffer_Release(&kv);
    if (held_z)
        PyBuffer_Release(&zv);
    release_buffers(v, NIN + NOUT);
    return result;
}

/* The second-order rows' columns at the table's points (RowModel._columns: point_rows of
 * the built-in constraints with the tangent of the friction and of the envelope at x0, the
 * same operations in the same order) */
static PyObject *columns(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *objs[6];
    Py_ssize_t m;
    int has_cap;
    if (!PyArg_ParseTuple(args, "OOOOOOni", &objs[0], &objs[1], &objs[2], &objs[3],
                          &objs[4], &objs[5], &m, &has_cap))
        return NULL;
    static const char *const names[6] = {"pts", "x0", "kinds", "pars", "root", "cols"};
    Py_buffer b[6];
    if (get_buffers(objs, b, 6, 5, names) < 0)
        return NULL;
    PyObject *result = NULL;
    /* (m checked against the constraints' count before any product of it) */
    Py_ssize_t n = b[1].len / 8, nc = b[2].len / 8;
    if (m != 4 * nc || (double)n * (double)(4 * nc + 2) > 1e15) {
        PyErr_SetString(PyExc_ValueError, "columns: inconsistent array sizes");
        goto done;
    }
    Py_ssize_t P = 4 * m + (has_cap ? 1 : 0);
    if (n < 1 || b[0].len / 8 != n * PTS || b[3].len / 8 != 6 * nc
        || b[4].len / 8 != (has_cap ? n : 0) || (double)n * (double)(P + 1) > 1e15
        || b[5].len / 8 != n * P) {
        PyErr_SetString(PyExc_ValueError, "columns: inconsistent array sizes");
        goto done;
    }
    {
        const double *pts = b[0].buf, *x0 = b[1].buf, *kinds = b[2].buf, *pars = b[3].buf;
        const double *root = b[4].buf;
        double *cols = b[5].buf;
        double xmax = x0[0], phmax = 0.0;
        for (Py_ssize_t i = 1; i < n; i++)  /* (numpy's max: a NaN wins) */
            if (!isnan(xmax) && (x0[i] > xmax || isnan(x0[i])))
                xmax = x0[i];
        double floor_ = 1e-9 * np_max(xmax, 1e-300);
        for (Py_ssize_t i = 0; i < n; i++) {
            const double *q = pts + i * PTS;
            double *out = cols + i * P;
            double r = sqrt(np_max(x0[i], floor_));
            for (int j = 0; j < 2; j++) {
                double a = q[j], bb = q[2 + j], g = q[4 + j], dq = q[6 + j], ddq = q[8 + j];
                double up = q[10 + j], down = q[12 + j], w = q[14 + j], coul = q[16 + j];
                double far_phi = coul + 0.5 * w * r, far_psi = 0.5 * w / r;
                double phi_lo = -down * far_phi, psi_lo = -down * far_psi;
                double phi_hi = up * far_phi, psi_hi = up * far_psi;
                for (Py_ssize_t c = 0; c < nc; c++) {
                    const double *pc = pars + 6 * c;
                    double pu, px_hi, px_lo, ph_hi, ph_lo;
                    if (kinds[c] == 0.0) {  /* a torque limit */
                        double tmax = pc[j];
                        pu = a;
                        px_hi = bb + psi_hi;
                        px_lo = -(bb + psi_lo);
                        ph_hi = tmax - g - phi_hi;
                        ph_lo = tmax + g + phi_lo;
                    } else if (kinds[c] == 1.0) {  /* the torque-speed envelope */
                        double tmax = pc[j], wmax = pc[2 + j], knee = pc[4 + j];
                        double sigma = tmax / (wmax - knee), qabs = fabs(dq);
                        double xk = INFINITY, slope = 0.0, offset = 0.0;
                        if (qabs > 0) {
                            double t = knee / qabs;
                            xk = t * t;
                        }
                        double rr = sqrt(np_min(np_max(x0[i], xk), 1e300));
                        if (qabs > 0) {
                            slope = sigma * qabs / (2 * rr);
                            offset = sigma * qabs * rr / 2;
                        }
                        double cap = tmax + sigma * knee - offset;
                        pu = a;
                        px_hi = bb + psi_hi + slope;
                        px_lo = -(bb + psi_lo) + slope;
                        ph_hi = cap - g - phi_hi;
                        ph_lo = cap + g + phi_lo;
                    } else {  /* an acceleration limit */
                        pu = dq;
                        px_hi = ddq;
                        px_lo = -ddq;
                        ph_hi = ph_lo = pc[j];
                    }
                    Py_ssize_t hi_col = 4 * c + j, lo_col = 4 * c + 2 + j;
                    out[hi_col] = pu;
                    out[lo_col] = -pu;
                    out[m + hi_col] = px_hi;
                    out[m + lo_col] = px_lo;
                    double ph[2] = {ph_hi, ph_lo};
                    Py_ssize_t at[2] = {hi_col, lo_col};
                    for (int e = 0; e < 2; e++) {
                        int fin = isfinite(ph[e]);
                        out[2 * m + at[e]] = fin ? ph[e] : 0.0;
                        out[3 * m + at[e]] = fin ? 1.0 : 0.0;
                        if (fin)
                            phmax = np_max(fabs(ph[e]), phmax);
                    }
                }
            }
            if (has_cap)
                out[4 * m] = root[i];
        }
        result = PyFloat_FromDouble(phmax);
    }
done:
    release_buffers(b, 6);
    return result;
}

/* numpy.gradient(f, dx, axis=0) of the columns of f (n x p, n >= 2) into g */
static void gradient(const double *f, double *g, Py_ssize_t n, Py_ssize_t p, double dx)
{
    for (Py_ssize_t i = 1; i + 1 < n; i++)
        for (Py_ssize_t j = 0; j < p; j++)
            g[i * p + j] = (f[(i + 1) * p + j] - f[(i - 1) * p + j]) / (2.0 * dx);
    for (Py_ssize_t j = 0; j < p; j++) {
        g[j] = (f[p + j] - f[j]) / dx;
        g[(n - 1) * p + j] = (f[(n - 1) * p + j] - f[(n - 2) * p + j]) / dx;
    }
}

static PyObject *monitor(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *objs[9];
    double dt;
    if (!PyArg_ParseTuple(args, "OOOOOOOOdO", &objs[0], &objs[1], &objs[2], &objs[3],
                          &objs[4], &objs[5], &objs[6], &objs[7], &dt, &objs[8]))
        return NULL;
    static const char *const names[9] = {"grid", "lo", "hi", "s", "v", "a", "kinds", "lims",
                                         "c2"};
    Py_buffer b[9];
    if (get_buffers(objs, b, 9, 8, names) < 0)
        return NULL;
    PyObject *result = NULL;
    double *P = NULL;
    Py_ssize_t n1 = b[0].len / 8, n = b[3].len / 8, np_ = b[6].len / 8;
    Py_ssize_t nc = n1 >= 2 ? b[1].len / 8 / (n1 - 1) : 0, p = 2 * np_;
    if (n1 < 2 || nc < 10 || b[1].len / 8 != (n1 - 1) * nc || b[2].len != b[1].len
        || b[4].len / 8 != n || b[5].len / 8 != n || b[7].len / 8 != p || b[8].len / 8 != n
        || n < 2 || (double)n * (double)p > 1e15) {
        PyErr_SetString(PyExc_ValueError, "monitor: inconsistent array sizes");
        goto done;
    }
    if (p > 0) {
        P = malloc((size_t)(2 * n * p) * sizeof(double));
        if (P == NULL) {
            PyErr_NoMemory();
            goto done;
        }
    }
    {
        const double *grid = b[0].buf, *lo = b[1].buf, *hi = b[2].buf, *s = b[3].buf;
        const double *v = b[4].buf, *a = b[5].buf, *kinds = b[6].buf, *lims = b[7].buf;
        double *c2 = b[8].buf, *G = p > 0 ? P + n * p : NULL;
        Py_ssize_t k = 0;
        for (Py_ssize_t i = 0; i < n && p > 0; i++) {
            /* the samples' arc lengths increase (a motion's): the segment walked to from the
             * last one, the same as the search's; else searched */
            if (i > 0 && s[i] >= s[i - 1] && !isnan(s[i]) && s[i - 1] >= grid[k]) {
                while (k < n1 - 2 && grid[k + 1] <= s[i])
                    k++;
            } else {
                k = segment(grid, n1, s[i], 0);
            }
            double ds = grid[k + 1] - grid[k];
            double u = (np_clip(s[i], grid[0], grid[n1 - 1]) - grid[k]) / ds;
            double vv = v[i], aa = a[i];
            for (int j = 0; j < 2; j++) {
#define VAL(c) ((hi[k * nc + (c) + j] - lo[k * nc + (c) + j]) * u + lo[k * nc + (c) + j])
                double q1 = VAL(Q1), q2 = VAL(Q2);
                for (Py_ssize_t c = 0; c < np_; c++) {
                    double x, lim = lims[2 * c + j];
                    double kind = kinds[c];  /* (compared as start.py does) */
                    if (kind == 0.0)
                        x = (q1 * aa + q2 * vv * vv) / lim;
                    else if (kind == 1.0)
                        x = (VAL(CA) * aa + VAL(CB) * vv * vv) / lim;
                    else if (kind == 2.0)
                        x = (3 * q2 * vv * aa + VAL(Q3) * pow(vv, 3)) / lim;
                    else
                        x = q1 * vv / lim;
                    P[i * p + 2 * c + j] = x;
                }
#undef VAL
            }
        }
        if (p > 0) {
            gradient(P, G, n, p, dt);
            gradient(G, P, n, p, dt);
        }
        for (Py_ssize_t i = 0; i < n; i++) {
            double m = 0.0;
            for (Py_ssize_t j = 0; j < p; j++) {
                double x = fabs(P[i * p + j]);
                m = np_max(x, m);
            }
            c2[i] = m;
        }
        result = Py_None;
        Py_INCREF(result);
    }
done:
    free(P);
    release_buffers(b, 9);
    return result;
}

static PyMethodDef methods[] = {
    {"block", block, METH_VARARGS,
     "block(grid, pcols, tlo, thi, h, J, Tk, sigma, w, alpha, kinds, lims, fric, F, norm, C, "
     "k, sizes, m, has_cap, k0, k1, cfloor, S, neg_inv_S, near, bulge, grad) -> (second, "
     "cap, w, "
     "third): "
     "the rows of the intervals k0 to k1 written into F, norm, C, k and sizes."},
    {"columns", columns, METH_VARARGS,
     "columns(pts, x0, kinds, pars, root, cols, m, has_cap) -> phmax: the second-order rows' "
     "columns at the table's points (pu | px | ph, 0 where not finite | finite | root cap)."},
    {"monitor", monitor, METH_VARARGS,
     "monitor(grid, lo, hi, s, v, a, kinds, lims, dt, c2): start.fractions' monitor, the "
     "largest second difference of its parts at each sample, into c2."},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_rows",
    "The jerk-limited law's rows, compiled.", -1, methods, NULL, NULL, NULL, NULL
};

PyMODINIT_FUNC PyInit__rows(void)
{
    PyObject *mod = PyModule_Create(&module);
    if (mod == NULL)
        return NULL;
    if (PyModule_AddIntConstant(mod, "VERSION", ROWS_VERSION) < 0) {
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
