/* jet.c -- the fitter workspace and the jet fit of one point (§2, §5.2).
 *
 * design, per point:
 *  1. translate the neighbours to p (p is the origin of the fit), drop the
 *     non-finite ones and those of weight 0;
 *  2. fitting frame (frame.c): PCA of the neighbours or the world axis;
 *  3. for d = degree down to 1 (adaptive degree, §5.2 last paragraph):
 *     rows = all points (approximation) or the N_d nearest (interpolation);
 *     precondition (§2.3): h = mean ||(x_i, y_i)||, column x^i y^j scaled
 *     by 1/h^(i+j); SVD of M' (GSL); stop at the first d whose M' has full
 *     rank and kappa = sigma_max/sigma_min <= max_cond, else record why;
 *  4. A_ij = Y_ij / h^(i+j); quantities (monge.c); residuals.
 * Nothing is allocated after jf_fitter_create. */
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
    free(f->res);
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
    f->res = malloc(rows * sizeof(double));
    if (!f->loc || !f->w || !f->dist || !f->order || !f->m || !f->v || !f->x || !f->s ||
        !f->work || !f->rhs || !f->sol || !f->res) {
        jf_fitter_free(f);
        return JF_ERR_NOMEM;
    }
    *out = f;
    return JF_OK;
}

const jf_params *jf_fitter_params(const jf_fitter *f) { return f ? &f->p : NULL; }

/* Householder QR of the rows x cols matrix a, stored column-major (column
 * j at a + j*rows, contiguous for the inner loops), applied to b in the
 * same sweep (Golub & Van Loan §5.2): on return the upper cols x cols
 * triangle of a is R and b[0..cols-1] is (Q^T b)[0..cols-1].  R has the
 * singular values of a, so the SVD that follows is only cols x cols. */
static void householder_qr(double *a, double *b, size_t rows, size_t cols)
{
    for (size_t k = 0; k < cols; k++) {
        double *ak = a + k * rows;
        double nrm2 = 0;
        for (size_t i = k; i < rows; i++) nrm2 += ak[i] * ak[i];
        if (nrm2 == 0.0) continue; /* zero column: R_kk = 0 */
        const double akk = ak[k];
        const double alpha = akk > 0 ? -sqrt(nrm2) : sqrt(nrm2);
        ak[k] = akk - alpha; /* v = ak[k..rows-1] */
        const double tau = 2.0 / (nrm2 - akk * akk + ak[k] * ak[k]);
        for (size_t j = k + 1; j <= cols; j++) { /* j == cols: the rhs */
            double *aj = j < cols ? a + j * rows : b;
            double sdot = 0;
            for (size_t i = k; i < rows; i++) sdot += ak[i] * aj[i];
            sdot *= tau;
            for (size_t i = k; i < rows; i++) aj[i] -= sdot * ak[i];
        }
        ak[k] = alpha;
    }
}

int jf__svd_solve(jf_fitter *f, size_t rows, size_t cols, double *cond)
{
    /* QR first (ours, plain loops on the workspace), then GSL's SVD of the
     * small triangle R: the same singular values as M', a fraction of the
     * cost of GSL's SVD of the tall matrix for N >> N_n. */
    householder_qr(f->m, f->rhs, rows, cols);
    double *r = f->x;
    for (size_t i = 0; i < cols; i++)
        for (size_t j = 0; j < cols; j++) r[i * cols + j] = j < i ? 0.0 : f->m[j * rows + i];
    gsl_matrix_view u = gsl_matrix_view_array(r, cols, cols);
    gsl_matrix_view v = gsl_matrix_view_array(f->v, cols, cols);
    gsl_vector_view s = gsl_vector_view_array(f->s, cols);
    gsl_vector_view w = gsl_vector_view_array(f->work, cols);
    if (gsl_linalg_SV_decomp(&u.matrix, &v.matrix, &s.vector, &w.vector) != GSL_SUCCESS) {
        *cond = NAN;
        return -1;
    }
    const double smax = f->s[0], smin = f->s[cols - 1];
    *cond = smax / smin; /* +Inf when singular */
    /* numerical rank test of LAPACK/numpy: sigma_min <= sigma_max max(m,n) eps */
    if (!(smax > 0) || smin <= smax * (double)rows * DBL_EPSILON) return 1;
    /* Y = V S^-1 U^T (Q^T b); gsl_linalg_SV_solve would allocate */
    double *t = f->work;
    for (size_t j = 0; j < cols; j++) {
        double acc = 0;
        for (size_t i = 0; i < cols; i++) acc += r[i * cols + j] * f->rhs[i];
        t[j] = acc / f->s[j];
    }
    for (size_t i = 0; i < cols; i++) {
        double acc = 0;
        for (size_t j = 0; j < cols; j++) acc += f->v[i * cols + j] * t[j];
        f->sol[i] = acc;
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
    for (size_t i = 0; i < n; i++) f->res[i] = NAN;
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
    const double ih = 1.0 / h;
    double sw2 = 0, sr2 = 0;
    for (size_t i = 0; i < n; i++) {
        const double *q = f->loc + 3 * i;
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
        monomials(q[0] * ih, q[1] * ih, deg, mon);
        double z = 0;
        for (size_t c = 0; c < cols; c++) z += f->sol[c] * mon[c];
        f->res[i] = q[2] - z;
    }
    for (size_t t = 0; t < rows; t++) {
        size_t i = f->order[t];
        double w2 = f->w[i] * f->w[i];
        sw2 += w2;
        sr2 += w2 * f->res[i] * f->res[i];
    }
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
    if (n > 0) memcpy(res, f->res, n * sizeof *res);
    return JF_OK;
}
