/* cmd_eval.c -- `jetfit eval RESULT TRUTH [--subset IDX] [--by-status]`:
 * normal angle and principal-curvature errors of a jetfit result against
 * ground truth (generate's truth file, or PCPNet's .normals/.curv), as a
 * small table on stdout. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "args.h"
#include "cmd.h"
#include "eval_errors.h"
#include "pipes.h"
#include "jetfit.h"

static void usage(FILE *out)
{
    fprintf(out,
        "usage: jetfit eval RESULT TRUTH [--subset IDX] [--by-status]\n"
        "\n"
        "  RESULT       jetfit estimate output (.ply/.csv/.xyz; columns nx ny nz,\n"
        "               k1 k2 and status are used when present)\n"
        "  TRUTH        a truth file with columns nx ny nz [k1 k2] (jetfit generate),\n"
        "               or PCPNet data: SHAPE.normals or SHAPE.xyz (reads\n"
        "               SHAPE.normals and, when present, SHAPE.curv), or a reference\n"
        "               result of the same cloud.  The points must be RESULT's:\n"
        "               a reference result's x y z exactly (1e-9 of the diagonal),\n"
        "               generate's noise-free x y z within 5%% (median); PCPNet's\n"
        "               .normals have no coordinates, so rows are matched by order only\n"
        "  --subset IDX only the rows whose 0-based indices IDX lists (e.g. .pidx)\n"
        "  --by-status  the same table for each status value of RESULT\n"
        "\n"
        "Normal error: unoriented angle acos|n.n_true| in degrees.  Curvature:\n"
        "k_rel = |k - k_t| / max(|k_t|, 1) (PCPNet) and k_abs = |k - k_t|, after\n"
        "orienting the estimate along the true normal.  PCPNet's .curv holds two\n"
        "curvatures per point, sorted here as k1 >= k2 w.r.t. its .normals with\n"
        "the sign convention of jetfit (a sphere with outward normals has k < 0).\n"
        "  --input-format FMT  read RESULT as FMT (ply csv xyz txt las); '-' as\n"
        "               RESULT is standard input (jetfit estimate ... -o - | ...)\n"
        "  -h, --help   this text\n");
}

/* Column indices of a result, -1 where missing. */
typedef struct {
    int n[3], k[2], status;
} cols;

static cols find_cols(const jf_eval_table *t)
{
    cols c;
    c.n[0] = jf_eval_table_col(t, "nx");
    c.n[1] = jf_eval_table_col(t, "ny");
    c.n[2] = jf_eval_table_col(t, "nz");
    c.k[0] = jf_eval_table_col(t, "k1");
    c.k[1] = jf_eval_table_col(t, "k2");
    c.status = jf_eval_table_col(t, "status");
    return c;
}

static int has_normal(const cols *c) { return c->n[0] >= 0 && c->n[1] >= 0 && c->n[2] >= 0; }
static int has_curv(const cols *c) { return c->k[0] >= 0 && c->k[1] >= 0; }

enum { NQ = JF_NQ };

static void print_table(double *err[NQ], size_t n, int with_k)
{
    printf("%-11s %8s %8s %10s %10s %10s %10s %10s\n", "quantity", "n", "nonfin",
           "rms", "mean", "median", "p95", "max");
    for (int q = 0; q < NQ; q++) {
        if (q > JF_Q_NORMAL && !with_k) break;
        jf_err_stats s;
        jf_err_stats_compute(err[q], n, &s);
        printf("%-11s %8zu %8zu %10.4g %10.4g %10.4g %10.4g %10.4g\n", jf_q_name[q], s.n,
               s.nonfinite, s.rms, s.mean, s.median, s.p95, s.max);
    }
}

int jf_cmd_eval(int argc, char **argv)
{
    const char *res_path = NULL, *truth_path = NULL, *subset_path = NULL;
    int by_status = 0;
    static const jf_cli_optdef optdefs[] = {
        {"--help", 0, 'h', NULL},
        {"--subset", 1, 0, NULL},
        {"--by-status", 0, 0, NULL},
        {"--input-format", 1, 0, NULL},
        {NULL, 0, 0, NULL}};
    const char *in_fmt = NULL;
    const jf_cli_optdef *const tables[] = {optdefs, NULL};
    jf_cli_args args;
    jf_cli_args_init(&args, argc, argv, tables);
    for (int k; (k = jf_cli_args_next(&args)) != JF_CLI_END;) {
        if (k == JF_CLI_ERROR) {
            fprintf(stderr, "jetfit eval: %s (jetfit eval --help)\n", args.err);
            return 2;
        } else if (k == JF_CLI_OPERAND) {
            if (!res_path) {
                res_path = args.val;
            } else if (!truth_path) {
                truth_path = args.val;
            } else {
                fprintf(stderr, "jetfit eval: unexpected argument '%s'\n", args.val);
                return 2;
            }
        } else if (!strcmp(args.name, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(args.name, "--subset")) {
            subset_path = args.val;
        } else if (!strcmp(args.name, "--input-format")) {
            in_fmt = args.val;
        } else { /* --by-status */
            by_status = 1;
        }
    }
    if (!res_path || !truth_path) {
        usage(stderr);
        return 2;
    }

    int rc = 1, truth_k = 0;
    size_t ntruth = 0, nsel = 0;
    double *truth = NULL, *err[NQ] = {0};
    size_t *sel = NULL;
    unsigned *stat = NULL;
    char msg[4200];
    jf_eval_table res;
    jf_error e;
    e.msg[0] = '\0';
    jf_cli_in rin; /* '-' and --input-format (pipes.h) */
    jf_status st = jf_cli_in_begin(&rin, res_path, in_fmt, &e);
    if (st == JF_OK) st = jf_eval_table_read(rin.path, &res, &e);
    jf_cli_in_end(&rin, st != JF_OK ? &e : NULL);
    if (st != JF_OK) {
        fprintf(stderr, "jetfit eval: %s\n", e.msg[0] ? e.msg : jf_strerror(st));
        return 1;
    }
    cols c = find_cols(&res);
    if (!has_normal(&c)) {
        fprintf(stderr, "jetfit eval: %s: no nx ny nz columns\n", res_path);
        goto done;
    }
    if (!(truth = jf_cli_truth_load(truth_path, &ntruth, &truth_k, msg, sizeof msg))) {
        fprintf(stderr, "jetfit eval: %s\n", msg);
        goto done;
    }
    if (ntruth != res.nrows) {
        fprintf(stderr, "jetfit eval: %s has %zu rows, %s has %zu\n", res_path, res.nrows,
                truth_path, ntruth);
        goto done;
    }
    if (jf_cli_truth_coords_check(truth_path, &res, msg, sizeof msg)) {
        fprintf(stderr, "jetfit eval: %s\n", msg);
        goto done;
    }
    if (subset_path) {
        if (jf_cli_subset_load(subset_path, res.nrows, &sel, &nsel, msg, sizeof msg)) {
            fprintf(stderr, "jetfit eval: %s\n", msg);
            goto done;
        }
    } else {
        nsel = res.nrows;
        sel = malloc((nsel ? nsel : 1) * sizeof *sel);
        for (size_t j = 0; sel && j < nsel; j++) sel[j] = j;
    }
    stat = malloc((nsel ? nsel : 1) * sizeof *stat);
    for (int q = 0; q < NQ; q++) err[q] = malloc((nsel ? nsel : 1) * sizeof *err[q]);
    if (!sel || !stat || !err[NQ - 1] || !err[0] || !err[1] || !err[2] || !err[3]) {
        fprintf(stderr, "jetfit eval: out of memory\n");
        goto done;
    }
    int with_k = truth_k && has_curv(&c);
    for (size_t j = 0; j < nsel; j++) {
        const double *r = res.v + sel[j] * res.ncols, *t = truth + 5 * sel[j];
        double n[3] = {r[c.n[0]], r[c.n[1]], r[c.n[2]]}, ev[NQ];
        jf_cli_point_errors(n, with_k ? r[c.k[0]] : NAN, with_k ? r[c.k[1]] : NAN, t, with_k, ev);
        for (int q = 0; q < NQ; q++) err[q][j] = ev[q];
        stat[j] = c.status >= 0 ? (unsigned)r[c.status] : 0u;
    }
    printf("# %s vs %s: %zu points%s\n", res_path, truth_path, nsel,
           subset_path ? " (subset)" : "");
    if (!with_k)
        printf("# curvatures: %s\n", truth_k ? "no k1 k2 in the result" : "no truth");
    if (!by_status) {
        print_table(err, nsel, with_k);
    } else {
        /* one table per distinct status: gather its rows to the front */
        double *tmp[NQ];
        for (int q = 0; q < NQ; q++) tmp[q] = err[q];
        size_t done_n = 0;
        while (done_n < nsel) {
            unsigned s = stat[done_n];
            size_t m = done_n;
            for (size_t j = done_n; j < nsel; j++) {
                if (stat[j] != s) continue;
                for (int q = 0; q < NQ; q++) {
                    double x = tmp[q][m];
                    tmp[q][m] = tmp[q][j];
                    tmp[q][j] = x;
                }
                unsigned y = stat[m];
                stat[m] = stat[j];
                stat[j] = y;
                m++;
            }
            char name[256];
            printf("\n## status %u (%s)\n", s, jf_point_status_str(s, name, sizeof name));
            double *part[NQ];
            for (int q = 0; q < NQ; q++) part[q] = tmp[q] + done_n;
            print_table(part, m - done_n, with_k);
            done_n = m;
        }
    }
    rc = 0;
done:
    jf_eval_table_free(&res);
    free(truth);
    free(sel);
    free(stat);
    for (int q = 0; q < NQ; q++) free(err[q]);
    return rc;
}
