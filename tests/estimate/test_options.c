/* test_options.c -- the estimate's options as text (src/estimate/options.c):
 * every parameter's accepted and refused values, the Monge degree derived
 * once from the degree, max_neighbors sized from the neighbourhood, the
 * cross-parameter rules naming the parameter at fault, and reasons that
 * speak of parameters, never of command-line flags (issue 24.2). */
#include <check.h>
#include <math.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static jf_estimate_opts o;

static void setup(void) { jf_estimate_opts_init(&o); }

/* set NAME VALUE must succeed */
static void ok(const char *name, const char *value)
{
    const char *why = "unset";
    ck_assert_msg(jf_estimate_opts_set(&o, name, value, &why) == JF_OK, "%s=%s: %s", name,
                  value ? value : "(null)", why ? why : "");
    ck_assert_ptr_null(why);
}

/* set NAME VALUE must fail, leave o unchanged, and say why without a flag */
static void refused(const char *name, const char *value)
{
    jf_estimate_opts before = o;
    const char *why = NULL;
    ck_assert_msg(jf_estimate_opts_set(&o, name, value, &why) == JF_ERR_INVALID, "%s=%s accepted",
                  name, value ? value : "(null)");
    ck_assert_ptr_nonnull(why);
    ck_assert_msg(!strstr(why, "--"), "%s=%s: the reason names a flag: %s", name, value, why);
    ck_assert_msg(!memcmp(&before, &o, sizeof o), "%s=%s changed the options", name, value);
}

START_TEST(each_parameter_parses_its_text)
{
    ok("neighbors", "knn:20");
    ck_assert_int_eq(o.nb.kind, JF_NB_KNN);
    ck_assert_uint_eq(o.nb.k, 20);
    ok("neighbors", "knn:12,radius:0.5");
    ck_assert_int_eq(o.nb.kind, JF_NB_KNN_RADIUS);
    ck_assert_double_eq(o.nb.r, 0.5);
    ok("degree", "4");
    ck_assert_int_eq(o.params.degree, 4);
    ok("monge_degree", "3");
    ck_assert_int_eq(o.params.monge_degree, 3);
    ok("fit", "interp");
    ck_assert_int_eq(o.params.fit, JF_FIT_INTERP);
    ok("frame", "axis");
    ck_assert_int_eq(o.params.frame, JF_FRAME_AXIS);
    ok("max_cond", "1e6");
    ck_assert_double_eq(o.params.max_cond, 1e6);
    ok("orient", "viewpoint:1,-2,3.5");
    ck_assert_int_eq(o.orient, JF_ORIENT_VIEWPOINT);
    ck_assert_double_eq(o.viewpoint[1], -2.0);
    ck_assert_double_eq(o.viewpoint[2], 3.5);
    ok("orient", "mst:12");
    ck_assert_int_eq(o.orient, JF_ORIENT_MST);
    ck_assert_uint_eq(o.orient_k, 12);
    ok("normal", "mincirc");
    ck_assert_int_eq(o.normal, JF_NORMAL_MINCIRC);
    ok("robust", "tukey");
    ck_assert_int_eq(o.params.robust, JF_ROBUST_TUKEY);
    ok("scales", "8,16,64");
    ck_assert_int_eq(o.params.nscales, 3);
    ck_assert_uint_eq(o.params.scales[2], 64);
    ok("degree_select", "2");
    ck_assert_int_eq(o.params.degree_select, 2);
    ok("dist_weight", "0.25");
    ck_assert_double_eq(o.params.dist_weight, 0.25);
    ok("threads", "3");
    ck_assert_int_eq(o.threads, 3);
    jf_estimate_opts_init(&o);
    ok("robust_normals", NULL); /* the preset of docs/robustness.md */
    ck_assert_int_eq(o.params.degree_select, 1);
    ck_assert_double_eq(o.params.dist_weight, 0.55);
}
END_TEST

START_TEST(bad_values_are_refused_whole)
{
    refused("neighbors", "knn:0");
    refused("neighbors", "knn:16junk");
    refused("degree", "0");
    refused("degree", "10");
    refused("degree", "2.5");
    refused("degree", "3 ");
    refused("monge_degree", "5");
    refused("fit", "Approx");
    refused("frame", "");
    refused("max_cond", "0.5");
    refused("max_cond", "nan");
    refused("max_cond", "inf");
    refused("orient", "viewpoint:1,2");
    refused("orient", "mst:0");
    refused("orient", "sideways");
    refused("normal", "magic");
    refused("robust", "cauchy");
    refused("scales", "16,8");
    refused("scales", "2,4");
    refused("scales", "8,16,");
    refused("scales", "1,2,3,4,5,6,7,8,9");
    refused("degree_select", "0");
    refused("dist_weight", "0");
    refused("dist_weight", "-1");
    refused("threads", "0");
    refused("threads", "4097");
    refused("degree", NULL);
    refused("colour", "red"); /* not a parameter */
}
END_TEST

START_TEST(monge_degree_derived_once_from_the_degree)
{
    const char *param, *why;
    for (int d = 1; d <= JF_MAX_DEGREE; d++) {
        jf_estimate_opts_init(&o);
        ck_assert_int_eq(o.params.monge_degree, 0); /* not given */
        char t[4];
        snprintf(t, sizeof t, "%d", d);
        ok("degree", t);
        ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_OK);
        int want = d < 2 ? 2 : d > 4 ? 4 : d;
        ck_assert_int_eq(o.params.monge_degree, want);
        ck_assert_int_eq(jf_monge_degree_of(d), want);
    }
    /* given: kept when the jet allows it, refused above it, whatever the order */
    jf_estimate_opts_init(&o);
    ok("monge_degree", "3");
    ok("degree", "4");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_OK);
    ck_assert_int_eq(o.params.monge_degree, 3);
    jf_estimate_opts_init(&o);
    ok("monge_degree", "4");
    ok("degree", "3");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_ERR_INVALID);
    ck_assert_str_eq(param, "monge_degree");
    ck_assert_str_eq(why, "must not exceed degree");
}
END_TEST

START_TEST(finish_sizes_and_checks_the_whole)
{
    const char *param, *why;
    ok("neighbors", "knn:300");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_OK);
    ck_assert_uint_ge(o.params.max_neighbors, 300);
    jf_estimate_opts_init(&o);
    ok("scales", "16,600");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_OK);
    ck_assert_uint_ge(o.params.max_neighbors, 600);
    jf_estimate_opts_init(&o);
    ok("neighbors", "auto");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_OK);
    ck_assert_uint_ge(o.params.max_neighbors, JF_NB_AUTO_KMAX);
    jf_estimate_opts_init(&o);
    ok("neighbors", "knn:2000000");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_ERR_INVALID);
    ck_assert_str_eq(param, "neighbors");
    ck_assert_ptr_nonnull(strstr(why, "1048576"));
    jf_estimate_opts_init(&o);
    ok("degree", "2");
    ok("degree_select", "3");
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_ERR_INVALID);
    ck_assert_str_eq(param, "degree_select");
    ck_assert_ptr_null(strstr(why, "--"));
    /* a field set directly, out of range: named as the library's field */
    jf_estimate_opts_init(&o);
    o.params.robust_iters = 0;
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_ERR_INVALID);
    ck_assert_str_eq(param, "robust_iters");
}
END_TEST

START_TEST(an_estimate_without_finish_derives_the_same)
{
    /* jf_estimate settles a Monge degree left at 0 by the same rule */
    enum { N = 400 };
    double xyz[3 * N];
    uint64_t st = 7;
    for (int i = 0; i < N; i++) {
        double x = jf_unit(jf_splitmix64(&st)) - 0.5, y = jf_unit(jf_splitmix64(&st)) - 0.5;
        xyz[3 * i] = x, xyz[3 * i + 1] = y, xyz[3 * i + 2] = 0.3 * x * x * x + 0.2 * x * y - y * y;
    }
    jf_cloud c = {0};
    c.xyz = xyz;
    c.n = N;
    jf_result a[N], b[N];
    jf_error err;
    ok("degree", "3");
    ok("neighbors", "knn:30");
    ok("threads", "1");
    ck_assert_int_eq(jf_estimate(&c, &o, a, &err), JF_OK); /* monge_degree 0 */
    const char *param, *why;
    ck_assert_int_eq(jf_estimate_opts_finish(&o, &param, &why), JF_OK);
    ck_assert_int_eq(o.params.monge_degree, 3);
    ck_assert_int_eq(jf_estimate(&c, &o, b, &err), JF_OK);
    ck_assert(!memcmp(a, b, sizeof a));
    ck_assert(isfinite(a[0].b[0])); /* b computed: Monge degree 3 */
}
END_TEST

START_TEST(read_options_as_text)
{
    jf_read_opts r;
    jf_read_opts_init(&r);
    const char *why;
    ck_assert_int_eq(jf_read_opts_set(&r, "columns", "2,0,1", &why), JF_OK);
    ck_assert_int_eq(r.columns[0], 2);
    ck_assert_int_eq(r.columns[2], 1);
    ck_assert_int_eq(r.columns[3], -1);
    ck_assert_int_eq(jf_read_opts_set(&r, "columns", "0,1,2,3,4,5", &why), JF_OK);
    ck_assert_int_eq(r.columns[5], 5);
    jf_read_opts before = r;
    ck_assert_int_eq(jf_read_opts_set(&r, "columns", "0,1", &why), JF_ERR_INVALID);
    ck_assert_int_eq(jf_read_opts_set(&r, "columns", "0,1,2.5", &why), JF_ERR_INVALID);
    ck_assert_int_eq(jf_read_opts_set(&r, "columns", "-1,1,2", &why), JF_ERR_INVALID);
    ck_assert(!memcmp(&before, &r, sizeof r));
    ck_assert_int_eq(jf_read_opts_set(&r, "bad_rows", "skip", &why), JF_OK);
    ck_assert_int_eq(r.bad_rows, 1);
    ck_assert_int_eq(jf_read_opts_set(&r, "bad_rows", "ignore", &why), JF_ERR_INVALID);
    ck_assert_int_eq(jf_read_opts_set(&r, "degree", "2", &why), JF_ERR_INVALID);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("options");
    TCase *t = tcase_create("options");
    tcase_add_checked_fixture(t, setup, NULL);
    tcase_add_test(t, each_parameter_parses_its_text);
    tcase_add_test(t, bad_values_are_refused_whole);
    tcase_add_test(t, monge_degree_derived_once_from_the_degree);
    tcase_add_test(t, finish_sizes_and_checks_the_whole);
    tcase_add_test(t, an_estimate_without_finish_derives_the_same);
    tcase_add_test(t, read_options_as_text);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
