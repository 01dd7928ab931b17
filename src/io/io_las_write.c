/*
 * io_las_write.c -- the LAS 1.4 side of the table writer (io_write.c):
 * point data record format 0 holding x y z, and every other column of the
 * table as an Extra Byte (LAS 1.4 R15 §2.5.2: one "LASF_Spec" VLR, record
 * id 4, a 192-byte description per column, named as the column: nx ... status;
 * double, or int32 for the integer columns).
 *
 * design: X Y Z are int32 counts of a scale per axis, the smallest power
 * of ten >= max(1e-7, extent / 2e9): 0.1 µm wherever the extent allows
 * (below about 200 m), never an overflow; the offset is the minimum.  The
 * frame comes from the whole cloud (jf_writer_las_frame) before the first
 * row; the header, which holds the point count and the bounds, is written
 * over the placeholder at offset 0 when the table is committed.  A non-finite
 * point is stored at the offset (status says nonfinite).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

size_t jf__las_prefix_size(size_t ncols)
{
    return LAS_HEADER + VLR_HEADER + EB_DESC * (ncols - 3);
}

size_t jf__las_record_size(const jf_col_type *types, size_t ncols)
{
    size_t n = 20;
    for (size_t j = 3; j < ncols; j++) n += types[j] == JF_COL_F64 ? 8 : 4;
    return n;
}

void jf__las_frame(const double *xyz, size_t n, double scale[3], double offset[3],
                   double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) lo[a] = INFINITY, hi[a] = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
        for (int a = 0; a < 3; a++) {
            lo[a] = p[a] < lo[a] ? p[a] : lo[a];
            hi[a] = p[a] > hi[a] ? p[a] : hi[a];
        }
    }
    for (int a = 0; a < 3; a++) {
        if (!(lo[a] <= hi[a])) lo[a] = hi[a] = 0; /* no finite point */
        double need = fmax(1e-7, (hi[a] - lo[a]) / 2e9);
        scale[a] = pow(10.0, ceil(log10(need) - 1e-12));
        offset[a] = lo[a];
        /* the bounds as stored: what X * scale + offset gives back */
        hi[a] = offset[a] + (double)llround((hi[a] - offset[a]) / scale[a]) * scale[a];
        lo[a] = offset[a];
    }
}

size_t jf__las_format_row(const double *vals, const jf_col_type *types, size_t ncols,
                          const double scale[3], const double offset[3], char *o)
{
    unsigned char *b = (unsigned char *)o;
    int finite = isfinite(vals[0]) && isfinite(vals[1]) && isfinite(vals[2]);
    for (int a = 0; a < 3; a++) {
        double q = finite ? (vals[a] - offset[a]) / scale[a] : 0.0;
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
    unsigned char *e = b + 20;
    for (size_t j = 3; j < ncols; j++) {
        if (types[j] == JF_COL_F64) {
            putd(e, vals[j]);
            e += 8;
        } else if (types[j] == JF_COL_F32) {
            float f = (float)vals[j];
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

int jf__las_write_prefix(int fd, char *const *names, const jf_col_type *types, size_t ncols,
                         size_t nrows, const double scale[3], const double offset[3],
                         const double lo[3], const double hi[3])
{
    size_t len = jf__las_prefix_size(ncols);
    unsigned char *b = calloc(1, len);
    if (!b) return -1;
    memcpy(b, "LASF", 4);
    b[24] = 1;
    b[25] = 4;
    snprintf((char *)b + 26, 32, "jetfit");
    snprintf((char *)b + 58, 32, "jetfit " JF_VERSION_STRING);
    put16(b + 94, LAS_HEADER);
    put32(b + 96, (uint32_t)len);
    put32(b + 100, 1); /* one VLR: the Extra Bytes descriptions */
    b[104] = 0;
    put16(b + 105, (unsigned)jf__las_record_size(types, ncols));
    uint32_t legacy = nrows <= UINT32_MAX ? (uint32_t)nrows : 0;
    put32(b + 107, legacy);
    put32(b + 111, legacy); /* all points are first returns */
    for (int a = 0; a < 3; a++) {
        putd(b + 131 + 8 * a, scale[a]);
        putd(b + 155 + 8 * a, offset[a]);
        putd(b + 179 + 16 * a, hi[a]);
        putd(b + 187 + 16 * a, lo[a]);
    }
    put64(b + 247, nrows);
    put64(b + 255, nrows);
    unsigned char *v = b + LAS_HEADER;
    snprintf((char *)v + 2, 16, "LASF_Spec");
    put16(v + 18, 4);
    put16(v + 20, (unsigned)(EB_DESC * (ncols - 3)));
    snprintf((char *)v + 22, 32, "jetfit columns");
    for (size_t j = 3; j < ncols; j++) {
        unsigned char *d = v + VLR_HEADER + EB_DESC * (j - 3);
        d[2] = types[j] == JF_COL_F64 ? 10 : types[j] == JF_COL_F32 ? 9 : 6;
        snprintf((char *)d + 4, 32, "%s", names[j]);
        snprintf((char *)d + 160, 32, "jetfit %s", names[j]);
    }
    size_t done = 0;
    while (done < len) {
        ssize_t w = pwrite(fd, b + done, len - done, (off_t)done);
        if (w <= 0) {
            free(b);
            return -1;
        }
        done += (size_t)w;
    }
    free(b);
    return 0;
}
