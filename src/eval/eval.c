/* eval.c -- error measures against ground truth, and a small named-column
 * table reader for what `jetfit eval` compares: jetfit's outputs (.csv with
 * a header line, .xyz/.txt with a "# name ..." header comment, .ply ascii or
 * binary), generate's truth files, and PCPNet's headerless .xyz / .normals /
 * .curv / .pidx (column names implied by the extension).
 *
 * Measures (PCPNet, Guerrero et al. 2018): unoriented normal angle
 * acos|n . n_true| in degrees; curvature error |k - k_t| / max(|k_t|, 1)
 * beside the plain absolute error. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "jetfit.h"

#define JF_PI 3.14159265358979323846

double jf_normal_angle_deg(const double a[3], const double b[3])
{
    double na = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double nb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    if (!(na > 0.0) || !(nb > 0.0) || !isfinite(na) || !isfinite(nb))
        return NAN;
    double c = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (na * nb);
    if (c > 1.0) c = 1.0; /* rounding: |a.b| may exceed |a||b| by an ulp */
    return acos(c) * (180.0 / JF_PI);
}

double jf_curv_error_rel(double k, double k_true)
{
    double d = fabs(k_true);
    return fabs(k - k_true) / (d > 1.0 ? d : 1.0);
}

void jf_curv_compare(const double n[3], double k1, double k2,
                     const double n_true[3], double k1_true, double k2_true,
                     double err_abs[2], double err_rel[2])
{
    /* Orient the estimate along the truth first: flipping the normal
     * negates the curvatures and swaps them (docs/design.md, CGAL's rule). */
    if (n[0] * n_true[0] + n[1] * n_true[1] + n[2] * n_true[2] < 0.0) {
        double t = k1;
        k1 = -k2;
        k2 = -t;
    }
    if (err_abs) {
        err_abs[0] = fabs(k1 - k1_true);
        err_abs[1] = fabs(k2 - k2_true);
    }
    if (err_rel) {
        err_rel[0] = jf_curv_error_rel(k1, k1_true);
        err_rel[1] = jf_curv_error_rel(k2, k2_true);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Order statistic at fraction q with linear interpolation (numpy's
 * default), on sorted v[0..n-1], n >= 1. */
static double quantile(const double *v, size_t n, double q)
{
    double pos = q * (double)(n - 1);
    size_t i = (size_t)pos;
    if (i + 1 >= n) return v[n - 1];
    return v[i] + (pos - (double)i) * (v[i + 1] - v[i]);
}

jf_status jf_err_stats_compute(double *v, size_t n, jf_err_stats *s)
{
    if (!s || (n && !v)) return JF_ERR_INVALID;
    memset(s, 0, sizeof *s);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) /* finite values to the front */
        if (isfinite(v[i])) {
            double t = v[m];
            v[m++] = v[i];
            v[i] = t;
        }
    s->n = m;
    s->nonfinite = n - m;
    if (m == 0) {
        s->rms = s->mean = s->median = s->p95 = s->max = NAN;
        return JF_OK;
    }
    qsort(v, m, sizeof *v, cmp_double);
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < m; i++) {
        sum += v[i];
        sum2 += v[i] * v[i];
    }
    s->mean = sum / (double)m;
    s->rms = sqrt(sum2 / (double)m);
    s->median = quantile(v, m, 0.5);
    s->p95 = quantile(v, m, 0.95);
    s->max = v[m - 1];
    return JF_OK;
}

/* ------------------------------------------------------------------ */
/* Named-column tables                                                 */
/* ------------------------------------------------------------------ */

void jf_eval_table_free(jf_eval_table *t)
{
    if (!t) return;
    free(t->names);
    free(t->v);
    memset(t, 0, sizeof *t);
}

int jf_eval_table_col(const jf_eval_table *t, const char *name)
{
    for (size_t j = 0; t && j < t->ncols; j++)
        if (!strcmp(t->names[j], name)) return (int)j;
    return -1;
}

typedef struct {
    jf_eval_table *t;
    size_t cap; /* rows allocated */
} builder;

static jf_status push_row(builder *b, const double *row)
{
    jf_eval_table *t = b->t;
    if (t->nrows == b->cap) {
        size_t nc = b->cap ? 2 * b->cap : 1024;
        double *nv = realloc(t->v, nc * t->ncols * sizeof *nv);
        if (!nv) return JF_ERR_NOMEM;
        t->v = nv;
        b->cap = nc;
    }
    memcpy(t->v + t->nrows * t->ncols, row, t->ncols * sizeof *row);
    t->nrows++;
    return JF_OK;
}

static const char *ext_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    const char *sl = strrchr(path, '/');
    return (dot && (!sl || dot > sl)) ? dot + 1 : "";
}

/* Names implied by a headerless file's extension (PCPNet, generate). */
static const char *default_name(const char *ext, size_t j)
{
    static const char *const pts[] = {"x", "y", "z", "nx", "ny", "nz", "k1", "k2"};
    static const char *const nrm[] = {"nx", "ny", "nz"};
    static const char *const crv[] = {"k1", "k2"};
    if (!strcmp(ext, "normals")) return j < 3 ? nrm[j] : "";
    if (!strcmp(ext, "curv")) return j < 2 ? crv[j] : "";
    if (!strcmp(ext, "pidx")) return j < 1 ? "index" : "";
    return j < 8 ? pts[j] : "";
}

static jf_status set_names(jf_eval_table *t, size_t ncols)
{
    t->ncols = ncols;
    t->names = calloc(ncols ? ncols : 1, sizeof *t->names);
    return t->names ? JF_OK : JF_ERR_NOMEM;
}

/* Splits s in place at separators (comma or blank); returns the count. */
static size_t split(char *s, char **tok, size_t max)
{
    size_t n = 0;
    char *p = s;
    while (*p) {
        while (*p == ',' || isspace((unsigned char)*p)) p++;
        if (!*p) break;
        if (n < max) tok[n] = p;
        n++;
        while (*p && *p != ',' && !isspace((unsigned char)*p)) p++;
        if (*p) *p++ = '\0';
    }
    return n;
}

#define MAXCOLS 256

static jf_status read_text(FILE *fp, const char *path, const char *ext,
                           jf_eval_table *t, jf_error *err)
{
    char line[8192];
    char *tok[MAXCOLS];
    double row[MAXCOLS];
    char header[8192] = "";
    builder b = {t, 0};
    size_t lineno = 0;
    int csv = !strcmp(ext, "csv");
    jf_status st = JF_OK;
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        if (!strchr(line, '\n') && !feof(fp)) {
            snprintf(err->msg, sizeof err->msg, "%s:%zu: line too long", path, lineno);
            return JF_ERR_FORMAT;
        }
        char *s = line;
        while (isspace((unsigned char)*s)) s++;
        if (!*s) continue;
        if (*s == '#') { /* the last comment before data names the columns */
            snprintf(header, sizeof header, "%s", s + 1);
            continue;
        }
        if (!t->names && csv && (isalpha((unsigned char)*s) || *s == '_')) {
            snprintf(header, sizeof header, "%s", s);
            continue;
        }
        size_t n = split(s, tok, MAXCOLS);
        if (n > MAXCOLS) {
            snprintf(err->msg, sizeof err->msg, "%s:%zu: more than %d columns", path, lineno, MAXCOLS);
            return JF_ERR_FORMAT;
        }
        if (!t->names) {
            char *htok[MAXCOLS];
            size_t hn = header[0] ? split(header, htok, MAXCOLS) : 0;
            if ((st = set_names(t, n)) != JF_OK) return st;
            for (size_t j = 0; j < n; j++)
                snprintf(t->names[j], sizeof t->names[j], "%s",
                         hn == n ? htok[j] : default_name(ext, j));
        }
        if (n != t->ncols) {
            snprintf(err->msg, sizeof err->msg, "%s:%zu: %zu columns, expected %zu",
                     path, lineno, n, t->ncols);
            return JF_ERR_FORMAT;
        }
        for (size_t j = 0; j < n; j++) {
            char *end;
            errno = 0;
            row[j] = strtod(tok[j], &end);
            if (end == tok[j] || *end) {
                snprintf(err->msg, sizeof err->msg, "%s:%zu: column %zu: not a number '%.40s'",
                         path, lineno, j + 1, tok[j]);
                return JF_ERR_FORMAT;
            }
        }
        if ((st = push_row(&b, row)) != JF_OK) {
            snprintf(err->msg, sizeof err->msg, "%s:%zu: out of memory", path, lineno);
            return st;
        }
    }
    if (ferror(fp)) {
        snprintf(err->msg, sizeof err->msg, "%s: read error", path);
        return JF_ERR_IO;
    }
    if (!t->names && (st = set_names(t, 0)) != JF_OK) return st;
    return JF_OK;
}

/* ---- PLY: the vertex element, ascii or binary little-endian ---- */

typedef enum { P_I8, P_U8, P_I16, P_U16, P_I32, P_U32, P_F32, P_F64, P_BAD } ptype;

static ptype ply_type(const char *s)
{
    static const struct { const char *n; ptype t; } m[] = {
        {"char", P_I8}, {"int8", P_I8}, {"uchar", P_U8}, {"uint8", P_U8},
        {"short", P_I16}, {"int16", P_I16}, {"ushort", P_U16}, {"uint16", P_U16},
        {"int", P_I32}, {"int32", P_I32}, {"uint", P_U32}, {"uint32", P_U32},
        {"float", P_F32}, {"float32", P_F32}, {"double", P_F64}, {"float64", P_F64}};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++)
        if (!strcmp(s, m[i].n)) return m[i].t;
    return P_BAD;
}

static const size_t ptype_size[] = {1, 1, 2, 2, 4, 4, 4, 8};

static double ply_decode(const unsigned char *p, ptype t)
{
    /* little-endian host assumed for binary_little_endian (x86/arm) */
    switch (t) {
    case P_I8: { int8_t v; memcpy(&v, p, 1); return v; }
    case P_U8: return p[0];
    case P_I16: { int16_t v; memcpy(&v, p, 2); return v; }
    case P_U16: { uint16_t v; memcpy(&v, p, 2); return v; }
    case P_I32: { int32_t v; memcpy(&v, p, 4); return v; }
    case P_U32: { uint32_t v; memcpy(&v, p, 4); return v; }
    case P_F32: { float v; memcpy(&v, p, 4); return v; }
    case P_F64: { double v; memcpy(&v, p, 8); return v; }
    default: return NAN;
    }
}

static jf_status read_ply(FILE *fp, const char *path, jf_eval_table *t, jf_error *err)
{
    char line[1024];
    char *tok[8];
    ptype types[MAXCOLS];
    char names[MAXCOLS][32];
    size_t np = 0, nvert = 0, lineno = 0;
    int binary = -1, in_vertex = 0, seen_vertex = 0;
    jf_status st;
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        size_t n = split(line, tok, 8);
        if (n == 0) continue;
        if (lineno == 1 && strcmp(tok[0], "ply")) break;
        if (!strcmp(tok[0], "format") && n >= 2) {
            binary = !strcmp(tok[1], "ascii") ? 0
                   : !strcmp(tok[1], "binary_little_endian") ? 1 : -2;
        } else if (!strcmp(tok[0], "element") && n >= 3) {
            in_vertex = !strcmp(tok[1], "vertex");
            if (in_vertex) {
                if (seen_vertex) {
                    snprintf(err->msg, sizeof err->msg, "%s:%zu: second vertex element", path, lineno);
                    return JF_ERR_FORMAT;
                }
                nvert = strtoul(tok[2], NULL, 10);
                seen_vertex = 1;
            } else if (!seen_vertex) {
                snprintf(err->msg, sizeof err->msg,
                         "%s:%zu: element '%s' before vertex: unsupported", path, lineno, tok[1]);
                return JF_ERR_UNSUPPORTED;
            }
        } else if (!strcmp(tok[0], "property") && in_vertex) {
            if (n < 3 || !strcmp(tok[1], "list") || ply_type(tok[1]) == P_BAD || np == MAXCOLS) {
                snprintf(err->msg, sizeof err->msg, "%s:%zu: unsupported vertex property", path, lineno);
                return JF_ERR_FORMAT;
            }
            types[np] = ply_type(tok[1]);
            snprintf(names[np], sizeof names[np], "%s", tok[2]);
            np++;
        } else if (!strcmp(tok[0], "end_header")) {
            goto body;
        }
    }
    snprintf(err->msg, sizeof err->msg, "%s:%zu: not a PLY header (no end_header)", path, lineno);
    return JF_ERR_FORMAT;
body:
    if (binary < 0 || !seen_vertex || np == 0) {
        snprintf(err->msg, sizeof err->msg, "%s: %s", path,
                 binary < 0 ? "unsupported PLY format (ascii or binary_little_endian)"
                            : "no vertex element with properties");
        return JF_ERR_FORMAT;
    }
    if ((st = set_names(t, np)) != JF_OK) return st;
    for (size_t j = 0; j < np; j++) memcpy(t->names[j], names[j], 32);
    t->v = malloc((nvert ? nvert : 1) * np * sizeof *t->v);
    if (!t->v) {
        snprintf(err->msg, sizeof err->msg, "%s: out of memory for %zu vertices", path, nvert);
        return JF_ERR_NOMEM;
    }
    for (size_t i = 0; i < nvert; i++) {
        double *row = t->v + i * np;
        for (size_t j = 0; j < np; j++) {
            if (binary) {
                unsigned char buf[8];
                if (fread(buf, ptype_size[types[j]], 1, fp) != 1) goto truncated;
                row[j] = ply_decode(buf, types[j]);
            } else if (fscanf(fp, "%lf", &row[j]) != 1) {
                goto truncated;
            }
        }
        t->nrows++;
    }
    return JF_OK;
truncated:
    snprintf(err->msg, sizeof err->msg, "%s: element vertex %zu: truncated or malformed", path, t->nrows);
    return JF_ERR_FORMAT;
}

/* ---- LAS: x y z and every dimension and Extra Byte (jetfit's columns
 * among them), through the library's reader ---- */

static jf_status read_las(const char *path, jf_eval_table *t, jf_error *err)
{
    jf_cloud c;
    jf_status st = jf_cloud_read(path, NULL, &c, err);
    if (st != JF_OK) return st;
    size_t nc = 3 + c.attrs.nattrs;
    if ((st = set_names(t, nc)) != JF_OK || !(t->v = malloc(c.n * nc * sizeof *t->v))) {
        jf_cloud_free(&c);
        snprintf(err->msg, sizeof err->msg, "%s: out of memory for %zu points", path, c.n);
        return JF_ERR_NOMEM;
    }
    for (size_t j = 0; j < 3; j++) snprintf(t->names[j], sizeof t->names[j], "%c", "xyz"[j]);
    for (size_t j = 0; j < c.attrs.nattrs; j++)
        snprintf(t->names[3 + j], sizeof t->names[j], "%.31s", c.attrs.attr[j].name);
    for (size_t i = 0; i < c.n; i++) {
        double *row = t->v + i * nc;
        memcpy(row, c.xyz + 3 * i, 3 * sizeof *row);
        for (size_t j = 0; j < c.attrs.nattrs; j++) row[3 + j] = jf_attr_get(&c.attrs, j, i);
    }
    t->nrows = c.n;
    jf_cloud_free(&c);
    return JF_OK;
}

jf_status jf_eval_table_read(const char *path, jf_eval_table *t, jf_error *err)
{
    jf_error dummy;
    if (!err) err = &dummy;
    err->msg[0] = '\0';
    if (!t || !path) return JF_ERR_INVALID;
    memset(t, 0, sizeof *t);
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        snprintf(err->msg, sizeof err->msg, "%s: %s", path, strerror(errno));
        return JF_ERR_IO;
    }
    const char *ext = ext_of(path);
    if (!strcasecmp(ext, "las")) {
        fclose(fp);
        jf_status st = read_las(path, t, err);
        if (st != JF_OK) jf_eval_table_free(t);
        return st;
    }
    /* a UTF-8 byte order mark (a text editor's) is not the first name */
    unsigned char bom[3];
    if (fread(bom, 1, 3, fp) != 3 || memcmp(bom, "\xEF\xBB\xBF", 3)) rewind(fp);
    jf_status st = !strcmp(ext, "ply") ? read_ply(fp, path, t, err)
                                       : read_text(fp, path, ext, t, err);
    fclose(fp);
    if (st != JF_OK) jf_eval_table_free(t);
    return st;
}
