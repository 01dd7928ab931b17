/*
 * laz_arith.h -- the range decoder of LASzip (not part of the public API):
 * Said's fast arithmetic coder ("Introduction to Arithmetic Coding Theory
 * and Practice", HPL-2004-76: 32-bit interval, adaptive models updated
 * periodically, table-driven symbol search) with LASzip's adaptive bit and
 * symbol models and its integer compressor (a corrector coded as its bit
 * length k, then k bits).  The hot paths are inline here; model set-up and
 * updates are in laz_arith.c.
 *
 * Hostile streams: the decoder never reads outside [p, end) (bytes past the
 * end read as 0 and are counted in `over`), never indexes a table out of
 * bounds and never loops on a zero interval (`bad` is set): the caller
 * turns `over` and `bad` into an error naming the chunk.
 */
#ifndef JF_LAZ_ARITH_H
#define JF_LAZ_ARITH_H

#include <stddef.h>
#include <stdint.h>

#define LZ_MIN_LENGTH 0x01000000u /* renormalise below 2^24 */
#define LZ_MAX_LENGTH 0xFFFFFFFFu
#define LZ_BM_SHIFT 13            /* bit models: probability of 0 in 13 bits */
#define LZ_BM_MAX (1u << 13)
#define LZ_DM_SHIFT 15            /* symbol models: distribution in 15 bits */
#define LZ_DM_MAX (1u << 15)

/* the decoder's steps are a few instructions each: inlined into the item
 * decoders (gcc would otherwise call lz_decode_sym) */
#if defined(__GNUC__)
#define LZ_INLINE static inline __attribute__((always_inline))
#else
#define LZ_INLINE static inline
#endif

/* A bump allocator for the models of one chunk (freed at once). */
typedef struct lz_block lz_block;
typedef struct {
    lz_block *head;
    int failed; /* an allocation failed: every later model is NULL */
} lz_arena;
void *lz_alloc(lz_arena *a, size_t bytes);
void lz_arena_free(lz_arena *a);

typedef struct {
    const uint8_t *p, *end;
    uint32_t value, length;
    size_t over; /* bytes asked for past the end */
    int bad;     /* 1: an interval collapsed (the stream is not LASzip's);
                    2: out of memory for a model */
    lz_arena *arena; /* where lz_decode_lazy makes its models */
} lz_dec;

typedef struct {
    uint32_t until, cycle, prob0, count0, count;
} lz_bit;

typedef struct {
    uint32_t *dist, *count, *table;
    uint32_t nsym, last, total, cycle, until, tsize, tshift;
} lz_sym;


/* The integer compressor's decoder (LASzip IntegerCompressor). */
typedef struct {
    uint32_t k, bits, contexts, bits_high, corr_bits, corr_range;
    int32_t corr_min;
    lz_sym *mbits;   /* contexts models of corr_bits + 1 symbols */
    lz_bit corr0;    /* k = 0: the corrector is 0 or 1 */
    lz_sym *corr;    /* k = 1..corr_bits: corr[k - 1] */
    lz_arena *arena; /* the models are made on first use (most k never come) */
} lz_ic;

void lz_bit_init(lz_bit *m);
void lz_bit_update(lz_bit *m);
/* 0 on allocation failure; nsym in 2..2048. */
int lz_sym_init(lz_sym *m, lz_arena *a, uint32_t nsym);
void lz_sym_update(lz_sym *m);
/* A model made on first use (NULL on allocation failure). */
lz_sym *lz_sym_lazy(lz_sym **slot, lz_arena *a, uint32_t nsym);
/* bits 1..32 (range 0), contexts >= 1; 0 on allocation failure. */
int lz_ic_init(lz_ic *ic, lz_arena *a, uint32_t bits, uint32_t contexts, uint32_t bits_high,
               uint32_t range);

static inline uint32_t lz_byte(lz_dec *d)
{
    if (d->p < d->end)
        return *d->p++;
    d->over++;
    return 0;
}

/* Starts the decoder on [p, end): the first four bytes are the value. */
static inline void lz_dec_init(lz_dec *d, const uint8_t *p, const uint8_t *end)
{
    d->p = p, d->end = end, d->over = 0, d->bad = 0, d->arena = NULL;
    d->length = LZ_MAX_LENGTH;
    d->value = lz_byte(d) << 24;
    d->value |= lz_byte(d) << 16;
    d->value |= lz_byte(d) << 8;
    d->value |= lz_byte(d);
}

/* Below 2^24 the interval takes whole bytes until it is 2^24 or more
 * again (Said, section 2.3): a length of b bits (1..24) takes
 * floor((32 - b) / 8) = clz / 8 bytes, 1 to 3, read in one go when four
 * bytes are left (byte by byte, zeros past the end, at the stream's end). */
static inline void lz_renorm(lz_dec *d)
{
    if (!d->length) { /* only a corrupt stream gets here: never loop forever */
        d->bad = 1;
        d->length = LZ_MAX_LENGTH;
        return;
    }
#if defined(__GNUC__)
    if (d->end - d->p >= 4) {
        unsigned sh = (unsigned)__builtin_clz(d->length) & ~7u; /* 8, 16 or 24 bits */
        uint32_t w = (uint32_t)d->p[0] << 24 | (uint32_t)d->p[1] << 16 |
                     (uint32_t)d->p[2] << 8 | d->p[3];
        d->value = d->value << sh | w >> (32 - sh);
        d->length <<= sh;
        d->p += sh >> 3;
        return;
    }
#endif
    do
        d->value = d->value << 8 | lz_byte(d);
    while ((d->length <<= 8) < LZ_MIN_LENGTH);
}

LZ_INLINE uint32_t lz_decode_bit(lz_dec *d, lz_bit *m)
{
    uint32_t x = m->prob0 * (d->length >> LZ_BM_SHIFT);
    uint32_t sym = d->value >= x;
    if (!sym) {
        d->length = x;
        m->count0++;
    } else {
        d->value -= x;
        d->length -= x;
    }
    if (d->length < LZ_MIN_LENGTH)
        lz_renorm(d);
    if (--m->until == 0)
        lz_bit_update(m);
    return sym;
}

LZ_INLINE uint32_t lz_decode_sym(lz_dec *d, lz_sym *m)
{
    uint32_t n, sym, x, y = d->length;
    if (m->table) { /* table look-up, then bisection (Said, section 4.4) */
        uint32_t dv = d->value / (d->length >>= LZ_DM_SHIFT);
        uint32_t t = dv >> m->tshift;
        if (t > m->tsize)
            t = m->tsize; /* value >= length: a corrupt stream */
        sym = m->table[t];
        n = m->table[t + 1] + 1;
        while (n > sym + 1) { /* without branches: the halves are a coin toss */
            uint32_t k = (sym + n) >> 1;
            int above = m->dist[k] > dv;
            n = above ? k : n;
            sym = above ? sym : k;
        }
        x = m->dist[sym] * d->length;
        if (sym != m->last)
            y = m->dist[sym + 1] * d->length;
    } else { /* bisection by multiplications only */
        x = sym = 0;
        d->length >>= LZ_DM_SHIFT;
        uint32_t k = (n = m->nsym) >> 1;
        do {
            uint32_t z = d->length * m->dist[k];
            int above = z > d->value;
            n = above ? k : n;
            y = above ? z : y;
            sym = above ? sym : k;
            x = above ? x : z;
        } while ((k = (sym + n) >> 1) != sym);
    }
    d->value -= x;
    d->length = y - x;
    if (d->length < LZ_MIN_LENGTH)
        lz_renorm(d);
    m->count[sym]++;
    if (--m->until == 0)
        lz_sym_update(m);
    return sym;
}

/* A symbol from model m of nsym symbols, made on first use (zeroed:
 * not made yet; a fresh model is what an eager set-up would hold at its
 * first use, so the output is the same and unused models cost nothing);
 * 0 and d->bad = 2 when it cannot be made. */
int lz_sym_make(lz_dec *d, lz_sym *m, uint32_t nsym);
LZ_INLINE uint32_t lz_decode_lazy(lz_dec *d, lz_sym *m, uint32_t nsym)
{
    if (!m->nsym && !lz_sym_make(d, m, nsym))
        return 0;
    return lz_decode_sym(d, m);
}

/* bits raw bits, 1..32 (more than 19 as 16 + the rest). */
static inline uint32_t lz_read_bits(lz_dec *d, uint32_t bits)
{
    if (bits > 19) {
        uint32_t lo = lz_read_bits(d, 16);
        return lz_read_bits(d, bits - 16) << 16 | lo;
    }
    uint32_t sym = d->value / (d->length >>= bits);
    d->value -= d->length * sym;
    if (d->length < LZ_MIN_LENGTH)
        lz_renorm(d);
    return sym;
}

static inline uint32_t lz_read_int(lz_dec *d)
{
    uint32_t lo = lz_read_bits(d, 16);
    return lz_read_bits(d, 16) << 16 | lo;
}

/* A model of the integer compressor, made on first use; NULL (and
 * d->bad = 2) on allocation failure. */
lz_sym *lz_ic_model(lz_dec *d, lz_ic *ic, lz_sym *m, uint32_t nsym);

/* The corrector c: its interval k (symbol), then its place in it. */
LZ_INLINE int32_t lz_ic_corrector(lz_dec *d, lz_ic *ic, lz_sym *mbits)
{
    if (!mbits->nsym && !lz_ic_model(d, ic, mbits, ic->corr_bits + 1))
        return 0;
    uint32_t k = ic->k = lz_decode_sym(d, mbits);
    if (!k)
        return (int32_t)lz_decode_bit(d, &ic->corr0);
    if (k >= 32)
        return ic->corr_min;
    uint32_t c;
    lz_sym *m = &ic->corr[k - 1];
    if (!m->nsym && !lz_ic_model(d, ic, m, k <= ic->bits_high ? 1u << k : 1u << ic->bits_high))
        return 0;
    c = lz_decode_sym(d, m);
    if (k > ic->bits_high) { /* high bits by model, the low k - bits_high raw */
        uint32_t k1 = k - ic->bits_high;
        c = c << k1 | lz_read_bits(d, k1);
    }
    /* [0, 2^(k-1)) -> [-(2^k - 1), -2^(k-1)]; [2^(k-1), 2^k) -> [2^(k-1) + 1, 2^k] */
    if (c >= 1u << (k - 1))
        return (int32_t)(c + 1);
    return (int32_t)(c - ((1u << k) - 1));
}

/* pred + corrector, wrapped into the compressor's range. */
LZ_INLINE int32_t lz_ic_decode(lz_dec *d, lz_ic *ic, int32_t pred, uint32_t ctx)
{
    uint32_t real = (uint32_t)pred + (uint32_t)lz_ic_corrector(d, ic, &ic->mbits[ctx]);
    if (ic->corr_range) {
        if ((int32_t)real < 0)
            real += ic->corr_range;
        else if (real >= ic->corr_range)
            real -= ic->corr_range;
    }
    return (int32_t)real;
}

#endif /* JF_LAZ_ARITH_H */
