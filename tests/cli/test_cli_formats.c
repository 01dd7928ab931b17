/* test_cli_formats.c -- `jetfit estimate` end to end on files: the same
 * points in PLY ascii / binary LE / binary BE / CSV / XYZ give the same
 * values in every output format; rows keep the input order exactly;
 * --threads 1 and 2 write identical bytes; --columns; Monge columns. */
#include <check.h>

#include "test_cli_util.h"
#include "jf_test.h"

#define N 700

static double pts[3 * N];

/* The §6.1 surface, shuffled, offset far from the origin (as
 * georeferenced scans are): coordinates are exact doubles in every
 * input format (text is written with %.17g). */
static void make_points(void)
{
    cli_surface61(26, pts, 99); /* 676 points */
    for (size_t i = 676; i < N; i++) /* pad with a second copy, shifted */
        for (int k = 0; k < 3; k++) pts[3 * i + k] = pts[3 * (i - 676) + k] + (k == 2 ? 3.0 : 0);
    for (size_t i = 0; i < N; i++) pts[3 * i] += 4.5e5, pts[3 * i + 1] -= 5.2e6;
}

/* Same bits, NaN equal to NaN. */
static int same(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static void assert_tables_equal(const jf_eval_table *a, const jf_eval_table *b, const char *what)
{
    ck_assert_msg(a->nrows == b->nrows && a->ncols == b->ncols, "%s: shape", what);
    for (size_t j = 0; j < a->ncols; j++) ck_assert_str_eq(a->names[j], b->names[j]);
    for (size_t i = 0; i < a->nrows * a->ncols; i++)
        ck_assert_msg(same(a->v[i], b->v[i]), "%s: row %zu column %s: %.17g vs %.17g", what,
                      i / a->ncols, a->names[i % a->ncols], a->v[i], b->v[i]);
}

START_TEST(input_formats_agree)
{
    make_points();
    cli_write_xyz(cli_path("in.xyz"), pts, NULL, N);
    cli_write_ply(cli_path("in_a.ply"), pts, N, 0);
    cli_write_ply(cli_path("in_le.ply"), pts, N, 1);
    cli_write_ply(cli_path("in_be.ply"), pts, N, 2);
    FILE *f = fopen(cli_path("in.csv"), "w");
    fprintf(f, "x,y,z\n");
    for (size_t i = 0; i < N; i++)
        fprintf(f, "%.17g,%.17g,%.17g\n", pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    fclose(f);
    static const char *const ins[] = {"in.xyz", "in_a.ply", "in_le.ply", "in_be.ply", "in.csv"};
    jf_eval_table ref;
    for (size_t k = 0; k < 5; k++) {
        ck_assert_msg(cli_run("estimate", cli_path(ins[k]), "-o", cli_path("o.csv"), "--quiet",
                              "--neighbors", "knn:20", NULL) == 0,
                      "%s: %s", ins[k], cli_err);
        ck_assert_str_eq(cli_err, ""); /* --quiet */
        jf_eval_table t;
        cli_read(cli_path("o.csv"), &t);
        if (k == 0) {
            ref = t;
            /* input order, exactly */
            ck_assert_uint_eq(ref.nrows, N);
            for (size_t i = 0; i < N; i++) {
                ck_assert(same(cli_val(&ref, i, "x"), pts[3 * i]));
                ck_assert(same(cli_val(&ref, i, "y"), pts[3 * i + 1]));
                ck_assert(same(cli_val(&ref, i, "z"), pts[3 * i + 2]));
                ck_assert_double_eq(cli_val(&ref, i, "status"), 0);
                ck_assert_double_eq(cli_val(&ref, i, "neighbors"), 20);
            }
        } else if (strstr(ins[k], ".ply")) {
            /* the PLY inputs' `float quality` is carried after x y z, in
             * its type, then the same columns as from the other formats */
            ck_assert_uint_eq(t.ncols, ref.ncols + 1);
            ck_assert_str_eq(t.names[3], "quality");
            for (size_t i = 0; i < t.nrows; i++) ck_assert(same(t.v[i * t.ncols + 3], 0.5));
            for (size_t i = 0; i < t.nrows; i++)
                memmove(t.v + i * ref.ncols, t.v + i * t.ncols, 3 * sizeof *t.v),
                memmove(t.v + i * ref.ncols + 3, t.v + i * t.ncols + 4,
                        (ref.ncols - 3) * sizeof *t.v);
            memmove(t.names + 3, t.names + 4, (ref.ncols - 3) * sizeof *t.names);
            t.ncols = ref.ncols;
            assert_tables_equal(&ref, &t, ins[k]);
            jf_eval_table_free(&t);
        } else {
            assert_tables_equal(&ref, &t, ins[k]);
            jf_eval_table_free(&t);
        }
    }
    jf_eval_table_free(&ref);
}
END_TEST

START_TEST(output_formats_agree)
{
    make_points();
    cli_write_xyz(cli_path("in.xyz"), pts, NULL, N);
    static const char *const outs[] = {"o.csv", "o.ply", "o_ascii.ply", "o.xyz", "o.txt"};
    jf_eval_table ref;
    for (size_t k = 0; k < 5; k++) {
        int ascii = k == 2;
        int rc = ascii ? cli_run("estimate", cli_path("in.xyz"), "-o", cli_path(outs[k]),
                                 "--ascii", "--degree", "4", NULL)
                       : cli_run("estimate", cli_path("in.xyz"), "-o", cli_path(outs[k]),
                                 "--degree", "4", NULL);
        ck_assert_msg(rc == 0, "%s: %s", outs[k], cli_err);
        /* the summary (stderr, not a terminal: no progress line) */
        ck_assert(strstr(cli_err, outs[k]) != NULL);
        ck_assert_msg(strstr(cli_err, "jetfit: 700 points in ") == cli_err, "%s", cli_err);
        ck_assert(strstr(cli_err, "points/s") && strstr(cli_err, "  status: ok "));
        ck_assert(strstr(cli_err, "  degree: ") && strstr(cli_err, "  cond: p50 "));
        ck_assert(!strchr(cli_err, '\r'));
        jf_eval_table t;
        cli_read(cli_path(outs[k]), &t);
        if (k == 0) {
            ref = t;
            static const char *const names[] = {
                "x",  "y",  "z",  "nx", "ny", "nz", "k1", "k2", "d1x", "d1y", "d1z",
                "d2x", "d2y", "d2z", "b0", "b1", "b2", "b3", "c0", "c1", "c2", "c3",
                "c4", "degree", "neighbors", "cond", "residual", "status"};
            ck_assert_uint_eq(ref.ncols, sizeof names / sizeof names[0]);
            for (size_t j = 0; j < ref.ncols; j++) ck_assert_str_eq(ref.names[j], names[j]);
        } else {
            assert_tables_equal(&ref, &t, outs[k]);
            jf_eval_table_free(&t);
        }
    }
    jf_eval_table_free(&ref);
    /* the PLY header says binary little endian unless --ascii */
    FILE *f = fopen(cli_path("o.ply"), "rb");
    char head[64] = {0};
    ck_assert(fread(head, 1, 40, f) == 40);
    fclose(f);
    ck_assert(strstr(head, "format binary_little_endian 1.0") != NULL);
    /* default monge degree follows the degree: 2 -> no b, c columns */
    ck_assert_int_eq(cli_run("estimate", cli_path("in.xyz"), "-o", cli_path("d2.csv"), NULL), 0);
    jf_eval_table t;
    cli_read(cli_path("d2.csv"), &t);
    ck_assert_int_eq(jf_eval_table_col(&t, "b0"), -1);
    ck_assert_int_eq(jf_eval_table_col(&t, "status"), 18);
    jf_eval_table_free(&t);
    ck_assert_int_eq(cli_run("estimate", cli_path("in.xyz"), "-o", cli_path("d3.csv"),
                             "--degree", "3", NULL), 0);
    cli_read(cli_path("d3.csv"), &t);
    ck_assert_int_eq(jf_eval_table_col(&t, "b3"), 17);
    ck_assert_int_eq(jf_eval_table_col(&t, "c0"), -1);
    jf_eval_table_free(&t);
}
END_TEST

static int files_equal(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int eq = fa && fb, ca, cb;
    while (eq) {
        ca = fgetc(fa);
        cb = fgetc(fb);
        if (ca != cb) eq = 0;
        if (ca == EOF) break;
    }
    if (fa) fclose(fa);
    if (fb) fclose(fb);
    return eq;
}

START_TEST(threads_identical)
{
    make_points();
    cli_write_ply(cli_path("in.ply"), pts, N, 1);
    static const char *const nbs[] = {"knn:16", "radius:0.08", "knn:40,radius:0.06"};
    for (size_t k = 0; k < 3; k++) {
        ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("t1.ply"),
                                 "--threads", "1", "--neighbors", nbs[k], "--degree", "3",
                                 "--orient", "mst", NULL), 0);
        ck_assert_int_eq(cli_run("estimate", cli_path("in.ply"), "-o", cli_path("t2.ply"),
                                 "--threads", "2", "--neighbors", nbs[k], "--degree", "3",
                                 "--orient", "mst", NULL), 0);
        ck_assert_msg(files_equal(cli_path("t1.ply"), cli_path("t2.ply")), "%s", nbs[k]);
    }
}
END_TEST

/* --columns picks x y z out of wider rows (0-based). */
START_TEST(columns_option)
{
    make_points();
    cli_write_xyz(cli_path("in.xyz"), pts, NULL, N);
    FILE *f = fopen(cli_path("wide.txt"), "w");
    for (size_t i = 0; i < N; i++)
        fprintf(f, "%zu 7 %.17g 9 %.17g %.17g\n", i, pts[3 * i + 2], pts[3 * i],
                pts[3 * i + 1]);
    fclose(f);
    ck_assert_int_eq(cli_run("estimate", cli_path("in.xyz"), "-o", cli_path("a.csv"), NULL), 0);
    ck_assert_msg(cli_run("estimate", cli_path("wide.txt"), "-o", cli_path("b.csv"),
                          "--columns", "4,5,2", NULL) == 0, "%s", cli_err);
    jf_eval_table a, b;
    cli_read(cli_path("a.csv"), &a);
    cli_read(cli_path("b.csv"), &b);
    assert_tables_equal(&a, &b, "--columns");
    jf_eval_table_free(&a);
    jf_eval_table_free(&b);
}
END_TEST

/* rings on an OFF mesh (a UV sphere), natural on its vertices as a
 * cloud; rings without faces is an error naming the option. */
START_TEST(neighbourhood_kinds)
{
    enum { NU = 60, NV = 30 };
    size_t n = (size_t)NU * (NV - 1), nf = 2 * (size_t)NU * (NV - 2);
    double R = 2, *xyz = malloc(3 * n * sizeof *xyz);
    FILE *f = fopen(cli_path("s.off"), "w");
    fprintf(f, "OFF\n%zu %zu 0\n", n, nf);
    for (int j = 1; j < NV; j++)
        for (int i = 0; i < NU; i++) {
            double th = M_PI * j / NV, ph = 2 * M_PI * i / NU;
            double *p = xyz + 3 * ((size_t)(j - 1) * NU + i);
            p[0] = R * sin(th) * cos(ph), p[1] = R * sin(th) * sin(ph), p[2] = R * cos(th);
            fprintf(f, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
        }
    for (int j = 0; j < NV - 2; j++)
        for (int i = 0; i < NU; i++) {
            int a = j * NU + i, b = j * NU + (i + 1) % NU;
            fprintf(f, "3 %d %d %d\n3 %d %d %d\n", a, a + NU, b, b, a + NU, b + NU);
        }
    fclose(f);
    cli_write_xyz(cli_path("s.xyz"), xyz, NULL, n);
    ck_assert_msg(cli_run("estimate", cli_path("s.off"), "-o", cli_path("r.csv"), "--neighbors",
                          "rings:19", "--orient", "viewpoint:0,0,0", NULL) == 0, "%s", cli_err);
    ck_assert_msg(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("n.csv"), "--neighbors",
                          "natural", "--orient", "mst", NULL) == 0, "%s", cli_err);
    jf_eval_table r, t;
    cli_read(cli_path("r.csv"), &r);
    cli_read(cli_path("n.csv"), &t);
    ck_assert_uint_eq(r.nrows, n);
    ck_assert_uint_eq(t.nrows, n);
    for (size_t i = 0; i < n; i++) {
        size_t lat = i / NU + 1;
        ck_assert(same(cli_val(&r, i, "x"), xyz[3 * i]));
        if (lat < 5 || lat > NV - 5) continue; /* thin triangles near the poles */
        ck_assert_double_eq(cli_val(&r, i, "neighbors"), 19);
        ck_assert_double_eq_tol(cli_val(&r, i, "k1"), 1 / R, 0.03 / R);  /* inward */
        ck_assert_double_eq_tol(cli_val(&t, i, "k2"), -1 / R, 0.05 / R); /* outward */
        unsigned st = (unsigned)cli_val(&t, i, "status");
        ck_assert_uint_ne(st & JF_PT_NORMAL_PCA, 0); /* clean: the PCA plane */
    }
    jf_eval_table_free(&r);
    jf_eval_table_free(&t);
    ck_assert_int_ne(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("x.csv"),
                             "--neighbors", "rings:19", NULL), 0);
    ck_assert(strstr(cli_err, "rings") != NULL);
    ck_assert_int_ne(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("x.csv"),
                             "--neighbors", "natural", "--normal", "input", NULL), 0);
    ck_assert(strstr(cli_err, "normal input") != NULL);
    ck_assert(!cli_exists(cli_path("x.csv")));
    free(xyz);
}
END_TEST

/* On a terminal: a progress line ("\r", phase, percent, points/s, ETA)
 * ending at 100% in each phase, then the summary; --quiet draws nothing. */
START_TEST(progress_on_terminal)
{
    make_points();
    cli_write_xyz(cli_path("in.xyz"), pts, NULL, N);
    ck_assert_int_eq(cli_run_tty("estimate", cli_path("in.xyz"), "-o", cli_path("p.csv"), NULL),
                     0);
    ck_assert_msg(strstr(cli_err, "\rjetfit: fitting  100.0%  700/700 points") != NULL, "%s",
                  cli_err);
    /* every phase: the file read (bytes), the rows written */
    ck_assert_msg(strstr(cli_err, "\rjetfit: reading  100.0%") != NULL, "%s", cli_err);
    ck_assert_msg(strstr(cli_err, "\rjetfit: writing  100.0%  700/700 points") != NULL, "%s",
                  cli_err);
    ck_assert(strstr(cli_err, "ETA") && strstr(cli_err, "cond: p50"));
    ck_assert_int_eq(cli_run_tty("estimate", cli_path("in.xyz"), "-o", cli_path("p.csv"),
                                 "--quiet", NULL), 0);
    ck_assert_str_eq(cli_err, "");
}
END_TEST

/* --memory in parts: one fit line for the whole cloud; the parts' own
 * index phases (each part's counts) are timed, not drawn. */
START_TEST(progress_in_parts)
{
    const size_t side = 250, n = side * side; /* parts pay (their halo rings) */
    double *xyz = malloc(3 * n * sizeof *xyz);
    cli_surface61(side, xyz, 5);
    cli_write_xyz(cli_path("big.xyz"), xyz, NULL, n);
    free(xyz);
    ck_assert_int_eq(cli_run("estimate", cli_path("big.xyz"), "-o", cli_path("p.csv"), "--memory",
                             "4K", NULL), 1);
    const char *lw = strstr(cli_err, "the least that works is --memory ");
    char mem[32] = "", want[80];
    ck_assert_msg(lw && sscanf(lw + 33, "%31s", mem) == 1, "%s", cli_err);
    ck_assert_int_eq(cli_run_tty("estimate", cli_path("big.xyz"), "-o", cli_path("p.csv"),
                                 "--memory", mem, NULL), 0);
    snprintf(want, sizeof want, "\rjetfit: fitting  100.0%%  %zu/%zu points", n, n);
    ck_assert_msg(strstr(cli_err, want) != NULL, "%s", cli_err);
    ck_assert_msg(strstr(cli_err, "indexing") == NULL, "%s", cli_err);
    ck_assert_msg(strstr(cli_err, "tree ") != NULL, "%s", cli_err); /* still timed */
}
END_TEST

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The summary's cond percentiles (a selection, not a sort) are the order
 * statistics of the output's cond column: on a random surface sample and
 * on a regular grid, where most points share one cond value. */
START_TEST(summary_percentiles)
{
    const size_t side = 40, n = side * side;
    double *xyz = malloc(3 * n * sizeof *xyz), *c = malloc(n * sizeof *c);
    for (int grid = 0; grid < 2; grid++) {
        if (grid)
            for (size_t i = 0; i < n; i++)
                xyz[3 * i] = (double)(i % side), xyz[3 * i + 1] = (double)(i / side), xyz[3 * i + 2] = 0;
        else
            cli_surface61(side, xyz, 7);
        cli_write_xyz(cli_path("p.xyz"), xyz, NULL, n);
        ck_assert_msg(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("p.csv"), "--neighbors",
                              "knn:12", NULL) == 0, "%s", cli_err);
        jf_eval_table t;
        cli_read(cli_path("p.csv"), &t);
        size_t m = 0;
        for (size_t i = 0; i < n; i++) {
            double v = cli_val(&t, i, "cond");
            if (isfinite(v)) c[m++] = v;
        }
        jf_eval_table_free(&t);
        ck_assert_uint_gt(m, n / 2);
        qsort(c, m, sizeof *c, cmp_dbl);
        char want[160];
        snprintf(want, sizeof want, "  cond: p50 %.3g, p90 %.3g, p99 %.3g, max %.3g\n", c[(m - 1) / 2],
                 c[(size_t)(0.9 * (double)(m - 1))], c[(size_t)(0.99 * (double)(m - 1))], c[m - 1]);
        ck_assert_msg(strstr(cli_err, want) != NULL, "grid %d: want %s in %s", grid, want, cli_err);
    }
    free(xyz);
    free(c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_formats");
    TCase *tc = tcase_create("cli_formats");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, input_formats_agree);
    tcase_add_test(tc, output_formats_agree);
    tcase_add_test(tc, threads_identical);
    tcase_add_test(tc, columns_option);
    tcase_add_test(tc, neighbourhood_kinds);
    tcase_add_test(tc, progress_on_terminal);
    tcase_add_test(tc, progress_in_parts);
    tcase_add_test(tc, summary_percentiles);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
