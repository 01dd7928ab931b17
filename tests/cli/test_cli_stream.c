/* test_cli_stream.c -- results never held for the whole cloud (issue 12.1):
 * jf_estimate_blocks + jf_writer_put (rows written at their input index:
 * in place for binary PLY and LAS, through a binary spool for text) give
 * files byte-identical to the whole-array path jf_estimate +
 * jf_writer_rows, for every output format, neighbourhood kind and the
 * options that change rows (robust, scales, degree 4, orientation input /
 * viewpoint / scanner / mst); `jetfit estimate` (which now streams) equals
 * the whole-array path too; a failed put leaves no file. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "io_internal.h"
#include "jetfit.h"
#include "test_cli_util.h"
#include "jf_test.h"

/* ---- fixtures ------------------------------------------------------- */

static uint64_t rng = 88172645463325252ULL;
static double urand(void)
{
    return jf_unit(jf_xorshift64(&rng));
}

/* A jittered grid on the paper's §6.1 surface z = 0.1 exp(2x + y - y^2)
 * (as a radius, bent round the y axis),
 * side x side vertices, triangulated (rings), shuffled vertex order (so
 * the walk is far from input order), plus: two exact duplicates, a NaN
 * point (nobody's neighbour, a nonfinite row), input normals of random
 * sign, and two scans (scanner positions above and below). */
static void make_cloud(jf_cloud *c, size_t side)
{
    size_t n = side * side;
    memset(c, 0, sizeof *c);
    c->n = n;
    c->xyz = malloc(3 * n * sizeof *c->xyz);
    c->nrm = malloc(3 * n * sizeof *c->nrm);
    c->scan = malloc(n * sizeof *c->scan);
    c->scanner = malloc(6 * sizeof *c->scanner);
    c->nscans = 2;
    uint32_t *perm = malloc(n * sizeof *perm);
    for (size_t i = 0; i < n; i++) perm[i] = (uint32_t)i;
    for (size_t i = n; i > 1; i--) {
        size_t j = (size_t)(urand() * (double)i);
        uint32_t t = perm[i - 1];
        perm[i - 1] = perm[j];
        perm[j] = t;
    }
    double h = 1.0 / (double)(side - 1);
    for (size_t g = 0; g < n; g++) {
        size_t i = perm[g];
        double x = -0.5 + h * ((double)(g % side) + 0.3 * (urand() - 0.5));
        double y = -0.5 + h * ((double)(g / side) + 0.3 * (urand() - 0.5));
        /* bent round a cylinder's axis (y), so that the fitted normals
         * (largest component positive) disagree and mst has to flip */
        double *p = c->xyz + 3 * i, t = 3 * x, rad = 0.5 + 0.1 * exp(2 * x + y - y * y);
        p[0] = rad * sin(t), p[1] = y, p[2] = rad * cos(t);
        double s = urand() < 0.5 ? -1 : 1;
        c->nrm[3 * i] = 0.1 * s, c->nrm[3 * i + 1] = 0.2 * s, c->nrm[3 * i + 2] = -s;
        c->scan[i] = urand() < 0.5;
    }
    memcpy(c->xyz + 3 * perm[5], c->xyz + 3 * perm[6], sizeof(double[3]));
    memcpy(c->xyz + 3 * perm[40], c->xyz + 3 * perm[41], sizeof(double[3]));
    c->xyz[3 * perm[77] + 1] = NAN;
    const double sc[6] = {0.1, 0.2, 3, -0.3, 0.1, -3};
    memcpy(c->scanner, sc, sizeof sc);
    c->nfaces = 2 * (side - 1) * (side - 1);
    c->face_off = malloc((c->nfaces + 1) * sizeof *c->face_off);
    c->face_idx = malloc(3 * c->nfaces * sizeof *c->face_idx);
    size_t f = 0;
    for (size_t r = 0; r + 1 < side; r++)
        for (size_t q = 0; q + 1 < side; q++) {
            uint32_t a = perm[r * side + q], b = perm[r * side + q + 1],
                     d = perm[(r + 1) * side + q], e = perm[(r + 1) * side + q + 1];
            uint32_t t[6] = {a, b, e, a, e, d};
            for (int k = 0; k < 6; k++) c->face_idx[3 * f + (size_t)k] = t[k];
            c->face_off[f] = 3 * f;
            c->face_off[f + 1] = 3 * f + 3;
            f++;
            c->face_off[f] = 3 * f;
            c->face_off[f + 1] = 3 * f + 3;
            f++;
        }
    free(perm);
}

/* ---- the rows: the command's columns, from the library's one list ---- */

static size_t columns(int monge, jf_column *cols) { return jf_result_columns(monge, 0, cols); }

static void row(const double *p, const jf_result *r, int monge, double *v)
{
    jf_result_row(p, r, monge, 0, v);
}

/* The whole-array path: every result, then rows in input order. */
static void write_whole(const char *path, const jf_cloud *c, const jf_estimate_opts *o,
                        int ascii)
{
    jf_column cols[JF_RESULT_MAX_COLS];
    int monge = o->params.monge_degree;
    size_t nc = columns(monge, cols);
    jf_result *r = malloc(c->n * sizeof *r);
    jf_error err;
    jf_status st = jf_estimate(c, o, r, &err);
    ck_assert_msg(st == JF_OK, "jf_estimate: %s", err.msg);
    jf_writer *w;
    ck_assert_int_eq(jf_writer_open(path, cols, nc, c->n, ascii, &w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_faces(w, c->nfaces, c->face_off, c->face_idx), JF_OK);
    ck_assert_int_eq(jf_writer_las_frame(w, c->xyz, c->n), JF_OK);
    ck_assert_int_eq(jf_writer_attrs(w, &c->attrs), JF_OK); /* the input's, as the command */
    double *v = malloc(c->n * nc * sizeof *v);
    for (size_t i = 0; i < c->n; i++) row(c->xyz + 3 * i, &r[i], monge, v + i * nc);
    ck_assert_int_eq(jf_writer_rows(w, v, c->n, 2), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &err), JF_OK);
    free(v);
    free(r);
}

typedef struct {
    jf_writer *w;
    const double *xyz;
    int monge;
    size_t nc;
    size_t calls, fail_after; /* fail_after: a sink that fails (0: never) */
} sinkctx;

static jf_status sink(void *user, const uint32_t *idx, jf_result *res, size_t m)
{
    sinkctx *s = user;
    ck_assert_uint_le(m, 256);
    size_t call = __atomic_add_fetch(&s->calls, 1, __ATOMIC_RELAXED);
    if (s->fail_after && call > s->fail_after) return JF_ERR_IO;
    double *v = malloc(m * s->nc * sizeof *v);
    for (size_t j = 0; j < m; j++) row(s->xyz + 3 * (size_t)idx[j], &res[j], s->monge, v + j * s->nc);
    jf_status st = jf_writer_put(s->w, idx, v, m);
    free(v);
    return st;
}

/* The streaming path. */
static jf_status write_blocks(const char *path, const jf_cloud *c, const jf_estimate_opts *o,
                              int ascii, size_t fail_after)
{
    jf_column cols[JF_RESULT_MAX_COLS];
    int monge = o->params.monge_degree;
    size_t nc = columns(monge, cols);
    jf_error err;
    jf_writer *w;
    ck_assert_int_eq(jf_writer_open(path, cols, nc, c->n, ascii, &w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_faces(w, c->nfaces, c->face_off, c->face_idx), JF_OK);
    ck_assert_int_eq(jf_writer_las_frame(w, c->xyz, c->n), JF_OK);
    ck_assert_int_eq(jf_writer_attrs(w, &c->attrs), JF_OK); /* the input's, as the command */
    ck_assert_int_eq(jf_writer_begin_put(w, 2), JF_OK);
    sinkctx s = {w, c->xyz, monge, nc, 0, fail_after};
    jf_status st = jf_estimate_blocks(c, o, sink, &s, &err);
    if (st != JF_OK) {
        jf_writer_abort(w);
        return st;
    }
    return jf_writer_commit(w, &err);
}

/* ---- the configurations ---------------------------------------------- */

typedef struct {
    const char *name;
    void (*set)(jf_estimate_opts *o);
} config;

static void c_knn(jf_estimate_opts *o) { o->nb.kind = JF_NB_KNN, o->nb.k = 16; }
static void c_radius(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_RADIUS, o->nb.r = 0.09;
    o->orient = JF_ORIENT_INPUT;
}
static void c_knn_radius_robust(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_KNN_RADIUS, o->nb.k = 24, o->nb.r = 0.08;
    o->params.robust = JF_ROBUST_TUKEY;
    o->orient = JF_ORIENT_VIEWPOINT;
    o->viewpoint[2] = 5;
}
static void c_scales(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_KNN, o->nb.k = 12;
    o->params.nscales = 3;
    o->params.scales[0] = 12, o->params.scales[1] = 20, o->params.scales[2] = 32;
    o->orient = JF_ORIENT_SCANNER;
}
static void c_mst(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_KNN, o->nb.k = 16;
    o->orient = JF_ORIENT_MST;
}
static void c_degree4(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_KNN, o->nb.k = 40;
    o->params.degree = 4, o->params.monge_degree = 4;
}
static void c_degree3(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_KNN, o->nb.k = 24;
    o->params.degree = 3, o->params.monge_degree = 3;
    o->params.robust = JF_ROBUST_HUBER;
}
static void c_rings_mst(jf_estimate_opts *o)
{
    o->nb.kind = JF_NB_RINGS, o->nb.n = 0;
    o->orient = JF_ORIENT_MST;
}
static void c_natural(jf_estimate_opts *o) { o->nb.kind = JF_NB_NATURAL, o->nb.n = 0; }

static const config configs[] = {
    {"knn:16", c_knn},
    {"radius, orient input", c_radius},
    {"knn+radius tukey, viewpoint", c_knn_radius_robust},
    {"scales, scanner", c_scales},
    {"knn mst", c_mst},
    {"degree 4", c_degree4},
    {"degree 3 huber", c_degree3},
    {"rings mst", c_rings_mst},
    {"natural", c_natural},
};

static const struct {
    const char *ext;
    int ascii;
} formats[] = {{"ply", 0}, {"ply", 1}, {"csv", 0}, {"xyz", 0}, {"las", 0}};

START_TEST(blocks_equal_whole_array)
{
    const config *cf = &configs[_i];
    jf_cloud c;
    make_cloud(&c, 24);
    cli_setup();
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.params.monge_degree = 2;
    o.threads = 2;
    cf->set(&o);
    for (size_t k = 0; k < sizeof formats / sizeof *formats; k++) {
        char na[64], nb[64];
        snprintf(na, sizeof na, "whole%s.%s", formats[k].ascii ? "a" : "", formats[k].ext);
        snprintf(nb, sizeof nb, "blocks%s.%s", formats[k].ascii ? "a" : "", formats[k].ext);
        char pa[512], pb[512];
        snprintf(pa, sizeof pa, "%s", cli_path(na));
        snprintf(pb, sizeof pb, "%s", cli_path(nb));
        write_whole(pa, &c, &o, formats[k].ascii);
        ck_assert_int_eq(write_blocks(pb, &c, &o, formats[k].ascii, 0), JF_OK);
        char what[128];
        snprintf(what, sizeof what, "%s, %s%s", cf->name, formats[k].ext,
                 formats[k].ascii ? " ascii" : "");
        jf_test_assert_same_files(what, pa, pb);
    }
    /* no spool or temporary left behind: 2 files per format */
    ck_assert_int_eq(cli_count_files(), 2 * (int)(sizeof formats / sizeof *formats));
    cli_teardown();
    jf_cloud_free(&c);
}
END_TEST

/* Parts with exact halos (jf_estimate_parts, `--memory`): the same file
 * as the whole cloud's blocks for 2, 3, 7 and 60 parts (60: parts of ~10
 * points, fewer than K; the duplicates and the NaN point are in the
 * fixture) for every k-d tree neighbourhood and per-point orientation. */
static jf_status write_parts(const char *path, const jf_cloud *c, const jf_estimate_opts *o,
                             int nparts)
{
    jf_column cols[JF_RESULT_MAX_COLS];
    int monge = o->params.monge_degree;
    size_t nc = columns(monge, cols);
    jf_error err;
    jf_writer *w;
    ck_assert_int_eq(jf_writer_open(path, cols, nc, c->n, 0, &w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_faces(w, c->nfaces, c->face_off, c->face_idx), JF_OK);
    ck_assert_int_eq(jf_writer_las_frame(w, c->xyz, c->n), JF_OK);
    ck_assert_int_eq(jf_writer_begin_put(w, 2), JF_OK);
    sinkctx s = {w, c->xyz, monge, nc, 0, 0};
    jf_status st = jf_estimate_parts(c, o, nparts, sink, &s, &err);
    if (st != JF_OK) {
        jf_writer_abort(w);
        return st;
    }
    return jf_writer_commit(w, &err);
}

START_TEST(parts_equal_whole_cloud)
{
    const config *cf = &configs[_i];
    jf_cloud c;
    make_cloud(&c, 24);
    cli_setup();
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.params.monge_degree = 2;
    o.threads = 2;
    cf->set(&o);
    const int kd = o.nb.kind <= JF_NB_KNN_RADIUS && o.orient != JF_ORIENT_MST;
    char pa[512];
    snprintf(pa, sizeof pa, "%s", cli_path("whole.ply"));
    ck_assert_int_eq(write_blocks(pa, &c, &o, 0, 0), JF_OK);
    static const int P[] = {2, 3, 7, 60};
    for (size_t k = 0; k < 4; k++) {
        char nb[32];
        snprintf(nb, sizeof nb, "parts%d.ply", P[k]);
        jf_status st = write_parts(cli_path(nb), &c, &o, P[k]);
        if (!kd) {
            ck_assert_int_eq(st, JF_ERR_UNSUPPORTED); /* rings, natural, mst */
            continue;
        }
        ck_assert_int_eq(st, JF_OK);
        char what[128];
        snprintf(what, sizeof what, "%s, %d parts", cf->name, P[k]);
        jf_test_assert_same_files(what, pa, cli_path(nb));
    }
    cli_teardown();
    jf_cloud_free(&c);
}
END_TEST

/* A sink that fails stops the fit with its status; the writer aborted
 * leaves nothing (the text spool included). */
START_TEST(failing_sink_leaves_nothing)
{
    jf_cloud c;
    make_cloud(&c, 24);
    cli_setup();
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.threads = 2;
    c_knn(&o);
    ck_assert_int_eq(write_blocks(cli_path("out.csv"), &c, &o, 0, 1), JF_ERR_IO);
    ck_assert_int_eq(write_blocks(cli_path("out.ply"), &c, &o, 0, 1), JF_ERR_IO);
    ck_assert_int_eq(cli_count_files(), 0);
    cli_teardown();
    jf_cloud_free(&c);
}
END_TEST

/* Rows put twice, out of range, or missing: commit refuses, no file. */
START_TEST(put_checks_rows)
{
    cli_setup();
    jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_I32}};
    const double v[6] = {1, 2, 3, 4, 5, 6};
    for (int k = 0; k < 3; k++) {
        const char *p = cli_path(k == 1 ? "t.csv" : "t.ply");
        jf_writer *w;
        jf_error err;
        ck_assert_int_eq(jf_writer_open(p, cols, 3, 2, 0, &w, &err), JF_OK);
        ck_assert_int_eq(jf_writer_begin_put(w, 2), JF_OK);
        ck_assert_int_eq(jf_writer_row(w, v), JF_ERR_INVALID); /* no appending */
        uint32_t r[2] = {1, k == 2 ? 2 : 1};
        jf_status st = jf_writer_put(w, r, v, 2);
        ck_assert_int_eq(st, k == 2 ? JF_ERR_INVALID : JF_OK);
        ck_assert_int_ne(jf_writer_commit(w, &err), JF_OK);
        ck_assert_msg(err.msg[0], "an error message");
    }
    ck_assert_int_eq(cli_count_files(), 0);
    /* and the rows in any order give the file jf_writer_rows gives */
    jf_writer *w;
    jf_error err;
    ck_assert_int_eq(jf_writer_open(cli_path("a.csv"), cols, 3, 2, 0, &w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_rows(w, v, 2, 1), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_open(cli_path("b.csv"), cols, 3, 2, 0, &w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_begin_put(w, 2), JF_OK);
    const uint32_t r[2] = {1, 0};
    const double sw[6] = {4, 5, 6, 1, 2, 3};
    ck_assert_int_eq(jf_writer_put(w, r, sw, 2), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &err), JF_OK);
    jf_test_assert_same_files("csv rows put out of order", cli_path("a.csv"), cli_path("b.csv"));
    cli_teardown();
}
END_TEST

/* The row spool with buckets of 100 rows (the default is 32 MiB of
 * values): 10007 rows put in a random order from 2 threads come back in
 * row order, each once; a row given twice or missing is an error. */
static size_t drained;
static jf_status check_rows(void *user, const double *v, size_t m)
{
    (void)user;
    for (size_t r = 0; r < m; r++, drained++)
        for (int j = 0; j < 3; j++)
            if (v[3 * r + (size_t)j] != (double)drained * 3 + j) return JF_ERR_FORMAT;
    return JF_OK;
}

START_TEST(spool_buckets)
{
    cli_setup();
    enum { N = 10007 };
    uint32_t *perm = malloc(N * sizeof *perm);
    double *v = malloc(3 * N * sizeof *v);
    for (size_t i = 0; i < N; i++) perm[i] = (uint32_t)i;
    for (size_t i = N; i > 1; i--) {
        size_t j = (size_t)(urand() * (double)i);
        uint32_t t = perm[i - 1];
        perm[i - 1] = perm[j];
        perm[j] = t;
    }
    for (size_t i = 0; i < N; i++)
        for (int j = 0; j < 3; j++) v[3 * i + (size_t)j] = (double)perm[i] * 3 + j;
    for (int mode = 0; mode < 3; mode++) {
        jf_spool *s;
        jf_error err;
        ck_assert_int_eq(jf__spool_open(cli_path("out.ply"), N, 3, 2400, &s, &err), JF_OK);
        size_t n = mode == 2 ? N - 1 : N; /* mode 2: the last row missing */
#pragma omp parallel for num_threads(2) schedule(dynamic, 1)
        for (size_t b = 0; b < n; b += 37) {
            size_t m = n - b < 37 ? n - b : 37;
            ck_assert_int_eq(jf__spool_put(s, perm + b, v + 3 * b, m), JF_OK);
        }
        if (mode == 1) /* a row twice (and so one missing in its bucket) */
            ck_assert_int_eq(jf__spool_put(s, perm, v, 1), JF_OK);
        drained = 0;
        jf_status st = jf__spool_drain(s, check_rows, NULL, "out.ply", &err);
        if (mode == 0) {
            ck_assert_int_eq(st, JF_OK);
            ck_assert_uint_eq(drained, N);
        } else {
            ck_assert_int_ne(st, JF_OK);
            ck_assert_msg(strstr(err.msg, "missing or given twice"), "%s", err.msg);
        }
        ck_assert_int_eq(cli_count_files(), 1); /* the spool, until freed */
        jf__spool_free(s);
        ck_assert_int_eq(cli_count_files(), 0);
    }
    free(perm);
    free(v);
    cli_teardown();
}
END_TEST

/* `jetfit estimate` (streaming) equals the whole-array path, end to end,
 * from a PLY input holding the points, normals and faces. */
START_TEST(command_equals_whole_array)
{
    jf_cloud c;
    make_cloud(&c, 20);
    cli_setup();
    jf_cloud in = c;
    in.scan = NULL, in.scanner = NULL, in.nscans = 0;
    jf_error err;
    ck_assert_int_eq(jf_cloud_write(cli_path("in.ply"), &in, 0, &err), JF_OK);
    /* read back, as the command will see it */
    jf_cloud r;
    ck_assert_int_eq(jf_cloud_read(cli_path("in.ply"), NULL, &r, &err), JF_OK);
    static const struct {
        const char *out, *nb, *orient;
        int kind;
    } runs[] = {{"knn.ply", "knn:16", "input", 0},  {"mst.csv", "knn:16", "mst", 1},
                {"rings.xyz", "rings", "none", 2}, {"knn.las", "knn:16", "viewpoint:0,0,5", 3}};
    for (size_t k = 0; k < sizeof runs / sizeof *runs; k++) {
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        o.params.monge_degree = 2;
        o.params.degree = 2;
        o.nb.kind = runs[k].kind == 2 ? JF_NB_RINGS : JF_NB_KNN;
        o.nb.k = 16, o.nb.n = 0;
        o.orient = runs[k].kind == 0 ? JF_ORIENT_INPUT
                   : runs[k].kind == 1 ? JF_ORIENT_MST
                   : runs[k].kind == 3 ? JF_ORIENT_VIEWPOINT : JF_ORIENT_NONE;
        o.viewpoint[2] = 5;
        char ref[512];
        snprintf(ref, sizeof ref, "%s", cli_path("ref.out"));
        strcat(ref, strrchr(runs[k].out, '.'));
        write_whole(ref, &r, &o, 0);
        ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path(runs[k].out),
                                 "--neighbors", runs[k].nb, "--degree", "2", "--orient",
                                 runs[k].orient, "--threads", "2", "--quiet", NULL),
                         0);
        jf_test_assert_same_files(runs[k].out, ref, cli_path(runs[k].out));
        /* --memory 4K: rings and mst fit the whole cloud with a note;
         * for knn it is refused with the least that works, which runs in
         * parts: the same bytes */
        const int whole = runs[k].kind == 1 || runs[k].kind == 2;
        ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path(runs[k].out),
                                 "--neighbors", runs[k].nb, "--degree", "2", "--orient",
                                 runs[k].orient, "--threads", "2", "--memory", "4K", NULL),
                         whole ? 0 : 1);
        if (!whole) {
            const char *lw = strstr(cli_err, "the least that works is --memory ");
            char mem[32] = "";
            ck_assert_msg(lw && sscanf(lw + 33, "%31s", mem) == 1, "%s", cli_err);
            ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path(runs[k].out),
                                     "--neighbors", runs[k].nb, "--degree", "2", "--orient",
                                     runs[k].orient, "--threads", "2", "--memory", mem, NULL),
                             0);
        }
        jf_test_assert_same_files(runs[k].out, ref, cli_path(runs[k].out));
        ck_assert_msg((strstr(cli_err, "note:") != NULL) == (runs[k].kind == 1 || runs[k].kind == 2),
                      "%s", cli_err);
    }
    ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("x.ply"), "--memory",
                             "lots", NULL),
                     2);
    ck_assert_msg(strstr(cli_err, "--memory 'lots'"), "%s", cli_err);
    jf_cloud_free(&r);
    cli_teardown();
    jf_cloud_free(&c);
}
END_TEST

/* `jetfit generate` writes a random cloud without truth or noise a chunk
 * of 2^20 points at a time: the same file as the whole-sample path (taken
 * when --truth is asked), over two chunks. */
START_TEST(generate_streamed)
{
    cli_setup();
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "1100000", "--seed", "5", "-o",
                             cli_path("a.ply"), NULL),
                     0);
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "1100000", "--seed", "5", "-o",
                             cli_path("b.ply"), "--truth", cli_path("t.ply"), NULL),
                     0);
    jf_test_assert_same_files("generate, streamed and whole", cli_path("a.ply"), cli_path("b.ply"));
    cli_teardown();
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("stream");
    TCase *t = tcase_create("blocks");
    tcase_set_timeout(t, 300);
    tcase_add_loop_test(t, blocks_equal_whole_array, 0, (int)(sizeof configs / sizeof *configs));
    tcase_add_loop_test(t, parts_equal_whole_cloud, 0, (int)(sizeof configs / sizeof *configs));
    tcase_add_test(t, failing_sink_leaves_nothing);
    tcase_add_test(t, put_checks_rows);
    tcase_add_test(t, spool_buckets);
    tcase_add_test(t, command_equals_whole_array);
    tcase_add_test(t, generate_streamed);
    suite_add_tcase(s, t);
    return s;
}

int main(void)
{
    return jf_test_run(suite());
}
