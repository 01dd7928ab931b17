/* test_convergence_mesh.c -- the §6.1 convergence rates through the mesh
 * path (perturbed triangulated grid, jf_mesh_build, jf_nb_query_mesh
 * rings, jf_fit_point): Theorem 3 says the error on a k-th order quantity
 * from a degree-n jet is O(h^(n-k+1)), so the slope of log(1/delta)
 * against log(1/h) is n for the normal and n - 1 for kmin and kmax.
 * Approximation, degrees 1..4, h = 2^-2 .. 2^-6: each slope within 0.5. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "convergence.h"
#include "jf_test.h"

START_TEST(approximation_slopes_match_theorem_3)
{
    jf_conv_config c;
    jf_conv_config_init(&c, 1);
    c.interp = 0;
    c.deg_lo = 1;
    c.deg_hi = 4;
    size_t nr = jf_conv_row_count(&c);
    ck_assert_uint_eq(nr, 4 * 5);
    jf_conv_row *rows = calloc(nr, sizeof *rows);
    ck_assert_int_eq(jf_conv_run(&c, rows), JF_OK);
    for (int d = 0; d < 4; d++) {
        const jf_conv_row *r = rows + d * c.nh;
        int n = d + 1;
        ck_assert_int_eq(r->degree, n);
        for (int k = 0; k < c.nh; k++) {
            ck_assert_uint_eq(r[k].lowered, 0);
            ck_assert_uint_eq(r[k].failed, 0);
            ck_assert(r[k].h == ldexp(1.0, -(k + 2)));
            ck_assert(r[k].max[JF_CONV_NORMAL] >= r[k].avg[JF_CONV_NORMAL]);
        }
        size_t used;
        double s = jf_conv_slope(r, (size_t)c.nh, JF_CONV_NORMAL, &used);
        ck_assert_msg(fabs(s - n) < 0.5, "degree %d normal slope %g", n, s);
        ck_assert_uint_ge(used, 4);
        for (int q = JF_CONV_KMIN; q <= JF_CONV_KMAX; q++) {
            s = jf_conv_slope(r, (size_t)c.nh, q, &used);
            if (n == 1) { /* a 1-jet has no curvature: NaN, no slope */
                ck_assert(isnan(r->avg[q]) && isnan(s));
                continue;
            }
            ck_assert_msg(fabs(s - (n - 1)) < 0.5, "degree %d %s slope %g", n,
                          q == JF_CONV_KMIN ? "kmin" : "kmax", s);
        }
    }
    /* the finest degree-4 errors are small in absolute terms too */
    ck_assert(rows[3 * c.nh + 4].avg[JF_CONV_NORMAL] < 1e-6);
    free(rows);
}
END_TEST

START_TEST(same_seed_same_bits)
{
    jf_conv_config c;
    jf_conv_config_init(&c, 1);
    c.deg_hi = 3;
    c.nh = 3;
    size_t nr = jf_conv_row_count(&c);
    jf_conv_row *a = calloc(nr, sizeof *a), *b = calloc(nr, sizeof *b);
    ck_assert_int_eq(jf_conv_run(&c, a), JF_OK);
    ck_assert_int_eq(jf_conv_run(&c, b), JF_OK);
    ck_assert(memcmp(a, b, nr * sizeof *a) == 0);
    c.seed = 2; /* another perturbation: other numbers */
    ck_assert_int_eq(jf_conv_run(&c, b), JF_OK);
    ck_assert(a[nr - 1].avg[0] != b[nr - 1].avg[0]);
    free(a);
    free(b);
}
END_TEST

/* The floor rule of jf_conv_slope on made-up rows: exact power laws
 * give their exponent; a flattened tail is left out. */
START_TEST(slope_floor_rule)
{
    jf_conv_row r[5];
    memset(r, 0, sizeof r);
    for (int k = 0; k < 5; k++) {
        r[k].h = ldexp(1.0, -(k + 2));
        r[k].avg[0] = 3e-3 * pow(r[k].h, 4);
    }
    size_t used;
    ck_assert(fabs(jf_conv_slope(r, 5, 0, &used) - 4) < 1e-12);
    ck_assert_uint_eq(used, 5);
    r[4].avg[0] = r[3].avg[0] * 0.9; /* stopped decreasing below 1e-6 */
    ck_assert(fabs(jf_conv_slope(r, 5, 0, &used) - 4) < 1e-12);
    ck_assert_uint_eq(used, 4);
    r[1].avg[0] = 1e-14; /* below the absolute floor at once */
    ck_assert(isnan(jf_conv_slope(r, 5, 0, &used)));
    ck_assert_uint_eq(used, 1);
}
END_TEST

START_TEST(bad_config)
{
    jf_conv_config c;
    jf_conv_row r[1];
    jf_conv_config_init(&c, 1);
    c.deg_hi = 10;
    ck_assert_int_eq(jf_conv_run(&c, r), JF_ERR_INVALID);
    jf_conv_config_init(&c, 1);
    c.h[1] = c.h[0]; /* h must decrease */
    ck_assert_int_eq(jf_conv_run(&c, r), JF_ERR_INVALID);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("convergence_mesh");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, approximation_slopes_match_theorem_3);
    tcase_add_test(tc, same_seed_same_bits);
    tcase_add_test(tc, slope_floor_rule);
    tcase_add_test(tc, bad_config);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
