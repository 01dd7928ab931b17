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
    if (f->ext_free) f->ext_free(f->ext);
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

/* A fit in progress, in the steps the design above lists; the steps are
 * functions so that two fits can run side by side (jf__fit_point_x2) and
 * share the SIMD lanes of their eigen-solvers. */
typedef struct {
    jf_fitter *f;
    jf_result *out;
    size_t n, usable, rows;
    int interp, d;
    double h;
    double r[9];
    double cov[9];
} fit_job;

static jf_status check_args(jf_fitter *f, const double p[3], const double *nbr, const double *w,
                            size_t n, jf_result *out)
{
    if (!f || !p || !out || (n > 0 && !nbr)) return JF_ERR_INVALID;
    if (n > f->maxn) return JF_ERR_TOO_LARGE;
    if (w)
        for (size_t i = 0; i < n; i++)
            if (!(w[i] >= 0) || !isfinite(w[i])) return JF_ERR_INVALID;
    return JF_OK;
}

/* Step 1 and the covariance of step 2.  Returns 1 to go on with the
 * eigen-decomposition of j->cov, 0 when out is final. */
static int job_begin(fit_job *j, jf_fitter *f, const double p[3], const double *nbr,
                     const double *w, size_t n, jf_result *out)
{
    j->f = f;
    j->out = out;
    j->n = n;
    memset(out, 0, sizeof *out);
    out->cond = NAN;
    out->sigma = NAN;
    f->last_n = n;
    f->have_last = 1;
    f->last_deg = 0;
    memcpy(f->last_p, p, sizeof f->last_p);
    for (int k = 0; k < 3; k++) out->pca_eval[k] = NAN;
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
        fail_result(out, JF_PT_NONFINITE);
        return 0;
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
    j->usable = usable;
    out->n_used = (int)usable;
    if (usable < 3) {
        fail_result(out, JF_PT_LOWERED_FEW | JF_PT_FAILED);
        return 0;
    }
    /* 2. fitting frame: its covariance */
    if (jf__frame_cov(f->loc, f->w, n, j->cov) != 0) {
        fail_result(out, JF_PT_FAILED);
        return 0;
    }
    return 1;
}

typedef double jet_v2d __attribute__((vector_size(16)));

/* M' and B of degree d (§2.3) column by column, each column contiguous
 * over the rows (vector loops): column (a, b) = w (x^a y^b) of the scaled
 * coordinates, the products of monomials() in the same order, so the bits
 * are its; powers are built in the pure columns before they are weighted.
 * Column of x^a y^b: (a + b)(a + b + 1)/2 + b. */
static inline __attribute__((always_inline)) void design(jf_fitter *f, size_t rows, int d, double ih)
{
    double *m = f->m, *w = m, *x = m + rows, *y = m + 2 * rows;
    /* two rows at a time, stored as pairs: the vector loops below (and
     * the QR's) load these pairs back at once, and a pair loaded from two
     * scalar stores just made cannot be forwarded (a stall per load) */
    size_t t = 0;
    for (; t + 2 <= rows; t += 2) {
        const size_t i0 = f->order[t], i1 = f->order[t + 1];
        const double *q0 = f->loc + 3 * i0, *q1 = f->loc + 3 * i1;
        const jet_v2d wv = {f->w[i0], f->w[i1]}; /* w (1 * 1) */
        const jet_v2d xv = (jet_v2d){q0[0], q1[0]} * ih, yv = (jet_v2d){q0[1], q1[1]} * ih;
        const jet_v2d bv = wv * (jet_v2d){q0[2], q1[2]};
        memcpy(w + t, &wv, sizeof wv);
        memcpy(x + t, &xv, sizeof xv);
        memcpy(y + t, &yv, sizeof yv);
        memcpy(f->rhs + t, &bv, sizeof bv);
    }
    for (; t < rows; t++) {
        const size_t i = f->order[t];
        const double *q = f->loc + 3 * i;
        w[t] = f->w[i];
        x[t] = q[0] * ih;
        y[t] = q[1] * ih;
        f->rhs[t] = f->w[i] * q[2];
    }
    for (int k = 2; k <= d; k++) {
        double *xk = m + (size_t)(k * (k + 1) / 2) * rows, *yk = xk + (size_t)k * rows;
        const double *xp = m + (size_t)((k - 1) * k / 2) * rows, *yp = xp + (size_t)(k - 1) * rows;
        for (size_t t = 0; t < rows; t++) {
            xk[t] = xp[t] * x[t];
            yk[t] = yp[t] * y[t];
        }
    }
    for (int k = 2; k <= d; k++)
        for (int b = 1; b < k; b++) {
            const int a = k - b;
            double *c = m + (size_t)(k * (k + 1) / 2 + b) * rows;
            const double *xa = m + (size_t)(a * (a + 1) / 2) * rows;
            const double *yb = m + (size_t)(b * (b + 1) / 2 + b) * rows;
            for (size_t t = 0; t < rows; t++) c[t] = w[t] * (xa[t] * yb[t]);
        }
    for (int k = 1; k <= d; k++) {
        double *xk = m + (size_t)(k * (k + 1) / 2) * rows, *yk = xk + (size_t)k * rows;
        for (size_t t = 0; t < rows; t++) {
            xk[t] *= w[t];
            yk[t] *= w[t];
        }
    }
}

static int job_system(fit_job *j);
static int job_system_ex(fit_job *j, int defer);

/* h, the mean distance of the rows to the z axis (§2.3's scale), then M'
 * and B of degree d scaled by it (design); returns h, and leaves M' unmade
 * when h is not a positive finite number. */
static inline __attribute__((always_inline)) double scaled_system(jf_fitter *f, size_t rows, int d)
{
    double h = 0;
    for (size_t t = 0; t < rows; t++) {
        const double *q = f->loc + 3 * f->order[t];
        h += sqrt(q[0] * q[0] + q[1] * q[1]);
    }
    h /= (double)rows;
    if (h > 0 && isfinite(h)) design(f, rows, d, 1.0 / h);
    return h;
}

/* scaled_system with the common sizes as constants (k-NN of 16 and 32 at
 * degree 2 and 3), which the compiler unrolls: the same bits. */
static double scaled_system_any(jf_fitter *f, size_t rows, int d)
{
    if (!jf__fixed_sizes) return scaled_system(f, rows, d);
    if (rows == 16 && d == 2) return scaled_system(f, 16, 2);
    if (rows == 32 && d == 2) return scaled_system(f, 32, 2);
    if (rows == 32 && d == 3) return scaled_system(f, 32, 3);
    return scaled_system(f, rows, d);
}

/* The rest of step 2 (the frame from the eigenvectors evec of j->cov;
 * out->pca_eval holds the eigenvalues), then the first system of step 3.
 * Returns as job_system_ex. */
static int job_frame_ex(fit_job *j, const double evec[9], int defer)
{
    jf_fitter *f = j->f;
    const size_t n = j->n;
    double *r = j->r;
    jf__frame_axes(evec, f->p.frame, r);
    for (size_t i = 0; i < n; i++) {
        double *q = f->loc + 3 * i;
        double x = r[0] * q[0] + r[1] * q[1] + r[2] * q[2];
        double y = r[3] * q[0] + r[4] * q[1] + r[5] * q[2];
        double z = r[6] * q[0] + r[7] * q[1] + r[8] * q[2];
        q[0] = x;
        q[1] = y;
        q[2] = z;
    }
    j->interp = f->p.fit == JF_FIT_INTERP;
    if (j->interp) {
        size_t usable = j->usable;
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
        j->usable = kept;
    }
    j->d = f->p.degree;
    return job_system_ex(j, defer);
}

static int job_frame(fit_job *j, const double evec[9]) { return job_frame_ex(j, evec, 0); }

/* 3. adaptive degree: from degree j->d down, the first whose system can
 * be set up; its scaled M' and B, then the QR (jf__qr_gram).  Returns 1
 * (G = R^T R is in f->x for the eigenvalues), 2 (QR done, no eigenvalues
 * wanted), or 0 when no degree is left (out is final); with defer, 3
 * instead of the QR (M' and B made, j->rows set: the caller's QR). */
static int job_system(fit_job *j) { return job_system_ex(j, 0); }

static int job_system_ex(fit_job *j, int defer)
{
    jf_fitter *f = j->f;
    jf_result *out = j->out;
    for (; j->d >= 1; j->d--) {
        const int d = j->d;
        size_t cols = jf_jet_size(d);
        if (j->usable < cols) {
            out->status |= JF_PT_LOWERED_FEW;
            continue;
        }
        size_t rows = j->interp ? cols : j->usable;
        const double h = scaled_system_any(f, rows, d);
        if (!(h > 0) || !isfinite(h)) { /* every point on the z axis */
            out->status |= JF_PT_LOWERED_RANK;
            out->cond = INFINITY;
            continue;
        }
        j->rows = rows;
        j->h = h;
        if (defer) return 3;
        return jf__qr_gram(f, rows, cols) ? 1 : 2;
    }
    fail_result(out, JF_PT_FAILED);
    out->n_used = (int)j->usable;
    return 0;
}

static void job_finish(fit_job *j);

/* After the solve of degree j->d (rc as jf__svd_solve's): keep it and
 * finish (returns 0), or lower the degree (returns as job_system). */
static int job_solved(fit_job *j, int rc)
{
    jf_result *out = j->out;
    if (rc != 0) {
        out->status |= JF_PT_LOWERED_RANK;
        j->d--;
        return job_system(j);
    }
    if (out->cond > j->f->p.max_cond) {
        out->status |= JF_PT_LOWERED_COND;
        j->d--;
        return job_system(j);
    }
    job_finish(j);
    return 0;
}

/* The solve of the current system, after job_system returned st. */
static int job_solve(fit_job *j, int st, int have_eig)
{
    const size_t cols = jf_jet_size(j->d);
    return jf__solve_after_eig(j->f, j->rows, cols, st == 1 && have_eig, &j->out->cond);
}

/* 4. unscale A_ij = Y_ij / h^(i+j); residuals; quantities. */
static void job_finish(fit_job *j)
{
    jf_fitter *f = j->f;
    jf_result *out = j->out;
    const int deg = j->d;
    const size_t rows = j->rows;
    const double h = j->h;
    /* With h = m 2^q, h^k = m^k 2^(qk) exactly, so Y / m^k then a power
     * of two gives the same bits as Y / h^k without h^k ever under- or
     * overflowing (lengths near 1e+-150), and scales exactly with h. */
    {
        int c = 0, q;
        double m = frexp(h, &q), mk = 1.0;
        for (int k = 0; k <= deg; k++, mk *= m)
            for (int i = 0; i <= k; i++, c++) f->coef[c] = jf__ldexp(f->sol[c] / mk, -q * k);
    }
    const size_t cols = jf_jet_size(deg);
    /* weighted residual norm for free: after the QR, the components
     * rows cols.. of Q^T b are the residual in an orthonormal basis */
    double sw2 = 0, sr2 = 0;
    for (size_t t = 0; t < rows; t++) sw2 += f->w[f->order[t]] * f->w[f->order[t]];
    for (size_t t = cols; t < rows; t++) sr2 += f->rhs[t] * f->rhs[t];
    f->last_h = h;
    memcpy(f->frame, j->r, sizeof j->r);
    f->last_deg = deg;
    out->degree = deg;
    out->n_used = (int)rows;
    out->residual = sqrt(sr2 / sw2);
    for (size_t c = 0; c < cols; c++)
        if (!isfinite(f->coef[c])) {
            fail_result(out, JF_PT_FAILED);
            return;
        }
    jf__quantities(f->coef, deg, f->p.monge_degree, j->r, h, out);
}

jf_status jf_fit_point_weighted(jf_fitter *f, const double p[3], const double *nbr,
                                const double *w, size_t n, jf_result *out)
{
    jf_status st0 = check_args(f, p, nbr, w, n, out);
    if (st0 != JF_OK) return st0;
    fit_job j;
    if (!job_begin(&j, f, p, nbr, w, n, out)) return JF_OK;
    double evec[9];
    jf__eig3(j.cov, out->pca_eval, evec);
    for (int st = job_frame(&j, evec); st;)
        st = job_solved(&j, job_solve(&j, st, st == 1 && jf__eigvals(f, jf_jet_size(j.d))));
    return JF_OK;
}

jf_status jf__fit_point_x2(jf_fitter *f0, const double p0[3], const double *nbr0, size_t n0,
                           jf_result *out0, jf_fitter *f1, const double p1[3],
                           const double *nbr1, size_t n1, jf_result *out1)
{
    if (f0 == f1 || check_args(f0, p0, nbr0, NULL, n0, out0) != JF_OK ||
        check_args(f1, p1, nbr1, NULL, n1, out1) != JF_OK) {
        jf_status st = jf_fit_point(f0, p0, nbr0, n0, out0);
        return st != JF_OK ? st : jf_fit_point(f1, p1, nbr1, n1, out1);
    }
    fit_job j[2];
    int st[2];
    double evec[2][9];
    st[0] = job_begin(&j[0], f0, p0, nbr0, NULL, n0, out0);
    st[1] = job_begin(&j[1], f1, p1, nbr1, NULL, n1, out1);
    if (st[0] && st[1])
        jf__eig3_x2(j[0].cov, j[1].cov, out0->pca_eval, evec[0], out1->pca_eval, evec[1]);
    for (int k = 0; k < 2; k++) {
        if (!st[k]) continue;
        if (!st[1 - k]) jf__eig3(j[k].cov, j[k].out->pca_eval, evec[k]);
        st[k] = job_frame(&j[k], evec[k]);
    }
    /* the first system of each, side by side when both want the
     * eigenvalues of same-sized G (the usual case: one degree, k-NN) */
    if (st[0] == 1 && st[1] == 1 && j[0].d == j[1].d) {
        int ok[2];
        jf__eigvals_x2(f0, f1, jf_jet_size(j[0].d), ok);
        for (int k = 0; k < 2; k++) st[k] = job_solved(&j[k], job_solve(&j[k], st[k], ok[k]));
    }
    for (int k = 0; k < 2; k++)
        while (st[k]) {
            jf_fitter *f = j[k].f;
            st[k] = job_solved(&j[k], job_solve(&j[k], st[k],
                                                st[k] == 1 && jf__eigvals(f, jf_jet_size(j[k].d))));
        }
    return JF_OK;
}

jf_status jf__fit_point_x4(jf_fitter *const f[4], const double *const p[4],
                           const double *const nbr[4], const size_t n[4], jf_result *const out[4])
{
    for (int k = 0; k < 4; k++) {
        int clash = 0;
        for (int l = 0; l < k; l++) clash |= f[l] == f[k];
        if (clash || check_args(f[k], p[k], nbr[k], NULL, n[k], out[k]) != JF_OK) {
            jf_status st = JF_OK;
            for (int l = 0; l < 4 && st == JF_OK; l++) st = jf_fit_point(f[l], p[l], nbr[l], n[l], out[l]);
            return st;
        }
    }
    fit_job j[4];
    int st[4], live = -1;
    double evec[4][9];
    for (int k = 0; k < 4; k++)
        if ((st[k] = job_begin(&j[k], f[k], p[k], nbr[k], NULL, n[k], out[k]))) live = k;
    if (live < 0) return JF_OK;
    /* the four covariances side by side; a finished fit's lane computes a
     * live one's again, into scratch (lanes do not mix) */
    {
        const double *a[4];
        double *ev[4], *vec[4], spare_ev[4][3], spare_vec[4][9];
        for (int k = 0; k < 4; k++) {
            a[k] = st[k] ? j[k].cov : j[live].cov;
            ev[k] = st[k] ? out[k]->pca_eval : spare_ev[k];
            vec[k] = st[k] ? evec[k] : spare_vec[k];
        }
        jf__eig3_x4(a, ev, vec);
    }
    for (int k = 0; k < 4; k++)
        if (st[k]) st[k] = job_frame_ex(&j[k], evec[k], 1);
    /* the QRs: side by side when all four have the same size */
    int same = 1;
    for (int k = 0; k < 4; k++)
        same &= st[k] == 3 && j[k].rows == j[0].rows && j[k].d == j[0].d;
    if (same) {
        const int r = jf__qr_gram_x4(f, j[0].rows, jf_jet_size(j[0].d)) ? 1 : 2;
        for (int k = 0; k < 4; k++) st[k] = r;
    } else
        for (int k = 0; k < 4; k++)
            if (st[k] == 3) st[k] = jf__qr_gram(f[k], j[k].rows, jf_jet_size(j[k].d)) ? 1 : 2;
    /* the first systems of the same size side by side (the usual case:
     * one degree, k-NN); the others' lanes repeat one of them, unused */
    int first = -1;
    for (int k = 0; k < 4 && first < 0; k++)
        if (st[k] == 1) first = k;
    if (first >= 0) {
        jf_fitter *g[4];
        int in[4], ok[4], d = j[first].d;
        for (int k = 0; k < 4; k++) {
            in[k] = st[k] == 1 && j[k].d == d;
            g[k] = in[k] ? f[k] : f[first];
        }
        /* a repeated fitter's lane writes its eigenvalues again, the same */
        jf__eigvals_x4(g, jf_jet_size(d), ok);
        for (int k = 0; k < 4; k++)
            if (in[k]) st[k] = job_solved(&j[k], job_solve(&j[k], st[k], ok[k]));
    }
    for (int k = 0; k < 4; k++)
        while (st[k]) {
            jf_fitter *fk = j[k].f;
            st[k] = job_solved(&j[k], job_solve(&j[k], st[k],
                                                st[k] == 1 && jf__eigvals(fk, jf_jet_size(j[k].d))));
        }
    return JF_OK;
}

jf_status jf_fit_point(jf_fitter *f, const double p[3], const double *nbr, size_t n,
                       jf_result *out)
{
    return jf_fit_point_weighted(f, p, nbr, NULL, n, out);
}

/* J(x, y) of the last fit (degree deg >= 1, local frame coordinates):
 * sum Y_ij (x/h)^i (y/h)^j with the scaled solution Y kept in f. */
static double last_jet_at(const jf_fitter *f, int deg, double ih, double x, double y)
{
    double mon[55], z = 0;
    monomials(x * ih, y * ih, deg, mon);
    for (size_t c = 0, cols = jf_jet_size(deg); c < cols; c++) z += f->sol[c] * mon[c];
    return z;
}

double jf__fitter_rms(const jf_fitter *f, const double *pts, size_t n)
{
    const int deg = f->have_last ? f->last_deg : 0;
    if (deg == 0) return NAN;
    const double ih = 1.0 / f->last_h, *r = f->frame, *o = f->last_p;
    double s2 = 0;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        const double d[3] = {pts[3 * i] - o[0], pts[3 * i + 1] - o[1], pts[3 * i + 2] - o[2]};
        const double x = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
        const double y = r[3] * d[0] + r[4] * d[1] + r[5] * d[2];
        const double z = r[6] * d[0] + r[7] * d[1] + r[8] * d[2];
        if (!isfinite(x) || !isfinite(y) || !isfinite(z)) continue;
        const double e = z - last_jet_at(f, deg, ih, x, y);
        s2 += e * e;
        m++;
    }
    return m ? sqrt(s2 / (double)m) : NAN;
}

jf_status jf_fitter_residuals(const jf_fitter *f, double *res, size_t n)
{
    if (!f || (n > 0 && !res) || !f->have_last || n != f->last_n) return JF_ERR_INVALID;
    /* computed on demand from the last fit's local points and scaled
     * solution Y (J(x,y) = sum Y_ij (x/h)^i (y/h)^j), kept in the fitter */
    const int deg = f->last_deg;
    const double ih = deg > 0 ? 1.0 / f->last_h : 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *q = f->loc + 3 * i;
        if (deg == 0 || !isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) {
            res[i] = NAN;
            continue;
        }
        res[i] = q[2] - last_jet_at(f, deg, ih, q[0], q[1]);
    }
    return JF_OK;
}
