/* laz_gen.h -- a generator of LAS files whose records exercise every path
 * of the LAZ coders (for test_io_laz_write and the laz-perf check): fields
 * that change now and then or never, returns that step by one or jump,
 * scanner channels switching, GPS times in several interleaved sequences
 * with repeats and 64-bit jumps, grey and coloured RGB, NIR, extra bytes
 * constant, noisy and slow.  A LAS 1.4 header (375 bytes, no VLR: the
 * extra bytes undocumented), scale 0.001, the bounds of the points. */
#ifndef JF_LAZ_GEN_H
#define JF_LAZ_GEN_H
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static const unsigned lazgen_base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static uint64_t lazgen_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
/* 1 with probability p/1000 */
static int lazgen_p(uint64_t *s, unsigned p) { return lazgen_next(s) % 1000 < p; }

static void lazgen_w16(unsigned char *p, unsigned v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }
static void lazgen_w32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void lazgen_w64(unsigned char *p, uint64_t v)
{
    for (int k = 0; k < 8; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void lazgen_wd(unsigned char *p, double d)
{
    uint64_t b;
    memcpy(&b, &d, 8);
    lazgen_w64(p, b);
}

/* Fills n records of point format fmt (0-3, 6-8) with `extra` bytes each. */
static void lazgen_records(unsigned fmt, unsigned extra, size_t n, uint64_t seed, unsigned char *rec)
{
    unsigned len = lazgen_base[fmt] + extra, wide = fmt >= 6;
    uint64_t s = seed;
    int32_t x = 1000000, y = -2000000, z = 5000;
    unsigned in = 100, rn = 1, nr = 1, cls = 2, ud = 0, psid = 7, sc = 0, fl = 0, sdir = 0, eof = 0;
    int sang = 0;
    uint64_t seq[3] = {0x41D0000000000000ull, 0x41E0000000000000ull, 0x4000000000000000ull};
    int64_t dt[3] = {12345, 1000, 77};
    unsigned cur = 0, rgb[4] = {1000, 2000, 3000, 4000};
    unsigned char eb[64] = {0};
    for (size_t i = 0; i < n; i++) {
        unsigned char *r = rec + i * len;
        if (lazgen_p(&s, 20)) { /* an identical point */
            if (i) memcpy(r, r - len, len);
            if (i) continue;
        }
        x += (int32_t)(lazgen_next(&s) % 2001) - 1000;
        y += (int32_t)(lazgen_next(&s) % 201) - 100;
        if (lazgen_p(&s, 5)) x = (int32_t)lazgen_next(&s); /* a jump */
        if (!lazgen_p(&s, 100)) z += (int32_t)(lazgen_next(&s) % 41) - 20;
        if (lazgen_p(&s, 500)) in = (unsigned)(lazgen_next(&s) % 65536);
        unsigned maxr = wide ? 15 : 7;
        if (lazgen_p(&s, 50)) nr = (unsigned)(lazgen_next(&s) % (maxr + 1));
        rn = lazgen_p(&s, 600) ? (rn + 1) % (maxr + 1) : lazgen_p(&s, 300) ? rn
                                                        : (unsigned)(lazgen_next(&s) % (maxr + 1));
        if (lazgen_p(&s, 100)) cls = (unsigned)(lazgen_next(&s) % (wide ? 256 : 32));
        if (lazgen_p(&s, 50)) ud = (unsigned)(lazgen_next(&s) % 256);
        if (lazgen_p(&s, 10)) psid = (unsigned)(lazgen_next(&s) % 65536);
        if (lazgen_p(&s, 300)) sang = (int)(lazgen_next(&s) % (wide ? 60001 : 181)) - (wide ? 30000 : 90);
        if (lazgen_p(&s, 20)) sc = (unsigned)(lazgen_next(&s) % 4);
        if (lazgen_p(&s, 30)) fl = (unsigned)(lazgen_next(&s) % 16);
        if (lazgen_p(&s, 50)) sdir ^= 1;
        eof = lazgen_p(&s, 20);
        /* GPS: mostly the current sequence's step, sometimes another
         * sequence, a repeat, a multiple of the step or a 64-bit jump */
        unsigned g = (unsigned)(lazgen_next(&s) % 1000);
        if (g < 30) cur = (cur + 1) % 3;
        if (g < 60) seq[cur] += 0;
        else if (g < 80) seq[cur] += (uint64_t)(dt[cur] * (int64_t)(lazgen_next(&s) % 700));
        else if (g < 90) seq[cur] -= (uint64_t)(dt[cur] * (int64_t)(lazgen_next(&s) % 20));
        else if (g < 95) seq[cur] = lazgen_next(&s);
        else seq[cur] += (uint64_t)(dt[cur] + (int64_t)(lazgen_next(&s) % 5) - 2);
        if (lazgen_p(&s, 300)) {
            unsigned c = (unsigned)(lazgen_next(&s) % 4);
            if (lazgen_p(&s, 500)) rgb[c] = (rgb[c] & 0xFF00) | (unsigned)(lazgen_next(&s) % 256);
            else rgb[c] = (unsigned)(lazgen_next(&s) % 65536);
            if (lazgen_p(&s, 200)) rgb[1] = rgb[2] = rgb[0]; /* grey */
        }
        for (unsigned k = 0; k < extra && k < 64; k++) {
            if (k % 3 == 1) eb[k] = (unsigned char)lazgen_next(&s);
            else if (k % 3 == 2 && lazgen_p(&s, 50)) eb[k]++;
        }
        lazgen_w32(r, (uint32_t)x), lazgen_w32(r + 4, (uint32_t)y), lazgen_w32(r + 8, (uint32_t)z);
        lazgen_w16(r + 12, in);
        unsigned o;
        if (wide) {
            r[14] = (unsigned char)(rn | nr << 4);
            r[15] = (unsigned char)(fl | sc << 4 | sdir << 6 | eof << 7);
            r[16] = (unsigned char)cls, r[17] = (unsigned char)ud;
            lazgen_w16(r + 18, (unsigned)(int16_t)sang);
            lazgen_w16(r + 20, psid);
            lazgen_w64(r + 22, seq[cur]);
            o = 30;
        } else {
            r[14] = (unsigned char)(rn | nr << 3 | sdir << 6 | eof << 7);
            r[15] = (unsigned char)(cls | (fl & 7) << 5);
            r[16] = (unsigned char)(int8_t)sang, r[17] = (unsigned char)ud;
            lazgen_w16(r + 18, psid);
            o = 20;
            if (fmt == 1 || fmt == 3) lazgen_w64(r + 20, seq[cur]), o = 28;
        }
        if (fmt == 2 || fmt == 3 || fmt == 7 || fmt == 8) {
            for (int c = 0; c < 3; c++) lazgen_w16(r + o + 2 * c, rgb[c]);
            o += 6;
        }
        if (fmt == 8) lazgen_w16(r + o, rgb[3]), o += 2;
        for (unsigned k = 0; k < extra; k++) r[o + k] = k < 64 ? eb[k] : (unsigned char)k;
    }
}

/* A whole LAS 1.4 file (malloc'd, *len bytes) of those records. */
static unsigned char *lazgen_las(unsigned fmt, unsigned extra, size_t n, uint64_t seed, size_t *len)
{
    unsigned rl = lazgen_base[fmt] + extra;
    *len = 375 + n * rl;
    unsigned char *b = calloc(1, *len);
    if (!b) return NULL;
    lazgen_records(fmt, extra, n, seed, b + 375);
    memcpy(b, "LASF", 4);
    b[24] = 1, b[25] = 4;
    memcpy(b + 26, "laz_gen", 7);
    lazgen_w16(b + 94, 375);
    lazgen_w32(b + 96, 375);
    b[104] = (unsigned char)fmt;
    lazgen_w16(b + 105, rl);
    lazgen_w32(b + 107, fmt < 6 ? (uint32_t)n : 0);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            const unsigned char *p = b + 375 + i * rl + 4 * a;
            double v = (int32_t)((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                                 (uint32_t)p[3] << 24) * 0.001;
            lo[a] = v < lo[a] ? v : lo[a], hi[a] = v > hi[a] ? v : hi[a];
        }
    for (int a = 0; a < 3; a++) {
        lazgen_wd(b + 131 + 8 * a, 0.001);
        lazgen_wd(b + 179 + 16 * a, n ? hi[a] : 0);
        lazgen_wd(b + 187 + 16 * a, n ? lo[a] : 0);
    }
    lazgen_w64(b + 247, n);
    return b;
}
#endif
