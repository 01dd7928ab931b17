/*
 * laz_enc.c -- LASzip's range encoder and integer compressor (laz_enc.h).
 *
 * design (Said, HPL-2004-76, section 2.3; LASzip's ArithmeticEncoder and
 * IntegerCompressor): each symbol narrows [base, base + length) to its
 * share of the model's distribution; when the length falls below 2^24 the
 * top byte of base goes out; an addition that wraps base carries into the
 * bytes already out.  Every step is the decoder's (laz_arith.h) mirrored.
 */
#include <stdlib.h>
#include <string.h>

#include "laz_enc.h"

void lz_enc_init(lz_enc *e, lz_arena *a)
{
    memset(e, 0, sizeof *e);
    e->length = LZ_MAX_LENGTH;
    e->arena = a;
}

void lz_enc_free(lz_enc *e)
{
    free(e->buf);
    e->buf = NULL;
    e->len = e->cap = 0;
}

static int grow(lz_enc *e, size_t more)
{
    if (e->cap - e->len >= more)
        return 1;
    size_t cap = e->cap ? e->cap : 4096;
    while (cap - e->len < more)
        cap *= 2;
    uint8_t *b = realloc(e->buf, cap);
    if (!b) {
        e->nomem = 1;
        return 0;
    }
    e->buf = b, e->cap = cap;
    return 1;
}

void lz_put_bytes(lz_enc *e, const void *p, size_t n)
{
    if (n && grow(e, n)) {
        memcpy(e->buf + e->len, p, n);
        e->len += n;
    }
}

static inline void put_byte(lz_enc *e, uint8_t b)
{
    if (e->len < e->cap || grow(e, 1))
        e->buf[e->len++] = b;
}

/* base wrapped: add one to the bytes out (0xFF bytes roll over to 0).  A
 * stream that starts at base 0 never carries past its first byte. */
static void carry(lz_enc *e)
{
    size_t i = e->len;
    while (i && e->buf[i - 1] == 0xFF)
        e->buf[--i] = 0;
    if (i)
        e->buf[i - 1]++;
}

static inline void renorm(lz_enc *e)
{
    do {
        put_byte(e, (uint8_t)(e->base >> 24));
        e->base <<= 8;
    } while ((e->length <<= 8) < LZ_MIN_LENGTH);
}

void lz_enc_done(lz_enc *e)
{
    uint32_t b0 = e->base;
    int another = 1;
    if (e->length > 2 * LZ_MIN_LENGTH) { /* one byte pins the interval */
        e->base += LZ_MIN_LENGTH;
        e->length = LZ_MIN_LENGTH >> 1;
    } else { /* two bytes */
        e->base += LZ_MIN_LENGTH >> 1;
        e->length = LZ_MIN_LENGTH >> 9;
        another = 0;
    }
    if (b0 > e->base)
        carry(e);
    renorm(e);
    put_byte(e, 0);
    put_byte(e, 0);
    if (another)
        put_byte(e, 0);
}

void lz_encode_bit(lz_enc *e, lz_bit *m, uint32_t bit)
{
    uint32_t x = m->prob0 * (e->length >> LZ_BM_SHIFT);
    if (!bit) {
        e->length = x;
        m->count0++;
    } else {
        uint32_t b0 = e->base;
        e->base += x;
        e->length -= x;
        if (b0 > e->base)
            carry(e);
    }
    if (e->length < LZ_MIN_LENGTH)
        renorm(e);
    if (--m->until == 0)
        lz_bit_update(m);
}

void lz_encode_sym(lz_enc *e, lz_sym *m, uint32_t sym)
{
    uint32_t x, b0 = e->base;
    if (sym == m->last) { /* the top of the interval: no product needed */
        x = m->dist[sym] * (e->length >> LZ_DM_SHIFT);
        e->base += x;
        e->length -= x;
    } else {
        x = m->dist[sym] * (e->length >>= LZ_DM_SHIFT);
        e->base += x;
        e->length = m->dist[sym + 1] * e->length - x;
    }
    if (b0 > e->base)
        carry(e);
    if (e->length < LZ_MIN_LENGTH)
        renorm(e);
    m->count[sym]++;
    if (--m->until == 0)
        lz_sym_update(m);
}

void lz_encode_lazy(lz_enc *e, lz_sym *m, uint32_t nsym, uint32_t sym)
{
    if (!m->nsym) {
        if (!e->arena || !lz_sym_init(m, e->arena, nsym)) {
            memset(m, 0, sizeof *m);
            e->nomem = 1;
            return;
        }
        m->table = NULL; /* the encoder needs no decoding table */
    }
    lz_encode_sym(e, m, sym);
}

void lz_encode_slot(lz_enc *e, lz_sym **slot, uint32_t nsym, uint32_t sym)
{
    if (!*slot) {
        if (!e->arena || !(*slot = lz_alloc(e->arena, sizeof **slot))) {
            e->nomem = 1;
            return;
        }
        memset(*slot, 0, sizeof **slot);
    }
    lz_encode_lazy(e, *slot, nsym, sym);
}

void lz_write_bits(lz_enc *e, uint32_t bits, uint32_t sym)
{
    if (bits > 19) {
        lz_write_bits(e, 16, sym & 0xFFFF);
        sym >>= 16;
        bits -= 16;
    }
    uint32_t b0 = e->base;
    e->base += sym * (e->length >>= bits);
    if (b0 > e->base)
        carry(e);
    if (e->length < LZ_MIN_LENGTH)
        renorm(e);
}

void lz_write_int(lz_enc *e, uint32_t v)
{
    lz_write_bits(e, 16, v & 0xFFFF);
    lz_write_bits(e, 16, v >> 16);
}

/* The corrector c: k, the smallest with c in [-(2^k - 1), 2^k], then its
 * place among those 2^k values (k = 0: c is 0 or 1, one bit). */
static void corrector(lz_enc *e, lz_ic *ic, lz_sym *mbits, int32_t c)
{
    uint32_t c1 = c <= 0 ? 0u - (uint32_t)c : (uint32_t)c - 1, k = 0;
    while (c1)
        c1 >>= 1, k++;
    ic->k = k;
    lz_encode_lazy(e, mbits, ic->corr_bits + 1, k);
    if (!k) {
        lz_encode_bit(e, &ic->corr0, (uint32_t)c);
        return;
    }
    if (k >= 32) /* c is corr_min: nothing more */
        return;
    /* [-(2^k - 1), -2^(k-1)] -> [0, 2^(k-1)); [2^(k-1) + 1, 2^k] -> [2^(k-1), 2^k) */
    uint32_t u = c < 0 ? (uint32_t)c + ((1u << k) - 1) : (uint32_t)c - 1;
    lz_sym *m = &ic->corr[k - 1];
    if (k <= ic->bits_high) {
        lz_encode_lazy(e, m, 1u << k, u);
    } else { /* the high bits_high bits by model, the rest raw */
        uint32_t k1 = k - ic->bits_high;
        lz_encode_lazy(e, m, 1u << ic->bits_high, u >> k1);
        lz_write_bits(e, k1, u & ((1u << k1) - 1));
    }
}

void lz_ic_encode(lz_enc *e, lz_ic *ic, int32_t pred, int32_t real, uint32_t ctx)
{
    int32_t c = (int32_t)((uint32_t)real - (uint32_t)pred);
    if (ic->corr_range) { /* into [corr_min, corr_min + range) */
        int64_t lo = ic->corr_min, hi = lo + (int64_t)ic->corr_range - 1;
        if (c < lo)
            c = (int32_t)((int64_t)c + ic->corr_range);
        else if (c > hi)
            c = (int32_t)((int64_t)c - ic->corr_range);
    }
    corrector(e, ic, &ic->mbits[ctx], c);
}
