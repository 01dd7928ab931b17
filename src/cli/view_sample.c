/* view_sample.c -- a spatially even order of the points: any prefix of it
 * is an even subsample (the page draws the first --max-points and puts
 * glyphs on the first few thousand).
 *
 * design: quantise the points to a 2^21 grid in their bounding cube and
 * sort them by Morton code, which lists every octree cell contiguously;
 * a point's level is the octree depth at which it is the first of its
 * cell (from the common prefix with its predecessor's code).  Points are
 * then taken level by level, coarse first; inside a level in bit-reversed
 * rank order, so a partly taken level is still spread over the whole
 * Morton curve rather than cut at one side. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "view.h"

typedef struct {
    uint64_t key;
    size_t i;
    int level;
} mk;

static uint64_t spread3(uint64_t x) /* 21 bits -> every third bit */
{
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}

static int cmp_key(const void *a, const void *b)
{
    const mk *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

static size_t bitrev(size_t j, int bits)
{
    size_t r = 0;
    for (int b = 0; b < bits; b++, j >>= 1) r = r << 1 | (j & 1);
    return r;
}

int jf_view_spread_order(const double *v, size_t ncols, int cx, size_t *idx, size_t m)
{
    if (m < 2) return 0;
    mk *a = malloc(m * sizeof *a);
    size_t *out = malloc(m * sizeof *out);
    if (!a || !out) { free(a); free(out); return -1; }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, side = 0;
    for (size_t k = 0; k < m; k++)
        for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], v[idx[k] * ncols + cx + d]);
    for (size_t k = 0; k < m; k++)
        for (int d = 0; d < 3; d++) side = fmax(side, v[idx[k] * ncols + cx + d] - lo[d]);
    double s = side > 0 ? 2097151.0 / side : 0;
    for (size_t k = 0; k < m; k++) {
        uint64_t key = 0;
        for (int d = 0; d < 3; d++) {
            double q = floor((v[idx[k] * ncols + cx + d] - lo[d]) * s);
            key |= spread3((uint64_t)fmin(fmax(q, 0), 2097151)) << (2 - d);
        }
        a[k] = (mk){key, idx[k], 0};
    }
    qsort(a, m, sizeof *a, cmp_key);
    size_t count[23] = {0};
    for (size_t k = 0; k < m; k++) {
        uint64_t d = k ? a[k].key ^ a[k - 1].key : 0;
        /* keys use the low 63 bits: the first differing bit's depth */
        a[k].level = !k ? 0 : !d ? 22 : (__builtin_clzll(d) - 1) / 3 + 1;
        count[a[k].level]++;
    }
    size_t start[23], pos = 0;
    for (int l = 0; l < 23; l++) start[l] = pos, pos += count[l];
    /* stable by level: a level's points stay in Morton order */
    size_t fill[23];
    memcpy(fill, start, sizeof fill);
    for (size_t k = 0; k < m; k++) out[fill[a[k].level]++] = a[k].i;
    size_t w = 0;
    for (int l = 0; l < 23; l++) {
        size_t c = count[l];
        int bits = 0;
        while (((size_t)1 << bits) < c) bits++;
        for (size_t j = 0; j < ((size_t)1 << bits); j++) {
            size_t r = bitrev(j, bits);
            if (r < c) idx[w++] = out[start[l] + r];
        }
    }
    free(a);
    free(out);
    return 0;
}
