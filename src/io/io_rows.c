/* io_rows.c -- the estimate's output table (jf_result_columns,
 * jf_result_row): one list of columns for the command, jetfit-mpi and the
 * Python module's files. */
#include "jetfit.h"

static const char *const base_cols[] = {"x",   "y",   "z",   "nx",  "ny",  "nz",  "k1",
                                        "k2",  "d1x", "d1y", "d1z", "d2x", "d2y", "d2z"};
static const char *const b_cols[] = {"b0", "b1", "b2", "b3"};
static const char *const c_cols[] = {"c0", "c1", "c2", "c3", "c4"};

size_t jf_result_columns(int monge, int sigma, jf_column *cols)
{
    size_t n = 0;
    for (size_t j = 0; j < 14; j++) cols[n++] = (jf_column){base_cols[j], JF_COL_F64};
    if (monge >= 3)
        for (size_t j = 0; j < 4; j++) cols[n++] = (jf_column){b_cols[j], JF_COL_F64};
    if (monge >= 4)
        for (size_t j = 0; j < 5; j++) cols[n++] = (jf_column){c_cols[j], JF_COL_F64};
    cols[n++] = (jf_column){"degree", JF_COL_I32};
    cols[n++] = (jf_column){"neighbors", JF_COL_I32};
    cols[n++] = (jf_column){"cond", JF_COL_F64};
    cols[n++] = (jf_column){"residual", JF_COL_F64};
    if (sigma) cols[n++] = (jf_column){"sigma", JF_COL_F64};
    cols[n++] = (jf_column){"status", JF_COL_I32};
    return n;
}

size_t jf_result_row(const double p[3], const jf_result *r, int monge, int sigma, double *v)
{
    size_t n = 0;
    for (int j = 0; j < 3; j++) v[n++] = p[j];
    for (int j = 0; j < 3; j++) v[n++] = r->normal[j];
    v[n++] = r->k1;
    v[n++] = r->k2;
    for (int j = 0; j < 3; j++) v[n++] = r->d1[j];
    for (int j = 0; j < 3; j++) v[n++] = r->d2[j];
    if (monge >= 3)
        for (int j = 0; j < 4; j++) v[n++] = r->b[j];
    if (monge >= 4)
        for (int j = 0; j < 5; j++) v[n++] = r->c[j];
    v[n++] = r->degree;
    v[n++] = r->n_used;
    v[n++] = r->cond;
    v[n++] = r->residual;
    if (sigma) v[n++] = r->sigma;
    v[n++] = (double)r->status;
    return n;
}
