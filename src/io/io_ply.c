/*
 * io_ply.c -- PLY reader (ascii, binary little and big endian).
 *
 * design: parse the header into elements and properties; then walk the
 * elements in file order.  `vertex` gives x y z (and nx ny nz when all
 * three exist), `face` its vertex_indices/vertex_index list; every other
 * element, property and list is skipped (the Stanford range scans carry a
 * range_grid element of lists).  Before allocating from a count the bytes
 * left are checked: a binary row needs at least its fixed size, an ascii
 * row a byte per value.  Ascii rows are one line each.
 */
#define _POSIX_C_SOURCE 200809L
#include "io_internal.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <omp.h>

#include "core/claim.h"

enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };
static const char *const type_names[][2] = {
    {"", ""},          {"char", "int8"},   {"uchar", "uint8"},
    {"short", "int16"}, {"ushort", "uint16"}, {"int", "int32"},
    {"uint", "uint32"}, {"float", "float32"}, {"double", "float64"}};
static const unsigned type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};

#define MAX_ELEMS 32
#define MAX_PROPS 64
#define NAME_LEN 64

typedef struct {
    char name[NAME_LEN];
    int type;        /* scalar type, or list item type */
    int count_type;  /* list count type, T_NONE for a scalar */
} ply_prop;

typedef struct {
    char name[NAME_LEN];
    uint64_t count;
    int nprops;
    ply_prop props[MAX_PROPS];
} ply_elem;

typedef struct {
    const char *name;            /* file name, for messages */
    jf_error *err;
    int format;                  /* 0 ascii, 1 little, 2 big endian */
    int nelems;
    ply_elem elems[MAX_ELEMS];
    jf_text tx;                  /* ascii body cursor */
    const unsigned char *p, *end;/* binary body cursor */
    size_t nverts_known;         /* vertex count once its element is read */
    int have_verts;
} ply;

static int type_of(const char *s, const char *e)
{
    size_t n = (size_t)(e - s);
    for (int t = T_I8; t <= T_F64; t++)
        for (int k = 0; k < 2; k++)
            if (strlen(type_names[t][k]) == n &&
                !memcmp(type_names[t][k], s, n))
                return t;
    return T_NONE;
}

static int tok_is(const char *s, const char *e, const char *word)
{
    size_t n = strlen(word);
    return (size_t)(e - s) == n && !memcmp(s, word, n);
}

static jf_status parse_header(ply *h, const char *buf, size_t len,
                              size_t *body)
{
    /* a UTF-8 byte order mark before "ply" (a text editor's) is skipped */
    size_t bom = len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3) ? 3 : 0;
    jf_text t = {buf + bom, buf + len, 0, 0};
    const char *ls, *le, *ts, *te, *q;
    if (!jf_text_line(&t, &ls, &le) || !tok_is(ls, le, "ply"))
        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, 1,
                          "not a PLY file (first line is not \"ply\")");
    h->format = -1;
    while (jf_text_line(&t, &ls, &le)) {
        /* the header is text: a NUL is named, not read as a name's end */
        if (memchr(ls, '\0', (size_t)(le - ls)))
            return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                              "a NUL byte in the header");
        q = ls;
        if (!jf_next_token(&q, le, 0, &ts, &te))
            continue; /* blank header line */
        if (tok_is(ts, te, "comment") || tok_is(ts, te, "obj_info"))
            continue;
        if (tok_is(ts, te, "end_header")) {
            if (h->format < 0)
                return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                  "no format line before end_header");
            *body = (size_t)(t.p - buf);
            h->tx = (jf_text){t.p, buf + len, t.line, 0};
            return JF_OK;
        }
        if (tok_is(ts, te, "format")) {
            if (!jf_next_token(&q, le, 0, &ts, &te))
                return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                  "format line without a format");
            if (tok_is(ts, te, "ascii"))
                h->format = 0;
            else if (tok_is(ts, te, "binary_little_endian"))
                h->format = 1;
            else if (tok_is(ts, te, "binary_big_endian"))
                h->format = 2;
            else
                return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                  "unsupported format '%.*s'",
                                  (int)(te - ts > 40 ? 40 : te - ts), ts);
            continue;
        }
        if (tok_is(ts, te, "element")) {
            const char *ns, *ne, *cs, *ce;
            uint64_t cnt;
            if (!jf_next_token(&q, le, 0, &ns, &ne) ||
                !jf_next_token(&q, le, 0, &cs, &ce) ||
                !jf_parse_size(cs, ce, UINT64_MAX, &cnt))
                return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                  "malformed element line (expected "
                                  "\"element NAME COUNT\")");
            if (h->nelems == MAX_ELEMS || ne - ns >= NAME_LEN)
                return jf_io_fail(h->err, JF_ERR_UNSUPPORTED, h->name, t.line,
                                  "too many elements or name too long");
            ply_elem *el = &h->elems[h->nelems++];
            memcpy(el->name, ns, (size_t)(ne - ns));
            el->name[ne - ns] = '\0';
            el->count = cnt;
            el->nprops = 0;
            continue;
        }
        if (tok_is(ts, te, "property")) {
            if (h->nelems == 0)
                return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                  "property before any element");
            ply_elem *el = &h->elems[h->nelems - 1];
            if (el->nprops == MAX_PROPS)
                return jf_io_fail(h->err, JF_ERR_UNSUPPORTED, h->name, t.line,
                                  "more than %d properties", MAX_PROPS);
            ply_prop *pr = &el->props[el->nprops];
            const char *a, *ae, *ns = NULL, *ne = NULL;
            int ok = jf_next_token(&q, le, 0, &a, &ae);
            pr->count_type = T_NONE;
            if (ok && tok_is(a, ae, "list")) {
                const char *c1, *c1e;
                ok = jf_next_token(&q, le, 0, &c1, &c1e) &&
                     jf_next_token(&q, le, 0, &a, &ae);
                pr->count_type = ok ? type_of(c1, c1e) : T_NONE;
                ok = ok && pr->count_type != T_NONE &&
                     pr->count_type != T_F32 && pr->count_type != T_F64;
            }
            pr->type = ok ? type_of(a, ae) : T_NONE;
            ok = ok && pr->type != T_NONE &&
                 jf_next_token(&q, le, 0, &ns, &ne) && ne - ns < NAME_LEN;
            if (!ok)
                return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                  "malformed property line (expected "
                                  "\"property TYPE NAME\" or \"property list "
                                  "INTTYPE TYPE NAME\")");
            memcpy(pr->name, ns, (size_t)(ne - ns));
            pr->name[ne - ns] = '\0';
            for (int k = 0; k < el->nprops; k++)
                if (!strcmp(el->props[k].name, pr->name))
                    return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                                      "property '%s' appears twice in element %s", pr->name,
                                      el->name);
            el->nprops++;
            continue;
        }
        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                          "unknown header line '%.*s'",
                          (int)(te - ts > 40 ? 40 : te - ts), ts);
    }
    return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, t.line,
                      "header has no end_header line");
}

/* One binary value at p as a double (byte order per h->format). */
static double load(const unsigned char *p, int type, int swap)
{
    unsigned char b[8];
    if (swap) {
        unsigned n = type_size[type];
        for (unsigned i = 0; i < n; i++)
            b[i] = p[n - 1 - i];
        p = b;
    }
    /* fixed-size copies (inlined loads, no memcpy call per value) */
    switch (type) {
    case T_I8: { int8_t v; memcpy(&v, p, 1); return v; }
    case T_U8: return p[0];
    case T_I16: { int16_t v; memcpy(&v, p, 2); return v; }
    case T_U16: { uint16_t v; memcpy(&v, p, 2); return v; }
    case T_I32: { int32_t v; memcpy(&v, p, 4); return v; }
    case T_U32: { uint32_t v; memcpy(&v, p, 4); return v; }
    case T_F32: { float v; memcpy(&v, p, 4); return v; }
    default: { double v; memcpy(&v, p, 8); return v; }
    }
}

/* What to do with each property of the element being read. */
typedef struct {
    double *dst[MAX_PROPS]; /* scalar destination row pointer or NULL */
    int face_list;          /* index of the face list property, or -1 */
    unsigned char *adst[MAX_PROPS]; /* attribute: its place in record 0 */
    size_t astride;         /* attribute record size                  */
} ply_plan;

/* The jf_attr_type of each PLY type. */
static const jf_attr_type attr_type[] = {JF_ATTR_U8, JF_ATTR_I8, JF_ATTR_U8, JF_ATTR_I16,
                                         JF_ATTR_U16, JF_ATTR_I32, JF_ATTR_U32, JF_ATTR_F32,
                                         JF_ATTR_F64};

/* Stores v (a value of PLY type t, so exact in a double) into an attribute
 * record, little endian; an ascii value outside the type's range is
 * clamped (NaN: 0). */
static void store_attr(unsigned char *p, int t, double v)
{
    static const double lo[] = {0, -128, 0, -32768, 0, -2147483648.0, 0};
    static const double hi[] = {0, 127, 255, 32767, 65535, 2147483647.0, 4294967295.0};
    uint64_t b;
    if (t == T_F32) {
        float f = (float)v;
        uint32_t u;
        memcpy(&u, &f, 4);
        b = u;
    } else if (t == T_F64) {
        memcpy(&b, &v, 8);
    } else {
        double c = v == v ? v : 0;
        c = c < lo[t] ? lo[t] : c > hi[t] ? hi[t] : c;
        b = (uint64_t)(int64_t)c;
    }
    for (unsigned k = 0; k < type_size[t]; k++)
        p[k] = (unsigned char)(b >> (8 * k));
}

/* Stores a face index (checked: integral, in range when known). */
static jf_status face_index(ply *h, jf_uvec *fi, double v, size_t line,
                            uint64_t row)
{
    if (!(v >= 0 && v < 4294967295.0) || v != (double)(uint32_t)v ||
        (h->have_verts && v >= (double)h->nverts_known))
        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                          "%sface %llu: vertex index %.17g out of range "
                          "(%zu vertices)", line ? "" : "element ",
                          (unsigned long long)row, v, h->nverts_known);
    fi->v[fi->n++] = (uint32_t)v;
    return JF_OK;
}

/* One value of type `t` of the current row: binary from h->p, or the next
 * token [*ts, *te) of the ascii line [*q, le).  Returns VAL_OK, or which
 * failure it was. */
enum { VAL_OK, VAL_TRUNCATED, VAL_SHORT_ROW, VAL_NOT_NUMBER };
static int read_value(ply *h, int t, int swap, const char **q, const char *le,
                      const char **ts, const char **te, int *found, double *v)
{
    if (h->format) {
        if ((size_t)(h->end - h->p) < type_size[t]) return VAL_TRUNCATED;
        *v = load(h->p, t, swap);
        h->p += type_size[t];
        return VAL_OK;
    }
    /* the usual token, a number ending at a blank: one pass (the same
     * value as jf_parse_double of the token); anything else, by token */
    const char *p = *q;
    while (p < le && jf_is_space(*p)) p++;
    const char *e = p < le ? jf_scan_double(p, le, v) : NULL;
    if (e && (e == le || jf_is_space(*e))) {
        *ts = p, *te = *q = e;
        (*found)++;
        return VAL_OK;
    }
    if (!jf_next_token(q, le, 0, ts, te)) return VAL_SHORT_ROW;
    (*found)++;
    return jf_parse_double(*ts, *te, v) ? VAL_OK : VAL_NOT_NUMBER;
}

static jf_status read_elem(ply *h, const ply_elem *el, const ply_plan *pl,
                           jf_cloud *c, jf_uvec *fi)
{
    int swap = 0;
    if (h->format) {
        const uint16_t one = 1;
        int little = *(const unsigned char *)&one == 1;
        swap = (h->format == 1) != little;
    }
    /* binary rows of scalar properties only (the usual vertex element) and
     * all there: fixed offsets, no per-value dispatch (a truncated file
     * takes the general loop below, which names the row) */
    if (h->format) {
        size_t row = 0, off[MAX_PROPS];
        int scalar = 1;
        for (int k = 0; k < el->nprops; k++) {
            scalar &= el->props[k].count_type == T_NONE;
            off[k] = row;
            row += type_size[el->props[k].type];
        }
        if (scalar && row && (uint64_t)(h->end - h->p) / row >= el->count) {
            for (uint64_t r = 0; r < el->count; r++, h->p += row)
                for (int k = 0; k < el->nprops; k++) {
                    if (pl->dst[k])
                        pl->dst[k][3 * r] = load(h->p + off[k], el->props[k].type, swap);
                    if (pl->adst[k]) /* normals too: also an attribute */
                        store_attr(pl->adst[k] + r * pl->astride, el->props[k].type,
                                   load(h->p + off[k], el->props[k].type, swap));
                }
            return JF_OK;
        }
    }
    const char *tag = h->format ? "element " : "";
    for (uint64_t r = 0; r < el->count; r++) {
        const char *ls = NULL, *le = NULL, *q = NULL, *ts, *te;
        size_t line = 0;
        int found = 0; /* ascii: values taken so far on this line */
        if (!h->format) {
            do {
                if (!jf_text_line(&h->tx, &ls, &le))
                    return jf_io_fail(h->err, JF_ERR_FORMAT, h->name,
                                      h->tx.line, "%s %llu: file ends "
                                      "(header says %llu)", el->name,
                                      (unsigned long long)r,
                                      (unsigned long long)el->count);
                q = ls;
                while (q < le && jf_is_space(*q)) q++; /* a blank line: skipped */
            } while (q == le);
            line = h->tx.line;
        }
        for (int k = 0; k < el->nprops; k++) {
            const ply_prop *pr = &el->props[k];
            uint64_t items = 1;
            int list = pr->count_type != T_NONE;
            double v = 0;
            if (list) {
                switch (read_value(h, pr->count_type, swap, &q, le, &ts, &te, &found, &v)) {
                case VAL_TRUNCATED: goto truncated;
                case VAL_SHORT_ROW: goto short_row;
                case VAL_NOT_NUMBER: goto not_number;
                }
                if (!(v >= 0 && v <= 4294967295.0) || v != (double)(uint64_t)v)
                    return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                                      "%s%s %llu: bad list count %.17g", tag,
                                      el->name, (unsigned long long)r, v);
                items = (uint64_t)v;
                if (k == pl->face_list) {
                    if (items < 3)
                        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name,
                                          line, "%sface %llu: %llu vertices "
                                          "(a face needs 3 or more)", tag,
                                          (unsigned long long)r,
                                          (unsigned long long)items);
                    /* bounded by the bytes left before reserving */
                    uint64_t room = h->format
                        ? (uint64_t)(h->end - h->p) / type_size[pr->type]
                        : (uint64_t)(le - q);
                    if (items > room)
                        goto truncated;
                    if (!jf_uvec_reserve(fi, fi->n + items))
                        return jf_io_fail(h->err, JF_ERR_NOMEM, h->name, 0,
                                          "out of memory");
                    c->face_off[r] = fi->n;
                }
            }
            for (uint64_t i = 0; i < items; i++) {
                switch (read_value(h, pr->type, swap, &q, le, &ts, &te, &found, &v)) {
                case VAL_TRUNCATED: goto truncated;
                case VAL_SHORT_ROW: goto short_row;
                case VAL_NOT_NUMBER: goto not_number;
                }
                if (list && k == pl->face_list) {
                    jf_status st = face_index(h, fi, v, line, r);
                    if (st != JF_OK)
                        return st;
                } else if (!list && pl->dst[k]) {
                    pl->dst[k][3 * r] = v;
                }
                if (!list && pl->adst[k]) {
                    store_attr(pl->adst[k] + r * pl->astride, pr->type, v);
                }
            }
        }
        if (!h->format && jf_next_token(&q, le, 0, &ts, &te)) {
            int n = found + 1;
            while (jf_next_token(&q, le, 0, &ts, &te))
                n++;
            return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                              "%s %llu: expected %d values, found %d",
                              el->name, (unsigned long long)r, found, n);
        }
        continue;
    truncated:
        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                          "%s%s %llu: truncated (the file ends or a list "
                          "is longer than the file)", tag, el->name,
                          (unsigned long long)r);
    short_row: {
        int lists = 0;
        for (int k = 0; k < el->nprops; k++)
            lists += el->props[k].count_type != T_NONE;
        if (!lists)
            return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                              "%s %llu: expected %d numbers, found %d",
                              el->name, (unsigned long long)r, el->nprops,
                              found);
        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                          "%s %llu: expected more than %d numbers (lists "
                          "included), found %d", el->name,
                          (unsigned long long)r, found, found);
    }
    not_number:
        return jf_io_fail(h->err, JF_ERR_FORMAT, h->name, line,
                          "%s %llu: '%.*s' is not a number", el->name,
                          (unsigned long long)r,
                          (int)(te - ts > 40 ? 40 : te - ts), ts);
    }
    return JF_OK;
}

static int prop_index(const ply_elem *el, const char *name, int list)
{
    for (int k = 0; k < el->nprops; k++)
        if (!strcmp(el->props[k].name, name) &&
            (el->props[k].count_type != T_NONE) == list)
            return k;
    return -1;
}

jf_status jf_read_ply(const char *buf, size_t len, const char *name,
                      const jf_read_opts *o, jf_cloud *c, jf_error *err)
{
    ply *h = calloc(1, sizeof *h);
    if (!h)
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    h->name = name;
    h->err = err;
    size_t body = 0;
    jf_status st = parse_header(h, buf, len, &body);
    jf_uvec fi = {0};
    int seen_vertex = 0, seen_face = 0;
    uint64_t vertex_row = 0; /* bytes of a binary vertex row */
    h->p = (const unsigned char *)buf + body;
    h->end = (const unsigned char *)buf + len;
    /* ascii body: a NUL is named as such (binary data in a text file?),
     * as in the other text readers, not reported as '' is not a number */
    const char *z = st == JF_OK && h->format == 0 ? memchr(buf + body, '\0', len - body) : NULL;
    if (z) {
        size_t line = h->tx.line + 1;
        for (const char *q = buf + body; (q = memchr(q, '\n', (size_t)(z - q))) != NULL; q++)
            line++;
        st = jf_io_fail(err, JF_ERR_FORMAT, name, line,
                        "a NUL byte (binary data in a text file?)");
    }
    for (int e = 0; st == JF_OK && e < h->nelems; e++) {
        const ply_elem *el = &h->elems[e];
        ply_plan pl = {{0}, -1, {0}, 0};
        int is_vertex = !seen_vertex && !strcmp(el->name, "vertex");
        int is_face = !seen_face && !strcmp(el->name, "face");
        /* room check: bytes a row needs at least */
        uint64_t need = 0;
        for (int k = 0; k < el->nprops; k++) {
            const ply_prop *pr = &el->props[k];
            need += h->format ? type_size[pr->count_type != T_NONE
                                              ? pr->count_type
                                              : pr->type]
                              : 1;
        }
        size_t left = h->format ? (size_t)(h->end - h->p)
                                : (size_t)(h->tx.end - h->tx.p) + 1;
        if (need == 0 && !is_vertex)
            continue; /* rows of no bytes (or faces without a list) */
        if (need && el->count > left / need) {
            st = jf_io_fail(err, JF_ERR_TOO_LARGE, name,
                            h->format ? 0 : h->tx.line,
                            "element %s: %llu rows cannot fit in the %zu "
                            "bytes left in the file (count too large or "
                            "file truncated)", el->name,
                            (unsigned long long)el->count, left);
            break;
        }
        if (is_vertex) {
            seen_vertex = 1;
            vertex_row = need;
            int ix = prop_index(el, "x", 0), iy = prop_index(el, "y", 0),
                iz = prop_index(el, "z", 0);
            if (ix < 0 || iy < 0 || iz < 0) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                "element vertex has no x, y, z properties");
                break;
            }
            if (el->count > JF_MAX_POINTS) {
                st = jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0,
                                "%llu vertices: more than supported",
                                (unsigned long long)el->count);
                break;
            }
            size_t n = (size_t)el->count;
            c->n = n;
            c->xyz = malloc((n ? n : 1) * 3 * sizeof(double));
            int inx = prop_index(el, "nx", 0), iny = prop_index(el, "ny", 0),
                inz = prop_index(el, "nz", 0);
            if (inx >= 0 && iny >= 0 && inz >= 0) {
                c->nrm = malloc((n ? n : 1) * 3 * sizeof(double));
                if (c->nrm) {
                    pl.dst[inx] = c->nrm;
                    pl.dst[iny] = c->nrm + 1;
                    pl.dst[inz] = c->nrm + 2;
                }
            }
            if (!c->xyz || (inx >= 0 && iny >= 0 && inz >= 0 && !c->nrm)) {
                st = jf_io_fail(err, JF_ERR_NOMEM, name, 0,
                                "out of memory for %zu vertices", n);
                break;
            }
            pl.dst[ix] = c->xyz;
            pl.dst[iy] = c->xyz + 1;
            pl.dst[iz] = c->xyz + 2;
            /* every other scalar property is carried (normals too: an
             * output names them in_nx ...), in its own type */
            jf_attrs *a = &c->attrs;
            for (int k = 0; k < el->nprops && !o->no_attrs; k++) {
                const ply_prop *pr = &el->props[k];
                if (k == ix || k == iy || k == iz || pr->count_type != T_NONE)
                    continue;
                if (!jf__attrs_add(a, pr->name, strlen(pr->name), attr_type[pr->type],
                                   (uint32_t)a->stride, 0, 0)) {
                    st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
                    break;
                }
                a->stride += type_size[pr->type];
            }
            if (st == JF_OK && a->nattrs) {
                a->rec = malloc((n ? n : 1) * a->stride);
                if (!a->rec) {
                    st = jf_io_fail(err, JF_ERR_NOMEM, name, 0,
                                    "out of memory for the attributes of %zu vertices", n);
                    break;
                }
                for (int k = 0, j = 0; k < el->nprops; k++) {
                    const ply_prop *pr = &el->props[k];
                    if (k == ix || k == iy || k == iz || pr->count_type != T_NONE)
                        continue;
                    pl.adst[k] = a->rec + a->attr[j++].offset;
                }
                pl.astride = a->stride;
            }
            if (st != JF_OK)
                break;
        } else if (is_face) {
            seen_face = 1;
            pl.face_list = prop_index(el, "vertex_indices", 1);
            if (pl.face_list < 0)
                pl.face_list = prop_index(el, "vertex_index", 1);
            if (pl.face_list >= 0) {
                c->nfaces = (size_t)el->count;
                c->face_off = malloc((c->nfaces + 1) * sizeof(size_t));
                if (!c->face_off) {
                    st = jf_io_fail(err, JF_ERR_NOMEM, name, 0,
                                    "out of memory for faces");
                    break;
                }
                c->face_off[0] = 0;
            }
        }
        st = read_elem(h, el, &pl, c, &fi);
        if (st == JF_OK && is_vertex) {
            h->have_verts = 1;
            h->nverts_known = c->n;
        }
        if (st == JF_OK && pl.face_list >= 0)
            c->face_off[c->nfaces] = fi.n;
    }
    if (st == JF_OK && !seen_vertex)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no vertex element");
    /* ascii: data after the last element means a count smaller than the
     * rows -- points would be dropped or read as faces */
    if (st == JF_OK && h->format == 0) {
        const char *ls, *le;
        while (jf_text_line(&h->tx, &ls, &le)) {
            const char *q = ls, *ts, *te;
            if (jf_next_token(&q, le, 0, &ts, &te)) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, h->tx.line,
                                "data after the last element: an element count in the "
                                "header is smaller than the rows in the file");
                break;
            }
        }
    }
    /* binary: room for another vertex row after the last element is the
     * same lie; fewer bytes (a writer's trailing newline) are tolerated */
    if (st == JF_OK && h->format && vertex_row && (uint64_t)(h->end - h->p) >= vertex_row)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                        "%zu bytes after the last element (a vertex row is %llu): an "
                        "element count in the header is smaller than the rows in the file",
                        (size_t)(h->end - h->p), (unsigned long long)vertex_row);
    /* faces listed before the vertices: check their indices now */
    for (size_t f = 0; st == JF_OK && f < c->nfaces; f++)
        for (size_t k = c->face_off[f]; k < c->face_off[f + 1]; k++)
            if (fi.v[k] >= c->n) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                "face %zu: vertex index %u out of range "
                                "(%zu vertices)", f, fi.v[k], c->n);
                break;
            }
    c->face_idx = fi.v;
    if (st == JF_OK && c->nfaces && !c->face_idx) /* all faces empty */
        c->face_idx = malloc(sizeof(uint32_t));
    free(h);
    return st;
}

/* ---- the vertex layout of a binary PLY (io_internal.h) ----------------- */

/* Offsets of the vertex element's rows and, per property, within a row;
 * 0 when an element has a list property or the file does not hold what
 * the header announces (lenient by less than one row, as the readers). */
static int vertex_rows(const ply *h, size_t body, uint64_t len, int *iv, uint64_t *at,
                       uint64_t *vrow)
{
    uint64_t total = body;
    *iv = -1;
    *vrow = 0;
    for (int k = 0; k < h->nelems; k++) {
        const ply_elem *el = &h->elems[k];
        uint64_t row = 0;
        for (int j = 0; j < el->nprops; j++) {
            if (el->props[j].count_type != T_NONE) return 0;
            row += type_size[el->props[j].type];
        }
        if (row && el->count > (UINT64_MAX - total) / row) return 0;
        if (*iv < 0 && !strcmp(el->name, "vertex")) {
            *iv = k;
            *vrow = row;
            *at = total;
        }
        total += row * el->count;
    }
    return *iv >= 0 && *vrow && total <= len && len - total < *vrow;
}

jf_status jf__ply_layout(const char *buf, size_t len, uint64_t size, const char *name,
                         jf_row_layout *l, jf_error *err)
{
    ply *h = calloc(1, sizeof *h);
    size_t body = 0;
    int iv;
    uint64_t at, vrow;
    memset(l, 0, sizeof *l);
    if (!h) return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    h->name = name;
    h->err = err;
    jf_status st = parse_header(h, buf, len, &body);
    if (st == JF_OK && h->format == 0)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "an ascii PLY: distributed runs read "
                        "binary PLY (jetfit estimate IN -o OUT.ply converts)");
    /* the faults the reader names, in its words and order (issue 32.5) */
    for (int k = 0; st == JF_OK && k < h->nelems; k++) {
        const ply_elem *el = &h->elems[k];
        if (strcmp(el->name, "vertex")) continue;
        if (prop_index(el, "x", 0) < 0 || prop_index(el, "y", 0) < 0 || prop_index(el, "z", 0) < 0)
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "element vertex has no x, y, z properties");
        else if (el->count > JF_MAX_POINTS)
            st = jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0, "%llu vertices: more than supported",
                            (unsigned long long)el->count);
        else if (el->count == 0) /* as jf_cloud_read: 0 vertices is an empty file */
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no points in the file");
        break;
    }
    if (st == JF_OK && !vertex_rows(h, body, size, &iv, &at, &vrow))
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "needs vertex rows of fixed size (no "
                        "lists) and a file as long as its header says");
    if (st == JF_OK) {
        const ply_elem *el = &h->elems[iv];
        static const char *const nm[6] = {"x", "y", "z", "nx", "ny", "nz"};
        int ip[6];
        for (int j = 0; j < 6; j++) ip[j] = prop_index(el, nm[j], 0);
        if (ip[0] < 0 || ip[1] < 0 || ip[2] < 0)
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "element vertex has no x y z");
        else if (el->count > JF_MAX_POINTS)
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "too many vertices");
        for (int j = 0; st == JF_OK && j < 6; j++) {
            size_t o = 0;
            for (int q = 0; q < ip[j]; q++) o += type_size[el->props[q].type];
            l->off[j] = o;
            l->type[j] = ip[j] >= 0 ? el->props[ip[j]].type : T_NONE;
        }
        const uint16_t one = 1;
        l->count = el->count;
        l->vertex_off = at;
        l->row = (size_t)vrow;
        l->has_normals = ip[3] >= 0 && ip[4] >= 0 && ip[5] >= 0;
        l->swap = (h->format == 1) != (*(const unsigned char *)&one == 1);
    }
    free(h);
    return st;
}

void jf__layout_rows(const unsigned char *raw, size_t k, const jf_row_layout *l, double *xyz,
                     double *nrm)
{
    if (l->las) {
        jf__las_rows(raw, k, l, xyz);
        if (nrm && l->has_normals)
            jf__las_normal_rows(raw, k, l, nrm);
        return;
    }
    for (size_t r = 0; r < k; r++, raw += l->row) {
        for (int j = 0; j < 3; j++) xyz[3 * r + j] = load(raw + l->off[j], l->type[j], l->swap);
        if (nrm && l->has_normals)
            for (int j = 0; j < 3; j++)
                nrm[3 * r + j] = load(raw + l->off[3 + j], l->type[3 + j], l->swap);
    }
}

int jf__layout_plain_xyz(const jf_row_layout *l)
{
    return !l->las && !l->laz && !l->swap && l->row == 24 && l->off[0] == 0 && l->off[1] == 8 &&
           l->off[2] == 16 && l->type[0] == T_F64 && l->type[1] == T_F64 && l->type[2] == T_F64;
}

/* ---- binary PLY read in chunks (jf_cloud_read) ------------------------ */

/* design (issue 12.1): a 10^8-point binary PLY must not be held twice (the
 * file image and the coordinates).  When every element has fixed-size
 * rows (scalar properties only: a point cloud, no face lists) and the
 * file's length is exactly what the header announces (up to the
 * tolerated trailing bytes), the rows are read with pread(2) a chunk at a
 * time straight into the coordinate arrays, by the same decoding as the
 * whole-file path.  Anything else (ascii, lists, a size that does not
 * match: whatever the whole-file path would refuse or treat specially)
 * returns JF_ERR_UNSUPPORTED with *c untouched, and the caller reads the
 * whole file as before, so results and messages stay the same. */
#define HEAD_MAX (1u << 20)
#define CHUNK_BYTES (4u << 20)

static int pread_all(int fd, unsigned char *p, size_t n, uint64_t at, int *e)
{
    while (n) {
        ssize_t k = pread(fd, p, n, (off_t)at);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            *e = k < 0 ? errno : 0;
            return 0;
        }
        p += k, n -= (size_t)k, at += (uint64_t)k;
    }
    return 1;
}

static jf_status read_chunked(int fd, size_t len, const char *name, const jf_read_opts *ro,
                              jf_cloud *c, jf_error *err, int with_xyz);

jf_status jf__read_ply_chunked(int fd, size_t len, const char *name, const jf_read_opts *ro,
                               jf_cloud *c, jf_error *err)
{
    return read_chunked(fd, len, name, ro, c, err, 1);
}

jf_status jf__read_ply_chunked_noxyz(int fd, size_t len, const char *name,
                                     const jf_read_opts *ro, jf_cloud *c, jf_error *err)
{
    return read_chunked(fd, len, name, ro, c, err, 0);
}

static jf_status read_chunked(int fd, size_t len, const char *name, const jf_read_opts *ro,
                              jf_cloud *c, jf_error *err, int with_xyz)
{
    size_t got = len < HEAD_MAX ? len : HEAD_MAX;
    unsigned char *buf = malloc(got > CHUNK_BYTES ? got : CHUNK_BYTES);
    ply *h = calloc(1, sizeof *h);
    jf_status st = JF_ERR_UNSUPPORTED;
    int e = 0;
    size_t body = 0;
    if (!buf || !h) {
        st = JF_ERR_UNSUPPORTED; /* the whole-file path says out of memory */
        goto out;
    }
    h->name = name;
    if (!pread_all(fd, buf, got, 0, &e)) {
        st = jf_io_fail(err, JF_ERR_IO, name, 0, "read failed: %s",
                        e ? strerror(e) : "the file shrank while it was read");
        goto out;
    }
    /* a header line cut by the prefix's end would parse differently */
    if (parse_header(h, (const char *)buf, got, &body) != JF_OK || h->format == 0 ||
        (body >= got && got < len))
        goto out;
    uint64_t at = 0, vrow = 0;
    int iv = -1;
    if (!vertex_rows(h, body, len, &iv, &at, &vrow) || h->elems[iv].count == 0 ||
        h->elems[iv].count > JF_MAX_POINTS)
        goto out;
    const ply_elem *el = &h->elems[iv];
    int ix = prop_index(el, "x", 0), iy = prop_index(el, "y", 0), iz = prop_index(el, "z", 0);
    int inx = prop_index(el, "nx", 0), iny = prop_index(el, "ny", 0),
        inz = prop_index(el, "nz", 0);
    if (ix < 0 || iy < 0 || iz < 0)
        goto out;
    size_t n = (size_t)el->count;
    /* huge pages: first-touch faults were most of the read (core/bigalloc.c) */
    double *xyz = with_xyz ? jf__big_alloc((n ? n : 1) * 3 * sizeof(double)) : NULL, *nrm = NULL;
    int has_n = inx >= 0 && iny >= 0 && inz >= 0;
    if (has_n)
        nrm = jf__big_alloc((n ? n : 1) * 3 * sizeof(double));
    if ((with_xyz && !xyz) || (has_n && !nrm)) {
        free(xyz);
        free(nrm);
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %zu vertices", n);
        goto out;
    }
    double *dst[MAX_PROPS] = {0};
    if (with_xyz)
        dst[ix] = xyz, dst[iy] = xyz + 1, dst[iz] = xyz + 2;
    if (has_n)
        dst[inx] = nrm, dst[iny] = nrm + 1, dst[inz] = nrm + 2;
    /* the attributes, as the whole-file path describes them */
    jf_attrs ta = {0};
    unsigned char *adst[MAX_PROPS] = {0};
    for (int j = 0; j < el->nprops && !(ro && ro->no_attrs); j++) {
        if (j == ix || j == iy || j == iz)
            continue;
        if (!jf__attrs_add(&ta, el->props[j].name, strlen(el->props[j].name),
                           attr_type[el->props[j].type], (uint32_t)ta.stride, 0, 0)) {
            ta.stride = SIZE_MAX;
            break;
        }
        ta.stride += type_size[el->props[j].type];
    }
    if (ta.stride == SIZE_MAX || (ta.nattrs && !(ta.rec = jf__big_alloc(n * ta.stride)))) {
        free(xyz);
        free(nrm);
        jf_attrs_free(&ta);
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0,
                        "out of memory for the attributes of %zu vertices", n);
        goto out;
    }
    for (int j = 0, k = 0; ta.nattrs && j < el->nprops; j++)
        if (j != ix && j != iy && j != iz)
            adst[j] = ta.rec + ta.attr[k++].offset;
    size_t off[MAX_PROPS], o = 0;
    for (int j = 0; j < el->nprops; j++) {
        off[j] = o;
        o += type_size[el->props[j].type];
    }
    const uint16_t one = 1;
    int swap = (h->format == 1) != (*(const unsigned char *)&one == 1);
    size_t per = CHUNK_BYTES / vrow ? CHUNK_BYTES / vrow : 1;
    if (per * vrow > (got > CHUNK_BYTES ? got : CHUNK_BYTES)) {
        free(xyz);
        free(nrm);
        jf_attrs_free(&ta);
        goto out; /* a row over the chunk: the whole-file path */
    }
    /* without coordinates, normals or attributes: nothing to read */
    const size_t nrows = with_xyz || has_n || ta.nattrs ? n : 0;
    const size_t nchunks = (nrows + per - 1) / per, cap = per * vrow;
    const int nt = ro && ro->threads > 0 ? ro->threads : jf_default_threads(NULL);
    size_t rows_done = 0;     /* atomic: progress, read by the calling thread */
    size_t next = 1;          /* the next chunk to claim (core/claim.h) */
    int failed = 0, fail_e = 0, nomem = 0;
    /* chunks read and decoded on the threads, each into its own rows (the
     * decode, not the copy from the page cache, is most of the time) */
#pragma omp parallel num_threads(nt) if (nchunks > 1)
    {
        const int tid = omp_get_thread_num();
        unsigned char *tb = tid == 0 ? buf : malloc(cap);
        if (!tb) __atomic_store_n(&nomem, 1, __ATOMIC_RELAXED);
        /* chunk 0 the calling thread's: a file of two chunks or more
         * always reports progress between its ends (core/claim.h) */
        for (size_t ch = jf__claim_first(&next); ch < nchunks; ch = jf__claim_next(&next)) {
            if (__atomic_load_n(&failed, __ATOMIC_RELAXED) || !tb) continue;
            size_t r0 = ch * per, m = n - r0 < per ? n - r0 : per;
            int pe = 0;
            if (!pread_all(fd, tb, m * vrow, at + r0 * vrow, &pe)) {
#pragma omp critical(jf_ply_chunk_fail)
                if (!__atomic_load_n(&failed, __ATOMIC_RELAXED)) {
                    fail_e = pe;
                    __atomic_store_n(&failed, 1, __ATOMIC_RELAXED);
                }
                continue;
            }
            const unsigned char *p = tb;
            for (size_t r = r0; r < r0 + m; r++, p += vrow)
                for (int j = 0; j < el->nprops; j++) {
                    if (dst[j])
                        dst[j][3 * r] = load(p + off[j], el->props[j].type, swap);
                    if (adst[j])
                        store_attr(adst[j] + r * ta.stride, el->props[j].type,
                                   load(p + off[j], el->props[j].type, swap));
                }
            size_t d = __atomic_add_fetch(&rows_done, m, __ATOMIC_RELAXED);
            if (tid == 0 && ro && ro->progress) /* bytes read so far */
                ro->progress(ro->progress_user, JF_PHASE_READ, (size_t)(at + d * vrow), len);
        }
        if (tid != 0) free(tb);
    }
    if (failed || nomem) {
        free(xyz);
        free(nrm);
        jf_attrs_free(&ta);
        st = nomem ? jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for the read buffers")
                   : jf_io_fail(err, JF_ERR_IO, name, 0, "read failed: %s",
                                fail_e ? strerror(fail_e) : "the file shrank while it was read");
        goto out;
    }
    c->n = n;
    c->xyz = xyz;
    c->nrm = nrm;
    c->attrs = ta;
    st = JF_OK;
out:
    free(buf);
    free(h);
    return st;
}
