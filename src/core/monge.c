/* monge.c -- differential quantities of a fitted jet (§3, §5.3, Table 1):
 * normal, principal curvatures and directions, Monge coefficients b0..b3,
 * c0..c4, and the orientation flip of docs/design.md.
 *
 * design: the jet z = J(u,v) lives in the fitting frame.  Its point above
 * p is P0 = (0,0,A00), with normal n ~ (-A10, -A01, 1) (the fitting frame's
 * +z side: the orientation before any user orientation).  We re-express
 * the surface as a height function w = g(s,t) over the orthonormal frame
 * (P0; t1, t2, n), t1 along X_u, by the implicit-function series below;
 * its Hessian is then the shape operator in an orthonormal basis (the
 * Weingarten map of Table 1 written in {t1, t2}), symmetric, so k1 >= k2
 * and d1, d2 come from a closed-form 2x2 eigen-decomposition, and the
 * cubic/quartic parts of g rotated onto (d1, d2) are the Monge b and c. */
#include <math.h>
#include <string.h>

#include "fitter_internal.h"

#define TPI(i, j) (((i) + (j)) * ((i) + (j) + 1) / 2 + (j)) /* x^i y^j */

/* out = a * b truncated at order m (out must not alias a or b); a has no
 * terms below order amin, b none below bmin (the loops skip them). */
static inline __attribute__((always_inline)) void tp_mul(const double *a, int amin,
                                                         const double *b, int bmin, int m,
                                                         double *out)
{
    int sz = (m + 1) * (m + 2) / 2;
    for (int k = 0; k < sz; k++) out[k] = 0.0;
    for (int ka = amin; ka + bmin <= m; ka++)
        for (int ja = 0; ja <= ka; ja++) {
            const double ca = a[ka * (ka + 1) / 2 + ja];
            for (int kb = bmin; kb + ka <= m; kb++) {
                const double *bk = b + kb * (kb + 1) / 2;
                double *o = out + TPI(ka - ja + kb, ja); /* x^(ka-ja+kb-jb) y^(ja+jb) */
                for (int jb = 0; jb <= kb; jb++) o[jb] += ca * bk[jb];
            }
        }
}

/* out = sum over orders kmin..min(deg,m) of the coefficients a (jet
 * order) evaluated at (U, V), truncated at order m.  U, V have no
 * constant term, so jet terms above order m do not contribute and
 * U^i V^j starts at order i + j. */
static inline __attribute__((always_inline)) void tp_compose_m(const double *a, int deg, int kmin,
                                                               const double *u, const double *v,
                                                               int m, double *out)
{
    double pw[JF_TP_ORDER + 1][JF_TP_ORDER + 1][JF_TP_SIZE];
    int sz = (m + 1) * (m + 2) / 2, top = deg < m ? deg : m;
    memset(pw[0][0], 0, sizeof pw[0][0]);
    pw[0][0][0] = 1.0;
    for (int i = 1; i <= top; i++) tp_mul(pw[i - 1][0], i - 1, u, 1, m, pw[i][0]);
    for (int i = 0; i <= top; i++)
        for (int j = 1; i + j <= top; j++) tp_mul(pw[i][j - 1], i + j - 1, v, 1, m, pw[i][j]);
    for (int k = 0; k < sz; k++) out[k] = 0.0;
    for (int k = kmin; k <= top; k++)
        for (int j = 0; j <= k; j++) {
            const double c = a[TPI(k - j, j)];
            if (c == 0.0) continue;
            for (int t = k * (k + 1) / 2; t < sz; t++) out[t] += c * pw[k - j][j][t];
        }
}

/* tp_compose with the usual orders m as constants, so its loops unroll
 * (the same operations in the same order: the same bits).  Scalar: the
 * vectorised sums loaded pairs of coefficients just stored one by one (a
 * store-forwarding stall each; measured 3% of a knn:16 run in this). */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-vectorize")))
#endif
static void tp_compose(const double *a, int deg, int kmin, const double *u, const double *v,
                       int m, double *out)
{
    switch (m) {
    case 2: tp_compose_m(a, deg, kmin, u, v, 2, out); break;
    case 3: tp_compose_m(a, deg, kmin, u, v, 3, out); break;
    default: tp_compose_m(a, deg, kmin, u, v, m, out); break;
    }
}

static void to_world(const double r[9], const double loc[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = loc[0] * r[i] + loc[1] * r[3 + i] + loc[2] * r[6 + i];
}

void jf__result_nan(jf_result *out)
{
    double nan = NAN;
    for (int i = 0; i < 3; i++) out->normal[i] = out->d1[i] = out->d2[i] = nan;
    out->k1 = out->k2 = nan;
    for (int i = 0; i < 4; i++) out->b[i] = nan;
    for (int i = 0; i < 5; i++) out->c[i] = nan;
    out->sigma = nan;
}

static void quantities(const double *a, int deg, int monge_degree, const double r[9],
                       double h, jf_result *out)
{
    const double a1 = a[TPI(1, 0)], a2 = a[TPI(0, 1)];
    const double wn = sqrt(1.0 + a1 * a1 + a2 * a2);
    const double n[3] = {-a1 / wn, -a2 / wn, 1.0 / wn};
    const double e1 = sqrt(1.0 + a1 * a1);
    const double t1[3] = {1.0 / e1, 0.0, a1 / e1};
    const double t2[3] = {n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2],
                          n[0] * t1[1] - n[1] * t1[0]};
    /* (s,t) = L (u,v) + (t1z, t2z) H(u,v), H = jet terms of order >= 2,
     * since X(u,v) - P0 = u X_u + v X_v + (0,0,H).  L is upper triangular
     * (t2 . X_u = 0).  w = n . (X - P0) = nz H: the linear part vanishes. */
    const double l00 = t1[0] + t1[2] * a1, l01 = t1[1] + t1[2] * a2;
    const double l11 = t2[1] + t2[2] * a2;
    const double i00 = 1.0 / l00, i11 = 1.0 / l11, i01 = -l01 / (l00 * l11);
    const double al = i00 * t1[2] + i01 * t2[2], be = i11 * t2[2];

    int m = monge_degree < 2 ? 2 : monge_degree;
    if (m > JF_TP_ORDER) m = JF_TP_ORDER;
    const int sz = (m + 1) * (m + 2) / 2;
    double lu[JF_TP_SIZE] = {0}, lv[JF_TP_SIZE] = {0}, u[JF_TP_SIZE], v[JF_TP_SIZE];
    double pp[JF_TP_SIZE] = {0}, g[JF_TP_SIZE];
    lu[TPI(1, 0)] = i00;
    lu[TPI(0, 1)] = i01;
    lv[TPI(0, 1)] = i11;
    /* fixed point (u,v) = L^-1 ((s,t) - (t1z,t2z) H(u,v)): P = H(u,v)
     * starts at order 2, each pass makes one more order exact. */
    if (deg >= 2)
        for (int it = 1; it < m; it++) {
            for (int k = 0; k < sz; k++) {
                u[k] = lu[k] - al * pp[k];
                v[k] = lv[k] - be * pp[k];
            }
            tp_compose(a, deg, 2, u, v, m, pp);
        }
    for (int k = 0; k < sz; k++) g[k] = n[2] * pp[k];

    /* Shape operator in {t1,t2}: [[2g20, g11], [g11, 2g02]]; closed-form
     * eigen-decomposition, theta = angle of d1 (largest eigenvalue). */
    const double g20 = g[TPI(2, 0)], g11 = g[TPI(1, 1)], g02 = g[TPI(0, 2)];
    const double mean = g20 + g02;
    const double rad = sqrt((g20 - g02) * (g20 - g02) + g11 * g11);
    double k1 = mean + rad, k2 = mean - rad, th = 0.5 * atan2(2.0 * g11, 2.0 * (g20 - g02));
    /* k1 - k2 against max(|k1|, |k2|, 1/h) (h the neighbourhood's size):
     * scale-invariant, as k scales as 1/length, and a plane, whose
     * curvatures are rounding noise of order eps/h, is umbilic */
    double big = fmax(fmax(fabs(k1), fabs(k2)), 1.0 / h);
    if (deg >= 2 && k1 - k2 <= 1e-10 * big) {
        /* umbilic: directions undefined, keep the orthonormal {t1, t2} */
        th = 0.0;
        out->status |= JF_PT_UMBILIC;
    }
    if (deg < 2) th = 0.0;
    const double cs = cos(th), sn = sin(th);
    double d1[3], d2[3];
    for (int i = 0; i < 3; i++) {
        d1[i] = cs * t1[i] + sn * t2[i];
        d2[i] = -sn * t1[i] + cs * t2[i];
    }
    to_world(r, n, out->normal);
    to_world(r, d1, out->d1);
    to_world(r, d2, out->d2);
    out->k1 = deg >= 2 ? k1 : NAN;
    out->k2 = deg >= 2 ? k2 : NAN;

    for (int i = 0; i < 4; i++) out->b[i] = 0.0;
    for (int i = 0; i < 5; i++) out->c[i] = 0.0;
    if (monge_degree >= 3) {
        /* Monge coordinates: (s,t) = rotation(th) (x,y); z = g(s,t) */
        double ru[JF_TP_SIZE] = {0}, rv[JF_TP_SIZE] = {0}, gm[JF_TP_SIZE];
        ru[TPI(1, 0)] = cs;
        ru[TPI(0, 1)] = -sn;
        rv[TPI(1, 0)] = sn;
        rv[TPI(0, 1)] = cs;
        tp_compose(g, m, 3, ru, rv, m, gm);
        /* z = ... + (b0 x^3 + 3 b1 x^2 y + 3 b2 x y^2 + b3 y^3)/6
         *         + (c0 x^4 + 4 c1 x^3 y + 6 c2 x^2y^2 + 4 c3 x y^3 + c4 y^4)/24 */
        const int okb = deg >= 3;
        out->b[0] = okb ? 6.0 * gm[TPI(3, 0)] : NAN;
        out->b[1] = okb ? 2.0 * gm[TPI(2, 1)] : NAN;
        out->b[2] = okb ? 2.0 * gm[TPI(1, 2)] : NAN;
        out->b[3] = okb ? 6.0 * gm[TPI(0, 3)] : NAN;
        if (monge_degree >= 4) {
            const int okc = deg >= 4;
            out->c[0] = okc ? 24.0 * gm[TPI(4, 0)] : NAN;
            out->c[1] = okc ? 6.0 * gm[TPI(3, 1)] : NAN;
            out->c[2] = okc ? 4.0 * gm[TPI(2, 2)] : NAN;
            out->c[3] = okc ? 6.0 * gm[TPI(1, 3)] : NAN;
            out->c[4] = okc ? 24.0 * gm[TPI(0, 4)] : NAN;
        }
    }
}

/* The series above multiplies coefficients of several orders, so in world
 * units it overflows or underflows when lengths are near 1e+-100 (order 4
 * scales as 1/length^3).  It runs in a unit of length L = 2^e with the
 * second-order coefficients O(1): a_k (order k) becomes a_k L^(k-1), and
 * k, b, c come back as k/L, b/L^2, c/L^3.  L is a power of two, so this is
 * exact: a cloud scaled by 2^j gives the same bits, k scaled by 2^-j. */
void jf__quantities(const double *a_in, int deg, int monge_degree, const double r[9],
                    double h, jf_result *out)
{
    double a[(JF_MAX_DEGREE + 1) * (JF_MAX_DEGREE + 2) / 2];
    int nc = (deg + 1) * (deg + 2) / 2;
    double big = 0.0;
    for (int k = TPI(2, 0); deg >= 2 && k < TPI(0, 2) + 1; k++)
        big = fmax(big, fabs(a_in[k]));
    int e = 0;
    if (big > 0.0 && isfinite(big))
        frexp(big, &e); /* big = m 2^e, m in [0.5, 1): L = 2^-e */
    for (int k = 0; k < nc; k++) {
        int order = 0;
        while ((order + 1) * (order + 2) / 2 <= k) order++;
        a[k] = jf__ldexp(a_in[k], -e * (order - 1));
    }
    quantities(a, deg, monge_degree, r, jf__ldexp(h, e), out); /* h in units of L */
    out->k1 = jf__ldexp(out->k1, e);
    out->k2 = jf__ldexp(out->k2, e);
    for (int i = 0; i < 4; i++) out->b[i] = jf__ldexp(out->b[i], 2 * e);
    for (int i = 0; i < 5; i++) out->c[i] = jf__ldexp(out->c[i], 3 * e);
    if ((deg >= 2 && !(isfinite(out->k1) && isfinite(out->k2))) ||
        !isfinite(out->normal[0]) || !isfinite(out->normal[1]) || !isfinite(out->normal[2])) {
        /* overflow: never a row that looks fitted */
        out->status = (out->status & ~(unsigned)JF_PT_UMBILIC) | JF_PT_FAILED;
        out->k1 = out->k2 = NAN;
        for (int i = 0; i < 3; i++)
            out->normal[i] = out->d1[i] = out->d2[i] = NAN;
    }
}

void jf_result_flip(jf_result *r)
{
    if (!r) return;
    double t;
    for (int i = 0; i < 3; i++) {
        r->normal[i] = -r->normal[i];
        t = r->d1[i];
        r->d1[i] = r->d2[i];
        r->d2[i] = t;
    }
    t = r->k1;
    r->k1 = -r->k2;
    r->k2 = -t;
    double b[4], c[5];
    for (int i = 0; i < 4; i++) b[i] = r->b[i];
    for (int i = 0; i < 5; i++) c[i] = r->c[i];
    for (int i = 0; i < 4; i++) r->b[i] = -b[3 - i];
    for (int i = 0; i < 5; i++) r->c[i] = -c[4 - i];
}

void jf_result_orient(jf_result *r, const double dir[3])
{
    if (!r || !dir) return;
    double d = r->normal[0] * dir[0] + r->normal[1] * dir[1] + r->normal[2] * dir[2];
    if (d < 0) jf_result_flip(r);
}
