/* cmd_generate.c -- `jetfit generate SURFACE -o FILE ...`: the paper's
 * surfaces (src/synth/surfaces.c) as clouds or triangulated meshes, with exact
 * ground truth and the noise models of issue 6.  Deterministic: the same
 * arguments and --seed give the same bytes. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "args.h"
#include "cmd.h"
#include "pipes.h"
#include "jetfit.h"
#include "surfaces.h"

#define DEFAULT_N 10000

static int gen_write(jf_surface surf, const char *surf_name, int grid, int mesh, double grid_h,
                     double perturb, unsigned long long n, jf_density density,
                     unsigned long long seed, double noise, double noise_u, double outliers,
                     const char *truth, int ascii, const char *out);

static void usage(FILE *out)
{
    fprintf(out,
        "usage: jetfit generate SURFACE -o FILE [--n N | --grid-h H] [--mesh]\n"
        "         [--perturb D] [--noise S] [--noise-uniform S] [--outliers F]\n"
        "         [--density uniform|gradient|stripes] [--seed S] [--truth FILE]\n"
        "         [--ascii]\n"
        "\n"
        "SURFACE (parameter domain; normal; k1 >= k2 signed w.r.t. the normal):\n"
        "  exp         z = 0.1 exp(2x + y - y^2), [-0.5,0.5]^2 (the paper's 6.1)\n"
        "  paraboloid  z = 2x^2 + y^2, [-1,1]^2 (Fig. 1; umbilics at (+-1/4, 0))\n"
        "  revolution  z = 0.1 sin(10 sqrt(x^2+y^2)), [-0.4,0.4]^2 (Fig. 2;\n"
        "              parabolic circles r = pi/20 and pi/10, K = 0; a cone\n"
        "              point at 0: its truth row is NaN)\n"
        "              graphs: upward normal; sampled uniformly in (x, y)\n"
        "  sphere      radius 1; area-uniform samples\n"
        "  ellipsoid   x^2 + (y/0.75)^2 + (z/0.5)^2 = 1; area-uniform samples\n"
        "  cylinder    radius 0.5, z in [-1,1], open; area-uniform samples\n"
        "  torus       (sqrt(x^2+y^2) - 1)^2 + z^2 = 0.4^2 (closed, with a hole;\n"
        "              hyperbolic inside); area-uniform samples\n"
        "              closed surfaces: outward normal (so convex k < 0)\n"
        "\n"
        "  -o, --output FILE  output: .ply (binary; --ascii for ascii), .off, .xyz,\n"
        "                   .txt, .csv, .las (a mesh needs .ply or .off); '-' is\n"
        "                   standard output (with --output-format)\n"
        "  --output-format FMT  write FMT (ply off xyz txt csv las) whatever the name\n"
        "  --n N            N random samples (default %d); with --mesh, a grid\n"
        "                   of about N vertices\n"
        "  --grid-h H       a grid of side H in parameter space instead (graphs:\n"
        "                   x,y; sphere/ellipsoid: theta,phi in radians; cylinder,\n"
        "                   torus: arc length); vertices only unless --mesh\n"
        "  --mesh           triangulated grid (graphs: squares split along one\n"
        "                   diagonal; sphere/ellipsoid: closed UV mesh with one\n"
        "                   vertex per pole; cylinder: open tube; torus: closed)\n"
        "  --perturb D      grids: move each vertex by (d h, d' h), d, d' uniform\n"
        "                   in [0, D] (default 0.9, the paper's 6.1; 0 = regular)\n"
        "  --noise S        Gaussian noise, sigma = S x bounding-box diagonal,\n"
        "                   on each coordinate\n"
        "  --noise-uniform S  PCPNet's \"white\" noise: each coordinate +\n"
        "                   U[-1/2, 1/2] x S x largest bounding-box side\n"
        "  --outliers F     replace a fraction F of the points by points uniform\n"
        "                   in the bounding box; their truth rows are NaN\n"
        "  --density M      random clouds only: uniform (default); gradient (keep\n"
        "                   probability 0.05 + 0.95 t along x, t in [0,1]);\n"
        "                   stripes (10 stripes across x, every other one keeps\n"
        "                   10%%)\n"
        "  --seed S         random seed, a 64-bit integer (default 1)\n"
        "  --truth FILE     exact truth, one row per point in output order:\n"
        "                   x y z nx ny nz k1 k2 [d1x d1y d1z d2x d2y d2z]\n"
        "                   (.csv, or .xyz/.txt with a '# names' header, or .ply;\n"
        "                   x y z is the noise-free point (an outlier: itself);\n"
        "                   d1, d2 are written for\n"
        "                   every surface but the sphere and are NaN at umbilics)\n"
        "  --ascii          ascii PLY\n"
        "  -h, --help       this text\n",
        DEFAULT_N);
}

static int fail(const char *fmt, const char *arg)
{
    fprintf(stderr, "jetfit generate: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (jetfit generate --help)\n");
    return 2;
}

static int parse_double(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    return end == s || *end || errno || !isfinite(*v) ? -1 : 0;
}

static int parse_u64(const char *s, unsigned long long *v)
{
    char *end;
    errno = 0;
    if (*s == '-' || *s == '+')
        return -1;
    *v = strtoull(s, &end, 10);
    return end == s || *end || errno ? -1 : 0;
}

static int has_ext(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *sl = strrchr(path, '/');
    if (!dot || (sl && dot < sl))
        return 0;
    return !strcasecmp(dot, ext);
}

/* A random cloud without truth, noise or outliers, written a chunk of
 * 2^20 points at a time (issue 12.1: 10^8 points without holding their
 * parameters and truth).  jf_sample_random draws point after point from
 * rng, so chunks give the points of one call, and the writer the bytes
 * of jf_cloud_write. */
static int stream_random(jf_surface surf, const char *surf_name, uint64_t n, jf_density d,
                         jf_rng *rng, const char *out, int ascii)
{
    enum { CHUNK = 1 << 20 };
    static const jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    jf_error err = {{0}};
    jf_writer *w = NULL;
    if (n > (uint64_t)UINT32_MAX - 2) {
        fprintf(stderr, "jetfit generate: --n %llu: at most 2^32 - 2 points\n",
                (unsigned long long)n);
        return 1;
    }
    jf_status st = jf_writer_open(out, cols, 3, (size_t)n, ascii, &w, &err);
    for (uint64_t k = 0; st == JF_OK && k < n; k += CHUNK) {
        jf_sample s;
        size_t m = n - k < CHUNK ? (size_t)(n - k) : CHUNK;
        if ((st = jf_sample_random(surf, m, d, rng, &s)) != JF_OK) {
            fprintf(stderr, "jetfit generate: cannot sample %s: %s\n", surf_name,
                    jf_strerror(st));
            jf_writer_abort(w);
            return 1;
        }
        st = jf_writer_rows(w, s.xyz, m, 1); /* binary rows: copying, not worth threads */
        jf_sample_free(&s);
    }
    if (w) st = jf_writer_commit(w, &err);
    if (st) {
        fprintf(stderr, "jetfit generate: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        return 1;
    }
    return 0;
}

static jf_status write_truth(const char *path, const jf_sample *s, int dirs,
                             int ascii, jf_error *err)
{
    static const char *names[14] = {"x", "y", "z", "nx", "ny", "nz", "k1",
                                    "k2", "d1x", "d1y", "d1z", "d2x", "d2y",
                                    "d2z"};
    jf_column cols[14];
    size_t nc = dirs ? 14 : 8;
    for (size_t c = 0; c < nc; c++) {
        cols[c].name = names[c];
        cols[c].type = JF_COL_F64;
    }
    jf_writer *w;
    jf_status st = jf_writer_open(path, cols, nc, s->n, ascii, &w, err);
    if (st)
        return st;
    double *xyz = malloc((s->n ? s->n : 1) * 3 * sizeof *xyz); /* .las: its frame */
    if (!xyz) {
        jf_writer_abort(w);
        return JF_ERR_NOMEM;
    }
    for (size_t i = 0; i < s->n; i++)
        memcpy(xyz + 3 * i, s->truth[i].xyz, 3 * sizeof *xyz);
    (void)jf_writer_las_frame(w, xyz, s->n);
    free(xyz);
    for (size_t i = 0; i < s->n && !st; i++) {
        const jf_truth *t = &s->truth[i];
        double row[14] = {t->xyz[0], t->xyz[1], t->xyz[2], t->normal[0],
                          t->normal[1], t->normal[2], t->k1, t->k2,
                          t->d1[0], t->d1[1], t->d1[2], t->d2[0], t->d2[1],
                          t->d2[2]};
        st = jf_writer_row(w, row);
    }
    if (st) {
        jf_writer_abort(w);
        snprintf(err->msg, sizeof err->msg, "%s: %s", path, jf_strerror(st));
        return st;
    }
    return jf_writer_commit(w, err);
}

int jf_cmd_generate(int argc, char **argv)
{
    const char *out = NULL, *truth = NULL, *surf_name = NULL;
    double grid_h = 0, perturb = 0.9, noise = 0, noise_u = 0, outliers = 0;
    unsigned long long n = 0, seed = 1;
    int mesh = 0, ascii = 0, have_perturb = 0;
    jf_density density = JF_DENSITY_UNIFORM;

    static const jf_cli_optdef optdefs[] = {
        {"--output", 1, 'o', NULL},
        {"--output-format", 1, 0, NULL},
        {"--help", 0, 'h', NULL},
        {"--mesh", 0, 0, NULL},
        {"--ascii", 0, 0, NULL},
        {"--truth", 1, 0, NULL},
        {"--n", 1, 0, NULL},
        {"--seed", 1, 0, NULL},
        {"--density", 1, 0, NULL},
        {"--grid-h", 1, 0, NULL},
        {"--perturb", 1, 0, NULL},
        {"--noise", 1, 0, NULL},
        {"--noise-uniform", 1, 0, NULL},
        {"--outliers", 1, 0, NULL},
        {NULL, 0, 0, NULL}};
    const jf_cli_optdef *const tables[] = {optdefs, NULL};
    const char *out_fmt = NULL;
    jf_cli_args args;
    jf_cli_args_init(&args, argc, argv, tables);
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        const char *a = args.name, *v = args.val;
        if (k == JF_CLI_ERROR)
            return fail("%s", args.err);
        if (k == JF_CLI_OPERAND) {
            if (surf_name)
                return fail("unexpected argument '%s'", v);
            surf_name = v;
            continue;
        }
        if (!strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(a, "--mesh")) {
            mesh = 1;
            continue;
        }
        if (!strcmp(a, "--ascii")) {
            ascii = 1;
            continue;
        }
        double d;
        if (!strcmp(a, "--output")) {
            out = v;
        } else if (!strcmp(a, "--output-format")) {
            out_fmt = v;
        } else if (!strcmp(a, "--truth")) {
            truth = v;
        } else if (!strcmp(a, "--n")) {
            if (parse_u64(v, &n) || n == 0)
                return fail("--n wants a positive integer, not '%s'", v);
        } else if (!strcmp(a, "--seed")) {
            if (parse_u64(v, &seed))
                return fail("--seed wants a non-negative integer, not '%s'", v);
        } else if (!strcmp(a, "--density")) {
            if (!strcmp(v, "uniform"))
                density = JF_DENSITY_UNIFORM;
            else if (!strcmp(v, "gradient"))
                density = JF_DENSITY_GRADIENT;
            else if (!strcmp(v, "stripes"))
                density = JF_DENSITY_STRIPES;
            else
                return fail("--density wants uniform, gradient or stripes, not '%s'", v);
        } else if (parse_double(v, &d)) {
            return fail("bad number '%s'", v);
        } else if (!strcmp(a, "--grid-h")) {
            if (!(d > 0))
                return fail("--grid-h wants a positive length, not '%s'", v);
            grid_h = d;
        } else if (!strcmp(a, "--perturb")) {
            if (!(d >= 0 && d < 1))
                return fail("--perturb wants D in [0, 1), not '%s'", v);
            perturb = d;
            have_perturb = 1;
        } else if (!strcmp(a, "--noise")) {
            if (!(d >= 0))
                return fail("--noise wants S >= 0, not '%s'", v);
            noise = d;
        } else if (!strcmp(a, "--noise-uniform")) {
            if (!(d >= 0))
                return fail("--noise-uniform wants S >= 0, not '%s'", v);
            noise_u = d;
        } else if (!strcmp(a, "--outliers")) {
            if (!(d >= 0 && d <= 1))
                return fail("--outliers wants F in [0, 1], not '%s'", v);
            outliers = d;
        }
    }
    jf_surface surf;
    if (!surf_name)
        return fail("%s", "which SURFACE? (exp, paraboloid, revolution, sphere, ellipsoid, cylinder, torus)");
    if (jf_surface_parse(surf_name, &surf))
        return fail("unknown surface '%s' (exp, paraboloid, revolution, sphere, ellipsoid, cylinder, torus)", surf_name);
    if (!out)
        return fail("%s", "-o FILE is required");
    if (n && grid_h > 0)
        return fail("%s", "--n and --grid-h exclude each other");
    int grid = mesh || grid_h > 0;
    if (!grid && have_perturb)
        return fail("%s", "--perturb applies to grids (--grid-h or --mesh)");
    if (grid && density != JF_DENSITY_UNIFORM)
        return fail("%s", "--density applies to random clouds (not --grid-h or --mesh)");
    /* "-o -" and --output-format: through a private file (pipes.h) */
    jf_cli_out po;
    jf_error perr = {{0}};
    if (jf_cli_out_begin(&po, out, out_fmt, &perr))
        return fail("%s", perr.msg);
    const char *shown = out;
    out = po.path;
    if (mesh && !has_ext(out, ".ply") && !has_ext(out, ".off")) {
        jf_cli_out_finish(&po, 0, NULL);
        return fail("--mesh needs a .ply or .off output, not '%s'", shown);
    }
    int rc = gen_write(surf, surf_name, grid, mesh, grid_h, perturb, n, density, seed, noise,
                       noise_u, outliers, truth, ascii, out);
    if (jf_cli_out_finish(&po, rc == 0, &perr)) {
        fprintf(stderr, "jetfit generate: %s\n", perr.msg);
        return 1;
    }
    return rc;
}

/* Samples and writes (out: the file to write, maybe a private one). */
static int gen_write(jf_surface surf, const char *surf_name, int grid, int mesh, double grid_h,
                     double perturb, unsigned long long n, jf_density density,
                     unsigned long long seed, double noise, double noise_u, double outliers,
                     const char *truth, int ascii, const char *out)
{
    jf_rng rng;
    jf_rng_seed(&rng, (uint64_t)seed);
    jf_sample s;
    jf_status st;
    if (!grid && !truth && !(noise > 0) && !(noise_u > 0) && !(outliers > 0) &&
        !has_ext(out, ".off") && !has_ext(out, ".las")) /* LAS: needs the bbox first */
        return stream_random(surf, surf_name, n ? n : DEFAULT_N, density, &rng, out, ascii);
    if (grid) {
        double h = grid_h > 0 ? grid_h : jf_sample_grid_h_for(surf, n ? n : DEFAULT_N);
        st = jf_sample_grid(surf, h, perturb, mesh, &rng, &s);
    } else {
        st = jf_sample_random(surf, n ? n : DEFAULT_N, density, &rng, &s);
    }
    if (st) {
        fprintf(stderr, "jetfit generate: cannot sample %s: %s\n", surf_name,
                jf_strerror(st));
        return 1;
    }
    /* noise after truth, outliers last (uniform in the noisy bbox) */
    if (noise > 0)
        jf_noise_gauss(&s, noise, &rng);
    if (noise_u > 0)
        jf_noise_uniform(&s, noise_u, &rng);
    if (outliers > 0)
        jf_noise_outliers(&s, outliers, &rng);

    jf_cloud c = {.n = s.n, .xyz = s.xyz, .nfaces = s.nfaces,
                  .face_off = s.face_off, .face_idx = s.face_idx};
    jf_error err = {{0}};
    st = jf_cloud_write(out, &c, ascii, &err);
    if (!st && truth)
        st = write_truth(truth, &s, jf_surface_has_directions(surf), ascii, &err);
    jf_sample_free(&s);
    if (st) {
        fprintf(stderr, "jetfit generate: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        return 1;
    }
    return 0;
}
