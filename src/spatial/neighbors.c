/* neighbors.c -- neighbourhood specs (--neighbors) and their queries.
 *
 * Grammar (no spaces):  knn:K | radius:R | knn:K,radius:R | radius:R,knn:K
 *                     | rings | rings:N | natural | natural:N
 * K, N: positive decimal integers; R: a positive finite number.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "index_internal.h"
#include "jetfit.h"

/* Parses a positive decimal integer ending at `end` (or at ','/'\0'). */
static int parse_count(const char *s, const char **rest, size_t *out)
{
    size_t v = 0;
    const char *p = s;
    if (*p < '0' || *p > '9') return 0;
    for (; *p >= '0' && *p <= '9'; p++) {
        size_t dgt = (size_t)(*p - '0');
        if (v > (SIZE_MAX - dgt) / 10) return 0;
        v = v * 10 + dgt;
    }
    if (v == 0) return 0;
    *rest = p;
    *out = v;
    return 1;
}

static int parse_radius(const char *s, const char **rest, double *out)
{
    /* strtod accepts leading spaces, "inf", "nan", hex: reject what is not
     * a plain decimal number */
    if (!((*s >= '0' && *s <= '9') || *s == '.')) return 0;
    char *end;
    errno = 0;
    double r = strtod(s, &end);
    if (end == s || errno == ERANGE || !isfinite(r) || !(r > 0)) return 0;
    for (const char *c = s; c < end; c++) /* no hex floats */
        if (!strchr("0123456789.eE+-", *c)) return 0;
    *rest = end;
    *out = r;
    return 1;
}

static int has_prefix(const char *s, const char *pre)
{
    return strncmp(s, pre, strlen(pre)) == 0;
}

jf_status jf_nb_parse(const char *text, jf_nb_spec *spec, const char **why)
{
    const char *dummy;
    if (!why) why = &dummy;
    *why = NULL;
    if (!text || !spec) {
        *why = "no neighbourhood given";
        return JF_ERR_INVALID;
    }
    jf_nb_spec s = {JF_NB_KNN, 0, 0.0, 0};
    const char *p = text;
    if (strcmp(p, "auto") == 0) {
        s.kind = JF_NB_AUTO;
        *spec = s;
        return JF_OK;
    }
    if (strcmp(p, "rings") == 0 || strcmp(p, "natural") == 0) {
        s.kind = p[0] == 'r' ? JF_NB_RINGS : JF_NB_NATURAL;
        *spec = s;
        return JF_OK;
    }
    if (has_prefix(p, "rings:") || has_prefix(p, "natural:")) {
        s.kind = p[0] == 'r' ? JF_NB_RINGS : JF_NB_NATURAL;
        p = strchr(p, ':') + 1;
        if (!parse_count(p, &p, &s.n) || *p) {
            *why = "N must be a positive integer (rings:N, natural:N)";
            return JF_ERR_INVALID;
        }
        *spec = s;
        return JF_OK;
    }
    int have_k = 0, have_r = 0;
    for (;;) {
        if (has_prefix(p, "knn:")) {
            if (have_k) {
                *why = "knn given twice";
                return JF_ERR_INVALID;
            }
            if (!parse_count(p + 4, &p, &s.k)) {
                *why = "K must be a positive integer (knn:K)";
                return JF_ERR_INVALID;
            }
            have_k = 1;
        } else if (has_prefix(p, "radius:")) {
            if (have_r) {
                *why = "radius given twice";
                return JF_ERR_INVALID;
            }
            if (!parse_radius(p + 7, &p, &s.r)) {
                *why = "R must be a positive finite number (radius:R)";
                return JF_ERR_INVALID;
            }
            have_r = 1;
        } else {
            *why = "expected knn:K, radius:R, knn:K,radius:R, rings[:N], "
                   "natural[:N] or auto";
            return JF_ERR_INVALID;
        }
        if (*p == '\0') break;
        if (*p != ',' || p[1] == '\0') {
            *why = "unexpected text after the value";
            return JF_ERR_INVALID;
        }
        p++;
    }
    s.kind = have_k && have_r ? JF_NB_KNN_RADIUS
                              : (have_k ? JF_NB_KNN : JF_NB_RADIUS);
    *spec = s;
    return JF_OK;
}

char *jf_nb_format(const jf_nb_spec *s, char *buf, size_t len)
{
    if (!buf || !len) return buf;
    if (!s) {
        buf[0] = '\0';
        return buf;
    }
    switch (s->kind) {
    case JF_NB_KNN: snprintf(buf, len, "knn:%zu", s->k); break;
    case JF_NB_RADIUS: snprintf(buf, len, "radius:%.17g", s->r); break;
    case JF_NB_KNN_RADIUS:
        snprintf(buf, len, "knn:%zu,radius:%.17g", s->k, s->r);
        break;
    case JF_NB_RINGS:
    case JF_NB_NATURAL: {
        const char *name = s->kind == JF_NB_RINGS ? "rings" : "natural";
        if (s->n) snprintf(buf, len, "%s:%zu", name, s->n);
        else snprintf(buf, len, "%s", name);
        break;
    }
    case JF_NB_AUTO: snprintf(buf, len, "auto"); break;
    default: snprintf(buf, len, "?"); break;
    }
    return buf;
}

jf_status jf__nb_query_xyz(const jf_index *ix, const jf_nb_spec *s, size_t min_count,
                           const double q[3], uint32_t *idx, double *d2, double *xyz,
                           size_t cap, size_t *found)
{
    if (found) *found = 0;
    if (!ix || !s || !q || !found || (cap && !idx)) return JF_ERR_INVALID;
    switch (s->kind) {
    case JF_NB_KNN:
        if (!s->k) return JF_ERR_INVALID;
        return jf__index_query(ix, q, s->k < cap ? s->k : cap, INFINITY, idx, d2, xyz, found);
    case JF_NB_AUTO:
        return jf__index_query(ix, q, JF_NB_AUTO_KMAX < cap ? JF_NB_AUTO_KMAX : cap, INFINITY, idx,
                               d2, xyz, found);
    case JF_NB_RADIUS:
        if (!(s->r >= 0) || !isfinite(s->r)) return JF_ERR_INVALID;
        return jf__index_query(ix, q, cap, s->r * s->r, idx, d2, xyz, found);
    case JF_NB_KNN_RADIUS: {
        if (!s->k || !(s->r >= 0) || !isfinite(s->r)) return JF_ERR_INVALID;
        size_t want = s->k < cap ? s->k : cap;
        /* K bounds the result even in the fallback */
        size_t floor = min_count < want ? min_count : want;
        jf_status st = jf__index_query(ix, q, want, s->r * s->r, idx, d2, xyz, found);
        if (st != JF_OK || *found >= floor) return st;
        return jf__index_query(ix, q, floor, INFINITY, idx, d2, xyz, found);
    }
    default:
        return JF_ERR_INVALID; /* rings: jf_nb_query_mesh; natural: bridge */
    }
}

jf_status jf_nb_query(const jf_index *ix, const jf_nb_spec *s,
                      size_t min_count, const double q[3], uint32_t *idx,
                      double *d2, size_t cap, size_t *found)
{
    return jf__nb_query_xyz(ix, s, min_count, q, idx, d2, NULL, cap, found);
}

jf_status jf_nb_query_mesh(const jf_mesh *m, const double *xyz,
                           const jf_nb_spec *s, size_t min_count,
                           jf_fit_mode fit, uint32_t v, uint32_t *idx,
                           size_t cap, size_t *found)
{
    if (found) *found = 0;
    if (!s || s->kind != JF_NB_RINGS) return JF_ERR_INVALID;
    if (s->n) return jf_mesh_rings(m, xyz, v, s->n, idx, cap, found);
    if (fit == JF_FIT_INTERP)
        return jf_mesh_rings(m, xyz, v, min_count, idx, cap, found);
    return jf_mesh_rings_full(m, xyz, v, 2 * min_count, idx, cap, found);
}
