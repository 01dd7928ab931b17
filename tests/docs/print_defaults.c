/* print_defaults.c -- the defaults of `jetfit estimate` as the code sets
 * them (jf_cli_est_init, jf_estimate_opts_init, jf_params_init,
 * jf_read_opts_init, the command line's own), one "name=value" a line,
 * for check_defaults.py to compare with every document that quotes them. */
#include <stdio.h>

#include "jetfit.h"
#include "opts.h"

int main(void)
{
    char *argv[] = {"estimate", "in.xyz", "-o", "out.ply", NULL};
    jf_cli_estimate_cmd cmd;
    jf_cli_bad bad;
    if (jf_cli_estimate_parse(4, argv, &cmd, &bad)) return 1;
    const jf_estimate_opts *o = &cmd.e.o;
    const jf_params *p = &o->params;
    char nb[64];
    static const char *const fit[] = {"approx", "interp"}, *const frame[] = {"pca", "axis"},
                             *const robust[] = {"none", "huber", "tukey"};
    printf("neighbors=%s\n", jf_nb_format(&o->nb, nb, sizeof nb));
    printf("degree=%d\n", p->degree);
    /* the Monge degree follows the jet's: min(degree, JF_MAX_MONGE_DEGREE) */
    printf("monge-degree=min(degree, %d)\n", JF_MAX_MONGE_DEGREE);
    printf("fit=%s\nframe=%s\n", fit[p->fit == JF_FIT_INTERP], frame[p->frame == JF_FRAME_AXIS]);
    printf("max-cond=%g\n", p->max_cond);
    printf("robust=%s\n", robust[p->robust]);
    printf("orient=%s\n", o->orient == JF_ORIENT_AUTO ? "auto" : "?");
    printf("orient-k=%zu\n", o->orient_k);
    printf("normal=%s\n", o->normal == JF_NORMAL_AUTO ? "auto" : "?");
    printf("scales=%s\n", p->nscales ? "on" : "off");
    printf("degree-select=%s\n", p->degree_select ? "on" : "off");
    printf("dist-weight=%s\n", p->dist_weight > 0 ? "on" : "off");
    printf("threads=%s\n", o->threads > 0 ? "fixed" : "all cores");
    printf("keep=%s\n", cmd.keep ? "all" : "none");
    printf("bad-rows=%s\n", cmd.e.ro.bad_rows ? "skip" : "error");
    printf("memory=%s\n", cmd.memory ? "fixed" : "MemAvailable");
    return 0;
}
