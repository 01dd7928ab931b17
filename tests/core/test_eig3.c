/* test_eig3.c -- the faster eigen-solvers neighbors auto uses for its
 * frames, against matrices of known spectrum A = R diag(l) R^T (R a
 * random rotation): jf__normal3 (closed form: the least eigenvector, a
 * tangent frame around it), jf__eig3_in (Jacobi to rounding in given
 * axes) and jf__eig3_near (normal3's normal, the rest from the 2 x 2
 * block around it), within what rounding allows (eps x l3 / gap), and
 * agreeing with jf__eig3; they refuse or fall back where the normal is
 * not unique. */
#include <check.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fitter_internal.h"
#include "jf_test.h"

static uint64_t rng_state;
static double urand(void) { return jf_unit(jf_splitmix64(&rng_state)); }

/* a random rotation (rows), from a random unit quaternion */
static void rand_rot(double r[9])
{
    double q[4], n = 0;
    for (int i = 0; i < 4; i++) q[i] = 2 * urand() - 1, n += q[i] * q[i];
    n = sqrt(n);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                   2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(r, m, sizeof m);
}

/* A = sum_k l[k] v_k v_k^T with v_k the rows of r */
static void compose(const double r[9], const double l[3], double a[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double t = 0;
            for (int k = 0; k < 3; k++) t += l[k] * r[3 * k + i] * r[3 * k + j];
            a[3 * i + j] = t;
        }
}

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* the angle between unit vectors u and +-v */
static double axis_angle(const double *u, const double *v)
{
    double c = fabs(dot(u, v));
    double s[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    return atan2(sqrt(dot(s, s)), c);
}

/* spectra: a plane's (l1 << l2), thick noise (l1 near l2), clean (l1 ~
 * 1e-12 l3), at the scales 1 and 1e+-150 (coordinates 1e+-75) */
static void spectrum(int kind, double l[3])
{
    double s = kind % 4 == 3 ? 1e-150 : kind % 4 == 2 ? 1e150 : 1.0;
    double l3 = 1 + urand(), l2 = l3 * (0.05 + 0.95 * urand());
    double l1 = kind < 4 ? l2 * 0.3 * urand() : kind < 8 ? l2 * (0.5 + 0.45 * urand()) : l2 * 1e-12 * urand();
    l[0] = s * l1, l[1] = s * l2, l[2] = s * l3;
}

START_TEST(test_normal3_known)
{
    rng_state = 31;
    for (int t = 0; t < 6000; t++) {
        double r[9], l[3], a[9], e[9], ev[3], ej[9];
        rand_rot(r);
        spectrum(t % 12, l);
        compose(r, l, a);
        ck_assert_int_eq(jf__normal3(a, e), 1);
        /* eps x l3 / (l2 - l1), with room for the closed form's
         * constants (acos near its ends) */
        double tol = 64 * DBL_EPSILON * l[2] / (l[1] - l[0]) + 1e-15;
        ck_assert_msg(axis_angle(e, r) <= tol, "case %d: normal %.3g rad off (tol %.3g)", t,
                      axis_angle(e, r), tol);
        jf__eig3(a, ev, ej);
        ck_assert_msg(axis_angle(e, ej) <= tol, "case %d: normal vs jf__eig3", t);
        /* a right-handed orthonormal frame (t2 = n x t1: evec[3..5]) */
        ck_assert(fabs(dot(e, e) - 1) < 1e-15 && fabs(dot(e + 6, e + 6) - 1) < 1e-15);
        ck_assert(fabs(dot(e, e + 6)) < 1e-15 && fabs(dot(e + 3, e + 6)) < 1e-15 &&
                  fabs(dot(e, e + 3)) < 1e-15);
        double c[3] = {e[1] * e[8] - e[2] * e[7], e[2] * e[6] - e[0] * e[8], e[0] * e[7] - e[1] * e[6]};
        for (int i = 0; i < 3; i++) ck_assert(fabs(c[i] - e[3 + i]) < 1e-15);
        /* the sign pinned as jf__eig3's: the largest component positive */
        int k = 0;
        for (int i = 1; i < 3; i++)
            if (fabs(e[i]) > fabs(e[k])) k = i;
        ck_assert(e[k] > 0);
    }
}
END_TEST

START_TEST(test_normal3_refuses)
{
    double e[9], keep[9];
    for (int i = 0; i < 9; i++) e[i] = keep[i] = 7;
    const double iso[9] = {2, 0, 0, 0, 2, 0, 0, 0, 2}, zero[9] = {0};
    ck_assert_int_eq(jf__normal3(iso, e), 0);
    ck_assert_int_eq(jf__normal3(zero, e), 0);
    double nan_[9] = {1, 0, 0, 0, 2, 0, 0, 0, NAN}, inf_[9] = {1, 0, 0, 0, INFINITY, 0, 0, 0, 3};
    ck_assert_int_eq(jf__normal3(nan_, e), 0);
    ck_assert_int_eq(jf__normal3(inf_, e), 0);
    ck_assert(memcmp(e, keep, sizeof e) == 0);
    /* l1 = l2 (a line's cross-section): no unique normal */
    rng_state = 7;
    for (int t = 0; t < 1000; t++) {
        double r[9], a[9], l[3] = {0.5, 0.5, 1 + urand()};
        rand_rot(r);
        compose(r, l, a);
        ck_assert_msg(jf__normal3(a, e) == 0, "case %d: a repeated least eigenvalue accepted", t);
    }
}
END_TEST

START_TEST(test_eig3_in_known)
{
    rng_state = 47;
    for (int t = 0; t < 6000; t++) {
        double r[9], l[3], a[9], ev[3], e[9], ev1[3], e1[9], ax[9], in[9];
        rand_rot(r);
        spectrum(t % 12, l);
        compose(r, l, a);
        /* the axes: near the eigenvectors (as auto's K-point frame from
         * its 32-point one), random, or the world's (NULL) */
        int mode = t % 3;
        if (mode == 0) {
            double dr[9];
            rand_rot(dr);
            /* a small rotation: r turned by 1e-2 of a random one's angle */
            double th = 1e-2 * urand(), u[3] = {dr[0], dr[1], dr[2]};
            double c = cos(th), s = sin(th);
            for (int k = 0; k < 3; k++) { /* Rodrigues about u, each row of r */
                const double *v = r + 3 * k;
                double uxv[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
                double ud = dot(u, v);
                for (int i = 0; i < 3; i++) ax[3 * k + i] = v[i] * c + uxv[i] * s + u[i] * ud * (1 - c);
            }
        } else
            rand_rot(ax);
        /* a in the axes: in = ax a ax^T */
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double s = 0;
                for (int p = 0; p < 3; p++)
                    for (int q = 0; q < 3; q++) s += ax[3 * i + p] * a[3 * p + q] * ax[3 * j + q];
                in[3 * i + j] = s;
            }
        jf__eig3(a, ev1, e1);
        for (int near = 0; near < 2; near++) {
            if (near)
                jf__eig3_near(mode == 2 ? a : in, mode == 2 ? NULL : ax, ev, e);
            else if (mode == 2)
                jf__eig3_in(a, NULL, ev, e);
            else
                jf__eig3_in(in, ax, ev, e);
            for (int k = 0; k < 3; k++) {
                ck_assert_msg(fabs(ev[k] - l[k]) <= 64 * DBL_EPSILON * l[2], "case %d: eigenvalue %d", t, k);
                ck_assert_msg(fabs(ev[k] - ev1[k]) <= 64 * DBL_EPSILON * l[2], "case %d: vs jf__eig3", t);
                double gap = k == 0 ? l[1] - l[0] : k == 2 ? l[2] - l[1] : fmin(l[1] - l[0], l[2] - l[1]);
                double tol = 64 * DBL_EPSILON * l[2] / gap + 1e-15;
                ck_assert_msg(axis_angle(e + 3 * k, r + 3 * k) <= tol, "case %d: vector %d %.3g off", t, k,
                              axis_angle(e + 3 * k, r + 3 * k));
                ck_assert_msg(axis_angle(e + 3 * k, e1 + 3 * k) <= 2 * tol, "case %d: vs jf__eig3", t);
                /* the sign pinned as jf__eig3's: the largest component positive */
                int m = 0;
                for (int i = 1; i < 3; i++)
                    if (fabs(e[3 * k + i]) > fabs(e[3 * k + m])) m = i;
                ck_assert_msg(e[3 * k + m] > 0, "case %d (near %d): vector %d's sign", t, near, k);
            }
        }
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("eig3");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_normal3_known);
    tcase_add_test(tc, test_normal3_refuses);
    tcase_add_test(tc, test_eig3_in_known);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
