/* auto_rule.c -- neighbors auto, steps 3-4 (auto.c's design block): from
 * the candidate jets at nested K (quadric and cubic, their normals and
 * the sd of each normal per unit noise) and the noise variance, the K and
 * the degree reported.
 *
 * design:
 *  3. Per degree, Lepski's rule (Lepski, Mammen & Spokoiny 1997; the
 *     intersection of confidence intervals of Katkovnik 1999; Mitra,
 *     Nguyen & Guibas 2004 for normals): grow K while the normal at K
 *     stays within tau (sd_j + sd_K) of the normal at every smaller
 *     accepted K j.
 *  4. Degree: the cubic's choice, unless the quadric at the largest K of
 *     its chain where it agrees with the cubic at the same K has the
 *     smaller sd.
 * auto_gl instead: Goldenshluger-Lepski over every (K, degree) (dropped,
 * docs/robustness.md). */
#include <math.h>

#include "robust_internal.h"

/* jf__angle(a, b) <= thr, without its acos where the cosine d = |a.b|
 * is clearly on one side of cos thr: 1 - thr^2/2 <= cos thr <= 1 - thr^2/2
 * + thr^4/24 (Taylor, every thr), with a margin of 1e-12 on d, far above
 * the rounding of d, of the bound and of acos (an angle moves at least as
 * much as its cosine); else jf__angle itself, so always its answer. */
int jf__angle_le(const double a[3], const double b[3], double thr)
{
    if (thr > 0.0) {
        const double d = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]), t2 = thr * thr / 2.0;
        if (d >= 1.0 - t2 + t2 * t2 / 6.0 + 1e-12) return 1;
        if (d <= 1.0 - t2 - 1e-12) return 0;
    }
    return jf__angle(a, b) <= thr;
}

/* Lepski / ICI over the candidates of one degree: the last K whose normal
 * agrees with every smaller accepted K's (within tau (sd_j + sd_K), or with
 * nest > 0 within nest sqrt(|sd_j^2 - sd_K^2|): the difference of nested
 * least-squares estimates has the variance difference).  With lof z > 0 a
 * K that fails passes when its residual variance shows no lack of fit:
 * below s2 (1 + z sqrt(2 / (K - 6))), the variance of a chi-square
 * estimate (dropped: docs/robustness.md).  Returns its index or -1. */
static int lepski(const jf__auto_cand *c, const size_t *ks, int nc, double s2, double tau, double sdmax,
                  double nest, double lof)
{
    int acc[JF_AUTO_NCAND], na = 0, best = -1;
    double sda[JF_AUTO_NCAND]; /* the accepted ones' sd, computed once */
    for (int i = 0; i < nc; i++) {
        if (!c[i].ok) continue;
        double sdi = sqrt(s2 * c[i].tr);
        int okk = 1;
        for (int j = 0; j < na && okk; j++) {
            double sdj = sda[j];
            if (!(sdj < sdmax)) continue; /* a normal of noise bounds nothing */
            okk = jf__angle_le(c[i].nrm, c[acc[j]].nrm,
                           nest > 0.0 ? nest * sqrt(fabs(sdj * sdj - sdi * sdi)) : tau * (sdi + sdj));
        }
        if (!okk && lof > 0.0) {
            double dof = ks[i] > 7 ? (double)(ks[i] - 6) : 1.0;
            okk = c[i].s2 <= s2 * (1.0 + lof * sqrt(2.0 / dof));
        }
        if (!okk) break;
        sda[na] = sdi;
        acc[na++] = i;
        best = i;
    }
    return best;
}

/* Goldenshluger-Lepski over every (K, degree): the squared bias of a
 * candidate is its largest excess move against each less biased one
 * (smaller K, or the cubic at the same K), less what noise of variance
 * |sd_a^2 - sd_b^2| explains; cost = bias^2 + varw sd^2. */
static int gold_lepski(const jf__knobs *kn, const jf__auto_cands *C, int *dout)
{
    int bd = -1, bc = -1;
    double bcost = INFINITY, s2 = C->s2;
    for (int i = 0; i < C->nc; i++)
        for (int d = 0; d < 2; d++) {
            const jf__auto_cand *a = &C->cf[d][i];
            if (!a->ok) continue;
            double va = s2 * a->tr, b2 = 0.0;
            for (int j = 0; j <= i; j++)
                for (int e = 0; e < 2; e++) {
                    const jf__auto_cand *b = &C->cf[e][j];
                    if (!b->ok || (j == i && e <= d)) continue;
                    double vb = s2 * b->tr;
                    if (!(vb < kn->auto_sdmax * kn->auto_sdmax)) continue;
                    double x = jf__angle(a->nrm, b->nrm) - kn->auto_tau * sqrt(fabs(vb - va));
                    if (x > 0.0 && x * x > b2) b2 = x * x;
                }
            double cost = b2 + kn->auto_varw * va;
            if (cost < bcost) {
                bcost = cost;
                bd = d;
                bc = i;
            }
        }
    *dout = bd ? 3 : 2;
    return bc;
}

int jf__auto_rule(const jf__knobs *kn, const jf__auto_cands *C, int *dout)
{
    if (kn->auto_gl) return gold_lepski(kn, C, dout);
    const double tau = kn->auto_tau;
    double s2 = C->s2;
    const jf__auto_cand *q = C->cf[0], *cu = C->cf[1];
    /* auto_s2floor (dropped): where the cubic at K = 32 underestimates the
     * noise (seen at the exp patch's border), the cubic's at K = 48 */
    if (kn->auto_s2floor > 0.0 && C->nc > 3 && C->ks[2] == 32 && C->ks[3] == 48 && cu[3].ok) {
        double hc = kn->auto_s2floor * cu[2].h;
        if (s2 > hc * hc && cu[3].s2 > s2) s2 = cu[3].s2;
    }
    /* step 3: Lepski per degree */
    int c2 = lepski(q, C->ks, C->nc, s2, tau, kn->auto_sdmax, kn->auto_nest, kn->auto_lof),
        c3 = lepski(cu, C->ks, C->nc, s2, tau, kn->auto_sdmax, kn->auto_nest, kn->auto_lof);
    /* step 4: the degree */
    int d = 3, ci = c3;
    if (c3 < 0) {
        d = 2;
        ci = c2;
    } else {
        /* the quadric at the largest K of its chain that agrees with the
         * cubic at the same K, if its sd is below the cubic's choice */
        double sd3 = sqrt(s2 * cu[c3].tr);
        for (int i = c2; i >= 0; i--) {
            if (!q[i].ok || !cu[i].ok) continue;
            if (!jf__angle_le(q[i].nrm, cu[i].nrm, tau * sqrt(s2 * cu[i].tr))) continue;
            if (sqrt(s2 * q[i].tr) < sd3) {
                d = 2;
                ci = i;
            }
            break;
        }
    }
    *dout = d;
    return ci;
}
