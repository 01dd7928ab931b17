/*
 * io_fmt.c -- number to text for the writers: jf_fmt_g17 writes a double
 * exactly as printf("%.17g") does (so it reads back bit for bit), about 5x
 * faster: for 1e-11 <= |v| < 1e17 the 17 digits come from exact 128-bit
 * integer arithmetic (|v| 10^k = m 5^k 2^(q+k), rounded half to even as
 * printf rounds); other magnitudes go to snprintf.
 */
#include "io_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- exact "%.17g" ---------------------------------------------------- */

char *jf_fmt_uint(char *o, uint64_t v)
{
    char tmp[24];
    int n = 0;
    do {
        tmp[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (n)
        *o++ = tmp[--n];
    return o;
}

/* For |v| = m 2^q: *out = round_half_even(|v| 10^k) and *fl its floor,
 * 0 <= k <= 27 (5^27 m < 2^116: exact in 128 bits); 0 if out of reach. */
static int scaled(uint64_t m, int q, int k, uint64_t *out, uint64_t *fl)
{
    unsigned __int128 p = (unsigned __int128)m * jf_pow5(k);
    int s = q + k; /* |v| * 10^k = p * 2^s */
    if (s >= 0) {
        if (s > 10)
            return 0;
        *out = *fl = (uint64_t)(p << s);
        return 1;
    }
    int r = -s;
    if (r >= 127)
        return 0;
    unsigned __int128 one = 1, t = p >> r, rem = p & ((one << r) - 1),
                      half = one << (r - 1);
    if (t >> 64)
        return 0;
    *fl = (uint64_t)t;
    if (rem > half || (rem == half && (t & 1)))
        t++;
    if (t >> 64)
        return 0;
    *out = (uint64_t)t;
    return 1;
}

/* Writes v as printf("%.17g") does (NaN as "nan"); returns the end. */
char *jf_fmt_g17(char *o, double v)
{
    if (isnan(v))
        return memcpy(o, "nan", 3), o + 3;
    if (isinf(v))
        return v < 0 ? (memcpy(o, "-inf", 4), o + 4)
                     : (memcpy(o, "inf", 3), o + 3);
    uint64_t bits;
    memcpy(&bits, &v, 8);
    int bexp = (int)((bits >> 52) & 0x7ff);
    double a = fabs(v);
    if (v == 0 || bexp == 0 || !(a >= 1e-11 && a < 1e17))
        return o + snprintf(o, 32, "%.17g", v);
    uint64_t m = (bits & ((UINT64_C(1) << 52) - 1)) | (UINT64_C(1) << 52);
    int q = bexp - 1075;
    int E = (int)floor(log10(a));
    uint64_t M = 0, F = 0;
    const uint64_t lo = UINT64_C(10000000000000000), hi = lo * 10;
    /* E = floor(log10|v|) may be off by one near powers of ten: the
     * floor of |v| 10^(16-E) must have exactly 17 digits */
    for (int tries = 0;; tries++) {
        int k = 16 - E;
        if (tries > 3 || k < 0 || k > 27 || !scaled(m, q, k, &M, &F))
            return o + snprintf(o, 32, "%.17g", v);
        if (F >= hi) {
            E++;
            continue;
        }
        if (F < lo) {
            E--;
            continue;
        }
        break;
    }
    if (M == hi) { /* rounding carried into an 18th digit */
        M /= 10;
        E++;
    }
    char d[17];
    for (int i = 16; i >= 0; i--) {
        d[i] = (char)('0' + M % 10);
        M /= 10;
    }
    int nd = 17;
    while (nd > 1 && d[nd - 1] == '0')
        nd--;
    if (v < 0)
        *o++ = '-';
    if (E < -4 || E >= 17) { /* %g's scientific form */
        *o++ = d[0];
        if (nd > 1) {
            *o++ = '.';
            memcpy(o, d + 1, (size_t)nd - 1);
            o += nd - 1;
        }
        *o++ = 'e';
        *o++ = E < 0 ? '-' : '+';
        int ae = E < 0 ? -E : E;
        if (ae < 10)
            *o++ = '0';
        return jf_fmt_uint(o, (uint64_t)ae);
    }
    if (E >= 0) {
        int ni = E + 1; /* integer digits, <= 17 */
        memcpy(o, d, (size_t)ni);
        o += ni;
        if (nd > ni) {
            *o++ = '.';
            memcpy(o, d + ni, (size_t)(nd - ni));
            o += nd - ni;
        }
        return o;
    }
    *o++ = '0';
    *o++ = '.';
    for (int i = 0; i < -E - 1; i++)
        *o++ = '0';
    memcpy(o, d, (size_t)nd);
    return o + nd;
}
