/*
 * laz_arith.c -- set-up and periodic updates of LASzip's adaptive models
 * and integer compressor (laz_arith.h).
 *
 * design: a model counts what it decodes and rebuilds its probabilities
 * every `cycle` symbols, the cycle growing by 5/4 up to a cap, the counts
 * halved past a maximum (Said, HPL-2004-76, section 4.3).  Encoder and
 * decoder must make exactly the same updates, so every constant here is
 * LASzip's.
 */
#include <stdlib.h>
#include <string.h>

#include "laz_arith.h"

struct lz_block {
    lz_block *next;
    size_t used, cap;
    max_align_t data[];
};

void *lz_alloc(lz_arena *a, size_t bytes)
{
    bytes = (bytes + 15) & ~(size_t)15;
    lz_block *b = a->head;
    if (a->failed)
        return NULL;
    if (!b || b->cap - b->used < bytes) {
        size_t cap = bytes > (1u << 15) ? bytes : (1u << 15);
        b = malloc(sizeof *b + cap);
        if (!b) {
            a->failed = 1;
            return NULL;
        }
        b->next = a->head, b->used = 0, b->cap = cap;
        a->head = b;
    }
    void *p = (char *)b->data + b->used;
    b->used += bytes;
    return p;
}

void lz_arena_free(lz_arena *a)
{
    while (a->head) {
        lz_block *n = a->head->next;
        free(a->head);
        a->head = n;
    }
    a->failed = 0;
}

void lz_bit_init(lz_bit *m)
{
    m->count0 = 1; /* equiprobable, frequent updates at first */
    m->count = 2;
    m->prob0 = 1u << (LZ_BM_SHIFT - 1);
    m->cycle = m->until = 4;
}

void lz_bit_update(lz_bit *m)
{
    if ((m->count += m->cycle) > LZ_BM_MAX) {
        m->count = (m->count + 1) >> 1;
        m->count0 = (m->count0 + 1) >> 1;
        if (m->count0 == m->count)
            ++m->count;
    }
    uint32_t scale = 0x80000000u / m->count;
    m->prob0 = (m->count0 * scale) >> (31 - LZ_BM_SHIFT);
    m->cycle = (5 * m->cycle) >> 2;
    if (m->cycle > 64)
        m->cycle = 64;
    m->until = m->cycle;
}

void lz_sym_update(lz_sym *m)
{
    if ((m->total += m->cycle) > LZ_DM_MAX) {
        m->total = 0;
        for (uint32_t n = 0; n < m->nsym; n++)
            m->total += (m->count[n] = (m->count[n] + 1) >> 1);
    }
    uint32_t sum = 0, s = 0, scale = 0x80000000u / m->total;
    if (!m->table) {
        for (uint32_t k = 0; k < m->nsym; k++) {
            m->dist[k] = (scale * sum) >> (31 - LZ_DM_SHIFT);
            sum += m->count[k];
        }
    } else {
        for (uint32_t k = 0; k < m->nsym; k++) {
            m->dist[k] = (scale * sum) >> (31 - LZ_DM_SHIFT);
            sum += m->count[k];
            uint32_t w = m->dist[k] >> m->tshift;
            while (s < w)
                m->table[++s] = k - 1;
        }
        m->table[0] = 0;
        while (s <= m->tsize)
            m->table[++s] = m->nsym - 1;
    }
    m->cycle = (5 * m->cycle) >> 2;
    uint32_t max_cycle = (m->nsym + 6) << 3;
    if (m->cycle > max_cycle)
        m->cycle = max_cycle;
    m->until = m->cycle;
}

int lz_sym_init(lz_sym *m, lz_arena *a, uint32_t nsym)
{
    memset(m, 0, sizeof *m);
    m->nsym = nsym;
    m->last = nsym - 1;
    if (nsym > 16) { /* a decoder table of about nsym / 4 entries */
        uint32_t tb = 3;
        while (nsym > (1u << (tb + 2)))
            tb++;
        m->tsize = 1u << tb;
        m->tshift = LZ_DM_SHIFT - tb;
    }
    uint32_t *mem = lz_alloc(a, sizeof(uint32_t) * (2 * nsym + (m->tsize ? m->tsize + 2 : 0)));
    if (!mem)
        return 0;
    m->dist = mem;
    m->count = mem + nsym;
    m->table = m->tsize ? mem + 2 * nsym : NULL;
    for (uint32_t k = 0; k < nsym; k++)
        m->count[k] = 1;
    m->cycle = nsym;
    lz_sym_update(m);
    m->until = m->cycle = (nsym + 6) >> 1;
    return 1;
}

lz_sym *lz_sym_lazy(lz_sym **slot, lz_arena *a, uint32_t nsym)
{
    if (*slot)
        return *slot;
    lz_sym *m = lz_alloc(a, sizeof *m);
    if (!m || !lz_sym_init(m, a, nsym))
        return NULL;
    return *slot = m;
}

int lz_ic_init(lz_ic *ic, lz_arena *a, uint32_t bits, uint32_t contexts, uint32_t bits_high,
               uint32_t range)
{
    memset(ic, 0, sizeof *ic);
    ic->bits = bits, ic->contexts = contexts, ic->bits_high = bits_high;
    if (range) { /* the corrector's bits and range from an explicit range */
        ic->corr_range = range;
        while (range) {
            range >>= 1;
            ic->corr_bits++;
        }
        if (ic->corr_range == 1u << (ic->corr_bits - 1))
            ic->corr_bits--;
        ic->corr_min = -(int32_t)(ic->corr_range / 2);
    } else if (bits && bits < 32) {
        ic->corr_bits = bits;
        ic->corr_range = 1u << bits;
        ic->corr_min = -(int32_t)(ic->corr_range / 2);
    } else {
        ic->corr_bits = 32;
        ic->corr_range = 0;
        ic->corr_min = INT32_MIN;
    }
    ic->arena = a;
    ic->mbits = lz_alloc(a, sizeof(lz_sym) * contexts);
    ic->corr = lz_alloc(a, sizeof(lz_sym) * ic->corr_bits);
    if (!ic->mbits || !ic->corr)
        return 0;
    /* nsym 0: not made yet (a fresh model is what LASzip's eager set-up
     * would hold at its first use) */
    memset(ic->mbits, 0, sizeof(lz_sym) * contexts);
    memset(ic->corr, 0, sizeof(lz_sym) * ic->corr_bits);
    lz_bit_init(&ic->corr0);
    return 1;
}

lz_sym *lz_ic_model(lz_dec *d, lz_ic *ic, lz_sym *m, uint32_t nsym)
{
    if (lz_sym_init(m, ic->arena, nsym))
        return m;
    m->nsym = 0;
    d->bad = 2;
    return NULL;
}

int lz_sym_make(lz_dec *d, lz_sym *m, uint32_t nsym)
{
    if (d->arena && lz_sym_init(m, d->arena, nsym))
        return 1;
    memset(m, 0, sizeof *m);
    d->bad = 2;
    return 0;
}
