/* order_stat.c -- quickselect with a three-way partition (many equal
 * values, as on grids, stay linear) and pivots from a fixed xorshift
 * sequence (no input order makes it quadratic by accident; the same
 * answer every run). */
#include <stdint.h>

#include "order_stat.h"

void jf__select_kth(double *a, size_t n, size_t k)
{
    uint64_t x = 0x9E3779B97F4A7C15ull;
    size_t lo = 0, hi = n; /* a[k] lies in [lo, hi) */
    while (hi - lo > 1) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        const double p = a[lo + (size_t)(x % (hi - lo))];
        size_t lt = lo, i = lo, gt = hi; /* [lo,lt) < p, [lt,i) == p, [gt,hi) > p */
        while (i < gt) {
            double v = a[i];
            if (v < p) a[i++] = a[lt], a[lt++] = v;
            else if (v > p) a[i] = a[--gt], a[gt] = v;
            else i++;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return;
    }
}
