/* study_report.c -- DIR/report.html: one self-contained page (no network:
 * the PNGs are embedded as base64 data URIs, the style and the sorting
 * script are inline).  Three tables, each sortable by clicking a column
 * heading: the best setting per noise level and metric (best.csv), the
 * mean and spread over repeats of every setting at every noise level, and
 * every cell (study.csv).  User text is HTML-escaped. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "study.h"

static void esc(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&#39;", f); break;
        default: fputc(*s, f);
        }
    }
}

static void num(FILE *f, double v)
{
    if (isnan(v)) fputs("<td>nan</td>", f);
    else fprintf(f, "<td>%.4g</td>", v);
}

/* The file as a data URI inside an <img>; 0 if it is not there. */
static int embed_png(FILE *f, const char *dir, const char *name, const char *alt)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char path[4096];
    jf_study_path(dir, name, path, sizeof path);
    FILE *in = fopen(path, "rb");
    if (!in) return 0;
    fprintf(f, "<figure><img alt=\"%s\" src=\"data:image/png;base64,", alt);
    unsigned char b[3];
    size_t m;
    while ((m = fread(b, 1, 3, in)) > 0) {
        if (m < 3) memset(b + m, 0, 3 - m);
        unsigned v = (unsigned)b[0] << 16 | (unsigned)b[1] << 8 | b[2];
        fputc(b64[v >> 18 & 63], f);
        fputc(b64[v >> 12 & 63], f);
        fputc(m > 1 ? b64[v >> 6 & 63] : '=', f);
        fputc(m > 2 ? b64[v & 63] : '=', f);
    }
    fclose(in);
    fprintf(f, "\"><figcaption>%s</figcaption></figure>\n", name);
    return 1;
}

static const char style_script[] =
    "<style>\n"
    "body{font-family:sans-serif;margin:1.5em;color:#222}\n"
    "table{border-collapse:collapse;margin:0.5em 0 1.5em;font-size:13px}\n"
    /* a wide table scrolls inside the page (a 1280-pixel window): the page never does */
    "div.scroll{max-width:100%;overflow-x:auto}\n"
    "td.t{max-width:24em;overflow-wrap:anywhere}\n"
    "th,td{border:1px solid #ccc;padding:2px 6px;text-align:right}\n"
    "td.t,th.t{text-align:left}\n"
    "th{background:#eef;cursor:pointer;user-select:none}\n"
    "th.asc::after{content:' \\25B2'}th.desc::after{content:' \\25BC'}\n"
    "tr.failed td{background:#fdd}\n"
    "img{max-width:100%;border:1px solid #ddd}\n"
    "code{background:#f4f4f4;padding:1px 3px}\n"
    "</style>\n"
    "<script>\n"
    "/* click a heading: sort by that column, numbers as numbers (nan last) */\n"
    "function sortBy(th){\n"
    "  var table=th.closest('table'),body=table.tBodies[0];\n"
    "  var col=Array.prototype.indexOf.call(th.parentNode.children,th);\n"
    "  var asc=!th.classList.contains('asc');\n"
    "  Array.prototype.forEach.call(th.parentNode.children,function(h){h.classList.remove('asc','desc');});\n"
    "  th.classList.add(asc?'asc':'desc');\n"
    "  var rows=Array.prototype.slice.call(body.rows);\n"
    "  function key(r){var t=r.cells[col].textContent,v=parseFloat(t);return isNaN(v)?t:v;}\n"
    "  rows.sort(function(a,b){\n"
    "    var x=key(a),y=key(b),nx=typeof x==='number',ny=typeof y==='number';\n"
    "    if(nx&&ny)return asc?x-y:y-x;\n"
    "    if(nx!==ny)return nx?-1:1;\n"
    "    return asc?x.localeCompare(y):y.localeCompare(x);});\n"
    "  rows.forEach(function(r){body.appendChild(r);});\n"
    "}\n"
    "document.addEventListener('DOMContentLoaded',function(){\n"
    "  document.querySelectorAll('table.sortable th').forEach(function(th){\n"
    "    th.addEventListener('click',function(){sortBy(th);});});});\n"
    "</script>\n";

static void head_cells(FILE *f, const char *const *names, int n)
{
    fputs("<thead><tr>", f);
    for (int i = 0; i < n; i++) {
        int text = !strcmp(names[i], "metric") || !strcmp(names[i], "strategy") ||
                   !strcmp(names[i], "flags") || !strcmp(names[i], "status");
        fprintf(f, "<th%s>%s</th>", text ? " class=\"t\"" : "", names[i]);
    }
    fputs("</tr></thead>\n<tbody>\n", f);
}

static void setting_cells(FILE *f, const jf_study *s, const jf_study_key *k)
{
    fputs("<td class=\"t\">", f);
    esc(f, s->strategy[k->strategy]);
    fprintf(f, "</td><td>%d</td><td class=\"t\">", s->degree[k->degree]);
    esc(f, s->flags[k->flags]);
    fputs("</td>", f);
}

static void level_cells(FILE *f, const jf_study *s, const jf_study_key *k)
{
    fprintf(f, "<td>%g</td><td>%g</td><td>%g</td>", s->noise[k->noise], s->noise_u[k->noise_u],
            s->outliers[k->outliers]);
}

static void best_table(FILE *f, const jf_study *s)
{
    static const char *const h[] = {"metric", "noise", "noise_uniform", "outliers", "strategy",
                                    "degree", "flags", "mean", "sd", "repeats"};
    fputs("<div class=\"scroll\"><table id=\"best\" class=\"sortable\">\n", f);
    head_cells(f, h, 10);
    jf_study_key lvl = {0};
    for (lvl.noise = 0; lvl.noise < s->nnoise; lvl.noise++)
        for (lvl.noise_u = 0; lvl.noise_u < s->nnoise_u; lvl.noise_u++)
            for (lvl.outliers = 0; lvl.outliers < s->noutliers; lvl.outliers++)
                for (int m = 0; m < JF_M_COUNT; m++) {
                    jf_study_key b;
                    jf_study_stat st;
                    if (!s->best[m] || !jf_study_best(s, &lvl, m, &b, &st)) continue;
                    fprintf(f, "<tr><td class=\"t\">%s</td>", jf_study_metric[m]);
                    level_cells(f, s, &lvl);
                    setting_cells(f, s, &b);
                    num(f, st.mean);
                    num(f, st.sd);
                    fprintf(f, "<td>%d</td></tr>\n", st.n);
                }
    fputs("</tbody></table></div>\n", f);
}

static void summary_table(FILE *f, const jf_study *s)
{
    const char *h[6 + 2 * JF_M_COUNT + 1];
    char names[JF_M_COUNT][2][40];
    static const char *const fixed[] = {"strategy", "degree", "flags", "noise", "noise_uniform",
                                        "outliers"};
    for (int i = 0; i < 6; i++) h[i] = fixed[i];
    for (int m = 0; m < JF_M_COUNT; m++) {
        snprintf(names[m][0], sizeof names[m][0], "%s", jf_study_metric[m]);
        snprintf(names[m][1], sizeof names[m][1], "&plusmn;");
        h[6 + 2 * m] = names[m][0];
        h[7 + 2 * m] = names[m][1];
    }
    h[6 + 2 * JF_M_COUNT] = "repeats";
    fputs("<div class=\"scroll\"><table id=\"summary\" class=\"sortable\">\n", f);
    head_cells(f, h, 7 + 2 * JF_M_COUNT);
    for (size_t i = 0; i < s->ncells; i++) {
        const jf_study_key *k = &s->cell[i].key;
        if (k->repeat) continue;
        fputs("<tr>", f);
        setting_cells(f, s, k);
        level_cells(f, s, k);
        int nrep = 0;
        for (int m = 0; m < JF_M_COUNT; m++) {
            jf_study_stat st;
            jf_study_mean(s, k, m, &st);
            num(f, st.mean);
            num(f, st.sd);
            if (st.n > nrep) nrep = st.n;
        }
        fprintf(f, "<td>%d</td></tr>\n", nrep);
    }
    fputs("</tbody></table></div>\n", f);
}

static void cells_table(FILE *f, const jf_study *s)
{
    const char *h[8 + JF_M_COUNT + 7];
    static const char *const a[] = {"strategy", "degree", "flags", "noise", "noise_uniform",
                                    "outliers", "repeat", "normal_n"};
    static const char *const b[] = {"ok", "lowered", "failed", "flagged", "status", "seconds",
                                    "points_per_s"};
    for (int i = 0; i < 8; i++) h[i] = a[i];
    for (int m = 0; m < JF_M_COUNT; m++) h[8 + m] = jf_study_metric[m];
    for (int i = 0; i < 7; i++) h[8 + JF_M_COUNT + i] = b[i];
    fputs("<div class=\"scroll\"><table id=\"cells\" class=\"sortable\">\n", f);
    head_cells(f, h, 8 + JF_M_COUNT + 7);
    for (size_t i = 0; i < s->ncells; i++) {
        const jf_study_cell *c = &s->cell[i];
        if (!c->done) continue;
        fprintf(f, "<tr%s>", strcmp(c->status, "ok") ? " class=\"failed\"" : "");
        setting_cells(f, s, &c->key);
        level_cells(f, s, &c->key);
        fprintf(f, "<td>%d</td><td>%zu</td>", c->key.repeat, c->normal_n);
        for (int m = 0; m < JF_M_COUNT; m++) num(f, c->m[m]);
        fprintf(f, "<td>%zu</td><td>%zu</td><td>%zu</td><td>%zu</td><td class=\"t\">", c->ok,
                c->lowered, c->failed, c->flagged);
        esc(f, c->status);
        fputs("</td>", f);
        num(f, c->seconds);
        num(f, c->points_per_s);
        fputs("</tr>\n", f);
    }
    fputs("</tbody></table></div>\n", f);
}

int jf_study_report(const jf_study *s, const char *dir, char *msg, size_t len)
{
    jf_study_out o;
    if (jf_study_out_open(&o, dir, "report.html", msg, len)) return -1;
    FILE *f = o.f;
    size_t ndone = 0, nfail = 0;
    for (size_t i = 0; i < s->ncells; i++) {
        ndone += s->cell[i].done != 0;
        nfail += s->cell[i].done && strcmp(s->cell[i].status, "ok");
    }
    fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
          "<title>jetfit study: ", f);
    esc(f, s->input);
    fputs("</title>\n", f);
    fputs(style_script, f);
    fputs("</head><body>\n<h1>jetfit study: ", f);
    esc(f, s->input);
    fputs("</h1>\n<p>", f);
    if (s->truth) {
        fputs("Truth: <code>", f);
        esc(f, s->truth);
        fputs("</code>. ", f);
    } else {
        fputs("A generated surface with its exact truth. ", f);
    }
    fprintf(f, "%zu cells of %zu finished, %zu failed; %d repeat%s per noise level "
               "(seed %llu + repeat).</p>\n<p>Command: <code>",
            ndone, s->ncells, nfail, s->repeat, s->repeat > 1 ? "s" : "", s->seed);
    esc(f, s->command);
    fputs("</code></p>\n<p>Errors as <code>jetfit eval</code> measures them: the unoriented "
          "normal angle in degrees; k1, k2: |k &minus; k<sub>true</sub>| / max(|k<sub>true</sub>|, 1). "
          "Means over repeats, &plusmn; their standard deviation.  Click a column heading to sort."
          "</p>\n<h2>Best setting per noise level</h2>\n", f);
    best_table(f, s);
    char vpath[4200]; /* cmd_study.c's study_view: the best setting in 3D */
    jf_study_path(dir, "view.html", vpath, sizeof vpath);
    FILE *vf = fopen(vpath, "rb");
    if (vf) {
        fclose(vf);
        fputs("<p><a href=\"view.html\">view.html</a>: the best setting's result (best.ply) in 3D, "
              "coloured by curvature; click a point for its row (<code>jetfit view</code>).</p>\n", f);
    }
    fputs("<h2>Plots</h2>\n", f);
    int np = embed_png(f, dir, "normal.png", "normal error against noise");
    np += embed_png(f, dir, "curvature.png", "curvature errors against noise");
    np += embed_png(f, dir, "k.png", "normal error against K");
    if (!np) fputs("<p>No plots (gnuplot was not found or failed).</p>\n", f);
    fputs("<h2>Every setting, mean over repeats</h2>\n", f);
    summary_table(f, s);
    fputs("<h2>Every cell (study.csv)</h2>\n", f);
    cells_table(f, s);
    fputs("</body></html>\n", f);
    return jf_study_out_commit(&o, msg, len);
}
