/* args.h -- GNU-style command lines for every command (src/cmdline/args.c):
 * what getopt_long(3) accepts, from tables of option names, so each
 * command's parser is a loop over (option, value) pairs and operands. */
#ifndef JF_CLI_ARGS_H
#define JF_CLI_ARGS_H

/* One option: its long name ("--output"), 1 if it takes a value, its
 * short letter (0: none), and for an alias the name it stands for
 * ("--neighbours" -> "--neighbors"; the scanner reports that one).  A
 * command passes several tables (its own, the estimation options of
 * opts.c), each ended by a {NULL} row. */
typedef struct {
    const char *name;
    int arg;
    char short_name;
    const char *alias_of;
} jf_cli_optdef;

/* The scanner's state; set it up with jf_cli_args_init. */
typedef struct {
    int argc;
    char **argv;
    int i, pos;            /* next argv, place in a cluster "-qoFILE"  */
    int only_operands;     /* after "--"                               */
    const jf_cli_optdef *const *tables;
    const char *name;      /* the option found: its long name           */
    const char *val;       /* its value, or the operand                 */
    char err[512];         /* why JF_CLI_ERROR                          */
} jf_cli_args;

enum { JF_CLI_END = 0, JF_CLI_OPTION = 1, JF_CLI_OPERAND = 2, JF_CLI_ERROR = -1 };

/* tables: NULL-terminated list.  argv[0] is the command's name. */
void jf_cli_args_init(jf_cli_args *a, int argc, char **argv, const jf_cli_optdef *const *tables);

/* The next item, as getopt_long gives it (with its permutation: options
 * and operands in any order):
 *   --name VALUE, --name=VALUE, a unique prefix of a long name (an exact
 *   name wins; several matches: an error listing them), -x VALUE, -xVALUE,
 *   clusters of flags (-qh), "--" ends the options, "-" is an operand
 *   (standard input or output).
 * JF_CLI_OPTION (a->name: the long name as in the table, a->val: the
 * value or NULL), JF_CLI_OPERAND (a->val), JF_CLI_END, or JF_CLI_ERROR
 * (a->err: "unknown option '--x'", "option '--degree' needs a value", ...). */
int jf_cli_args_next(jf_cli_args *a);

/* 1 if NAME is a long name in the tables (exactly). */
int jf_cli_args_known(const jf_cli_optdef *const *tables, const char *name);

#endif
