/* test_io_text_pieces.c -- a large text file is read in pieces of whole
 * lines (io_xyz.c, jf__read_xyz_fd): the cloud, its bad rows and every
 * message are those of the whole-buffer read of the same bytes
 * (jf_cloud_read_mem), for pieces of a few bytes (lines split across
 * pieces, lines longer than a piece) to a few KiB, any thread count; the
 * first bad row's line is the one the generator wrote. */
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
#include "test_io_util.h"
#include "test_text_gen.h"


/* A good row (an intensity column when attrs), now and then CRLF. */
static void good_row(text *t, uint64_t *rng, int attrs)
{
    double x = jf_unit(jf_splitmix64(rng)) - 0.5, y = jf_unit(jf_splitmix64(rng)),
           z = jf_unit(jf_splitmix64(rng)) * 1e3;
    int crlf = jf_splitmix64(rng) % 7 == 0;
    if (attrs)
        put(t, "%.17g %.17g %.17g %d%s", x, y, z, (int)(jf_splitmix64(rng) % 1000),
            crlf ? "\r\n" : "\n");
    else
        put(t, "%.17g %.17g %.17g%s", x, y, z, crlf ? "\r\n" : "\n");
}

/* Rows, comments, blank lines, bad rows (every ~40), a comment longer
 * than most pieces; at least `bytes` of text. */
static text make_text(uint64_t seed, size_t bytes, int attrs)
{
    text t = {0};
    uint64_t rng = seed;
    put(&t, attrs ? "# made by the test\nx y z intensity\n" : "# made by the test\n");
    while (t.n < bytes) {
        uint64_t r = jf_splitmix64(&rng) % 80;
        if (r == 0)
            put(&t, attrs ? "1 2 abc 4\n" : "1 2 abc\n");
        else if (r == 1)
            put(&t, "4 5\n");
        else if (r == 2)
            put(&t, "# a comment\n\n");
        else if (r == 3)
            put(&t, "%.17g %.17g %.17g%s # trailing\n", 1.0, 2.0, 3.0, attrs ? " 7" : "");
        else if (r == 4 && t.n > bytes / 2 && t.n < bytes / 2 + 200) {
            put(&t, "#");
            for (int k = 0; k < 300; k++)
                put(&t, " long comment %d", k);
            put(&t, "\n");
        } else
            good_row(&t, &rng, attrs);
    }
    return t;
}

/* The file read in pieces of `piece` bytes (blocks of `block`). */
static jf_status read_file(const char *path, int threads, size_t piece, size_t block, int skip,
                           jf_cloud *c, jf_error *e)
{
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.threads = threads;
    o.bad_rows = skip;
    jf__xyz_piece_bytes(piece);
    jf__xyz_block_bytes(block);
    jf_status st = jf_cloud_read(path, &o, c, e);
    jf__xyz_piece_bytes(0);
    jf__xyz_block_bytes(0);
    return st;
}

static jf_status read_whole(const text *t, const char *path, int skip, jf_cloud *c, jf_error *e)
{
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.threads = 1;
    o.bad_rows = skip;
    return jf_cloud_read_mem(t->s, t->n, jf_format_from_path(path), path, &o, c, e);
}


/* The pieces' read is the whole read: status, cloud or message. */
static void same_read(const text *t, const char *name, int threads, size_t piece, size_t block,
                      int skip)
{
    const char *path = fixture(name, t->s, t->n);
    jf_cloud a, b;
    jf_error ea, eb;
    jf_status sa = read_file(path, threads, piece, block, skip, &a, &ea);
    jf_status sb = read_whole(t, path, skip, &b, &eb);
    ck_assert_msg(sa == sb, "piece %zu threads %d: %d (%s) vs %d (%s)", piece, threads, sa,
                  ea.msg, sb, eb.msg);
    if (sa == JF_OK)
        same_cloud(&a, &b);
    else
        ck_assert_str_eq(ea.msg, eb.msg);
    jf_cloud_free(&a);
    jf_cloud_free(&b);
}

static const size_t pieces[] = {7, 61, 997, 4096};

static void setup(void)
{
    tmpdir_setup("/tmp/jf_io_text_pieces_XXXXXX");
}

/* --bad-rows skip and the error mode, with and without attributes. */
START_TEST(pieces_match)
{
    for (int attrs = 0; attrs < 2; attrs++) {
        text t = make_text(31 + (uint64_t)attrs, 60000, attrs);
        for (size_t i = 0; i < sizeof pieces / sizeof *pieces; i++)
            for (int threads = 1; threads <= 3; threads += 2)
                for (int skip = 0; skip < 2; skip++)
                    same_read(&t, "gen.xyz", threads, pieces[i], threads == 1 ? 0 : 500, skip);
        free(t.s);
    }
}
END_TEST

/* A bad row split across two pieces, starting just before, at or just
 * after a piece's start: its line, in both reads. */
START_TEST(bad_line_at_piece_end)
{
    for (size_t i = 1; i < sizeof pieces / sizeof *pieces; i++) {
        const size_t P = pieces[i];
        for (int d = -9; d <= 1; d++) {
            text t = {0};
            uint64_t rng = 77 + (uint64_t)P;
            while (t.n + 100 < 3 * P)
                good_row(&t, &rng, 0);
            /* a comment pads the text to 3P + d, where the bad row starts */
            size_t pad = (size_t)((long)(3 * P) + d) - t.n;
            put(&t, "#%*s\n", (int)pad - 2, "");
            ck_assert_uint_eq(t.n, (size_t)((long)(3 * P) + d));
            size_t bad = t.lines + 1;
            put(&t, "1.5 2.5 x3.25\n");
            while (t.n < 6 * P)
                good_row(&t, &rng, 0);
            jf_cloud c;
            jf_error e;
            const char *path = fixture("split.xyz", t.s, t.n);
            ck_assert_int_eq(read_file(path, 1, P, 0, 0, &c, &e), JF_ERR_FORMAT);
            char want[64];
            snprintf(want, sizeof want, "split.xyz:%zu: row ", bad);
            ck_assert_msg(strstr(e.msg, want) != NULL, "%s lacks %s", e.msg, want);
            ck_assert_ptr_nonnull(strstr(e.msg, "'x3.25' is not a number"));
            for (int threads = 1; threads <= 2; threads++)
                same_read(&t, "split.xyz", threads, P, 0, 0);
            free(t.s);
        }
    }
}
END_TEST

/* A NUL byte late in the file is reported (its line) before a bad row
 * early in it, as by the whole read. */
START_TEST(nul_after_bad_row)
{
    text t = make_text(5, 20000, 0);
    size_t at = t.n - 100;
    t.s[at] = '\0';
    size_t line = 1;
    for (size_t i = 0; i < at; i++)
        line += t.s[i] == '\n';
    const char *path = fixture("nul.xyz", t.s, t.n);
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(read_file(path, 1, 997, 0, 0, &c, &e), JF_ERR_FORMAT);
    char want[64];
    snprintf(want, sizeof want, "nul.xyz:%zu: a NUL byte", line);
    ck_assert_msg(strstr(e.msg, want) != NULL, "%s lacks %s", e.msg, want);
    same_read(&t, "nul.xyz", 1, 997, 0, 0);
    same_read(&t, "nul.xyz", 2, 61, 300, 1);
    free(t.s);
}
END_TEST

/* First lines that do not settle the columns within the first piece
 * (comments, bad rows kept as NaN) and PTS count lines across pieces. */
START_TEST(late_start_and_counts)
{
    text t = {0};
    uint64_t rng = 9;
    for (int k = 0; k < 300; k++)
        put(&t, "# header comment %d\n", k);
    put(&t, "1 2\n4 5\n");
    while (t.n < 30000)
        good_row(&t, &rng, 0);
    for (size_t i = 0; i < sizeof pieces / sizeof *pieces; i++)
        for (int skip = 0; skip < 2; skip++)
            same_read(&t, "late.xyz", 1, pieces[i], 0, skip);
    free(t.s);

    text p = {0};
    for (int scan = 0; scan < 40; scan++) {
        int n = 20 + scan * 7;
        put(&p, "%d\n", n);
        for (int k = 0; k < n; k++)
            put(&p, "%d.5 %d.25 %d\n", scan, k, scan * k);
    }
    for (size_t i = 0; i < sizeof pieces / sizeof *pieces; i++)
        for (int threads = 1; threads <= 2; threads++)
            same_read(&p, "scans.pts", threads, pieces[i], 0, 0);
    free(p.s);
}
END_TEST

static void hook(void *user, jf_phase ph, size_t done, size_t total)
{
    size_t *v = user; /* last done, total, calls, 1 if ever backwards */
    ck_assert_int_eq(ph, JF_PHASE_READ);
    v[3] |= done < v[0] || done > total;
    v[0] = done;
    v[1] = total;
    v[2]++;
}

/* The read's progress in bytes of the file: never backwards, to its end. */
START_TEST(progress_in_bytes)
{
    text t = make_text(3, 50000, 0);
    const char *path = fixture("prog.xyz", t.s, t.n);
    size_t v[4] = {0, 0, 0, 0};
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.threads = 1;
    o.bad_rows = 1;
    o.progress = hook;
    o.progress_user = v;
    jf__xyz_piece_bytes(4096);
    jf__xyz_block_bytes(1000);
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(path, &o, &c, &e), JF_OK);
    jf__xyz_piece_bytes(0);
    jf__xyz_block_bytes(0);
    ck_assert_uint_eq(v[3], 0);
    ck_assert_uint_eq(v[0], t.n);
    ck_assert_uint_eq(v[1], t.n);
    ck_assert_uint_gt(v[2], 12); /* a call a block at least */
    jf_cloud_free(&c);
    free(t.s);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_text_pieces");
    TCase *tc = tcase_create("pieces");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, pieces_match);
    tcase_add_test(tc, bad_line_at_piece_end);
    tcase_add_test(tc, nul_after_bad_row);
    tcase_add_test(tc, late_start_and_counts);
    tcase_add_test(tc, progress_in_bytes);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
