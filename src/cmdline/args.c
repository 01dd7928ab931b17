/* args.c -- the GNU command-line conventions (args.h), as getopt_long(3)
 * implements them (GNU libc manual, "Parsing Long Options"), without its
 * global state and with messages naming the candidates of an ambiguous
 * abbreviation. */
#include <stdio.h>
#include <string.h>

#include "args.h"

void jf_cli_args_init(jf_cli_args *a, int argc, char **argv, const jf_cli_optdef *const *tables)
{
    memset(a, 0, sizeof *a);
    a->argc = argc;
    a->argv = argv;
    a->i = 1;
    a->tables = tables;
}

static const char *canonical(const jf_cli_optdef *d)
{
    return d->alias_of ? d->alias_of : d->name;
}

int jf_cli_args_known(const jf_cli_optdef *const *tables, const char *name)
{
    for (int t = 0; tables[t]; t++)
        for (const jf_cli_optdef *d = tables[t]; d->name; d++)
            if (!strcmp(d->name, name)) return 1;
    return 0;
}

/* The option "--" + text[0..len): exact, else the unique prefix. */
static const jf_cli_optdef *find_long(jf_cli_args *a, const char *text, size_t len)
{
    const jf_cli_optdef *hit = NULL;
    int ambiguous = 0;
    for (int t = 0; a->tables[t]; t++)
        for (const jf_cli_optdef *d = a->tables[t]; d->name; d++) {
            if (strncmp(d->name, text, len)) continue;
            if (d->name[len] == '\0') return d; /* an exact name wins */
            if (hit && strcmp(canonical(hit), canonical(d))) ambiguous = 1;
            if (!hit) hit = d;
        }
    if (!hit) {
        snprintf(a->err, sizeof a->err, "unknown option '%.*s'", (int)len, text);
        return NULL;
    }
    if (ambiguous) {
        /* name every candidate once, as GNU getopt does */
        size_t u = (size_t)snprintf(a->err, sizeof a->err,
                                    "option '%.*s' is ambiguous; possibilities:", (int)len, text);
        for (int t = 0; a->tables[t]; t++)
            for (const jf_cli_optdef *d = a->tables[t]; d->name && u < sizeof a->err; d++)
                if (!strncmp(d->name, text, len) && !d->alias_of)
                    u += (size_t)snprintf(a->err + u, sizeof a->err - u, " '%s'", d->name);
        return NULL;
    }
    return hit;
}

static const jf_cli_optdef *find_short(jf_cli_args *a, char c)
{
    for (int t = 0; a->tables[t]; t++)
        for (const jf_cli_optdef *d = a->tables[t]; d->name; d++)
            if (d->short_name == c) return d;
    snprintf(a->err, sizeof a->err, "unknown option '-%c'", c);
    return NULL;
}

int jf_cli_args_next(jf_cli_args *a)
{
    a->name = a->val = NULL;
    if (a->pos) { /* inside a cluster of short options: "-qo FILE" */
        const char *s = a->argv[a->i];
        const jf_cli_optdef *d = find_short(a, s[a->pos]);
        if (!d) return JF_CLI_ERROR;
        a->name = canonical(d);
        if (!d->arg) {
            if (!s[++a->pos]) a->pos = 0, a->i++;
            return JF_CLI_OPTION;
        }
        if (s[a->pos + 1]) {
            a->val = s + a->pos + 1; /* -oFILE */
            a->pos = 0, a->i++;
            return JF_CLI_OPTION;
        }
        a->pos = 0, a->i++;
        if (a->i >= a->argc) {
            snprintf(a->err, sizeof a->err, "option '-%c' (%s) needs a value", d->short_name, d->name);
            return JF_CLI_ERROR;
        }
        a->val = a->argv[a->i++];
        return JF_CLI_OPTION;
    }
    if (a->i >= a->argc) return JF_CLI_END;
    const char *s = a->argv[a->i];
    if (a->only_operands || s[0] != '-' || !s[1]) { /* "-": standard input or output */
        a->val = s;
        a->i++;
        return JF_CLI_OPERAND;
    }
    if (!strcmp(s, "--")) {
        a->only_operands = 1;
        a->i++;
        return jf_cli_args_next(a);
    }
    if (s[1] != '-') {
        a->pos = 1;
        return jf_cli_args_next(a);
    }
    const char *eq = strchr(s, '=');
    size_t len = eq ? (size_t)(eq - s) : strlen(s);
    const jf_cli_optdef *d = find_long(a, s, len);
    if (!d) return JF_CLI_ERROR;
    a->name = canonical(d);
    a->i++;
    if (!d->arg) {
        if (eq) {
            snprintf(a->err, sizeof a->err, "option '%s' takes no value", d->name);
            return JF_CLI_ERROR;
        }
        return JF_CLI_OPTION;
    }
    if (eq) {
        a->val = eq + 1;
        return JF_CLI_OPTION;
    }
    if (a->i >= a->argc) {
        snprintf(a->err, sizeof a->err, "option '%s' needs a value", d->name);
        return JF_CLI_ERROR;
    }
    a->val = a->argv[a->i++];
    return JF_CLI_OPTION;
}
