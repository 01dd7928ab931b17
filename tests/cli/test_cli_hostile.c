/* test_cli_hostile.c -- issue 11, items 1-7: the command against a hostile
 * user.  Each test fails on the code before the fix (said per test). */
#define _GNU_SOURCE
#include <check.h>
#include <pthread.h>
#include <signal.h>
#include <time.h>

#include "test_cli_util.h"
#include "jf_test.h"

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

static size_t file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (size_t)sb.st_size : (size_t)-1;
}

/* Temporaries ("." NAME "." ... ".tmp") left in cli_dir. */
static int temporaries(void)
{
    int n = 0;
    DIR *d = opendir(cli_dir);
    for (struct dirent *e; d && (e = readdir(d));)
        if (e->d_name[0] == '.' && strstr(e->d_name, ".tmp")) n++;
    if (d) closedir(d);
    return n;
}

static const char *sphere(size_t n)
{
    char nb[32];
    snprintf(nb, sizeof nb, "%zu", n);
    const char *p = cli_path("sphere.ply");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", nb, "-o", p, NULL), 0);
    return p;
}

/* 1. Backquotes in a file name or title used to run inside gnuplot's
 * double-quoted strings (before: PWNED created by each of the three). */
START_TEST(render_no_injection)
{
    /* gnuplot runs in our folder: chdir there so that the backquoted
     * command, if run, makes cli_dir/PWNED */
    char cwd[4096];
    ck_assert_ptr_nonnull(getcwd(cwd, sizeof cwd));
    ck_assert_int_eq(chdir(cli_dir), 0);
    const char *name = "a`touch PWNED`b.xyz", *out = "x`touch PWNED`.png";
    write_file(name, "# x y z k1 k2\n0 0 0 1 1\n1 0 0 1 2\n0 1 0 2 1\n1 1 1 3 1\n");
    int r1 = cli_run("render", name, "-o", "o.png", NULL);
    int r2 = cli_run("render", name, "-o", "t.png", "--title", "`touch PWNED` it's \"q\" \\", NULL);
    int r3 = cli_run("render", name, "-o", out, NULL);
    int pwned = cli_exists("PWNED"), big = file_size(out) > 100;
    ck_assert_int_eq(chdir(cwd), 0);
    ck_assert_int_eq(r1, 0);
    ck_assert_int_eq(r2, 0);
    ck_assert_int_eq(r3, 0);
    ck_assert_msg(!pwned, "a command ran through gnuplot");
    ck_assert(big);
    ck_assert_int_eq(temporaries(), 0);
}
END_TEST

/* 2. A link planted at the temporary's name (before: the predictable
 * ".out.xyz.tmp.PID", opened without O_EXCL, wrote through to the victim). */
START_TEST(planted_link_not_followed)
{
    const char *in = sphere(500);
    const char *victim = cli_path("victim.txt");
    write_file(victim, "precious\n");
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        char link[600];
        snprintf(link, sizeof link, "%s/.out.xyz.tmp.%ld", cli_dir, (long)getpid());
        if (symlink(victim, link) != 0) _exit(125);
        int fo = open("/dev/null", O_WRONLY);
        dup2(fo, 1), dup2(fo, 2);
        execl(JETFIT_BIN, JETFIT_BIN, "estimate", in, "-o", cli_path("out.xyz"), (char *)NULL);
        _exit(127);
    }
    int st;
    waitpid(pid, &st, 0);
    ck_assert(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    size_t n;
    char *v = jf_test_slurp(victim, &n);
    ck_assert_str_eq(v, "precious\n");
    free(v);
    ck_assert(file_size(cli_path("out.xyz")) > 1000);
}
END_TEST

/* 2. Long names, permissions kept, symlinked output written through
 * (before: a 250-byte name failed on its longer temporary; a replaced
 * 0640 file became 0644; the link was replaced by a plain file). */
START_TEST(output_file_rules)
{
    const char *in = sphere(300);
    char base[251];
    memset(base, 'n', 246);
    memcpy(base + 246, ".xyz", 5);
    ck_assert_int_eq(cli_run("estimate", in, "-o", cli_path(base), "--quiet", NULL), 0);
    ck_assert(file_size(cli_path(base)) > 1000);

    const char *out = cli_path("mode.xyz");
    write_file(out, "old\n");
    chmod(out, 0640);
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--quiet", NULL), 0);
    struct stat sb;
    ck_assert_int_eq(stat(out, &sb), 0);
    ck_assert_uint_eq(sb.st_mode & 07777, 0640);
    ck_assert(sb.st_size > 1000);

    const char *target = cli_path("target.xyz"), *link = cli_path("link.xyz");
    write_file(target, "old\n");
    ck_assert_int_eq(symlink("target.xyz", link), 0);
    ck_assert_int_eq(cli_run("estimate", in, "-o", link, "--quiet", NULL), 0);
    ck_assert_int_eq(lstat(link, &sb), 0);
    ck_assert(S_ISLNK(sb.st_mode));
    ck_assert(file_size(target) > 1000);
    ck_assert_int_eq(temporaries(), 0);
}
END_TEST

/* 3. A file that shrinks while it is read is an error, never SIGBUS
 * (before: the mapped file's pages vanished under the parser). */
static const char *shrink_path;
static volatile int shrink_stop;
static void *shrinker(void *arg)
{
    const char *data = arg;
    size_t n = strlen(data);
    while (!shrink_stop) {
        truncate(shrink_path, 100);
        int fd = open(shrink_path, O_WRONLY);
        if (fd >= 0) {
            if (write(fd, data, n) < 0) {}
            close(fd);
        }
    }
    return NULL;
}

START_TEST(shrinking_input)
{
    /* a big text cloud, rewritten and truncated by a thread while read */
    size_t npts = 200000, cap = npts * 64;
    char *data = malloc(cap), *o = data;
    for (size_t i = 0; i < npts; i++)
        o += sprintf(o, "%.17g %.17g %.17g\n", sin((double)i), cos(i * 0.7), (double)i * 1e-5);
    shrink_path = cli_path("shrink.xyz");
    write_file(shrink_path, data);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        pthread_t th;
        shrink_stop = 0;
        pthread_create(&th, NULL, shrinker, data);
        for (int k = 0; k < 40; k++) {
            jf_cloud c;
            jf_error e;
            if (jf_cloud_read(shrink_path, NULL, &c, &e) == JF_OK) jf_cloud_free(&c);
        }
        shrink_stop = 1;
        pthread_join(th, NULL);
        _exit(0);
    }
    int st;
    waitpid(pid, &st, 0);
    ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 0, "reader died (signal %d)",
                  WIFSIGNALED(st) ? WTERMSIG(st) : 0);
    free(data);
}
END_TEST

/* 4. A FIFO is refused at once (before: open blocked forever). */
START_TEST(fifo_refused)
{
    const char *f = cli_path("f.xyz");
    ck_assert_int_eq(mkfifo(f, 0600), 0);
    ck_assert_int_eq(cli_run("estimate", f, "-o", cli_path("o.xyz"), NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "not a regular file"));
    ck_assert(!cli_exists(cli_path("o.xyz")));
}
END_TEST

/* 5. The output is the input, directly, by a symlink or a hard link
 * (before: the input was replaced by the result). */
START_TEST(output_is_input)
{
    const char *in = sphere(300);
    size_t n0 = 0, n1 = 0;
    char *before = jf_test_slurp(in, &n0);
    ck_assert_int_eq(symlink("sphere.ply", cli_path("sl.ply")), 0);
    ck_assert_int_eq(link(in, cli_path("hl.ply")), 0);
    const char *outs[] = {in, cli_path("sl.ply"), cli_path("hl.ply")};
    for (int k = 0; k < 3; k++) {
        ck_assert_int_eq(cli_run("estimate", in, "-o", outs[k], NULL), 1);
        ck_assert_ptr_nonnull(strstr(cli_err, "is the input file"));
    }
    char *after = jf_test_slurp(in, &n1);
    ck_assert(n0 == n1 && memcmp(before, after, n0) == 0);
    free(before), free(after);
    ck_assert_int_eq(temporaries(), 0);
}
END_TEST

/* 6. SIGINT / SIGTERM / SIGHUP mid-run: the temporary is removed and the
 * exit status is 128 + the signal (before: .NAME.tmp.PID stayed). */
START_TEST(signals_leave_nothing)
{
    const char *in = cli_path("big.ply");
    ck_assert_int_eq(cli_run("generate", "exp", "--n", "400000", "-o", in, NULL), 0);
    int sigs[4] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE}; /* SIGPIPE: `2>&1 | head` */
    for (int k = 0; k < 4; k++) {
        const char *out = cli_path("sig.ply");
        fflush(NULL);
        pid_t pid = fork();
        if (pid == 0) {
            int fo = open("/dev/null", O_WRONLY);
            dup2(fo, 1), dup2(fo, 2);
            execl(JETFIT_BIN, JETFIT_BIN, "estimate", in, "-o", out, "--neighbors", "knn:64",
                  "--degree", "3", "--threads", "1", (char *)NULL);
            _exit(127);
        }
        /* wait until the run has its temporaries (the output's and the
         * row spool, docs/scale.md), then signal it */
        for (int t = 0; t < 2000 && temporaries() < 2; t++) usleep(5000);
        ck_assert_int_eq(temporaries(), 2);
        usleep(100000);
        kill(pid, sigs[k]);
        int st;
        waitpid(pid, &st, 0);
        ck_assert_msg(WIFEXITED(st) && WEXITSTATUS(st) == 128 + sigs[k], "signal %d: status %d",
                      sigs[k], st);
        ck_assert_int_eq(temporaries(), 0);
        ck_assert(!cli_exists(out));
    }
}
END_TEST

/* 7. render: a failure keeps the old picture and prints one line; a
 * missing folder writes nothing anywhere, stdout included (before: a
 * 0-byte PNG and 8 gnuplot lines; PNG bytes on stdout). */
START_TEST(render_failure_keeps_old)
{
    const char *png = cli_path("keep.png"), *nan = cli_path("nan.xyz");
    write_file(png, "old picture");
    write_file(nan, "# x y z k1 k2\nnan nan nan 1 1\nnan nan nan 2 1\n");
    ck_assert_int_eq(cli_run("render", nan, "-o", png, NULL), 1);
    size_t n;
    char *v = jf_test_slurp(png, &n);
    ck_assert_str_eq(v, "old picture");
    free(v);
    ck_assert_ptr_null(strchr(cli_err, '\n') ? strchr(strchr(cli_err, '\n') + 1, '\n') : NULL);
    ck_assert_int_eq(temporaries(), 0);

    write_file(cli_path("ok.xyz"), "# x y z k1 k2\n0 0 0 1 1\n1 0 0 1 2\n0 1 0 2 1\n");
    const char *stdout_path = cli_path("stdout.bin");
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int fo = open(stdout_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int fe = open("/dev/null", O_WRONLY);
        dup2(fo, 1), dup2(fe, 2);
        execl(JETFIT_BIN, JETFIT_BIN, "render", cli_path("ok.xyz"), "-o",
              cli_path("nodir/o.png"), (char *)NULL);
        _exit(127);
    }
    int st;
    waitpid(pid, &st, 0);
    ck_assert(WIFEXITED(st) && WEXITSTATUS(st) == 1);
    ck_assert_uint_eq(file_size(stdout_path), 0);
}
END_TEST

/* 9, 10: the messages a user fixing a command line needs (before:
 * "needs a value" for an unknown last option, no limit named, and an
 * invalid "parameters" line for a huge K); --bad-rows skip keeps the
 * rows aligned and says which lines (before: no such option). */
START_TEST(messages)
{
    const char *in = sphere(300), *out = cli_path("m.xyz");
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--bogus", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "unknown option"));
    /* study too (before: "--bogus '': needs a value") */
    ck_assert_int_eq(cli_run("study", "exp", "-o", cli_path("st"), "--bogus", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "unknown option '--bogus'"));
    ck_assert_int_eq(cli_run("study", "exp", "-o", cli_path("st"), "--repeat", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "needs a value"));
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--threads", "5000", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "4096"));
    ck_assert_int_eq(cli_run("estimate", in, "-o", out, "--neighbors", "knn:5000000000", NULL), 2);
    ck_assert_ptr_nonnull(strstr(cli_err, "too large: at most 1048576"));
    ck_assert(!cli_exists(out));

    const char *g = cli_path("g.xyz");
    write_file(g, "0 0 0\n1 0 0\n0 1 0\nbad row here\n1 1 0.1\n0.5 0.5 0\n2 0 0.2\n0 2 0.1\n");
    ck_assert_int_eq(cli_run("estimate", g, "-o", out, NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "g.xyz:4:"));
    ck_assert_int_eq(cli_run("estimate", g, "-o", out, "--bad-rows", "skip", NULL), 0);
    ck_assert_ptr_nonnull(strstr(cli_err, "1 unparsable rows kept as NaN rows"));
    ck_assert_ptr_nonnull(strstr(cli_err, "lines 4"));
    ck_assert_ptr_nonnull(strstr(cli_err, "bad rows: 1"));
    jf_eval_table t;
    cli_read(out, &t);
    ck_assert_uint_eq(t.nrows, 8);
    ck_assert((unsigned)cli_val(&t, 3, "status") & JF_PT_NONFINITE);
    ck_assert(cli_val(&t, 4, "x") == 1 && cli_val(&t, 4, "z") == 0.1);
    jf_eval_table_free(&t);
}
END_TEST

/* 8: eval of a result against another cloud's truth with the same row
 * count (before: 60 degrees of "error", rc 0). */
START_TEST(eval_other_cloud)
{
    const char *a = cli_path("a.xyz"), *b = cli_path("b.xyz");
    const char *ta = cli_path("ta.csv"), *tb = cli_path("tb.csv");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "2000", "--noise", "0.005", "--seed",
                             "1", "-o", a, "--truth", ta, NULL), 0);
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "2000", "--seed", "2", "-o", b,
                             "--truth", tb, NULL), 0);
    const char *ra = cli_path("ra.csv"), *rb = cli_path("rb.csv");
    ck_assert_int_eq(cli_run("estimate", a, "-o", ra, "--quiet", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", b, "-o", rb, "--quiet", NULL), 0);
    ck_assert_int_eq(cli_run("eval", ra, ta, NULL), 0);  /* noisy vs its own truth */
    ck_assert_int_eq(cli_run("eval", ra, tb, NULL), 1);  /* another cloud's truth */
    ck_assert_ptr_nonnull(strstr(cli_err, "not the same cloud"));
    ck_assert_int_eq(cli_run("eval", ra, rb, NULL), 1);  /* another cloud's result */
    ck_assert_ptr_nonnull(strstr(cli_err, "not the same cloud"));
    ck_assert_int_eq(cli_run("eval", rb, rb, NULL), 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_hostile");
    TCase *tc = tcase_create("hostile");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, render_no_injection);
    tcase_add_test(tc, planted_link_not_followed);
    tcase_add_test(tc, output_file_rules);
    tcase_add_test(tc, shrinking_input);
    tcase_add_test(tc, fifo_refused);
    tcase_add_test(tc, output_is_input);
    tcase_add_test(tc, signals_leave_nothing);
    tcase_add_test(tc, render_failure_keeps_old);
    tcase_add_test(tc, messages);
    tcase_add_test(tc, eval_other_cloud);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
