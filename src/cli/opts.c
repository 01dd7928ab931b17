/* opts.c -- estimation options shared by `jetfit estimate` and `jetfit
 * study` (opts.h): the parsing moved out of cmd_estimate.c unchanged, so
 * both commands accept and reject the same text with the same words. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "opts.h"

int jf_cli_parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return -1;
    *out = (int)v;
    return 0;
}

int jf_cli_parse_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

int jf_cli_parse_list(const char *s, double *v, int max)
{
    int n = 0;
    const char *p = s;
    while (*p) {
        char buf[64];
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == 0 || len >= sizeof buf || n == max) return -1;
        memcpy(buf, p, len);
        buf[len] = '\0';
        if (jf_cli_parse_double(buf, &v[n++])) return -1;
        p += len;
        if (*p == ',') {
            p++;
            if (!*p) return -1;
        }
    }
    return n;
}

void jf_cli_est_init(jf_cli_est *e)
{
    memset(e, 0, sizeof *e);
    jf_estimate_opts_init(&e->o);
    jf_read_opts_init(&e->ro);
    e->nbspec = JF_CLI_DEFAULT_NEIGHBORS;
    e->monge = -1;
    e->monge_s = "";
    e->dsel_s = "";
}

/* The estimation options, one per line (a new option: one row here and
 * its branch in jf_cli_est_option).  Every command that takes them scans
 * its command line with this table (args.h). */
const jf_cli_optdef jf_cli_est_optdefs[] = {
    {"--neighbors", 1, 0, NULL},
    {"--neighbours", 1, 0, "--neighbors"},
    {"--degree", 1, 0, NULL},
    {"--monge-degree", 1, 0, NULL},
    {"--fit", 1, 0, NULL},
    {"--frame", 1, 0, NULL},
    {"--max-cond", 1, 0, NULL},
    {"--orient", 1, 0, NULL},
    {"--normal", 1, 0, NULL},
    {"--robust", 1, 0, NULL},
    {"--scales", 1, 0, NULL},
    {"--degree-select", 1, 0, NULL},
    {"--dist-weight", 1, 0, NULL},
    {"--columns", 1, 0, NULL},
    {"--threads", 1, 0, NULL},
    {"--bad-rows", 1, 0, NULL},
    {"--robust-normals", 0, 0, NULL},
    {NULL, 0, 0, NULL}};

int jf_cli_est_takes_value(const char *name)
{
    for (const jf_cli_optdef *d = jf_cli_est_optdefs; d->name; d++)
        if (!strcmp(name, d->name)) return d->arg;
    return -1;
}

static int bad_(jf_cli_bad *b, const char *opt, const char *val, const char *why)
{
    b->opt = opt;
    b->val = val ? val : "";
    b->why = why;
    return -1;
}

int jf_cli_est_option(jf_cli_est *e, const char *name, const char *val, jf_cli_bad *bad)
{
    jf_estimate_opts *o = &e->o;
    int iv;
    double dv, list[8];
    if (!strcmp(name, "--robust-normals")) {
        /* the preset measured on PCPNet (docs/robustness.md): degree
         * selection down to the plane, headed by the weighted top-degree fit */
        o->params.degree_select = 1;
        o->params.dist_weight = 0.55;
        return 0;
    }
    if (jf_cli_est_takes_value(name) != 1)
        return bad_(bad, "unknown option", name, "not an option of estimate");
    if (!val) return bad_(bad, name, "", "needs a value");
    if (!strcmp(name, "--neighbors") || !strcmp(name, "--neighbours")) {
        e->nbspec = val;
    } else if (!strcmp(name, "--degree")) {
        if (jf_cli_parse_int(val, 1, JF_MAX_DEGREE, &iv))
            return bad_(bad, name, val, "expected an integer 1..9");
        o->params.degree = iv;
    } else if (!strcmp(name, "--monge-degree")) {
        if (jf_cli_parse_int(val, 2, JF_MAX_MONGE_DEGREE, &iv))
            return bad_(bad, name, val, "expected 2, 3 or 4");
        e->monge = iv;
        e->monge_s = val;
    } else if (!strcmp(name, "--fit")) {
        if (!strcmp(val, "approx")) o->params.fit = JF_FIT_APPROX;
        else if (!strcmp(val, "interp")) o->params.fit = JF_FIT_INTERP;
        else return bad_(bad, name, val, "expected approx or interp");
    } else if (!strcmp(name, "--frame")) {
        if (!strcmp(val, "pca")) o->params.frame = JF_FRAME_PCA;
        else if (!strcmp(val, "axis")) o->params.frame = JF_FRAME_AXIS;
        else return bad_(bad, name, val, "expected pca or axis");
    } else if (!strcmp(name, "--max-cond")) {
        if (jf_cli_parse_double(val, &dv) || !(dv >= 1))
            return bad_(bad, name, val, "expected a number >= 1");
        o->params.max_cond = dv;
    } else if (!strcmp(name, "--orient")) {
        if (!strcmp(val, "none")) o->orient = JF_ORIENT_NONE;
        else if (!strcmp(val, "input")) o->orient = JF_ORIENT_INPUT;
        else if (!strncmp(val, "viewpoint:", 10)) {
            if (jf_cli_parse_list(val + 10, o->viewpoint, 3) != 3)
                return bad_(bad, name, val, "expected viewpoint:X,Y,Z");
            o->orient = JF_ORIENT_VIEWPOINT;
        } else if (!strcmp(val, "scanner")) o->orient = JF_ORIENT_SCANNER;
        else if (!strcmp(val, "mst")) o->orient = JF_ORIENT_MST;
        else if (!strncmp(val, "mst:", 4)) {
            if (jf_cli_parse_int(val + 4, 1, 256, &iv))
                return bad_(bad, name, val, "expected mst:K with K in 1..256");
            o->orient = JF_ORIENT_MST;
            o->orient_k = (size_t)iv;
        } else
            return bad_(bad, name, val, "expected none, input, viewpoint:X,Y,Z, scanner or mst[:K]");
    } else if (!strcmp(name, "--normal")) {
        if (!strcmp(val, "poles")) o->normal = JF_NORMAL_POLES;
        else if (!strcmp(val, "mincirc")) o->normal = JF_NORMAL_MINCIRC;
        else if (!strcmp(val, "pca")) o->normal = JF_NORMAL_PCA;
        else if (!strcmp(val, "input")) o->normal = JF_NORMAL_INPUT;
        else if (!strcmp(val, "jet")) o->normal = JF_NORMAL_JET;
        else if (!strcmp(val, "auto")) o->normal = JF_NORMAL_AUTO;
        else return bad_(bad, name, val, "expected auto, poles, mincirc, pca, jet or input");
    } else if (!strcmp(name, "--robust")) {
        if (!strcmp(val, "none")) o->params.robust = JF_ROBUST_NONE;
        else if (!strcmp(val, "huber")) o->params.robust = JF_ROBUST_HUBER;
        else if (!strcmp(val, "tukey")) o->params.robust = JF_ROBUST_TUKEY;
        else return bad_(bad, name, val, "expected none, huber or tukey");
    } else if (!strcmp(name, "--scales")) {
        int m = jf_cli_parse_list(val, list, 8);
        if (m < 1) return bad_(bad, name, val, "expected 1 to 8 sizes K1,K2,...");
        for (int j = 0; j < m; j++) {
            if (list[j] < 3 || list[j] > 100000 || list[j] != floor(list[j]) ||
                (j && list[j] <= list[j - 1]))
                return bad_(bad, name, val, "expected ascending integers >= 3");
            o->params.scales[j] = (size_t)list[j];
        }
        o->params.nscales = m;
    } else if (!strcmp(name, "--degree-select")) {
        if (jf_cli_parse_int(val, 1, JF_MAX_DEGREE, &iv))
            return bad_(bad, name, val, "expected a degree 1..9");
        o->params.degree_select = iv;
        e->dsel_s = val;
    } else if (!strcmp(name, "--dist-weight")) {
        if (jf_cli_parse_double(val, &dv) || !(dv > 0) || !isfinite(dv))
            return bad_(bad, name, val, "expected a positive number");
        o->params.dist_weight = dv;
    } else if (!strcmp(name, "--columns")) {
        int m = jf_cli_parse_list(val, list, 6);
        if (m != 3 && m != 6) return bad_(bad, name, val, "expected 3 or 6 column numbers");
        for (int j = 0; j < m; j++) {
            if (list[j] < 0 || list[j] > 1000 || list[j] != floor(list[j]))
                return bad_(bad, name, val, "expected 0-based column numbers");
            e->ro.columns[j] = (int)list[j];
        }
    } else if (!strcmp(name, "--bad-rows")) {
        if (!strcmp(val, "error")) e->ro.bad_rows = 0;
        else if (!strcmp(val, "skip")) e->ro.bad_rows = 1;
        else return bad_(bad, name, val, "expected error or skip");
    } else { /* --threads */
        if (jf_cli_parse_int(val, 1, 4096, &iv))
            return bad_(bad, name, val, "expected an integer from 1 to 4096 (the limit)");
        o->threads = iv;
    }
    return 0;
}

int jf_cli_est_finish(jf_cli_est *e, jf_cli_bad *bad)
{
    jf_estimate_opts *o = &e->o;
    const char *why = NULL;
    if (jf_nb_parse(e->nbspec, &o->nb, &why) != JF_OK)
        return bad_(bad, "--neighbors", e->nbspec, why ? why : "bad neighbourhood");
    /* degree 1 has no curvature: monge 2, its columns are NaN */
    int top = o->params.degree < 2 ? 2 : o->params.degree;
    if (e->monge < 0) e->monge = top < JF_MAX_MONGE_DEGREE ? top : JF_MAX_MONGE_DEGREE;
    else if (e->monge > top) return bad_(bad, "--monge-degree", e->monge_s, "must not exceed --degree");
    o->params.monge_degree = e->monge;
    /* the fitter must accept the largest neighbourhood we may hand it */
    size_t need = o->nb.kind == JF_NB_KNN || o->nb.kind == JF_NB_KNN_RADIUS ? o->nb.k : o->nb.n;
    if (o->nb.kind == JF_NB_AUTO) need = JF_NB_AUTO_KMAX;
    for (int j = 0; j < o->params.nscales; j++)
        if (o->params.scales[j] > need) need = o->params.scales[j];
    if (need > JF_MAX_NEIGHBORS) {
        static char why2[96];
        snprintf(why2, sizeof why2, "K (or N) is too large: at most %zu", JF_MAX_NEIGHBORS);
        return bad_(bad, "--neighbors", e->nbspec, why2);
    }
    if (need > o->params.max_neighbors) o->params.max_neighbors = need;
    if (o->params.degree_select > o->params.degree)
        return bad_(bad, "--degree-select", e->dsel_s, "must not exceed --degree");
    const char *bf = NULL;
    if (jf_params_validate(&o->params, &bf) != JF_OK)
        return bad_(bad, "parameters", bf ? bf : "?", "invalid combination");
    return 0;
}

/* ---- the whole estimate command line ---------------------------------- */

static int bad_set(jf_cli_bad *bad, const char *opt, const char *val, const char *why)
{
    bad->opt = opt, bad->val = val, bad->why = why;
    return -1;
}

unsigned long long jf_cli_parse_size(const char *s)
{
    char *end = NULL;
    if (!s || !*s || *s == '-') return 0;
    double v = strtod(s, &end);
    if (end == s || !(v > 0)) return 0;
    double mul = 1;
    switch (*end) {
    case 'k': case 'K': mul = 1024.0, end++; break;
    case 'm': case 'M': mul = 1048576.0, end++; break;
    case 'g': case 'G': mul = 1073741824.0, end++; break;
    case 't': case 'T': mul = 1099511627776.0, end++; break;
    default: break;
    }
    if (*end == 'b' || *end == 'B') end++;
    if (*end || !(v * mul < 1.8e19) || v * mul < 1) return 0;
    return (unsigned long long)(v * mul);
}

/* "X,Y,Z" (or one value for the three axes) of finite numbers into v; 0 if
 * not, or (positive) a value <= 0. */
static int parse_xyz(const char *s, double v[3], int positive)
{
    int k = 0;
    for (const char *p = s;; k++) {
        char *end;
        if (k == 3 || !*p || isspace((unsigned char)*p)) return 0;
        v[k] = strtod(p, &end);
        if (end == p || !isfinite(v[k]) || (positive && !(v[k] > 0))) return 0;
        if (!*end) break;
        if (*end != ',') return 0;
        p = end + 1;
    }
    if (k == 0) v[1] = v[2] = v[0];
    return k == 0 || k == 2;
}

/* estimate's own options (and jetfit-mpi estimate's) */
static const jf_cli_optdef estimate_optdefs[] = {
    {"--output", 1, 'o', NULL},
    {"--quiet", 0, 'q', NULL},
    {"--help", 0, 'h', NULL},
    {"--ascii", 0, 0, NULL},
    {"--keep", 1, 0, NULL},
    {"--memory", 1, 0, NULL},
    {"--input-format", 1, 0, NULL},
    {"--output-format", 1, 0, NULL},
    {"--las-scale", 1, 0, NULL},
    {"--las-offset", 1, 0, NULL},
    {NULL, 0, 0, NULL}};

int jf_cli_estimate_parse(int argc, char **argv, jf_cli_estimate_cmd *cmd, jf_cli_bad *bad)
{
    memset(cmd, 0, sizeof *cmd);
    cmd->keep = 1;
    jf_cli_est *e = &cmd->e;
    jf_cli_est_init(e);
    const jf_cli_optdef *const tables[] = {estimate_optdefs, jf_cli_est_optdefs, NULL};
    jf_cli_args *a = &cmd->args;
    jf_cli_args_init(a, argc, argv, tables);
    int k;
    while ((k = jf_cli_args_next(a)) != JF_CLI_END) {
        const char *name = a->name, *val = a->val;
        if (k == JF_CLI_ERROR) return bad_set(bad, NULL, "", a->err); /* the whole message */
        if (k == JF_CLI_OPERAND) {
            if (cmd->in) return bad_set(bad, "argument", val, "only one INPUT file is accepted");
            cmd->in = val;
        } else if (!strcmp(name, "--help")) {
            cmd->help = 1;
            return 0;
        } else if (!strcmp(name, "--quiet")) {
            cmd->quiet = 1;
        } else if (!strcmp(name, "--ascii")) {
            cmd->ascii = 1;
        } else if (!strcmp(name, "--output")) {
            cmd->out = val;
        } else if (!strcmp(name, "--input-format")) {
            cmd->in_fmt = val;
        } else if (!strcmp(name, "--output-format")) {
            cmd->out_fmt = val;
        } else if (!strcmp(name, "--memory")) {
            if (!(cmd->memory = jf_cli_parse_size(val)))
                return bad_set(bad, "--memory", val, "expected a size such as 8G, 256M or 1500000000");
        } else if (!strcmp(name, "--las-scale") || !strcmp(name, "--las-offset")) {
            int sc = name[6] == 's';
            if (!parse_xyz(val, sc ? cmd->las_scale : cmd->las_offset, sc))
                return bad_set(bad, sc ? "--las-scale" : "--las-offset", val,
                               sc ? "expected X,Y,Z (or one value): positive numbers"
                                  : "expected X,Y,Z (or one value): finite numbers");
            *(sc ? &cmd->las_scale_set : &cmd->las_offset_set) = 1;
        } else if (!strcmp(name, "--keep")) {
            if (!strcmp(val, "all")) cmd->keep = 1;
            else if (!strcmp(val, "none")) cmd->keep = 0;
            else return bad_set(bad, "--keep", val, "expected all or none");
        } else if (jf_cli_est_option(e, name, val, bad)) {
            return -1;
        }
    }
    if (!cmd->in) return bad_set(bad, "INPUT", "", "missing input file ('-': standard input)");
    if (!cmd->out) return bad_set(bad, "-o", "", "missing output file ('-o -': standard output)");
    if (jf_cli_est_finish(e, bad)) return -1;
    return 0;
}
