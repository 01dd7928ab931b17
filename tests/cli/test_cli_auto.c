/* test_cli_auto.c -- `--neighbors auto` end to end: the extra sigma column
 * holds the noise estimate (near the noise added), the status column has
 * the auto bit on every row, neighbors/degree say what was chosen, the
 * summary line prints the distribution of K and step 0's decision, and
 * --memory parts and one thread give the same bytes as the whole cloud on
 * two threads. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_cli_util.h"
#include "jf_test.h"

#define SIDE 40
#define NOISE 0.004 /* Gaussian-ish: a sum of 12 uniforms, sd NOISE */

static void write_noisy(const char *path)
{
    static double xyz[3 * SIDE * SIDE];
    cli_surface61(SIDE, xyz, 7);
    unsigned long long s = 27;
    for (size_t i = 0; i < 3 * SIDE * SIDE; i++) {
        double g = -6.0;
        for (int k = 0; k < 12; k++) {
            s = s * 6364136223846793005ULL + 1442695040888963407ULL;
            g += (double)(s >> 11) / 9007199254740992.0;
        }
        xyz[i] += NOISE * g;
    }
    cli_write_xyz(path, xyz, NULL, SIDE * SIDE);
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

START_TEST(auto_columns_and_summary)
{
    write_noisy(cli_path("in.xyz"));
    ck_assert_int_eq(cli_run("estimate", cli_path("in.xyz"), "-o", cli_path("a.csv"), "--neighbors",
                             "auto", "--threads", "2", NULL),
                     0);
    ck_assert_msg(strstr(cli_err, "auto K: <="), "%s", cli_err);
    ck_assert_msg(strstr(cli_err, ", auto 1600"), "%s", cli_err);
    ck_assert_msg(strstr(cli_err, "\n  auto step 0: "), "%s", cli_err);
    /* "ok" counts the rows with no flag but auto's (which say how the
     * row was made, not that anything went wrong) */
    const char *okp = strstr(cli_err, "  status: ok ");
    unsigned long ok = 0, nok = 0;
    ck_assert_msg(okp && sscanf(okp + 13, "%lu", &ok) == 1, "%s", cli_err);
    jf_eval_table t;
    cli_read(cli_path("a.csv"), &t);
    ck_assert_uint_eq(t.nrows, SIDE * SIDE);
    static double sg[SIDE * SIDE];
    for (size_t i = 0; i < t.nrows; i++) {
        unsigned st = (unsigned)cli_val(&t, i, "status");
        ck_assert_uint_ne(st & JF_PT_AUTO, 0);
        nok += !(st & ~(unsigned)(JF_PT_AUTO | JF_PT_AUTO_CAPPED | JF_PT_AUTO_WEIGHTED |
                                  JF_PT_AUTO_SPREAD));
        double k = cli_val(&t, i, "neighbors"), d = cli_val(&t, i, "degree");
        ck_assert(k >= 16 && k <= JF_NB_AUTO_KMAX);
        ck_assert(d == 2 || d == 3);
        sg[i] = cli_val(&t, i, "sigma");
    }
    jf_eval_table_free(&t);
    ck_assert_uint_eq(ok, nok);
    ck_assert_uint_gt(ok, SIDE * SIDE / 2);
    /* the noise along the normal has sd NOISE (isotropic noise) */
    qsort(sg, SIDE * SIDE, sizeof sg[0], cmp_d);
    double med = sg[SIDE * SIDE / 2];
    ck_assert_msg(med > 0.6 * NOISE && med < 1.5 * NOISE, "median sigma %g vs %g", med, NOISE);
    /* knn runs have no sigma column, nor step 0's line */
    ck_assert_int_eq(cli_run("estimate", cli_path("in.xyz"), "-o", cli_path("k.csv"), NULL), 0);
    ck_assert_msg(!strstr(cli_err, "auto step 0"), "%s", cli_err);
    cli_read(cli_path("k.csv"), &t);
    ck_assert_int_lt(jf_eval_table_col(&t, "sigma"), 0);
    jf_eval_table_free(&t);
}
END_TEST

/* in: auto's rows on 2 threads, in --memory parts (the least plan that
 * works) and on one thread are the same bytes; returns how many rows
 * carry flag */
static size_t parts_threads(const char *in, unsigned flag)
{
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("w.csv"), "--neighbors", "auto",
                             "--threads", "2", "--quiet", NULL),
                     0);
    /* --memory 16K is refused with the least that works: that runs in parts */
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("p.csv"), "--neighbors", "auto",
                             "--threads", "2", "--memory", "16K", "--quiet", NULL),
                     1);
    const char *lw = strstr(cli_err, "the least that works is --memory ");
    char mem[32] = "";
    ck_assert_msg(lw && sscanf(lw + 33, "%31s", mem) == 1, "%s", cli_err);
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("p.csv"), "--neighbors", "auto",
                             "--threads", "2", "--memory", mem, "--quiet", NULL),
                     0);
    jf_test_assert_same_files("auto, in parts", cli_path("w.csv"), cli_path("p.csv"));
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("t.csv"), "--neighbors", "auto",
                             "--threads", "1", "--quiet", NULL),
                     0);
    jf_test_assert_same_files("auto, one thread", cli_path("w.csv"), cli_path("t.csv"));
    jf_eval_table t;
    cli_read(cli_path("w.csv"), &t);
    size_t c = 0;
    for (size_t i = 0; i < t.nrows; i++) c += ((unsigned)cli_val(&t, i, "status") & flag) != 0;
    jf_eval_table_free(&t);
    return c;
}

/* The summary's step 0 line of `jetfit estimate in --neighbors auto`
 * into line, asserting it is there and the same in --memory parts (the
 * least plan). */
static void step0_line(const char *in, char *line, size_t len)
{
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("s.csv"), "--neighbors", "auto", NULL), 0);
    const char *a = strstr(cli_err, "\n  auto step 0: ");
    ck_assert_msg(a, "%s", cli_err);
    snprintf(line, len, "%.*s", (int)strcspn(a + 3, "\n"), a + 3);
    /* not --quiet: the least counts the summary's values */
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("s.csv"), "--neighbors", "auto", "--memory",
                             "16K", NULL),
                     1);
    const char *lw = strstr(cli_err, "the least that works is --memory ");
    char mem[32] = "";
    ck_assert_msg(lw && sscanf(lw + 33, "%31s", mem) == 1, "%s", cli_err);
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path("s.csv"), "--neighbors", "auto", "--memory", mem,
                             NULL),
                     0);
    ck_assert_msg(strstr(cli_err, "  parts: "), "in parts: %s", cli_err);
    const char *b = strstr(cli_err, "\n  auto step 0: ");
    ck_assert_msg(b && !strncmp(b + 3, line, strlen(line)) && b[3 + strlen(line)] == '\n',
                  "parts: %s\nwhole: %s", cli_err, line);
}

START_TEST(auto_parts_threads)
{
    write_noisy(cli_path("in.xyz"));
    parts_threads(cli_path("in.xyz"), 0);
}
END_TEST

/* Step 0's bias test: a torus with a density gradient at 0.3% reads a
 * mild bias (its rows whose noise is small against their fit's spread,
 * 1,355 here, take the spread carry, whose halo reaches the 128th
 * nearest; the others the weighted mean), an `exp` patch at 0.05% none
 * (every row weighted) */
START_TEST(auto_parts_step0_flags)
{
    ck_assert_int_eq(cli_run("generate", "torus", "-o", cli_path("torus.ply"), "--n", "6000", "--noise",
                             "0.003", "--density", "gradient", "--seed", "27", NULL),
                     0);
    ck_assert_uint_gt(parts_threads(cli_path("torus.ply"), JF_PT_AUTO_SPREAD), 600);
    /* the summary says so: no cap, the spread carry; the exp patch below:
     * no cap, every row's mean weighted */
    char line[256];
    step0_line(cli_path("torus.ply"), line, sizeof line);
    ck_assert_msg(strstr(line, "auto step 0: no cap on K") == line && strstr(line, "; step 6: the spread carry") &&
                      !strstr(line, "weighted"),
                  "%s", line);
    ck_assert_int_eq(cli_run("generate", "exp", "-o", cli_path("exp.ply"), "--n", "4000", "--noise",
                             "0.0005", "--seed", "27", NULL),
                     0);
    ck_assert_uint_eq(parts_threads(cli_path("exp.ply"), JF_PT_AUTO_WEIGHTED), 4000);
    step0_line(cli_path("exp.ply"), line, sizeof line);
    ck_assert_msg(strstr(line, "auto step 0: no cap on K") == line &&
                      strstr(line, "; step 6: every row's weighted mean") && !strstr(line, "spread"),
                  "%s", line);
}
END_TEST

/* A raw range scan (data/bun090.ply): step 0 caps K and reads a mild
 * bias on 32 points (item 8 of docs/robustness.md), so every row is
 * fitted on 32 points (the cap raised from the least CV's 24, none
 * below it) and takes the weighted mean; the same bytes in parts and on
 * one thread */
START_TEST(auto_scan_capped_weighted)
{
    const char *bun = JF_TEST_DATA "/bun090.ply";
    ck_assert_uint_eq(parts_threads(bun, JF_PT_AUTO_CAPPED | JF_PT_AUTO_WEIGHTED), 30379);
    jf_eval_table t;
    cli_read(cli_path("w.csv"), &t);
    size_t both = 0, at32 = 0;
    for (size_t i = 0; i < t.nrows; i++) {
        const unsigned st = (unsigned)cli_val(&t, i, "status");
        both += (st & (JF_PT_AUTO_CAPPED | JF_PT_AUTO_WEIGHTED)) == (JF_PT_AUTO_CAPPED | JF_PT_AUTO_WEIGHTED);
        at32 += cli_val(&t, i, "neighbors") == 32;
    }
    jf_eval_table_free(&t);
    ck_assert_uint_eq(both, 30379);
    ck_assert_uint_eq(at32, 30379);
    /* the summary says what the rows show: K capped at 32, capped rows
     * weighted (and no cubic below 48: every row a quadric) */
    char line[256];
    step0_line(bun, line, sizeof line);
    ck_assert_msg(strstr(line, "auto step 0: K capped at 32;") == line &&
                      strstr(line, "; capped rows: the weighted mean, K at least 32"),
                  "%s", line);
    size_t deg2 = 0;
    cli_read(cli_path("s.csv"), &t);
    for (size_t i = 0; i < t.nrows; i++) deg2 += cli_val(&t, i, "degree") == 2;
    jf_eval_table_free(&t);
    if (strstr(line, "no cubic below K = 48")) ck_assert_uint_eq(deg2, 30379);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_auto");
    TCase *tc = tcase_create("neighbors auto");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, auto_columns_and_summary);
    tcase_add_test(tc, auto_parts_threads);
    tcase_add_test(tc, auto_parts_step0_flags);
    tcase_add_test(tc, auto_scan_capped_weighted);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
