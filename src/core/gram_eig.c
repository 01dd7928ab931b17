/* gram_eig.c -- the extreme eigenvalues of the Gram matrix G = R^T R of a
 * jet fit (solve.c's fast path: kappa = sqrt(lambda_max / lambda_min)),
 * for two or four fits at once in the lanes of vectors (gram_lanes.h).
 *
 * Householder tridiagonalisation T = H G H (as solve.c's jf__sym_eigvals),
 * then Laguerre's iteration on det(T - x I), evaluated with its first two
 * derivatives by the three-term recurrence, from Gershgorin's bounds: for
 * a polynomial whose roots are all real, Laguerre's step from outside the
 * roots moves monotonically and cubically to the nearest one (Numerical
 * Recipes §9.5), so lambda_max comes from above and lambda_min from below,
 * each in 4-7 steps of one division, against the QL iteration's chain of
 * dependent divisions for all cols eigenvalues (measured: the QL was 85%
 * of the eigen-step, itself 19% of a one-thread knn:16 run).  kappa from
 * these extremes agrees with GSL's SVD to 1e-12 up to kappa 4e3, where
 * the QL's was off by up to 2.2e-9 (test_jet: test_gram_extremes). */
#include <float.h>
#include <math.h>
#include <stddef.h>

#include "fitter_internal.h"
#include "simd.h"


#define GE_MAX 10    /* cols up to degree 3; larger: solve.c's QL       */
#define GE_ITERS 100 /* Laguerre steps before a lane is declared failed */
#define GE_TOL (8 * DBL_EPSILON) /* last step, absolute, T scaled to ~1  */

/* two lanes (SSE2): jf__eigvals_x2, and one fit in both lanes */
#define GL_N 2
#define GL_V v2d
#define GL_M v2l
#define GL_SEL sel2
#define GL_ABS abs2
#define GL_ALL(m) ((m)[0] && (m)[1])
#define GL_SQRT(x) sqrt2(x)
#define GL_SQ_DECL
#define GL_SQ_PASS
#define GL_LOAD(g, i) ((v2d){(g)[0][i], (g)[1][i]})
#define GL_FN(name) name##_x2
#include "gram_lanes.h"
#undef GL_N
#undef GL_V
#undef GL_M
#undef GL_SEL
#undef GL_ABS
#undef GL_ALL
#undef GL_SQRT
#undef GL_SQ_DECL
#undef GL_SQ_PASS
#undef GL_LOAD
#undef GL_FN

/* four lanes: one AVX register, two SSE2 ones in the default build; the
 * sqrt of four lanes is a parameter (simd.h) */
#define GL_N 4
#define GL_V v4d
#define GL_M v4l
#define GL_SEL sel4
#define GL_ABS abs4
#define GL_ALL(m) all4(m)
#define GL_SQRT(x) vsqrt4(x, sq)
#define GL_SQ_DECL , sqrt4_fn sq
#define GL_SQ_PASS , sq
#define GL_LOAD(g, i) ((v4d){(g)[0][i], (g)[1][i], (g)[2][i], (g)[3][i]})
#define GL_FN(name) name##_x4
#include "gram_lanes.h"

/* f->s[0] = lambda_max, f->s[1..cols-1] = lambda_min (fast_finish reads
 * only the extremes) */
static void put(jf_fitter *f, size_t cols, double hi, double lo)
{
    f->s[0] = hi;
    for (size_t j = 1; j < cols; j++) f->s[j] = lo;
}

/* Not inlined: one copy for the one-fit and the pair callers. */
static void gram_extremes(const double *g0, const double *g1, size_t cols, double hi[2],
                          double lo[2], int rc[2])
{
    const double *const g[2] = {g0, g1};
    gram_extremes_x2(g, cols, hi, lo, rc);
}

void jf__eigvals_x2(jf_fitter *f0, jf_fitter *f1, size_t cols, int ok[2])
{
    if (cols > GE_MAX || cols < 2) {
        ok[0] = jf__eigvals(f0, cols);
        ok[1] = jf__eigvals(f1, cols);
        return;
    }
    double hi[2], lo[2];
    int rc[2];
    gram_extremes(f0->x, f1->x, cols, hi, lo, rc);
    put(f0, cols, hi[0], lo[0]);
    put(f1, cols, hi[1], lo[1]);
    ok[0] = rc[0] == 0;
    ok[1] = rc[1] == 0;
}

#if JF_AVX_PATH
JF_AVX_FN static void gram_extremes_x4_avx(const double *const g[4], size_t cols, double hi[4],
                                           double lo[4], int rc[4])
{
    gram_extremes_x4(g, cols, hi, lo, rc, sqrt4_avx);
    JF_AVX_LEAVE();
}
#endif

void jf__gram_extremes_x4(const double *const g[4], size_t cols, double hi[4], double lo[4],
                          int ok[4])
{
    if (cols > GE_MAX || cols < 2) {
        for (int L = 0; L < 4; L++) ok[L] = 0;
        return;
    }
    int rc[4];
#if JF_AVX_PATH
    if (JF_HAVE_AVX()) gram_extremes_x4_avx(g, cols, hi, lo, rc);
    else
#endif
        gram_extremes_x4(g, cols, hi, lo, rc, sqrt4_sse);
    for (int L = 0; L < 4; L++) ok[L] = rc[L] == 0;
}

/* f[L] may repeat (a lane whose result is not wanted): its lanes compute
 * the same values. */
void jf__eigvals_x4(jf_fitter *const f[4], size_t cols, int ok[4])
{
    if (cols > GE_MAX || cols < 2) { /* once per fitter: the QL destroys f->x */
        for (int L = 0; L < 4; L++) {
            int l = 0;
            while (l < L && f[l] != f[L]) l++;
            ok[L] = l < L ? ok[l] : jf__eigvals(f[L], cols);
        }
        return;
    }
    const double *g[4] = {f[0]->x, f[1]->x, f[2]->x, f[3]->x};
    double hi[4], lo[4];
    jf__gram_extremes_x4(g, cols, hi, lo, ok);
    for (int L = 0; L < 4; L++) put(f[L], cols, hi[L], lo[L]);
}

int jf__eigvals(jf_fitter *f, size_t cols)
{
    if (cols > GE_MAX || cols < 2) return jf__sym_eigvals(f->x, cols, f->s, f->work) == 0;
    /* both lanes on the same matrix: the bits of jf__eigvals_x2's lanes */
    double hi[2], lo[2];
    int rc[2];
    gram_extremes(f->x, f->x, cols, hi, lo, rc);
    put(f, cols, hi[0], lo[0]);
    return rc[0] == 0;
}

int jf__gram_extremes(const double *g, size_t cols, double *hi, double *lo)
{
    if (cols > GE_MAX || cols < 2) return 0;
    double h[2], l[2];
    int rc[2];
    gram_extremes(g, g, cols, h, l, rc);
    *hi = h[0];
    *lo = l[0];
    return rc[0] == 0;
}
