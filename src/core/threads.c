/* threads.c -- jf_default_threads: the thread count when a call leaves it
 * to the environment.  OMP_NUM_THREADS is a default, not a request: a
 * value beyond the processors only slows a CPU-bound fit, and one of
 * 20,000 or more ran libgomp out of memory or threads and crashed it
 * (issue 33 item 5), so it is clamped; an explicit threads argument (the
 * command's --threads, up to JF_THREADS_MAX) is obeyed as given. */
#include <omp.h>

#include "jetfit.h"

int jf_default_threads(int *asked)
{
    const int want = omp_get_max_threads();
    int procs = omp_get_num_procs(); /* the affinity mask's CPUs */
    if (procs < 1) procs = 1;
    if (procs > JF_THREADS_MAX) procs = JF_THREADS_MAX;
    if (asked) *asked = want;
    return want < 1 ? 1 : want > procs ? procs : want;
}
