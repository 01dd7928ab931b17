/*
 * laz_enc.h -- the range encoder of LASzip (not part of the public API):
 * the mirror of laz_arith.h's decoder (Said, HPL-2004-76: a 32-bit base
 * and length, bytes out when the length falls below 2^24, a carry walked
 * back through the bytes already out), with the same adaptive models
 * (laz_arith.c) and LASzip's integer compressor (a corrector coded as its
 * bit length k, then its place among the 2^k values).  The encoder makes
 * exactly the decoder's model updates, so a stream decodes as written.
 */
#ifndef JF_LAZ_ENC_H
#define JF_LAZ_ENC_H

#include <stddef.h>
#include <stdint.h>

#include "laz_arith.h"
#include "laz_internal.h"

/* An encoder writing into its own growing buffer. */
typedef struct {
    uint8_t *buf;
    size_t len, cap;
    uint32_t base, length;
    int nomem;       /* an allocation failed: the stream is void */
    lz_arena *arena; /* where lazily made models live */
} lz_enc;

void lz_enc_init(lz_enc *e, lz_arena *a);
void lz_enc_free(lz_enc *e);
/* The last symbol's interval pinned by one or two more bytes, then two or
 * three zero bytes: the decoder, which reads four bytes ahead, ends
 * exactly at the stream's end (LASzip's flush). */
void lz_enc_done(lz_enc *e);
/* Appends raw bytes (a chunk's first point, counts, sizes). */
void lz_put_bytes(lz_enc *e, const void *p, size_t n);

void lz_encode_bit(lz_enc *e, lz_bit *m, uint32_t bit);
void lz_encode_sym(lz_enc *e, lz_sym *m, uint32_t sym);
/* sym with model m of nsym symbols, made on first use (as the decoder's
 * lz_decode_lazy makes it). */
void lz_encode_lazy(lz_enc *e, lz_sym *m, uint32_t nsym, uint32_t sym);
/* bits raw bits, 1..32 (more than 19 as 16 + the rest). */
void lz_write_bits(lz_enc *e, uint32_t bits, uint32_t sym);
void lz_write_int(lz_enc *e, uint32_t v);
/* real as pred + a corrector in context ctx (ic set up by lz_ic_init). */
void lz_ic_encode(lz_enc *e, lz_ic *ic, int32_t pred, int32_t real, uint32_t ctx);

/* *slot's model of nsym symbols, made on first use (the decoder's
 * lz_sym_lazy), then sym with it. */
void lz_encode_slot(lz_enc *e, lz_sym **slot, uint32_t nsym, uint32_t sym);

/* The item coders both chunk encoders use (laz_v2_enc.c): the time t
 * with g (u = 1: GPSTIME11, with the "unchanged" code; u = 0: POINT14's),
 * the mirror of laz_internal.h's lz_gps_decode; the colour v against the
 * last l, the mirror of lz_rgb_decode. */
void jf__lz_gps_encode(lz_gps *g, lz_enc *e, uint64_t t, unsigned u);
void jf__lz_rgb_encode(lz_enc *e, lz_sym *used, lz_sym *diff, const uint16_t *l,
                       const unsigned *v);

/* One chunk of `count` records (rec_len bytes each, the items' sizes
 * summing to rec_len) appended to out as LASzip writes it: pointwise
 * (laz_v2_enc.c) or layered (laz_v3_enc.c).  0, or -1 out of memory. */
int jf__laz_v2_encode(const lz_item *items, unsigned nitems, unsigned rec_len,
                      const uint8_t *recs, uint32_t count, lz_enc *out);
int jf__laz_v3_encode(const lz_item *items, unsigned nitems, unsigned rec_len,
                      const uint8_t *recs, uint32_t count, lz_enc *out);

#endif /* JF_LAZ_ENC_H */
