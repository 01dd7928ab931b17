/* test_cli_gnu_more.c -- `jetfit study` and `jetfit view` take the
 * command-line habits of the other commands (issue 31; test_cli_gnu.c
 * covers estimate, generate, render, eval, convergence): study's '-' as
 * INPUT (standard input, with --input-format), inside --flags sets the
 * GNU spellings estimate takes (--opt=VALUE, unique prefixes), ambiguous
 * and unknown ones refused with one line; view's -oFILE, --opt=V,
 * prefixes, '--'.  Each spelling is checked against the plain one: the
 * same study.csv (every measured column) and study.def, the same page. */
#include <check.h>

#include "jf_test.h"
#include "test_cli_util.h"

/* Splits a CSV line (quotes "..." may hold commas) into at most 32 fields,
 * in place. */
static int split_csv(char *line, char *f[32])
{
    int n = 0, q = 0;
    f[n++] = line;
    for (char *p = line; *p && n < 32; p++) {
        if (*p == '"') q = !q;
        else if (*p == ',' && !q) *p = '\0', f[n++] = p + 1;
    }
    return n;
}

/* study.csv of two folders: the same rows, field for field, except the
 * flags text (column 2: spelt differently) and the timing columns
 * (seconds, points_per_s: the last two).  Returns the rows compared. */
static int same_study(const char *dir_a, const char *dir_b, int skip_flags)
{
    char pa[600], pb[600];
    snprintf(pa, sizeof pa, "%s/study.csv", dir_a);
    snprintf(pb, sizeof pb, "%s/study.csv", dir_b);
    char *a = jf_test_slurp(pa, NULL), *b = jf_test_slurp(pb, NULL);
    ck_assert_ptr_nonnull(a);
    ck_assert_ptr_nonnull(b);
    int rows = 0;
    char *sa, *sb, *la = strtok_r(a, "\n", &sa), *lb = strtok_r(b, "\n", &sb);
    for (; la && lb; la = strtok_r(NULL, "\n", &sa), lb = strtok_r(NULL, "\n", &sb), rows++) {
        char *fa[32], *fb[32];
        int na = split_csv(la, fa), nb = split_csv(lb, fb);
        ck_assert_int_eq(na, nb);
        ck_assert_int_ge(na, 10);
        for (int j = 0; j < na - 2; j++)
            if (!(skip_flags && j == 2) || rows == 0)
                ck_assert_msg(!strcmp(fa[j], fb[j]), "row %d column %d: '%s' vs '%s'", rows, j,
                              fa[j], fb[j]);
        if (rows > 0) ck_assert_str_eq(fa[na - 3], "ok"); /* status: every cell ran */
    }
    ck_assert_msg(!la && !lb, "study.csv files of different lengths");
    free(a), free(b);
    return rows - 1;
}

/* A LAZ (or E57) on standard input, named by --input-format: the same
 * result as from the file; -o - with --output-format laz likewise. */
START_TEST(compressed_formats_through_pipes)
{
    cli_setup();
    const char *laz = JF_TESTS_DIR "/data/laz/1815.laz";
    char tmp[300];
    snprintf(tmp, sizeof tmp, "%s", cli_path("tmp"));
    ck_assert_int_eq(mkdir(tmp, 0700), 0);
    ck_assert_int_eq(cli_run("estimate", laz, "-o", cli_path("file.laz"), "--neighbors", "knn:8",
                             "-q", NULL), 0);
    ck_assert_int_eq(cli_run_io(laz, NULL, tmp, "estimate", "-", "--input-format", "laz", "-o",
                                cli_path("pipe.laz"), "--neighbors", "knn:8", "-q", NULL),
                     0);
    size_t na, nb;
    char *a = jf_test_slurp(cli_path("file.laz"), &na), *b = jf_test_slurp(cli_path("pipe.laz"), &nb);
    ck_assert(a && b && na == nb && !memcmp(a, b, na));
    free(a), free(b);
    ck_assert_int_eq(cli_run_io(laz, NULL, tmp, "estimate", "-", "-o", cli_path("x.laz"), NULL), 1);
    ck_assert(!cli_exists(cli_path("x.laz")));
    ck_assert_ptr_nonnull(strstr(cli_err, "--input-format"));
    cli_rm_rf(tmp);
    cli_teardown();
}
END_TEST

START_TEST(standard_input_is_the_file)
{
    cli_setup();
    char cloud[512], truth[512], tmp[512], d1[512], d2[512], d3[512];
    snprintf(cloud, sizeof cloud, "%s/c.ply", cli_dir);
    snprintf(truth, sizeof truth, "%s/t.csv", cli_dir);
    snprintf(tmp, sizeof tmp, "%s/tmp", cli_dir);
    snprintf(d1, sizeof d1, "%s/from-file", cli_dir);
    snprintf(d2, sizeof d2, "%s/from-pipe", cli_dir);
    snprintf(d3, sizeof d3, "%s/resumed", cli_dir);
    ck_assert_int_eq(mkdir(tmp, 0700), 0);
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "500", "--seed", "4", "-o", cloud,
                             "--truth", truth, NULL), 0);
    const char *nb = "knn:16;knn:24";
    ck_assert_int_eq(cli_run("study", cloud, "--truth", truth, "-o", d1, "-q", "--neighbors",
                             nb, "--noise", "0;0.002", NULL), 0);
    ck_assert_int_eq(cli_run_io(cloud, NULL, tmp, "study", "-", "--input-format", "ply", "--truth",
                                truth, "-o", d2, "-q", "--neighbors", nb, "--noise", "0;0.002",
                                NULL),
                     0);
    ck_assert_str_eq(cli_err, "");
    ck_assert_int_eq(same_study(d1, d2, 0), 4);
    /* study.def: the input by its content, the same for the pipe */
    char p1[600], p2[600];
    snprintf(p1, sizeof p1, "%s/study.def", d1);
    snprintf(p2, sizeof p2, "%s/study.def", d2);
    char *t1 = jf_test_slurp(p1, NULL), *t2 = jf_test_slurp(p2, NULL);
    ck_assert_ptr_nonnull(t1);
    ck_assert_ptr_nonnull(t2);
    ck_assert_str_eq(t1, t2);
    ck_assert_ptr_nonnull(strstr(t1, "input: "));
    free(t1), free(t2);
    /* the spooled copy of standard input is gone */
    DIR *d = opendir(tmp);
    int left = 0;
    for (struct dirent *e; d && (e = readdir(d));) left += e->d_name[0] != '.';
    if (d) closedir(d);
    ck_assert_int_eq(left, 0);
    /* the same bytes piped into a --resume of the file's study keep its cells */
    ck_assert_int_eq(cli_run("study", cloud, "--truth", truth, "-o", d3, "-q", "--neighbors",
                             "knn:16", NULL), 0);
    ck_assert_int_eq(cli_run_io(cloud, NULL, tmp, "study", "-", "--input-format=ply", "--truth",
                                truth, "-o", d3, "--neighbors", nb, "--resume", NULL),
                     0);
    ck_assert_msg(strstr(cli_err, "resuming: 1 of 2 cells kept"), "%s", cli_err);
    /* a bad standard input: one line naming it, no folder */
    char junk[512], d4[512];
    snprintf(junk, sizeof junk, "%s/junk.txt", cli_dir);
    snprintf(d4, sizeof d4, "%s/never", cli_dir);
    cli_write_text(junk, "0 0 0\n1 x 2\n");
    ck_assert_int_eq(cli_run_io(junk, NULL, tmp, "study", "-", "--input-format", "xyz", "--truth",
                                truth, "-o", d4, "-q", NULL),
                     1);
    ck_assert_msg(!strncmp(cli_err, "jetfit: (standard input):2", 26), "%s", cli_err);
    ck_assert_int_eq((int)(strchr(cli_err, '\n') - cli_err + 1), (int)strlen(cli_err));
    ck_assert(!cli_exists(d4));
    /* without --input-format standard input has no extension to go by */
    ck_assert_int_eq(cli_run_io(cloud, NULL, tmp, "study", "-", "--truth", truth, "-o", d4, NULL),
                     1);
    ck_assert_ptr_nonnull(strstr(cli_err, "--input-format"));
    ck_assert(!cli_exists(d4));
    /* only INPUT may come from standard input */
    ck_assert_int_eq(cli_run_io(truth, NULL, tmp, "study", cloud, "--truth", "-", "-o", d4, NULL),
                     2);
    ck_assert_ptr_nonnull(strstr(cli_err, "--truth '-'"));
    ck_assert_int_eq(cli_run("study", "exp", "--input-format", "ply", "-o", d4, NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "applies to INPUT"));
    ck_assert(!cli_exists(d4));
    cli_rm_rf(d1), cli_rm_rf(d2), cli_rm_rf(d3), cli_rm_rf(tmp);
    cli_teardown();
}
END_TEST

START_TEST(flag_sets_take_gnu_spellings)
{
    cli_setup();
    char full[512], gnu[512], bad[512];
    snprintf(full, sizeof full, "%s/full", cli_dir);
    snprintf(gnu, sizeof gnu, "%s/gnu", cli_dir);
    snprintf(bad, sizeof bad, "%s/bad", cli_dir);
    /* the same four sets, written in full and abbreviated / with '=' */
    ck_assert_int_eq(cli_run("study", "paraboloid", "--n", "600", "-o", full, "-q", "--neighbors",
                             "knn:16", "--noise", "0.001", "--flags",
                             ";--robust-normals;--robust huber --max-cond 100;--scales 8,16,32;"
                             "--dist-weight 0.5 --degree-select 1",
                             NULL), 0);
    ck_assert_int_eq(cli_run("study", "paraboloid", "--n=600", "-o", gnu, "-q", "--neighb",
                             "knn:16", "--noise=0.001", "--fl",
                             ";--robust-n;--robust=huber --max-c=100;--scal 8,16,32;"
                             "--dist-w=0.5 --degree-sel 1",
                             NULL), 0);
    ck_assert_int_eq(same_study(full, gnu, 1), 5);
    /* the sets differ: not every row measured the same (the check can fail) */
    char p[600];
    snprintf(p, sizeof p, "%s/study.csv", full);
    char *t = jf_test_slurp(p, NULL);
    ck_assert_ptr_nonnull(t);
    char *l1 = strchr(t, '\n') + 1, *l2 = strchr(l1, '\n') + 1, *f1[32], *f2[32];
    l1[-1] = '\0', *strchr(l1, '\n') = '\0', *strchr(l2, '\n') = '\0';
    split_csv(l1, f1), split_csv(l2, f2);
    ck_assert_str_ne(f1[10], f2[10]); /* normal_rms of '' and of --robust-normals */
    free(t);
    struct {
        const char *flags, *says;
    } cases[] = {
        {"--rob=huber", "'--rob' is ambiguous; possibilities: '--robust' '--robust-normals'"},
        {"--deg 3", "'--deg' is ambiguous"},
        {"--degree=3", "the study's own options"},
        {"--neighbours knn:8", "the study's own options"},
        {"--bad-rows skip", "the study's own options"},
        {"--robust", "'--robust' needs a value"},
        {"--robust-normals=1", "takes no value"},
        {"--bogus", "unknown option '--bogus' (not an estimate option)"},
        {"-x", "unknown option '-x'"},
        {"huber", "'huber' is not an estimate option"},
        {"--robust=nope", "--robust 'nope'"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ck_assert_int_eq(cli_run("study", "exp", "--n", "300", "-o", bad, "--flags",
                                 cases[k].flags, NULL), 2);
        ck_assert_msg(strstr(cli_err, cases[k].says), "%s: %s", cases[k].flags, cli_err);
        ck_assert_int_eq((int)(strchr(cli_err, '\n') - cli_err + 1), (int)strlen(cli_err));
        ck_assert(!cli_exists(bad));
    }
    cli_rm_rf(full), cli_rm_rf(gnu);
    cli_teardown();
}
END_TEST

START_TEST(view_takes_gnu_spellings)
{
    cli_setup();
    char cloud[512], res[512], a[512], b[512], c[512];
    snprintf(cloud, sizeof cloud, "%s/s.xyz", cli_dir);
    snprintf(res, sizeof res, "%s/r.ply", cli_dir);
    snprintf(a, sizeof a, "%s/a.html", cli_dir);
    snprintf(b, sizeof b, "%s/b.html", cli_dir);
    snprintf(c, sizeof c, "%s/c.html", cli_dir);
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "1500", "-o", cloud, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cloud, "-o", res, "-q", NULL), 0);
    ck_assert_int_eq(cli_run("view", res, "-o", a, "--quiet", "--color", "k2", "--max-points",
                             "700", "--title", "T", NULL), 0);
    char ob[600];
    snprintf(ob, sizeof ob, "-qo%s", b);
    ck_assert_int_eq(cli_run("view", "--colo=k2", ob, "--max-p=700", "--tit", "T", "--", res,
                             NULL), 0);
    ck_assert_str_eq(cli_err, "");
    ck_assert(jf_test_same_files(a, b));
    /* another colour: another page (the comparison can fail) */
    ck_assert_int_eq(cli_run("view", res, "-o", c, "-q", "--color", "k1", "--max-points", "700",
                             "--title", "T", NULL), 0);
    ck_assert(!jf_test_same_files(a, c));
    /* with --estimate, estimate's options in the same spellings */
    unlink(c);
    ck_assert_int_eq(cli_run("view", "--est", cloud, "-q", "--neighb=knn:16", "--degree=3",
                             "--keep", "none", "-o", c, NULL), 0);
    ck_assert(cli_exists(c));
    struct {
        const char *o1, *o2, *says;
    } cases[] = {
        {"--col", "k2", "'--col' is ambiguous; possibilities: '--color' '--columns'"},
        {"--degree", "3", "--degree is an estimate option: it applies with --estimate"},
        {"--bogus", NULL, "unknown option '--bogus'"},
        {"--all-columns=1", NULL, "takes no value"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        unlink(c);
        ck_assert_int_eq(cli_run("view", res, "-o", c, cases[k].o1, cases[k].o2, NULL), 2);
        ck_assert_msg(strstr(cli_err, cases[k].says), "%s: %s", cases[k].o1, cli_err);
        ck_assert(!cli_exists(c));
    }
    cli_teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_gnu_more");
    TCase *t = tcase_create("gnu_more");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, standard_input_is_the_file);
    tcase_add_test(t, flag_sets_take_gnu_spellings);
    tcase_add_test(t, compressed_formats_through_pipes);
    tcase_add_test(t, view_takes_gnu_spellings);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
