/* fuzz_laz_rt.c -- libFuzzer round trip of the LAZ chunk coders
 * (tests/fuzz/README.md): the first byte picks a point format (0-3, 6-8)
 * and the extra bytes (0-7), the rest is records; they are encoded as one
 * chunk (laz_v2_enc.c / laz_v3_enc.c) and decoded back (laz_v2.c /
 * laz_v3.c): any difference or decoder complaint aborts. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "laz_enc.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const unsigned fmts[8] = {0, 1, 2, 3, 6, 7, 8, 6};
    static const unsigned base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
    if (size < 2)
        return 0;
    unsigned fmt = fmts[data[0] & 7], extra = (data[0] >> 3) & 7, rl = base[fmt] + extra;
    uint32_t n = (uint32_t)((size - 1) / rl);
    if (!n)
        return 0;
    lz_item it[6];
    unsigned ni = 0;
    if (fmt < 6) {
        it[ni++] = (lz_item){LZ_POINT10, 20, 2};
        if (fmt & 1) it[ni++] = (lz_item){LZ_GPSTIME11, 8, 2};
        if (fmt >= 2) it[ni++] = (lz_item){LZ_RGB12, 6, 2};
        if (extra) it[ni++] = (lz_item){LZ_BYTE, extra, 2};
    } else {
        it[ni++] = (lz_item){LZ_POINT14, 30, 3};
        if (fmt == 7) it[ni++] = (lz_item){LZ_RGB14, 6, 3};
        if (fmt == 8) it[ni++] = (lz_item){LZ_RGBNIR14, 8, 3};
        if (extra) it[ni++] = (lz_item){LZ_BYTE14, extra, 3};
    }
    const uint8_t *rec = data + 1;
    uint8_t *back = malloc((size_t)n * rl);
    lz_enc o;
    lz_enc_init(&o, NULL);
    int rc = fmt < 6 ? jf__laz_v2_encode(it, ni, rl, rec, n, &o)
                     : jf__laz_v3_encode(it, ni, rl, rec, n, &o);
    char msg[160];
    if (rc == 0)
        rc = fmt < 6 ? jf__laz_v2_chunk(it, ni, rl, o.buf, o.buf + o.len, n, back, msg, sizeof msg)
                     : jf__laz_v3_chunk(it, ni, rl, o.buf, o.buf + o.len, n, back, msg, sizeof msg);
    if (rc != 0 || memcmp(rec, back, (size_t)n * rl)) {
        fprintf(stderr, "fuzz_laz_rt: format %u, %u points: %s\n", fmt, n,
                rc ? msg : "records differ");
        abort();
    }
    lz_enc_free(&o);
    free(back);
    return 0;
}
