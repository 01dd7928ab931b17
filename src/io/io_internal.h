/*
 * io_internal.h -- shared pieces of the file readers and writers (not part
 * of the public API).  Every reader parses a caller-owned byte buffer
 * [buf, buf+len) and never reads outside it (no NUL terminator needed), so
 * the file reader can map the file and the fuzzers can pass their bytes.
 */
#ifndef JF_IO_INTERNAL_H
#define JF_IO_INTERNAL_H

#include "core/bigalloc.h" /* jf__big_alloc, for the readers */
#include "jetfit.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* A float column's value: the nearest float, after rounding to a multiple
 * of 2^-16 for JF_COL_F32_Q16 (exact scalings by 2^16; NaN stays NaN). */
static inline float jf__f32(jf_col_type t, double v)
{
    return (float)(t == JF_COL_F32_Q16 ? nearbyint(v * 65536.0) / 65536.0 : v);
}

typedef enum {
    JF_FMT_UNKNOWN = 0,
    JF_FMT_PLY,
    JF_FMT_XYZ,   /* .xyz and .txt */
    JF_FMT_PTS,
    JF_FMT_CSV,
    JF_FMT_OFF,
    JF_FMT_LAS,   /* .las and .laz (the compression bit decides) */
    JF_FMT_PTX,   /* .ptx (Leica/Faro scans with their scanner poses) */
    JF_FMT_E57    /* .e57 (ASTM E2807 scans with their poses) */
} jf_format;

/* Format from the extension (any case); JF_FMT_UNKNOWN if none fits. */
jf_format jf_format_from_path(const char *path);

/* Parses a whole file image.  `name` is used in messages only.  Same
 * contract as jf_cloud_read: on failure *c is zeroed, nothing allocated. */
jf_status jf_cloud_read_mem(const char *buf, size_t len, jf_format fmt,
                            const char *name, const jf_read_opts *o,
                            jf_cloud *c, jf_error *err);

/* The per-format readers called by jf_cloud_read_mem (c zeroed on entry;
 * on failure they may leave arrays in c: the caller frees them). */
jf_status jf_read_ply(const char *buf, size_t len, const char *name,
                      const jf_read_opts *o, jf_cloud *c, jf_error *err);
jf_status jf_read_xyz(const char *buf, size_t len, jf_format fmt,
                      const char *name, const jf_read_opts *o, jf_cloud *c,
                      jf_error *err);
/* io_xyz.c: bytes of text a parallel block takes (0: the default,
 * 1 MiB); tests make blocks small to cut files of a few rows. */
void jf__xyz_block_bytes(size_t bytes);
jf_status jf_read_off(const char *buf, size_t len, const char *name,
                      jf_cloud *c, jf_error *err);
jf_status jf_read_las(const char *buf, size_t len, const char *name,
                      const jf_read_opts *o, jf_cloud *c, jf_error *err);
/* io_read.c: a text file read in pieces of whole lines into one reused
 * buffer (no image of the whole file: its fresh pages cost the kernel a
 * zeroing each).  region [buf, buf + re) holds whole lines (all the rest
 * at the end of the file); off is the file offset of buf[0]. */
typedef struct {
    int fd;
    const char *name;
    size_t len, piece;   /* the file's size; bytes read at a time         */
    char *buf;
    size_t cap, have;    /* buf's size; bytes in it                       */
    size_t re, off, got; /* region end; buf's offset; bytes read in all   */
} jf_pieces;
/* The next region (empty at the end of the file); an I/O error, a short
 * read or a NUL byte is the error of the whole file (as jf_cloud_read). */
jf_status jf__pieces_next(jf_pieces *p, jf_error *err);
/* After a parse error: reads the rest, so that an I/O error or a NUL byte
 * later in the file is the one reported, as for a whole read; JF_OK keeps
 * the parse error. */
jf_status jf__pieces_drain(jf_pieces *p, jf_error *err);
/* io_xyz.c: a text table of len bytes read from fd in pieces; *declined:
 * a file of at most two pieces, or whose first lines do not settle the
 * columns within the first piece (the caller reads the whole file; c is
 * zeroed).  Tests make pieces small (jf__xyz_piece_bytes; 0: 8 MiB). */
jf_status jf__read_xyz_fd(int fd, size_t len, jf_format fmt, const char *name,
                          const jf_read_opts *o, jf_cloud *c, jf_error *err, int *declined);
void jf__xyz_piece_bytes(size_t bytes);
/* io_laz.c: a LAZ file image decoded into the plain LAS file it stands
 * for (*img, *img_len: malloc'd, the caller frees; the laszip VLR dropped,
 * the compression bits cleared).  err "NAME: reason" naming the chunk. */
jf_status jf__laz_unpack(const char *buf, size_t len, const char *name, char **img,
                         size_t *img_len, jf_error *err);
/* The same, a piece at a time (jetfit-mpi: each rank its rows): the file
 * image buf (kept by the caller while L lives) checked and indexed; the
 * plain LAS file's header and VLRs (head_len bytes: its records would
 * start there), its point count and record length; count records from
 * point `first` decoded into out (the chunks they lie in; the last one
 * kept for the next call: not thread-safe). */
typedef struct jf_laz jf_laz;
jf_status jf__laz_open(const char *buf, size_t len, const char *name, jf_laz **L,
                       jf_error *err);
const unsigned char *jf__laz_head(const jf_laz *L, size_t *head_len, uint64_t *n,
                                  unsigned *rec_len);
jf_status jf__laz_rows(jf_laz *L, uint64_t first, size_t count, char *out, jf_error *err);
/* Every record of L decoded into rec (n * rec_len bytes), the chunks in
 * parallel (the bytes do not depend on the thread count); the plain LAS
 * file's EVLRs (*len bytes, in the caller's image; 0 if none). */
jf_status jf__laz_decode(jf_laz *L, unsigned char *rec, jf_error *err);
const unsigned char *jf__laz_evlr(const jf_laz *L, size_t *len);
void jf__laz_close(jf_laz *L);
/* jf__laz_open of a malloc'ed image that L then owns (freed by
 * jf__laz_close; on failure at once). */
jf_status jf__laz_open_owned(char *buf, size_t len, const char *name, jf_laz **L,
                             jf_error *err);
jf_status jf_read_ptx(const char *buf, size_t len, const char *name, const jf_read_opts *o,
                      jf_cloud *c, jf_error *err);
jf_status jf_read_e57(const char *buf, size_t len, const char *name, const jf_read_opts *o,
                      jf_cloud *c, jf_error *err);

/* io_ply.c: a binary PLY whose elements all have fixed-size rows and
 * whose length matches its header, read from fd (len bytes) a chunk at a
 * time straight into c (no file image in memory; attributes too unless
 * o->no_attrs; o may be NULL).  JF_ERR_UNSUPPORTED
 * (c untouched, err not set) when the file does not qualify: read it
 * whole.  Otherwise JF_OK, or JF_ERR_IO / _NOMEM with err set. */
jf_status jf__read_ply_chunked(int fd, size_t len, const char *name, const jf_read_opts *o,
                               jf_cloud *c, jf_error *err);
/* The same without the coordinates (c->xyz NULL; n, normals, attributes
 * read): the bounded-memory estimate reads them from the file as it goes
 * (src/estimate/parts.h, jf_xyz_src). */
jf_status jf__read_ply_chunked_noxyz(int fd, size_t len, const char *name,
                                     const jf_read_opts *o, jf_cloud *c, jf_error *err);

/* The types of a .las or .laz output's real-valued columns (las_columns.c;
 * the command's --las-columns): mode 0 by path (.laz compact, else
 * double), or one of these; columns 0-2 (x y z) and integers untouched. */
enum { JF_LASCOL_DOUBLE = 1, JF_LASCOL_FLOAT = 2, JF_LASCOL_COMPACT = 3 };
void jf__las_columns(const char *path, int mode, jf_column *cols, size_t ncols);

/* Where the point rows of a binary PLY (io_ply.c) or a LAS file
 * (io_las.c) are -- fixed-size rows, the file's length as its header says
 * -- for readers of a byte range of them (jetfit-mpi: each rank its own
 * rows). */
typedef struct {
    uint64_t count;        /* points                                     */
    uint64_t vertex_off;   /* file offset of row 0                       */
    size_t row;            /* bytes per row                              */
    int has_normals;       /* PLY: nx ny nz are properties; LAS: Extra Bytes */
    int swap;              /* PLY: byte order differs from the machine's */
    int type[6];           /* PLY: x y z nx ny nz scalar types           */
    size_t off[6];         /* PLY: their offsets in the row              */
    int las;               /* LAS: x y z are int32 at 0, 4, 8, then      */
    double scale[3], offset[3]; /* value * scale + offset                */
    struct jf_laz *laz;    /* LAZ: the rows come from its chunks (jf__laz_rows) */
} jf_row_layout;

/* The layout from the file's first len bytes (the whole header), the
 * file being size bytes.  JF_ERR_FORMAT (or the LAS reader's status) with
 * err "NAME:LINE: reason" when it is not a binary PLY whose vertices have
 * fixed-size rows that the file holds, with x y z; or for LAS, every
 * header rule of jf_read_las. */
jf_status jf__ply_layout(const char *buf, size_t len, uint64_t size, const char *name,
                         jf_row_layout *l, jf_error *err);
jf_status jf__las_layout(const char *buf, size_t len, uint64_t size, const char *name,
                         jf_row_layout *l, jf_error *err);
/* Decodes k rows at raw into xyz (3k) and, if nrm and l->has_normals,
 * nrm (3k), exactly as jf_read_ply / jf_read_las would. */
void jf__layout_rows(const unsigned char *raw, size_t k, const jf_row_layout *l, double *xyz,
                     double *nrm);
/* 1 when a row is x y z as the machine's doubles and nothing else: its
 * bytes are jf__layout_rows's coordinates (no normals to decode). */
int jf__layout_plain_xyz(const jf_row_layout *l);
void jf__las_rows(const unsigned char *raw, size_t k, const jf_row_layout *l, double *xyz);
/* LAS with l->has_normals: the Extra Bytes normals of k rows (type[3..5]:
 * 9 float, 10 double). */
void jf__las_normal_rows(const unsigned char *raw, size_t k, const jf_row_layout *l, double *nrm);

/* io_write.c, for rows written by other processes (jetfit-mpi): a binary
 * little-endian PLY table without attributes or faces gets its header
 * written and flushed; *header its size, *tmp the temporary's path (the
 * rows go at header + row * row size).  placed: all nrows rows are in the
 * file (commit then only renames).  row_le: one row in the file's bytes. */
jf_status jf__writer_begin(jf_writer *w, uint64_t *header, const char **tmp);
jf_status jf__writer_placed(jf_writer *w, size_t nrows);
void jf__ply_row_le(const jf_col_type *types, size_t ncols, const double *vals, char *o);

/* io_spool.c: rows put in any order from any thread, drained in row
 * order (the table writer's positioned rows).  open: a temporary beside
 * `final` for nrows rows of ncols doubles, buckets of bucket_bytes of
 * values (0: jf__spool_bucket; small values are for tests).  put: thread-safe; JF_ERR_IO /
 * _INVALID (a row >= nrows, or more rows than a bucket holds) stick.
 * drain (once, one thread): every row must have been put exactly once;
 * emit gets the rows in order, a bucket (up to 128 MiB of values) at a
 * time; err "NAME: reason".  free: removes the temporary (NULL ok). */
typedef struct jf_spool jf_spool;
/* The bucket size jf__spool_open takes for bucket_bytes 0, and the most
 * memory such a spool holds at once (staging or drain). */
size_t jf__spool_bucket(size_t nrows, size_t ncols);
size_t jf__spool_bytes(size_t nrows, size_t ncols);
jf_status jf__spool_open(const char *final, size_t nrows, size_t ncols, size_t bucket_bytes,
                         jf_spool **s, jf_error *err);
jf_status jf__spool_put(jf_spool *s, const uint32_t *rows, const double *vals, size_t m);
jf_status jf__spool_drain(jf_spool *s, jf_status (*emit)(void *, const double *, size_t),
                          void *user, const char *name, jf_error *err);
void jf__spool_free(jf_spool *s);

/* LAS output (io_las_write.c), used by the table writer: what the output
 * holds (the table's columns, x y z first; the attributes, NULL if none,
 * and their output names; the frame of a format-0 output), the header and
 * VLRs' size, the record size, the frame of a cloud, one record (the
 * attributes of input row `row`), and the header and VLRs written at
 * offset 0 of fd at commit (0, or -1 on a write error). */
typedef struct {
    char *const *names;
    const jf_col_type *types;
    size_t ncols, nrows;
    const jf_attrs *a;
    char (*anames)[64];
    double scale[3], offset[3], lo[3], hi[3];
    char (*ebn)[33];     /* the Extra Bytes names: the attributes', then
                            columns 3..'s, at most 32 bytes (jf__las_names) */
    char *warn_frame, *warn_names; /* warning lines "FILE: ...\n", or NULL */
} jf_las_out;
size_t jf__las_prefix_size(const jf_las_out *L);
size_t jf__las_record_size(const jf_las_out *L);
/* The frame of a format-0 output from the cloud: scale and offset per axis
 * by the rule, or as given (scale or offset NULL: by the rule); a warning
 * (warn_frame) when the rule's scale rounds coordinates by more than 1e-6
 * of the cloud's bulk size.  JF_ERR_TOO_LARGE, why filled (the axis and its
 * extent), when the coordinates cannot be stored as int32 counts. */
jf_status jf__las_frame(jf_las_out *L, const char *file, const double *xyz, size_t n,
                        const double *scale, const double *offset, char *why, size_t whylen);
/* The Extra Bytes names (ebn) from anames and the column names: up to 32
 * bytes kept, longer ones shortened to distinct names with a warning line
 * each (warn_names).  0, or -1 out of memory. */
int jf__las_names(jf_las_out *L, const char *file);
/* Frees ebn and the warnings. */
void jf__las_out_free(jf_las_out *L);
size_t jf__las_format_row(const jf_las_out *L, size_t row, const double *vals, char *o);
int jf__las_write_prefix(int fd, const jf_las_out *L);
/* The header and VLRs jf__las_write_prefix writes, in a buffer of *len
 * bytes for the caller to free (NULL without memory). */
unsigned char *jf__las_prefix(const jf_las_out *L, size_t *len);
/* The output's point format (the input's under keep, else 0). */
unsigned jf__las_out_format(const jf_las_out *L);

/* The dimension names of point format 0 (as the LAS reader names them). */
#define JF__LAS_FMT0_NDIMS 12
extern const char *const jf__las_fmt0_dims[JF__LAS_FMT0_NDIMS];
/* 1 if the record (<= 65535 bytes) and the Extra Bytes VLR (<= 341
 * descriptions) fit the format. */
int jf__las_fits(const jf_las_out *L);

/* ---- the attribute table (io_attrs.c) ---- */

/* Bytes of a value of each jf_attr_type. */
extern const unsigned jf_attr_size[10];
/* dst = the name [s, s+len) cut to 63 bytes, blanks ',' '#' made '_'. */
void jf__attr_name(char dst[64], const char *s, size_t len);
/* Appends a description (the record layout is the caller's); 0 on
 * allocation failure. */
int jf__attrs_add(jf_attrs *a, const char *name, size_t len, jf_attr_type t,
                  uint32_t offset, unsigned shift, unsigned bits);
/* The output names: each attribute's, with `in_` put before it while it
 * clashes with one of cols[0..ncols-1] or an earlier attribute.  -1 if a
 * name cannot be made unique in 63 bytes, -2 out of memory.  Linear time. */
int jf__attrs_names(const jf_attrs *a, char *const *cols, size_t ncols, char (*out)[64]);
/* The type a value is written as (a bit field: U8), its PLY type name
 * (64-bit integers: double). */
jf_attr_type jf__attr_out_type(const jf_attr *at);
const char *jf__attr_ply_type(const jf_attr *at);
/* Formats the attributes of point `row` at o and returns the end: binary
 * PLY little or big endian (64-bit integers as doubles), LAS Extra Bytes
 * (little endian, every type as it is), or text (each value preceded by
 * sep; integers exact, floats and doubles %.17g: exact).  At most 32 bytes a value. */
enum { JF__ATTR_PLY_LE, JF__ATTR_PLY_BE, JF__ATTR_LAS, JF__ATTR_TEXT };
char *jf__attrs_put(const jf_attrs *a, size_t row, int mode, char sep, char *o);
/* Bytes of a row of attributes in a binary mode. */
size_t jf__attrs_bin_size(const jf_attrs *a, int mode);

/* Fills err (may be NULL) with "NAME:LINE: reason" (line > 0) or
 * "NAME: reason" (line == 0); returns st. */
jf_status jf_io_fail(jf_error *err, jf_status st, const char *name,
                     size_t line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Parses the whole token [s, e) as a double (decimal, exponent, "nan",
 * "inf", hex floats): 1 on success, 0 if the token is not one number.
 * Exact: <= 19 digits with mantissa <= 2^53 and |exp| <= 22 is Clinger's
 * one-rounding case; other <= 19 digit numbers with |exp| <= 64 are
 * Eisel-Lemire's (jf__lemire), and where it cannot tell, |exp| <= 27 use
 * exact 128-bit integers; everything else goes to strtod. */
int jf_parse_double(const char *s, const char *e, double *out);

/* The number at the start of [s, e) in jf_parse_double's exact fast
 * ranges: its end (the token is [s, end) if a separator follows), or NULL
 * where jf_parse_double would ask strtod. */
const char *jf_scan_double(const char *s, const char *e, double *out);

/* m 10^q (m != 0) correctly rounded, by Eisel-Lemire (io_lemire.c): 1 and
 * *out, or 0 when it cannot tell (subnormal or overflowing results, |q| >
 * 64, the rare ambiguous products): the caller's exact path decides. */
int jf__lemire(uint64_t m, int q, double *out);

/* 5^k for 0 <= k <= 27 (5^27 < 2^63): the exact decimal paths of
 * jf_parse_double and jf_fmt_g17. */
static inline uint64_t jf_pow5(int k)
{
    uint64_t p = 1;
    while (k--)
        p *= 5;
    return p;
}

/* Writes v exactly as printf("%.17g", v) does, except NaN -> "nan"
 * (never "-nan"); at most 24 bytes, no NUL.  Returns the end. */
char *jf_fmt_g17(char *out, double v);

/* Writes v in decimal (no NUL); returns the end. */
char *jf_fmt_uint(char *out, uint64_t v);

/* Parses [s, e) as an unsigned decimal integer <= max: 1 ok, 0 not. */
int jf_parse_size(const char *s, const char *e, uint64_t max, uint64_t *out);

/* Text cursor: line by line over [p, end), counting lines from 1. */
typedef struct {
    const char *p, *end;
    size_t line;          /* number of the line last returned */
    int no_cr;            /* the text has no '\r' (known): no search   */
} jf_text;

/* Next line as [*ls, *le) without its end: '\n', "\r\n", or a lone '\r'
 * (old Mac exports end lines with CR only).  0 at end. */
static inline int jf_text_line(jf_text *t, const char **ls, const char **le)
{
    if (t->p >= t->end)
        return 0;
    const char *s = t->p;
    const char *nl = memchr(s, '\n', (size_t)(t->end - s));
    const char *e = nl ? nl : t->end;
    t->p = nl ? nl + 1 : t->end;
    const char *cr = t->no_cr ? NULL : memchr(s, '\r', (size_t)(e - s));
    if (cr && cr + 1 < e) { /* a lone CR ends the line */
        e = cr;
        t->p = cr + 1;
    } else if (cr) {
        e--; /* CRLF, or a CR at the very end */
    }
    t->line++;
    *ls = s;
    *le = e;
    return 1;
}

/* Separator classes for jf_next_token: 1 = blank, 2 = ',' or ';'. */
extern const unsigned char jf_sep_class[256];

static inline int jf_is_space(char ch)
{
    return jf_sep_class[(unsigned char)ch] & 1;
}

/* Next token of [*p, e) separated by whitespace (and ',' ';' when
 * `commas`); sets [*ts, *te) and advances *p.  0 when none is left. */
static inline int jf_next_token(const char **p, const char *e, int commas,
                                const char **ts, const char **te)
{
    const unsigned mask = commas ? 3u : 1u;
    const char *q = *p;
    while (q < e && (jf_sep_class[(unsigned char)*q] & mask))
        q++;
    if (q >= e) {
        *p = q;
        return 0;
    }
    *ts = q;
    while (q < e && !(jf_sep_class[(unsigned char)*q] & mask))
        q++;
    *te = q;
    *p = q;
    return 1;
}

/* Growable array of doubles / uint32 / size_t (amortised doubling: no
 * allocation per element).  Return 0 on allocation failure. */
typedef struct { double *v; size_t n, cap; } jf_dvec;
typedef struct { uint32_t *v; size_t n, cap; } jf_uvec;
int jf_dvec_reserve(jf_dvec *a, size_t cap);
int jf_uvec_reserve(jf_uvec *a, size_t cap);
int jf_zvec_reserve(size_t **v, size_t *cap, size_t want);

/* Largest number of points a cloud may hold (indices are uint32). */
#define JF_MAX_POINTS ((size_t)UINT32_MAX - 1)


/* ---- the buffered output file (io_wfile.c) ---- */

/* An output file in the making: buffered writes to a temporary beside the
 * final name; the first failure sticks in st/err and later calls do
 * nothing. */
typedef struct {
    int fd;              /* t.fd                                     */
    jf_tmpfile t;        /* the temporary (io_tmpfile.c)             */
    char *final;
    char *buf;
    size_t len, cap;
    jf_status st;
    jf_error err;
} jf_wfile;

/* Opens the temporary for `path` (buffer >= min_cap bytes). */
jf_status jf_wf_open(jf_wfile *f, const char *path, size_t min_cap);
/* Records the first failure (message "FINAL: reason"); returns f->st. */
jf_status jf_wf_fail(jf_wfile *f, jf_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Writes the buffer out. */
jf_status jf_wf_flush(jf_wfile *f);
/* Writes the buffer out, then [p, p + n) straight to the file. */
jf_status jf_wf_write(jf_wfile *f, const char *p, size_t n);
/* Appends the string s. */
jf_status jf_wf_puts(jf_wfile *f, const char *s);
/* Frees f; on success (st OK) renames the temporary onto the final name,
 * else removes it.  Returns the final status and fills err. */
jf_status jf_wf_close(jf_wfile *f, jf_error *err);

/* Room for `need` more bytes in the buffer (need <= cap). */
static inline char *jf_wf_room(jf_wfile *f, size_t need)
{
    if (f->cap - f->len < need && jf_wf_flush(f) != JF_OK)
        return NULL;
    return f->buf + f->len;
}

/* LAZ output (io_laz_write.c): the records of a LAS output, compressed in
 * chunks as they come (LASzip compressor 2 for point formats 0-3, 3 for
 * 6-8), the chunk table after them, and the LAS prefix with the laszip
 * VLR and the table's offset at commit. */
typedef struct jf_lazw jf_lazw;
/* NULL with why filled for a format not written as LAZ (4, 5, 9, 10, or
 * out of memory). */
jf_lazw *jf__lazw_open(unsigned fmt, unsigned rec_len, size_t prefix, char *why, size_t whylen);
/* Bytes the LAZ adds between the LAS prefix and the records (the laszip
 * VLR and the chunk table's offset). */
size_t jf__lazw_extra(const jf_lazw *z);
/* Takes n whole records (n * rec_len bytes), writing full chunks to f. */
jf_status jf__lazw_add(jf_lazw *z, const char *recs, size_t n, jf_wfile *f);
/* The last chunk and the chunk table, to f. */
jf_status jf__lazw_finish(jf_lazw *z, jf_wfile *f);
/* The prefix (header, VLRs, laszip VLR, table offset) at offset 0 of fd;
 * 0, or -1 on a write error or without memory. */
int jf__lazw_write_prefix(int fd, const jf_las_out *L, const jf_lazw *z);
void jf__lazw_free(jf_lazw *z);

/* io_spool.c: n bytes at offset at, through short writes and EINTR; 0 or
 * the errno (EIO for a write that wrote nothing). */
int jf__pwrite_all(int fd, const void *buf, size_t n, size_t at);

#endif /* JF_IO_INTERNAL_H */
