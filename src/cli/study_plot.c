/* study_plot.c -- `jetfit study`'s PNGs through gnuplot (pngcairo), one
 * gnuplot process for all of them (gnuplot.c: no shell, its messages kept
 * aside), data inline ($blocks), each PNG drawn into a jf_tmpfile:
 *   normal.png     median normal angle against noise, one line per
 *                  setting, error bars = spread over the repeats
 *   curvature.png  k1 and k2 median errors against noise, likewise
 *   k.png          median normal angle against K (knn:K, knn:K,radius:R,
 *                  natural:N), one line per kind, degree, flags and noise
 *                  level; only when some line has two K
 * The noise axis is the first list with several values (noise,
 * noise_uniform, outliers); the other two are held at their first value.
 * User text (labels hold --neighbors and --flags text; DIR is a path)
 * reaches gnuplot only through jf_gp_quote, where gnuplot expands nothing
 * (double-quoted strings would run backquotes). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gnuplot.h"
#include "jetfit.h"
#include "study.h"

/* Line i's look: 8 colours that read on white (Okabe & Ito's palette
 * without its yellow, which gnuplot's own 5th colour is), then the next
 * dash and point. */
static const char *style(int i)
{
    static const char *const rgb[8] = {"#0072b2", "#d55e00", "#009e73", "#cc79a7",
                                       "#000000", "#e69f00", "#56b4e9", "#8c564b"};
    static char buf[96];
    snprintf(buf, sizeof buf, "lw 2 lc rgb '%s' dt %d pt %d", rgb[i % 8], 1 + (i / 8) % 5,
             (int[]){7, 5, 9, 11, 13}[(i / 8) % 5]);
    return buf;
}

static const char *const axis_name[3] = {
    "Gaussian noise (fraction of the bounding-box diagonal)",
    "uniform noise (fraction of the largest side)", "outlier fraction"};

static int axis_len(const jf_study *s, int ax)
{
    return ax == 0 ? s->nnoise : ax == 1 ? s->nnoise_u : s->noutliers;
}

static double axis_val(const jf_study *s, int ax, int i)
{
    return ax == 0 ? s->noise[i] : ax == 1 ? s->noise_u[i] : s->outliers[i];
}

static void set_axis(jf_study_key *k, int ax, int i)
{
    if (ax == 0) k->noise = i;
    else if (ax == 1) k->noise_u = i;
    else k->outliers = i;
}

/* One plot command of metric m against noise, a line per setting with a
 * finite point; returns how many lines (0: nothing plotted). */
static int noise_lines(FILE *gp, const jf_study *s, int m, int first_block)
{
    int ax = jf_study_noise_axis(s), nl = 0, blk = first_block;
    double lo = INFINITY, hi = 0;
    jf_study_key k = {0};
    /* the data blocks */
    for (k.strategy = 0; k.strategy < s->nstrategy; k.strategy++)
        for (k.degree = 0; k.degree < s->ndegree; k.degree++)
            for (k.flags = 0; k.flags < s->nflags; k.flags++, blk++) {
                fprintf(gp, "$b%d << EOD\n", blk);
                for (int i = 0; i < axis_len(s, ax); i++) {
                    jf_study_key q = k;
                    set_axis(&q, ax, i);
                    jf_study_stat st;
                    jf_study_mean(s, &q, m, &st);
                    if (st.n) fprintf(gp, "%.9g %.9g %.9g\n", axis_val(s, ax, i), st.mean, st.sd);
                    if (st.n) lo = fmin(lo, st.mean), hi = fmax(hi, st.mean);
                }
                fprintf(gp, "EOD\n");
            }
    /* values that span more than a decade (errors at noise 0 against
     * noisy ones): a log axis, else the small ones lie flat on zero */
    fprintf(gp, lo > 0 && hi >= 20 * lo ? "set logscale y\n" : "unset logscale y\n");
    blk = first_block;
    for (k.strategy = 0; k.strategy < s->nstrategy; k.strategy++)
        for (k.degree = 0; k.degree < s->ndegree; k.degree++)
            for (k.flags = 0; k.flags < s->nflags; k.flags++, blk++) {
                int any = 0;
                for (int i = 0; i < axis_len(s, ax); i++) {
                    jf_study_key q = k;
                    set_axis(&q, ax, i);
                    jf_study_stat st;
                    jf_study_mean(s, &q, m, &st);
                    any |= st.n > 0;
                }
                if (!any) continue;
                char label[600];
                jf_study_label(s, &k, label, sizeof label);
                fprintf(gp, nl ? ", \\\n  " : "plot ");
                fprintf(gp, "$b%d using 1:2:3 with yerrorlines %s title ", blk, style(nl));
                jf_gp_quote(gp, label);
                nl++;
            }
    if (nl) fputc('\n', gp);
    return nl;
}

/* The size a strategy gives K (knn, knn+radius) or N (natural), or 0. */
static size_t strategy_size(const char *text, char *kind, size_t len)
{
    jf_nb_spec sp;
    if (jf_nb_parse(text, &sp, NULL) != JF_OK) return 0;
    if (sp.kind == JF_NB_KNN) {
        snprintf(kind, len, "knn");
        return sp.k;
    }
    if (sp.kind == JF_NB_KNN_RADIUS) {
        snprintf(kind, len, "knn radius:%g", sp.r);
        return sp.k;
    }
    if (sp.kind == JF_NB_NATURAL && sp.n) {
        snprintf(kind, len, "natural");
        return sp.n;
    }
    return 0;
}

/* Lines of the K plot: for each kind x degree x flags x noise value, the
 * strategies of that kind in increasing K.  mode 0 counts, 1 writes the
 * data blocks, 2 the plot command; returns the number of lines with >= 2
 * K. */
static int k_lines(FILE *gp, const jf_study *s, int mode)
{
    int ax = jf_study_noise_axis(s), nl = 0, blk = 0, write_blocks = mode == 1;
    size_t *kk = malloc((size_t)s->nstrategy * sizeof *kk);
    char (*kind)[64] = malloc((size_t)s->nstrategy * sizeof *kind);
    if (!kk || !kind) {
        free(kk);
        free(kind);
        return 0;
    }
    for (int a = 0; a < s->nstrategy; a++) kk[a] = strategy_size(s->strategy[a], kind[a], 64);
    for (int a = 0; a < s->nstrategy; a++) {
        int lead = kk[a] > 0; /* the first strategy of its kind leads a group */
        for (int b = 0; lead && b < a; b++) lead = !(kk[b] && !strcmp(kind[a], kind[b]));
        if (!lead) continue;
        jf_study_key k = {0};
        for (k.degree = 0; k.degree < s->ndegree; k.degree++)
            for (k.flags = 0; k.flags < s->nflags; k.flags++)
                for (int i = 0; i < axis_len(s, ax); i++) {
                    set_axis(&k, ax, i);
                    if (write_blocks) fprintf(gp, "$k%d << EOD\n", blk);
                    int pts = 0;
                    /* the group's strategies, by increasing K */
                    size_t last = 0;
                    for (;;) {
                        int next = -1;
                        for (int b = 0; b < s->nstrategy; b++)
                            if (kk[b] > last && !strcmp(kind[a], kind[b]) &&
                                (next < 0 || kk[b] < kk[next]))
                                next = b;
                        if (next < 0) break;
                        last = kk[next];
                        k.strategy = next;
                        jf_study_stat st;
                        jf_study_mean(s, &k, JF_M_NORMAL_MEDIAN, &st);
                        if (!st.n) continue;
                        pts++;
                        if (write_blocks)
                            fprintf(gp, "%zu %.9g %.9g\n", kk[next], st.mean, st.sd);
                    }
                    if (write_blocks) fprintf(gp, "EOD\n");
                    if (pts >= 2 && mode == 2) {
                        char label[700];
                        const char *fl = s->flags[k.flags];
                        snprintf(label, sizeof label, "%s d%d%s%s, noise %g", kind[a],
                                 s->degree[k.degree], fl[0] ? " " : "", fl, axis_val(s, ax, i));
                        fprintf(gp, nl ? ", \\\n  " : "plot ");
                        fprintf(gp, "$k%d using 1:2:3 with yerrorlines %s title ", blk, style(nl));
                        jf_gp_quote(gp, label);
                    }
                    nl += pts >= 2;
                    blk++;
                }
    }
    if (nl && mode == 2) fputc('\n', gp);
    free(kk);
    free(kind);
    return nl;
}

static void set_output(FILE *gp, const jf_tmpfile *t)
{
    jf_gp_output(gp, t->fd); /* a descriptor: no name to swap, none to quote */
}

int jf_study_plots(const jf_study *s, const char *dir, char *msg, size_t len)
{
    static const char *const names[3] = {"normal.png", "curvature.png", "k.png"};
    int made[3] = {0, 0, 0};
    char path[3][4096];
    jf_tmpfile tf[3];
    jf_error e = {{0}};
    /* a previous study's plots must not outlive this one's table */
    for (int p = 0; p < 3; p++) {
        jf_study_path(dir, names[p], path[p], sizeof path[p]);
        remove(path[p]);
    }
    /* gnuplot draws into temporaries made here (exclusive, unpredictable
     * names), renamed once it has succeeded */
    for (int p = 0; p < 3; p++)
        if (jf_tmpfile_open(path[p], &tf[p], &e) != JF_OK) {
            for (int q = 0; q < p; q++) jf_tmpfile_discard(&tf[q]);
            snprintf(msg, len, "%s", e.msg);
            return -1;
        }
    jf_gp g;
    int fds[3] = {tf[0].fd, tf[1].fd, tf[2].fd};
    if (jf_gp_open(&g, fds, 3, msg, len)) {
        for (int p = 0; p < 3; p++) jf_tmpfile_discard(&tf[p]);
        return g.missing ? -2 : -1;
    }
    FILE *gp = g.in;
    int ax = jf_study_noise_axis(s);
    fprintf(gp, "set terminal pngcairo size 960,600 font ',10' noenhanced\n"
                "set grid\nset key outside right top\nset xlabel ");
    jf_gp_quote(gp, axis_name[ax]);
    fputc('\n', gp);
    int nset = s->nstrategy * s->ndegree * s->nflags;

    /* normal.png */
    set_output(gp, &tf[0]);
    fprintf(gp, "set title 'normal error against noise (mean over repeats, bars: spread)'\n"
                "set ylabel 'median normal angle (degrees)'\n");
    made[0] = noise_lines(gp, s, JF_M_NORMAL_MEDIAN, 0) > 0;
    fprintf(gp, "unset output\n");

    /* curvature.png: two panels */
    fprintf(gp, "set terminal pngcairo size 960,900 font ',10' noenhanced\n");
    set_output(gp, &tf[1]);
    fprintf(gp, "set multiplot layout 2,1\nset title 'k1 error against noise'\n"
                "set ylabel 'median |k1 - k1_true| / max(|k1_true|, 1)'\n");
    int c1 = noise_lines(gp, s, JF_M_K1_MEDIAN, nset);
    fprintf(gp, "set title 'k2 error against noise'\n"
                "set ylabel 'median |k2 - k2_true| / max(|k2_true|, 1)'\n");
    int c2 = noise_lines(gp, s, JF_M_K2_MEDIAN, 2 * nset);
    fprintf(gp, "unset multiplot\nunset output\n");
    made[1] = c1 > 0 || c2 > 0;

    /* k.png */
    if (k_lines(gp, s, 0) > 0) {
        fprintf(gp, "set terminal pngcairo size 960,600 font ',10' noenhanced\n");
        set_output(gp, &tf[2]);
        fprintf(gp, "set title 'normal error against neighbourhood size'\n"
                    "set xlabel 'K (knn) or N (natural)'\n"
                    "set ylabel 'median normal angle (degrees)'\n");
        k_lines(gp, s, 1);
        k_lines(gp, s, 2);
        fprintf(gp, "unset output\n");
        made[2] = 1;
    }
    int bad = jf_gp_close(&g, msg, len) != 0, n = 0;
    /* gnuplot does not report a failed write: every picture is checked
     * before any is renamed, so a full disk leaves the old ones */
    for (int p = 0; p < 3 && !bad; p++)
        if (made[p] && jf_gp_png_whole(tf[p].fd, msg, len)) {
            char m2[600];
            snprintf(m2, sizeof m2, "%s: %s", path[p], msg);
            snprintf(msg, len, "%s", m2);
            bad = 1;
        }
    for (int p = 0; p < 3; p++) {
        if (!bad && made[p] && jf_tmpfile_commit(&tf[p], path[p], &e) == JF_OK) n++;
        else if (!bad && made[p]) {
            snprintf(msg, len, "%s", e.msg);
            bad = 1;
        } else jf_tmpfile_discard(&tf[p]);
    }
    return bad ? -1 : n;
}
