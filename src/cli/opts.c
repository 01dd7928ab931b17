/* opts.c -- estimation options shared by `jetfit estimate` and `jetfit
 * study` (opts.h): the parsing moved out of cmd_estimate.c unchanged, so
 * both commands accept and reject the same text with the same words. */
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
}

static const char *const valued[] = {
    "--neighbors", "--neighbours", "--degree", "--monge-degree", "--fit", "--frame",
    "--max-cond", "--orient", "--normal", "--robust", "--scales", "--degree-select",
    "--dist-weight", "--columns", "--threads", "--bad-rows"};

int jf_cli_est_takes_value(const char *name)
{
    if (!strcmp(name, "--robust-normals")) return 0;
    for (size_t k = 0; k < sizeof valued / sizeof valued[0]; k++)
        if (!strcmp(name, valued[k])) return 1;
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
        return bad_(bad, "--degree-select", "", "must not exceed --degree");
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


int jf_cli_estimate_parse(int argc, char **argv, jf_cli_estimate_cmd *cmd, jf_cli_bad *bad)
{
    memset(cmd, 0, sizeof *cmd);
    cmd->keep = 1;
    jf_cli_est *e = &cmd->e;
    jf_cli_est_init(e);

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            cmd->help = 1;
            return 0;
        }
        if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
            cmd->quiet = 1;
            continue;
        }
        if (!strcmp(a, "--ascii")) {
            cmd->ascii = 1;
            continue;
        }
        if (jf_cli_est_takes_value(a) == 0) {
            (void)jf_cli_est_option(e, a, NULL, bad);
            continue;
        }
        if (a[0] != '-' || !a[1]) {
            if (cmd->in) return bad_set(bad, "argument", a, "only one INPUT file is accepted");
            cmd->in = a;
            continue;
        }
        /* every other option takes a value: "--opt VALUE" or "--opt=VALUE" */
        char name[32];
        const char *val = NULL, *eq = strchr(a, '=');
        if (eq && (size_t)(eq - a) < sizeof name) {
            memcpy(name, a, (size_t)(eq - a));
            name[eq - a] = '\0';
            val = eq + 1;
        } else {
            snprintf(name, sizeof name, "%s", a);
            if (i + 1 >= argc)
                return strcmp(name, "-o") && strcmp(name, "--output") && strcmp(name, "--keep") &&
                               strcmp(name, "--memory") &&
                               jf_cli_est_takes_value(name) != 1
                           ? bad_set(bad, "unknown option", a, "not an option of estimate")
                           : bad_set(bad, a, "", "needs a value");
            val = argv[++i];
        }
        if (!strcmp(name, "-o") || !strcmp(name, "--output")) {
            cmd->out = val;
        } else if (!strcmp(name, "--memory")) {
            if (!(cmd->memory = jf_cli_parse_size(val)))
                return bad_set(bad, "--memory", val, "expected a size such as 8G, 256M or 1500000000");
        } else if (!strcmp(name, "--keep")) {
            if (!strcmp(val, "all")) cmd->keep = 1;
            else if (!strcmp(val, "none")) cmd->keep = 0;
            else return bad_set(bad, "--keep", val, "expected all or none");
        } else if (jf_cli_est_takes_value(name) != 1) {
            return bad_set(bad, "unknown option", a, "not an option of estimate");
        } else if (jf_cli_est_option(e, name, val, bad)) {
            if (bad->opt == name) { /* name dies with this loop */
                memcpy(cmd->badname, name, sizeof cmd->badname);
                bad->opt = cmd->badname;
            }
            return -1;
        }
    }
    if (!cmd->in) return bad_set(bad, "INPUT", "", "missing input file");
    if (!cmd->out) return bad_set(bad, "-o", "", "missing output file");
    if (jf_cli_est_finish(e, bad)) return -1;
    return 0;
}
