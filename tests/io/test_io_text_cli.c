/* test_io_text_cli.c -- `jetfit estimate --threads N` on a text file large
 * enough (> 2 MiB) to be parsed in parallel blocks and written in
 * parallel blocks: 1, 2 and 3 threads give the same output bytes and the
 * same messages -- the bad rows kept under --bad-rows skip (their lines),
 * and the error of a bad row deep in the file (its line and row). */
#include <check.h>

#include "jf_test.h"
#include "test_cli_util.h"

#define NROWS 60000

static void setup(void) { cli_setup(); }
static void teardown(void) { cli_teardown(); }

/* The file: rows of a paraboloid, a bad row every 997 (or only at row
 * `only`, when set), comments, some CRLF; *line_of_bad the line of the
 * last bad row written. */
static void write_file(const char *path, size_t only, size_t *line_of_bad, size_t *row_of_bad)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    uint64_t s = 21;
    size_t line = 0, row = 0;
    fputs("# x y z\n", f), line++;
    for (size_t i = 0; i < NROWS; i++) {
        if (i % 1499 == 7)
            fputs("# a comment\n", f), line++;
        int bad = only ? i == only : i % 997 == 5;
        line++, row++;
        if (bad) {
            fputs("1 2 x\n", f);
            *line_of_bad = line, *row_of_bad = row;
            continue;
        }
        double x = jf_unit(jf_splitmix64(&s)) - 0.5, y = jf_unit(jf_splitmix64(&s)) - 0.5;
        fprintf(f, "%.17g %.17g %.17g%s", x, y, 0.3 * x * x - 0.2 * y * y,
                i % 5 == 1 ? "\r\n" : "\n");
    }
    ck_assert_int_eq(fclose(f), 0);
}

START_TEST(skip_same_bytes)
{
    size_t bl = 0, br = 0;
    char in[300];
    snprintf(in, sizeof in, "%s", cli_path("in.xyz"));
    write_file(in, 0, &bl, &br);
    struct stat sb;
    ck_assert_int_eq(stat(in, &sb), 0);
    ck_assert_int_gt(sb.st_size, 3 << 20); /* past the one-thread start */
    char err1[8192];
    size_t l1 = 0;
    char *o1 = NULL;
    static const char *const th[3] = {"1", "2", "3"};
    for (int k = 0; k < 3; k++) {
        char out[32];
        snprintf(out, sizeof out, "o%d.xyz", k);
        ck_assert_msg(cli_run("estimate", in, "-o", cli_path(out), "--bad-rows", "skip",
                              "--neighbors", "knn:8", "--degree", "1", "--threads", th[k], "-q",
                              NULL) == 0, "%s", cli_err);
        /* 61 bad rows; the first at line 7 (row 6) */
        ck_assert_msg(strstr(cli_err, "61 unparsable rows kept as NaN rows") &&
                          strstr(cli_err, "lines 7, "), "%s", cli_err);
        size_t l;
        char *o = jf_test_must_slurp(cli_path(out), &l);
        if (!k) {
            snprintf(err1, sizeof err1, "%s", cli_err);
            o1 = o, l1 = l;
            continue;
        }
        ck_assert_str_eq(cli_err, err1);
        ck_assert_uint_eq(l, l1);
        ck_assert(!memcmp(o, o1, l));
        free(o);
    }
    free(o1);
}
END_TEST

START_TEST(error_line_same)
{
    size_t bl = 0, br = 0;
    char in[300], want[512];
    snprintf(in, sizeof in, "%s", cli_path("in.xyz"));
    write_file(in, 45678, &bl, &br);
    ck_assert_uint_gt(bl, br);
    snprintf(want, sizeof want, "jetfit: %s:%zu: row %zu: column 3: 'x' is not a number\n", in, bl,
             br);
    for (int t = 1; t <= 3; t++) {
        char ts[4];
        snprintf(ts, sizeof ts, "%d", t);
        ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("o.csv"), "--threads", ts, "-q",
                                 NULL), 1);
        ck_assert_str_eq(cli_err, want);
        ck_assert(!cli_exists(cli_path("o.csv")));
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_text_cli");
    TCase *tc = tcase_create("threads");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, skip_same_bytes);
    tcase_add_test(tc, error_line_same);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
