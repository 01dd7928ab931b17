/* pipeline.c -- jf_estimate: index -> per point {neighbourhood, fit} ->
 * orientation, over a whole cloud, with OpenMP.
 *
 * design (docs/design.md "Data flow of an estimate", "Performance rules"):
 *  1. Build what the neighbourhood needs once: the k-d tree (non-finite
 *     points are left out of it: nobody's neighbour), the mesh adjacency
 *     (rings), or the Delaunay triangulation and a tangent-plane normal
 *     per point (natural, §5.1); and a walk: the k-d tree's leaf order
 *     for its neighbourhoods, else a Z-order of the points.
 *  2. Threads take chunks of the walk (consecutive queries touch the same
 *     tree nodes and coordinates: cache friendly; k-NN and radius
 *     neighbours are read from the tree's contiguous copy of the points,
 *     not gathered from the input array); each thread owns a fitter and
 *     buffers made once, so nothing is allocated per point.
 *     Result i is stored at out[i] (input order), and each result depends
 *     only on its own neighbourhood (sorted, ties by index): any thread
 *     count gives the same bits.
 *  3. Orientation (orient.c), which needs every normal.
 * Step 2, the walk, is walk.c's.
 */
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>

#include "auto_cloud.h"
#include "index_internal.h"
#include "jetfit.h"
#include "nbctx.h"
#include "neigh_jets.h"
#include "orient_internal.h"
#include "parts.h"
#include "walk.h"

void jf_estimate_opts_init(jf_estimate_opts *o)
{
    if (!o) return;
    memset(o, 0, sizeof *o);
    jf_params_init(&o->params);
    o->params.monge_degree = 0; /* from the degree: jf_monge_degree_of */
    o->nb.kind = JF_NB_KNN;
    o->nb.k = JF_ESTIMATE_DEFAULT_K;
    o->normal = JF_NORMAL_AUTO;
    o->orient = JF_ORIENT_AUTO;
    o->orient_k = 8;
}

jf_orient_mode jf_orient_resolve(jf_orient_mode m, int has_normals, int has_scanners)
{
    if (m != JF_ORIENT_AUTO) return m;
    return has_scanners ? JF_ORIENT_SCANNER : has_normals ? JF_ORIENT_INPUT : JF_ORIENT_NONE;
}

/* ---- the whole cloud ------------------------------------------------- */

static size_t max_sz(size_t a, size_t b) { return a > b ? a : b; }

jf_status jf__estimate_check(const jf_cloud *c, const jf_estimate_opts *o, jf_estimate_opts *use,
                             jf_error *err)
{
    const char *bad = NULL;
    *use = *o;
    if (use->params.monge_degree == 0) use->params.monge_degree = jf_monge_degree_of(use->params.degree);
    jf__nb_auto_opts(use); /* auto: knn:JF_NB_AUTO_KMAX and the fit's choice */
    use->orient = jf_orient_resolve(o->orient, c->nrm != NULL,
                                    c->scan && c->scanner && c->nscans);
    if (use->orient == JF_ORIENT_INPUT && !c->nrm) {
        jf__set_err(err, "orient input: the cloud has no normals");
        return JF_ERR_INVALID;
    }
    if (use->orient == JF_ORIENT_SCANNER && (!c->scan || !c->scanner || !c->nscans)) {
        jf__set_err(err, "orient scanner: the cloud has no scanner positions (PTX input has)");
        return JF_ERR_INVALID;
    }
    if (o->nb.kind == JF_NB_RINGS && !c->nfaces) {
        jf__set_err(err, "neighbors rings needs a mesh (faces in the input)");
        return JF_ERR_INVALID;
    }
    if ((unsigned)o->orient > JF_ORIENT_AUTO) {
        jf__set_err(err, "invalid parameter 'orient'");
        return JF_ERR_INVALID;
    }
    if (jf_params_validate(&use->params, &bad) != JF_OK) {
        char m[128];
        snprintf(m, sizeof m, "invalid parameter '%s'", bad ? bad : "?");
        jf__set_err(err, m);
        return JF_ERR_INVALID;
    }
    if (c->n >= UINT32_MAX - 2) {
        jf__set_err(err, "too many points (2^32 - 2 at most)");
        return JF_ERR_TOO_LARGE;
    }
    return JF_OK;
}

void jf__nb_auto_opts(jf_estimate_opts *o)
{
    if (o->nb.kind != JF_NB_AUTO) return;
    o->nb.kind = JF_NB_KNN;
    o->nb.k = JF_NB_AUTO_KMAX;
    if (o->params.auto_select < 1) o->params.auto_select = 1; /* a cap given stays */
    if (o->params.max_neighbors < JF_NB_AUTO_KMAX) o->params.max_neighbors = JF_NB_AUTO_KMAX;
}

/* jf_estimate (out != NULL) and jf_estimate_blocks (sink != NULL); fit:
 * parts.h's mask (NULL: every point). */
static jf_status estimate(const jf_cloud *c, const jf_estimate_opts *o_in, const uint8_t *fit,
                          jf_result *out, jf_block_fn sink, jf__block_xyz_fn sinkx, void *user,
                          jf_error *err)
{
    if (err) err->msg[0] = '\0';
    if (!c || !o_in || (c->n && (!c->xyz || (!out && !sink && !sinkx)))) {
        jf__set_err(err, out || !(sink || sinkx) ? "jf_estimate: NULL argument" : "jf_estimate_blocks: NULL argument");
        return JF_ERR_INVALID;
    }
    jf_estimate_opts use;
    jf_status cst = jf__estimate_check(c, o_in, &use, err);
    if (cst != JF_OK) return cst;
    const jf_estimate_opts *o = &use;
    size_t n = c->n;
    if (n == 0) return JF_OK;
    if (!out && o->orient == JF_ORIENT_SCANNER)
        for (size_t i = 0; i < n; i++) /* blocks go out oriented: check first */
            if (c->scan[i] >= c->nscans) {
                jf__set_err(err, "orientation failed");
                return JF_ERR_INVALID;
            }

    int nt = o->threads > 0 ? o->threads : jf_default_threads(NULL);
    const jf_params *p = &o->params;
    nbctx x = {0};
    jf_nb_spec nb = o->nb;
    /* scale selection picks among the first K of the list: fetch the most */
    if (nb.kind == JF_NB_KNN)
        for (int j = 0; j < p->nscales; j++) nb.k = max_sz(nb.k, p->scales[j]);
    x.nb = &nb;
    x.xyz = c->xyz;
    x.fit = p->fit;
    x.plain = p->robust == JF_ROBUST_NONE && p->nscales <= 0 && p->degree_select <= 0 &&
              !p->auto_select &&
              !(p->dist_weight > 0.0);
    x.min_count = jf_jet_size(p->degree);
    x.cap = p->max_neighbors;
    switch (o->nb.kind) {
    case JF_NB_KNN: x.want = x.cap = nb.k; break;
    case JF_NB_KNN_RADIUS: x.cap = o->nb.k; x.want = x.min_count < x.cap ? x.min_count : x.cap; break;
    case JF_NB_RADIUS: x.want = 0; break;
    case JF_NB_RINGS:
        x.want = o->nb.n ? o->nb.n : x.min_count;
        if (o->nb.n) x.cap = o->nb.n;
        break;
    case JF_NB_NATURAL: x.want = x.cap = o->nb.n ? o->nb.n : max_sz(2 * x.min_count, 12); break;
    case JF_NB_AUTO: break; /* knn by now (jf__nb_auto_opts) */
    }
    x.cap = max_sz(x.cap, 1);
    if (x.cap > p->max_neighbors) {
        jf__set_err(err, "neighbourhood larger than params.max_neighbors");
        return JF_ERR_INVALID;
    }

    const int mst_blocks = !out && o->orient == JF_ORIENT_MST;
    jf__runctx R = {c, o, &x, fit, out, sink, sinkx, user, mst_blocks, NULL, NULL, NULL, 0, mst_blocks ? 2 * n : n};
    jf_status st = JF_OK;
    jf_index *ix = NULL;
    uint32_t *order = NULL;
    /* natural: the k-NN form's candidates and planes come from the tree */
    int knn_cells = o->nb.kind == JF_NB_NATURAL && o->normal != JF_NORMAL_POLES &&
                    o->normal != JF_NORMAL_MINCIRC;
    int need_index = nb.kind <= JF_NB_KNN_RADIUS || knn_cells;
    if (need_index && o->phase) o->phase(o->phase_user, JF_PHASE_INDEX, 0, n);
    if (need_index && (st = jf__index_build_threads(c->xyz, n, nt, &ix)) != JF_OK) {
        jf__set_err(err, "building the k-d tree failed");
        goto out;
    }
    if (need_index && o->phase) o->phase(o->phase_user, JF_PHASE_INDEX, n, n);
    x.ix = ix;
    /* auto's step 6 (neigh_jets.h); a part's halo holds what it reads
     * (parts.c, jf__halo_requests) */
    jf__njs njs = {0};
    if (jf__nj_on(p, &nb) && need_index) {
        x.nj = &njs;
        if (jf__njs_alloc(&njs, jf_index_size(ix)) != JF_OK) {
            st = JF_ERR_NOMEM;
            jf__set_err(err, "out of memory (auto's neighbour fits)");
            goto out;
        }
    }
    /* auto's step 0: the cloud's cap on K, from a sample (auto_cloud.c);
     * a part's or a rank's estimate is given the whole cloud's */
    if (jf__auto_cv_wanted(p, &nb) && need_index) {
        if (fit) {
            st = JF_ERR_INVALID;
            jf__set_err(err, "neighbors auto: a part's estimate needs the cloud's cap on K");
            goto out;
        }
        jf__cvrec *cv = NULL;
        size_t ncv = 0;
        if ((st = jf__auto_cv_sample(c->xyz, n, NULL, NULL, n, ix, p, nt, &cv, &ncv)) != JF_OK) {
            jf__set_err(err, st == JF_ERR_NOMEM ? "out of memory (auto's sample)" : jf_strerror(st));
            goto out;
        }
        use.params.auto_select = jf__auto_cv_select(p, cv, ncv);
        if (o->auto_chosen) *o->auto_chosen = use.params.auto_select;
        free(cv);
    }
    jf__njs_set(&njs, &use.params);
    if (jf__cancelled(o)) {
        st = jf__cancel_status(err);
        goto out;
    }
    if (o->nb.kind == JF_NB_RINGS &&
        (st = jf_mesh_build(n, c->nfaces, c->face_off, c->face_idx, &x.mesh, err)) != JF_OK)
        goto out;
    if (o->nb.kind == JF_NB_NATURAL && (st = jf__nb_natural_setup(&x, c, o->normal, nt, p, err)) != JF_OK) {
        if (err && !err->msg[0]) jf__set_err(err, jf_strerror(st));
        goto out;
    }
    if (o->orient == JF_ORIENT_MST) {
        /* mst on the fit's own neighbourhoods: no queries again later */
        if (o->orient_k < 1 || o->orient_k > 1024) {
            st = JF_ERR_INVALID;
            jf__set_err(err, "orient_k must be 1..1024");
            goto out;
        }
        x.gk = o->orient_k;
        x.graph = malloc(n * x.gk * sizeof *x.graph);
        if (mst_blocks) {
            R.vn = malloc(3 * n * sizeof *R.vn);
            R.vs = malloc(n * sizeof *R.vs);
        }
        if (!x.graph || (mst_blocks && (!R.vn || !R.vs))) {
            st = JF_ERR_NOMEM;
            jf__set_err(err, "out of memory (orientation graph)");
            goto out;
        }
    }
    /* the walk (step 2): where the neighbourhoods come from the k-d tree,
     * its leaf order over its own copy of the points, so a point and its
     * neighbours are read from a few adjacent leaves (the non-finite points,
     * not in the tree, get their row first); else the Morton order */
    const uint32_t *walk;
    const double *walk_xyz = NULL;
    size_t nwalk = n;
    if (need_index) {
        nwalk = jf__index_points(ix, &walk_xyz, &walk);
        x.pts = walk_xyz;
    } else {
        order = malloc(n * sizeof *order);
        if (!order) {
            st = JF_ERR_NOMEM;
            jf__set_err(err, "out of memory (point order)");
            goto out;
        }
        if (o->phase) o->phase(o->phase_user, JF_PHASE_ORDER, 0, n);
        if ((st = jf_spatial_order(c->xyz, n, order)) != JF_OK) {
            jf__set_err(err, "spatial order failed");
            goto out;
        }
        if (o->phase) o->phase(o->phase_user, JF_PHASE_ORDER, n, n);
        walk = order;
    }

    /* step 2 (twice for mst in block mode: see jf__runctx) */
    for (int pass = 0; pass < 1 + mst_blocks; pass++) {
        if (jf__cancelled(o)) {
            st = jf__cancel_status(err);
            goto out;
        }
        R.done0 = (size_t)pass * n + (n - nwalk);
        if (nwalk < n && (st = jf__walk_nonfinite(&R, n)) != JF_OK) {
            jf__set_err(err, "writing a block of results failed");
            goto out;
        }
        if ((st = jf__walk_pass(&R, walk, walk_xyz, nwalk, nt, err)) != JF_OK)
            goto out;
        if (pass == 0 && mst_blocks) {
            /* Prim on the normals alone; the second pass flips the rows */
            R.vf = calloc(n, 1);
            if (!R.vf) {
                st = JF_ERR_NOMEM;
                jf__set_err(err, "out of memory (orientation)");
                goto out;
            }
            st = jf__orient_mst_view(R.vn, R.vs, R.vf, c->xyz, n, x.graph, x.gk);
            if (st != JF_OK) {
                jf__set_err(err, "orientation failed");
                goto out;
            }
            free(R.vn);
            free(x.graph);
            R.vn = NULL;
            x.graph = NULL;
            x.gk = 0;
            R.collect = 0;
            for (size_t i = 0; i < n; i++) R.vs[i] &= JF_PT_ORIENT_UNKNOWN;
        }
    }
    free(order);
    order = NULL;
    jf_natural_free(x.nt); /* may borrow ix */
    x.nt = NULL;
    jf_index_free(ix); /* the orientation does not need it: lower peak */
    ix = NULL;
    if (o->progress) o->progress(o->progress_user, R.total, R.total);
    if (o->phase) o->phase(o->phase_user, JF_PHASE_FIT, R.total, R.total);
    if (!out) goto out; /* blocks left oriented */
    if (o->orient != JF_ORIENT_NONE && jf__cancelled(o)) {
        st = jf__cancel_status(err);
        goto out;
    }

    /* step 3 */
    switch (o->orient) {
    case JF_ORIENT_NONE: break;
    case JF_ORIENT_INPUT: st = jf_orient_input(out, n, c->nrm); break;
    case JF_ORIENT_VIEWPOINT: st = jf_orient_viewpoint(out, c->xyz, n, o->viewpoint); break;
    case JF_ORIENT_SCANNER:
        st = jf_orient_scanner(out, c->xyz, n, c->scan, c->scanner, c->nscans);
        break;
    case JF_ORIENT_MST: st = jf_orient_mst_graph(out, c->xyz, n, x.graph, x.gk); break;
    default: st = JF_ERR_INVALID;
    }
    if (st != JF_OK) jf__set_err(err, "orientation failed");
out:
    free(order);
    jf_index_free(ix);
    jf_mesh_free(x.mesh);
    jf_natural_free(x.nt);
    free(x.nrm_own);
    free(x.nflags);
    free(x.graph);
    jf__njs_free(&njs);
    free(R.vn);
    free(R.vs);
    free(R.vf);
    return st;
}

jf_status jf_estimate(const jf_cloud *c, const jf_estimate_opts *o, jf_result *out,
                      jf_error *err)
{
    return estimate(c, o, NULL, out, NULL, NULL, NULL, err);
}

/* parts.h: the points of a part's halo are neighbours, not fitted */
jf_status jf__estimate_masked(const jf_cloud *c, const jf_estimate_opts *o, const uint8_t *fit,
                              jf_result *out, jf_error *err)
{
    return estimate(c, o, fit, out, NULL, NULL, NULL, err);
}

jf_status jf_estimate_blocks(const jf_cloud *c, const jf_estimate_opts *o, jf_block_fn sink,
                             void *user, jf_error *err)
{
    return estimate(c, o, NULL, NULL, sink, NULL, user, err);
}

jf_status jf__estimate_blocks_xyz(const jf_cloud *c, const jf_estimate_opts *o,
                                  jf__block_xyz_fn sink, void *user, jf_error *err)
{
    return estimate(c, o, NULL, NULL, NULL, sink, user, err);
}

jf_status jf__estimate_blocks_masked_xyz(const jf_cloud *c, const jf_estimate_opts *o,
                                         const uint8_t *fit, jf__block_xyz_fn sink, void *user,
                                         jf_error *err)
{
    return estimate(c, o, fit, NULL, NULL, sink, user, err);
}
