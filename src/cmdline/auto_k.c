/* auto_k.c -- neighbors auto's K distribution in the summaries (auto_k.h). */
#include "auto_k.h"

static const int kbin[JF_CLI_NKBIN] = {16, 24, 32, 48, 64, 96, 128, 160, 200, JF_NB_AUTO_KMAX};

int jf_cli_kbin(int n_used)
{
    int b = 0;
    while (b < JF_CLI_NKBIN - 1 && n_used > kbin[b]) b++;
    return b;
}

void jf_cli_kbins_print(FILE *f, const size_t cnt[JF_CLI_NKBIN])
{
    size_t n = 0;
    for (int b = 0; b < JF_CLI_NKBIN; b++) n += cnt[b];
    if (!n) return;
    fprintf(f, "  auto K:");
    for (int b = 0; b < JF_CLI_NKBIN; b++)
        if (cnt[b]) fprintf(f, " <=%d: %zu (%.0f%%)", kbin[b], cnt[b], 100.0 * (double)cnt[b] / (double)n);
    fputc('\n', f);
}
