/* test_gnuplot_quote.c -- issue 11: every title or file name, any byte but
 * NUL, reaches gnuplot as exactly the intended string (control characters
 * as blanks) and runs nothing.  Random strings are quoted by jf_gp_quote
 * (src/cli/gnuplot.c, what render and study use) into `print` commands of
 * one real gnuplot run; what gnuplot prints must equal the strings. */
#define _GNU_SOURCE
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gnuplot.h"
#include "jf_test.h"

#define NSTR 400
#define MAXLEN 60

START_TEST(random_strings_round_trip)
{
    char dir[] = "/tmp/jf_gpq_XXXXXX";
    ck_assert_ptr_nonnull(mkdtemp(dir));
    char script[64], out[64], cmd[256];
    snprintf(script, sizeof script, "%s/s.gp", dir);
    snprintf(out, sizeof out, "%s/out", dir);
    static char want[NSTR][MAXLEN + 1];
    static const char *nasty[] = {"`touch PWNED`", "'", "''", "\"`touch PWNED`\"", "\\", "$(touch PWNED)",
                                  "a\nb", "@x", "%s%n", "\\n\\t", "system('touch PWNED')"};
    unsigned long long r = 88172645463325252ULL;
    FILE *f = fopen(script, "w");
    ck_assert_ptr_nonnull(f);
    for (int i = 0; i < NSTR; i++) {
        char s[MAXLEN + 1];
        if (i < (int)(sizeof nasty / sizeof *nasty)) {
            snprintf(s, sizeof s, "%s", nasty[i]);
        } else {
            int len = 1 + (int)(r % MAXLEN);
            for (int k = 0; k < len; k++) {
                r ^= r << 13, r ^= r >> 7, r ^= r << 17;
                s[k] = (char)(1 + r % 255); /* any byte but NUL */
            }
            s[len] = '\0';
        }
        for (int k = 0; s[k]; k++)
            want[i][k] = (unsigned char)s[k] < 0x20 || s[k] == 0x7f ? ' ' : s[k];
        want[i][strlen(s)] = '\0';
        fprintf(f, "print ");
        jf_gp_quote(f, s);
        fputc('\n', f);
    }
    fclose(f);
    snprintf(cmd, sizeof cmd, "cd %s && gnuplot s.gp 2> out", dir);
    ck_assert_int_eq(system(cmd), 0);
    f = fopen(out, "r");
    ck_assert_ptr_nonnull(f);
    char line[4 * MAXLEN];
    for (int i = 0; i < NSTR; i++) {
        ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
        line[strcspn(line, "\n")] = '\0';
        ck_assert_msg(strcmp(line, want[i]) == 0, "string %d: got '%s' want '%s'", i, line, want[i]);
    }
    fclose(f);
    char pwn[64];
    snprintf(pwn, sizeof pwn, "%s/PWNED", dir);
    ck_assert_msg(access(pwn, F_OK) != 0, "a command ran");
    unlink(script), unlink(out), rmdir(dir);
}
END_TEST

int main(void)
{
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) { /* a reported skip (ctest: 77) */
        printf("SKIP: gnuplot is not installed (Debian package gnuplot-nox)\n");
        return 77;
    }
    Suite *s = suite_create("gnuplot_quote");
    TCase *tc = tcase_create("quote");
    tcase_add_test(tc, random_strings_round_trip);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
