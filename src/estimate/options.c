/* options.c -- the estimate's options as text, by parameter name: the one
 * parser of every front end (the command, jetfit-mpi, jetfit study,
 * Python), so that a value means the same everywhere, the Monge degree is
 * derived in one place and the rules are checked once.  Reasons speak of
 * parameters ("must not exceed degree"); front ends add their own
 * spelling of the name (a flag, a keyword). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

/* Strict numbers: the whole string, finite, in range; 0 or -1. */
static int int_of(const char *s, int lo, int hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return -1;
    *out = (int)v;
    return 0;
}

static int double_of(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

/* "a,b,c" -> up to max doubles; the count, or -1. */
static int list_of(const char *s, double *v, int max)
{
    int n = 0;
    for (const char *p = s; *p;) {
        char buf[64];
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == 0 || len >= sizeof buf || n == max) return -1;
        memcpy(buf, p, len);
        buf[len] = '\0';
        if (double_of(buf, &v[n++])) return -1;
        p += len;
        if (*p == ',' && !*++p) return -1;
    }
    return n;
}

static jf_status no(const char **why, const char *reason)
{
    if (why) *why = reason;
    return JF_ERR_INVALID;
}

/* One keyword of a closed set: its index in names (NULL-ended), or -1. */
static int word_of(const char *s, const char *const *names)
{
    for (int i = 0; names[i]; i++)
        if (!strcmp(s, names[i])) return i;
    return -1;
}

static jf_status set_orient(jf_estimate_opts *o, const char *v, const char **why)
{
    int k;
    if (!strncmp(v, "viewpoint:", 10)) {
        double at[3];
        if (list_of(v + 10, at, 3) != 3) return no(why, "expected viewpoint:X,Y,Z");
        memcpy(o->viewpoint, at, sizeof at);
        o->orient = JF_ORIENT_VIEWPOINT;
    } else if (!strncmp(v, "mst:", 4)) {
        if (int_of(v + 4, 1, 256, &k)) return no(why, "expected mst:K with K in 1..256");
        o->orient = JF_ORIENT_MST;
        o->orient_k = (size_t)k;
    } else {
        static const char *const w[] = {"none", "input", "scanner", "mst", NULL};
        static const jf_orient_mode m[] = {JF_ORIENT_NONE, JF_ORIENT_INPUT, JF_ORIENT_SCANNER,
                                           JF_ORIENT_MST};
        if ((k = word_of(v, w)) < 0)
            return no(why, "expected none, input, viewpoint:X,Y,Z, scanner or mst[:K]");
        o->orient = m[k];
    }
    return JF_OK;
}

static jf_status set_scales(jf_params *p, const char *v, const char **why)
{
    double list[8];
    int m = list_of(v, list, 8);
    if (m < 1) return no(why, "expected 1 to 8 sizes K1,K2,...");
    for (int j = 0; j < m; j++) {
        if (list[j] < 3 || list[j] > 100000 || list[j] != floor(list[j]) ||
            (j && list[j] <= list[j - 1]))
            return no(why, "expected ascending integers >= 3");
    }
    for (int j = 0; j < m; j++) p->scales[j] = (size_t)list[j];
    p->nscales = m;
    return JF_OK;
}

jf_status jf_estimate_opts_set(jf_estimate_opts *o, const char *name, const char *v,
                               const char **why)
{
    if (why) *why = NULL;
    if (!o || !name) return no(why, "NULL argument");
    jf_params *p = &o->params;
    int iv, k;
    double dv;
    if (!strcmp(name, "robust_normals")) {
        /* the preset measured on PCPNet (docs/robustness.md): degree
         * selection down to the plane, headed by the weighted top-degree fit */
        p->degree_select = 1;
        p->dist_weight = 0.55;
        return JF_OK;
    }
    static const char *const names[] = {"neighbors", "degree", "monge_degree", "fit", "frame",
                                        "max_cond", "orient", "normal", "robust", "scales",
                                        "degree_select", "dist_weight", "threads", NULL};
    int which = word_of(name, names);
    if (which < 0) return no(why, "not an estimate parameter");
    if (!v) return no(why, "needs a value");
    switch (which) {
    case 0:
        return jf_nb_parse(v, &o->nb, why) == JF_OK ? JF_OK : no(why, why && *why ? *why : "bad neighbourhood");
    case 1:
        if (int_of(v, 1, JF_MAX_DEGREE, &iv)) return no(why, "expected an integer 1..9");
        p->degree = iv;
        break;
    case 2:
        if (int_of(v, 2, JF_MAX_MONGE_DEGREE, &iv)) return no(why, "expected 2, 3 or 4");
        p->monge_degree = iv;
        break;
    case 3: {
        static const char *const w[] = {"approx", "interp", NULL};
        if ((k = word_of(v, w)) < 0) return no(why, "expected approx or interp");
        p->fit = k ? JF_FIT_INTERP : JF_FIT_APPROX;
        break;
    }
    case 4: {
        static const char *const w[] = {"pca", "axis", NULL};
        if ((k = word_of(v, w)) < 0) return no(why, "expected pca or axis");
        p->frame = k ? JF_FRAME_AXIS : JF_FRAME_PCA;
        break;
    }
    case 5:
        if (double_of(v, &dv) || !(dv >= 1)) return no(why, "expected a number >= 1");
        p->max_cond = dv;
        break;
    case 6:
        return set_orient(o, v, why);
    case 7: {
        static const char *const w[] = {"poles", "mincirc", "pca", "input", "jet", "auto", NULL};
        static const jf_normal_source m[] = {JF_NORMAL_POLES, JF_NORMAL_MINCIRC, JF_NORMAL_PCA,
                                             JF_NORMAL_INPUT, JF_NORMAL_JET, JF_NORMAL_AUTO};
        if ((k = word_of(v, w)) < 0) return no(why, "expected auto, poles, mincirc, pca, jet or input");
        o->normal = m[k];
        break;
    }
    case 8: {
        static const char *const w[] = {"none", "huber", "tukey", NULL};
        static const jf_robust_mode m[] = {JF_ROBUST_NONE, JF_ROBUST_HUBER, JF_ROBUST_TUKEY};
        if ((k = word_of(v, w)) < 0) return no(why, "expected none, huber or tukey");
        p->robust = m[k];
        break;
    }
    case 9:
        return set_scales(p, v, why);
    case 10:
        if (int_of(v, 1, JF_MAX_DEGREE, &iv)) return no(why, "expected a degree 1..9");
        p->degree_select = iv;
        break;
    case 11:
        if (double_of(v, &dv) || !(dv > 0)) return no(why, "expected a positive number");
        p->dist_weight = dv;
        break;
    default: /* threads */
        if (int_of(v, 1, 4096, &iv)) return no(why, "expected an integer from 1 to 4096 (the limit)");
        o->threads = iv;
        break;
    }
    return JF_OK;
}

static jf_status bad_param(const char **param, const char **why, const char *name, const char *reason)
{
    if (param) *param = name;
    return no(why, reason);
}

/* The neighbourhood the fitter must hold: the largest the walk may hand it. */
static size_t largest_neighbourhood(const jf_estimate_opts *o)
{
    size_t need = o->nb.kind == JF_NB_KNN || o->nb.kind == JF_NB_KNN_RADIUS ? o->nb.k : o->nb.n;
    if (o->nb.kind == JF_NB_AUTO) need = JF_NB_AUTO_KMAX;
    for (int j = 0; j < o->params.nscales; j++)
        if (o->params.scales[j] > need) need = o->params.scales[j];
    return need;
}

int jf_monge_degree_of(int degree)
{
    /* degree 1 has no curvature: Monge 2, its columns are NaN */
    return degree < 2 ? 2 : degree < JF_MAX_MONGE_DEGREE ? degree : JF_MAX_MONGE_DEGREE;
}

jf_status jf_estimate_opts_finish(jf_estimate_opts *o, const char **param, const char **why)
{
    if (param) *param = NULL;
    if (why) *why = NULL;
    if (!o) return bad_param(param, why, "opts", "NULL argument");
    jf_params *p = &o->params;
    if (p->degree >= 1 && p->degree <= JF_MAX_DEGREE) {
        int top = jf_monge_degree_of(p->degree);
        if (p->monge_degree == 0) p->monge_degree = top;
        else if (p->monge_degree > top)
            return bad_param(param, why, "monge_degree", "must not exceed degree");
    }
    size_t need = largest_neighbourhood(o);
    _Static_assert(JF_MAX_NEIGHBORS == 1048576, "the reason below quotes it");
    if (need > JF_MAX_NEIGHBORS)
        return bad_param(param, why, "neighbors", "K (or N) is too large: at most 1048576");
    if (need > p->max_neighbors) p->max_neighbors = need;
    if (p->degree_select > p->degree)
        return bad_param(param, why, "degree_select", "must not exceed degree");
    const char *field = NULL;
    if (jf_params_validate(p, &field) != JF_OK)
        return bad_param(param, why, field ? field : "params", "invalid value");
    if ((unsigned)o->orient > JF_ORIENT_AUTO) return bad_param(param, why, "orient", "invalid value");
    return JF_OK;
}

jf_status jf_read_opts_set(jf_read_opts *o, const char *name, const char *v, const char **why)
{
    if (why) *why = NULL;
    if (!o || !name) return no(why, "NULL argument");
    if (!v) return no(why, "needs a value");
    if (!strcmp(name, "columns")) {
        double list[6];
        int m = list_of(v, list, 6);
        if (m != 3 && m != 6) return no(why, "expected 3 or 6 column numbers");
        for (int j = 0; j < m; j++)
            if (list[j] < 0 || list[j] > 1000 || list[j] != floor(list[j]))
                return no(why, "expected 0-based column numbers");
        for (int j = 0; j < m; j++) o->columns[j] = (int)list[j];
        return JF_OK;
    }
    if (!strcmp(name, "bad_rows")) {
        static const char *const w[] = {"error", "skip", NULL};
        int k = word_of(v, w);
        if (k < 0) return no(why, "expected error or skip");
        o->bad_rows = k;
        return JF_OK;
    }
    return no(why, "not a reading parameter");
}
