/* jet.c -- the fitter workspace and the jet fit of one point (§2, §5.2).
 *
 * design, per point:
 *  1. translate the neighbours to p (p is the origin of the fit), drop the
 *     non-finite ones and those of weight 0;
 *  2. fitting frame (frame.c): PCA of the neighbours or the world axis;
 *  3. for d = degree down to 1 (adaptive degree, §5.2 last paragraph):
 *     rows = all points (approximation) or the N_d nearest (interpolation);
 *     precondition (§2.3): h = mean ||(x_i, y_i)||, column x^i y^j scaled
 *     by 1/h^(i+j); least squares and kappa of M' (solve.c); stop at the
 *     first d whose M' has full rank and kappa = sigma_max/sigma_min <=
 *     max_cond, else record why;
 *  4. A_ij = Y_ij / h^(i+j); quantities (monge.c); residuals.
 * Nothing is allocated after jf_fitter_create. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

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

    /* 4. unscale A_ij = Y_ij / h^(i+j); residuals; quantities.  With
     * h = m 2^q, h^k = m^k 2^(qk) exactly, so Y / m^k then a power of two
     * gives the same bits as Y / h^k without h^k ever under- or
     * overflowing (lengths near 1e+-150), and scales exactly with h. */
    {
        int c = 0, q;
        double m = frexp(h, &q), mk = 1.0;
        for (int k = 0; k <= deg; k++, mk *= m)
            for (int j = 0; j <= k; j++, c++) f->coef[c] = ldexp(f->sol[c] / mk, -q * k);
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
    jf__quantities(f->coef, deg, f->p.monge_degree, r, h, out);
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
