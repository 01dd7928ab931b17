/* auto_k.c -- neighbors auto in the summaries (auto_k.h). */
#include "auto_k.h"

int jf_cli_kbin(int n_used)
{
    int b = 0;
    while (b < JF_CLI_NKBIN - 1 && (size_t)n_used > jf__auto_ks[b]) b++;
    return b;
}

void jf_cli_auto_summary(FILE *f, const size_t cnt[JF_CLI_NKBIN], int chosen)
{
    size_t n = 0;
    for (int b = 0; b < JF_CLI_NKBIN; b++) n += cnt[b];
    if (n) {
        fprintf(f, "  auto K:");
        for (int b = 0; b < JF_CLI_NKBIN; b++)
            if (cnt[b])
                fprintf(f, " <=%zu: %zu (%.0f%%)", jf__auto_ks[b], cnt[b], 100.0 * (double)cnt[b] / (double)n);
        fputc('\n', f);
    }
    if (chosen) { /* step 0: what the cloud's cross-validation decided */
        char line[256];
        fprintf(f, "  auto step 0: %s\n", jf_auto_step0_str(chosen, line, sizeof line));
    }
}
