/* mesh.c -- jf_mesh: vertex adjacency of a polygon mesh and its rings.
 *
 * design (build): every valid polygon adds its boundary edges to both
 * endpoints' lists (counting sort into CSR); each list is sorted, and a
 * neighbour's multiplicity is the number of faces sharing that edge:
 * 1 = boundary, 2 = manifold, > 2 = non-manifold.  Duplicates are then
 * removed in place.  Polygons with fewer than 3 vertices or a repeated
 * vertex are skipped and counted; an index out of range is an error.
 *
 * design (rings, §5.1 mesh case): breadth first from v; ring j is the set
 * of vertices at edge distance j.  Each ring is gathered in a bounded
 * max-heap keyed by (squared distance to v, index) in the output buffer:
 * if the ring fits it is kept whole, otherwise the heap keeps its nearest
 * vertices and the search stops.  A small open-addressing "seen" set on the
 * stack makes membership O(1); if it fills up, membership falls back to a
 * scan of the output (same result: a vertex refused by a full heap is
 * refused again, since the heap's worst only improves).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

struct jf_mesh {
    size_t n;
    size_t *off;       /* n+1 offsets into adj                           */
    uint32_t *adj;     /* sorted, distinct neighbours of each vertex      */
    uint8_t *flags;    /* JF_MESH_* per vertex                            */
    jf_mesh_stats stats;
};

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static void sort_u32(uint32_t *a, size_t n)
{
    if (n > 32) {
        qsort(a, n, sizeof *a, cmp_u32);
        return;
    }
    for (size_t i = 1; i < n; i++) {
        uint32_t t = a[i];
        size_t j = i;
        for (; j > 0 && a[j - 1] > t; j--) a[j] = a[j - 1];
        a[j] = t;
    }
}

/* 1 if face f is usable; 0 if degenerate; -1 (err filled) if invalid. */
static int check_face(size_t n, const size_t *off, const uint32_t *fi,
                      size_t f, uint32_t *stamp, jf_error *err)
{
    size_t b = off[f], e = off[f + 1];
    if (e < b) {
        if (err)
            snprintf(err->msg, sizeof err->msg,
                     "face %zu: offsets decrease (%zu then %zu)", f, b, e);
        return -1;
    }
    for (size_t i = b; i < e; i++)
        if (fi[i] >= n) {
            if (err)
                snprintf(err->msg, sizeof err->msg,
                         "face %zu: vertex index %lu out of range "
                         "(%zu vertices)", f, (unsigned long)fi[i], n);
            return -1;
        }
    if (e - b < 3) return 0;
    /* stamp[v] = f+1 marks v as seen in this face: repeated vertex */
    int ok = 1;
    for (size_t i = b; i < e; i++) {
        if (stamp[fi[i]] == (uint32_t)(f + 1)) ok = 0;
        stamp[fi[i]] = (uint32_t)(f + 1);
    }
    return ok;
}

jf_status jf_mesh_build(size_t n, size_t nfaces, const size_t *face_off,
                        const uint32_t *face_idx, jf_mesh **out,
                        jf_error *err)
{
    if (err) err->msg[0] = '\0';
    if (!out) return JF_ERR_INVALID;
    *out = NULL;
    if (nfaces && (!face_off || (!face_idx && face_off[nfaces])))
        return JF_ERR_INVALID;
    if (n >= UINT32_MAX || nfaces >= UINT32_MAX) return JF_ERR_TOO_LARGE;
    jf_mesh *m = calloc(1, sizeof *m);
    if (!m) return JF_ERR_NOMEM;
    m->n = n;
    m->off = calloc(n + 1, sizeof *m->off);
    m->flags = calloc(n ? n : 1, 1);
    uint32_t *stamp = calloc(n ? n : 1, sizeof *stamp);
    uint8_t *good = malloc(nfaces ? nfaces : 1);
    uint32_t *raw = NULL;
    jf_status st = JF_ERR_NOMEM;
    if (!m->off || !m->flags || !stamp || !good) goto fail;

    /* pass 1: validate faces, count edge ends per vertex */
    size_t total = 0;
    for (size_t f = 0; f < nfaces; f++) {
        int r = check_face(n, face_off, face_idx, f, stamp, err);
        if (r < 0) {
            st = JF_ERR_FORMAT;
            goto fail;
        }
        good[f] = (uint8_t)r;
        if (!r) {
            m->stats.degenerate_faces++;
            continue;
        }
        for (size_t i = face_off[f]; i < face_off[f + 1]; i++)
            m->off[face_idx[i] + 1] += 2; /* each vertex is on two edges */
        total += 2 * (face_off[f + 1] - face_off[f]);
    }
    for (size_t v = 0; v < n; v++) m->off[v + 1] += m->off[v];
    raw = malloc((total ? total : 1) * sizeof *raw);
    if (!raw) goto fail;

    /* pass 2: fill; stamp reused as the per-vertex fill cursor */
    for (size_t v = 0; v < n; v++) stamp[v] = 0;
    for (size_t f = 0; f < nfaces; f++) {
        if (!good[f]) continue;
        size_t b = face_off[f], e = face_off[f + 1];
        for (size_t i = b; i < e; i++) {
            uint32_t u = face_idx[i], w = face_idx[i + 1 < e ? i + 1 : b];
            raw[m->off[u] + stamp[u]++] = w;
            raw[m->off[w] + stamp[w]++] = u;
        }
    }

    /* pass 3: sort each list, classify edges by multiplicity, dedupe */
    size_t wr = 0;
    for (size_t v = 0; v < n; v++) {
        size_t b = m->off[v], e = m->off[v + 1];
        m->off[v] = wr;
        sort_u32(raw + b, e - b);
        for (size_t i = b; i < e;) {
            size_t j = i;
            while (j < e && raw[j] == raw[i]) j++;
            size_t mult = j - i;
            if (mult > 2) {
                m->flags[v] |= JF_MESH_NONMANIFOLD;
                if (v < raw[i]) m->stats.nonmanifold_edges++;
            } else if (mult == 1) {
                m->flags[v] |= JF_MESH_BOUNDARY;
                if (v < raw[i]) m->stats.boundary_edges++;
            }
            raw[wr++] = raw[i];
            i = j;
        }
        if (m->off[v] == wr) {
            m->flags[v] |= JF_MESH_ISOLATED;
            m->stats.isolated_vertices++;
        }
        if (m->flags[v] & JF_MESH_NONMANIFOLD)
            m->stats.nonmanifold_vertices++;
    }
    m->off[n] = wr;
    /* shrink to the deduplicated size; if that fails keep the larger block */
    uint32_t *shrunk = wr ? realloc(raw, wr * sizeof *raw) : NULL;
    m->adj = shrunk ? shrunk : raw;
    free(stamp);
    free(good);
    *out = m;
    return JF_OK;
fail:
    free(raw);
    free(stamp);
    free(good);
    jf_mesh_free(m);
    if (st == JF_ERR_NOMEM && err)
        snprintf(err->msg, sizeof err->msg, "mesh adjacency: out of memory");
    return st;
}

void jf_mesh_free(jf_mesh *m)
{
    if (!m) return;
    free(m->off);
    free(m->adj);
    free(m->flags);
    free(m);
}

size_t jf_mesh_vertex_count(const jf_mesh *m) { return m ? m->n : 0; }

const uint8_t *jf_mesh_vertex_flags(const jf_mesh *m)
{
    return m ? m->flags : NULL;
}

void jf_mesh_get_stats(const jf_mesh *m, jf_mesh_stats *s)
{
    if (!s) return;
    if (!m) memset(s, 0, sizeof *s);
    else *s = m->stats;
}

size_t jf_mesh_neighbors(const jf_mesh *m, uint32_t v, const uint32_t **nbr)
{
    if (nbr) *nbr = NULL;
    if (!m || v >= m->n) return 0;
    if (nbr) *nbr = m->adj + m->off[v];
    return m->off[v + 1] - m->off[v];
}

/* ---------------------------------------------------------------- rings */

#define RING_SEEN_MAX 4096   /* slots of the on-stack seen set          */

typedef struct {
    const double *xyz;
    double c[3];          /* the centre vertex                           */
    uint32_t *heap;       /* idx + ring start                            */
    size_t cnt, cap;
} ring_heap;

static double dist2(const ring_heap *h, uint32_t w)
{
    const double *p = h->xyz + 3 * (size_t)w;
    double dx = h->c[0] - p[0], dy = h->c[1] - p[1], dz = h->c[2] - p[2];
    return dx * dx + dy * dy + dz * dz;
}

/* (d2(a), a) < (d2(b), b) */
static int ring_less(const ring_heap *h, uint32_t a, uint32_t b)
{
    double da = dist2(h, a), db = dist2(h, b);
    return da < db || (da == db && a < b);
}

static void ring_sift_down(const ring_heap *h, size_t cnt, size_t k)
{
    uint32_t *a = h->heap, x = a[k];
    for (;;) {
        size_t c = 2 * k + 1;
        if (c >= cnt) break;
        if (c + 1 < cnt && ring_less(h, a[c], a[c + 1])) c++;
        if (!ring_less(h, x, a[c])) break;
        a[k] = a[c];
        k = c;
    }
    a[k] = x;
}

/* Offers w to the ring heap; returns 1 if the heap was full (ring cut). */
static int ring_offer(ring_heap *h, uint32_t w)
{
    uint32_t *a = h->heap;
    if (h->cnt < h->cap) {
        size_t k = h->cnt++;
        while (k > 0 && ring_less(h, a[(k - 1) / 2], w)) {
            a[k] = a[(k - 1) / 2];
            k = (k - 1) / 2;
        }
        a[k] = w;
        return 0;
    }
    if (h->cap && ring_less(h, w, a[0])) {
        a[0] = w;
        ring_sift_down(h, h->cnt, 0);
    }
    return 1;
}

typedef struct {
    uint32_t slot[RING_SEEN_MAX];
    size_t size, used; /* size: power of two <= RING_SEEN_MAX; 0 = off */
} seen_set;

/* 1 if w was already seen, else marks it; -1 when the table is full. */
static int seen_test_set(seen_set *s, uint32_t w)
{
    if (s->used * 2 >= s->size) return -1;
    size_t mask = s->size - 1, k = (size_t)(w * 2654435761u) & mask;
    while (s->slot[k]) {
        if (s->slot[k] == w + 1) return 1;
        k = (k + 1) & mask;
    }
    s->slot[k] = w + 1;
    s->used++;
    return 0;
}

static int finite_at(const double *xyz, uint32_t w)
{
    const double *p = xyz + 3 * (size_t)w;
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

/* want: exact mode stops at `want` points (last ring cut to its nearest);
 * full mode adds whole rings until at least `want` points (cap cuts). */
static jf_status rings_impl(const jf_mesh *m, const double *xyz, uint32_t v,
                            size_t want, int full, uint32_t *idx, size_t cap,
                            size_t *found)
{
    if (found) *found = 0;
    if (!m || !xyz || !found || !want || v >= m->n) return JF_ERR_INVALID;
    if (!cap) return JF_OK;
    if (!idx || !finite_at(xyz, v)) return JF_ERR_INVALID;
    size_t limit = full ? cap : (want < cap ? want : cap);
    seen_set seen;
    seen.size = 64;
    size_t expect = full && want < cap / 4 ? 4 * want : limit;
    while (seen.size < RING_SEEN_MAX && seen.size < 4 * expect)
        seen.size *= 2;
    memset(seen.slot, 0, seen.size * sizeof seen.slot[0]);
    seen.used = 0;
    int use_hash = 1;
    seen_test_set(&seen, v);
    idx[0] = v;
    size_t cnt = 1, ring_b = 0, ring_e = 1;
    ring_heap h = {xyz, {xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]},
                   NULL, 0, 0};
    while (cnt < limit && (!full || cnt < want)) {
        h.heap = idx + cnt;
        h.cnt = 0;
        h.cap = limit - cnt;
        int cut = 0;
        for (size_t r = ring_b; r < ring_e; r++) {
            uint32_t u = idx[r];
            for (size_t a = m->off[u]; a < m->off[u + 1]; a++) {
                uint32_t w = m->adj[a];
                int was = -1;
                if (use_hash) {
                    was = seen_test_set(&seen, w);
                    if (was < 0) use_hash = 0;
                }
                if (was < 0) { /* scan: rings so far + this ring's heap */
                    was = 0;
                    for (size_t i = 0; i < cnt + h.cnt && !was; i++)
                        was = idx[i] == w;
                }
                if (was || !finite_at(xyz, w)) continue;
                cut |= ring_offer(&h, w);
            }
        }
        if (!h.cnt) break; /* connected component exhausted */
        for (size_t e = h.cnt; e > 1; e--) { /* heap sort: nearest first */
            uint32_t t = h.heap[0];
            h.heap[0] = h.heap[e - 1];
            h.heap[e - 1] = t;
            ring_sift_down(&h, e - 1, 0);
        }
        ring_b = cnt;
        cnt += h.cnt;
        ring_e = cnt;
        if (cut) break;
    }
    *found = cnt;
    return JF_OK;
}

jf_status jf_mesh_rings(const jf_mesh *m, const double *xyz, uint32_t v,
                        size_t N, uint32_t *idx, size_t cap, size_t *found)
{
    return rings_impl(m, xyz, v, N, 0, idx, cap, found);
}

jf_status jf_mesh_rings_full(const jf_mesh *m, const double *xyz, uint32_t v,
                             size_t min_count, uint32_t *idx, size_t cap,
                             size_t *found)
{
    return rings_impl(m, xyz, v, min_count, 1, idx, cap, found);
}
