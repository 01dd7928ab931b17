/* planes.c -- tangent planes for natural neighbourhoods: on a clean
 * cloud the PCA of the 16 nearest points (below), on a noisy one the jet
 * planes and denoised positions (issue 15.1, docs/natural.md).
 *
 * design (noisy clouds):
 *  - The natural neighbourhood of p is built in a plane H through p with
 *    power weights -h^2 (§5.1, natural.c): of the samples around p it
 *    prefers those nearest H.  On a noisy cloud that choice follows the
 *    noise: the ring favours samples on the side of H's tilt and flatter
 *    than the surface, so the fitted jet reproduces H's error instead of
 *    correcting it (measured: with the exact plane natural:N is as good as
 *    knn:N, with the pole plane 2-3.5x worse, with the jet plane of knn:N
 *    still 1.14x worse in the normal and 1.7x in k1 at N = 256).
 *  - So both the plane and the positions the rings are built on come from
 *    the jet of the N nearest points: the normal of that jet, and each
 *    sample moved to the jet's point above it (0, 0, A00 in the fitting
 *    frame).  The triangulation of the moved samples is that of a nearly
 *    clean surface, where natural neighbourhoods work as designed; the fit
 *    then uses the original samples of that ring.
 *  - One fitter and buffers per thread, made once; each result depends
 *    only on its own neighbourhood: any thread count gives the same bits.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "fitter_internal.h"
#include "jetfit.h"
#include "index_internal.h"
#include "planes_internal.h"

#define PCA_K 16 /* PCA of the 16 nearest points */
#define PREFETCH 8 /* pairs ahead */

jf_status jf__planes_knn_jet(const jf_index *ix, const double *xyz, size_t n, size_t k,
                             const jf_params *prm, int nt, double *nrm, double *proj,
                             unsigned *ok)
{
    if (!ix || !xyz || !nrm || !proj || !ok || !prm || k < 1) return JF_ERR_INVALID;
    jf_params p = *prm;
    if (p.max_neighbors < k) p.max_neighbors = k;
    jf_status failed = JF_OK;
#pragma omp parallel num_threads(nt)
    {
        jf_fitter *f = NULL;
        uint32_t *idx = malloc(k * sizeof *idx);
        double *pts = malloc(3 * k * sizeof *pts), *d2 = malloc(k * sizeof *d2);
        jf_status wst = jf_fitter_create(&p, &f);
        if (wst == JF_OK && (!idx || !pts || !d2)) wst = JF_ERR_NOMEM;
        if (wst != JF_OK) {
#pragma omp atomic write
            failed = wst;
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const double *q = xyz + 3 * i;
            double *o = nrm + 3 * i;
            size_t found = 0;
            jf_result r;
            ok[i] = 0;
            o[0] = o[1] = o[2] = NAN;
            memcpy(proj + 3 * i, q, sizeof(double[3]));
            if (wst != JF_OK || !isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
            if (jf_index_knn(ix, q, k, idx, d2, &found) != JF_OK) continue;
            for (size_t j = 0; j < found; j++)
                memcpy(pts + 3 * j, xyz + 3 * (size_t)idx[j], sizeof(double[3]));
            /* plain fit (no robust weights, no scale choice): only the
             * plane and the jet's point above q are used */
            if (jf_fit_point(f, q, pts, found, &r) != JF_OK || (r.status & JF_PT_FAILED)) continue;
            memcpy(o, r.normal, sizeof r.normal);
            /* the jet's point above q: frame row 3 is ez (world) */
            for (int c = 0; c < 3; c++) proj[3 * i + c] = q[c] + f->coef[0] * f->frame[6 + c];
            ok[i] = 1;
        }
        jf_fitter_free(f);
        free(idx);
        free(pts);
        free(d2);
    }
    return failed;
}

/* ---- PCA planes (clean clouds) ---------------------------------------- */

/* The centred scatter matrix a (3x3, row-major) of point v of tp and its
 * k neighbours c (indices into tp, v not among them), in one pass about
 * v itself: sum d d^T - s s^T / m over d = q - v (v's own d is 0), m =
 * k + 1.  The neighbours' mean is within their spread of v, so the
 * subtraction loses nothing to speak of; no copy of the points is made.
 * Returns 0 for fewer than 3 points. */
static int pca_cov_about(const double *tp, size_t v, const uint32_t *c, size_t k, double a[9])
{
    if (k < 2) return 0;
    const double *u = tp + 3 * v;
    double sx = 0, sy = 0, sz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
    for (size_t j = 0; j < k; j++) {
        const double *q = tp + 3 * (size_t)c[j];
        const double dx = q[0] - u[0], dy = q[1] - u[1], dz = q[2] - u[2];
        sx += dx, sy += dy, sz += dz;
        xx += dx * dx, xy += dx * dy, xz += dx * dz;
        yy += dy * dy, yz += dy * dz, zz += dz * dz;
    }
    const double im = 1 / (double)(k + 1);
    a[0] = xx - sx * sx * im, a[1] = a[3] = xy - sx * sy * im, a[2] = a[6] = xz - sx * sz * im;
    a[4] = yy - sy * sy * im, a[5] = a[7] = yz - sy * sz * im, a[8] = zz - sz * sz * im;
    return 1;
}

/* The normal from the eigen-decomposition of the covariance: its
 * smallest eigenvalue's eigenvector.  0 if the points span less than a
 * plane (no unique normal). */
static int pca_pick(const double eval[3], const double evec[9], double nrm[3])
{
    if (!(eval[1] > 1e-24 * eval[2])) return 0; /* collinear */
    memcpy(nrm, evec, sizeof(double[3]));
    return 1;
}

/* The smallest eigenvector of a (3x3 symmetric, positive semi-definite)
 * by power iteration on its adjugate, whose eigenvalues are l2 l3 >=
 * l1 l3 >= l1 l2 on the same eigenvectors: each step divides the error
 * by l2 / l1, large for a sample of a surface.  A tenth of the Jacobi
 * solver's time.  Returns 0 (the caller uses jf__eig3) when a is zero
 * or not finite, l2 is not clearly above 0 (collinear points: jf__eig3
 * decides) or the iteration has not settled in PCA_ITER steps (l1 near
 * l2: no clear plane). */
#define PCA_ITER 64
#define PCA_TOL 1e-14 /* step (x scaled to max 1): the error is about this */
int jf__pca_smallest(const double a[9], double nrm[3])
{
    double s = 0;
    for (int k = 0; k < 9; k++) s = fabs(a[k]) > s ? fabs(a[k]) : s;
    if (!(s > 0) || !(s < INFINITY)) return 0;
    const double r = 1 / s, a00 = a[0] * r, a01 = a[1] * r, a02 = a[2] * r, a11 = a[4] * r,
                 a12 = a[5] * r, a22 = a[8] * r;
    const double c[9] = {a11 * a22 - a12 * a12, a02 * a12 - a01 * a22, a01 * a12 - a02 * a11,
                         a02 * a12 - a01 * a22, a00 * a22 - a02 * a02, a01 * a02 - a00 * a12,
                         a01 * a12 - a02 * a11, a01 * a02 - a00 * a12, a00 * a11 - a01 * a01};
    if (!(c[0] + c[4] + c[8] > 1e-12)) return 0; /* l2 l3 <= ~1e-12 l3^2 */
    int k0 = c[0] >= c[4] ? (c[0] >= c[8] ? 0 : 2) : (c[4] >= c[8] ? 1 : 2);
    double x[3] = {c[k0], c[3 + k0], c[6 + k0]}; /* column k0: nearly along v1 */
    for (int it = 0; it < PCA_ITER; it++) {
        double y[3], m = 0;
        for (int i = 0; i < 3; i++) {
            y[i] = c[3 * i] * x[0] + c[3 * i + 1] * x[1] + c[3 * i + 2] * x[2];
            m = fabs(y[i]) > m ? fabs(y[i]) : m;
        }
        if (!(m > 0)) return 0;
        double e = 0, im = 1 / m;
        for (int i = 0; i < 3; i++) { /* x is scaled to max 1 as y now is */
            y[i] *= im;
            e = fabs(y[i] - x[i]) > e ? fabs(y[i] - x[i]) : e;
            x[i] = y[i];
        }
        if (it > 0 && e <= PCA_TOL) {
            double l = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            for (int i = 0; i < 3; i++) nrm[i] = x[i] / l;
            return 1;
        }
    }
    return 0;
}

int jf__planes_pca_one(const jf_index *ix, const double *xyz, size_t i, double nrm[3])
{
    uint32_t idx[PCA_K], c[PCA_K];
    double d2[PCA_K], a[9], eval[3], evec[9];
    size_t found = 0, k = 0;
    if (!isfinite(xyz[3 * i]) || !isfinite(xyz[3 * i + 1]) || !isfinite(xyz[3 * i + 2]) ||
        jf_index_knn(ix, xyz + 3 * i, PCA_K, idx, d2, &found) != JF_OK)
        return 0;
    /* the point and its nearest others (16 in all: as the PCA pass) */
    for (size_t j = 0; j < found && k + 1 < PCA_K; j++)
        if (idx[j] != i) c[k++] = idx[j];
    if (!pca_cov_about(xyz, i, c, k, a)) return 0;
    if (jf__pca_smallest(a, nrm)) return 1;
    jf__eig3(a, eval, evec);
    return pca_pick(eval, evec, nrm);
}

jf_status jf__planes_pca_knn(jf_natural *ntl, size_t n, int nt, double *nrm, unsigned *flags)
{
    const double *tp;
    const uint32_t *id;
    size_t m = jf__index_points(jf__natural_index(ntl), &tp, &id);
#pragma omp parallel for schedule(static) num_threads(nt)
    for (size_t i = 0; i < n; i++) nrm[3 * i] = nrm[3 * i + 1] = nrm[3 * i + 2] = NAN;
    jf_status st = jf__natural_rows_alloc(ntl, nrm);
    if (st != JF_OK) return st;
    int bad = 0; /* 1: no memory, 2: a failed query */
#pragma omp parallel num_threads(nt) reduction(| : bad)
    {
        jf_natural_ws *ws = NULL;
        bad |= jf_natural_ws_create(ntl, &ws) != JF_OK;
#pragma omp for schedule(static, 512)
        for (size_t h = 0; h < (m + 1) / 2; h++) {
            const size_t v0 = 2 * h, cnt = v0 + 1 < m ? 2 : 1;
            double a[2][9], eval[2][3], evec[2][9];
            uint32_t c[2][JF_NATURAL_CAND];
            jf__kd_scan scan[2];
            size_t k[2] = {0, 0};
            int ok[2] = {0, 0};
            if (bad) continue;
            if (v0 + 2 * PREFETCH + 1 < m) /* flags and nrm are in input order: misses */
                for (size_t L = 0; L < 2; L++) {
                    __builtin_prefetch(flags + id[v0 + 2 * PREFETCH + L], 1);
                    __builtin_prefetch(nrm + 3 * (size_t)id[v0 + 2 * PREFETCH + L], 1);
                }
            for (size_t L = 0; L < cnt; L++) {
                if ((k[L] = jf__natural_query(ntl, v0 + L, c[L], &scan[L])) == SIZE_MAX) {
                    bad |= 2;
                    k[L] = 0;
                }
                ok[L] = pca_cov_about(tp, v0 + L, c[L], k[L] < PCA_K - 1 ? k[L] : PCA_K - 1, a[L]);
            }
            int jac[2] = {0, 0}; /* the rare hard ones: Jacobi, paired in lanes */
            for (size_t L = 0; L < cnt; L++)
                jac[L] = ok[L] && !jf__pca_smallest(a[L], nrm + 3 * (size_t)id[v0 + L]);
            if (jac[0] && jac[1])
                jf__eig3_x2(a[0], a[1], eval[0], evec[0], eval[1], evec[1]);
            else
                for (size_t L = 0; L < cnt; L++)
                    if (jac[L]) jf__eig3(a[L], eval[L], evec[L]);
            for (size_t L = 0; L < cnt; L++) {
                const size_t i = id[v0 + L];
                flags[i] |= ok[L] && (!jac[L] || pca_pick(eval[L], evec[L], nrm + 3 * i))
                                ? JF_PT_NORMAL_PCA
                                : JF_PT_FAILED;
                /* the cell in this plane, while its candidates are at hand */
                bad |= !bad && !jf__natural_own_row(ws, v0 + L, nrm + 3 * i, c[L], k[L], &scan[L]);
            }
        }
        jf_natural_ws_free(ws);
    }
    return bad & 1 ? JF_ERR_NOMEM : bad ? JF_ERR_INTERNAL : JF_OK;
}
