/* opts.c -- the estimate's command line, shared by `jetfit estimate`,
 * `jetfit study` and `jetfit-mpi estimate` (opts.h): each flag is handed
 * to the library's parser of its parameter (jf_estimate_opts_set), so
 * every front end accepts and rejects the same text with the same words;
 * the flag and its text are added here. */
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

void jf_cli_est_init(jf_cli_est *e)
{
    memset(e, 0, sizeof *e);
    jf_estimate_opts_init(&e->o);
    jf_read_opts_init(&e->ro);
}

/* The estimation options, one per line: the flag, its parameter in the
 * library (jf_estimate_opts_set, or jf_read_opts_set when `read`).  Every
 * command that takes them scans its command line with jf_cli_est_optdefs,
 * made from the same names (args.h). */
static const struct {
    const char *flag, *param;
    int read;
} params[] = {
    {"--neighbors", "neighbors", 0},         {"--neighbours", "neighbors", 0},
    {"--degree", "degree", 0},               {"--monge-degree", "monge_degree", 0},
    {"--fit", "fit", 0},                     {"--frame", "frame", 0},
    {"--max-cond", "max_cond", 0},           {"--orient", "orient", 0},
    {"--normal", "normal", 0},               {"--robust", "robust", 0},
    {"--scales", "scales", 0},               {"--degree-select", "degree_select", 0},
    {"--dist-weight", "dist_weight", 0},     {"--columns", "columns", 1},
    {"--threads", "threads", 0},             {"--bad-rows", "bad_rows", 1},
    {"--robust-normals", "robust_normals", 0},
};
#define NPARAMS (sizeof params / sizeof params[0])
_Static_assert(NPARAMS == sizeof ((jf_cli_est *)0)->given / sizeof(char *), "one text per flag");
_Static_assert(JF_ESTIMATE_DEFAULT_K == 32, "JF_CLI_DEFAULT_NEIGHBORS says knn:32");

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

static int find(const char *flag)
{
    for (size_t i = 0; i < NPARAMS; i++)
        if (!strcmp(flag, params[i].flag)) return (int)i;
    return -1;
}

int jf_cli_est_option(jf_cli_est *e, const char *name, const char *val, jf_cli_bad *bad)
{
    int i = find(name);
    if (i < 0) return bad_(bad, "unknown option", name, "not an option of estimate");
    const char *why = NULL;
    jf_status st = params[i].read ? jf_read_opts_set(&e->ro, params[i].param, val, &why)
                                  : jf_estimate_opts_set(&e->o, params[i].param, val, &why);
    if (st != JF_OK) return bad_(bad, name, val, why ? why : "invalid value");
    e->given[i] = val;
    return 0;
}

int jf_cli_est_finish(jf_cli_est *e, jf_cli_bad *bad)
{
    const char *param = NULL, *why = NULL;
    if (jf_estimate_opts_finish(&e->o, &param, &why) == JF_OK) return 0;
    /* the parameter's flag and the text it was given, for the message */
    const char *flag = NULL, *val = "";
    for (size_t i = 0; param && i < NPARAMS; i++)
        if (!strcmp(params[i].param, param)) {
            if (!flag) flag = params[i].flag;
            if (e->given[i]) flag = params[i].flag, val = e->given[i];
        }
    if (!flag) { /* a field no flag sets: its name as a flag would be */
        size_t u = (size_t)snprintf(e->flag, sizeof e->flag, "--%s", param ? param : "?");
        for (size_t k = 2; k < u && k < sizeof e->flag; k++)
            if (e->flag[k] == '_') e->flag[k] = '-';
        flag = e->flag;
    }
    return bad_(bad, flag, val, why ? why : "invalid value");
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
    {"--las-columns", 1, 0, NULL},
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
        } else if (!strcmp(name, "--las-columns")) {
            if (!strcmp(val, "double")) cmd->las_columns = 1;
            else if (!strcmp(val, "float")) cmd->las_columns = 2;
            else if (!strcmp(val, "compact")) cmd->las_columns = 3;
            else return bad_set(bad, "--las-columns", val, "expected double, float or compact");
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
