/* test_cli_view.c -- `jetfit view` without a browser: the half floats
 * against an independent decoder, base64 against an independent decoder,
 * the escaping of names and inlined scripts, the spread order, and the
 * command end to end (errors name the file and leave no output; the
 * metadata it writes; --max-points; --estimate; bytes per point).  The
 * page in a browser: tests/view/view_check.js. */
#define _GNU_SOURCE
#include <check.h>

#include "test_cli_util.h"
#include "view.h"
#include "jf_test.h"


/* IEEE 754 binary16 -> double, from the definition (not view_pack.c) */
static double half_to_double(uint16_t h)
{
    int s = h >> 15, e = h >> 10 & 31, f = h & 1023;
    double v = e == 0 ? ldexp(f, -24) : e == 31 ? (f ? NAN : INFINITY) : ldexp(1024 + f, e - 25);
    return s ? -v : v;
}

START_TEST(half_rounds_to_nearest)
{
    /* every finite half pattern comes back exactly */
    for (unsigned h = 0; h < 65536; h++) {
        double v = half_to_double((uint16_t)h);
        if (isnan(v)) continue;
        ck_assert_uint_eq(jf_view_half(v), h);
    }
    /* random values: the nearest half, relative error <= 2^-11 */
    unsigned long long r = 88172645463325252ULL;
    for (int i = 0; i < 100000; i++) {
        r ^= r << 13, r ^= r >> 7, r ^= r << 17;
        double v = ldexp((double)(r >> 11) / 9007199254740992.0, (int)(r % 30) - 14) * (r & 1 ? -1 : 1);
        double back = half_to_double(jf_view_half(v));
        ck_assert(fabs(back - v) <= fabs(v) * 0x1p-11 + 0x1p-25);
    }
    ck_assert(isnan(half_to_double(jf_view_half(NAN))));
    ck_assert(half_to_double(jf_view_half(1e6)) == INFINITY);
    ck_assert(half_to_double(jf_view_half(-1e6)) == -INFINITY);
    ck_assert(half_to_double(jf_view_half(65504)) == 65504);
}
END_TEST

static int b64val(int c)
{
    return c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26
           : c >= '0' && c <= '9' ? c - '0' + 52 : c == '+' ? 62 : c == '/' ? 63 : -1;
}

START_TEST(base64_round_trips)
{
    unsigned char in[1000], out[1000];
    for (int i = 0; i < 1000; i++) in[i] = (unsigned char)(i * 37 + (i >> 3));
    for (size_t n = 0; n < 40; n++) {
        char *buf = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&buf, &len);
        jf_b64 b = {f, {0}, 0};
        for (size_t k = 0; k < n;) { /* uneven chunks */
            size_t c = (k % 3) + 1 < n - k ? (k % 3) + 1 : n - k;
            jf_b64_put(&b, in + k, c);
            k += c;
        }
        jf_b64_end(&b);
        fclose(f);
        ck_assert_uint_eq(len, (n + 2) / 3 * 4);
        size_t m = 0;
        for (size_t i = 0; i + 4 <= len; i += 4) {
            int v[4];
            for (int j = 0; j < 4; j++) v[j] = buf[i + j] == '=' ? 0 : b64val(buf[i + j]);
            for (int j = 0; j < 4; j++) ck_assert_int_ge(v[j], 0);
            unsigned w = (unsigned)v[0] << 18 | (unsigned)v[1] << 12 | (unsigned)v[2] << 6 | (unsigned)v[3];
            out[m++] = w >> 16;
            if (buf[i + 2] != '=') out[m++] = w >> 8 & 255;
            if (buf[i + 3] != '=') out[m++] = w & 255;
        }
        ck_assert_uint_eq(m, n);
        ck_assert(memcmp(in, out, n) == 0);
        free(buf);
    }
}
END_TEST

static char *capture(void (*fn)(FILE *, const char *), const char *s)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    fn(f, s);
    fclose(f);
    return buf;
}

START_TEST(names_and_scripts_are_escaped)
{
    const char *nasty = "</script><script>alert(1)</script><!--\"'&\x01\xe2\x80\xa8";
    char *h = capture(jf_view_html, nasty), *j = capture(jf_view_json_str, nasty);
    ck_assert_ptr_null(strchr(h, '<'));
    ck_assert_ptr_null(strchr(h, '>'));
    ck_assert_ptr_null(strchr(h, '"'));
    ck_assert_ptr_null(strchr(h, '\x01'));
    ck_assert_ptr_null(strchr(j, '<'));
    ck_assert_ptr_null(strchr(j, '>'));
    ck_assert_ptr_null(strchr(j, '\x01'));
    ck_assert_ptr_null(strstr(j, "\xe2\x80\xa8"));
    ck_assert_str_eq(j, "\"\\u003c/script\\u003e\\u003cscript\\u003ealert(1)\\u003c/script\\u003e"
                        "\\u003c!--\\\"'\\u0026\\u0001\\u2028\"");
    char *s = capture(jf_view_inline_js, "a='</SCRIPT>';b=/<!--/;c='</scrip';");
    ck_assert_str_eq(s, "a='<\\/SCRIPT>';b=/<\\!--/;c='</scrip';");
    free(h), free(j), free(s);
}
END_TEST

START_TEST(spread_order_is_an_even_permutation)
{
    /* a 64 x 64 grid: the first 64 of the order fall one in each 8 x 8 block */
    enum { S = 64, N = S * S };
    static double v[N * 3];
    static size_t idx[N];
    for (size_t i = 0; i < N; i++) {
        v[3 * i] = (double)(i % S), v[3 * i + 1] = (double)(i / S), v[3 * i + 2] = 0;
        idx[i] = (i * 2654435761u) % N; /* a shuffled start */
    }
    ck_assert_int_eq(jf_view_spread_order(v, 3, 0, idx, N), 0);
    static unsigned char seen[N];
    for (size_t i = 0; i < N; i++) {
        ck_assert_uint_lt(idx[i], N);
        ck_assert(!seen[idx[i]]);
        seen[idx[i]] = 1;
    }
    int block[64] = {0};
    for (size_t k = 0; k < 64; k++) {
        size_t i = idx[k];
        block[(i % S) / 8 + 8 * ((i / S) / 8)]++;
    }
    for (int b = 0; b < 64; b++) ck_assert_int_eq(block[b], 1);
}
END_TEST

/* the "key":NUMBER in FILE's metadata, or -1 */
static double meta_num(const char *path, const char *key)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    static char buf[1 << 22]; /* the metadata follows three.js (~0.9 MB) */
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    char *p = strstr(buf, "id=\"jf-meta\"");
    p = p ? strstr(p, pat) : NULL;
    return p ? atof(p + strlen(pat)) : -1;
}

static long fsize(const char *p)
{
    struct stat st;
    return stat(p, &st) ? -1 : (long)st.st_size;
}

START_TEST(errors_name_the_file_and_write_nothing)
{
    cli_write_text(cli_path("abc.csv"), "a,b,c\n1,2,3\n");
    cli_write_text(cli_path("old.html"), "old");
    ck_assert_int_eq(cli_run("view", cli_path("nope.ply"), "-o", cli_path("old.html"), NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "jetfit view: "));
    ck_assert_ptr_nonnull(strstr(cli_err, "nope.ply"));
    ck_assert_int_eq(cli_run("view", cli_path("abc.csv"), "-o", cli_path("old.html"), NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "abc.csv: no columns x y z"));
    ck_assert_int_eq(fsize(cli_path("old.html")), 3); /* not clobbered */
    cli_write_text(cli_path("nan.csv"), "x,y,z\n1,nan,2\n");
    ck_assert_int_eq(cli_run("view", cli_path("nan.csv"), "-o", cli_path("old.html"), NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "nan.csv: no row has finite x y z"));
    cli_write_text(cli_path("p.csv"), "x,y,z\n0,1,2\n");
    ck_assert_int_eq(cli_run("view", cli_path("p.csv"), "-o", cli_path("no/such/dir/v.html"), NULL), 1);
    ck_assert_int_eq(cli_run("view", cli_path("p.csv"), "-o", cli_path("v.png"), NULL), 2);
    ck_assert_int_eq(cli_run("view", cli_path("p.csv"), "-o", cli_path("v.html"), "--max-points", "0", NULL), 2);
    ck_assert_int_eq(cli_run("view", cli_path("p.csv"), "-o", cli_path("v.html"), "--color", "k9", NULL), 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "no column 'k9'"));
    ck_assert_int_eq(cli_run("view", cli_path("p.csv"), "-o", cli_path("v.html"), "--degree", "2", NULL), 2);
    ck_assert_int_eq(cli_count_files(), 4); /* abc.csv old.html nan.csv p.csv */
    ck_assert_int_eq(cli_run("view", cli_path("p.csv"), "-o", cli_path("v.html"), NULL), 0);
    ck_assert_int_eq(meta_num(cli_path("v.html"), "ndrawn"), 1);
}
END_TEST

START_TEST(no_three_is_one_clear_line)
{
    cli_write_text(cli_path("p.csv"), "x,y,z\n0,1,2\n");
    setenv("JETFIT_THREE_DIR", cli_path("none"), 1);
    int rc = cli_run("view", cli_path("p.csv"), "-o", cli_path("v.html"), NULL);
    unsetenv("JETFIT_THREE_DIR");
    ck_assert_int_eq(rc, 1);
    ck_assert_ptr_nonnull(strstr(cli_err, "libjs-three"));
    ck_assert(!cli_exists(cli_path("v.html")));
}
END_TEST

START_TEST(subsample_estimate_and_size)
{
    ck_assert_int_eq(cli_run("generate", "paraboloid", "-o", cli_path("raw.ply"), "--n", "4000", NULL), 0);
    ck_assert_int_eq(cli_run("view", "--estimate", cli_path("raw.ply"), "-o", cli_path("e.html"),
                             "--degree", "2", "--neighbors", "knn:20", "--threads", "1", "--quiet", NULL), 0);
    ck_assert_int_eq(meta_num(cli_path("e.html"), "ndrawn"), 4000);
    ck_assert_int_eq(cli_count_files(), 2); /* the estimate's temporary is gone */
    ck_assert_int_eq(cli_run("estimate", cli_path("raw.ply"), "-o", cli_path("est.ply"), "--quiet", NULL), 0);
    ck_assert_int_eq(cli_run("view", cli_path("est.ply"), "-o", cli_path("a.html"), "--quiet", NULL), 0);
    ck_assert_int_eq(cli_run("view", cli_path("est.ply"), "-o", cli_path("b.html"), "--max-points", "1000",
                             "--quiet", NULL), 0);
    ck_assert_int_eq(meta_num(cli_path("b.html"), "ndrawn"), 1000);
    ck_assert_int_eq(meta_num(cli_path("b.html"), "nrows"), 4000);
    /* every column of an estimate's output: under 40 bytes per drawn point */
    double per = (double)(fsize(cli_path("a.html")) - fsize(cli_path("b.html"))) / 3000;
    ck_assert_msg(per > 20 && per < 40, "%.1f bytes per point", per);
}
END_TEST

/* view --estimate names the INPUT, not its temporary: two runs give the
 * same page byte for byte. */
START_TEST(estimate_page_names_the_input)
{
    ck_assert_int_eq(cli_run("generate", "sphere", "-o", cli_path("cloud.ply"), "--n", "500", NULL), 0);
    for (int k = 0; k < 2; k++)
        ck_assert_int_eq(cli_run("view", "--estimate", cli_path("cloud.ply"), "-o",
                                 cli_path(k ? "b.html" : "a.html"), "--threads", "1", "--quiet", NULL), 0);
    size_t na, nb;
    char *a = jf_test_slurp(cli_path("a.html"), &na), *b = jf_test_slurp(cli_path("b.html"), &nb);
    ck_assert(a && b);
    ck_assert_ptr_nonnull(strstr(a, "{\"file\":\"cloud.ply\""));
    ck_assert_ptr_null(strstr(a, "jetfit-view-"));
    ck_assert(na == nb && !memcmp(a, b, na));
    free(a);
    free(b);
}
END_TEST

START_TEST(study_report_links_the_best_result)
{
    ck_assert_int_eq(cli_run("study", "sphere", "-o", cli_path("st"), "--n", "600", "--degree", "2,3",
                             "--quiet", NULL), 0);
    ck_assert_int_eq(meta_num(cli_path("st/view.html"), "ndrawn"), 600);
    jf_eval_table t;
    jf_error e = {{0}};
    ck_assert_int_eq(jf_eval_table_read(cli_path("st/best.ply"), &t, &e), JF_OK);
    ck_assert_uint_eq(t.nrows, 600);
    ck_assert_int_ge(jf_eval_table_col(&t, "k1"), 0);
    jf_eval_table_free(&t);
    FILE *f = fopen(cli_path("st/report.html"), "rb");
    ck_assert_ptr_nonnull(f);
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    ck_assert_ptr_nonnull(strstr(buf, "<a href=\"view.html\">"));
    const char *rm[] = {"/bin/rm", "-rf", cli_path("st"), NULL};
    pid_t pid = fork();
    if (pid == 0) { execv(rm[0], (char *const *)rm); _exit(127); }
    waitpid(pid, NULL, 0);
}
END_TEST

int main(void)
{
    char v[8192];
    FILE *p = popen(JETFIT_BIN " --version", "r");
    size_t n = p ? fread(v, 1, sizeof v - 1, p) : 0;
    v[n] = 0;
    if (p) pclose(p);
    int have_three = strstr(v, "view: three.js r") != NULL;
    Suite *s = suite_create("cli_view");
    TCase *tc = tcase_create("view");
    tcase_set_timeout(tc, 120);
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_add_test(tc, half_rounds_to_nearest);
    tcase_add_test(tc, base64_round_trips);
    tcase_add_test(tc, names_and_scripts_are_escaped);
    tcase_add_test(tc, spread_order_is_an_even_permutation);
    tcase_add_test(tc, no_three_is_one_clear_line);
    suite_add_tcase(s, tc);
    /* the command's pages need three.js: their own ctest, test_cli_view_three */
    TCase *th = tcase_create("three");
    tcase_set_timeout(th, 120);
    tcase_set_tags(th, "three");
    tcase_add_checked_fixture(th, cli_setup, cli_teardown);
    tcase_add_test(th, errors_name_the_file_and_write_nothing);
    tcase_add_test(th, subsample_estimate_and_size);
    tcase_add_test(th, study_report_links_the_best_result);
    tcase_add_test(th, estimate_page_names_the_input);
    suite_add_tcase(s, th);
    return jf_test_run_tool(s, "three", have_three, "three.js not found (Debian: libjs-three)");
}
