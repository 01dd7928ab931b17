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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
} text_attrs;

typedef struct {
    const char *name;
    jf_error *err;
    int csv;        /* fields split at ',' only (else whitespace , ;) */
    int col[6];     /* column of x y z nx ny nz, -1 = not read */
    int maxcol;     /* largest column needed */
    text_attrs *ta; /* NULL: attributes not wanted */
    int no_hash;    /* no '#' in the whole text */
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
static int strip_comment(const tab *t, const char *ls, const char **le)
{
    const char *q = ls;
    while (q < *le && jf_is_space(*q))
        q++;
    if (q == *le || *q == '#' || (*le - q >= 2 && q[0] == '/' && q[1] == '/'))
        return 0;
    if (!t->csv && !t->no_hash) {
        const char *h = memchr(q, '#', (size_t)(*le - q));
        if (h)
            *le = h;
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

/* Attribute values of row n: fields [0, maxcol] of the line (NaN when the
 * row is bad or a field is empty; a field that is not a number marks its
 * column as text). */
static int text_attrs_row(const tab *t, size_t n, const char *ls, const char *le, int bad)
{
    text_attrs *ta = t->ta;
    if (n >= ta->rows_cap) {
        size_t cap = ta->rows_cap ? 2 * ta->rows_cap : 1024;
        double *q = realloc(ta->v, cap * (size_t)ta->na * sizeof *q);
        if (!q)
            return 0;
        ta->v = q;
        ta->rows_cap = cap;
    }
    double *v = ta->v + n * (size_t)ta->na;
    for (int k = 0; k < ta->na; k++)
        v[k] = NAN;
    if (bad)
        return 1;
    const char *p = ls, *fs, *fe;
    for (int j = 0; j <= ta->maxcol && next_field(t, &p, le, &fs, &fe); j++) {
        int k = ta->acol[j];
        if (k >= 0 && fs < fe && !jf_parse_double(fs, fe, &v[k]))
            ta->text[k] = 1;
    }
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

static jf_status read_xyz(const char *buf, size_t len, jf_format fmt,
                         const char *name, const jf_read_opts *o, jf_cloud *c,
                         jf_error *err, text_attrs *ta)
{
    tab t = {name, err, fmt == JF_FMT_CSV, {-1, -1, -1, -1, -1, -1}, -1, ta, 0};
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
    /* upper bound on data rows: the lines, and the bytes (a row of m
     * needed fields takes at least 2m, separators and newline included) */
    /* a UTF-8 byte order mark (spreadsheet exports) is not data */
    if (len >= 3 && !memcmp(buf, "\xEF\xBB\xBF", 3))
        buf += 3, len -= 3;
    size_t lines = 1, crs = 0;
    for (const char *q = buf, *e = buf + len;
         (q = memchr(q, '\n', (size_t)(e - q))) != NULL; q++)
        lines++;
    for (const char *q = buf, *e = buf + len; /* lone-CR line ends too */
         (q = memchr(q, '\r', (size_t)(e - q))) != NULL; q++)
        crs++;
    lines += crs;
    /* no '\r' or '#' anywhere: the per-line searches for them are skipped */
    t.no_hash = !memchr(buf, '#', len);
    size_t cap = 0;
    jf_text tx = {buf, buf + len, 0, crs == 0};
    const char *ls, *le;
    int started = 0, have_nrm = 0;
    size_t n = 0, since_count = 0, last_count = 0;
    int counted = 0, nf0 = -1, fast = 0;
    size_t count_line = 0;
    const int skip = o->bad_rows == 1;
    while (jf_text_line(&tx, &ls, &le)) {
        if (!strip_comment(&t, ls, &le))
            continue;
        /* a point count line (PTS) */
        if (!t.csv && digits_first(ls, le)) {
            const char *p = ls, *fs, *fe, *gs, *ge;
            uint64_t cnt;
            if (next_field(&t, &p, le, &fs, &fe) &&
                !next_field(&t, &p, le, &gs, &ge) &&
                jf_parse_size(fs, fe, UINT64_MAX, &cnt) &&
                (!counted ? n == 0 : since_count == last_count)) {
                counted = 1;
                count_line = tx.line;
                last_count = (size_t)cnt;
                since_count = 0;
                continue;
            }
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
            have_nrm = t.col[3] >= 0;
            cap = (len + 1) / (2 * (size_t)(t.maxcol + 1));
            cap = cap < lines ? cap : lines;
            cap = cap < JF_MAX_POINTS ? cap : JF_MAX_POINTS;
            c->xyz = malloc(cap * 3 * sizeof(double));
            c->nrm = have_nrm ? malloc(cap * 3 * sizeof(double)) : NULL;
            if (!c->xyz || (have_nrm && !c->nrm))
                return jf_io_fail(err, JF_ERR_NOMEM, name, 0,
                                  "out of memory for %zu points", cap);
            if (header)
                continue;
        }
        double v[6];
        int room;
        if (fast && fast_row(ls, le, nf0, v))
            goto store;
        const char *p = ls, *fs, *fe;
        int j = 0, bad = 0;
        char why[160]; /* rows, like lines and columns, count from 1 (docs/formats.md) */
        why[0] = '\0';
        for (; j <= t.maxcol && next_field(&t, &p, le, &fs, &fe); j++) {
            for (int k = 0; k < 6 && !bad; k++) {
                if (t.col[k] != j)
                    continue;
                if (fs == fe)
                    bad = snprintf(why, sizeof why, "row %zu: empty field in column %d", n + 1,
                                   j + 1);
                else if (!jf_parse_double(fs, fe, &v[k]))
                    bad = snprintf(why, sizeof why, "row %zu: column %d: '%.*s' is not a number",
                                   n + 1, j + 1, (int)(fe - fs > 40 ? 40 : fe - fs), fs);
            }
        }
        int nf = j;
        while (next_field(&t, &p, le, &fs, &fe))
            nf++;
        if (!bad && j <= t.maxcol)
            bad = snprintf(why, sizeof why, "row %zu: expected %d numbers, found %d", n + 1,
                           t.maxcol + 1, nf);
        /* a row of another width is a broken or shifted line, not data */
        if (!bad && nf0 >= 0 && nf != nf0)
            bad = !t.csv && decimal_commas(ls, le)
                      ? snprintf(why, sizeof why, "row %zu: '%.*s' has decimal commas; jetfit "
                                 "reads '.' as the decimal point (sed 's/,/./g')", n + 1,
                                 (int)(le - ls > 40 ? 40 : le - ls), ls)
                      : snprintf(why, sizeof why, "row %zu: %d columns, the first data row has %d",
                                 n + 1, nf, nf0);
        if (bad && !skip)
            return jf_io_fail(err, JF_ERR_FORMAT, name, tx.line, "%s", why);
        if (bad) { /* --bad-rows skip: a NaN row keeps every later index */
            if (c->nbad < sizeof c->bad_line / sizeof c->bad_line[0])
                c->bad_line[c->nbad] = tx.line;
            c->nbad++;
            for (int k = 0; k < 6; k++)
                v[k] = NAN;
        } else if (nf0 < 0) {
            nf0 = nf;
            fast = !t.csv && !ta && nf0 == t.maxcol + 1 && in_order(&t);
            /* the rows are narrower than the header: its last names
             * name nothing */
            if (ta)
                for (int jj = nf; jj < ta->ncols; jj++)
                    if (ta->acol[jj] >= 0)
                        ta->text[ta->acol[jj]] = 1;
        }
        if (ta && !text_attrs_row(&t, n, ls, le, bad))
            return jf_io_fail(err, JF_ERR_NOMEM, name, tx.line, "out of memory");
    store:
        /* rows that parse fit the byte bound; bad rows kept as NaN under
         * --bad-rows skip can be shorter ("4 5"): only the line count
         * bounds them, so the arrays grow up to it */
        if (n == cap && (room = grow_rows(c, &cap, lines, have_nrm)) <= 0)
            return room < 0 ? jf_io_fail(err, JF_ERR_NOMEM, name, tx.line,
                                         "out of memory for %zu points", n + 1)
                            : jf_io_fail(err, JF_ERR_TOO_LARGE, name, tx.line,
                                         "more than %zu rows", (size_t)JF_MAX_POINTS);
        memcpy(c->xyz + 3 * n, v, 3 * sizeof(double));
        if (have_nrm)
            memcpy(c->nrm + 3 * n, v + 3, 3 * sizeof(double));
        n++;
        since_count++;
    }
    if (counted && since_count != last_count)
        return jf_io_fail(err, JF_ERR_FORMAT, name, count_line,
                          "the count line says %zu points, %zu rows follow it", last_count,
                          since_count);
    if (n == 0 || n == c->nbad)
        return jf_io_fail(err, JF_ERR_FORMAT, name, tx.line ? tx.line : 0,
                          "no points in the file");
    c->n = n;
    /* give back the unused tail of the estimate */
    double *q = realloc(c->xyz, n * 3 * sizeof(double));
    if (q)
        c->xyz = q;
    if (have_nrm && (q = realloc(c->nrm, n * 3 * sizeof(double))) != NULL)
        c->nrm = q;
    return ta ? text_attrs_pack(&t, n, c) : JF_OK;
}

jf_status jf_read_xyz(const char *buf, size_t len, jf_format fmt,
                      const char *name, const jf_read_opts *o, jf_cloud *c,
                      jf_error *err)
{
    text_attrs ta = {0};
    ta.maxcol = -1;
    jf_status st = read_xyz(buf, len, fmt, name, o, c, err, o->no_attrs ? NULL : &ta);
    free(ta.nm);
    free(ta.nml);
    free(ta.acol);
    free(ta.v);
    free(ta.text);
    return st;
}
