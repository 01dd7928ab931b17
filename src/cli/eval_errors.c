/* eval_errors.c -- truth, subsets and per-point errors shared by `jetfit
 * eval` and `jetfit study` (eval_errors.h).  Measures: src/eval/eval.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <unistd.h>
#include "eval_errors.h"
#include "jetfit.h"

const char *const jf_q_name[JF_NQ] = {"normal_deg", "k1_rel", "k2_rel", "k1_abs", "k2_abs"};

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && !strcmp(s + a - b, suf);
}

/* "dir/SHAPE.ext" -> "dir/SHAPE" + newext into buf. */
static void sibling(const char *path, const char *newext, char *buf, size_t len)
{
    snprintf(buf, len, "%s", path);
    char *dot = strrchr(buf, '.'), *sl = strrchr(buf, '/');
    if (dot && (!sl || dot > sl)) *dot = '\0';
    size_t u = strlen(buf);
    snprintf(buf + u, len - u, "%s", newext);
}

static int load(const char *path, jf_eval_table *t, char *msg, size_t len)
{
    jf_error e;
    jf_status st = jf_eval_table_read(path, t, &e);
    if (st != JF_OK) {
        snprintf(msg, len, "%s", e.msg[0] ? e.msg : jf_strerror(st));
        return -1;
    }
    return 0;
}

static int col3(const jf_eval_table *t, int c[3])
{
    c[0] = jf_eval_table_col(t, "nx");
    c[1] = jf_eval_table_col(t, "ny");
    c[2] = jf_eval_table_col(t, "nz");
    return c[0] >= 0 && c[1] >= 0 && c[2] >= 0;
}

double *jf_cli_truth_load(const char *path, size_t *nrows, int *has_k, char *msg, size_t len)
{
    jf_eval_table t, tc;
    memset(&tc, 0, sizeof tc);
    char buf[4096];
    int pcpnet = ends_with(path, ".normals");
    if (!pcpnet && ends_with(path, ".xyz")) {
        sibling(path, ".normals", buf, sizeof buf);
        FILE *fp = fopen(buf, "r");
        if (fp) { /* a PCPNet shape: the .xyz itself has no normals */
            fclose(fp);
            pcpnet = 1;
            path = buf;
        }
    }
    char npath[4096];
    snprintf(npath, sizeof npath, "%s", path);
    if (load(npath, &t, msg, len)) return NULL;
    int cn[3], ck[2] = {jf_eval_table_col(&t, "k1"), jf_eval_table_col(&t, "k2")};
    if (!col3(&t, cn)) {
        snprintf(msg, len, "%s: no nx ny nz columns", npath);
        jf_eval_table_free(&t);
        return NULL;
    }
    *has_k = ck[0] >= 0 && ck[1] >= 0;
    if (pcpnet) {
        sibling(npath, ".curv", buf, sizeof buf);
        FILE *fp = fopen(buf, "r");
        *has_k = 0;
        if (fp) {
            fclose(fp);
            if (load(buf, &tc, msg, len)) {
                jf_eval_table_free(&t);
                return NULL;
            }
            if (tc.nrows != t.nrows || tc.ncols < 2) {
                snprintf(msg, len, "%s: %zu rows, %s has %zu", buf, tc.nrows, npath, t.nrows);
                jf_eval_table_free(&t);
                jf_eval_table_free(&tc);
                return NULL;
            }
            *has_k = 1;
        }
    }
    double *v = malloc((t.nrows ? t.nrows : 1) * 5 * sizeof *v);
    if (!v) {
        snprintf(msg, len, "%s: out of memory", npath);
    } else {
        for (size_t i = 0; i < t.nrows; i++) {
            const double *r = t.v + i * t.ncols;
            double *o = v + 5 * i;
            for (int d = 0; d < 3; d++) o[d] = r[cn[d]];
            o[3] = o[4] = NAN;
            if (pcpnet && *has_k) {
                /* PCPNet's .curv: two curvatures per point, positive where
                 * the surface bends toward its (outward) .normals side,
                 * i.e. the opposite of jetfit's sign; order them as
                 * k1 >= k2 in jetfit's convention (verified on
                 * armadillo100k against jet fits, docs/robustness.md). */
                double a = -tc.v[i * tc.ncols], b = -tc.v[i * tc.ncols + 1];
                o[3] = a > b ? a : b;
                o[4] = a > b ? b : a;
            } else if (*has_k) {
                o[3] = r[ck[0]];
                o[4] = r[ck[1]];
            }
        }
        *nrows = t.nrows;
    }
    jf_eval_table_free(&t);
    jf_eval_table_free(&tc);
    return v;
}

int jf_cli_subset_load(const char *path, size_t nrows, size_t **sel, size_t *nsel, char *msg,
                       size_t len)
{
    jf_eval_table sub;
    *sel = NULL;
    if (load(path, &sub, msg, len)) return -1;
    if (!sub.nrows) { /* no rows: every metric would be NaN (issue 33.12) */
        snprintf(msg, len, "%s: no indices (an empty subset has no metrics)", path);
        jf_eval_table_free(&sub);
        return -1;
    }
    size_t *s = malloc((sub.nrows ? sub.nrows : 1) * sizeof *s);
    if (!s) {
        snprintf(msg, len, "%s: out of memory", path);
        jf_eval_table_free(&sub);
        return -1;
    }
    for (size_t j = 0; j < sub.nrows; j++) {
        double x = sub.v[j * sub.ncols];
        if (!(x >= 0.0 && x < (double)nrows) || x != floor(x)) {
            snprintf(msg, len, "%s:%zu: index %g out of range 0..%zu", path, j + 1, x,
                     nrows ? nrows - 1 : 0);
            free(s);
            jf_eval_table_free(&sub);
            return -1;
        }
        s[j] = (size_t)x;
    }
    *sel = s;
    *nsel = sub.nrows;
    jf_eval_table_free(&sub);
    return 0;
}

void jf_cli_point_errors(const double n[3], double k1, double k2, const double t[5], int with_k,
                         double e[JF_NQ])
{
    double ea[2] = {NAN, NAN}, er[2] = {NAN, NAN};
    e[JF_Q_NORMAL] = jf_normal_angle_deg(n, t);
    if (with_k) jf_curv_compare(n, k1, k2, t, t[3], t[4], ea, er);
    e[JF_Q_K1REL] = er[0];
    e[JF_Q_K2REL] = er[1];
    e[JF_Q_K1ABS] = ea[0];
    e[JF_Q_K2ABS] = ea[1];
}

/* Are RESULT's points TRUTH's points?  A result scored against another
 * cloud's truth with the same row count would report nonsense.  A truth
 * written by `estimate` (a reference result: it has a status column)
 * holds the same input points: each coordinate must agree within 1e-9 of
 * the bounding-box diagonal.  generate's truth holds the noise-free
 * points: the median distance must stay under 5% of the diagonal (1%
 * Gaussian noise moves a point about 1.7%; another cloud, about half the
 * diagonal).  No x y z in TRUTH (PCPNet .normals): nothing to check. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int jf_cli_truth_coords_check(const char *truth_path, const jf_eval_table *res, char *msg,
                              size_t len)
{
    const char *path = truth_path;
    char buf[4096];
    if (ends_with(path, ".normals") || ends_with(path, ".xyz")) {
        sibling(path, ".normals", buf, sizeof buf);
        if (!access(buf, F_OK))
            return 0; /* PCPNet: no coordinates beside the normals */
    }
    jf_eval_table t;
    if (load(path, &t, msg, len))
        return -1;
    int tx[3] = {jf_eval_table_col(&t, "x"), jf_eval_table_col(&t, "y"),
                 jf_eval_table_col(&t, "z")};
    int rx[3] = {jf_eval_table_col(res, "x"), jf_eval_table_col(res, "y"),
                 jf_eval_table_col(res, "z")};
    int rc = 0;
    if (tx[0] < 0 || tx[1] < 0 || tx[2] < 0 || rx[0] < 0 || rx[1] < 0 || rx[2] < 0 ||
        t.nrows != res->nrows || t.nrows == 0) {
        jf_eval_table_free(&t);
        return 0;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < res->nrows; i++)
        for (int a = 0; a < 3; a++) {
            double v = res->v[i * res->ncols + rx[a]];
            if (isfinite(v)) {
                lo[a] = v < lo[a] ? v : lo[a];
                hi[a] = v > hi[a] ? v : hi[a];
            }
        }
    double diag = 0;
    for (int a = 0; a < 3; a++)
        diag += hi[a] > lo[a] ? (hi[a] - lo[a]) * (hi[a] - lo[a]) : 0;
    diag = sqrt(diag);
    int exact = jf_eval_table_col(&t, "status") >= 0;
    double *d = malloc(t.nrows * sizeof *d);
    size_t nd = 0, worst = 0;
    double worst_d = -1;
    for (size_t i = 0; d && i < t.nrows; i++) {
        double s = 0;
        for (int a = 0; a < 3; a++) {
            double u = res->v[i * res->ncols + rx[a]] - t.v[i * t.ncols + tx[a]];
            s += u * u;
        }
        if (!isfinite(s))
            continue; /* a nonfinite input point, or an outlier's NaN */
        s = sqrt(s);
        d[nd++] = s;
        if (s > worst_d)
            worst_d = s, worst = i;
    }
    if (!d) {
        snprintf(msg, len, "out of memory");
        rc = -1;
    } else if (exact && worst_d > 1e-9 * diag) {
        snprintf(msg, len, "%s: row %zu: point differs from the result's by %.3g (%.3g of the "
                           "bounding-box diagonal): not the same cloud",
                 path, worst + 1, worst_d, diag > 0 ? worst_d / diag : INFINITY);
        rc = -1;
    } else if (!exact && nd) {
        qsort(d, nd, sizeof *d, cmp_double);
        double med = d[nd / 2];
        if (med > 0.05 * diag) {
            snprintf(msg, len, "%s: its points are not the result's (median distance %.3g, "
                               "%.1f%% of the bounding-box diagonal): not the same cloud",
                     path, med, diag > 0 ? 100 * med / diag : INFINITY);
            rc = -1;
        }
    }
    free(d);
    jf_eval_table_free(&t);
    return rc;
}
