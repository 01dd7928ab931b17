/* cmd_convergence.c -- `jetfit convergence -o DIR [--quick]`: the §6.1
 * experiment end to end (src/synth/convergence.c), its tables and the plots of
 * Figures 5-12 made with gnuplot (optional: without it the CSVs are still
 * written and a note goes to stderr). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "args.h"
#include "cmd.h"
#include "gnuplot.h"
#include "convergence.h"
#include "jetfit.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: jetfit convergence -o DIR [--quick] [--seed S] [--finest K]\n"
        "         [--no-plots]\n"
        "\n"
        "The paper's 6.1 experiment: f(u,v) = 0.1 exp(2u + v - v^2) on a\n"
        "triangulated square grid of side h = 2^-2 .. 2^-6, each vertex moved by\n"
        "(d h, d' h), d, d' uniform in [0, 0.9]; jets of degree 1..9 by\n"
        "interpolation (N_n points) and approximation (the fewest whole mesh\n"
        "rings with >= 2 N_n points) at the grid vertices nearest to a 5 x 5\n"
        "lattice over [-0.25, 0.25]^2; errors against the exact values: sine of\n"
        "the normal angle, relative errors of kmin and kmax (average, maximum).\n"
        "\n"
        "  -o, --output DIR  (also --out DIR) writes DIR/convergence.csv\n"
        "              (mode,degree,h,normal_avg,normal_max,kmin_avg,kmin_max,\n"
        "              kmax_avg,kmax_max), DIR/slopes.csv (mode,degree,\n"
        "              normal_slope,kmin_slope,kmax_slope: least-squares slopes of\n"
        "              log(1/delta_avg) against log(1/h), Theorem 3 predicts\n"
        "              n - k + 1), DIR/slopes_points.csv (how many h, from the\n"
        "              coarsest, each slope used: the points above the double-\n"
        "              precision floor), DIR/convergence.gp and its PNGs\n"
        "  --quick     degrees 1..4 and a 3 x 3 lattice (seconds; for CI)\n"
        "  --seed S    grid perturbation seed (default 1); same seed, same bits\n"
        "  --finest K  h down to 2^-K, K in 3..9 (default 6, the paper's; 8 or 9\n"
        "              shows the double-precision floor of high degrees)\n"
        "  --no-plots  do not run gnuplot\n"
        "  -h, --help  this text\n");
}

static const char *mode_name(jf_fit_mode m) { return m == JF_FIT_INTERP ? "interp" : "approx"; }

static FILE *open_in(const char *dir, const char *name, char *path, size_t len)
{
    snprintf(path, len, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f)
        fprintf(stderr, "jetfit convergence: %s: %s\n", path, strerror(errno));
    return f;
}

static int close_checked(FILE *f, const char *path)
{
    int bad = ferror(f);
    if (fclose(f) || bad) {
        fprintf(stderr, "jetfit convergence: %s: write failed\n", path);
        return -1;
    }
    return 0;
}

static const char *const qn[3] = {"normal", "kmin", "kmax"};

/* The PNG names, in the order the script draws them: per mode drawn,
 * normal/kmin/kmax against h, then degree.  Returns how many (<= 8). */
static int png_names(const jf_conv_config *c, char name[8][32])
{
    int n = 0;
    for (int m = 0; m < 2; m++) {
        const char *mn = m ? "approx" : "interp";
        if ((m == 0 && !c->interp) || (m == 1 && !c->approx))
            continue;
        for (int q = 0; q < 3; q++)
            snprintf(name[n++], 32, "%s_%s.png", qn[q], mn);
        snprintf(name[n++], 32, "degree_%s.png", mn);
    }
    return n;
}

/* The gnuplot script: Figs. 5-10 (log(1/delta) vs log(1/h) per degree,
 * read from convergence.csv) and Figs. 11-12 (log(1/delta)/log(1/h) vs
 * degree at h = c->h[kfix], inline data blocks so the lines join).
 * fd NULL: the script users run in DIR (file names); else the one jetfit
 * runs: convergence.csv's rows inline and each picture to descriptor
 * fd[i] (gnuplot opens no name in DIR, issue 33.2). */
static void emit_script(FILE *f, const jf_conv_config *c, const jf_conv_row *rows, int kfix,
                        const int *fd)
{
    int nd = c->deg_hi - c->deg_lo + 1, np = 0;
    char pn[8][32];
    png_names(c, pn);
    fprintf(f, "# made by jetfit convergence; run in this folder: gnuplot convergence.gp\n"
               "set terminal pngcairo size 640,480 font ',10' noenhanced\n"
               "set datafile separator ','\nset key outside right\nset grid\n");
    if (fd) {
        fprintf(f, "$csv << EOD\n");
        for (size_t k = 0, nr = jf_conv_row_count(c); k < nr; k++) {
            fprintf(f, "%s,%d,%.17g", mode_name(rows[k].mode), rows[k].degree, rows[k].h);
            for (int q = 0; q < 3; q++)
                fprintf(f, ",%.17g,%.17g", rows[k].avg[q], rows[k].max[q]);
            fprintf(f, "\n");
        }
        fprintf(f, "EOD\n");
    }
    for (int m = 0, g = 0; m < 2; m++) {
        const char *mn = m ? "approx" : "interp";
        if ((m == 0 && !c->interp) || (m == 1 && !c->approx))
            continue;
        fprintf(f, "$deg_%s << EOD\n", mn);
        for (int d = 0; d < nd; d++) {
            const jf_conv_row *r = rows + ((size_t)g * nd + d) * c->nh + kfix;
            fprintf(f, "%d", r->degree);
            for (int q = 0; q < 3; q++)
                fprintf(f, ",%.6g,%.6g", log(1 / r->avg[q]) / log(1 / r->h),
                        log(1 / r->max[q]) / log(1 / r->h));
            fprintf(f, "\n");
        }
        fprintf(f, "EOD\n");
        g++;
        fprintf(f, "set xlabel 'log(1/h)'\nset ylabel 'log(1/delta)'\n");
        for (int q = 0; q < 3; q++) {
            if (fd)
                jf_gp_output(f, fd[np++]);
            else
                fprintf(f, "set output '%s'\n", pn[np++]);
            fprintf(f, "set title 'exp graph: %s error (average) vs h, %s'\n"
                       "plot for [d=%d:%d] %s using "
                       "(strcol(1) eq '%s' && $2 == d ? log(1/$3) : 1/0):"
                       "(log(1/$%d)) with linespoints title sprintf('deg %%d', d)\n",
                    qn[q], mn, q && c->deg_lo < 2 ? 2 : c->deg_lo,
                    c->deg_hi, fd ? "$csv" : "'convergence.csv' skip 1", mn, 4 + 2 * q);
        }
        if (fd)
            jf_gp_output(f, fd[np++]);
        else
            fprintf(f, "set output '%s'\n", pn[np++]);
        fprintf(f, "set xlabel 'degree'\n"
                   "set ylabel 'log(1/delta)/log(1/h)'\n"
                   "set title 'exp graph: errors vs degree at h = %g, %s'\nplot ",
                c->h[kfix], mn);
        for (int q = 0; q < 3; q++)
            for (int a = 0; a < 2; a++)
                fprintf(f, "%s$deg_%s using 1:%d with linespoints title '%s_%s'",
                        q + a ? ", " : "", mn, 2 + 2 * q + a, qn[q], a ? "max" : "av");
        fprintf(f, "\n");
    }
    if (fd)
        fprintf(f, "unset output\n");
}

static int write_script(const char *dir, const jf_conv_config *c,
                        const jf_conv_row *rows, int kfix)
{
    char path[4096];
    FILE *f = open_in(dir, "convergence.gp", path, sizeof path);
    if (!f)
        return -1;
    emit_script(f, c, rows, kfix, NULL);
    return close_checked(f, path);
}

/* gnuplot draws each picture into a temporary beside its final name
 * (jf_tmpfile) through an inherited descriptor; all are checked whole
 * (gnuplot says nothing of a full disk) before any is renamed.  0, or -1
 * after one line; *missing set when gnuplot is not installed. */
static int run_plots(const char *dir, const jf_conv_config *c, const jf_conv_row *rows,
                     int kfix, int *missing)
{
    char pn[8][32], path[8][4096], why[600];
    int np = png_names(c, pn), fd[8], ok = 0, bad = 0;
    jf_tmpfile tf[8];
    jf_error e = {{0}};
    *missing = 0;
    for (; ok < np; ok++) {
        snprintf(path[ok], sizeof path[ok], "%s/%s", dir, pn[ok]);
        if (jf_tmpfile_open(path[ok], &tf[ok], &e) != JF_OK)
            break;
        fd[ok] = tf[ok].fd;
    }
    if (ok < np) {
        fprintf(stderr, "jetfit convergence: %s\n", e.msg);
        bad = 1;
    }
    jf_gp g;
    if (!bad && jf_gp_open(&g, fd, np, why, sizeof why) != 0) {
        *missing = g.missing;
        if (!g.missing)
            fprintf(stderr, "jetfit convergence: %s\n", why);
        bad = 1;
    }
    if (!bad) {
        emit_script(g.in, c, rows, kfix, fd);
        if (jf_gp_close(&g, why, sizeof why) != 0) {
            fprintf(stderr, "jetfit convergence: %s; CSVs are written\n", why);
            bad = 1;
        }
    }
    for (int p = 0; p < np && !bad; p++)
        if (jf_gp_png_whole(fd[p], why, sizeof why)) {
            fprintf(stderr, "jetfit convergence: %s: %s\n", path[p], why);
            bad = 1;
        }
    for (int p = 0; p < ok; p++) {
        if (bad)
            jf_tmpfile_discard(&tf[p]);
        else if (jf_tmpfile_commit(&tf[p], path[p], &e) != JF_OK) {
            fprintf(stderr, "jetfit convergence: %s\n", e.msg);
            bad = 1;
        }
    }
    return bad ? -1 : 0;
}

int jf_cmd_convergence(int argc, char **argv)
{
    const char *dir = NULL;
    int quick = 0, plots = 1;
    unsigned long long seed = 1;
    int finest = 6;
    static const jf_cli_optdef optdefs[] = {
        {"--output", 1, 'o', NULL},
        {"--out", 1, 0, "--output"},
        {"--help", 0, 'h', NULL},
        {"--quick", 0, 0, NULL},
        {"--no-plots", 0, 0, NULL},
        {"--finest", 1, 0, NULL},
        {"--seed", 1, 0, NULL},
        {NULL, 0, 0, NULL}};
    const jf_cli_optdef *const tables[] = {optdefs, NULL};
    jf_cli_args args;
    jf_cli_args_init(&args, argc, argv, tables);
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        const char *a = args.name, *v = args.val;
        if (k == JF_CLI_ERROR || k == JF_CLI_OPERAND) {
            if (k == JF_CLI_OPERAND) snprintf(args.err, sizeof args.err, "unexpected argument '%s'", v);
            fprintf(stderr, "jetfit convergence: %s (jetfit convergence --help)\n", args.err);
            return 2;
        } else if (!strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "--quick")) {
            quick = 1;
        } else if (!strcmp(a, "--no-plots")) {
            plots = 0;
        } else if (!strcmp(a, "--output")) {
            dir = v;
        } else if (!strcmp(a, "--finest")) {
            if (strlen(v) != 1 || v[0] < '3' || v[0] > '9') {
                fprintf(stderr, "jetfit convergence: --finest wants K in 3..9, not '%s'\n", v);
                return 2;
            }
            finest = v[0] - '0';
        } else { /* --seed */
            char *end;
            errno = 0;
            seed = strtoull(v, &end, 10);
            if (end == v || *end || errno || *v == '-') {
                fprintf(stderr, "jetfit convergence: --seed wants a non-negative integer, not '%s'\n", v);
                return 2;
            }
        }
    }
    if (!dir) {
        fprintf(stderr, "jetfit convergence: -o DIR is required (jetfit convergence --help)\n");
        return 2;
    }
    struct stat sb;
    if (stat(dir, &sb) != 0 && lstat(dir, &sb) == 0 && S_ISLNK(sb.st_mode)) {
        fprintf(stderr, "jetfit convergence: %s: a symbolic link to a folder that does not "
                        "exist\n", dir);
        return 1;
    }
    if (mkdir(dir, 0777) && errno != EEXIST) {
        fprintf(stderr, "jetfit convergence: cannot create %s: %s\n", dir, strerror(errno));
        return 1;
    }
    jf_conv_config c;
    jf_conv_config_init(&c, quick);
    c.seed = seed;
    c.nh = finest - 1; /* 2^-2 .. 2^-finest */
    for (int k = 0; k < c.nh; k++)
        c.h[k] = ldexp(1.0, -(k + 2));
    size_t nr = jf_conv_row_count(&c);
    jf_conv_row *rows = calloc(nr, sizeof *rows);
    jf_status st = rows ? jf_conv_run(&c, rows) : JF_ERR_NOMEM;
    if (st) {
        fprintf(stderr, "jetfit convergence: %s\n", jf_strerror(st));
        free(rows);
        return 1;
    }
    char p1[4096], p2[4096], p3[4096];
    FILE *fc = open_in(dir, "convergence.csv", p1, sizeof p1);
    FILE *fs = fc ? open_in(dir, "slopes.csv", p2, sizeof p2) : NULL;
    FILE *fu = fs ? open_in(dir, "slopes_points.csv", p3, sizeof p3) : NULL;
    if (!fu) {
        if (fc) fclose(fc);
        if (fs) fclose(fs);
        free(rows);
        return 1;
    }
    fprintf(fc, "mode,degree,h,normal_avg,normal_max,kmin_avg,kmin_max,kmax_avg,kmax_max\n");
    fprintf(fs, "mode,degree,normal_slope,kmin_slope,kmax_slope\n");
    fprintf(fu, "mode,degree,normal_used,kmin_used,kmax_used\n");
    printf("%-6s %3s  %14s %14s %14s   (Theorem 3: n, n-1, n-1)\n", "mode", "deg",
           "normal_slope", "kmin_slope", "kmax_slope");
    size_t lowered = 0, failed = 0;
    for (size_t g = 0; g < nr; g += (size_t)c.nh) {
        const jf_conv_row *r = rows + g;
        for (int k = 0; k < c.nh; k++) {
            fprintf(fc, "%s,%d,%.17g", mode_name(r[k].mode), r[k].degree, r[k].h);
            for (int q = 0; q < 3; q++)
                fprintf(fc, ",%.17g,%.17g", r[k].avg[q], r[k].max[q]);
            fprintf(fc, "\n");
            lowered += r[k].lowered;
            failed += r[k].failed;
        }
        size_t used[3];
        double sl[3];
        for (int q = 0; q < 3; q++)
            sl[q] = jf_conv_slope(r, (size_t)c.nh, q, &used[q]);
        fprintf(fs, "%s,%d,%.17g,%.17g,%.17g\n", mode_name(r->mode), r->degree,
                sl[0], sl[1], sl[2]);
        fprintf(fu, "%s,%d,%zu,%zu,%zu\n", mode_name(r->mode), r->degree, used[0],
                used[1], used[2]);
        printf("%-6s %3d  %8.2f (%zu h) %8.2f (%zu h) %8.2f (%zu h)\n", mode_name(r->mode),
               r->degree, sl[0], used[0], sl[1], used[1], sl[2], used[2]);
    }
    int bad = close_checked(fc, p1) | close_checked(fs, p2) | close_checked(fu, p3);
    if (bad || write_script(dir, &c, rows, c.nh > 2 ? 2 : c.nh - 1)) {
        free(rows);
        return 1;
    }
    jf_conv_row *rows_kept = rows; /* the plots' data */
    if (lowered || failed)
        fprintf(stderr, "jetfit convergence: note: %zu fits were rank deficient "
                        "(lower degree), %zu failed\n", lowered, failed);
    if (!plots) {
        free(rows_kept);
        return 0;
    }
    int missing = 0;
    if (run_plots(dir, &c, rows_kept, c.nh > 2 ? 2 : c.nh - 1, &missing) == 0) {
        free(rows_kept);
        return 0;
    }
    free(rows_kept);
    if (missing) { /* the plots are optional */
        fprintf(stderr, "jetfit convergence: gnuplot not found: CSVs written, no plots "
                        "(install gnuplot-nox, then run gnuplot convergence.gp in %s)\n", dir);
        return 0;
    }
    return 1;
}
