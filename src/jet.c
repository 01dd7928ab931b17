/* jet.c -- the fitter workspace and the jet fit of one point (§2, §5.2).
 *
 * design, per point:
 *  1. translate the neighbours to p (p is the origin of the fit), drop the
 *     non-finite ones and those of weight 0;
 *  2. fitting frame (frame.c): PCA of the neighbours or the world axis;
 *  3. for d = degree down to 1 (adaptive degree, §5.2 last paragraph):
 *     rows = all points (approximation) or the N_d nearest (interpolation);
 *     precondition (§2.3): h = mean ||(x_i, y_i)||, column x^i y^j scaled
 *     by 1/h^(i+j); SVD of M' (below); stop at the first d whose M' has
 *     full rank and kappa = sigma_max/sigma_min <= max_cond, else record
 *     why;
 *  4. A_ij = Y_ij / h^(i+j); quantities (monge.c); residuals.
 * Nothing is allocated after jf_fitter_create.
 *
 * The SVD: M' = QR (pivoted Householder, ours), then the SVD of the small
 * R by one-sided Jacobi (ours), GSL's gsl_linalg_SV_decomp as the fallback
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
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>

#include "fitter_internal.h"

static pthread_once_t gsl_once = PTHREAD_ONCE_INIT;
static void gsl_init_once(void) { gsl_set_error_handler_off(); }

/* GSL's default handler aborts; the library validates every input first,
 * and turns the handler off once per process (process-wide: a program that
 * installs its own handler after creating a fitter overrides this). */
void jf__gsl_init(void) { pthread_once(&gsl_once, gsl_init_once); }

void jf_fitter_free(jf_fitter *f)
{
    if (!f) return;
    free(f->loc);
    free(f->w);
    free(f->dist);
    free(f->order);
    free(f->m);
    free(f->v);
    free(f->x);
    free(f->s);
    free(f->work);
    free(f->rhs);
    free(f->sol);
    free(f);
}

jf_status jf_fitter_create(const jf_params *p, jf_fitter **out)
{
    if (!out) return JF_ERR_INVALID;
    *out = NULL;
    jf_status st = jf_params_validate(p, NULL);
    if (st != JF_OK) return st;
    jf__gsl_init();
    jf_fitter *f = calloc(1, sizeof *f);
    if (!f) return JF_ERR_NOMEM;
    f->p = *p;
    f->maxn = p->max_neighbors;
    f->maxc = jf_jet_size(p->degree);
    if (f->maxc < JF_CURVE_COLS) f->maxc = JF_CURVE_COLS;
    size_t rows = f->maxn > f->maxc ? f->maxn : f->maxc;
    f->loc = malloc(3 * rows * sizeof(double));
    f->w = malloc(rows * sizeof(double));
    f->dist = malloc(rows * sizeof(double));
    f->order = malloc(rows * sizeof(uint32_t));
    f->m = malloc(rows * f->maxc * sizeof(double));
    f->v = malloc(f->maxc * f->maxc * sizeof(double));
    f->x = malloc(f->maxc * f->maxc * sizeof(double));
    f->s = malloc(f->maxc * sizeof(double));
    f->work = malloc(f->maxc * sizeof(double));
    f->rhs = malloc(rows * sizeof(double));
    f->sol = malloc(f->maxc * sizeof(double));
    if (!f->loc || !f->w || !f->dist || !f->order || !f->m || !f->v || !f->x || !f->s ||
        !f->work || !f->rhs || !f->sol) {
        jf_fitter_free(f);
        return JF_ERR_NOMEM;
    }
    *out = f;
    return JF_OK;
}

const jf_params *jf_fitter_params(const jf_fitter *f) { return f ? &f->p : NULL; }

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
    for (; i < n; i++) s0 += x[i] * y[i];
    return (s0 + s1) + (s2 + s3);
}

/* Householder QR with column pivoting (Businger & Golub; Golub & Van Loan
 * §5.4.1) of the rows x cols matrix a, stored column-major (column j at
 * a + j*rows, contiguous for the inner loops), applied to b in the same
 * sweep: on return the upper cols x cols triangle of a is R, column j of
 * R being original column perm[j], and b[0..cols-1] is (Q^T b)[0..].
 * R has the singular values of a, so the SVD that follows is only cols x
 * cols; pivoting makes R graded (Drmac & Veselic: fewer Jacobi sweeps).
 * nrm, nrm0: cols scratch doubles for the pivoting norms. */
static void householder_qr(double *a, double *b, size_t rows, size_t cols, int *perm,
                           double *nrm, double *nrm0)
{
    for (size_t j = 0; j < cols; j++) {
        perm[j] = (int)j;
        nrm[j] = nrm0[j] = dot(a + j * rows, a + j * rows, rows);
    }
    for (size_t k = 0; k < cols; k++) {
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
        if (nrm2 == 0.0) continue; /* zero column: R_kk = 0 */
        const double akk = ak[k];
        const double alpha = akk > 0 ? -sqrt(nrm2) : sqrt(nrm2);
        ak[k] = akk - alpha; /* v = ak[k..rows-1] */
        const double tau = 2.0 / (nrm2 - akk * akk + ak[k] * ak[k]);
        for (size_t j = k + 1; j <= cols; j++) { /* j == cols: the rhs */
            double *aj = j < cols ? a + j * rows : b;
            const double sdot = tau * dot(ak + k, aj + k, rows - k);
            for (size_t i = k; i < rows; i++) aj[i] -= sdot * ak[i];
            if (j < cols) nrm[j] -= aj[k] * aj[k];
        }
        ak[k] = alpha;
    }
}

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

int jf__svd_solve(jf_fitter *f, size_t rows, size_t cols, double *cond)
{
    /* 1. Householder QR: M' = QR, rhs <- Q^T rhs.  2. SVD of the small
     * triangle R (same singular values as M').  3. Y = R^-1 rhs. */
    householder_qr(f->m, f->rhs, rows, cols, f->perm, f->tmp, f->work);
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

/* x^(k-j) y^j for k <= d, j <= k, in the jet's column order. */
static inline void monomials(double x, double y, int d, double *mon)
{
    double xp[JF_MAX_DEGREE + 1], yp[JF_MAX_DEGREE + 1];
    xp[0] = yp[0] = 1.0;
    for (int k = 1; k <= d; k++) {
        xp[k] = xp[k - 1] * x;
        yp[k] = yp[k - 1] * y;
    }
    int c = 0;
    for (int k = 0; k <= d; k++)
        for (int j = 0; j <= k; j++) mon[c++] = xp[k - j] * yp[j];
}

/* Usable points nearest first, ties by index (deterministic). */
static void sort_by_distance(const double *dist, uint32_t *order, size_t cnt)
{
    for (size_t i = 1; i < cnt; i++) {
        uint32_t o = order[i];
        size_t j = i;
        while (j > 0 && (dist[order[j - 1]] > dist[o] ||
                         (dist[order[j - 1]] == dist[o] && order[j - 1] > o))) {
            order[j] = order[j - 1];
            j--;
        }
        order[j] = o;
    }
}

static void fail_result(jf_result *out, unsigned flags)
{
    out->status |= flags;
    out->degree = 0;
    out->residual = NAN;
    jf__result_nan(out);
}

jf_status jf_fit_point_weighted(jf_fitter *f, const double p[3], const double *nbr,
                                const double *w, size_t n, jf_result *out)
{
    if (!f || !p || !out || (n > 0 && !nbr)) return JF_ERR_INVALID;
    if (n > f->maxn) return JF_ERR_TOO_LARGE;
    if (w)
        for (size_t i = 0; i < n; i++)
            if (!(w[i] >= 0) || !isfinite(w[i])) return JF_ERR_INVALID;

    memset(out, 0, sizeof *out);
    out->cond = NAN;
    f->last_n = n;
    f->have_last = 1;
    f->last_deg = 0;
    for (int k = 0; k < 3; k++) out->pca_eval[k] = NAN;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
        fail_result(out, JF_PT_NONFINITE);
        return JF_OK;
    }

    /* 1. translate to p; unusable points get weight 0 */
    size_t usable = 0;
    for (size_t i = 0; i < n; i++) {
        double q0 = nbr[3 * i] - p[0], q1 = nbr[3 * i + 1] - p[1], q2 = nbr[3 * i + 2] - p[2];
        double wi = w ? w[i] : 1.0;
        int ok = isfinite(q0) && isfinite(q1) && isfinite(q2);
        f->loc[3 * i] = q0;
        f->loc[3 * i + 1] = q1;
        f->loc[3 * i + 2] = q2;
        f->w[i] = ok ? wi : 0.0;
        if (f->w[i] > 0) f->order[usable++] = (uint32_t)i;
    }
    out->n_used = (int)usable;
    if (usable < 3) {
        fail_result(out, JF_PT_LOWERED_FEW | JF_PT_FAILED);
        return JF_OK;
    }

    /* 2. fitting frame; local coordinates */
    double r[9];
    if (jf__frame(f->loc, f->w, n, f->p.frame, r, out->pca_eval) != 0) {
        fail_result(out, JF_PT_FAILED);
        return JF_OK;
    }
    for (size_t i = 0; i < n; i++) {
        double *q = f->loc + 3 * i;
        double x = r[0] * q[0] + r[1] * q[1] + r[2] * q[2];
        double y = r[3] * q[0] + r[4] * q[1] + r[5] * q[2];
        double z = r[6] * q[0] + r[7] * q[1] + r[8] * q[2];
        q[0] = x;
        q[1] = y;
        q[2] = z;
    }
    const int interp = f->p.fit == JF_FIT_INTERP;
    if (interp) {
        for (size_t t = 0; t < usable; t++) {
            const double *q = f->loc + 3 * f->order[t];
            f->dist[f->order[t]] = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
        }
        sort_by_distance(f->dist, f->order, usable);
        /* interpolation needs distinct points: an exact duplicate (same
         * distance, same coordinates as a point kept before) is skipped,
         * else it would make every degree rank deficient */
        size_t kept = 0;
        for (size_t t = 0; t < usable; t++) {
            const uint32_t i = f->order[t];
            const double *q = f->loc + 3 * i;
            int dup = 0;
            for (size_t u = kept; u-- > 0 && f->dist[f->order[u]] == f->dist[i];) {
                const double *o = f->loc + 3 * f->order[u];
                if (o[0] == q[0] && o[1] == q[1] && o[2] == q[2]) {
                    dup = 1;
                    break;
                }
            }
            if (!dup) f->order[kept++] = i;
        }
        usable = kept;
    }

    /* 3. adaptive degree */
    int deg = 0;
    size_t rows = 0;
    double h = 0, mon[55];
    for (int d = f->p.degree; d >= 1; d--) {
        size_t cols = jf_jet_size(d);
        if (usable < cols) {
            out->status |= JF_PT_LOWERED_FEW;
            continue;
        }
        rows = interp ? cols : usable;
        h = 0;
        for (size_t t = 0; t < rows; t++) {
            const double *q = f->loc + 3 * f->order[t];
            h += sqrt(q[0] * q[0] + q[1] * q[1]);
        }
        h /= (double)rows;
        if (!(h > 0) || !isfinite(h)) { /* every point on the z axis */
            out->status |= JF_PT_LOWERED_RANK;
            out->cond = INFINITY;
            continue;
        }
        const double ih = 1.0 / h;
        for (size_t t = 0; t < rows; t++) {
            size_t i = f->order[t];
            const double *q = f->loc + 3 * i;
            monomials(q[0] * ih, q[1] * ih, d, mon);
            const double wi = f->w[i];
            for (size_t c = 0; c < cols; c++) f->m[c * rows + t] = wi * mon[c];
            f->rhs[t] = wi * q[2];
        }
        int rc = jf__svd_solve(f, rows, cols, &out->cond);
        if (rc != 0) {
            out->status |= JF_PT_LOWERED_RANK;
            continue;
        }
        if (out->cond > f->p.max_cond) {
            out->status |= JF_PT_LOWERED_COND;
            continue;
        }
        deg = d;
        break;
    }
    if (deg == 0) {
        fail_result(out, JF_PT_FAILED);
        out->n_used = (int)usable;
        return JF_OK;
    }

    /* 4. unscale A_ij = Y_ij / h^(i+j); residuals; quantities */
    {
        int c = 0;
        double hk = 1.0;
        for (int k = 0; k <= deg; k++, hk *= h)
            for (int j = 0; j <= k; j++, c++) f->coef[c] = f->sol[c] / hk;
    }
    const size_t cols = jf_jet_size(deg);
    /* weighted residual norm for free: after the QR, the components
     * rows cols.. of Q^T b are the residual in an orthonormal basis */
    double sw2 = 0, sr2 = 0;
    for (size_t t = 0; t < rows; t++) sw2 += f->w[f->order[t]] * f->w[f->order[t]];
    for (size_t t = cols; t < rows; t++) sr2 += f->rhs[t] * f->rhs[t];
    f->last_h = h;
    memcpy(f->frame, r, sizeof r);
    f->last_deg = deg;
    out->degree = deg;
    out->n_used = (int)rows;
    out->residual = sqrt(sr2 / sw2);
    for (size_t c = 0; c < cols; c++)
        if (!isfinite(f->coef[c])) {
            fail_result(out, JF_PT_FAILED);
            return JF_OK;
        }
    jf__quantities(f->coef, deg, f->p.monge_degree, r, out);
    return JF_OK;
}

jf_status jf_fit_point(jf_fitter *f, const double p[3], const double *nbr, size_t n,
                       jf_result *out)
{
    return jf_fit_point_weighted(f, p, nbr, NULL, n, out);
}

jf_status jf_fitter_residuals(const jf_fitter *f, double *res, size_t n)
{
    if (!f || (n > 0 && !res) || !f->have_last || n != f->last_n) return JF_ERR_INVALID;
    /* computed on demand from the last fit's local points and scaled
     * solution Y (J(x,y) = sum Y_ij (x/h)^i (y/h)^j), kept in the fitter */
    const int deg = f->last_deg;
    const size_t cols = jf_jet_size(deg);
    const double ih = deg > 0 ? 1.0 / f->last_h : 0.0;
    double mon[55];
    for (size_t i = 0; i < n; i++) {
        const double *q = f->loc + 3 * i;
        if (deg == 0 || !isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
            res[i] = NAN;
            continue;
        }
        monomials(q[0] * ih, q[1] * ih, deg, mon);
        double z = 0;
        for (size_t c = 0; c < cols; c++) z += f->sol[c] * mon[c];
        res[i] = q[2] - z;
    }
    return JF_OK;
}
