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
 * its finished cells and --resume skips them.  The command line:
 * study_args.c; the files: study_csv.c, study_plot.c, study_report.c. */
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
#include "pipes.h"
#include "study_args.h"
#include "view.h"

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
    stop_asked = sig; /* the exit status is 128 + sig, as main.c's */
}

static int cancel_hook(void *user)
{
    (void)user;
    return stop_asked != 0;
}

static int make_cells(jf_study_args *c)
{
    jf_study *s = &c->s;
    size_t nlev = (size_t)s->nnoise * (size_t)s->nnoise_u * (size_t)s->noutliers;
    s->ncells = nlev * (size_t)s->repeat * (size_t)c->nsetting;
    s->cell = calloc(s->ncells, sizeof *s->cell);
    if (!s->cell) {
        fprintf(stderr, "jetfit: out of memory (%zu cells)\n", s->ncells);
        return 1;
    }
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
                                cl->points = c->ndraw;
                            }
    return 0;
}

/* ---- one noisy draw ---- */

/* The draw of cell key k (its noise level and repeat) into *smp: what
 * `jetfit generate` writes for a SURFACE, or the INPUT with that noise.
 * truth5 gets nx ny nz k1 k2 per point (NaN rows for outliers). */
static jf_status make_draw(const jf_study_args *c, const jf_study_key *k, jf_sample *smp,
                           double *truth5)
{
    const jf_study *s = &c->s;
    jf_rng rng;
    jf_rng_seed(&rng, (uint64_t)(s->seed + (unsigned long long)k->repeat));
    jf_status st;
    memset(smp, 0, sizeof *smp);
    if (c->is_surface && c->mesh) {
        st = jf_sample_grid(c->surf, jf_sample_grid_h_for(c->surf, c->npoints), 0.9, 1, &rng, smp);
        if (st) return st;
    } else if (c->is_surface) {
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
static int run_cell(jf_study_args *c, jf_study_cell *cl, const jf_sample *smp, const double *truth5,
                    jf_result *res, double *err[3], study_progress *pp)
{
    const jf_study *s = &c->s;
    jf_estimate_opts o = c->setting[jf_study_setting(s, &cl->key)];
    jf_cloud cloud = {.n = smp->n, .xyz = smp->xyz, .nfaces = smp->nfaces,
                      .face_off = smp->face_off, .face_idx = smp->face_idx};
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
        unsigned u = res[i].status & ~(unsigned)JF_CLI_HOW_FLAGS;
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

/* ---- files ---- */

static int load_input(jf_study_args *c)
{
    jf_study *s = &c->s;
    jf_error e = {{0}};
    char msg[4200];
    size_t nt = 0;
    /* '-' (standard input) or --input-format: through a private file
     * (pipes.c), read once and hashed for study.def, then removed: the
     * cells work on the cloud in memory */
    jf_cli_in in;
    jf_status st = jf_cli_in_begin(&in, s->input, c->in_fmt, &e);
    if (st == JF_OK) st = jf_cloud_read(in.path, &c->base.ro, &c->cloud, &e);
    if (st == JF_OK &&
        jf_study_def_identity(in.path, c->input_id, sizeof c->input_id, e.msg, sizeof e.msg))
        st = JF_ERR_IO;
    if (in.dir[0]) s->input = in.shown; /* messages and the report name what was given */
    jf_cli_in_end(&in, st == JF_OK ? NULL : &e);
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
    /* as eval: a truth with coordinates must be about this cloud */
    char names[3][32] = {"x", "y", "z"};
    jf_eval_table view = {.nrows = c->cloud.n, .ncols = 3, .names = names, .v = c->cloud.xyz};
    if (jf_cli_truth_coords_check(s->truth, &view, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        return 1;
    }
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
    } else if (lstat(dir, &sb) == 0 && S_ISLNK(sb.st_mode)) {
        /* mkdir would say "File exists" (issue 33.12) */
        fprintf(stderr, "jetfit: %s: a symbolic link to a folder that does not exist\n", dir);
        return 1;
    } else if (mkdir(dir, 0777)) {
        fprintf(stderr, "jetfit: %s: %s\n", dir, strerror(errno));
        return 1;
    }
    /* jf_tmpfile names: ".NAME.RANDOM.tmp", RANDOM a few letters and
     * digits (io_tmpfile.c) */
    static const char *const ours[] = {"study.csv", "best.csv", "normal.png", "curvature.png",
                                       "k.png", "report.html", "best.ply", "view.html"};
    DIR *d = opendir(dir);
    struct dirent *en;
    while (d && (en = readdir(d))) {
        const char *nm = en->d_name;
        size_t ln = strlen(nm);
        for (size_t k = 0; k < sizeof ours / sizeof ours[0]; k++) {
            size_t lo = strlen(ours[k]), mid = ln > lo + 6 ? ln - lo - 6 : 0;
            if (nm[0] != '.' || mid < 6 || mid > 16 || strncmp(nm + 1, ours[k], lo) ||
                nm[1 + lo] != '.' || strcmp(nm + ln - 4, ".tmp"))
                continue;
            int plain = 1;
            for (size_t j = 2 + lo; j < 2 + lo + mid; j++) plain &= isalnum((unsigned char)nm[j]) != 0;
            if (!plain) continue;
            char p[4096];
            snprintf(p, sizeof p, "%s/%s", dir, nm);
            remove(p);
        }
    }
    if (d) closedir(d);
    return 0;
}

/* ---- the 3D view of the best setting (jetfit view) ---- */

/* DIR/best.ply, the best setting's result on the first noise level's
 * first draw (by the first --metrics metric, else the median normal
 * error), and DIR/view.html showing it.  0, 1 when there is no best
 * setting, -1 with msg. */
static int study_view(jf_study_args *c, char *msg, size_t len)
{
    jf_study *s = &c->s;
    int metric = JF_M_NORMAL_MEDIAN;
    for (int m = JF_M_COUNT - 1; m >= 0; m--)
        if (s->best[m]) metric = m;
    jf_study_key lvl = {0}, best;
    jf_study_stat bs;
    if (!jf_study_best(s, &lvl, metric, &best, &bs)) return 1;
    best.repeat = 0;
    size_t n = c->ndraw;
    jf_result *res = malloc(n * sizeof *res);
    double *truth5 = malloc(5 * n * sizeof *truth5);
    jf_sample smp = {0};
    jf_writer *w = NULL;
    jf_error e = {{0}};
    char ply[4200], html[4200];
    jf_study_path(c->dir, "best.ply", ply, sizeof ply);
    jf_study_path(c->dir, "view.html", html, sizeof html);
    jf_status st = res && truth5 ? make_draw(c, &best, &smp, truth5) : JF_ERR_NOMEM;
    jf_estimate_opts o = c->setting[jf_study_setting(s, &best)];
    if (st == JF_OK) {
        jf_cloud cloud = {.n = smp.n, .xyz = smp.xyz, .nfaces = smp.nfaces,
                          .face_off = smp.face_off, .face_idx = smp.face_idx};
        if (!c->is_surface) {
            cloud.nrm = c->cloud.nrm;
            cloud.nfaces = c->cloud.nfaces;
            cloud.face_off = c->cloud.face_off;
            cloud.face_idx = c->cloud.face_idx;
        }
        st = jf_estimate(&cloud, &o, res, &e);
    }
    jf_column cols[JF_RESULT_MAX_COLS];
    int monge = o.params.monge_degree;
    const int sigma = o.nb.kind == JF_NB_AUTO;
    size_t ncols = jf_result_columns(monge, sigma, cols);
    if (st == JF_OK) st = jf_writer_open(ply, cols, ncols, smp.n, 0, &w, &e);
    for (size_t i = 0; st == JF_OK && i < smp.n; i++) {
        double v[JF_RESULT_MAX_COLS];
        jf_result_row(smp.xyz + 3 * i, &res[i], monge, sigma, v);
        st = jf_writer_row(w, v);
    }
    if (w && st != JF_OK) jf_writer_abort(w);
    else if (w) st = jf_writer_commit(w, &e);
    jf_sample_free(&smp);
    free(res), free(truth5);
    if (st != JF_OK) {
        if (e.msg[0]) snprintf(msg, len, "%s", e.msg);
        else snprintf(msg, len, "%.4000s: %s", ply, jf_strerror(st));
        return -1;
    }
    char label[200], title[400];
    jf_study_label(s, &best, label, sizeof label);
    snprintf(title, sizeof title, "best by %s: %s, noise %g/%g/%g", jf_study_metric[metric], label,
             s->noise[0], s->noise_u[0], s->outliers[0]);
    jf_view_opts vo;
    jf_view_opts_init(&vo);
    vo.title = title;
    return jf_view_write(ply, html, &vo, 1, msg, len) ? -1 : 0;
}

/* ---- the command ---- */

int jf_cmd_study(int argc, char **argv)
{
    jf_study_args c;
    memset(&c, 0, sizeof c);
    int rc = jf_study_args_parse(&c, argc, argv);
    if (rc) {
        jf_study_args_free(&c);
        return rc < 0 ? 0 : rc;
    }
    jf_study *s = &c.s;
    char msg[4200];
    if (!c.is_surface && load_input(&c)) goto fail;
    c.ndraw = c.is_surface ? c.npoints : c.cloud.n;
    if (c.mesh) {
        /* a grid's vertex count follows from N and the surface (the
         * perturbation moves vertices only): make one to count them */
        jf_sample probe;
        jf_rng rng;
        jf_rng_seed(&rng, s->seed);
        jf_status st = jf_sample_grid(c.surf, jf_sample_grid_h_for(c.surf, c.npoints), 0.9, 0,
                                      &rng, &probe);
        if (st != JF_OK) {
            fprintf(stderr, "jetfit: %s --mesh --n %zu: %s\n", s->input, c.npoints,
                    jf_strerror(st));
            goto fail;
        }
        c.ndraw = probe.n;
        jf_sample_free(&probe);
    }
    if (s->subset) {
        if (jf_cli_subset_load(s->subset, c.ndraw, &c.sel, &c.nsel, msg, sizeof msg)) {
            fprintf(stderr, "jetfit: %s\n", msg);
            goto fail;
        }
    }
    if (make_cells(&c) || prepare_dir(c.dir)) goto fail;
    int kept = 0;
    char def[8192];
    if (jf_study_def_make(&c, def, sizeof def, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    /* a resume keeps cells of this study only (study_def.c) */
    char csv[4096];
    jf_study_path(c.dir, "study.csv", csv, sizeof csv);
    if (c.resume && access(csv, F_OK) == 0 && jf_study_def_check(c.dir, def, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    if (c.resume && (kept = jf_study_read_csv(s, c.dir, msg, sizeof msg)) < 0) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    if (jf_study_def_write(c.dir, def, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    /* without --resume a new study replaces the table at once */
    if (jf_study_write_csv(s, c.dir, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    size_t n = c.ndraw, nsel = c.sel ? c.nsel : n;
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
    /* an ignored signal (nohup, a background job) stays ignored, as in main.c */
    sigaction(SIGINT, NULL, &old_int);
    sigaction(SIGTERM, NULL, &old_term);
    if (old_int.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, NULL);
    if (old_term.sa_handler != SIG_IGN) sigaction(SIGTERM, &sa, NULL);
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
        jf_study_args_free(&c);
        return 128 + (int)stop_asked;
    }
    if (werr || jf_study_write_best(s, c.dir, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    int nplots = jf_study_plots(s, c.dir, msg, sizeof msg);
    if (nplots < 0) fprintf(stderr, "jetfit study: no plots: %s\n", msg);
    /* gnuplot missing is a note (the plots are optional); gnuplot failing,
     * or a picture cut short, is an error once the report is written */
    int plot_err = nplots == -1;
    if (study_view(&c, msg, sizeof msg) < 0) fprintf(stderr, "jetfit study: no 3D view: %s\n", msg);
    if (jf_study_report(s, c.dir, msg, sizeof msg)) {
        fprintf(stderr, "jetfit: %s\n", msg);
        goto fail;
    }
    if (!c.quiet)
        fprintf(stderr, "jetfit study: %zu cells (%zu run, %zu failed) in %.1f s: %s/report.html\n",
                s->ncells, pg.cell_no, nfailed, now_s() - pg.t0, c.dir);
    jf_study_args_free(&c);
    return plot_err ? 1 : 0;
fail:
    jf_study_args_free(&c);
    return 1;
}
