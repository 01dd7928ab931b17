/* cmd_study.c -- `jetfit study INPUT --truth TRUTH -o DIR` and `jetfit
 * study SURFACE -o DIR`: every combination of neighbourhood strategy,
 * degree and option set at every noise level, each through the library
 * (jf_estimate) on the same noisy draws, measured as `jetfit eval` does
 * (eval_errors.c), into DIR/study.csv, DIR/best.csv, PNG plots and
 * DIR/report.html.
 *
 * Plan: cells in the order noise level, repeat, setting, so one noisy
 * draw serves every setting (common random numbers: settings are compared
 * on the same points).  A draw is what `jetfit generate` makes: repeat r
 * uses seed S + r; the surface is sampled, then Gaussian noise, uniform
 * noise, outliers, each only when non-zero, from one generator.  On an
 * INPUT the same noise is added to its points.  study.csv is rewritten
 * (temporary + rename) after every cell, so an interrupted study keeps
 * its finished cells and --resume skips them. */
#define _POSIX_C_SOURCE 200809L /* mkdir, isatty, strdup */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cmd.h"
#include "eval_errors.h"
#include "jetfit.h"
#include "opts.h"
#include "study.h"
#include "surfaces.h"

#define DEFAULT_N 10000

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
        "  SURFACE         exp, paraboloid, revolution, sphere, ellipsoid, cylinder:\n"
        "                  `jetfit generate SURFACE --n N --seed S+r` with exact truth\n"
        "  -o DIR          the folder (made if missing): study.csv, best.csv,\n"
        "                  normal.png, curvature.png, k.png, report.html\n"
        "\n"
        "Lists are ';'-separated (numbers also ','):\n"
        "  --neighbors LIST      e.g. 'knn:16;knn:64;natural:32;knn:64,radius:0.05'\n"
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
        "  --subset IDX          only these 0-based rows count (as eval --subset)\n"
        "  --metrics LIST        best.csv's metrics (default all): normal_rms,\n"
        "                        normal_median, normal_p95, k1_median, k1_p95,\n"
        "                        k2_median, k2_p95\n"
        "  --threads N           OpenMP threads of each estimate\n"
        "  --resume              keep the finished cells of DIR/study.csv, run the rest\n"
        "  --quiet               no progress line, no summary\n"
        "  any other estimate option (e.g. --orient, --columns, --robust) applies\n"
        "  to every cell, before the cell's flag set.\n"
        "\n"
        "Errors: normal angle in degrees; k1, k2: |k - k_t| / max(|k_t|, 1), eval's\n"
        "k1_rel/k2_rel.  A cell that fails is recorded as failed; the rest go on.\n",
        DEFAULT_N);
}

static int bad_opt(const char *opt, const char *val, const char *why)
{
    fprintf(stderr, "jetfit study: %s '%s': %s (jetfit study --help)\n", opt, val ? val : "",
            why);
    return 2;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Ctrl-C (SIGINT) or SIGTERM: the running cell stops at its next block
 * (jf_estimate_opts.cancel), the finished ones stay in study.csv. */
static volatile sig_atomic_t stop_asked;

static void on_signal(int sig)
{
    (void)sig;
    stop_asked = 1;
}

static int cancel_hook(void *user)
{
    (void)user;
    return stop_asked != 0;
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

/* ---- the command's state ---- */

typedef struct {
    jf_study s;
    const char *dir, *surface_name, *nb_text, *deg_text, *flags_text, *metrics_text;
    char **strat_block, **flags_block;
    jf_surface surf;
    int is_surface, quiet, resume;
    size_t npoints;
    jf_cli_est base;             /* options outside --flags           */
    jf_estimate_opts *setting;   /* strategy x degree x flags         */
    int nsetting;
    /* INPUT mode */
    jf_cloud cloud;
    double *truth; /* 5 per row: nx ny nz k1 k2 */
    int truth_k;
    size_t *sel, nsel;
} study_cmd;

static void free_cmd(study_cmd *c)
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

/* Tokens of one flag set, applied to e; the study's own axes refused. */
static int apply_flags(jf_cli_est *e, char *set, const char *text)
{
    char *tok[64];
    int n = 0;
    for (char *p = strtok(set, " \t"); p && n < 64; p = strtok(NULL, " \t")) tok[n++] = p;
    jf_cli_bad bad;
    for (int i = 0; i < n; i++) {
        char *a = tok[i], *val = NULL, *eq = strchr(a, '=');
        if (eq) *eq = '\0';
        int tv = jf_cli_est_takes_value(a);
        if (tv < 0) return bad_opt("--flags", text, "an option set holds a word that is not an estimate option");
        if (!strcmp(a, "--neighbors") || !strcmp(a, "--neighbours") || !strcmp(a, "--degree") ||
            !strcmp(a, "--threads") || !strcmp(a, "--columns"))
            return bad_opt("--flags", text, "--neighbors, --degree, --threads and --columns are the study's own options");
        if (tv == 1) {
            if (eq) val = eq + 1;
            else if (i + 1 < n) val = tok[++i];
            else return bad_opt("--flags", text, "an option in a set needs its value");
        } else if (eq) {
            return bad_opt("--flags", text, "--robust-normals takes no value");
        }
        if (jf_cli_est_option(e, a, val, &bad)) {
            char why[256];
            snprintf(why, sizeof why, "%s '%s': %s", bad.opt, bad.val, bad.why);
            return bad_opt("--flags", text, why);
        }
    }
    return 0;
}

/* Every (strategy, degree, flags): parsed and validated before any work. */
static int make_settings(study_cmd *c)
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
                e.nbspec = s->strategy[a];
                e.o.params.degree = s->degree[d];
                char set[1024];
                snprintf(set, sizeof set, "%s", s->flags[f]);
                int rc = apply_flags(&e, set, s->flags[f]);
                if (rc) return rc;
                if (jf_cli_est_finish(&e, &bad)) {
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
static int setting_of(const jf_study *s, const jf_study_key *k)
{
    return (k->strategy * s->ndegree + k->degree) * s->nflags + k->flags;
}

static int make_cells(study_cmd *c)
{
    jf_study *s = &c->s;
    size_t nlev = (size_t)s->nnoise * (size_t)s->nnoise_u * (size_t)s->noutliers;
    s->ncells = nlev * (size_t)s->repeat * (size_t)c->nsetting;
    s->cell = calloc(s->ncells, sizeof *s->cell);
    if (!s->cell) return bad_opt("cells", "", "out of memory");
    size_t i = 0;
    jf_study_key k;
    for (k.noise = 0; k.noise < s->nnoise; k.noise++)
        for (k.noise_u = 0; k.noise_u < s->nnoise_u; k.noise_u++)
            for (k.outliers = 0; k.outliers < s->noutliers; k.outliers++)
                for (k.repeat = 0; k.repeat < s->repeat; k.repeat++)
                    for (k.strategy = 0; k.strategy < s->nstrategy; k.strategy++)
                        for (k.degree = 0; k.degree < s->ndegree; k.degree++)
                            for (k.flags = 0; k.flags < s->nflags; k.flags++) {
                                jf_study_cell *cl = &s->cell[i++];
                                cl->key = k;
                                cl->seed = s->seed + (unsigned long long)k.repeat;
                                cl->points = c->is_surface ? c->npoints : c->cloud.n;
                            }
    return 0;
}

/* ---- one noisy draw ---- */

/* The draw of cell key k (its noise level and repeat) into *smp: what
 * `jetfit generate` writes for a SURFACE, or the INPUT with that noise.
 * truth5 gets nx ny nz k1 k2 per point (NaN rows for outliers). */
static jf_status make_draw(const study_cmd *c, const jf_study_key *k, jf_sample *smp,
                           double *truth5)
{
    const jf_study *s = &c->s;
    jf_rng rng;
    jf_rng_seed(&rng, (uint64_t)(s->seed + (unsigned long long)k->repeat));
    jf_status st;
    memset(smp, 0, sizeof *smp);
    if (c->is_surface) {
        st = jf_sample_random(c->surf, c->npoints, JF_DENSITY_UNIFORM, &rng, smp);
        if (st) return st;
    } else {
        size_t n = c->cloud.n;
        smp->n = n;
        smp->xyz = malloc(3 * n * sizeof *smp->xyz);
        smp->truth = malloc(n * sizeof *smp->truth);
        if (!smp->xyz || !smp->truth) {
            jf_sample_free(smp);
            return JF_ERR_NOMEM;
        }
        memcpy(smp->xyz, c->cloud.xyz, 3 * n * sizeof *smp->xyz);
        for (size_t i = 0; i < n; i++) {
            jf_truth *t = &smp->truth[i];
            const double *r = c->truth + 5 * i;
            for (int d = 0; d < 3; d++) {
                t->xyz[d] = c->cloud.xyz[3 * i + d];
                t->normal[d] = r[d];
                t->d1[d] = t->d2[d] = NAN;
            }
            t->k1 = r[3];
            t->k2 = r[4];
            t->valid = 1;
        }
    }
    /* noise after truth, outliers last: generate's order */
    if (s->noise[k->noise] > 0) jf_noise_gauss(smp, s->noise[k->noise], &rng);
    if (s->noise_u[k->noise_u] > 0) jf_noise_uniform(smp, s->noise_u[k->noise_u], &rng);
    if (s->outliers[k->outliers] > 0) jf_noise_outliers(smp, s->outliers[k->outliers], &rng);
    for (size_t i = 0; i < smp->n; i++) {
        const jf_truth *t = &smp->truth[i];
        double *o = truth5 + 5 * i;
        for (int d = 0; d < 3; d++) o[d] = t->normal[d];
        o[3] = t->k1;
        o[4] = t->k2;
    }
    return JF_OK;
}

/* ---- progress: one line for the whole study ---- */

typedef struct {
    double t0, last;
    size_t units_done, units_total; /* points of finished cells, of all to run */
    size_t cell_no, cells_todo;
    char label[80];
} study_progress;

static void progress(void *user, size_t done, size_t total)
{
    study_progress *p = user;
    double t = now_s();
    if (done < total && t - p->last < 0.25) return;
    p->last = t;
    double units = (double)p->units_done + (double)done, el = t - p->t0;
    double frac = p->units_total ? units / (double)p->units_total : 1.0;
    double eta = units > 0 ? el * ((double)p->units_total - units) / units : 0;
    fprintf(stderr, "\rjetfit study: cell %zu/%zu  %5.1f%%  ETA %.0f s  %-40.40s", p->cell_no,
            p->cells_todo, 100.0 * frac, eta, p->label);
    fflush(stderr);
}

/* ---- one cell ---- */

/* Runs one cell into cl; -1 if it was cancelled (cl stays undone). */
static int run_cell(study_cmd *c, jf_study_cell *cl, const jf_sample *smp, const double *truth5,
                    jf_result *res, double *err[3], study_progress *pp)
{
    const jf_study *s = &c->s;
    jf_estimate_opts o = c->setting[setting_of(s, &cl->key)];
    jf_cloud cloud = {.n = smp->n, .xyz = smp->xyz};
    if (!c->is_surface) {
        cloud.nrm = c->cloud.nrm;
        cloud.nfaces = c->cloud.nfaces;
        cloud.face_off = c->cloud.face_off;
        cloud.face_idx = c->cloud.face_idx;
    }
    if (pp) {
        o.progress = progress;
        o.progress_user = pp;
    }
    o.cancel = cancel_hook;
    jf_error e = {{0}};
    double t0 = now_s();
    jf_status st = jf_estimate(&cloud, &o, res, &e);
    if (st == JF_ERR_CANCELLED || stop_asked) return -1;
    cl->seconds = now_s() - t0;
    cl->points_per_s = cl->seconds > 0 ? (double)smp->n / cl->seconds : NAN;
    cl->done = 1;
    if (st != JF_OK) {
        snprintf(cl->status, sizeof cl->status, "failed: %s", e.msg[0] ? e.msg : jf_strerror(st));
        for (char *q = cl->status; *q; q++)
            if (*q == '\n' || *q == '\r') *q = ' ';
        for (int m = 0; m < JF_M_COUNT; m++) cl->m[m] = NAN;
        return 0;
    }
    snprintf(cl->status, sizeof cl->status, "ok");
    cl->ok = cl->lowered = cl->failed = cl->flagged = 0;
    for (size_t i = 0; i < smp->n; i++) {
        unsigned u = res[i].status;
        cl->ok += u == 0;
        cl->lowered += (u & (JF_PT_LOWERED_COND | JF_PT_LOWERED_RANK | JF_PT_LOWERED_FEW)) != 0;
        cl->failed += (u & JF_PT_FAILED) != 0;
        cl->flagged += u != 0;
    }
    int with_k = c->is_surface || c->truth_k;
    size_t nsel = c->sel ? c->nsel : smp->n;
    for (size_t j = 0; j < nsel; j++) {
        size_t i = c->sel ? c->sel[j] : j;
        double ev[JF_NQ];
        jf_cli_point_errors(res[i].normal, res[i].k1, res[i].k2, truth5 + 5 * i, with_k, ev);
        err[0][j] = ev[JF_Q_NORMAL];
        err[1][j] = ev[JF_Q_K1REL];
        err[2][j] = ev[JF_Q_K2REL];
    }
    jf_err_stats a, b, d;
    jf_err_stats_compute(err[0], nsel, &a);
    jf_err_stats_compute(err[1], nsel, &b);
    jf_err_stats_compute(err[2], nsel, &d);
    cl->normal_n = a.n;
    cl->m[JF_M_NORMAL_RMS] = a.rms;
    cl->m[JF_M_NORMAL_MEDIAN] = a.median;
    cl->m[JF_M_NORMAL_P95] = a.p95;
    cl->m[JF_M_K1_MEDIAN] = b.median;
    cl->m[JF_M_K1_P95] = b.p95;
    cl->m[JF_M_K2_MEDIAN] = d.median;
    cl->m[JF_M_K2_P95] = d.p95;
    return 0;
}

/* ---- options ---- */

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

static int parse_args(study_cmd *c, int argc, char **argv)
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
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return -1;
        }
        if (!strcmp(a, "--resume")) {
            c->resume = 1;
            continue;
        }
        if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            c->quiet = 1;
            continue;
        }
        if (jf_cli_est_takes_value(a) == 0) {
            jf_cli_bad bad;
            (void)jf_cli_est_option(&c->base, a, NULL, &bad);
            continue;
        }
        if (a[0] != '-' || !a[1]) {
            if (pos) return bad_opt("argument", a, "only one INPUT or SURFACE is accepted");
            pos = a;
            continue;
        }
        char name[32];
        const char *val, *eq = strchr(a, '=');
        if (eq && (size_t)(eq - a) < sizeof name) {
            memcpy(name, a, (size_t)(eq - a));
            name[eq - a] = '\0';
            val = eq + 1;
        } else {
            snprintf(name, sizeof name, "%s", a);
            if (i + 1 >= argc) return bad_opt(a, "", "needs a value");
            val = argv[++i];
        }
        int iv;
        if (!strcmp(name, "-o") || !strcmp(name, "--output")) c->dir = val;
        else if (!strcmp(name, "--truth")) s->truth = val;
        else if (!strcmp(name, "--subset")) s->subset = val;
        else if (!strcmp(name, "--neighbors") || !strcmp(name, "--neighbours")) c->nb_text = val;
        else if (!strcmp(name, "--degree")) c->deg_text = val;
        else if (!strcmp(name, "--flags")) c->flags_text = val;
        else if (!strcmp(name, "--noise")) noise = val;
        else if (!strcmp(name, "--noise-uniform")) noise_u = val;
        else if (!strcmp(name, "--outliers")) outl = val;
        else if (!strcmp(name, "--metrics")) c->metrics_text = val;
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
        } else {
            return bad_opt("unknown option", a, "not an option of study");
        }
    }
    if (!pos) return bad_opt("INPUT", "", "missing INPUT file or SURFACE name");
    if (!c->dir || !c->dir[0]) return bad_opt("-o", "", "missing output folder DIR");
    s->input = pos;
    if (!s->truth) {
        if (jf_surface_parse(pos, &c->surf))
            return bad_opt("SURFACE", pos, "not a surface (exp, paraboloid, revolution, sphere, ellipsoid, cylinder); an INPUT file needs --truth");
        c->is_surface = 1;
        if (!c->npoints) c->npoints = DEFAULT_N;
    } else if (c->npoints) {
        return bad_opt("--n", "", "applies to a SURFACE, not to INPUT --truth");
    }
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
    return make_settings(c);
}

/* ---- files ---- */

static int load_input(study_cmd *c)
{
    jf_study *s = &c->s;
    jf_error e = {{0}};
    char msg[4200];
    size_t nt = 0;
    jf_status st = jf_cloud_read(s->input, &c->base.ro, &c->cloud, &e);
    if (st != JF_OK) {
        fprintf(stderr, "jetfit: %s\n", e.msg[0] ? e.msg : jf_strerror(st));
        return 1;
    }
    if (!(c->truth = jf_cli_truth_load(s->truth, &nt, &c->truth_k, msg, sizeof msg))) {
        fprintf(stderr, "jetfit: %s\n", msg);
        return 1;
    }
    if (nt != c->cloud.n) {
        fprintf(stderr, "jetfit: %s: %zu rows, %s has %zu points\n", s->truth, nt, s->input,
                c->cloud.n);
        return 1;
    }
    /* as estimate: input normals orient the result unless told otherwise */
    if (!c->base.orient_set && c->cloud.nrm)
        for (int i = 0; i < c->nsetting; i++) c->setting[i].orient = JF_ORIENT_INPUT;
    return 0;
}

/* DIR made if missing; temporaries a killed study left removed. */
static int prepare_dir(const char *dir)
{
    struct stat sb;
    if (stat(dir, &sb) == 0) {
        if (!S_ISDIR(sb.st_mode)) {
            fprintf(stderr, "jetfit: %s: not a folder\n", dir);
            return 1;
        }
    } else if (mkdir(dir, 0777)) {
        fprintf(stderr, "jetfit: %s: %s\n", dir, strerror(errno));
        return 1;
    }
    static const char *const ours[] = {".study.csv.tmp.", ".best.csv.tmp.", ".normal.png.tmp.",
                                       ".curvature.png.tmp.", ".k.png.tmp.", ".report.html.tmp."};
    DIR *d = opendir(dir);
    struct dirent *en;
    while (d && (en = readdir(d))) {
        for (size_t k = 0; k < sizeof ours / sizeof ours[0]; k++) {
            if (strncmp(en->d_name, ours[k], strlen(ours[k]))) continue;
            char p[4096];
            snprintf(p, sizeof p, "%s/%s", dir, en->d_name);
            remove(p);
        }
    }
    if (d) closedir(d);
    return 0;
}

/* ---- the command ---- */

int jf_cmd_study(int argc, char **argv)
{
    study_cmd c;
    memset(&c, 0, sizeof c);
    int rc = parse_args(&c, argc, argv);
    if (rc) {
        free_cmd(&c);
        return rc < 0 ? 0 : rc;
    }
    jf_study *s = &c.s;
    record_command(s, argc, argv);
    char msg[4200];
    if (!c.is_surface && load_input(&c)) goto fail;
    if (s->subset) {
        size_t n = c.is_surface ? c.npoints : c.cloud.n;
        if (jf_cli_subset_load(s->subset, n, &c.sel, &c.nsel, msg, sizeof msg)) {
            fprintf(stderr, "jetfit: %s\n", msg);
            goto fail;
        }
    }
    if (make_cells(&c) || prepare_dir(c.dir)) goto fail;
    int kept = 0;
    if (c.resume && (kept = jf_study_read_csv(s, c.dir, msg, sizeof msg)) < 0) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    /* without --resume a new study replaces the table at once */
    if (jf_study_write_csv(s, c.dir, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    size_t n = c.is_surface ? c.npoints : c.cloud.n, nsel = c.sel ? c.nsel : n;
    jf_result *res = malloc(n * sizeof *res);
    double *truth5 = malloc(5 * n * sizeof *truth5), *err[3];
    for (int q = 0; q < 3; q++) err[q] = malloc((nsel ? nsel : 1) * sizeof *err[q]);
    if (!res || !truth5 || !err[0] || !err[1] || !err[2]) {
        fprintf(stderr, "jetfit: out of memory (%zu points)\n", n);
        free(res), free(truth5), free(err[0]), free(err[1]), free(err[2]);
        goto fail;
    }
    study_progress pg = {now_s(), 0, 0, 0, 0, 0, ""};
    for (size_t i = 0; i < s->ncells; i++) pg.cells_todo += !s->cell[i].done;
    pg.units_total = pg.cells_todo * n;
    int show = !c.quiet && isatty(2);
    if (kept && !c.quiet)
        fprintf(stderr, "jetfit study: resuming: %d of %zu cells kept from %s/study.csv\n", kept,
                s->ncells, c.dir);
    size_t nfailed = 0;
    int werr = 0;
    /* one draw per (noise level, repeat): a run of nsetting cells */
    struct sigaction sa, old_int, old_term;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    for (size_t g = 0; g < s->ncells && !werr && !stop_asked; g += (size_t)c.nsetting) {
        int todo = 0;
        for (int j = 0; j < c.nsetting; j++) todo |= !s->cell[g + (size_t)j].done;
        if (!todo) continue;
        jf_sample smp;
        jf_status st = make_draw(&c, &s->cell[g].key, &smp, truth5);
        for (int j = 0; j < c.nsetting && !werr && !stop_asked; j++) {
            jf_study_cell *cl = &s->cell[g + (size_t)j];
            if (cl->done) continue;
            char label[200];
            jf_study_label(s, &cl->key, label, sizeof label);
            pg.cell_no++;
            { /* the line shows the label's start */
                size_t m = strlen(label) < sizeof pg.label - 1 ? strlen(label) : sizeof pg.label - 1;
                memcpy(pg.label, label, m);
                pg.label[m] = '\0';
            }
            if (st != JF_OK) { /* the draw itself failed: its cells fail */
                cl->done = 1;
                snprintf(cl->status, sizeof cl->status, "failed: cannot make the draw: %s", jf_strerror(st));
                for (int m = 0; m < JF_M_COUNT; m++) cl->m[m] = NAN;
                cl->seconds = cl->points_per_s = NAN;
            } else if (run_cell(&c, cl, &smp, truth5, res, err, show ? &pg : NULL)) {
                break; /* interrupted */
            }
            pg.units_done += n;
            if (strcmp(cl->status, "ok")) {
                nfailed++;
                if (show) fputc('\n', stderr);
                fprintf(stderr, "jetfit: %s: cell %s, noise %g/%g/%g, repeat %d: %s\n", s->input,
                        label, s->noise[cl->key.noise], s->noise_u[cl->key.noise_u],
                        s->outliers[cl->key.outliers], cl->key.repeat, cl->status);
            }
            if (jf_study_write_csv(s, c.dir, msg, sizeof msg)) werr = 1;
        }
        jf_sample_free(&smp);
    }
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    if (show && pg.cell_no) fputc('\n', stderr);
    free(res), free(truth5), free(err[0]), free(err[1]), free(err[2]);
    if (stop_asked && !werr) {
        size_t done = 0;
        for (size_t i = 0; i < s->ncells; i++) done += s->cell[i].done != 0;
        fprintf(stderr, "jetfit study: interrupted: %zu of %zu cells in %s/study.csv; the same "
                        "command with --resume goes on\n", done, s->ncells, c.dir);
        free_cmd(&c);
        return 130;
    }
    if (werr || jf_study_write_best(s, c.dir, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    int nplots = jf_study_plots(s, c.dir, msg, sizeof msg);
    if (nplots < 0) fprintf(stderr, "jetfit study: no plots: %s\n", msg);
    if (jf_study_report(s, c.dir, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    if (!c.quiet)
        fprintf(stderr, "jetfit study: %zu cells (%zu run, %zu failed) in %.1f s: %s/report.html\n",
                s->ncells, pg.cell_no, nfailed, now_s() - pg.t0, c.dir);
    free_cmd(&c);
    return 0;
fail:
    free_cmd(&c);
    return 1;
}
