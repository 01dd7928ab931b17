/* fuzz_laz_rt.c -- libFuzzer round trip of the LAZ chunk coders
 * (tests/fuzz/README.md): the first byte picks a point format (0-3, 6-8)
 * and the extra bytes (0-7), the rest is records; they are encoded as one
 * chunk (laz_v2_enc.c / laz_v3_enc.c) and decoded back (laz_v2.c /
 * laz_v3.c): any difference or decoder complaint aborts. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/laz_roundtrip.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const unsigned fmts[8] = {0, 1, 2, 3, 6, 7, 8, 6};
    if (size < 2)
        return 0;
    unsigned fmt = fmts[data[0] & 7], extra = (data[0] >> 3) & 7, rl = lazgen_base[fmt] + extra;
    uint32_t n = (uint32_t)((size - 1) / rl);
    if (!n)
        return 0;
    uint8_t *back = malloc((size_t)n * rl);
    char msg[160];
    if (lazrt_roundtrip(fmt, extra, data + 1, n, back, msg, sizeof msg)) {
        fprintf(stderr, "fuzz_laz_rt: format %u, %u points: %s\n", fmt, n, msg);
        abort();
    }
    free(back);
    return 0;
}
