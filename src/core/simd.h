/* simd.h -- the two- and four-lane vector helpers of the side-by-side
 * kernels (frame.c's Jacobi rotations, gram_eig.c's extreme eigenvalues):
 * lane masks, |x| and IEEE square roots, which are correctly rounded, so
 * every lane gets the bits of the one-at-a-time code. */
#ifndef JF_SIMD_H
#define JF_SIMD_H

#include <math.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "avx_path.h"

typedef double v2d __attribute__((vector_size(16)));
typedef long long v2l __attribute__((vector_size(16)));

static inline v2d sel2(v2l m, v2d a, v2d b) { return (v2d)(((v2l)a & m) | ((v2l)b & ~m)); }
static inline v2d abs2(v2d x) { return (v2d)((v2l)x & ~(v2l)(v2d){-0.0, -0.0}); }
static inline v2d sqrt2(v2d x)
{
#if defined(__SSE2__)
    return (v2d)_mm_sqrt_pd((__m128d)x);
#else
    return (v2d){sqrt(x[0]), sqrt(x[1])};
#endif
}

/* Four lanes: one AVX register, two SSE2 ones in the default build.  The
 * sqrt of four lanes is a parameter of the kernels (always inlined:
 * vsqrtpd in their AVX build, two sqrtpd else). */
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4l __attribute__((vector_size(32)));
typedef void (*sqrt4_fn)(v4d *);
/* all inlined: no call passes a v4d (GCC's ABI note does not apply) */
#if defined(__GNUC__) /* clang too */
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

static inline v4d sel4(v4l m, v4d a, v4d b) { return (v4d)(((v4l)a & m) | ((v4l)b & ~m)); }
static inline v4d abs4(v4d x) { return (v4d)((v4l)x & ~(v4l)(v4d){-0.0, -0.0, -0.0, -0.0}); }
static inline int any4(v4l m) { return m[0] || m[1] || m[2] || m[3]; }
static inline int all4(v4l m) { return m[0] && m[1] && m[2] && m[3]; }
static inline v4d vsqrt4(v4d x, sqrt4_fn sq)
{
    sq(&x);
    return x;
}
static inline __attribute__((always_inline)) void sqrt4_sse(v4d *x)
{
    const v2d lo = sqrt2((v2d){(*x)[0], (*x)[1]}), hi = sqrt2((v2d){(*x)[2], (*x)[3]});
    *x = (v4d){lo[0], lo[1], hi[0], hi[1]};
}
#if JF_AVX_PATH
__attribute__((target("avx"), always_inline)) static inline void sqrt4_avx(v4d *x)
{
    *x = __builtin_ia32_sqrtpd256(*x);
}
#endif

#endif /* JF_SIMD_H */
