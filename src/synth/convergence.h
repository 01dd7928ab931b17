/* convergence.h -- the §6.1 convergence experiment as a library call
 * (internal header: src/synth/convergence.c; used by cmd_convergence.c and
 * tests/synth/test_convergence_mesh.c).
 *
 * Setup (§6.1): the graph f(u,v) = 0.1 exp(2u + v - v^2) sampled on a
 * triangulated square grid of side h, each vertex moved by (d h, d' h),
 * d, d' uniform in [0, 0.9]; the grid's connectivity gives the
 * neighbourhoods (mesh rings, exactly as `jetfit estimate --neighbors
 * rings` chooses them: N_n points for interpolation, the fewest whole
 * rings with >= 2 N_n points for approximation).  Selected points: the
 * grid vertices nearest to a P x P lattice of locations spanning
 * [-0.25, 0.25]^2 (duplicates kept at coarse h); the grid extends 10 rings
 * beyond them, so no neighbourhood meets the border.  The adaptive degree
 * is off (max_cond = DBL_MAX): every fit is at the requested degree
 * unless the system is rank deficient (counted in `lowered`).
 * Errors per point against the exact values of src/synth/surfaces.c, the
 * estimate oriented along the exact normal: sin of the normal angle and
 * the relative errors |k - k_true| / |k_true| of kmin (k2) and kmax (k1);
 * the exp graph is hyperbolic everywhere (K < 0), so k_true != 0. */
#ifndef JF_CONVERGENCE_H
#define JF_CONVERGENCE_H

#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

#define JF_CONV_MAX_H 8

typedef struct {
    uint64_t seed;       /* grid perturbation; the grid of the k-th h
                            depends only on (seed, h)                     */
    int deg_lo, deg_hi;  /* degrees, within 1..JF_MAX_DEGREE              */
    int interp, approx;  /* which modes to run (interp rows come first)  */
    int nh;              /* h[0] > h[1] > ... (coarse to fine)           */
    double h[JF_CONV_MAX_H];
    int lattice;         /* P >= 1 */
} jf_conv_config;

/* The paper's full run: h = 2^-2 .. 2^-6, degrees 1..9, both modes,
 * P = 5; quick: degrees 1..4, P = 3. */
void jf_conv_config_init(jf_conv_config *c, int quick);

enum { JF_CONV_NORMAL = 0, JF_CONV_KMIN = 1, JF_CONV_KMAX = 2 };

typedef struct {
    jf_fit_mode mode;
    int degree;
    double h;
    double avg[3], max[3]; /* by JF_CONV_NORMAL, _KMIN, _KMAX             */
    size_t npoints;        /* selected points                             */
    size_t lowered;        /* fits below the requested degree             */
    size_t failed;         /* JF_PT_FAILED fits (left out of the errors)  */
} jf_conv_row;

/* Number of rows jf_conv_run writes: modes x degrees x nh. */
size_t jf_conv_row_count(const jf_conv_config *c);

/* Runs the experiment; rows (jf_conv_row_count entries, caller-owned) are
 * ordered by mode (interp, approx), degree, then h as given.  Returns
 * JF_ERR_INVALID for a bad config, JF_ERR_NOMEM, or a mesh/fit error.
 * Deterministic: the same config gives the same bits.  Not printing. */
jf_status jf_conv_run(const jf_conv_config *c, jf_conv_row *rows);

/* Least-squares slope of log(1/delta) against log(1/h) over the rows
 * r[0..n-1] of one (mode, degree) (h decreasing), quantity q, using avg.
 * Only the part above the double-precision floor is used: from the
 * coarsest h, rows are taken while delta > 1e-13 and, once delta < 1e-6,
 * while it still decreases by at least a factor sqrt(2) when h halves
 * (beyond that the error is rounding, not truncation).  *used gets the
 * number of rows taken (the first *used); the slope is NaN when < 2. */
double jf_conv_slope(const jf_conv_row *r, size_t n, int q, size_t *used);

#endif /* JF_CONVERGENCE_H */
