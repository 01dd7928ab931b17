/* params.c -- fit parameters: defaults and validation. */
#include <math.h>
#include <string.h>

#include "jetfit.h"

/* Default kappa threshold of the adaptive degree (§5.2), measured (docs/numerics.md
 * "Per point"): on exact §6.1 data kappa stays below ~3e4 and
 * errors grow ~ kappa; on a raw bunny scan (bun000) fits with kappa > 1e3
 * have normals 38-57 degrees off a K64 2-jet on average, and lowering
 * them brings that to 11-18 degrees. */
#define JF_DEFAULT_MAX_COND 1e3

/* Largest neighbourhood a fitter accepts (bounds the workspace). */

size_t jf_jet_size(int degree)
{
    if (degree < 0) return 0;
    return (size_t)(degree + 1) * (size_t)(degree + 2) / 2;
}

void jf_params_init(jf_params *p)
{
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->degree = 2;
    p->monge_degree = 2;
    p->fit = JF_FIT_APPROX;
    p->frame = JF_FRAME_PCA;
    p->max_cond = JF_DEFAULT_MAX_COND;
    p->max_neighbors = 256;
    p->robust = JF_ROBUST_NONE;
    p->robust_iters = 10;
    p->nscales = 0;
}

static jf_status bad(const char **bad_field, const char *name)
{
    if (bad_field) *bad_field = name;
    return JF_ERR_INVALID;
}

jf_status jf_params_validate(const jf_params *p, const char **bad_field)
{
    if (bad_field) *bad_field = NULL;
    if (!p) return bad(bad_field, "params");
    if (p->degree < 1 || p->degree > JF_MAX_DEGREE) return bad(bad_field, "degree");
    /* Degree 1 keeps the default monge_degree 2 valid: its curvatures are
     * reported NaN (a 1-jet has no second order). */
    if (p->monge_degree < 2 || p->monge_degree > JF_MAX_MONGE_DEGREE ||
        p->monge_degree > (p->degree < 2 ? 2 : p->degree))
        return bad(bad_field, "monge_degree");
    if (p->fit != JF_FIT_APPROX && p->fit != JF_FIT_INTERP) return bad(bad_field, "fit");
    if (p->frame != JF_FRAME_PCA && p->frame != JF_FRAME_AXIS) return bad(bad_field, "frame");
    /* NaN fails the comparison; +Inf disables the condition test. */
    if (!(p->max_cond >= 1.0)) return bad(bad_field, "max_cond");
    if (p->max_neighbors < 1 || p->max_neighbors > JF_MAX_NEIGHBORS)
        return bad(bad_field, "max_neighbors");
    if (p->robust != JF_ROBUST_NONE && p->robust != JF_ROBUST_HUBER &&
        p->robust != JF_ROBUST_TUKEY)
        return bad(bad_field, "robust");
    if (p->robust_iters < 1 || p->robust_iters > 1000) return bad(bad_field, "robust_iters");
    if (p->nscales < 0 || p->nscales > (int)(sizeof p->scales / sizeof p->scales[0]))
        return bad(bad_field, "nscales");
    for (int i = 0; i < p->nscales; i++) {
        if (p->scales[i] < 1 || p->scales[i] > p->max_neighbors) return bad(bad_field, "scales");
        if (i > 0 && p->scales[i] <= p->scales[i - 1]) return bad(bad_field, "scales");
    }
    if (p->degree_select < 0 || p->degree_select > p->degree)
        return bad(bad_field, "degree_select");
    if (!(p->dist_weight >= 0.0) || !isfinite(p->dist_weight)) return bad(bad_field, "dist_weight");
    const int cap = p->auto_select & ~JF_AUTO_FLAGS;
    if (p->auto_select < 0 || cap > JF_NB_AUTO_KMAX || (cap > 1 && cap < 16) ||
        (cap == 0 && p->auto_select))
        return bad(bad_field, "auto_select");
    return JF_OK;
}
