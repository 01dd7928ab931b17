/* eval_errors.h -- what `jetfit eval` and `jetfit study` both measure
 * (src/cli/eval_errors.c): ground truth read from generate's truth file,
 * PCPNet's .normals/.curv or a reference result; the subset of rows that
 * counts; the per-point errors.  One implementation, so a study's table
 * holds the numbers eval prints for the same result. */
#ifndef JF_CLI_EVAL_ERRORS_H
#define JF_CLI_EVAL_ERRORS_H

#include <stddef.h>

#include "jetfit.h"

enum { JF_Q_NORMAL, JF_Q_K1REL, JF_Q_K2REL, JF_Q_K1ABS, JF_Q_K2ABS, JF_NQ };
extern const char *const jf_q_name[JF_NQ]; /* "normal_deg", "k1_rel", ... */

/* The truth as malloc'ed rows nx ny nz k1 k2 (k NaN when unknown);
 * *has_k says whether curvatures are known.  NULL on failure with one
 * line "FILE:PLACE: reason" in msg. */
double *jf_cli_truth_load(const char *path, size_t *nrows, int *has_k, char *msg, size_t len);

/* The 0-based row indices listed in IDX (e.g. PCPNet's .pidx), each
 * checked against nrows.  0, or -1 with msg. */
int jf_cli_subset_load(const char *path, size_t nrows, size_t **sel, size_t *nsel, char *msg,
                       size_t len);

/* The errors of one estimate (n, k1 >= k2) against its truth row t
 * (nx ny nz k1 k2): e[JF_Q_NORMAL] the unoriented angle in degrees, the
 * curvature errors after orienting along the true normal (NaN unless
 * with_k). */
void jf_cli_point_errors(const double n[3], double k1, double k2, const double t[5], int with_k,
                         double e[JF_NQ]);

/* 0 when RESULT's x y z are TRUTH's (exactly, 1e-9 of the diagonal, for a
 * reference result; median within 5% for generate's noise-free truth), or
 * TRUTH has no coordinates (PCPNet); -1 with msg otherwise. */
int jf_cli_truth_coords_check(const char *truth_path, const jf_eval_table *res, char *msg,
                              size_t len);

#endif
