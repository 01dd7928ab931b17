/* test_cli_mesh.c -- `jetfit estimate --neighbors rings` on bad meshes:
 * an out-of-range face index is a clear error and no output file; a
 * non-manifold edge, an isolated vertex and a degenerate face give
 * per-vertex statuses and every row, never a crash (issue 5). */
#include <check.h>
#include <math.h>

#include "test_cli_util.h"
#include "jf_test.h"

/* A 5x5 grid of z = x^2 + y^2 / 2 as OFF, 32 triangles, then `extra`
 * faces and vertices appended verbatim. */
static void write_grid_off(const char *path, const char *extra_v, int extra_nv,
                           const char *extra_f, int extra_nf)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, "OFF\n%d %d 0\n", 25 + extra_nv, 32 + extra_nf);
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            double x = 0.1 * (i - 2), y = 0.1 * (j - 2);
            fprintf(f, "%.17g %.17g %.17g\n", x, y, x * x + 0.5 * y * y);
        }
    fputs(extra_v, f);
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            int a = 5 * j + i, b = a + 1, c = a + 5, d = a + 6;
            fprintf(f, "3 %d %d %d\n3 %d %d %d\n", a, b, d, a, d, c);
        }
    fputs(extra_f, f);
    fclose(f);
}

START_TEST(face_index_out_of_range)
{
    write_grid_off(cli_path("bad.off"), "", 0, "3 0 1 99\n", 1);
    ck_assert_int_ne(cli_run("estimate", cli_path("bad.off"), "-o", cli_path("out.csv"),
                             "--neighbors", "rings", "--quiet", NULL), 0);
    ck_assert_msg(strstr(cli_err, "bad.off") && strstr(cli_err, "99"), "stderr: %s", cli_err);
    ck_assert(!cli_exists(cli_path("out.csv")));
}
END_TEST

START_TEST(nonmanifold_isolated_degenerate)
{
    /* vertex 25 hangs a third triangle on the interior edge 6-12
     * (6 = (1,1), 12 = (2,2)); vertex 26 is in no face; the face 7 7 8
     * is degenerate. */
    write_grid_off(cli_path("m.off"), "0.05 0.05 0.3\n0.9 0.9 0.9\n", 2,
                   "3 6 12 25\n3 7 7 8\n", 2);
    ck_assert_int_eq(cli_run("estimate", cli_path("m.off"), "-o", cli_path("out.csv"),
                             "--neighbors", "rings", "--degree", "2", "--frame", "axis", "--quiet", NULL),
                     0);
    jf_eval_table t;
    cli_read(cli_path("out.csv"), &t);
    ck_assert_uint_eq(t.nrows, 27); /* every vertex has its row */
    unsigned s6 = (unsigned)cli_val(&t, 6, "status");
    unsigned s12 = (unsigned)cli_val(&t, 12, "status");
    unsigned s18 = (unsigned)cli_val(&t, 18, "status");
    unsigned s26 = (unsigned)cli_val(&t, 26, "status");
    ck_assert_msg(s6 & JF_PT_MESH_NONMANIFOLD, "status of 6: %u", s6);
    ck_assert_msg(s12 & JF_PT_MESH_NONMANIFOLD, "status of 12: %u", s12);
    ck_assert_msg(!(s18 & JF_PT_MESH_NONMANIFOLD), "status of 18: %u", s18);
    /* the isolated vertex has only itself: no fit, said so, NaN row */
    ck_assert_msg(s26 & JF_PT_FAILED, "status of 26: %u", s26);
    ck_assert(isnan(cli_val(&t, 26, "nx")));
    /* vertex 4 = (0.2, -0.2) is four rings from the hanging vertex 25, so
     * its rings (1 + 2 + 3 + 4 + 5 = 15 >= 2 N_2 vertices) lie on the exact
     * z = x^2 + y^2/2, a 2-jet exactly in the axis frame: normal (-2x, -y, 1)/|.| = (-0.4, 0.2, 1)/|.| */
    double n[3] = {cli_val(&t, 4, "nx"), cli_val(&t, 4, "ny"), cli_val(&t, 4, "nz")};
    double len = sqrt(0.16 + 0.04 + 1);
    double dot = fabs(-0.4 * n[0] + 0.2 * n[1] + n[2]) / len;
    ck_assert_msg(dot > 1 - 1e-9, "normal at 4 off by %g", 1 - dot);
    ck_assert_uint_eq((unsigned)cli_val(&t, 4, "status"), 0);
    jf_eval_table_free(&t);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_mesh");
    TCase *tc = tcase_create("bad meshes");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, face_index_out_of_range);
    tcase_add_test(tc, nonmanifold_isolated_degenerate);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
