/* test_cli_study.c -- `jetfit study` end to end (issue 16):
 *  - on a generated surface its table holds, cell by cell, the numbers
 *    that `jetfit generate` + `jetfit estimate` + `jetfit eval` print for
 *    the same cell (the commands run here; compared at eval's printed
 *    precision, %.4g, as strings);
 *  - a study killed (SIGKILL) after some cells and resumed gives the files
 *    of an uninterrupted run (study.csv but its timing columns, best.csv,
 *    the PNGs byte for byte, report.html but its timing cells);
 *  - an INPUT with --truth and --subset: estimate + eval --subset; a
 *    SURFACE --mesh (rings): generate --mesh + estimate + eval;
 *  - report.html opened in headless Chromium has the expected rows and
 *    images, a click sorts a column both ways, and its screenshot is not
 *    blank (skipped, with the reason printed, when /usr/bin/chromium is
 *    not installed);
 *  - Ctrl-C cancels the running cell and keeps the finished ones;
 *  - bad input: one line, no DIR; a failing cell is recorded, the rest go
 *    on; one progress line with an ETA for the whole study; user text
 *    (a folder name) runs nothing through gnuplot and is escaped;
 *  - --resume refuses another study (surface, --n, an estimate option, an
 *    input of the same size) and a value jetfit cannot have written
 *    (NaN, a non-number, a fractional count), naming the field (issue 32). */
#include <check.h>
#include <signal.h>
#include <time.h>

#include "test_cli_util.h"
#include "jf_test.h"

/* ---- helpers ---- */

/* Runs argv[0] (a path) with stdout into outpath (NULL: /dev/null) and
 * stderr into cli_err; returns the exit status. */
static int run_to(const char *outpath, const char *const *argv)
{
    char errpath[512];
    snprintf(errpath, sizeof errpath, "%s.stderr", cli_dir);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int fe = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int fo = open(outpath ? outpath : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fe < 0 || fo < 0) _exit(126);
        dup2(fe, 2);
        dup2(fo, 1);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    cli_err[0] = '\0';
    FILE *f = fopen(errpath, "r");
    if (f) {
        size_t m = fread(cli_err, 1, sizeof cli_err - 1, f);
        cli_err[m] = '\0';
        fclose(f);
    }
    unlink(errpath);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

static int count_str(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = hay; (p = strstr(p, needle)); p += strlen(needle)) n++;
    return n;
}

/* One CSV record (quotes undone) into fld[], in place; returns the count. */
static int csv_fields(char *line, char **fld, int max)
{
    int n = 0;
    char *p = line;
    while (n < max) {
        char *w = p;
        fld[n++] = w;
        if (*p == '"') {
            for (p++; *p && !(*p == '"' && p[1] != '"'); p++) {
                if (*p == '"') p++;
                *w++ = *p;
            }
            if (*p) p++;
        } else {
            while (*p && *p != ',' && *p != '\n') *w++ = *p++;
        }
        int more = *p == ',';
        *w = '\0';
        if (!more) break;
        p++;
    }
    return n;
}

/* study.csv as rows of fields (header first); *nrows rows.  Owned by the
 * caller: free(rows[0].buf) per row, free(rows). */
typedef struct {
    char *buf;
    char *f[40];
    int n;
} csv_row;

static csv_row *read_csv(const char *path, int *nrows)
{
    FILE *fp = fopen(path, "r");
    ck_assert_msg(fp != NULL, "cannot open %s", path);
    csv_row *rows = NULL;
    int n = 0;
    char line[8192];
    while (fgets(line, sizeof line, fp)) {
        line[strcspn(line, "\r\n")] = '\0';
        rows = realloc(rows, (size_t)(n + 1) * sizeof *rows);
        rows[n].buf = strdup(line);
        rows[n].n = csv_fields(rows[n].buf, rows[n].f, 40);
        n++;
    }
    fclose(fp);
    *nrows = n;
    return rows;
}

static void free_csv(csv_row *r, int n)
{
    for (int i = 0; i < n; i++) free(r[i].buf);
    free(r);
}

static int col(const csv_row *head, const char *name)
{
    for (int j = 0; j < head->n; j++)
        if (!strcmp(head->f[j], name)) return j;
    ck_abort_msg("no column %s", name);
    return -1;
}

/* ---- the study equals generate + estimate + eval ---- */

/* eval's printed row for `quantity`: n nonfin rms mean median p95 max. */
static void eval_row(const char *out, const char *quantity, char tok[7][32])
{
    const char *p = out;
    size_t ql = strlen(quantity);
    while (p && !(strncmp(p, quantity, ql) == 0 && p[ql] == ' ')) {
        p = strchr(p, '\n');
        if (p) p++;
    }
    ck_assert_msg(p != NULL, "eval printed no %s row:\n%s", quantity, out);
    int got = sscanf(p + ql, "%31s %31s %31s %31s %31s %31s %31s", tok[0], tok[1], tok[2],
                     tok[3], tok[4], tok[5], tok[6]);
    ck_assert_int_eq(got, 7);
}

/* The study's value as eval prints it (%10.4g, blanks trimmed). */
static void expect_same(const char *study_text, const char *eval_tok, const char *what)
{
    char b[64];
    snprintf(b, sizeof b, "%.4g", strtod(study_text, NULL));
    ck_assert_msg(!strcmp(b, eval_tok), "%s: study %s (%s), eval %s", what, study_text, b, eval_tok);
}

/* Runs `estimate` on input with row c's strategy, degree and flag set,
 * then `eval` against truth (and subset), and checks c's numbers against
 * what eval prints. */
static void check_cell(const csv_row *h, const csv_row *c, const char *input, const char *truth,
                       const char *subset)
{
    static const char *const mname[7] = {"normal_rms", "normal_median", "normal_p95",
                                         "k1_median", "k1_p95", "k2_median", "k2_p95"};
    char est[600], evo[600]; /* not cli_path: its 8 buffers hold the caller's */
    snprintf(est, sizeof est, "%s/e.ply", cli_dir);
    snprintf(evo, sizeof evo, "%s/eval.txt", cli_dir);
    const char *e[32] = {JETFIT_BIN, "estimate", input, "-o", est, "--neighbors",
                         c->f[col(h, "strategy")], "--degree", c->f[col(h, "degree")],
                         "--threads", "2", "--quiet"};
    int ne = 12;
    char fl[256];
    snprintf(fl, sizeof fl, "%s", c->f[col(h, "flags")]);
    for (char *t = strtok(fl, " "); t; t = strtok(NULL, " ")) e[ne++] = t;
    e[ne] = NULL;
    ck_assert_msg(run_to(NULL, e) == 0, "estimate: %s", cli_err);
    const char *v[] = {JETFIT_BIN, "eval", est, truth, subset ? "--subset" : NULL, subset, NULL};
    ck_assert_msg(run_to(evo, v) == 0, "eval: %s", cli_err);
    char *out = jf_test_slurp(evo, NULL);
    char tn[7][32], t1[7][32], t2[7][32];
    eval_row(out, "normal_deg", tn);
    eval_row(out, "k1_rel", t1);
    eval_row(out, "k2_rel", t2);
    free(out);
    ck_assert_str_eq(c->f[col(h, "normal_n")], tn[0]);
    const char *want[7] = {tn[2], tn[4], tn[5], t1[4], t1[5], t2[4], t2[5]};
    for (int m = 0; m < 7; m++) expect_same(c->f[col(h, mname[m])], want[m], mname[m]);
}

START_TEST(study_equals_generate_estimate_eval)
{
    cli_setup();
    char dir[300]; /* not cli_path's rotating buffer: more paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    const char *nb = "knn:16;knn:24,radius:0.3", *deg = "2;3";
    const char *flags = ";--robust-normals;--scales 8,16,32";
    int rc = cli_run("study", "exp", "-o", dir, "--n", "1500", "--neighbors", nb, "--degree",
                     deg, "--flags", flags, "--noise", "0;0.004", "--outliers", "0;0.05",
                     "--repeat", "2", "--seed", "7", "--threads", "2", NULL);
    ck_assert_msg(rc == 0, "study failed (%d): %s", rc, cli_err);
    char path[600];
    snprintf(path, sizeof path, "%s/study.csv", dir);
    int nr;
    csv_row *r = read_csv(path, &nr);
    ck_assert_int_eq(nr, 1 + 2 * 2 * 3 * 2 * 2 * 2); /* header + cells */
    const csv_row *h = &r[0];
    int cn = col(h, "noise"), co = col(h, "outliers"), cseed = col(h, "seed"),
        cst = col(h, "status"), cnn = col(h, "normal_n");
    char last_draw[128] = "";
    const char *gen = cli_path("g.ply"), *truth = cli_path("t.ply");
    for (int i = 1; i < nr; i++) {
        const csv_row *c = &r[i];
        ck_assert_str_eq(c->f[cst], "ok");
        /* the draw: generate with the cell's seed, noise and outliers */
        char draw[128];
        snprintf(draw, sizeof draw, "%s %s %s", c->f[cseed], c->f[cn], c->f[co]);
        if (strcmp(draw, last_draw)) {
            const char *g[] = {JETFIT_BIN, "generate", "exp", "--n", "1500", "--seed", c->f[cseed],
                               "--noise", c->f[cn], "--outliers", c->f[co], "-o", gen,
                               "--truth", truth, NULL};
            ck_assert_msg(run_to(NULL, g) == 0, "generate: %s", cli_err);
            snprintf(last_draw, sizeof last_draw, "%s", draw);
        }
        check_cell(h, c, gen, truth, NULL);
    }
    /* the outliers' truth rows are NaN: fewer points measured */
    int with_out = 0;
    for (int i = 1; i < nr; i++)
        if (strtod(r[i].f[co], NULL) > 0) {
            ck_assert_int_eq(atoi(r[i].f[cnn]), 1500 - 75);
            with_out = 1;
        }
    ck_assert(with_out);
    free_csv(r, nr);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* neighbors auto is a strategy (issue 27): its cells are generate +
 * estimate --neighbors auto + eval, beside knn:K's */
START_TEST(study_knows_auto)
{
    cli_setup();
    char dir[300];
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    int rc = cli_run("study", "exp", "-o", dir, "--n", "1500", "--neighbors", "knn:16;auto",
                     "--noise", "0.004", "--seed", "7", "--threads", "2", NULL);
    ck_assert_msg(rc == 0, "study failed (%d): %s", rc, cli_err);
    char path[600];
    snprintf(path, sizeof path, "%s/study.csv", dir);
    int nr;
    csv_row *r = read_csv(path, &nr);
    ck_assert_int_eq(nr, 1 + 2);
    const csv_row *h = &r[0];
    int cs = col(h, "strategy"), cseed = col(h, "seed"), cn = col(h, "noise");
    ck_assert_str_eq(r[2].f[cs], "auto");
    /* auto's flag says how the points were fitted: they are ok, not flagged */
    ck_assert_msg(atoi(r[2].f[col(h, "ok")]) > 750 && atoi(r[2].f[col(h, "flagged")]) < 750,
                  "auto cell: ok %s, flagged %s", r[2].f[col(h, "ok")], r[2].f[col(h, "flagged")]);
    const char *gen = cli_path("g.ply"), *truth = cli_path("t.ply");
    const char *g[] = {JETFIT_BIN, "generate", "exp", "--n", "1500", "--seed", r[2].f[cseed],
                       "--noise", r[2].f[cn], "-o", gen, "--truth", truth, NULL};
    ck_assert_msg(run_to(NULL, g) == 0, "generate: %s", cli_err);
    for (int i = 1; i < nr; i++) check_cell(h, &r[i], gen, truth, NULL);
    free_csv(r, nr);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* INPUT --truth --subset: the same numbers as estimate + eval --subset */
START_TEST(study_of_an_input_equals_estimate_eval_subset)
{
    cli_setup();
    const char *in = cli_path("in.ply"), *truth = cli_path("t.csv"), *sub = cli_path("s.pidx");
    ck_assert_int_eq(cli_run("generate", "ellipsoid", "--n", "1200", "--noise", "0.003", "--seed",
                             "5", "-o", in, "--truth", truth, NULL), 0);
    FILE *f = fopen(sub, "w");
    for (int i = 0; i < 1200; i += 3) fprintf(f, "%d\n", i);
    fclose(f);
    char dir[300]; /* not cli_path's rotating buffer: more paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    int rc = cli_run("study", in, "--truth", truth, "--subset", sub, "-o", dir, "--neighbors",
                     "knn:12;natural:24", "--degree", "2;4", "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    char path[600];
    snprintf(path, sizeof path, "%s/study.csv", dir);
    int nr;
    csv_row *r = read_csv(path, &nr);
    ck_assert_int_eq(nr, 1 + 2 * 2);
    for (int i = 1; i < nr; i++) {
        ck_assert_str_eq(r[i].f[col(&r[0], "status")], "ok");
        ck_assert_str_eq(r[i].f[col(&r[0], "normal_n")], "400");
        check_cell(&r[0], &r[i], in, truth, sub);
    }
    free_csv(r, nr);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* SURFACE --mesh: rings on generate --mesh's grid, the same numbers */
START_TEST(mesh_study_equals_generate_mesh)
{
    cli_setup();
    char dir[300]; /* not cli_path's rotating buffer: more paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    int rc = cli_run("study", "paraboloid", "--mesh", "--n", "900", "-o", dir, "--neighbors",
                     "rings;rings:20;knn:12", "--noise", "0;0.003", "--seed", "4", "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    char path[600], gen[600], truth[600];
    snprintf(path, sizeof path, "%s/study.csv", dir);
    snprintf(gen, sizeof gen, "%s/g.ply", cli_dir);
    snprintf(truth, sizeof truth, "%s/t.ply", cli_dir);
    int nr;
    csv_row *r = read_csv(path, &nr);
    ck_assert_int_eq(nr, 1 + 3 * 2);
    for (int i = 1; i < nr; i++) {
        const char *g[] = {JETFIT_BIN, "generate", "paraboloid", "--mesh", "--n", "900", "--seed",
                           r[i].f[col(&r[0], "seed")], "--noise", r[i].f[col(&r[0], "noise")],
                           "-o", gen, "--truth", truth, NULL};
        ck_assert_msg(run_to(NULL, g) == 0, "generate: %s", cli_err);
        ck_assert_str_eq(r[i].f[col(&r[0], "status")], "ok");
        check_cell(&r[0], &r[i], gen, truth, NULL);
    }
    free_csv(r, nr);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* ---- resume after a real interruption ---- */

static int lines_in(const char *path)
{
    char *b = jf_test_slurp(path, NULL);
    int n = b ? count_str(b, "\n") : 0;
    free(b);
    return n;
}

/* Ends s at the last occurrence of sep; NULL if there is none. */
static char *strrstr_cut(char *s, const char *sep)
{
    char *last = NULL;
    for (char *p = s; (p = strstr(p, sep)); p++) last = p;
    if (last) *last = '\0';
    return last;
}

/* Same text but for the last two fields of each line (the timing). */
static void same_but_timing(const char *a_path, const char *b_path, const char *sep)
{
    char *a = jf_test_slurp(a_path, NULL), *b = jf_test_slurp(b_path, NULL);
    ck_assert(a && b);
    char *sa, *sb, *la = strtok_r(a, "\n", &sa), *lb = strtok_r(b, "\n", &sb);
    int line = 0;
    while (la && lb) {
        line++;
        if (strcmp(la, lb)) {
            /* cut both after their third-last separator */
            for (int k = 0; k < 2; k++) {
                char *x = strrstr_cut(la, sep), *y = strrstr_cut(lb, sep);
                ck_assert_msg(x && y, "%s:%d differs", b_path, line);
            }
            ck_assert_msg(!strcmp(la, lb), "%s:%d differs beyond timing:\n%s\n%s", b_path, line,
                          la, lb);
        }
        la = strtok_r(NULL, "\n", &sa);
        lb = strtok_r(NULL, "\n", &sb);
    }
    ck_assert_msg(!la && !lb, "%s and %s differ in length", a_path, b_path);
    free(a);
    free(b);
}

START_TEST(resume_after_kill_gives_the_same_files)
{
    cli_setup();
    char a[600], b[600], pa[700], pb[700];
    /* both runs write to the same DIR (the report shows the command):
     * the uninterrupted one is then moved to a/ */
    snprintf(a, sizeof a, "%s", cli_path("a"));
    snprintf(b, sizeof b, "%s", cli_path("st"));
    /* 8 cells of 20000 points, one thread: each takes a while */
    const char *argv_b[] = {JETFIT_BIN, "study", "sphere", "-o", b, "--n", "20000",
                            "--neighbors", "knn:16;knn:24;knn:32;knn:40", "--noise", "0;0.01",
                            "--threads", "1", "--seed", "3", NULL, NULL};
    ck_assert_msg(run_to(NULL, argv_b) == 0, "study: %s", cli_err);
    ck_assert_int_eq(rename(b, a), 0);
    snprintf(pb, sizeof pb, "%s/study.csv", b);
    /* interrupt for real: SIGKILL once two cells are in study.csv */
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int fo = open("/dev/null", O_WRONLY);
        dup2(fo, 1);
        dup2(fo, 2);
        execv(argv_b[0], (char *const *)argv_b);
        _exit(127);
    }
    int killed = 0, status;
    for (int t = 0; t < 120000; t++) {
        if (lines_in(pb) >= 3) {
            kill(pid, SIGKILL);
            killed = 1;
            break;
        }
        if (waitpid(pid, &status, WNOHANG) == pid) break;
        struct timespec ts = {0, 1000000};
        nanosleep(&ts, NULL);
    }
    if (killed) waitpid(pid, &status, 0);
    ck_assert_msg(killed && WIFSIGNALED(status), "the study ended before it was interrupted");
    int kept = lines_in(pb) - 1;
    ck_assert_msg(kept >= 2 && kept < 8, "%d cells before the kill", kept);
    snprintf(pa, sizeof pa, "%s/report.html", b);
    ck_assert(!cli_exists(pa)); /* the interrupted study had not finished */
    /* what a kill during a write leaves: resuming removes it */
    snprintf(pa, sizeof pa, "%s/.study.csv.Ab3dEf9hJk.tmp", b);
    cli_write_text(pa, "half a table");
    argv_b[15] = "--resume";
    ck_assert_msg(run_to(NULL, argv_b) == 0, "resume: %s", cli_err);
    ck_assert_msg(strstr(cli_err, "resuming") != NULL, "%s", cli_err);
    ck_assert(!cli_exists(pa));
    snprintf(pa, sizeof pa, "%s/study.csv", a);
    same_but_timing(pa, pb, ",");
    snprintf(pa, sizeof pa, "%s/best.csv", a);
    snprintf(pb, sizeof pb, "%s/best.csv", b);
    ck_assert_msg(jf_test_same_files(pa, pb), "best.csv differs");
    static const char *const png[] = {"normal.png", "curvature.png", "k.png"};
    for (int i = 0; i < 3; i++) {
        snprintf(pa, sizeof pa, "%s/%s", a, png[i]);
        snprintf(pb, sizeof pb, "%s/%s", b, png[i]);
        ck_assert_int_eq(cli_exists(pa), cli_exists(pb));
        if (cli_exists(pa)) ck_assert_msg(jf_test_same_files(pa, pb), "%s differs", png[i]);
    }
    snprintf(pa, sizeof pa, "%s/report.html", a);
    snprintf(pb, sizeof pb, "%s/report.html", b);
    same_but_timing(pa, pb, "<td>");
    /* Ctrl-C: the running cell is cancelled, the finished ones are kept,
     * exit 130 and one line saying how to go on; resuming completes it */
    char c[600];
    snprintf(c, sizeof c, "%s", cli_path("c"));
    argv_b[4] = c;
    argv_b[15] = NULL;
    snprintf(pb, sizeof pb, "%s/study.csv", c);
    char errpath[700];
    snprintf(errpath, sizeof errpath, "%s", cli_path("c.stderr"));
    fflush(NULL);
    pid = fork();
    if (pid == 0) {
        int fe = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644), fo = open("/dev/null", O_WRONLY);
        dup2(fo, 1);
        dup2(fe, 2);
        execv(argv_b[0], (char *const *)argv_b);
        _exit(127);
    }
    int sent = 0;
    for (int t = 0; t < 120000; t++) {
        if (lines_in(pb) >= 2) {
            kill(pid, SIGINT);
            sent = 1;
            break;
        }
        if (waitpid(pid, &status, WNOHANG) == pid) break;
        struct timespec ts = {0, 1000000};
        nanosleep(&ts, NULL);
    }
    ck_assert_msg(sent, "the study ended before it was interrupted");
    waitpid(pid, &status, 0);
    ck_assert_msg(WIFEXITED(status) && WEXITSTATUS(status) == 130, "status %d", status);
    char *said = jf_test_slurp(errpath, NULL);
    unlink(errpath);
    ck_assert_msg(said && strstr(said, "interrupted") && strstr(said, "--resume") &&
                  count_str(said, "\n") == 1, "%s", said ? said : "");
    free(said);
    kept = lines_in(pb) - 1;
    ck_assert_msg(kept >= 1 && kept < 8, "%d cells after Ctrl-C", kept);
    argv_b[15] = "--resume";
    ck_assert_msg(run_to(NULL, argv_b) == 0, "resume: %s", cli_err);
    snprintf(pa, sizeof pa, "%s/study.csv", a);
    same_but_timing(pa, pb, ",");
    snprintf(pa, sizeof pa, "%s/best.csv", a);
    snprintf(pb, sizeof pb, "%s/best.csv", c);
    ck_assert_msg(jf_test_same_files(pa, pb), "best.csv differs after Ctrl-C and --resume");
    const char *rm[] = {"/bin/rm", "-rf", c, NULL};
    run_to(NULL, rm);

    /* no temporary left in either folder */
    const char *files[] = {"study.csv", "best.csv", "report.html", "normal.png",
                           "curvature.png", "k.png", "study.def", "best.ply", "view.html"};
    for (int i = 0; i < 9; i++) {
        snprintf(pa, sizeof pa, "%s/%s", a, files[i]);
        unlink(pa);
        snprintf(pb, sizeof pb, "%s/%s", b, files[i]);
        unlink(pb);
    }
    ck_assert_msg(rmdir(a) == 0 && rmdir(b) == 0, "files left in the study folders");
    cli_teardown();
}
END_TEST

/* ---- report.html in headless Chromium ---- */

#define CHROMIUM "/usr/bin/chromium"

/* Runs headless Chromium on file://page with one more argument (what to
 * produce), a fresh profile, no network; stdout into out (or NULL). */
static int chromium_flag(const char *page, const char *what, const char *out, const char *extra);

static int chromium(const char *page, const char *what, const char *out)
{
    return chromium_flag(page, what, out, "--disable-sync");
}

/* As chromium(), with one more flag (or a repeated harmless one). */
static int chromium_flag(const char *page, const char *what, const char *out, const char *extra)
{
    char url[700], ud[600];
    snprintf(url, sizeof url, "file://%s", page);
    snprintf(ud, sizeof ud, "--user-data-dir=%s", cli_path("profile"));
    const char *argv[] = {"/usr/bin/timeout", "120", CHROMIUM, "--headless", "--no-sandbox",
                          "--disable-gpu", "--disable-quic", "--no-first-run",
                          "--disable-background-networking", "--disable-component-update",
                          "--disable-sync", extra, ud, "--window-size=1200,1600", what, url,
                          NULL};
    int rc = run_to(out, argv);
    /* the profile is a tree: remove it with the tool made for that */
    const char *rm[] = {"/bin/rm", "-rf", cli_path("profile"), NULL};
    run_to(NULL, rm);
    return rc;
}

START_TEST(report_opens_in_chromium)
{
    cli_setup();
    char dir[300]; /* not cli_path's rotating buffer: more paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    int rc = cli_run("study", "paraboloid", "-o", dir, "--n", "2000", "--neighbors",
                     "knn:12;knn:24;knn:48", "--degree", "2;3", "--noise", "0;0.002;0.005",
                     "--repeat", "2", "--threads", "2", NULL);
    ck_assert_msg(rc == 0, "study: %s", cli_err);
    char page[600], shot[600], blank[600], dom[600];
    snprintf(page, sizeof page, "%s/report.html", dir);
    snprintf(dom, sizeof dom, "%s", cli_path("dom.html"));
    ck_assert_msg(chromium(page, "--dump-dom", dom) == 0, "chromium: %s", cli_err);
    char *d = jf_test_slurp(dom, NULL);
    ck_assert(d != NULL);
    /* rows: best 3 levels x 7 metrics; summary 3 strategies x 2 degrees
     * x 3 levels; cells x 2 repeats; one heading row each */
    char *best = strstr(d, "id=\"best\""), *sum = strstr(d, "id=\"summary\""),
         *cells = strstr(d, "id=\"cells\"");
    ck_assert(best && sum && cells && best < sum && sum < cells);
    *sum = '\0';
    *cells = '\0';
    ck_assert_int_eq(count_str(best, "<tr"), 1 + 3 * 7);
    ck_assert_int_eq(count_str(sum + 1, "<tr"), 1 + 3 * 2 * 3);
    ck_assert_int_eq(count_str(cells + 1, "<tr"), 1 + 3 * 2 * 3 * 2);
    int have_gnuplot = system("command -v gnuplot >/dev/null 2>&1") == 0;
    ck_assert_int_eq(count_str(d, "<img"), have_gnuplot ? 3 : 0);
    ck_assert_int_eq(count_str(d, "src=\"data:image/png;base64,"), have_gnuplot ? 3 : 0);
    ck_assert_msg(strstr(d, "http://") == NULL && strstr(d, "https://") == NULL,
                  "the page refers to the network");
    free(d);
    /* sorting: a page frames the report, clicks the normal_median heading
     * twice and copies the column out (file:// frames need
     * --allow-file-access-from-files to be read by their parent) */
    const char *wrap = cli_path("sort.html");
    cli_write_text(wrap,
        "<!DOCTYPE html><html><body><pre id=\"out\"></pre>\n"
        "<iframe id=\"f\" src=\"st/report.html\" onload=\"go()\"></iframe><script>\n"
        "function column(d, c) { return Array.prototype.map.call(\n"
        "  d.querySelectorAll('#cells tbody tr'), function (r) { return r.cells[c].textContent; }).join(' '); }\n"
        "function go() {\n"
        "  var d = document.getElementById('f').contentDocument;\n"
        "  var hs = d.querySelectorAll('#cells thead th'), c = -1;\n"
        "  for (var i = 0; i < hs.length; i++) if (hs[i].textContent === 'normal_median') c = i;\n"
        "  hs[c].click(); var up = column(d, c); hs[c].click(); var down = column(d, c);\n"
        "  document.getElementById('out').textContent = '\\nASC ' + up + '\\nDESC ' + down + '\\n';\n"
        "}\n</script></body></html>\n");
    ck_assert_msg(chromium_flag(wrap, "--dump-dom", dom, "--allow-file-access-from-files") == 0,
                  "chromium: %s", cli_err);
    d = jf_test_slurp(dom, NULL);
    char *asc = strstr(d, "\nASC "), *desc = strstr(d, "\nDESC ");
    ck_assert_msg(asc && desc, "the sorting page did not run");
    for (int pass = 0; pass < 2; pass++) {
        char *p = (pass ? desc : asc) + (pass ? 6 : 5), *end;
        double prev = pass ? INFINITY : -INFINITY;
        int n = 0;
        for (;;) {
            double v = strtod(p, &end);
            if (end == p) break;
            ck_assert_msg(pass ? v <= prev : v >= prev, "not sorted at %g after %g", v, prev);
            prev = v;
            p = end;
            n++;
        }
        ck_assert_int_eq(n, 3 * 2 * 3 * 2);
    }
    free(d);
    /* in a 1280-pixel window the page never scrolls sideways (issue 31):
     * wide tables scroll inside their own box */
    cli_write_text(wrap,
        "<!DOCTYPE html><html><body style=\"margin:0\"><pre id=\"out\"></pre>\n"
        "<iframe id=\"f\" src=\"st/report.html\" style=\"width:1280px;height:800px;border:0\" onload=\"go()\"></iframe><script>\n"
        "function go() {\n"
        "  var d = document.getElementById('f').contentDocument.documentElement;\n"
        "  document.getElementById('out').textContent = '\\nWIDTH ' + d.scrollWidth + ' ' + d.clientWidth + '\\n';\n"
        "}\n</script></body></html>\n");
    ck_assert_msg(chromium_flag(wrap, "--dump-dom", dom, "--allow-file-access-from-files") == 0,
                  "chromium: %s", cli_err);
    d = jf_test_slurp(dom, NULL);
    char *wd = d ? strstr(d, "\nWIDTH ") : NULL;
    ck_assert_msg(wd != NULL, "the width page did not run");
    long sw = 0, cw = 0;
    ck_assert_int_eq(sscanf(wd, "\nWIDTH %ld %ld", &sw, &cw), 2);
    ck_assert_msg(cw > 1000 && sw <= cw, "the report is %ld pixels wide in a %ld-pixel window", sw, cw);
    free(d);
    /* a screenshot of the page, beside one of an empty page of the same
     * size: plots and tables make a much larger PNG than white */
    const char *empty = cli_path("empty.html");
    cli_write_text(empty, "<!DOCTYPE html><html><body></body></html>\n");
    snprintf(shot, sizeof shot, "--screenshot=%s", cli_path("shot.png"));
    snprintf(blank, sizeof blank, "--screenshot=%s", cli_path("blank.png"));
    ck_assert_msg(chromium(page, shot, NULL) == 0, "chromium: %s", cli_err);
    ck_assert_msg(chromium(empty, blank, NULL) == 0, "chromium: %s", cli_err);
    size_t ls = 0, lb = 0;
    char *s = jf_test_slurp(cli_path("shot.png"), &ls), *b = jf_test_slurp(cli_path("blank.png"), &lb);
    ck_assert_msg(s && ls > 8 && !memcmp(s, "\x89PNG", 4), "no PNG screenshot");
    ck_assert_msg(b && lb > 8, "no blank screenshot");
    ck_assert_msg(ls > 10 * lb, "screenshot %zu bytes, a blank page %zu", ls, lb);
    free(s);
    free(b);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* issue 31: a natural cell's points carry their normal's source
 * (JF_PT_NORMAL_PCA...), which is not a problem: they count as ok */
START_TEST(natural_points_count_as_ok)
{
    cli_setup();
    char dir[300];
    snprintf(dir, sizeof dir, "%s/nat", cli_dir);
    int rc = cli_run("study", "sphere", "-o", dir, "--n", "300", "--neighbors", "natural;knn:16",
                     "--quiet", NULL);
    ck_assert_msg(rc == 0, "study: %s", cli_err);
    char csv[400];
    snprintf(csv, sizeof csv, "%s/study.csv", dir);
    int nr = 0;
    csv_row *r = read_csv(csv, &nr);
    ck_assert_int_eq(nr, 3);
    int cs = col(&r[0], "strategy"), co = col(&r[0], "ok"), cf = col(&r[0], "flagged");
    for (int i = 1; i < nr; i++) {
        ck_assert_msg(!strcmp(r[i].f[co], "300"), "%s: ok = %s", r[i].f[cs], r[i].f[co]);
        ck_assert_str_eq(r[i].f[cf], "0");
    }
    free_csv(r, nr);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* ---- bad input, failing cells ---- */

START_TEST(bad_input_one_line_no_folder)
{
    cli_setup();
    char dir[300]; /* not cli_path's rotating buffer: many paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    struct {
        const char *args[8];
        int rc;
        const char *says;
    } cases[] = {
        {{"--neighbors", "knn:16;knm:3"}, 2, "knm:3"},
        {{"--degree", "2;12"}, 2, "--degree"},
        {{"--metrics", "normal_median,k3_p95"}, 2, "unknown metric 'k3_p95'"},
        {{"--flags", ";--robust nope"}, 2, "--robust 'nope'"},
        {{"--flags", "--degree 3"}, 2, "the study's own options"},
        {{"--flags", "--bogus"}, 2, "not an estimate option"},
        {{"--noise", "0;-1"}, 2, "--noise"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int rc = cli_run("study", "exp", "-o", dir, "--n", "500", cases[k].args[0],
                         cases[k].args[1], NULL);
        ck_assert_int_eq(rc, cases[k].rc);
        ck_assert_msg(strstr(cli_err, cases[k].says) != NULL, "%s", cli_err);
        ck_assert_int_eq(count_str(cli_err, "\n"), 1);
        ck_assert(!cli_exists(dir));
    }
    /* truth with another row count */
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "400", "-o", cli_path("c.ply"), NULL), 0);
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "399", "-o", cli_path("x.ply"), "--truth",
                             cli_path("t.csv"), NULL), 0);
    int rc = cli_run("study", cli_path("c.ply"), "--truth", cli_path("t.csv"), "-o", dir, NULL);
    ck_assert_int_eq(rc, 1);
    ck_assert_msg(strstr(cli_err, "399 rows") && strstr(cli_err, "400 points"), "%s", cli_err);
    ck_assert_int_eq(count_str(cli_err, "\n"), 1);
    ck_assert(!cli_exists(dir));
    /* a truth of another cloud with as many rows (eval's check) */
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "400", "--seed", "2", "-o",
                             cli_path("y.ply"), "--truth", cli_path("t2.csv"), NULL), 0);
    rc = cli_run("study", cli_path("c.ply"), "--truth", cli_path("t2.csv"), "-o", dir, NULL);
    ck_assert_int_eq(rc, 1);
    ck_assert_msg(strstr(cli_err, "not the same cloud"), "%s", cli_err);
    ck_assert_int_eq(count_str(cli_err, "\n"), 1);
    ck_assert(!cli_exists(dir));
    /* neither a surface nor an input with truth */
    ck_assert_int_eq(cli_run("study", "klein", "-o", dir, NULL), 2);
    ck_assert(!cli_exists(dir));
    cli_teardown();
}
END_TEST

/* ---- a resume is the study its command line describes (issue 32.3, 32.4) ---- */

/* Replaces field `col` (0-based) of line `line` (1-based) of path with val. */
static void plant(const char *path, int line, int col, const char *val)
{
    size_t len;
    char *t = jf_test_slurp(path, &len), out[65536];
    ck_assert(t && len < sizeof out - 64);
    size_t u = 0;
    int ln = 1, c = 0;
    for (size_t i = 0; i < len; i++) {
        if (ln == line && c == col) {
            u += (size_t)snprintf(out + u, sizeof out - u, "%s", val);
            while (i < len && t[i] != ',' && t[i] != '\n') i++;
            c++;
        }
        if (i < len) out[u++] = t[i];
        if (i < len && t[i] == '\n') ln++, c = 0;
        else if (i < len && t[i] == ',' && ln == line) c++;
    }
    free(t);
    FILE *f = fopen(path, "wb");
    ck_assert(f && fwrite(out, 1, u, f) == u);
    fclose(f);
}

START_TEST(resume_refuses_another_study)
{
    cli_setup();
    char dir[300], csv[340], copy[340];
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    snprintf(csv, sizeof csv, "%s/study.csv", dir);
    snprintf(copy, sizeof copy, "%s/kept.csv", cli_dir);
#define STUDY(surf, ...) cli_run("study", surf, "-o", dir, "--neighbors", "knn:12;knn:16", \
                                 "--quiet", __VA_ARGS__, NULL)
    ck_assert_msg(STUDY("ellipsoid", "--n", "400") == 0, "%s", cli_err);
    size_t clen;
    char *ctext = jf_test_slurp(csv, &clen);
    FILE *cf = fopen(copy, "wb");
    ck_assert(ctext && cf && fwrite(ctext, 1, clen, cf) == clen);
    fclose(cf);
    free(ctext);
    struct {
        const char *surf, *a, *b, *says;
    } cases[] = {
        {"sphere", "--n", "400", "surface was 'ellipsoid', is now 'sphere'"},
        {"ellipsoid", "--n", "500", "n was '400', is now '500'"},
        {"ellipsoid", "--robust", "huber", "options was '(none)', is now '--robust=huber'"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int rc = cases[k].a[2] == 'n' ? STUDY(cases[k].surf, cases[k].a, cases[k].b, "--resume")
                                     : STUDY(cases[k].surf, "--n", "400", cases[k].a, cases[k].b,
                                             "--resume");
        ck_assert_msg(rc == 1, "case %zu: exit %d: %s", k, rc, cli_err);
        ck_assert_msg(strstr(cli_err, cases[k].says), "case %zu: %s", k, cli_err);
        ck_assert_int_eq(count_str(cli_err, "\n"), 1);
        ck_assert_msg(jf_test_same_files(csv, copy), "case %zu: study.csv changed", k);
    }
    /* the same study resumes; --threads does not define it */
    ck_assert_msg(STUDY("ellipsoid", "--n", "400", "--threads", "2", "--resume") == 0, "%s",
                  cli_err);
    /* two input files of the same size: the content hash tells them apart */
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "300", "-o", cli_path("a.ply"),
                             "--truth", cli_path("ta.csv"), NULL), 0);
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "300", "--seed", "5", "-o",
                             cli_path("b.ply"), "--truth", cli_path("tb.csv"), NULL), 0);
    char a[300], ta[300], b[300], tb[300];
    snprintf(a, sizeof a, "%s", cli_path("a.ply"));
    snprintf(ta, sizeof ta, "%s", cli_path("ta.csv"));
    snprintf(b, sizeof b, "%s", cli_path("b.ply"));
    snprintf(tb, sizeof tb, "%s", cli_path("tb.csv"));
    ck_assert_msg(cli_run("study", a, "--truth", ta, "-o", dir, "--quiet", NULL) == 0, "%s",
                  cli_err);
    ck_assert_int_eq(cli_run("study", b, "--truth", tb, "-o", dir, "--quiet", "--resume", NULL),
                     1);
    ck_assert_msg(strstr(cli_err, "input was '") && strstr(cli_err, "fnv1a64"), "%s", cli_err);
    ck_assert_int_eq(count_str(cli_err, "\n"), 1);
#undef STUDY
    cli_teardown();
}
END_TEST

START_TEST(resume_refuses_values_jetfit_did_not_write)
{
    cli_setup();
    char dir[300], csv[340];
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    snprintf(csv, sizeof csv, "%s/study.csv", dir);
    const char *const planted[][2] = {{"nan", "column 11 (normal_rms): 'nan' is not finite"},
                                      {"abc", "column 11 (normal_rms): 'abc' is not a number"}};
    for (int k = 0; k < 2; k++) {
        ck_assert_msg(cli_run("study", "sphere", "-o", dir, "--n", "400", "--repeat", "2",
                              "--quiet", NULL) == 0, "%s", cli_err);
        plant(csv, 3, 10, planted[k][0]); /* row 2's normal_rms */
        int rc = cli_run("study", "sphere", "-o", dir, "--n", "400", "--repeat", "2", "--quiet",
                         "--resume", NULL);
        ck_assert_msg(rc == 1, "%s: exit %d: %s", planted[k][0], rc, cli_err);
        ck_assert_msg(strstr(cli_err, "study.csv:3: ") && strstr(cli_err, planted[k][1]), "%s",
                      cli_err);
        ck_assert_int_eq(count_str(cli_err, "\n"), 1);
    }
    /* a count that is not whole */
    plant(csv, 2, 8, "12.5");
    ck_assert_int_eq(cli_run("study", "sphere", "-o", dir, "--n", "400", "--repeat", "2",
                             "--quiet", "--resume", NULL), 1);
    ck_assert_msg(strstr(cli_err, "column 9 (points): '12.5' is not a count"), "%s", cli_err);
    cli_teardown();
}
END_TEST

START_TEST(failing_cell_recorded_study_goes_on)
{
    cli_setup();
    char dir[300]; /* not cli_path's rotating buffer: more paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    /* rings needs a mesh: a cloud makes that cell fail, knn goes on */
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "800", "-o", cli_path("s.ply"),
                             "--truth", cli_path("t.ply"), NULL), 0);
    int rc = cli_run("study", cli_path("s.ply"), "--truth", cli_path("t.ply"), "-o", dir,
                     "--neighbors", "rings;knn:16", "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    ck_assert_msg(strstr(cli_err, "rings") && strstr(cli_err, "failed"), "%s", cli_err);
    ck_assert_int_eq(count_str(cli_err, "\n"), 1);
    char path[600];
    snprintf(path, sizeof path, "%s/study.csv", dir);
    int nr;
    csv_row *r = read_csv(path, &nr);
    ck_assert_int_eq(nr, 3);
    int cst = col(&r[0], "status"), cm = col(&r[0], "normal_median");
    ck_assert_str_eq(r[1].f[0], "rings");
    ck_assert_msg(!strncmp(r[1].f[cst], "failed: ", 8), "%s", r[1].f[cst]);
    ck_assert_str_eq(r[1].f[cm], "nan");
    ck_assert_str_eq(r[2].f[0], "knn:16");
    ck_assert_str_eq(r[2].f[cst], "ok");
    /* a sphere of radius 1, clean: knn:16 normals within a degree */
    ck_assert(strtod(r[2].f[cm], NULL) < 1.0);
    free_csv(r, nr);
    snprintf(path, sizeof path, "%s/best.csv", dir);
    char *b = jf_test_slurp(path, NULL);
    ck_assert(b && strstr(b, ",knn:16,") && !strstr(b, ",rings,"));
    free(b);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

START_TEST(one_progress_line_with_eta)
{
    cli_setup();
    char dir[300]; /* not cli_path's rotating buffer: more paths follow */
    snprintf(dir, sizeof dir, "%s/st", cli_dir);
    int rc = cli_run_tty("study", "exp", "-o", dir, "--n", "3000", "--neighbors",
                         "knn:16;knn:32", "--noise", "0;0.01", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    /* redrawn in place (\r) for the whole study, then the summary */
    ck_assert_msg(strstr(cli_err, "ETA") && strstr(cli_err, "cell 4/4") &&
                  strstr(cli_err, "100.0%") && strstr(cli_err, "4 cells (4 run, 0 failed)"),
                  "%s", cli_err);
    ck_assert_int_eq(count_str(cli_err, "\n"), 2);
    ck_assert_int_ge(count_str(cli_err, "\r"), 4 + 2);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

/* A folder name with quotes, a backquote command and HTML: gnuplot gets it
 * single-quoted (no command runs), the page escapes it. */
START_TEST(user_text_stays_text)
{
    cli_setup();
    char dir[600];
    snprintf(dir, sizeof dir, "%s/it's \"`touch jf_study_pwned`\" <b>", cli_dir);
    unlink("jf_study_pwned");
    int rc = cli_run("study", "exp", "-o", dir, "--n", "600", "--neighbors", "knn:12;knn:24",
                     "--noise", "0;0.01", "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    ck_assert_msg(access("jf_study_pwned", F_OK) != 0, "gnuplot ran the backquoted command");
    unlink("jf_study_pwned");
    char path[800];
    int have_gnuplot = system("command -v gnuplot >/dev/null 2>&1") == 0;
    snprintf(path, sizeof path, "%s/k.png", dir);
    ck_assert_int_eq(cli_exists(path), have_gnuplot);
    snprintf(path, sizeof path, "%s/report.html", dir);
    char *html = jf_test_slurp(path, NULL);
    ck_assert(html != NULL);
    ck_assert_msg(!strstr(html, "<b>") && strstr(html, "&quot;`touch jf_study_pwned`&quot; &lt;b&gt;") &&
                      strstr(html, "it&#39;"),
                  "the folder name is not escaped in the page");
    free(html);
    const char *rm[] = {"/bin/rm", "-rf", dir, NULL};
    run_to(NULL, rm);
    cli_teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_study");
    TCase *t = tcase_create("study");
    tcase_set_timeout(t, 600);
    tcase_add_test(t, study_equals_generate_estimate_eval);
    tcase_add_test(t, study_knows_auto);
    tcase_add_test(t, study_of_an_input_equals_estimate_eval_subset);
    tcase_add_test(t, mesh_study_equals_generate_mesh);
    tcase_add_test(t, resume_after_kill_gives_the_same_files);
    tcase_add_test(t, natural_points_count_as_ok);
    tcase_add_test(t, bad_input_one_line_no_folder);
    tcase_add_test(t, failing_cell_recorded_study_goes_on);
    tcase_add_test(t, resume_refuses_another_study);
    tcase_add_test(t, resume_refuses_values_jetfit_did_not_write);
    tcase_add_test(t, one_progress_line_with_eta);
    tcase_add_test(t, user_text_stays_text);
    suite_add_tcase(s, t);
    TCase *c = tcase_create("chromium"); /* its own ctest: test_cli_study_chromium */
    tcase_set_timeout(c, 600);
    tcase_set_tags(c, "chromium");
    tcase_add_test(c, report_opens_in_chromium);
    suite_add_tcase(s, c);
    return jf_test_run_tool(s, "chromium", access(CHROMIUM, X_OK) == 0,
                            CHROMIUM " is not installed (Debian package chromium)");
}
