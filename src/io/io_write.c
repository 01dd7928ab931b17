/*
 * io_write.c -- the table writer (jf_writer_*) and jf_cloud_write.
 *
 * design: output goes through a jf_wfile (io_wfile.c: a temporary file
 * beside the final one, renamed onto it only on success), so a reader
 * never sees a partial file under the final name.  Doubles are written
 * exactly as "%.17g" would write them (jf_fmt_g17, io_fmt.c).
 */
#define _POSIX_C_SOURCE 200809L
#include "io_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <omp.h>

/* ---- the table writer ------------------------------------------------- */

enum { FMT_PLY, FMT_CSV, FMT_XYZ, FMT_LAS };

struct jf_writer {
    jf_wfile f;
    int fmt, ascii;
    size_t ncols, nrows, rows;
    jf_col_type *types;
    char **names;
    int header_done;
    size_t nfaces;
    int face_count4;                 /* a face over 255 vertices: uint counts */
    const size_t *foff;
    const uint32_t *fidx;
    int las_framed;                  /* LAS: jf_writer_las_frame called  */
    jf_las_out las;                  /* LAS: what the output holds       */
    int is_laz;                      /* LAS compressed: .laz             */
    jf_lazw *laz;                    /* its chunk writer (io_laz_write.c) */
    const jf_attrs *attrs;           /* carried attributes, or NULL      */
    char (*anames)[64];              /* their output names               */
    size_t row_max;                  /* bytes a formatted row may take   */
    /* positioned rows (jf_writer_begin_put / _put) */
    int put;                         /* begun, not yet drained           */
    int put_threads;                 /* for the drain's formatting       */
    jf_spool *spool;                 /* io_spool.c                       */
    char *warn;                      /* jf_writer_warnings' text         */
    jf_phase_fn prog;                /* jf_writer_progress, or NULL      */
    void *prog_user;
};

/* The attribute columns go after column 2 (x y z). */
#define ATTRS_AFTER 2

static int host_little(void)
{
    const uint16_t one = 1;
    return *(const unsigned char *)&one == 1;
}

static int32_t to_i32(double v)
{
    if (!(v >= -2147483648.0 && v <= 2147483647.0))
        return INT32_MIN;
    int32_t t = (int32_t)v; /* the usual integer value: no lround call */
    return (double)t == v ? t : (int32_t)lround(v);
}

static jf_status write_header(jf_writer *w)
{
    jf_wfile *f = &w->f;
    static const char *const ply_t[] = {"double", "float", "int", "float"};
    char line[128];
    w->header_done = 1;
    if (w->fmt == FMT_LAS) {
        /* a placeholder of the header's size: the real one, with the
         * count and bounds, is written over it at commit */
        if (!w->las_framed && !(w->attrs && w->attrs->las_head && w->attrs->rec))
            return jf_wf_fail(f, JF_ERR_INVALID, "LAS output needs the cloud's frame "
                                                 "(jf_writer_las_frame) before the rows");
        size_t n = jf__las_prefix_size(&w->las);
        if (w->is_laz) {
            char why[160];
            w->laz = jf__lazw_open(jf__las_out_format(&w->las),
                                   (unsigned)jf__las_record_size(&w->las), n, why, sizeof why);
            if (!w->laz)
                return jf_wf_fail(f, JF_ERR_UNSUPPORTED, "%s", why);
            n += jf__lazw_extra(w->laz);
        }
        while (n && f->st == JF_OK) {
            size_t k = n < 4096 ? n : 4096;
            char *o = jf_wf_room(f, k);
            if (!o)
                break;
            memset(o, 0, k);
            f->len += k;
            n -= k;
        }
        return f->st;
    }
    if (w->fmt == FMT_PLY) {
        snprintf(line, sizeof line, "ply\nformat %s 1.0\n",
                 w->ascii ? "ascii" : "binary_little_endian");
        jf_wf_puts(f, line);
        jf_wf_puts(f, "comment written by jetfit " JF_VERSION_STRING "\n");
        snprintf(line, sizeof line, "element vertex %zu\n", w->nrows);
        jf_wf_puts(f, line);
        for (size_t j = 0; j < w->ncols; j++) {
            jf_wf_puts(f, "property ");
            jf_wf_puts(f, ply_t[w->types[j]]);
            jf_wf_puts(f, " ");
            jf_wf_puts(f, w->names[j]);
            jf_wf_puts(f, "\n");
            for (size_t k = 0; j == ATTRS_AFTER && w->attrs && k < w->attrs->nattrs; k++) {
                jf_wf_puts(f, "property ");
                jf_wf_puts(f, jf__attr_ply_type(&w->attrs->attr[k]));
                jf_wf_puts(f, " ");
                jf_wf_puts(f, w->anames[k]);
                jf_wf_puts(f, "\n");
            }
        }
        if (w->foff) {
            snprintf(line, sizeof line, "element face %zu\n", w->nfaces);
            jf_wf_puts(f, line);
            /* uchar counts, as every PLY mesh tool writes them; a polygon
             * over 255 vertices needs uint counts (PLY allows any integer
             * type for a list count) */
            jf_wf_puts(f, w->face_count4 ? "property list uint int vertex_indices\n"
                                         : "property list uchar int vertex_indices\n");
        }
        return jf_wf_puts(f, "end_header\n");
    }
    jf_wf_puts(f, w->fmt == FMT_CSV ? "" : "# ");
    for (size_t j = 0; j < w->ncols; j++) {
        if (j)
            jf_wf_puts(f, w->fmt == FMT_CSV ? "," : " ");
        jf_wf_puts(f, w->names[j]);
        for (size_t k = 0; j == ATTRS_AFTER && w->attrs && k < w->attrs->nattrs; k++) {
            jf_wf_puts(f, w->fmt == FMT_CSV ? "," : " ");
            jf_wf_puts(f, w->anames[k]);
        }
    }
    return jf_wf_puts(f, "\n");
}

jf_status jf_writer_open(const char *path, const jf_column *cols,
                         size_t ncols, size_t nrows, int ascii,
                         jf_writer **out, jf_error *err)
{
    if (out)
        *out = NULL;
    if (err)
        err->msg[0] = '\0';
    const char *nm = path ? path : "(null)";
    if (!path || !cols || !out || ncols == 0 || ncols > 4096)
        return jf_io_fail(err, JF_ERR_INVALID, nm, 0,
                          "invalid writer arguments");
    jf_format fmt = jf_format_from_path(path);
    size_t pl = strlen(path);
    int laz = pl >= 4 && (!strcmp(path + pl - 4, ".laz") || !strcmp(path + pl - 4, ".LAZ"));
    if (fmt != JF_FMT_PLY && fmt != JF_FMT_CSV && fmt != JF_FMT_XYZ && fmt != JF_FMT_LAS)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, nm, 0,
                          "cannot write a table in this format (use .ply, "
                          ".csv, .xyz, .txt, .las or .laz)");
    if (fmt == JF_FMT_LAS &&
        (ncols < 3 || strcmp(cols[0].name, "x") || strcmp(cols[1].name, "y") ||
         strcmp(cols[2].name, "z") || ncols - 3 > 65535 / 192))
        return jf_io_fail(err, JF_ERR_INVALID, nm, 0,
                          "LAS output needs x y z as the first columns (and at most 341 more)");
    for (size_t j = 0; j < ncols; j++) {
        const char *c = cols[j].name;
        int bad = !c || !*c || (unsigned)cols[j].type > JF_COL_F32_Q16;
        for (; c && *c && !bad; c++)
            bad = (unsigned char)*c <= ' ' || *c == ',' || *c == '#';
        if (bad)
            return jf_io_fail(err, JF_ERR_INVALID, nm, 0,
                              "column %zu: bad name or type", j);
    }
    jf_writer *w = calloc(1, sizeof *w);
    if (!w)
        return jf_io_fail(err, JF_ERR_NOMEM, nm, 0, "out of memory");
    w->fmt = fmt == JF_FMT_PLY ? FMT_PLY : fmt == JF_FMT_CSV ? FMT_CSV
                                         : fmt == JF_FMT_LAS ? FMT_LAS : FMT_XYZ;
    w->ascii = ascii != 0;
    w->is_laz = laz;
    w->ncols = ncols;
    w->nrows = nrows;
    w->types = malloc(ncols * sizeof *w->types);
    w->names = calloc(ncols, sizeof *w->names);
    w->row_max = ncols * 32 + 2;
    jf_status st = JF_OK;
    /* a row takes at most 32 bytes per value */
    if (jf_wf_open(&w->f, path, ncols * 32 + 64) != JF_OK)
        st = w->f.st != JF_OK ? w->f.st : JF_ERR_NOMEM;
    for (size_t j = 0; st == JF_OK && j < ncols; j++) {
        if (!w->types || !w->names || !(w->names[j] = strdup(cols[j].name)))
            st = jf_wf_fail(&w->f, JF_ERR_NOMEM, "out of memory");
        else
            w->types[j] = cols[j].type;
    }
    w->las.names = w->names;
    w->las.types = w->types;
    w->las.ncols = ncols;
    w->las.nrows = nrows;
    if (st == JF_OK && w->fmt == FMT_LAS && jf__las_names(&w->las, path) != 0)
        st = jf_wf_fail(&w->f, JF_ERR_NOMEM, "out of memory");
    if (st != JF_OK) {
        if (err) {
            *err = w->f.err;
            if (!err->msg[0])
                jf_io_fail(err, st, nm, 0, "out of memory");
        }
        jf_writer_abort(w);
        return st;
    }
    *out = w;
    return JF_OK;
}

jf_status jf_writer_las_frame(jf_writer *w, const double *xyz, size_t n)
{
    return jf_writer_las_frame_given(w, xyz, n, NULL, NULL);
}

jf_status jf_writer_las_frame_given(jf_writer *w, const double *xyz, size_t n,
                                    const double scale[3], const double offset[3])
{
    if (!w || w->header_done || (n && !xyz))
        return JF_ERR_INVALID;
    if (w->fmt != FMT_LAS)
        return JF_OK;
    for (int a = 0; a < 3; a++)
        if ((scale && !(scale[a] > 0 && isfinite(scale[a]))) || (offset && !isfinite(offset[a])))
            return jf_wf_fail(&w->f, JF_ERR_INVALID, "LAS scale %c: must be positive and "
                              "finite, offsets finite", "xyz"[a]);
    char why[400];
    jf_status st = jf__las_frame(&w->las, w->f.final ? w->f.final : "(output)", xyz, n, scale,
                                 offset, why, sizeof why);
    if (st != JF_OK)
        return jf_wf_fail(&w->f, st, "%s", why);
    w->las_framed = 1;
    return JF_OK;
}

const char *jf_writer_warnings(jf_writer *w)
{
    if (!w) return "";
    const char *a = w->las.warn_names ? w->las.warn_names : "";
    const char *b = w->las.warn_frame ? w->las.warn_frame : "";
    size_t n = strlen(a) + strlen(b) + 1;
    char *t = realloc(w->warn, n);
    if (!t) return a;
    snprintf(t, n, "%s%s", a, b);
    w->warn = t;
    return t;
}

jf_status jf_writer_attrs(jf_writer *w, const jf_attrs *a)
{
    if (!w || w->header_done || w->attrs || w->f.st != JF_OK)
        return JF_ERR_INVALID;
    if (!a || (!a->nattrs && !(a->las_head && w->fmt == FMT_LAS)))
        return JF_OK; /* nothing to carry */
    if (w->ncols < 3 || (a->nattrs && !a->rec))
        return JF_ERR_INVALID;
    char (*nm)[64] = calloc(a->nattrs ? a->nattrs : 1, sizeof *nm);
    if (!nm)
        return JF_ERR_NOMEM;
    /* a format 0 LAS output also has its own dimensions: an Extra Byte
     * named as one (intensity, classification, ...) would be a second
     * dimension of that name to LAS readers */
    int fmt0 = w->fmt == FMT_LAS && !(a->las_head && a->rec);
    size_t nn = w->ncols + (fmt0 ? JF__LAS_FMT0_NDIMS : 0);
    char **taken = malloc(nn * sizeof *taken);
    if (!taken) {
        free(nm);
        return JF_ERR_NOMEM;
    }
    memcpy(taken, w->names, w->ncols * sizeof *taken);
    for (size_t k = w->ncols; k < nn; k++) taken[k] = (char *)jf__las_fmt0_dims[k - w->ncols];
    int bad = jf__attrs_names(a, taken, nn, nm);
    free(taken);
    if (bad) {
        free(nm);
        return bad == -2 ? JF_ERR_NOMEM : JF_ERR_INVALID;
    }
    size_t need = w->row_max + a->nattrs * 32;
    w->las.a = a;
    w->las.anames = nm;
    if (w->fmt == FMT_LAS) {
        size_t rec = jf__las_record_size(&w->las);
        if (!jf__las_fits(&w->las)) {
            w->las.a = NULL;
            w->las.anames = NULL;
            free(nm);
            return JF_ERR_TOO_LARGE;
        }
        need = rec > need ? rec : need;
    }
    if (need > w->f.cap) { /* nothing is buffered yet: the header is not written */
        char *b = realloc(w->f.buf, need);
        if (!b) {
            w->las.a = NULL;
            w->las.anames = NULL;
            free(nm);
            return JF_ERR_NOMEM;
        }
        w->f.buf = b;
        w->f.cap = need;
    }
    if (w->fmt == FMT_LAS && jf__las_names(&w->las, w->f.final ? w->f.final : "(output)")) {
        w->las.a = NULL;
        w->las.anames = NULL;
        free(nm);
        jf__las_names(&w->las, w->f.final ? w->f.final : "(output)");
        return JF_ERR_NOMEM;
    }
    w->row_max = need;
    w->attrs = a;
    w->anames = nm;
    return JF_OK;
}

jf_status jf_writer_faces(jf_writer *w, size_t nfaces, const size_t *off,
                          const uint32_t *idx)
{
    if (!w || w->header_done || (nfaces && (!off || !idx)))
        return JF_ERR_INVALID;
    int wide = 0;
    for (size_t f = 0; f < nfaces; f++) {
        if (off[f + 1] < off[f] || off[f + 1] - off[f] > UINT32_MAX)
            return JF_ERR_INVALID;
        wide |= off[f + 1] - off[f] > 255;
        for (size_t k = off[f]; k < off[f + 1]; k++)
            if (idx[k] >= w->nrows || idx[k] > INT32_MAX) /* written as PLY int */
                return JF_ERR_INVALID;
    }
    w->face_count4 = wide;
    w->nfaces = nfaces;
    w->foff = off;
    w->fidx = idx;
    return JF_OK;
}

/* One row, formatted into o (room for w->row_max bytes); `row` is the
 * input index of the point, whose attributes the row carries.  Returns
 * the number of bytes.  Reads w only: safe from several threads at once. */
static size_t format_row(const jf_writer *w, const double *vals, size_t row, char *o)
{
    char *o0 = o;
    const jf_attrs *at = w->attrs;
    if (w->fmt == FMT_LAS)
        return jf__las_format_row(&w->las, row, vals, o);
    if (w->fmt == FMT_PLY && !w->ascii && host_little()) {
        /* the usual case, kept tight (it runs once per point): fixed-size
         * copies, no per-value memcpy call */
        for (size_t j = 0; j < w->ncols; j++) {
            const double v = vals[j];
            if (w->types[j] == JF_COL_F64) {
                memcpy(o, &v, 8);
                o += 8;
            } else if (w->types[j] != JF_COL_I32) {
                float x = jf__f32(w->types[j], v);
                memcpy(o, &x, 4);
                o += 4;
            } else {
                int32_t x = to_i32(v);
                memcpy(o, &x, 4);
                o += 4;
            }
            if (j == ATTRS_AFTER && at) /* the attributes after x y z */
                o = jf__attrs_put(at, row, JF__ATTR_PLY_LE, 0, o);
        }
    } else if (w->fmt == FMT_PLY && !w->ascii) {
        int little = host_little();
        for (size_t j = 0; j < w->ncols; j++) {
            unsigned char b[8];
            size_t n;
            if (w->types[j] == JF_COL_F64) {
                memcpy(b, &vals[j], 8), n = 8;
            } else if (w->types[j] != JF_COL_I32) {
                float x = jf__f32(w->types[j], vals[j]);
                memcpy(b, &x, 4), n = 4;
            } else {
                int32_t x = to_i32(vals[j]);
                memcpy(b, &x, 4), n = 4;
            }
            if (little) {
                memcpy(o, b, n);
            } else {
                for (size_t i = 0; i < n; i++)
                    o[i] = (char)b[n - 1 - i];
            }
            o += n;
            if (j == ATTRS_AFTER && at)
                o = jf__attrs_put(at, row, little ? JF__ATTR_PLY_LE : JF__ATTR_PLY_BE, 0, o);
        }
    } else {
        char sep = w->fmt == FMT_CSV ? ',' : ' ';
        for (size_t j = 0; j < w->ncols; j++) {
            if (j)
                *o++ = sep;
            double v = vals[j];
            if (w->types[j] == JF_COL_F64) {
                o = jf_fmt_g17(o, v);
            } else if (w->types[j] != JF_COL_I32) {
                float x = jf__f32(w->types[j], v);
                if (isnan(x))
                    memcpy(o, "nan", 3), o += 3;
                else
                    o += snprintf(o, 32, "%.9g", (double)x);
            } else {
                int32_t x = to_i32(v);
                if (x < 0)
                    *o++ = '-';
                o = jf_fmt_uint(o, x < 0 ? (uint64_t)(-(int64_t)x) : (uint64_t)x);
            }
            if (j == ATTRS_AFTER && at)
                o = jf__attrs_put(at, row, JF__ATTR_TEXT, sep, o);
        }
        *o++ = '\n';
    }
    return (size_t)(o - o0);
}

/* The writer can take nrows more rows: no earlier failure, the header
 * written, no more rows than announced. */
static jf_status ready_for(jf_writer *w, size_t nrows)
{
    jf_wfile *f = &w->f;
    if (f->st != JF_OK)
        return f->st;
    if (!w->header_done && write_header(w) != JF_OK)
        return f->st;
    if (w->put)
        return jf_wf_fail(f, JF_ERR_INVALID, "rows appended to a table of positioned rows");
    if (nrows > w->nrows - w->rows)
        return jf_wf_fail(f, JF_ERR_INVALID, "more rows than the %zu announced", w->nrows);
    return JF_OK;
}

jf_status jf_writer_row(jf_writer *w, const double *vals)
{
    if (!w || !vals)
        return JF_ERR_INVALID;
    jf_wfile *f = &w->f;
    if (ready_for(w, 1) != JF_OK)
        return f->st;
    char *o = jf_wf_room(f, w->row_max);
    if (!o)
        return f->st;
    size_t len = format_row(w, vals, w->rows, o);
    if (w->laz) /* the record goes to the chunk writer, not the file */
        jf__lazw_add(w->laz, o, 1, f);
    else
        f->len += len;
    w->rows++;
    return JF_OK;
}

/* Rows formatted per thread and round by jf_writer_rows. */
#define ROWS_BLOCK 4096

jf_status jf_writer_rows(jf_writer *w, const double *vals, size_t nrows,
                         int threads)
{
    if (!w || (nrows && !vals))
        return JF_ERR_INVALID;
    jf_wfile *f = &w->f;
    if (ready_for(w, nrows) != JF_OK)
        return f->st;
    const int nt = threads > 0 ? threads : jf_default_threads(NULL);
    /* wide rows (a CSV of 100,000 named columns: 3 MB a row) take fewer
     * rows a block, so the scratch stays near 8 MB a thread */
    const size_t row_max = w->row_max,
                 blk = row_max * ROWS_BLOCK <= ((size_t)8 << 20) ? ROWS_BLOCK
                       : row_max >= ((size_t)8 << 20) ? 1 : ((size_t)8 << 20) / row_max,
                 slot = blk * row_max;
    char *scratch = malloc((w->laz ? 1 : (size_t)nt) * slot);
    if (!scratch)
        return jf_wf_fail(f, JF_ERR_NOMEM, "out of memory");
    if (w->laz) { /* LAS records, cheap to format: the chunk writer
                     compresses them on the threads (io_laz_write.c) */
        for (size_t a = 0; a < nrows && f->st == JF_OK; a += blk) {
            size_t e = a + blk < nrows ? a + blk : nrows, l = 0;
            for (size_t r = a; r < e; r++)
                l += format_row(w, vals + r * w->ncols, w->rows + r, scratch + l);
            jf__lazw_add(w->laz, scratch, e - a, f);
            if (w->prog && f->st == JF_OK)
                w->prog(w->prog_user, JF_PHASE_WRITE, w->rows + e, w->nrows);
        }
        free(scratch);
        if (f->st == JF_OK)
            w->rows += nrows;
        return f->st;
    }
    /* blocks of blk rows handed out one at a time: each thread formats
     * its block into its slot, then waits for its turn (ordered) to
     * write it, while the others format the next ones -- no round
     * barrier, the file gets the blocks in row order */
    const size_t nblk = (nrows + blk - 1) / blk;
    int failed = f->st != JF_OK;
#pragma omp parallel num_threads(nt)
    {
        const int tid = omp_get_thread_num();
        char *o = scratch + (size_t)tid * slot;
#pragma omp for schedule(dynamic, 1) ordered
        for (size_t k = 0; k < nblk; k++) {
            int halt;
#pragma omp atomic read
            halt = failed;
            size_t a = k * blk, e = a + blk < nrows ? a + blk : nrows, l = 0;
            for (size_t r = a; r < e && !halt; r++)
                l += format_row(w, vals + r * w->ncols, w->rows + r, o + l);
#pragma omp ordered
            if (f->st == JF_OK) {
                if (jf_wf_write(f, o, l) != JF_OK) {
#pragma omp atomic write
                    failed = 1;
                } else if (tid == 0 && w->prog) { /* the calling thread */
                    w->prog(w->prog_user, JF_PHASE_WRITE, w->rows + e, w->nrows);
                }
            }
        }
    }
    if (w->prog && f->st == JF_OK)
        w->prog(w->prog_user, JF_PHASE_WRITE, w->rows + nrows, w->nrows);
    free(scratch);
    if (f->st == JF_OK)
        w->rows += nrows;
    return f->st;
}

void jf_writer_progress(jf_writer *w, jf_phase_fn fn, void *user)
{
    if (!w)
        return;
    w->prog = fn;
    w->prog_user = user;
}

/* ---- positioned rows --------------------------------------------------- */

/* design: the rows go to a row spool (io_spool.c: a bucket sort through a
 * temporary beside the output) and come back in row order at commit,
 * where jf_writer_rows formats and appends them as it always does: the
 * bytes of a whole-array write, for every format. */
jf_status jf_writer_begin_put(jf_writer *w, int threads)
{
    if (!w || w->put || w->rows)
        return JF_ERR_INVALID;
    jf_wfile *f = &w->f;
    if (ready_for(w, 0) != JF_OK)
        return f->st;
    jf_error e = {{0}};
    if (jf__spool_open(w->f.final, w->nrows, w->ncols, 0, &w->spool, &e) != JF_OK)
        return jf_wf_fail(f, JF_ERR_IO, "cannot create the row spool beside it");
    w->put = 1;
    w->put_threads = threads;
    return JF_OK;
}

jf_status jf_writer_put(jf_writer *w, const uint32_t *rows, const double *vals, size_t m)
{
    if (!w || !w->put || (m && (!rows || !vals)))
        return JF_ERR_INVALID;
    return jf__spool_put(w->spool, rows, vals, m);
}

static jf_status emit_rows(void *user, const double *vals, size_t nrows)
{
    jf_writer *w = user;
    return jf_writer_rows(w, vals, nrows, w->put_threads);
}

/* Commit of a put table: the spool drained in row order through
 * jf_writer_rows (which counts the rows). */
static jf_status put_finish(jf_writer *w)
{
    jf_wfile *f = &w->f;
    w->put = 0; /* jf_writer_rows appends again */
    jf_error e = {{0}};
    if (f->st == JF_OK && jf__spool_drain(w->spool, emit_rows, w, w->f.final, &e) != JF_OK &&
        f->st == JF_OK) {
        /* the spool's own message, "FINAL: reason", without the name */
        const char *why = strstr(e.msg, ": ");
        jf_wf_fail(f, JF_ERR_IO, "%s", why ? why + 2 : e.msg);
    }
    jf__spool_free(w->spool);
    w->spool = NULL;
    return f->st;
}

static jf_status write_faces(jf_writer *w)
{
    jf_wfile *f = &w->f;
    int little = host_little();
    for (size_t i = 0; i < w->nfaces && f->st == JF_OK; i++) {
        size_t k = w->foff[i + 1] - w->foff[i];
        char *o = jf_wf_room(f, 16 * k + 8);
        if (!o)
            break;
        char *o0 = o;
        const uint32_t *ix = w->fidx + w->foff[i];
        if (w->ascii) {
            o = jf_fmt_uint(o, k);
            for (size_t j = 0; j < k; j++) {
                *o++ = ' ';
                o = jf_fmt_uint(o, ix[j]);
            }
            *o++ = '\n';
        } else {
            if (w->face_count4) {
                uint32_t c = (uint32_t)k;
                for (int t = 0; t < 4; t++)
                    *o++ = (char)(unsigned char)(c >> (8 * t)); /* the file is little-endian */
            } else {
                *o++ = (char)(unsigned char)k;
            }
            for (size_t j = 0; j < k; j++) {
                int32_t x = (int32_t)ix[j];
                unsigned char b[4];
                memcpy(b, &x, 4);
                for (int t = 0; t < 4; t++)
                    *o++ = (char)(little ? b[t] : b[3 - t]);
            }
        }
        f->len += (size_t)(o - o0);
    }
    return f->st;
}

/* Frees the writer itself (its file is closed by jf_wf_close). */
/* ---- rows written by other processes (jetfit-mpi, io_internal.h) ------- */

jf_status jf__writer_begin(jf_writer *w, uint64_t *header, const char **tmp)
{
    if (!w || w->fmt != FMT_PLY || w->ascii || w->attrs || w->foff || w->rows || w->put)
        return JF_ERR_INVALID;
    jf_wfile *f = &w->f;
    if (ready_for(w, 0) != JF_OK || jf_wf_flush(f) != JF_OK)
        return f->st;
    off_t at = lseek(f->fd, 0, SEEK_CUR);
    if (at < 0)
        return jf_wf_fail(f, JF_ERR_IO, "%s", strerror(errno));
    *header = (uint64_t)at;
    *tmp = f->t.tmp;
    return JF_OK;
}

jf_status jf__writer_placed(jf_writer *w, size_t nrows)
{
    if (!w || nrows != w->nrows || w->rows)
        return JF_ERR_INVALID;
    w->rows = nrows;
    return JF_OK;
}

void jf__ply_row_le(const jf_col_type *types, size_t ncols, const double *vals, char *o)
{
    for (size_t j = 0; j < ncols; j++) {
        unsigned char b[8];
        size_t n;
        if (types[j] == JF_COL_F64) {
            memcpy(b, &vals[j], 8), n = 8;
        } else if (types[j] != JF_COL_I32) {
            float x = jf__f32(types[j], vals[j]);
            memcpy(b, &x, 4), n = 4;
        } else {
            int32_t x = to_i32(vals[j]);
            memcpy(b, &x, 4), n = 4;
        }
        for (size_t i = 0; i < n; i++)
            o[i] = (char)(host_little() ? b[i] : b[n - 1 - i]);
        o += n;
    }
}

static void free_writer(jf_writer *w)
{
    jf__spool_free(w->spool);
    for (size_t j = 0; w->names && j < w->ncols; j++)
        free(w->names[j]);
    free(w->names);
    free(w->types);
    free(w->anames);
    jf__las_out_free(&w->las);
    jf__lazw_free(w->laz);
    free(w->warn);
    free(w);
}

jf_status jf_writer_commit(jf_writer *w, jf_error *err)
{
    if (!w)
        return JF_ERR_INVALID;
    jf_wfile *f = &w->f;
    if (f->st == JF_OK && !w->header_done)
        write_header(w);
    if (w->put)
        put_finish(w);
    if (f->st == JF_OK && w->rows != w->nrows)
        jf_wf_fail(f, JF_ERR_INVALID, "%zu rows written, %zu announced",
                w->rows, w->nrows);
    if (f->st == JF_OK && w->fmt == FMT_PLY && w->foff)
        write_faces(w);
    /* LAZ: the last chunk and the chunk table */
    if (f->st == JF_OK && w->laz)
        jf__lazw_finish(w->laz, f);
    /* LAS: the input's EVLRs after the records, then the header */
    if (f->st == JF_OK && w->fmt == FMT_LAS && w->attrs && w->attrs->las_head &&
        w->attrs->rec && w->attrs->las_evlr)
        jf_wf_write(f, (const char *)w->attrs->las_evlr, w->attrs->las_evlr_len);
    if (f->st == JF_OK && w->fmt == FMT_LAS && jf_wf_flush(f) == JF_OK &&
        (w->laz ? jf__lazw_write_prefix(f->fd, &w->las, w->laz)
                : jf__las_write_prefix(f->fd, &w->las)) != 0)
        jf_wf_fail(f, JF_ERR_IO, "cannot write the LAS header");
    jf_status st = jf_wf_close(f, err);
    free_writer(w);
    return st;
}

void jf_writer_abort(jf_writer *w)
{
    if (!w)
        return;
    if (w->f.st == JF_OK)
        w->f.st = JF_ERR_INVALID; /* makes jf_wf_close remove the temporary */
    jf_wf_close(&w->f, NULL);
    free_writer(w);
}

/* ---- clouds and meshes -------------------------------------------------- */

static jf_status write_off(const char *path, const jf_cloud *c, jf_error *err)
{
    jf_wfile f;
    if (jf_wf_open(&f, path, 4096) != JF_OK)
        return jf_wf_close(&f, err);
    char line[96];
    jf_wf_puts(&f, c->nrm ? "NOFF\n" : "OFF\n");
    snprintf(line, sizeof line, "%zu %zu 0\n", c->n, c->nfaces);
    jf_wf_puts(&f, line);
    int nc = c->nrm ? 6 : 3;
    for (size_t i = 0; i < c->n && f.st == JF_OK; i++) {
        char *o = jf_wf_room(&f, 6 * 32 + 2);
        if (!o)
            break;
        char *o0 = o;
        for (int j = 0; j < nc; j++) {
            if (j)
                *o++ = ' ';
            o = jf_fmt_g17(o, j < 3 ? c->xyz[3 * i + j] : c->nrm[3 * i + j - 3]);
        }
        *o++ = '\n';
        f.len += (size_t)(o - o0);
    }
    for (size_t i = 0; i < c->nfaces && f.st == JF_OK; i++) {
        size_t k = c->face_off[i + 1] - c->face_off[i];
        if (k > 1000000) {
            jf_wf_fail(&f, JF_ERR_INVALID, "face %zu: bad offsets", i);
            break;
        }
        char *o = jf_wf_room(&f, 12 * k + 24);
        if (!o)
            break;
        char *o0 = o;
        o = jf_fmt_uint(o, k);
        for (size_t j = 0; j < k; j++) {
            *o++ = ' ';
            o = jf_fmt_uint(o, c->face_idx[c->face_off[i] + j]);
        }
        *o++ = '\n';
        f.len += (size_t)(o - o0);
    }
    return jf_wf_close(&f, err);
}

jf_status jf_cloud_write(const char *path, const jf_cloud *c, int ascii,
                         jf_error *err)
{
    const char *nm = path ? path : "(null)";
    if (err)
        err->msg[0] = '\0';
    if (!path || !c || (c->n && !c->xyz) ||
        (c->nfaces && (!c->face_off || !c->face_idx)))
        return jf_io_fail(err, JF_ERR_INVALID, nm, 0, "invalid arguments");
    if (jf_format_from_path(path) == JF_FMT_OFF)
        return write_off(path, c, err);
    static const char *const names[6] = {"x", "y", "z", "nx", "ny", "nz"};
    jf_column cols[6];
    size_t nc = c->nrm ? 6 : 3;
    for (size_t j = 0; j < nc; j++)
        cols[j] = (jf_column){names[j], JF_COL_F64};
    jf_writer *w;
    jf_status st = jf_writer_open(path, cols, nc, c->n, ascii, &w, err);
    if (st != JF_OK)
        return st;
    /* .las: scale and offset from the cloud; commit names a refusal */
    if (jf_writer_las_frame(w, c->xyz, c->n) != JF_OK)
        return jf_writer_commit(w, err);
    if (c->nfaces && (st = jf_writer_faces(w, c->nfaces, c->face_off,
                                           c->face_idx)) != JF_OK) {
        jf_writer_abort(w);
        return jf_io_fail(err, st, nm, 0, "a face has bad offsets or a vertex "
                                          "index out of range");
    }
    /* rows gathered a slice at a time and formatted on the threads
     * (jf_writer_rows: the bytes of row-by-row writes) */
    const size_t slice = (size_t)1 << 16;
    double *v = malloc((c->n < slice ? c->n : slice) * nc * sizeof *v + sizeof *v);
    if (!v) {
        jf_writer_abort(w);
        return jf_io_fail(err, JF_ERR_NOMEM, nm, 0, "out of memory");
    }
    for (size_t i0 = 0; i0 < c->n && st == JF_OK; i0 += slice) {
        size_t k = c->n - i0 < slice ? c->n - i0 : slice;
        for (size_t i = 0; i < k; i++) {
            memcpy(v + nc * i, c->xyz + 3 * (i0 + i), 3 * sizeof(double));
            if (c->nrm)
                memcpy(v + nc * i + 3, c->nrm + 3 * (i0 + i), 3 * sizeof(double));
        }
        st = jf_writer_rows(w, v, k, 0);
    }
    free(v);
    return jf_writer_commit(w, err);
}
