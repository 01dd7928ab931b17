/* test_pipeline.c -- jf_estimate on whole clouds: analytic sphere values
 * and the sign convention, equality with fits on brute-force neighbours,
 * bit-identical results for 1 and 2 threads, rings on a mesh, natural
 * neighbours, progress calls, degenerate clouds. */
#include <check.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static void fib_sphere(size_t n, double R, const double c[3], double *xyz)
{
    const double ga = M_PI * (3.0 - sqrt(5.0));
    for (size_t i = 0; i < n; i++) {
        double z = 1 - 2 * ((double)i + 0.5) / (double)n, rr = sqrt(1 - z * z);
        xyz[3 * i] = c[0] + R * rr * cos(ga * (double)i);
        xyz[3 * i + 1] = c[1] + R * rr * sin(ga * (double)i);
        xyz[3 * i + 2] = c[2] + R * z;
    }
}

/* cos of the angle between the normal and the outward radial direction */
static double radial_cos(const jf_result *r, const double *p, const double c[3])
{
    double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    return (r->normal[0] * d[0] + r->normal[1] * d[1] + r->normal[2] * d[2]) / l;
}

/* §6.1 surface z = 0.1 exp(2x + y - y^2), jittered grid, shuffled. */
static void surface61(size_t side, double *xyz)
{
    unsigned long long s = 12345;
    size_t n = side * side;
    double h = 1.0 / (double)side;
    for (size_t i = 0; i < n; i++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        double dx = (double)(s >> 11) / 9007199254740992.0;
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        double dy = (double)(s >> 11) / 9007199254740992.0;
        double x = -0.5 + h * ((double)(i % side) + 0.9 * dx);
        double y = -0.5 + h * ((double)(i / side) + 0.9 * dy);
        xyz[3 * i] = x, xyz[3 * i + 1] = y, xyz[3 * i + 2] = 0.1 * exp(2 * x + y - y * y);
    }
    for (size_t i = n; i > 1; i--) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        size_t j = (size_t)((s >> 11) % i);
        for (int k = 0; k < 3; k++) {
            double t = xyz[3 * (i - 1) + k];
            xyz[3 * (i - 1) + k] = xyz[3 * j + k];
            xyz[3 * j + k] = t;
        }
    }
}

/* Sphere, knn:16, degree 2, mst: outward everywhere, and with outward
 * normals the sphere bends away: k1 = k2 = -1/R (DESIGN: z = (k1 x^2 +
 * k2 y^2)/2 along the normal).  Viewpoint at the centre: inward, +1/R. */
START_TEST(sphere_values_and_sign)
{
    size_t n = 3000;
    double R = 2, c[3] = {1, -2, 3}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r);
    fib_sphere(n, R, c, xyz);
    jf_cloud cl = {.n = n, .xyz = xyz};
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.k = 16;
    o.orient = JF_ORIENT_MST;
    jf_error e;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert_uint_eq(r[i].status, 0);
        ck_assert_int_eq(r[i].degree, 2);
        ck_assert_int_eq(r[i].n_used, 16);
        ck_assert_msg(radial_cos(&r[i], xyz + 3 * i, c) > cos(M_PI / 180), "point %zu", i);
        ck_assert_double_eq_tol(r[i].k1, -1 / R, 0.02 / R);
        ck_assert_double_eq_tol(r[i].k2, -1 / R, 0.02 / R);
        ck_assert(r[i].k1 >= r[i].k2);
    }
    o.orient = JF_ORIENT_VIEWPOINT;
    memcpy(o.viewpoint, c, sizeof o.viewpoint);
    ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert(radial_cos(&r[i], xyz + 3 * i, c) < -cos(M_PI / 180));
        ck_assert_double_eq_tol(r[i].k1, 1 / R, 0.02 / R);
    }
    free(xyz);
    free(r);
}
END_TEST

/* Each result equals a direct fit on brute-force nearest neighbours, and
 * 1 thread equals 2 threads bit for bit. */
static int cmp_d2(const void *a, const void *b)
{
    const double *x = a, *y = b;
    if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
    return (x[1] > y[1]) - (x[1] < y[1]);
}

START_TEST(brute_force_and_threads)
{
    size_t side = 90, n = side * side, K = 20;
    double *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r1 = malloc(n * sizeof *r1), *r2 = malloc(n * sizeof *r2);
    surface61(side, xyz);
    jf_cloud cl = {.n = n, .xyz = xyz};
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.params.degree = 3;
    o.params.monge_degree = 3;
    o.nb.k = K;
    o.threads = 1;
    ck_assert_int_eq(jf_estimate(&cl, &o, r1, NULL), JF_OK);
    o.threads = 2;
    ck_assert_int_eq(jf_estimate(&cl, &o, r2, NULL), JF_OK);
    ck_assert(memcmp(r1, r2, n * sizeof *r1) == 0);

    jf_fitter *f = NULL;
    ck_assert_int_eq(jf_fitter_create(&o.params, &f), JF_OK);
    double *key = malloc(2 * n * sizeof *key), nb[3 * 64];
    for (size_t q = 0; q < n; q += 97) {
        const double *p = xyz + 3 * q;
        for (size_t j = 0; j < n; j++) {
            const double *s = xyz + 3 * j;
            double dx = s[0] - p[0], dy = s[1] - p[1], dz = s[2] - p[2];
            key[2 * j] = dx * dx + dy * dy + dz * dz;
            key[2 * j + 1] = (double)j;
        }
        qsort(key, n, 2 * sizeof *key, cmp_d2);
        for (size_t j = 0; j < K; j++)
            memcpy(nb + 3 * j, xyz + 3 * (size_t)key[2 * j + 1], 3 * sizeof(double));
        jf_result ref;
        ck_assert_int_eq(jf_fit_point_full(f, p, nb, K, &ref), JF_OK);
        ck_assert_msg(memcmp(&ref, &r1[q], sizeof ref) == 0, "point %zu differs", q);
    }
    jf_fitter_free(f);
    free(key);
    free(xyz);
    free(r1);
    free(r2);
}
END_TEST

static size_t calls, last_done, last_total;
static int bad_thread, not_monotone;
static void prog(void *user, size_t done, size_t total)
{
    (void)user;
    if (omp_get_thread_num() != 0 || omp_in_parallel() > 1) bad_thread = 1;
    if (done < last_done) not_monotone = 1;
    calls++;
    last_done = done;
    last_total = total;
}

START_TEST(progress_and_nonfinite)
{
    size_t n = 5000;
    double c[3] = {0, 0, 0}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r);
    fib_sphere(n, 1, c, xyz);
    xyz[3 * 17 + 1] = NAN;
    xyz[3 * 18 + 2] = -INFINITY;
    jf_cloud cl = {.n = n, .xyz = xyz};
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.k = 12;
    o.threads = 2;
    o.progress = prog;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, NULL), JF_OK);
    ck_assert(calls >= 2);
    ck_assert_uint_eq(last_done, n);
    ck_assert_uint_eq(last_total, n);
    ck_assert(!bad_thread && !not_monotone);
    ck_assert_uint_eq(r[17].status, JF_PT_NONFINITE);
    ck_assert_uint_eq(r[18].status, JF_PT_NONFINITE);
    ck_assert(isnan(r[17].k1) && isnan(r[18].normal[0]));
    for (size_t i = 0; i < n; i++)
        if (i != 17 && i != 18) ck_assert_uint_eq(r[i].status, 0);
    free(xyz);
    free(r);
}
END_TEST

/* The cancel hook: polled on the calling thread; stopping at the k-th
 * poll returns JF_ERR_CANCELLED with no poll after it, and a hook that
 * never stops leaves the results bit-identical to no hook. */
typedef struct {
    int polls, stop_at, bad_thread;
} cancel_state;

static int cancel_at(void *user)
{
    cancel_state *s = user;
    if (omp_get_thread_num() != 0) s->bad_thread = 1;
    return ++s->polls == s->stop_at;
}

START_TEST(cancel_hook)
{
    size_t n = 20000;
    double c[3] = {0, 0, 0}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r0 = malloc(n * sizeof *r0), *r1 = malloc(n * sizeof *r1);
    fib_sphere(n, 1, c, xyz);
    jf_cloud cl = {.n = n, .xyz = xyz};
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.k = 12;
    o.threads = 2;
    o.orient = JF_ORIENT_VIEWPOINT;
    ck_assert_int_eq(jf_estimate(&cl, &o, r0, NULL), JF_OK);
    cancel_state s = {0, -1, 0};
    o.cancel = cancel_at;
    o.cancel_user = &s;
    ck_assert_int_eq(jf_estimate(&cl, &o, r1, NULL), JF_OK);
    ck_assert(memcmp(r0, r1, n * sizeof *r0) == 0);
    /* polls: after the tree, before the fit, >= 1 per block of thread 0,
     * before the orientation */
    ck_assert_int_ge(s.polls, 4);
    ck_assert(!s.bad_thread);
    for (int k = 1; k <= 4; k++) {
        jf_error e;
        s = (cancel_state){0, k, 0};
        ck_assert_int_eq(jf_estimate(&cl, &o, r1, &e), JF_ERR_CANCELLED);
        ck_assert_int_eq(s.polls, k);
        ck_assert_str_eq(e.msg, "cancelled");
        ck_assert(!s.bad_thread);
    }
    ck_assert_str_eq(jf_strerror(JF_ERR_CANCELLED), "cancelled");
    free(xyz);
    free(r0);
    free(r1);
}
END_TEST

START_TEST(degenerate_clouds)
{
    double xyz[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.1, 0.5, 0.3, 0.02};
    jf_result r[5];
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    jf_cloud cl = {.n = 2, .xyz = xyz};
    ck_assert_int_eq(jf_estimate(&cl, &o, r, NULL), JF_OK);
    for (int i = 0; i < 2; i++) {
        ck_assert_uint_ne(r[i].status & JF_PT_FAILED, 0);
        ck_assert_uint_ne(r[i].status & JF_PT_FEW_NEIGHBORS, 0);
    }
    cl.n = 5; /* 5 < N_2 = 6: degree 1 */
    ck_assert_int_eq(jf_estimate(&cl, &o, r, NULL), JF_OK);
    for (int i = 0; i < 5; i++) ck_assert_int_eq(r[i].degree, 1);
    cl.n = 0;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, NULL), JF_OK);
    /* rings without faces, orient input without normals: errors */
    cl.n = 5;
    jf_error e;
    o.nb.kind = JF_NB_RINGS;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_ERR_INVALID);
    ck_assert(strstr(e.msg, "rings") != NULL);
    jf_estimate_opts_init(&o);
    o.orient = JF_ORIENT_INPUT;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_ERR_INVALID);
    ck_assert(strstr(e.msg, "normals") != NULL);
}
END_TEST

/* A UV sphere mesh; rings:N neighbourhoods; viewpoint at the centre:
 * inward normals, k = +1/R away from the poles. */
START_TEST(rings_on_mesh)
{
    int nu = 80, nv = 40; /* longitude x latitude (poles excluded) */
    size_t n = (size_t)nu * (size_t)(nv - 1), nf = (size_t)nu * (size_t)(nv - 2);
    double R = 1.5, c[3] = {0, 0, 0}, *xyz = malloc(3 * n * sizeof *xyz);
    size_t *off = malloc((2 * nf + 1) * sizeof *off);
    uint32_t *idx = malloc(6 * nf * sizeof *idx);
    for (int j = 1; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            double th = M_PI * j / nv, ph = 2 * M_PI * i / nu;
            double *p = xyz + 3 * ((size_t)(j - 1) * nu + i);
            p[0] = R * sin(th) * cos(ph), p[1] = R * sin(th) * sin(ph), p[2] = R * cos(th);
        }
    size_t f = 0;
    for (int j = 0; j < nv - 2; j++)
        for (int i = 0; i < nu; i++) {
            uint32_t a = (uint32_t)(j * nu + i), b = (uint32_t)(j * nu + (i + 1) % nu);
            uint32_t cc = a + (uint32_t)nu, d = b + (uint32_t)nu;
            off[f] = 3 * f, idx[3 * f] = a, idx[3 * f + 1] = cc, idx[3 * f + 2] = b, f++;
            off[f] = 3 * f, idx[3 * f] = b, idx[3 * f + 1] = cc, idx[3 * f + 2] = d, f++;
        }
    off[f] = 3 * f;
    jf_cloud cl = {.n = n, .xyz = xyz, .nfaces = f, .face_off = off, .face_idx = idx};
    jf_result *r = malloc(n * sizeof *r);
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.kind = JF_NB_RINGS;
    o.nb.n = 19;
    o.orient = JF_ORIENT_VIEWPOINT;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, NULL), JF_OK);
    for (size_t i = 0; i < n; i++) {
        int lat = (int)(i / (size_t)nu) + 1;
        if (lat < 5 || lat > nv - 5) continue; /* rings stretch near the poles */
        ck_assert_int_eq(r[i].n_used, 19);
        ck_assert(radial_cos(&r[i], xyz + 3 * i, c) < -cos(M_PI / 180));
        ck_assert_double_eq_tol(r[i].k1, 1 / R, 0.03 / R);
        ck_assert_double_eq_tol(r[i].k2, 1 / R, 0.03 / R);
    }
    free(xyz);
    free(off);
    free(idx);
    free(r);
}
END_TEST

/* natural neighbours on a sphere: the default (PCA plane, k-NN cells)
 * and the pole plane (3D Delaunay cells) agree with the sphere. */
START_TEST(natural_on_sphere)
{
    size_t n = 2000;
    double R = 1, c[3] = {0.5, 0, 0}, *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *r = malloc(n * sizeof *r);
    fib_sphere(n, R, c, xyz);
    jf_cloud cl = {.n = n, .xyz = xyz};
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.kind = JF_NB_NATURAL;
    o.nb.n = 0;
    o.orient = JF_ORIENT_MST;
    jf_error e;
    for (int poles = 0; poles < 2; poles++) {
        o.normal = poles ? JF_NORMAL_POLES : JF_NORMAL_AUTO;
#ifdef JF_WITHOUT_CGAL /* the pole plane needs CGAL: the build says so */
        if (poles) {
            ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_ERR_UNSUPPORTED);
            ck_assert_ptr_nonnull(strstr(e.msg, "JF_CGAL=OFF"));
            break;
        }
#endif
        ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_OK);
        for (size_t i = 0; i < n; i++) {
            ck_assert_uint_ne(r[i].status & (poles ? JF_PT_NORMAL_POLES | JF_PT_NORMAL_MINCIRC
                                                   : JF_PT_NORMAL_PCA), 0);
            ck_assert_uint_eq(r[i].status & JF_PT_FAILED, 0);
            ck_assert_int_eq(r[i].n_used, 12);
            ck_assert(radial_cos(&r[i], xyz + 3 * i, c) > cos(2 * M_PI / 180));
            ck_assert_double_eq_tol(r[i].k1, -1 / R, 0.05 / R);
        }
    }
    o.normal = JF_NORMAL_AUTO;
    /* normals from the input: a zero one fails that row only */
    double *nrm = malloc(3 * n * sizeof *nrm);
    for (size_t i = 0; i < 3 * n; i++) nrm[i] = xyz[i] - c[i % 3];
    nrm[3 * 7] = nrm[3 * 7 + 1] = nrm[3 * 7 + 2] = 0;
    cl.nrm = nrm;
    o.normal = JF_NORMAL_INPUT;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_OK);
    for (size_t i = 0; i < n; i++) {
        if (i == 7) {
            ck_assert_uint_ne(r[i].status & JF_PT_FAILED, 0);
            continue;
        }
        ck_assert_uint_eq(r[i].status & ~(unsigned)JF_PT_UMBILIC, JF_PT_NORMAL_INPUT);
        ck_assert(radial_cos(&r[i], xyz + 3 * i, c) > cos(2 * M_PI / 180));
    }
    cl.nrm = NULL;
    free(nrm);
    /* pca normals: same neighbourhood kind, the pca flag alone */
    o.normal = JF_NORMAL_PCA;
    ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert_uint_eq(r[i].status, JF_PT_NORMAL_PCA);
        ck_assert(radial_cos(&r[i], xyz + 3 * i, c) > cos(2 * M_PI / 180));
    }
    free(xyz);
    free(r);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("pipeline");
    TCase *tc = tcase_create("pipeline");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, sphere_values_and_sign);
    tcase_add_test(tc, brute_force_and_threads);
    tcase_add_test(tc, progress_and_nonfinite);
    tcase_add_test(tc, cancel_hook);
    tcase_add_test(tc, degenerate_clouds);
    tcase_add_test(tc, rings_on_mesh);
    tcase_add_test(tc, natural_on_sphere);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
