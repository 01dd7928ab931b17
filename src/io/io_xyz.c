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

typedef struct {
    const char *name;
    jf_error *err;
    int csv;        /* fields split at ',' only (else whitespace , ;) */
    int col[6];     /* column of x y z nx ny nz, -1 = not read */
    int maxcol;     /* largest column needed */
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

/* The row without a comment: [ls, *le) shortened; 0 if nothing is left. */
static int strip_comment(const tab *t, const char *ls, const char **le)
{
    const char *q = ls;
    while (q < *le && jf_is_space(*q))
        q++;
    if (q == *le || *q == '#' || (*le - q >= 2 && q[0] == '/' && q[1] == '/'))
        return 0;
    if (!t->csv) {
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
    for (int j = 0; next_field(t, &p, le, &fs, &fe); j++) {
        if (fe - fs >= 2 && (*fs == '"' || *fs == '\'') && fe[-1] == *fs) {
            fs++;
            fe--;
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

jf_status jf_read_xyz(const char *buf, size_t len, jf_format fmt,
                      const char *name, const jf_read_opts *o, jf_cloud *c,
                      jf_error *err)
{
    tab t = {name, err, fmt == JF_FMT_CSV, {-1, -1, -1, -1, -1, -1}, -1};
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
    size_t lines = 1;
    for (const char *q = buf, *e = buf + len;
         (q = memchr(q, '\n', (size_t)(e - q))) != NULL; q++)
        lines++;
    for (const char *q = buf, *e = buf + len; /* lone-CR line ends too */
         (q = memchr(q, '\r', (size_t)(e - q))) != NULL; q++)
        lines++;
    size_t cap = 0;
    jf_text tx = {buf, buf + len, 0};
    const char *ls, *le;
    int started = 0, have_nrm = 0;
    size_t n = 0, since_count = 0, last_count = 0;
    int counted = 0, nf0 = -1;
    size_t count_line = 0;
    const int skip = o->bad_rows == 1;
    while (jf_text_line(&tx, &ls, &le)) {
        if (!strip_comment(&t, ls, &le))
            continue;
        /* a point count line (PTS) */
        if (!t.csv) {
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
            } else {
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
        const char *p = ls, *fs, *fe;
        double v[6];
        int j = 0, bad = 0;
        char why[160] = "";
        for (; j <= t.maxcol && next_field(&t, &p, le, &fs, &fe); j++) {
            for (int k = 0; k < 6 && !bad; k++) {
                if (t.col[k] != j)
                    continue;
                if (fs == fe)
                    bad = snprintf(why, sizeof why, "row %zu: empty field in column %d", n,
                                   j + 1);
                else if (!jf_parse_double(fs, fe, &v[k]))
                    bad = snprintf(why, sizeof why, "row %zu: column %d: '%.*s' is not a number",
                                   n, j + 1, (int)(fe - fs > 40 ? 40 : fe - fs), fs);
            }
        }
        int nf = j;
        while (next_field(&t, &p, le, &fs, &fe))
            nf++;
        if (!bad && j <= t.maxcol)
            bad = snprintf(why, sizeof why, "row %zu: expected %d numbers, found %d", n,
                           t.maxcol + 1, nf);
        /* a row of another width is a broken or shifted line, not data */
        if (!bad && nf0 >= 0 && nf != nf0)
            bad = !t.csv && decimal_commas(ls, le)
                      ? snprintf(why, sizeof why, "row %zu: '%.*s' has decimal commas; jetfit "
                                 "reads '.' as the decimal point (sed 's/,/./g')", n,
                                 (int)(le - ls > 40 ? 40 : le - ls), ls)
                      : snprintf(why, sizeof why, "row %zu: %d columns, the first data row has %d",
                                 n, nf, nf0);
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
        }
        if (n == cap) /* cannot happen for rows that parse: the bound */
            return jf_io_fail(err, JF_ERR_TOO_LARGE, name, tx.line,
                              "more rows than supported");
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
    return JF_OK;
}
