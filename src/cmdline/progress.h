/* progress.h -- the commands' progress line (jetfit estimate, jetfit-mpi
 * on rank 0) and the phases' times for the summary, fed by the library's
 * progress hooks (jf_phase_fn): the library reports, the command draws. */
#ifndef JF_CLI_PROGRESS_H
#define JF_CLI_PROGRESS_H
#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

#define JF_CLI_NPHASES 5

typedef struct {
    const char *who;        /* "jetfit", "jetfit-mpi"                    */
    int draw;               /* draw the line (a terminal, not --quiet)   */
    int counted;            /* the fit's points come from _fitted         */
    int parts;              /* in parts: their index and order phases are
                             * timed, not drawn (each part's own counts
                             * would interrupt the whole cloud's fit line) */
    int cur;                /* phase being timed, -1 none                 */
    double start, lastcall; /* its first and latest report                */
    double secs[JF_CLI_NPHASES];
    double last;            /* latest redraw (under busy)                 */
    int shown, busy;        /* a line is on screen; a thread draws        */
    uint64_t fit_t0ns;      /* first point counted (atomic)               */
    size_t fitted, fit_total; /* points counted (atomic), of              */
    int fit_final;          /* the fit's 100% line was drawn by _end      */
} jf_cli_progress;

void jf_cli_progress_init(jf_cli_progress *p, const char *who, int draw);
/* A jf_phase_fn (user = p): times the phases, draws the line at most 4
 * times a second. */
void jf_cli_progress_phase(void *user, jf_phase ph, size_t done, size_t total);
/* m more points fitted, from any thread (the estimate's sink). */
void jf_cli_progress_fitted(jf_cli_progress *p, size_t m);
/* Closes the phase being timed and ends the line on screen. */
void jf_cli_progress_end(jf_cli_progress *p);
/* "read 1.20 s, tree 0.81 s, ..." for the phases that ran. */
void jf_cli_progress_times(const jf_cli_progress *p, char *out, size_t len);
#endif
