/* laz_roundtrip.h -- the LAZ chunk coders' round trip, shared by
 * test_io_laz_write (codec_fuzz) and tests/fuzz/fuzz_laz_rt.c: n records
 * of point format fmt (0-3, 6-8) with `extra` extra bytes encoded as one
 * chunk (laz_v2_enc.c / laz_v3_enc.c), then decoded back (laz_v2.c /
 * laz_v3.c) into `back`. */
#ifndef JF_LAZ_ROUNDTRIP_H
#define JF_LAZ_ROUNDTRIP_H
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "laz_enc.h"
#include "laz_gen.h"

/* The items of the laszip VLR for fmt and extra (as io_laz_write.c
 * writes them); their count. */
static unsigned lazrt_items(unsigned fmt, unsigned extra, lz_item it[6])
{
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
    return ni;
}

/* rec's n records (lazgen_base[fmt] + extra bytes each) encoded and
 * decoded into back: 0 when back equals rec, else -1 and msg says what
 * failed (the encoder, the decoder's message, or the records differ). */
static int lazrt_roundtrip(unsigned fmt, unsigned extra, const uint8_t *rec, uint32_t n,
                           uint8_t *back, char *msg, size_t msglen)
{
    lz_item it[6];
    unsigned ni = lazrt_items(fmt, extra, it), rl = lazgen_base[fmt] + extra;
    lz_enc o;
    lz_enc_init(&o, NULL);
    int rc = fmt < 6 ? jf__laz_v2_encode(it, ni, rl, rec, n, &o)
                     : jf__laz_v3_encode(it, ni, rl, rec, n, &o);
    if (rc)
        snprintf(msg, msglen, "the encoder failed");
    else
        rc = fmt < 6 ? jf__laz_v2_chunk(it, ni, rl, o.buf, o.buf + o.len, n, back, msg, msglen)
                     : jf__laz_v3_chunk(it, ni, rl, o.buf, o.buf + o.len, n, back, msg, msglen);
    if (!rc && memcmp(rec, back, (size_t)n * rl)) {
        snprintf(msg, msglen, "records differ");
        rc = -1;
    }
    lz_enc_free(&o);
    return rc;
}

#endif /* JF_LAZ_ROUNDTRIP_H */
