/* The time-optimal law's reachability analysis compiled: the stages' elimination and both
 * passes of dextar.laws.time_optimal (_stages, _static_interval, _controllable, _fastest) in
 * one call, with the same formulas in the same order of operations, so that the squared
 * speeds are the same to the last bit (the tests compare the two on random stages and on
 * the examples' paths).
 *
 * Built by `pip install` when a C compiler is there (an optional extension: without one,
 * dextar runs the Python passes and gives the same law).
 *
 * reach(Gu, Gx, h, ds, x) -> k
 *   Gu, Gx, h: C-contiguous float64 buffers of n * m values, the rows Gu u + Gx x <= h of
 *   the n stages (m rows each, stage by stage); ds: n float64 values, the stages' lengths;
 *   x: a writable float64 buffer of n + 1 values, the squared speeds at the grid points.
 *   Returns -1 when x is written, else the stage k at which no motion passes (the caller
 *   names its point): the controllable set at k is empty (backward pass) or the largest
 *   acceleration at k cannot reach the next controllable set (forward pass). The caller
 *   gives finite Gu and Gx and no NaN in h (time_optimal._passes checks them: NumPy's
 *   reductions and these loops would treat a NaN otherwise); n >= 1, m >= 1.
 *
 * chebval(x, c, out)
 *   The Chebyshev series c (N >= 1 float64 values) at the points x (n) into out (n) by
 *   Clenshaw's recurrence, the operations of numpy.polynomial.chebyshev.chebval in its order
 *   (the same values to the last bit), without its Python loop over the terms (~3 us a
 *   term: the forward re-simulation of a 30 s optimal law with eta = 0.001 s^2/kg evaluates
 *   its 1029 terms at 352 windows' times per step: 1.74 -> 1.09 s). For dextar.laws.optimal.
 *
 * Compiled without contraction into fused multiply-adds (-ffp-contract=off): each product
 * and sum rounds as it does in NumPy and in Python's floats.
 */

#include "../_buffers.h"
#include <float.h>
#include <math.h>
#include <stdlib.h>

#if (defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0) || defined(__FAST_MATH__)
#error "dextar's compiled reachability needs double evaluation without -ffast-math"
#endif

/* The interface version: time_optimal.py and optimal.py use a build of this version only
 * (2: with chebval). */
#define REACH_VERSION 2

/* the kinds of a row once solved for u */
enum { ROW_X_ONLY, ROW_UPPER, ROW_LOWER };

/* One stage solved for u, as _stages does it: each row's kind and u <= / >= alpha x + beta,
 * the interval of x every row and pair of rows allows on its own (lo = inf: empty). No NaN
 * arises from the finite Gu, Gx and the h without NaN or -inf that _passes lets through, so
 * plain minima and maxima are NumPy's reductions here. */
static void stage(const double *gu, const double *gx, const double *h, double ds,
                  Py_ssize_t m, int *kind, double *alpha, double *beta, double *lo_out,
                  double *hi_out)
{
    double two_ds = 2 * ds;
    int empty = 0;
    for (Py_ssize_t j = 0; j < m; j++) {
        double tiny = 1e-12 * (fabs(gu[j]) + two_ds * fabs(gx[j]));
        kind[j] = gu[j] > tiny ? ROW_UPPER : gu[j] < -tiny ? ROW_LOWER : ROW_X_ONLY;
        alpha[j] = kind[j] == ROW_X_ONLY ? 0.0 : -gx[j] / gu[j];
        beta[j] = kind[j] == ROW_X_ONLY ? 0.0 : h[j] / gu[j];
    }
    /* every lower row below every upper row, (al - au) x <= bu - bl; the rows in x alone */
    double hi = INFINITY, lo = -INFINITY;
    for (Py_ssize_t i = 0; i < m; i++) {
        if (kind[i] == ROW_X_ONLY) {
            double rx = h[i] / gx[i];
            if (gx[i] > 0 && rx < hi)
                hi = rx;
            else if (gx[i] < 0 && rx > lo)
                lo = rx;
            empty |= (gx[i] == 0) & (h[i] < 0);
            continue;
        }
        if (kind[i] != ROW_UPPER)
            continue;
        for (Py_ssize_t j = 0; j < m; j++) {
            if (kind[j] != ROW_LOWER)
                continue;
            double c = alpha[j] - alpha[i];
            double d = beta[i] - beta[j];
            double r = d / c;
            if (c > 0 && r < hi)
                hi = r;
            else if (c < 0 && r > lo)
                lo = r;
            empty |= (c == 0) & (d < 0);
        }
    }
    *lo_out = empty ? INFINITY : (lo >= 0.0 ? lo : 0.0);
    *hi_out = hi;
}

/* A bound c x <= v c on x: x <= v where c > 0, x >= v where c < 0. */
static inline void bound(double c, double v, double *xl, double *xh)
{
    if (c > 0) {
        if (v < *xh)
            *xh = v;
    } else if (c < 0) {
        if (v > *xl)
            *xl = v;
    }
}

/* The backward pass (_controllable): the controllable interval [K_lo, K_hi] at each point
 * from rest at the end; returns the stage where it is empty, or -1. */
static Py_ssize_t controllable(Py_ssize_t n, Py_ssize_t m, const double *ds, const int *kind,
                               const double *alpha, const double *beta, const double *x_lo,
                               const double *x_hi, double *K_lo, double *K_hi)
{
    const double big = 1e300;  /* an unbounded hi stays finite, so that 0 * hi is 0 */
    K_lo[n] = 0.0;
    K_hi[n] = 0.0;
    for (Py_ssize_t k = n - 1; k >= 0; k--) {
        double lo = K_lo[k + 1], hi = K_hi[k + 1];
        if (hi > big)
            hi = big;
        double inv2 = 1.0 / (2 * ds[k]);
        double xl = x_lo[k], xh = x_hi[k];
        const int *kd = kind + k * m;
        const double *a = alpha + k * m, *b = beta + k * m;
        for (Py_ssize_t j = 0; j < m; j++) {
            if (!isfinite(b[j]))
                continue;  /* (no limit; or none at all: the static interval says it) */
            if (kd[j] == ROW_LOWER) {
                /* u >= al x + bl and u <= (hi - x) / (2 ds): cl x <= hi / (2 ds) - bl */
                double cl = a[j] + inv2;
                bound(cl, inv2 / cl * hi + -b[j] / cl, &xl, &xh);
            } else if (kd[j] == ROW_UPPER) {
                /* u >= (lo - x) / (2 ds) and u <= au x + bu: cu x <= bu - lo / (2 ds) */
                double cu = -inv2 - a[j];
                bound(cu, -inv2 / cu * lo + b[j] / cu, &xl, &xh);
            }
        }
        if (xl > xh + 1e-12 * (1.0 + fabs(xh)))
            return k;
        double v = xh < xl ? xh : xl;
        K_lo[k] = v > 0.0 ? v : 0.0;
        K_hi[k] = xh > 0.0 ? xh : 0.0;
    }
    if (K_lo[0] > 1e-12 * (1.0 + K_hi[0]))
        return 0;
    return -1;
}

/* The forward pass (_fastest): from rest, the largest acceleration every row allows that
 * keeps the next point controllable; returns the stage where none does, or -1. */
static Py_ssize_t fastest(Py_ssize_t n, Py_ssize_t m, const double *ds, const int *kind,
                          const double *alpha, const double *beta, const double *K_lo,
                          const double *K_hi, double *x)
{
    x[0] = 0.0;
    for (Py_ssize_t k = 0; k < n; k++) {
        double xk = x[k];
        double half = 1.0 / (2 * ds[k]), two_ds = 2 * ds[k];
        double u_hi = (K_hi[k + 1] - xk) * half;
        double u_lo = (K_lo[k + 1] - xk) * half;
        const int *kd = kind + k * m;
        const double *au = alpha + k * m, *bu = beta + k * m;
        for (Py_ssize_t j = 0; j < m; j++) {
            if (kd[j] == ROW_UPPER && isfinite(bu[j])) {
                double v = au[j] * xk + bu[j];
                if (v < u_hi)
                    u_hi = v;
            }
        }
        if (u_lo > u_hi + 1e-9 * (1.0 + fabs(u_hi)))
            return k;
        double v = xk + two_ds * u_hi;
        if (v < K_lo[k + 1])
            v = K_lo[k + 1];
        x[k + 1] = K_hi[k + 1] < v ? K_hi[k + 1] : v;
    }
    x[n] = 0.0;
    return -1;
}

static Py_ssize_t solve(Py_ssize_t n, Py_ssize_t m, const double *Gu, const double *Gx,
                        const double *h, const double *ds, double *x, int *failed)
{
    /* one block: the rows' kinds, alpha and beta (n * m each), x_lo, x_hi, K_lo, K_hi */
    size_t nm = (size_t)n * (size_t)m;
    int *kind = malloc(nm * sizeof(int) + 1);
    double *work = malloc((2 * nm + 4 * (size_t)(n + 1)) * sizeof(double));
    if (kind == NULL || work == NULL) {
        free(kind);
        free(work);
        *failed = 1;
        return -1;
    }
    double *alpha = work, *beta = work + nm, *x_lo = work + 2 * nm;
    double *x_hi = x_lo + (n + 1), *K_lo = x_hi + (n + 1), *K_hi = K_lo + (n + 1);
    for (Py_ssize_t k = 0; k < n; k++)
        stage(Gu + k * m, Gx + k * m, h + k * m, ds[k], m, kind + k * m, alpha + k * m,
              beta + k * m, x_lo + k, x_hi + k);
    Py_ssize_t bad = controllable(n, m, ds, kind, alpha, beta, x_lo, x_hi, K_lo, K_hi);
    if (bad < 0)
        bad = fastest(n, m, ds, kind, alpha, beta, K_lo, K_hi, x);
    free(kind);
    free(work);
    *failed = 0;
    return bad;
}

static PyObject *reach(PyObject *self, PyObject *args)
{
    PyObject *objs[5];
    static const char *names[5] = {"Gu", "Gx", "h", "ds", "x"};
    Py_buffer views[5];
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4]))
        return NULL;
    if (get_buffers(objs, views, 5, 4, names) < 0)
        return NULL;
    {
        Py_ssize_t n = views[3].len / 8;
        Py_ssize_t len = views[0].len / 8;
        if (n < 1 || len < n || len % n != 0 || views[1].len != views[0].len
                || views[2].len != views[0].len || views[4].len != (n + 1) * 8) {
            PyErr_SetString(PyExc_ValueError,
                            "Gu, Gx, h must hold n * m values, ds n and x n + 1");
            goto done;
        }
        Py_ssize_t m = len / n, bad;
        int failed;
        Py_BEGIN_ALLOW_THREADS
        bad = solve(n, m, views[0].buf, views[1].buf, views[2].buf, views[3].buf,
                    views[4].buf, &failed);
        Py_END_ALLOW_THREADS
        if (failed)
            PyErr_NoMemory();
        else
            result = PyLong_FromSsize_t(bad);
    }
done:
    release_buffers(views, 5);
    return result;
}

static PyObject *chebval(PyObject *self, PyObject *args)
{
    PyObject *objs[3];
    static const char *names[3] = {"x", "c", "out"};
    Py_buffer views[3];
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &objs[0], &objs[1], &objs[2]))
        return NULL;
    if (get_buffers(objs, views, 3, 2, names) < 0)
        return NULL;
    {
        Py_ssize_t n = views[0].len / 8, N = views[1].len / 8;
        if (N < 1 || views[2].len != views[0].len) {
            PyErr_SetString(PyExc_ValueError, "chebval: c must hold a term, out as many "
                                              "values as x");
            goto done;
        }
        const double *x = views[0].buf, *c = views[1].buf;
        double *out = views[2].buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t i = 0; i < n; i++) {
            double c0, c1;
            if (N == 1) {
                c0 = c[0];
                c1 = 0.0;
            } else if (N == 2) {
                c0 = c[0];
                c1 = c[1];
            } else {
                double x2 = 2 * x[i];
                c0 = c[N - 2];
                c1 = c[N - 1];
                for (Py_ssize_t j = 3; j <= N; j++) {
                    double tmp = c0;
                    c0 = c[N - j] - c1;
                    c1 = tmp + c1 * x2;
                }
            }
            out[i] = c0 + c1 * x[i];
        }
        Py_END_ALLOW_THREADS
        result = Py_None;
        Py_INCREF(result);
    }
done:
    release_buffers(views, 3);
    return result;
}

static PyMethodDef methods[] = {
    {"chebval", chebval, METH_VARARGS,
     "chebval(x, c, out): the Chebyshev series c at x into out (Clenshaw, as numpy's)."},
    {"reach", reach, METH_VARARGS,
     "reach(Gu, Gx, h, ds, x) -> k: the squared speeds into x (k = -1), or the stage k "
     "no motion passes."},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_reach",
    "The time-optimal law's reachability analysis, compiled.", -1, methods,
    NULL, NULL, NULL, NULL
};

PyMODINIT_FUNC PyInit__reach(void)
{
    PyObject *mod = PyModule_Create(&module);
    if (mod == NULL)
        return NULL;
    if (PyModule_AddIntConstant(mod, "VERSION", REACH_VERSION) < 0) {
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
