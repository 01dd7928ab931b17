/* parts.h -- space cut into parts, and the exact halo each part needs to
 * compute its points' k-NN / radius neighbourhoods as one index over the
 * whole cloud would (src/estimate/parts.c; not part of the public API).
 *
 * Used by `jetfit-mpi` (one part per rank, src/mpi/) and by the bounded-
 * memory estimate (parts processed one at a time).  Both follow the same
 * steps:
 *  1. partition: the finite points sorted by (Morton key over the cloud's
 *     bounding box, input index) and cut into P runs of equal count
 *     (within one point); non-finite points belong to no part (they are
 *     nobody's neighbour; their row is NaN).
 *  2. each part indexes its own points; each point turns its neighbourhood
 *     into at most two requests "top k within squared distance <= bound"
 *     (jf__halo_requests), bound tightened by what its own part holds;
 *  3. every other part whose bounding box is within the bound answers with
 *     its own top k within the bound: the union of the answers is the halo.
 *  4. an index over own points + halo, ordered by input index (so the k-d
 *     tree's tie rule, smaller position first, is the input index's),
 *     gives every own point exactly the neighbourhood of the whole cloud.
 */
#ifndef JF_PARTS_H
#define JF_PARTS_H

#include <stddef.h>
#include <stdint.h>

#include "io/io_internal.h"
#include "jetfit.h"
#include "spatial/order_internal.h"

/* The neighbourhood query jf_estimate makes for a kind the k-d tree
 * answers (knn, radius, knn+radius), with the pipeline's sizes. */
typedef struct {
    jf_nb_spec nb;    /* knn: K raised to the largest --scales entry    */
    size_t cap;       /* largest neighbourhood (radius: max_neighbors)  */
    size_t min_count; /* N_n of the degree: knn+radius's fallback floor */
    size_t nj;        /* auto's step 6 (robust/neigh_jets.h): a row reads
                         the fits of its nj nearest, so the halo holds
                         their k nearest too (jf__halo_requests); 0: off */
    const uint8_t *only; /* jf__halo_of: requests from the own points j
                            with only[j] (NULL: every one; auto's step
                            0 sweep: its sample's)                      */
} jf_part_query;

/* neighbors auto (src/robust/auto.c): turns o->nb = auto into knn:
 * JF_NB_AUTO_KMAX with params.auto_select = 1 (max_neighbors raised to
 * hold it); other kinds are left alone. */
void jf__nb_auto_opts(jf_estimate_opts *o);

/* Fills *q from estimate options as jf_estimate does.  JF_OK, or
 * JF_ERR_UNSUPPORTED (rings, natural: not a k-d tree query),
 * JF_ERR_INVALID (bad parameters). */
jf_status jf__part_query_init(const jf_estimate_opts *o, jf_part_query *q);

/* The checks every whole-cloud entry point makes once (parameters, size,
 * orientation against the cloud, rings against faces), with *use = *o and
 * its orient "auto" resolved (jf_orient_resolve).  Defined in
 * estimate/pipeline.c; used by estimate/parts_run.c. */
jf_status jf__estimate_check(const jf_cloud *c, const jf_estimate_opts *o, jf_estimate_opts *use,
                             jf_error *err);

/* Step 1 in one process: part[i] in 0..nparts-1 for each finite point,
 * -1 for the others.  Part r holds the finite points of ranks
 * [nf r / P, nf (r+1) / P) in the (Morton key, index) order (nf finite
 * points): balanced within one point; parts may be empty when nf < P.
 * JF_OK, JF_ERR_INVALID (nparts < 1 or > JF_PARTS_MAX), JF_ERR_NOMEM,
 * JF_ERR_TOO_LARGE (n >= 2^32 - 1). */
#define JF_PARTS_MAX 65536
jf_status jf__parts_split(const double *xyz, size_t n, int nparts, int32_t *part);

/* Step 1 without sorting the cloud (the bounded-memory estimate): the
 * (Morton key, index) order's quantiles of a sample of about
 * jf__parts_sample_size finite points (every stride-th in input order) cut it
 * into nparts runs; part[i] as jf__parts_split's, -1 for non-finite
 * points.  Parts are near equal, not exactly (the sample's error, about
 * sqrt(P / JF_PARTS_SAMPLE) of a part); memory: 16 bytes per sampled
 * point, not 12+ per point as the sort.  Same errors as jf__parts_split. */
/* A sampled point: its Morton key and input index, ordered by (key,
 * index) (jf__keyed_cmp, for qsort); jf__keyed_rank: how many of the
 * ncut sorted cuts are <= (key, id), the part of that point. */
typedef struct {
    uint64_t key;
    uint32_t id;
} jf__keyed;
int jf__keyed_cmp(const void *a, const void *b);
int32_t jf__keyed_rank(const jf__keyed *cut, int ncut, uint64_t key, uint32_t id);
#define JF_PARTS_SAMPLE ((size_t)1 << 16)
/* The sample's size for nf finite points: nf / 16, in 256..2^16. */
size_t jf__parts_sample_size(size_t nf);
jf_status jf__parts_split_sampled(const double *xyz, size_t n, int nparts, int threads,
                                  int32_t *part);

/* What the memory plan needs of an estimate's neighbourhood: fit_pt,
 * bytes more per fitted point (own and halo) while fitting (auto's step
 * 6 records: JF_PLAN_NJ_PT), fit_thread, bytes more per thread while
 * fitting (auto's walk: JF_PLAN_NJ_THREAD), and ball, the points a halo
 * request's ball holds on a surface (knn: K, raised to the largest
 * --scales entry; auto: (sqrt K + 2 sqrt m)^2, step 6's r_K + 2 r_m, m
 * jf__nj_reach's; 0: not known, radius kinds).  jf__plan_nb fills them
 * from the options (zeros when the parts cannot take them). */
typedef struct {
    size_t fit_pt, fit_thread;
    double ball;
} jf_plan_nb;
void jf__plan_nb(const jf_estimate_opts *o, jf_plan_nb *nb);

/* The memory plan of `jetfit estimate --memory SIZE` (docs/scale.md):
 * bytes per point measured with massif (tests/bench/bench_memory.sh).
 * held: what the caller holds whatever the plan (the cloud, the
 * summary's values); the plan adds the output's row spool
 * (jf__spool_bytes: nrows = n, ncols) and the writer's buffers for nt
 * threads.  The whole-cloud estimate
 * adds its k-d tree (copy of the points, indices, nodes); the parts add
 * part[] per point, two grids (jf__parts_grid_bits each), the sample,
 * and one part at a time: own and halo points (jf__plan_part_points)
 * with their coordinates, input index, mask and index (the own index
 * during the halo, the fit's after), nb->fit_pt more each while fitting,
 * and JF_PLAN_HALO_PT more a halo point while the halo is gathered (the
 * threads' lists, their merge and its sort).  nb may be NULL (knn:32's
 * ring).  Returns 1 (whole), P >= 2 parts, or 0 when even
 * min(JF_PLAN_PARTS_MAX, n / JF_PLAN_PART_MIN) parts (2 at least) do not fit; *need_whole, *need_min: the least
 * budget for the whole cloud and for any plan. */
#define JF_PLAN_WHOLE_PT 36
#define JF_PLAN_PART_PT 68
#define JF_PLAN_SPLIT_PT 4
#define JF_PLAN_HALO_PT 64
#define JF_PLAN_IMBALANCE 1.1  /* own points: the sample's quantiles, within 10% */
#define JF_PLAN_HALO 0.2       /* halo points / own points, at least      */
#define JF_PLAN_RING 24.0      /* ... and RING sqrt(ball / own points): the
                                  ring about a part of a surface, as the
                                  halo grid's cells take it; the largest
                                  part's, on tori and sheets of 2*10^4 to
                                  10^6 points cut in 4 to 32, at most 6 to
                                  23 (docs/scale.md)                      */
#define JF_PLAN_NJ_PT 17       /* auto: step 6's record and state per point
                                  (robust/neigh_jets.h): fit_pt          */
#define JF_PLAN_NJ_THREAD (5120u << 10) /* auto: a thread's rows in hand
                                  (a unit and twice as many waiting:
                                  224-byte rows, 32 nearest each, decoded
                                  records; about 4.8 MiB, walk.c):
                                  fit_thread */
#define JF_PLAN_PARTS_MAX 32   /* each part scans the cloud three times */
#define JF_PLAN_PART_MIN 1024  /* points: a part's fixed costs (threads,
                                  workspaces, grids) stay small          */
int jf__parts_plan(size_t n, size_t held, size_t ncols, int nt, const jf_plan_nb *nb,
                   size_t budget, size_t *need_whole, size_t *need_min);

/* The most own and halo points the plan holds for one of P parts of n
 * points (at most n; nb as jf__parts_plan's). */
double jf__plan_part_points(size_t n, int P, const jf_plan_nb *nb);

/* Where the bounded-memory estimate reads the coordinates (issue 28): an
 * array in memory, or the rows of the input file itself (a binary PLY or
 * LAS file's fixed-size rows, decoded by jf__layout_rows exactly as the
 * reader decodes them), read a chunk at a time on every scan, so that the
 * cloud's coordinates are never held (24 bytes a point). */
typedef struct {
    const double *xyz;      /* in memory: 3n coordinates; NULL: on disk  */
    int fd;                 /* on disk: the input file, read by pread(2) */
    const jf_row_layout *l; /* ... its rows                              */
} jf_xyz_src;
#define JF_SRC_CHUNK 4096   /* points a thread reads at once from disk   */

/* A sink that also gets the points' coordinates (3m, as read). */
typedef jf_status (*jf__block_xyz_fn)(void *user, const uint32_t *idx, const double *xyz,
                                      jf_result *res, size_t m);

/* jf_estimate_parts over n points whose coordinates come from src (c
 * gives n and what stays in memory: normals, scan ids; c->xyz unused).
 * The same rows as jf_estimate_parts, bit for bit.  Besides its errors:
 * JF_ERR_IO with err "read failed at vertex R: reason" when the
 * file cannot be read.  Memory beyond jf_estimate_parts's per part:
 * threads x JF_SRC_CHUNK x (24 + row) bytes of read buffers. */
jf_status jf__estimate_parts_src(const jf_cloud *c, const jf_xyz_src *src,
                                 const jf_estimate_opts *o, int nparts, jf__block_xyz_fn sink,
                                 void *user, jf_error *err);

/* jf__parts_plan's parts for an estimate whose coordinates stay on disk
 * (held: without them; the read buffers added here): P >= 2, or 0 when
 * even the most parts do not fit; *need_min as jf__parts_plan's. */
int jf__parts_plan_ooc(size_t n, size_t held, size_t ncols, int nt, const jf_plan_nb *nb, size_t row,
                       size_t budget, size_t *need_min);

/* --memory's check before the input is read (jetfit estimate): for a
 * binary PLY or LAS input (in_fmt NULL, path ending .ply or .las), whose
 * header gives the point count, the least budget the run can take -- the
 * coordinates, normals and (cond_held) the summary's condition numbers
 * at least -- against `budget` bytes.  JF_MEMCHK_OOC: the coordinates do
 * not fit but the binary PLY can be read from the file as needed (not
 * for a LAS or LAZ output, whose frame takes them all: out_fmt, else out's
 * ending); *l its rows.  JF_MEMCHK_REFUSED: too small, with r's figures.
 * JF_MEMCHK_OK otherwise (fits; budget 0; not kd; another input; a header
 * the reader will name).  Reads the file's first 64 KiB; prints nothing. */
typedef struct {
    size_t n;        /* the points the header announces                   */
    size_t need_min; /* refused: the least budget that works              */
    size_t held;     /* refused: what the run holds beside the parts      */
    int ooc;         /* refused: that least reads the coordinates from the file */
} jf_memchk;
enum { JF_MEMCHK_OK = 0, JF_MEMCHK_REFUSED = 1, JF_MEMCHK_OOC = 2 };
int jf__memory_precheck(const char *in, const char *in_fmt, size_t budget, int cond_held,
                        size_t ncols, int threads, int kd, const jf_plan_nb *nb, int keep, const char *out,
                        const char *out_fmt, jf_row_layout *l, jf_memchk *r);

/* Bits of the parts' occupancy and halo grids for n points (<= 2^26). */
size_t jf__parts_grid_bits(size_t n);

/* Squared distance from q to the box, a lower bound of the distance to
 * every point inside computed by the same rounded operations (never
 * larger: a part is skipped only if none of its points can qualify).
 * +inf for an empty box (lo > hi). */
double jf__box_dist2(const double box[6], const double q[3]);

/* A request a point sends to the other parts. */
typedef struct {
    size_t k;     /* the answer: the k nearest ...                      */
    double bound; /* ... within squared distance <= bound (may be inf)  */
} jf_halo_req;

/* Step 2 for a point q of a part indexed by `own` (its own points only):
 * fills req[0..] and returns their number (1 or 2; 0 if q is not
 * finite).  idx, d2: scratch of max(q->cap, q->min_count) entries.
 * knn K: (K, the K-th own distance, or inf if the part has fewer).
 * radius R: (cap, R^2 tightened likewise).  knn+radius: (K, R^2
 * tightened) and, when fewer than the floor own points lie within R,
 * (floor, inf tightened) for the fallback query.  Exact: every point of
 * another part that is in q's neighbourhood over the whole cloud is in
 * its part's answer to one of the requests (the own k-th distance bounds
 * the whole cloud's).  Thread-safe. */
int jf__halo_requests(const jf_index *own, const jf_part_query *q, const double p[3],
                      uint32_t *idx, double *d2, jf_halo_req req[2]);

/* jf__halo_requests, or 0 requests when (knn only) no other part can
 * hold one of p's k nearest: p's own k-th distance is at most last[3] +
 * |p - last| (last: the point queried before on this thread, last[3] its
 * own k-th distance; start with last[3] = inf), and every box but
 * boxes[self] (nboxes of them, 6 doubles each) lies strictly farther
 * (a 1e-9 margin for the roundings).  Walked in space order, interior
 * points skip their query.  last is updated when p is queried. */
int jf__halo_requests_near(const jf_index *own, const jf_part_query *q, const double *boxes,
                           int nboxes, int self, const double p[3], double last[4],
                           uint32_t *idx, double *d2, jf_halo_req req[2]);

/* A candidate of a request: squared distance, input index, and whether
 * it came from another part.  jf__halo_cmp orders by (d2, index), the
 * k-d tree's order: a request's neighbourhood is the first k of its
 * merged candidates. */
typedef struct {
    double d2;
    uint32_t id;
    uint32_t remote;
} jf_halo_cand;
int jf__halo_cmp(const void *a, const void *b);

typedef struct {
    size_t requests; /* (point, part) requests sent                      */
    size_t fetched;  /* distinct candidates the answers carried, summed
                        over the parts (what a distributed run sends)    */
} jf_halo_stats;

/* Steps 2-3 for every part in one process (a reference, for the tests and
 * the halo figures, and for parts processed one at a time): halo_off[
 * nparts + 1] (caller-owned) and *halo (malloc'ed, caller frees) list,
 * for part a, the input indices of the points of other parts that are in
 * the neighbourhood of one of its points, ascending, at halo[halo_off[a]
 * .. halo_off[a+1]): each request's answers are merged with the own
 * candidates and only the first k kept, so a part whose points are far
 * from each other (a Z-curve run may be in two pieces) keeps no more than
 * its points' real neighbours.  stats may be NULL.  threads <= 0: all
 * cores.  JF_OK, JF_ERR_INVALID, JF_ERR_NOMEM. */
jf_status jf__parts_halos(const double *xyz, size_t n, const int32_t *part, int nparts,
                          const jf_part_query *q, int threads, size_t *halo_off,
                          uint32_t **halo, jf_halo_stats *stats);

/* jf_estimate on c fitting only the points with fit[i] != 0 (fit NULL:
 * all); the others get a NONFINITE row (NaN, left alone by the
 * orientation) and are still neighbours.  Defined in estimate/pipeline.c. */
jf_status jf__estimate_masked(const jf_cloud *c, const jf_estimate_opts *o,
                              const uint8_t *fit, jf_result *out, jf_error *err);

/* jf_estimate_blocks handing the sink each block's coordinates too (the
 * walk's, bit for bit those of c->xyz), so that it need not read them
 * by input index.  Defined in estimate/pipeline.c. */
jf_status jf__estimate_blocks_xyz(const jf_cloud *c, const jf_estimate_opts *o,
                                  jf__block_xyz_fn sink, void *user, jf_error *err);

/* jf_estimate_blocks with the same mask (only the points with fit[i] !=
 * 0 are fitted and handed to the sink; the halo points are neighbours
 * only), handing the sink each block's coordinates (the
 * bounded-memory estimate's parts need not gather them by index). */
jf_status jf__estimate_blocks_masked_xyz(const jf_cloud *c, const jf_estimate_opts *o,
                                         const uint8_t *fit, jf__block_xyz_fn sink, void *user,
                                         jf_error *err);

/* Room for one more element in a growable array v of *cap elements of
 * size elem holding n: v, or v moved with *cap doubled (first 1024) when
 * full; NULL out of memory (v still valid, *cap unchanged). */
void *jf__grow(void *v, size_t *cap, size_t n, size_t elem);

#endif /* JF_PARTS_H */
