/* avx_path.h -- the AVX builds of the hot kernels (fit kernels in core,
 * the k-d tree's small-k query) beside their default builds. */
#ifndef JF_AVX_PATH_H
#define JF_AVX_PATH_H

/* The hot fit kernels have an AVX build beside the default (SSE2) one,
 * picked per call (JF_HAVE_AVX): VEX encodings and 4-lane registers, no
 * FMA (so no contraction): the same IEEE operations in the same order,
 * the same bits on every machine.  An AVX kernel calls nothing and ends
 * with JF_AVX_LEAVE (vzeroupper): GCC 12's target_clones omitted it
 * before a call, and the legacy-SSE code after ran 1.7x slower.  GCC on
 * x86-64 only (clang's fuzz build, other targets, -DJF_NO_CLONES: the
 * default build alone). */
/* 1: the default build even where AVX is there (tests compare the two;
 * not thread-safe to change while fitting) */
extern int jf__no_avx;
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(JF_NO_CLONES)
#define JF_AVX_PATH 1
#define JF_AVX_FN __attribute__((target("avx"), noinline))
#define JF_AVX_LEAVE() __builtin_ia32_vzeroupper()
#define JF_HAVE_AVX() (__builtin_cpu_supports("avx") && !jf__no_avx)
/* a function built twice, AVX and default, picked at load (no FMA: the
 * same bits on every machine) */
#define JF_CLONES __attribute__((target_clones("avx", "default")))
#else
#define JF_AVX_PATH 0
#define JF_CLONES
#endif

#endif /* JF_AVX_PATH_H */
