/*
 * laz_internal.h -- the LAZ (LASzip) decoder's pieces (not part of the
 * public API): the items of the LASzip VLR, and the chunk decoders of the
 * pointwise (version 2, laz_v2.c) and layered (version 3, laz_v3.c)
 * compressors.  io_laz.c reads the VLR and the chunk table and calls them.
 */
#ifndef JF_LAZ_INTERNAL_H
#define JF_LAZ_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

/* LASzip item types (laszip VLR, record 22204) */
enum {
    LZ_BYTE = 0,
    LZ_POINT10 = 6,
    LZ_GPSTIME11 = 7,
    LZ_RGB12 = 8,
    LZ_WAVEPACKET13 = 9,
    LZ_POINT14 = 10,
    LZ_RGB14 = 11,
    LZ_RGBNIR14 = 12,
    LZ_WAVEPACKET14 = 13,
    LZ_BYTE14 = 14
};

typedef struct {
    unsigned type, size, version;
} lz_item;

/* Decodes one chunk of `count` points from [p, end) into out (count
 * records of rec_len bytes, the items' sizes summing to rec_len).  0 on
 * success; otherwise -1 and msg (what is wrong, naming the point of the
 * chunk, 0-based) -- a stream that ends early, collapses or asks for an
 * impossible value; or out of memory. */
int jf__laz_v2_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen);
/* jf__laz_v2_chunk on a chunk whose end is not known (a chunk table to
 * rebuild): decodes from p on, end bounding the reads, and sets *used to
 * the bytes the chunk took (the decoder ends where the encoder did). */
int jf__laz_v2_chunk_len(const lz_item *items, unsigned nitems, unsigned rec_len,
                         const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                         size_t *used, char *msg, size_t msglen);
int jf__laz_v3_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen);

/* The streaming median of five (LASzip's StreamingMedian5): the predictor
 * of the x and y differences. */
typedef struct {
    int32_t v[5];
    int high;
} lz_med;

static inline void lz_med_init(lz_med *m)
{
    for (int k = 0; k < 5; k++)
        m->v[k] = 0;
    m->high = 1;
}

static inline void lz_med_add(lz_med *m, int32_t x)
{
    int32_t *v = m->v;
    if (m->high) {
        if (x < v[2]) {
            v[4] = v[3], v[3] = v[2];
            if (x < v[0])
                v[2] = v[1], v[1] = v[0], v[0] = x;
            else if (x < v[1])
                v[2] = v[1], v[1] = x;
            else
                v[2] = x;
        } else {
            if (x < v[3])
                v[4] = v[3], v[3] = x;
            else
                v[4] = x;
            m->high = 0;
        }
    } else {
        if (v[2] < x) {
            v[0] = v[1], v[1] = v[2];
            if (v[4] < x)
                v[2] = v[3], v[3] = v[4], v[4] = x;
            else if (v[3] < x)
                v[2] = v[3], v[3] = x;
            else
                v[2] = x;
        } else {
            if (v[1] < x)
                v[0] = v[1], v[1] = x;
            else
                v[0] = x;
            m->high = 1;
        }
    }
}

/* The context tables of POINT10 (LASzip v2) by number of returns n and
 * return number r, completed for files that number returns from 0. */
extern const uint8_t jf__lz_return_map[8][8];
extern const uint8_t jf__lz_return_level[8][8];

#endif /* JF_LAZ_INTERNAL_H */
