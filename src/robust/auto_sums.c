/* auto_sums.c -- neighbors auto's power sums (auto.c's design, step 1):
 * x^i y^j and x^i y^j z of a point's neighbours in a frame, four
 * neighbours a step in SIMD lanes, for every candidate K at once
 * (jf__auto_first_pass) or for one K (jf__auto_moments). */
#include <math.h>
#include <string.h>

#include "avx_path.h"
#include "auto_internal.h"

_Static_assert(NPOW % 4 == 0 && NMON >= 8, "first_pass sums four power sums a step");

/* Power sums in four SIMD lanes (four neighbours a step, lane l the
 * neighbours l, l + 4, ...; summed (l0 + l1) + (l2 + l3) at the end).  The
 * loops are built twice (target_clones): AVX (four lanes a register, no
 * FMA, so no contraction) and the default (two SSE2 registers) -- the same
 * operations on every lane, so the same bits on every machine. */
typedef struct {
    v4d S[NPOW], T[NMON], zz, m, rmax2, rsum;
} acc4;

static inline double sum4(v4d v) { return (v[0] + v[1]) + (v[2] + v[3]); }

/* out[i] = sum4(v[i]), i < 4: the same additions, four sums a step
 * (pairs of lanes side by side, then the pairs' sums) */
#if defined(__clang__) /* GCC's __builtin_shuffle is clang's shufflevector */
#define SHUF4(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define SHUF4(a, b, i, j, k, l) __builtin_shuffle(a, b, (v4l){i, j, k, l})
#endif
static inline __attribute__((always_inline)) void sum4x4(const v4d *v, double *out)
{
    const v4d ab = SHUF4(v[0], v[1], 0, 4, 2, 6) + SHUF4(v[0], v[1], 1, 5, 3, 7); /* a01 b01 a23 b23 */
    const v4d cd = SHUF4(v[2], v[3], 0, 4, 2, 6) + SHUF4(v[2], v[3], 1, 5, 3, 7);
    const v4d r = SHUF4(ab, cd, 0, 1, 4, 5) + SHUF4(ab, cd, 2, 3, 6, 7);
    memcpy(out, &r, sizeof r);
}

/* One quad of neighbours q[0..3] (NULL: none) in the frame: x, y (units
 * of H: scaled by iH), z, and w = 1 (0: none or not finite). */
typedef struct {
    v4d x, y, z, w;
} quad4;

static inline __attribute__((always_inline)) void quad_load(quad4 *Q, const double *const q[4],
                                                            const double p[3], const double fr[9],
                                                            double iH)
{
    const v4d zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0};
    v4d v0, v1, v2;
    v4l live;
    if (q[3]) { /* four in a row (quad_of): one transpose of 12 doubles */
        const double *a = q[0];
        v4d r0, r1, r2;
        memcpy(&r0, a, sizeof r0); /* x0 y0 z0 x1 */
        memcpy(&r1, a + 4, sizeof r1); /* y1 z1 x2 y2 */
        memcpy(&r2, a + 8, sizeof r2); /* z2 x3 y3 z3 */
        const v4d pp = {p[0], p[1], p[2], p[0]};
        v0 = (v4d){r0[0], r0[3], r1[2], r2[1]} - pp[0];
        v1 = (v4d){r0[1], r1[0], r1[3], r2[2]} - pp[1];
        v2 = (v4d){r0[2], r1[1], r2[0], r2[3]} - pp[2];
        live = (v4l){-1, -1, -1, -1};
    } else
        for (int l = 0; l < 4; l++) {
            v0[l] = q[l] ? q[l][0] - p[0] : 0.0;
            v1[l] = q[l] ? q[l][1] - p[1] : 0.0;
            v2[l] = q[l] ? q[l][2] - p[2] : 0.0;
            live[l] = q[l] ? -1 : 0;
        }
    v4d x = (v0 * fr[0] + v1 * fr[1] + v2 * fr[2]) * iH;
    v4d y = (v0 * fr[3] + v1 * fr[4] + v2 * fr[5]) * iH;
    v4d z = v0 * fr[6] + v1 * fr[7] + v2 * fr[8];
    /* finite: t - t == 0 (NaN for an infinity or a NaN) */
    v4l ok = ((x - x) == zero) & ((y - y) == zero) & ((z - z) == zero) & live;
    Q->x = (v4d)((v4l)x & ok);
    Q->y = (v4d)((v4l)y & ok);
    Q->z = (v4d)((v4l)z & ok);
    Q->w = (v4d)((v4l)one & ok);
}

/* Adds nq (1 or 2) quads Q[0..nq) to A, in that order: x^i y^j for
 * i + j <= top, x^i y^j z for i + j <= deg, z^2, the count, the largest
 * x^2 + y^2 and (rs) the sum of sqrt(x^2 + y^2).  Two quads add to each
 * sum one after the other in a register, (A + a) + b, the bits of two
 * calls with one quad, with half the loads and stores of the ~40 sums
 * (which do not fit in registers: the stores bounded the loop). */
static inline __attribute__((always_inline)) void acc_quads(acc4 *A, const quad4 *Q, int nq, int top,
                                                            int deg, int rs)
{
    const v4d one = {1.0, 1.0, 1.0, 1.0};
    v4d xp[2][7], yp[2][7];
    for (int u = 0; u < nq; u++) {
        xp[u][0] = Q[u].w;
        yp[u][0] = one;
        for (int e = 1; e <= top; e++) {
            xp[u][e] = xp[u][e - 1] * Q[u].x;
            yp[u][e] = yp[u][e - 1] * Q[u].y;
        }
    }
    int at = 0; /* PIDX order: degree t, then j = 0..t */
    for (int t = 0; t <= top; t++)
        for (int j = 0; j <= t; j++, at++) {
            v4d a = A->S[at];
            for (int u = 0; u < nq; u++) a += xp[u][t - j] * yp[u][j];
            A->S[at] = a;
        }
    at = 0;
    for (int t = 0; t <= deg; t++)
        for (int j = 0; j <= t; j++, at++) {
            v4d a = A->T[at];
            for (int u = 0; u < nq; u++) a += xp[u][t - j] * yp[u][j] * Q[u].z;
            A->T[at] = a;
        }
    for (int u = 0; u < nq; u++) {
        const v4d x = Q[u].x, y = Q[u].y, z = Q[u].z;
        A->zz += Q[u].w * z * z;
        A->m += Q[u].w;
        v4d r2 = x * x + y * y;
        v4l gt = (v4l)(r2 > A->rmax2);
        A->rmax2 = (v4d)(((v4l)r2 & gt) | ((v4l)A->rmax2 & ~gt));
        if (rs) { /* four lanes a step (sqrt is correctly rounded: the bits of one at a time) */
            v4d r;
            sqrt4(&r, &r2);
            A->rsum += r;
        }
    }
}

/* Adds neighbours q[0..3] (NULL: none) to A (acc_quads). */
static inline __attribute__((always_inline)) void acc_quad(acc4 *A, const double *const q[4],
                                                           const double p[3], const double fr[9],
                                                           double iH, int top, int deg, int rs)
{
    quad4 Q;
    quad_load(&Q, q, p, fr, iH);
    acc_quads(A, &Q, 1, top, deg, rs);
}

/* Adds the eight neighbours nbr[i..i + 8) to A, as two acc_quad calls. */
static inline __attribute__((always_inline)) void acc_eight(acc4 *A, const double *nbr, size_t i,
                                                            const double p[3], const double fr[9],
                                                            double iH, int top, int deg, int rs)
{
    quad4 Q[2];
    const double *q0[4] = {nbr + 3 * i, nbr + 3 * i + 3, nbr + 3 * i + 6, nbr + 3 * i + 9};
    const double *q1[4] = {nbr + 3 * i + 12, nbr + 3 * i + 15, nbr + 3 * i + 18, nbr + 3 * i + 21};
    quad_load(&Q[0], q0, p, fr, iH);
    quad_load(&Q[1], q1, p, fr, iH);
    acc_quads(A, Q, 2, top, deg, rs);
}

/* The four neighbours from i (NULL past k). */
static inline void quad_of(const double *nbr, size_t i, size_t k, const double *q[4])
{
    for (int l = 0; l < 4; l++) q[l] = i + (size_t)l < k ? nbr + 3 * (i + (size_t)l) : NULL;
}

/* The power sums of the first k neighbours in the frame fr (as step 1's,
 * x, y in units of H; up to degree 2 deg), their count and mean planar
 * distance (length units). */
JF_CLONES static void moments(const double p[3], const double *nbr, size_t k, const double fr[9],
                              double H, int deg, mom *mo)
{
    const double iH = 1.0 / H;
    const int top = 2 * deg, ntop = (top + 1) * (top + 2) / 2, nt = (deg + 1) * (deg + 2) / 2;
    acc4 A;
    memset(&A, 0, sizeof A);
    const double *q[4];
    size_t i = 0;
    if (deg == 2) {
        for (; i + 8 <= k; i += 8) acc_eight(&A, nbr, i, p, fr, iH, 4, 2, 1);
        for (; i < k; i += 4) quad_of(nbr, i, k, q), acc_quad(&A, q, p, fr, iH, 4, 2, 1);
    } else if (deg == 3) { /* constants: the sums' loops unrolled (the same operations) */
        for (; i + 8 <= k; i += 8) acc_eight(&A, nbr, i, p, fr, iH, 6, 3, 1);
        for (; i < k; i += 4) quad_of(nbr, i, k, q), acc_quad(&A, q, p, fr, iH, 6, 3, 1);
    } else {
        for (; i + 8 <= k; i += 8) acc_eight(&A, nbr, i, p, fr, iH, top, deg, 1);
        for (; i < k; i += 4) quad_of(nbr, i, k, q), acc_quad(&A, q, p, fr, iH, top, deg, 1);
    }
    for (int j = 0; j < ntop; j++) mo->S[j] = sum4(A.S[j]);
    for (int j = 0; j < nt; j++) mo->T[j] = sum4(A.T[j]);
    mo->zz = sum4(A.zz);
    mo->m = (size_t)sum4(A.m);
    mo->hmean = mo->m ? sum4(A.rsum) / (double)mo->m * H : 0.0;
}

/* Step 1's power sums (degree 6 and 3, in the frame fr) of the first ks[c]
 * neighbours for every candidate c < nc into mo[c], and their radius
 * (largest planar distance, length units) into hk[c].  Every candidate K
 * but a short list's last (nmax) is a multiple of 4. */
JF_CLONES static void first_pass(const double p[3], const double *nbr, size_t nmax, const double fr[9],
                                 double H, const size_t *ks, int nc, mom *mo, double *hk)
{
    const double iH = 1.0 / H;
    acc4 A;
    memset(&A, 0, sizeof A);
    const double *q[4];
    int c = 0;
    for (size_t i = 0; i < nmax && c < nc;) {
        if (i + 8 <= nmax && ks[c] > i + 4) { /* no sums are read between the two quads */
            acc_eight(&A, nbr, i, p, fr, iH, 6, 3, 0);
            i += 8;
        } else {
            quad_of(nbr, i, nmax, q);
            acc_quad(&A, q, p, fr, iH, 6, 3, 0);
            i += 4;
        }
        if ((i < nmax ? i : nmax) < ks[c]) continue;
        mom *mc = &mo[c];
        mc->zz = sum4(A.zz);
        for (int j = 0; j < NPOW; j += 4) sum4x4(A.S + j, mc->S + j);
        sum4x4(A.T, mc->T);
        sum4x4(A.T + 4, mc->T + 4);
        for (int j = 8; j < NMON; j++) mc->T[j] = sum4(A.T[j]);
        mc->m = (size_t)sum4(A.m);
        mc->hmean = 0.0; /* unused: the reported jet has its own sums */
        v4d r = A.rmax2;
        double a = r[0] > r[1] ? r[0] : r[1], b = r[2] > r[3] ? r[2] : r[3];
        hk[c] = sqrt(a > b ? a : b) * H;
        c++;
    }
}

void jf__auto_moments(const double p[3], const double *nbr, size_t k, const double fr[9], double H, int deg,
                      mom *mo)
{
    moments(p, nbr, k, fr, H, deg, mo);
}

void jf__auto_first_pass(const double p[3], const double *nbr, size_t nmax, const double fr[9], double H,
                         const size_t *ks, int nc, mom *mo, double *hk)
{
    first_pass(p, nbr, nmax, fr, H, ks, nc, mo, hk);
}
