/*
 * io_las.c -- ASPRS LAS 1.0-1.4 reader (point data record formats 0-10).
 *
 * design: the public header block gives the version, the offset to the
 * point data, the record format and length, the point count (legacy 32-bit,
 * or the 64-bit count of LAS 1.4), and the scale and offset that turn the
 * records' int32 X Y Z into coordinates (x = X * scale + offset).  Every
 * record format starts with X Y Z; what follows (intensity, returns,
 * classification, GPS time, colour, waveform, Extra Bytes) is not needed
 * for the fit and is skipped by the record length.  VLRs and EVLRs are not
 * read.  Compressed LAZ (the compression bit of the format byte, as laszip
 * sets it) is refused with how to convert it.  Every header field that
 * points into the file is checked against its size before use, so a lying
 * header is a one-line error, never a read past the end.
 */
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

jf_status jf_read_las(const char *buf, size_t len, const char *name, jf_cloud *c,
                      jf_error *err)
{
    const unsigned char *b = (const unsigned char *)buf;
    if (len < 4 || memcmp(b, "LASF", 4))
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "not a LAS file (no LASF signature)");
    if (len < 227)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: %zu bytes, a LAS header has at least 227", len);
    unsigned major = b[24], minor = b[25];
    if (major != 1 || minor > 4)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: LAS version %u.%u (1.0 to 1.4 are read)", major, minor);
    unsigned hsize = u16(b + 94);
    uint32_t data_off = u32(b + 96);
    unsigned fmt_byte = b[104], rec_len = u16(b + 105);
    uint64_t n = u32(b + 107);
    if (fmt_byte & 0x80)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "compressed LAS (LAZ) is not read: decompress it first, e.g. "
                          "`pdal translate in.laz out.las` or `las2las -i in.laz -o out.las`");
    unsigned fmt = fmt_byte & 0x3f;
    if (fmt > 10)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: point data record format %u (0 to 10 are read)", fmt);
    if (hsize < 227 || hsize > len)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: header size %u (at least 227, at most the file's %zu bytes)",
                          hsize, len);
    if (minor >= 4) {
        if (hsize < 375)
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "header: LAS 1.4 header size %u (at least 375)", hsize);
        uint64_t n14 = u64(b + 247);
        if (n14)
            n = n14; /* the 64-bit count; the legacy one is 0 beyond 2^32 or for formats 6-10 */
    }
    if (rec_len < base_len[fmt])
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: point record length %u is shorter than format %u's %u bytes",
                          rec_len, fmt, base_len[fmt]);
    if (data_off < hsize || data_off > len)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: offset to point data %u is outside the file (header %u, "
                          "file %zu bytes)", (unsigned)data_off, hsize, len);
    if (n == 0)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no points in the file");
    if (n > (len - data_off) / rec_len) /* name the first record that is not whole */
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0,
                          "header: point count %llu: records of %u bytes cannot fit in the %zu "
                          "bytes after the offset to point data (point record %llu is missing "
                          "or cut short: count too large or file truncated)",
                          (unsigned long long)n, rec_len, len - data_off,
                          (unsigned long long)((len - data_off) / rec_len + 1));
    if (n > JF_MAX_POINTS)
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0, "%llu points: more than supported",
                          (unsigned long long)n);
    double scale[3], off[3];
    for (int a = 0; a < 3; a++) {
        scale[a] = f64(b + 131 + 8 * a);
        off[a] = f64(b + 155 + 8 * a);
        if (!(scale[a] != 0.0 && scale[a] == scale[a] && scale[a] - scale[a] == 0.0) ||
            !(off[a] - off[a] == 0.0))
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "header: the %c scale or offset is zero or not finite", "xyz"[a]);
    }
    c->xyz = malloc((size_t)n * 3 * sizeof(double));
    if (!c->xyz)
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %llu points",
                          (unsigned long long)n);
    c->n = (size_t)n;
    const unsigned char *r = b + data_off;
    for (size_t i = 0; i < c->n; i++, r += rec_len)
        for (int a = 0; a < 3; a++)
            c->xyz[3 * i + a] = (double)i32(r + 4 * a) * scale[a] + off[a];
    return JF_OK;
}
