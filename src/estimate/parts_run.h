/* parts_run.h -- what the bounded-memory estimate's files share
 * (parts_run.c: the driver; parts_scan.c: the cloud read in chunks;
 * parts_halo.c: each part's halo; not part of the public API). */
#ifndef JF_PARTS_RUN_H
#define JF_PARTS_RUN_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "index_internal.h"
#include "jetfit.h"
#include "parts.h"

/* The coordinates' reader (jf_xyz_src): every scan walks the cloud in
 * chunks of JF_SRC_CHUNK points on the threads, each thread reading its
 * chunk into its own buffers (in memory: a pointer, no copy).  The first
 * failed read is kept; the scans then skip, and the caller returns it. */
typedef struct {
    const jf_xyz_src *s;
    size_t n, nch;         /* points, chunks                            */
    double **xyz;          /* per thread: JF_SRC_CHUNK x 3              */
    unsigned char **raw;   /* per thread: JF_SRC_CHUNK rows             */
    int nt;
    int plain;             /* rows are x y z doubles (no raw buffers)   */
    int fail;              /* a read failed: io_row, io_errno           */
    size_t io_row;
    int io_errno;
} reader;

/* Points in chunk ch. */
size_t jf__chunk_len(const reader *rd, size_t ch);
/* Chunk ch's coordinates (jf__chunk_len points, this thread's buffer),
 * or NULL after a failed read. */
const double *jf__chunk_xyz(reader *rd, size_t ch);
jf_status jf__reader_open(reader *rd, const jf_xyz_src *s, size_t n, int nt);
void jf__reader_close(reader *rd);
/* JF_ERR_IO with the vertex and the reason after a failed read. */
jf_status jf__reader_status(const reader *rd, jf_error *err);
/* The points of part a (input order) and their coordinates; cnt: nch + 1
 * entries of scratch. */
size_t jf__gather(reader *rd, const int32_t *part, int32_t a, uint32_t *ids, double *xyz, size_t *cnt);

/* Who owns each cell of a grid over the cloud's box (built once, in
 * split's part pass): OCC_EMPTY, the one part (+1) whose points it holds,
 * or OCC_MIXED.  A ball over no cell owned by another part (empty, or a's
 * only) holds no foreign point, so its point needs no halo (boxes of
 * Z-curve runs overlap too much to tell).  cell(v) = floor((v - lo) / s),
 * clamped (a product by 1/s), is monotone in v, so a point inside a box
 * is in one of the box's cells.  A byte a cell: the cells are jf__parts_grid_bits / 8, the
 * bytes of the bit grid rebuilt per part by a scan before. */
typedef struct {
    double lo[3], s;
    size_t dim[3];
    uint8_t *own;
    int P;
    double inv;        /* 1 / s: a product per axis, not a division     */
} occgrid;

#define OCC_EMPTY 0
#define OCC_MIXED 255              /* also every cell when P > 254      */
#define OCC_PROBE 4096             /* more cells in a ball: just ask   */
/* (skipping a query: at most 64 cells probed, a query costs less) */

static inline size_t cell1(double v, double lo, double inv, size_t dim)
{
    double t = floor((v - lo) * inv);
    if (!(t > 0)) return 0;
    return t >= (double)dim ? dim - 1 : (size_t)t;
}

/* A grid over box widened by pad cells on every side, of at most
 * maxcells cells: the finest of ext / 4096 times powers of 2^(1/3). */
static inline void occ_setup(occgrid *g, const double box[6], size_t maxcells, size_t pad)
{
    double ext = 0;
    for (int d = 0; d < 3; d++) ext = box[3 + d] - box[d] > ext ? box[3 + d] - box[d] : ext;
    g->s = ext > 0 && isfinite(ext) ? ext / 4096 : 1;
    for (;;) {
        double cells = 1;
        for (int d = 0; d < 3; d++) cells *= floor((box[3 + d] - box[d]) / g->s) + 1 + 2 * (double)pad;
        if (cells <= (double)maxcells) break;
        g->s *= 1.25992104989487316; /* cube root of 2: half the cells */
    }
    for (int d = 0; d < 3; d++) {
        g->lo[d] = box[d] - (double)pad * g->s;
        g->dim[d] = (size_t)floor((box[3 + d] - box[d]) / g->s) + 1 + 2 * pad;
    }
    g->inv = 1 / g->s;
}

static inline size_t occ_cells(const occgrid *g) { return g->dim[0] * g->dim[1] * g->dim[2]; }

static inline size_t occ_cell(const occgrid *g, const double *x)
{
    return (cell1(x[2], g->lo[2], g->inv, g->dim[2]) * g->dim[1] +
            cell1(x[1], g->lo[1], g->inv, g->dim[1])) * g->dim[0] +
           cell1(x[0], g->lo[0], g->inv, g->dim[0]);
}

/* Part a (-1: none) holds x: its cell goes empty -> a + 1 -> mixed, on
 * any thread (values only move forward, so a lost race retries once). */
static inline void occ_set(occgrid *g, const double *x, int32_t a)
{
    uint8_t *c = g->own + occ_cell(g, x);
    const uint8_t mine = g->P <= 254 ? (uint8_t)(a + 1) : OCC_MIXED;
    uint8_t v = __atomic_load_n(c, __ATOMIC_RELAXED);
    if (v == mine || v == OCC_MIXED) return;
    if (v == OCC_EMPTY &&
        __atomic_compare_exchange_n(c, &v, mine, 0, __ATOMIC_RELAXED, __ATOMIC_RELAXED))
        return;
    if (v != mine) __atomic_store_n(c, (uint8_t)OCC_MIXED, __ATOMIC_RELAXED);
}

/* 1 when no cell meeting the box p +- r holds a point of a part other
 * than a. */
static inline int occ_free(const occgrid *g, const double p[3], double r, double probe, int32_t a)
{
    size_t lo[3], hi[3];
    double cells = 1;
    for (int d = 0; d < 3; d++) {
        lo[d] = cell1(p[d] - r, g->lo[d], g->inv, g->dim[d]);
        hi[d] = cell1(p[d] + r, g->lo[d], g->inv, g->dim[d]);
        cells *= (double)(hi[d] - lo[d] + 1);
    }
    if (!(r < INFINITY) || cells > probe) return 0;
    const uint8_t mine = g->P <= 254 ? (uint8_t)(a + 1) : OCC_EMPTY;
    for (size_t z = lo[2]; z <= hi[2]; z++)
        for (size_t y = lo[1]; y <= hi[1]; y++) {
            const uint8_t *row = g->own + (z * g->dim[1] + y) * g->dim[0];
            for (size_t x = lo[0]; x <= hi[0]; x++)
                if (row[x] != OCC_EMPTY && row[x] != mine) return 0;
        }
    return 1;
}

/* A halo point: input index and coordinates, as the scan read them. */
typedef struct {
    uint32_t id;
    double x[3];
} hpoint;

typedef struct {
    hpoint *v;
    size_t n, cap;
} hvec;

/* Step 2 for part a (parts_halo.c): its halo by the requests of its own
 * points (jf__halo_of), with a knn's bounds from the cloud (jf__wide_index),
 * or by dense cells without an index (jf__halo_by_cells). */
jf_status jf__halo_of(reader *rd, const int32_t *part, const double *box, int P,
                         const occgrid *occ, int32_t a,
                         const jf_index *own, const jf_index *qix, double cap, int *capped,
                         const double *xyz, size_t m, const jf_part_query *q, int nt,
                         hpoint **halo, size_t *nhalo);

jf_status jf__wide_index(reader *rd, const int32_t *part, const double *box, int P,
                            const occgrid *occ, int32_t a, const jf_index *own,
                            const double *xyz, size_t m, const jf_part_query *q, int nt,
                            hpoint **halo, size_t *nhalo, jf_index **wide);

jf_status jf__halo_by_cells(reader *rd, const int32_t *part, const double *boxa, int32_t a,
                               const double *xyz, size_t m, size_t K, size_t cap, size_t maxcells,
                               int nt, hpoint **halo, size_t *nhalo, int *served);

#endif /* JF_PARTS_RUN_H */
