/* progress.c -- the progress line: phase, points (bytes while reading)
 * done, rate and time left, redrawn in place on stderr; and each phase's
 * time (progress.h). */
#include "progress.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

static const char *const verb[JF_CLI_NPHASES] = {"reading", "ordering", "indexing", "fitting",
                                                 "writing"};
static const char *const noun[JF_CLI_NPHASES] = {"read", "order", "tree", "fit", "write"};

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void jf_cli_progress_init(jf_cli_progress *p, const char *who, int draw)
{
    memset(p, 0, sizeof *p);
    p->who = who;
    p->draw = draw;
    p->cur = -1;
}

/* One redraw (the caller holds busy); since: the phase's start. */
static void draw(jf_cli_progress *p, int ph, size_t done, size_t total, double since)
{
    double t = now_s();
    if (done < total && t - p->last < 0.25) return;
    p->last = t;
    double el = t - since, rate = el > 0 ? (double)done / el : 0;
    double eta = rate > 0 && total > done ? (double)(total - done) / rate : 0;
    double pct = total ? 100.0 * (double)done / (double)total : 100.0;
    if (ph == JF_PHASE_READ)
        fprintf(stderr, "\r%s: %-8s %5.1f%%  %.1f/%.1f MB  %.1f MB/s  ETA %.0f s     ", p->who,
                verb[ph], pct, (double)done / 1e6, (double)total / 1e6, rate / 1e6, eta);
    else
        fprintf(stderr, "\r%s: %-8s %5.1f%%  %zu/%zu points  %.0f points/s  ETA %.0f s     ",
                p->who, verb[ph], pct, done, total, rate, eta);
    fflush(stderr);
    p->shown = 1;
}

void jf_cli_progress_phase(void *user, jf_phase ph, size_t done, size_t total)
{
    jf_cli_progress *p = user;
    if ((int)ph < 0 || (int)ph >= JF_CLI_NPHASES) return;
    double t = now_s();
    if ((int)ph != p->cur) {
        if (p->cur >= 0) p->secs[p->cur] += p->lastcall - p->start;
        /* the fit's first report comes after its first block: it began
         * where the index or order ended */
        p->start = ph == JF_PHASE_FIT && (p->cur == JF_PHASE_INDEX || p->cur == JF_PHASE_ORDER)
                       ? p->lastcall
                       : t;
        p->cur = (int)ph;
    }
    p->lastcall = t;
    if (!p->draw || (ph == JF_PHASE_FIT && p->counted) ||
        (p->parts && (ph == JF_PHASE_INDEX || ph == JF_PHASE_ORDER)))
        return;
    if (__atomic_exchange_n(&p->busy, 1, __ATOMIC_ACQUIRE)) return;
    draw(p, (int)ph, done, total, p->start);
    __atomic_store_n(&p->busy, 0, __ATOMIC_RELEASE);
}

void jf_cli_progress_fitted(jf_cli_progress *p, size_t m)
{
    size_t done = __atomic_add_fetch(&p->fitted, m, __ATOMIC_RELAXED);
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    uint64_t ns = (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec, z = 0;
    __atomic_compare_exchange_n(&p->fit_t0ns, &z, ns, 0, __ATOMIC_RELAXED, __ATOMIC_RELAXED);
    if (!p->draw || __atomic_exchange_n(&p->busy, 1, __ATOMIC_ACQUIRE)) return;
    uint64_t t0 = __atomic_load_n(&p->fit_t0ns, __ATOMIC_RELAXED);
    draw(p, JF_PHASE_FIT, done, p->fit_total, 1e-9 * (double)t0);
    __atomic_store_n(&p->busy, 0, __ATOMIC_RELEASE);
}

void jf_cli_progress_end(jf_cli_progress *p)
{
    if (p->cur >= 0) p->secs[p->cur] += p->lastcall - p->start;
    if (p->draw && p->counted && p->fitted && !p->fit_final) {
        /* the last block's redraw may have met another thread drawing */
        draw(p, JF_PHASE_FIT, p->fitted, p->fit_total, 1e-9 * (double)p->fit_t0ns);
        p->fit_final = 1;
    }
    p->cur = -1;
    if (p->shown) {
        fputc('\n', stderr);
        fflush(stderr);
        p->shown = 0;
    }
}

void jf_cli_progress_times(const jf_cli_progress *p, char *out, size_t len)
{
    size_t u = 0;
    out[0] = '\0';
    for (int k = 0; k < JF_CLI_NPHASES && u < len; k++)
        if (p->secs[k] > 0)
            u += (size_t)snprintf(out + u, len - u, "%s%s %.2f s", u ? ", " : "", noun[k],
                                  p->secs[k]);
}
