/*
 * io_e57.c -- the E57 reader (ASTM E2807-11): every scan of /data3D in one
 * frame, with its scanner position, attributes and the scan index.
 *
 * design (the standard's sections in brackets):
 *  1. the 48-byte file header [7.1]: "ASTM-E57", version 1.x, the file's
 *     physical length (a shorter file is truncated), the XML section's
 *     physical offset and logical length, page size 1024;
 *  2. every page's CRC-32C [7.2] (e57_crc.c), giving the logical image;
 *  3. the XML section [8] as a tree (e57_xml.c);
 *  4. per /data3D child [8.4.3]: `points`, a CompressedVector whose
 *     prototype names the fields -- cartesianX/Y/Z, or sphericalRange,
 *     sphericalAzimuth, sphericalElevation (radians) converted to x y z;
 *     cartesianInvalidState / sphericalInvalidState (non-zero: no usable
 *     point) -- and `pose`, a unit quaternion (w x y z) and a translation:
 *     p' = R p + t puts every scan in the file's frame and t is the
 *     scanner's origin there (--orient scanner);
 *  5. the binary sections (e57_cv.c) decoded straight into the cloud: x y z
 *     as doubles, every other prototype field into the attribute table in
 *     its own type (Integer: the smallest integer type holding its
 *     [minimum, maximum]; Float single: float; ScaledInteger, double
 *     Floats: double), plus `scan`, the /data3D index of the row.
 * Invalid points stay as rows of NaN (the pipeline marks them nonfinite),
 * so rows keep one-to-one with the file's records.  A field that appears
 * in some scans only is NaN (float types) or 0 (integers) in the others.
 */
#include "e57.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t le64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int k = 7; k >= 0; k--)
        v = v << 8 | p[k];
    return v;
}

#define le32(p) (le64(p) & 0xFFFFFFFFu)

/* One attribute of the output: the union of a name over every scan. */
typedef struct {
    const char *name;
    int kinds;          /* bit per JF_E57_* kind seen */
    int64_t min, max;   /* Integer: the union of the ranges */
} acol;

typedef struct {
    const unsigned char *log;
    size_t loglen;
    const char *name;
    const jf_e57_xml *x;
    jf_error *err;
} ctx;

static int is_coord(const char *n)
{
    static const char *const c[] = {"cartesianX",     "cartesianY",       "cartesianZ",
                                    "sphericalRange", "sphericalAzimuth", "sphericalElevation",
                                    "cartesianInvalidState", "sphericalInvalidState"};
    for (size_t k = 0; k < sizeof c / sizeof *c; k++)
        if (!strcmp(n, c[k]))
            return (int)k + 1;
    return 0;
}

/* Whole string s as a signed 64-bit decimal integer. */
static int parse_i64(const char *s, int64_t *out)
{
    const char *p = s;
    int neg = 0;
    if (*p == '-' || *p == '+')
        neg = *p++ == '-';
    if (!*p)
        return 0;
    uint64_t v = 0, lim = neg ? (uint64_t)INT64_MAX + 1 : (uint64_t)INT64_MAX;
    for (; *p; p++) {
        unsigned d = (unsigned)(*p - '0');
        if (d > 9 || v > (lim - d) / 10)
            return 0;
        v = v * 10 + d;
    }
    *out = neg ? (int64_t)(0 - v) : (int64_t)v;
    return 1;
}

static int parse_real(const char *s, double *out)
{
    return *s ? jf_parse_double(s, s + strlen(s), out) : (*out = 0, 1);
}

/* A Float or Integer leaf's value (absent: def). */
static int leaf_value(const jf_e57_xml *x, int parent, const char *name, double def,
                      double *out)
{
    int i = jf__e57_child(x, parent, name);
    if (i < 0) {
        *out = def;
        return 1;
    }
    return parse_real(x->node[i].text, out) && isfinite(*out);
}

/* The prototype's field i as f (sink unset); 0 with err set if it is not a
 * field this reader can decode. */
static int field_of(ctx *c, size_t scan, int i, jf_e57_field *f)
{
    const jf_e57_xml *x = c->x;
    const jf_e57_node *nd = &x->node[i];
    const char *type = jf__e57_attr(x, i, "type");
    memset(f, 0, sizeof *f);
    f->name = nd->name;
    f->scale = 1;
#define BAD(...)                                                                      \
    do {                                                                              \
        jf_io_fail(c->err, JF_ERR_FORMAT, c->name, 0, "XML line %zu: data3D[%zu] "   \
                   "prototype field %s: ", nd->line, scan, nd->name);                 \
        size_t k_ = strlen(c->err ? c->err->msg : "");                                \
        if (c->err && k_ < sizeof c->err->msg)                                        \
            snprintf(c->err->msg + k_, sizeof c->err->msg - k_, __VA_ARGS__);         \
        return 0;                                                                     \
    } while (0)
    if (!type)
        BAD("no type");
    if (!strcmp(type, "Float")) {
        const char *pr = jf__e57_attr(x, i, "precision");
        if (pr && strcmp(pr, "single") && strcmp(pr, "double"))
            BAD("precision '%s' (expected single or double)", pr);
        f->kind = pr && !strcmp(pr, "single") ? JF_E57_FLOAT : JF_E57_DOUBLE;
        return 1;
    }
    if (strcmp(type, "Integer") && strcmp(type, "ScaledInteger"))
        BAD("type '%s' cannot be a point field (expected Integer, ScaledInteger or Float)",
            type);
    f->kind = strcmp(type, "Integer") ? JF_E57_SCALED : JF_E57_INT;
    const char *mn = jf__e57_attr(x, i, "minimum"), *mx = jf__e57_attr(x, i, "maximum");
    f->min = INT64_MIN; /* the standard's defaults [8.3.5] */
    f->max = INT64_MAX;
    if (mn && !parse_i64(mn, &f->min))
        BAD("minimum '%s' is not a 64-bit integer (a width over 64 bits)", mn);
    if (mx && !parse_i64(mx, &f->max))
        BAD("maximum '%s' is not a 64-bit integer (a width over 64 bits)", mx);
    if (f->min > f->max)
        BAD("minimum %lld > maximum %lld", (long long)f->min, (long long)f->max);
    f->bits = jf__e57_bits(f->min, f->max);
    if (f->kind == JF_E57_SCALED) {
        const char *sc = jf__e57_attr(x, i, "scale"), *of = jf__e57_attr(x, i, "offset");
        if ((sc && (!parse_real(sc, &f->scale) || !isfinite(f->scale) || f->scale == 0)) ||
            (of && (!parse_real(of, &f->offset) || !isfinite(f->offset))))
            BAD("scale or offset is not a finite number (scale non-zero)");
    }
    return 1;
#undef BAD
}

/* The output type of an attribute column. */
static jf_attr_type col_type(const acol *a)
{
    if (a->kinds == 1 << JF_E57_FLOAT)
        return JF_ATTR_F32;
    if (a->kinds != 1 << JF_E57_INT)
        return JF_ATTR_F64;
    if (a->min >= 0)
        return a->max <= 255 ? JF_ATTR_U8 : a->max <= 65535 ? JF_ATTR_U16
               : a->max <= (int64_t)UINT32_MAX ? JF_ATTR_U32 : JF_ATTR_U64;
    if (a->min >= -128 && a->max <= 127)
        return JF_ATTR_I8;
    if (a->min >= -32768 && a->max <= 32767)
        return JF_ATTR_I16;
    return a->min >= INT32_MIN && a->max <= INT32_MAX ? JF_ATTR_I32 : JF_ATTR_I64;
}

/* One scan as found in the XML. */
typedef struct {
    int proto;          /* prototype node */
    size_t sec;         /* logical offset of its binary section */
    uint64_t count;
    double R[3][3], t[3];
    int spherical;
} scaninfo;

static jf_status scan_header(ctx *c, size_t s, int vc, scaninfo *si, jf_e57_field **fs,
                             size_t *nfs, acol **cols, size_t *ncols)
{
    const jf_e57_xml *x = c->x;
    size_t line = x->node[vc].line;
#define FAIL(...)                                                                          \
    return jf_io_fail(c->err, JF_ERR_FORMAT, c->name, 0, __VA_ARGS__)
    int pts = jf__e57_child(x, vc, "points");
    const char *ty = jf__e57_attr(x, pts, "type");
    if (pts < 0 || !ty || strcmp(ty, "CompressedVector"))
        FAIL("XML line %zu: data3D[%zu] has no points CompressedVector", line, s);
    line = x->node[pts].line;
    const char *fo = jf__e57_attr(x, pts, "fileOffset"), *rc = jf__e57_attr(x, pts, "recordCount");
    int64_t off, cnt;
    if (!fo || !rc || !parse_i64(fo, &off) || !parse_i64(rc, &cnt) || off < 0 || cnt < 0)
        FAIL("XML line %zu: data3D[%zu] points: fileOffset and recordCount must be "
             "non-negative integers", line, s);
    if (!jf__e57_logical((uint64_t)off, &si->sec))
        FAIL("XML line %zu: data3D[%zu] points: fileOffset %lld is inside a page checksum",
             line, s, (long long)off);
    if (si->sec > c->loglen || c->loglen - si->sec < 32 || c->log[si->sec] != 1)
        FAIL("XML line %zu: data3D[%zu] points: fileOffset %lld is not a CompressedVector "
             "binary section (no section id 1 there)", line, s, (long long)off);
    /* a record costs a bit at least: a count the whole file cannot hold lies */
    if ((uint64_t)cnt > (uint64_t)c->loglen * 8 || (uint64_t)cnt > JF_MAX_POINTS)
        FAIL("XML line %zu: data3D[%zu] points: recordCount %lld is more than the file's "
             "%zu bytes can hold", line, s, (long long)cnt, c->loglen);
    si->count = (uint64_t)cnt;
    si->proto = jf__e57_child(x, pts, "prototype");
    if (si->proto < 0)
        FAIL("XML line %zu: data3D[%zu] points: no prototype", line, s);
    size_t nf = 0;
    for (int k = x->node[si->proto].child; k >= 0; k = x->node[k].next)
        nf++;
    jf_e57_field *f = calloc(nf ? nf : 1, sizeof *f);
    if (!f)
        return jf_io_fail(c->err, JF_ERR_NOMEM, c->name, 0, "out of memory");
    *fs = f;
    *nfs = nf;
    int have = 0;
    size_t j = 0;
    for (int k = x->node[si->proto].child; k >= 0; k = x->node[k].next, j++) {
        if (!field_of(c, s, k, &f[j]))
            return JF_ERR_FORMAT;
        for (size_t q = 0; q < j; q++)
            if (!strcmp(f[q].name, f[j].name))
                FAIL("XML line %zu: data3D[%zu] prototype: field %s appears twice",
                     x->node[k].line, s, f[j].name);
        int cc = is_coord(f[j].name);
        if (cc >= 1 && cc <= 6)
            have |= 1 << (cc - 1);
        if (cc)
            continue;
        size_t a = 0;
        while (a < *ncols && strcmp((*cols)[a].name, f[j].name))
            a++;
        if (a == *ncols) {
            acol *q = realloc(*cols, (a + 1) * sizeof *q);
            if (!q)
                return jf_io_fail(c->err, JF_ERR_NOMEM, c->name, 0, "out of memory");
            *cols = q;
            q[a].name = f[j].name;
            q[a].kinds = 0;
            q[a].min = f[j].min;
            q[a].max = f[j].max;
            (*ncols)++;
        }
        acol *ac = &(*cols)[a];
        ac->kinds |= 1 << f[j].kind;
        if (f[j].min < ac->min)
            ac->min = f[j].min;
        if (f[j].max > ac->max)
            ac->max = f[j].max;
    }
    /* the values' bits against the section's bytes, before anything is
     * allocated from the count (the decoder checks each field again) */
    uint64_t bpr = 0, seclen = le64(c->log + si->sec + 8);
    for (size_t q = 0; q < nf; q++)
        bpr += f[q].kind == JF_E57_FLOAT ? 32 : f[q].kind == JF_E57_DOUBLE ? 64 : f[q].bits;
    if (bpr && si->count > (seclen > c->loglen ? c->loglen : seclen) * 8 / bpr)
        FAIL("XML line %zu: data3D[%zu] points: recordCount %llu needs %llu bits a record, "
             "more than its binary section's %llu bytes hold", line, s,
             (unsigned long long)si->count, (unsigned long long)bpr,
             (unsigned long long)seclen);
    if ((have & 7) == 7)
        si->spherical = 0;
    else if ((have & 0x38) == 0x38)
        si->spherical = 1;
    else
        FAIL("XML line %zu: data3D[%zu] prototype: neither cartesianX/Y/Z nor "
             "sphericalRange/Azimuth/Elevation", x->node[si->proto].line, s);
    /* pose [8.4.3]: absent parts are the identity */
    int pose = jf__e57_child(x, vc, "pose");
    int rot = jf__e57_child(x, pose, "rotation"), tr = jf__e57_child(x, pose, "translation");
    double q[4];
    static const char *const qn[4] = {"w", "x", "y", "z"}, *const tn[3] = {"x", "y", "z"};
    for (int k = 0; k < 4; k++)
        if (!leaf_value(x, rot, qn[k], rot < 0 && k == 0 ? 1 : 0, &q[k]))
            FAIL("XML line %zu: data3D[%zu] pose rotation %s: not a finite number",
                 x->node[rot].line, s, qn[k]);
    for (int k = 0; k < 3; k++)
        if (!leaf_value(x, tr, tn[k], 0, &si->t[k]))
            FAIL("XML line %zu: data3D[%zu] pose translation %s: not a finite number",
                 x->node[tr].line, s, tn[k]);
    double nq = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    /* a unit quaternion [8.4.3]; written ones carry rounding: normalised */
    if (!(nq > 0.5 && nq < 2))
        FAIL("XML line %zu: data3D[%zu] pose rotation: not a unit quaternion (norm %g)",
             rot >= 0 ? x->node[rot].line : line, s, nq);
    double w = q[0] / nq, a = q[1] / nq, b = q[2] / nq, d = q[3] / nq;
    double R[3][3] = {{1 - 2 * (b * b + d * d), 2 * (a * b - w * d), 2 * (a * d + w * b)},
                      {2 * (a * b + w * d), 1 - 2 * (a * a + d * d), 2 * (b * d - w * a)},
                      {2 * (a * d - w * b), 2 * (b * d + w * a), 1 - 2 * (a * a + b * b)}};
    memcpy(si->R, R, sizeof R);
    return JF_OK;
#undef FAIL
}

jf_status jf_read_e57(const char *buf, size_t len, const char *name, const jf_read_opts *o,
                      jf_cloud *cl, jf_error *err)
{
    const unsigned char *b = (const unsigned char *)buf;
    if (len >= 8 && len < 48 && !memcmp(b, "ASTM-E57", 8))
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "truncated: %zu bytes, shorter than "
                          "the 48-byte E57 header", len);
    if (len < 48 || memcmp(b, "ASTM-E57", 8))
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "not an E57 file (no ASTM-E57 "
                          "signature in its first 8 bytes)");
    uint32_t major = (uint32_t)le32(b + 8);
    uint64_t plen = le64(b + 16), xoff = le64(b + 24), xlen = le64(b + 32), psz = le64(b + 40);
    if (major != 1)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0, "E57 version %u (this reader "
                          "knows version 1)", (unsigned)major);
    if (psz != JF_E57_PAGE)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "page size %llu (E57 pages are 1024 "
                          "bytes)", (unsigned long long)psz);
    if (plen != len)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "the header says %llu bytes but the "
                          "file has %zu (%s)", (unsigned long long)plen, len,
                          plen > len ? "truncated" : "trailing bytes");
    unsigned char *log = NULL;
    size_t loglen = 0;
    jf_status st = jf__e57_unpage(b, len, name, &log, &loglen, err);
    if (st != JF_OK)
        return st;
    jf_e57_xml x = {0};
    size_t xl;
    ctx c = {log, loglen, name, &x, err};
    scaninfo *si = NULL;
    jf_e57_field **fs = NULL;
    size_t *nfs = NULL, ns = 0, ncols = 0;
    acol *cols = NULL;
    unsigned char *inv = NULL;
#define FAIL(s_, ...)                                                                      \
    do {                                                                                   \
        st = jf_io_fail(err, s_, name, 0, __VA_ARGS__);                                    \
        goto out;                                                                          \
    } while (0)
    if (!jf__e57_logical(xoff, &xl) || xl > loglen || xlen > loglen - xl)
        FAIL(JF_ERR_FORMAT, "the XML section (physical offset %llu, %llu bytes) is not "
             "inside the file", (unsigned long long)xoff, (unsigned long long)xlen);
    if ((st = jf__e57_xml_parse((const char *)log + xl, (size_t)xlen, name, &x, err)) != JF_OK)
        goto out;
    if (strcmp(x.node[0].name, "e57Root"))
        FAIL(JF_ERR_FORMAT, "XML section: the root element is %.40s, not e57Root",
             x.node[0].name);
    int d3 = jf__e57_child(&x, 0, "data3D");
    for (int k = d3 >= 0 ? x.node[d3].child : -1; k >= 0; k = x.node[k].next)
        ns++;
    if (ns == 0)
        FAIL(JF_ERR_FORMAT, "no scan in /data3D");
    if (ns > UINT32_MAX - 1)
        FAIL(JF_ERR_TOO_LARGE, "too many scans");
    si = calloc(ns, sizeof *si);
    fs = calloc(ns, sizeof *fs);
    nfs = calloc(ns, sizeof *nfs);
    if (!si || !fs || !nfs)
        FAIL(JF_ERR_NOMEM, "out of memory for %zu scans", ns);
    uint64_t n = 0;
    size_t s = 0;
    for (int k = x.node[d3].child; k >= 0; k = x.node[k].next, s++) {
        if ((st = scan_header(&c, s, k, &si[s], &fs[s], &nfs[s], &cols, &ncols)) != JF_OK)
            goto out;
        n += si[s].count;
        if (n > JF_MAX_POINTS)
            FAIL(JF_ERR_TOO_LARGE, "more than %zu points", JF_MAX_POINTS);
    }
    if (n == 0)
        FAIL(JF_ERR_FORMAT, "no points: the %zu scan%s in /data3D %s empty", ns,
             ns > 1 ? "s" : "", ns > 1 ? "are all" : "is");
    /* the attribute table: every non-coordinate field, then the scan */
    jf_attrs *at = &cl->attrs;
    int keep = !(o && o->no_attrs);
    size_t stride = 0;
    for (size_t a = 0; keep && a <= ncols; a++) {
        jf_attr_type t = a < ncols ? col_type(&cols[a]) : ns <= 65536 ? JF_ATTR_U16 : JF_ATTR_U32;
        const char *nm = a < ncols ? cols[a].name : "scan";
        if (!jf__attrs_add(at, nm, strlen(nm), t, (uint32_t)stride, 0, 0))
            FAIL(JF_ERR_NOMEM, "out of memory");
        stride += jf_attr_size[t];
    }
    at->stride = stride;
    cl->xyz = malloc((size_t)n * 3 * sizeof(double));
    cl->scan = malloc((size_t)n * sizeof(uint32_t));
    cl->scanner = malloc(ns * 3 * sizeof(double));
    inv = malloc((size_t)n);
    if (keep)
        at->rec = malloc((size_t)n * stride);
    if (!cl->xyz || !cl->scan || !cl->scanner || !inv || (keep && !at->rec))
        FAIL(JF_ERR_NOMEM, "out of memory for %llu points", (unsigned long long)n);
    cl->n = (size_t)n;
    cl->nscans = ns;
    size_t base = 0;
    for (s = 0; s < ns; s++) {
        size_t m = (size_t)si[s].count;
        double *xyz = cl->xyz + 3 * base;
        unsigned char *rec = keep ? at->rec + base * stride : NULL;
        memset(inv + base, 0, m);
        /* fields absent from this scan: NaN or 0 */
        for (size_t a = 0; keep && a < ncols; a++) {
            size_t j = 0;
            while (j < nfs[s] && strcmp(fs[s][j].name, cols[a].name))
                j++;
            if (j < nfs[s])
                continue;
            const jf_attr *ad = &at->attr[a];
            double nan = NAN;
            float nanf = NAN;
            for (size_t i = 0; i < m; i++) {
                unsigned char *d = rec + i * stride + ad->offset;
                if (ad->type == JF_ATTR_F64)
                    memcpy(d, &nan, 8);
                else if (ad->type == JF_ATTR_F32)
                    memcpy(d, &nanf, 4);
                else
                    memset(d, 0, jf_attr_size[ad->type]);
            }
        }
        for (size_t j = 0; j < nfs[s]; j++) {
            jf_e57_field *f = &fs[s][j];
            int cc = is_coord(f->name);
            if (cc >= 1 && cc <= 6) {
                /* x y z, or range azimuth elevation, in the xyz slots */
                if ((cc <= 3) == !si[s].spherical) {
                    f->dst = (unsigned char *)(xyz + (cc - 1) % 3);
                    f->stride = 3 * sizeof(double);
                    f->type = JF_ATTR_F64;
                }
            } else if (cc == 7 + si[s].spherical) {
                f->dst = inv + base;
                f->stride = 1;
                f->type = JF_ATTR_U8;
            } else if (keep && !cc) {
                size_t a = 0;
                while (strcmp(cols[a].name, f->name))
                    a++;
                f->dst = rec + at->attr[a].offset;
                f->stride = stride;
                f->type = at->attr[a].type;
            }
        }
        char what[48];
        snprintf(what, sizeof what, "data3D[%zu] points", s);
        if ((st = jf__e57_cv_read(log, loglen, si[s].sec, fs[s], nfs[s], si[s].count, name,
                                  what, err)) != JF_OK)
            goto out;
        const double (*R)[3] = (const double (*)[3])si[s].R;
        const double *t = si[s].t;
        for (size_t i = 0; i < m; i++) {
            double *p = xyz + 3 * i;
            if (inv[base + i]) {
                p[0] = p[1] = p[2] = NAN; /* no usable point: kept as a row */
            } else {
                double v[3] = {p[0], p[1], p[2]};
                if (si[s].spherical) { /* [8.4.10]: azimuth from x towards y, elevation up */
                    double ce = cos(v[2]);
                    v[0] = p[0] * ce * cos(p[1]);
                    v[1] = p[0] * ce * sin(p[1]);
                    v[2] = p[0] * sin(p[2]);
                }
                for (int r = 0; r < 3; r++)
                    p[r] = R[r][0] * v[0] + R[r][1] * v[1] + R[r][2] * v[2] + t[r];
            }
            cl->scan[base + i] = (uint32_t)s;
        }
        if (keep) {
            const jf_attr *sa = &at->attr[ncols];
            for (size_t i = 0; i < m; i++) {
                unsigned char *d = rec + i * stride + sa->offset;
                d[0] = (unsigned char)s;
                d[1] = (unsigned char)(s >> 8);
                if (sa->type == JF_ATTR_U32) {
                    d[2] = (unsigned char)(s >> 16);
                    d[3] = (unsigned char)(s >> 24);
                }
            }
        }
        memcpy(cl->scanner + 3 * s, t, 3 * sizeof(double));
        base += m;
    }
    if (!keep)
        jf_attrs_free(at);
out:
    for (size_t k = 0; fs && k < ns; k++)
        free(fs[k]);
    free(fs);
    free(nfs);
    free(si);
    free(cols);
    free(inv);
    jf__e57_xml_free(&x);
    free(log);
    return st;
#undef FAIL
}
