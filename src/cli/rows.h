/* rows.h -- the output table of `jetfit estimate` (and `jetfit-mpi
 * estimate`, src/mpi/): its columns and one row per point (rows.c). */
#ifndef JF_CLI_ROWS_H
#define JF_CLI_ROWS_H

#include <stddef.h>

#include "jetfit.h"

/* Largest number of columns (14 + 4 + 5 + 6). */
#define JF_CLI_MAX_COLS 32

/* x y z nx ny nz k1 k2 d1x..d2z [b0..b3] [c0..c4] degree neighbors cond
 * residual [sigma] status, for Monge degree `monge` (sigma: the noise
 * estimate of neighbors auto, when `sigma` is nonzero); returns their
 * number. */
size_t jf_cli_columns(int monge, int sigma, jf_column *cols);

/* The row of point p with result r into v (jf_cli_columns' order);
 * returns the number of values. */
size_t jf_cli_row(const double *p, const jf_result *r, int monge, int sigma, double *v);

#endif
