/* test_cli_las_normals.c -- a LAS file jetfit wrote carries its normals
 * as nx ny nz Extra Bytes; read back they are the cloud's normals (issue
 * 31), so --orient input works on it and follows them. */
#include <check.h>

#include "test_cli_util.h"

START_TEST(las_extra_bytes_are_normals)
{
    cli_setup();
    enum { N = 1500 };
    double *xyz = malloc(3 * N * sizeof *xyz);
    const double c[3] = {0, 0, 0};
    cli_sphere(N, 2.0, c, xyz);
    cli_write_xyz(cli_path("s.xyz"), xyz, NULL, N);
    /* towards the centre: every normal points inwards (n.x < 0) */
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("in.las"), "--quiet",
                             "--orient", "viewpoint:0,0,0", NULL), 0);
    jf_cloud cl;
    jf_error e = {{0}};
    ck_assert_int_eq(jf_cloud_read(cli_path("in.las"), NULL, &cl, &e), JF_OK);
    ck_assert_ptr_nonnull(cl.nrm);
    size_t inward = 0;
    for (size_t i = 0; i < cl.n; i++) {
        double d = 0, len = 0;
        for (int a = 0; a < 3; a++) d += cl.nrm[3 * i + a] * cl.xyz[3 * i + a], len += cl.nrm[3 * i + a] * cl.nrm[3 * i + a];
        inward += d < 0;
        ck_assert_double_eq_tol(len, 1.0, 1e-9);
    }
    ck_assert_uint_eq(inward, N);
    jf_cloud_free(&cl);
    /* --orient input follows them; --keep none reads them too */
    ck_assert_int_eq(cli_run("estimate", cli_path("in.las"), "-o", cli_path("r.csv"), "--quiet",
                             "--orient", "input", "--keep", "none", "--neighbors", "knn:20", NULL), 0);
    jf_eval_table t;
    cli_read(cli_path("r.csv"), &t);
    for (size_t i = 0; i < N; i++) {
        double d = cli_val(&t, i, "nx") * cli_val(&t, i, "x") + cli_val(&t, i, "ny") * cli_val(&t, i, "y") +
                   cli_val(&t, i, "nz") * cli_val(&t, i, "z");
        ck_assert_msg(d < 0, "point %zu: n.x = %g, not inwards", i, d);
    }
    jf_eval_table_free(&t);
    free(xyz);
    cli_teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_las_normals");
    TCase *t = tcase_create("las");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, las_extra_bytes_are_normals);
    suite_add_tcase(s, t);
    SRunner *r = srunner_create(s);
    srunner_run_all(r, CK_NORMAL);
    int nf = srunner_ntests_failed(r);
    srunner_free(r);
    return nf ? 1 : 0;
}
