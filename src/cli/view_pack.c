/* view_pack.c -- each column as the smallest typed array that keeps what a
 * viewer needs (the page stays under ~40 bytes per point in base64):
 * positions as uint16 in the bounding box (1/65534 of each side), unit
 * vectors as an int8 pair on the octahedron (Meyer et al. 2010, "On
 * floating-point normal vectors": ~1 degree), integers exactly in the
 * narrowest unsigned type, other values as IEEE 754 half floats (11
 * significant bits) after a power-of-two scale, or of log2 v for positive
 * columns spanning more than 2^24 (cond).  NaN stays NaN in every form. */
#include <math.h>
#include <string.h>

#include "view.h"

uint16_t jf_view_half(double v)
{
    if (isnan(v)) return 0x7e00;
    uint16_t s = signbit(v) ? 0x8000 : 0;
    double a = fabs(v);
    if (a >= 65520.0) return s | 0x7c00; /* rounds past the largest half */
    if (a < 0x1p-14)                     /* subnormal: units of 2^-24 */
        return s | (uint16_t)nearbyint(a * 0x1p24);
    int e;
    double f = frexp(a, &e); /* a = f 2^e, f in [0.5, 1) */
    double mant = nearbyint((2 * f - 1) * 1024);
    int E = e - 1 + 15;
    if (mant >= 1024) mant = 0, E++;
    if (E >= 31) return s | 0x7c00;
    return s | (uint16_t)(E << 10) | (uint16_t)mant;
}

void jf_view_pack_box(const double *v, size_t ncols, const size_t *idx, size_t m,
                      jf_view_col *c)
{
    c->enc = JF_VE_POS;
    c->bytes = 6;
    for (int d = 0; d < 3; d++) c->lo[d] = INFINITY, c->hi[d] = -INFINITY;
    for (size_t k = 0; k < m; k++)
        for (int d = 0; d < 3; d++) {
            double x = v[idx[k] * ncols + c->col + d];
            if (isfinite(x)) c->lo[d] = fmin(c->lo[d], x), c->hi[d] = fmax(c->hi[d], x);
        }
    for (int d = 0; d < 3; d++)
        if (!(c->hi[d] >= c->lo[d])) c->lo[d] = c->hi[d] = 0;
}

void jf_view_pack_choose(const double *v, size_t ncols, const size_t *idx, size_t m,
                         jf_view_col *c)
{
    double mn = INFINITY, mx = -INFINITY, amax = 0, pmin = INFINITY;
    int integer = 1, anyinf = 0, positive = 1;
    size_t nfin = 0;
    for (size_t k = 0; k < m; k++) {
        double x = v[idx[k] * ncols + c->col];
        if (isnan(x)) continue;
        if (isinf(x)) { anyinf = 1; continue; }
        nfin++;
        mn = fmin(mn, x), mx = fmax(mx, x), amax = fmax(amax, fabs(x));
        if (x != floor(x)) integer = 0;
        if (x > 0) pmin = fmin(pmin, x); else positive = 0;
    }
    c->scale = 1, c->off = 0;
    if (nfin && integer && !anyinf && mx - mn < 4294967295.0) {
        c->off = mn;
        double r = mx - mn;
        c->enc = r < 255 ? JF_VE_U8 : r < 65535 ? JF_VE_U16 : JF_VE_U32;
        c->bytes = r < 255 ? 1 : r < 65535 ? 2 : 4;
        return;
    }
    c->bytes = 2;
    if (nfin && positive && mx / pmin > 0x1p24) {
        c->enc = JF_VE_LOG16;
        return;
    }
    c->enc = JF_VE_F16;
    if (amax > 0 && isfinite(amax)) {
        int e;
        frexp(amax, &e); /* amax / 2^(e-15) in [2^14, 2^15): inside half's range */
        c->scale = ldexp(1.0, e - 15);
    }
}

static void oct(const double *n, unsigned char *out)
{
    double x = n[0], y = n[1], z = n[2], l1 = fabs(x) + fabs(y) + fabs(z);
    if (!isfinite(l1) || l1 == 0) {
        out[0] = out[1] = 0x80; /* -128: missing */
        return;
    }
    x /= l1, y /= l1, z /= l1;
    if (z < 0) { /* fold the lower half over the diagonals */
        double ox = x;
        x = (1 - fabs(y)) * (x >= 0 ? 1 : -1);
        y = (1 - fabs(ox)) * (y >= 0 ? 1 : -1);
    }
    out[0] = (unsigned char)(int8_t)lrint(fmax(-127, fmin(127, x * 127)));
    out[1] = (unsigned char)(int8_t)lrint(fmax(-127, fmin(127, y * 127)));
}

void jf_view_pack_row(const jf_view_col *c, const double *row, unsigned char *out)
{
    const double *x = row + c->col;
    switch (c->enc) {
    case JF_VE_POS:
        for (int d = 0; d < 3; d++) {
            double span = c->hi[d] - c->lo[d];
            unsigned q = !isfinite(x[d]) ? 65535u
                         : span > 0 ? (unsigned)lrint(fmin(65534, fmax(0, (x[d] - c->lo[d]) / span * 65534)))
                                    : 0u;
            out[2 * d] = q & 255, out[2 * d + 1] = q >> 8;
        }
        return;
    case JF_VE_OCT: oct(x, out); return;
    case JF_VE_F16:
    case JF_VE_LOG16: {
        double y = c->enc == JF_VE_F16 ? x[0] / c->scale : x[0] > 0 ? log2(x[0]) : NAN;
        uint16_t h = jf_view_half(y);
        out[0] = h & 255, out[1] = h >> 8;
        return;
    }
    default: {
        uint32_t nanq = c->enc == JF_VE_U8 ? 255u : c->enc == JF_VE_U16 ? 65535u : 4294967295u;
        uint32_t q = isfinite(x[0]) ? (uint32_t)(x[0] - c->off) : nanq;
        for (size_t b = 0; b < c->bytes; b++) out[b] = q >> (8 * b) & 255;
    }
    }
}
