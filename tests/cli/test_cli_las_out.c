/* test_cli_las_out.c -- `jetfit estimate ... -o X.las` from non-LAS input
 * (issue 30.2-4): the scale warning on stderr, also under --quiet;
 * --las-scale / --las-offset written into the header (decoded here) and
 * every bad use refused; coordinates LAS cannot hold refused with no file;
 * long column names shortened with a line each; --keep none keeps a LAS
 * input's CRS VLR byte for byte; --las-columns (issue 25.2): compact by
 * default in a .laz (floats, unit vectors to 2^-16), doubles in a .las,
 * each way on request, read back as the float of the double; bad uses
 * refused. */
#include <check.h>
#include <math.h>

#include "test_cli_util.h"
#include "jf_test.h"

/* n points of a paraboloid patch at (4123456.789012, 5e6, 100) +- 50. */
static void patch(const char *path, size_t n, const char *extra)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    for (size_t i = 0; i < n; i++) {
        double u = 100.0 * (double)(i % 20) / 19 - 50, v = 100.0 * (double)(i / 20) / 19 - 50;
        fprintf(f, "%.17g %.17g %.17g\n", 4123456.789012 + u, 5e6 + v, 100 + 1e-3 * (u * u + v * v));
    }
    if (extra) fputs(extra, f);
    fclose(f);
}

static double header_d(const char *path, size_t at)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    unsigned char b[8];
    ck_assert_int_eq(fseek(f, (long)at, SEEK_SET), 0);
    ck_assert_uint_eq(fread(b, 1, 8, f), 8);
    fclose(f);
    uint64_t u = 0;
    for (int k = 7; k >= 0; k--) u = u << 8 | b[k];
    double d;
    memcpy(&d, &u, 8);
    return d;
}

START_TEST(scale_warning_and_options)
{
    patch(cli_path("p.xyz"), 400, NULL);
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("p.las"), "--quiet",
                             NULL), 0);
    ck_assert_str_eq(cli_err, ""); /* 0.1 um: nothing to say */
    patch(cli_path("o.xyz"), 400, "1e10 5e6 100\n");
    ck_assert_int_eq(cli_run("estimate", cli_path("o.xyz"), "-o", cli_path("o.las"), "--quiet",
                             NULL), 0);
    char want[600];
    snprintf(want, sizeof want, "jetfit: %s: x: the LAS scale 10 (for coordinates from",
             cli_path("o.las"));
    ck_assert_msg(strstr(cli_err, want) == cli_err, "'%s'", cli_err);
    ck_assert_ptr_eq(strchr(cli_err, '\n'), cli_err + strlen(cli_err) - 1); /* one line */
    ck_assert(header_d(cli_path("o.las"), 131) == 10);
    /* chosen: in the header, no warning */
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("g.las"), "--quiet",
                             "--las-scale", "0.25,1e-3,1e-4", "--las-offset=4e6,5e6,0", NULL), 0);
    ck_assert_str_eq(cli_err, "");
    static const double sc[3] = {0.25, 1e-3, 1e-4}, of[3] = {4e6, 5e6, 0};
    for (int a = 0; a < 3; a++) {
        ck_assert(header_d(cli_path("g.las"), 131 + 8 * (size_t)a) == sc[a]);
        ck_assert(header_d(cli_path("g.las"), 155 + 8 * (size_t)a) == of[a]);
    }
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("g1.las"), "--quiet",
                             "--las-scale", "0.001", NULL), 0);
    for (int a = 0; a < 3; a++) ck_assert(header_d(cli_path("g1.las"), 131 + 8 * (size_t)a) == 1e-3);
    /* refused: bad values, a scale too fine for the extent, not a .las */
    static const char *const bad[] = {"0", "-1", "1,2", "1,2,3,4", "nan", "1e-3,x,1", "", "inf"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("b.las"),
                                 "--las-scale", bad[k], NULL), 2); /* a bad option */
        ck_assert_msg(strstr(cli_err, "--las-scale"), "'%s'", cli_err);
        ck_assert(!cli_exists(cli_path("b.las")));
    }
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("b.las"),
                             "--las-offset", "1,nan,2", NULL), 2);
    ck_assert_int_eq(cli_run("estimate", cli_path("o.xyz"), "-o", cli_path("b.las"),
                             "--las-scale", "1e-3", NULL), 1);
    ck_assert_msg(strstr(cli_err, "b.las: x: coordinates from") &&
                      strstr(cli_err, "do not fit int32 counts of the scale 0.001"),
                  "'%s'", cli_err);
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("b.ply"),
                             "--las-scale", "1e-3", NULL), 1);
    ck_assert_msg(strstr(cli_err, "apply to a .las output"), "'%s'", cli_err);
    ck_assert(!cli_exists(cli_path("b.las")) && !cli_exists(cli_path("b.ply")));
}
END_TEST

/* The attribute named nm of a cloud read from path (its index), the
 * cloud in *c. */
static size_t read_attr(const char *path, const char *nm, jf_cloud *c)
{
    jf_error e;
    ck_assert_msg(jf_cloud_read(path, NULL, c, &e) == JF_OK, "%s", e.msg);
    size_t k = 0;
    while (k < c->attrs.nattrs && strcmp(c->attrs.attr[k].name, nm)) k++;
    ck_assert_msg(k < c->attrs.nattrs, "%s: no %s", path, nm);
    return k;
}

/* 25.2: the Extra Bytes type of jetfit's real columns; one thread, so the
 * doubles are the same in every run */
START_TEST(las_columns)
{
    patch(cli_path("p.xyz"), 400, NULL);
    static const char *const out[] = {"d.las", "f.las", "f.laz", "d.laz"};
    static const char *const opt[] = {NULL, "float", NULL, "double"};
    for (int k = 0; k < 4; k++)
        ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path(out[k]),
                                 "--quiet", "--threads", "1",
                                 opt[k] ? "--las-columns" : NULL, opt[k], NULL), 0);
    static const char *const names[] = {"nx", "k1", "d2z", "cond", "residual", "status"};
    jf_cloud c[4];
    for (size_t q = 0; q < sizeof names / sizeof *names; q++) {
        size_t j[4];
        for (int k = 0; k < 4; k++) j[k] = read_attr(cli_path(out[k]), names[q], &c[k]);
        int integer = !strcmp(names[q], "status"), unit = q == 0 || q == 2;
        for (int k = 0; k < 4; k++)
            ck_assert_msg(c[k].attrs.attr[j[k]].type ==
                              (integer ? JF_ATTR_I32 : k == 0 || k == 3 ? JF_ATTR_F64 : JF_ATTR_F32),
                          "%s: %s", out[k], names[q]);
        for (size_t i = 0; i < c[0].n; i++) {
            double d = jf_attr_get(&c[0].attrs, j[0], i);
            double f = integer ? d : (double)(float)d, g = jf_attr_get(&c[2].attrs, j[2], i);
            ck_assert(jf_attr_get(&c[1].attrs, j[1], i) == f || (d != d));
            if (unit) /* compact: the nearest multiple of 2^-16 */
                ck_assert_msg((g * 65536 == floor(g * 65536) && fabs(g - d) <= 0x1p-17) || (d != d),
                              "%s: %.17g for %.17g", names[q], g, d);
            else
                ck_assert(g == f || (d != d));
            ck_assert(jf_attr_get(&c[3].attrs, j[3], i) == d || (d != d));
        }
        for (int k = 0; k < 4; k++) jf_cloud_free(&c[k]);
    }
    /* 13 real columns of 4 bytes, not 8 */
    read_attr(cli_path("d.las"), "nx", &c[0]);
    read_attr(cli_path("f.laz"), "nx", &c[1]);
    ck_assert_uint_eq(c[0].attrs.stride, c[1].attrs.stride + 13 * 4);
    jf_cloud_free(&c[0]);
    jf_cloud_free(&c[1]);
    /* refused: a bad type (a bad option), an output that is not LAS */
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("b.las"),
                             "--las-columns", "half", NULL), 2);
    ck_assert_msg(strstr(cli_err, "--las-columns") && strstr(cli_err, "expected double, float or compact"),
                  "'%s'", cli_err);
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("b.ply"),
                             "--las-columns", "float", NULL), 1);
    char want[600];
    snprintf(want, sizeof want, "jetfit: %s: --las-columns applies to a .las or .laz output\n",
             cli_path("b.ply"));
    ck_assert_str_eq(cli_err, want);
    ck_assert(!cli_exists(cli_path("b.las")) && !cli_exists(cli_path("b.ply")));
}
END_TEST

/* 30.4: +-1.7e308 wrote a header with an infinite scale, rc 0 */
START_TEST(huge_refused)
{
    patch(cli_path("h.xyz"), 100, "-1.7e308 5e6 100\n1.7e308 5e6 100\n");
    ck_assert_int_eq(cli_run("estimate", cli_path("h.xyz"), "-o", cli_path("h.las"), "--quiet",
                             NULL), 1);
    char want[600];
    snprintf(want, sizeof want, "jetfit: %s: x: coordinates from -1.6999999999999999e+308 to "
             "1.6999999999999999e+308: too far apart", cli_path("h.las"));
    ck_assert_msg(strstr(cli_err, want) == cli_err, "'%s'", cli_err);
    ck_assert(!cli_exists(cli_path("h.las")));
    ck_assert_int_eq(cli_count_files(), 1); /* no temporary left either */
}
END_TEST

START_TEST(long_names)
{
    FILE *f = fopen(cli_path("n.csv"), "w");
    fprintf(f, "x,y,z,a_column_name_of_forty_bytes_long_one,"
               "a_column_name_of_forty_bytes_long_two\n");
    for (int i = 0; i < 100; i++) fprintf(f, "%d,%d,%g,%d,%d\n", i % 10, i / 10, 0.01 * i, i, -i);
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", cli_path("n.csv"), "-o", cli_path("n.las"), "--quiet",
                             NULL), 0);
    char want[800];
    snprintf(want, sizeof want,
             "jetfit: %s: Extra Bytes name 'a_column_name_of_forty_bytes_long_one' is longer "
             "than LAS's 32 bytes: written as 'a_column_name_of_forty_bytes_l~1'\n"
             "jetfit: %s: Extra Bytes name 'a_column_name_of_forty_bytes_long_two' is longer "
             "than LAS's 32 bytes: written as 'a_column_name_of_forty_bytes_l~2'\n",
             cli_path("n.las"), cli_path("n.las"));
    ck_assert_str_eq(cli_err, want);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(cli_path("n.las"), NULL, &c, &e) == JF_OK, "%s", e.msg);
    int k = jf_attr_find(&c.attrs, "a_column_name_of_forty_bytes_l~2");
    ck_assert_int_ge(k, 0);
    ck_assert(jf_attr_get(&c.attrs, (size_t)k, 7) == -7);
    jf_cloud_free(&c);
}
END_TEST

/* --keep none: new records, but the input's CRS VLR (GeoKeyDirectory,
 * "LASF_Projection" 34735) copied byte for byte. */
START_TEST(keep_none_keeps_crs)
{
    const size_t n = 100, hs = 227, vl = 54 + 16, rl = 20;
    size_t len = hs + vl + n * rl;
    unsigned char *b = calloc(1, len);
    memcpy(b, "LASF", 4);
    b[24] = 1, b[25] = 2, b[94] = (unsigned char)hs;
    uint32_t off = (uint32_t)(hs + vl);
    memcpy(b + 96, &off, 4); /* little-endian host (CI: x86-64) */
    b[100] = 1, b[105] = (unsigned char)rl, b[107] = (unsigned char)n;
    double s = 0.01;
    for (int a = 0; a < 3; a++) memcpy(b + 131 + 8 * a, &s, 8);
    unsigned char *v = b + hs;
    memcpy(v + 2, "LASF_Projection", 15);
    v[18] = 0xAF, v[19] = 0x87, v[20] = 16; /* record 34735, 16 bytes */
    static const unsigned char keys[16] = {1, 0, 1, 0, 0, 0, 1, 0, 0x0C, 0x0C, 0, 0, 1, 0, 0x66, 0x7F};
    memcpy(v + 54, keys, 16);
    for (size_t i = 0; i < n; i++) {
        int32_t p[3] = {(int32_t)(i % 10) * 100, (int32_t)(i / 10) * 100, (int32_t)(i % 7)};
        memcpy(b + off + i * rl, p, 12);
    }
    FILE *f = fopen(cli_path("crs.las"), "wb");
    fwrite(b, 1, len, f);
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", cli_path("crs.las"), "-o", cli_path("k.las"), "--quiet",
                             "--keep", "none", NULL), 0);
    f = fopen(cli_path("k.las"), "rb");
    static unsigned char o[1 << 16];
    size_t ol = fread(o, 1, sizeof o, f);
    fclose(f);
    ck_assert_uint_ge(ol, 375);
    ck_assert_uint_eq(o[104], 0);
    size_t p = o[94] | o[95] << 8;
    uint32_t nv;
    memcpy(&nv, o + 100, 4);
    int found = 0;
    for (uint32_t k = 0; k < nv && p + 54 <= ol; k++) {
        size_t r = o[p + 20] | o[p + 21] << 8;
        if (!memcmp(o + p, v, 54 + 16)) found++;
        p += 54 + r;
    }
    ck_assert_int_eq(found, 1);
    free(b);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_las_out");
    TCase *tc = tcase_create("cli_las_out");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, scale_warning_and_options);
    tcase_add_test(tc, huge_refused);
    tcase_add_test(tc, long_names);
    tcase_add_test(tc, keep_none_keeps_crs);
    tcase_add_test(tc, las_columns);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
