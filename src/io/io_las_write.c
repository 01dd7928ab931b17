/*
 * io_las_write.c -- the LAS 1.4 side of the table writer (io_write.c):
 * point data record format 0 holding x y z, and every other column of the
 * table as an Extra Byte (LAS 1.4 R15 §2.5.2: one "LASF_Spec" VLR, record
 * id 4, a 192-byte description per column, named as the column: nx ... status;
 * double, or int32 for the integer columns).
 *
 * design: X Y Z are int32 counts of a scale per axis, the smallest power
 * of ten >= max(1e-7, extent / 2e9): 0.1 µm wherever the extent allows
 * (below about 200 m), never an overflow; the offset is the minimum (or
 * both as the caller gives them; counts beyond int32, an extent beyond the
 * largest double: refused, issue 30.4).  A warning names an axis the rule
 * rounds by more than 1e-6 of the cloud's bulk size (issue 30.3).  The
 * frame comes from the whole cloud (jf_writer_las_frame) before the first
 * row; the header, which holds the point count and the bounds, is written
 * over the placeholder at offset 0 when the table is committed.  A non-finite
 * point is stored at the offset (status says nonfinite).
 *
 * Attributes (issue 13.2, 13.4): from a LAS input (jf_attrs.las_head) the
 * output keeps the input's records byte for byte -- same point format,
 * scale, offset, bounds, header fields (file source ID, global encoding,
 * GUID, system identifier, creation date), VLRs (the CRS ones among them)
 * and EVLRs -- and appends jetfit's columns as Extra Bytes after the
 * input's own (whose descriptions are copied, renamed when they clash:
 * `nx` -> `in_nx`; undescribed bytes get an "undocumented" description so
 * the offsets stay right).  From any other input, format 0 as above with
 * the attributes as Extra Bytes of their own type ahead of jetfit's (and
 * a LAS input's CRS VLRs under --keep none).  Extra Bytes names fill the
 * 32-byte field whole; longer ones become distinct "first bytes~N" with a
 * warning (jf__las_names, issue 30.2).
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "io_internal.h"

#define LAS_HEADER 375u
#define VLR_HEADER 54u
#define EB_DESC 192u

static void put16(unsigned char *p, unsigned v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }
static void put32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void put64(unsigned char *p, uint64_t v)
{
    for (int k = 0; k < 8; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void putd(unsigned char *p, double d)
{
    uint64_t b;
    memcpy(&b, &d, 8);
    put64(p, b);
}

/* Appends one line "FILE: ..." to *buf (left as it was without memory). */
static void warn_add(char **buf, const char *file, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void warn_add(char **buf, const char *file, const char *fmt, ...)
{
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    size_t old = *buf ? strlen(*buf) : 0, add = strlen(file) + strlen(line) + 4;
    char *b = realloc(*buf, old + add);
    if (!b) return;
    snprintf(b + old, add, "%s: %s\n", file, line);
    *buf = b;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The cloud's bulk size: the largest over the axes of the range of the
 * middle 99% of the finite points (from every k-th point, at most 65,536),
 * which a few outliers do not widen.  0 without memory or points. */
static double bulk_size(const double *xyz, size_t n)
{
    enum { SAMPLE = 65536 };
    size_t step = n / SAMPLE + 1, m = 0, cap = n < SAMPLE ? n + 1 : SAMPLE;
    double *v = malloc(3 * cap * sizeof *v), size = 0;
    if (!v) return 0;
    for (size_t i = 0; i < n && m < cap; i += step) {
        const double *p = xyz + 3 * i;
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
        for (int a = 0; a < 3; a++) v[a * cap + m] = p[a];
        m++;
    }
    for (int a = 0; m > 1 && a < 3; a++) {
        double *q = v + a * cap;
        qsort(q, m, sizeof *q, cmp_double);
        double r = q[(size_t)(0.995 * (double)(m - 1))] - q[(size_t)(0.005 * (double)(m - 1))];
        size = r > size ? r : size;
    }
    free(v);
    return size;
}

jf_status jf__las_frame(jf_las_out *L, const char *file, const double *xyz, size_t n,
                        const double *gscale, const double *goffset, char *why, size_t whylen)
{
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
        for (int a = 0; a < 3; a++) {
            lo[a] = p[a] < lo[a] ? p[a] : lo[a];
            hi[a] = p[a] > hi[a] ? p[a] : hi[a];
        }
    }
    free(L->warn_frame);
    L->warn_frame = NULL;
    for (int a = 0; a < 3; a++) {
        if (!(lo[a] <= hi[a])) lo[a] = hi[a] = 0; /* no finite point */
        double off = goffset ? goffset[a] : lo[a];
        /* how far the counts reach from the offset (the rule's offset is
         * the minimum: 0 to the extent) */
        double reach = fmax(hi[a] - off, off - lo[a]), s;
        if (!isfinite(reach)) {
            snprintf(why, whylen, "%c: coordinates from %.17g to %.17g%s: too far apart for a "
                     "LAS file (int32 counts of one scale per axis)", "xyz"[a], lo[a], hi[a],
                     goffset ? " (with the offset given)" : "");
            return JF_ERR_TOO_LARGE;
        }
        if (gscale) {
            s = gscale[a];
        } else {
            double need = fmax(1e-7, reach / 2e9);
            s = pow(10.0, ceil(log10(need) - 1e-12));
        }
        if (!(s > 0 && isfinite(s) && isfinite(off)) || reach / s > 2147483647.0) {
            snprintf(why, whylen, "%c: coordinates from %.17g to %.17g do not fit int32 counts "
                     "of the scale %.17g from the offset %.17g", "xyz"[a], lo[a], hi[a], s, off);
            return JF_ERR_TOO_LARGE;
        }
        L->scale[a] = s;
        L->offset[a] = off;
        /* the bounds as stored: what X * scale + offset gives back */
        L->hi[a] = off + (double)llround((hi[a] - off) / s) * s;
        L->lo[a] = off + (double)llround((lo[a] - off) / s) * s;
    }
    if (gscale) return JF_OK; /* the caller's choice: no warning */
    /* the largest rounding per axis, against the bulk size: an outlier
     * that widens the extent coarsens every coordinate (issue 30.3) */
    double r[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
        for (int a = 0; a < 3; a++) {
            double q = L->offset[a] + (double)llround((p[a] - L->offset[a]) / L->scale[a]) *
                                          L->scale[a];
            r[a] = fabs(q - p[a]) > r[a] ? fabs(q - p[a]) : r[a];
        }
    }
    double bulk = bulk_size(xyz, n);
    for (int a = 0; a < 3; a++)
        if (r[a] > 1e-6 * bulk)
            warn_add(&L->warn_frame, file, "%c: the LAS scale %g (for coordinates from %.17g to "
                     "%.17g) rounds them by up to %.3g, more than 1e-6 of the cloud's bulk size "
                     "%.6g (an outlier?)", "xyz"[a], L->scale[a], lo[a], hi[a], r[a], bulk);
    return JF_OK;
}

const char *const jf__las_fmt0_dims[JF__LAS_FMT0_NDIMS] = {
    "intensity", "return_number", "number_of_returns", "scan_direction_flag",
    "edge_of_flight_line", "classification", "synthetic", "key_point", "withheld",
    "scan_angle_rank", "user_data", "point_source_id"};

/* Extra Bytes data_type of each jf_attr_type (LAS 1.4 R15 table 24). */
static const unsigned char eb_code[10] = {2, 1, 4, 3, 6, 5, 8, 7, 9, 10};
static const unsigned base_len[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static int keep(const jf_las_out *L) { return L->a && L->a->las_head && L->a->rec; }
/* A LAS input read without its records (no_attrs): its CRS VLRs only. */
static int crs_only(const jf_las_out *L) { return L->a && L->a->las_head && !L->a->rec; }

static uint16_t g16(const unsigned char *p) { return (uint16_t)(p[0] | p[1] << 8); }
static uint32_t g32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t g64(const unsigned char *p) { return g32(p) | (uint64_t)g32(p + 4) << 32; }

static size_t jetfit_eb_bytes(const jf_las_out *L)
{
    size_t n = 0;
    for (size_t j = 3; j < L->ncols; j++) n += L->types[j] == JF_COL_F64 ? 8 : 4;
    return n;
}

size_t jf__las_record_size(const jf_las_out *L)
{
    if (keep(L)) return L->a->stride + jetfit_eb_bytes(L);
    return 20 + (L->a ? jf__attrs_bin_size(L->a, JF__ATTR_LAS) : 0) + jetfit_eb_bytes(L);
}

/* The input's point format and header size (keep mode). */
static unsigned in_fmt(const jf_las_out *L) { return L->a->las_head[104] & 0x3f; }
static size_t in_hsize(const jf_las_out *L) { return g16(L->a->las_head + 94); }
unsigned jf__las_out_format(const jf_las_out *L) { return keep(L) ? in_fmt(L) : 0; }

/* Walks the input's VLRs: calls f on each (offset, total size) that lies
 * inside the header block; returns the number visited. */
typedef void (*vlr_fn)(void *u, const unsigned char *v, size_t len);
static uint32_t walk_vlrs(const jf_las_out *L, vlr_fn f, void *u)
{
    const unsigned char *h = L->a->las_head;
    size_t p = in_hsize(L), end = L->a->las_head_len;
    uint32_t n = g32(h + 100), k = 0;
    for (; k < n && p + 54 <= end; k++) {
        size_t len = 54 + (size_t)g16(h + p + 20);
        if (len > end - p) break;
        f(u, h + p, len);
        p += len;
    }
    return k;
}

static int is_eb(const unsigned char *v)
{
    return !memcmp(v + 2, "LASF_Spec\0", 10) && g16(v + 18) == 4;
}

/* GeoTIFF keys, OGC WKT (LAS 1.4 R15 §2.5.1): the "LASF_Projection" VLRs */
static int is_crs(const unsigned char *v) { return !memcmp(v + 2, "LASF_Projection\0", 16); }

/* The Extra Bytes VLR of the input (NULL if none) and its descriptions
 * that fit the record (the reader's rule). */
typedef struct { const unsigned char *eb; size_t len; } eb_find;
static void find_eb(void *u, const unsigned char *v, size_t len)
{
    eb_find *e = u;
    if (!e->eb && is_eb(v)) e->eb = v, e->len = len;
}

/* Descriptions kept from the input and the bytes they cover. */
static size_t kept_descs(const jf_las_out *L, const unsigned char **first, size_t *covered)
{
    eb_find e = {NULL, 0};
    walk_vlrs(L, find_eb, &e);
    size_t room = L->a->stride - base_len[in_fmt(L)], off = 0, k = 0;
    *first = e.eb ? e.eb + 54 : NULL;
    for (; e.eb && 54 + 192 * (k + 1) <= e.len; k++) {
        const unsigned char *d = e.eb + 54 + 192 * k;
        static const unsigned base[10] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
        unsigned dt = d[2], sz = dt == 0 ? d[3] : dt <= 10 ? base[dt - 1]
                               : dt <= 30 ? base[(dt - 11) % 10] * (dt <= 20 ? 2 : 3) : 0;
        if (!sz || sz > room - off) break;
        off += sz;
    }
    *covered = off;
    return k;
}

/* Number of descriptions of the output's Extra Bytes VLR. */
static size_t out_descs(const jf_las_out *L)
{
    size_t n = L->ncols - 3;
    if (!keep(L)) return n + (L->a ? L->a->nattrs : 0);
    const unsigned char *first;
    size_t covered, k = kept_descs(L, &first, &covered);
    size_t rest = L->a->stride - base_len[in_fmt(L)] - covered;
    return n + k + (rest + 254) / 255; /* undocumented bytes, <= 255 a description */
}

typedef struct { size_t bytes; uint32_t n; } vlr_sum;
static void sum_vlr(void *u, const unsigned char *v, size_t len)
{
    vlr_sum *s = u;
    if (!is_eb(v)) s->bytes += len, s->n++;
}
static void sum_crs(void *u, const unsigned char *v, size_t len)
{
    if (is_crs(v)) sum_vlr(u, v, len);
}

int jf__las_fits(const jf_las_out *L)
{
    return jf__las_record_size(L) <= 65535 && out_descs(L) <= 65535 / EB_DESC &&
           jf__las_prefix_size(L) <= UINT32_MAX;
}

size_t jf__las_prefix_size(const jf_las_out *L)
{
    vlr_sum s = {0, 0};
    if (keep(L) || crs_only(L)) walk_vlrs(L, keep(L) ? sum_vlr : sum_crs, &s);
    return LAS_HEADER + s.bytes + VLR_HEADER + EB_DESC * out_descs(L);
}

size_t jf__las_format_row(const jf_las_out *L, size_t row, const double *vals, char *o)
{
    unsigned char *b = (unsigned char *)o;
    unsigned char *e;
    if (keep(L)) {
        memcpy(b, L->a->rec + row * L->a->stride, L->a->stride);
        e = b + L->a->stride;
    } else {
        int finite = isfinite(vals[0]) && isfinite(vals[1]) && isfinite(vals[2]);
        for (int a = 0; a < 3; a++) {
            double q = finite ? (vals[a] - L->offset[a]) / L->scale[a] : 0.0;
            long long v = llround(q);
            if (v > INT32_MAX) v = INT32_MAX;
            if (v < INT32_MIN) v = INT32_MIN;
            put32(b + 4 * a, (uint32_t)(int32_t)v);
        }
        put16(b + 12, 0);      /* intensity */
        b[14] = 1 | 1 << 3;    /* return 1 of 1 */
        b[15] = 1;             /* classification: unclassified */
        b[16] = 0;             /* scan angle rank */
        b[17] = 0;             /* user data */
        put16(b + 18, 0);      /* point source ID */
        e = b + 20;
        if (L->a && L->a->nattrs)
            e = (unsigned char *)jf__attrs_put(L->a, row, JF__ATTR_LAS, 0, (char *)e);
    }
    for (size_t j = 3; j < L->ncols; j++) {
        if (L->types[j] == JF_COL_F64) {
            putd(e, vals[j]);
            e += 8;
        } else if (L->types[j] != JF_COL_I32) {
            float f = jf__f32(L->types[j], vals[j]);
            uint32_t u;
            memcpy(&u, &f, 4);
            put32(e, u);
            e += 4;
        } else {
            double v = vals[j];
            int32_t x = v >= -2147483648.0 && v <= 2147483647.0 ? (int32_t)llround(v) : INT32_MIN;
            put32(e, (uint32_t)x);
            e += 4;
        }
    }
    return (size_t)(e - b);
}

typedef struct { unsigned char *o; } vlr_copy;
static void copy_vlr(void *u, const unsigned char *v, size_t len)
{
    vlr_copy *c = u;
    if (is_eb(v)) return;
    memcpy(c->o, v, len);
    c->o += len;
}
static void copy_crs(void *u, const unsigned char *v, size_t len)
{
    if (is_crs(v)) copy_vlr(u, v, len);
}

/* One description: type, name (all 32 bytes of the field: LAS 1.4 R15
 * table 24 needs no NUL in a full one), and description text. */
static void put_desc(unsigned char *d, unsigned code, const char *name, const char *what)
{
    d[2] = (unsigned char)code;
    memcpy(d + 4, name, strnlen(name, 32));
    snprintf((char *)d + 160, 32, "%s", what);
}

static void no_vlr(void *u, const unsigned char *v, size_t len) { (void)u, (void)v, (void)len; }

int jf__las_names(jf_las_out *L, const char *file)
{
    size_t na = L->a ? L->a->nattrs : 0, nc = L->ncols - 3, nt = na + nc;
    free(L->ebn);
    free(L->warn_names);
    L->ebn = NULL;
    L->warn_names = NULL;
    char(*e)[33] = calloc(nt ? nt : 1, sizeof *e);
    const char **full = malloc((nt ? nt : 1) * sizeof *full);
    unsigned char *used = calloc(nt ? nt : 1, 1);
    if (!e || !full || !used) {
        free(e), free(full), free(used);
        return -1;
    }
    /* the names written as descriptions: keep mode, the Extra Bytes
     * attributes (the format's own dimensions lie before base) */
    unsigned base = keep(L) ? base_len[in_fmt(L)] : 0;
    for (size_t k = 0; k < na; k++)
        full[k] = L->anames[k], used[k] = L->a->attr[k].offset >= base;
    for (size_t j = 0; j < nc; j++) full[na + j] = L->names[3 + j], used[na + j] = 1;
    for (size_t k = 0; k < nt; k++)
        if (strlen(full[k]) <= 32) memcpy(e[k], full[k], strlen(full[k]));
    /* longer: the first bytes (whole UTF-8 characters) and "~N", N = 1, 2,
     * ... the first that no other name holds (docs/formats.md) */
    for (size_t k = 0; k < nt; k++) {
        if (strlen(full[k]) <= 32) continue;
        for (unsigned t = 1;; t++) {
            char suf[16], cand[33];
            size_t sl = (size_t)snprintf(suf, sizeof suf, "~%u", t), cut = 32 - sl;
            while (cut && ((unsigned char)full[k][cut] & 0xC0) == 0x80) cut--;
            memcpy(cand, full[k], cut);
            memcpy(cand + cut, suf, sl + 1);
            int clash = 0;
            for (size_t q = 0; q < nt && !clash; q++) clash = used[q] && !strcmp(e[q], cand);
            if (clash) continue;
            memcpy(e[k], cand, strlen(cand) + 1);
            if (used[k])
                warn_add(&L->warn_names, file, "Extra Bytes name '%s' is longer than LAS's 32 "
                         "bytes: written as '%s'", full[k], cand);
            break;
        }
    }
    free(full);
    free(used);
    L->ebn = e;
    if (keep(L) || crs_only(L)) {
        uint32_t seen = walk_vlrs(L, no_vlr, NULL), decl = g32(L->a->las_head + 100);
        if (seen < decl)
            warn_add(&L->warn_names, file, "the input's VLR %u of %u runs past its point data: "
                     "VLRs %u to %u are not copied", seen + 1, decl, seen + 1, decl);
    }
    return 0;
}

void jf__las_out_free(jf_las_out *L)
{
    free(L->ebn);
    free(L->warn_frame);
    free(L->warn_names);
    L->ebn = NULL;
    L->warn_frame = L->warn_names = NULL;
}

/* The header fields a keep-mode output copies or recomputes. */
static void keep_header(const jf_las_out *L, unsigned char *b, size_t prefix)
{
    const unsigned char *h = L->a->las_head;
    unsigned minor = h[25], fmt = in_fmt(L);
    memcpy(b + 4, h + 4, 4);       /* file source ID, global encoding */
    memcpy(b + 8, h + 8, 16);      /* project GUID */
    memcpy(b + 26, h + 26, 32);    /* system identifier */
    memcpy(b + 90, h + 90, 4);     /* creation day and year */
    b[104] = (unsigned char)fmt;
    memcpy(b + 131, h + 131, 96);  /* scale, offset, bounds */
    uint64_t n = L->nrows;
    put32(b + 107, fmt < 6 && n <= UINT32_MAX ? (uint32_t)n : 0);
    if (fmt < 6) memcpy(b + 111, h + 111, 20); /* legacy points by return */
    if (minor >= 4 && in_hsize(L) >= 375) {
        memcpy(b + 255, h + 255, 120);
    } else {
        for (int r = 0; r < 5; r++) put64(b + 255 + 8 * r, g32(h + 111 + 4 * r));
    }
    /* EVLRs move: they follow the records, which grew */
    size_t evlr_at = prefix + (size_t)n * jf__las_record_size(L);
    /* the 1.3 field exists only in a header that long (a 1.3 file may
     * declare a 227-byte header) */
    int has_wave = minor >= 3 && in_hsize(L) >= 235;
    uint64_t wave = has_wave ? g64(h + 227) : 0;
    uint64_t old_evlr = minor >= 4 ? g64(h + 235) : wave;
    if (L->a->las_evlr) {
        put64(b + 235, evlr_at);
        put32(b + 243, minor >= 4 ? g32(h + 243) : 1);
        /* internal waveform data inside the EVLRs moves with them */
        if (wave >= old_evlr && wave - old_evlr < L->a->las_evlr_len)
            put64(b + 227, evlr_at + (wave - old_evlr));
    } else if (wave && !(g16(h + 6) & 2)) {
        put64(b + 227, wave); /* external waveform file: no offset in ours */
    }
}

unsigned char *jf__las_prefix(const jf_las_out *L, size_t *lenp)
{
    size_t len = *lenp = jf__las_prefix_size(L);
    unsigned char *b = calloc(1, len);
    if (!b) return NULL;
    memcpy(b, "LASF", 4);
    b[24] = 1;
    b[25] = 4;
    snprintf((char *)b + 26, 32, "jetfit");
    snprintf((char *)b + 58, 32, "jetfit " JF_VERSION_STRING);
    put16(b + 94, LAS_HEADER);
    put32(b + 96, (uint32_t)len);
    b[104] = 0;
    put16(b + 105, (unsigned)jf__las_record_size(L));
    uint32_t legacy = L->nrows <= UINT32_MAX ? (uint32_t)L->nrows : 0;
    put32(b + 107, legacy);
    put32(b + 111, legacy); /* all points are first returns */
    for (int a = 0; a < 3; a++) {
        putd(b + 131 + 8 * a, L->scale[a]);
        putd(b + 155 + 8 * a, L->offset[a]);
        putd(b + 179 + 16 * a, L->hi[a]);
        putd(b + 187 + 16 * a, L->lo[a]);
    }
    put64(b + 247, L->nrows);
    put64(b + 255, L->nrows);
    /* creation day of year (January 1 is 1) and year, in UTC (LAS 1.4 R15
     * table 3); SOURCE_DATE_EPOCH fixes them for reproducible files; a
     * LAS input's own date is kept below */
    const char *sde = getenv("SOURCE_DATE_EPOCH");
    time_t now = sde && *sde ? (time_t)strtoll(sde, NULL, 10) : time(NULL);
    struct tm tm;
    if (gmtime_r(&now, &tm)) {
        put16(b + 90, (unsigned)tm.tm_yday + 1);
        put16(b + 92, (unsigned)tm.tm_year + 1900);
    }
    unsigned char *v = b + LAS_HEADER;
    uint32_t nvlr = 1;
    if (keep(L)) {
        memset(b + 111, 0, 20);
        memset(b + 255, 0, 8);
        keep_header(L, b, len);
        vlr_copy c = {v};
        vlr_sum s = {0, 0};
        walk_vlrs(L, sum_vlr, &s);
        walk_vlrs(L, copy_vlr, &c);
        v = c.o;
        nvlr += s.n;
    } else if (crs_only(L)) {
        /* new records, the input's CRS: its VLRs and the WKT bit (4) of
         * the global encoding */
        vlr_copy c = {v};
        vlr_sum s = {0, 0};
        walk_vlrs(L, sum_crs, &s);
        walk_vlrs(L, copy_crs, &c);
        v = c.o;
        nvlr += s.n;
        b[6] = (unsigned char)(L->a->las_head[6] & 0x10);
    }
    put32(b + 100, nvlr); /* the input's VLRs, then the Extra Bytes one */
    size_t nd = out_descs(L);
    snprintf((char *)v + 2, 16, "LASF_Spec");
    put16(v + 18, 4);
    put16(v + 20, (unsigned)(EB_DESC * nd));
    snprintf((char *)v + 22, 32, "jetfit columns");
    unsigned char *d = v + VLR_HEADER;
    if (keep(L)) {
        /* the input's descriptions, scalar ones named as the columns they
         * became (an attribute per scalar, in order, after the format's
         * dimensions), then undocumented bytes in 255-byte pieces */
        const unsigned char *first;
        size_t covered, k = kept_descs(L, &first, &covered), m = 0;
        unsigned base = base_len[in_fmt(L)];
        for (size_t q = 0; q < k; q++, d += EB_DESC) {
            memcpy(d, first + EB_DESC * q, EB_DESC);
            if (d[2] >= 1 && d[2] <= 10) {
                while (m < L->a->nattrs && L->a->attr[m].offset < base) m++;
                if (m < L->a->nattrs) {
                    memset(d + 4, 0, 32);
                    memcpy(d + 4, L->ebn[m], strnlen(L->ebn[m], 32));
                    m++;
                }
            }
        }
        for (size_t rest = L->a->stride - base - covered; rest; d += EB_DESC) {
            unsigned piece = rest > 255 ? 255 : (unsigned)rest;
            d[3] = (unsigned char)piece; /* data_type 0: options = bytes */
            snprintf((char *)d + 160, 32, "undocumented extra bytes");
            rest -= piece;
        }
    } else {
        for (size_t j = 0; L->a && j < L->a->nattrs; j++, d += EB_DESC)
            put_desc(d, eb_code[jf__attr_out_type(&L->a->attr[j])], L->ebn[j], "input attribute");
    }
    for (size_t j = 3; j < L->ncols; j++, d += EB_DESC) {
        char what[32];
        snprintf(what, sizeof what, "jetfit %s", L->names[j]);
        put_desc(d, L->types[j] == JF_COL_F64 ? 10 : L->types[j] != JF_COL_I32 ? 9 : 6,
                 L->ebn[(L->a ? L->a->nattrs : 0) + j - 3], what);
    }
    return b;
}

int jf__las_write_prefix(int fd, const jf_las_out *L)
{
    size_t len;
    unsigned char *b = jf__las_prefix(L, &len);
    if (!b) return -1;
    int e = jf__pwrite_all(fd, b, len, 0);
    free(b);
    return e ? -1 : 0;
}
