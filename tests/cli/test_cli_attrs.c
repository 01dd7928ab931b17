/* test_cli_attrs.c -- `jetfit estimate` carries the input's attributes
 * (issue 13.2, 13.4): a PLY with uchar colour and float intensity gives
 * them back after x y z in PLY, CSV and LAS outputs, bit for bit; the
 * jetfit columns are those of the same points without attributes; an
 * input `nx` comes out as `in_nx`; --keep none writes exactly the bytes of
 * the same points given without attributes (PLY and LAS inputs); a LAS
 * output of a LAS input reads back with jetfit's columns, and eval takes
 * it; a bad --keep is refused. */
#include <check.h>

#include "test_cli_util.h"
#include "jf_test.h"

#define N 300

static double pts[3 * N];

static void make_points(void)
{
    cli_surface61(17, pts, 5); /* 289 points */
    for (size_t i = 289; i < N; i++)
        for (int k = 0; k < 3; k++) pts[3 * i + k] = pts[3 * (i - 289) + k] + (k == 2 ? 2.0 : 0);
    for (size_t i = 0; i < N; i++) pts[3 * i] += 3e5;
}

/* Binary LE PLY: x y z double, red green blue uchar, intensity float,
 * nx float. */
static void write_colour_ply(const char *path)
{
    FILE *f = fopen(path, "wb");
    fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\n"
               "property double y\nproperty double z\nproperty uchar red\nproperty uchar green\n"
               "property uchar blue\nproperty float intensity\nproperty float nx\nend_header\n",
            N);
    for (size_t i = 0; i < N; i++) {
        fwrite(pts + 3 * i, sizeof(double), 3, f);
        unsigned char rgb[3] = {(unsigned char)i, (unsigned char)(255 - i % 256), 7};
        float in = 0.1f * (float)i, nx = 2.0f;
        fwrite(rgb, 1, 3, f);
        fwrite(&in, 4, 1, f);
        fwrite(&nx, 4, 1, f);
    }
    fclose(f);
}

START_TEST(colour_carried)
{
    make_points();
    write_colour_ply(cli_path("c.ply"));
    cli_write_xyz(cli_path("p.xyz"), pts, NULL, N);
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("ref.csv"), "--quiet",
                             "--neighbors", "knn:16", NULL), 0);
    jf_eval_table ref;
    cli_read(cli_path("ref.csv"), &ref);
    static const char *const outs[] = {"o.csv", "o.ply", "o.las"};
    for (size_t q = 0; q < 3; q++) {
        ck_assert_msg(cli_run("estimate", cli_path("c.ply"), "-o", cli_path(outs[q]), "--quiet",
                              "--neighbors", "knn:16", NULL) == 0, "%s", cli_err);
        /* the attributes, read with the library's reader: types and bits */
        jf_cloud c;
        jf_error e;
        ck_assert_msg(jf_cloud_read(cli_path(outs[q]), NULL, &c, &e) == JF_OK, "%s", e.msg);
        int r = jf_attr_find(&c.attrs, "red"), in = jf_attr_find(&c.attrs, q == 2 ? "in_intensity"
                                                                                 : "intensity");
        int nx = jf_attr_find(&c.attrs, "in_nx");
        ck_assert_msg(r >= 0 && in >= 0 && nx >= 0, "%s", outs[q]);
        if (q == 1) { /* PLY keeps the types */
            ck_assert_int_eq(c.attrs.attr[r].type, JF_ATTR_U8);
            ck_assert_int_eq(c.attrs.attr[in].type, JF_ATTR_F32);
        }
        for (size_t i = 0; i < N; i++) {
            ck_assert(jf_attr_get(&c.attrs, (size_t)r, i) == (double)(unsigned char)i);
            ck_assert(jf_attr_get(&c.attrs, (size_t)in, i) == (double)(0.1f * (float)i));
            ck_assert(jf_attr_get(&c.attrs, (size_t)nx, i) == 2.0);
        }
        jf_cloud_free(&c);
        /* the jetfit columns are the attribute-free run's */
        jf_eval_table t;
        cli_read(cli_path(outs[q]), &t);
        for (size_t j = 3; j < ref.ncols; j++)
            for (size_t i = 0; i < N; i++) {
                double a = cli_val(&ref, i, ref.names[j]), b = cli_val(&t, i, ref.names[j]);
                ck_assert_msg(!memcmp(&a, &b, 8) || (isnan(a) && isnan(b)), "%s %s row %zu",
                              outs[q], ref.names[j], i);
            }
        if (q == 0) { /* the order: x y z, the attributes, jetfit's */
            ck_assert_str_eq(t.names[3], "red");
            ck_assert_str_eq(t.names[7], "in_nx");
            ck_assert_str_eq(t.names[8], "nx");
        }
        jf_eval_table_free(&t);
    }
    jf_eval_table_free(&ref);
}
END_TEST

START_TEST(keep_none_is_todays_bytes)
{
    make_points();
    write_colour_ply(cli_path("c.ply"));
    cli_write_xyz(cli_path("p.xyz"), pts, NULL, N);
    static const char *const outs[] = {"csv", "ply", "las"};
    for (size_t q = 0; q < 3; q++) {
        char a[16], b[16];
        snprintf(a, sizeof a, "a.%s", outs[q]);
        snprintf(b, sizeof b, "b.%s", outs[q]);
        ck_assert_int_eq(cli_run("estimate", cli_path("c.ply"), "-o", cli_path(a), "--quiet",
                                 "--keep", "none", NULL), 0);
        ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path(b), "--quiet",
                                 NULL), 0);
        jf_test_assert_same_files("colour and attributes", cli_path(a), cli_path(b));
    }
    /* a LAS input: --keep none is the format 0 output of its x y z */
    const char *las = JF_TESTS_DIR "/data/las/simple.las";
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(las, NULL, &c, &e), JF_OK);
    cli_write_xyz(cli_path("s.xyz"), c.xyz, NULL, c.n);
    ck_assert_int_eq(cli_run("estimate", las, "-o", cli_path("s1.las"), "--quiet", "--keep",
                             "none", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("s2.las"), "--quiet",
                             NULL), 0);
    jf_test_assert_same_files("colour and attributes", cli_path("s1.las"), cli_path("s2.las"));
    /* --keep all (the default) keeps the input's format 3 records */
    ck_assert_int_eq(cli_run("estimate", las, "-o", cli_path("s3.las"), "--quiet", NULL), 0);
    size_t len;
    unsigned char *b = jf_test_slurp(cli_path("s3.las"), &len);
    ck_assert_int_eq(b[104], 3);
    free(b);
    /* which reads back with jetfit's columns: eval of it against the CSV
     * of the same run finds no difference */
    ck_assert_int_eq(cli_run("estimate", las, "-o", cli_path("s3.csv"), "--quiet", NULL), 0);
    ck_assert_msg(cli_run("eval", cli_path("s3.las"), cli_path("s3.csv"), NULL) == 0, "%s",
                  cli_err);
    jf_eval_table t, u;
    cli_read(cli_path("s3.las"), &t);
    cli_read(cli_path("s3.csv"), &u);
    ck_assert_uint_eq(t.ncols, u.ncols);
    for (size_t j = 0; j < t.ncols; j++) ck_assert_str_eq(t.names[j], u.names[j]);
    for (size_t i = 0; i < t.nrows * t.ncols; i++)
        ck_assert(!memcmp(&t.v[i], &u.v[i], 8) || (isnan(t.v[i]) && isnan(u.v[i])));
    jf_eval_table_free(&t);
    jf_eval_table_free(&u);
    jf_cloud_free(&c);
    /* a bad value */
    ck_assert_int_eq(cli_run("estimate", las, "-o", cli_path("x.csv"), "--keep", "some", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "--keep 'some': expected all or none"));
    ck_assert(!cli_exists(cli_path("x.csv")));
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_attrs");
    TCase *tc = tcase_create("attrs");
    tcase_set_timeout(tc, 120);
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_add_test(tc, colour_carried);
    tcase_add_test(tc, keep_none_is_todays_bytes);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
