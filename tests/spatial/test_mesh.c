/* test_mesh.c -- jf_mesh adjacency, validation and §5.1 rings on hand-built
 * meshes whose rings are known in closed form. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

/* A g x g grid, vertex i + g*j at (i, j, 0), each cell split by the
 * diagonal (i,j)-(i+1,j+1).  Its edge graph is the hexagonal lattice:
 * the ring of (i,j) seen from (a,b) is max(|dx|,|dy|) when dx, dy have the
 * same sign, else |dx| + |dy| (shortest paths stay in the grid's box). */
typedef struct {
    size_t n, nf;
    double *xyz;
    size_t *off;
    uint32_t *idx;
} grid_mesh;

static grid_mesh make_grid(size_t g, int quads)
{
    grid_mesh m;
    m.n = g * g;
    m.nf = (g - 1) * (g - 1) * (quads ? 1 : 2);
    m.xyz = malloc(3 * m.n * sizeof *m.xyz);
    m.off = malloc((m.nf + 1) * sizeof *m.off);
    m.idx = malloc(4 * m.nf * sizeof *m.idx);
    for (size_t v = 0; v < m.n; v++) {
        m.xyz[3 * v] = (double)(v % g);
        m.xyz[3 * v + 1] = (double)(v / g);
        m.xyz[3 * v + 2] = 0.0;
    }
    size_t f = 0, k = 0;
    m.off[0] = 0;
    for (size_t j = 0; j + 1 < g; j++)
        for (size_t i = 0; i + 1 < g; i++) {
            uint32_t a = (uint32_t)(i + g * j), b = a + 1,
                     c = (uint32_t)(a + g + 1), d = (uint32_t)(a + g);
            if (quads) {
                m.idx[k++] = a, m.idx[k++] = b, m.idx[k++] = c, m.idx[k++] = d;
                m.off[++f] = k;
            } else {
                m.idx[k++] = a, m.idx[k++] = b, m.idx[k++] = c;
                m.off[++f] = k;
                m.idx[k++] = a, m.idx[k++] = c, m.idx[k++] = d;
                m.off[++f] = k;
            }
        }
    return m;
}

static void free_grid(grid_mesh *m)
{
    free(m->xyz);
    free(m->off);
    free(m->idx);
}

static long ring_of(size_t g, size_t v, size_t w, int quads)
{
    long dx = (long)(w % g) - (long)(v % g), dy = (long)(w / g) - (long)(v / g);
    long ax = labs(dx), ay = labs(dy);
    if (quads) return ax + ay;
    if ((dx >= 0) == (dy >= 0) || dx == 0 || dy == 0)
        return ax > ay ? ax : ay;
    return ax + ay;
}

typedef struct {
    long ring;
    double d;
    uint32_t i;
} key;

static int cmp_key(const void *a, const void *b)
{
    const key *x = a, *y = b;
    if (x->ring != y->ring) return x->ring < y->ring ? -1 : 1;
    if (x->d != y->d) return x->d < y->d ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

/* Every vertex sorted by (ring, squared distance to v, index). */
static void expected_order(const grid_mesh *m, size_t g, size_t v, int quads,
                           key *out)
{
    for (size_t w = 0; w < m->n; w++) {
        double dx = m->xyz[3 * v] - m->xyz[3 * w],
               dy = m->xyz[3 * v + 1] - m->xyz[3 * w + 1],
               dz = m->xyz[3 * v + 2] - m->xyz[3 * w + 2];
        out[w].ring = ring_of(g, v, w, quads);
        out[w].d = dx * dx + dy * dy + dz * dz;
        out[w].i = (uint32_t)w;
    }
    qsort(out, m->n, sizeof *out, cmp_key);
}

static void check_all_rings(size_t g, int quads, size_t step)
{
    grid_mesh gm = make_grid(g, quads);
    jf_mesh *m = NULL;
    jf_error err;
    ck_assert_int_eq(jf_mesh_build(gm.n, gm.nf, gm.off, gm.idx, &m, &err),
                     JF_OK);
    key *ref = malloc(gm.n * sizeof *ref);
    uint32_t *idx = malloc((gm.n + 5) * sizeof *idx);
    for (size_t v = 0; v < gm.n; v += step) {
        expected_order(&gm, g, v, quads, ref);
        size_t Ns[] = {1, 2, 5, 7, 10, 13, 19, 24, gm.n, gm.n + 5};
        for (size_t t = 0; t < sizeof Ns / sizeof Ns[0]; t++) {
            size_t N = Ns[t], found = 0;
            ck_assert_int_eq(jf_mesh_rings(m, gm.xyz, (uint32_t)v, N, idx,
                                           gm.n + 5, &found), JF_OK);
            ck_assert_uint_eq(found, N < gm.n ? N : gm.n);
            for (size_t j = 0; j < found; j++)
                ck_assert_uint_eq(idx[j], ref[j].i);
            /* whole rings: the shortest prefix of full rings >= N */
            size_t want = N < gm.n ? N : gm.n;
            while (want < gm.n && want > 0 &&
                   ref[want].ring == ref[want - 1].ring)
                want++;
            ck_assert_int_eq(jf_mesh_rings_full(m, gm.xyz, (uint32_t)v, N,
                                                idx, gm.n + 5, &found), JF_OK);
            ck_assert_uint_eq(found, want);
            for (size_t j = 0; j < found; j++)
                ck_assert_uint_eq(idx[j], ref[j].i);
        }
        /* cap cuts: the first cap of the same order */
        size_t found;
        ck_assert_int_eq(jf_mesh_rings_full(m, gm.xyz, (uint32_t)v, gm.n, idx,
                                            9, &found), JF_OK);
        ck_assert_uint_eq(found, 9 < gm.n ? 9 : gm.n);
        for (size_t j = 0; j < found; j++) ck_assert_uint_eq(idx[j], ref[j].i);
    }
    free(ref);
    free(idx);
    jf_mesh_free(m);
    free_grid(&gm);
}

START_TEST(grid_adjacency)
{
    grid_mesh gm = make_grid(5, 0);
    jf_mesh *m;
    jf_error err;
    ck_assert_int_eq(jf_mesh_build(gm.n, gm.nf, gm.off, gm.idx, &m, &err),
                     JF_OK);
    jf_mesh_stats st;
    jf_mesh_get_stats(m, &st);
    ck_assert_uint_eq(st.degenerate_faces, 0);
    ck_assert_uint_eq(st.nonmanifold_edges, 0);
    ck_assert_uint_eq(st.isolated_vertices, 0);
    ck_assert_uint_eq(st.boundary_edges, 16);
    ck_assert_uint_eq(jf_mesh_vertex_count(m), 25);
    const uint32_t *nb;
    ck_assert_uint_eq(jf_mesh_neighbors(m, 12, &nb), 6);
    const uint32_t want12[6] = {6, 7, 11, 13, 17, 18};
    for (int i = 0; i < 6; i++) ck_assert_uint_eq(nb[i], want12[i]);
    ck_assert_uint_eq(jf_mesh_neighbors(m, 0, &nb), 3);  /* 1, 5, 6 */
    ck_assert_uint_eq(jf_mesh_neighbors(m, 4, &nb), 2);  /* 3, 9 */
    ck_assert_uint_eq(jf_mesh_neighbors(m, 25, &nb), 0);
    const uint8_t *fl = jf_mesh_vertex_flags(m);
    for (size_t v = 0; v < 25; v++) {
        int border = v % 5 == 0 || v % 5 == 4 || v / 5 == 0 || v / 5 == 4;
        ck_assert_int_eq(fl[v], border ? JF_MESH_BOUNDARY : 0);
    }
    /* ring 1 of the centre = its 6 neighbours, ring 2 = the next 12 */
    uint32_t idx[32];
    size_t found;
    ck_assert_int_eq(jf_mesh_rings_full(m, gm.xyz, 12, 2, idx, 32, &found),
                     JF_OK);
    ck_assert_uint_eq(found, 7);
    ck_assert_int_eq(jf_mesh_rings_full(m, gm.xyz, 12, 8, idx, 32, &found),
                     JF_OK);
    ck_assert_uint_eq(found, 19);
    jf_mesh_free(m);
    free_grid(&gm);
}
END_TEST

START_TEST(grid_rings_exact) { check_all_rings(5, 0, 1); }
END_TEST

START_TEST(quad_rings_exact) { check_all_rings(6, 1, 1); }
END_TEST

START_TEST(large_rings_fallback)
{
    /* 2400 points from one vertex overflow the on-stack seen set */
    size_t g = 50;
    grid_mesh gm = make_grid(g, 0);
    jf_mesh *m;
    ck_assert_int_eq(jf_mesh_build(gm.n, gm.nf, gm.off, gm.idx, &m, NULL),
                     JF_OK);
    key *ref = malloc(gm.n * sizeof *ref);
    uint32_t *idx = malloc(gm.n * sizeof *idx);
    size_t v = 25 + g * 24, found;
    expected_order(&gm, g, v, 0, ref);
    ck_assert_int_eq(jf_mesh_rings(m, gm.xyz, (uint32_t)v, 2400, idx, gm.n,
                                   &found), JF_OK);
    ck_assert_uint_eq(found, 2400);
    for (size_t j = 0; j < found; j++) ck_assert_uint_eq(idx[j], ref[j].i);
    free(ref);
    free(idx);
    jf_mesh_free(m);
    free_grid(&gm);
}
END_TEST

START_TEST(nb_query_mesh_defaults)
{
    grid_mesh gm = make_grid(7, 0);
    jf_mesh *m;
    ck_assert_int_eq(jf_mesh_build(gm.n, gm.nf, gm.off, gm.idx, &m, NULL),
                     JF_OK);
    jf_nb_spec s;
    uint32_t idx[64];
    size_t found;
    uint32_t c = 3 + 7 * 3;
    ck_assert_int_eq(jf_nb_parse("rings", &s, NULL), JF_OK);
    /* degree 2: N_2 = 6; approx -> whole rings >= 12 = 2 rings, 19 points */
    ck_assert_int_eq(jf_nb_query_mesh(m, gm.xyz, &s, 6, JF_FIT_APPROX, c, idx,
                                      64, &found), JF_OK);
    ck_assert_uint_eq(found, 19);
    /* degree 4: N_4 = 15 -> 3 rings, 37 points */
    ck_assert_int_eq(jf_nb_query_mesh(m, gm.xyz, &s, 15, JF_FIT_APPROX, c, idx,
                                      64, &found), JF_OK);
    ck_assert_uint_eq(found, 37);
    ck_assert_int_eq(jf_nb_query_mesh(m, gm.xyz, &s, 6, JF_FIT_INTERP, c, idx,
                                      64, &found), JF_OK);
    ck_assert_uint_eq(found, 6);
    ck_assert_int_eq(jf_nb_parse("rings:10", &s, NULL), JF_OK);
    ck_assert_int_eq(jf_nb_query_mesh(m, gm.xyz, &s, 6, JF_FIT_APPROX, c, idx,
                                      64, &found), JF_OK);
    ck_assert_uint_eq(found, 10);
    ck_assert_int_eq(jf_nb_parse("knn:10", &s, NULL), JF_OK);
    ck_assert_int_eq(jf_nb_query_mesh(m, gm.xyz, &s, 6, JF_FIT_APPROX, c, idx,
                                      64, &found), JF_ERR_INVALID);
    jf_mesh_free(m);
    free_grid(&gm);
}
END_TEST

START_TEST(bad_index)
{
    const size_t off[4] = {0, 3, 6, 9};
    const uint32_t fi[9] = {0, 1, 2, 1, 2, 3, 2, 3, 9};
    jf_mesh *m = (jf_mesh *)1;
    jf_error err;
    ck_assert_int_eq(jf_mesh_build(5, 3, off, fi, &m, &err), JF_ERR_FORMAT);
    ck_assert_ptr_null(m);
    ck_assert_ptr_nonnull(strstr(err.msg, "face 2"));
    ck_assert_ptr_nonnull(strstr(err.msg, "9"));
    const size_t off2[3] = {0, 3, 2};
    ck_assert_int_eq(jf_mesh_build(5, 2, off2, fi, &m, &err), JF_ERR_FORMAT);
    ck_assert_ptr_nonnull(strstr(err.msg, "face 1"));
    ck_assert_int_eq(jf_mesh_build(5, 3, off, fi, &m, NULL), JF_ERR_FORMAT);
    ck_assert_int_eq(jf_mesh_build(5, 3, NULL, fi, &m, NULL), JF_ERR_INVALID);
    ck_assert_int_eq(jf_mesh_build(5, 0, NULL, NULL, NULL, NULL),
                     JF_ERR_INVALID);
    jf_mesh_free(NULL);
}
END_TEST

START_TEST(degenerate_nonmanifold_isolated)
{
    /* faces: 3 degenerate ones, then three triangles on edge 0-1 (a
     * non-manifold "book"); vertex 5 is in no face */
    const size_t off[7] = {0, 3, 5, 8, 11, 14, 17};
    const uint32_t fi[17] = {0, 0, 1, /**/ 0, 1, /**/ 1, 2, 1,
                             0, 1, 2, /**/ 1, 0, 3, /**/ 0, 1, 4};
    double xyz[6 * 3] = {0, 0, 0, 1, 0, 0, 0.5, 1, 0,
                         0.5, -1, 0, 0.5, 0, 1, 9, 9, 9};
    jf_mesh *m;
    jf_error err;
    ck_assert_int_eq(jf_mesh_build(6, 6, off, fi, &m, &err), JF_OK);
    jf_mesh_stats st;
    jf_mesh_get_stats(m, &st);
    ck_assert_uint_eq(st.degenerate_faces, 3);
    ck_assert_uint_eq(st.nonmanifold_edges, 1);
    ck_assert_uint_eq(st.nonmanifold_vertices, 2);
    ck_assert_uint_eq(st.isolated_vertices, 1);
    ck_assert_uint_eq(st.boundary_edges, 6);
    const uint8_t *fl = jf_mesh_vertex_flags(m);
    ck_assert(fl[0] & JF_MESH_NONMANIFOLD);
    ck_assert(fl[1] & JF_MESH_NONMANIFOLD);
    for (int v = 2; v < 5; v++) {
        ck_assert(!(fl[v] & JF_MESH_NONMANIFOLD));
        ck_assert(fl[v] & JF_MESH_BOUNDARY);
    }
    ck_assert_int_eq(fl[5], JF_MESH_ISOLATED);
    /* rings still work: ring 1 of vertex 0 is 1..4 (1 nearest, then ties
     * 2/3/4 at distance^2 1.25 by index) */
    uint32_t idx[8];
    size_t found;
    ck_assert_int_eq(jf_mesh_rings(m, xyz, 0, 8, idx, 8, &found), JF_OK);
    ck_assert_uint_eq(found, 5);
    const uint32_t want[5] = {0, 1, 2, 3, 4};
    for (int j = 0; j < 5; j++) ck_assert_uint_eq(idx[j], want[j]);
    ck_assert_int_eq(jf_mesh_rings(m, xyz, 5, 8, idx, 8, &found), JF_OK);
    ck_assert_uint_eq(found, 1);
    ck_assert_uint_eq(idx[0], 5);
    /* bad arguments */
    ck_assert_int_eq(jf_mesh_rings(m, xyz, 6, 8, idx, 8, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_mesh_rings(m, xyz, 0, 0, idx, 8, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_mesh_rings(m, NULL, 0, 3, idx, 8, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_mesh_rings(m, xyz, 0, 3, idx, 0, &found), JF_OK);
    ck_assert_uint_eq(found, 0);
    jf_mesh_free(m);
}
END_TEST

START_TEST(nonfinite_vertex)
{
    grid_mesh gm = make_grid(5, 0);
    gm.xyz[3 * 13 + 1] = NAN;
    jf_mesh *m;
    ck_assert_int_eq(jf_mesh_build(gm.n, gm.nf, gm.off, gm.idx, &m, NULL),
                     JF_OK);
    uint32_t idx[32];
    size_t found;
    ck_assert_int_eq(jf_mesh_rings(m, gm.xyz, 12, 30, idx, 32, &found), JF_OK);
    ck_assert_uint_eq(found, 24);
    for (size_t j = 0; j < found; j++) ck_assert_uint_ne(idx[j], 13);
    /* ring 1 without 13: 6, 7, 11, 17, 18 (distances 1,1,1 / 2,2) */
    const uint32_t want[6] = {12, 7, 11, 17, 6, 18};
    for (int j = 0; j < 6; j++) ck_assert_uint_eq(idx[j], want[j]);
    ck_assert_int_eq(jf_mesh_rings(m, gm.xyz, 13, 30, idx, 32, &found),
                     JF_ERR_INVALID);
    jf_mesh_free(m);
    free_grid(&gm);
}
END_TEST

static Suite *mesh_suite(void)
{
    Suite *s = suite_create("mesh");
    TCase *tc = tcase_create("mesh");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, grid_adjacency);
    tcase_add_test(tc, grid_rings_exact);
    tcase_add_test(tc, quad_rings_exact);
    tcase_add_test(tc, large_rings_fallback);
    tcase_add_test(tc, nb_query_mesh_defaults);
    tcase_add_test(tc, bad_index);
    tcase_add_test(tc, degenerate_nonmanifold_isolated);
    tcase_add_test(tc, nonfinite_vertex);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return jf_test_run(mesh_suite());
}
