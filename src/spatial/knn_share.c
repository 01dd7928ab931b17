/* knn_share.c -- the k nearest of consecutive, nearby query points from
 * one k-d tree search (neighbors auto's 256 nearest: docs/robustness.md).
 *
 * design:
 *  1. At a query point c, one search for its KSHARE x k nearest (the
 *     candidates), with rk = |c - k-th| and R = |c - last candidate|:
 *     every point nearer c than R is a candidate.  4k, not 2k: where the
 *     noise is thicker than the spacing R / rk is 4^(1/3), not 2^(1/3),
 *     and a search serves 13 points, not 2 (10^6 noisy torus).  The
 *     search is bounded by a prediction from the last one (rebuild).
 *  2. A later query q, delta = |q - c|: c's k nearest lie within
 *     rk + delta of q, so q's k nearest are among the candidates within
 *     that of q (a prefix of them: within rk + 2 delta of c).  Sorted by
 *     (squared distance, input index), the tree's order with its own d2
 *     arithmetic, the first k give t = |q - k-th|; every point within t
 *     of q is within t + delta of c, so if t + delta < R they are q's k
 *     nearest -- the same list, bit for bit, as jf__index_query,
 *     whichever point built the candidates (threads, parts and ranks
 *     still agree).  A bucket sort by d2 (as the tree's buf_finish).
 *  3. Otherwise q becomes the new c.  The last SH_SETS searches'
 *     candidates are kept (the walk comes back to a neighbourhood it
 *     left), the set whose centre is nearest q tried first (the shortest
 *     prefix); a search replaces the oldest.
 * Rounding: the test keeps a relative margin of 1e-9 (distances carry
 * errors near 1e-16), and a selection that finds fewer than k inside
 * the bound falls back to the search.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "avx_path.h" /* JF_CLONES */
#include "index_internal.h"
#include "simd.h"

#define SH_AHEAD 16 /* walk points looked at for a search's centre */
#define KSHARE 4 /* candidates: KSHARE x k (up to 1024: the tree's buffer mode) */
#define SH_MARGIN 1.3 /* on the squared radius a search predicts (rebuild) */
#define SH_JUMP 1.25 /* on the last search's squared radius, where it predicts nothing */
#define SH_SETS 3 /* candidate sets kept: the walk comes back to the last but one */

/* One search's candidates. */
typedef struct {
    size_t nc;     /* candidates held (0: none yet)                     */
    double c[3];   /* the point they were searched from                 */
    double rk, R;  /* |c - k-th|, |c - last| (INFINITY: the whole cloud) */
    uint32_t *cid; /* input indices, coordinates of the candidates      */
    uint32_t *cpos; /* and their tree positions                        */
    double *cxyz;
    double *cx, *cy, *cz; /* the same coordinates by axis (the d2 loop)    */
    double *cd2;   /* their squared distances to c, ascending           */
} sh_set;

struct jf__knn_share {
    size_t k, kc;  /* asked, candidates searched                       */
    size_t npos;   /* positions written per query (the first npos)     */
    sh_set set[SH_SETS];
    int cur;       /* the set that served last (or was searched last)  */
    double *d2;    /* per query: candidates' d2                          */
    uint32_t *sel, *start, *bkt;
    double *td;
    uint32_t *tp;
    const double *ahead; /* the walk's next points (ahead[0..2]: this one) */
    size_t nahead;
    double rk_last;      /* rk of the last search (0: none yet)          */
    double t_last;       /* the last query's k-th distance               */
    double expo;         /* log2 of the last search's d2, last / middle (0: none) */
};

void jf__knn_share_ahead(jf__knn_share *s, const double *xyz, size_t n)
{
    s->ahead = xyz;
    s->nahead = n;
}

void jf__knn_share_free(jf__knn_share *s)
{
    if (!s) return;
    for (int i = 0; i < SH_SETS; i++) {
        free(s->set[i].cid);
        free(s->set[i].cpos);
        free(s->set[i].cxyz);
        free(s->set[i].cx);
        free(s->set[i].cd2);
    }
    free(s->d2);
    free(s->sel);
    free(s->bkt);
    free(s->start);
    free(s->td);
    free(s->tp);
    free(s);
}

jf_status jf__knn_share_create(size_t k, size_t npos, jf__knn_share **out)
{
    *out = NULL;
    if (!k) return JF_ERR_INVALID;
    jf__knn_share *s = calloc(1, sizeof *s);
    if (!s) return JF_ERR_NOMEM;
    s->k = k;
    s->npos = npos < k ? npos : k;
    s->kc = KSHARE * k;
    int ok = 1;
    for (int i = 0; i < SH_SETS; i++) {
        sh_set *cs = &s->set[i];
        cs->cid = malloc(s->kc * sizeof *cs->cid);
        cs->cpos = malloc(s->kc * sizeof *cs->cpos);
        cs->cxyz = malloc(3 * s->kc * sizeof *cs->cxyz);
        cs->cx = malloc(3 * s->kc * sizeof *cs->cx);
        cs->cd2 = malloc(s->kc * sizeof *cs->cd2);
        ok &= cs->cid && cs->cpos && cs->cxyz && cs->cx && cs->cd2;
        if (cs->cx) cs->cy = cs->cx + s->kc, cs->cz = cs->cy + s->kc;
    }
    s->d2 = malloc(s->kc * sizeof *s->d2);
    s->sel = malloc(s->kc * sizeof *s->sel);
    s->bkt = malloc(s->kc * sizeof *s->bkt);
    s->start = malloc((2 * s->kc + 1) * sizeof *s->start);
    s->td = malloc(s->kc * sizeof *s->td);
    s->tp = malloc(s->kc * sizeof *s->tp);
    if (!ok || !s->d2 || !s->sel || !s->bkt || !s->start || !s->td || !s->tp) {
        jf__knn_share_free(s);
        return JF_ERR_NOMEM;
    }
    *out = s;
    return JF_OK;
}

/* (d, id) < (da, ida): the tree's order */
#define SH_LESS(d, i, da, ia) ((d) < (da) || ((d) == (da) && (i) < (ia)))

/* Step 1 at q: the candidates, and q's own k nearest as their prefix. */
static jf_status rebuild(jf__knn_share *s, const jf_index *ix, const double q[3], int slot,
                         uint32_t *idx, uint32_t *pos, double *d2, double *xyz, size_t *found)
{
    size_t f = 0;
    const sh_set *ls = &s->set[s->cur]; /* the last set served from or searched */
    sh_set *cs = &s->set[slot];
    /* the tree's own bound for a large k assumes a surface (d2 ~ k); in
     * noise thicker than the spacing the cloud is locally 3-D and that
     * bound reads twice the points.  The candidates held count exactly the
     * m points within R - |q - c| of q; d2 grows from there to the kc-th
     * as the last search's did, (kc / m)^expo (expo from its last and
     * middle d2).  Exact either way: too few inside, the search runs
     * unbounded (SH_MARGIN 1.3: 2% of them on a 10^6 noisy torus) */
    double bound = INFINITY;
    if (ls->nc == s->kc && s->expo > 0.0) {
        double e0 = q[0] - ls->c[0], e1 = q[1] - ls->c[1], e2 = q[2] - ls->c[2];
        double rin = ls->R - sqrt(e0 * e0 + e1 * e1 + e2 * e2), rin2 = rin * rin;
        size_t m = 0;
        for (size_t j = 0; rin > 0.0 && j < ls->nc; j++) {
            double dx = q[0] - ls->cx[j], dy = q[1] - ls->cy[j], dz = q[2] - ls->cz[j];
            m += dx * dx + dy * dy + dz * dz <= rin2;
        }
        /* too few inside (the walk moved on): the last R^2 x SH_JUMP
         * (the density changes slowly along the walk; the tree's own
         * probe assumes a surface and, in 3-D noise, reads 6x the points).
         * 3e5 noisy torus: x 1.5 overflowed the 2k buffer in half of
         * these searches, x 1.0 found too few in half, x 1.25 in 4% */
        double b = m >= s->kc / 16 ? rin2 * pow((double)s->kc / (double)m, s->expo) * SH_MARGIN
                                   : ls->R * ls->R * SH_JUMP;
        if (b >= 0.0 && b < INFINITY) bound = b;
    }
    cs->nc = 0;
    s->cur = slot;
    /* positions kept too (auto's step 6 keys its records by them) */
    jf_status st = jf__index_knn_pos(ix, q, s->kc, bound, cs->cpos, cs->cd2, &f);
    if (st == JF_OK && f < s->kc && bound < INFINITY)
        st = jf__index_knn_pos(ix, q, s->kc, INFINITY, cs->cpos, cs->cd2, &f);
    if (st != JF_OK) return st;
    const double *pts;
    const uint32_t *id;
    jf__index_points(ix, &pts, &id);
    for (size_t j = 0; j < f; j++) {
        cs->cid[j] = id[cs->cpos[j]];
        memcpy(cs->cxyz + 3 * j, pts + 3 * (size_t)cs->cpos[j], 3 * sizeof *pts);
    }
    s->expo = f == s->kc && cs->cd2[f / 2 - 1] > 0.0 ? log2(cs->cd2[f - 1] / cs->cd2[f / 2 - 1]) : 0.0;
    size_t m = f < s->k ? f : s->k;
    if (idx) memcpy(idx, cs->cid, m * sizeof *idx);
    if (pos) memcpy(pos, cs->cpos, (m < s->npos ? m : s->npos) * sizeof *pos);
    if (d2) memcpy(d2, cs->cd2, m * sizeof *d2);
    if (xyz) memcpy(xyz, cs->cxyz, 3 * m * sizeof *xyz);
    *found = m;
    if (f <= s->k) return JF_OK; /* the whole cloud: nothing to share */
    memcpy(cs->c, q, sizeof cs->c);
    cs->rk = s->rk_last = s->t_last = sqrt(cs->cd2[s->k - 1]);
    cs->R = f < s->kc ? INFINITY : sqrt(cs->cd2[f - 1]);
    for (size_t j = 0; j < f; j++) {
        cs->cx[j] = cs->cxyz[3 * j];
        cs->cy[j] = cs->cxyz[3 * j + 1];
        cs->cz[j] = cs->cxyz[3 * j + 2];
    }
    cs->nc = f;
    return JF_OK;
}

/* The d[j] <= b2 of d[j0..n) and their j, in order, into out and sel
 * after the m0 already there (both of room n; a compare and moves only:
 * the same bits everywhere); returns the count.  AVX-512's compress does
 * eight a step where the machine has it (compact_le). */
static size_t compact_le_from(const double *d, size_t j0, size_t n, double b2, double *out,
                              uint32_t *sel, size_t m0)
{
    size_t m = m0;
    for (size_t j = j0; j < n; j++) {
        out[m] = d[j];
        sel[m] = (uint32_t)j;
        m += d[j] <= b2;
    }
    return m;
}

#if JF_AVX_PATH
#include <immintrin.h>
__attribute__((target("avx512f"), noinline)) static size_t compact_le_512(const double *d, size_t n,
                                                                         double b2, double *out,
                                                                         uint32_t *sel)
{
    size_t m = 0, j = 0;
    const __m512d vb = _mm512_set1_pd(b2);
    __m512i id = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 0, 0, 0, 0, 0, 0, 0, 0);
    const __m512i eight = _mm512_set1_epi32(8);
    for (; j + 8 <= n; j += 8) { /* m <= j: the full stores stay below n */
        __m512d v = _mm512_loadu_pd(d + j);
        __mmask8 k = _mm512_cmp_pd_mask(v, vb, _CMP_LE_OQ);
        _mm512_storeu_pd(out + m, _mm512_maskz_compress_pd(k, v));
        _mm256_storeu_si256((__m256i *)(sel + m),
                            _mm512_castsi512_si256(_mm512_maskz_compress_epi32((__mmask16)k, id)));
        m += (size_t)__builtin_popcount(k);
        id = _mm512_add_epi32(id, eight);
    }
    return compact_le_from(d, j, n, b2, out, sel, m);
}
#endif

static size_t compact_le(const double *d, size_t n, double b2, double *out, uint32_t *sel)
{
#if JF_AVX_PATH
    if (__builtin_cpu_supports("avx512f") && !jf__no_avx) return compact_le_512(d, n, b2, out, sel);
#endif
    return compact_le_from(d, 0, n, b2, out, sel, 0);
}

/* Step 2 for q from the candidates held: 1 with q's k nearest, or 0. */
/* Built twice (target_clones): AVX (four distances a step, no FMA, so
 * no contraction: the tree's bits) and the default (SSE2). */
JF_CLONES static int select_k(jf__knn_share *s, const sh_set *cs, const double q[3], uint32_t *idx,
                              uint32_t *pos, double *d2, double *xyz, size_t *found)
{
    if (!cs->nc) return 0;
    double e0 = q[0] - cs->c[0], e1 = q[1] - cs->c[1], e2 = q[2] - cs->c[2];
    const double delta = sqrt(e0 * e0 + e1 * e1 + e2 * e2);
    /* q's k-th nearest is within rk + delta (c's k nearest are), so its k
     * nearest are the candidates within that of q, and among those no
     * farther than rk + 2 delta from c: a prefix of the candidates */
    if (!((cs->rk + delta) * (1.0 + 1e-9) < cs->R)) return 0;
    const double bmax = (cs->rk + delta) * (1.0 + 1e-9);
    /* first a tighter b from the last query's k-th distance (+5%): if k
     * candidates lie within it, q's k nearest do too (fewer to sort);
     * too few, b x 1.3 up to bmax, the distances computed kept (straight
     * to bmax: 2.6% more auto CPU on a 10^6 noisy torus, 14% retries) */
    double b = s->t_last * 1.05 < bmax ? s->t_last * 1.05 : bmax;
    size_t done = 0; /* dd[] computed so far */
again:;
    const double b2 = b * b, lc = (b + delta) * (1.0 + 1e-9), lc2 = lc * lc;
    size_t lim = 0, hi = cs->nc;
    while (lim < hi) {
        size_t mid = lim + (hi - lim) / 2;
        if (cs->cd2[mid] <= lc2) lim = mid + 1;
        else hi = mid;
    }
    const double q0 = q[0], q1 = q[1], q2 = q[2];
    double *dd = s->td; /* scratch until the sort */
    const double *cx = cs->cx, *cy = cs->cy, *cz = cs->cz;
    for (size_t j = done; j < lim; j++) {
        double dx = q0 - cx[j], dy = q1 - cy[j], dz = q2 - cz[j];
        dd[j] = dx * dx + dy * dy + dz * dz; /* as the tree's scan_leaf */
    }
    done = lim; /* lim grows with b */
    size_t n = compact_le(dd, lim, b2, s->d2, s->sel);
    if (n < s->k && b < bmax) {
        b = b * 1.3 < bmax ? b * 1.3 : bmax;
        goto again;
    }
    if (n < s->k || !(b2 > 0.0)) return 0;
    /* bucket sort by d2 into 2n monotone buckets (mostly one point or
     * none), then one insertion sort by (d2, index) of the buckets up to
     * the k-th's: it moves only the few bucket mates out of order (a
     * loop per bucket mispredicted on every bucket size) */
    uint32_t *start = s->start, *tp = s->tp, *bkt = s->bkt;
    double *td = s->td;
    const double *sd = s->d2;
    const uint32_t *sel = s->sel, *cid = cs->cid;
    const size_t nb = 2 * n;
    const double scale = (double)nb / b2;
    if (!isfinite(scale)) return 0; /* b2 subnormal: the buckets would overflow */
    memset(start, 0, (nb + 1) * sizeof *start);
    for (size_t j = 0; j < n; j++) {
        size_t bk = (size_t)(sd[j] * scale);
        bkt[j] = (uint32_t)(bk < nb ? bk : nb - 1);
        start[bkt[j] + 1]++;
    }
    for (size_t bk = 0; bk < nb; bk++) start[bk + 1] += start[bk];
    for (size_t j = 0; j < n; j++) {
        uint32_t at = start[bkt[j]]++;
        td[at] = sd[j];
        tp[at] = sel[j];
    }
    /* start[bk] is now the end of bucket bk: the first end >= k closes
     * the k-th's bucket */
    const size_t k = s->k;
    size_t bl = 0, bh = nb - 1;
    while (bl < bh) {
        size_t mid = bl + (bh - bl) / 2;
        if (start[mid] >= k) bh = mid;
        else bl = mid + 1;
    }
    const size_t end = start[bl];
    for (size_t i = 1; i < end; i++) {
        /* four at once while each is above the one before (most buckets
         * hold one point: most of the list is in order already) */
        for (v4d a, b; i + 4 <= end; i += 4) {
            memcpy(&a, td + i, sizeof a);
            memcpy(&b, td + i - 1, sizeof b);
            if (!all4((v4l)(a > b))) break;
        }
        if (i >= end) break;
        double d = td[i];
        if (!SH_LESS(d, cid[tp[i]], td[i - 1], cid[tp[i - 1]])) continue;
        uint32_t p = tp[i], pid = cid[p];
        size_t j = i;
        do {
            td[j] = td[j - 1];
            tp[j] = tp[j - 1];
            j--;
        } while (j > 0 && SH_LESS(d, pid, td[j - 1], cid[tp[j - 1]]));
        td[j] = d;
        tp[j] = p;
    }
    /* every point within t = |q - k-th| of q is within t + delta of c:
     * a candidate if that is below R (else a point beyond the candidates
     * may be nearer q) */
    if (!((sqrt(td[k - 1]) + delta) * (1.0 + 1e-9) < cs->R))
        return 0;
    const double *cxyz = cs->cxyz;
    if (idx)
        for (size_t i = 0; i < k; i++) idx[i] = cid[tp[i]];
    if (pos)
        for (size_t i = 0; i < s->npos; i++) pos[i] = cs->cpos[tp[i]];
    if (d2) memcpy(d2, td, k * sizeof *d2);
    if (xyz)
        for (size_t i = 0; i < k; i++) /* one 16- and one 8-byte move */
            memcpy(xyz + 3 * i, cxyz + 3 * (size_t)tp[i], 3 * sizeof *xyz);
    s->t_last = sqrt(s->td[k - 1]);
    *found = k;
    return 1;
}

jf_status jf__knn_share_query(jf__knn_share *s, const jf_index *ix, const double q[3],
                              uint32_t *idx, uint32_t *pos, double *d2, double *xyz,
                              size_t *found)
{
    *found = 0;
    /* the sets whose centre is nearest q first (the shortest prefix) */
    double dl[SH_SETS];
    for (int j = 0; j < SH_SETS; j++) {
        const sh_set *cs = &s->set[j];
        double e0 = q[0] - cs->c[0], e1 = q[1] - cs->c[1], e2 = q[2] - cs->c[2];
        dl[j] = cs->nc ? e0 * e0 + e1 * e1 + e2 * e2 : INFINITY;
    }
    for (int i = 0; i < SH_SETS; i++) {
        int j = 0;
        for (int t = 1; t < SH_SETS; t++)
            if (dl[t] < dl[j]) j = t;
        if (!(dl[j] < INFINITY)) break;
        dl[j] = INFINITY;
        if (select_k(s, &s->set[j], q, idx, pos, d2, xyz, found)) {
            s->cur = j;
            return JF_OK;
        }
    }
    /* step 3, from the centroid of the walk's next points near q (within
     * half the last rk: the walk goes leaf by leaf, so a search there
     * serves the whole leaf); q itself when there are none */
    double c[3] = {q[0], q[1], q[2]};
    size_t nc = 1;
    if (s->ahead && s->rk_last > 0.0 && s->ahead[0] == q[0] && s->ahead[1] == q[1] &&
        s->ahead[2] == q[2]) {
        const double lim = s->rk_last / 2.0, lim2 = lim * lim;
        for (size_t j = 1; j < s->nahead && j < SH_AHEAD; j++) {
            const double *a = s->ahead + 3 * j;
            double e0 = a[0] - q[0], e1 = a[1] - q[1], e2 = a[2] - q[2];
            if (!(e0 * e0 + e1 * e1 + e2 * e2 <= lim2)) continue;
            c[0] += a[0], c[1] += a[1], c[2] += a[2];
            nc++;
        }
        for (int d = 0; d < 3; d++) c[d] /= (double)nc;
    }
    /* into the oldest set; a centre's that does not serve q, replaced */
    int slot = (s->cur + 1) % SH_SETS;
    if (nc > 1) {
        size_t f = 0;
        jf_status st = rebuild(s, ix, c, slot, idx, pos, d2, xyz, &f);
        if (st != JF_OK) return st;
        if (select_k(s, &s->set[slot], q, idx, pos, d2, xyz, found)) return JF_OK;
    }
    return rebuild(s, ix, q, slot, idx, pos, d2, xyz, found);
}
