/*
 * io_las.c -- ASPRS LAS 1.0-1.4 reader (point data record formats 0-10).
 *
 * design: the public header block gives the version, the offset to the
 * point data, the record format and length, the point count (legacy 32-bit,
 * or the 64-bit count of LAS 1.4), and the scale and offset that turn the
 * records' int32 X Y Z into coordinates (x = X * scale + offset).  Every
 * record format starts with X Y Z; what follows (intensity, returns,
 * classification, GPS time, colour, waveform, Extra Bytes) is not needed
 * for the fit: unless attributes are refused (jf_read_opts.no_attrs) the
 * records are kept whole as the cloud's attribute table, described
 * dimension by dimension (laspy's names, bit fields included), the Extra
 * Bytes by the "LASF_Spec" record 4 VLR's descriptions (so a file jetfit
 * wrote reads back with its columns); the header, VLRs and EVLRs are kept
 * verbatim for a LAS output (the header block even without attributes:
 * the output keeps the CRS).  Other VLRs are not interpreted.  Compressed LAZ (the compression bit of the format byte, as laszip
 * sets it) is decoded by io_laz.c into the LAS file it stands for.  Every header field that
 * points into the file is checked against its size before use, so a lying
 * header is a one-line error, never a read past the end; a format byte
 * outside 0-10, two disagreeing point counts and whole records past the
 * count are refused too (issue 30.1, 33.7), never read as something else.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io_internal.h"

/* Minimum record length of each point data record format (LAS 1.4 R15,
 * tables 7-17). */
static const unsigned base_len[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static uint16_t u16(const unsigned char *p) { return (uint16_t)(p[0] | p[1] << 8); }
static uint32_t u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t u64(const unsigned char *p) { return u32(p) | (uint64_t)u32(p + 4) << 32; }
static int32_t i32(const unsigned char *p) { return (int32_t)u32(p); }
static double f64(const unsigned char *p)
{
    uint64_t b = u64(p);
    double d;
    memcpy(&d, &b, sizeof d);
    return d;
}

/* The dimensions of each point data record format (LAS 1.4 R15 tables
 * 7-17), after X Y Z: name, type, offset, bit shift and width. */
typedef struct {
    const char *name;
    jf_attr_type t;
    unsigned off, shift, bits;
} dim;

static const dim legacy_dims[] = { /* formats 0-5 */
    {"intensity", JF_ATTR_U16, 12, 0, 0},
    {"return_number", JF_ATTR_U8, 14, 0, 3},
    {"number_of_returns", JF_ATTR_U8, 14, 3, 3},
    {"scan_direction_flag", JF_ATTR_U8, 14, 6, 1},
    {"edge_of_flight_line", JF_ATTR_U8, 14, 7, 1},
    {"classification", JF_ATTR_U8, 15, 0, 5},
    {"synthetic", JF_ATTR_U8, 15, 5, 1},
    {"key_point", JF_ATTR_U8, 15, 6, 1},
    {"withheld", JF_ATTR_U8, 15, 7, 1},
    {"scan_angle_rank", JF_ATTR_I8, 16, 0, 0},
    {"user_data", JF_ATTR_U8, 17, 0, 0},
    {"point_source_id", JF_ATTR_U16, 18, 0, 0},
};
static const dim extended_dims[] = { /* formats 6-10 */
    {"intensity", JF_ATTR_U16, 12, 0, 0},
    {"return_number", JF_ATTR_U8, 14, 0, 4},
    {"number_of_returns", JF_ATTR_U8, 14, 4, 4},
    {"synthetic", JF_ATTR_U8, 15, 0, 1},
    {"key_point", JF_ATTR_U8, 15, 1, 1},
    {"withheld", JF_ATTR_U8, 15, 2, 1},
    {"overlap", JF_ATTR_U8, 15, 3, 1},
    {"scanner_channel", JF_ATTR_U8, 15, 4, 2},
    {"scan_direction_flag", JF_ATTR_U8, 15, 6, 1},
    {"edge_of_flight_line", JF_ATTR_U8, 15, 7, 1},
    {"classification", JF_ATTR_U8, 16, 0, 0},
    {"user_data", JF_ATTR_U8, 17, 0, 0},
    {"scan_angle", JF_ATTR_I16, 18, 0, 0},
    {"point_source_id", JF_ATTR_U16, 20, 0, 0},
    {"gps_time", JF_ATTR_F64, 22, 0, 0},
};
static const char *const wave_names[7] = {"wavepacket_index", "wavepacket_offset",
                                          "wavepacket_size", "return_point_wave_location",
                                          "x_t", "y_t", "z_t"};
static const jf_attr_type wave_types[7] = {JF_ATTR_U8, JF_ATTR_U64, JF_ATTR_U32, JF_ATTR_F32,
                                           JF_ATTR_F32, JF_ATTR_F32, JF_ATTR_F32};
static const unsigned wave_rel[7] = {0, 1, 9, 13, 17, 21, 25};

/* Describes the dimensions of format fmt; 0 on allocation failure. */
static int add_dims(jf_attrs *a, unsigned fmt)
{
    const dim *d = fmt < 6 ? legacy_dims : extended_dims;
    size_t nd = fmt < 6 ? sizeof legacy_dims / sizeof *d : sizeof extended_dims / sizeof *d;
    for (size_t k = 0; k < nd; k++)
        if (!jf__attrs_add(a, d[k].name, strlen(d[k].name), d[k].t, d[k].off, d[k].shift,
                           d[k].bits))
            return 0;
    /* GPS time (1, 3, 4, 5), colour (2, 3, 5, 7, 8, 10), NIR (8, 10),
     * wave packets (4, 5, 9, 10) */
    static const int gps_at[11] = {0, 20, 0, 20, 20, 20, 0, 0, 0, 0, 0};
    static const int rgb_at[11] = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30};
    static const int wave_at[11] = {0, 0, 0, 0, 28, 34, 0, 0, 0, 30, 38};
    if (gps_at[fmt] && !jf__attrs_add(a, "gps_time", 8, JF_ATTR_F64, (uint32_t)gps_at[fmt], 0, 0))
        return 0;
    for (int k = 0; rgb_at[fmt] && k < 3; k++)
        if (!jf__attrs_add(a, k == 0 ? "red" : k == 1 ? "green" : "blue", k == 1 ? 5 : k ? 4 : 3,
                           JF_ATTR_U16, (uint32_t)(rgb_at[fmt] + 2 * k), 0, 0))
            return 0;
    if ((fmt == 8 || fmt == 10) && !jf__attrs_add(a, "nir", 3, JF_ATTR_U16, 36, 0, 0))
        return 0;
    for (int k = 0; wave_at[fmt] && k < 7; k++)
        if (!jf__attrs_add(a, wave_names[k], strlen(wave_names[k]), wave_types[k],
                           (uint32_t)wave_at[fmt] + wave_rel[k], 0, 0))
            return 0;
    return 1;
}

/* Bytes of an Extra Bytes value of data_type dt (LAS 1.4 R15 table 24):
 * 1-10 scalars, 11-30 the deprecated 2- and 3-vectors, 0 `options`
 * undocumented bytes; 0 for a reserved type. */
static unsigned eb_size(unsigned dt, unsigned options)
{
    static const unsigned base[10] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    if (dt == 0)
        return options;
    if (dt <= 10)
        return base[dt - 1];
    if (dt <= 30)
        return base[(dt - 11) % 10] * (dt <= 20 ? 2 : 3);
    return 0;
}

/* The Extra Bytes described by the VLRs in [hsize, data_off) (VLR
 * "LASF_Spec", record 4): scalar ones become attributes at base_len on,
 * with their scale and offset when the options say so (bits 3 and 4; the
 * doubles at bytes 112 and 136 of the 192, R15 table 24); a description
 * that runs past the record ends the list (what follows is kept in the
 * record, undescribed). */
static jf_status add_extra_bytes(jf_attrs *a, const unsigned char *b, size_t hsize,
                                 size_t data_off, uint32_t nvlr, unsigned base,
                                 unsigned rec_len, const char *name, jf_error *err)
{
    static const jf_attr_type eb_type[10] = {JF_ATTR_U8,  JF_ATTR_I8,  JF_ATTR_U16, JF_ATTR_I16,
                                             JF_ATTR_U32, JF_ATTR_I32, JF_ATTR_U64, JF_ATTR_I64,
                                             JF_ATTR_F32, JF_ATTR_F64};
    size_t p = hsize;
    for (uint32_t v = 0; v < nvlr && p + 54 <= data_off; v++) {
        size_t rl = u16(b + p + 20);
        if (rl > data_off - p - 54)
            break; /* a VLR past the point data: not trusted */
        int eb = !memcmp(b + p + 2, "LASF_Spec\0", 10) && u16(b + p + 18) == 4;
        if (eb) {
            unsigned off = base;
            for (size_t d = p + 54; d + 192 <= p + 54 + rl; d += 192) {
                unsigned dt = b[d + 2], sz = eb_size(dt, b[d + 3]);
                if (!sz || sz > rec_len - off)
                    break;
                if (dt >= 1 && dt <= 10) {
                    const char *nm = (const char *)b + d + 4;
                    size_t nl = strnlen(nm, 32);
                    unsigned opt = b[d + 3];
                    double sc = opt & 8 ? f64(b + d + 112) : 1;
                    double of = opt & 16 ? f64(b + d + 136) : 0;
                    if (!isfinite(sc) || !isfinite(of) || sc == 0) {
                        char shown[64]; /* the name's control bytes not echoed */
                        jf__attr_name(shown, nm, nl);
                        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                          "Extra Bytes description %zu (\"%s\", byte %zu): "
                                          "scale %g, offset %g: the scale must be nonzero "
                                          "and both finite",
                                          (d - p - 54) / 192, shown, d, sc, of);
                    }
                    if (!jf__attrs_add(a, nm, nl, eb_type[dt - 1], off, 0, 0))
                        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
                    if (opt & 24) {
                        jf_attr *at = &a->attr[a->nattrs - 1];
                        at->scale_factor = sc, at->add_offset = of;
                    }
                }
                off += sz;
            }
            return JF_OK; /* one Extra Bytes VLR */
        }
        p += 54 + rl;
    }
    return JF_OK;
}

/* Normals in Extra Bytes (a LAS file jetfit wrote: nx ny nz; PDAL's
 * NormalX NormalY NormalZ), float or double: their offsets in the record
 * and types (9 float, 10 double; LAS 1.4 R15 table 24), from the Extra
 * Bytes VLR among the VLRs in [hsize, end).  1 if all three are there. */
static int las_normal_fields(const unsigned char *b, size_t hsize, size_t end, uint32_t nvlr,
                             unsigned base, unsigned rec_len, size_t at[3], int dts[3])
{
    static const char *const names[2][3] = {{"nx", "ny", "nz"}, {"normalx", "normaly", "normalz"}};
    int found = 0;
    size_t p = hsize;
    for (uint32_t v = 0; v < nvlr && p + 54 <= end; v++) {
        size_t rl = u16(b + p + 20);
        if (rl > end - p - 54)
            break;
        if (!memcmp(b + p + 2, "LASF_Spec\0", 10) && u16(b + p + 18) == 4) {
            unsigned off = base;
            for (size_t d = p + 54; d + 192 <= p + 54 + rl; d += 192) {
                unsigned dt = b[d + 2], sz = eb_size(dt, b[d + 3]);
                if (!sz || sz > rec_len - off)
                    break;
                char nm[33] = {0};
                for (int k = 0; k < 32 && b[d + 4 + k]; k++)
                    nm[k] = (char)(b[d + 4 + k] | (b[d + 4 + k] >= 'A' && b[d + 4 + k] <= 'Z' ? 0x20 : 0));
                for (int a = 0; a < 3; a++) /* scaled ones stay attributes */
                    if ((dt == 9 || dt == 10) && !(b[d + 3] & 24) && (!strcmp(nm, names[0][a]) || !strcmp(nm, names[1][a]))) {
                        at[a] = off, dts[a] = (int)dt;
                        found |= 1 << a;
                    }
                off += sz;
            }
            break;
        }
        p += 54 + rl;
    }
    return found == 7;
}

/* k records' normals from their fields (las_normal_fields). */
static void las_normal_rows(const unsigned char *r, size_t k, size_t rec_len, const size_t at[3],
                            const int dts[3], double *nrm)
{
    for (size_t i = 0; i < k; i++, r += rec_len)
        for (int a = 0; a < 3; a++) {
            uint32_t w = u32(r + at[a]); /* little endian whatever the host */
            float f;
            memcpy(&f, &w, sizeof f);
            nrm[3 * i + a] = dts[a] == 9 ? (double)f : f64(r + at[a]);
        }
}

/* Into c->nrm when the records carry normals, so that orient input works
 * on them.  0 on a failed allocation. */
static int las_normals(jf_cloud *c, const unsigned char *b, size_t hsize, size_t data_off,
                       uint32_t nvlr, unsigned base, unsigned rec_len, const unsigned char *rec)
{
    size_t at[3];
    int dts[3];
    if (!las_normal_fields(b, hsize, data_off, nvlr, base, rec_len, at, dts))
        return 1;
    if (!(c->nrm = malloc(c->n * 3 * sizeof(double))))
        return 0;
    las_normal_rows(rec, c->n, rec_len, at, dts, c->nrm);
    return 1;
}

/* The header's checks (every lie named), from the first `have` bytes of a
 * file of `size` bytes. */
typedef struct {
    unsigned minor, hsize, fmt, rec_len;
    uint32_t data_off;
    uint64_t n;
    double scale[3], offset[3];
} las_hdr;

static jf_status las_header(const unsigned char *b, size_t have, uint64_t size, const char *name,
                            las_hdr *h, jf_error *err)
{
    if (have < 4 || memcmp(b, "LASF", 4))
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "not a LAS file (no LASF signature)");
    if (have < 227)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: %zu bytes, a LAS header has at least 227", have);
    unsigned major = b[24], minor = b[25];
    if (major != 1 || minor > 4)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: LAS version %u.%u (1.0 to 1.4 are read)", major, minor);
    unsigned hsize = u16(b + 94);
    uint32_t data_off = u32(b + 96);
    unsigned fmt_byte = b[104], rec_len = u16(b + 105);
    uint64_t n = u32(b + 107);
    /* bits 7 and 6 flag compression (LASzip sets 7, and 6 too in some
     * versions); the low six bits are the format, 0-10 (LAS 1.4 R15 §2.4):
     * any other byte is refused as the file holds it, never masked */
    if ((fmt_byte & 0x3f) > 10)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: point data record format %u (byte 104 holds 0x%02X; "
                          "formats 0 to 10 are read, bits 7 and 6 meaning compression)",
                          fmt_byte, fmt_byte);
    if (fmt_byte & 0xc0)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: byte 104 (0x%02X) flags compressed points where the "
                          "plain LAS records were expected", fmt_byte);
    unsigned fmt = fmt_byte & 0x3f;
    if (hsize < 227 || hsize > size || hsize > have)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: header size %u (at least 227, at most the file's %llu bytes)",
                          hsize, (unsigned long long)size);
    if (minor >= 4) {
        if (hsize < 375 || have < 375)
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "header: LAS 1.4 header size %u (at least 375)", hsize);
        uint64_t n14 = u64(b + 247);
        /* the legacy count is 0 (formats 6-10, beyond 2^32) or the same
         * (LAS 1.4 R15 §2.4): two different counts, neither is trusted */
        if (n14 && n && n != n14)
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "header: legacy point count %llu disagrees with the 64-bit "
                              "point count %llu (LAS 1.4: the legacy one is 0 or the same)",
                              (unsigned long long)n, (unsigned long long)n14);
        if (n14)
            n = n14; /* a 1.4 header whose 64-bit count is 0: the legacy one */
    }
    if (rec_len < base_len[fmt])
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: point record length %u is shorter than format %u's %u bytes",
                          rec_len, fmt, base_len[fmt]);
    if (data_off < hsize || data_off > size)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: offset to point data %u is outside the file (header %u, "
                          "file %llu bytes)", (unsigned)data_off, hsize, (unsigned long long)size);
    if (n == 0)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no points in the file");
    if (n > (size - data_off) / rec_len) /* name the first record that is not whole */
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0,
                          "header: point count %llu: records of %u bytes cannot fit in the %zu "
                          "bytes after the offset to point data (point record %llu is missing "
                          "or cut short: count too large or file truncated)",
                          (unsigned long long)n, rec_len, (size_t)(size - data_off),
                          (unsigned long long)((size - data_off) / rec_len + 1));
    if (n > JF_MAX_POINTS)
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0, "%llu points: more than supported",
                          (unsigned long long)n);
    /* whole records after the counted ones, before the EVLRs (or the
     * waveform data) or the end: a count too small, as a PLY with extra
     * rows is; bytes short of one record are not a point (docs/formats.md) */
    uint64_t stop = size, end = data_off + n * rec_len;
    if (minor >= 4 && have >= 375 && u32(b + 243) && u64(b + 235) >= end && u64(b + 235) < stop)
        stop = u64(b + 235);
    if (minor >= 3 && hsize >= 235 && (u16(b + 6) & 2) && u64(b + 227) >= end &&
        u64(b + 227) < stop)
        stop = u64(b + 227);
    if ((stop - end) / rec_len)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: point count %llu, but %llu more whole records of %u bytes "
                          "follow point record %llu (count too small, or data appended)",
                          (unsigned long long)n, (unsigned long long)((stop - end) / rec_len),
                          rec_len, (unsigned long long)n);
    for (int a = 0; a < 3; a++) {
        h->scale[a] = f64(b + 131 + 8 * a);
        h->offset[a] = f64(b + 155 + 8 * a);
        if (!(h->scale[a] != 0.0 && h->scale[a] == h->scale[a] && h->scale[a] - h->scale[a] == 0.0) ||
            !(h->offset[a] - h->offset[a] == 0.0))
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "header: the %c scale or offset is zero or not finite", "xyz"[a]);
    }
    h->minor = minor, h->hsize = hsize, h->fmt = fmt, h->rec_len = rec_len;
    h->data_off = data_off, h->n = n;
    return JF_OK;
}

/* The cloud from a LAS file's parts: b its header and VLRs (h->data_off
 * bytes), rec its h->n records, ev its EVLRs (ev_len bytes).  own: rec
 * is malloc'ed and becomes the attribute table (LAZ: decoded there, no
 * copy), else it is copied.  x y z are made in parallel (a whole file's
 * records are read once, as fast as memory allows). */
static jf_status las_fill(const unsigned char *b, const las_hdr *h, const unsigned char *rec,
                          unsigned char *own, const unsigned char *ev, size_t ev_len,
                          const char *name, const jf_read_opts *o, jf_cloud *c, jf_error *err)
{
    const unsigned fmt = h->fmt, rec_len = h->rec_len;
    const uint32_t data_off = h->data_off;
    const uint64_t n = h->n;
    const double *scale = h->scale, *off = h->offset;
    jf_attrs *at = &c->attrs;
    if (own && !o->no_attrs) /* freed with the cloud from here on */
        at->rec = own, at->stride = rec_len;
    c->xyz = jf__big_alloc((size_t)n * 3 * sizeof(double));
    if (!c->xyz) {
        if (own && o->no_attrs)
            free(own);
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %llu points",
                          (unsigned long long)n);
    }
    c->n = (size_t)n;
    double *xyz = c->xyz;
    const long long np = (long long)n;
#pragma omp parallel for schedule(static) if (np > 100000)
    for (long long i = 0; i < np; i++) {
        const unsigned char *r = rec + (size_t)i * rec_len;
        for (int a = 0; a < 3; a++)
            xyz[3 * i + a] = (double)i32(r + 4 * a) * scale[a] + off[a];
    }
    int nrm_ok = las_normals(c, b, h->hsize, data_off, u32(b + 100), base_len[fmt], rec_len, rec);
    if (own && o->no_attrs)
        free(own);
    if (!nrm_ok)
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %zu normals", c->n);
    /* the header and VLRs, even without attributes: a LAS output keeps
     * the CRS (a CRS is not an attribute; docs/formats.md) */
    if (!(at->las_head = malloc(data_off)))
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for the header");
    memcpy(at->las_head, b, data_off);
    at->las_head_len = data_off;
    if (o->no_attrs)
        return JF_OK;
    /* the records whole, the EVLRs */
    if (!own) {
        at->stride = rec_len;
        at->rec = malloc(c->n * rec_len);
        if (!at->rec)
            return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %zu records", c->n);
        memcpy(at->rec, rec, c->n * rec_len);
    }
    if (ev_len) {
        at->las_evlr_len = ev_len;
        if (!(at->las_evlr = malloc(at->las_evlr_len)))
            return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for the EVLRs");
        memcpy(at->las_evlr, ev, at->las_evlr_len);
    }
    if (!add_dims(at, fmt))
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    return add_extra_bytes(at, b, h->hsize, data_off, u32(b + 100), base_len[fmt], rec_len,
                           name, err);
}

/* LAZ: decoded (io_laz.c) straight into the attribute table; the header
 * the plain LAS file it stands for would have, checked as a LAS one. */
static jf_status laz_read(const char *buf, size_t len, const char *name, const jf_read_opts *o,
                          jf_cloud *c, jf_error *err)
{
    jf_laz *L;
    jf_status st = jf__laz_open(buf, len, name, &L, err);
    if (st != JF_OK)
        return st;
    size_t head_len, ev_len;
    uint64_t n;
    unsigned rec_len;
    const unsigned char *head = jf__laz_head(L, &head_len, &n, &rec_len);
    const unsigned char *ev = jf__laz_evlr(L, &ev_len);
    unsigned char *rec = jf__big_alloc((size_t)n * rec_len);
    las_hdr h;
    if (!rec)
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %llu points",
                        (unsigned long long)n);
    else if ((st = jf__laz_decode(L, rec, err)) == JF_OK &&
             (st = las_header(head, head_len, head_len + (uint64_t)n * rec_len + ev_len, name,
                              &h, err)) == JF_OK) {
        st = las_fill(head, &h, rec, rec, ev, ev_len, name, o, c, err);
        rec = NULL; /* las_fill's */
    }
    free(rec);
    jf__laz_close(L);
    return st;
}

jf_status jf_read_las(const char *buf, size_t len, const char *name, const jf_read_opts *o,
                      jf_cloud *c, jf_error *err)
{
    const unsigned char *b = (const unsigned char *)buf;
    if (len >= 227 && !memcmp(b, "LASF", 4) && (b[104] & 0xc0))
        return laz_read(buf, len, name, o, c, err);
    las_hdr h;
    jf_status st = las_header(b, len, len, name, &h, err);
    if (st != JF_OK)
        return st;
    /* the EVLRs (1.4: the count and start in the header; 1.3: the
     * waveform data record) */
    size_t end = h.data_off + (size_t)h.n * h.rec_len;
    uint64_t evlr = 0;
    if (h.minor >= 4 && u32(b + 243))
        evlr = u64(b + 235);
    else if (h.minor == 3 && (u16(b + 6) & 2) && h.hsize >= 235)
        evlr = u64(b + 227); /* internal waveform data */
    size_t ev_len = evlr >= end && evlr < len ? len - (size_t)evlr : 0;
    return las_fill(b, &h, b + h.data_off, NULL, b + (ev_len ? evlr : 0), ev_len, name, o, c,
                    err);
}

/* ---- point rows for readers of a byte range (io_internal.h) ----------- */

jf_status jf__las_layout(const char *buf, size_t len, uint64_t size, const char *name,
                         jf_row_layout *l, jf_error *err)
{
    las_hdr h;
    memset(l, 0, sizeof *l);
    jf_status st = las_header((const unsigned char *)buf, len, size, name, &h, err);
    if (st != JF_OK)
        return st;
    l->count = h.n;
    l->vertex_off = h.data_off;
    l->row = h.rec_len;
    l->las = 1;
    /* normals in Extra Bytes, as jf_read_las finds them (VLRs within the
     * bytes given) */
    size_t end = h.data_off < len ? h.data_off : len;
    const unsigned char *b = (const unsigned char *)buf;
    int dts[3];
    l->has_normals = las_normal_fields(b, h.hsize, end, u32(b + 100), base_len[h.fmt], h.rec_len,
                                       l->off + 3, dts);
    for (int a = 0; a < 3; a++)
        l->type[3 + a] = dts[a];
    memcpy(l->scale, h.scale, sizeof l->scale);
    memcpy(l->offset, h.offset, sizeof l->offset);
    return JF_OK;
}

void jf__las_normal_rows(const unsigned char *raw, size_t k, const jf_row_layout *l, double *nrm)
{
    las_normal_rows(raw, k, l->row, l->off + 3, l->type + 3, nrm);
}

void jf__las_rows(const unsigned char *raw, size_t k, const jf_row_layout *l, double *xyz)
{
    for (size_t i = 0; i < k; i++, raw += l->row)
        for (int a = 0; a < 3; a++)
            xyz[3 * i + a] = (double)i32(raw + 4 * a) * l->scale[a] + l->offset[a];
}
