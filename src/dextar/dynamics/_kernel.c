/* The fused torque kernel of dextar.dynamics.exact compiled: one pass over the samples, the
 * equations of the numpy kernel (_fused_block) in its order of operations, one sample at a
 * time; only the motor angles' cosines and sines come another way (below), so that the
 * torques agree to rounding (the tests: 8e-15 of the largest).
 *
 * Built by `pip install` when a C compiler is there (an optional extension: without one,
 * dextar uses the numpy kernel and gives the same torques to rounding).
 *
 * torques(consts, q, dq, ddq, out) -> (disc, worst, finite)
 *   consts: the model's constants (float64, N_CONSTS, the order of the C_* indices below);
 *   q, dq, ddq: C-contiguous float64 buffers of n * 2 values (n samples, (phi, psi));
 *   out: a writable C-contiguous float64 buffer of n * 2 values, the motor torques.
 *   Returns the smallest (h / |B - C|^2)^2 (negative where the rods cannot meet) and the
 *   largest 1 / |det A| over the samples, for the checks that name a bad sample, and
 *   whether every input is finite (the inputs are checked here, where they are read, and
 *   named by the caller only when one is not).
 *
 * task_torques(consts, legs, P, dP, ddP, dq, ddq, out) -> (bad, disc, worst, finite)
 *   the same torques from the end-effector's motion in one pass: the inverse kinematics in
 *   the working mode, legs = (s1, s2, L1, L2) its signs and the distal rods' lengths (the
 *   motor angles' cosines and sines from the elbows,
 *   no angle needed), the joint rates and accelerations (written to dq and ddq), then the
 *   torque kernel; bad is the first sample out of reach of a leg or at a serial
 *   singularity to rounding (|B - A| x |P - B| at most 1e-12 l L: the rates there are
 *   rounding noise) (-1: none), finite says whether every input and every rate is finite.
 *   Where either says so the caller runs the stages in turn, which name the sample.
 *
 * The motor angles' cosines and sines come from a polynomial on the angle reduced to
 * [-pi/4, pi/4] (Cody-Waite reduction with pi/2 in three parts, Taylor series to the 17th
 * and 16th degree: the truncation is under 1e-18), within an ulp or two of libm's cos and
 * sin; an angle beyond +-2^19 pi/2 (where the reduction loses bits) goes to libm.
 * Compiled without contraction into fused multiply-adds (-ffp-contract=off), so the
 * results do not depend on the machine's instruction set.
 */

#include "../_buffers.h"
#include <float.h>
#include <math.h>

/* The angle reduction rounds by adding and subtracting 1.5 * 2^52, which needs each sum
 * stored as a double: not so with x87 extended precision or -ffast-math (then no extension
 * is built, the install goes on and dextar uses the numpy kernel). */
#if (defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0) || defined(__FAST_MATH__)
#error "dextar's compiled kernel needs double evaluation without -ffast-math"
#endif

/* The kernel's interface version: exact.py uses a build of this version only (an older
 * build left in place, after an edit whose build failed, is not used). */
#define KERNEL_VERSION 4

enum {
    C_L1, C_L2, C_D, C_LSQ1, C_LSQ2, C_ILSQ1, C_ILSQ2, C_L2SQ, C_UE0, C_CST, C_SIGN,
    C_J1, C_J2, C_MP, C_CK1, C_CK2, C_GAX1, C_GAX2, C_GAY1, C_GAY2, C_MPGX, C_MPGY,
    C_VISC1, C_VISC2, C_COUL1, C_COUL2, C_INV_VS, C_FRICTION, N_CONSTS
};

/* pi/2 in three parts, the first two of 33 significant bits (k * part exact for |k| < 2^20) */
static const double PIO2_1 = 1.57079632673412561417e+00;  /* 0x1.921fb544p+0 */
static const double PIO2_2 = 6.07710050630396597660e-11;  /* 0x1.0b4611a6p-34 */
static const double PIO2_3 = 2.02226624879595063154e-21;  /* 0x1.3198a2e037073p-69 */
static const double TWO_OVER_PI = 6.36619772367581382433e-01;
static const double REDUCTION_LIMIT = 823549.6;  /* 2^19 pi/2 */
static const double ROUND = 6755399441055744.0;  /* 1.5 * 2^52: y + ROUND - ROUND rounds y */

/* the nearest integer to y (|y| < 2^51; no -ffast-math, so the sum is kept as written: libm's
 * nearbyint is a call that saves the floating-point environment, slower than the rest) */
static inline double nearest(double y)
{
    return (y + ROUND) - ROUND;
}

/* cos and sin of x (|x| <= REDUCTION_LIMIT), branch-free so that the loop is vectorised */
static inline void cos_sin(double x, double *c, double *s)
{
    double k = nearest(x * TWO_OVER_PI);  /* x = k pi/2 + r */
    double r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    double z = r * r;
    /* Taylor series: 1/3! ... 1/17! and 1/4! ... 1/16! */
    double ps = -1.0 / 6 + z * (1.0 / 120 + z * (-1.0 / 5040 + z * (1.0 / 362880
                + z * (-1.0 / 39916800 + z * (1.0 / 6227020800.0 + z * (-1.0 / 1307674368000.0
                + z * (1.0 / 355687428096000.0)))))));
    double pc = 1.0 / 24 + z * (-1.0 / 720 + z * (1.0 / 40320 + z * (-1.0 / 3628800
                + z * (1.0 / 479001600.0 + z * (-1.0 / 87178291200.0
                + z * (1.0 / 20922789888000.0))))));
    double sr = r + r * (z * ps);
    double cr = (1.0 - 0.5 * z) + (z * z) * pc;
    /* the quadrant k mod 4 from m = k - 4 nearest(k / 4) in {-2, -1, 0, 1, 2}:
     * 0 (sr, cr), 1 (cr, -sr), 2 (-sr, -cr), 3 = -1 (-cr, sr) */
    double m = k - 4.0 * nearest(0.25 * k);
    int odd = fabs(m) == 1.0, two = fabs(m) == 2.0;
    double sv = odd ? cr : sr;
    double cv = odd ? sr : cr;
    *s = (two | (m == -1.0)) ? -sv : sv;
    *c = (two | (m == 1.0)) ? -cv : cv;
}

/* the torques of one sample (its angles' cosines and sines given) and, through disc and
 * worst, the discriminant and 1 / |det| */
static inline void sample(const double *restrict k, double c1, double s1, double c2,
                          double s2, const double *dq, const double *ddq, double *out,
                          double *disc, double *worst)
{
    /* proximal rods a = l (cos q, sin q); v = B - C */
    double ax1 = k[C_L1] * c1, ay1 = k[C_L1] * s1;
    double ax2 = k[C_L2] * c2, ay2 = k[C_L2] * s2;
    double vx = (ax1 - ax2) + k[C_D];
    double vy = ay1 - ay2;
    double del2 = vx * vx + vy * vy;
    double ue = k[C_UE0] - del2 * 0.5;
    double idel = 1.0 / del2;
    double kk = idel * k[C_CST] + 0.5;
    double hh = idel * k[C_L2SQ] - kk * kk;
    *disc = hh;
    hh = sqrt(hh < 0.0 ? 0.0 : hh);
    double iabs = idel / hh;  /* 1 / |det| */
    *worst = iabs;
    double sg = k[C_SIGN];  /* +-1: the products by it are exact */
    double idet = -sg * iabs;
    double nidet = -idet;
    /* e = P - C = kk v + sign hh perp(v), u = P - B = e - v */
    double ex = vx * kk - sg * (hh * vy);
    double ey = vy * kk + sg * (hh * vx);
    double ux = ex - vx, uy = ey - vy;
    /* b = a x U, c = a . U per leg (U: u for leg 1, e for leg 2) */
    double b1 = ax1 * uy - ay1 * ux, b2 = ax2 * ey - ay2 * ex;
    double cu1 = ax1 * ux + ay1 * uy, cu2 = ax2 * ex + ay2 * ey;
    double w1 = dq[0], w2 = dq[1], a1 = ddq[0], a2 = ddq[1];
    /* rates: omega L^2 = T (b qdot) - c qdot; x = -bias = omega^2 L^2 + qdot^2 c */
    double r1 = b1 * w1, r2 = b2 * w2;
    double x1 = (k[C_LSQ1] * r2 - ue * r1) * idet - w1 * cu1;
    double x2 = (k[C_LSQ2] * r1 - ue * r2) * nidet - w2 * cu2;
    x1 = x1 * x1 * k[C_ILSQ1] + w1 * (w1 * cu1);
    x2 = x2 * x2 * k[C_ILSQ2] + w2 * (w2 * cu2);
    /* accelerations: rr = b qddot + bias, y = U x Pddot = T rr */
    double rr1 = b1 * a1 - x1, rr2 = b2 * a2 - x2;
    double y1 = (k[C_LSQ1] * rr2 - ue * rr1) * idet;
    double y2 = (k[C_LSQ2] * rr1 - ue * rr2) * nidet;
    /* the rods' couples k = I_r alpha / L^2, alpha L^2 = y - c qddot - b qdot^2 */
    double k1 = ((y1 - a1 * cu1) - w1 * r1) * k[C_CK1];
    double k2 = ((y2 - a2 * cu2) - w2 * r2) * k[C_CK2];
    /* MP (U x Pddot - U x g) + (L1^2 k1, L2^2 k2) + ue (k2, k1), over det */
    y1 = y1 * k[C_MP];
    y2 = y2 * k[C_MP];
    /* (a term that is zero adds an exact zero: the same sums as the numpy kernel's, which
     * leaves it out) */
    y1 = (y1 - ux * k[C_MPGY]) + uy * k[C_MPGX];
    y2 = (y2 - ex * k[C_MPGY]) + ey * k[C_MPGX];
    y1 = ((y1 + k[C_LSQ1] * k1) + ue * k2) * idet;
    y2 = ((y2 + k[C_LSQ2] * k2) + ue * k1) * nidet;
    /* tau = b lam - k c + J qddot + gravity + viscous friction (Coulomb's: coulomb()) */
    double t1 = (b1 * y2 - k1 * cu1) + a1 * k[C_J1];
    double t2 = (b2 * y1 - k2 * cu2) + a2 * k[C_J2];
    out[0] = ((t1 + ax1 * k[C_GAX1]) + ay1 * k[C_GAY1]) + w1 * k[C_VISC1];
    out[1] = ((t2 + ax2 * k[C_GAX2]) + ay2 * k[C_GAY2]) + w2 * k[C_VISC2];
}

/* Samples per block: the loop over a block is vectorised (no call, no branch on the data);
 * the reductions and what needs libm (large angles, Coulomb friction) follow it. */
#define BLOCK 256

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
/* AVX2 where the machine has it (4 samples an instruction instead of 2); the same results */
#define WIDE __attribute__((target_clones("avx2", "default")))
#else
#define WIDE
#endif

WIDE static void block(const double *restrict k, const double *restrict q,
                       const double *restrict dq, const double *restrict ddq,
                       double *restrict out, Py_ssize_t n, double *restrict disc,
                       double *restrict worst)
{
    for (Py_ssize_t i = 0; i < n; i++) {
        double c1, s1, c2, s2;
        cos_sin(q[2 * i], &c1, &s1);
        cos_sin(q[2 * i + 1], &c2, &s2);
        sample(k, c1, s1, c2, s2, dq + 2 * i, ddq + 2 * i, out + 2 * i, disc + i, worst + i);
    }
}

/* the samples of a block with an angle beyond REDUCTION_LIMIT again, with libm's cos and sin */
static void large_angles(const double *k, const double *q, const double *dq,
                         const double *ddq, double *out, Py_ssize_t n, double *disc,
                         double *worst)
{
    for (Py_ssize_t i = 0; i < n; i++) {
        double x1 = q[2 * i], x2 = q[2 * i + 1];
        if (fabs(x1) > REDUCTION_LIMIT || fabs(x2) > REDUCTION_LIMIT)
            sample(k, cos(x1), sin(x1), cos(x2), sin(x2), dq + 2 * i, ddq + 2 * i,
                   out + 2 * i, disc + i, worst + i);
    }
}

/* Coulomb friction c tanh(qdot / vs), added last as the numpy kernel adds it */
static void coulomb(const double *k, const double *dq, double *out, Py_ssize_t n)
{
    for (Py_ssize_t i = 0; i < n; i++) {
        out[2 * i] = out[2 * i] + tanh(dq[2 * i] * k[C_INV_VS]) * k[C_COUL1];
        out[2 * i + 1] = out[2 * i + 1] + tanh(dq[2 * i + 1] * k[C_INV_VS]) * k[C_COUL2];
    }
}

/* whether the values x[0..n) are all finite (a loop the compiler vectorises) */
static int all_finite(const double *x, Py_ssize_t n)
{
    int bad = 0;
    for (Py_ssize_t i = 0; i < n; i++)
        bad |= !(fabs(x[i]) <= DBL_MAX);
    return !bad;
}

/* The samples' extremes for the caller's checks: the smallest discriminant, the largest
 * 1 / |det|, and whether a NaN was among them (elbows that coincide: told, not skipped). */
typedef struct {
    double dmin, wmax;
    int nan;
} Extremes;

static void extremes_of(Extremes *e, const double *disc, const double *worst, Py_ssize_t m)
{
    for (Py_ssize_t i = 0; i < m; i++) {
        if (disc[i] < e->dmin)
            e->dmin = disc[i];
        if (worst[i] > e->wmax)
            e->wmax = worst[i];
        e->nan |= disc[i] != disc[i] || worst[i] != worst[i];
    }
}

static void extremes_out(const Extremes *e, double *disc_min, double *worst_max)
{
    *disc_min = e->nan ? NAN : e->dmin;
    *worst_max = e->nan ? NAN : e->wmax;
}

static int all_samples(const double *k, const double *q, const double *dq, const double *ddq,
                       double *out, Py_ssize_t n, double *disc_min, double *worst_max)
{
    double disc[BLOCK], worst[BLOCK];
    Extremes e = {INFINITY, 0.0, 0};
    int inputs_finite = 1;
    for (Py_ssize_t start = 0; start < n; start += BLOCK) {
        Py_ssize_t m = n - start < BLOCK ? n - start : BLOCK;
        const double *qb = q + 2 * start, *dqb = dq + 2 * start, *ddqb = ddq + 2 * start;
        double *ob = out + 2 * start;
        int large = 0;
        inputs_finite &= all_finite(qb, 2 * m) & all_finite(dqb, 2 * m)
                         & all_finite(ddqb, 2 * m);
        block(k, qb, dqb, ddqb, ob, m, disc, worst);
        for (Py_ssize_t i = 0; i < 2 * m; i++)
            large |= !(fabs(qb[i]) <= REDUCTION_LIMIT);
        if (large)
            large_angles(k, qb, dqb, ddqb, ob, m, disc, worst);
        if (k[C_FRICTION] != 0.0)
            coulomb(k, dqb, ob, m);
        extremes_of(&e, disc, worst, m);
    }
    extremes_out(&e, disc_min, worst_max);
    return inputs_finite;
}

/* One leg's inverse kinematics as dextar.kinematics.positions._leg_solve: the elbow's
 * direction from the pivot (ex, ey), unnormalised, for u = P - pivot; whether P is out of
 * reach. */
static inline int leg(double ux, double uy, double l, double L, double sign, double *ex,
                      double *ey)
{
    double rho2 = ux * ux + uy * uy;
    double kk = 0.5 * (rho2 + (l * l - L * L));
    double w2 = (l * l) * rho2 - kk * kk;
    int bad = !(w2 >= -1e-12 * (l * l) * rho2) | (rho2 <= 1e-24 * ((l + L) * (l + L)));
    double w = sqrt(w2 > 0.0 ? w2 : 0.0) * -sign;  /* s = +1: the perp term negated */
    *ex = kk * ux - w * uy;
    *ey = kk * uy + w * ux;
    return bad;
}

/* A block of samples from the end-effector's motion: per sample the motor angles' cosines
 * and sines (the elbows' directions normalised), the rates as
 * dextar.kinematics.velocity.joint_rates gives them, then the torques. */
WIDE static void task_block(const double *restrict k, const double *restrict legs,
                            const double *restrict P, const double *restrict dP,
                            const double *restrict ddP, double *restrict dq,
                            double *restrict ddq, double *restrict out, Py_ssize_t n,
                            double *restrict disc, double *restrict worst, int *restrict bad)
{
    double l1 = k[C_L1], l2 = k[C_L2], half = 0.5 * k[C_D];
    double sg1 = legs[0], sg2 = legs[1], L1 = legs[2], L2 = legs[3];
    for (Py_ssize_t i = 0; i < n; i++) {
        double px = P[2 * i], py = P[2 * i + 1];
        double e1x, e1y, e2x, e2y;
        int b = leg(px - half, py, l1, L1, sg1, &e1x, &e1y);
        b |= leg(px + half, py, l2, L2, sg2, &e2x, &e2y);
        double n1 = 1.0 / sqrt(e1x * e1x + e1y * e1y), n2 = 1.0 / sqrt(e2x * e2x + e2y * e2y);
        double c1 = e1x * n1, s1 = e1y * n1, c2 = e2x * n2, s2 = e2y * n2;
        /* the frame: u = P - B, v = P - C, b = l (c x u) */
        double ux = px - (half + l1 * c1), uy = py - l1 * s1;
        double vx = px - (-half + l2 * c2), vy = py - l2 * s2;
        double b1 = l1 * (c1 * uy - s1 * ux), b2 = l2 * (c2 * vy - s2 * vx);
        b |= !(fabs(b1) > 1e-12 * (l1 * L1)) | !(fabs(b2) > 1e-12 * (l2 * L2));
        bad[i] = b;
        double dx = dP[2 * i], dy = dP[2 * i + 1];
        double w1 = (ux * dx + uy * dy) / b1, w2 = (vx * dx + vy * dy) / b2;
        /* the velocity-product term: Pdot - Bdot, Bdot = l w (-s, c) */
        double ex1 = dx + l1 * w1 * s1, ey1 = dy - l1 * w1 * c1;
        double ex2 = dx + l2 * w2 * s2, ey2 = dy - l2 * w2 * c2;
        double bias1 = -(ex1 * ex1 + ey1 * ey1) - l1 * w1 * w1 * (ux * c1 + uy * s1);
        double bias2 = -(ex2 * ex2 + ey2 * ey2) - l2 * w2 * w2 * (vx * c2 + vy * s2);
        double ax = ddP[2 * i], ay = ddP[2 * i + 1];
        dq[2 * i] = w1;
        dq[2 * i + 1] = w2;
        ddq[2 * i] = (ux * ax + uy * ay - bias1) / b1;
        ddq[2 * i + 1] = (vx * ax + vy * ay - bias2) / b2;
        sample(k, c1, s1, c2, s2, dq + 2 * i, ddq + 2 * i, out + 2 * i, disc + i, worst + i);
    }
}

static Py_ssize_t all_task_samples(const double *k, const double *legs, const double *P,
                                   const double *dP, const double *ddP, double *dq,
                                   double *ddq, double *out, Py_ssize_t n, double *disc_min,
                                   double *worst_max, int *finite)
{
    double disc[BLOCK], worst[BLOCK];
    int bad[BLOCK];
    Extremes e = {INFINITY, 0.0, 0};
    int all = 1;
    Py_ssize_t first_bad = -1;
    for (Py_ssize_t start = 0; start < n; start += BLOCK) {
        Py_ssize_t m = n - start < BLOCK ? n - start : BLOCK;
        Py_ssize_t o = 2 * start;
        all &= all_finite(P + o, 2 * m) & all_finite(dP + o, 2 * m) & all_finite(ddP + o, 2 * m);
        task_block(k, legs, P + o, dP + o, ddP + o, dq + o, ddq + o, out + o, m, disc,
                   worst, bad);
        all &= all_finite(dq + o, 2 * m) & all_finite(ddq + o, 2 * m);
        if (k[C_FRICTION] != 0.0)
            coulomb(k, dq + o, out + o, m);
        for (Py_ssize_t i = 0; i < m && first_bad < 0; i++)
            if (bad[i])
                first_bad = start + i;
        extremes_of(&e, disc, worst, m);
    }
    extremes_out(&e, disc_min, worst_max);
    *finite = all;
    return first_bad;
}

static PyObject *torques(PyObject *self, PyObject *args)
{
    PyObject *objs[5];
    static const char *names[5] = {"consts", "q", "dq", "ddq", "out"};
    Py_buffer views[5];
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4]))
        return NULL;
    if (get_buffers(objs, views, 5, 4, names) < 0)
        return NULL;
    if (views[0].len != N_CONSTS * 8) {
        PyErr_Format(PyExc_ValueError, "consts must hold %d values", (int)N_CONSTS);
        goto done;
    }
    Py_ssize_t len = views[1].len;
    if (len % 16 != 0 || views[2].len != len || views[3].len != len || views[4].len != len) {
        PyErr_SetString(PyExc_ValueError, "q, dq, ddq and out must hold n * 2 values each");
        goto done;
    }
    {
        const double *k = views[0].buf;
        const double *q = views[1].buf, *dq = views[2].buf, *ddq = views[3].buf;
        double *out = views[4].buf;
        Py_ssize_t n = len / 16;
        double disc, worst;
        int ok;
        Py_BEGIN_ALLOW_THREADS
        ok = all_samples(k, q, dq, ddq, out, n, &disc, &worst);
        Py_END_ALLOW_THREADS
        result = Py_BuildValue("(ddO)", disc, worst, ok ? Py_True : Py_False);
    }
done:
    release_buffers(views, 5);
    return result;
}

static PyObject *task_torques(PyObject *self, PyObject *args)
{
    PyObject *objs[7];
    static const char *names[7] = {"consts", "P", "dP", "ddP", "dq", "ddq", "out"};
    Py_buffer views[7];
    double legs[4];
    PyObject *result = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "O(dddd)OOOOOO", &objs[0], &legs[0], &legs[1], &legs[2],
                          &legs[3], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6]))
        return NULL;
    if (get_buffers(objs, views, 7, 4, names) < 0)
        return NULL;
    if (views[0].len != N_CONSTS * 8) {
        PyErr_Format(PyExc_ValueError, "consts must hold %d values", (int)N_CONSTS);
        goto done;
    }
    Py_ssize_t len = views[1].len;
    int same = len % 16 == 0;
    for (int j = 2; j < 7; j++)
        same &= views[j].len == len;
    if (!same) {
        PyErr_SetString(PyExc_ValueError,
                        "P, dP, ddP, dq, ddq and out must hold n * 2 values each");
        goto done;
    }
    {
        const double *k = views[0].buf;
        Py_ssize_t n = len / 16, bad;
        double disc, worst;
        int finite;
        Py_BEGIN_ALLOW_THREADS
        bad = all_task_samples(k, legs, views[1].buf, views[2].buf, views[3].buf,
                               views[4].buf, views[5].buf, views[6].buf, n, &disc, &worst,
                               &finite);
        Py_END_ALLOW_THREADS
        result = Py_BuildValue("(nddO)", bad, disc, worst, finite ? Py_True : Py_False);
    }
done:
    release_buffers(views, 7);
    return result;
}

static PyMethodDef methods[] = {
    {"torques", torques, METH_VARARGS,
     "torques(consts, q, dq, ddq, out) -> (disc, worst, finite): the fused torque kernel."},
    {"task_torques", task_torques, METH_VARARGS,
     "task_torques(consts, legs, P, dP, ddP, dq, ddq, out) -> (bad, disc, worst, finite): "
     "the torques from the end-effector's motion."},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernel",
    "The fused torque kernel of dextar.dynamics.exact, compiled.", -1, methods,
    NULL, NULL, NULL, NULL
};

/* cos_sin against libm on angles of every quadrant, at the quarter turns and near the
 * reduction's limit: a build that rounds otherwise (whatever the flags) is not used */
static int cos_sin_agrees(void)
{
    static const double angles[] = {0.0, 0.3, -0.3, 1.5707963267948966, -1.5707963267948966,
                                    2.4, -2.4, 3.141592653589793, -3.9, 4.7123889803846897,
                                    6.283185307179586, -7.0, 1e3 + 0.25, -2.5e5, 823549.0};
    for (size_t i = 0; i < sizeof angles / sizeof angles[0]; i++) {
        double c, s;
        cos_sin(angles[i], &c, &s);
        if (!(fabs(c - cos(angles[i])) <= 1e-15 && fabs(s - sin(angles[i])) <= 1e-15))
            return 0;
    }
    return 1;
}

PyMODINIT_FUNC PyInit__kernel(void)
{
    if (!cos_sin_agrees()) {
        PyErr_SetString(PyExc_ImportError, "dextar's compiled kernel disagrees with libm's cos "
                        "and sin (a compiler's rounding): the numpy kernel is used");
        return NULL;
    }
    PyObject *m = PyModule_Create(&module);
    if (m != NULL && (PyModule_AddIntConstant(m, "N_CONSTS", N_CONSTS) < 0
                      || PyModule_AddIntConstant(m, "VERSION", KERNEL_VERSION) < 0)) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
