/* robust_internal.h -- shared by robust.c (IRLS, the fitter's state),
 * select.c (a normal's uncertainty, degree selection) and scale.c (scale
 * selection, jf_fit_point_full).  Not part of the public API. */
#ifndef JF_ROBUST_INTERNAL_H
#define JF_ROBUST_INTERNAL_H

#include <stddef.h>

#include "jetfit.h"

/* Neighbourhoods up to this size use the caller's stack for the 4n
 * doubles of residuals and weights; larger ones the fitter's buffer. */
#define JF_STACK_N 512

/* Tuning constants of the selection rules and of neighbors auto
 * (defaults and reasons in robust.c and auto.c).  Each fitter carries its
 * own copy (the defaults until jf__robust_tune changes them): the library
 * keeps no mutable global. */
typedef struct {
    double scale_varw;   /* scale selection: weight of the variance */
    double scale_target; /* scale selection: stop once sd is below (rad) */
    double scale_floor;  /* normal sd floor: sigma/h above this is a blob */
    double degree_tau;   /* degree selection: interval width, in sd */
    double degree_sdmin; /* degree selection: keep the top degree below */
    double degree_floor_n; /* degree selection: the blob floor shrinks as
                              sqrt(degree_floor_n / n) above this n */
    double auto_tau, auto_blob, auto_sdmax, auto_clean, auto_varw; /* auto.c */
    int auto_gl;
    double auto_nest; /* auto.c: > 0: Lepski on nested variances (dropped) */
    double auto_lof, auto_s2floor; /* auto_rule.c (off: 0; dropped) */
    double auto_flat; /* auto.c step 2: the flat test's z (off: 0) */
    double auto_dw;   /* auto.c step 5: distance weights (off: 0; dropped) */
    struct jf__auto_diag *auto_diag; /* bench-only: auto's candidates out */
} jf__knobs;
extern const jf__knobs jf__knob_defaults;

/* Fitter f's tuning (the defaults when its state cannot be made). */
const jf__knobs *jf__knobs_of(jf_fitter *f);
/* Bench- and test-only setter of one of f's knobs by name (a field of
 * jf__knobs); 0, or -1 if unknown or out of memory. */
int jf__robust_tune(jf_fitter *f, const char *name, double v);

/* Neither failed nor non-finite: the fit's quantities can be used. */
int jf__usable(const jf_result *r);

/* Fitter f's scratch of at least `need` doubles (NULL: out of memory),
 * and its companion fitter of degree d with pr's other fitting parameters:
 * both live with f (the caller's workspace) and are freed with it. */
double *jf__ws_buf(jf_fitter *f, size_t need);
jf_fitter *jf__ws_fitter(jf_fitter *f, const jf_params *pr, int d);

/* One fit of the first n neighbours, distance-weighted when dist_c > 0
 * and reweighted when pr->robust asks.  buf: 4n doubles.  *sigma: noise
 * scale of the final fit; *neff: Kish's effective sample size. */
jf_status jf__fit_robust(jf_fitter *f, const jf_params *pr, const double p[3],
                         const double *nbr, size_t n, double *buf, double dist_c,
                         jf_result *out, double *sigma, double *neff);

/* Standard deviation (radians) of the normal of fit r of n points with
 * noise variance s2; INFINITY when undefined. */
double jf__normal_sd(const jf__knobs *k, const jf_result *r, double s2, const double p[3], const double *nbr,
                     size_t n);
/* Unbiased residual variance of r from its residual scale sigma. */
double jf__unbiased_var(const jf_result *r, double sigma, size_t n);
/* Angle (radians) between two unoriented unit vectors. */
double jf__angle(const double a[3], const double b[3]);
/* jf__angle(a, b) <= thr, the same answer, mostly without acos (auto_rule.c). */
int jf__angle_le(const double a[3], const double b[3], double thr);

/* The fit with degree selection and distance weights as pr asks (the
 * plain or reweighted fit when neither is set). */
jf_status jf__fit_select(jf_fitter *f, const jf_params *pr, const double p[3],
                         const double *nbr, size_t n, double *buf, jf_result *out,
                         double *sigma);

/* neighbors auto (auto.c): chooses K among the first entries of nbr
 * (nearest first) and the degree; fills out->sigma. */
jf_status jf__fit_auto(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                       size_t n, jf_result *out);
/* jf__fit_auto of L <= 4 points (p[l], its nbr[l] of n[l]) into out[l],
 * their fits' eigen-steps side by side: the bits of one by one. */
jf_status jf__fit_auto_lanes(jf_fitter *f, const jf_params *pr, int L, const double *const p[],
                             const double *const nbr[], const size_t n[], jf_result *const out[]);

/* neighbors auto's candidates (auto.c step 1-2, read by auto_rule.c). */
#define JF_AUTO_NCAND 10
extern const size_t jf__auto_ks[JF_AUTO_NCAND]; /* the candidates' K, increasing */
typedef struct {
    int ok;
    double nrm[3]; /* world normal (in step 1's frame)               */
    double tr;     /* sd^2 of the normal's angle per unit noise var  */
    double s2;     /* unbiased residual variance                     */
    double h;      /* radius (farthest planar distance)              */
} jf__auto_cand;
typedef struct {
    int nc;                              /* candidates                */
    size_t ks[JF_AUTO_NCAND];            /* their K, increasing       */
    jf__auto_cand cf[2][JF_AUTO_NCAND]; /* [0] quadric, [1] cubic    */
    double s2;                           /* the noise variance (step 2) */
} jf__auto_cands;
/* Steps 3-4 (auto_rule.c): the chosen candidate's index (-1: none) and
 * its degree (*d, 2 or 3). */
int jf__auto_rule(const jf__knobs *kn, const jf__auto_cands *c, int *d);

/* Step 0 (the cloud's cross-validation) at one point p, its list nbr
 * nearest first (p itself first): out[c] the squared leave-one-out
 * residual at p of the quadric on the first cand[c] points, in step 1's
 * frame (NaN where that candidate is not there or not fitted),
 * out[JF_AUTO_NCAND] step 2's sigma over the 16th neighbour's distance
 * (|nbr[16] - p|), and out[JF_AUTO_CV_SMALL], out[JF_AUTO_CV_SMALL + 1]
 * the quadric's and the cubic's on the smallest candidate, in the frame
 * of its own points, and out[JF_AUTO_CV_BIAS] the squared angle between
 * the quadric's and the cubic's normals on the largest candidate (in step
 * 1's frame) over the variance the noise alone gives it (sigma^2 times
 * the cubic's angle variance less the quadric's: nested least squares),
 * out[JF_AUTO_CV_BIAS32] the same on 32 points (JF_AUTO_CV_K32);
 * all NaN where steps 1-2 fail.  The decision from a sample of these:
 * auto_cloud.c. */
#define JF_AUTO_CV_SMALL (JF_AUTO_NCAND + 1)
#define JF_AUTO_CV_BIAS (JF_AUTO_CV_SMALL + 2)
#define JF_AUTO_CV_BIAS32 (JF_AUTO_CV_BIAS + 1)
#define JF_AUTO_CV_N (JF_AUTO_CV_BIAS32 + 1)
#define JF_AUTO_CV_K32 2 /* jf__auto_ks[JF_AUTO_CV_K32] == 32 */
/* Under JF_AUTO_CAPPED_WEIGHTED step 0's cap is at least this, and no
 * capped row's candidate below it or the cap (docs/robustness.md, item 8). */
#define JF_AUTO_CAPW_KMIN 32
void jf__auto_cv_point(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                       size_t n, double out[JF_AUTO_CV_N]);

/* Bench-only (tests/bench/bench_auto_diag.cpp): with jf__auto_diag_attach,
 * every auto fit of f also fills *dg: the candidates, the choice, and each
 * candidate's reported fit (res[degree - 2][i], as knn:K --degree d). */
typedef struct jf__auto_diag {
    jf__auto_cands c;
    int ci, d;
    jf_result res[2][JF_AUTO_NCAND];
} jf__auto_diag;
int jf__auto_diag_attach(jf_fitter *f, jf__auto_diag *dg);
#endif
