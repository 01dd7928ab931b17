/* cmd_view.c -- `jetfit view RESULT -o FILE.html`: one self-contained page
 * (no network) to turn a result in 3D, colour it by any column, filter by
 * status, show normals and principal directions and read a point's row.
 * With --estimate, RESULT is a raw cloud estimated first (the estimate's
 * own options, into a temporary PLY removed afterwards).  The page is
 * written by view_write.c; docs/view.md describes it. */
#define _DEFAULT_SOURCE /* mkstemps */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cmd.h"
#include "opts.h"
#include "view.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: jetfit view RESULT -o FILE.html [--color COLUMN] [--max-points N]\n"
        "         [--glyphs N] [--title TEXT] [--all-columns] [--quiet]\n"
        "       jetfit view --estimate INPUT -o FILE.html [view options] [estimate options]\n"
        "\n"
        "  RESULT          a jetfit output or generate truth file (.ply .csv .xyz\n"
        "                  .txt .las): columns x y z, and any of nx..nz k1 k2\n"
        "                  d1x..d2z degree neighbors cond residual status sigma\n"
        "                  and the input's attributes\n"
        "  -o, --output FILE.html\n"
        "                  the page: one file, opens from disk, no network (three.js\n"
        "                  inlined from Debian's libjs-three)\n"
        "  --color COLUMN  the column coloured first (default k1; mean and gauss are\n"
        "                  (k1+k2)/2 and k1 k2; rgb: the input's red green blue);\n"
        "                  the page changes it\n"
        "  --max-points N  draw at most N points (default 2000000); beyond, a\n"
        "                  spatially even subsample, said in the page\n"
        "  --glyphs N      normal / d1 / d2 glyphs on at most N points (default 3000)\n"
        "  --title TEXT    the page's title (default: RESULT's name)\n"
        "  --all-columns   also the Monge coefficients b0..b3 c0..c4\n"
        "  --estimate      INPUT is a raw cloud: run `jetfit estimate` on it first;\n"
        "                  other options go to the estimate (jetfit estimate --help)\n"
        "  -q, --quiet     no summary line\n"
        "  -h, --help      this text\n"
        "  --memory SIZE, --keep all|none, --input-format FMT: as estimate's, with\n"
        "                  --estimate (INPUT '-': standard input)\n");
}

static int bad(const char *fmt, const char *arg)
{
    fprintf(stderr, "jetfit view: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (jetfit view --help)\n");
    return 2;
}

static int count_arg(const char *a, const char *v, size_t lo, size_t *out)
{
    char *end;
    errno = 0;
    unsigned long long n = strtoull(v, &end, 10);
    if (end == v || *end || errno || *v == '-' || n < lo || n > 4294967295ull) {
        fprintf(stderr, "jetfit view: %s wants a count %zu..4294967295, not '%s' (jetfit view --help)\n",
                a, lo, v);
        return 2;
    }
    *out = (size_t)n;
    return 0;
}

/* view's own options; with --estimate, estimate's (opts.h) and those of
 * its own that make sense here are passed on.  Scanned by args.c, as
 * every command's line is. */
static const jf_cli_optdef view_optdefs[] = {
    {"--output", 1, 'o', NULL},
    {"--help", 0, 'h', NULL},
    {"--quiet", 0, 'q', NULL},
    {"--color", 1, 0, NULL},
    {"--max-points", 1, 0, NULL},
    {"--glyphs", 1, 0, NULL},
    {"--title", 1, 0, NULL},
    {"--all-columns", 0, 0, NULL},
    {"--estimate", 0, 0, NULL},
    {"--memory", 1, 0, NULL},
    {"--keep", 1, 0, NULL},
    {"--input-format", 1, 0, NULL},
    {NULL, 0, 0, NULL}};

int jf_cmd_view(int argc, char **argv)
{
    jf_view_opts o;
    jf_view_opts_init(&o);
    const char *in = NULL, *out = NULL;
    int estimate = 0, quiet = 0;
    char **pass = calloc(2 * (size_t)argc + 8, sizeof *pass); /* estimate's argv */
    if (!pass) return bad("%s", "out of memory");
    int npass = 1, rc;
    pass[0] = "estimate";
    const jf_cli_optdef *const tables[] = {view_optdefs, jf_cli_est_optdefs, NULL};
    jf_cli_args args;
    jf_cli_args_init(&args, argc, argv, tables);
    const char *first_est = NULL; /* an estimate option, refused without --estimate */
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        const char *a = args.name, *v = args.val;
        if (k == JF_CLI_ERROR) {
            free(pass);
            return bad("%s", args.err);
        }
        if (k == JF_CLI_OPERAND) {
            if (in) { free(pass); return bad("unexpected argument '%s'", v); }
            in = v;
            continue;
        }
        if (!strcmp(a, "--help")) {
            usage(stdout);
            free(pass);
            return 0;
        }
        if (!strcmp(a, "--estimate")) estimate = 1;
        else if (!strcmp(a, "--all-columns")) o.all_columns = 1;
        else if (!strcmp(a, "--quiet")) quiet = 1, pass[npass++] = "--quiet";
        else if (!strcmp(a, "--output")) out = v;
        else if (!strcmp(a, "--color")) o.color = v;
        else if (!strcmp(a, "--title")) o.title = v;
        else if (!strcmp(a, "--max-points")) {
            if (count_arg(a, v, 1, &o.max_points)) { free(pass); return 2; }
        } else if (!strcmp(a, "--glyphs")) {
            if (count_arg(a, v, 0, &o.glyphs)) { free(pass); return 2; }
        } else { /* the estimate's: its long name, then its value */
            if (!first_est) first_est = a;
            pass[npass++] = (char *)a;
            if (v) pass[npass++] = (char *)v;
        }
    }
    if (first_est && !estimate) {
        free(pass);
        return bad("%s is an estimate option: it applies with --estimate", first_est);
    }
    if (!in) { free(pass); return bad("%s", estimate ? "which INPUT cloud?" : "which RESULT file?"); }
    if (!out) { free(pass); return bad("%s", "-o FILE.html is required"); }
    size_t lo = strlen(out);
    if (lo < 5 || (strcasecmp(out + lo - 5, ".html") && strcasecmp(out + lo - 4, ".htm")))
        { free(pass); return bad("-o wants a .html file, not '%s'", out); }
    if (jf_same_file(in, out)) {
        fprintf(stderr, "jetfit view: %s: is the input file (%s)\n", out, in);
        free(pass);
        return 2;
    }
    char tmp[4200] = "";
    if (estimate) {
        const char *td = getenv("TMPDIR");
        snprintf(tmp, sizeof tmp, "%s/jetfit-view-XXXXXX.ply", td && *td ? td : "/tmp");
        int fd = mkstemps(tmp, 4);
        if (fd < 0) {
            fprintf(stderr, "jetfit view: %s: %s\n", tmp, strerror(errno));
            free(pass);
            return 1;
        }
        close(fd);
        pass[npass++] = "-o";
        pass[npass++] = tmp;
        pass[npass++] = "--"; /* INPUT may start with '-' */
        pass[npass++] = (char *)in;
        pass[npass] = NULL;
        rc = jf_cmd_estimate(npass, pass);
        if (rc) {
            unlink(tmp);
            free(pass);
            return rc;
        }
    }
    free(pass);
    char msg[4600];
    if (!o.title && estimate) o.title = strrchr(in, '/') ? strrchr(in, '/') + 1 : in;
    if (estimate) o.name = in; /* the page names the cloud, not the temporary */
    rc = jf_view_write(estimate ? tmp : in, out, &o, quiet, msg, sizeof msg);
    if (estimate) unlink(tmp);
    if (rc) fprintf(stderr, "jetfit view: %s\n", msg);
    return rc;
}
