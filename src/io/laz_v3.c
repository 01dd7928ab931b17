/*
 * laz_v3.c -- LASzip's layered compressors, item version 3 (LAS 1.4 point
 * formats 6-8): not decoded yet.
 */
#include <stdio.h>

#include "laz_internal.h"

int jf__laz_v3_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen)
{
    (void)items, (void)nitems, (void)rec_len, (void)p, (void)end, (void)count, (void)out;
    snprintf(msg, msglen, "the layered (LAS 1.4) compressors are not decoded yet");
    return -1;
}
