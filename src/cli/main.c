/* main.c -- `jetfit SUBCOMMAND ...`: dispatch to src/cli/cmd_*.c. */
#define _POSIX_C_SOURCE 200809L /* sigaction */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <gsl/gsl_version.h>

#include "cgal_bridge.h"
#include "cmd.h"
#include "jetfit.h"
#include "view.h"

static const struct {
    const char *name;
    int (*run)(int, char **);
    const char *what;
} cmds[] = {
    {"estimate", jf_cmd_estimate, "normals, curvatures, Monge coefficients"},
    {"generate", jf_cmd_generate, "the paper's surfaces with exact truth"},
    {"convergence", jf_cmd_convergence, "the paper's §6.1 experiment"},
    {"render", jf_cmd_render, "a PNG of a result coloured by curvature"},
    {"eval", jf_cmd_eval, "errors of a result against ground truth"},
    {"study", jf_cmd_study, "neighbourhoods x degrees x flags x noise: table, plots, report"},
    {"view", jf_cmd_view, "a self-contained 3D page of a result (HTML, three.js)"},
};

/* The OpenMP specification version from _OPENMP's date (yyyymm). */
static const char *openmp_version(void)
{
#ifdef _OPENMP
    static const struct { long date; const char *v; } specs[] = {
        {202111, "5.2"}, {202011, "5.1"}, {201811, "5.0"}, {201511, "4.5"},
        {201307, "4.0"}, {201107, "3.1"}, {200805, "3.0"}};
    for (size_t i = 0; i < sizeof specs / sizeof specs[0]; i++)
        if (_OPENMP >= specs[i].date)
            return specs[i].v;
    return "before 3.0";
#else
    return "none";
#endif
}

static void usage(FILE *out)
{
    fprintf(out, "usage: jetfit COMMAND [options]   (jetfit COMMAND --help)\n\n");
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++)
        fprintf(out, "  %-12s %s\n", cmds[i].name, cmds[i].what);
    fprintf(out, "\n  --help       this list\n  --version    print the version\n");
}

/* SIGINT, SIGTERM, SIGHUP, SIGPIPE (a reader of stdout or stderr gone): no
 * temporary output file is left behind, and the exit status says which
 * signal (128 + its number: 130, 143, 129, 141). */
static void on_fatal_signal(int sig)
{
    jf_tmpfiles_remove_all();
    _exit(128 + sig);
}

int main(int argc, char **argv)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction old;
        /* an ignored signal (nohup, a shell's background job) stays ignored */
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(sigs[i], &sa, NULL);
    }
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(stdout);
        return 0;
    }
    int asked, nt = jf_default_threads(&asked); /* OMP_NUM_THREADS clamped: say so, once */
    if (nt != asked)
        fprintf(stderr, "jetfit: OMP_NUM_THREADS asks for %d threads: %d by default here "
                        "(the processors available; --threads N overrides)\n", asked, nt);
    if (!strcmp(argv[1], "--version")) {
        printf("jetfit %s\n", jf_version());
        const char *cgal = jfb_cgal_version(); /* NULL: built with -DJF_CGAL=OFF */
        if (cgal)
            printf("built with CGAL %s, GSL %s, OpenMP %s\n", cgal, GSL_VERSION, openmp_version());
        else
            printf("built without CGAL (natural with --normal poles|mincirc unavailable), "
                   "GSL %s, OpenMP %s\n", GSL_VERSION, openmp_version());
        char three[4200];
        jf_view_three_describe(three, sizeof three);
        printf("view: %s\n", three);
        return 0;
    }
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++)
        if (!strcmp(argv[1], cmds[i].name))
            return cmds[i].run(argc - 1, argv + 1);
    fprintf(stderr, "jetfit: unknown command '%s' (jetfit --help lists them)\n", argv[1]);
    return 2;
}
