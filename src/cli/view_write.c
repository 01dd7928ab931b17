/* view_write.c -- the page of `jetfit view`: read a result table, choose
 * and pack its columns, write the template with three.js, the metadata
 * (JSON) and one base64 block per column inlined.
 *
 * design: rows with finite x y z are put in a spatially even order
 * (view_sample.c); the first --max-points are drawn, so a subsample keeps
 * the cloud's extent, and the first --glyphs carry the glyphs.  Every
 * block is indexed by drawn point; "rows" gives each its row in RESULT. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "view.h"

void jf_view_opts_init(jf_view_opts *o)
{
    memset(o, 0, sizeof *o);
    o->max_points = 2000000;
    o->glyphs = 3000;
}

static const char *const enc_name[] = {"pos", "oct", "f16", "log16", "u8", "u16", "u32"};

/* The unit a column's colour bar is labelled with: jetfit's own columns
 * are in the cloud's length unit ("u"); the input's are as in the file. */
static const char *unit_of(const char *n)
{
    static const struct { const char *name, *unit; } u[] = {
        {"k1", "1/u"}, {"k2", "1/u"}, {"residual", "u"}, {"sigma", "u"},
        {"cond", "ratio"}, {"degree", "degree"}, {"neighbors", "points"},
        {"status", "flags"}, {"b0", "1/u^2"}, {"b1", "1/u^2"}, {"b2", "1/u^2"},
        {"b3", "1/u^2"}, {"c0", "1/u^3"}, {"c1", "1/u^3"}, {"c2", "1/u^3"},
        {"c3", "1/u^3"}, {"c4", "1/u^3"}};
    for (size_t i = 0; i < sizeof u / sizeof u[0]; i++)
        if (!strcmp(n, u[i].name)) return u[i].unit;
    return "";
}

static int is_monge(const char *n)
{
    return (n[0] == 'b' && n[1] >= '0' && n[1] <= '3' && !n[2]) ||
           (n[0] == 'c' && n[1] >= '0' && n[1] <= '4' && !n[2]);
}

typedef struct {
    jf_view_col *c;
    size_t n;
} colset;

/* The columns of the page: x y z, the triplets as unit vectors, every
 * other named scalar (Monge coefficients only with all_columns). */
static int choose_columns(const jf_eval_table *t, const jf_view_opts *o, colset *cs)
{
    static const char *const trip[][4] = {{"x", "y", "z", "pos"}, {"nx", "ny", "nz", "normal"},
                                          {"d1x", "d1y", "d1z", "d1"}, {"d2x", "d2y", "d2z", "d2"}};
    cs->c = calloc(t->ncols + 1, sizeof *cs->c);
    unsigned char *used = calloc(t->ncols + 1, 1);
    if (!cs->c || !used) { free(used); return -1; }
    cs->n = 0;
    for (int k = 0; k < 4; k++) {
        int a = jf_eval_table_col(t, trip[k][0]), b = jf_eval_table_col(t, trip[k][1]),
            c = jf_eval_table_col(t, trip[k][2]);
        if (a < 0 || b != a + 1 || c != a + 2) continue;
        jf_view_col *v = &cs->c[cs->n++];
        snprintf(v->name, sizeof v->name, "%s", trip[k][3]);
        v->col = a;
        v->enc = k ? JF_VE_OCT : JF_VE_POS;
        v->bytes = k ? 2 : 6;
        used[a] = used[b] = used[c] = 1;
    }
    for (size_t j = 0; j < t->ncols; j++) {
        if (used[j] || (!o->all_columns && is_monge(t->names[j]))) continue;
        jf_view_col *v = &cs->c[cs->n++];
        /* the page's own names (triplets, derived columns) stay unique */
        static const char *const own[] = {"pos", "normal", "d1", "d2", "mean", "gauss", "rgb"};
        int clash = 0;
        for (size_t k = 0; k < sizeof own / sizeof own[0]; k++) clash |= !strcmp(t->names[j], own[k]);
        if (t->names[j][0] && !clash) snprintf(v->name, sizeof v->name, "%s", t->names[j]);
        else if (clash) snprintf(v->name, sizeof v->name, "%s (column %zu)", t->names[j], j + 1);
        else snprintf(v->name, sizeof v->name, "column %zu", j + 1);
        v->col = (int)j;
        v->enc = JF_VE_F16; /* chosen over the drawn rows later */
    }
    free(used);
    return 0;
}

static void put_template(FILE *f, const char *tpl, const char *title, const jf_view_three *th,
                         void (*data)(FILE *, void *), void *user)
{
    for (const char *p = tpl; *p;) {
        const char *q = strstr(p, "{{");
        if (!q) { fputs(p, f); break; }
        fwrite(p, 1, (size_t)(q - p), f);
        if (!strncmp(q, "{{TITLE}}", 9)) jf_view_html(f, title), p = q + 9;
        else if (!strncmp(q, "{{THREE}}", 9)) {
            jf_view_inline_js(f, th->lib);
            fputs("\n</script>\n<script>\n", f);
            jf_view_inline_js(f, th->controls);
            p = q + 9;
        } else if (!strncmp(q, "{{DATA}}", 8)) data(f, user), p = q + 8;
        else if (!strncmp(q, "{{APP}}", 7)) jf_view_inline_js(f, jf_view_page_js), p = q + 7;
        else fputs("{{", f), p = q + 2;
    }
}

typedef struct {
    const jf_eval_table *t;
    const char *in, *title, *color, *three;
    colset cs;
    const size_t *idx;
    size_t m, nfinite, glyphs, max_points;
    int fail;
} page;

static void num(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.17g", v);
    else fputs("null", f);
}

static void write_data(FILE *f, void *user)
{
    page *pg = user;
    const jf_eval_table *t = pg->t;
    fputs("<script type=\"application/json\" id=\"jf-meta\">{\"file\":", f);
    const char *base = strrchr(pg->in, '/') ? strrchr(pg->in, '/') + 1 : pg->in;
    jf_view_json_str(f, base);
    fputs(",\"title\":", f);
    jf_view_json_str(f, pg->title);
    fprintf(f, ",\"version\":");
    jf_view_json_str(f, jf_version());
    fprintf(f, ",\"three\":");
    jf_view_json_str(f, pg->three);
    fprintf(f, ",\"nrows\":%zu,\"nfinite\":%zu,\"ndrawn\":%zu,\"maxPoints\":%zu,\"glyphs\":%zu,"
               "\"color\":", t->nrows, pg->nfinite, pg->m, pg->max_points, pg->glyphs);
    jf_view_json_str(f, pg->color ? pg->color : "");
    fputs(",\"flags\":[", f);
    for (int b = 0; b < 32; b++) {
        char nm[64];
        jf_point_status_str(1u << b, nm, sizeof nm);
        if (b) fputc(',', f);
        jf_view_json_str(f, strchr(nm, '|') || !strncmp(nm, "unknown", 7) ? "" : nm);
    }
    fputs("],\"columns\":[", f);
    for (size_t k = 0; k < pg->cs.n; k++) {
        const jf_view_col *c = &pg->cs.c[k];
        fprintf(f, "%s{\"name\":", k ? "," : "");
        jf_view_json_str(f, c->name);
        fprintf(f, ",\"enc\":\"%s\",\"bytes\":%zu,\"scale\":", enc_name[c->enc], c->bytes);
        num(f, c->scale);
        fputs(",\"off\":", f);
        num(f, c->off);
        fputs(",\"lo\":[", f);
        for (int d = 0; d < 3; d++) num(f, c->lo[d]), fputs(d < 2 ? "," : "]", f);
        fputs(",\"hi\":[", f);
        for (int d = 0; d < 3; d++) num(f, c->hi[d]), fputs(d < 2 ? "," : "]", f);
        fputs(",\"unit\":", f);
        jf_view_json_str(f, c->enc == JF_VE_POS ? "u" : c->enc == JF_VE_OCT ? "" : unit_of(c->name));
        fputs("}", f);
    }
    fputs("]}</script>\n", f);
    /* the rows: uint32 row numbers of the drawn points */
    unsigned char buf[4096];
    jf_b64 b = {f, {0}, 0};
    fputs("<script type=\"text/plain\" id=\"jf-rows\">", f);
    for (size_t k = 0; k < pg->m; k++) {
        uint32_t r = (uint32_t)pg->idx[k];
        unsigned char o[4] = {r & 255, r >> 8 & 255, r >> 16 & 255, r >> 24};
        jf_b64_put(&b, o, 4);
    }
    jf_b64_end(&b);
    fputs("</script>\n", f);
    for (size_t k = 0; k < pg->cs.n; k++) {
        const jf_view_col *c = &pg->cs.c[k];
        fprintf(f, "<script type=\"text/plain\" id=\"jf-c%zu\">", k);
        size_t per = sizeof buf / c->bytes, done = 0;
        while (done < pg->m) {
            size_t cnt = pg->m - done < per ? pg->m - done : per;
            for (size_t j = 0; j < cnt; j++)
                jf_view_pack_row(c, t->v + pg->idx[done + j] * t->ncols, buf + j * c->bytes);
            jf_b64_put(&b, buf, cnt * c->bytes);
            done += cnt;
        }
        jf_b64_end(&b);
        fputs("</script>\n", f);
    }
}

int jf_view_write(const char *in, const char *out, const jf_view_opts *o, int quiet,
                  char *msg, size_t len)
{
    jf_view_three th;
    char why[4400];
    if (jf_view_three_load(&th, why, sizeof why)) {
        snprintf(msg, len, "%s", why);
        return 1;
    }
    jf_eval_table t;
    jf_error err = {{0}};
    jf_status st = jf_eval_table_read(in, &t, &err);
    if (st) {
        snprintf(msg, len, "%s", err.msg[0] ? err.msg : jf_strerror(st));
        jf_view_three_free(&th);
        return 1;
    }
    page pg = {.t = &t, .in = o->name ? o->name : in, .max_points = o->max_points, .glyphs = o->glyphs};
    int rc = 1, cx = jf_eval_table_col(&t, "x");
    size_t *idx = NULL;
    if (cx < 0 || jf_eval_table_col(&t, "y") != cx + 1 || jf_eval_table_col(&t, "z") != cx + 2) {
        snprintf(msg, len, "%s: no columns x y z (side by side)", in);
        goto done;
    }
    if (!t.nrows) {
        snprintf(msg, len, "%s: no rows", in);
        goto done;
    }
    if (t.nrows > 4294967295u) {
        snprintf(msg, len, "%s: %zu rows: more than the page's 2^32 - 1", in, t.nrows);
        goto done;
    }
    if (choose_columns(&t, o, &pg.cs) || !(idx = malloc(t.nrows * sizeof *idx))) {
        snprintf(msg, len, "%s: out of memory", in);
        goto done;
    }
    for (size_t i = 0; i < t.nrows; i++) {
        const double *r = t.v + i * t.ncols + cx;
        if (isfinite(r[0]) && isfinite(r[1]) && isfinite(r[2])) idx[pg.nfinite++] = i;
    }
    if (!pg.nfinite) {
        snprintf(msg, len, "%s: no row has finite x y z: nothing to draw", in);
        goto done;
    }
    if (jf_view_spread_order(t.v, t.ncols, cx, idx, pg.nfinite)) {
        snprintf(msg, len, "%s: out of memory", in);
        goto done;
    }
    pg.m = pg.nfinite < o->max_points ? pg.nfinite : o->max_points;
    pg.idx = idx;
    const char *color = NULL;
    for (size_t k = 0; k < pg.cs.n; k++) {
        jf_view_col *c = &pg.cs.c[k];
        if (c->enc == JF_VE_POS) jf_view_pack_box(t.v, t.ncols, idx, pg.m, c);
        else if (c->enc != JF_VE_OCT) {
            jf_view_pack_choose(t.v, t.ncols, idx, pg.m, c);
            if (!color || !strcmp(c->name, "k1")) color = c->name;
        }
    }
    if (o->color) {
        int k1 = jf_eval_table_col(&t, "k1") >= 0 && jf_eval_table_col(&t, "k2") >= 0;
        int rgb = jf_eval_table_col(&t, "red") >= 0 && jf_eval_table_col(&t, "green") >= 0 &&
                  jf_eval_table_col(&t, "blue") >= 0;
        int found = (k1 && (!strcmp(o->color, "mean") || !strcmp(o->color, "gauss"))) ||
                    (rgb && !strcmp(o->color, "rgb"));
        for (size_t k = 0; k < pg.cs.n; k++) found |= !strcmp(pg.cs.c[k].name, o->color);
        if (!found) {
            snprintf(msg, len, "%s: no column '%.64s' to colour by", in, o->color);
            goto done;
        }
        color = o->color;
    }
    pg.color = color;
    char title[600], three[64];
    const char *base = strrchr(in, '/') ? strrchr(in, '/') + 1 : in;
    snprintf(title, sizeof title, "%s", o->title ? o->title : base);
    pg.title = title;
    snprintf(three, sizeof three, "r%s", th.revision);
    pg.three = three;

    jf_tmpfile tf;
    if (jf_tmpfile_open(out, &tf, &err) != JF_OK) {
        snprintf(msg, len, "%s", err.msg);
        goto done;
    }
    int fd = dup(tf.fd);
    FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!f) {
        snprintf(msg, len, "%s: %s", out, strerror(errno));
        if (fd >= 0) close(fd);
        jf_tmpfile_discard(&tf);
        goto done;
    }
    put_template(f, jf_view_page_html, title, &th, write_data, &pg);
    int bad = ferror(f);
    if (fclose(f)) bad = 1;
    if (bad) {
        snprintf(msg, len, "%s: %s", out, strerror(errno ? errno : EIO));
        jf_tmpfile_discard(&tf);
        goto done;
    }
    if (jf_tmpfile_commit(&tf, out, &err) != JF_OK) {
        snprintf(msg, len, "%s", err.msg);
        goto done;
    }
    if (!quiet)
        fprintf(stderr, "jetfit view: %s: %zu of %zu rows drawn%s\n", out, pg.m, t.nrows,
                pg.m < pg.nfinite ? " (a spatially even subsample)" : "");
    rc = 0;
done:
    free(idx);
    free(pg.cs.c);
    jf_eval_table_free(&t);
    jf_view_three_free(&th);
    return rc;
}
