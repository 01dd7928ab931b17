/* frame.c -- the fitting frame of §5.2: PCA of the neighbourhood or the
 * world axis closest to the PCA normal.
 *
 * design: the points arrive already translated to p (so coordinates of
 * 1e6 lose nothing); the covariance is accumulated in two passes about the
 * weighted centroid (CGAL 5.5.1 sums in one pass in world coordinates and
 * loses all precision at large offsets, docs/design.md "CGAL 5.5.1"); a cyclic Jacobi
 * eigen-solver gives orthonormal eigenvectors whose signs are pinned so the
 * frame, hence every result, is reproducible.  neighbors auto's frames
 * take two faster forms: the least eigenvector in closed form
 * (jf__normal3) and Jacobi to rounding in given axes (jf__eig3_in). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "fitter_internal.h"
#include "simd.h"

/* Pins the sign of v: its largest-|component| (first on ties) positive. */
static void pin_sign(double *v)
{
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(v[i]) > fabs(v[k])) k = i;
    if (v[k] < 0) {
        v[0] = -v[0];
        v[1] = -v[1];
        v[2] = -v[2];
    }
}

/* Eigenvalues (diagonal of a) ascending, stable on ties (deterministic),
 * and their eigenvectors (columns of v) with pinned signs. */
static void eig3_sorted(double a[3][3], double v[3][3], double eval[3], double evec[9])
{
    int idx[3] = {0, 1, 2};
    for (int i = 1; i < 3; i++)
        for (int j = i; j > 0 && a[idx[j]][idx[j]] < a[idx[j - 1]][idx[j - 1]]; j--) {
            int t = idx[j];
            idx[j] = idx[j - 1];
            idx[j - 1] = t;
        }
    for (int k = 0; k < 3; k++) {
        eval[k] = a[idx[k]][idx[k]];
        for (int i = 0; i < 3; i++) evec[3 * k + i] = v[i][idx[k]];
        pin_sign(evec + 3 * k);
    }
}

/* Cyclic Jacobi on a (symmetric), rotations accumulated into v, until
 * the off-diagonal sum is at most tol x the diagonal's. */
static inline __attribute__((always_inline)) void jacobi3(double a[3][3], double v[3][3], double tol)
{
    /* Cyclic Jacobi (Golub & Van Loan §8.5): each rotation zeroes a[p][q];
     * converges quadratically, 50 sweeps is far beyond what doubles need. */
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        if (off == 0.0 || off <= tol * diag) break;
        for (int p = 0; p < 2; p++) {
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0) continue;
                double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                /* t = tan of the rotation angle, the smaller root */
                /* theta^2 would overflow: t ~ 1/(2 theta) */
                double t = fabs(theta) > 1e150
                               ? 1.0 / (2.0 * theta)
                               : (theta >= 0 ? 1.0 : -1.0) /
                                     (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J */
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A */
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                a[p][q] = a[q][p] = 0.0;
                for (int k = 0; k < 3; k++) { /* V <- V J */
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
}

/* a_in symmetrised, Jacobi until off-diagonal <= tol x diagonal, the
 * eigenvectors turned to the world from the axes rot (rows; NULL: the
 * world's), sorted and pinned */
static inline __attribute__((always_inline)) void
eig3_tol(const double a_in[9], const double rot[9], double tol, double eval[3], double evec[9])
{
    double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, w[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) a[i][j] = 0.5 * (a_in[3 * i + j] + a_in[3 * j + i]);
    jacobi3(a, v, tol);
    if (!rot) {
        eig3_sorted(a, v, eval, evec);
        return;
    }
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            w[i][k] = rot[i] * v[0][k] + rot[3 + i] * v[1][k] + rot[6 + i] * v[2][k];
    eig3_sorted(a, w, eval, evec);
}

void jf__eig3(const double a_in[9], double eval[3], double evec[9])
{
    eig3_tol(a_in, NULL, DBL_EPSILON * DBL_EPSILON, eval, evec);
}

/* off-diagonal to rounding (eps, not eps^2 x the diagonal): the
 * eigenvectors to rounding too, a sweep sooner */
void jf__eig3_in(const double a_in[9], const double rot[9], double eval[3], double evec[9])
{
    eig3_tol(a_in, rot, DBL_EPSILON, eval, evec);
}

static void cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

int jf__normal3(const double a[9], double evec[9])
{
    /* the eigenvalues in closed form (Smith, CACM 1961): A = q I + p B,
     * det(B) / 2 = cos(3 phi) */
    double m = 0.0; /* scaled to entries <= 1: no underflow in the products below */
    for (int k = 0; k < 9; k++) m = fabs(a[k]) > m ? fabs(a[k]) : m;
    if (!(m > 0.0) || !(m < INFINITY)) return 0;
    const double im = 1.0 / m;
    if (!(im < INFINITY)) return 0; /* subnormal entries only */
    const double a00 = a[0] * im, a11 = a[4] * im, a22 = a[8] * im;
    const double a01 = 0.5 * (a[1] + a[3]) * im, a02 = 0.5 * (a[2] + a[6]) * im,
                 a12 = 0.5 * (a[5] + a[7]) * im;
    const double q = (a00 + a11 + a22) / 3.0;
    const double d0 = a00 - q, d1 = a11 - q, d2 = a22 - q;
    const double p2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * (a01 * a01 + a02 * a02 + a12 * a12);
    if (!(p2 > 0.0)) return 0; /* a multiple of I, or NaN */
    const double p = sqrt(p2 / 6.0), ip = 1.0 / p;
    const double b00 = d0 * ip, b11 = d1 * ip, b22 = d2 * ip, b01 = a01 * ip, b02 = a02 * ip,
                 b12 = a12 * ip;
    double r = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) +
                      b02 * (b01 * b12 - b11 * b02));
    r = r < -1.0 ? -1.0 : r > 1.0 ? 1.0 : r;
    const double phi = acos(r) / 3.0;
    const double l1 = q + 2.0 * p * cos(phi + 2.0943951023931957); /* + 2 pi / 3: the least */
    /* its eigenvector: the longest cross product of two rows of A - l1 I
     * (their length is about (l2 - l1)(l3 - l1)) */
    const double r0[3] = {a00 - l1, a01, a02}, r1[3] = {a01, a11 - l1, a12},
                 r2[3] = {a02, a12, a22 - l1};
    double c[3][3], best = 0.0;
    int kb = 0;
    cross(r0, r1, c[0]);
    cross(r0, r2, c[1]);
    cross(r1, r2, c[2]);
    for (int k = 0; k < 3; k++) {
        double n2 = c[k][0] * c[k][0] + c[k][1] * c[k][1] + c[k][2] * c[k][2];
        if (n2 > best) best = n2, kb = k;
    }
    /* l1 near l2 (no clear normal): the caller's Jacobi decides */
    if (!(best > 1e-12 * (9.0 * p2) * (9.0 * p2))) return 0;
    const double il = 1.0 / sqrt(best);
    double *n = evec, *t = evec + 6;
    for (int i = 0; i < 3; i++) n[i] = c[kb][i] * il;
    pin_sign(n);
    /* any unit t perpendicular to n (from the world axis least along n) */
    int ax = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(n[i]) < fabs(n[ax])) ax = i;
    for (int i = 0; i < 3; i++) t[i] = (i == ax) - n[ax] * n[i];
    const double it = 1.0 / sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int i = 0; i < 3; i++) t[i] *= it;
    cross(n, t, evec + 3);
    return 1;
}

void jf__eig3_near(const double a[9], const double rot[9], double eval[3], double evec[9])
{
    double e[9];
    if (!jf__normal3(a, e)) {
        jf__eig3_in(a, rot, eval, evec);
        return;
    }
    /* the other two from the 2 x 2 block of a in the plane normal to n
     * (t, u: normal3's axes there) */
    const double *n = e, *u = e + 3, *t = e + 6;
    double an[3], at[3], au[3];
    for (int i = 0; i < 3; i++) {
        an[i] = a[3 * i] * n[0] + a[3 * i + 1] * n[1] + a[3 * i + 2] * n[2];
        at[i] = a[3 * i] * t[0] + a[3 * i + 1] * t[1] + a[3 * i + 2] * t[2];
        au[i] = a[3 * i] * u[0] + a[3 * i + 1] * u[1] + a[3 * i + 2] * u[2];
    }
    const double tt = t[0] * at[0] + t[1] * at[1] + t[2] * at[2];
    const double uu = u[0] * au[0] + u[1] * au[1] + u[2] * au[2];
    const double tu = t[0] * au[0] + t[1] * au[1] + t[2] * au[2];
    const double mid = 0.5 * (tt + uu), rad = hypot(0.5 * (tt - uu), tu), l3 = mid + rad;
    eval[0] = n[0] * an[0] + n[1] * an[1] + n[2] * an[2];
    eval[1] = mid - rad;
    eval[2] = l3;
    /* the largest's eigenvector (tu, l3 - tt) or (l3 - uu, tu) in (t, u),
     * whichever is longer (one vanishes where t or u is it already) */
    const double e0 = tu, e1 = l3 - tt, f0 = l3 - uu, f1 = tu;
    const int ef = e0 * e0 + e1 * e1 >= f0 * f0 + f1 * f1;
    double g0 = ef ? e0 : f0, g1 = ef ? e1 : f1, gl = sqrt(g0 * g0 + g1 * g1);
    if (!(gl > 0.0)) g0 = 1.0, g1 = 0.0, gl = 1.0; /* a multiple of I there: any */
    g0 /= gl, g1 /= gl;
    const double v[3][3] = {{n[0], n[1], n[2]},
                            {g1 * t[0] - g0 * u[0], g1 * t[1] - g0 * u[1], g1 * t[2] - g0 * u[2]},
                            {g0 * t[0] + g1 * u[0], g0 * t[1] + g1 * u[1], g0 * t[2] + g1 * u[2]}};
    static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double *R = rot ? rot : id;
    for (int r = 0; r < 3; r++) { /* to the world's axes, pinned as jf__eig3's */
        for (int k = 0; k < 3; k++)
            evec[3 * r + k] = v[r][0] * R[k] + v[r][1] * R[3 + k] + v[r][2] * R[6 + k];
        pin_sign(evec + 3 * r);
    }
}

int jf__frame_cov(const double *q, const double *w, size_t n, double cov[9])
{
    /* pass 1: weighted centroid */
    double sw = 0, c[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        if (!(w[i] > 0)) continue;
        sw += w[i];
        for (int k = 0; k < 3; k++) c[k] += w[i] * q[3 * i + k];
    }
    if (!(sw > 0) || !isfinite(sw)) return -1;
    for (int k = 0; k < 3; k++) c[k] /= sw;
    /* pass 2: covariance about the centroid, in locals (sums in cov[]
     * would be stored and reloaded each point: cov may alias q and w) */
    double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
    for (size_t i = 0; i < n; i++) {
        if (!(w[i] > 0)) continue;
        /* scalars: an array d[3] here is vectorised through the stack
         * (partial stores reloaded whole: a store-forwarding stall) */
        const double dx = q[3 * i] - c[0], dy = q[3 * i + 1] - c[1], dz = q[3 * i + 2] - c[2];
        const double wx = w[i] * dx, wy = w[i] * dy, wz = w[i] * dz;
        xx += wx * dx;
        xy += wx * dy;
        xz += wx * dz;
        yy += wy * dy;
        yz += wy * dz;
        zz += wz * dz;
    }
    cov[0] = xx / sw;
    cov[1] = cov[3] = xy / sw;
    cov[2] = cov[6] = xz / sw;
    cov[4] = yy / sw;
    cov[5] = cov[7] = yz / sw;
    cov[8] = zz / sw;
    for (int k = 0; k < 9; k++)
        if (!isfinite(cov[k])) return -1;
    return 0;
}

void jf__frame_axes(const double evec[9], jf_frame_mode mode, double r[9])
{
    if (mode == JF_FRAME_AXIS) {
        /* §5.2: z is the world axis closest to the rough (PCA) normal; its
         * positive direction, since the pinned normal's largest component
         * is positive.  x, y cyclic so the frame is right-handed. */
        const double *nrm = evec;
        int k = 0;
        for (int i = 1; i < 3; i++)
            if (fabs(nrm[i]) > fabs(nrm[k])) k = i;
        memset(r, 0, 9 * sizeof r[0]);
        r[0 + (k + 1) % 3] = 1.0; /* ex */
        r[3 + (k + 2) % 3] = 1.0; /* ey */
        r[6 + k] = 1.0;           /* ez */
    } else {
        /* z = smallest-eigenvalue eigenvector, x = largest, y = z cross x */
        memcpy(r + 0, evec + 6, 3 * sizeof r[0]);
        memcpy(r + 6, evec + 0, 3 * sizeof r[0]);
        cross(r + 6, r + 0, r + 3);
    }
}

int jf__frame(const double *q, const double *w, size_t n, jf_frame_mode mode,
              double r[9], double eval[3])
{
    double cov[9], evec[9];
    if (jf__frame_cov(q, w, n, cov) != 0) return -1;
    jf__eig3(cov, eval, evec);
    jf__frame_axes(evec, mode, r);
    return 0;
}

/* ---- two at once ------------------------------------------------------
 * jf__eig3 of two matrices in the two lanes of SSE2 vectors: the same
 * rotations in the same order, each lane's own skips and stop kept by
 * masks (a lane that would skip a rotation keeps its values), so each
 * lane gets the bits jf__eig3 gives.  The Jacobi rotations are a chain of
 * dependent divisions and square roots: two chains side by side cost
 * little more than one (lane helpers: simd.h). */

/* The rotations of jf__eig3_x2: the diagonalised matrices and the
 * rotations' products, lane by lane, into al[lane], vl[lane]. */
static inline __attribute__((always_inline)) void eig3_x2_sweeps(const double a0[9],
                                                                 const double a1[9],
                                                                 double al[2][3][3],
                                                                 double vl[2][3][3])
{
    v2d a[3][3], v[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            a[i][j] = (v2d){0.5 * (a0[3 * i + j] + a0[3 * j + i]),
                            0.5 * (a1[3 * i + j] + a1[3 * j + i])};
            v[i][j] = (v2d){i == j ? 1.0 : 0.0, i == j ? 1.0 : 0.0};
        }
    const v2d one = {1.0, 1.0}, zero = {0.0, 0.0};
    v2l live = {-1, -1}; /* lanes still sweeping */
    for (int sweep = 0; sweep < 50; sweep++) {
        v2d off = abs2(a[0][1]) + abs2(a[0][2]) + abs2(a[1][2]);
        v2d diag = abs2(a[0][0]) + abs2(a[1][1]) + abs2(a[2][2]);
        live &= ~((v2l)(off == zero) | (v2l)(off <= DBL_EPSILON * DBL_EPSILON * diag));
        if (!live[0] && !live[1]) break;
        /* unrolled: constant indices keep a and v in registers (the loop
         * kept them on the stack, a store and reload in the chain) */
#pragma GCC unroll 2
        for (int p = 0; p < 2; p++) {
#pragma GCC unroll 2
            for (int q = p + 1; q < 3; q++) {
                const v2l on = live & ~(v2l)(a[p][q] == zero);
                if (!on[0] && !on[1]) continue;
                /* a lane that skips may divide by 0 here: masked below */
                v2d theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                v2d sg = sel2((v2l)(theta >= zero), one, -one);
                v2d t = sel2((v2l)(abs2(theta) > (v2d){1e150, 1e150}), one / (2.0 * theta),
                             sg / (abs2(theta) + sqrt2(theta * theta + one)));
                v2d c = one / sqrt2(t * t + one), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A J */
                    v2d akp = a[k][p], akq = a[k][q];
                    a[k][p] = sel2(on, c * akp - s * akq, akp);
                    a[k][q] = sel2(on, s * akp + c * akq, akq);
                }
                for (int k = 0; k < 3; k++) { /* A <- J^T A */
                    v2d apk = a[p][k], aqk = a[q][k];
                    a[p][k] = sel2(on, c * apk - s * aqk, apk);
                    a[q][k] = sel2(on, s * apk + c * aqk, aqk);
                }
                a[p][q] = a[q][p] = sel2(on, zero, a[p][q]);
                for (int k = 0; k < 3; k++) { /* V <- V J */
                    v2d vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = sel2(on, c * vkp - s * vkq, vkp);
                    v[k][q] = sel2(on, s * vkp + c * vkq, vkq);
                }
            }
        }
    }
    for (int lane = 0; lane < 2; lane++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                al[lane][i][j] = a[i][j][lane];
                vl[lane][i][j] = v[i][j][lane];
            }
}

#if JF_AVX_PATH
JF_AVX_FN static void eig3_x2_avx(const double a0[9], const double a1[9], double al[2][3][3],
                                  double vl[2][3][3])
{
    eig3_x2_sweeps(a0, a1, al, vl);
    JF_AVX_LEAVE();
}
#endif

void jf__eig3_x2(const double a0[9], const double a1[9], double eval0[3], double evec0[9],
                 double eval1[3], double evec1[9])
{
    double al[2][3][3], vl[2][3][3];
#if JF_AVX_PATH
    if (JF_HAVE_AVX()) eig3_x2_avx(a0, a1, al, vl);
    else
#endif
        eig3_x2_sweeps(a0, a1, al, vl);
    eig3_sorted(al[0], vl[0], eval0, evec0);
    eig3_sorted(al[1], vl[1], eval1, evec1);
}

/* ---- four at once ------------------------------------------------------
 * jf__eig3_x2's rotations for four matrices in the four lanes of 32-byte
 * vectors (one AVX register, two SSE2 ones in the default build): each
 * lane the same operations, the bits of jf__eig3.  The sqrt of four lanes
 * is a parameter (always inlined: vsqrtpd in the AVX build). */

static inline __attribute__((always_inline)) void eig3_x4_sweeps(const double *const m[4],
                                                                 double al[4][3][3],
                                                                 double vl[4][3][3], sqrt4_fn sq)
{
    v4d a[3][3], v[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            for (int L = 0; L < 4; L++) a[i][j][L] = 0.5 * (m[L][3 * i + j] + m[L][3 * j + i]);
            const double id = i == j ? 1.0 : 0.0;
            v[i][j] = (v4d){id, id, id, id};
        }
    const v4d one = {1.0, 1.0, 1.0, 1.0}, zero = {0.0, 0.0, 0.0, 0.0};
    const v4d big = {1e150, 1e150, 1e150, 1e150};
    v4l live = {-1, -1, -1, -1};
    for (int sweep = 0; sweep < 50; sweep++) {
        v4d off = abs4(a[0][1]) + abs4(a[0][2]) + abs4(a[1][2]);
        v4d diag = abs4(a[0][0]) + abs4(a[1][1]) + abs4(a[2][2]);
        live &= ~((v4l)(off == zero) | (v4l)(off <= DBL_EPSILON * DBL_EPSILON * diag));
        if (!any4(live)) break;
#pragma GCC unroll 2
        for (int p = 0; p < 2; p++) {
#pragma GCC unroll 2
            for (int q = p + 1; q < 3; q++) {
                const v4l on = live & ~(v4l)(a[p][q] == zero);
                if (!any4(on)) continue;
                v4d theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                v4d sg = sel4((v4l)(theta >= zero), one, -one);
                v4d t = sel4((v4l)(abs4(theta) > big), one / (2.0 * theta),
                             sg / (abs4(theta) + vsqrt4(theta * theta + one, sq)));
                v4d c = one / vsqrt4(t * t + one, sq), s = t * c;
                for (int k = 0; k < 3; k++) {
                    v4d akp = a[k][p], akq = a[k][q];
                    a[k][p] = sel4(on, c * akp - s * akq, akp);
                    a[k][q] = sel4(on, s * akp + c * akq, akq);
                }
                for (int k = 0; k < 3; k++) {
                    v4d apk = a[p][k], aqk = a[q][k];
                    a[p][k] = sel4(on, c * apk - s * aqk, apk);
                    a[q][k] = sel4(on, s * apk + c * aqk, aqk);
                }
                a[p][q] = a[q][p] = sel4(on, zero, a[p][q]);
                for (int k = 0; k < 3; k++) {
                    v4d vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = sel4(on, c * vkp - s * vkq, vkp);
                    v[k][q] = sel4(on, s * vkp + c * vkq, vkq);
                }
            }
        }
    }
    for (int L = 0; L < 4; L++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                al[L][i][j] = a[i][j][L];
                vl[L][i][j] = v[i][j][L];
            }
}

#if JF_AVX_PATH
JF_AVX_FN static void eig3_x4_avx(const double *const m[4], double al[4][3][3], double vl[4][3][3])
{
    eig3_x4_sweeps(m, al, vl, sqrt4_avx);
    JF_AVX_LEAVE();
}
#endif

void jf__eig3_x4(const double *const a[4], double *const eval[4], double *const evec[4])
{
    double al[4][3][3], vl[4][3][3];
#if JF_AVX_PATH
    if (JF_HAVE_AVX()) eig3_x4_avx(a, al, vl);
    else
#endif
        eig3_x4_sweeps(a, al, vl, sqrt4_sse);
    for (int L = 0; L < 4; L++) eig3_sorted(al[L], vl[L], eval[L], evec[L]);
}
