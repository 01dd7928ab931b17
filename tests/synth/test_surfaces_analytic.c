/* test_surfaces_analytic.c -- differential quantities on surfaces with
 * known answers: Monge graphs (exact k, d, b0..b3, c0..c4), the saddle,
 * umbilics (never NaN), the sphere in both orientations and the cylinder
 * at points where the fitting frame is tilted from the normal (this
 * exercises the re-expansion over the tangent plane; the error is the
 * jet's truncation, O(h^(n-k+1)) by Theorem 3), the flip rule of docs/design.md
 * and jf_fit_cloud (1 thread == 2 threads, bit for bit). */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static uint64_t rng_state;
static double urand(void)
{
    return jf_unit(jf_splitmix64(&rng_state));
}

static jf_result fit(const double *p, const double *xyz, size_t n, int degree, int monge,
                     jf_frame_mode frame, jf_fit_mode mode)
{
    jf_params prm;
    jf_params_init(&prm);
    prm.degree = degree;
    prm.monge_degree = monge;
    prm.frame = frame;
    prm.fit = mode;
    prm.max_cond = INFINITY;
    jf_fitter *f = NULL;
    ck_assert_int_eq(jf_fitter_create(&prm, &f), JF_OK);
    jf_result r;
    ck_assert_int_eq(jf_fit_point(f, p, xyz, n, &r), JF_OK);
    jf_fitter_free(f);
    return r;
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Monge form z = (k1 x^2 + k2 y^2)/2 + (b0 x^3 + 3 b1 x^2 y + 3 b2 x y^2
 * + b3 y^3)/6 + (c0 x^4 + 4 c1 x^3 y + 6 c2 x^2 y^2 + 4 c3 x y^3 + c4 y^4)/24 */
static double monge_z(double k1, double k2, const double *b, const double *c, double x, double y)
{
    return (k1 * x * x + k2 * y * y) / 2 +
           (b[0] * x * x * x + 3 * b[1] * x * x * y + 3 * b[2] * x * y * y + b[3] * y * y * y) / 6 +
           (c[0] * x * x * x * x + 4 * c[1] * x * x * x * y + 6 * c[2] * x * x * y * y +
            4 * c[3] * x * y * y * y + c[4] * y * y * y * y) / 24;
}

/* A Monge graph in the world frame, then turned about z by alpha: the
 * axis frame is z, the jet is exact, and the fit must rotate back to the
 * principal directions (cos alpha, sin alpha, 0) and recover b, c. */
START_TEST(test_monge_graph)
{
    const double k1 = 1.5, k2 = -0.5, b[4] = {0.3, -0.2, 0.7, 0.1};
    const double c[5] = {0.4, 0.1, -0.3, 0.2, -0.6}, c0[5] = {0};
    const double alphas[4] = {0, 0.3, 1.2, -2.0};
    rng_state = 5;
    for (int m = 3; m <= 4; m++)
        for (int t = 0; t < 4; t++) {
            const double ca = cos(alphas[t]), sa = sin(alphas[t]);
            double xyz[3 * 40];
            const double *cc = m == 4 ? c : c0;
            for (int i = 0; i < 40; i++) {
                double x = i ? 0.4 * (2 * urand() - 1) : 0, y = i ? 0.4 * (2 * urand() - 1) : 0;
                double z = monge_z(k1, k2, b, cc, x, y);
                xyz[3 * i] = ca * x - sa * y;
                xyz[3 * i + 1] = sa * x + ca * y;
                xyz[3 * i + 2] = z;
            }
            for (int mode = 0; mode < 2; mode++) {
                size_t n = mode ? (m == 4 ? 15 : 10) : 40;
                jf_result r = fit(xyz, xyz, n, m, m, JF_FRAME_AXIS, (jf_fit_mode)mode);
                ck_assert_uint_eq(r.status, 0);
                ck_assert_double_eq_tol(r.k1, k1, 1e-9);
                ck_assert_double_eq_tol(r.k2, k2, 1e-9);
                ck_assert_double_eq_tol(r.normal[2], 1, 1e-12);
                /* d1 = +-(ca, sa, 0): pin the sign to compare b, c */
                double s = r.d1[0] * ca + r.d1[1] * sa;
                ck_assert_double_eq_tol(fabs(s), 1, 1e-9);
                for (int k = 0; k < 4; k++) /* x -> -x, y -> -y: odd order flips */
                    ck_assert_double_eq_tol(r.b[k] * s, b[k], 1e-9);
                for (int k = 0; k < 5; k++) ck_assert_double_eq_tol(r.c[k], cc[k], 1e-9);
                /* d1 x d2 = n */
                double cr[3] = {r.d1[1] * r.d2[2] - r.d1[2] * r.d2[1],
                                r.d1[2] * r.d2[0] - r.d1[0] * r.d2[2],
                                r.d1[0] * r.d2[1] - r.d1[1] * r.d2[0]};
                for (int k = 0; k < 3; k++) ck_assert_double_eq_tol(cr[k], r.normal[k], 1e-12);
            }
        }
}
END_TEST

/* The saddle z = (x^2 - y^2)/2 on centrally symmetric samples (so the PCA
 * normal is z too): k1 = 1, k2 = -1, d1 = +-x, in both frames. */
START_TEST(test_saddle)
{
    double xyz[3 * 49];
    int n = 0;
    for (int i = -3; i <= 3; i++)
        for (int j = -3; j <= 3; j++) {
            double x = 0.1 * i + 0.013 * j, y = 0.1 * j - 0.007 * i;
            xyz[3 * n] = x;
            xyz[3 * n + 1] = y;
            xyz[3 * n + 2] = (x * x - y * y) / 2;
            n++;
        }
    for (int fr = 0; fr < 2; fr++) {
        const double p[3] = {0, 0, 0};
        jf_result r = fit(p, xyz, 49, 2, 2, (jf_frame_mode)fr, JF_FIT_APPROX);
        ck_assert_uint_eq(r.status, 0);
        ck_assert_double_eq_tol(r.k1, 1, 1e-12);
        ck_assert_double_eq_tol(r.k2, -1, 1e-12);
        ck_assert_double_eq_tol(fabs(r.d1[0]), 1, 1e-12);
        ck_assert_double_eq_tol(fabs(r.d2[1]), 1, 1e-12);
        ck_assert_double_eq_tol(r.normal[2], 1, 1e-12);
    }
}
END_TEST

/* Umbilics: z = (x^2 + y^2) (k1 = k2 = 2) and a plane (k = 0): status
 * UMBILIC, d1, d2 an orthonormal tangent pair, nothing NaN. */
START_TEST(test_umbilic)
{
    double xyz[3 * 30];
    rng_state = 9;
    for (int s = 0; s < 2; s++) {
        for (int i = 0; i < 30; i++) {
            double x = i ? 2 * urand() - 1 : 0, y = i ? 2 * urand() - 1 : 0;
            xyz[3 * i] = x;
            xyz[3 * i + 1] = y;
            xyz[3 * i + 2] = s ? 0.2 * x - 0.1 * y : x * x + y * y;
        }
        jf_result r = fit(xyz, xyz, 30, 4, 4, JF_FRAME_AXIS, JF_FIT_APPROX);
        ck_assert_uint_eq(r.status, JF_PT_UMBILIC);
        ck_assert_double_eq_tol(r.k1, s ? 0 : 2, 1e-10);
        ck_assert_double_eq_tol(r.k2, s ? 0 : 2, 1e-10);
        ck_assert_double_eq_tol(dot(r.d1, r.d1), 1, 1e-14);
        ck_assert_double_eq_tol(dot(r.d2, r.d2), 1, 1e-14);
        ck_assert_double_eq_tol(dot(r.d1, r.d2), 0, 1e-14);
        ck_assert_double_eq_tol(dot(r.d1, r.normal), 0, 1e-14);
        for (int k = 0; k < 4; k++) ck_assert(isfinite(r.b[k]));
        for (int k = 0; k < 5; k++) ck_assert(isfinite(r.c[k]));
    }
}
END_TEST

/* Sphere of radius R at a point 35 degrees from the world z axis, axis and
 * PCA frames, 7-jet on a cap of angular radius 0.03 (measured errors: k
 * ~4e-10, b ~5e-9, c ~1e-5, each shrinking as h^(8-k) when the cap
 * shrinks: truncation, not a formula error).  Towards the centre: k1 = k2 = 1/R, b = 0, c0 = c4 = 3/R^3,
 * c2 = 1/R^3 (z = R - sqrt(R^2 - r^2) = r^2/2R + r^4/8R^3 + ...); towards
 * the outside every sign flips. */
START_TEST(test_sphere)
{
    const double R = 1.5, ctr[3] = {0.2, -0.1, 0.3}, th0 = 35 * M_PI / 180, ph0 = 0.6;
    double xyz[3 * 80], p[3];
    rng_state = 21;
    for (int i = 0; i < 80; i++) {
        double th = th0 + (i ? 0.03 * (2 * urand() - 1) : 0);
        double ph = ph0 + (i ? 0.03 * (2 * urand() - 1) : 0);
        xyz[3 * i] = ctr[0] + R * sin(th) * cos(ph);
        xyz[3 * i + 1] = ctr[1] + R * sin(th) * sin(ph);
        xyz[3 * i + 2] = ctr[2] + R * cos(th);
    }
    memcpy(p, xyz, sizeof p);
    const double in[3] = {ctr[0] - p[0], ctr[1] - p[1], ctr[2] - p[2]};
    const double out_[3] = {-in[0], -in[1], -in[2]};
    for (int fr = 0; fr < 2; fr++)
        for (int o = 0; o < 2; o++) {
            jf_result r = fit(p, xyz, 80, 7, 4, (jf_frame_mode)fr, JF_FIT_APPROX);
            ck_assert_int_eq(r.degree, 7);
            jf_result_orient(&r, o ? out_ : in);
            const double sg = o ? -1 : 1;
            ck_assert_double_eq_tol(dot(r.normal, in) / R, sg, 1e-10);
            ck_assert_double_eq_tol(r.k1, sg / R, 1e-8);
            ck_assert_double_eq_tol(r.k2, sg / R, 1e-8);
            for (int k = 0; k < 4; k++) ck_assert_double_eq_tol(r.b[k], 0, 1e-6);
            const double cw[5] = {3, 0, 1, 0, 3};
            for (int k = 0; k < 5; k++)
                ck_assert_double_eq_tol(r.c[k], sg * cw[k] / (R * R * R), 1e-4);
        }
}
END_TEST

/* Cylinder of radius R, axis along world y, at 30 degrees round: towards
 * the axis k1 = 1/R along the circle, k2 = 0 along the axis, b = 0,
 * c0 = 3/R^3 and c1..c4 = 0; flipped: k1 = 0, k2 = -1/R, c4 = -3/R^3. */
START_TEST(test_cylinder)
{
    const double R = 0.8, th0 = 30 * M_PI / 180;
    double xyz[3 * 80];
    rng_state = 33;
    for (int i = 0; i < 80; i++) {
        double th = th0 + (i ? 0.04 * (2 * urand() - 1) : 0), y = i ? 0.03 * (2 * urand() - 1) : 0;
        xyz[3 * i] = R * sin(th);
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = R * cos(th);
    }
    const double in[3] = {-xyz[0], 0, -xyz[2]}, out_[3] = {xyz[0], 0, xyz[2]};
    for (int fr = 0; fr < 2; fr++) {
        jf_result r = fit(xyz, xyz, 80, 7, 4, (jf_frame_mode)fr, JF_FIT_APPROX);
        jf_result_orient(&r, in);
        ck_assert_double_eq_tol(r.k1, 1 / R, 1e-8);
        ck_assert_double_eq_tol(r.k2, 0, 1e-8);
        ck_assert_double_eq_tol(fabs(r.d2[1]), 1, 1e-8); /* d2 along the axis */
        for (int k = 0; k < 4; k++) ck_assert_double_eq_tol(r.b[k], 0, 1e-6);
        ck_assert_double_eq_tol(r.c[0], 3 / (R * R * R), 1e-4);
        for (int k = 1; k < 5; k++) ck_assert_double_eq_tol(r.c[k], 0, 1e-4);
        jf_result_orient(&r, out_);
        ck_assert_double_eq_tol(r.k1, 0, 1e-8);
        ck_assert_double_eq_tol(r.k2, -1 / R, 1e-8);
        ck_assert_double_eq_tol(fabs(r.d1[1]), 1, 1e-8);
        ck_assert_double_eq_tol(r.c[4], -3 / (R * R * R), 1e-4);
    }
}
END_TEST

/* The flip rule is a change of Monge frame (x', y', z') = (y, x, -z): a
 * point of the Monge surface of r is on that of flip(r). */
START_TEST(test_flip_rule)
{
    jf_result r;
    memset(&r, 0, sizeof r);
    const double n[3] = {0.36, 0.48, 0.8}, d1[3] = {0.8, -0.6, 0};
    double d2[3] = {n[1] * d1[2] - n[2] * d1[1], n[2] * d1[0] - n[0] * d1[2],
                    n[0] * d1[1] - n[1] * d1[0]};
    memcpy(r.normal, n, sizeof n);
    memcpy(r.d1, d1, sizeof d1);
    memcpy(r.d2, d2, sizeof d2);
    r.k1 = 1.3;
    r.k2 = -0.4;
    const double b[4] = {0.1, 0.2, -0.3, 0.4}, c[5] = {0.5, -0.6, 0.7, 0.8, -0.9};
    memcpy(r.b, b, sizeof b);
    memcpy(r.c, c, sizeof c);
    jf_result f = r;
    jf_result_flip(&f);
    ck_assert(f.k1 >= f.k2);
    for (int t = 0; t < 5; t++) {
        double x = 0.1 * t - 0.2, y = 0.05 * t + 0.1, z = monge_z(r.k1, r.k2, r.b, r.c, x, y);
        double X[3];
        for (int k = 0; k < 3; k++) X[k] = x * r.d1[k] + y * r.d2[k] + z * r.normal[k];
        double xf = dot(X, f.d1), yf = dot(X, f.d2), zf = dot(X, f.normal);
        ck_assert_double_eq_tol(zf, monge_z(f.k1, f.k2, f.b, f.c, xf, yf), 1e-15);
    }
    jf_result_orient(&f, r.normal); /* back: the original, exactly */
    ck_assert(memcmp(&f, &r, sizeof r) == 0);
}
END_TEST

/* jf_fit_cloud on a grid of the Monge graph: 1 thread == 2 threads bit
 * for bit, equal to jf_fit_point, and a NaN point is NONFINITE. */
START_TEST(test_fit_cloud)
{
    enum { G = 12, K = 12 };
    double xyz[3 * G * G];
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            double x = 0.05 * i + 0.001 * j, y = 0.05 * j;
            double *q = xyz + 3 * (i * G + j);
            q[0] = x;
            q[1] = y;
            q[2] = 0.5 * x * x - 0.2 * y * y + 0.1 * x * y * y;
        }
    xyz[3 * 17 + 1] = NAN;
    size_t off[G * G + 1];
    uint32_t idx[G * G * K];
    /* brute-force K nearest (ties by index), NaN point excluded */
    for (size_t i = 0; i < G * G; i++) {
        off[i] = i * K;
        double dd[G * G];
        for (size_t j = 0; j < G * G; j++) {
            double dx = xyz[3 * j] - xyz[3 * i], dy = xyz[3 * j + 1] - xyz[3 * i + 1],
                   dz = xyz[3 * j + 2] - xyz[3 * i + 2];
            dd[j] = j == 17 ? INFINITY : dx * dx + dy * dy + dz * dz;
            if (isnan(dd[j])) dd[j] = INFINITY;
        }
        for (size_t k = 0; k < K; k++) {
            size_t best = 0;
            for (size_t j = 1; j < G * G; j++)
                if (dd[j] < dd[best]) best = j;
            idx[i * K + k] = (uint32_t)best;
            dd[best] = INFINITY * 0 + 1e300;
        }
    }
    off[G * G] = G * G * K;
    jf_params p;
    jf_params_init(&p);
    p.degree = 3;
    p.monge_degree = 3;
    static jf_result r1[G * G], r2[G * G];
    ck_assert_int_eq(jf_fit_cloud(&p, xyz, G * G, off, idx, 1, r1), JF_OK);
    ck_assert_int_eq(jf_fit_cloud(&p, xyz, G * G, off, idx, 2, r2), JF_OK);
    ck_assert(memcmp(r1, r2, sizeof r1) == 0);
    ck_assert_uint_eq(r1[17].status, JF_PT_NONFINITE);
    ck_assert(isnan(r1[17].k1));
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    double nb[3 * K];
    jf_result r;
    for (size_t k = 0; k < K; k++) memcpy(nb + 3 * k, xyz + 3 * idx[40 * K + k], 3 * sizeof(double));
    jf_fit_point(f, xyz + 3 * 40, nb, K, &r);
    ck_assert(memcmp(&r, &r1[40], sizeof r) == 0);
    jf_fitter_free(f);
    idx[5] = G * G; /* out of range */
    ck_assert_int_eq(jf_fit_cloud(&p, xyz, G * G, off, idx, 1, r1), JF_ERR_INVALID);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("surfaces_analytic");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_monge_graph);
    tcase_add_test(tc, test_saddle);
    tcase_add_test(tc, test_umbilic);
    tcase_add_test(tc, test_sphere);
    tcase_add_test(tc, test_cylinder);
    tcase_add_test(tc, test_flip_rule);
    tcase_add_test(tc, test_fit_cloud);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
