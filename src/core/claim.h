/* claim.h -- chunks of a parallel loop claimed from a shared counter, with
 * chunk 0 always the calling thread's (OpenMP thread 0): the progress and
 * cancel hooks run on that thread only, so with `omp for schedule(dynamic)`
 * a loop of few chunks could end without the hooks seeing one (another
 * thread took them all).  In core: the PLY reader (io/) and the fit pass
 * (estimate/) share their chunks this way.
 *
 *   size_t next = 1;                             (shared, before the region)
 *   for (size_t ch = jf__claim_first(&next); ch < n; ch = jf__claim_next(&next))
 */
#ifndef JF_CLAIM_H
#define JF_CLAIM_H
#include <stddef.h>

#include <omp.h>

/* The next unclaimed chunk (the counter starts at 1: chunk 0 is reserved). */
static inline size_t jf__claim_next(size_t *next)
{
    return __atomic_fetch_add(next, 1, __ATOMIC_RELAXED);
}

/* A thread's first chunk: 0 on the calling thread, else the next unclaimed. */
static inline size_t jf__claim_first(size_t *next)
{
    return omp_get_thread_num() == 0 ? 0 : jf__claim_next(next);
}
#endif
