/*
 * e57_cv.c -- the binary section of an E57 CompressedVector (ASTM E2807,
 * section 9): a 32-byte section header (id 1, section length, offset of
 * the first data packet, offset of the index packet), then packets.  A
 * data packet (type 1) holds one bytestream piece per prototype field, in
 * prototype order; a field's values are its pieces concatenated across
 * packets: IEEE floats or doubles (little endian), or Integer and
 * ScaledInteger values minus their minimum, bit-packed in
 * ceil(log2(max - min + 1)) bits, least significant bit first.  Index
 * packets (type 0) and empty packets (type 2) carry no values.
 *
 * design: two passes over the packets -- sizes, then copies -- gather each
 * field's stream into one buffer (a value may straddle packets), then each
 * field is decoded in one loop into its sink.  Every length is checked
 * against the section and the record count before a byte is read: a
 * recordCount the packets cannot hold is an error naming the field.
 */
#include "e57.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t le(const unsigned char *p, unsigned n)
{
    uint64_t v = 0;
    for (unsigned k = 0; k < n; k++)
        v |= (uint64_t)p[k] << (8 * k);
    return v;
}

unsigned jf__e57_bits(int64_t min, int64_t max)
{
    uint64_t range = (uint64_t)max - (uint64_t)min; /* max >= min: exact */
    unsigned b = 0;
    while (b < 64 && (range >> b))
        b++;
    return b;
}

/* Bytes a field's stream needs for count values. */
static uint64_t need_bytes(const jf_e57_field *f, uint64_t count)
{
    if (f->kind == JF_E57_FLOAT)
        return 4 * count;
    if (f->kind == JF_E57_DOUBLE)
        return 8 * count;
    return (count * f->bits + 7) / 8; /* count < 2^32, bits <= 64: no overflow */
}

static void store(unsigned char *d, jf_attr_type t, int64_t iv, double dv, int isint)
{
    switch (t) {
    case JF_ATTR_F64:
        if (isint)
            dv = (double)iv;
        memcpy(d, &dv, 8);
        return;
    case JF_ATTR_F32: {
        float f = (float)(isint ? (double)iv : dv);
        memcpy(d, &f, 4);
        return;
    }
    default: {
        if (!isint)
            iv = (int64_t)dv;
        uint64_t u = (uint64_t)iv;
        for (unsigned k = 0; k < jf_attr_size[t]; k++)
            d[k] = (unsigned char)(u >> (8 * k));
    }
    }
}

/* Decodes one gathered stream s into the field's sink.  0, or 1 when a
 * value is outside [min, max] (*bad its index). */
static int decode(const jf_e57_field *f, const unsigned char *s, uint64_t count, uint64_t *bad)
{
    unsigned char *d = f->dst;
    size_t st = f->stride;
    if (f->kind == JF_E57_FLOAT || f->kind == JF_E57_DOUBLE) {
        int sgl = f->kind == JF_E57_FLOAT;
        for (uint64_t k = 0; k < count; k++, d += st) {
            double v;
            if (sgl) {
                uint32_t u = (uint32_t)le(s + 4 * k, 4);
                float x;
                memcpy(&x, &u, 4);
                v = x;
            } else {
                uint64_t u = le(s + 8 * k, 8);
                memcpy(&v, &u, 8);
            }
            if (f->type == JF_ATTR_F64)
                memcpy(d, &v, 8);
            else
                store(d, f->type, 0, v, 0);
        }
        return 0;
    }
    unsigned w = f->bits;
    uint64_t mask = w == 64 ? ~(uint64_t)0 : ((uint64_t)1 << w) - 1;
    uint64_t range = (uint64_t)f->max - (uint64_t)f->min;
    for (uint64_t k = 0; k < count; k++, d += st) {
        uint64_t raw = 0;
        if (w) {
            uint64_t bit = k * w;
            const unsigned char *p = s + (bit >> 3);
            unsigned sh = (unsigned)(bit & 7);
            raw = le(p, 8) >> sh;
            if (sh + w > 64)
                raw |= (uint64_t)p[8] << (64 - sh);
            raw &= mask;
            if (raw > range) {
                *bad = k;
                return 1;
            }
        }
        int64_t iv = (int64_t)((uint64_t)f->min + raw);
        if (f->kind == JF_E57_SCALED)
            store(d, f->type, 0, (double)iv * f->scale + f->offset, 0);
        else
            store(d, f->type, iv, 0, 1);
    }
    return 0;
}

jf_status jf__e57_cv_read(const unsigned char *log, size_t loglen, size_t sec,
                          jf_e57_field *f, size_t nf, uint64_t count, const char *name,
                          const char *what, jf_error *err)
{
#define FAIL(...) return jf_io_fail(err, JF_ERR_FORMAT, name, 0, __VA_ARGS__)
    if (sec > loglen || loglen - sec < 32)
        FAIL("%s: the binary section at logical byte %zu is past the end of the file", what,
             sec);
    const unsigned char *h = log + sec;
    if (h[0] != 1)
        FAIL("%s: the binary section at logical byte %zu is not a CompressedVector section "
             "(section id %u, expected 1)", what, sec, h[0]);
    uint64_t seclen = le(h + 8, 8), dphys = le(h + 16, 8);
    size_t data;
    if (seclen < 32 || seclen > loglen - sec)
        FAIL("%s: the binary section's length (%llu bytes) runs past the end of the file",
             what, (unsigned long long)seclen);
    size_t end = sec + (size_t)seclen;
    if (count && (!jf__e57_logical(dphys, &data) || data < sec + 32 || data > end))
        FAIL("%s: the first data packet's offset (%llu) is outside its section", what,
             (unsigned long long)dphys);
    if (nf > 65535)
        FAIL("%s: %zu fields, more than a packet can hold", what, nf);
    uint64_t *need = calloc(nf ? nf : 1, sizeof *need);
    uint64_t *have = calloc(nf ? nf : 1, sizeof *have);
    unsigned char **buf = calloc(nf ? nf : 1, sizeof *buf);
    jf_status st = JF_OK;
    if (!need || !have || !buf) {
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "%s: out of memory", what);
        goto out;
    }
    int nothing = 1, enough;
    for (size_t j = 0; j < nf; j++) {
        need[j] = need_bytes(&f[j], count);
        nothing &= need[j] == 0;
    }
    /* pass 0 sizes the streams, pass 1 copies them */
    for (int pass = 0; pass < 2 && !nothing; pass++) {
        if (pass == 1) {
            for (size_t j = 0; j < nf; j++) {
                /* 16 zero bytes after: the bit unpacker loads 9 at a time */
                if (!(buf[j] = calloc(have[j] + 16, 1))) {
                    st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "%s: out of memory for %llu "
                                    "bytes of field %s", what,
                                    (unsigned long long)have[j], f[j].name);
                    goto out;
                }
                have[j] = 0;
            }
        }
        size_t pos = data;
        for (;;) {
            enough = 1;
            for (size_t j = 0; j < nf; j++)
                enough &= have[j] >= need[j];
            if (enough)
                break;
            if (end - pos < 4) {
                size_t j = 0;
                while (have[j] >= need[j])
                    j++;
                uint64_t got = f[j].kind == JF_E57_FLOAT    ? have[j] / 4
                               : f[j].kind == JF_E57_DOUBLE ? have[j] / 8
                                                            : have[j] * 8 / f[j].bits;
                st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "%s: recordCount is %llu but the "
                                "binary section holds %llu values of field %s", what,
                                (unsigned long long)count, (unsigned long long)got, f[j].name);
                goto out;
            }
            const unsigned char *p = log + pos;
            size_t plen = (size_t)le(p + 2, 2) + 1;
            if (plen > end - pos) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "%s: the packet at logical byte "
                                "%zu (%zu bytes) runs past its section", what, pos, plen);
                goto out;
            }
            if (p[0] == 1) {
                if (plen < 6 || le(p + 4, 2) != nf || 6 + 2 * nf > plen) {
                    st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "%s: the data packet at "
                                    "logical byte %zu has %llu bytestreams for %zu fields",
                                    what, pos, plen < 6 ? 0ULL : (unsigned long long)le(p + 4, 2),
                                    nf);
                    goto out;
                }
                size_t off = 6 + 2 * nf;
                for (size_t j = 0; j < nf; j++) {
                    size_t bl = (size_t)le(p + 6 + 2 * j, 2);
                    if (bl > plen - off) {
                        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "%s: the data packet at "
                                        "logical byte %zu: bytestream %zu overruns the packet",
                                        what, pos, j);
                        goto out;
                    }
                    if (pass == 1)
                        memcpy(buf[j] + have[j], p + off, bl);
                    have[j] += bl;
                    off += bl;
                }
            } else if (p[0] != 0 && p[0] != 2) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "%s: the packet at logical byte "
                                "%zu has type %u (expected 0 index, 1 data or 2 empty)", what,
                                pos, p[0]);
                goto out;
            }
            pos += plen;
        }
    }
    for (size_t j = 0; j < nf; j++) {
        uint64_t bad;
        if (f[j].dst && need[j] && decode(&f[j], buf[j], count, &bad)) {
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "%s: record %llu: field %s is outside "
                            "its declared range [%lld, %lld]", what, (unsigned long long)bad,
                            f[j].name, (long long)f[j].min, (long long)f[j].max);
            goto out;
        }
        if (f[j].dst && !need[j]) /* 0 bits: every value is the minimum */
            for (uint64_t k = 0; k < count; k++) {
                unsigned char *d = f[j].dst + k * f[j].stride;
                if (f[j].kind == JF_E57_SCALED)
                    store(d, f[j].type, 0, (double)f[j].min * f[j].scale + f[j].offset, 0);
                else
                    store(d, f[j].type, f[j].min, 0, 1);
            }
    }
out:
    for (size_t j = 0; buf && j < nf; j++)
        free(buf[j]);
    free(buf);
    free(need);
    free(have);
    return st;
#undef FAIL
}
