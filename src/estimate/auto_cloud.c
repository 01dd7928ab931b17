/* auto_cloud.c -- neighbors auto's step 0: one cap on K for the whole
 * cloud, from its leave-one-out cross-validation (docs/robustness.md,
 * "Neighbourhood auto", step 0).
 *
 * design:
 *  - the sample: the finite points whose input index is a multiple of
 *    jf__auto_cv_stride(n) (n: the whole cloud's count), so a part or a
 *    rank finds its share of the same sample from input indices alone;
 *  - per sampled point, jf__auto_cv_point on its JF_NB_AUTO_KMAX nearest
 *    (the walk's list, bit for bit): the quadric's squared leave-one-out
 *    residual at each candidate K and sigma / r16;
 *  - the decision (jf__auto_cv_decide) sums them, each clipped at 25
 *    times its candidate's median, in input-index order,
 *    whoever computed them: whole cloud, parts and ranks agree.
 * Where the cubic on the 16 nearest, in their own frame, predicts p better
 * than the quadric at no more than half the sample, the noise outweighs
 * the detail a small cubic adds: no cubic below K = 48
 * (JF_AUTO_CUBIC_MIN48; the cubic is nearer at 63% of the clean
 * armadillo's points, 82-100% of clean generated clouds', 36-49% of
 * noisy clouds' and of the range scans', where cubics at K = 32 were 6.3
 * degrees RMS off the mesh against the quadric's 4.8).
 * Where the noise is thin against the spacing (median sigma / r16 at most
 * JF_CV_THICK) CV(K) is the error of the height at p plus the noise, and
 * its least K is the cloud's best K or its neighbour (item 7 of "What is
 * not met"); where it is thick the 3-D nearest of a noisy p lie on its
 * side and CV is least at the smallest K whatever the surface, so no cap.
 * A pick of 128 or more caps nothing: the curvatures want the largest K
 * (every cap below 256 loses the torus's |dk1|, item 7).
 * Where nothing is capped and the quadric's normal on the 256 nearest is
 * as near the cubic's as noise alone would put it (the median of
 * JF_AUTO_CV_BIAS at most 1; about ln 2 without bias), the quadric's slope
 * bias is small against its noise: step 6 takes its weighted trapezoid
 * mean on every row (JF_AUTO_WEIGHTED_MEAN; the `exp` patch at 0.1% reads
 * 0.65); where it is above 1 and at most 4, a cubic term's bias, step 6's
 * plain carry reads every 4th of the K/2 nearest (JF_AUTO_SPREAD_CARRY;
 * the ellipsoid and the torus at 0.1% read 1.9 and 1.5; item 6).
 * Where K is capped and the same statistic on 32 points is above 1, at
 * most 4, the capped rows take the weighted mean and K = 32 where the
 * cap was below (JF_AUTO_CAPPED_WEIGHTED; the range scans read 1.5-2.1;
 * item 8). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "auto_cloud.h"
#include "core/order_stat.h"
#include "index_internal.h"
#include "nbctx.h" /* jf__finite3 */
#include "robust_internal.h"

#define JF_CV_SAMPLES 2048 /* about this many points (2% of 10^5)         */
#define JF_CV_THICK 0.4    /* median sigma / r16 above: thick noise        */
#define JF_CV_MAXPICK 64   /* a pick above this caps nothing               */
#define JF_CV_MINREC 32    /* fewer usable sample points: no cap           */
#define JF_CV_CLIP 25.0    /* a squared residual counts at most this times
                              its candidate's median                      */
#define JF_CV_NOBIAS 1.0   /* median bias statistic at most: noise-bound   */
#define JF_CV_MILDBIAS 4.0 /* at most: a cubic term's bias, spread carry   */

size_t jf__auto_cv_stride(size_t ntotal)
{
    /* a quarter at most: on a small cloud the sample is no second pass */
    return ntotal / JF_CV_SAMPLES > 4 ? ntotal / JF_CV_SAMPLES : 4;
}

/* local point i is sampled: own, finite, its input index a multiple of stride */
static int sampled(const double *xyz, const uint8_t *own, const uint32_t *gid, size_t stride, size_t i)
{
    return (!own || own[i]) && (gid ? gid[i] : i) % stride == 0 && jf__finite3(xyz + 3 * i);
}

int jf__auto_cv_wanted(const jf_params *p, const jf_nb_spec *nb)
{
    return (p->auto_select & ~JF_AUTO_FLAGS) == 1 && nb->kind == JF_NB_KNN &&
           nb->k >= JF_NB_AUTO_KMAX;
}

jf_status jf__auto_cv_sample(const double *xyz, size_t n, const uint8_t *own, const uint32_t *gid,
                             size_t ntotal, const jf_index *ix, const jf_params *pr, int nt,
                             jf__cvrec **out, size_t *nout)
{
    *out = NULL;
    *nout = 0;
    const size_t stride = jf__auto_cv_stride(ntotal);
    size_t ns = 0;
    for (size_t i = 0; i < n; i++) ns += (size_t)sampled(xyz, own, gid, stride, i);
    if (!ns) return JF_OK;
    jf__cvrec *r = malloc(ns * sizeof *r);
    if (!r) return JF_ERR_NOMEM;
    ns = 0;
    for (size_t i = 0; i < n; i++)
        if (sampled(xyz, own, gid, stride, i)) r[ns++].gid = (uint32_t)i; /* local until the fits */
    jf_index *mine = NULL;
    jf_status st = JF_OK;
    if (!ix && (st = jf__index_build_threads(xyz, n, nt, &mine)) != JF_OK) {
        free(r);
        return st;
    }
    const jf_index *use = ix ? ix : mine;
    jf_params fp = *pr;
    if (fp.max_neighbors < JF_NB_AUTO_KMAX) fp.max_neighbors = JF_NB_AUTO_KMAX;
    fp.auto_select = 1;
#pragma omp parallel num_threads(nt)
    {
        jf_fitter *f = NULL;
        uint32_t idx[JF_NB_AUTO_KMAX];
        double d2[JF_NB_AUTO_KMAX], *nbr = malloc(3 * JF_NB_AUTO_KMAX * sizeof *nbr);
        jf_status ts = nbr ? jf_fitter_create(&fp, &f) : JF_ERR_NOMEM;
#pragma omp for schedule(dynamic, 16)
        for (size_t s = 0; s < ns; s++) {
            if (ts != JF_OK) continue;
            const size_t i = r[s].gid;
            size_t found = 0;
            ts = jf__index_query(use, xyz + 3 * i, JF_NB_AUTO_KMAX, INFINITY, idx, d2, nbr, &found);
            if (ts == JF_OK) jf__auto_cv_point(f, &fp, xyz + 3 * i, nbr, found, r[s].v);
        }
        if (ts != JF_OK) {
#pragma omp critical(jf_auto_cv)
            st = ts;
        }
        jf_fitter_free(f);
        free(nbr);
    }
    jf_index_free(mine);
    if (st != JF_OK) {
        free(r);
        return st;
    }
    for (size_t s = 0; s < ns; s++) r[s].gid = gid ? gid[r[s].gid] : r[s].gid;
    *out = r;
    *nout = ns;
    return JF_OK;
}

static int by_gid(const void *a, const void *b)
{
    const uint32_t x = ((const jf__cvrec *)a)->gid, y = ((const jf__cvrec *)b)->gid;
    return (x > y) - (x < y);
}

/* every candidate's CV is there */
static int usable(const jf__cvrec *r)
{
    for (int c = 0; c < JF_AUTO_NCAND; c++)
        if (!isfinite(r->v[c])) return 0;
    return 1;
}

/* The median (the upper one of an even count) of value f of the records
 * (only the usable ones' finite values where cv, else every one not NaN:
 * +inf, a bias with no noise at all, is the largest), gathered in t (room
 * n; NULL, no memory: none); *m (may be NULL) how many there were. */
static double field_median(const jf__cvrec *r, size_t n, int f, int cv, double *t, size_t *m)
{
    size_t k = 0;
    for (size_t s = 0; s < n && t; s++) {
        const double v = r[s].v[f];
        if (cv ? usable(&r[s]) && isfinite(v) : !isnan(v)) t[k++] = v;
    }
    if (m) *m = k;
    if (!k) return NAN;
    jf__select_kth(t, k, k / 2);
    return t[k / 2];
}

int jf__auto_cv_decide(jf__cvrec *r, size_t n, jf__auto_cv_why *why)
{
    jf__auto_cv_why w;
    memset(&w, 0, sizeof w);
    w.cap = JF_NB_AUTO_KMAX;
    qsort(r, n, sizeof *r, by_gid); /* input order: every split sums alike */
    double *t = malloc((n ? n : 1) * sizeof *t);
    /* each candidate's squared residuals clipped at JF_CV_CLIP times their
     * median over the usable records (no clip where none, or no memory).
     * A few wild points' residuals dominate the plain sums (the range scan
     * ear_back's: 2 10^4 to 1, least at K = 96 where its other scans' is
     * at 16-24); clipped, a point counts at most about (3.4 sigma)^2 for
     * Gaussian residuals, whose median square is 0.455 sigma^2 (robust
     * cross-validation: Leung, Ann. Stat. 2005) */
    double clip[JF_AUTO_NCAND], sum[JF_AUTO_NCAND] = {0};
    for (int c = 0; c < JF_AUTO_NCAND; c++) {
        const double md = field_median(r, n, c, 1, t, NULL);
        clip[c] = isnan(md) ? INFINITY : JF_CV_CLIP * md;
    }
    size_t nb = 0, n32 = 0, nsmall = 0, cubic = 0; /* the smallest K's: both fitted, the cubic nearer */
    for (size_t s = 0; s < n; s++) {
        const double *v2 = r[s].v + JF_AUTO_CV_SMALL;
        if (isfinite(v2[0]) && isfinite(v2[1])) cubic += v2[1] < v2[0], nsmall++;
        if (!usable(&r[s])) continue;
        for (int c = 0; c < JF_AUTO_NCAND; c++) sum[c] += fmin(r[s].v[c], clip[c]);
        w.used++;
    }
    w.median = field_median(r, n, JF_AUTO_NCAND, 1, t, NULL);
    w.bias = field_median(r, n, JF_AUTO_CV_BIAS, 0, t, &nb);
    w.bias32 = field_median(r, n, JF_AUTO_CV_BIAS32, 0, t, &n32);
    free(t);
    if (w.used >= JF_CV_MINREC) {
        int b = 0;
        for (int c = 1; c < JF_AUTO_NCAND; c++)
            if (sum[c] < sum[b]) b = c;
        w.pick = (int)jf__auto_ks[b];
        if (w.median <= JF_CV_THICK && jf__auto_ks[b] <= JF_CV_MAXPICK) w.cap = (int)jf__auto_ks[b + 1];
    }
    /* the cubic on the fewest points predicts p better than the quadric
     * at no more than half the sample: the noise outweighs the detail a
     * cubic would add (a vote, not the sums: a few wild points move them) */
    if (nsmall >= JF_CV_MINREC) w.cubic_min48 = 2 * cubic <= nsmall;
    if (w.cubic_min48) w.cap |= JF_AUTO_CUBIC_MIN48;
    /* no cap, and the quadric's normal on the most points is as near the
     * cubic's as the noise alone puts it at most of the sample: the noise,
     * not the bias, bounds the fits, and the weighted trapezoid mean,
     * which averages the neighbours' slopes and keeps their bias, is the
     * better of step 6's two means on every row (the `exp` patch at 0.1%) */
    if ((w.cap & ~JF_AUTO_FLAGS) == JF_NB_AUTO_KMAX && nb >= JF_CV_MINREC)
        w.cap |= w.bias <= JF_CV_NOBIAS ? JF_AUTO_WEIGHTED_MEAN
                 /* a mild bias, a cubic term's: the plain carry over a
                  * spread that averages it out (neigh_jets.c); a larger
                  * one is detail or thin parts the spread would cross
                  * (the uncapped range scan ear_back reads 45) */
                 : w.bias <= JF_CV_MILDBIAS ? JF_AUTO_SPREAD_CARRY
                                            : 0;
    /* capped, and the quadric on 32 points a little more off the cubic
     * than the noise explains (the range scans read 1.5-2.1; the
     * armadillo at 0.125%, whose fits at its cap are noise-bound, 0.8,
     * the clean one 13): the plain carry by each neighbour's own shape
     * operator added more noise than it took (the scans' normals agree
     * less between overlapping scans with it); the weighted trapezoid
     * mean does not; and the scans' best K is 32 (as the mesh judges,
     * the least CV's 16-24 less), which the cap and the fits keep
     * (auto.c: no candidate below it; item 8) */
    const int cap = w.cap & ~JF_AUTO_FLAGS;
    if (cap < JF_NB_AUTO_KMAX && n32 >= JF_CV_MINREC && w.bias32 > JF_CV_NOBIAS &&
        w.bias32 <= JF_CV_MILDBIAS)
        w.cap = (w.cap & JF_AUTO_FLAGS) | JF_AUTO_CAPPED_WEIGHTED |
                (cap < JF_AUTO_CAPW_KMIN ? JF_AUTO_CAPW_KMIN : cap);
    if (why) *why = w;
    return w.cap;
}

int jf__auto_cv_select(const jf_params *p, jf__cvrec *r, size_t n)
{
    return jf__auto_cv_decide(r, n, NULL) | (p->auto_select & JF_AUTO_FLAGS);
}
