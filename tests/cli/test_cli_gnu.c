/* test_cli_gnu.c -- every command takes GNU command lines (issue 31):
 * -oFILE, --opt=V, unique abbreviations (ambiguous ones refused naming the
 * candidates), '--', flag clusters, '-' as standard input and '-o -' as
 * standard output with --input-format/--output-format.  Each spelling is
 * checked against the plain one byte for byte. */
#include <check.h>

#include <signal.h>

#include "jf_test.h"
#include "test_cli_util.h"

static void sphere_file(const char *name, size_t n)
{
    double *xyz = malloc(3 * n * sizeof *xyz);
    const double c[3] = {0.5, -1, 2};
    cli_sphere(n, 1.5, c, xyz);
    cli_write_xyz(cli_path(name), xyz, NULL, n);
    free(xyz);
}

START_TEST(attached_and_equals_values)
{
    cli_setup();
    sphere_file("s.xyz", 600);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("ref.csv"), "--degree",
                             "3", "--neighbors", "knn:20", "--quiet", NULL), 0);
    char oarg[600];
    snprintf(oarg, sizeof oarg, "-o%s", cli_path("a.csv"));
    ck_assert_int_eq(cli_run("estimate", oarg, "--degree=3", "--neighbors=knn:20", "-q",
                             cli_path("s.xyz"), NULL), 0);
    ck_assert(jf_test_same_files(cli_path("ref.csv"), cli_path("a.csv")));
    char long_eq[600];
    snprintf(long_eq, sizeof long_eq, "--output=%s", cli_path("b.csv"));
    /* unique abbreviations: --neighb (neighbors/neighbours: one option), --qu */
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), long_eq, "--degree", "3", "--neighb",
                             "knn:20", "--qu", NULL), 0);
    ck_assert(jf_test_same_files(cli_path("ref.csv"), cli_path("b.csv")));
    ck_assert_str_eq(cli_err, ""); /* --qu is --quiet */
    /* a cluster: -q and -o with its value attached */
    char qo[600];
    snprintf(qo, sizeof qo, "-qo%s", cli_path("c.csv"));
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), qo, "--degree", "3", "--neighbors",
                             "knn:20", NULL), 0);
    ck_assert(jf_test_same_files(cli_path("ref.csv"), cli_path("c.csv")));
    ck_assert_str_eq(cli_err, "");
    cli_teardown();
}
END_TEST

START_TEST(ambiguous_and_unknown)
{
    cli_setup();
    sphere_file("s.xyz", 100);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("x.csv"), "--deg", "3",
                             NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "'--deg' is ambiguous"));
    ck_assert_ptr_nonnull(strstr(cli_err, "'--degree'"));
    ck_assert_ptr_nonnull(strstr(cli_err, "'--degree-select'"));
    ck_assert(!cli_exists(cli_path("x.csv")));
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("x.csv"), "--robust-normals=1",
                             NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "takes no value"));
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-x", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "unknown option '-x'"));
    /* every command scans the same way */
    ck_assert_int_eq(cli_run("render", "--dir", "--bogus", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "unknown option '--bogus'"));
    ck_assert_int_eq(cli_run("study", "sphere", "-o", cli_path("st"), "--no", "0", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "'--noise'"));
    ck_assert_ptr_nonnull(strstr(cli_err, "'--noise-uniform'"));
    ck_assert_int_eq(cli_run("eval", "--sub", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "'--subset' needs a value"));
    /* convergence: -o DIR (its --out kept as an alias) reaches --seed's check */
    ck_assert_int_eq(cli_run("convergence", "-o", cli_path("cv"), "--seed", "x", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "--seed wants"));
    ck_assert_int_eq(cli_run("convergence", "--out", cli_path("cv"), "--seed=y", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "--seed wants"));
    cli_teardown();
}
END_TEST

START_TEST(double_dash_ends_options)
{
    cli_setup();
    sphere_file("s.xyz", 300);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-q", "-o", cli_path("ref.ply"), NULL), 0);
    /* a file whose name starts with '-': after "--" it is INPUT */
    char cwd[512];
    ck_assert_ptr_nonnull(getcwd(cwd, sizeof cwd));
    ck_assert_int_eq(chdir(cli_dir), 0);
    ck_assert_int_eq(rename("s.xyz", "-s.xyz"), 0);
    ck_assert_int_eq(cli_run("estimate", "-q", "-o", "dash.ply", "--", "-s.xyz", NULL), 0);
    ck_assert(jf_test_same_files("ref.ply", "dash.ply"));
    ck_assert_int_eq(cli_run("estimate", "-q", "-o", "x.ply", "-s.xyz", NULL), 2);
    ck_assert_int_eq(chdir(cwd), 0);
    cli_teardown();
}
END_TEST

START_TEST(standard_input_and_output)
{
    cli_setup();
    sphere_file("s.xyz", 500);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-q", "-o", cli_path("ref.csv"), NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-q", "-o", cli_path("ref.ply"), NULL), 0);
    /* a pipe in: '-' with --input-format */
    ck_assert_int_eq(cli_run_io(cli_path("s.xyz"), cli_path("stdout"), NULL, "estimate", "-",
                                "--input-format", "xyz", "-q", "-o", cli_path("in.csv"), NULL),
                     0);
    ck_assert(jf_test_same_files(cli_path("ref.csv"), cli_path("in.csv")));
    /* a pipe out: '-o -' with --output-format, binary too */
    ck_assert_int_eq(cli_run_io(NULL, cli_path("out.csv"), NULL, "estimate", cli_path("s.xyz"),
                                "-q", "-o", "-", "--output-format", "csv", NULL),
                     0);
    ck_assert(jf_test_same_files(cli_path("ref.csv"), cli_path("out.csv")));
    ck_assert_int_eq(cli_run_io(cli_path("s.xyz"), cli_path("out.ply"), NULL, "estimate", "-", "-q",
                                "--input-format=xyz", "-o", "-", "--output-format=ply", NULL),
                     0);
    ck_assert(jf_test_same_files(cli_path("ref.ply"), cli_path("out.ply")));
    /* a summary goes to stderr, never into the data on stdout */
    ck_assert_int_eq(cli_run_io(NULL, cli_path("out2.csv"), NULL, "estimate", cli_path("s.xyz"),
                                "-o", "-", "--output-format", "csv", NULL),
                     0);
    ck_assert(jf_test_same_files(cli_path("ref.csv"), cli_path("out2.csv")));
    ck_assert_ptr_nonnull(strstr(cli_err, "points in"));
    /* standard input needs its format; a bad row is named on it */
    ck_assert_int_eq(cli_run_io(cli_path("s.xyz"), cli_path("o"), NULL, "estimate", "-", "-o",
                                cli_path("x.csv"), NULL),
                     1);
    ck_assert_ptr_nonnull(strstr(cli_err, "--input-format"));
    cli_write_text(cli_path("bad.xyz"), "0 0 0\n1 0 0\n0 1\n");
    ck_assert_int_eq(cli_run_io(cli_path("bad.xyz"), cli_path("o"), NULL, "estimate", "-",
                                "--input-format", "xyz", "-o", cli_path("x.csv"), NULL),
                     1);
    ck_assert_ptr_nonnull(strstr(cli_err, "jetfit: (standard input):3:"));
    ck_assert(!cli_exists(cli_path("x.csv")));
    /* generate to a pipe: the bytes of its file */
    ck_assert_int_eq(cli_run("generate", "torus", "--n", "300", "-o", cli_path("g.xyz"), NULL), 0);
    ck_assert_int_eq(cli_run_io(NULL, cli_path("g.out"), NULL, "generate", "torus", "--n=300",
                                "-o-", "--output-format", "xyz", NULL),
                     0);
    ck_assert(jf_test_same_files(cli_path("g.xyz"), cli_path("g.out")));
    cli_teardown();
}
END_TEST

START_TEST(formats_named_on_the_command_line)
{
    cli_setup();
    sphere_file("s.xyz", 400);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-q", "-o", cli_path("ref.ply"), NULL), 0);
    ck_assert_int_eq(rename(cli_path("s.xyz"), cli_path("cloud.dat")), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("cloud.dat"), "-q", "-o", cli_path("r.dat"), NULL), 1);
    ck_assert_int_eq(cli_run("estimate", cli_path("cloud.dat"), "--input-format", "xyz", "-q", "-o",
                             cli_path("r.dat"), "--output-format", "ply", NULL), 0);
    ck_assert(jf_test_same_files(cli_path("ref.ply"), cli_path("r.dat")));
    /* nothing left beside: cloud.dat ref.ply r.dat */
    ck_assert_int_eq(cli_count_files(), 3);
    ck_assert_int_eq(cli_run("estimate", cli_path("cloud.dat"), "--input-format", "e57x", "-o",
                             cli_path("y.csv"), NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "--input-format 'e57x'"));
    cli_teardown();
}
END_TEST

/* A reader that stops early (head): jetfit dies of SIGPIPE mid-copy and
 * leaves nothing in $TMPDIR; eval and render read standard input too. */
START_TEST(closed_pipe_leaves_nothing)
{
    cli_setup();
    sphere_file("s.xyz", 3000);
    ck_assert_int_eq(mkdir(cli_path("tmpd"), 0700), 0);
    char tmpd[600];
    snprintf(tmpd, sizeof tmpd, "%s", cli_path("tmpd"));
    int pfd[2];
    ck_assert_int_eq(pipe(pfd), 0);
    close(pfd[0]); /* no reader at all */
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        setenv("TMPDIR", tmpd, 1);
        signal(SIGPIPE, SIG_DFL);
        dup2(pfd[1], 1);
        int fe = open("/dev/null", O_WRONLY);
        dup2(fe, 2);
        execl(JETFIT_BIN, JETFIT_BIN, "estimate", cli_path("s.xyz"), "-q", "-o", "-",
              "--output-format", "csv", (char *)NULL);
        _exit(127);
    }
    close(pfd[1]);
    int status = 0;
    waitpid(pid, &status, 0);
    /* 141 = 128 + SIGPIPE: the handler removed the temporaries and said which signal */
    ck_assert_msg(WIFEXITED(status) &&
                      (WEXITSTATUS(status) == 128 + SIGPIPE || WEXITSTATUS(status) == 1),
                  "status %d", status);
    DIR *d = opendir(tmpd);
    struct dirent *e;
    int left = 0;
    while (d && (e = readdir(d)))
        left += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d) closedir(d);
    ck_assert_int_eq(left, 0);
    rmdir(tmpd);
    /* eval reads its RESULT from a pipe: the same table as from the file */
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-q", "-o", cli_path("r.csv"), NULL), 0);
    ck_assert_int_eq(cli_run_io(NULL, cli_path("e1.txt"), NULL, "eval", cli_path("r.csv"),
                                cli_path("r.csv"), NULL),
                     0);
    ck_assert_int_eq(cli_run_io(cli_path("r.csv"), cli_path("e2.txt"), NULL, "eval", "-",
                                cli_path("r.csv"), "--input-format", "csv", NULL),
                     0);
    /* the first line names the inputs; the table after it must agree */
    FILE *a = fopen(cli_path("e1.txt"), "r"), *b = fopen(cli_path("e2.txt"), "r");
    char la[512], lb[512];
    ck_assert(a && b && fgets(la, sizeof la, a) && fgets(lb, sizeof lb, b));
    int rows = 0;
    while (fgets(la, sizeof la, a)) {
        ck_assert(fgets(lb, sizeof lb, b) != NULL);
        ck_assert_str_eq(la, lb);
        rows++;
    }
    ck_assert_int_ge(rows, 2);
    fclose(a);
    fclose(b);
    cli_teardown();
}
END_TEST

START_TEST(help_lists_short_options)
{
    cli_setup();
    ck_assert_int_eq(cli_run_io(NULL, cli_path("h.txt"), NULL, "estimate", "--help", NULL), 0);
    FILE *f = fopen(cli_path("h.txt"), "r");
    char buf[16384];
    size_t m = fread(buf, 1, sizeof buf - 1, f);
    buf[m] = '\0';
    fclose(f);
    ck_assert_ptr_nonnull(strstr(buf, "-q, --quiet"));
    ck_assert_ptr_nonnull(strstr(buf, "--input-format"));
    ck_assert_ptr_nonnull(strstr(buf, "--output-format"));
    cli_teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_gnu");
    TCase *t = tcase_create("gnu");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, attached_and_equals_values);
    tcase_add_test(t, ambiguous_and_unknown);
    tcase_add_test(t, double_dash_ends_options);
    tcase_add_test(t, standard_input_and_output);
    tcase_add_test(t, formats_named_on_the_command_line);
    tcase_add_test(t, closed_pipe_leaves_nothing);
    tcase_add_test(t, help_lists_short_options);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
