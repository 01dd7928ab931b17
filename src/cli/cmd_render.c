/* cmd_render.c -- `jetfit render RESULT -o FILE.png [--color ...]
 * [--directions]`: a picture of a jetfit result (or a generate truth
 * file), points coloured by a curvature, with principal-direction glyphs
 * (kmax = d1 red, kmin = d2 blue, as the paper's colour plates), drawn by
 * gnuplot (pngcairo; already the plotting dependency of convergence).
 *
 * design: read the table (jf_eval_table_read: .csv, .xyz/.txt with a
 * '# names' header, .ply vertex properties); colour range from the 2nd
 * and 98th percentiles (one outlier must not wash the picture out),
 * symmetric about 0 with a diverging palette when the values change sign
 * (so K = 0, the parabolic lines, is the neutral colour); glyphs on at
 * most --glyphs points, one per cell of a screen-space grid, each a
 * segment centred on its point; everything is piped to gnuplot as inline
 * data blocks (no temporary files). */
#define _POSIX_C_SOURCE 200809L /* popen, pclose */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/wait.h>

#include "args.h"
#include "cmd.h"
#include "gnuplot.h"
#include "pipes.h"
#include "jetfit.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static void usage(FILE *out)
{
    fprintf(out,
        "usage: jetfit render RESULT -o FILE.png [--color k1|k2|mean|gauss|aniso|none]\n"
        "         [--directions] [--view top|3d|ROTX,ROTZ] [--glyphs N]\n"
        "         [--point-size S] [--title TEXT] [--size W,H] [--small]\n"
        "\n"
        "  RESULT        jetfit estimate output or a generate truth file (.ply,\n"
        "                .csv, .xyz/.txt, .las): columns x y z, k1 k2 for --color,\n"
        "                d1x..d2z for --directions (mesh faces are not drawn:\n"
        "                the vertices are)\n"
        "  -o, --output FILE.png  the picture (PNG, gnuplot's pngcairo terminal)\n"
        "  --color Q     k1 (kmax), k2 (kmin), mean (k1+k2)/2 (default), gauss\n"
        "                k1 k2, aniso (k1 - k2)/(|k1| + |k2|) (0 at umbilics), or\n"
        "                none; range =\n"
        "                2nd..98th percentile, symmetric\n"
        "                about 0 (purple < 0 < green) when the values change sign\n"
        "  --directions  principal directions: kmax (d1) red, kmin (d2) blue\n"
        "  --view V      top (x-y plane, for graphs z = f(x,y)), 3d (default:\n"
        "                gnuplot's rotation 60,30), or ROTX,ROTZ in degrees\n"
        "  --glyphs N    at most N direction glyphs, spread over the picture\n"
        "                (default 400)\n"
        "  --point-size S  gnuplot point size (default: from the point count)\n"
        "  --title TEXT  a title (default: the file name and the colour)\n"
        "  --size W,H    pixels (default 800,700)\n"
        "  --small       gnuplot's libgd png terminal (256 colours, no\n"
        "                anti-aliasing): files several times smaller\n"
        "  --input-format FMT  read RESULT as FMT (ply csv xyz txt las); '-' as\n"
        "                RESULT is standard input (jetfit estimate ... -o - | ...)\n"
        "  -h, --help    this text\n");
}

static int bad(const char *fmt, const char *arg)
{
    fprintf(stderr, "jetfit render: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (jetfit render --help)\n");
    return 2;
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Quantile q of the finite values of v (sorted copy in tmp). */
static double quantile(double *tmp, size_t n, double q)
{
    if (!n)
        return NAN;
    double pos = q * (double)(n - 1);
    size_t i = (size_t)pos;
    double f = pos - (double)i;
    return i + 1 < n ? tmp[i] * (1 - f) + tmp[i + 1] * f : tmp[i];
}

/* Screen coordinates of p for the view (gnuplot: rotate about z by rotz,
 * then about x by rotx; top view is rotx = rotz = 0) and its depth
 * (larger = nearer the viewer; checked against gnuplot's `set view`). */
static double project(const double p[3], double rotx, double rotz, double s[2])
{
    double cz = cos(rotz), sz = sin(rotz), cx = cos(rotx), sx = sin(rotx);
    double x = cz * p[0] + sz * p[1], y = -sz * p[0] + cz * p[1];
    s[0] = x;
    s[1] = cx * y + sx * p[2];
    return cx * p[2] - sx * y;
}

typedef struct {
    double depth;
    size_t i;
} by_depth;

static int cmp_depth(const void *a, const void *b)
{
    const by_depth *x = a, *y = b;
    if (x->depth != y->depth)
        return x->depth < y->depth ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

typedef struct {
    int x, y, z, k1, k2, d1, d2; /* column indices (d1, d2: of d1x, d2x) */
} cols;

int jf_cmd_render(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *color = "mean", *title = NULL;
    int dirs = 0, small = 0, top = 0, w = 800, hgt = 700;
    double rotx = 60, rotz = 30, ps = 0;
    unsigned long glyphs = 400;
    static const jf_cli_optdef optdefs[] = {
        {"--output", 1, 'o', NULL},
        {"--help", 0, 'h', NULL},
        {"--directions", 0, 0, NULL},
        {"--small", 0, 0, NULL},
        {"--color", 1, 0, NULL},
        {"--view", 1, 0, NULL},
        {"--glyphs", 1, 0, NULL},
        {"--point-size", 1, 0, NULL},
        {"--title", 1, 0, NULL},
        {"--size", 1, 0, NULL},
        {"--input-format", 1, 0, NULL},
        {NULL, 0, 0, NULL}};
    const char *in_fmt = NULL;
    const jf_cli_optdef *const tables[] = {optdefs, NULL};
    jf_cli_args args;
    jf_cli_args_init(&args, argc, argv, tables);
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        const char *a = args.name, *v = args.val;
        if (k == JF_CLI_ERROR)
            return bad("%s", args.err);
        if (k == JF_CLI_OPERAND) {
            if (in)
                return bad("unexpected argument '%s'", v);
            in = v;
            continue;
        }
        if (!strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(a, "--directions")) {
            dirs = 1;
            continue;
        }
        if (!strcmp(a, "--small")) {
            small = 1;
            continue;
        }
        char *end;
        if (!strcmp(a, "--output")) {
            out = v;
        } else if (!strcmp(a, "--input-format")) {
            in_fmt = v;
        } else if (!strcmp(a, "--title")) {
            title = v;
        } else if (!strcmp(a, "--color")) {
            if (strcmp(v, "k1") && strcmp(v, "k2") && strcmp(v, "mean") &&
                strcmp(v, "gauss") && strcmp(v, "aniso") && strcmp(v, "none"))
                return bad("--color wants k1, k2, mean, gauss, aniso or none, not '%s'", v);
            color = v;
        } else if (!strcmp(a, "--view")) {
            if (!strcmp(v, "top")) {
                top = 1;
                rotx = rotz = 0;
            } else if (!strcmp(v, "3d")) {
                top = 0;
            } else if (sscanf(v, "%lf,%lf", &rotx, &rotz) != 2 ||
                       !isfinite(rotx) || !isfinite(rotz)) {
                return bad("--view wants top, 3d or ROTX,ROTZ, not '%s'", v);
            }
        } else if (!strcmp(a, "--glyphs")) {
            errno = 0;
            glyphs = strtoul(v, &end, 10);
            if (end == v || *end || errno || *v == '-' || glyphs > 100000)
                return bad("--glyphs wants a count 0..100000, not '%s'", v);
        } else if (!strcmp(a, "--point-size")) {
            ps = strtod(v, &end);
            if (end == v || *end || !(ps > 0 && ps < 100))
                return bad("--point-size wants a positive number, not '%s'", v);
        } else if (!strcmp(a, "--size")) {
            if (sscanf(v, "%d,%d", &w, &hgt) != 2 || w < 64 || hgt < 64 ||
                w > 8000 || hgt > 8000)
                return bad("--size wants W,H in 64..8000, not '%s'", v);
        }
    }
    if (!in)
        return bad("%s", "which RESULT file?");
    if (!out)
        return bad("%s", "-o FILE.png is required");
    size_t lo = strlen(out);
    if (lo < 4 || strcasecmp(out + lo - 4, ".png"))
        return bad("-o wants a .png file, not '%s'", out);
    for (const char *q = out; *q; q++)
        if ((unsigned char)*q < 0x20 || *q == 0x7f)
            return bad("%s", "the output name has a control character");
    if (jf_same_file(in, out)) {
        fprintf(stderr, "jetfit render: %s: is the input file (%s)\n", out, in);
        return 2;
    }

    jf_eval_table t;
    jf_error err = {{0}};
    jf_cli_in rin; /* '-' and --input-format (pipes.h) */
    jf_status st = jf_cli_in_begin(&rin, in, in_fmt, &err);
    if (st == JF_OK) st = jf_eval_table_read(rin.path, &t, &err);
    jf_cli_in_end(&rin, st ? &err : NULL);
    if (st) {
        fprintf(stderr, "jetfit render: %s\n", err.msg[0] ? err.msg : jf_strerror(st));
        return 1;
    }
    cols c = {jf_eval_table_col(&t, "x"), jf_eval_table_col(&t, "y"),
              jf_eval_table_col(&t, "z"), jf_eval_table_col(&t, "k1"),
              jf_eval_table_col(&t, "k2"), jf_eval_table_col(&t, "d1x"),
              jf_eval_table_col(&t, "d2x")};
    int need_k = strcmp(color, "none") != 0;
    const char *missing = c.x < 0 || c.y < 0 || c.z < 0 ? "x y z"
                          : need_k && (c.k1 < 0 || c.k2 < 0) ? "k1 k2 (or use --color none)"
                          : dirs && (c.d1 < 0 || c.d2 < 0) ? "d1x..d2z"
                          : NULL;
    if (missing || t.nrows == 0) {
        fprintf(stderr, "jetfit render: %s: %s\n", in,
                missing ? "missing columns" : "no rows");
        if (missing)
            fprintf(stderr, "jetfit render: needs %s\n", missing);
        jf_eval_table_free(&t);
        return 1;
    }
    size_t finite = 0;
    for (size_t i = 0; i < t.nrows; i++) {
        const double *r = t.v + i * t.ncols;
        finite += isfinite(r[c.x]) && isfinite(r[c.y]) && isfinite(r[c.z]);
    }
    if (!finite) {
        fprintf(stderr, "jetfit render: %s: no row has finite x y z: nothing to draw\n", in);
        jf_eval_table_free(&t);
        return 1;
    }
    size_t n = t.nrows, nc = t.ncols;
    double *val = malloc(n * sizeof *val), *tmp = malloc(n * sizeof *tmp);
    unsigned char *take = calloc(n, 1);
    by_depth *ord = malloc(n * sizeof *ord); /* painter's order, below */
    if (!val || !tmp || !take || !ord) {
        fprintf(stderr, "jetfit render: out of memory\n");
        free(val), free(tmp), free(take), free(ord);
        jf_eval_table_free(&t);
        return 1;
    }
    size_t nfin = 0;
    double smin[2] = {INFINITY, INFINITY}, smax[2] = {-INFINITY, -INFINITY};
    rotx *= M_PI / 180.0;
    rotz *= M_PI / 180.0;
    for (size_t i = 0; i < n; i++) {
        const double *r = t.v + i * nc;
        double k1 = need_k ? r[c.k1] : 0, k2 = need_k ? r[c.k2] : 0;
        val[i] = !strcmp(color, "k1") ? k1 : !strcmp(color, "k2") ? k2
                 : !strcmp(color, "gauss") ? k1 * k2
                 : !strcmp(color, "aniso") ? (k1 - k2) / (fabs(k1) + fabs(k2))
                 : 0.5 * (k1 + k2);
        if (isfinite(val[i]))
            tmp[nfin++] = val[i];
        double s[2];
        ord[i].depth = project(r + c.x, rotx, rotz, s);
        ord[i].i = i;
        if (!isfinite(ord[i].depth))
            ord[i].depth = -INFINITY;
        for (int k = 0; k < 2; k++)
            if (isfinite(s[k])) {
                smin[k] = fmin(smin[k], s[k]);
                smax[k] = fmax(smax[k], s[k]);
            }
    }
    qsort(tmp, nfin, sizeof *tmp, cmp_dbl);
    double vlo = quantile(tmp, nfin, 0.02), vhi = quantile(tmp, nfin, 0.98);
    if (!strcmp(color, "aniso"))
        vlo = 0.0; /* an absolute scale: 0 is an umbilic */
    int diverging = vlo < 0 && vhi > 0;
    if (diverging)
        vhi = fmax(-vlo, vhi), vlo = -vhi;
    if (!(vhi > vlo))
        vhi = vlo + 1e-12 + fabs(vlo) * 1e-6;
    /* painter's order: far points first, so near ones cover them
     * (gnuplot does not depth-sort points) */
    qsort(ord, n, sizeof *ord, cmp_depth);
    /* glyphs: the nearest point of each cell of a g x g screen grid */
    double span = fmax(smax[0] - smin[0], smax[1] - smin[1]);
    int g = (int)ceil(sqrt((double)glyphs));
    double cell = g ? span / g : 0, len = 0.8 * cell;
    if (dirs && g > 0 && span > 0) {
        size_t *best = malloc((size_t)g * g * sizeof *best);
        for (size_t k = 0; best && k < (size_t)g * g; k++)
            best[k] = SIZE_MAX;
        for (size_t k = 0; best && k < n; k++) { /* far to near */
            size_t i = ord[k].i;
            const double *r = t.v + i * nc;
            double s[2];
            project(r + c.x, rotx, rotz, s);
            if (!isfinite(r[c.d1]) || !isfinite(r[c.d2]) || !isfinite(s[0]) || !isfinite(s[1]))
                continue;
            int a = (int)fmin(g - 1, (s[0] - smin[0]) / cell);
            int b = (int)fmin(g - 1, (s[1] - smin[1]) / cell);
            best[(size_t)b * g + a] = i;
        }
        for (size_t k = 0; best && k < (size_t)g * g; k++)
            if (best[k] != SIZE_MAX)
                take[best[k]] = 1;
        free(best);
    }
    if (ps <= 0)
        ps = n > 100000 ? 0.15 : n > 20000 ? 0.3 : n > 4000 ? 0.5 : 0.8;

    /* the picture goes to a temporary beside FILE.png, renamed on success:
     * an old picture survives a failure, and a missing folder is found
     * before gnuplot runs */
    jf_tmpfile tf;
    jf_gp gpr;
    char why[600];
    if (jf_tmpfile_open(out, &tf, &err) != JF_OK) {
        fprintf(stderr, "jetfit render: %s\n", err.msg);
        free(val), free(tmp), free(take), free(ord);
        jf_eval_table_free(&t);
        return 1;
    }
    if (jf_gp_open(&gpr, &tf.fd, 1, why, sizeof why) != 0) {
        fprintf(stderr, "jetfit render: %s\n", why);
        jf_tmpfile_discard(&tf);
        free(val), free(tmp), free(take), free(ord);
        jf_eval_table_free(&t);
        return 1;
    }
    FILE *gp = gpr.in;
    if (small)
        fprintf(gp, "set terminal png size %d,%d noenhanced\n", w, hgt);
    else
        fprintf(gp, "set terminal pngcairo size %d,%d font ',10' noenhanced\n", w, hgt);
    jf_gp_output(gp, tf.fd);
    char def_title[600];
    const char *base = strrchr(in, '/') ? strrchr(in, '/') + 1 : in;
    snprintf(def_title, sizeof def_title, "%s: %s%s", base,
             need_k ? color : "points", dirs ? "; kmax red, kmin blue" : "");
    fprintf(gp, "set title ");
    jf_gp_quote(gp, title ? title : def_title);
    fprintf(gp, "\nunset key\nset border 0\nunset xtics\nunset ytics\nunset ztics\n");
    fprintf(gp, diverging ? "set palette defined (0 '#762a83', 0.5 '#f2f2f2', 1 '#1b7837')\n"
                          : "set palette defined (0 '#440154', 0.25 '#3b528b', 0.5 '#21918c', 0.75 '#5ec962', 1 '#fde725')\n");
    if (need_k) {
        /* curvatures are 1/length (the input's unit); gauss 1/length^2;
         * aniso is a ratio */
        const char *unit = !strcmp(color, "gauss")   ? " (1/length^2)"
                           : !strcmp(color, "aniso") ? " (no unit)"
                                                     : " (1/length)";
        fprintf(gp, "set cbrange [%.9g:%.9g]\nset cblabel '%s%s'\n", vlo, vhi, color, unit);
    } else {
        fprintf(gp, "unset colorbox\n");
    }
    /* data: x y z value; glyph segments: x y z dx dy dz, per direction */
    fprintf(gp, "$pts << EOD\n");
    for (size_t k = 0; k < n; k++) {
        size_t i = ord[k].i;
        const double *r = t.v + i * nc;
        if (isfinite(r[c.x]) && isfinite(r[c.y]) && isfinite(r[c.z]))
            fprintf(gp, "%.9g %.9g %.9g %.9g\n", r[c.x], r[c.y], r[c.z],
                    need_k ? (isfinite(val[i]) ? val[i] : NAN) : 0.0);
    }
    fprintf(gp, "EOD\n");
    for (int d = 0; dirs && d < 2; d++) {
        fprintf(gp, "$dir%d << EOD\n", d + 1);
        for (size_t i = 0; i < n; i++) {
            if (!take[i])
                continue;
            const double *r = t.v + i * nc, *dv = r + (d ? c.d2 : c.d1);
            fprintf(gp, "%.9g %.9g %.9g %.9g %.9g %.9g\n", r[c.x] - 0.5 * len * dv[0],
                    r[c.y] - 0.5 * len * dv[1], r[c.z] - 0.5 * len * dv[2],
                    len * dv[0], len * dv[1], len * dv[2]);
        }
        fprintf(gp, "EOD\n");
    }
    const char *pts = need_k ? "lc palette" : "lc rgb '#707070'";
    if (top) {
        fprintf(gp, "set size ratio -1\nplot $pts using 1:2%s with points pt 7 ps %g %s",
                need_k ? ":4" : "", ps, pts);
        if (dirs)
            fprintf(gp, ", $dir1 using 1:2:4:5 with vectors nohead lw 2 lc rgb '#e41a1c'"
                        ", $dir2 using 1:2:4:5 with vectors nohead lw 2 lc rgb '#1f4fd8'");
    } else {
        fprintf(gp, "set view %g,%g,1.5\nset view equal xyz\nset xyplane 0\n",
                rotx * 180.0 / M_PI, rotz * 180.0 / M_PI);
        fprintf(gp, "splot $pts using 1:2:3%s with points pt 7 ps %g %s",
                need_k ? ":4" : "", ps, pts);
        if (dirs)
            fprintf(gp, ", $dir1 using 1:2:3:4:5:6 with vectors nohead lw 2 lc rgb '#e41a1c'"
                        ", $dir2 using 1:2:3:4:5:6 with vectors nohead lw 2 lc rgb '#1f4fd8'");
    }
    fprintf(gp, "\nset output\n"); /* closes the picture before gnuplot exits */
    int rc = jf_gp_close(&gpr, why, sizeof why);
    if (rc == 0)
        rc = jf_gp_png_whole(tf.fd, why, sizeof why);
    free(val), free(tmp), free(take), free(ord);
    jf_eval_table_free(&t);
    if (rc != 0) {
        jf_tmpfile_discard(&tf);
        fprintf(stderr, "jetfit render: %s: %s\n", out, why);
        return 1;
    }
    if (jf_tmpfile_commit(&tf, out, &err) != JF_OK) {
        fprintf(stderr, "jetfit render: %s\n", err.msg);
        return 1;
    }
    return 0;
}
