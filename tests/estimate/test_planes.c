/* test_planes.c -- the PCA planes' smallest eigenvector (planes.c,
 * jf__pca_smallest: power iteration on the adjugate) against matrices
 * built from a known eigen-decomposition, and its refusals (the cases
 * left to jf__eig3). */
#include <check.h>
#include <math.h>
#include <stdint.h>

#include "fitter_internal.h"
#include "planes_internal.h"
#include "jf_test.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double urand(void) /* in [0, 1) */
{
    return jf_unit(jf_xorshift64s(&rng));
}

/* a random rotation q (columns: eigenvectors) from a unit quaternion */
static void rotation(double q[9])
{
    double w, x, y, z, l;
    do {
        w = 2 * urand() - 1, x = 2 * urand() - 1, y = 2 * urand() - 1, z = 2 * urand() - 1;
        l = w * w + x * x + y * y + z * z;
    } while (l > 1 || l < 1e-3);
    l = sqrt(l), w /= l, x /= l, y /= l, z /= l;
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                         2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    for (int k = 0; k < 9; k++) q[k] = r[k];
}

/* a = s q diag(l) q^T */
static void compose(const double q[9], const double l[3], double s, double a[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double v = 0;
            for (int k = 0; k < 3; k++) v += q[3 * i + k] * l[k] * q[3 * j + k];
            a[3 * i + j] = s * v;
        }
}

/* |sin| of the angle between unit n and q's first column */
static double sine(const double n[3], const double q[9])
{
    const double v[3] = {q[0], q[3], q[6]};
    const double c[3] = {n[1] * v[2] - n[2] * v[1], n[2] * v[0] - n[0] * v[2], n[0] * v[1] - n[1] * v[0]};
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

/* Separated spectra (l1/l2 from 1e-9 to 0.5, l2/l3 from 1e-3 to 1, any
 * scale from 1e-150 to 1e150): the unit eigenvector of l1 to
 * 1e-13 l3 / (l2 - l1) (what the rounding of a allows), as jf__eig3's. */
START_TEST(separated)
{
    const double r12[] = {1e-9, 1e-6, 1e-3, 0.1, 0.5}, r23[] = {1e-3, 0.1, 1},
                 sc[] = {1e-150, 1e-3, 1, 1e150};
    int n = 0;
    for (size_t a1 = 0; a1 < sizeof r12 / sizeof *r12; a1++)
        for (size_t a2 = 0; a2 < sizeof r23 / sizeof *r23; a2++)
            for (size_t a3 = 0; a3 < sizeof sc / sizeof *sc; a3++)
                for (int t = 0; t < 20; t++) {
                    double q[9], a[9], nrm[3], ev[3], evec[9];
                    double l[3] = {r12[a1] * r23[a2], r23[a2], 1};
                    rotation(q);
                    compose(q, l, sc[a3], a);
                    ck_assert_int_eq(jf__pca_smallest(a, nrm), 1);
                    jf__eig3(a, ev, evec);
                    double tol = 1e-13 / (l[1] - l[0]);
                    ck_assert_msg(sine(nrm, q) <= tol, "l %g %g %g s %g: angle %g", l[0], l[1],
                                  l[2], sc[a3], sine(nrm, q));
                    ck_assert(sine(evec, q) <= tol);
                    ck_assert(fabs(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2] - 1) < 1e-15);
                    n++;
                }
    ck_assert_int_eq(n, 5 * 3 * 4 * 20);
}
END_TEST

/* Points on a plane (l1 = 0): a n = 0 to rounding. */
START_TEST(coplanar)
{
    for (int t = 0; t < 200; t++) {
        double q[9], a[9], nrm[3], l[3] = {0, 0.01 + urand(), 1};
        rotation(q);
        compose(q, l, 1, a);
        ck_assert_int_eq(jf__pca_smallest(a, nrm), 1);
        for (int i = 0; i < 3; i++) {
            double r = a[3 * i] * nrm[0] + a[3 * i + 1] * nrm[1] + a[3 * i + 2] * nrm[2];
            ck_assert_msg(fabs(r) < 1e-14, "residual %g", r);
        }
    }
}
END_TEST

/* Refused, left to jf__eig3: zero, non-finite, collinear (l2 = 0), l1
 * within 1e-4 of l2 (the iteration would need ~3e5 steps).  (l1 = l2
 * exactly is accepted: any vector of that plane is an answer.) */
START_TEST(refused)
{
    double q[9], a[9], nrm[3] = {7, 7, 7};
    const double zero[9] = {0}, inf[9] = {INFINITY, 0, 0, 0, 1, 0, 0, 0, 1},
                 nan[9] = {NAN, 0, 0, 0, 1, 0, 0, 0, 1};
    ck_assert_int_eq(jf__pca_smallest(zero, nrm), 0);
    ck_assert_int_eq(jf__pca_smallest(inf, nrm), 0);
    ck_assert_int_eq(jf__pca_smallest(nan, nrm), 0);
    const double spectra[][3] = {{0, 0, 1}, {0, 0, 1e-30}, {0.5, 0.50005, 1}, {0.3, 0.30003, 2}};
    for (size_t k = 0; k < sizeof spectra / sizeof *spectra; k++) {
        rotation(q);
        compose(q, spectra[k], 1, a);
        ck_assert_msg(jf__pca_smallest(a, nrm) == 0, "spectrum %zu", k);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("planes");
    TCase *tc = tcase_create("pca");
    tcase_add_test(tc, separated);
    tcase_add_test(tc, coplanar);
    tcase_add_test(tc, refused);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
