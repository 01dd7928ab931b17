/* offthread.c -- the module's OpenMP work runs on a thread of its own,
 * one per call, while the calling thread waits with the GIL released.
 *
 * why: the module and the command share one OpenMP runtime, GCC's libgomp
 * (LLVM's libomp, serving the GOMP_* calls of GCC-built code, aborted in
 * kmp_alloc or corrupted the heap when two Python threads estimated at
 * once -- issue 32 -- and on an empty OMP_NUM_THREADS -- issue 31).
 * libgomp keeps a thread pool per thread that starts a parallel region and
 * frees it when that thread exits; a child forked after the pool's owner
 * ran a region waits forever for the pool's threads.  A short-lived thread
 * per call owns the pool and takes it away with it, so no interpreter
 * thread ever owns one: a forked child (multiprocessing) starts afresh, and
 * concurrent calls each have their own team.
 * Signals: the caller takes the GIL back every 0.1 s to run Python's
 * handlers; an exception raised there (KeyboardInterrupt) sets *stop, which
 * the work's cancel hook reads (jetfit.h's jf_cancel_fn). */
#include <errno.h>
#include <pthread.h>
#include <time.h>

#include "jfpy.h"

typedef struct {
    void (*fn)(void *);
    void *arg;
    int done;
    pthread_mutex_t mu;
    pthread_cond_t cv;
} job;

static void *trampoline(void *p)
{
    job *j = p;
    j->fn(j->arg);
    pthread_mutex_lock(&j->mu);
    j->done = 1;
    pthread_cond_signal(&j->cv);
    pthread_mutex_unlock(&j->mu);
    return NULL;
}

void jf_py_off_thread(void (*fn)(void *), void *arg, volatile int *stop)
{
    job j = {fn, arg, 0, PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER};
    PyThreadState *ts = PyEval_SaveThread();
    pthread_t t;
    if (pthread_create(&t, NULL, trampoline, &j) != 0) {
        fn(arg); /* no thread to spare: here, as before (not fork-safe) */
        PyEval_RestoreThread(ts);
        return;
    }
    pthread_mutex_lock(&j.mu);
    while (!j.done) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_nsec += 100000000L;
        if (until.tv_nsec >= 1000000000L) until.tv_sec++, until.tv_nsec -= 1000000000L;
        int rc = pthread_cond_timedwait(&j.cv, &j.mu, &until);
        if (rc == ETIMEDOUT && !j.done && stop && !*stop) {
            pthread_mutex_unlock(&j.mu);
            PyEval_RestoreThread(ts);
            if (PyErr_CheckSignals() < 0) __atomic_store_n(stop, 1, __ATOMIC_RELEASE);
            ts = PyEval_SaveThread();
            pthread_mutex_lock(&j.mu);
        }
    }
    pthread_mutex_unlock(&j.mu);
    pthread_join(t, NULL);
    PyEval_RestoreThread(ts);
}
