/* test_cli_threads.c -- the thread count left to the environment (issue
 * 33 item 5, issue 31): OMP_NUM_THREADS=100000 crashed libgomp inside the
 * estimate (SIGSEGV in GOMP_parallel); it is clamped to the processors,
 * with one line, and the output equals a --threads 1 run byte for byte.
 * An explicit --threads above the processors is obeyed without a line;
 * an empty OMP_NUM_THREADS runs. */
#include <check.h>

#include "test_cli_util.h"
#include "jf_test.h"

static int count_lines(const char *s)
{
    int n = 0;
    for (; *s; s++) n += *s == '\n';
    return n;
}

START_TEST(huge_omp_num_threads_clamped)
{
    cli_setup();
    char in[300], ref[300], got[300];
    snprintf(in, sizeof in, "%s", cli_path("in.ply"));
    snprintf(ref, sizeof ref, "%s", cli_path("ref.ply"));
    snprintf(got, sizeof got, "%s", cli_path("got.ply"));
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "2000", "-o", in, NULL), 0);
    ck_assert_msg(cli_run("estimate", in, "-o", ref, "--threads", "1", "--quiet", NULL) == 0,
                  "%s", cli_err);
    setenv("OMP_NUM_THREADS", "100000", 1);
    int rc = cli_run("estimate", in, "-o", got, "--quiet", NULL);
    unsetenv("OMP_NUM_THREADS");
    ck_assert_msg(rc == 0, "exit %d: %s", rc, cli_err);
    ck_assert_msg(strstr(cli_err, "OMP_NUM_THREADS asks for 100000 threads") != NULL, "%s",
                  cli_err);
    ck_assert_int_eq(count_lines(cli_err), 1);
    ck_assert(jf_test_same_files(ref, got));
    cli_teardown();
}
END_TEST

START_TEST(explicit_threads_and_empty_environment)
{
    cli_setup();
    char in[300], ref[300], got[300];
    snprintf(in, sizeof in, "%s", cli_path("in.ply"));
    snprintf(ref, sizeof ref, "%s", cli_path("ref.ply"));
    snprintf(got, sizeof got, "%s", cli_path("got.ply"));
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "2000", "-o", in, NULL), 0);
    ck_assert_int_eq(cli_run("estimate", in, "-o", ref, "--threads", "1", "--quiet", NULL), 0);
    setenv("OMP_NUM_THREADS", "1", 1);
    ck_assert_msg(cli_run("estimate", in, "-o", got, "--threads", "6", "--quiet", NULL) == 0,
                  "%s", cli_err);
    ck_assert_msg(cli_err[0] == '\0', "%s", cli_err);
    ck_assert(jf_test_same_files(ref, got));
    setenv("OMP_NUM_THREADS", "", 1);
    int rc = cli_run("estimate", in, "-o", got, "--quiet", NULL);
    unsetenv("OMP_NUM_THREADS");
    ck_assert_msg(rc == 0, "exit %d: %s", rc, cli_err);
    ck_assert(jf_test_same_files(ref, got));
    cli_teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_threads");
    TCase *t = tcase_create("threads");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, huge_omp_num_threads_clamped);
    tcase_add_test(t, explicit_threads_and_empty_environment);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
