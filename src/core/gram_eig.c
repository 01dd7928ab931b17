/* gram_eig.c -- the extreme eigenvalues of the Gram matrix G = R^T R of a
 * jet fit (solve.c's fast path: kappa = sqrt(lambda_max / lambda_min)),
 * for two fits at once in the two lanes of SSE2 vectors.
 *
 * Householder tridiagonalisation T = H G H (as solve.c's jf__sym_eigvals),
 * then Laguerre's iteration on det(T - x I), evaluated with its first two
 * derivatives by the three-term recurrence, from Gershgorin's bounds: for
 * a polynomial whose roots are all real, Laguerre's step from outside the
 * roots moves monotonically and cubically to the nearest one (Numerical
 * Recipes §9.5), so lambda_max comes from above and lambda_min from below,
 * each in 4-7 steps of one division, against the QL iteration's chain of
 * dependent divisions for all cols eigenvalues (measured: the QL was 85%
 * of the eigen-step, itself 19% of a one-thread knn:16 run).  kappa from
 * these extremes agrees with GSL's SVD to 1e-12 up to kappa 4e3, where
 * the QL's was off by up to 2.2e-9 (test_jet: test_gram_extremes). */
#include <float.h>
#include <math.h>
#include <stddef.h>

#include "fitter_internal.h"
#include "simd.h"


#define GE_MAX 10    /* cols up to degree 3; larger: solve.c's QL       */
#define GE_ITERS 100 /* Laguerre steps before a lane is declared failed */
#define GE_TOL (8 * DBL_EPSILON) /* last step, absolute, T scaled to ~1  */

/* T = H A H for the two n x n row-major matrices in the lanes of a
 * (destroyed): diagonal d, squared sub-diagonal e (e[n-1] = 0).  Each
 * lane does exactly jf__sym_eigvals' operations; a lane with a zero column
 * keeps its values (mask). */
static inline __attribute__((always_inline)) void tridiag_x2(v2d *a, size_t n, v2d *d, v2d *e)
{
    const v2d zero = {0.0, 0.0};
    for (size_t k = 0; k + 2 < n; k++) {
        const size_t m = n - k - 1, o = k + 1;
        v2d v[GE_MAX], p[GE_MAX], nx = zero;
        for (size_t i = 0; i < m; i++) {
            v[i] = a[(o + i) * n + k];
            nx += v[i] * v[i];
        }
        d[k] = a[k * n + k];
        e[k] = nx;
        const v2l skip = (v2l)(nx == zero); /* that lane's `continue` */
        if (skip[0] && skip[1]) continue;
        const v2d x0 = v[0], rt = sqrt2(nx);
        const v2d alpha = sel2((v2l)(x0 > zero), -rt, rt);
        v[0] = x0 - alpha;
        const v2d vv = 2.0 * (nx - x0 * alpha), beta = 2.0 / vv;
        v2d vp = zero;
        for (size_t i = 0; i < m; i++) {
            const v2d *ai = a + (o + i) * n + o;
            v2d t = zero;
            for (size_t j = 0; j < m; j++) t += ai[j] * v[j];
            p[i] = beta * t;
            vp += v[i] * p[i];
        }
        const v2d kq = vp / vv;
        for (size_t i = 0; i < m; i++) p[i] -= kq * v[i];
        for (size_t i = 0; i < m; i++) {
            v2d *ai = a + (o + i) * n + o;
            for (size_t j = 0; j < m; j++) ai[j] = sel2(skip, ai[j], ai[j] - (v[i] * p[j] + p[i] * v[j]));
        }
    }
    if (n >= 2) {
        const v2d t = a[(n - 1) * n + n - 2];
        d[n - 2] = a[(n - 2) * n + n - 2];
        e[n - 2] = t * t;
    }
    d[n - 1] = a[(n - 1) * n + n - 1];
    e[n - 1] = zero;
}

/* det(T - xI) and its first two derivatives at x (per lane). */
static inline __attribute__((always_inline)) void charpoly(const v2d *d, const v2d *e, size_t n, v2d x, v2d *p, v2d *p1,
                            v2d *p2)
{
    v2d a = d[0] - x, a1 = {-1.0, -1.0}, a2 = {0.0, 0.0};
    v2d b = {1.0, 1.0}, b1 = {0.0, 0.0}, b2 = {0.0, 0.0};
    for (size_t k = 1; k < n; k++) {
        const v2d t = d[k] - x, s = e[k - 1];
        const v2d c = t * a - s * b, c1 = t * a1 - s * b1 - a, c2 = t * a2 - s * b2 - 2.0 * a1;
        b = a, b1 = a1, b2 = a2;
        a = c, a1 = c1, a2 = c2;
    }
    *p = a, *p1 = a1, *p2 = a2;
}

/* One Laguerre step for each lane of x (hi: toward the largest root from
 * above, else the smallest from below).  A lane stays put and is marked
 * done when it is already, when det(T - xI) is 0 or has the sign of the
 * roots' other side (rounding carried x across the root), or when the
 * step makes no progress in its direction; the lane is done after a
 * step of at most GE_TOL. */
static inline __attribute__((always_inline)) v2d laguerre(const v2d *d, const v2d *e, size_t n, v2d x, int hi, v2l *done)
{
    v2d p, p1, p2;
    charpoly(d, e, n, x, &p, &p1, &p2);
    const v2d nn = {(double)n, (double)n}, zero = {0.0, 0.0};
    /* outside the roots, det(T - xI) > 0 below them, (-1)^n p > 0 above */
    const v2d sp = hi && (n & 1) ? -p : p;
    const v2l live = ~*done & (v2l)(sp > zero);
    const v2d ps = sel2(live, p, (v2d){1.0, 1.0});
    const v2d g = p1 / ps, h = g * g - p2 / ps;
    v2d disc = (nn - 1.0) * (nn * h - g * g);
    disc = sqrt2(sel2((v2l)(disc > zero), disc, zero));
    const v2d den = hi ? g + disc : g - disc;
    const v2d xn = x - nn / sel2((v2l)(den != zero), den, (v2d){1.0, 1.0});
    const v2l ok = live & (v2l)(den != zero) & (v2l)(hi ? xn < x : xn > x);
    /* a step below the evaluation's rounding (T is scaled to norm ~1)
     * ends it: past that point the steps only wander in the noise */
    *done = ~ok | (v2l)(abs2(xn - x) <= (v2d){GE_TOL, GE_TOL});
    return sel2(ok, xn, x);
}

/* Largest and smallest eigenvalue of each lane's T; rc[lane] -1 when the
 * iteration did not settle (not finite, or GE_ITERS steps). */
static inline __attribute__((always_inline)) void extremes_x2(v2d *d, v2d *e, size_t n, v2d *lmax, v2d *lmin,
                                                              int rc[2])
{
    /* Gershgorin's interval, and a power of two bringing it to ~1 so the
     * recurrence neither over- nor underflows (exact scaling) */
    v2d ub = d[0], lb = d[0], bprev = {0.0, 0.0};
    for (size_t k = 0; k < n; k++) {
        const v2d b = sqrt2(e[k]); /* |T[k+1][k]| */
        const v2d hi = d[k] + (bprev + b), lo = d[k] - (bprev + b);
        ub = sel2((v2l)(hi > ub), hi, ub);
        lb = sel2((v2l)(lo < lb), lo, lb);
        bprev = b;
    }
    v2d sc, isc;
    for (int L = 0; L < 2; L++) {
        int q = 0;
        frexp(fmax(fabs(ub[L]), fabs(lb[L])), &q);
        sc[L] = ldexp(1.0, -q);
        isc[L] = ldexp(1.0, q);
    }
    for (size_t k = 0; k < n; k++) {
        d[k] *= sc;
        e[k] *= sc * sc;
    }
    v2d xh = ub * sc, xl = lb * sc;
    v2l dh = {0, 0}, dl = {0, 0};
    int it = 0;
    for (; it < GE_ITERS && !(dh[0] && dh[1] && dl[0] && dl[1]); it++) {
        /* a side done in both lanes would only keep them: skipped */
        if (!(dh[0] && dh[1])) xh = laguerre(d, e, n, xh, 1, &dh);
        if (!(dl[0] && dl[1])) xl = laguerre(d, e, n, xl, 0, &dl);
    }
    *lmax = xh * isc;
    *lmin = xl * isc;
    for (int L = 0; L < 2; L++)
        rc[L] = dh[L] && dl[L] && isfinite((*lmax)[L]) && isfinite((*lmin)[L]) ? 0 : -1;
}

/* f->s[0] = lambda_max, f->s[1..cols-1] = lambda_min (fast_finish reads
 * only the extremes) */
static void put(jf_fitter *f, size_t cols, double hi, double lo)
{
    f->s[0] = hi;
    for (size_t j = 1; j < cols; j++) f->s[j] = lo;
}

/* The extremes of the Gram matrices g0 and g1 (cols x cols, cols <=
 * GE_MAX), each in its lane. */
static inline __attribute__((always_inline)) void
extremes_of(const double *g0, const double *g1, size_t cols, v2d *hi, v2d *lo, int rc[2])
{
    v2d a[GE_MAX * GE_MAX], d[GE_MAX], e[GE_MAX];
    for (size_t i = 0; i < cols * cols; i++) a[i] = (v2d){g0[i], g1[i]};
    tridiag_x2(a, cols, d, e);
    extremes_x2(d, e, cols, hi, lo, rc);
}

/* Degree 2 (6 columns) and 3 (10) with the size a constant, which the
 * compiler unrolls: the same operations in the same order, the same bits. */
static void gram_extremes(const double *g0, const double *g1, size_t cols, v2d *hi, v2d *lo,
                          int rc[2])
{
    if (cols == 6 && jf__fixed_sizes) extremes_of(g0, g1, 6, hi, lo, rc);
    else if (cols == 10 && jf__fixed_sizes) extremes_of(g0, g1, 10, hi, lo, rc);
    else extremes_of(g0, g1, cols, hi, lo, rc);
}

void jf__eigvals_x2(jf_fitter *f0, jf_fitter *f1, size_t cols, int ok[2])
{
    if (cols > GE_MAX || cols < 2) {
        ok[0] = jf__eigvals(f0, cols);
        ok[1] = jf__eigvals(f1, cols);
        return;
    }
    v2d hi, lo;
    int rc[2];
    gram_extremes(f0->x, f1->x, cols, &hi, &lo, rc);
    put(f0, cols, hi[0], lo[0]);
    put(f1, cols, hi[1], lo[1]);
    ok[0] = rc[0] == 0;
    ok[1] = rc[1] == 0;
}

/* ---- four at once -----------------------------------------------------
 * The same steps for four fits in the four lanes of 32-byte vectors
 * (one AVX register; two SSE2 registers in the default build): each lane
 * does exactly the operations of the two-lane code above, so each gets
 * the bits jf__eigvals gives.  The sqrt of four lanes is a parameter (an
 * always-inlined call: vsqrtpd in the AVX build, two sqrtpd else;
 * simd.h). */
static inline __attribute__((always_inline)) void tridiag_x4(v4d *a, size_t n, v4d *d, v4d *e,
                                                             sqrt4_fn sq)
{
    const v4d zero = {0.0, 0.0, 0.0, 0.0};
    for (size_t k = 0; k + 2 < n; k++) {
        const size_t m = n - k - 1, o = k + 1;
        v4d v[GE_MAX], p[GE_MAX], nx = zero;
        for (size_t i = 0; i < m; i++) {
            v[i] = a[(o + i) * n + k];
            nx += v[i] * v[i];
        }
        d[k] = a[k * n + k];
        e[k] = nx;
        const v4l skip = (v4l)(nx == zero);
        if (all4(skip)) continue;
        const v4d x0 = v[0], rt = vsqrt4(nx, sq);
        const v4d alpha = sel4((v4l)(x0 > zero), -rt, rt);
        v[0] = x0 - alpha;
        const v4d vv = 2.0 * (nx - x0 * alpha), beta = 2.0 / vv;
        v4d vp = zero;
        for (size_t i = 0; i < m; i++) {
            const v4d *ai = a + (o + i) * n + o;
            v4d t = zero;
            for (size_t j = 0; j < m; j++) t += ai[j] * v[j];
            p[i] = beta * t;
            vp += v[i] * p[i];
        }
        const v4d kq = vp / vv;
        for (size_t i = 0; i < m; i++) p[i] -= kq * v[i];
        for (size_t i = 0; i < m; i++) {
            v4d *ai = a + (o + i) * n + o;
            for (size_t j = 0; j < m; j++) ai[j] = sel4(skip, ai[j], ai[j] - (v[i] * p[j] + p[i] * v[j]));
        }
    }
    if (n >= 2) {
        const v4d t = a[(n - 1) * n + n - 2];
        d[n - 2] = a[(n - 2) * n + n - 2];
        e[n - 2] = t * t;
    }
    d[n - 1] = a[(n - 1) * n + n - 1];
    e[n - 1] = zero;
}

static inline __attribute__((always_inline)) void charpoly_x4(const v4d *d, const v4d *e, size_t n,
                                                              v4d x, v4d *p, v4d *p1, v4d *p2)
{
    v4d a = d[0] - x, a1 = {-1.0, -1.0, -1.0, -1.0}, a2 = {0.0, 0.0, 0.0, 0.0};
    v4d b = {1.0, 1.0, 1.0, 1.0}, b1 = {0.0, 0.0, 0.0, 0.0}, b2 = {0.0, 0.0, 0.0, 0.0};
    for (size_t k = 1; k < n; k++) {
        const v4d t = d[k] - x, s = e[k - 1];
        const v4d c = t * a - s * b, c1 = t * a1 - s * b1 - a, c2 = t * a2 - s * b2 - 2.0 * a1;
        b = a, b1 = a1, b2 = a2;
        a = c, a1 = c1, a2 = c2;
    }
    *p = a, *p1 = a1, *p2 = a2;
}

static inline __attribute__((always_inline)) v4d laguerre_x4(const v4d *d, const v4d *e, size_t n,
                                                             v4d x, int hi, v4l *done, sqrt4_fn sq)
{
    v4d p, p1, p2;
    charpoly_x4(d, e, n, x, &p, &p1, &p2);
    const v4d nn = {(double)n, (double)n, (double)n, (double)n}, zero = {0.0, 0.0, 0.0, 0.0};
    const v4d one = {1.0, 1.0, 1.0, 1.0};
    const v4d sp = hi && (n & 1) ? -p : p;
    const v4l live = ~*done & (v4l)(sp > zero);
    const v4d ps = sel4(live, p, one);
    const v4d g = p1 / ps, h = g * g - p2 / ps;
    v4d disc = (nn - 1.0) * (nn * h - g * g);
    disc = vsqrt4(sel4((v4l)(disc > zero), disc, zero), sq);
    const v4d den = hi ? g + disc : g - disc;
    const v4d xn = x - nn / sel4((v4l)(den != zero), den, one);
    const v4l ok = live & (v4l)(den != zero) & (v4l)(hi ? xn < x : xn > x);
    const v4d tol = {GE_TOL, GE_TOL, GE_TOL, GE_TOL};
    *done = ~ok | (v4l)(abs4(xn - x) <= tol);
    return sel4(ok, xn, x);
}

static inline __attribute__((always_inline)) void extremes_x4(v4d *d, v4d *e, size_t n, v4d *lmax,
                                                              v4d *lmin, int rc[4], sqrt4_fn sq)
{
    v4d ub = d[0], lb = d[0], bprev = {0.0, 0.0, 0.0, 0.0};
    for (size_t k = 0; k < n; k++) {
        const v4d b = vsqrt4(e[k], sq);
        const v4d hi = d[k] + (bprev + b), lo = d[k] - (bprev + b);
        ub = sel4((v4l)(hi > ub), hi, ub);
        lb = sel4((v4l)(lo < lb), lo, lb);
        bprev = b;
    }
    v4d sc, isc;
    for (int L = 0; L < 4; L++) {
        int q = 0;
        frexp(fmax(fabs(ub[L]), fabs(lb[L])), &q);
        sc[L] = ldexp(1.0, -q);
        isc[L] = ldexp(1.0, q);
    }
    for (size_t k = 0; k < n; k++) {
        d[k] *= sc;
        e[k] *= sc * sc;
    }
    v4d xh = ub * sc, xl = lb * sc;
    v4l dh = {0, 0, 0, 0}, dl = {0, 0, 0, 0};
    int it = 0;
    for (; it < GE_ITERS && !(all4(dh) && all4(dl)); it++) {
        if (!all4(dh)) xh = laguerre_x4(d, e, n, xh, 1, &dh, sq);
        if (!all4(dl)) xl = laguerre_x4(d, e, n, xl, 0, &dl, sq);
    }
    *lmax = xh * isc;
    *lmin = xl * isc;
    for (int L = 0; L < 4; L++)
        rc[L] = dh[L] && dl[L] && isfinite((*lmax)[L]) && isfinite((*lmin)[L]) ? 0 : -1;
}

/* The extremes of the four Gram matrices g[0..3] (cols x cols), lane by
 * lane, into hi[L], lo[L]; rc[L] as extremes_x2's. */
static inline __attribute__((always_inline)) void extremes_of_x4(const double *const g[4],
                                                                 size_t cols, double hi[4],
                                                                 double lo[4], int rc[4],
                                                                 sqrt4_fn sq)
{
    v4d a[GE_MAX * GE_MAX], d[GE_MAX], e[GE_MAX], h, l;
    for (size_t i = 0; i < cols * cols; i++) a[i] = (v4d){g[0][i], g[1][i], g[2][i], g[3][i]};
    tridiag_x4(a, cols, d, e, sq);
    extremes_x4(d, e, cols, &h, &l, rc, sq);
    for (int L = 0; L < 4; L++) hi[L] = h[L], lo[L] = l[L];
}

static inline __attribute__((always_inline)) void gram_extremes_x4(const double *const g[4],
                                                                   size_t cols, double hi[4],
                                                                   double lo[4], int rc[4],
                                                                   sqrt4_fn sq)
{
    if (cols == 6 && jf__fixed_sizes) extremes_of_x4(g, 6, hi, lo, rc, sq);
    else if (cols == 10 && jf__fixed_sizes) extremes_of_x4(g, 10, hi, lo, rc, sq);
    else extremes_of_x4(g, cols, hi, lo, rc, sq);
}

#if JF_AVX_PATH
JF_AVX_FN static void gram_extremes_x4_avx(const double *const g[4], size_t cols, double hi[4],
                                           double lo[4], int rc[4])
{
    gram_extremes_x4(g, cols, hi, lo, rc, sqrt4_avx);
    JF_AVX_LEAVE();
}
#endif

/* f[L] may repeat (a lane whose result is not wanted): its lanes compute
 * the same values. */
void jf__eigvals_x4(jf_fitter *const f[4], size_t cols, int ok[4])
{
    if (cols > GE_MAX || cols < 2) { /* once per fitter: the QL destroys f->x */
        for (int L = 0; L < 4; L++) {
            int l = 0;
            while (l < L && f[l] != f[L]) l++;
            ok[L] = l < L ? ok[l] : jf__eigvals(f[L], cols);
        }
        return;
    }
    const double *g[4] = {f[0]->x, f[1]->x, f[2]->x, f[3]->x};
    double hi[4], lo[4];
    int rc[4];
#if JF_AVX_PATH
    if (JF_HAVE_AVX()) gram_extremes_x4_avx(g, cols, hi, lo, rc);
    else
#endif
        gram_extremes_x4(g, cols, hi, lo, rc, sqrt4_sse);
    for (int L = 0; L < 4; L++) {
        put(f[L], cols, hi[L], lo[L]);
        ok[L] = rc[L] == 0;
    }
}

int jf__eigvals(jf_fitter *f, size_t cols)
{
    if (cols > GE_MAX || cols < 2) return jf__sym_eigvals(f->x, cols, f->s, f->work) == 0;
    /* both lanes on the same matrix: the bits of jf__eigvals_x2's lanes */
    v2d hi, lo;
    int rc[2];
    gram_extremes(f->x, f->x, cols, &hi, &lo, rc);
    put(f, cols, hi[0], lo[0]);
    return rc[0] == 0;
}

int jf__gram_extremes(const double *g, size_t cols, double *hi, double *lo)
{
    if (cols > GE_MAX || cols < 2) return 0;
    v2d h, l;
    int rc[2];
    gram_extremes(g, g, cols, &h, &l, rc);
    *hi = h[0];
    *lo = l[0];
    return rc[0] == 0;
}
