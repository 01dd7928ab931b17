/* order_internal.h -- the Morton keys and the radix sort behind
 * jf_spatial_order (order.c), shared with the parts (estimate/parts.c)
 * and jetfit-mpi's sample sort.  Not part of the public API. */
#ifndef JF_ORDER_INTERNAL_H
#define JF_ORDER_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

/* Stable LSD radix sort (11-bit digits; a digit all keys share is
 * skipped) of the pairs (key[i], order[i]) by the low nbits of key; the
 * result is left in key and order.  key_tmp, order_tmp: n entries of
 * scratch.  jf_spatial_order's sort; jetfit-mpi's record sorts. */
void jf__radix_sort(uint64_t *key, uint32_t *order, size_t n, int nbits, uint64_t *key_tmp,
                    uint32_t *order_tmp);

/* Morton keys as jf_spatial_order makes them: 21 bits per axis over the
 * cube of side max extent from lo (box = lo xyz, hi xyz of the finite
 * points).  *scale for jf__morton_key. */
double jf__morton_scale(const double box[6]);
uint64_t jf__morton_key(const double p[3], const double box[6], double scale);

/* Bounding box of the finite points of xyz[3n] (lo xyz, hi xyz); with no
 * finite point lo = +inf, hi = -inf.  Returns the number of finite points. */
size_t jf__parts_bbox(const double *xyz, size_t n, double box[6]);

#endif
