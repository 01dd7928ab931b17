/* test_rand.h -- helpers of the spatial suites: a reproducible uniform
 * generator (xorshift64*, seeded by the suite's JF_TEST_SEED) and
 * (distance, index) pairs sorted as the k-d tree orders its results. */
#ifndef JF_TEST_RAND_H
#define JF_TEST_RAND_H
#include <stdint.h>

static uint64_t rng_state = JF_TEST_SEED;
static double urand(void) /* in [0, 1) */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

typedef struct {
    double d;
    uint32_t i;
} pair;

static int cmp_pair(const void *a, const void *b) /* by (d, i) */
{
    const pair *x = a, *y = b;
    if (x->d != y->d) return x->d < y->d ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}
#endif
