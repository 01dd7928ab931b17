/* test_rand.h -- helpers of the spatial suites: a reproducible uniform
 * generator (xorshift64*, seeded by the suite's JF_TEST_SEED), a
 * Gaussian one, a noisy ellipsoid with its exact normals, and
 * (distance, index) pairs sorted as the k-d tree orders its results. */
#ifndef JF_TEST_RAND_H
#define JF_TEST_RAND_H
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include "jf_test.h"

static uint64_t rng_state = JF_TEST_SEED;
static double urand(void) /* in [0, 1) */
{
    return jf_unit(jf_xorshift64s(&rng_state));
}

static inline double gauss(void) /* standard normal, Box-Muller */
{
    double u = urand() + 1e-300, v = urand();
    return sqrt(-2 * log(u)) * cos(2 * 3.14159265358979 * v);
}

/* n points of x^2 + (y/.75)^2 + (z/.5)^2 = 1 with Gaussian noise sigma
 * along each axis, and the exact normal of the noise-free point */
static inline void ellipsoid(size_t n, double sigma, double *p, double *nrm)
{
    for (size_t i = 0; i < n; i++) {
        double z = 2 * urand() - 1, t = 2 * 3.14159265358979 * urand(), r = sqrt(1 - z * z);
        double x = r * cos(t), y = 0.75 * r * sin(t), w = 0.5 * z;
        nrm[3 * i] = x, nrm[3 * i + 1] = y / 0.5625, nrm[3 * i + 2] = w / 0.25;
        p[3 * i] = x + sigma * gauss(), p[3 * i + 1] = y + sigma * gauss(), p[3 * i + 2] = w + sigma * gauss();
    }
}

typedef struct {
    double d;
    uint32_t i;
} pair;

static inline int cmp_pair(const void *a, const void *b) /* by (d, i) */
{
    const pair *x = a, *y = b;
    if (x->d != y->d) return x->d < y->d ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}
#endif
