/* auto_k.h -- neighbors auto in the commands' summaries (jetfit estimate,
 * jetfit-mpi): the distribution of the chosen K over auto's candidates
 * and step 0's decision, the same lines in both. */
#ifndef JF_CLI_AUTO_K_H
#define JF_CLI_AUTO_K_H
#include <stddef.h>
#include <stdio.h>

#include "robust/robust_internal.h" /* JF_AUTO_NCAND, jf__auto_ks */

#define JF_CLI_NKBIN JF_AUTO_NCAND /* a bin per candidate K (its upper bound) */

/* The bin of a row's K (its n_used; above the last candidate: the last). */
int jf_cli_kbin(int n_used);
/* "  auto K: <=16: 12 (0%) <=24: ..." (the empty bins left out; nothing
 * when no row was counted), then, when chosen is not 0, "  auto step 0:
 * K capped at 32; ..." (jf_auto_step0_str), each with a newline, to f. */
void jf_cli_auto_summary(FILE *f, const size_t cnt[JF_CLI_NKBIN], int chosen);
#endif
