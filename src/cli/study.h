/* study.h -- `jetfit study`'s table, shared by its files: cmd_study.c (the
 * command: cells, draws, running them), study_args.c (the command line),
 * study_csv.c (study.csv, best.csv,
 * means over repeats), study_plot.c (gnuplot PNGs), study_report.c (the
 * self-contained report.html). */
#ifndef JF_STUDY_H
#define JF_STUDY_H

#include <stddef.h>
#include <stdio.h>

#include "jetfit.h"

/* The metrics a cell reports (study.csv columns, best.csv's `metric`):
 * the unoriented normal angle in degrees and PCPNet's relative curvature
 * error |k - k_t| / max(|k_t|, 1), as `jetfit eval` prints them. */
enum {
    JF_M_NORMAL_RMS, JF_M_NORMAL_MEDIAN, JF_M_NORMAL_P95,
    JF_M_K1_MEDIAN, JF_M_K1_P95, JF_M_K2_MEDIAN, JF_M_K2_P95,
    JF_M_COUNT
};
extern const char *const jf_study_metric[JF_M_COUNT];

/* Where a cell sits in the study: setting (strategy, degree, flags) and
 * noise level (noise, noise_uniform, outliers), each an index into the
 * study's lists, and its repeat. */
typedef struct {
    int strategy, degree, flags, noise, noise_u, outliers, repeat;
} jf_study_key;

/* One cell: one estimate of one noisy draw, its errors and counts. */
typedef struct {
    jf_study_key key;
    int done;              /* finished (ok or failed): in study.csv    */
    unsigned long long seed;
    size_t points;         /* points estimated                          */
    size_t normal_n;       /* points with a finite normal error        */
    double m[JF_M_COUNT];
    size_t ok, lowered, failed, flagged; /* point status counts:
                              0; a LOWERED bit; JF_PT_FAILED; nonzero   */
    char status[600];      /* "ok" or "failed: reason" (one line)      */
    double seconds, points_per_s;
} jf_study_cell;

typedef struct {
    /* the lists (strings as given; numbers parsed) */
    char **strategy;  int nstrategy;
    int *degree;      int ndegree;
    char **flags;     int nflags;
    double *noise;    int nnoise;
    double *noise_u;  int nnoise_u;
    double *outliers; int noutliers;
    int repeat;
    unsigned long long seed;
    int best[JF_M_COUNT];  /* --metrics: which metrics best.csv lists  */
    /* what was studied, for the report */
    const char *input, *truth, *subset;
    char command[2048];
    /* the cells, in plan order: noise level, repeat, setting */
    jf_study_cell *cell;
    size_t ncells;
} jf_study;

/* The plan's order (cmd_study.c makes the cells in it): noise, noise
 * uniform, outliers, repeat, strategy, degree, flags, the last fastest.
 * jf_study_setting: the key's setting among strategy x degree x flags;
 * jf_study_cell_index: the key's cell in s->cell. */
int jf_study_setting(const jf_study *s, const jf_study_key *k);
size_t jf_study_cell_index(const jf_study *s, const jf_study_key *k);

/* The cell's setting as one label, "knn:16 d2 --robust-normals". */
void jf_study_label(const jf_study *s, const jf_study_key *k, char *buf, size_t len);

/* Mean and sample standard deviation over the repeats of one setting at
 * one noise level (cells with a finite value; sd 0 for one). */
typedef struct {
    double mean, sd;
    int n;
} jf_study_stat;
void jf_study_mean(const jf_study *s, const jf_study_key *k, int metric, jf_study_stat *out);

/* The setting with the lowest mean of `metric` at noise level lvl (its
 * noise indices; strategy, degree, flags, repeat ignored); ties: the
 * first in plan order.  0 if no setting has a finite mean. */
int jf_study_best(const jf_study *s, const jf_study_key *lvl, int metric, jf_study_key *best,
                  jf_study_stat *bs);

/* Files of DIR, each written to a jf_tmpfile (exclusive, unpredictable
 * name, removed on a signal) and renamed whole: 0, or -1 with one line in
 * msg. */
int jf_study_write_csv(const jf_study *s, const char *dir, char *msg, size_t len);
int jf_study_write_best(const jf_study *s, const char *dir, char *msg, size_t len);
/* Marks the cells found in DIR/study.csv as done, with its values;
 * returns how many, or -1 with msg (a malformed file). */
int jf_study_read_csv(jf_study *s, const char *dir, char *msg, size_t len);

/* The plots: DIR/normal.png, DIR/curvature.png, DIR/k.png (the last only
 * when two strategies differ by K alone).  Returns how many were made,
 * -2 with msg when gnuplot is missing (the plots are optional), or -1
 * with msg (gnuplot failed, a picture was cut short, a rename failed). */
int jf_study_plots(const jf_study *s, const char *dir, char *msg, size_t len);

/* DIR/report.html from the cells, best.csv's choice and the PNGs found
 * in DIR.  0, or -1 with msg. */
int jf_study_report(const jf_study *s, const char *dir, char *msg, size_t len);

/* Helpers shared by the writers: "DIR/NAME"; an output of DIR as a
 * stdio stream over a jf_tmpfile, committed (renamed onto DIR/NAME) or,
 * after an error, discarded. */
void jf_study_path(const char *dir, const char *name, char *buf, size_t len);
typedef struct {
    jf_tmpfile t;
    FILE *f;
    char final[4096];
} jf_study_out;
int jf_study_out_open(jf_study_out *o, const char *dir, const char *name, char *msg, size_t len);
int jf_study_out_commit(jf_study_out *o, char *msg, size_t len);

/* Which noise list the plots put on x: the first with several values
 * (noise, noise_uniform, outliers), else noise: 0, 1, 2. */
int jf_study_noise_axis(const jf_study *s);

#endif
