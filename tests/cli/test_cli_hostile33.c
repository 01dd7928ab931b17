/* test_cli_hostile33.c -- issue 33 (hostile probe, round 3), items 3, 4,
 * 6, 11 and 12: faces, short bad rows, wide CSVs, messages, and the
 * outputs and inputs a command must refuse.  Each test fails on the code
 * before the fix (said per test).  The picture cases are in
 * test_cli_pictures.c and test_cli_fulldisk.c. */
#define _GNU_SOURCE
#include <check.h>
#include <signal.h>

#include "jf_test.h"
#include "test_cli_util.h"

static void teardown(void) { cli_rm_rf(cli_dir); }

/* An OFF: a 300-gon (a wavy circle) and a triangle with a centre vertex. */
static void write_polygon_off(const char *path)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, "OFF\n301 2 0\n");
    for (int i = 0; i < 300; i++)
        fprintf(f, "%.17g %.17g %.17g\n", cos(2 * M_PI * i / 300), sin(2 * M_PI * i / 300),
                0.01 * sin(5.0 * i));
    fprintf(f, "0 0 0.1\n300");
    for (int i = 0; i < 300; i++) fprintf(f, " %d", i);
    fprintf(f, "\n3 0 1 300\n");
    fclose(f);
}

/* 3. A 300-vertex polygon and a triangle reach the PLY output (before:
 * no face element at all, rc 0).  Read back by hand from the ascii PLY:
 * the header's face element and count type, then the face lines. */
START_TEST(mesh_faces_kept)
{
    const char *off = cli_path("poly.off"), *ply = cli_path("poly.ply");
    write_polygon_off(off);
    ck_assert_int_eq(cli_run("estimate", off, "-o", ply, "--ascii", "--quiet", NULL), 0);
    size_t n;
    char *b = jf_test_slurp(ply, &n);
    ck_assert_ptr_nonnull(b);
    ck_assert_ptr_nonnull(strstr(b, "element face 2\nproperty list uint int vertex_indices\n"));
    char *body = strstr(b, "end_header\n");
    ck_assert_ptr_nonnull(body);
    body += strlen("end_header\n");
    for (int i = 0; i < 301; i++) { /* the vertex rows */
        body = strchr(body, '\n');
        ck_assert_ptr_nonnull(body);
        body++;
    }
    char *e;
    ck_assert_int_eq(strtol(body, &e, 10), 300);
    for (long i = 0; i < 300; i++) ck_assert_int_eq(strtol(e, &e, 10), i);
    ck_assert_int_eq(*e, '\n');
    ck_assert_int_eq(strtol(e + 1, &e, 10), 3);
    ck_assert_int_eq(strtol(e, &e, 10), 0);
    ck_assert_int_eq(strtol(e, &e, 10), 1);
    ck_assert_int_eq(strtol(e, &e, 10), 300);
    ck_assert_str_eq(e, "\n");
    free(b);
    /* the binary PLY too, read back through the library's reader */
    ck_assert_int_eq(cli_run("estimate", off, "-o", ply, "--quiet", NULL), 0);
    jf_cloud c;
    jf_error err;
    ck_assert_int_eq(jf_cloud_read(ply, NULL, &c, &err), JF_OK);
    ck_assert_uint_eq(c.nfaces, 2);
    ck_assert_uint_eq(c.face_off[1], 300);
    ck_assert_uint_eq(c.face_idx[299], 299);
    ck_assert_uint_eq(c.face_idx[302], 300);
    jf_cloud_free(&c);
}
END_TEST

/* 3. The writer: a face naming a row the file does not have is refused
 * (JF_ERR_INVALID: the return the command and Python now act on; this
 * check passed before too), and a triangle mesh keeps its uchar counts. */
START_TEST(writer_faces_checked)
{
    jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    jf_writer *w;
    jf_error err;
    size_t off[2] = {0, 3};
    uint32_t bad[3] = {0, 1, 99999}, good[3] = {0, 1, 2};
    ck_assert_int_eq(jf_writer_open(cli_path("w.ply"), cols, 3, 3, 1, &w, &err), JF_OK);
    ck_assert_int_eq(jf_writer_faces(w, 1, off, bad), JF_ERR_INVALID);
    ck_assert_int_eq(jf_writer_faces(w, 1, off, good), JF_OK);
    double v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    ck_assert_int_eq(jf_writer_rows(w, v, 3, 1), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &err), JF_OK);
    size_t n;
    char *b = jf_test_slurp(cli_path("w.ply"), &n);
    ck_assert_ptr_nonnull(strstr(b, "property list uchar int vertex_indices\nend_header\n"));
    ck_assert_ptr_nonnull(strstr(b, "\n3 0 1 2\n"));
    free(b);
}
END_TEST

/* 4. --bad-rows skip with a short bad row (before: "more rows than
 * supported", rc 1: the row bound assumed 2 bytes a field). */
START_TEST(short_bad_rows_skipped)
{
    const char *in = cli_path("short.xyz"), *out = cli_path("short.csv");
    cli_write_text(in, "1 2 3\n4 5\n7 8 9\n1 1 1\n");
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--bad-rows", "skip", "--neighbors",
                             "knn:3", NULL), 0);
    ck_assert_ptr_nonnull(strstr(cli_err, "lines 2"));
    jf_eval_table t;
    cli_read(out, &t);
    ck_assert_uint_eq(t.nrows, 4);
    ck_assert(isnan(cli_val(&t, 1, "x")));
    ck_assert((unsigned)cli_val(&t, 1, "status") & JF_PT_NONFINITE);
    ck_assert(cli_val(&t, 2, "x") == 7 && cli_val(&t, 3, "z") == 1);
    jf_eval_table_free(&t);
    /* many one-character bad rows between good ones */
    FILE *f = fopen(in, "w");
    for (int i = 0; i < 2000; i++) fprintf(f, "%d %d %d\nx\n", i % 7, i % 11, i % 13);
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--bad-rows", "skip", "--quiet", NULL), 0);
    cli_read(out, &t);
    ck_assert_uint_eq(t.nrows, 4000);
    ck_assert(cli_val(&t, 3998, "x") == 1999 % 7 && isnan(cli_val(&t, 3999, "x")));
    jf_eval_table_free(&t);
}
END_TEST

/* 6. A CSV of 100,000 named columns (before: "out of memory" after half
 * a minute: a name search per pair of columns, then a 3 MB row times 4096
 * rows per thread).  Every column reaches the output, values intact. */
START_TEST(wide_csv)
{
    const char *in = cli_path("wide.csv"), *out = cli_path("wide_out.csv");
    const int m = 100000;
    FILE *f = fopen(in, "w");
    fprintf(f, "x,y,z");
    for (int j = 0; j < m; j++) fprintf(f, ",c%d", j);
    fputc('\n', f);
    for (int r = 0; r < 5; r++) {
        fprintf(f, "%d,%d,%d", r, r * r, r % 2);
        for (int j = 0; j < m; j++) fprintf(f, ",%d", (j + r) % 1000);
        fputc('\n', f);
    }
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--neighbors", "knn:4", "--quiet", NULL),
                     0);
    size_t n;
    char *b = jf_test_slurp(out, &n);
    ck_assert_ptr_nonnull(b);
    char *nl = strchr(b, '\n');
    *nl = '\0';
    ck_assert_ptr_nonnull(strstr(b, ",c0,"));
    ck_assert_ptr_nonnull(strstr(b, ",c99999,"));
    /* the last row: x y z, then c0 c1 c2 ... (the input's columns) */
    char *last = strrchr(nl + 1, '\n');
    *last = '\0';
    last = strrchr(nl + 1, '\n') + 1;
    const char *want = "4,16,0,4,5,6,";
    ck_assert_msg(!strncmp(last, want, strlen(want)), "%.40s", last);
    free(b);
}
END_TEST

/* 11. --degree-select above --degree names its value (before: "''"). */
START_TEST(degree_select_message)
{
    const char *in = cli_path("s.ply");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "300", "-o", in, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("o.csv"), "--degree", "2",
                             "--degree-select", "5", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "--degree-select '5': must not exceed degree"));
}
END_TEST

/* 12. study stops on SIGTERM with 128 + 15 (before: 130, SIGINT's). */
START_TEST(study_sigterm_143)
{
    char dir[600];
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int fo = open("/dev/null", O_WRONLY);
        dup2(fo, 1), dup2(fo, 2);
        execl(JETFIT_BIN, JETFIT_BIN, "study", "exp", "-o", dir, "--n", "200000", "--repeat",
              "20", "--threads", "1", "--quiet", (char *)NULL);
        _exit(127);
    }
    char csv[700];
    snprintf(csv, sizeof csv, "%s/study.csv", dir);
    /* signal it once its first cell is in study.csv: its own handler runs
     * (before it, main.c's gives 143 anyway) */
    for (int t = 0; t < 6000 && !cli_exists(csv); t++) usleep(5000);
    ck_assert(cli_exists(csv));
    kill(pid, SIGTERM);
    int st;
    waitpid(pid, &st, 0);
    ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 143, "status %d", st);
}
END_TEST

/* 12. -o onto a FIFO: refused, the FIFO stays (before: replaced by a
 * regular file, rc 0). */
START_TEST(fifo_output_refused)
{
    const char *in = cli_path("s.ply"), *fifo = cli_path("out.csv");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "300", "-o", in, NULL), 0);
    ck_assert_int_eq(mkfifo(fifo, 0600), 0);
    ck_assert_int_eq(cli_run("estimate", in, "-o", fifo, "--quiet", NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "out.csv: is a FIFO, not a regular file"));
    struct stat sb;
    ck_assert_int_eq(lstat(fifo, &sb), 0);
    ck_assert(S_ISFIFO(sb.st_mode));
    ck_assert_int_eq(cli_count_files(), 2);
}
END_TEST

/* 12. Coordinates near 1e160: no point can be fitted -> exit 1, one line,
 * nothing written (before: rc 0, every point failed, nothing said);
 * most points unfitted -> a warning. */
START_TEST(no_point_fitted)
{
    const char *in = cli_path("huge.xyz"), *out = cli_path("huge.csv");
    FILE *f = fopen(in, "w");
    for (int i = 0; i < 400; i++)
        fprintf(f, "%.17g %.17g %.17g\n", 1e160 * sin(i * 1.1), 1e160 * cos(i * 0.7),
                1e160 * sin(i * 0.3));
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "huge.xyz: no point could be fitted (0 non-finite, 400 failed)"));
    ck_assert_ptr_nonnull(strstr(cli_err, "overflow"));
    ck_assert(!cli_exists(out));
    /* knn:1 (issue 31): no fit is possible either */
    const char *s = cli_path("s.ply");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "300", "-o", s, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", s, "-o", out, "--neighbors", "knn:1", NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "no point could be fitted"));
    ck_assert(!cli_exists(out));
    /* 300 NaN rows (kept by --bad-rows skip) and 100 good ones: a warning */
    f = fopen(in, "w");
    for (int i = 0; i < 400; i++)
        if (i % 4 == 0) fprintf(f, "%.17g %.17g %.17g\n", sin(i * 1.1), cos(i * 0.7), sin(i * 0.3));
        else fprintf(f, "bad\n");
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--bad-rows", "skip", "--quiet", NULL), 0);
    ck_assert_ptr_nonnull(strstr(cli_err, "warning: 300 of 400 points could not be fitted"));
    ck_assert(cli_exists(out));
}
END_TEST

/* 12. -o a dangling link: the folder commands name it (before: "File
 * exists"); estimate says the link's folder is missing. */
START_TEST(dangling_link_named)
{
    const char *link = cli_path("dl");
    ck_assert_int_eq(symlink("missing_dir", link), 0);
    ck_assert_int_eq(cli_run("study", "exp", "-o", link, "--n", "300", "--quiet", NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "dl: a symbolic link to a folder that does not exist"));
    ck_assert_int_eq(cli_run("convergence", "--out", link, "--quick", "--no-plots", NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "dl: a symbolic link to a folder that does not exist"));
    ck_assert(!cli_exists(cli_path("missing_dir")));
}
END_TEST

/* 12. An empty --subset: refused (before: rc 0, NaN metrics). */
START_TEST(empty_subset_refused)
{
    const char *p = cli_path("s.xyz"), *t = cli_path("t.csv"), *r = cli_path("r.csv");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "500", "-o", p, "--truth", t, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", p, "-o", r, "--quiet", NULL), 0);
    const char *sub = cli_path("empty.idx");
    cli_write_text(sub, "");
    ck_assert_int_eq(cli_run("eval", r, t, "--subset", sub, NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "empty.idx: no indices"));
    cli_write_text(sub, "# index\n");
    ck_assert_int_eq(cli_run("eval", r, t, "--subset", sub, NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "empty.idx: no indices"));
    cli_write_text(sub, "3\n7\n");
    ck_assert_int_eq(cli_run("eval", r, t, "--subset", sub, NULL), 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_hostile33");
    TCase *tc = tcase_create("hostile33");
    tcase_add_checked_fixture(tc, cli_setup, teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, mesh_faces_kept);
    tcase_add_test(tc, writer_faces_checked);
    tcase_add_test(tc, short_bad_rows_skipped);
    tcase_add_test(tc, wide_csv);
    tcase_add_test(tc, degree_select_message);
    tcase_add_test(tc, study_sigterm_143);
    tcase_add_test(tc, fifo_output_refused);
    tcase_add_test(tc, no_point_fitted);
    tcase_add_test(tc, dangling_link_named);
    tcase_add_test(tc, empty_subset_refused);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
