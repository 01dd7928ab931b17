/*
 * io_xyz.c -- text tables: .xyz/.txt/.pts (whitespace, ',' or ';'
 * separated) and .csv (comma separated, header naming the columns).
 *
 * design: one pass counts lines (memchr) to size the arrays once -- bounded
 * by the bytes too, since a data row takes at least 6 -- then one pass
 * parses rows in place.  Comments ('#', '//') and blank lines are
 * skipped; a line holding a single integer is a point count (PTS files
 * start with one, concatenated scans repeat it) and is skipped when it is
 * the first data line or follows exactly that many rows.  A first line
 * of names only ("X Y Z nx ny nz") is a header, as in CSV.
 */
#include "io_internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* How many bytes of [p, p + n) are c: eight at a time (a byte of x ^ c
 * is zero exactly where the byte is c: the carry-free test below leaves
 * a 1 in that byte, and a multiply sums the eight bytes). */
static size_t count_byte(const char *p, size_t n, char c)
{
    const uint64_t ones = 0x0101010101010101ULL, low7 = 0x7F7F7F7F7F7F7F7FULL;
    const uint64_t cc = ones * (unsigned char)c;
    size_t k = 0, i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t x;
        memcpy(&x, p + i, 8);
        x ^= cc;
        uint64_t t = ((x & low7) + low7) | x; /* high bit set: byte non-zero */
        k += (size_t)((((~t & ~low7) >> 7) * ones) >> 56); /* the bytes' sum */
    }
    for (; i < n; i++)
        k += p[i] == c;
    return k;
}

/* Whether the row's first field could be a count (jf_parse_size: '+'
 * and digits): a quick look that spares data rows the full test. */
static int digits_first(const char *q, const char *le)
{
    while (q < le && jf_is_space(*q))
        q++;
    if (q < le && *q == '+')
        q++;
    while (q < le && *q >= '0' && *q <= '9')
        q++;
    return q == le || (jf_sep_class[(unsigned char)*q] & 3u);
}

/* The header-named columns other than x y z, carried as attributes:
 * read as doubles into v (row-major, grown by doubling), then packed in
 * the smallest exact type of each column (text_attrs_pack). */
typedef struct {
    int ncols;          /* header fields                               */
    const char **nm;    /* their names in the file, and lengths        */
    size_t *nml;
    int *acol;          /* attribute index of each header field, or -1 */
    int na;             /* attributes                                  */
    int maxcol;         /* largest column of an attribute, -1 if none  */
    double *v;          /* rows * na values                            */
    size_t rows_cap;
    unsigned char *text;/* per attribute: a field that is not a number
                           was seen (the column is dropped)            */
    char *own;          /* in pieces: the names copied (the buffer is
                           reused)                                     */
} text_attrs;

typedef struct {
    const char *name;
    jf_error *err;
    int csv;        /* fields split at ',' only (else whitespace , ;) */
    int col[6];     /* column of x y z nx ny nz, -1 = not read */
    int maxcol;     /* largest column needed */
    text_attrs *ta; /* NULL: attributes not wanted */
    const char *hash; /* the first '#' at or after the last line looked
                         at (tend: none), NULL before the first        */
    const char *tend; /* the end of the text (of the block)            */
} tab;

/* Next field of a row; csv fields are trimmed and may be empty. */
static int next_field(const tab *t, const char **p, const char *e,
                      const char **fs, const char **fe)
{
    if (!t->csv)
        return jf_next_token(p, e, 1, fs, fe);
    const char *q = *p;
    if (q > e)
        return 0;
    const char *c = memchr(q, ',', (size_t)(e - q));
    const char *end = c ? c : e;
    *p = c ? c + 1 : e + 1; /* past e: no more fields */
    while (q < end && jf_is_space(*q))
        q++;
    const char *r = end;
    while (r > q && jf_is_space(r[-1]))
        r--;
    *fs = q;
    *fe = r;
    return 1;
}

/* Columns x y z (nx ny nz) are fields 0, 1, 2 (3, 4, 5), nothing else read. */
static int in_order(const tab *t)
{
    if (t->maxcol != 2 && t->maxcol != 5)
        return 0;
    for (int k = 0; k < 6; k++)
        if (t->col[k] != (k <= t->maxcol ? k : -1))
            return 0;
    return 1;
}

/* A row of exactly w numbers between separators, the common case (what
 * %.17g writers produce), in one pass: each number's end must be a
 * separator or the row's.  0 sends the row to the field-by-field path,
 * which reads every form and says what is wrong; the values are the same
 * (jf_parse_double is jf_scan_double over the whole field). */
static int fast_row(const char *p, const char *e, int w, double *v)
{
    for (int k = 0; k < w; k++) {
        while (p < e && (jf_sep_class[(unsigned char)*p] & 3u))
            p++;
        const char *q = jf_scan_double(p, e, &v[k]);
        if (!q || (q < e && !(jf_sep_class[(unsigned char)*q] & 3u)))
            return 0;
        p = q;
    }
    while (p < e && (jf_sep_class[(unsigned char)*p] & 3u))
        p++;
    return p == e;
}

/* The row without a comment: [ls, *le) shortened; 0 if nothing is left. */
static int strip_comment(tab *t, const char *ls, const char **le)
{
    const char *q = ls;
    while (q < *le && jf_is_space(*q))
        q++;
    if (q == *le || *q == '#' || (*le - q >= 2 && q[0] == '/' && q[1] == '/'))
        return 0;
    if (!t->csv) { /* one search for the next '#' serves every line before it */
        if (!t->hash || t->hash < q) {
            t->hash = memchr(q, '#', (size_t)(t->tend - q));
            t->hash = t->hash ? t->hash : t->tend;
        }
        if (t->hash < *le)
            *le = t->hash;
    }
    return 1;
}

static int count_fields(const tab *t, const char *ls, const char *le)
{
    const char *p = ls, *fs, *fe;
    int n = 0;
    while (next_field(t, &p, le, &fs, &fe))
        n++;
    return n;
}

static int lower_eq(const char *s, const char *e, const char *word)
{
    size_t n = strlen(word);
    if ((size_t)(e - s) != n)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char ch = s[i];
        if (ch >= 'A' && ch <= 'Z')
            ch = (char)(ch - 'A' + 'a');
        if (ch != word[i])
            return 0;
    }
    return 1;
}

/* CSV header: finds x y z [nx ny nz] by name (quotes and case ignored). */
static jf_status csv_header(tab *t, const char *ls, const char *le,
                            size_t line, int want_names)
{
    static const char *const names[6] = {"x", "y", "z", "nx", "ny", "nz"};
    int found[6] = {-1, -1, -1, -1, -1, -1};
    const char *p = ls, *fs, *fe;
    text_attrs *ta = t->ta;
    if (ta) {
        int nf = count_fields(t, ls, le);
        ta->nm = malloc((size_t)(nf ? nf : 1) * sizeof *ta->nm);
        ta->nml = malloc((size_t)(nf ? nf : 1) * sizeof *ta->nml);
        ta->acol = malloc((size_t)(nf ? nf : 1) * sizeof *ta->acol);
        if (!ta->nm || !ta->nml || !ta->acol)
            return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, line, "out of memory");
    }
    for (int j = 0; next_field(t, &p, le, &fs, &fe); j++) {
        if (fe - fs >= 2 && (*fs == '"' || *fs == '\'') && fe[-1] == *fs) {
            fs++;
            fe--;
        }
        if (ta) {
            ta->nm[j] = fs;
            ta->nml[j] = (size_t)(fe - fs);
            ta->ncols = j + 1;
        }
        for (int k = 0; k < 6; k++) {
            if (!lower_eq(fs, fe, names[k]))
                continue;
            /* a duplicated name would make the choice of column a guess */
            if (found[k] >= 0)
                return jf_io_fail(t->err, JF_ERR_FORMAT, t->name, line,
                                  "column '%s' appears twice (columns %d and %d)",
                                  names[k], found[k] + 1, j + 1);
            found[k] = j;
        }
    }
    if (want_names & 1) {
        int named = found[0] >= 0 && found[1] >= 0 && found[2] >= 0;
        if (!named && t->csv)
            return jf_io_fail(t->err, JF_ERR_FORMAT, t->name, line,
                              "CSV header has no columns named x, y and z");
        for (int k = 0; k < 3; k++)
            t->col[k] = named ? found[k] : k; /* xyz: default columns */
    }
    if ((want_names & 2) && found[3] >= 0 && found[4] >= 0 && found[5] >= 0)
        for (int k = 3; k < 6; k++)
            t->col[k] = found[k];
    /* every other named column is an attribute (normals too: an output
     * names them in_nx ...) */
    if (ta) {
        ta->maxcol = -1;
        for (int j = 0; j < ta->ncols; j++) {
            int xyz = j == t->col[0] || j == t->col[1] || j == t->col[2];
            ta->acol[j] = xyz || !ta->nml[j] ? -1 : ta->na++;
            if (ta->acol[j] >= 0)
                ta->maxcol = j;
        }
        ta->text = calloc((size_t)(ta->na ? ta->na : 1), 1);
        if (!ta->text)
            return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, line, "out of memory");
    }
    return JF_OK;
}

/* Attribute values of one row into v (na values) from fields [0, maxcol]
 * of the line (NaN when the row is bad or a field is empty; a field that
 * is not a number marks its column in text[]). */
static void attrs_fill(const tab *t, double *v, unsigned char *text, const char *ls,
                       const char *le, int bad)
{
    const text_attrs *ta = t->ta;
    for (int k = 0; k < ta->na; k++)
        v[k] = NAN;
    if (bad)
        return;
    const char *p = ls, *fs, *fe;
    for (int j = 0; j <= ta->maxcol && next_field(t, &p, le, &fs, &fe); j++) {
        int k = ta->acol[j];
        if (k >= 0 && fs < fe && !jf_parse_double(fs, fe, &v[k]))
            text[k] = 1;
    }
}

/* Room for `rows` rows of attribute values (grown by doubling). */
static int attrs_room(text_attrs *ta, size_t rows)
{
    if (rows <= ta->rows_cap)
        return 1;
    size_t cap = ta->rows_cap ? ta->rows_cap : 1024;
    while (cap < rows)
        cap *= 2;
    double *q = realloc(ta->v, cap * (size_t)ta->na * sizeof *q);
    if (!q)
        return 0;
    ta->v = q;
    ta->rows_cap = cap;
    return 1;
}

/* Attribute values of row n (see attrs_fill). */
static int text_attrs_row(const tab *t, size_t n, const char *ls, const char *le, int bad)
{
    text_attrs *ta = t->ta;
    if (!attrs_room(ta, n + 1))
        return 0;
    attrs_fill(t, ta->v + n * (size_t)ta->na, ta->text, ls, le, bad);
    return 1;
}

/* The smallest type holding every value of attribute k exactly: integers
 * (no -0) in uchar, ushort or int range, else double. */
static jf_attr_type text_attr_type(const text_attrs *ta, int k, size_t n)
{
    double lo = 0, hi = 0;
    for (size_t i = 0; i < n; i++) {
        double x = ta->v[i * (size_t)ta->na + (size_t)k];
        if (!(x == floor(x)) || (x == 0 && signbit(x)) || !(fabs(x) <= 2147483648.0))
            return JF_ATTR_F64;
        lo = x < lo ? x : lo;
        hi = x > hi ? x : hi;
    }
    if (lo >= 0 && hi <= 255)
        return JF_ATTR_U8;
    if (lo >= 0 && hi <= 65535)
        return JF_ATTR_U16;
    return lo >= -2147483648.0 && hi <= 2147483647.0 ? JF_ATTR_I32 : JF_ATTR_F64;
}

/* Moves the values into c->attrs, packed. */
static jf_status text_attrs_pack(const tab *t, size_t n, jf_cloud *c)
{
    text_attrs *ta = t->ta;
    jf_attrs *a = &c->attrs;
    int *type = malloc((size_t)(ta->na ? ta->na : 1) * sizeof *type);
    if (!type)
        return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0, "out of memory");
    for (int j = 0; j < ta->ncols; j++) {
        int k = ta->acol[j];
        if (k < 0 || ta->text[k])
            continue; /* a column of words is not carried */
        jf_attr_type at = text_attr_type(ta, k, n);
        type[k] = at;
        if (!jf__attrs_add(a, ta->nm[j], ta->nml[j], at, (uint32_t)a->stride, 0, 0)) {
            free(type);
            return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0, "out of memory");
        }
        a->stride += jf_attr_size[at];
    }
    if (a->nattrs && !(a->rec = malloc(n * a->stride))) {
        free(type);
        return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0,
                          "out of memory for the attributes of %zu points", n);
    }
    for (int j = 0, m = 0; j < ta->ncols; j++) {
        int k = ta->acol[j];
        if (k < 0 || ta->text[k])
            continue;
        const jf_attr *at = &a->attr[m++];
        for (size_t i = 0; i < n; i++) {
            double x = ta->v[i * (size_t)ta->na + (size_t)k];
            unsigned char *d = a->rec + i * a->stride + at->offset;
            uint64_t b;
            if (at->type == JF_ATTR_F64)
                memcpy(&b, &x, 8);
            else
                b = (uint64_t)(int64_t)x;
            for (unsigned q = 0; q < jf_attr_size[at->type]; q++)
                d[q] = (unsigned char)(b >> (8 * q));
        }
    }
    free(type);
    return JF_OK;
}

/* 1 if every field of the row is a number (a headerless CSV). */
static int all_numeric(const tab *t, const char *ls, const char *le)
{
    const char *p = ls, *fs, *fe;
    double v;
    int n = 0;
    while (next_field(t, &p, le, &fs, &fe)) {
        if (!jf_parse_double(fs, fe, &v))
            return 0;
        n++;
    }
    return n > 0;
}

/* 1 if no field of the row is a number (a header line of names). */
static int none_numeric(const tab *t, const char *ls, const char *le)
{
    const char *p = ls, *fs, *fe;
    double v;
    while (next_field(t, &p, le, &fs, &fe))
        if (jf_parse_double(fs, fe, &v))
            return 0;
    return 1;
}

/* Default normals: exactly 6 fields whose 3..5 look like a unit vector. */
static int default_normals(const tab *t, const char *ls, const char *le)
{
    if (count_fields(t, ls, le) != 6)
        return 0;
    const char *p = ls, *fs, *fe;
    double v[6];
    for (int j = 0; j < 6 && next_field(t, &p, le, &fs, &fe); j++)
        if (!jf_parse_double(fs, fe, &v[j]))
            return 0;
    double n2 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5];
    return n2 >= 0.81 && n2 <= 1.21;
}

/* 1 if the row's fields, separated by blanks or ';', are numbers written
 * with a decimal comma ("-0,352 -0,698 0,736", "1,5;2,5;3,5" from a
 * European spreadsheet): each holds exactly one ',' with a digit on both
 * sides.  Read as separators they would double the columns and shift
 * every value. */
static int decimal_commas(const char *ls, const char *le)
{
    const char *p = ls, *fs, *fe;
    int n = 0;
    for (;;) {
        while (p < le && (jf_is_space(*p) || *p == ';'))
            p++;
        if (p == le)
            break;
        fs = p;
        while (p < le && !jf_is_space(*p) && *p != ';')
            p++;
        fe = p;
        const char *c = memchr(fs, ',', (size_t)(fe - fs));
        if (!c || c == fs || c + 1 == fe || memchr(c + 1, ',', (size_t)(fe - c - 1)) ||
            c[-1] < '0' || c[-1] > '9' || c[1] < '0' || c[1] > '9')
            return 0;
        n++;
    }
    return n >= 2;
}

static int set_maxcol(tab *t)
{
    t->maxcol = -1;
    for (int k = 0; k < 6; k++)
        if (t->col[k] > t->maxcol)
            t->maxcol = t->col[k];
    return t->maxcol;
}

/* Room for more rows: the arrays grow by half, up to the line count and
 * JF_MAX_POINTS.  1 done, 0 at the limit, -1 out of memory. */
static int grow_rows(jf_cloud *c, size_t *cap, size_t lines, int have_nrm)
{
    size_t lim = lines < JF_MAX_POINTS ? lines : JF_MAX_POINTS;
    if (*cap >= lim)
        return 0;
    size_t nc = *cap + *cap / 2 + 16;
    nc = nc < lim ? nc : lim;
    double *q = realloc(c->xyz, nc * 3 * sizeof *q);
    if (!q)
        return -1;
    c->xyz = q;
    if (have_nrm) {
        if (!(q = realloc(c->nrm, nc * 3 * sizeof *q)))
            return -1;
        c->nrm = q;
    }
    *cap = nc;
    return 1;
}

/* One data row [ls, le) into v (x y z nx ny nz as t->col says): 0, or
 * the length of why, the reason the row is bad, without the "row N: "
 * its caller puts first.  nf0: the first data row's width (-1: none yet);
 * fast: its rows take fast_row; *nfp: the row's fields. */
static int parse_row(const tab *t, const char *ls, const char *le, int nf0, int fast,
                     double *v, char *why, size_t wl, int *nfp)
{
    if (fast && fast_row(ls, le, nf0, v)) {
        *nfp = nf0;
        return 0;
    }
    const char *p = ls, *fs, *fe;
    int j = 0, bad = 0;
    /* rows, like lines and columns, count from 1 (docs/formats.md) */
    why[0] = '\0';
    for (; j <= t->maxcol && next_field(t, &p, le, &fs, &fe); j++) {
        for (int k = 0; k < 6 && !bad; k++) {
            if (t->col[k] != j)
                continue;
            if (fs == fe)
                bad = snprintf(why, wl, "empty field in column %d", j + 1);
            else if (!jf_parse_double(fs, fe, &v[k]))
                bad = snprintf(why, wl, "column %d: '%.*s' is not a number", j + 1,
                               (int)(fe - fs > 40 ? 40 : fe - fs), fs);
        }
    }
    int nf = j;
    while (next_field(t, &p, le, &fs, &fe))
        nf++;
    *nfp = nf;
    if (!bad && j <= t->maxcol)
        bad = snprintf(why, wl, "expected %d numbers, found %d", t->maxcol + 1, nf);
    /* a row of another width is a broken or shifted line, not data */
    if (!bad && nf0 >= 0 && nf != nf0)
        bad = !t->csv && decimal_commas(ls, le)
                  ? snprintf(why, wl, "'%.*s' has decimal commas; jetfit "
                             "reads '.' as the decimal point (sed 's/,/./g')",
                             (int)(le - ls > 40 ? 40 : le - ls), ls)
                  : snprintf(why, wl, "%d columns, the first data row has %d", nf, nf0);
    return bad;
}

/* A line holding one integer that may be a point count (PTS): its value. */
static int count_candidate(const tab *t, const char *ls, const char *le, uint64_t *cnt)
{
    const char *p = ls, *fs, *fe, *gs, *ge;
    return !t->csv && digits_first(ls, le) && next_field(t, &p, le, &fs, &fe) &&
           !next_field(t, &p, le, &gs, &ge) && jf_parse_size(fs, fe, UINT64_MAX, cnt);
}

/* The reader's running state, shared by the serial start and the merge
 * of the parallel blocks. */
typedef struct {
    size_t n, cap;           /* rows stored, room in c->xyz (c->nrm)      */
    size_t lines;            /* upper bound on rows: the file's lines     */
    size_t since_count, last_count, count_line;
    int counted;             /* a count line was seen                     */
    int have_nrm, nf0, fast;
    size_t line;             /* lines read                                */
} xstate;

/* ---- the parallel part ------------------------------------------------
 * design: once the first data row has fixed the columns and the width,
 * every later line is parsed on its own: the text is cut into blocks at
 * line ends, each thread parses blocks into their own rows, and the
 * blocks are merged in order on the calling thread.  What a line means
 * beyond itself is an event the merge settles in order: a bad row (its
 * row and line numbers, known only then; the error is the first in file
 * order, its reason parsed again from the line) and a line of one
 * integer, a PTS count line when exactly that many rows precede it since
 * the last count, else a bad row.  The rows are the serial reader's, bit
 * for bit, for every thread count. */

/* Bytes of text per block (tests make it small: jf__xyz_block_bytes). */
static size_t block_bytes = (size_t)1 << 20;

void jf__xyz_block_bytes(size_t bytes)
{
    block_bytes = bytes ? bytes : (size_t)1 << 20;
}

typedef struct {
    size_t row, line;        /* in the block, from 0 and 1               */
    const char *ls, *le;     /* the line (comment cut)                    */
    uint64_t cnt;            /* cand: its integer                         */
    int cand;                /* a line of one integer (a NaN slot)        */
} xevent;

typedef struct {
    const char *s, *e;       /* whole lines                               */
    double *xyz, *nrm, *av;  /* rows (attributes: na a row)              */
    size_t n, cap;
    xevent *ev;
    size_t nev, evcap;
    size_t lines;
    unsigned char *text;     /* per attribute: a word seen                */
    int nomem;
} xblock;

static void block_free(xblock *b)
{
    free(b->xyz);
    free(b->nrm);
    free(b->av);
    free(b->ev);
    free(b->text);
}

static int block_room(xblock *b, int have_nrm, int na)
{
    size_t nc = b->cap ? 2 * b->cap : 4096;
    double *q = realloc(b->xyz, nc * 3 * sizeof *q);
    if (!q)
        return 0;
    b->xyz = q;
    if (have_nrm) {
        if (!(q = realloc(b->nrm, nc * 3 * sizeof *q)))
            return 0;
        b->nrm = q;
    }
    if (na) {
        if (!(q = realloc(b->av, nc * (size_t)na * sizeof *q)))
            return 0;
        b->av = q;
    }
    b->cap = nc;
    return 1;
}

/* Parses block b (one thread).  Error mode stops at the first bad row
 * that is not a line of one integer: nothing after it matters. */
static void parse_block(const tab *t0, const xstate *s, xblock *b, int skip)
{
    tab t = *t0;
    t.hash = NULL;
    t.tend = b->e;
    const int na = t.ta ? t.ta->na : 0;
    jf_text tx = {b->s, b->e, 0, !memchr(b->s, '\r', (size_t)(b->e - b->s))};
    const char *ls, *le;
    b->n = b->nev = 0;
    b->nomem = 0;
    if (na)
        memset(b->text, 0, (size_t)na);
    while (jf_text_line(&tx, &ls, &le)) {
        if (!strip_comment(&t, ls, &le))
            continue;
        double v[6];
        char why[160];
        int nf, bad;
        uint64_t cnt = 0;
        /* a count is possible only after a count (the first data row is
         * behind us) */
        int cand = s->counted && count_candidate(&t, ls, le, &cnt);
        bad = cand || parse_row(&t, ls, le, s->nf0, s->fast, v, why, sizeof why, &nf);
        if (bad) {
            if (b->nev == b->evcap) {
                size_t nc = b->evcap ? 2 * b->evcap : 64;
                xevent *q = realloc(b->ev, nc * sizeof *q);
                if (!q) {
                    b->nomem = 1;
                    break;
                }
                b->ev = q;
                b->evcap = nc;
            }
            b->ev[b->nev++] = (xevent){b->n, tx.line, ls, le, cnt, cand};
            if (!cand && !skip)
                break;
            for (int k = 0; k < 6; k++)
                v[k] = NAN;
        }
        if (b->n == b->cap && !block_room(b, s->have_nrm, na)) {
            b->nomem = 1;
            break;
        }
        memcpy(b->xyz + 3 * b->n, v, 3 * sizeof(double));
        if (s->have_nrm)
            memcpy(b->nrm + 3 * b->n, v + 3, 3 * sizeof(double));
        if (na)
            attrs_fill(&t, b->av + b->n * (size_t)na, b->text, ls, le, bad);
        b->n++;
    }
    b->lines = tx.line;
}

/* Appends rows [from, to) of block b to the cloud. */
static jf_status take_rows(const tab *t, xstate *s, const xblock *b, size_t from, size_t to,
                           jf_cloud *c)
{
    size_t k = to - from;
    if (!k)
        return JF_OK;
    while (s->cap < s->n + k) {
        int room = grow_rows(c, &s->cap, s->lines, s->have_nrm);
        if (room <= 0)
            return room < 0 ? jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0,
                                         "out of memory for %zu points", s->n + k)
                            : jf_io_fail(t->err, JF_ERR_TOO_LARGE, t->name, 0,
                                         "more than %zu rows", (size_t)JF_MAX_POINTS);
    }
    memcpy(c->xyz + 3 * s->n, b->xyz + 3 * from, 3 * k * sizeof(double));
    if (s->have_nrm)
        memcpy(c->nrm + 3 * s->n, b->nrm + 3 * from, 3 * k * sizeof(double));
    if (t->ta) {
        size_t na = (size_t)t->ta->na;
        if (!attrs_room(t->ta, s->n + k))
            return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0, "out of memory");
        memcpy(t->ta->v + s->n * na, b->av + from * na, k * na * sizeof(double));
    }
    s->n += k;
    s->since_count += k;
    return JF_OK;
}

/* Block b's rows after the cloud's, its events settled in order. */
static jf_status merge_block(const tab *t, xstate *s, const xblock *b, int skip, jf_cloud *c)
{
    size_t seg = 0; /* rows of b not taken yet start here */
    jf_status st;
    for (size_t i = 0; i < b->nev; i++) {
        const xevent *e = &b->ev[i];
        if (e->cand && s->since_count + (e->row - seg) == s->last_count) {
            if ((st = take_rows(t, s, b, seg, e->row, c)) != JF_OK)
                return st;
            s->last_count = (size_t)e->cnt;
            s->count_line = s->line + e->line;
            s->since_count = 0;
            seg = e->row + 1; /* a count line is not a row */
            continue;
        }
        if (!skip) {
            double v[6];
            char why[160];
            int nf;
            parse_row(t, e->ls, e->le, s->nf0, s->fast, v, why, sizeof why, &nf);
            return jf_io_fail(t->err, JF_ERR_FORMAT, t->name, s->line + e->line, "row %zu: %s",
                              s->n + (e->row - seg) + 1, why);
        }
        /* --bad-rows skip: its NaN row is in the block */
        if (c->nbad < sizeof c->bad_line / sizeof c->bad_line[0])
            c->bad_line[c->nbad] = s->line + e->line;
        c->nbad++;
    }
    if (b->nomem)
        return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0, "out of memory for %zu points",
                          s->n + b->n);
    if ((st = take_rows(t, s, b, seg, b->n, c)) != JF_OK)
        return st;
    if (t->ta)
        for (int k = 0; k < t->ta->na; k++)
            t->ta->text[k] |= b->text[k];
    s->line += b->lines;
    return JF_OK;
}

/* The text [p, end): blocks handed out one at a time, each parsed by a
 * thread into its own rows, then merged in order (ordered) while the
 * other threads parse the next ones; no round barrier. */
static jf_status read_blocks(const tab *t, xstate *s, const char *p, const char *end, int nt,
                             int skip, jf_cloud *c, const jf_read_opts *o, const char *buf0,
                             size_t off0, size_t total)
{
    const int na = t->ta ? t->ta->na : 0;
    size_t nblk = 0, cap = 0;
    const char **cut = NULL;
    for (const char *q = p; q < end; nblk++) { /* the blocks' ends, at line ends */
        const char *e = (size_t)(end - q) > block_bytes ? q + block_bytes : end;
        if (e < end) {
            const char *nl = memchr(e - 1, '\n', (size_t)(end - e + 1));
            e = nl ? nl + 1 : end;
        }
        if (nblk + 2 > cap) {
            cap = cap ? 2 * cap : 256;
            const char **g = realloc(cut, cap * sizeof *g);
            if (!g) {
                free(cut);
                return jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0, "out of memory");
            }
            cut = g;
        }
        cut[nblk] = q;
        q = e;
        cut[nblk + 1] = e;
    }
    xblock *bl = calloc((size_t)nt, sizeof *bl);
    int ok = bl != NULL;
    for (int i = 0; ok && i < nt; i++)
        ok = !na || (bl[i].text = malloc((size_t)na)) != NULL;
    jf_status st = ok ? JF_OK : jf_io_fail(t->err, JF_ERR_NOMEM, t->name, 0, "out of memory");
    const xstate s0 = *s; /* what the parsers read; the merge changes s */
    int stop = st != JF_OK;
#pragma omp parallel num_threads(nt) if (ok)
    {
        const int tid = omp_get_thread_num();
        xblock *b = ok ? &bl[tid] : NULL;
#pragma omp for schedule(dynamic, 1) ordered
        for (size_t i = 0; i < nblk; i++) {
            int halt;
#pragma omp atomic read
            halt = stop;
            if (!halt) {
                b->s = cut[i];
                b->e = cut[i + 1];
                parse_block(t, &s0, b, skip);
            }
#pragma omp ordered
            if (!halt && st == JF_OK) {
                st = merge_block(t, s, b, skip, c);
                if (st != JF_OK) {
#pragma omp atomic write
                    stop = 1;
                } else if (tid == 0 && o->progress) { /* the calling thread */
                    o->progress(o->progress_user, JF_PHASE_READ,
                                off0 + (size_t)(cut[i + 1] - buf0), total);
                }
            }
        }
    }
    for (int i = 0; bl && i < nt; i++)
        block_free(&bl[i]);
    free(bl);
    free(cut);
    return st;
}

static jf_status read_xyz(const char *buf, size_t len, jf_format fmt,
                         const char *name, const jf_read_opts *o, jf_cloud *c,
                         jf_error *err, text_attrs *ta, jf_pieces *src, int *declined)
{
    tab t = {name, err, fmt == JF_FMT_CSV, {-1, -1, -1, -1, -1, -1}, -1, ta, NULL, NULL};
    int setx = 0, setn = 0;
    for (int k = 0; k < 6; k++) {
        if (o->columns[k] < -1 || o->columns[k] > 4095)
            return jf_io_fail(err, JF_ERR_INVALID, name, 0,
                              "column %d out of range", o->columns[k]);
        if (o->columns[k] >= 0)
            *(k < 3 ? &setx : &setn) += 1;
        t.col[k] = o->columns[k];
    }
    if ((setx != 0 && setx != 3) || (setn != 0 && setn != 3))
        return jf_io_fail(err, JF_ERR_INVALID, name, 0,
                          "columns: give all of x,y,z (and of nx,ny,nz) or "
                          "none");
    const char *const buf0 = buf;
    const size_t total = src ? src->len : len;
    /* upper bound on data rows: the lines, and the bytes (a row of m
     * needed fields takes at least 2m, separators and newline included) */
    /* a UTF-8 byte order mark (spreadsheet exports) is not data */
    if (len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3))
        buf += 3, len -= 3;
    const int nt = o->threads > 0 ? o->threads : jf_default_threads(NULL);
    size_t lines = 1, crs = 0;
    /* counted in nt slices on the threads (a pass over the whole text);
     * lone-CR line ends too */
#pragma omp parallel for num_threads(nt) reduction(+ : lines, crs) schedule(static, 1)
    for (int k = 0; k < nt; k++) {
        const char *q = buf + len / (size_t)nt * (size_t)k,
                   *e = k == nt - 1 ? buf + len : buf + len / (size_t)nt * (size_t)(k + 1);
        lines += count_byte(q, (size_t)(e - q), '\n');
        crs += count_byte(q, (size_t)(e - q), '\r');
    }
    lines += crs;
    /* in pieces (src: buf is the first): the rows estimated from the first
     * piece's lines, the arrays grow past it; the lines bounded by bytes */
    size_t est = lines;
    if (src) {
        est = (size_t)((double)lines * ((double)src->len / (double)(len ? len : 1)) * 1.0625) +
              1024;
        lines = src->len + 1;
    }
    /* no '\r' anywhere: the per-line search for it is skipped */
    t.tend = buf + len;
    jf_text tx = {buf, buf + len, 0, crs == 0};
    const char *ls, *le;
    int started = 0;
    xstate s = {0, 0, lines, 0, 0, 0, 0, 0, -1, 0, 0};
    const int skip = o->bad_rows == 1;
    for (size_t r = 0;; r++) {
        /* the columns and width are known: the rest in parallel blocks */
        if ((nt > 1 || src) && s.nf0 >= 0 && (src || (size_t)(tx.end - tx.p) > 2 * block_bytes))
            break;
        if (!jf_text_line(&tx, &ls, &le))
            break;
        if (o->progress && (r & 0xFFFF) == 0xFFFF)
            o->progress(o->progress_user, JF_PHASE_READ, (size_t)(tx.p - buf0), total);
        if (!strip_comment(&t, ls, &le))
            continue;
        /* a point count line (PTS) */
        uint64_t cnt;
        if (count_candidate(&t, ls, le, &cnt) &&
            (!s.counted ? s.n == 0 : s.since_count == s.last_count)) {
            s.counted = 1;
            s.count_line = tx.line;
            s.last_count = (size_t)cnt;
            s.since_count = 0;
            continue;
        }
        if (!started) {
            /* the first data line decides the columns */
            started = 1;
            if (!t.csv && decimal_commas(ls, le))
                return jf_io_fail(err, JF_ERR_FORMAT, name, tx.line,
                                  "'%.*s' has decimal commas; jetfit reads '.' as the decimal "
                                  "point (convert with: sed 's/,/./g')",
                                  (int)(le - ls > 40 ? 40 : le - ls), ls);
            /* csv: a header unless all numbers; xyz: a line of names
             * only ("X Y Z", "x y z nx ny nz") */
            int header = t.csv ? !all_numeric(&t, ls, le)
                               : none_numeric(&t, ls, le);
            if (header) {
                jf_status st = csv_header(&t, ls, le, tx.line,
                                          (setx ? 0 : 1) | (setn ? 0 : 2));
                if (st != JF_OK)
                    return st;
                if (ta && !ta->na)
                    t.ta = ta = NULL; /* only x y z are named */
            } else {
                t.ta = ta = NULL; /* no names: nothing to carry */
                if (!setx)
                    t.col[0] = 0, t.col[1] = 1, t.col[2] = 2;
                if (!setn && fmt != JF_FMT_PTS && default_normals(&t, ls, le))
                    t.col[3] = 3, t.col[4] = 4, t.col[5] = 5;
            }
            set_maxcol(&t);
            s.have_nrm = t.col[3] >= 0;
            s.cap = ((src ? src->len : len) + 1) / (2 * (size_t)(t.maxcol + 1));
            s.cap = s.cap < est ? s.cap : est;
            s.cap = s.cap < JF_MAX_POINTS ? s.cap : JF_MAX_POINTS;
            c->xyz = jf__big_alloc(s.cap * 3 * sizeof(double)); /* written whole */
            c->nrm = s.have_nrm ? jf__big_alloc(s.cap * 3 * sizeof(double)) : NULL;
            if (!c->xyz || (s.have_nrm && !c->nrm))
                return jf_io_fail(err, JF_ERR_NOMEM, name, 0,
                                  "out of memory for %zu points", s.cap);
            if (header)
                continue;
        }
        double v[6];
        char why[160];
        int nf, room;
        int bad = parse_row(&t, ls, le, s.nf0, s.fast, v, why, sizeof why, &nf);
        if (bad && !skip)
            return jf_io_fail(err, JF_ERR_FORMAT, name, tx.line, "row %zu: %s", s.n + 1, why);
        if (bad) { /* --bad-rows skip: a NaN row keeps every later index */
            if (c->nbad < sizeof c->bad_line / sizeof c->bad_line[0])
                c->bad_line[c->nbad] = tx.line;
            c->nbad++;
            for (int k = 0; k < 6; k++)
                v[k] = NAN;
        } else if (s.nf0 < 0) {
            s.nf0 = nf;
            s.fast = !t.csv && !ta && s.nf0 == t.maxcol + 1 && in_order(&t);
            /* the rows are narrower than the header: its last names
             * name nothing */
            if (ta)
                for (int jj = nf; jj < ta->ncols; jj++)
                    if (ta->acol[jj] >= 0)
                        ta->text[ta->acol[jj]] = 1;
        }
        if (ta && !text_attrs_row(&t, s.n, ls, le, bad))
            return jf_io_fail(err, JF_ERR_NOMEM, name, tx.line, "out of memory");
        /* rows that parse fit the byte bound; bad rows kept as NaN under
         * --bad-rows skip can be shorter ("4 5"): only the line count
         * bounds them, so the arrays grow up to it */
        if (s.n == s.cap && (room = grow_rows(c, &s.cap, lines, s.have_nrm)) <= 0)
            return room < 0 ? jf_io_fail(err, JF_ERR_NOMEM, name, tx.line,
                                         "out of memory for %zu points", s.n + 1)
                            : jf_io_fail(err, JF_ERR_TOO_LARGE, name, tx.line,
                                         "more than %zu rows", (size_t)JF_MAX_POINTS);
        memcpy(c->xyz + 3 * s.n, v, 3 * sizeof(double));
        if (s.have_nrm)
            memcpy(c->nrm + 3 * s.n, v + 3, 3 * sizeof(double));
        s.n++;
        s.since_count++;
    }
    s.line = tx.line;
    if (src && s.nf0 < 0 && (src->got < src->len || src->re < src->have)) {
        *declined = 1; /* the first piece did not settle the columns */
        return JF_OK;
    }
    if (src && ta) { /* the header's names outlive the first piece */
        size_t all = 1;
        for (int j = 0; j < ta->ncols; j++)
            all += ta->nml[j];
        if (!(ta->own = malloc(all)))
            return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
        char *q = ta->own;
        for (int j = 0; j < ta->ncols; q += ta->nml[j++]) {
            memcpy(q, ta->nm[j], ta->nml[j]);
            ta->nm[j] = q;
        }
    }
    if (tx.p < tx.end) {
        jf_status st = read_blocks(&t, &s, tx.p, tx.end, nt, skip, c, o, buf0, 0, total);
        if (st != JF_OK)
            return st;
    }
    while (src) { /* the next pieces' whole lines, in order */
        jf_status st = jf__pieces_next(src, err);
        if (st == JF_OK && src->re)
            st = read_blocks(&t, &s, src->buf, src->buf + src->re, nt, skip, c, o, src->buf,
                             src->off, src->len);
        if (st != JF_OK)
            return st;
        if (!src->re)
            break;
    }
    size_t n = s.n;
    if (s.counted && s.since_count != s.last_count)
        return jf_io_fail(err, JF_ERR_FORMAT, name, s.count_line,
                          "the count line says %zu points, %zu rows follow it", s.last_count,
                          s.since_count);
    if (n == 0 || n == c->nbad)
        return jf_io_fail(err, JF_ERR_FORMAT, name, s.line ? s.line : 0,
                          "no points in the file");
    c->n = n;
    /* give back the unused tail of the estimate */
    double *q = realloc(c->xyz, n * 3 * sizeof(double));
    if (q)
        c->xyz = q;
    if (s.have_nrm && (q = realloc(c->nrm, n * 3 * sizeof(double))) != NULL)
        c->nrm = q;
    return ta ? text_attrs_pack(&t, n, c) : JF_OK;
}

jf_status jf_read_xyz(const char *buf, size_t len, jf_format fmt,
                      const char *name, const jf_read_opts *o, jf_cloud *c,
                      jf_error *err)
{
    text_attrs ta = {0};
    ta.maxcol = -1;
    jf_status st = read_xyz(buf, len, fmt, name, o, c, err, o->no_attrs ? NULL : &ta, NULL,
                            NULL);
    free(ta.nm);
    free(ta.nml);
    free(ta.acol);
    free(ta.v);
    free(ta.text);
    return st;
}

/* ---- in pieces ---------------------------------------------------------
 * design: a large text file is read a piece of whole lines at a time into
 * one reused buffer (jf_pieces), the partial last line carried to the
 * next; the first piece goes through the serial start (header, columns,
 * first data row), every later line through read_blocks, whose rows and
 * messages are those of the whole-buffer read.  No image of the file: its
 * fresh pages were a zeroing by the kernel of as many bytes as the file. */

static size_t piece_bytes = (size_t)8 << 20;

void jf__xyz_piece_bytes(size_t bytes)
{
    piece_bytes = bytes ? bytes : (size_t)8 << 20;
}

jf_status jf__read_xyz_fd(int fd, size_t len, jf_format fmt, const char *name,
                          const jf_read_opts *o, jf_cloud *c, jf_error *err, int *declined)
{
    *declined = len <= 2 * piece_bytes;
    if (*declined)
        return JF_OK;
    jf_read_opts def;
    if (!o) {
        jf_read_opts_init(&def);
        o = &def;
    }
    if (o->progress)
        o->progress(o->progress_user, JF_PHASE_READ, 0, len);
    jf_pieces p = {fd, name, len, piece_bytes, NULL, 0, 0, 0, 0, 0};
    text_attrs ta = {0};
    ta.maxcol = -1;
    jf_status st = jf__pieces_next(&p, err);
    if (st == JF_OK)
        st = read_xyz(p.buf, p.re, fmt, name, o, c, err, o->no_attrs ? NULL : &ta, &p,
                      declined);
    free(ta.nm);
    free(ta.nml);
    free(ta.acol);
    free(ta.v);
    free(ta.text);
    free(ta.own);
    if (st != JF_OK) { /* an I/O error or a NUL later in the file comes first */
        jf_status ds = jf__pieces_drain(&p, err);
        st = ds != JF_OK ? ds : st;
    }
    free(p.buf);
    if (st != JF_OK || *declined)
        jf_cloud_free(c);
    else if (o->progress)
        o->progress(o->progress_user, JF_PHASE_READ, len, len);
    return st;
}
