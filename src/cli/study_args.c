/* study_args.c -- `jetfit study`'s command line: usage, the ';'-separated
 * lists, the estimate options outside --flags (every cell's base), and
 * every setting (strategy x degree x flag set) parsed with estimate's own
 * code (opts.c) and validated before any work, so a bad list costs one
 * line and no folder. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "study_args.h"

static void usage(FILE *f)
{
    fprintf(f,
        "usage: jetfit study INPUT --truth TRUTH -o DIR [options]\n"
        "       jetfit study SURFACE -o DIR [options]\n"
        "\n"
        "Estimates every combination of the lists below and measures it against\n"
        "the truth as `jetfit eval` does: which neighbourhood, degree and flags\n"
        "to use at which noise level.\n"
        "  INPUT, --truth TRUTH  a cloud and its truth: a `generate` truth file,\n"
        "                  PCPNet .normals (with .curv beside it when present),\n"
        "                  or a reference result (e.g. estimated on a cleaner scan)\n"
        "                  ('-': standard input, with --input-format FMT)\n"
        "  SURFACE         exp, paraboloid, revolution, sphere, ellipsoid, cylinder,\n"
        "                  torus:\n"
        "                  `jetfit generate SURFACE --n N --seed S+r` with exact truth\n"
        "  -o, --output DIR  the folder (made if missing): study.csv, study.def, best.csv,\n"
        "                  normal.png, curvature.png, k.png, report.html,\n"
        "                  best.ply and view.html (the best setting in 3D)\n"
        "\n"
        "Lists are ';'-separated (numbers also ','):\n"
        "  --neighbors LIST      e.g. 'knn:16;knn:64;natural:32;knn:64,radius:0.05'\n"
        "                        or auto (K and degree chosen per point)\n"
        "                        (default " JF_CLI_DEFAULT_NEIGHBORS ")\n"
        "  --degree LIST         jet degrees (default 2)\n"
        "  --flags LIST          estimate option sets, e.g. ';--robust-normals;--scales\n"
        "                        16,32,64' (an empty set is the defaults; default '')\n"
        "  --noise LIST          Gaussian sigma, fractions of the bounding-box diagonal\n"
        "  --noise-uniform LIST  uniform noise, fractions of the largest side\n"
        "  --outliers LIST       fractions of points replaced (default 0 for all three)\n"
        "  --repeat R            noise draws per level (default 1): mean and spread\n"
        "  --seed S              seed of repeat 0 (default 1); repeat r uses S + r\n"
        "  --n N                 SURFACE: points (default %d)\n"
        "  --mesh                SURFACE: a perturbed triangulated grid of about N\n"
        "                        vertices, as generate --mesh (rings need it)\n"
        "  --subset IDX          only these 0-based rows count (as eval --subset)\n"
        "  --input-format FMT    read INPUT as FMT (ply xyz txt pts csv off las laz ptx e57):\n"
        "                        needed when INPUT is '-' (standard input)\n"
        "  --metrics LIST        best.csv's metrics (default all): normal_rms,\n"
        "                        normal_median, normal_p95, k1_median, k1_p95,\n"
        "                        k2_median, k2_p95\n"
        "  --threads N           OpenMP threads of each estimate\n"
        "  --resume              keep the finished cells of DIR/study.csv, run the rest\n"
        "                        (refused when DIR/study.def: input, truth, options, differ)\n"
        "  -q, --quiet           no progress line, no summary\n"
        "  -h, --help            this text\n"
        "  any other estimate option (e.g. --orient, --columns, --robust) applies\n"
        "  to every cell, before the cell's flag set.  Every option, in a --flags\n"
        "  set too, may be written NAME=VALUE (--robust=huber) or as a unique\n"
        "  prefix (--robust-norm).\n"
        "\n"
        "Errors: normal angle in degrees; k1, k2: |k - k_t| / max(|k_t|, 1), eval's\n"
        "k1_rel/k2_rel.  A cell that fails is recorded as failed; the rest go on.\n",
        JF_STUDY_DEFAULT_N);
}

static int bad_opt(const char *opt, const char *val, const char *why)
{
    fprintf(stderr, "jetfit study: %s '%s': %s (jetfit study --help)\n", opt, val ? val : "",
            why);
    return 2;
}

/* ---- lists ---- */

/* Splits a copy of text at any of seps into *out (strings trimmed of
 * blanks; owned: one block, out[0] is its start); returns the count. */
static int split_list(const char *text, const char *seps, char ***out)
{
    size_t len = strlen(text);
    int n = 1;
    for (const char *p = text; *p; p++) n += strchr(seps, *p) != NULL;
    char **v = malloc((size_t)n * sizeof *v + len + 1);
    if (!v) return -1;
    char *buf = (char *)(v + n);
    memcpy(buf, text, len + 1);
    int k = 0;
    char *p = buf;
    for (;;) {
        char *end = p + strcspn(p, seps);
        int last = !*end;
        *end = '\0';
        while (isspace((unsigned char)*p)) p++;
        for (char *q = p + strlen(p); q > p && isspace((unsigned char)q[-1]);) *--q = '\0';
        v[k++] = p;
        if (last) break;
        p = end + 1;
    }
    *out = v;
    return k;
}

static int num_list(const char *opt, const char *text, double lo, double hi, double **out,
                    int *n)
{
    char **s;
    int m = split_list(text, ";,", &s);
    if (m < 0) return bad_opt(opt, text, "out of memory");
    double *v = malloc((size_t)m * sizeof *v);
    for (int i = 0; v && i < m; i++) {
        if (jf_cli_parse_double(s[i], &v[i]) || !(v[i] >= lo && v[i] <= hi)) {
            char why[96];
            snprintf(why, sizeof why, "expected numbers in [%g, %g] separated by ';'", lo, hi);
            free(s);
            free(v);
            return bad_opt(opt, text, why);
        }
        for (int j = 0; j < i; j++)
            if (v[j] == v[i]) {
                free(s);
                free(v);
                return bad_opt(opt, text, "a value is listed twice");
            }
    }
    free(s);
    free(*out);
    *out = v;
    *n = m;
    return v ? 0 : bad_opt(opt, text, "out of memory");
}

void jf_study_args_free(jf_study_args *c)
{
    free(c->strat_block);
    free(c->flags_block);
    free(c->s.degree);
    free(c->s.noise);
    free(c->s.noise_u);
    free(c->s.outliers);
    free(c->s.cell);
    free(c->setting);
    jf_cloud_free(&c->cloud);
    free(c->truth);
    free(c->sel);
}

/* Tokens of one flag set, applied to e; the study's own axes refused.
 * A set is scanned as estimate's command line is (args.c: --opt=V,
 * unique prefixes, "--"), so an option is spelt the same in both. */
static int apply_flags(jf_cli_est *e, char *set, const char *text)
{
    char *tok[66];
    int n = 1;
    tok[0] = "--flags"; /* the scanner's argv[0] */
    for (char *p = strtok(set, " \t"); p; p = strtok(NULL, " \t")) {
        if (n == 65) return bad_opt("--flags", text, "a set holds more than 64 words");
        tok[n++] = p;
    }
    tok[n] = NULL;
    const jf_cli_optdef *const tables[] = {jf_cli_est_optdefs, NULL};
    jf_cli_args args;
    jf_cli_args_init(&args, n, tok, tables);
    jf_cli_bad bad;
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        char why[700];
        if (k == JF_CLI_ERROR) {
            snprintf(why, sizeof why, "%s%s", args.err,
                     strncmp(args.err, "unknown", 7) ? "" : " (not an estimate option)");
            return bad_opt("--flags", text, why);
        }
        if (k == JF_CLI_OPERAND) {
            snprintf(why, sizeof why, "'%s' is not an estimate option", args.val);
            return bad_opt("--flags", text, why);
        }
        const char *a = args.name; /* the long name, aliases resolved */
        if (!strcmp(a, "--neighbors") || !strcmp(a, "--degree") || !strcmp(a, "--threads") ||
            !strcmp(a, "--columns") || !strcmp(a, "--bad-rows"))
            return bad_opt("--flags", text, "--neighbors, --degree, --threads, --columns and "
                                            "--bad-rows are the study's own options (give "
                                            "them outside --flags)");
        if (jf_cli_est_option(e, a, args.val, &bad)) {
            snprintf(why, sizeof why, "%s '%s': %s", bad.opt, bad.val, bad.why);
            return bad_opt("--flags", text, why);
        }
    }
    return 0;
}

/* Every (strategy, degree, flags): parsed and validated before any work. */
static int make_settings(jf_study_args *c)
{
    jf_study *s = &c->s;
    int n = s->nstrategy * s->ndegree * s->nflags;
    c->setting = malloc((size_t)n * sizeof *c->setting);
    if (!c->setting) return bad_opt("settings", "", "out of memory");
    c->nsetting = n;
    int k = 0;
    for (int a = 0; a < s->nstrategy; a++)
        for (int d = 0; d < s->ndegree; d++)
            for (int f = 0; f < s->nflags; f++) {
                jf_cli_est e = c->base;
                jf_cli_bad bad;
                e.o.params.degree = s->degree[d];
                char set[1024];
                snprintf(set, sizeof set, "%s", s->flags[f]);
                int rc = apply_flags(&e, set, s->flags[f]);
                if (rc) return rc;
                if (jf_cli_est_option(&e, "--neighbors", s->strategy[a], &bad) ||
                    jf_cli_est_finish(&e, &bad)) {
                    char why[300];
                    snprintf(why, sizeof why, "%s '%s': %s (degree %d, flags '%s')", bad.opt,
                             bad.val, bad.why, s->degree[d], s->flags[f]);
                    return bad_opt("setting", s->strategy[a], why);
                }
                e.o.progress = NULL;
                c->setting[k++] = e.o;
            }
    return 0;
}

/* Setting index of a key (its position in make_settings' loops). */


static void record_command(jf_study *s, int argc, char **argv)
{
    size_t u = (size_t)snprintf(s->command, sizeof s->command, "jetfit");
    for (int i = 0; i < argc && u < sizeof s->command; i++) {
        const char *a = argv[i];
        /* how it ran, not what it studies: the report shows the study */
        if (!strcmp(a, "--resume") || !strcmp(a, "--quiet") || !strcmp(a, "-q")) continue;
        int plain = *a != '\0';
        for (const char *p = a; *p; p++)
            if (!isalnum((unsigned char)*p) && !strchr("-_.,:/=+", *p)) plain = 0;
        if (plain) {
            u += (size_t)snprintf(s->command + u, sizeof s->command - u, " %s", a);
            continue;
        }
        u += (size_t)snprintf(s->command + u, sizeof s->command - u, " '");
        for (const char *p = a; *p && u < sizeof s->command; p++) {
            if (*p == '\'') u += (size_t)snprintf(s->command + u, sizeof s->command - u, "'\\''");
            else u += (size_t)snprintf(s->command + u, sizeof s->command - u, "%c", *p);
        }
        if (u < sizeof s->command) u += (size_t)snprintf(s->command + u, sizeof s->command - u, "'");
    }
}

/* Appends " NAME[=VALUE]" to the estimate options that define the study. */
static void base_add(jf_study_args *c, const char *name, const char *val)
{
    size_t u = strlen(c->base_text);
    snprintf(c->base_text + u, sizeof c->base_text - u, "%s%s%s%s", u ? " " : "", name,
             val ? "=" : "", val ? val : "");
}

int jf_study_args_parse(jf_study_args *c, int argc, char **argv)
{
    jf_study *s = &c->s;
    const char *pos = NULL, *noise = "0", *noise_u = "0", *outl = "0";
    c->nb_text = JF_CLI_DEFAULT_NEIGHBORS;
    c->deg_text = NULL;
    c->flags_text = "";
    s->repeat = 1;
    s->seed = 1;
    for (int m = 0; m < JF_M_COUNT; m++) s->best[m] = 1;
    jf_cli_est_init(&c->base);
    static const jf_cli_optdef optdefs[] = {
        {"--output", 1, 'o', NULL},
        {"--help", 0, 'h', NULL},
        {"--quiet", 0, 'q', NULL},
        {"--resume", 0, 0, NULL},
        {"--mesh", 0, 0, NULL},
        {"--truth", 1, 0, NULL},
        {"--subset", 1, 0, NULL},
        {"--flags", 1, 0, NULL},
        {"--noise", 1, 0, NULL},
        {"--noise-uniform", 1, 0, NULL},
        {"--outliers", 1, 0, NULL},
        {"--metrics", 1, 0, NULL},
        {"--repeat", 1, 0, NULL},
        {"--seed", 1, 0, NULL},
        {"--n", 1, 0, NULL},
        {"--input-format", 1, 0, NULL},
        {NULL, 0, 0, NULL}};
    /* --neighbors and --degree are the study's axes (lists), from estimate's table */
    const jf_cli_optdef *const tables[] = {optdefs, jf_cli_est_optdefs, NULL};
    jf_cli_args args;
    jf_cli_args_init(&args, argc, argv, tables);
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        const char *name = args.name, *val = args.val;
        if (k == JF_CLI_ERROR) {
            fprintf(stderr, "jetfit study: %s (jetfit study --help)\n", args.err);
            return 2;
        }
        if (k == JF_CLI_OPERAND) {
            if (pos) return bad_opt("argument", val, "only one INPUT or SURFACE is accepted");
            pos = val;
            continue;
        }
        if (!strcmp(name, "--help")) {
            usage(stdout);
            return -1;
        }
        if (!strcmp(name, "--resume")) {
            c->resume = 1;
            continue;
        }
        if (!strcmp(name, "--quiet")) {
            c->quiet = 1;
            continue;
        }
        if (!strcmp(name, "--mesh")) {
            c->mesh = 1;
            continue;
        }
        if (jf_cli_est_takes_value(name) == 0) {
            jf_cli_bad bad;
            (void)jf_cli_est_option(&c->base, name, NULL, &bad);
            base_add(c, name, NULL);
            continue;
        }
        int iv;
        if (!strcmp(name, "--output")) c->dir = val;
        else if (!strcmp(name, "--truth")) s->truth = val;
        else if (!strcmp(name, "--subset")) s->subset = val;
        else if (!strcmp(name, "--neighbors")) c->nb_text = val;
        else if (!strcmp(name, "--degree")) c->deg_text = val;
        else if (!strcmp(name, "--flags")) c->flags_text = val;
        else if (!strcmp(name, "--noise")) noise = val;
        else if (!strcmp(name, "--noise-uniform")) noise_u = val;
        else if (!strcmp(name, "--outliers")) outl = val;
        else if (!strcmp(name, "--metrics")) c->metrics_text = val;
        else if (!strcmp(name, "--input-format")) c->in_fmt = val;
        else if (!strcmp(name, "--repeat")) {
            if (jf_cli_parse_int(val, 1, 100000, &iv)) return bad_opt(name, val, "expected a positive integer");
            s->repeat = iv;
        } else if (!strcmp(name, "--seed")) {
            char *end;
            errno = 0;
            s->seed = strtoull(val, &end, 10);
            if (errno || end == val || *end || *val == '-' || *val == '+')
                return bad_opt(name, val, "expected a non-negative integer");
        } else if (!strcmp(name, "--n")) {
            if (jf_cli_parse_int(val, 10, 100000000, &iv)) return bad_opt(name, val, "expected an integer >= 10");
            c->npoints = (size_t)iv;
        } else if (jf_cli_est_takes_value(name) == 1) {
            jf_cli_bad bad;
            if (jf_cli_est_option(&c->base, name, val, &bad)) return bad_opt(bad.opt, bad.val, bad.why);
            if (strcmp(name, "--threads")) base_add(c, name, val);
        }
    }
    if (!pos) return bad_opt("INPUT", "", "missing INPUT file or SURFACE name");
    if (!c->dir || !c->dir[0]) return bad_opt("-o", "", "missing output folder DIR");
    s->input = pos;
    if (!s->truth) {
        if (jf_surface_parse(pos, &c->surf))
            return bad_opt("SURFACE", pos, "not a surface (exp, paraboloid, revolution, sphere, ellipsoid, cylinder, torus); an INPUT file needs --truth");
        c->is_surface = 1;
        if (!c->npoints) c->npoints = JF_STUDY_DEFAULT_N;
    } else if (c->npoints || c->mesh) {
        return bad_opt(c->mesh ? "--mesh" : "--n", "", "applies to a SURFACE, not to INPUT --truth");
    } else if (!strcmp(s->truth, "-") || (s->subset && !strcmp(s->subset, "-"))) {
        return bad_opt(!strcmp(s->truth, "-") ? "--truth" : "--subset", "-",
                       "a named file (standard input can only carry INPUT)");
    }
    if (c->in_fmt && c->is_surface)
        return bad_opt("--input-format", c->in_fmt, "applies to INPUT, not to a SURFACE");
    /* the lists */
    int ns = split_list(c->nb_text, ";", &c->strat_block);
    if (ns < 0) return bad_opt("--neighbors", c->nb_text, "out of memory");
    s->strategy = c->strat_block;
    s->nstrategy = ns;
    for (int i = 0; i < ns; i++) {
        jf_nb_spec spec;
        const char *why = NULL;
        if (jf_nb_parse(s->strategy[i], &spec, &why) != JF_OK) {
            char msg[200];
            snprintf(msg, sizeof msg, "'%s': %s", s->strategy[i], why ? why : "bad neighbourhood");
            return bad_opt("--neighbors", c->nb_text, msg);
        }
        for (int j = 0; j < i; j++)
            if (!strcmp(s->strategy[i], s->strategy[j])) return bad_opt("--neighbors", c->nb_text, "a strategy is listed twice");
    }
    int nf = split_list(c->flags_text, ";", &c->flags_block);
    if (nf < 0) return bad_opt("--flags", c->flags_text, "out of memory");
    s->flags = c->flags_block;
    s->nflags = nf;
    for (int i = 0; i < nf; i++)
        for (int j = 0; j < i; j++)
            if (!strcmp(s->flags[i], s->flags[j])) return bad_opt("--flags", c->flags_text, "a set is listed twice");
    double *dv = NULL;
    int nd = 0;
    char dflt[16];
    snprintf(dflt, sizeof dflt, "%d", c->base.o.params.degree);
    if (num_list("--degree", c->deg_text ? c->deg_text : dflt, 1, JF_MAX_DEGREE, &dv, &nd)) return 2;
    s->degree = malloc((size_t)nd * sizeof *s->degree);
    if (!s->degree) {
        free(dv);
        return bad_opt("--degree", "", "out of memory");
    }
    for (int i = 0; i < nd; i++) {
        if (dv[i] != floor(dv[i])) {
            free(dv);
            return bad_opt("--degree", c->deg_text, "expected integers 1..9");
        }
        s->degree[i] = (int)dv[i];
    }
    free(dv);
    s->ndegree = nd;
    if (num_list("--noise", noise, 0, 10, &s->noise, &s->nnoise) ||
        num_list("--noise-uniform", noise_u, 0, 10, &s->noise_u, &s->nnoise_u) ||
        num_list("--outliers", outl, 0, 1, &s->outliers, &s->noutliers))
        return 2;
    if (c->metrics_text) {
        char **mv;
        int nm = split_list(c->metrics_text, ";,", &mv);
        if (nm < 0) return bad_opt("--metrics", c->metrics_text, "out of memory");
        for (int m = 0; m < JF_M_COUNT; m++) s->best[m] = 0;
        for (int i = 0; i < nm; i++) {
            int m = 0;
            while (m < JF_M_COUNT && strcmp(mv[i], jf_study_metric[m])) m++;
            if (m == JF_M_COUNT) {
                char why[200];
                snprintf(why, sizeof why, "unknown metric '%s' (normal_rms, normal_median, normal_p95, k1_median, k1_p95, k2_median, k2_p95)", mv[i]);
                free(mv);
                return bad_opt("--metrics", c->metrics_text, why);
            }
            s->best[m] = 1;
        }
        free(mv);
    }
    record_command(s, argc, argv);
    return make_settings(c);
}
