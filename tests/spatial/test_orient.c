/* test_orient.c -- orient.c on results built by hand from exact normals
 * with random signs (no fitting involved): input, viewpoint and mst must
 * recover a consistent side, and flipping must carry the curvatures. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

/* Deterministic LCG in [0,1). */
static double rnd(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* n points on a sphere of radius R at c (Fibonacci spiral); results carry
 * the outward normal with a random sign and k1 = k2 = -1/R w.r.t. it
 * (outward normal: the sphere bends away, z = -(x^2+y^2)/(2R)). */
static void sphere(size_t n, double R, const double c[3], double *xyz, jf_result *r,
                   unsigned long long seed)
{
    const double ga = M_PI * (3.0 - sqrt(5.0));
    for (size_t i = 0; i < n; i++) {
        double z = 1 - 2 * ((double)i + 0.5) / (double)n, rr = sqrt(1 - z * z);
        double u[3] = {rr * cos(ga * (double)i), rr * sin(ga * (double)i), z};
        for (int j = 0; j < 3; j++) xyz[3 * i + j] = c[j] + R * u[j];
        memset(&r[i], 0, sizeof r[i]);
        r[i].degree = 2;
        for (int j = 0; j < 3; j++) r[i].normal[j] = u[j];
        /* any tangent pair with d1 x d2 = n */
        double a[3] = {fabs(u[0]) < 0.9 ? 1 : 0, fabs(u[0]) < 0.9 ? 0 : 1, 0};
        double d1[3] = {u[1] * a[2] - u[2] * a[1], u[2] * a[0] - u[0] * a[2],
                        u[0] * a[1] - u[1] * a[0]};
        double l = sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]);
        for (int j = 0; j < 3; j++) r[i].d1[j] = d1[j] / l;
        double *e = r[i].d1;
        r[i].d2[0] = u[1] * e[2] - u[2] * e[1];
        r[i].d2[1] = u[2] * e[0] - u[0] * e[2];
        r[i].d2[2] = u[0] * e[1] - u[1] * e[0];
        r[i].k1 = r[i].k2 = -1.0 / R;
        if (rnd(&seed) < 0.5) jf_result_flip(&r[i]);
    }
}

static double side(const jf_result *r, const double *p, const double c[3])
{
    double s = 0;
    for (int j = 0; j < 3; j++) s += r->normal[j] * (p[j] - c[j]);
    return s;
}

START_TEST(viewpoint_centre_inward)
{
    size_t n = 2000;
    double c[3] = {0.3, -1, 2}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r);
    sphere(n, 2.0, c, xyz, r, 7);
    ck_assert_int_eq(jf_orient_viewpoint(r, xyz, n, c), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert(side(&r[i], xyz + 3 * i, c) < 0); /* inward */
        /* inward normal: the sphere bends towards it, k = +1/R */
        ck_assert_double_eq_tol(r[i].k1, 0.5, 1e-15);
        ck_assert_double_eq_tol(r[i].k2, 0.5, 1e-15);
        ck_assert_uint_eq(r[i].status & JF_PT_ORIENT_UNKNOWN, 0);
    }
    free(xyz);
    free(r);
}
END_TEST

START_TEST(input_agrees)
{
    size_t n = 500;
    double c[3] = {0, 0, 0}, *xyz = malloc(3 * n * sizeof *xyz), *nrm = malloc(3 * n * sizeof *nrm);
    jf_result *r = malloc(n * sizeof *r);
    sphere(n, 1.0, c, xyz, r, 11);
    for (size_t i = 0; i < 3 * n; i++) nrm[i] = 0.5 * xyz[i]; /* outward, not unit */
    ck_assert_int_eq(jf_orient_input(r, n, nrm), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert(side(&r[i], xyz + 3 * i, c) > 0);
        ck_assert_double_eq_tol(r[i].k1, -1.0, 1e-15);
    }
    /* a zero input normal cannot decide */
    memset(nrm, 0, 3 * sizeof *nrm);
    ck_assert_int_eq(jf_orient_input(r, 1, nrm), JF_OK);
    ck_assert_uint_ne(r[0].status & JF_PT_ORIENT_UNKNOWN, 0);
    free(xyz);
    free(nrm);
    free(r);
}
END_TEST

/* mst on a closed surface: every normal outward (the seed is the top
 * point, oriented +z), whatever the random initial signs. */
START_TEST(mst_sphere_outward)
{
    size_t n = 4000;
    double c[3] = {1e3, 2e3, -5e2}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r);
    sphere(n, 3.0, c, xyz, r, 3);
    jf_index *ix = NULL;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    ck_assert_int_eq(jf_orient_mst(r, xyz, n, ix, 8), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg(side(&r[i], xyz + 3 * i, c) > 0, "point %zu inward", i);
        ck_assert_double_eq_tol(r[i].k1, -1.0 / 3.0, 1e-15);
    }
    jf_index_free(ix);
    free(xyz);
    free(r);
}
END_TEST

/* Two separate spheres: two components, each outward; failed and
 * non-finite points are skipped untouched; a far point above both is the
 * first seed and faces +z. */
START_TEST(mst_components)
{
    size_t m = 1500, n = 2 * m + 3;
    double c0[3] = {0, 0, 0}, c1[3] = {10, 0, 0};
    double *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r);
    sphere(m, 1.0, c0, xyz, r, 5);
    sphere(m, 2.0, c1, xyz + 3 * m, r + m, 9);
    /* a failed point, a NaN point, a lone point far away */
    size_t f = 2 * m, nf = 2 * m + 1, lone = 2 * m + 2;
    memcpy(xyz + 3 * f, xyz, 3 * sizeof *xyz);
    memset(&r[f], 0, sizeof r[f]);
    r[f].status = JF_PT_FAILED;
    r[f].normal[0] = r[f].normal[1] = r[f].normal[2] = NAN;
    xyz[3 * nf] = NAN, xyz[3 * nf + 1] = 0, xyz[3 * nf + 2] = 0;
    r[nf] = r[f];
    r[nf].status = JF_PT_NONFINITE;
    xyz[3 * lone] = 100, xyz[3 * lone + 1] = 100, xyz[3 * lone + 2] = 100;
    memcpy(&r[lone], &r[0], sizeof r[0]);
    r[lone].status = 0;
    r[lone].normal[0] = 0, r[lone].normal[1] = 0, r[lone].normal[2] = -1;
    jf_index *ix = NULL;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    ck_assert_int_eq(jf_orient_mst(r, xyz, n, ix, 8), JF_OK);
    for (size_t i = 0; i < m; i++) ck_assert(side(&r[i], xyz + 3 * i, c0) > 0);
    for (size_t i = m; i < 2 * m; i++) ck_assert(side(&r[i], xyz + 3 * i, c1) > 0);
    ck_assert_uint_eq(r[f].status, JF_PT_FAILED);
    ck_assert(isnan(r[f].normal[0]));
    ck_assert_uint_eq(r[nf].status, JF_PT_NONFINITE);
    ck_assert_double_eq(r[lone].normal[2], 1.0);
    jf_index_free(ix);
    free(xyz);
    free(r);
}
END_TEST

START_TEST(bad_args)
{
    jf_result r;
    double p[3] = {0, 0, 0};
    ck_assert_int_eq(jf_orient_input(NULL, 1, p), JF_ERR_INVALID);
    ck_assert_int_eq(jf_orient_viewpoint(&r, NULL, 1, p), JF_ERR_INVALID);
    ck_assert_int_eq(jf_orient_mst(&r, p, 1, NULL, 8), JF_ERR_INVALID);
    ck_assert_int_eq(jf_orient_input(NULL, 0, NULL), JF_OK);
    /* one point: no neighbour to agree with, flagged, faces +z */
    memset(&r, 0, sizeof r);
    r.normal[2] = -1;
    r.d1[0] = 1;
    r.d2[1] = -1;
    jf_index *ix = NULL;
    ck_assert_int_eq(jf_index_build(p, 1, &ix), JF_OK);
    ck_assert_int_eq(jf_orient_mst(&r, p, 1, ix, 8), JF_OK);
    ck_assert_double_eq(r.normal[2], 1.0);
    ck_assert_uint_ne(r.status & JF_PT_ORIENT_UNKNOWN, 0);
    jf_index_free(ix);
}
END_TEST

/* The stored-graph variant on the k-NN lists gives the same bits as the
 * querying one (same graph, same Prim). */
START_TEST(mst_graph_equals_queries)
{
    size_t n = 3000, k = 8;
    double c[3] = {0, 0, 0}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r), *r2 = malloc(n * sizeof *r2);
    uint32_t *g = malloc(n * k * sizeof *g), nb[9];
    sphere(n, 1.0, c, xyz, r, 21);
    memcpy(r2, r, n * sizeof *r);
    jf_index *ix = NULL;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    for (size_t i = 0; i < n; i++) {
        size_t found = 0, m = 0;
        ck_assert_int_eq(jf_index_knn(ix, xyz + 3 * i, k + 1, nb, NULL, &found), JF_OK);
        for (size_t j = 0; j < found && m < k; j++)
            if (nb[j] != i) g[i * k + m++] = nb[j];
        while (m < k) g[i * k + m++] = UINT32_MAX;
    }
    ck_assert_int_eq(jf_orient_mst(r, xyz, n, ix, k), JF_OK);
    ck_assert_int_eq(jf_orient_mst_graph(r2, xyz, n, g, k), JF_OK);
    ck_assert(memcmp(r, r2, n * sizeof *r) == 0);
    for (size_t i = 0; i < n; i++) ck_assert(side(&r2[i], xyz + 3 * i, c) > 0);
    ck_assert_int_eq(jf_orient_mst_graph(r2, xyz, n, NULL, k), JF_ERR_INVALID);
    jf_index_free(ix);
    free(xyz);
    free(r);
    free(r2);
    free(g);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("orient");
    TCase *tc = tcase_create("orient");
    tcase_add_test(tc, viewpoint_centre_inward);
    tcase_add_test(tc, input_agrees);
    tcase_add_test(tc, mst_sphere_outward);
    tcase_add_test(tc, mst_components);
    tcase_add_test(tc, bad_args);
    tcase_add_test(tc, mst_graph_equals_queries);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
