/* kdtree.c -- jf_index: a static k-d tree with exact k-NN and radius queries.
 *
 * design:
 *  - build: the finite points are copied, permuted, into one contiguous array
 *    (24 bytes/point) beside their original indices (4 bytes/point).  Each
 *    node splits its range at the median of the axis of largest extent
 *    (quickselect, a branch-free Lomuto partition: O(n log n) total);
 *    ranges of at most KD_LEAF points are leaves (their sets depend only
 *    on the (coordinate, index) order; their inner order on the partition).  An inner node keeps the largest coordinate
 *    of its left half and the smallest of its right half along its axis
 *    (as nanoflann does), so the gap between the halves prunes too.
 *  - query: depth first, nearer child first; a bounded max-heap (or, for
 *    k up to KD_BUF_MAX / 2 = 1024, a 2k buffer cut back to k by
 *    quickselect, on the heap above k = 500; for k up to 48, a buffer
 *    appended to without branches, ranked at the end) of
 *    (d2, position in tree order) pairs lives in the caller's buffers,
 *    positions turned into original indices at the end (and, for the
 *    pipeline, the points' coordinates copied from the tree's storage:
 *    index_internal.h).  Order is the lexicographic (d2, original index),
 *    so ties go to the smaller index and results never depend on the
 *    tree's shape.
 *  - exactness: the lower bound of a cell is g0*g0 + g1*g1 + g2*g2 with
 *    g_i <= |q_i - p_i| computed by the same rounded operations as a point's
 *    distance, so (rounding being monotonic) it never exceeds the distance of
 *    any point inside; a cell is skipped only if its bound is strictly
 *    larger than the current worst, or equal to it and its smallest original
 *    index above the worst's, so ties are never lost -- and a cloud of
 *    identical points (every bound a tie) is not read whole per query.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "index_internal.h"
#include "bigalloc.h" /* jf__big_alloc */
#include "jetfit.h"

#define KD_LEAF 24          /* largest leaf: 12..24 points (measured best
                               in random query order at 1M points)     */
#define KD_STACK_KEYS 1024  /* d2 scratch on the stack when d2 == NULL    */
#define KD_SORTED_MAX 48    /* k up to this: sorted array, else heap      */
#define KD_BUF_MAX 2048     /* 2k up to this: buffer and quickselect      */
#define KD_BUF_STACK 1024   /* its scratch on the stack up to this 2k + KD_LEAF */
#define KD_PROBE_MIN 8      /* k >= 8 x this: a k/8 probe bounds the search */
#ifndef KD_PROBE_GROW
#define KD_PROBE_GROW 1.25  /* squared-radius margin of the probe's bound  */
#endif
#define KD_BKT_INS 16       /* buf_finish: one insertion sort if no bucket is larger */
#define KD_IS_LEAF 3u       /* `dim` value marking a leaf                 */
#define KD_APP_MAX (2 * KD_SORTED_MAX + KD_LEAF) /* append buffer (mode 3) */
_Static_assert(KD_APP_MAX <= KD_BUF_STACK, "mode 3 uses the stack buffer of mode 2");

typedef struct {
    double lo;        /* inner: max coordinate of the left child          */
    double hi;        /* inner: min coordinate of the right child         */
    uint32_t first;   /* inner: index of the left child (right = +1);
                         leaf: first point of the leaf                    */
    uint32_t dim;     /* inner: split axis 0..2; leaf: KD_IS_LEAF | count<<2 */
} kd_node;

struct jf_index {
    size_t n;          /* points given                                    */
    size_t m;          /* finite points indexed                           */
    double *pts;       /* 3m coordinates, in tree order                   */
    uint32_t *id;      /* m original indices, in tree order               */
    kd_node *nodes;
    uint32_t *minid;   /* nnodes: the smallest original index under a node */
    size_t nnodes;
    double bbox[6];    /* lo x,y,z then hi x,y,z of the finite points     */
};

/* ---------------------------------------------------------------- build */

static size_t count_nodes(size_t cnt)
{
    if (cnt <= KD_LEAF) return 1;
    return 1 + count_nodes(cnt / 2) + count_nodes(cnt - cnt / 2);
}

static void swap_pt(double *pts, uint32_t *id, size_t a, size_t b)
{
    double t0 = pts[3 * a], t1 = pts[3 * a + 1], t2 = pts[3 * a + 2];
    uint32_t ti = id[a];
    pts[3 * a] = pts[3 * b];
    pts[3 * a + 1] = pts[3 * b + 1];
    pts[3 * a + 2] = pts[3 * b + 2];
    id[a] = id[b];
    pts[3 * b] = t0;
    pts[3 * b + 1] = t1;
    pts[3 * b + 2] = t2;
    id[b] = ti;
}

/* (coordinate d, original index) order of positions a, b: ties on the
 * axis go by index, so a run of equal coordinates (a grid's rows, or a
 * hostile cloud of one repeated point) is laid out by index and a query's
 * ties prune whole subtrees (minid). */
static int key_less(const double *pts, const uint32_t *id, size_t a, size_t b, int d)
{
    const double x = pts[3 * a + d], y = pts[3 * b + d];
    return x < y || (x == y && id[a] < id[b]);
}

/* Quickselect (median of three, Lomuto partition) on (coordinate d, index):
 * afterwards every point in [lo, nth) is before nth and every one in
 * (nth, hi) after it in that order, so coordinates in [lo, nth) <= that
 * of nth <= those in (nth, hi).  The keys are distinct: O(n) expected. */
static void select_nth(double *pts, uint32_t *id, size_t lo, size_t hi,
                       size_t nth, int d)
{
    while (hi - lo > 2) {
        size_t mid = lo + (hi - lo) / 2, last = hi - 1;
        if (key_less(pts, id, mid, lo, d)) swap_pt(pts, id, mid, lo);
        if (key_less(pts, id, last, lo, d)) swap_pt(pts, id, last, lo);
        if (key_less(pts, id, last, mid, d)) swap_pt(pts, id, last, mid);
        /* Lomuto without a branch on the data: every element is swapped
         * with the boundary, which advances past those before the pivot
         * (Hoare's two scans mispredicted about one element in two) */
        swap_pt(pts, id, mid, last); /* the pivot, out of the way */
        const double pc = pts[3 * last + d];
        const uint32_t pi = id[last];
        size_t st = lo;
        for (size_t i = lo; i < last; i++) {
            const double x = pts[3 * i + d];
            const size_t less = (x < pc) | ((x == pc) & (id[i] < pi));
            swap_pt(pts, id, i, st);
            st += less;
        }
        swap_pt(pts, id, st, last); /* [lo, st) < pivot at st < (st, hi) */
        if (nth == st) return;
        if (nth < st) hi = st;
        else lo = st + 1;
    }
    if (hi - lo == 2 && key_less(pts, id, lo + 1, lo, d))
        swap_pt(pts, id, lo, lo + 1);
}

typedef struct {
    double *pts;
    uint32_t *id;
    kd_node *nodes;
    uint32_t *minid; /* each node's smallest input index (the tie rule's) */
} kd_builder;

#define KD_TASK_MIN 65536 /* subtrees at least this big build as OpenMP tasks */
#define KD_COPY_BLOCK 65536 /* input points a thread copies into the tree at a time */

/* Builds node ni over [begin, end); its descendants take the node slots
 * from `next` on, in depth-first order (children side by side, the left
 * subtree's before the right's), so the layout does not depend on which
 * thread builds which subtree.  Large subtrees run as OpenMP tasks. */
static void build_node(const kd_builder *b, size_t ni, size_t begin, size_t end, size_t next,
                       const double *box)
{
    kd_node *nd = &b->nodes[ni];
    size_t cnt = end - begin;
    if (cnt <= KD_LEAF) {
        nd->lo = nd->hi = 0.0;
        nd->first = (uint32_t)begin;
        nd->dim = KD_IS_LEAF | (uint32_t)(cnt << 2);
        uint32_t mn = UINT32_MAX;
        for (size_t j = begin; j < end; j++) mn = b->id[j] < mn ? b->id[j] : mn;
        b->minid[ni] = mn;
        return;
    }
    double lo[3], hi[3];
    const double *p = b->pts;
    if (box) { /* the root: the cloud's box, found by the threads */
        for (int d = 0; d < 3; d++) lo[d] = box[d], hi[d] = box[3 + d];
    } else {
        for (int d = 0; d < 3; d++) lo[d] = hi[d] = p[3 * begin + d];
        for (size_t i = begin + 1; i < end; i++)
            for (int d = 0; d < 3; d++) { /* finite: min/max without branches */
                const double v = p[3 * i + d];
                lo[d] = v < lo[d] ? v : lo[d];
                hi[d] = v > hi[d] ? v : hi[d];
            }
    }
    int dim = 0;
    for (int d = 1; d < 3; d++)
        if (hi[d] - lo[d] > hi[dim] - lo[dim]) dim = d;
    size_t mid = begin + cnt / 2;
    select_nth(b->pts, b->id, begin, end, mid, dim);
    double lmax = p[3 * begin + dim];
    for (size_t i = begin + 1; i < mid; i++) lmax = p[3 * i + dim] > lmax ? p[3 * i + dim] : lmax;
    size_t child = next;
    nd->lo = lmax;
    nd->hi = p[3 * mid + dim]; /* the selected element is the right minimum */
    nd->first = (uint32_t)child;
    nd->dim = (uint32_t)dim;
    size_t right_next = child + 2 + count_nodes(mid - begin) - 1;
#pragma omp task if (cnt >= KD_TASK_MIN) default(none) firstprivate(b, child, begin, mid)
    build_node(b, child, begin, mid, child + 2, NULL);
    build_node(b, child + 1, mid, end, right_next, NULL);
#pragma omp taskwait
    b->minid[ni] = b->minid[child] < b->minid[child + 1] ? b->minid[child] : b->minid[child + 1];
}

static int finite3(const double *p)
{
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

jf_status jf_index_build(const double *xyz, size_t n, jf_index **out)
{
    return jf__index_build_threads(xyz, n, 0, out);
}

jf_status jf__index_build_threads(const double *xyz, size_t n, int threads, jf_index **out)
{
    if (!out) return JF_ERR_INVALID;
    *out = NULL;
    if (!xyz && n) return JF_ERR_INVALID;
    /* UINT32_MAX itself is the heap's "no point" sentinel */
    if (n >= UINT32_MAX) return JF_ERR_TOO_LARGE;
    jf_index *ix = calloc(1, sizeof *ix);
    if (!ix) return JF_ERR_NOMEM;
    ix->n = n;
    /* the finite points in input order, on the threads: counted per block,
     * each block then copied at its offset with its box (issue 28.3) */
    const int nt = threads > 0 ? threads : jf_default_threads(NULL);
    const size_t nblk = (n + KD_COPY_BLOCK - 1) / KD_COPY_BLOCK;
    size_t *off = calloc(nblk + 1, sizeof *off);
    double *bb = malloc((nblk ? nblk : 1) * 6 * sizeof *bb);
    if (!off || !bb) {
        free(off), free(bb), free(ix);
        return JF_ERR_NOMEM;
    }
#pragma omp parallel for num_threads(nt) schedule(static) if (nblk > 1)
    for (size_t k = 0; k < nblk; k++) {
        size_t c = 0, e = (k + 1) * KD_COPY_BLOCK < n ? (k + 1) * KD_COPY_BLOCK : n;
        for (size_t i = k * KD_COPY_BLOCK; i < e; i++) c += finite3(xyz + 3 * i) ? 1 : 0;
        off[k + 1] = c;
    }
    for (size_t k = 0; k < nblk; k++) off[k + 1] += off[k];
    size_t m = off[nblk];
    ix->m = m;
    ix->nnodes = m ? count_nodes(m) : 0;
    /* written whole: huge pages, one fault per 2 MiB (core/bigalloc.c) */
    ix->pts = jf__big_alloc((m ? m : 1) * 3 * sizeof *ix->pts);
    ix->id = jf__big_alloc((m ? m : 1) * sizeof *ix->id);
    ix->nodes = malloc((ix->nnodes ? ix->nnodes : 1) * sizeof *ix->nodes);
    ix->minid = malloc((ix->nnodes ? ix->nnodes : 1) * sizeof *ix->minid);
    if (!ix->pts || !ix->id || !ix->nodes || !ix->minid) {
        free(off), free(bb);
        jf_index_free(ix);
        return JF_ERR_NOMEM;
    }
#pragma omp parallel for num_threads(nt) schedule(static) if (nblk > 1)
    for (size_t k = 0; k < nblk; k++) {
        size_t j = off[k], e = (k + 1) * KD_COPY_BLOCK < n ? (k + 1) * KD_COPY_BLOCK : n;
        double *q = bb + 6 * k;
        for (size_t i = k * KD_COPY_BLOCK; i < e; i++) {
            const double *p = xyz + 3 * i;
            if (!finite3(p)) continue;
            if (j == off[k])
                for (int d = 0; d < 3; d++) q[d] = q[3 + d] = p[d];
            for (int d = 0; d < 3; d++) {
                if (p[d] < q[d]) q[d] = p[d];
                if (p[d] > q[3 + d]) q[3 + d] = p[d];
            }
            memcpy(ix->pts + 3 * j, p, 3 * sizeof(double));
            ix->id[j++] = (uint32_t)i;
        }
    }
    /* blocks in input order, the first of equal values kept, as one pass would */
    for (int d = 0; d < 6; d++) ix->bbox[d] = 0.0;
    for (size_t k = 0, any = 0; k < nblk; k++) {
        if (off[k + 1] == off[k]) continue;
        const double *q = bb + 6 * k;
        for (int d = 0; d < 3; d++) {
            if (!any || q[d] < ix->bbox[d]) ix->bbox[d] = q[d];
            if (!any || q[3 + d] > ix->bbox[3 + d]) ix->bbox[3 + d] = q[3 + d];
        }
        any = 1;
    }
    free(off), free(bb);
    if (m) {
        const kd_builder b = {ix->pts, ix->id, ix->nodes, ix->minid};
        const kd_builder *bp = &b;
        const double *box = ix->bbox;
#pragma omp parallel if (m >= 2 * KD_TASK_MIN) num_threads(nt) default(none) shared(bp, m, box)
#pragma omp single
        build_node(bp, 0, 0, m, 1, box);
    }
    *out = ix;
    return JF_OK;
}

void jf_index_free(jf_index *ix)
{
    if (!ix) return;
    free(ix->pts);
    free(ix->id);
    free(ix->nodes);
    free(ix->minid);
    free(ix);
}

size_t jf_index_size(const jf_index *ix) { return ix ? ix->m : 0; }

size_t jf__index_input_size(const jf_index *ix) { return ix ? ix->n : 0; }

size_t jf_index_memory(const jf_index *ix)
{
    if (!ix) return 0;
    return sizeof *ix + ix->m * (3 * sizeof(double) + sizeof(uint32_t)) +
           ix->nnodes * (sizeof(kd_node) + sizeof(uint32_t));
}

/* ---------------------------------------------------------------- query */

size_t jf__index_points(const jf_index *ix, const double **pts, const uint32_t **id)
{
    if (pts) *pts = ix ? ix->pts : NULL;
    if (id) *id = ix ? ix->id : NULL;
    return ix ? ix->m : 0;
}

/* The candidates are kept as positions in the tree's storage (so their
 * coordinates can be copied from it at the end) and compared in the order
 * of (d2, original index): the index is looked up only on equal d2. */
typedef double kd_v2d __attribute__((vector_size(16)));
typedef long long kd_v2l __attribute__((vector_size(16)));

typedef struct {
    const jf_index *ix;
    double q[3];
    double *hd;       /* heap keys: squared distances                     */
    uint32_t *hp;     /* heap values: positions in tree order             */
    size_t cap, cnt;
    int sorted;       /* 1: sorted array; 2: buffer (buf_push); 0: heap;
                         3: append buffer (small k, app_leaf)              */
    double worst_d;   /* (worst_d, worst_p): the pair a candidate must beat */
    uint32_t worst_p; /* UINT32_MAX: none (an index above every index)    */
    jf__kd_scan *scan; /* when not NULL: the leaves read, the cells passed */
    double *td;       /* buffer mode: buf_finish's scratch (2 cap slots, */
    uint32_t *tp, *start; /* start 2 cap + 1)                           */
} kd_query;

/* (d, position p) < (da, position pa) in the (distance, index) order */
#define KD_LESS(id, d, p, da, pa) ((d) < (da) || ((d) == (da) && (id)[p] < (id)[pa]))

static void heap_sift_down(const uint32_t *id, double *hd, uint32_t *hp, size_t cnt, size_t k)
{
    double d = hd[k];
    uint32_t pos = hp[k];
    for (;;) {
        size_t c = 2 * k + 1;
        if (c >= cnt) break;
        if (c + 1 < cnt && KD_LESS(id, hd[c], hp[c], hd[c + 1], hp[c + 1])) c++;
        if (!KD_LESS(id, d, pos, hd[c], hp[c])) break;
        hd[k] = hd[c];
        hp[k] = hp[c];
        k = c;
    }
    hd[k] = d;
    hp[k] = pos;
}

static void heap_push(kd_query *s, double d, uint32_t pos)
{
    const uint32_t *id = s->ix->id;
    if (s->cnt < s->cap) {
        size_t k = s->cnt++;
        while (k > 0) {
            size_t p = (k - 1) / 2;
            if (!KD_LESS(id, s->hd[p], s->hp[p], d, pos)) break;
            s->hd[k] = s->hd[p];
            s->hp[k] = s->hp[p];
            k = p;
        }
        s->hd[k] = d;
        s->hp[k] = pos;
        if (s->cnt < s->cap) return; /* not full: the bound stays open */
    } else {
        s->hd[0] = d;
        s->hp[0] = pos;
        heap_sift_down(id, s->hd, s->hp, s->cnt, 0);
    }
    s->worst_d = s->hd[0];
    s->worst_p = s->hp[0];
}

/* Small k: insertion into the sorted prefix (short, predictable moves
 * beat the heap's data-dependent sifts). */
static void sorted_push(kd_query *s, double d, uint32_t pos)
{
    const uint32_t *id = s->ix->id;
    size_t j = s->cnt < s->cap ? s->cnt++ : s->cap - 1;
    while (j > 0 && KD_LESS(id, d, pos, s->hd[j - 1], s->hp[j - 1])) {
        s->hd[j] = s->hd[j - 1];
        s->hp[j] = s->hp[j - 1];
        j--;
    }
    s->hd[j] = d;
    s->hp[j] = pos;
    if (s->cnt == s->cap) {
        s->worst_d = s->hd[s->cap - 1];
        s->worst_p = s->hp[s->cap - 1];
    }
}

/* Larger k: candidates appended to a buffer of 2k; when it fills, a
 * quickselect keeps the k least and the k-th becomes the worst (O(1)
 * amortised per candidate, against the heap's log k sifts, which
 * dominated knn:256).  The (d2, index) order is total, so the k kept and
 * their final order are the heap's. */
static void buf_swap(double *hd, uint32_t *hp, size_t a, size_t b)
{
    double td = hd[a];
    uint32_t tp = hp[a];
    hd[a] = hd[b];
    hp[a] = hp[b];
    hd[b] = td;
    hp[b] = tp;
}

/* Quickselect (median of three, Hoare partition) on (d2, index): [lo, nth)
 * before nth, (nth, hi) after it.  Keys are distinct. */
static void buf_select(const uint32_t *id, double *hd, uint32_t *hp, size_t lo, size_t hi,
                       size_t nth)
{
    while (hi - lo > 2) {
        size_t mid = lo + (hi - lo) / 2, last = hi - 1;
        if (KD_LESS(id, hd[mid], hp[mid], hd[lo], hp[lo])) buf_swap(hd, hp, mid, lo);
        if (KD_LESS(id, hd[last], hp[last], hd[lo], hp[lo])) buf_swap(hd, hp, last, lo);
        if (KD_LESS(id, hd[last], hp[last], hd[mid], hp[mid])) buf_swap(hd, hp, last, mid);
        const double pd = hd[mid];
        const uint32_t pp = hp[mid];
        size_t i = lo, j = last;
        for (;;) {
            while (KD_LESS(id, hd[i], hp[i], pd, pp)) i++;
            while (KD_LESS(id, pd, pp, hd[j], hp[j])) j--;
            if (i >= j) break;
            buf_swap(hd, hp, i, j);
            i++;
            j--;
        }
        if (nth <= j) hi = j + 1;
        else lo = j + 1;
    }
    if (hi - lo == 2 && KD_LESS(id, hd[lo + 1], hp[lo + 1], hd[lo], hp[lo]))
        buf_swap(hd, hp, lo, lo + 1);
}

/* Sorts [lo, hi) by (d2, index): quicksort, insertion sort below 16. */
static void buf_sort(const uint32_t *id, double *hd, uint32_t *hp, size_t lo, size_t hi)
{
    while (hi - lo > 16) {
        size_t mid = lo + (hi - lo) / 2;
        buf_select(id, hd, hp, lo, hi, mid); /* [lo, mid) <= mid <= (mid, hi) */
        if (mid - lo < hi - mid - 1) {
            buf_sort(id, hd, hp, lo, mid);
            lo = mid + 1;
        } else {
            buf_sort(id, hd, hp, mid + 1, hi);
            hi = mid;
        }
    }
    for (size_t i = lo + 1; i < hi; i++) {
        double d = hd[i];
        uint32_t p = hp[i];
        size_t j = i;
        while (j > lo && KD_LESS(id, d, p, hd[j - 1], hp[j - 1])) {
            hd[j] = hd[j - 1];
            hp[j] = hp[j - 1];
            j--;
        }
        hd[j] = d;
        hp[j] = p;
    }
}

/* The k least of the buffer's cnt candidates, nearest first: a counting
 * sort into cnt buckets of equal width in d2 (about as many points per
 * bucket on a surface, where d2 grows with the area), each bucket then
 * sorted by (d2, index) -- the bucket of a key is monotone in it, so the
 * order is exactly the heap's, in O(cnt) instead of a comparison sort's
 * unpredictable branches.  td, tp: cnt slots; start: cnt + 1. */
static void buf_finish(const uint32_t *id, double *hd, uint32_t *hp, size_t cnt, size_t k,
                       double *td, uint32_t *tp, uint32_t *start)
{
    double mx = 0.0;
    for (size_t i = 0; i < cnt; i++)
        if (hd[i] > mx) mx = hd[i];
    if (!(mx > 0.0) || !isfinite(mx) || cnt > KD_BUF_MAX) { /* all ties: compare */
        if (cnt > k) buf_select(id, hd, hp, 0, cnt, k - 1);
        buf_sort(id, hd, hp, 0, cnt < k ? cnt : k);
        return;
    }
    const double scale = (double)cnt / mx;
    if (!isfinite(scale)) { /* mx subnormal: the buckets would overflow */
        if (cnt > k) buf_select(id, hd, hp, 0, cnt, k - 1);
        buf_sort(id, hd, hp, 0, cnt < k ? cnt : k);
        return;
    }
    memset(start, 0, (cnt + 1) * sizeof *start);
    for (size_t i = 0; i < cnt; i++) {
        size_t b = (size_t)(hd[i] * scale);
        start[(b < cnt ? b : cnt - 1) + 1]++;
    }
    for (size_t b = 0; b < cnt; b++) start[b + 1] += start[b];
    for (size_t i = 0; i < cnt; i++) {
        size_t b = (size_t)(hd[i] * scale);
        uint32_t at = start[b < cnt ? b : cnt - 1]++;
        td[at] = hd[i];
        tp[at] = hp[i];
    }
    /* start[b] is now the end of bucket b.  Buckets of at most KD_BKT_INS
     * up to the k-th's: one insertion sort of them all, which moves only
     * the few bucket mates out of order (a sort per bucket mispredicts on
     * every bucket size); else each bucket sorted on its own */
    size_t bl = 0, bh = cnt - 1;
    while (bl < bh) {
        size_t mid = bl + (bh - bl) / 2;
        if (start[mid] >= (k < cnt ? k : cnt)) bh = mid;
        else bl = mid + 1;
    }
    uint32_t big = start[0] > KD_BKT_INS;
    for (size_t b = 1; b <= bl; b++) big |= start[b] - start[b - 1] > KD_BKT_INS;
    if (!big) {
        const size_t end = start[bl], m = k < cnt ? k : cnt;
        for (size_t i = 1; i < end; i++) {
            const double d = td[i];
            if (!KD_LESS(id, d, tp[i], td[i - 1], tp[i - 1])) continue;
            const uint32_t p = tp[i];
            size_t j = i;
            do {
                td[j] = td[j - 1];
                tp[j] = tp[j - 1];
                j--;
            } while (j > 0 && KD_LESS(id, d, p, td[j - 1], tp[j - 1]));
            td[j] = d;
            tp[j] = p;
        }
        memcpy(hd, td, m * sizeof *hd);
        memcpy(hp, tp, m * sizeof *hp);
        return;
    }
    size_t out = 0, lo = 0;
    for (size_t b = 0; b < cnt && out < k; b++) {
        size_t hi = start[b];
        if (hi - lo > 1) buf_sort(id, td, tp, lo, hi);
        for (size_t i = lo; i < hi && out < k; i++, out++) {
            hd[out] = td[i];
            hp[out] = tp[i];
        }
        lo = hi;
    }
}

/* The k least of the cnt candidates kept (quickselect), the k-th of them
 * the new worst. */
static void keep_least(kd_query *s)
{
    buf_select(s->ix->id, s->hd, s->hp, 0, s->cnt, s->cap - 1);
    s->cnt = s->cap;
    s->worst_d = s->hd[s->cap - 1];
    s->worst_p = s->hp[s->cap - 1];
}

static void buf_push(kd_query *s, double d, uint32_t pos)
{
    s->hd[s->cnt] = d;
    s->hp[s->cnt++] = pos;
    if (s->cnt < 2 * s->cap) return;
    keep_least(s);
}

/* Every point of a leaf within the bound appended without a branch (store
 * always, advance on d <= worst): a superset of what the (d2, index) rule
 * admits.  Returns the new count. */
static inline __attribute__((always_inline)) size_t leaf_append(kd_query *s, const kd_node *nd)
{
    const uint32_t first = nd->first, cnt = nd->dim >> 2;
    const double *p = s->ix->pts + 3 * (size_t)first;
    const double q0 = s->q[0], q1 = s->q[1], q2 = s->q[2], w = s->worst_d;
    double *hd = s->hd;
    uint32_t *hp = s->hp;
    size_t c = s->cnt;
    for (uint32_t j = 0; j < cnt; j++, p += 3) {
        const double dx = q0 - p[0], dy = q1 - p[1], dz = q2 - p[2];
        const double d = dx * dx + dy * dy + dz * dz;
        hd[c] = d;
        hp[c] = first + j;
        c += d <= w;
    }
    return s->cnt = c;
}

/* Mode 2 without a scan record: a leaf appended (leaf_append: half the
 * points of a k = 1024 search's leaves fail the test, unpredictably);
 * from 2k on, a quickselect keeps the k least (as buf_push).  The buffer
 * holds 2k + KD_LEAF. */
static void buf_leaf(kd_query *s, const kd_node *nd)
{
    if (leaf_append(s, nd) >= 2 * s->cap) keep_least(s);
}

/* Mode 3's bound, lowered while at least k candidates stay within it: a
 * factor at a time, each step one counting pass and one filtering pass,
 * neither with a data-dependent branch.  Exact: the k nearest are among
 * k points at d2 <= the bound (ties included: the bound is inclusive and
 * names no point, worst_p = none). */
#define KD_SHRINK 0.8
static void app_shrink(kd_query *s)
{
    double *hd = s->hd;
    uint32_t *hp = s->hp;
    size_t c = s->cnt;
    double w = s->worst_d;
    if (!(w < INFINITY)) { /* no bound yet: the farthest candidate's */
        w = 0;
        for (size_t j = 0; j < c; j++) w = hd[j] > w ? hd[j] : w;
    }
    for (;;) {
        const double v = w * KD_SHRINK;
        size_t n = 0;
        for (size_t j = 0; j < c; j++) n += hd[j] <= v;
        if (n < s->cap || !(v < w)) break;
        w = v;
    }
    size_t m = 0;
    for (size_t j = 0; j < c; j++) {
        const double d = hd[j];
        hd[m] = d;
        hp[m] = hp[j];
        m += d <= w;
    }
    s->cnt = m;
    if (w < s->worst_d) s->worst_d = w, s->worst_p = UINT32_MAX;
}

/* Small k without a scan record: a leaf appended (leaf_append); from 2k
 * candidates on, app_shrink lowers the bound.  The sorted insertion this replaces spent
 * ~30% of a knn:16 query in mispredicted shifts.  Should the bound not
 * come down (many equal d2), a quickselect keeps the k least. */
static void app_leaf(kd_query *s, const kd_node *nd)
{
    if (leaf_append(s, nd) < 2 * s->cap) return;
    app_shrink(s);
    if (s->cnt + KD_LEAF <= KD_APP_MAX) return;
    keep_least(s);
}

/* The k least of mode 3's cnt candidates, nearest first, into (od, op):
 * each candidate's rank in the (d2, index) order is the count of those
 * before it (d2 compared for all pairs at once, vectorised; the index only
 * where d2 ties), so the order is the heap's without a data-dependent
 * branch.  app_shrink leaves cnt near k, so the cnt^2 pairs are few. */
static size_t app_finish(const uint32_t *id, double *hd, const uint32_t *hp, size_t cnt,
                         size_t k, double *od, uint32_t *op)
{
    hd[cnt] = INFINITY; /* pads the last pair: never below, equal only to an infinite d2 */
    for (size_t i = 0; i < cnt; i++) {
        const double d = hd[i];
        const kd_v2d dv = {d, d};
        kd_v2l vlt = {0, 0}, vle = {0, 0};
        for (size_t j = 0; j < cnt; j += 2) {
            kd_v2d v;
            memcpy(&v, hd + j, sizeof v);
            vlt -= (kd_v2l)(v < dv); /* -1 where true */
            vle -= (kd_v2l)(v <= dv);
        }
        long long lt = vlt[0] + vlt[1], le = vle[0] + vle[1];
        if (le > lt + 1) /* equal d2 (besides itself): by index */
            for (size_t j = 0; j < cnt; j++) lt += hd[j] == d && id[hp[j]] < id[hp[i]];
        if ((size_t)lt < k) {
            od[lt] = d;
            op[lt] = hp[i];
        }
    }
    return cnt < k ? cnt : k;
}

static void scan_leaf(kd_query *s, const kd_node *nd)
{
    const uint32_t first = nd->first, cnt = nd->dim >> 2;
    if (s->scan) {
        jf__kd_scan *r = s->scan;
        if (r->n < JF_KD_SCAN_LEAVES) r->first[r->n] = first, r->cnt[r->n] = cnt;
        r->n++;
    }
    const double *p = s->ix->pts + 3 * (size_t)first;
    const uint32_t *id = s->ix->id;
    double q0 = s->q[0], q1 = s->q[1], q2 = s->q[2];
    for (uint32_t j = 0; j < cnt; j++, p += 3) {
        double dx = q0 - p[0], dy = q1 - p[1], dz = q2 - p[2];
        double d = dx * dx + dy * dy + dz * dz;
        if (d > s->worst_d) continue; /* the common case, decided fast */
        /* on a tie, the smaller index wins; no worst yet: any index */
        if (d < s->worst_d || s->worst_p == UINT32_MAX || id[first + j] < id[s->worst_p]) {
            if (s->sorted == 1) sorted_push(s, d, first + j);
            else if (s->sorted == 2) buf_push(s, d, first + j);
            else heap_push(s, d, first + j);
        }
    }
}

/* Depth first, nearer child first, with an explicit stack of deferred
 * far children, each with its per-axis gaps (the tree is balanced, so
 * depth <= log2(UINT32_MAX) + 1 and KD_DEPTH entries suffice). */
#define KD_DEPTH 64
typedef struct {
    double g[3];
    uint32_t node;
} kd_frame;

static void search(kd_query *s, const double g0[3])
{
    const kd_node *nodes = s->ix->nodes;
    kd_frame stack[KD_DEPTH];
    size_t top = 0;
    double g[3] = {g0[0], g0[1], g0[2]};
    uint32_t ni = 0;
    for (;;) {
        const kd_node *nd = &nodes[ni];
        if ((nd->dim & 3u) != KD_IS_LEAF) {
            int dim = (int)nd->dim;
            double v = s->q[dim], gap;
            uint32_t far;
            if ((v - nd->lo) + (v - nd->hi) <= 0) { /* a tie: left, the smaller indices */
                ni = nd->first;
                far = nd->first + 1;
                gap = nd->hi - v; /* far (right) points: coordinate >= hi */
            } else {
                ni = nd->first + 1;
                far = nd->first;
                gap = v - nd->lo; /* far (left) points: coordinate <= lo */
            }
            kd_frame *f = &stack[top];
            f->g[0] = g[0];
            f->g[1] = g[1];
            f->g[2] = g[2];
            /* both are lower bounds of |q - p| on dim */
            if (gap > f->g[dim]) f->g[dim] = gap;
            f->node = far;
            top++;
            continue;
        }
        if (s->sorted == 3) app_leaf(s, nd);
        else if (s->sorted == 2 && !s->scan) buf_leaf(s, nd);
        else scan_leaf(s, nd);
        /* next deferred cell whose bound can still beat the worst */
        for (;;) {
            if (!top) return;
            kd_frame *f = &stack[--top];
            double bound = f->g[0] * f->g[0] + f->g[1] * f->g[1] +
                           f->g[2] * f->g[2];
            /* a tie reads the cell only if it may hold a smaller index */
            if (bound < s->worst_d ||
                (bound == s->worst_d && (s->worst_p == UINT32_MAX ||
                                         s->ix->minid[f->node] < s->ix->id[s->worst_p]))) {
                g[0] = f->g[0];
                g[1] = f->g[1];
                g[2] = f->g[2];
                ni = f->node;
                break;
            }
            if (s->scan && bound < s->scan->rc2) s->scan->rc2 = bound;
        }
    }
}

/* Runs the search and sorts the heap nearest first. */
static void run_query(kd_query *s)
{
    const jf_index *ix = s->ix;
    if (!ix->m || !s->cap) return;
    double g[3];
    for (int d = 0; d < 3; d++) {
        double a = ix->bbox[d] - s->q[d], b = s->q[d] - ix->bbox[3 + d];
        g[d] = a > 0 ? a : (b > 0 ? b : 0);
    }
    double bound = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (bound <= s->worst_d) search(s, g);
    else if (s->scan) s->scan->rc2 = bound;
    if (s->sorted == 3 && s->cnt > s->cap) app_shrink(s); /* fewer to sort */
    if (s->sorted == 1 || s->sorted == 3) return;
    if (s->sorted == 2) {
        buf_finish(ix->id, s->hd, s->hp, s->cnt, s->cap, s->td, s->tp, s->start);
        if (s->cnt > s->cap) s->cnt = s->cap;
        return;
    }
    /* heap sort: repeatedly move the worst to the end */
    for (size_t end = s->cnt; end > 1; end--) {
        double td = s->hd[0];
        uint32_t tp = s->hp[0];
        s->hd[0] = s->hd[end - 1];
        s->hp[0] = s->hp[end - 1];
        s->hd[end - 1] = td;
        s->hp[end - 1] = tp;
        heap_sift_down(ix->id, s->hd, s->hp, end - 1, 0);
    }
}

/* The query proper; ids = 0 leaves tree positions in idx; scan (may be
 * NULL) records what the search read. */
static jf_status query(const jf_index *ix, const double q[3], size_t k, double bound,
                       uint32_t *idx, double *d2, double *xyz, size_t *found, int ids,
                       jf__kd_scan *scan)
{
    if (found) *found = 0;
    if (!ix || !q || !found || (k && !idx)) return JF_ERR_INVALID;
    if (!finite3(q) || !(bound >= 0)) return JF_ERR_INVALID;
    if (k > ix->m) k = ix->m;
    double stack_keys[KD_STACK_KEYS];
    double *keys = d2;
    /* the 2k buffer of buf_push, on the stack */
    int mode = k <= KD_SORTED_MAX ? (scan ? 1 : 3) : 2 * k <= KD_BUF_MAX ? 2 : 0;
    double buf_keys[KD_BUF_STACK], buf_td[KD_BUF_STACK];
    uint32_t buf_pos[KD_BUF_STACK], buf_tp[KD_BUF_STACK], buf_start[KD_BUF_STACK + 1];
    double *bk = buf_keys, *btd = buf_td;
    uint32_t *bp = buf_pos, *btp = buf_tp, *bst = buf_start;
    void *heap = NULL; /* 2k + KD_LEAF (buf_leaf) above KD_BUF_STACK: on the heap */
    if (mode == 2 && 2 * k + KD_LEAF > KD_BUF_STACK) {
        const size_t nb = 2 * k + KD_LEAF;
        if (!(heap = malloc(nb * (2 * sizeof(double) + 3 * sizeof(uint32_t)) + sizeof(uint32_t))))
            return JF_ERR_NOMEM;
        bk = heap;
        btd = bk + nb;
        bp = (uint32_t *)(btd + nb);
        btp = bp + nb;
        bst = btp + nb;
    }
    if (mode >= 2) keys = bk; /* mode 3: KD_APP_MAX <= KD_BUF_STACK */
    else if (!keys) {
        if (k <= KD_STACK_KEYS) keys = stack_keys;
        else if (!(keys = malloc(k * sizeof *keys))) return JF_ERR_NOMEM;
    }
    /* idx holds positions during the search, indices after */
    kd_query s = {ix,    {q[0], q[1], q[2]}, keys,  mode >= 2 ? bp : idx,
                  k,     0, mode, bound, UINT32_MAX, scan, btd, btp, bst};
    if (scan) scan->n = 0, scan->rc2 = INFINITY;
    if (mode == 2 && !scan && bound == INFINITY && k >= 8 * KD_PROBE_MIN) {
        /* Probe: the k/8 nearest give a radius that, grown as on a surface
         * (r ~ sqrt k) with a margin, bounds the k-th nearest; the bounded
         * search then reads little beyond that ball.  Exact either way:
         * fewer than k inside the bound and the search runs unbounded. */
        size_t k1 = k / 8 < KD_SORTED_MAX ? k / 8 : KD_SORTED_MAX;
        double pd[KD_SORTED_MAX];
        uint32_t pp[KD_SORTED_MAX];
        kd_query s1 = {ix, {q[0], q[1], q[2]}, pd, pp, k1, 0, 1, INFINITY, UINT32_MAX, NULL, NULL, NULL, NULL};
        run_query(&s1);
        if (s1.cnt == k1) {
            double r2 = pd[k1 - 1] * ((double)k / (double)k1) * KD_PROBE_GROW;
            s.worst_d = r2;
            run_query(&s);
            if (s.cnt < k) { /* the bound was too tight: unbounded */
                s.cnt = 0;
                s.worst_d = INFINITY;
                s.worst_p = UINT32_MAX;
                run_query(&s);
            }
        } else
            run_query(&s);
    } else
        run_query(&s);
    if (mode == 3) {
        s.cnt = app_finish(ix->id, bk, bp, s.cnt, k, d2 ? d2 : stack_keys, idx);
        keys = d2;
    } else if (mode == 2) {
        if (d2) memcpy(d2, bk, s.cnt * sizeof *d2);
        memcpy(idx, bp, s.cnt * sizeof *idx);
        keys = d2;
        free(heap);
    }
    if (scan && scan->n > JF_KD_SCAN_LEAVES) scan->rc2 = 0; /* not all kept */
    if (keys != d2 && keys != stack_keys) free(keys);
    for (size_t j = 0; ids && j < s.cnt; j++) {
        const uint32_t pos = idx[j];
        if (xyz) memcpy(xyz + 3 * j, ix->pts + 3 * (size_t)pos, 3 * sizeof(double));
        idx[j] = ix->id[pos];
    }
    *found = s.cnt;
    return JF_OK;
}

jf_status jf__index_query(const jf_index *ix, const double q[3], size_t k, double bound,
                          uint32_t *idx, double *d2, double *xyz, size_t *found)
{
    return query(ix, q, k, bound, idx, d2, xyz, found, 1, NULL);
}

jf_status jf__index_knn_pos(const jf_index *ix, const double q[3], size_t k, double bound,
                            uint32_t *pos, double *d2, size_t *found)
{
    return query(ix, q, k, bound, pos, d2, NULL, found, 0, NULL);
}

jf_status jf__index_knn_scan(const jf_index *ix, const double q[3], size_t k, uint32_t *pos,
                             double *d2, size_t *found, jf__kd_scan *scan)
{
    return query(ix, q, k, INFINITY, pos, d2, NULL, found, 0, scan);
}

jf_status jf_index_knn(const jf_index *ix, const double q[3], size_t k,
                       uint32_t *idx, double *d2, size_t *found)
{
    return jf__index_query(ix, q, k, INFINITY, idx, d2, NULL, found);
}

jf_status jf_index_radius(const jf_index *ix, const double q[3], double r,
                          size_t max, uint32_t *idx, double *d2,
                          size_t *found)
{
    if (found) *found = 0;
    if (!(r >= 0) || !isfinite(r)) return JF_ERR_INVALID;
    /* inclusive: a candidate at d2 == r*r beats the open bound (r*r, none) */
    return jf__index_query(ix, q, max, r * r, idx, d2, NULL, found);
}
