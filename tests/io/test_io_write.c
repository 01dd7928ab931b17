/*
 * test_io_write.c -- the table writer and jf_cloud_write: exact text
 * (compared with printf's "%.17g"), bit-exact round trips through every
 * format, headers and property types, the temporary-then-rename rule.
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io_internal.h"
#include "jetfit.h"

#include "test_io_util.h"
#include "jf_test.h"

static const char *tpath(const char *name)
{
    static char path[4][256];
    static int k;
    k = (k + 1) % 4;
    snprintf(path[k], sizeof path[k], "%s/%s", tmpdir, name);
    return path[k];
}

static int exists(const char *p)
{
    struct stat sb;
    return stat(p, &sb) == 0;
}

static void setup(void)
{
    tmpdir_setup("/tmp/jf_io_write_XXXXXX");
}

static uint64_t rng = 0x9e3779b97f4a7c15u;
static uint64_t next(void)
{
    return jf_xorshift64(&rng);
}

START_TEST(g17_matches_printf)
{
    char a[64], b[64];
    int checked = 0;
    /* powers of ten and their neighbours: where the exponent guess and the
     * rounding carry are delicate */
    for (int e = -320; e <= 308; e++) {
        double p = strtod((snprintf(a, sizeof a, "1e%d", e), a), NULL);
        double vs[5] = {p, nextafter(p, 0), nextafter(p, INFINITY),
                        -p, p * 9.999999999999999};
        for (int i = 0; i < 5; i++) {
            snprintf(a, sizeof a, "%.17g", vs[i]);
            *jf_fmt_g17(b, vs[i]) = '\0';
            ck_assert_str_eq(a, b);
            checked++;
        }
    }
    for (int i = 0; i < 300000; i++) {
        double v;
        uint64_t r = next();
        if (i % 2) {
            memcpy(&v, &r, 8);
        } else {
            v = (double)(int64_t)r * 1e-18 * pow(10, (int)(next() % 30) - 15);
        }
        if (isnan(v))
            continue;
        snprintf(a, sizeof a, "%.17g", v);
        *jf_fmt_g17(b, v) = '\0';
        ck_assert_str_eq(a, b);
        checked++;
    }
    *jf_fmt_g17(b, -NAN) = '\0';
    ck_assert_str_eq(b, "nan");
    *jf_fmt_g17(b, -0.0) = '\0';
    ck_assert_str_eq(b, "-0");
    ck_assert_int_gt(checked, 300000);
}
END_TEST

/* n points with awkward values (NaN, inf, -0, denormals, huge, offsets) */
static jf_cloud make_cloud(size_t n, int normals)
{
    jf_cloud c = {0};
    c.n = n;
    c.xyz = malloc(3 * n * sizeof(double));
    c.nrm = normals ? malloc(3 * n * sizeof(double)) : NULL;
    static const double special[] = {0.0, -0.0, 1e-310, -1e300, 1e6 + 0.1,
                                     INFINITY, -INFINITY, 0.1, 1.0 / 3};
    for (size_t i = 0; i < 3 * n; i++) {
        uint64_t r = next();
        double v;
        if (i < 9)
            v = special[i];
        else if (i % 4 == 0)
            memcpy(&v, &r, 8);
        else
            v = (double)(int64_t)r * 1e-12;
        if (isnan(v))
            v = 2.5;
        c.xyz[i] = v;
        if (normals)
            c.nrm[i] = -v;
    }
    c.xyz[3 * (n / 2) + 1] = NAN; /* a NaN row */
    return c;
}

static void same_bits(const double *a, const double *b, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (isnan(a[i])) {
            ck_assert_msg(isnan(b[i]), "value %zu: NaN became %g", i, b[i]);
            continue;
        }
        ck_assert_msg(memcmp(&a[i], &b[i], 8) == 0, "value %zu: %.17g vs %.17g",
                      i, a[i], b[i]);
    }
}

START_TEST(round_trips)
{
    static const char *const names[] = {"c.ply", "c.csv", "c.xyz", "c.txt",
                                        "c.off"};
    for (int normals = 0; normals < 2; normals++) {
        jf_cloud c = make_cloud(2000, normals);
        for (int ascii = 0; ascii < 2; ascii++) {
            for (size_t k = 0; k < sizeof names / sizeof *names; k++) {
                const char *p = tpath(names[k]);
                jf_error e;
                ck_assert_msg(jf_cloud_write(p, &c, ascii, &e) == JF_OK, "%s",
                              e.msg);
                jf_cloud d;
                jf_read_opts o;
                jf_read_opts_init(&o);
                if (normals && k > 0 && k < 4) /* text: normals by position */
                    o.columns[0] = 0, o.columns[1] = 1, o.columns[2] = 2,
                    o.columns[3] = 3, o.columns[4] = 4, o.columns[5] = 5;
                ck_assert_msg(jf_cloud_read(p, &o, &d, &e) == JF_OK, "%s: %s",
                              names[k], e.msg);
                ck_assert_uint_eq(d.n, c.n);
                same_bits(c.xyz, d.xyz, 3 * c.n);
                if (normals) {
                    ck_assert_ptr_nonnull(d.nrm);
                    same_bits(c.nrm, d.nrm, 3 * c.n);
                }
                jf_cloud_free(&d);
            }
        }
        jf_cloud_free(&c);
    }
}
END_TEST

START_TEST(mesh_round_trip)
{
    jf_cloud c = make_cloud(5, 0);
    size_t off[3] = {0, 3, 7};
    uint32_t idx[7] = {0, 1, 2, 4, 3, 2, 1};
    c.nfaces = 2;
    c.face_off = malloc(sizeof off);
    c.face_idx = malloc(sizeof idx);
    memcpy(c.face_off, off, sizeof off);
    memcpy(c.face_idx, idx, sizeof idx);
    const char *names[3] = {"m.off", "m.ply", "m.ply"};
    for (int k = 0; k < 3; k++) {
        jf_error e;
        ck_assert_int_eq(jf_cloud_write(tpath(names[k]), &c, k == 2, &e),
                         JF_OK);
        jf_cloud d;
        ck_assert_int_eq(jf_cloud_read(tpath(names[k]), NULL, &d, &e), JF_OK);
        ck_assert_uint_eq(d.nfaces, 2);
        ck_assert(memcmp(d.face_off, off, sizeof off) == 0);
        ck_assert(memcmp(d.face_idx, idx, sizeof idx) == 0);
        same_bits(c.xyz, d.xyz, 15);
        jf_cloud_free(&d);
    }
    jf_cloud_free(&c);
}
END_TEST

static const jf_column cols[4] = {{"x", JF_COL_F64},
                                  {"y", JF_COL_F64},
                                  {"z", JF_COL_F32},
                                  {"status", JF_COL_I32}};
static const double rows[3][4] = {{1.5, -2, 0.1, 3},
                                  {NAN, 1e-300, 0.1, -2.6},
                                  {7, 8, 9, NAN}};

static void write_table(const char *p, int ascii)
{
    jf_writer *w;
    jf_error e;
    ck_assert_int_eq(jf_writer_open(p, cols, 4, 3, ascii, &w, &e), JF_OK);
    for (int i = 0; i < 3; i++)
        ck_assert_int_eq(jf_writer_row(w, rows[i]), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
}

START_TEST(table_text)
{
    write_table(tpath("t.csv"), 0);
    char *s = jf_test_must_slurp(tpath("t.csv"), NULL);
    ck_assert_str_eq(s, "x,y,z,status\n"
                        "1.5,-2,0.100000001,3\n"
                        "nan,1e-300,0.100000001,-3\n"
                        "7,8,9,-2147483648\n");
    free(s);
    write_table(tpath("t.xyz"), 0);
    s = jf_test_must_slurp(tpath("t.xyz"), NULL);
    ck_assert_str_eq(s, "# x y z status\n"
                        "1.5 -2 0.100000001 3\n"
                        "nan 1e-300 0.100000001 -3\n"
                        "7 8 9 -2147483648\n");
    free(s);
    /* and the reader takes the NaN back */
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(tpath("t.csv"), NULL, &c, &e), JF_OK);
    ck_assert(isnan(c.xyz[3]) && c.xyz[4] == 1e-300);
    ck_assert((float)c.xyz[5] == 0.1f); /* %.9g: exact for a float */
    jf_cloud_free(&c);
}
END_TEST

START_TEST(table_ply)
{
    write_table(tpath("t.ply"), 1);
    char *s = jf_test_must_slurp(tpath("t.ply"), NULL);
    ck_assert_ptr_nonnull(strstr(s, "format ascii 1.0\n"));
    ck_assert_ptr_nonnull(strstr(s, "element vertex 3\nproperty double x\n"
                                    "property double y\nproperty float z\n"
                                    "property int status\nend_header\n"
                                    "1.5 -2 0.100000001 3\n"));
    free(s);
    write_table(tpath("b.ply"), 0);
    size_t len;
    s = jf_test_must_slurp(tpath("b.ply"), &len);
    ck_assert_ptr_nonnull(strstr(s, "format binary_little_endian 1.0\n"));
    const char *body = strstr(s, "end_header\n") + 11;
    ck_assert_uint_eq(len - (size_t)(body - s), 3 * (8 + 8 + 4 + 4));
    for (int i = 0; i < 3; i++) {
        const char *r = body + i * 24;
        double x, y;
        float z;
        int32_t st;
        memcpy(&x, r, 8), memcpy(&y, r + 8, 8), memcpy(&z, r + 16, 4);
        memcpy(&st, r + 20, 4);
        ck_assert(isnan(rows[i][0]) ? isnan(x) : x == rows[i][0]);
        ck_assert(y == rows[i][1] && z == (float)rows[i][2]);
        ck_assert_int_eq(st, i == 0 ? 3 : i == 1 ? -3 : INT32_MIN);
    }
    free(s);
}
END_TEST

/* jf_writer_rows (blocks formatted on several threads) writes exactly the
 * bytes of row-by-row jf_writer_row, in every format, for row counts
 * spanning several rounds of its 4096-row blocks. */
START_TEST(rows_in_blocks)
{
    const size_t n = 14000, split = 1000; /* 13000 rows: 2 rounds of 3 x 4096 */
    double *v = malloc(n * 4 * sizeof *v);
    for (size_t i = 0; i < 4 * n; i++) {
        uint64_t u = next();
        double x = (double)(int64_t)(u >> 11) * 0x1p-40;
        v[i] = u % 97 == 0 ? NAN : i % 4 == 3 ? (double)(int)(x * 1e-3) + (u % 3) * 0.5 : x;
    }
    const char *names[4] = {"r.csv", "r.xyz", "r.ply", "rb.ply"};
    for (int f = 0; f < 4; f++) {
        const int ascii = f < 3;
        jf_writer *w;
        jf_error e;
        char ref[64], got[64];
        snprintf(ref, sizeof ref, "ref_%s", names[f]);
        ck_assert_int_eq(jf_writer_open(tpath(ref), cols, 4, n, ascii, &w, &e), JF_OK);
        for (size_t i = 0; i < n; i++) ck_assert_int_eq(jf_writer_row(w, v + 4 * i), JF_OK);
        ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
        size_t lr, lg;
        char *a = jf_test_must_slurp(tpath(ref), &lr);
        const int threads = 3;
        snprintf(got, sizeof got, "t_%s", names[f]);
        if (f == 0) { /* one row too many fails, and leaves no file */
            ck_assert_int_eq(jf_writer_open(tpath(got), cols, 4, 3, ascii, &w, &e), JF_OK);
            ck_assert_int_eq(jf_writer_row(w, v), JF_OK);
            ck_assert_int_eq(jf_writer_rows(w, v + 4, 3, threads), JF_ERR_INVALID);
            ck_assert_int_ne(jf_writer_commit(w, &e), JF_OK);
            ck_assert(!exists(tpath(got)));
        }
        ck_assert_int_eq(jf_writer_open(tpath(got), cols, 4, n, ascii, &w, &e), JF_OK);
        ck_assert_int_eq(jf_writer_row(w, v), JF_OK);
        ck_assert_int_eq(jf_writer_rows(w, v + 4, split - 1, threads), JF_OK);
        ck_assert_int_eq(jf_writer_rows(w, v + 4 * split, n - split, threads), JF_OK);
        ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
        char *b = jf_test_must_slurp(tpath(got), &lg);
        ck_assert_uint_eq(lg, lr);
        ck_assert(memcmp(a, b, lr) == 0);
        free(b);
        free(a);
    }
    free(v);
}
END_TEST

/* How many temporaries of out.csv (".out.csv.*.tmp") are in tmpdir. */
static int tmp_count(void)
{
    DIR *d = opendir(tmpdir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));)
        if (!strncmp(e->d_name, ".out.csv.", 9) && strstr(e->d_name, ".tmp"))
            n++;
    if (d)
        closedir(d);
    return n;
}

START_TEST(temp_then_rename)
{
    const char *p = tpath("out.csv");
    jf_writer *w;
    jf_error e;
    /* abort: neither file remains */
    ck_assert_int_eq(jf_writer_open(p, cols, 4, 3, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_row(w, rows[0]), JF_OK);
    ck_assert(tmp_count() == 1 && !exists(p));
    jf_writer_abort(w);
    ck_assert(tmp_count() == 0 && !exists(p));
    jf_writer_abort(NULL);
    /* too few rows: commit fails, nothing under the final name */
    ck_assert_int_eq(jf_writer_open(p, cols, 4, 3, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_row(w, rows[0]), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_ERR_INVALID);
    ck_assert_ptr_nonnull(strstr(e.msg, "1 rows written, 3 announced"));
    ck_assert(tmp_count() == 0 && !exists(p));
    /* too many rows */
    ck_assert_int_eq(jf_writer_open(p, cols, 4, 1, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_row(w, rows[0]), JF_OK);
    ck_assert_int_eq(jf_writer_row(w, rows[1]), JF_ERR_INVALID);
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_ERR_INVALID);
    ck_assert(tmp_count() == 0 && !exists(p));
    /* an existing file is untouched by an abort, replaced by a commit */
    FILE *f = fopen(p, "w");
    fputs("old\n", f);
    fclose(f);
    ck_assert_int_eq(jf_writer_open(p, cols, 4, 3, 0, &w, &e), JF_OK);
    jf_writer_abort(w);
    char *s = jf_test_must_slurp(p, NULL);
    ck_assert_str_eq(s, "old\n");
    free(s);
    write_table(p, 0);
    s = jf_test_must_slurp(p, NULL);
    ck_assert(strncmp(s, "x,y,z,status\n", 13) == 0);
    free(s);
    ck_assert(tmp_count() == 0);
    /* a folder that does not exist: clean failure, no file */
    const char *q = tpath("no/such/dir/out.ply");
    ck_assert_int_eq(jf_writer_open(q, cols, 4, 3, 0, &w, &e), JF_ERR_IO);
    ck_assert_ptr_null(w);
    ck_assert(strstr(e.msg, q) == e.msg);
    ck_assert_ptr_null(strchr(e.msg, '\n'));
    jf_cloud c = make_cloud(3, 0);
    ck_assert_int_eq(jf_cloud_write(tpath("nodir/c.off"), &c, 0, &e),
                     JF_ERR_IO);
    jf_cloud_free(&c);
    /* bad arguments */
    jf_column bad[1] = {{"two words", JF_COL_F64}};
    ck_assert_int_eq(jf_writer_open(p, bad, 1, 1, 0, &w, &e), JF_ERR_INVALID);
    ck_assert_int_eq(jf_writer_open(tpath("x.off"), cols, 4, 1, 0, &w, &e),
                     JF_ERR_UNSUPPORTED);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_write");
    TCase *tc = tcase_create("write");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, g17_matches_printf);
    tcase_add_test(tc, round_trips);
    tcase_add_test(tc, mesh_round_trip);
    tcase_add_test(tc, table_text);
    tcase_add_test(tc, table_ply);
    tcase_add_test(tc, rows_in_blocks);
    tcase_add_test(tc, temp_then_rename);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
