/* neigh_jets.c -- auto's step 6 (neigh_jets.h): the neighbours' jets.
 *
 * Why: where the best K is auto's largest (most noisy cells), one fit on
 * K points can at best tie the fixed K (Gauss-Markov); the fits of the
 * nearest points reach beyond those K.  Each neighbour's normal is
 * carried to q by its own shape operator W_j = k1 d1 d1' + k2 d2 d2' (a
 * first-order step of the Monge form, §2), so a curved patch adds no
 * bias of first order; the curvatures are those of the mean W_j.  Both
 * over the round(K/8) nearest, measured offline (tests/bench/auto_agg.py;
 * docs/robustness.md: K/16 for the normal lost the ellipsoid at 0.1%,
 * K/4 the clean armadillo).  Where the noise is large against the fit's
 * spread (JF_NJ_MID) each W_j is noisy: the normal is then the mean of
 * that and the normals carried by the mean shape operator (a trapezoid
 * step), each neighbour weighted by its slope's inverse variance (a
 * one-sided fit at a border, on fewer points, counts less). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "neigh_jets.h"

int jf__nj_weighted(const jf__njs *s, const jf_result *r)
{
    /* a capped cloud (step 0) has detail at its small K, which the mean
     * shape operator would smooth: the plain carry there, unless step 0
     * found its small fits mildly biased (the range scans: item 8) */
    if (r->status & JF_PT_AUTO_CAPPED) return s->capw;
    return s->weighted || r->sigma / sqrt(2.0 * (r->pca_eval[1] + r->pca_eval[2])) > JF_NJ_MID;
}

/* step 6's divisors of K: the nearest K/4 on capped rows, K/8 for the
 * weighted mean, K/2 (every JF_NJ_STEP-th) for the spread carry */
#define F_CAPPED 4.0
#define F_WEIGHTED 8.0
#define F_SPREAD 2.0

size_t jf__nj_head(const jf__njs *s, const jf_result *r, int wide, size_t *step)
{
    /* half to even, as the offline study; a capped K leaves more noise
     * for the mean to take (step 0).  A quadric fitted on a disk of radius
     * R to the cubic term b x^3 / 6 is off in slope by b R^2 / 12 at its
     * centre, carried to d from it by b (R^2 / 12 - d^2 / 2) along d:
     * over the nearest m of its K points (E d^2 = m R^2 / 2K, half of it
     * along x) the mean error is b R^2 (1/12 - m / 8K), a quarter of the
     * centre's at m = K/2 (nil at 2K/3, where the curvatures' noise has
     * grown: measured within 3%).  The spread cancels it, not the count:
     * every 4th of the K/2 nearest keeps most of the gain at the cost of
     * K/8 (docs/robustness.md, step 6) */
    const int capped = (r->status & JF_PT_AUTO_CAPPED) != 0;
    const int spread = !capped && s->spread && !wide;
    const double f = capped ? F_CAPPED : spread ? F_SPREAD : F_WEIGHTED;
    *step = spread ? JF_NJ_STEP : 1;
    double m = nearbyint(r->n_used / f);
    m = ceil(m / (double)*step); /* the point itself and every step-th after */
    return m < 1 ? 1 : m > JF_NJ_HEAD ? JF_NJ_HEAD : (size_t)m;
}

size_t jf__nj_reach(const jf_params *p)
{
    int cap = p->auto_select & ~JF_AUTO_FLAGS;
    if (cap <= 1 || cap > JF_NB_AUTO_KMAX) cap = JF_NB_AUTO_KMAX;
    const int spread = (p->auto_select & ~JF_AUTO_FLAGS) == 1 || (p->auto_select & JF_AUTO_SPREAD_CARRY);
    const double f = spread ? F_SPREAD : cap < JF_NB_AUTO_KMAX ? F_CAPPED : F_WEIGHTED;
    const size_t m = (size_t)ceil(cap / f);
    return m < 1 ? 1 : m > JF_NJ_REACH ? JF_NJ_REACH : m;
}

void jf__njs_set(jf__njs *s, const jf_params *p)
{
    s->weighted = (p->auto_select & JF_AUTO_WEIGHTED_MEAN) != 0;
    s->spread = (p->auto_select & JF_AUTO_SPREAD_CARRY) != 0;
    s->capw = (p->auto_select & JF_AUTO_CAPPED_WEIGHTED) != 0;
    s->reach = jf__nj_reach(p);
}


/* A tangent basis of a unit n, a function of n alone (Duff et al., "Building
 * an orthonormal basis, revisited", JCGT 2017). */
static void basis(const double n[3], double e1[3], double e2[3])
{
    const double s = n[2] >= 0 ? 1.0 : -1.0, a = -1.0 / (s + n[2]), b = n[0] * n[1] * a;
    e1[0] = 1.0 + s * n[0] * n[0] * a, e1[1] = s * b, e1[2] = -s * n[0];
    e2[0] = b, e2[1] = s + n[1] * n[1] * a, e2[2] = -n[1];
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int16_t q16(double u)
{
    return (int16_t)lrint(u < -1 ? -32767.0 : u > 1 ? 32767.0 : u * 32767.0);
}

static void oct_decode(const int16_t o[2], double n[3])
{
    double u = o[0] / 32767.0, v = o[1] / 32767.0, z = 1.0 - fabs(u) - fabs(v);
    if (z < 0) {
        const double u0 = u;
        u = copysign(1.0 - fabs(v), u0);
        v = copysign(1.0 - fabs(u0), v);
    }
    const double l = sqrt(u * u + v * v + z * z);
    n[0] = u / l, n[1] = v / l, n[2] = z / l;
}

jf_status jf__njs_alloc(jf__njs *s, size_t n)
{
    s->v = malloc((n ? n : 1) * sizeof *s->v);
    s->state = calloc(n ? n : 1, 1);
    if (s->v && s->state) return JF_OK;
    jf__njs_free(s);
    return JF_ERR_NOMEM;
}

void jf__njs_free(jf__njs *s)
{
    free(s->v);
    free(s->state);
    s->v = NULL;
    s->state = NULL;
}

int jf__nj_state(const jf__njs *s, size_t i)
{
    return __atomic_load_n(&s->state[i], __ATOMIC_ACQUIRE);
}

void jf__nj_put(const jf__njs *s, size_t i, const jf_result *r)
{
    uint8_t want = JF_NJ_EMPTY;
    if (__atomic_load_n(&s->state[i], __ATOMIC_RELAXED) != JF_NJ_EMPTY ||
        !__atomic_compare_exchange_n(&s->state[i], &want, JF_NJ_BUSY, 0, __ATOMIC_ACQUIRE,
                                     __ATOMIC_RELAXED))
        return; /* another thread writes (or wrote) the same bytes */
    jf__njet *e = &s->v[i];
    const double *n = r->normal;
    int good = r->degree >= 2 && !(r->status & (JF_PT_FAILED | JF_PT_NONFINITE)) &&
               isfinite(r->k1) && isfinite(r->k2) && isfinite(n[0]) && isfinite(n[1]) &&
               isfinite(n[2]) && isfinite(r->d1[0]) && isfinite(r->d1[1]) && isfinite(r->d1[2]);
    if (good) {
        const double l1 = fabs(n[0]) + fabs(n[1]) + fabs(n[2]);
        double u = n[0] / l1, w = n[1] / l1;
        if (n[2] < 0) {
            const double u0 = u;
            u = copysign(1.0 - fabs(w), u0);
            w = copysign(1.0 - fabs(u0), w);
        }
        e->oct[0] = q16(u), e->oct[1] = q16(w);
        /* W = k1 d1 d1' + k2 d2 d2' in the basis of the normal as decoded */
        double m[3], e1[3], e2[3];
        oct_decode(e->oct, m);
        basis(m, e1, e2);
        const double a1 = dot3(r->d1, e1), b1 = dot3(r->d1, e2), a2 = dot3(r->d2, e1),
                     b2 = dot3(r->d2, e2);
        e->w[0] = (float)(r->k1 * a1 * a1 + r->k2 * a2 * a2);
        e->w[1] = (float)(r->k1 * a1 * b1 + r->k2 * a2 * b2);
        e->w[2] = (float)(r->k1 * b1 * b1 + r->k2 * b2 * b2);
        /* 1 / var of the slope, up to sigma's constant: K points spread
         * over l1 + l2 each (0 where sigma is unknown, FLT_MAX exact) */
        const double iv = r->n_used * (r->pca_eval[1] + r->pca_eval[2]) / (r->sigma * r->sigma);
        e->iv = !(iv >= 0.0) ? 0.0f : iv < FLT_MAX ? (float)iv : FLT_MAX;
    }
    __atomic_store_n(&s->state[i], good ? JF_NJ_FIT : JF_NJ_NONE, __ATOMIC_RELEASE);
}

int jf__nj_decode(const jf__njs *s, size_t j, double out[JF_NJ_DEC])
{
    int st;
    while ((st = __atomic_load_n(&s->state[j], __ATOMIC_ACQUIRE)) == JF_NJ_BUSY)
        ; /* another thread is copying the same bytes in: a few stores */
    if (st != JF_NJ_FIT) return 0;
    const jf__njet *e = &s->v[j];
    double *n = out, *W = out + 3, e1[3], e2[3], u1[3], u2[3];
    oct_decode(e->oct, n);
    basis(n, e1, e2);
    /* W = u1 e1' + u2 e2', u1 = W e1, u2 = W e2 */
    for (int k = 0; k < 3; k++)
        u1[k] = e->w[0] * e1[k] + e->w[1] * e2[k], u2[k] = e->w[1] * e1[k] + e->w[2] * e2[k];
    W[0] = u1[0] * e1[0] + u2[0] * e2[0];
    W[1] = u1[0] * e1[1] + u2[0] * e2[1];
    W[2] = u1[0] * e1[2] + u2[0] * e2[2];
    W[3] = u1[1] * e1[1] + u2[1] * e2[1];
    W[4] = u1[1] * e1[2] + u2[1] * e2[2];
    W[5] = u1[2] * e1[2] + u2[2] * e2[2];
    out[9] = e->iv;
    return 1;
}

void jf__nj_mix(const jf__njs *s, const jf__nj_cache *c, const double *xyz, const double p[3],
                const uint32_t *head, size_t m, jf_result *r)
{
    if (r->degree < 2 || (r->status & (JF_PT_FAILED | JF_PT_NONFINITE)) || !isfinite(r->k1) ||
        !isfinite(r->k2))
        return;
    const int wide = jf__nj_weighted(s, r);
    size_t step, mc = jf__nj_head(s, r, wide, &step);
    if (mc > m) mc = m;
    double ind[3] = {0, 0, 0}, W[6] = {0, 0, 0, 0, 0, 0}; /* W: xx xy xz yy yz zz */
    size_t cc = 0;
    /* the weighted sums: carried normals, normals, q - j, W */
    double sw = 0, iw[3] = {0, 0, 0}, nw[3] = {0, 0, 0}, dw[3] = {0, 0, 0};
    double Ww[6] = {0, 0, 0, 0, 0, 0};
    for (size_t t = 0; t < mc; t++) {
        const size_t j = head[t];
        double own[JF_NJ_DEC];
        const double *D = own;
        if (c && j - c->beg < c->n && c->ok[j - c->beg] != 2) { /* decoded once */
            if (!c->ok[j - c->beg]) continue;
            D = c->dec + JF_NJ_DEC * (j - c->beg);
        } else if (!jf__nj_decode(s, j, own))
            continue;
        const double *n = D, *Wj = D + 3;
        /* every neighbour on q's side: a flip negates the shape operator */
        const double sg = dot3(n, r->normal) < 0 ? -1.0 : 1.0;
        for (int k = 0; k < 6; k++) W[k] += sg * Wj[k];
        cc++;
        /* n_j - W_j (q - j): n_j carried to q (§2) */
        const double *pj = xyz + 3 * j;
        const double d[3] = {p[0] - pj[0], p[1] - pj[1], p[2] - pj[2]};
        const double wd[3] = {Wj[0] * d[0] + Wj[1] * d[1] + Wj[2] * d[2],
                              Wj[1] * d[0] + Wj[3] * d[1] + Wj[4] * d[2],
                              Wj[2] * d[0] + Wj[4] * d[1] + Wj[5] * d[2]};
        for (int k = 0; k < 3; k++) ind[k] += sg * (n[k] - wd[k]);
        if (!wide) continue;
        const double w = D[9], ws = sg * w;
        sw += w;
        for (int k = 0; k < 3; k++)
            iw[k] += ws * (n[k] - wd[k]), nw[k] += ws * n[k], dw[k] += w * d[k];
        for (int k = 0; k < 6; k++) Ww[k] += ws * Wj[k];
    }
    if (wide && sw > 0 && isfinite(sw)) {
        /* (mean of n_j - W_j (q - j) + mean of n_j - W (q - j)) / 2, W
         * the mean W_j; the second is mean n_j - W (mean q - j) */
        for (int k = 0; k < 3; k++) dw[k] /= sw; /* mean q - j; the sums stay x sw */
        const double wb[3] = {nw[0] - (Ww[0] * dw[0] + Ww[1] * dw[1] + Ww[2] * dw[2]),
                              nw[1] - (Ww[1] * dw[0] + Ww[3] * dw[1] + Ww[4] * dw[2]),
                              nw[2] - (Ww[2] * dw[0] + Ww[4] * dw[1] + Ww[5] * dw[2])};
        for (int k = 0; k < 3; k++) ind[k] = iw[k] + wb[k]; /* x 2 sw: normalised below */
    }
    const double l = sqrt(dot3(ind, ind));
    if (!cc || !(l > 0) || !isfinite(l)) return;
    double n[3] = {ind[0] / l, ind[1] / l, ind[2] / l}, e1[3], e2[3];
    basis(n, e1, e2);
    /* the mean W in the plane normal to n: 2 x 2, closed form */
    double We1[3], We2[3];
    for (int k = 0; k < 3; k++) W[k] /= (double)cc, W[3 + k] /= (double)cc;
    We1[0] = W[0] * e1[0] + W[1] * e1[1] + W[2] * e1[2];
    We1[1] = W[1] * e1[0] + W[3] * e1[1] + W[4] * e1[2];
    We1[2] = W[2] * e1[0] + W[4] * e1[1] + W[5] * e1[2];
    We2[0] = W[0] * e2[0] + W[1] * e2[1] + W[2] * e2[2];
    We2[1] = W[1] * e2[0] + W[3] * e2[1] + W[4] * e2[2];
    We2[2] = W[2] * e2[0] + W[4] * e2[1] + W[5] * e2[2];
    const double a = dot3(e1, We1), b = dot3(e1, We2), cc2 = dot3(e2, We2);
    const double mid = 0.5 * (a + cc2), rad = hypot(0.5 * (a - cc2), b),
                 phi = 0.5 * atan2(2.0 * b, a - cc2);
    const double cp = cos(phi), sp = sin(phi);
    memcpy(r->normal, n, sizeof n);
    r->k1 = mid + rad, r->k2 = mid - rad;
    for (int k = 0; k < 3; k++) r->d1[k] = cp * e1[k] + sp * e2[k];
    r->d2[0] = n[1] * r->d1[2] - n[2] * r->d1[1];
    r->d2[1] = n[2] * r->d1[0] - n[0] * r->d1[2];
    r->d2[2] = n[0] * r->d1[1] - n[1] * r->d1[0];
    /* umbilic as the fit's rule (monge.c): k1 - k2 <= 1e-10 max(|k1|,
     * |k2|, 1/h), h here the distance to the farthest record read */
    const double *pf = xyz + 3 * (size_t)head[mc - 1];
    const double h = sqrt((p[0] - pf[0]) * (p[0] - pf[0]) + (p[1] - pf[1]) * (p[1] - pf[1]) +
                          (p[2] - pf[2]) * (p[2] - pf[2]));
    const double big = fmax(fmax(fabs(r->k1), fabs(r->k2)), h > 0 ? 1.0 / h : 0.0);
    r->status &= ~(unsigned)(JF_PT_UMBILIC | JF_PT_AUTO_WEIGHTED | JF_PT_AUTO_SPREAD);
    if (wide && sw > 0 && isfinite(sw)) r->status |= JF_PT_AUTO_WEIGHTED;
    if (step > 1) r->status |= JF_PT_AUTO_SPREAD;
    if (2.0 * rad <= 1e-10 * big) r->status |= JF_PT_UMBILIC;
}
