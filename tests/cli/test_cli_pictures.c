/* test_cli_pictures.c -- issue 33, items 2 and 9: the pictures of render,
 * study and convergence against another process that has write access to
 * the output folder, and against a folder name gnuplot cannot take.  Each
 * test fails on the code before the fix (said per test).  Needs gnuplot:
 * without it the suite reports a skip (77). */
#define _GNU_SOURCE
#include <check.h>
#include <signal.h>

#include "jf_test.h"
#include "test_cli_util.h"

static void teardown(void) { cli_rm_rf(cli_dir); }

/* The swapper: a child that, until killed, replaces every ".*.tmp" entry
 * of dir with a symbolic link to victim (what any process with write
 * access to the folder can do).  Returns its pid. */
static pid_t start_swapper(const char *dir, const char *victim)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid != 0) return pid;
    for (;;) {
        DIR *d = opendir(dir);
        for (struct dirent *e; d && (e = readdir(d));) {
            size_t n = strlen(e->d_name);
            if (e->d_name[0] != '.' || n < 5 || strcmp(e->d_name + n - 4, ".tmp")) continue;
            char p[1024];
            snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            struct stat sb;
            if (lstat(p, &sb) == 0 && S_ISLNK(sb.st_mode)) continue;
            unlink(p);
            if (symlink(victim, p) != 0) {}
        }
        if (d) closedir(d);
    }
}

static void stop(pid_t pid)
{
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
}

/* How many entries of dir are symbolic links, the swapper's own ".*.tmp"
 * aside (it may plant one after jetfit removed its temporary): an output
 * that is a link is the attacker's file become ours. */
static int links_in(const char *dir)
{
    int n = 0;
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        char p[1024];
        struct stat sb;
        size_t l = strlen(e->d_name);
        if (e->d_name[0] == '.' && l > 4 && !strcmp(e->d_name + l - 4, ".tmp")) continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (lstat(p, &sb) == 0 && S_ISLNK(sb.st_mode)) n++;
    }
    if (d) closedir(d);
    return n;
}

static const char victim_text[] = "precious, not a picture\n";

/* 2. render: the temporary swapped for a link during the run (before:
 * gnuplot reopened the name with O_TRUNC and wrote the PNG into the link's
 * target, rc 0, and the output became the attacker's link).  Now the
 * victim is untouched, and the output is either our whole PNG or, when the
 * swap came before the rename, absent with rc 1 and one line. */
START_TEST(render_temporary_swapped)
{
    const char *pts = cli_path("s.ply"), *res = cli_path("s.csv");
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "20000", "-o", pts, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", pts, "-o", res, "--quiet", NULL), 0);
    char out[600], victim[600];
    snprintf(out, sizeof out, "%s/pic", cli_dir);
    ck_assert_int_eq(mkdir(out, 0777), 0);
    snprintf(victim, sizeof victim, "%s/victim.txt", cli_dir);
    cli_write_text(victim, victim_text);
    int failed = 0;
    for (int k = 0; k < 3; k++) {
        pid_t sw = start_swapper(out, victim);
        char png[700];
        snprintf(png, sizeof png, "%s/r%d.png", out, k);
        int rc = cli_run("render", res, "-o", png, NULL);
        stop(sw);
        size_t n;
        char *v = jf_test_slurp(victim, &n);
        ck_assert_msg(v && !strcmp(v, victim_text), "render %d wrote into the link's target", k);
        free(v);
        ck_assert_int_eq(links_in(out), 0);
        if (rc == 0) {
            ck_assert(cli_whole_png(png));
        } else {
            ck_assert_int_eq(rc, 1);
            ck_assert_ptr_nonnull(strstr(cli_err, "replaced by another process"));
            ck_assert(!cli_exists(png));
            failed++;
        }
    }
    ck_assert_msg(failed > 0, "the swapper never caught a temporary: the test proves nothing");
}
END_TEST

/* 2. study and convergence: the same swapper over their folder (before:
 * gnuplot wrote through the links into the victim). */
START_TEST(study_convergence_temporaries_swapped)
{
    char victim[600], sdir[600], cdir[600];
    snprintf(victim, sizeof victim, "%s/victim.txt", cli_dir);
    cli_write_text(victim, victim_text);
    snprintf(sdir, sizeof sdir, "%s/study", cli_dir);
    snprintf(cdir, sizeof cdir, "%s/conv", cli_dir);
    ck_assert_int_eq(mkdir(sdir, 0777), 0);
    ck_assert_int_eq(mkdir(cdir, 0777), 0);
    pid_t sw = start_swapper(sdir, victim);
    int rs = cli_run("study", "exp", "-o", sdir, "--n", "600", "--neighbors", "knn:12;knn:24",
                     "--noise", "0;0.01", "--quiet", NULL);
    stop(sw);
    sw = start_swapper(cdir, victim);
    int rcv = cli_run("convergence", "--out", cdir, "--quick", NULL);
    stop(sw);
    size_t n;
    char *v = jf_test_slurp(victim, &n);
    ck_assert_msg(v && !strcmp(v, victim_text),
                  "something went into the link's target (study %d, convergence %d): %zu bytes "
                  "starting %.40s", rs, rcv, n, v ? v : "(unreadable)");
    free(v);
    ck_assert_int_eq(links_in(sdir), 0);
    ck_assert_int_eq(links_in(cdir), 0);
    ck_assert(rs == 0 || rs == 1);
    ck_assert(rcv == 0 || rcv == 1);
}
END_TEST

/* 9. A newline (control characters) in the -o folder of study and
 * convergence's folder: the pictures are made, whole
 * (before: study said "no plots: gnuplot failed: No such file or
 * directory" and exited 0: the newline reached gnuplot as a blank). */
START_TEST(control_characters_in_names)
{
    char sdir[600], cdir[600], path[800];
    snprintf(sdir, sizeof sdir, "%s/st\nudy\t\x01", cli_dir);
    int rc = cli_run("study", "exp", "-o", sdir, "--n", "600", "--neighbors", "knn:12;knn:24",
                     "--noise", "0;0.01", "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    ck_assert_ptr_null(strstr(cli_err, "no plots"));
    const char *names[3] = {"normal.png", "curvature.png", "k.png"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/%s", sdir, names[k]);
        ck_assert_msg(cli_whole_png(path), "%s", names[k]);
    }
    snprintf(cdir, sizeof cdir, "%s/con\nv", cli_dir);
    ck_assert_int_eq(cli_run("convergence", "--out", cdir, "--quick", NULL), 0);
    snprintf(path, sizeof path, "%s/degree_approx.png", cdir);
    ck_assert(cli_whole_png(path));
}
END_TEST

int main(void)
{
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) { /* a reported skip (ctest: 77) */
        printf("SKIP: gnuplot is not installed (Debian package gnuplot-nox)\n");
        return 77;
    }
    Suite *s = suite_create("cli_pictures");
    TCase *tc = tcase_create("pictures");
    tcase_add_checked_fixture(tc, cli_setup, teardown);
    tcase_set_timeout(tc, 180);
    tcase_add_test(tc, render_temporary_swapped);
    tcase_add_test(tc, study_convergence_temporaries_swapped);
    tcase_add_test(tc, control_characters_in_names);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
