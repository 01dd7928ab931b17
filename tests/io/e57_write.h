/* e57_write.h -- a small E57 writer for the tests only (ASTM E2807, not the
 * library): scans of Float (single/double), Integer and ScaledInteger
 * fields, each with a pose, laid out as the 48-byte header, one
 * CompressedVector binary section per scan (data packets of at most
 * `chunk` bytes per bytestream, so values straddle packets), then the XML
 * section, paged 1024 bytes at a time with each page's CRC-32C (a bitwise
 * implementation, independent of the reader's tables) stored big endian.
 * `edit`, if set, may rewrite the XML text before it is laid out (lies). */
#ifndef JF_TEST_E57_WRITE_H
#define JF_TEST_E57_WRITE_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { EW_FLOAT, EW_DOUBLE, EW_INT, EW_SCALED };

typedef struct {
    const char *name;   /* prototype element name                       */
    int kind;           /* EW_*                                         */
    long long min, max; /* EW_INT / EW_SCALED raw bounds                */
    double scale;       /* EW_SCALED: value = raw * scale (offset 0)    */
    const double *v;    /* n values (EW_SCALED: raw integers)           */
    size_t stride;      /* value i at v[i * stride]; 0 means 1          */
} ew_field;

typedef struct {
    double q[4], t[3];  /* pose: quaternion w x y z, translation        */
    size_t n;
    const ew_field *f;
    size_t nf;
} ew_scan;

typedef struct {
    unsigned char *b;
    size_t n, cap;
} ew_buf;

static inline void ew_put(ew_buf *o, const void *p, size_t n)
{
    if (o->n + n > o->cap) {
        o->cap = (o->n + n) * 2 + 4096;
        o->b = realloc(o->b, o->cap);
        if (!o->b) exit(2);
    }
    if (p) memcpy(o->b + o->n, p, n);
    else memset(o->b + o->n, 0, n);
    o->n += n;
}

static inline void ew_le(unsigned char *p, uint64_t v, int n)
{
    for (int k = 0; k < n; k++) p[k] = (unsigned char)(v >> (8 * k));
}

static inline uint32_t ew_crc32c(const unsigned char *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = c & 1 ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    }
    return ~c;
}

static inline uint64_t ew_phys(uint64_t logical) { return logical / 1020 * 1024 + logical % 1020; }

static inline unsigned ew_bits(long long min, long long max)
{
    uint64_t r = (uint64_t)max - (uint64_t)min;
    unsigned b = 0;
    while (b < 64 && (r >> b)) b++;
    return b;
}

/* Field f's whole bytestream (*len bytes). */
static inline unsigned char *ew_stream(const ew_field *f, size_t n, size_t *len)
{
    size_t vs = f->stride ? f->stride : 1;
    if (f->kind == EW_FLOAT || f->kind == EW_DOUBLE) {
        size_t w = f->kind == EW_FLOAT ? 4 : 8;
        unsigned char *s = malloc(n * w + 1);
        for (size_t i = 0; i < n; i++) {
            uint64_t u = 0;
            if (w == 4) {
                float x = (float)f->v[i * vs];
                uint32_t u32;
                memcpy(&u32, &x, 4);
                u = u32;
            } else {
                memcpy(&u, &f->v[i * vs], 8);
            }
            ew_le(s + w * i, u, (int)w);
        }
        *len = n * w;
        return s;
    }
    unsigned w = ew_bits(f->min, f->max);
    size_t bytes = (n * w + 7) / 8;
    unsigned char *s = calloc(bytes + 1, 1);
    for (size_t i = 0; i < n; i++) {
        uint64_t raw = (uint64_t)((long long)f->v[i * vs] - f->min);
        for (unsigned k = 0; k < w; k++) /* one bit at a time: LSB first */
            if ((raw >> k) & 1) {
                size_t bit = i * w + k;
                s[bit / 8] |= (unsigned char)(1u << (bit % 8));
            }
    }
    *len = bytes;
    return s;
}

/* The E57 file of the scans (malloc'd, *len bytes). */
static inline unsigned char *ew_make(const ew_scan *sc, size_t ns, size_t chunk,
                                     void (*edit)(char *xml, size_t cap), size_t *len)
{
    ew_buf L = {0}, X = {0};
    ew_put(&L, NULL, 48);
    uint64_t *sec = calloc(ns, sizeof *sec);
    for (size_t s = 0; s < ns; s++) {
        const ew_scan *S = &sc[s];
        unsigned char **st = calloc(S->nf, sizeof *st);
        size_t *sl = calloc(S->nf, sizeof *sl), *done = calloc(S->nf, sizeof *done);
        for (size_t j = 0; j < S->nf; j++) st[j] = ew_stream(&S->f[j], S->n, &sl[j]);
        sec[s] = L.n;
        size_t h = L.n;
        ew_put(&L, NULL, 32);
        L.b[h] = 1;
        ew_le(L.b + h + 16, ew_phys(h + 32), 8);
        for (;;) {
            int left = 0;
            for (size_t j = 0; j < S->nf; j++) left |= done[j] < sl[j];
            if (!left) break;
            size_t p = L.n, body = 6 + 2 * S->nf;
            ew_put(&L, NULL, body);
            for (size_t j = 0; j < S->nf; j++) {
                size_t k = sl[j] - done[j] < chunk ? sl[j] - done[j] : chunk;
                ew_le(L.b + p + 6 + 2 * j, k, 2);
                ew_put(&L, st[j] + done[j], k);
                done[j] += k;
            }
            while ((L.n - p) % 4) ew_put(&L, NULL, 1);
            L.b[p] = 1;
            ew_le(L.b + p + 2, L.n - p - 1, 2);
            ew_le(L.b + p + 4, S->nf, 2);
        }
        ew_le(L.b + h + 8, L.n - h, 8);
        for (size_t j = 0; j < S->nf; j++) free(st[j]);
        free(st), free(sl), free(done);
    }
    size_t xcap = 4096 + ns * 4096;
    char *x = malloc(xcap);
    size_t k = (size_t)snprintf(x, xcap, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<e57Root type=\"Structure\" xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\">\n"
        "  <formatName type=\"String\"><![CDATA[ASTM E57 3D Imaging Data File]]></formatName>\n"
        "  <data3D type=\"Vector\" allowHeterogeneousChildren=\"1\">\n");
    for (size_t s = 0; s < ns; s++) {
        const ew_scan *S = &sc[s];
        k += (size_t)snprintf(x + k, xcap - k, "    <vectorChild type=\"Structure\">\n"
            "      <pose type=\"Structure\"><rotation type=\"Structure\">"
            "<w type=\"Float\">%.17g</w><x type=\"Float\">%.17g</x><y type=\"Float\">%.17g</y>"
            "<z type=\"Float\">%.17g</z></rotation>\n"
            "        <translation type=\"Structure\"><x type=\"Float\">%.17g</x>"
            "<y type=\"Float\">%.17g</y><z type=\"Float\">%.17g</z></translation></pose>\n"
            "      <points type=\"CompressedVector\" fileOffset=\"%llu\" recordCount=\"%zu\">\n"
            "        <prototype type=\"Structure\">\n",
            S->q[0], S->q[1], S->q[2], S->q[3], S->t[0], S->t[1], S->t[2],
            (unsigned long long)ew_phys(sec[s]), S->n);
        for (size_t j = 0; j < S->nf; j++) {
            const ew_field *f = &S->f[j];
            if (f->kind == EW_FLOAT || f->kind == EW_DOUBLE)
                k += (size_t)snprintf(x + k, xcap - k, "          <%s type=\"Float\"%s/>\n",
                                      f->name, f->kind == EW_FLOAT ? " precision=\"single\"" : "");
            else
                k += (size_t)snprintf(x + k, xcap - k, "          <%s type=\"%s\" minimum=\"%lld\""
                                      " maximum=\"%lld\" scale=\"%.17g\"/>\n", f->name,
                                      f->kind == EW_INT ? "Integer" : "ScaledInteger", f->min,
                                      f->max, f->kind == EW_INT ? 1.0 : f->scale);
        }
        k += (size_t)snprintf(x + k, xcap - k, "        </prototype>\n"
            "        <codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"></codecs>\n"
            "      </points>\n    </vectorChild>\n");
    }
    snprintf(x + k, xcap - k, "  </data3D>\n</e57Root>\n");
    if (edit) edit(x, xcap);
    size_t xoff = L.n, xlen = strlen(x);
    ew_put(&L, x, xlen);
    free(x);
    free(sec);
    size_t pages = (L.n + 1019) / 1020;
    ew_put(&L, NULL, pages * 1020 - L.n); /* the last page padded with zeros */
    memcpy(L.b, "ASTM-E57", 8);
    ew_le(L.b + 8, 1, 4);
    ew_le(L.b + 16, pages * 1024, 8);
    ew_le(L.b + 24, ew_phys(xoff), 8);
    ew_le(L.b + 32, xlen, 8);
    ew_le(L.b + 40, 1024, 8);
    for (size_t p = 0; p < pages; p++) {
        ew_put(&X, L.b + p * 1020, 1020);
        uint32_t c = ew_crc32c(L.b + p * 1020, 1020);
        unsigned char be[4] = {(unsigned char)(c >> 24), (unsigned char)(c >> 16),
                               (unsigned char)(c >> 8), (unsigned char)c};
        ew_put(&X, be, 4);
    }
    free(L.b);
    *len = X.n;
    return X.b;
}

/* Writes bytes to path (0 ok). */
static inline int ew_save(const char *path, const unsigned char *b, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    int ok = fwrite(b, 1, n, f) == n;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}
#endif
