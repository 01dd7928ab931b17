/* nbctx.c -- the neighbourhood of a point, whatever its kind: the
 * natural neighbourhoods' setup (cells and tangent planes, §5.1) and the
 * per-point query the estimate's walk makes (walk.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "nbctx.h"
#include "planes_internal.h"


static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* JF_NORMAL_AUTO's test (jetfit.h): at up to NOISE_SAMPLES points spread
 * over the input order, the RMS residual of a plain degree-2 jet fitted to
 * the NOISE_N natural neighbours (rings of the PCA planes' own-plane
 * rows), relative to their RMS distance to the point.  A clean surface leaves a residual of higher
 * order (~ r^3 / R^2); noise leaves ~ sigma.  Noisy: the median ratio is
 * above JF_NATURAL_NOISY_RESIDUAL. */
#define NOISE_SAMPLES 2000
#define NOISE_N 20
static jf_status noisy_cloud(const jf_natural *nt, const double *xyz, const double *nrm,
                             size_t n, int threads, int *noisy)
{
    *noisy = 0;
    jf_params p;
    jf_params_init(&p);
    p.degree = 2;
    /* every n / NOISE_SAMPLES-th point (fewer than 4000 points: each),
     * side by side, one slot each; the first NOISE_SAMPLES that give a
     * ratio are the test's, whatever the thread count */
    const size_t step = n > NOISE_SAMPLES ? n / NOISE_SAMPLES : 1;
    const long ns = (long)((n + step - 1) / step);
    double *ratio = malloc((size_t)ns * sizeof *ratio);
    if (!ratio) return JF_ERR_NOMEM;
    jf_status failed = JF_OK;
#pragma omp parallel num_threads(threads)
    {
        jf_fitter *f = NULL;
        jf_natural_ws *ws = NULL;
        jf_status st = jf_fitter_create(&p, &f);
        if (st == JF_OK) st = jf_natural_ws_create(nt, &ws);
#pragma omp for schedule(static)
        for (long k = 0; k < ns; k++) {
            const size_t i = (size_t)k * step;
            uint32_t idx[NOISE_N];
            double pts[3 * NOISE_N], d2 = 0;
            size_t found = 0;
            jf_result r;
            ratio[k] = NAN;
            if (st != JF_OK || jf_natural_kept(nt, i) != i || !jf__finite3(nrm + 3 * i)) continue;
            if ((st = jf__natural_neighbors_own(nt, ws, i, nrm + 3 * i, NOISE_N, idx, NOISE_N, &found)) != JF_OK)
                continue;
            for (size_t j = 0; j < found; j++)
                for (int c = 0; c < 3; c++) {
                    pts[3 * j + c] = xyz[3 * (size_t)idx[j] + c];
                    d2 += (pts[3 * j + c] - xyz[3 * i + c]) * (pts[3 * j + c] - xyz[3 * i + c]);
                }
            if (found < NOISE_N || (st = jf_fit_point(f, xyz + 3 * i, pts, found, &r)) != JF_OK) continue;
            if (r.degree == 2 && d2 > 0) ratio[k] = r.residual / sqrt(d2 / (double)found);
        }
        if (st != JF_OK) {
#pragma omp atomic write
            failed = st;
        }
        jf_natural_ws_free(ws);
        jf_fitter_free(f);
    }
    size_t m = 0;
    for (long k = 0; k < ns && m < NOISE_SAMPLES; k++)
        if (!isnan(ratio[k])) ratio[m++] = ratio[k];
    if (failed == JF_OK && m > 0) {
        qsort(ratio, m, sizeof *ratio, cmp_double);
        *noisy = ratio[m / 2] > JF_NATURAL_NOISY_RESIDUAL;
    }
    free(ratio);
    return failed;
}

/* The k-NN form's own-plane rows from the normals nrm (by input index). */
static jf_status own_rows(nbctx *x, const double *nrm, int nt, jf_error *err)
{
    jf_status st = jf__natural_own_rows(x->nt, nt, nrm);
    if (st != JF_OK) jf__set_err(err, "natural neighbours: the own-plane cells failed");
    return st;
}

/* JF_NORMAL_JET (planes.c): the plane of point i is the jet normal of its
 * N nearest points, and the cells are made on the points moved to their
 * jets (the k-NN form, over a tree of its own); the fit later uses the
 * original points (x->xyz).  A point whose jet failed (too few points)
 * gets its PCA plane. */
static jf_status jet_setup(nbctx *x, const jf_cloud *c, int nt, const jf_params *prm,
                           jf_error *err)
{
    size_t n = c->n;
    double *proj = malloc(3 * n * sizeof *proj);
    jf_status st = proj ? JF_OK : JF_ERR_NOMEM;
    /* x->nflags holds "jet ok" until turned into flags below */
    if (st == JF_OK)
        st = jf__planes_knn_jet(x->ix, c->xyz, n, x->want, prm, nt, x->nrm_own, proj, x->nflags);
    x->fit_moved = 1;
    if (st == JF_OK && (st = jf_natural_create_knn(proj, n, nt, &x->nt)) != JF_OK)
        jf__set_err(err, "natural neighbours: the k-d tree of the moved points failed");
    free(proj);
    for (size_t i = 0; st == JF_OK && i < n; i++) {
        if (x->nflags[i]) {
            x->nflags[i] = JF_PT_NORMAL_JET;
        } else if (jf__finite3(c->xyz + 3 * i)) {
            double *m = x->nrm_own + 3 * i;
            x->nflags[i] = jf__planes_pca_one(x->ix, c->xyz, i, m) ? JF_PT_NORMAL_PCA : JF_PT_FAILED;
            if (x->nflags[i] == JF_PT_FAILED) m[0] = m[1] = m[2] = NAN;
        }
    }
    return st == JF_OK ? own_rows(x, x->nrm_own, nt, err) : st;
}

/* Step 1 for natural[:N]: the cells' structure and the tangent-plane
 * normals.  POLES and MINCIRC need the 3D Delaunay triangulation; every
 * other source uses the k-NN form over x->ix (docs/natural.md, "Speed").
 * AUTO is PCA on a clean cloud and JET on a noisy one. */
jf_status jf__nb_natural_setup(nbctx *x, const jf_cloud *c, jf_normal_source src, int nt,
                               const jf_params *prm, jf_error *err)
{
    size_t n = c->n;
    x->nflags = calloc(n, sizeof *x->nflags);
    if (!x->nflags) return JF_ERR_NOMEM;
    if (src == JF_NORMAL_INPUT && !c->nrm) {
        jf__set_err(err, "normal input: the cloud has no normals");
        return JF_ERR_INVALID;
    }
    if (src != JF_NORMAL_INPUT) {
        x->nrm_own = malloc(3 * n * sizeof *x->nrm_own);
        if (!x->nrm_own) return JF_ERR_NOMEM;
        x->nrm = x->nrm_own;
    }
    if (src == JF_NORMAL_JET) return jet_setup(x, c, nt, prm, err);
    int delaunay = src == JF_NORMAL_POLES || src == JF_NORMAL_MINCIRC;
    jf_status st = delaunay ? jf_natural_create_threads(c->xyz, n, nt, &x->nt)
                            : jf__natural_from_index(x->ix, nt, &x->nt);
    if (st != JF_OK) {
        jf__set_err(err, st == JF_ERR_UNSUPPORTED
                         ? "natural neighbours: the poles and mincirc normals need a 3D Delaunay "
                           "triangulation (CGAL), which this build leaves out (JF_CGAL=OFF)"
                     : delaunay ? "natural neighbours: building the Delaunay triangulation failed"
                                : "natural neighbours: the k-NN form failed");
        return st;
    }
    if (src == JF_NORMAL_INPUT) {
        x->nrm = c->nrm;
        for (size_t i = 0; i < n; i++) x->nflags[i] = JF_PT_NORMAL_INPUT;
        return own_rows(x, c->nrm, nt, err);
    }
    if (delaunay) {
        st = jf_natural_normals(x->nt, src, nt, x->nrm_own, x->nflags, NULL);
        if (st != JF_OK) jf__set_err(err, "natural neighbours: tangent-plane normals failed");
        return st;
    }
    if ((st = jf__planes_pca_knn(x->nt, n, nt, x->nrm_own, x->nflags)) != JF_OK) {
        jf__set_err(err, "natural neighbours: the PCA planes and own-plane cells failed");
        return st;
    }
    int noisy = 0;
    if (src == JF_NORMAL_AUTO && (st = noisy_cloud(x->nt, c->xyz, x->nrm_own, n, nt, &noisy)) != JF_OK) {
        jf__set_err(err, "natural neighbours: the noise test failed");
        return st;
    }
    if (!noisy) return JF_OK;
    jf_natural_free(x->nt); /* made anew on the projected points */
    x->nt = NULL;
    memset(x->nflags, 0, n * sizeof *x->nflags);
    return jet_setup(x, c, nt, prm, err);
}

/* knn: the previous point of the walk's neighbours (hint, hint_n of them)
 * bound this one's k-th distance (their farthest from p): the search
 * starts with that radius instead of none, so it inserts fewer
 * candidates.  Exact: with k points inside, the k nearest are inside; too
 * few found (the bound rounded low), the search runs unbounded. */
static jf_status knn_hinted(const nbctx *x, const double *p, const double *hint, size_t hint_n,
                            uint32_t *idx, double *d2, double *xyz, size_t *found)
{
    const size_t k = x->nb->k < x->cap ? x->nb->k : x->cap;
    double b = 0;
    for (size_t j = 0; j < hint_n; j++) {
        const double dx = p[0] - hint[3 * j], dy = p[1] - hint[3 * j + 1], dz = p[2] - hint[3 * j + 2];
        const double d = dx * dx + dy * dy + dz * dz;
        b = d > b ? d : b;
    }
    jf_status st = jf__index_query(x->ix, p, k, b, idx, d2, xyz, found);
    if (st == JF_OK && *found < k) st = jf__index_query(x->ix, p, k, INFINITY, idx, d2, xyz, found);
    return st;
}

/* The neighbourhood of point i (nbctx.h). */
jf_status jf__nb_point(const nbctx *x, jf_natural_ws *ws, jf__knn_share *sh, size_t i,
                       const double *p, uint32_t *idx, uint32_t *pos, double *d2, double *xyz,
                       size_t *found, unsigned *flags, const double *hint, size_t hint_n)
{
    jf_status st;
    *found = 0;
    *flags = 0;
    switch (x->nb->kind) {
    case JF_NB_RINGS:
        st = jf_nb_query_mesh(x->mesh, x->xyz, x->nb, x->min_count, x->fit, (uint32_t)i, idx,
                              x->cap, found);
        /* rings through a non-manifold edge mix sheets: say so */
        if (jf_mesh_vertex_flags(x->mesh)[i] & JF_MESH_NONMANIFOLD)
            *flags |= JF_PT_MESH_NONMANIFOLD;
        break;
    case JF_NB_NATURAL:
        *flags = x->nflags[i];
        const double *m = x->nrm + 3 * i;
        /* a PCA or jet plane is a unit normal: not read here (input order,
         * a cache miss per point); the others are checked */
        if (!(*flags & (JF_PT_NORMAL_PCA | JF_PT_NORMAL_JET)) &&
            (!jf__finite3(m) || (m[0] == 0 && m[1] == 0 && m[2] == 0))) {
            *flags |= JF_PT_FAILED; /* no tangent plane (e.g. a zero input normal) */
            return JF_OK;
        }
        /* the k-NN form's own-plane rows, or the triangulation's cells;
         * input indices only for the graph and the raw points */
        st = jf__natural_neighbors_own(x->nt, ws, i, m, x->want,
                                       x->graph || x->fit_moved ? idx : NULL, x->cap, found);
        break;
    default: /* sh: auto's 256 nearest, shared along the walk (knn_share.c) */
        if (sh)
            /* input indices for the graph only; nobody reads d2 */
            st = jf__knn_share_query(sh, x->ix, p, x->graph ? idx : NULL, pos, NULL, xyz, found);
        else if (x->nb->kind == JF_NB_KNN && hint && x->nb->k && hint_n == x->nb->k &&
                 hint_n <= x->cap)
            st = knn_hinted(x, p, hint, hint_n, idx, d2, xyz, found);
        else
            st = jf__nb_query_xyz(x->ix, x->nb, x->min_count, p, idx, d2, xyz, x->cap, found);
    }
    if (st == JF_OK && *found < x->want) *flags |= JF_PT_FEW_NEIGHBORS;
    return st;
}

