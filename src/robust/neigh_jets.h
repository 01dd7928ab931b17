/* neigh_jets.h -- auto's last step: a point's normal and curvatures from
 * the jets of its nearest points (docs/robustness.md, "Neighbourhood
 * auto", step 6).  The estimate keeps one 20-byte record per point (its
 * fit's normal, shape operator and slope's weight), written by whichever
 * thread fits the point first: each fit depends only on its own
 * neighbourhood, so every writer writes the same bytes. */
#ifndef JF_NEIGH_JETS_H
#define JF_NEIGH_JETS_H
#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

/* One point's fit, compact: its normal (octahedral, 2 x 16 bits),
 * shape operator in the tangent basis of that normal as decoded (w11,
 * w12, w22: no angle to decode) and the inverse variance of its slope
 * up to a constant, K (l1 + l2) / sigma^2 (l: the K points' tangent
 * covariance eigenvalues).  The states are a byte array beside. */
typedef struct {
    int16_t oct[2];
    float w[3];
    float iv;
} jf__njet;

typedef struct {
    jf__njet *v;
    uint8_t *state; /* JF_NJ_*: read and written atomically */
    int weighted;   /* JF_AUTO_WEIGHTED_MEAN: the weighted mean on every
                       row not capped, whatever its noise                  */
    int spread;     /* JF_AUTO_SPREAD_CARRY: the plain carry over every
                       JF_NJ_STEP-th of the K/2 nearest                    */
    int capw;       /* JF_AUTO_CAPPED_WEIGHTED: the weighted mean on
                       capped rows too                                   */
    size_t reach;   /* the farthest of a point's nearest a row reads
                       (jf__nj_reach)                                      */
} jf__njs;

enum { JF_NJ_EMPTY = 0, JF_NJ_BUSY = 1, JF_NJ_FIT = 2, JF_NJ_NONE = 3 };

/* n records, all JF_NJ_EMPTY (the rest of s: jf__njs_set); JF_OK or
 * JF_ERR_NOMEM. */
jf_status jf__njs_alloc(jf__njs *s, size_t n);
void jf__njs_free(jf__njs *s);

/* sigma / sqrt(2 (l1 + l2)) of the point's own fit (about sigma / r_K
 * on a disk of radius r_K) above which the normal mixes with weights
 * (jf__nj_mix; docs/robustness.md, step 6) */
#define JF_NJ_MID 0.03

/* The most records a row reads (K/8 of K <= 256, or every JF_NJ_STEP-th
 * of the nearest K/2), and the farthest of its nearest among them. */
#define JF_NJ_HEAD 32
#define JF_NJ_STEP 4
#define JF_NJ_REACH (JF_NJ_HEAD * JF_NJ_STEP)

/* The farthest of its nearest points a row of an estimate with p reads
 * (1-based): up to JF_NJ_REACH where a row may take the spread carry
 * (JF_AUTO_SPREAD_CARRY, or params.auto_select 1: not yet decided), else
 * 32, less under a cap. */
size_t jf__nj_reach(const jf_params *p);

/* s's weighted, spread and reach from an estimate's params (after step 0
 * decided them). */
void jf__njs_set(jf__njs *s, const jf_params *p);

/* Whether an estimate runs step 6: auto on a k-NN of at least
 * JF_NJ_KMIN (JF_NB_AUTO's knn:JF_NB_AUTO_KMAX), whose shared search
 * (knn_share.c) gives the tree positions the records are keyed by. */
#define JF_NJ_KMIN 128
static inline int jf__nj_on(const jf_params *p, const jf_nb_spec *nb)
{
#ifdef JF_STEP6_OFF /* a study build: steps 1-5's rows (tests/bench/auto_agg.py) */
    (void)p, (void)nb;
    return 0;
#else
    return p->auto_select && nb->kind == JF_NB_KNN && nb->k >= JF_NJ_KMIN;
#endif
}

/* Whether row r takes the weighted trapezoid mean: capped, where step 0
 * says so (s->capw); else where its noise is large against its fit's
 * spread (JF_NJ_MID) or the cloud's fits are bound by the noise
 * (s->weighted). */
int jf__nj_weighted(const jf__njs *s, const jf_result *r);

/* Which of a point's nearest its row r reads (wide: jf__nj_weighted's),
 * the normal and the curvatures from: the nearest round(K / 4) where K
 * was capped (step 0), round(K / 8) where the mean is weighted or the
 * carry not spread, every
 * JF_NJ_STEP-th of the nearest round(K / 2) for the spread carry (s->
 * spread: a mean over that spread cancels most of the slope bias a cubic
 * term leaves in the quadric).  Returns how many (at least 1, at most
 * JF_NJ_HEAD), *step the stride (1 or JF_NJ_STEP) from the point
 * itself. */
size_t jf__nj_head(const jf__njs *s, const jf_result *r, int wide, size_t *step);

/* The state of point i's record (JF_NJ_*). */
int jf__nj_state(const jf__njs *s, size_t i);

/* Point i's record from its row r (any thread; the first writer wins,
 * later ones leave it: the same bytes). */
void jf__nj_put(const jf__njs *s, size_t i, const jf_result *r);

/* Record j decoded: its normal (3), shape operator in 3-D (xx xy xz
 * yy yz zz) and weight iv to out; 0 if it holds no fit.  Waits out a
 * JF_NJ_BUSY record (its writer is mid-copy); j must not be JF_NJ_EMPTY. */
#define JF_NJ_DEC 10
int jf__nj_decode(const jf__njs *s, size_t j, double out[JF_NJ_DEC]);

/* Records beg .. beg + n - 1 decoded once (ok[t]: jf__nj_decode's
 * return, or 2: not decoded, read the record), for the rows that read
 * them most: the same bits. */
typedef struct {
    const double *dec;
    const uint8_t *ok;
    size_t beg, n;
} jf__nj_cache;

/* Row r of point q (at p) from the records head[0..m-1] of its nearest
 * that jf__nj_head names (q's own first; none JF_NJ_EMPTY), through the cache c where it
 * holds them (may be NULL), at coordinates xyz (3 per record): the
 * normal the mean of each neighbour's normal carried to p by its shape
 * operator (where the noise is small against the fit's spread; above
 * JF_NJ_MID, the mean of that and the normals carried by the mean
 * shape operator, weighted by the slopes' inverse variances), the
 * curvatures and directions those of the mean shape operator in the
 * plane normal to it.  Rows not fitted at degree >= 2 are left as they
 * are. */
void jf__nj_mix(const jf__njs *s, const jf__nj_cache *c, const double *xyz, const double p[3],
                const uint32_t *head, size_t m, jf_result *r);
#endif
