/* test_cli_version.c -- `jetfit --version` names jetfit's version and the
 * CGAL, GSL and OpenMP it was built with (issue 10). */
#include <check.h>
#include <gsl/gsl_version.h>
#include <stdio.h>
#include <string.h>

#include "cgal_bridge.h"
#include "jetfit.h"
#include "jf_test.h"

#define JETFIT_BIN JF_BUILD_DIR "/jetfit"

START_TEST(version_lines)
{
    FILE *p = popen(JETFIT_BIN " --version", "r");
    ck_assert_ptr_nonnull(p);
    char out[1024] = "";
    size_t n = fread(out, 1, sizeof out - 1, p);
    out[n] = 0;
    ck_assert_int_eq(pclose(p), 0);
    char want[256];
    snprintf(want, sizeof want, "jetfit %s\n", jf_version());
    ck_assert_msg(strncmp(out, want, strlen(want)) == 0, "first line: %s", out);
    if (jfb_cgal_version())
        snprintf(want, sizeof want, "CGAL %s,", jfb_cgal_version());
    else /* -DJF_CGAL=OFF */
        snprintf(want, sizeof want, "built without CGAL");
    ck_assert_msg(strstr(out, want), "no '%s' in: %s", want, out);
    snprintf(want, sizeof want, "GSL %s,", GSL_VERSION);
    ck_assert_msg(strstr(out, want), "no '%s' in: %s", want, out);
    /* libgomp of GCC 12 implements OpenMP 4.5 (_OPENMP 201511) */
    const char *omp = strstr(out, "OpenMP ");
    ck_assert_ptr_nonnull(omp);
    ck_assert_msg(omp[7] >= '3' && omp[7] <= '9' && omp[8] == '.', "OpenMP: %s", omp);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_version");
    TCase *tc = tcase_create("version");
    tcase_add_test(tc, version_lines);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
