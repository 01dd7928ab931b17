/* solve.c -- the scaled least-squares system M'Y = B of a jet fit (§2.3):
 * its solution Y and kappa(M') = sigma_max/sigma_min.
 *
 * M' = QR (pivoted Householder, ours); then, when kappa is safely small
 * (the fast path below), kappa from the eigenvalues of R^T R and Y by
 * back-substitution on R; else the SVD of the small R by one-sided Jacobi
 * (ours), GSL's gsl_linalg_SV_decomp as the fallback
 * should Jacobi not converge, and throughout when built with
 * -DJF_GSL_SVD.  Measured (callgrind, §6.1 data): GSL's SV_decomp was
 * 55-60% of all instructions of a fit and allocates on every call
 * (gsl_linalg_bidiag_decomp), which the no-allocation rule forbids; the
 * Jacobi path is 1.0-1.3x faster overall and agrees with GSL to ~kappa
 * eps (test_jet: test_solver_vs_gsl).  -DJF_SVD_GSLJ runs GSL's own
 * one-sided Jacobi (gsl_linalg_SV_decomp_jacobi, allocation-free) on R
 * instead: same results, but 2-3x slower fits (bench_fit 20000 3:
 * 1.1-2.0x CGAL against 3.2-3.8x), below the >= 3x goal: not the default. */
#include <float.h>
#include <math.h>
#include <stddef.h>

#include <gsl/gsl_linalg.h>

#include "fitter_internal.h"

static inline double dot(const double *x, const double *y, size_t n)
{
    /* four partial sums: independent chains the compiler can vectorise
     * (a fixed order, so results stay deterministic) */
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        s0 += x[i] * y[i];
        s1 += x[i + 1] * y[i + 1];
        s2 += x[i + 2] * y[i + 2];
        s3 += x[i + 3] * y[i + 3];
    }
    /* the 0..3 left; counted down, so that no unrolled copy with n a
     * constant multiple of 4 leaves GCC a dead loop to warn about */
    for (size_t r = n - i; r > 0; r--, i++) s0 += x[i] * y[i];
    return (s0 + s1) + (s2 + s3);
}

/* y += a x; y and x are distinct columns (restrict: no run-time overlap
 * test before the vectorised loop) */
static inline void axpy(double *restrict y, const double *restrict x, double a, size_t n)
{
    for (size_t i = 0; i < n; i++) y[i] += a * x[i];
}

/* Householder QR with column pivoting (Businger & Golub; Golub & Van Loan
 * §5.4.1) of the rows x cols matrix a, stored column-major (column j at
 * a + j*rows, contiguous for the inner loops), applied to b in the same
 * sweep: on return the upper cols x cols triangle of a is R, column j of
 * R being original column perm[j], and b[0..cols-1] is (Q^T b)[0..].
 * R has the singular values of a, so the SVD that follows is only cols x
 * cols; pivoting makes R graded (Drmac & Veselic: fewer Jacobi sweeps).
 * nrm, nrm0: cols scratch doubles for the pivoting norms. */
/* Step k of householder_qr: pivot, then reflect column k into R_kk and
 * apply the reflector to the columns right of it and to b. */
static inline __attribute__((always_inline)) void
qr_step(double *a, double *b, size_t rows, size_t cols, size_t k, int *perm, double *nrm,
        double *nrm0)
{
    /* pivot: the remaining column of largest norm (first on ties);
     * norms are downdated, recomputed when cancellation looms */
    size_t piv = k;
    for (size_t j = k; j < cols; j++) {
        if (nrm[j] < 1e-2 * nrm0[j]) {
            nrm[j] = dot(a + j * rows + k, a + j * rows + k, rows - k);
            nrm0[j] = nrm[j];
        }
        if (nrm[j] > nrm[piv]) piv = j;
    }
    if (piv != k) {
        double *x = a + k * rows, *y = a + piv * rows;
        for (size_t i = 0; i < rows; i++) {
            double t = x[i];
            x[i] = y[i];
            y[i] = t;
        }
        int t = perm[k];
        perm[k] = perm[piv];
        perm[piv] = t;
        double u = nrm[k];
        nrm[k] = nrm[piv];
        nrm[piv] = u;
        u = nrm0[k];
        nrm0[k] = nrm0[piv];
        nrm0[piv] = u;
    }
    double *ak = a + k * rows;
    const double nrm2 = dot(ak + k, ak + k, rows - k); /* exact, not downdated */
    if (nrm2 == 0.0) return; /* zero column: R_kk = 0 */
    const double akk = ak[k];
    const double alpha = akk > 0 ? -sqrt(nrm2) : sqrt(nrm2);
    ak[k] = akk - alpha; /* v = ak[k..rows-1] */
    const double tau = 2.0 / (nrm2 - akk * akk + ak[k] * ak[k]);
    for (size_t j = k + 1; j <= cols; j++) { /* j == cols: the rhs */
        double *aj = j < cols ? a + j * rows : b;
        const double sdot = tau * dot(ak + k, aj + k, rows - k);
        axpy(aj + k, ak + k, -sdot, rows - k);
        if (j < cols) nrm[j] -= aj[k] * aj[k];
    }
    ak[k] = alpha;
}

static inline __attribute__((always_inline)) void
qr_norms(const double *a, size_t rows, size_t cols, int *perm, double *nrm, double *nrm0)
{
    for (size_t j = 0; j < cols; j++) {
        perm[j] = (int)j;
        nrm[j] = nrm0[j] = dot(a + j * rows, a + j * rows, rows);
    }
}

static inline __attribute__((always_inline)) void
householder_qr(double *a, double *b, size_t rows, size_t cols, int *perm, double *nrm, double *nrm0)
{
    qr_norms(a, rows, cols, perm, nrm, nrm0);
    for (size_t k = 0; k < cols; k++) qr_step(a, b, rows, cols, k, perm, nrm, nrm0);
}

/* householder_qr for the common sizes as constants: every step unrolled,
 * each with its own constant lengths (1.7x fewer instructions at 16 x 6);
 * the same operations in the same order, so the same bits. */
#define QR_PRAGMA(x) _Pragma(#x)
#define QR_UNROLL(C) QR_PRAGMA(GCC unroll C)
#define QR_FIXED(R, C)                                                                     \
    static inline __attribute__((always_inline)) void householder_qr_##R##_##C(            \
        double *a, double *b, int *perm, double *nrm, double *nrm0)                        \
    {                                                                                      \
        qr_norms(a, R, C, perm, nrm, nrm0);                                                \
        QR_UNROLL(C) for (size_t k = 0; k < C; k++)                                        \
            qr_step(a, b, R, C, k, perm, nrm, nrm0);                                       \
    }
QR_FIXED(16, 6)
QR_FIXED(32, 6)
QR_FIXED(32, 10)

#if !defined(JF_GSL_SVD) && !defined(JF_SVD_GSLJ)
/* One-sided (Hestenes) Jacobi SVD of the cols x cols matrix a, stored
 * column-major (Demmel & Veselic 1992; Golub & Van Loan §8.6.3): plane
 * rotations of column pairs until all are orthogonal to working accuracy,
 * accumulated in v (column-major).  Then a = U diag(s), s_j = ||a_j||.
 * Applied to R of a QR it is accurate in the small singular values, which
 * kappa needs.  Returns 0, or -1 if it did not converge in 60 sweeps. */
static int jacobi_svd(double *a, double *v, double *s, size_t c)
{
    const double tol = (double)c * DBL_EPSILON;
    for (size_t i = 0; i < c * c; i++) v[i] = 0.0;
    for (size_t i = 0; i < c; i++) v[i * c + i] = 1.0;
    for (int sweep = 0; sweep < 60; sweep++) {
        int rotated = 0;
        /* squared column norms, recomputed each sweep, updated exactly by
         * each rotation in between (alpha - t gamma, beta + t gamma) */
        for (size_t j = 0; j < c; j++) s[j] = dot(a + j * c, a + j * c, c);
        for (size_t p = 0; p + 1 < c; p++)
            for (size_t q = p + 1; q < c; q++) {
                double *ap = a + p * c, *aq = a + q * c;
                const double ga = dot(ap, aq, c);
                if (!(fabs(ga) > tol * sqrt(s[p] * s[q]))) continue; /* orthogonal enough */
                const double zeta = (s[q] - s[p]) / (2.0 * ga);
                /* the smaller root of t^2 + 2 zeta t - 1 = 0 (|angle| <= pi/4) */
                const double t = fabs(zeta) > 1e150
                                     ? 0.5 / zeta
                                     : (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
                const double cs = 1.0 / sqrt(1.0 + t * t), sn = cs * t;
                for (size_t i = 0; i < c; i++) {
                    const double x = ap[i], y = aq[i];
                    ap[i] = cs * x - sn * y;
                    aq[i] = sn * x + cs * y;
                }
                double *vp = v + p * c, *vq = v + q * c;
                for (size_t i = 0; i < c; i++) {
                    const double x = vp[i], y = vq[i];
                    vp[i] = cs * x - sn * y;
                    vq[i] = sn * x + cs * y;
                }
                s[p] -= t * ga;
                s[q] += t * ga;
                rotated = 1;
            }
        if (!rotated) {
            for (size_t j = 0; j < c; j++) s[j] = sqrt(dot(a + j * c, a + j * c, c));
            return 0;
        }
    }
    return -1;
}
#endif

/* GSL's SVD of the same R: gr, Golub-Reinsch (allocates per call: the
 * fallback), else its one-sided Jacobi (allocation-free).  A = R^T when
 * tr (Jacobi on the rows of R converges faster, Drmac & Veselic 2008),
 * else A = R; A = U S V^T leaves U in f->x, V in f->v (row-major), s in
 * f->s. */
static int gsl_svd(jf_fitter *f, size_t rows, size_t cols, int tr, int gr)
{
    double *a = f->x;
    for (size_t i = 0; i < cols; i++)
        for (size_t j = 0; j < cols; j++) {
            size_t r = tr ? j : i, c = tr ? i : j; /* a_ij = R_rc */
            a[i * cols + j] = c < r ? 0.0 : f->m[c * rows + r];
        }
    gsl_matrix_view u = gsl_matrix_view_array(a, cols, cols);
    gsl_matrix_view v = gsl_matrix_view_array(f->v, cols, cols);
    gsl_vector_view s = gsl_vector_view_array(f->s, cols);
    gsl_vector_view w = gsl_vector_view_array(f->work, cols);
    int rc = gr ? gsl_linalg_SV_decomp(&u.matrix, &v.matrix, &s.vector, &w.vector)
                : gsl_linalg_SV_decomp_jacobi(&u.matrix, &v.matrix, &s.vector);
    return rc == GSL_SUCCESS ? 0 : -1;
}

/* kappa = s_max / s_min of the singular values s (+Inf when singular).
 * Returns -1 when one is not finite (overflow in M', e.g. huge weights:
 * no fit), 1 when M' is rank deficient (s_min <= s_max rows eps), else 0. */
static int cond_of(const double *s, size_t rows, size_t cols, double *cond)
{
    double smax = 0, smin = INFINITY;
    for (size_t j = 0; j < cols; j++) {
        if (!isfinite(s[j])) {
            *cond = NAN;
            return -1;
        }
        smax = fmax(smax, s[j]);
        smin = fmin(smin, s[j]);
    }
    *cond = smax / smin;
    return !(smax > 0) || smin <= smax * (double)rows * DBL_EPSILON ? 1 : 0;
}

/* ---- the fast path: kappa from the eigenvalues of R^T R ----------------
 * A well-conditioned M' (the usual case: p99 of kappa is 15-50 on the
 * §6.1 surface) needs no singular vectors: the eigenvalues of the small
 * Gram matrix R^T R are the sigma_j^2 (only the extremes are needed:
 * gram_eig.c), and Y = R^-1 (Q^T B) by back-substitution.  Measured
 * (callgrind, jetfit estimate knn:16 d2): the Jacobi SVD with its vectors
 * was most of the fit's instructions.  kappa agrees with the SVD's to
 * 1e-12 relative below FAST_COND (test_gram_extremes).  Above it, and
 * within FAST_MARGIN of max_cond (where the verdict of the adaptive degree
 * could differ from the SVD's), the Jacobi SVD below decides. */
#define FAST_COND 1e3
#define FAST_MARGIN 1e-6

/* Eigenvalues d[0..n-1] (unsorted) of the symmetric n x n matrix a
 * (row-major, destroyed), n <= 55: Householder tridiagonalisation, then
 * the implicit QL iteration with Wilkinson's shift in the square-root-free
 * form of Pal, Walker and Kahan (Golub & Van Loan §8.3; LAPACK's dsterf,
 * QL branch): the rotations' chain of dependent operations is what bounds
 * its speed, and it has no sqrt (measured 10-15% faster than the plain
 * QL of Numerical Recipes' tqli, same eigenvalues to 2e-15 lambda_max).
 * e: n scratch (squared off-diagonals).  Returns 0, or -1 if an
 * eigenvalue took more than 30 iterations. */
int jf__sym_eigvals(double *a, size_t n, double *d, double *e)
{
    /* 1. A <- H A H, H = I - beta v v^T zeroing column k below k+1;
     *    with p = beta A v, q = p - (v.p / v.v) v: A <- A - v q^T - q v^T */
    for (size_t k = 0; k + 2 < n; k++) {
        const size_t m = n - k - 1, o = k + 1;
        double v[55], p[55], nx = 0;
        for (size_t i = 0; i < m; i++) {
            v[i] = a[(o + i) * n + k];
            nx += v[i] * v[i];
        }
        d[k] = a[k * n + k];
        e[k] = nx; /* the new off-diagonal is -+sqrt(nx): its square */
        if (nx == 0.0) continue;
        const double x0 = v[0], alpha = x0 > 0 ? -sqrt(nx) : sqrt(nx);
        v[0] = x0 - alpha;
        const double vv = 2.0 * (nx - x0 * alpha), beta = 2.0 / vv;
        double vp = 0;
        for (size_t i = 0; i < m; i++) {
            const double *ai = a + (o + i) * n + o;
            double t = 0;
            for (size_t j = 0; j < m; j++) t += ai[j] * v[j];
            p[i] = beta * t;
            vp += v[i] * p[i];
        }
        const double kq = vp / vv;
        for (size_t i = 0; i < m; i++) p[i] -= kq * v[i];
        for (size_t i = 0; i < m; i++) {
            double *ai = a + (o + i) * n + o;
            for (size_t j = 0; j < m; j++) ai[j] -= v[i] * p[j] + p[i] * v[j];
        }
    }
    if (n >= 2) {
        const double t = a[(n - 1) * n + n - 2];
        d[n - 2] = a[(n - 2) * n + n - 2];
        e[n - 2] = t * t;
    }
    d[n - 1] = a[(n - 1) * n + n - 1];
    e[n - 1] = 0.0;
    /* 2. QL on the tridiagonal (d, e = squared T[i+1][i]) */
    const double eps2 = DBL_EPSILON * DBL_EPSILON;
    for (size_t l = 0; l < n; l++) {
        for (int iter = 0;; iter++) {
            size_t m = l;
            for (; m + 1 < n; m++) { /* a negligible e[m] splits T */
                const double s = fabs(d[m]) + fabs(d[m + 1]);
                if (e[m] <= eps2 * s * s) break;
            }
            if (m == l) break;
            if (iter == 30) return -1;
            /* shift: the eigenvalue of the leading 2x2 nearer d[l] */
            const double rte = sqrt(e[l]);
            double sigma = (d[l + 1] - d[l]) / (2.0 * rte);
            double r = fabs(sigma) > 1e150 ? fabs(sigma) : sqrt(sigma * sigma + 1.0);
            sigma = d[l] - rte / (sigma + (sigma >= 0 ? r : -r));
            double c = 1.0, s = 0.0, gamma = d[m] - sigma, p = gamma * gamma;
            for (size_t i = m; i-- > l;) { /* c, s: squared cosine and sine */
                const double bb = e[i];
                r = p + bb;
                if (i + 1 != m) e[i + 1] = s * r;
                const double oldc = c, oldgam = gamma;
                c = p / r;
                s = bb / r;
                gamma = c * (d[i] - sigma) - s * oldgam;
                d[i + 1] = oldgam + (d[i] - gamma);
                p = c != 0.0 ? gamma * gamma / c : oldc * bb;
            }
            e[l] = s * p;
            d[l] = sigma + gamma;
        }
    }
    return 0;
}

/* After the QR: G = R^T R into f->x (cols <= 55). */
static inline __attribute__((always_inline)) void gram(jf_fitter *f, size_t rows, size_t cols)
{
    const double *m = f->m; /* R_ij = m[j*rows + i], i <= j */
    double *g = f->x;
    for (size_t i = 0; i < cols; i++) {
        const double *ri = m + i * rows;
        for (size_t j = i; j < cols; j++) { /* (R^T R)_ij = sum_{t<=i} R_ti R_tj */
            const double *rj = m + j * rows;
            double t = 0; /* short: plain loop, dot()'s set-up costs more */
            for (size_t k = 0; k <= i; k++) t += ri[k] * rj[k];
            g[i * cols + j] = g[j * cols + i] = t;
        }
    }
}

/* R y = c (R_ij = m[j*rows + i], i <= j), y into y.  Scalar loops: the
 * vectorised inner product loads y[j], y[j+1] whole just after y[j] was
 * stored alone (a store-forwarding stall on every row). */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-vectorize")))
#endif
static void back_subst(const double *m, const double *c, double *y, size_t rows, size_t cols)
{
    for (size_t i = cols; i-- > 0;) {
        double t = c[i];
        for (size_t j = i + 1; j < cols; j++) t -= m[j * rows + i] * y[j];
        y[i] = t / m[i * rows + i];
    }
}

/* With the eigenvalues of G in f->s: kappa, and Y by back-substitution on
 * R if kappa is safely small (above).  Returns 0, or -1 to leave it to
 * the SVD (R and Q^T B are left untouched). */
static int fast_finish(jf_fitter *f, size_t rows, size_t cols, double *cond)
{
    const double *m = f->m;
    double lmax = 0, lmin = INFINITY;
    for (size_t j = 0; j < cols; j++) {
        lmax = fmax(lmax, f->s[j]);
        lmin = fmin(lmin, f->s[j]);
    }
    if (!(lmin > 0) || !isfinite(lmax)) return -1;
    const double kappa = sqrt(lmax / lmin);
    if (!(kappa <= FAST_COND) || !(kappa < f->p.max_cond * (1.0 - FAST_MARGIN))) return -1;
    back_subst(m, f->rhs, f->tmp, rows, cols);
    for (size_t j = 0; j < cols; j++) f->sol[f->perm[j]] = f->tmp[j];
    *cond = kappa;
    return 0;
}

/* The SVD of R (after the QR, when the fast path declined). */
static int svd_rest(jf_fitter *f, size_t rows, size_t cols, double *cond);

int jf__fixed_sizes = 1;
int jf__no_avx = 0;

static inline __attribute__((always_inline)) int qr_gram(jf_fitter *f, size_t rows, size_t cols)
{
    /* knn:16 and knn:32 at degree 2 (6 columns) and knn:32 at degree 3 (10):
     * the same code with constant sizes, which the compiler unrolls; the
     * same operations in the same order, so the same bits */
    if (!jf__fixed_sizes)
        householder_qr(f->m, f->rhs, rows, cols, f->perm, f->tmp, f->work);
    else if (rows == 16 && cols == 6)
        householder_qr_16_6(f->m, f->rhs, f->perm, f->tmp, f->work);
    else if (rows == 32 && cols == 6)
        householder_qr_32_6(f->m, f->rhs, f->perm, f->tmp, f->work);
    else if (rows == 32 && cols == 10)
        householder_qr_32_10(f->m, f->rhs, f->perm, f->tmp, f->work);
    else
        householder_qr(f->m, f->rhs, rows, cols, f->perm, f->tmp, f->work);
#if !defined(JF_GSL_SVD) && !defined(JF_SVD_GSLJ)
    if (cols > 55) return 0;
    if (cols == 6 && jf__fixed_sizes) gram(f, rows, 6);
    else if (cols == 10 && jf__fixed_sizes) gram(f, rows, 10);
    else gram(f, rows, cols);
    return 1;
#else
    return 0;
#endif
}

/* qr_gram in the AVX build (fitter_internal.h): dot()'s four partial
 * sums in one register, the same bits */
#if JF_AVX_PATH
JF_AVX_FN static int qr_gram_avx(jf_fitter *f, size_t rows, size_t cols)
{
    int r = qr_gram(f, rows, cols);
    JF_AVX_LEAVE();
    return r;
}
#endif

/* Four QRs of the same constant size, step k of each in turn: each
 * fit's steps are one chain of dependent operations (norm, sqrt,
 * division, then the reflections), and the four chains side by side keep
 * the core busy where one left it waiting.  Each fit's operations are
 * householder_qr's, in its order: the same bits. */
#define QR_FIXED_X4(R, C)                                                                  \
    static inline __attribute__((always_inline)) void householder_qr_##R##_##C##_x4(       \
        jf_fitter *const f[4])                                                             \
    {                                                                                      \
        for (int L = 0; L < 4; L++)                                                        \
            qr_norms(f[L]->m, R, C, f[L]->perm, f[L]->tmp, f[L]->work);                    \
        QR_UNROLL(C) for (size_t k = 0; k < C; k++)                                        \
            QR_UNROLL(1) for (int L = 0; L < 4; L++)                                       \
                qr_step(f[L]->m, f[L]->rhs, R, C, k, f[L]->perm, f[L]->tmp, f[L]->work);   \
        for (int L = 0; L < 4; L++) gram(f[L], R, C);                                      \
    }
QR_FIXED_X4(16, 6)
QR_FIXED_X4(32, 6)
QR_FIXED_X4(32, 10)

static inline __attribute__((always_inline)) void qr_gram_x4(jf_fitter *const f[4], size_t rows,
                                                             size_t cols)
{
    if (rows == 16 && cols == 6) householder_qr_16_6_x4(f);
    else if (rows == 32 && cols == 6) householder_qr_32_6_x4(f);
    else householder_qr_32_10_x4(f);
}

#if JF_AVX_PATH
JF_AVX_FN static void qr_gram_x4_avx(jf_fitter *const f[4], size_t rows, size_t cols)
{
    qr_gram_x4(f, rows, cols);
    JF_AVX_LEAVE();
}
#endif

int jf__qr_gram_x4(jf_fitter *const f[4], size_t rows, size_t cols)
{
#if !defined(JF_GSL_SVD) && !defined(JF_SVD_GSLJ)
    if (jf__fixed_sizes && ((rows == 16 && cols == 6) || (rows == 32 && (cols == 6 || cols == 10)))) {
#if JF_AVX_PATH
        if (JF_HAVE_AVX()) qr_gram_x4_avx(f, rows, cols);
        else
#endif
            qr_gram_x4(f, rows, cols);
        return 1;
    }
#endif
    int r = 1;
    for (int L = 0; L < 4; L++) r = jf__qr_gram(f[L], rows, cols);
    return r;
}

int jf__qr_gram(jf_fitter *f, size_t rows, size_t cols)
{
#if JF_AVX_PATH
    if (JF_HAVE_AVX()) return qr_gram_avx(f, rows, cols);
#endif
    return qr_gram(f, rows, cols);
}

int jf__solve_after_eig(jf_fitter *f, size_t rows, size_t cols, int have_eig, double *cond)
{
    if (have_eig && fast_finish(f, rows, cols, cond) == 0) return 0;
    return svd_rest(f, rows, cols, cond);
}

int jf__svd_solve(jf_fitter *f, size_t rows, size_t cols, double *cond)
{
    /* 1. Householder QR: M' = QR, rhs <- Q^T rhs.  2. The fast path, or
     * the SVD of the small triangle R (same singular values as M').
     * 3. Y = R^-1 rhs. */
    int have = jf__qr_gram(f, rows, cols);
    return jf__solve_after_eig(f, rows, cols, have && jf__eigvals(f, cols), cond);
}

static int svd_rest(jf_fitter *f, size_t rows, size_t cols, double *cond)
{
#if !defined(JF_GSL_SVD) && !defined(JF_SVD_GSLJ)
    /* X = R^T, column-major, into f->x: column j of X is row j of R,
     * R_ji = m[i*rows + j] for i >= j.  Jacobi on R^T (rows of R) converges
     * in fewer sweeps than on R (Drmac & Veselic 2008, the QR-preconditioned
     * one-sided Jacobi).  X V = U S gives R = V S U^T: the solve below uses
     * X_final (= U S) as R's right factor and V as its left one. */
    for (size_t j = 0; j < cols; j++)
        for (size_t i = 0; i < cols; i++) f->x[j * cols + i] = i >= j ? f->m[i * rows + j] : 0.0;
    if (jacobi_svd(f->x, f->v, f->s, cols) == 0) {
        int rc = cond_of(f->s, rows, cols, cond);
        if (rc != 0) return rc;
        /* R = V S U^T with U S = X: Y = R^-1 rhs = sum_j x_j (v_j . rhs) / s_j^2 */
        for (size_t i = 0; i < cols; i++) f->tmp[i] = 0.0;
        for (size_t j = 0; j < cols; j++) {
            double d = 0;
            for (size_t i = 0; i < cols; i++) d += f->v[j * cols + i] * f->rhs[i];
            d /= f->s[j] * f->s[j];
            for (size_t i = 0; i < cols; i++) f->tmp[i] += d * f->x[j * cols + i];
        }
        for (size_t j = 0; j < cols; j++) f->sol[f->perm[j]] = f->tmp[j];
        return 0;
    }
#endif
    int tr = 0;
#if defined(JF_SVD_GSLJ)
    tr = 1;
    if (gsl_svd(f, rows, cols, tr, 0) != 0)
#endif
    {
        tr = 0;
        if (gsl_svd(f, rows, cols, 0, 1) != 0) {
            *cond = NAN;
            return -1;
        }
    }
    int rc = cond_of(f->s, rows, cols, cond);
    if (rc != 0) return rc;
    /* R = L S T^T, L = U, T = V (A = R) or L = V, T = U (A = R^T):
     * Y = T S^-1 L^T rhs (gsl_linalg_SV_solve would allocate) */
    const double *l = tr ? f->v : f->x, *t = tr ? f->x : f->v;
    for (size_t j = 0; j < cols; j++) {
        double acc = 0;
        for (size_t i = 0; i < cols; i++) acc += l[i * cols + j] * f->rhs[i];
        f->work[j] = acc / f->s[j];
    }
    for (size_t i = 0; i < cols; i++) {
        double acc = 0;
        for (size_t j = 0; j < cols; j++) acc += t[i * cols + j] * f->work[j];
        f->sol[f->perm[i]] = acc;
    }
    return 0;
}
