/*
 * io_off.c -- OFF mesh reader (also COFF, NOFF, STOFF and their mixes).
 *
 * design: a header keyword ([ST][C][N]OFF; "OFF" may be missing), then
 * "nv nf [ne]" (possibly on the keyword's line), then one vertex per line
 * (x y z, then nx ny nz for NOFF; colours and texture coordinates after
 * are ignored), then one face per line ("k i1 .. ik", colour ignored).
 * '#' starts a comment.  Counts are checked against the bytes left before
 * anything is allocated; every index is checked against nv.
 */
#include "io_internal.h"

#include <stdlib.h>
#include <string.h>

/* Next non-blank line with its comment removed. */
static int data_line(jf_text *t, const char **ls, const char **le)
{
    while (jf_text_line(t, ls, le)) {
        const char *h = memchr(*ls, '#', (size_t)(*le - *ls));
        if (h)
            *le = h;
        const char *p = *ls, *ts, *te;
        if (jf_next_token(&p, *le, 0, &ts, &te))
            return 1;
    }
    return 0;
}

/* Parses the header keyword; -1 not a keyword, 0 unsupported, else 1
 * (*normals set for NOFF). */
static int keyword(const char *s, const char *e, int *normals)
{
    if (e - s >= 6 && !memcmp(e - 6, "BINARY", 6))
        return 0;
    if (e - s < 3 || memcmp(e - 3, "OFF", 3))
        return -1;
    const char *p = s;
    if (e - p >= 5 && !memcmp(p, "ST", 2))
        p += 2;
    if (p < e - 3 && *p == 'C')
        p++;
    if (p < e - 3 && *p == 'N') {
        *normals = 1;
        p++;
    }
    if (p < e - 3 && *p == 'C') /* "NCOFF" */
        p++;
    if (p < e - 3 && (*p == '4' || *p == 'n'))
        return 0; /* 4D or n-dimensional */
    return p == e - 3 ? 1 : -1;
}

jf_status jf_read_off(const char *buf, size_t len, const char *name,
                      jf_cloud *c, jf_error *err)
{
    /* a UTF-8 byte order mark is not part of the header keyword */
    size_t bom = len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3) ? 3 : 0;
    jf_text t = {buf + bom, buf + len, 0, 0};
    const char *ls, *le, *p, *ts = buf, *te = buf;
    int normals = 0;
    if (!data_line(&t, &ls, &le))
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no OFF header");
    p = ls;
    jf_next_token(&p, le, 0, &ts, &te);
    int kw = keyword(ts, te, &normals);
    const char *bs, *be, *bp = p;
    if (kw > 0 && jf_next_token(&bp, le, 0, &bs, &be) && be - bs == 6 && !memcmp(bs, "BINARY", 6))
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, t.line,
                          "binary OFF is not supported (convert it to ascii OFF or to PLY)");
    if (kw == 0)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, t.line,
                          "unsupported OFF variant '%.*s' (4D, nD and "
                          "binary OFF are not read)",
                          (int)(te - ts > 40 ? 40 : te - ts), ts);
    if (kw < 0)
        p = ls; /* no keyword: the counts come first */
    /* the counts: on the keyword's line or the next data line */
    uint64_t cnt[3] = {0, 0, 0};
    int nc = 0;
    if (!jf_next_token(&p, le, 0, &ts, &te)) {
        if (!data_line(&t, &ls, &le))
            return jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                              "file ends before the vertex and face counts");
        p = ls;
    } else {
        p = ts;
    }
    size_t cline = t.line;
    while (nc < 3 && jf_next_token(&p, le, 0, &ts, &te)) {
        if (!jf_parse_size(ts, te, UINT64_MAX, &cnt[nc]))
            return jf_io_fail(err, JF_ERR_FORMAT, name, cline,
                              "%s '%.*s'",
                              kw < 0 && nc == 0 ? "not an OFF file: no OFF "
                                                  "keyword and no counts at"
                                                : "bad count",
                              (int)(te - ts > 40 ? 40 : te - ts), ts);
        nc++;
    }
    if (nc < 2)
        return jf_io_fail(err, JF_ERR_FORMAT, name, cline,
                          "expected the counts \"nv nf [ne]\"");
    /* room before allocating: any line takes >= 2 bytes (a short line
     * then gets its own message below) */
    size_t left = (size_t)(t.end - t.p) + 1;
    if (cnt[0] > left / 2 || cnt[1] > left / 2 ||
        cnt[0] * 2 + cnt[1] * 2 > left)
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, cline,
                          "%llu vertices and %llu faces cannot fit in the "
                          "%zu bytes left in the file",
                          (unsigned long long)cnt[0],
                          (unsigned long long)cnt[1], left);
    if (cnt[0] > JF_MAX_POINTS)
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, cline,
                          "too many vertices");
    size_t nv = (size_t)cnt[0], nf = (size_t)cnt[1];
    c->xyz = malloc((nv ? nv : 1) * 3 * sizeof(double));
    c->nrm = normals ? malloc((nv ? nv : 1) * 3 * sizeof(double)) : NULL;
    c->face_off = nf ? malloc((nf + 1) * sizeof(size_t)) : NULL;
    if (!c->xyz || (normals && !c->nrm) || (nf && !c->face_off))
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    c->n = nv;
    int need = normals ? 6 : 3;
    for (size_t i = 0; i < nv; i++) {
        if (!data_line(&t, &ls, &le))
            return jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                              "vertex %zu: file ends (header says %zu "
                              "vertices)", i, nv);
        p = ls;
        double v[6];
        int k = 0;
        for (; k < need && jf_next_token(&p, le, 0, &ts, &te); k++)
            if (!jf_parse_double(ts, te, &v[k]))
                return jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                                  "vertex %zu: '%.*s' is not a number", i,
                                  (int)(te - ts > 40 ? 40 : te - ts), ts);
        if (k < need)
            return jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                              "vertex %zu: expected %d numbers, found %d", i,
                              need, k);
        memcpy(c->xyz + 3 * i, v, 3 * sizeof(double));
        if (normals)
            memcpy(c->nrm + 3 * i, v + 3, 3 * sizeof(double));
    }
    jf_uvec fi = {0};
    jf_status st = JF_OK;
    for (size_t f = 0; f < nf && st == JF_OK; f++) {
        uint64_t k;
        if (!data_line(&t, &ls, &le)) {
            st = jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                            "face %zu: file ends (header says %zu faces)", f,
                            nf);
            break;
        }
        p = ls;
        jf_next_token(&p, le, 0, &ts, &te);
        if (!jf_parse_size(ts, te, UINT32_MAX, &k) || k < 3) {
            st = jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                            "face %zu: bad vertex count '%.*s' (a face needs "
                            "3 or more)", f,
                            (int)(te - ts > 40 ? 40 : te - ts), ts);
            break;
        }
        if (k > (uint64_t)(le - p) || !jf_uvec_reserve(&fi, fi.n + k)) {
            st = jf_io_fail(err, k > (uint64_t)(le - p) ? JF_ERR_FORMAT
                                                        : JF_ERR_NOMEM,
                            name, t.line, "face %zu: expected %llu indices",
                            f, (unsigned long long)k);
            break;
        }
        c->face_off[f] = fi.n;
        for (uint64_t j = 0; j < k; j++) {
            uint64_t ix;
            if (!jf_next_token(&p, le, 0, &ts, &te)) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                                "face %zu: expected %llu indices, found %llu",
                                f, (unsigned long long)k,
                                (unsigned long long)j);
                break;
            }
            if (!jf_parse_size(ts, te, UINT64_MAX, &ix) || ix >= nv) {
                st = jf_io_fail(err, JF_ERR_FORMAT, name, t.line,
                                "face %zu: vertex index '%.*s' out of range "
                                "(%zu vertices)", f,
                                (int)(te - ts > 40 ? 40 : te - ts), ts, nv);
                break;
            }
            fi.v[fi.n++] = (uint32_t)ix;
        }
    }
    c->face_idx = fi.v;
    if (st != JF_OK)
        return st;
    c->nfaces = nf;
    if (nf)
        c->face_off[nf] = fi.n;
    return JF_OK;
}
