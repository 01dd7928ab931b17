/* auto_k.h -- neighbors auto's distribution of the chosen K in the
 * commands' summaries (jetfit estimate, jetfit-mpi): the same bins and
 * the same line in both. */
#ifndef JF_CLI_AUTO_K_H
#define JF_CLI_AUTO_K_H
#include <stddef.h>
#include <stdio.h>

#include "jetfit.h"

#define JF_CLI_NKBIN 10 /* auto's candidate K, the bins' upper bounds */

/* The bin of a row's K (its n_used; above the last bound: the last). */
int jf_cli_kbin(int n_used);
/* "  auto K: <=16: 12 (0%) <=24: ..." and a newline to f, the empty bins
 * left out; nothing when no row was counted. */
void jf_cli_kbins_print(FILE *f, const size_t cnt[JF_CLI_NKBIN]);
#endif
