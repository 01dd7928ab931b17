/*
 * io_attrs.c -- the per-point attribute table (jf_attrs, jetfit.h): what
 * the readers keep of an input besides x y z, and how the table writer
 * puts it back out, one row at a time (issue 13.4).
 *
 * design: a point's attributes are one packed little-endian record of
 * `stride` bytes, each value in the input's own type, so colour costs 3
 * bytes a point and a LAS record is kept whole (its bit fields are
 * described, not unpacked).  The writer formats the attribute columns of
 * row i from record i (jf__attrs_put): rows are written in input order,
 * one per input point, so the writer's row number is the input index and
 * a block-wise or streaming writer needs nothing else.  Names that clash
 * with a column of the output get an `in_` prefix (jf__attrs_names).
 */
#include "io_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const unsigned jf_attr_size[10] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};

static uint64_t load_le(const unsigned char *p, unsigned n)
{
    uint64_t v = 0;
    for (unsigned k = 0; k < n; k++)
        v |= (uint64_t)p[k] << (8 * k);
    return v;
}

/* The value as its exact integer (signed types sign-extended) or double. */
typedef struct {
    int kind;      /* 0 signed, 1 unsigned, 2 float */
    int64_t i;
    uint64_t u;
    double d;
} attr_val;

static attr_val value_of(const jf_attr *at, const unsigned char *rec)
{
    attr_val v = {1, 0, 0, 0};
    const unsigned char *p = rec + at->offset;
    if (at->bits) {
        v.u = (uint64_t)((p[0] >> at->shift) & ((1u << at->bits) - 1u));
        return v;
    }
    unsigned n = jf_attr_size[at->type];
    uint64_t b = load_le(p, n);
    switch (at->type) {
    case JF_ATTR_I8: case JF_ATTR_I16: case JF_ATTR_I32: case JF_ATTR_I64: {
        unsigned sh = 64 - 8 * n;
        v.kind = 0;
        v.i = (int64_t)(b << sh) >> sh; /* sign extension */
        break;
    }
    case JF_ATTR_F32: {
        uint32_t u = (uint32_t)b;
        float f;
        memcpy(&f, &u, 4);
        v.kind = 2;
        v.d = f;
        break;
    }
    case JF_ATTR_F64:
        v.kind = 2;
        memcpy(&v.d, &b, 8);
        break;
    default:
        v.u = b;
    }
    if (at->scale_factor != 0) { /* LAS Extra Bytes: raw * scale + offset (R15 table 24) */
        double raw = v.kind == 0 ? (double)v.i : v.kind == 1 ? (double)v.u : v.d;
        v.kind = 2;
        v.d = raw * at->scale_factor + at->add_offset;
    }
    return v;
}

double jf_attr_get(const jf_attrs *a, size_t j, size_t i)
{
    if (!a || j >= a->nattrs || !a->rec)
        return NAN;
    attr_val v = value_of(&a->attr[j], a->rec + i * a->stride);
    return v.kind == 0 ? (double)v.i : v.kind == 1 ? (double)v.u : v.d;
}

int jf_attr_find(const jf_attrs *a, const char *name)
{
    for (size_t j = 0; a && name && j < a->nattrs; j++)
        if (!strcmp(a->attr[j].name, name))
            return (int)j;
    return -1;
}

void jf_attrs_free(jf_attrs *a)
{
    if (!a)
        return;
    free(a->attr);
    free(a->rec);
    free(a->las_head);
    free(a->las_evlr);
    memset(a, 0, sizeof *a);
}

void jf__attr_name(char dst[64], const char *s, size_t len)
{
    if (len > 63)
        len = 63;
    for (size_t k = 0; k < len; k++) {
        unsigned char ch = (unsigned char)s[k];
        dst[k] = ch <= ' ' || ch == ',' || ch == '#' || ch == 0x7f ? '_' : (char)ch;
    }
    dst[len] = '\0';
    if (!len)
        snprintf(dst, 64, "_");
}

int jf__attrs_add(jf_attrs *a, const char *name, size_t len, jf_attr_type t,
                  uint32_t offset, unsigned shift, unsigned bits)
{
    /* capacity: powers of two from 16 (a CSV of 100,000 named columns
     * grew by 16 at a time: quadratic copying) */
    size_t n = a->nattrs;
    if (n % 16 == 0 && (n < 16 || (n & (n - 1)) == 0)) {
        jf_attr *q = realloc(a->attr, (n < 16 ? 16 : 2 * n) * sizeof *q);
        if (!q)
            return 0;
        a->attr = q;
    }
    jf_attr *at = &a->attr[a->nattrs++];
    memset(at, 0, sizeof *at);
    jf__attr_name(at->name, name, len);
    at->type = t;
    at->offset = offset;
    at->shift = (uint8_t)shift;
    at->bits = (uint8_t)bits;
    return 1;
}

/* ---- output --------------------------------------------------------------- */

/* A set of names for jf__attrs_names: open addressing over FNV-1a
 * hashes, so a CSV with 100,000 named columns costs linear time (a
 * search per pair of names took minutes). */
typedef struct {
    const char **slot;
    size_t mask;
} name_set;

static size_t name_hash(const char *s)
{
    uint64_t h = 14695981039346656037ULL;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ULL;
    return (size_t)h;
}

/* 1 if s is in the set; else adds it when add is set (s must outlive the set) */
static int name_seen(name_set *ns, const char *s, int add)
{
    size_t i = name_hash(s) & ns->mask;
    for (; ns->slot[i]; i = (i + 1) & ns->mask)
        if (!strcmp(ns->slot[i], s))
            return 1;
    if (add)
        ns->slot[i] = s;
    return 0;
}

int jf__attrs_names(const jf_attrs *a, char *const *cols, size_t ncols, char (*out)[64])
{
    name_set ns;
    size_t want = 2 * (ncols + a->nattrs) + 2, cap = 16;
    while (cap < want)
        cap *= 2;
    ns.mask = cap - 1;
    ns.slot = calloc(cap, sizeof *ns.slot);
    if (!ns.slot)
        return -2;
    for (size_t k = 0; k < ncols; k++)
        name_seen(&ns, cols[k], 1);
    for (size_t j = 0; j < a->nattrs; j++) {
        char nm[64];
        snprintf(nm, sizeof nm, "%s", a->attr[j].name);
        while (name_seen(&ns, nm, 0)) {
            char t[64];
            if (strlen(nm) + 3 >= sizeof t) {
                free(ns.slot);
                return -1; /* cannot be made unique within 63 bytes */
            }
            snprintf(t, sizeof t, "in_%s", nm);
            memcpy(nm, t, sizeof nm);
        }
        memcpy(out[j], nm, sizeof nm);
        name_seen(&ns, out[j], 1);
    }
    free(ns.slot);
    return 0;
}

jf_attr_type jf__attr_out_type(const jf_attr *at)
{
    return at->bits ? JF_ATTR_U8 : at->scale_factor != 0 ? JF_ATTR_F64 : at->type;
}

const char *jf__attr_ply_type(const jf_attr *at)
{
    static const char *const t[10] = {"char", "uchar", "short", "ushort", "int",
                                      "uint", "double", "double", "float", "double"};
    return t[jf__attr_out_type(at)];
}

static char *put_le(char *o, uint64_t v, unsigned n, int big)
{
    for (unsigned k = 0; k < n; k++)
        o[big ? n - 1 - k : k] = (char)(unsigned char)(v >> (8 * k));
    return o + n;
}

char *jf__attrs_put(const jf_attrs *a, size_t row, int mode, char sep, char *o)
{
    const unsigned char *rec = a->rec + row * a->stride;
    for (size_t j = 0; j < a->nattrs; j++) {
        const jf_attr *at = &a->attr[j];
        jf_attr_type t = jf__attr_out_type(at);
        if (mode == JF__ATTR_TEXT) {
            attr_val v = value_of(at, rec);
            *o++ = sep;
            if (v.kind == 0) {
                if (v.i < 0)
                    *o++ = '-';
                o = jf_fmt_uint(o, v.i < 0 ? (uint64_t)0 - (uint64_t)v.i : (uint64_t)v.i);
            } else if (v.kind == 1) {
                o = jf_fmt_uint(o, v.u);
            } else {
                /* a float too: its exact value as a double, so a reader
                 * gets the same number back, not a near one */
                o = jf_fmt_g17(o, v.d);
            }
            continue;
        }
        int big = mode == JF__ATTR_PLY_BE;
        if (at->bits) {
            attr_val v = value_of(at, rec);
            *o++ = (char)(unsigned char)v.u;
        } else if (at->scale_factor != 0 ||
                   (mode != JF__ATTR_LAS && (t == JF_ATTR_I64 || t == JF_ATTR_U64))) {
            /* a scaled value, or a 64-bit integer (PLY has none): a double
             * (exact up to 2^53) */
            double d = jf_attr_get(a, j, row);
            uint64_t b;
            memcpy(&b, &d, 8);
            o = put_le(o, b, 8, big);
        } else {
            unsigned n = jf_attr_size[t];
            o = put_le(o, load_le(rec + at->offset, n), n, big);
        }
    }
    return o;
}

size_t jf__attrs_bin_size(const jf_attrs *a, int mode)
{
    size_t n = 0;
    for (size_t j = 0; j < a->nattrs; j++) {
        jf_attr_type t = jf__attr_out_type(&a->attr[j]);
        n += mode != JF__ATTR_LAS && (t == JF_ATTR_I64 || t == JF_ATTR_U64) ? 8 : jf_attr_size[t];
    }
    return n;
}
