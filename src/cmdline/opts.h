/* opts.h -- the estimate's command line (src/cmdline/opts.c), shared by
 * `jetfit estimate`, `jetfit study` and `jetfit-mpi estimate`: one flag at
 * a time into a jf_estimate_opts through the library's jf_estimate_opts_set,
 * then jf_estimate_opts_finish.  Study parses each of its --flags sets
 * with the same code, so an option means the same in every command. */
#ifndef JF_CLI_OPTS_H
#define JF_CLI_OPTS_H

#include <stddef.h>

#include "args.h"
#include "jetfit.h"

/* Strict parsing: the whole string must be consumed; 0 or -1. */
int jf_cli_parse_int(const char *s, int lo, int hi, int *out);
int jf_cli_parse_double(const char *s, double *out);

/* One set of estimation options as the command line gives them. */
typedef struct {
    jf_estimate_opts o;
    jf_read_opts ro;         /* --columns, --bad-rows                    */
    const char *given[17];   /* each flag's text as given (for messages) */
    char flag[48];           /* a message's flag made from a parameter   */
} jf_cli_est;

/* The default neighbourhood as the help says it (the library's default:
 * opts.c checks that they agree). */
#define JF_CLI_DEFAULT_NEIGHBORS "knn:32"

/* What was wrong: option, its value, why (static or argv strings). */
typedef struct {
    const char *opt, *val, *why;
} jf_cli_bad;

void jf_cli_est_init(jf_cli_est *e);

/* The estimation options' names (args.h), ended by a {NULL} row. */
extern const jf_cli_optdef jf_cli_est_optdefs[];

/* 1 if NAME is an estimation option taking a value, 0 if it is one
 * without (--robust-normals), -1 if it is not an estimation option. */
int jf_cli_est_takes_value(const char *name);

/* Applies option NAME (with VAL, NULL for a flag).  0, or -1 with *bad. */
int jf_cli_est_option(jf_cli_est *e, const char *name, const char *val, jf_cli_bad *bad);

/* After all options: jf_estimate_opts_finish (the Monge degree,
 * max_neighbors, the checks).  0, or -1 with *bad. */
int jf_cli_est_finish(jf_cli_est *e, jf_cli_bad *bad);

/* The whole `jetfit estimate` (and `jetfit-mpi estimate`) command line. */
typedef struct {
    jf_cli_est e;
    const char *in, *out;
    int quiet, ascii, keep, help;  /* keep: --keep all (1) or none (0) */
    unsigned long long memory;     /* --memory in bytes, 0 = not given  */
    const char *in_fmt, *out_fmt;  /* --input-format, --output-format, or NULL */
    jf_cli_args args;              /* the scanner (its message outlives the parse) */
    int las_scale_set, las_offset_set; /* --las-scale, --las-offset given */
    double las_scale[3], las_offset[3];
    int las_columns;               /* --las-columns: 0 not given, 1 double, 2 float, 3 compact */
} jf_cli_estimate_cmd;

/* Parses argv[1..] (argv[0] is the command's name).  0, or -1 with *bad
 * (option, value, why: the command prints them). */
int jf_cli_estimate_parse(int argc, char **argv, jf_cli_estimate_cmd *cmd, jf_cli_bad *bad);

/* SIZE: bytes with an optional K, M, G or T (powers of 1024, an optional
 * trailing B).  0 if it is not one. */
unsigned long long jf_cli_parse_size(const char *s);

#endif
