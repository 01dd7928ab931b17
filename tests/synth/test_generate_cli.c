/* test_generate_cli.c -- `jetfit generate` and `jetfit convergence` end to
 * end through the built binary: determinism for a seed (byte-identical
 * files), the truth file's exact columns and values (against the surface
 * formula and finite differences, computed here), outliers, meshes, and
 * bad options (clear message, exit status 2). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "jetfit.h"
#include "jf_test.h"

#define BIN JF_BUILD_DIR "/jetfit"

static char dir[64];

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/jf_gen_XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

static void teardown(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
}

/* Runs "BIN args" in dir; stderr into dir/err.txt; returns exit status. */
static int run(const char *args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >out.txt 2>err.txt", dir, BIN, args);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static char *slurp(const char *name, size_t *len)
{
    char p[256];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    return jf_test_slurp(p, len);
}

static int same_file(const char *a, const char *b)
{
    size_t la, lb;
    char *x = slurp(a, &la), *y = slurp(b, &lb);
    int same = x && y && la == lb && la > 0 && !memcmp(x, y, la);
    free(x);
    free(y);
    return same;
}

static int err_has(const char *needle)
{
    size_t n;
    char *e = slurp("err.txt", &n);
    int has = e && strstr(e, needle) != NULL;
    free(e);
    return has;
}

START_TEST(same_seed_same_bytes)
{
    ck_assert_int_eq(run("generate exp --n 300 --seed 5 --noise 0.01 -o a.ply --truth a.xyz"), 0);
    ck_assert_int_eq(run("generate exp --n 300 --seed 5 --noise 0.01 -o b.ply --truth b.xyz"), 0);
    ck_assert(same_file("a.ply", "b.ply"));
    ck_assert(same_file("a.xyz", "b.xyz"));
    ck_assert_int_eq(run("generate exp --n 300 --seed 6 --noise 0.01 -o c.ply"), 0);
    ck_assert(!same_file("a.ply", "c.ply"));
    ck_assert_int_eq(run("generate ellipsoid --mesh --grid-h 0.2 --seed 3 -o m1.off"), 0);
    ck_assert_int_eq(run("generate ellipsoid --mesh --grid-h 0.2 --seed 3 -o m2.off"), 0);
    ck_assert(same_file("m1.off", "m2.off"));
}
END_TEST

/* Truth columns exactly; values: z = f(x,y) and the normal of the exp
 * graph from central differences of f, here; points = truth x y z. */
START_TEST(truth_columns_and_values)
{
    ck_assert_int_eq(run("generate exp --n 200 --seed 2 -o p.csv --truth t.csv"), 0);
    char p[256];
    jf_eval_table t;
    jf_error e;
    snprintf(p, sizeof p, "%s/t.csv", dir);
    ck_assert_int_eq(jf_eval_table_read(p, &t, &e), JF_OK);
    static const char *names[14] = {"x", "y", "z", "nx", "ny", "nz", "k1", "k2",
                                    "d1x", "d1y", "d1z", "d2x", "d2y", "d2z"};
    ck_assert_uint_eq(t.ncols, 14);
    ck_assert_uint_eq(t.nrows, 200);
    for (int c = 0; c < 14; c++)
        ck_assert_str_eq(t.names[c], names[c]);
    jf_cloud cl;
    snprintf(p, sizeof p, "%s/p.csv", dir);
    ck_assert_int_eq(jf_cloud_read(p, NULL, &cl, &e), JF_OK);
    ck_assert_uint_eq(cl.n, 200);
    for (size_t i = 0; i < t.nrows; i++) {
        const double *r = t.v + i * t.ncols;
        double x = r[0], y = r[1], hh = 1e-5;
        for (int k = 0; k < 3; k++)
            ck_assert(r[k] == cl.xyz[3 * i + k]);
        ck_assert(fabs(x) <= 0.5 && fabs(y) <= 0.5);
        ck_assert(fabs(r[2] - 0.1 * exp(2 * x + y - y * y)) < 1e-15);
#define F(a, b) (0.1 * exp(2 * (a) + (b) - (b) * (b)))
        double fx = (F(x + hh, y) - F(x - hh, y)) / (2 * hh);
        double fy = (F(x, y + hh) - F(x, y - hh)) / (2 * hh);
        double W = sqrt(1 + fx * fx + fy * fy);
        ck_assert(fabs(r[3] + fx / W) < 1e-8 && fabs(r[4] + fy / W) < 1e-8 &&
                  fabs(r[5] - 1 / W) < 1e-8);
        ck_assert(r[6] >= r[7] && r[6] > 0 && r[7] < 0); /* hyperbolic */
    }
    jf_cloud_free(&cl);
    jf_eval_table_free(&t);
    /* the sphere has no principal directions: 8 columns */
    ck_assert_int_eq(run("generate sphere --n 50 -o s.xyz --truth s_t.xyz"), 0);
    snprintf(p, sizeof p, "%s/s_t.xyz", dir);
    ck_assert_int_eq(jf_eval_table_read(p, &t, &e), JF_OK);
    ck_assert_uint_eq(t.ncols, 8);
    for (size_t i = 0; i < t.nrows; i++)
        ck_assert(fabs(t.v[i * 8 + 6] + 1) < 1e-12 && fabs(t.v[i * 8 + 7] + 1) < 1e-12);
    jf_eval_table_free(&t);
}
END_TEST

START_TEST(outliers_and_meshes)
{
    ck_assert_int_eq(run("generate cylinder --n 200 --outliers 0.1 -o o.xyz --truth o_t.csv"), 0);
    char p[256];
    jf_eval_table t;
    jf_error e;
    snprintf(p, sizeof p, "%s/o_t.csv", dir);
    ck_assert_int_eq(jf_eval_table_read(p, &t, &e), JF_OK);
    size_t nan_rows = 0;
    for (size_t i = 0; i < t.nrows; i++)
        nan_rows += isnan(t.v[i * t.ncols + 6]) && isnan(t.v[i * t.ncols + 3]);
    ck_assert_uint_eq(nan_rows, 20);
    jf_eval_table_free(&t);
    /* a triangulated §6.1 grid: (1/h + 1)^2 vertices, 2/h^2 triangles */
    ck_assert_int_eq(run("generate exp --mesh --grid-h 0.125 -o g.ply"), 0);
    jf_cloud c;
    snprintf(p, sizeof p, "%s/g.ply", dir);
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, &e), JF_OK);
    ck_assert_uint_eq(c.n, 81);
    ck_assert_uint_eq(c.nfaces, 128);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(convergence_quick_reproducible)
{
    ck_assert_int_eq(run("convergence --quick --no-plots --out r1"), 0);
    ck_assert_int_eq(run("convergence --quick --no-plots --out r2"), 0);
    ck_assert(same_file("r1/convergence.csv", "r2/convergence.csv"));
    ck_assert(same_file("r1/slopes.csv", "r2/slopes.csv"));
    size_t n;
    char *s = slurp("r1/convergence.csv", &n);
    ck_assert(!strncmp(s, "mode,degree,h,normal_avg,normal_max,kmin_avg,kmin_max,"
                          "kmax_avg,kmax_max\ninterp,1,0.25,", 79));
    free(s);
    s = slurp("r1/slopes.csv", &n);
    ck_assert(!strncmp(s, "mode,degree,normal_slope,kmin_slope,kmax_slope\n", 47));
    free(s);
    ck_assert_int_eq(run("convergence --quick --no-plots --seed 9 --out r3"), 0);
    ck_assert(!same_file("r1/convergence.csv", "r3/convergence.csv"));
}
END_TEST

START_TEST(bad_options)
{
    static const struct {
        const char *args, *msg;
    } cases[] = {
        {"generate klein -o x.ply", "unknown surface 'klein'"},
        {"generate exp", "-o FILE is required"},
        {"generate exp --n 0 -o x.ply", "--n wants a positive integer"},
        {"generate exp --n 12abc -o x.ply", "--n wants a positive integer"},
        {"generate exp --n 10 --grid-h 0.1 -o x.ply", "exclude each other"},
        {"generate exp --mesh --perturb 1.5 -o x.ply", "--perturb wants"},
        {"generate exp --perturb 0.5 -o x.ply", "--perturb applies to grids"},
        {"generate exp --mesh --density stripes -o x.ply", "--density applies"},
        {"generate exp --density wavy -o x.ply", "--density wants"},
        {"generate exp --mesh -o x.xyz", "--mesh needs a .ply or .off"},
        {"generate exp --outliers 2 -o x.ply", "--outliers wants"},
        {"generate exp --noise -1 -o x.ply", "--noise wants"},
        {"generate exp --frobnicate -o x.ply", "unknown option"},
        {"generate exp -o", "option '-o' (--output) needs a value"},
        {"convergence", "-o DIR is required"},
        {"convergence --out d --seed x", "--seed wants"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        ck_assert_msg(run(cases[i].args) == 2, "%s: exit status", cases[i].args);
        ck_assert_msg(err_has(cases[i].msg), "%s: message", cases[i].args);
    }
    char xp[128];
    snprintf(xp, sizeof xp, "%s/x.ply", dir);
    ck_assert(access(xp, F_OK) != 0); /* no output after a usage error */
    /* an output that cannot be written: exit 1 and a message naming it */
    ck_assert_int_eq(run("generate exp --n 10 -o no/such/dir/x.ply"), 1);
    ck_assert(err_has("no/such/dir/x.ply"));
    ck_assert_int_eq(run("generate --help"), 0);
    size_t n;
    char *h = slurp("out.txt", &n);
    const char *flags[] = {"--n", "--grid-h", "--mesh", "--perturb", "--noise ",
                           "--noise-uniform", "--outliers", "--density", "--seed",
                           "--truth"};
    for (size_t i = 0; i < sizeof flags / sizeof flags[0]; i++)
        ck_assert_msg(strstr(h, flags[i]), "help lacks %s", flags[i]);
    free(h);
}
END_TEST

/* Largest and median of v[0..n-1] (sorts v). */
static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Errors of an estimate against a truth file, row by row: sine of the
 * normal angle and relative k1, k2 errors after orienting the estimate
 * along the true normal (flip: k1, k2 -> -k2, -k1). */
static void mesh_errors(const char *est, const char *truth, double med[3], double mx[3])
{
    char p[256];
    jf_eval_table e, t;
    jf_error err;
    snprintf(p, sizeof p, "%s/%s", dir, est);
    ck_assert_int_eq(jf_eval_table_read(p, &e, &err), JF_OK);
    snprintf(p, sizeof p, "%s/%s", dir, truth);
    ck_assert_int_eq(jf_eval_table_read(p, &t, &err), JF_OK);
    ck_assert_uint_eq(e.nrows, t.nrows);
    int en = jf_eval_table_col(&e, "nx"), ek = jf_eval_table_col(&e, "k1");
    ck_assert(en >= 0 && ek == en + 3);
    size_t n = t.nrows;
    double *v[3];
    for (int q = 0; q < 3; q++)
        v[q] = malloc(n * sizeof(double));
    for (size_t i = 0; i < n; i++) {
        const double *a = e.v + i * e.ncols + en, *b = t.v + i * t.ncols + 3;
        double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
        double k1 = d >= 0 ? a[3] : -a[4], k2 = d >= 0 ? a[4] : -a[3];
        v[0][i] = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        v[1][i] = fabs(k1 - b[3]) / fabs(b[3]);
        v[2][i] = fabs(k2 - b[4]) / fabs(b[4]);
    }
    for (int q = 0; q < 3; q++) {
        qsort(v[q], n, sizeof(double), cmp_d);
        med[q] = v[q][n / 2];
        mx[q] = v[q][n - 1];
        free(v[q]);
    }
    jf_eval_table_free(&e);
    jf_eval_table_free(&t);
}

/* `jetfit estimate --neighbors rings` on generated meshes against their
 * exact truth: a closed UV sphere (OFF; poles and seam) and the §6.1
 * graph (PLY, perturbed grid, boundary included). */
START_TEST(estimate_on_generated_meshes)
{
    double med[3], mx[3];
    ck_assert_int_eq(run("generate sphere --mesh --grid-h 0.1 -o s.off --truth s_t.csv"), 0);
    ck_assert_int_eq(run("estimate s.off -o s_e.csv --neighbors rings --degree 2 --quiet"), 0);
    mesh_errors("s_e.csv", "s_t.csv", med, mx);
    ck_assert_msg(mx[0] < 1e-2 && med[0] < 2e-3, "sphere normal %g %g", med[0], mx[0]);
    ck_assert_msg(mx[1] < 0.1 && mx[2] < 0.1 && med[1] < 0.03 && med[2] < 0.03,
                  "sphere k %g %g %g %g", med[1], med[2], mx[1], mx[2]);
    ck_assert_int_eq(run("generate exp --mesh --grid-h 0.03125 -o g.ply --truth g_t.csv"), 0);
    ck_assert_int_eq(run("estimate g.ply -o g_e.csv --neighbors rings --degree 3 --quiet"), 0);
    mesh_errors("g_e.csv", "g_t.csv", med, mx);
    ck_assert_msg(mx[0] < 1e-3 && med[0] < 1e-4, "exp normal %g %g", med[0], mx[0]);
    ck_assert_msg(mx[1] < 0.1 && mx[2] < 0.1 && med[1] < 5e-3 && med[2] < 5e-3,
                  "exp k %g %g %g %g", med[1], med[2], mx[1], mx[2]);
}
END_TEST

/* render: a PNG from a truth file (it has k1 k2 d1 d2), both views; a
 * missing column or a bad option is a clear error. */
START_TEST(render_pictures)
{
    ck_assert_int_eq(run("generate paraboloid --n 400 -o p.xyz --truth t.csv"), 0);
    ck_assert_int_eq(run("render t.csv -o top.png --color aniso --directions --view top --small"), 0);
    ck_assert_int_eq(run("render t.csv -o 3d.png --color gauss --directions --glyphs 50"), 0);
    static const unsigned char magic[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    const char *files[2] = {"top.png", "3d.png"};
    for (int i = 0; i < 2; i++) {
        size_t n;
        char *b = slurp(files[i], &n);
        ck_assert_msg(b && n > 1000 && !memcmp(b, magic, 8), "%s is not a PNG", files[i]);
        free(b);
    }
    /* p.xyz has x y z only: colouring needs k1 k2 */
    ck_assert_int_eq(run("render p.xyz -o x.png"), 1);
    ck_assert(err_has("needs k1 k2"));
    ck_assert_int_eq(run("render p.xyz -o x.png --color none"), 0);
    ck_assert_int_eq(run("render t.csv -o x.jpg"), 2);
    ck_assert(err_has("-o wants a .png file"));
    ck_assert_int_eq(run("render t.csv -o x.png --color curl"), 2);
    ck_assert(err_has("--color wants"));
    ck_assert_int_eq(run("render t.csv -o x.png --view sideways"), 2);
    ck_assert(err_has("--view wants"));
    ck_assert_int_eq(run("render missing.csv -o x.png"), 1);
    ck_assert(err_has("missing.csv"));
}
END_TEST

int main(void)
{
    Suite *s = suite_create("generate_cli");
    TCase *tc = tcase_create("cli");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, same_seed_same_bytes);
    tcase_add_test(tc, truth_columns_and_values);
    tcase_add_test(tc, outliers_and_meshes);
    tcase_add_test(tc, convergence_quick_reproducible);
    tcase_add_test(tc, bad_options);
    tcase_add_test(tc, render_pictures);
    tcase_add_test(tc, estimate_on_generated_meshes);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
