/* test_io_text_par.c -- the text readers parse in blocks on the threads
 * (io_xyz.c): the cloud, its bad rows and every message are those of a
 * single-thread read, and the values those the generator wrote.  Blocks
 * are made small (jf__xyz_block_bytes) so that a few thousand rows cross
 * hundreds of block ends: comments, CRLF, bad rows, PTS count lines and
 * attributes on either side of them. */
#include <check.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_internal.h"
#include "jetfit.h"

#include "jf_test.h"
#include "test_text_gen.h"

#define NROWS 6000

/* What the generator meant: rows (NaN for a bad one), intensity, the
 * lines of the bad rows, and the first bad row's line and row. */
typedef struct {
    double *xyz, *nrm;
    int *inten;
    size_t n, nbad, bad_line[10], first_line, first_row;
} expect;

/* An .xyz with a header "x y z nx ny nz intensity": good rows written
 * with %.17g, and (every ~50 rows) a bad row of several kinds, comments,
 * blank lines, CRLF line ends. */
static text make_xyz(uint64_t seed, expect *ex)
{
    text t = {0};
    memset(ex, 0, sizeof *ex);
    ex->xyz = malloc(3 * NROWS * sizeof(double));
    ex->nrm = malloc(3 * NROWS * sizeof(double));
    ex->inten = malloc(NROWS * sizeof(int));
    size_t line = 0;
    put(&t, "# generated\n"), line++;
    put(&t, "x y z nx ny nz intensity\n"), line++;
    for (size_t r = 0; r < NROWS; r++) {
        uint64_t b = jf_splitmix64(&seed);
        int kind = r > 0 && b % 50 == 0 ? 1 + (int)(b / 50 % 4) : 0;
        if (b % 37 == 1)
            put(&t, b % 2 ? "\n" : "  # a comment line\r\n"), line++;
        line++;
        if (kind) { /* a bad row: kept as NaN under skip */
            static const char *const bad[4] = {"1 2 abc 4 5 6 7\n", "1 2\n",
                                               "1 2 3 4 5 6 7 8\n", "1,5 2,5 3,5 4 5 6 7\n"};
            put(&t, "%s", bad[kind - 1]);
            for (int k = 0; k < 3; k++)
                ex->xyz[3 * r + k] = ex->nrm[3 * r + k] = NAN;
            ex->inten[r] = -1;
            if (ex->nbad < 10)
                ex->bad_line[ex->nbad] = line;
            if (!ex->nbad++)
                ex->first_line = line, ex->first_row = r + 1;
            continue;
        }
        double v[6];
        for (int k = 0; k < 6; k++)
            v[k] = (jf_unit(jf_splitmix64(&seed)) - 0.5) * (k < 3 ? 1e3 : 2.0);
        double s = 1 / sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5]);
        for (int k = 3; k < 6; k++)
            v[k] *= s;
        int in = (int)(jf_splitmix64(&seed) % 60000);
        put(&t, "%.17g %.17g %.17g %.17g %.17g %.17g %d%s", v[0], v[1], v[2], v[3], v[4], v[5],
            in, b % 5 == 2 ? "\r\n" : b % 7 == 3 ? "  # tail\n" : "\n");
        memcpy(ex->xyz + 3 * r, v, 3 * sizeof(double));
        memcpy(ex->nrm + 3 * r, v + 3, 3 * sizeof(double));
        ex->inten[r] = in;
    }
    ex->n = NROWS;
    return t;
}

static void expect_free(expect *ex)
{
    free(ex->xyz);
    free(ex->nrm);
    free(ex->inten);
}

/* Reads text with `threads` threads (blocks of `bytes`). */
static jf_status read_with(const text *t, jf_format fmt, int threads, size_t bytes, int skip,
                           jf_cloud *c, jf_error *e)
{
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.threads = threads;
    o.bad_rows = skip;
    jf__xyz_block_bytes(bytes);
    jf_status st = jf_cloud_read_mem(t->s, t->n, fmt, "gen.xyz", &o, c, e);
    jf__xyz_block_bytes(0);
    return st;
}


/* --bad-rows skip: every thread count and block size gives the rows the
 * generator wrote, the bad ones NaN, their lines, the intensity column. */
START_TEST(skip_rows_match)
{
    expect ex;
    text t = make_xyz(11, &ex);
    ck_assert_uint_gt(ex.nbad, 20);
    jf_cloud one;
    jf_error e;
    ck_assert_int_eq(read_with(&t, JF_FMT_XYZ, 1, 0, 1, &one, &e), JF_OK);
    /* the generator's values (an independent account of the file) */
    ck_assert_uint_eq(one.n, ex.n);
    ck_assert_uint_eq(one.nbad, ex.nbad);
    ck_assert_int_eq(memcmp(one.bad_line, ex.bad_line, sizeof ex.bad_line), 0);
    ck_assert_ptr_nonnull(one.nrm);
    for (size_t i = 0; i < ex.n; i++)
        for (int k = 0; k < 3; k++) {
            ck_assert(isnan(ex.xyz[3 * i + k]) ? isnan(one.xyz[3 * i + k])
                                               : one.xyz[3 * i + k] == ex.xyz[3 * i + k]);
            ck_assert(isnan(ex.nrm[3 * i + k]) ? isnan(one.nrm[3 * i + k])
                                               : one.nrm[3 * i + k] == ex.nrm[3 * i + k]);
        }
    /* nx ny nz are also carried (an output names them in_nx ...) */
    ck_assert_uint_eq(one.attrs.nattrs, 4);
    ck_assert_str_eq(one.attrs.attr[3].name, "intensity");
    ck_assert_int_eq(one.attrs.attr[3].type, JF_ATTR_F64); /* NaN rows: not integers */
    for (size_t i = 0; i < ex.n; i++) {
        double v;
        memcpy(&v, one.attrs.rec + i * one.attrs.stride + one.attrs.attr[3].offset, 8);
        ck_assert(ex.inten[i] < 0 ? isnan(v) : v == ex.inten[i]);
    }
    static const int threads[] = {2, 3, 7};
    static const size_t bytes[] = {64, 333, 4096, 0};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 4; b++) {
            jf_cloud c;
            ck_assert_int_eq(read_with(&t, JF_FMT_XYZ, threads[a], bytes[b], 1, &c, &e), JF_OK);
            same_cloud(&one, &c);
            jf_cloud_free(&c);
        }
    jf_cloud_free(&one);
    expect_free(&ex);
    free(t.s);
}
END_TEST

/* Error mode: the first bad row in file order, with its line and row
 * number, whatever the threads. */
START_TEST(first_error_named)
{
    expect ex;
    text t = make_xyz(12, &ex);
    jf_cloud c;
    jf_error one, e;
    ck_assert_int_eq(read_with(&t, JF_FMT_XYZ, 1, 0, 0, &c, &one), JF_ERR_FORMAT);
    char want[64];
    snprintf(want, sizeof want, "gen.xyz:%zu: row %zu: ", ex.first_line, ex.first_row);
    ck_assert_msg(!strncmp(one.msg, want, strlen(want)), "%s vs %s", one.msg, want);
    for (int th = 2; th <= 5; th += 3)
        for (size_t bytes = 50; bytes < 20000; bytes *= 7) {
            ck_assert_int_eq(read_with(&t, JF_FMT_XYZ, th, bytes, 0, &c, &e), JF_ERR_FORMAT);
            ck_assert_str_eq(e.msg, one.msg);
            ck_assert_uint_eq(c.n, 0); /* nothing left allocated */
        }
    /* only the very last row is bad: named after every block */
    text u = {0};
    size_t lines = 0;
    for (int r = 0; r < 3000; r++)
        put(&u, "%d.5 %d 1e-3\n", r, -r), lines++;
    put(&u, "7 8 nine\n");
    for (int th = 1; th <= 4; th += 3) {
        ck_assert_int_eq(read_with(&u, JF_FMT_XYZ, th, 128, 0, &c, &e), JF_ERR_FORMAT);
        snprintf(want, sizeof want, "gen.xyz:%zu: row %zu: column 3: 'nine' is not a number",
                 lines + 1, lines + 1);
        ck_assert_str_eq(e.msg, want);
    }
    free(u.s);
    expect_free(&ex);
    free(t.s);
}
END_TEST

/* PTS: count lines before each scan (concatenated scans), and a line of
 * one integer that is not a count (a bad row) -- in any block. */
START_TEST(pts_counts)
{
    text t = {0};
    uint64_t seed = 5;
    size_t rows = 0, line = 0, badline = 0, badrow = 0;
    for (int scan = 0; scan < 40; scan++) {
        size_t m = 20 + jf_splitmix64(&seed) % 200;
        /* scan 25: a line "42" amid its rows, counted by its count line
         * (so that the later counts hold): a bad row, not a count */
        put(&t, "%zu\n", m + (scan == 25)), line++;
        for (size_t r = 0; r < m; r++) {
            double x = jf_unit(jf_splitmix64(&seed));
            put(&t, "%.17g %.17g %.17g 12 200 100 7\n", x, 2 * x, 3 * x), line++, rows++;
            if (scan == 25 && r == m / 2) {
                put(&t, "42\n"), line++, rows++;
                badline = line, badrow = rows;
            }
        }
    }
    jf_cloud one, c;
    jf_error e1, e;
    ck_assert_int_eq(read_with(&t, JF_FMT_PTS, 1, 0, 0, &one, &e1), JF_ERR_FORMAT);
    char want[64];
    snprintf(want, sizeof want, "gen.xyz:%zu: row %zu: expected 3 numbers, found 1", badline,
             badrow);
    ck_assert_str_eq(e1.msg, want);
    for (int th = 2; th <= 6; th += 4)
        for (size_t bytes = 40; bytes < 5000; bytes *= 3) {
            ck_assert_int_eq(read_with(&t, JF_FMT_PTS, th, bytes, 0, &c, &e), JF_ERR_FORMAT);
            ck_assert_str_eq(e.msg, e1.msg);
        }
    /* skip: the 42 is a NaN row, the count lines are no rows */
    ck_assert_int_eq(read_with(&t, JF_FMT_PTS, 1, 0, 1, &one, &e1), JF_OK);
    ck_assert_uint_eq(one.nbad, 1);
    ck_assert_uint_eq(one.bad_line[0], badline);
    ck_assert_uint_eq(one.n, rows);
    ck_assert(isnan(one.xyz[3 * (badrow - 1)]) && !isnan(one.xyz[3 * badrow]));
    for (int th = 2; th <= 6; th += 4)
        for (size_t bytes = 40; bytes < 5000; bytes *= 3) {
            ck_assert_int_eq(read_with(&t, JF_FMT_PTS, th, bytes, 1, &c, &e), JF_OK);
            same_cloud(&one, &c);
            jf_cloud_free(&c);
        }
    jf_cloud_free(&one);
    /* a count that disagrees with its rows: named at the count's line */
    text u = {0};
    put(&u, "%s", t.s);
    put(&u, "5\n1 2 3 0 0 0 0\n");
    ck_assert_int_eq(read_with(&u, JF_FMT_PTS, 1, 0, 1, &one, &e1), JF_ERR_FORMAT);
    ck_assert_ptr_nonnull(strstr(e1.msg, "the count line says 5 points, 1 rows follow it"));
    ck_assert_int_eq(read_with(&u, JF_FMT_PTS, 3, 64, 1, &c, &e), JF_ERR_FORMAT);
    ck_assert_str_eq(e.msg, e1.msg);
    free(u.s);
    free(t.s);
}
END_TEST

/* CSV with a BOM, CRLF, a header with a column that turns to words in a
 * late row (dropped), and a column of small integers (packed uchar). */
START_TEST(csv_attrs)
{
    text t = {0};
    uint64_t seed = 9;
    put(&t, "\xEF\xBB\xBFX,Y,Z,label,class\r\n");
    for (int r = 0; r < 5000; r++) {
        double x = jf_unit(jf_splitmix64(&seed));
        if (r == 4321)
            put(&t, "%.17g,%.17g,%.17g,ground,%d\r\n", x, x * x, -x, r % 7);
        else
            put(&t, "%.17g,%.17g,%.17g,%d,%d\r\n", x, x * x, -x, r, r % 7);
    }
    jf_cloud one, c;
    jf_error e;
    ck_assert_int_eq(read_with(&t, JF_FMT_CSV, 1, 0, 0, &one, &e), JF_OK);
    ck_assert_uint_eq(one.n, 5000);
    ck_assert_uint_eq(one.attrs.nattrs, 1); /* label has a word: dropped */
    ck_assert_str_eq(one.attrs.attr[0].name, "class");
    ck_assert_int_eq(one.attrs.attr[0].type, JF_ATTR_U8);
    for (int th = 2; th <= 8; th *= 2)
        for (size_t bytes = 30; bytes < 40000; bytes *= 11) {
            ck_assert_int_eq(read_with(&t, JF_FMT_CSV, th, bytes, 0, &c, &e), JF_OK);
            same_cloud(&one, &c);
            jf_cloud_free(&c);
        }
    jf_cloud_free(&one);
    free(t.s);
}
END_TEST

/* The read hook: JF_PHASE_READ, bytes non-decreasing, ending at the
 * file's size. */
typedef struct {
    size_t calls, last, total;
    int bad;
} seen;

static void hook(void *user, jf_phase ph, size_t done, size_t total)
{
    seen *s = user;
    if (ph != JF_PHASE_READ || done < s->last || done > total || (s->calls && total != s->total))
        s->bad = 1;
    s->calls++;
    s->last = done;
    s->total = total;
}

START_TEST(read_progress)
{
    expect ex;
    text t = make_xyz(13, &ex);
    for (int th = 1; th <= 3; th += 2) {
        seen s = {0};
        jf_read_opts o;
        jf_read_opts_init(&o);
        o.threads = th;
        o.bad_rows = 1;
        o.progress = hook;
        o.progress_user = &s;
        jf_cloud c;
        jf_error e;
        jf__xyz_block_bytes(1000);
        ck_assert_int_eq(jf_cloud_read_mem(t.s, t.n, JF_FMT_XYZ, "gen.xyz", &o, &c, &e), JF_OK);
        jf__xyz_block_bytes(0);
        ck_assert_int_eq(s.bad, 0);
        ck_assert_uint_ge(s.calls, 2);
        ck_assert_uint_eq(s.last, t.n);
        ck_assert_uint_eq(s.total, t.n);
        jf_cloud_free(&c);
    }
    expect_free(&ex);
    free(t.s);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_text_par");
    TCase *tc = tcase_create("blocks");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, skip_rows_match);
    tcase_add_test(tc, first_error_named);
    tcase_add_test(tc, pts_counts);
    tcase_add_test(tc, csv_attrs);
    tcase_add_test(tc, read_progress);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
