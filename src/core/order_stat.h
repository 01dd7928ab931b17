/* order_stat.h -- the k-th smallest of an array in linear time (the
 * robust fit's MAD, the command's cond percentiles); not public. */
#ifndef JF_ORDER_STAT_H
#define JF_ORDER_STAT_H

#include <stddef.h>

/* Moves the k-th smallest (k < n) of a[0..n) (no NaN) to a[k], smaller
 * or equal ones before it, larger or equal ones after. */
void jf__select_kth(double *a, size_t n, size_t k);

#endif
