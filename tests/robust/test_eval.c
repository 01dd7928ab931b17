/* test_eval.c -- eval's error measures on hand-computed cases, and the
 * named-column table reader on small files of every supported kind. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "jetfit.h"
#include "jf_test.h"

static char tmpdir[256];

static const char *tmp_write(const char *name, const void *data, size_t len)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *fp = fopen(path, "wb");
    ck_assert_ptr_nonnull(fp);
    ck_assert_uint_eq(fwrite(data, 1, len, fp), len);
    fclose(fp);
    return path;
}

START_TEST(angle_hand_values)
{
    double x[3] = {1, 0, 0}, d[3] = {1, 1, 0}, z[3] = {0, 0, 2}, mz[3] = {0, 0, -1};
    double zero[3] = {0, 0, 0}, nan3[3] = {NAN, 0, 1};
    ck_assert_double_eq_tol(jf_normal_angle_deg(x, d), 45.0, 1e-12);
    ck_assert_double_eq_tol(jf_normal_angle_deg(z, mz), 0.0, 1e-12); /* unoriented */
    ck_assert_double_eq_tol(jf_normal_angle_deg(x, z), 90.0, 1e-12);
    /* 30 degrees, opposite orientation, unnormalised */
    double a[3] = {0, 0, 3}, b[3] = {-0.5, 0, -sqrt(3.0) / 2};
    ck_assert_double_eq_tol(jf_normal_angle_deg(a, b), 30.0, 1e-12);
    /* a.b rounding above |a||b| must not give NaN */
    double u[3] = {0.6, 0.8, 0}, v[3] = {0.6, 0.8, 0};
    ck_assert(jf_normal_angle_deg(u, v) >= 0.0);
    ck_assert(isnan(jf_normal_angle_deg(x, zero)));
    ck_assert(isnan(jf_normal_angle_deg(nan3, x)));
}
END_TEST

START_TEST(curvature_errors)
{
    ck_assert_double_eq_tol(jf_curv_error_rel(0.5, 0.2), 0.3, 1e-15);  /* max(|kt|,1)=1 */
    ck_assert_double_eq_tol(jf_curv_error_rel(3.0, -2.0), 2.5, 1e-15); /* 5 / 2 */
    ck_assert_double_eq(jf_curv_error_rel(-4.0, -4.0), 0.0);
    double ea[2], er[2];
    /* estimate oriented against the truth: (1, -3) w.r.t. -z is (3, -1) w.r.t. +z */
    double n[3] = {0, 0, -1}, nt[3] = {0, 0.1, 1};
    jf_curv_compare(n, 1.0, -3.0, nt, 3.0, -1.0, ea, er);
    ck_assert_double_eq_tol(ea[0], 0.0, 1e-15);
    ck_assert_double_eq_tol(ea[1], 0.0, 1e-15);
    /* same orientation: plain differences */
    double np[3] = {0, 0, 1};
    jf_curv_compare(np, 4.0, 0.5, nt, 2.0, -0.5, ea, er);
    ck_assert_double_eq_tol(ea[0], 2.0, 1e-15);
    ck_assert_double_eq_tol(er[0], 1.0, 1e-15); /* 2 / 2 */
    ck_assert_double_eq_tol(ea[1], 1.0, 1e-15);
    ck_assert_double_eq_tol(er[1], 1.0, 1e-15); /* 1 / max(0.5, 1) */
    jf_curv_compare(np, 4.0, 0.5, nt, 2.0, -0.5, NULL, er); /* NULL allowed */
}
END_TEST

START_TEST(stats_hand_values)
{
    double v[] = {3, 1, NAN, 2, INFINITY, 4};
    jf_err_stats s;
    ck_assert_int_eq(jf_err_stats_compute(v, 6, &s), JF_OK);
    ck_assert_uint_eq(s.n, 4);
    ck_assert_uint_eq(s.nonfinite, 2);
    ck_assert_double_eq_tol(s.mean, 2.5, 1e-15);
    ck_assert_double_eq_tol(s.rms, sqrt(30.0 / 4.0), 1e-15);
    ck_assert_double_eq_tol(s.median, 2.5, 1e-15);
    ck_assert_double_eq_tol(s.p95, 3.85, 1e-12); /* 3 + 0.85 * (4 - 3) */
    ck_assert_double_eq(s.max, 4.0);
    double one = 7.0;
    ck_assert_int_eq(jf_err_stats_compute(&one, 1, &s), JF_OK);
    ck_assert_double_eq(s.median, 7.0);
    ck_assert_double_eq(s.p95, 7.0);
    ck_assert_int_eq(jf_err_stats_compute(NULL, 0, &s), JF_OK);
    ck_assert_uint_eq(s.n, 0);
    ck_assert(isnan(s.rms));
    ck_assert_int_eq(jf_err_stats_compute(v, 6, NULL), JF_ERR_INVALID);
    /* odd count: the middle element; p95 of 0..100 is 95 */
    double r[101];
    for (int i = 0; i < 101; i++) r[i] = (double)(100 - i);
    jf_err_stats_compute(r, 101, &s);
    ck_assert_double_eq(s.median, 50.0);
    ck_assert_double_eq_tol(s.p95, 95.0, 1e-12);
}
END_TEST

START_TEST(read_csv_and_xyz)
{
    jf_eval_table t;
    jf_error e;
    const char csv[] = "x,y,z,nx,ny,nz,k1,k2,status\r\n1,2,3,0,0,1,0.5,-0.25,0\r\n"
                       "4,5,6,1,0,0,nan,nan,16\r\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("a.csv", csv, strlen(csv)), &t, &e), JF_OK);
    ck_assert_uint_eq(t.nrows, 2);
    ck_assert_uint_eq(t.ncols, 9);
    ck_assert_int_eq(jf_eval_table_col(&t, "k2"), 7);
    ck_assert_int_eq(jf_eval_table_col(&t, "nope"), -1);
    ck_assert_double_eq(t.v[7], -0.25);
    ck_assert_double_eq(t.v[9 + 8], 16.0);
    ck_assert(isnan(t.v[9 + 6]));
    jf_eval_table_free(&t);

    const char xyz[] = "# jetfit 0.1.0\n# x y z nx ny nz k1 k2\n0 0 0 0 0 1 2 1\n\n1 1 1 0 1 0 3 -1\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("b.xyz", xyz, strlen(xyz)), &t, &e), JF_OK);
    ck_assert_uint_eq(t.nrows, 2);
    ck_assert_int_eq(jf_eval_table_col(&t, "k1"), 6);
    ck_assert_double_eq(t.v[8 + 7], -1.0);
    jf_eval_table_free(&t);

    /* headerless PCPNet-style files: names from the extension */
    const char nrm[] = "-0.48 -0.005 -0.87\n0.8 -0.5 -0.29\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("s.normals", nrm, strlen(nrm)), &t, &e), JF_OK);
    ck_assert_int_eq(jf_eval_table_col(&t, "ny"), 1);
    ck_assert_double_eq(t.v[3], 0.8);
    jf_eval_table_free(&t);
    const char crv[] = "0.13 -0.06\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("s.curv", crv, strlen(crv)), &t, &e), JF_OK);
    ck_assert_int_eq(jf_eval_table_col(&t, "k2"), 1);
    jf_eval_table_free(&t);

    /* errors name file and line */
    const char bad[] = "# x y z\n1 2 3\n1 2\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("bad.xyz", bad, strlen(bad)), &t, &e), JF_ERR_FORMAT);
    ck_assert_ptr_nonnull(strstr(e.msg, "bad.xyz:3:"));
    ck_assert_ptr_null(t.v);
    const char word[] = "1 2 3\n1 2 x\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("w.xyz", word, strlen(word)), &t, &e), JF_ERR_FORMAT);
    ck_assert_ptr_nonnull(strstr(e.msg, "w.xyz:2:"));
    ck_assert_int_eq(jf_eval_table_read("/nonexistent/q.csv", &t, &e), JF_ERR_IO);
    ck_assert_ptr_nonnull(strstr(e.msg, "/nonexistent/q.csv"));
}
END_TEST

START_TEST(read_ply)
{
    jf_eval_table t;
    jf_error e;
    const char asc[] = "ply\nformat ascii 1.0\ncomment x\nelement vertex 2\nproperty float x\n"
                       "property double nz\nproperty uchar status\nelement face 1\n"
                       "property list uchar int vertex_indices\nend_header\n1.5 -1 3\n2 0.25 0\n3 0 1 0\n";
    ck_assert_int_eq(jf_eval_table_read(tmp_write("a.ply", asc, strlen(asc)), &t, &e), JF_OK);
    ck_assert_uint_eq(t.nrows, 2);
    ck_assert_int_eq(jf_eval_table_col(&t, "status"), 2);
    ck_assert_double_eq(t.v[0], 1.5);
    ck_assert_double_eq(t.v[4], 0.25);
    jf_eval_table_free(&t);

    const char hdr[] = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
                       "property double k1\nproperty int status\nend_header\n";
    unsigned char buf[256];
    size_t len = strlen(hdr);
    memcpy(buf, hdr, len);
    float fx[2] = {1.25f, -2.0f};
    double k[2] = {0.125, -7.5};
    int32_t s[2] = {0, 1024};
    for (int i = 0; i < 2; i++) {
        memcpy(buf + len, &fx[i], 4);
        memcpy(buf + len + 4, &k[i], 8);
        memcpy(buf + len + 12, &s[i], 4);
        len += 16;
    }
    ck_assert_int_eq(jf_eval_table_read(tmp_write("b.ply", buf, len), &t, &e), JF_OK);
    ck_assert_uint_eq(t.nrows, 2);
    ck_assert_double_eq(t.v[3], -2.0);
    ck_assert_double_eq(t.v[4], -7.5);
    ck_assert_double_eq(t.v[5], 1024.0);
    jf_eval_table_free(&t);
    /* truncated body */
    ck_assert_int_eq(jf_eval_table_read(tmp_write("c.ply", buf, len - 3), &t, &e), JF_ERR_FORMAT);
    ck_assert_ptr_nonnull(strstr(e.msg, "c.ply: element vertex 1"));
}
END_TEST

/* End to end: `jetfit eval` on a hand-made result/truth pair. */
START_TEST(cmd_eval_end_to_end)
{
    const char res[] = "x,y,z,nx,ny,nz,k1,k2,status\n"
                       "0,0,0,0,0,1,1,0,0\n"
                       "1,0,0,0,1,1,1,0,0\n"        /* 45 deg */
                       "2,0,0,0,0,-1,0,-2,0\n"      /* flipped: k = (2, 0) */
                       "3,0,0,nan,nan,nan,nan,nan,16\n";
    const char tru[] = "# x y z nx ny nz k1 k2\n0 0 0 0 0 1 1 0\n1 0 0 0 0 1 1 0\n"
                       "2 0 0 0 0 1 2 0\n3 0 0 0 0 1 0 0\n";
    char rp[512], tp[512], ip[512], cmd[4096], out[512];
    snprintf(rp, sizeof rp, "%s", tmp_write("r.csv", res, strlen(res)));
    snprintf(tp, sizeof tp, "%s", tmp_write("t.xyz", tru, strlen(tru)));
    snprintf(ip, sizeof ip, "%s", tmp_write("i.pidx", "1\n2\n", 4));
    snprintf(out, sizeof out, "%s/out.txt", tmpdir);
    snprintf(cmd, sizeof cmd, "%s/jetfit eval %s %s --subset %s > %s", JF_BUILD_DIR, rp, tp, ip, out);
    ck_assert_int_eq(system(cmd), 0);
    FILE *fp = fopen(out, "r");
    ck_assert_ptr_nonnull(fp);
    char line[512];
    int seen = 0;
    while (fgets(line, sizeof line, fp)) {
        double rms, mean, med;
        size_t n, nf;
        if (sscanf(line, "normal_deg %zu %zu %lf %lf %lf", &n, &nf, &rms, &mean, &med) == 5) {
            ck_assert_uint_eq(n, 2);
            ck_assert_double_eq_tol(mean, 22.5, 1e-3);
            ck_assert_double_eq_tol(rms, sqrt(45.0 * 45.0 / 2), 1e-3);
            seen++;
        }
        if (sscanf(line, "k1_abs %zu %zu %lf %lf", &n, &nf, &rms, &mean) == 4) {
            ck_assert_double_eq_tol(mean, 0.0, 1e-9);
            seen++;
        }
    }
    fclose(fp);
    ck_assert_int_eq(seen, 2);
    /* --by-status over all rows: the failed row's NaN is counted apart */
    snprintf(cmd, sizeof cmd, "%s/jetfit eval %s %s --by-status > %s", JF_BUILD_DIR, rp, tp, out);
    ck_assert_int_eq(system(cmd), 0);
    fp = fopen(out, "r");
    int status16 = 0;
    while (fgets(line, sizeof line, fp)) {
        size_t n, nf;
        if (strstr(line, "## status 16")) status16 = 1;
        if (status16 && sscanf(line, "normal_deg %zu %zu", &n, &nf) == 2) {
            ck_assert_uint_eq(n, 0);
            ck_assert_uint_eq(nf, 1);
            status16 = 2;
        }
    }
    fclose(fp);
    ck_assert_int_eq(status16, 2);
    /* bad subset index: error exit */
    snprintf(ip, sizeof ip, "%s", tmp_write("j.pidx", "7\n", 2));
    snprintf(cmd, sizeof cmd, "%s/jetfit eval %s %s --subset %s 2>/dev/null >/dev/null",
             JF_BUILD_DIR, rp, tp, ip);
    ck_assert_int_ne(system(cmd), 0);
}
END_TEST

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/jf_test_eval_XXXXXX");
    if (!mkdtemp(tmpdir)) return 1;
    Suite *s = suite_create("eval");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, angle_hand_values);
    tcase_add_test(tc, curvature_errors);
    tcase_add_test(tc, stats_hand_values);
    tcase_add_test(tc, read_csv_and_xyz);
    tcase_add_test(tc, read_ply);
    tcase_add_test(tc, cmd_eval_end_to_end);
    suite_add_tcase(s, tc);
    int rc = jf_test_run(s);
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    if (system(cmd) != 0) { /* leftover temp files are harmless */ }
    return rc;
}
