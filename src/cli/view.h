/* view.h -- the pieces of `jetfit view` (cmd_view.c): the packaged
 * three.js it inlines (view_three.c), the columns packed into small typed
 * arrays (view_pack.c), the page written around them (view_page.c) and the
 * spatially even subsample (view_sample.c). */
#ifndef JF_CLI_VIEW_H
#define JF_CLI_VIEW_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "jetfit.h"

/* ---- view_three.c: three.js from Debian's libjs-three ---------------- */
typedef struct {
    char dir[4096];     /* where it was found                          */
    char revision[16];  /* three.REVISION, e.g. "111"                  */
    char *lib, *controls; /* three.min.js, OrbitControls.js (malloc'd) */
} jf_view_three;

/* Finds and reads three.js: $JETFIT_THREE_DIR, else the folder configured
 * at build time (JF_THREE_DIR, Debian's /usr/share/javascript/three).
 * 0, or -1 with a one-line reason in why. */
int jf_view_three_load(jf_view_three *t, char *why, size_t len);
void jf_view_three_free(jf_view_three *t);
/* "three.js r111 (DIR)" or "three.js not found (...)": for --version. */
void jf_view_three_describe(char *buf, size_t len);

/* ---- view_sample.c ---------------------------------------------------- */
/* Orders the m points xyz[idx[k]] (finite) from most to least spatially
 * spread: a point comes before another when it is the first of its cell
 * in a coarser octree level (Morton order inside a level), so any prefix
 * of the order is a spatially even subsample.  idx is reordered in place.
 * 0, or -1 when out of memory. */
int jf_view_spread_order(const double *v, size_t ncols, int cx, size_t *idx, size_t m);

/* ---- view_pack.c: a column as a small typed array --------------------- */
typedef enum {
    JF_VE_POS = 0, /* x y z: uint16 each in the bounding box, 65535 = NaN */
    JF_VE_OCT,     /* a unit vector: int8 pair, octahedral map; -128 = NaN */
    JF_VE_F16,     /* IEEE half of v / scale (scale a power of 2)       */
    JF_VE_LOG16,   /* IEEE half of log2(v): positive, wide-range columns */
    JF_VE_U8,      /* off + q, q = 255 (or 65535, 2^32-1) is NaN         */
    JF_VE_U16,
    JF_VE_U32
} jf_view_enc;

typedef struct {
    char name[64];
    int col;            /* table column (x of a triplet)               */
    jf_view_enc enc;
    double scale, off;  /* F16: scale; U*: off; POS: box min in lo[] ...*/
    double lo[3], hi[3];/* POS: the box                                */
    size_t bytes;       /* per point                                   */
} jf_view_col;

/* Chooses the encoding of column c (a scalar) over the rows idx[0..m). */
void jf_view_pack_choose(const double *v, size_t ncols, const size_t *idx, size_t m,
                         jf_view_col *c);
/* Bounding box of the positions (POS). */
void jf_view_pack_box(const double *v, size_t ncols, const size_t *idx, size_t m,
                      jf_view_col *c);
/* Encodes the value(s) of row r into out (c->bytes bytes, little endian). */
void jf_view_pack_row(const jf_view_col *c, const double *row, unsigned char *out);
uint16_t jf_view_half(double v); /* round to nearest even; NaN, Inf kept */

/* ---- view_page.c: streaming out the page ------------------------------ */
typedef struct {
    FILE *f;
    unsigned char pend[3];
    int npend;
} jf_b64;
void jf_b64_put(jf_b64 *b, const unsigned char *p, size_t n);
void jf_b64_end(jf_b64 *b);
/* s as HTML text (& < > " ' escaped; control characters as U+FFFD). */
void jf_view_html(FILE *f, const char *s);
/* s as a JSON string literal safe inside <script>: < > & and U+2028/9
 * escaped, so no "</script>" or "<!--" can close or bend the element. */
void jf_view_json_str(FILE *f, const char *s);
/* Inlines JavaScript source: any "</script" (any case) or "<!--" is
 * written with a backslash ("<\/script", "<\!--"), which JavaScript
 * reads the same inside strings and regular expressions. */
void jf_view_inline_js(FILE *f, const char *js);

/* The page's template (src/cli/view/, embedded at build time). */
extern const char jf_view_page_html[];
extern const char jf_view_page_js[];

/* ---- view_write.c: the whole page ------------------------------------ */
typedef struct {
    size_t max_points;  /* drawn at most (default 2000000)             */
    size_t glyphs;      /* normal/d1/d2 glyphs at most (default 3000)   */
    const char *color;  /* the column coloured at first (NULL: k1, else
                           the first non-position column)             */
    const char *title;  /* NULL: the file's name                      */
    const char *name;   /* the file the page names (NULL: `in`; view
                           --estimate: the INPUT, not its temporary)  */
    int all_columns;    /* also b0..b3, c0..c4                         */
} jf_view_opts;

void jf_view_opts_init(jf_view_opts *o);
/* Reads the result table `in` and writes the page `out` (a temporary
 * renamed at the end).  0, or 1 with "FILE: reason" in msg. */
int jf_view_write(const char *in, const char *out, const jf_view_opts *o,
                  int quiet, char *msg, size_t len);

#endif
