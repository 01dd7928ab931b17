/* mpi_dist.c -- one rank's share of a distributed estimate: its byte range
 * of the input, its part of the cloud and the part's halo (parts.h).
 *
 * design (every step collective, checked by jf_mpi_check before the next):
 *  1. read: rank r decodes rows [N r / P, N (r+1) / P) of the binary PLY
 *     (pread at their offsets: no rank reads the whole file);
 *  2. partition (parts.h's, distributed): the global bounding box of the
 *     finite points (allreduce), Morton keys, a sample sort on (key, input
 *     index) -- local radix sort, regular samples allgathered, P-1 splitters,
 *     all-to-all -- then a second all-to-all by global rank in that order,
 *     so part r holds exactly the ranks [nf r / P, nf (r+1) / P) (balanced
 *     within one point, whatever the splitters were);
 *  3. halo: each own point's requests (jf__halo_requests_near over the
 *     own k-d tree, in space order: interior knn points need none) go to
 *     the ranks whose part's box is within their bound;
 *     each rank answers with its top k within the bound; the requester
 *     merges each request's answers with its own candidates in the
 *     (d2, index) order and keeps the first k: the remote points kept are
 *     the halo.  One round is exact (parts.c says why).
 * Non-finite points stay on the rank that read them (nobody's neighbour;
 * the pipeline gives them their NaN row). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <omp.h>

#include "index_internal.h"
#include "mpi_internal.h"

int jf_mpi_fail(jf_mpi *m, const char *fmt, ...)
{
    if (m->failed) return 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->msg, sizeof m->msg, fmt, ap);
    va_end(ap);
    m->failed = 1;
    return 1;
}

int jf_mpi_check(jf_mpi *m)
{
    int me = m->failed ? m->rank : m->size, first = m->size;
    MPI_Allreduce(&me, &first, 1, MPI_INT, MPI_MIN, m->comm);
    if (first == m->size) return 0;
    if (first == m->rank) {
        fprintf(stderr, "jetfit-mpi: %s\n", m->msg);
        fflush(stderr);
    }
    m->failed = 1;
    return 1;
}

void jf_mpi_cloud_free(jf_mpi_cloud *c)
{
    free(c->xyz);
    free(c->nrm);
    free(c->gid);
    free(c->own);
    memset(c, 0, sizeof *c);
}

static int finite3(const double *p)
{
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

/* pread all of [buf, buf + len) from offset at. */
static int read_at(int fd, void *buf, size_t len, uint64_t at)
{
    char *p = buf;
    while (len) {
        ssize_t k = pread(fd, p, len, (off_t)at);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) return -1;
        p += k;
        len -= (size_t)k;
        at += (uint64_t)k;
    }
    return 0;
}

void jf_mpi_probe(jf_mpi *m, const char *path, jf_row_layout *l)
{
    memset(l, 0, sizeof *l);
    int fd = open(path, O_RDONLY);
    if (fd < 0) {
        jf_mpi_fail(m, "%s: %s", path, strerror(errno));
        return;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        jf_mpi_fail(m, "%s: not a regular file", path);
        close(fd);
        return;
    }
    size_t len = (uint64_t)sb.st_size < (1u << 20) ? (size_t)sb.st_size : (1u << 20);
    char *buf = malloc(len ? len : 1);
    jf_error err = {{0}};
    if (!buf) jf_mpi_fail(m, "out of memory");
    else if (read_at(fd, buf, len, 0)) jf_mpi_fail(m, "%s: %s", path, strerror(errno));
    else if (len > 104 && !memcmp(buf, "LASF", 4) && (buf[104] & 0xC0)) {
        /* LAZ: every rank holds the compressed file and decodes the chunks
         * of its rows (io_laz.c); the layout is the plain LAS file's */
        char *all = (uint64_t)sb.st_size > SIZE_MAX ? NULL : malloc((size_t)sb.st_size);
        size_t hl;
        uint64_t n;
        unsigned rl;
        if (!all) jf_mpi_fail(m, "%s: out of memory for the compressed file", path);
        else if (read_at(fd, all, (size_t)sb.st_size, 0)) {
            jf_mpi_fail(m, "%s: %s", path, strerror(errno));
            free(all);
        } else if (jf__laz_open_owned(all, (size_t)sb.st_size, path, &l->laz, &err) != JF_OK)
            jf_mpi_fail(m, "%s", err.msg);
        else {
            const unsigned char *h = jf__laz_head(l->laz, &hl, &n, &rl);
            jf_laz *z = l->laz;
            if (jf__las_layout((const char *)h, hl, hl + n * rl, path, l, &err) != JF_OK)
                jf_mpi_fail(m, "%s", err.msg);
            l->laz = z;
        }
    } else if ((jf_format_from_path(path) == JF_FMT_LAS ? jf__las_layout : jf__ply_layout)(
                 buf, len, (uint64_t)sb.st_size, path, l, &err) != JF_OK)
        jf_mpi_fail(m, "%s", err.msg);
    free(buf);
    close(fd);
}

/* ---- records exchanged ------------------------------------------------- */

typedef struct { /* a point on its way to its part */
    uint64_t key;
    uint32_t gid, pad;
    double xyz[3];
    double nrm[3];
} prec;

typedef struct { /* a halo request */
    double q[3];
    double bound;
    uint64_t k;
    uint32_t id; /* 2 * own point + request number */
    uint32_t pad;
} qrec;

typedef struct { /* one point of an answer */
    uint32_t id, gid;
    double d2;
    double xyz[3];
} arec;

/* Sorts *pp[0..n) by (key, gid), or by gid alone: jf__radix_sort of the
 * positions by gid, then (stable) by key, and one gather into a new
 * array, its loads independent of each other (qsort moved the 64-byte
 * records log n times).  0: no memory (*pp unchanged). */
static int sort_precs(prec **pp, size_t n, int by_key)
{
    if (n < 2) return 1;
    prec *p = *pp;
    uint64_t *key = malloc(2 * n * sizeof *key);
    uint32_t *ord = malloc(2 * n * sizeof *ord);
    if (!key || !ord) {
        free(key), free(ord);
        return 0;
    }
    for (size_t i = 0; i < n; i++) key[i] = p[i].gid, ord[i] = (uint32_t)i;
    jf__radix_sort(key, ord, n, 32, key + n, ord + n);
    if (by_key) {
        for (size_t i = 0; i < n; i++) key[i] = p[ord[i]].key;
        jf__radix_sort(key, ord, n, 64, key + n, ord + n);
    }
    free(key);
    prec *out = malloc(n * sizeof *out);
    if (!out) {
        free(ord);
        return 0;
    }
    for (size_t i = 0; i < n; i++) out[i] = p[ord[i]];
    free(ord), free(p);
    *pp = out;
    return 1;
}

static int cmp_pair(const void *a, const void *b)
{
    const uint64_t *x = a, *y = b;
    if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
    return (x[1] > y[1]) - (x[1] < y[1]);
}

static int cmp_answer(const void *a, const void *b)
{
    const arec *x = a, *y = b;
    if (x->id != y->id) return x->id < y->id ? -1 : 1;
    if (x->d2 != y->d2) return x->d2 < y->d2 ? -1 : 1;
    return (x->gid > y->gid) - (x->gid < y->gid);
}

/* All-to-all of records of `size` bytes: send[displs by scount] to every
 * rank; *recv (malloc'ed) gets *nrecv records.  0, or -1 (no memory:
 * recorded in m; the collective calls are still made). */
static int exchange(jf_mpi *m, const void *send, const int *scount, size_t size, void **recv,
                    size_t *nrecv)
{
    const int P = m->size;
    int *rcount = calloc((size_t)P, sizeof *rcount), *sd = calloc((size_t)P, sizeof *sd),
        *rd = calloc((size_t)P, sizeof *rd);
    int ok = rcount && sd && rd;
    if (!ok) jf_mpi_fail(m, "out of memory (exchange)");
    if (jf_mpi_check(m)) {
        free(rcount);
        free(sd);
        free(rd);
        return -1;
    }
    MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, m->comm);
    size_t ns = 0, nr = 0;
    for (int r = 0; r < P; r++) {
        if (ns > INT32_MAX || nr > INT32_MAX) ok = 0;
        sd[r] = (int)ns;
        rd[r] = (int)nr;
        ns += (size_t)scount[r];
        nr += (size_t)rcount[r];
    }
    *recv = malloc((nr ? nr : 1) * size);
    if (!ok) jf_mpi_fail(m, "more than 2^31 records to exchange with one rank: use more ranks");
    else if (!*recv) jf_mpi_fail(m, "out of memory (%zu records received)", nr);
    if (jf_mpi_check(m)) {
        free(*recv);
        *recv = NULL;
        free(rcount);
        free(sd);
        free(rd);
        return -1;
    }
    MPI_Datatype t;
    MPI_Type_contiguous((int)size, MPI_BYTE, &t);
    MPI_Type_commit(&t);
    MPI_Alltoallv(send, scount, sd, t, *recv, rcount, rd, t, m->comm);
    MPI_Type_free(&t);
    *nrecv = nr;
    free(rcount);
    free(sd);
    free(rd);
    return 0;
}

/* First rank of the part holding global position pos (parts.h's cut). */
static int owner(uint64_t pos, uint64_t nf, int P)
{
    int r = (int)((pos * (uint64_t)P) / nf);
    while (r + 1 < P && (nf * (uint64_t)(r + 1)) / (uint64_t)P <= pos) r++;
    while (r > 0 && (nf * (uint64_t)r) / (uint64_t)P > pos) r--;
    return r;
}

/* ---- step 1 and 2: read, partition -------------------------------------- */

/* Reads this rank's rows into *pts (finite, keyed) and *bad (non-finite). */
static void read_rows(jf_mpi *m, const char *path, const jf_row_layout *l, int normals,
                      prec **pts, size_t *npts, prec **bad, size_t *nbad)
{
    const uint64_t N = l->count, first = N * (uint64_t)m->rank / (uint64_t)m->size,
                   cnt = N * (uint64_t)(m->rank + 1) / (uint64_t)m->size - first;
    enum { CHUNK = 1 << 16 };
    unsigned char *raw = malloc(CHUNK * l->row + 1);
    double *xyz = malloc(3 * CHUNK * sizeof *xyz), *nrm = malloc(3 * CHUNK * sizeof *nrm);
    *pts = malloc((cnt ? cnt : 1) * sizeof **pts);
    *npts = *nbad = 0;
    *bad = NULL;
    size_t badcap = 0;
    int fd = open(path, O_RDONLY);
    if (!raw || !xyz || !nrm || !*pts) jf_mpi_fail(m, "out of memory (%llu rows)",
                                                   (unsigned long long)cnt);
    else if (fd < 0) jf_mpi_fail(m, "%s: %s", path, strerror(errno));
    for (uint64_t r0 = 0; !m->failed && r0 < cnt; r0 += CHUNK) {
        size_t k = cnt - r0 < CHUNK ? (size_t)(cnt - r0) : CHUNK;
        jf_error e = {{0}};
        if (l->laz && jf__laz_rows(l->laz, first + r0, k, (char *)raw, &e) != JF_OK) {
            jf_mpi_fail(m, "%s", e.msg);
            break;
        }
        if (!l->laz && read_at(fd, raw, k * l->row, l->vertex_off + (first + r0) * l->row)) {
            jf_mpi_fail(m, "%s: cannot read element vertex %llu..%llu (%s)", path,
                        (unsigned long long)(first + r0), (unsigned long long)(first + r0 + k),
                        errno ? strerror(errno) : "file shorter than its header says");
            break;
        }
        jf__layout_rows(raw, k, l, xyz, normals ? nrm : NULL);
        for (size_t j = 0; j < k; j++) {
            prec p = {0, (uint32_t)(first + r0 + j), 0, {0}, {0}};
            memcpy(p.xyz, xyz + 3 * j, sizeof p.xyz);
            if (normals) memcpy(p.nrm, nrm + 3 * j, sizeof p.nrm);
            if (finite3(p.xyz)) {
                (*pts)[(*npts)++] = p;
                continue;
            }
            if (*nbad == badcap) {
                size_t nc = badcap ? 2 * badcap : 256;
                prec *nb = realloc(*bad, nc * sizeof *nb);
                if (!nb) {
                    jf_mpi_fail(m, "out of memory");
                    break;
                }
                *bad = nb;
                badcap = nc;
            }
            (*bad)[(*nbad)++] = p;
        }
    }
    if (fd >= 0) close(fd);
    free(raw);
    free(xyz);
    free(nrm);
}

/* Sample sort + rebalance: *pts becomes this rank's part, by input index. */
static void partition(jf_mpi *m, prec **pts, size_t *npts)
{
    const int P = m->size;
    /* global bounding box and count of the finite points */
    double box[6], lbox[6], red[6], lred[6];
    double *tmp = malloc((*npts ? *npts : 1) * 3 * sizeof *tmp);
    if (!tmp) jf_mpi_fail(m, "out of memory");
    if (jf_mpi_check(m)) return;
    for (size_t i = 0; i < *npts; i++) memcpy(tmp + 3 * i, (*pts)[i].xyz, sizeof(double[3]));
    jf__parts_bbox(tmp, *npts, lbox);
    free(tmp);
    for (int d = 0; d < 3; d++) {
        lred[d] = lbox[d];
        lred[3 + d] = -lbox[3 + d];
    }
    MPI_Allreduce(lred, red, 6, MPI_DOUBLE, MPI_MIN, m->comm);
    for (int d = 0; d < 3; d++) {
        box[d] = red[d];
        box[3 + d] = -red[3 + d];
    }
    uint64_t nloc = *npts, nf = 0;
    MPI_Allreduce(&nloc, &nf, 1, MPI_UINT64_T, MPI_SUM, m->comm);
    if (!nf) return; /* no finite point anywhere: every part is empty */
    const double scale = jf__morton_scale(box);
    for (size_t i = 0; i < *npts; i++)
        (*pts)[i].key = jf__morton_key((*pts)[i].xyz, box, scale);
    if (!sort_precs(pts, *npts, 1)) jf_mpi_fail(m, "out of memory (sort)");

    /* regular samples -> P-1 splitters */
    int ns = (int)(*npts < (size_t)(16 * P) ? *npts : (size_t)(16 * P)), tot = 0;
    int *cnt = calloc((size_t)P, sizeof *cnt), *dsp = calloc((size_t)P, sizeof *dsp);
    uint64_t *smp = malloc(2 * (size_t)(ns ? ns : 1) * sizeof *smp), *all = NULL;
    if (!cnt || !dsp || !smp) jf_mpi_fail(m, "out of memory");
    if (jf_mpi_check(m)) goto out;
    for (int j = 0; j < ns; j++) {
        const prec *p = &(*pts)[((size_t)j * *npts) / (size_t)ns];
        smp[2 * j] = p->key;
        smp[2 * j + 1] = p->gid;
    }
    int ns2 = 2 * ns;
    MPI_Allgather(&ns2, 1, MPI_INT, cnt, 1, MPI_INT, m->comm);
    for (int r = 0; r < P; r++) {
        dsp[r] = tot;
        tot += cnt[r];
    }
    all = malloc((size_t)(tot ? tot : 1) * sizeof *all);
    if (!all) jf_mpi_fail(m, "out of memory");
    if (jf_mpi_check(m)) goto out;
    MPI_Allgatherv(smp, ns2, MPI_UINT64_T, all, cnt, dsp, MPI_UINT64_T, m->comm);
    qsort(all, (size_t)tot / 2, 2 * sizeof *all, cmp_pair);
    {
        /* splitter j = sample ((j+1) S / P): send each point to the number
         * of splitters not above it */
        size_t S = (size_t)tot / 2;
        int *scount = cnt; /* reused */
        for (int r = 0; r < P; r++) scount[r] = 0;
        int dest = 0;
        for (size_t i = 0; i < *npts; i++) {
            const prec *p = &(*pts)[i];
            while (dest < P - 1) {
                const uint64_t *s = all + 2 * (((size_t)(dest + 1) * S) / (size_t)P);
                if (p->key < s[0] || (p->key == s[0] && p->gid < s[1])) break;
                dest++;
            }
            scount[dest]++;
        }
        prec *got = NULL;
        size_t ngot = 0;
        if (exchange(m, *pts, scount, sizeof(prec), (void **)&got, &ngot)) goto out;
        free(*pts);
        *pts = got;
        *npts = ngot;
        if (!sort_precs(pts, *npts, 1)) jf_mpi_fail(m, "out of memory (sort)");
        if (jf_mpi_check(m)) goto out;

        /* rebalance: global position in the (key, index) order -> part */
        uint64_t mine = *npts, off = 0;
        MPI_Exscan(&mine, &off, 1, MPI_UINT64_T, MPI_SUM, m->comm);
        if (m->rank == 0) off = 0;
        for (int r = 0; r < P; r++) scount[r] = 0;
        for (size_t i = 0; i < *npts; i++) scount[owner(off + i, nf, P)]++;
        if (exchange(m, *pts, scount, sizeof(prec), (void **)&got, &ngot)) goto out;
        free(*pts);
        *pts = got;
        *npts = ngot;
    }
    if (!sort_precs(pts, *npts, 0)) jf_mpi_fail(m, "out of memory (sort)");
out:
    free(cnt);
    free(dsp);
    free(smp);
    free(all);
}

/* ---- step 3: the halo ---------------------------------------------------- */

typedef struct {
    uint32_t gid;
    double xyz[3];
} hpt;

static int cmp_hpt(const void *a, const void *b)
{
    const hpt *x = a, *y = b;
    return (x->gid > y->gid) - (x->gid < y->gid);
}

/* Appends (gid, xyz) to the halo list *v (*n of *cap); 0 when out of
 * memory (the rank failed). */
static int hpt_push(jf_mpi *m, hpt **v, size_t *n, size_t *cap, uint32_t gid, const double *xyz)
{
    if (*n == *cap) {
        size_t nc = *cap ? 2 * *cap : 1024;
        hpt *nh = realloc(*v, nc * sizeof *nh);
        if (!nh) {
            jf_mpi_fail(m, "out of memory");
            return 0;
        }
        *v = nh;
        *cap = nc;
    }
    (*v)[*n].gid = gid;
    memcpy((*v)[*n].xyz, xyz, sizeof(double[3]));
    (*n)++;
    return 1;
}

/* The halo of this rank's part (own: its points, by input index). */
static void fetch_halo(jf_mpi *m, const prec *own, size_t nown, const jf_part_query *q,
                       int threads, hpt **halo, size_t *nhalo, size_t *fetched)
{
    const int P = m->size;
    const size_t scratch = (q->cap > q->min_count ? q->cap : q->min_count) + 1;
    double lbox[6], *boxes = malloc(6 * (size_t)P * sizeof *boxes);
    double *xo = malloc((nown ? nown : 1) * 3 * sizeof *xo);
    jf_halo_req *rq = malloc((nown ? nown : 1) * 2 * sizeof *rq);
    uint8_t *nrq = malloc(nown ? nown : 1);
    uint32_t *ord = malloc((nown ? nown : 1) * sizeof *ord); /* space order */
    int *scount = calloc((size_t)P, sizeof *scount), *at = calloc((size_t)P, sizeof *at);
    jf_index *ix = NULL;
    qrec *qs = NULL, *qr = NULL;
    arec *ans = NULL, *back = NULL;
    jf_halo_cand *mc = NULL;
    uint32_t *idx = malloc(scratch * sizeof *idx);
    double *d2 = malloc(scratch * sizeof *d2), *xs = malloc(3 * scratch * sizeof *xs);
    size_t nqr = 0, nback = 0, nans = 0;
    *halo = NULL;
    *nhalo = *fetched = 0;
    if (!boxes || !xo || !rq || !nrq || !ord || !scount || !at || !idx || !d2 || !xs)
        jf_mpi_fail(m, "out of memory (halo)");
    else {
        for (size_t i = 0; i < nown; i++) memcpy(xo + 3 * i, own[i].xyz, sizeof(double[3]));
        jf__parts_bbox(xo, nown, lbox);
        if (jf__index_build_threads(xo, nown, threads, &ix) != JF_OK ||
            (nown && jf_spatial_order(xo, nown, ord) != JF_OK))
            jf_mpi_fail(m, "out of memory (k-d tree of %zu points)", nown);
    }
    if (jf_mpi_check(m)) goto out;
    MPI_Allgather(lbox, 6, MPI_DOUBLE, boxes, 6, MPI_DOUBLE, m->comm);

    /* each own point's requests, then where they go */
    int ok = 1;
#pragma omp parallel num_threads(threads > 0 ? threads : jf_default_threads(NULL)) reduction(&& : ok)
    {
        uint32_t *ti = malloc(scratch * sizeof *ti);
        double *td = malloc(scratch * sizeof *td);
        double last[4] = {0, 0, 0, INFINITY};
        ok = ti && td;
#pragma omp for schedule(dynamic, 1024)
        for (size_t j = 0; j < nown; j++) {
            const size_t i = ord[j];
            nrq[i] = ok ? (uint8_t)jf__halo_requests_near(ix, q, boxes, P, m->rank, own[i].xyz,
                                                          last, ti, td, rq + 2 * i)
                        : 0;
        }
        free(ti);
        free(td);
    }
    /* an empty part's box (lo > hi) is at NaN: never asked */
    size_t nq = 0;
    for (size_t i = 0; i < nown; i++)
        for (int r = 0; r < nrq[i]; r++)
            for (int b = 0; b < P; b++)
                if (b != m->rank && jf__box_dist2(boxes + 6 * b, own[i].xyz) <= rq[2 * i + r].bound) {
                    scount[b]++;
                    nq++;
                }
    qs = malloc((nq ? nq : 1) * sizeof *qs);
    if (!ok || !qs) jf_mpi_fail(m, "out of memory (halo requests)");
    else {
        for (int b = 1; b < P; b++) at[b] = at[b - 1] + scount[b - 1];
        for (size_t i = 0; i < nown; i++)
            for (int r = 0; r < nrq[i]; r++)
                for (int b = 0; b < P; b++)
                    if (b != m->rank &&
                        jf__box_dist2(boxes + 6 * b, own[i].xyz) <= rq[2 * i + r].bound) {
                        qrec *o = &qs[at[b]++];
                        memcpy(o->q, own[i].xyz, sizeof o->q);
                        o->bound = rq[2 * i + r].bound;
                        o->k = rq[2 * i + r].k;
                        o->id = (uint32_t)(2 * i + (size_t)r);
                        o->pad = 0;
                    }
    }
    if (exchange(m, qs, scount, sizeof *qs, (void **)&qr, &nqr)) goto out;

    /* answer: our top k within each bound; per source rank, in order */
    {
        int *rcount = calloc((size_t)P, sizeof *rcount);
        int *acount = scount; /* reused: answers per source */
        size_t cap = 0;
        /* auto's balls overlap (one per border point, each ~3 K points):
         * each own point goes to a source once, stamped with it (a 10^5
         * torus on 2 ranks fetched 28 times the cloud before) */
        uint32_t *sent = q->nj ? calloc(nown ? nown : 1, sizeof *sent) : NULL;
        if (!rcount || (q->nj && !sent)) jf_mpi_fail(m, "out of memory");
        if (jf_mpi_check(m)) {
            free(rcount);
            free(sent);
            goto out;
        }
        MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, m->comm); /* requests per source */
        size_t k0 = 0;
        for (int s = 0; s < P && !m->failed; s++) {
            acount[s] = 0;
            for (int j = 0; j < rcount[s] && !m->failed; j++) {
                const qrec *r = &qr[k0 + (size_t)j];
                size_t found = 0;
                size_t k = r->k < scratch ? (size_t)r->k : scratch;
                if (q->nj) { /* auto's step 6: the whole ball (parts.c) */
                    for (;;) {
                        if (jf__index_query(ix, r->q, k, r->bound, idx, d2, NULL, &found) != JF_OK ||
                            found < k)
                            break;
                        k *= 2;
                        uint32_t *ni = realloc(idx, k * sizeof *idx);
                        if (ni) idx = ni;
                        double *nd = realloc(d2, k * sizeof *d2), *nx = NULL;
                        if (nd) d2 = nd, nx = realloc(xs, 3 * k * sizeof *xs);
                        if (nx) xs = nx;
                        if (!ni || !nd || !nx) {
                            jf_mpi_fail(m, "out of memory (halo answers)");
                            break;
                        }
                    }
                    if (m->failed) break;
                    k = found > 0 ? found : 1;
                }
                if (nans + k > cap) {
                    size_t nc = cap ? 2 * cap : 4096;
                    while (nc < nans + k) nc *= 2;
                    arec *na = realloc(ans, nc * sizeof *na);
                    if (!na) {
                        jf_mpi_fail(m, "out of memory (halo answers)");
                        break;
                    }
                    ans = na;
                    cap = nc;
                }
                if (jf__index_query(ix, r->q, k, r->bound, idx, d2, xs, &found) != JF_OK) {
                    jf_mpi_fail(m, "halo query failed");
                    break;
                }
                size_t put = 0;
                for (size_t t = 0; t < found; t++) {
                    if (sent) {
                        if (sent[idx[t]] == (uint32_t)s + 1) continue;
                        sent[idx[t]] = (uint32_t)s + 1;
                    }
                    arec *a = &ans[nans++];
                    a->id = r->id;
                    a->gid = own[idx[t]].gid;
                    a->d2 = d2[t];
                    memcpy(a->xyz, xs + 3 * t, sizeof a->xyz);
                    put++;
                }
                acount[s] += (int)put;
            }
            k0 += (size_t)rcount[s];
        }
        free(rcount);
        free(sent);
    }
    if (exchange(m, ans, scount, sizeof *ans, (void **)&back, &nback)) goto out;
    *fetched = nback;

    /* merge each request's answers with the own candidates; keep k */
    qsort(back, nback, sizeof *back, cmp_answer);
    {
        size_t mcap = 0, hcap = 0;
        for (size_t g = 0; g < nback && !m->failed;) {
            size_t e = g;
            while (e < nback && back[e].id == back[g].id) e++;
            const jf_halo_req *r = &rq[back[g].id];
            size_t found = 0;
            size_t k = r->k < scratch ? r->k : scratch;
            if (q->nj) { /* auto's step 6: every answer is in the ball */
                for (size_t t = g; t < e && hpt_push(m, halo, nhalo, &hcap, back[t].gid, back[t].xyz);)
                    t++;
                g = e;
                continue;
            }
            if (jf__index_query(ix, own[back[g].id / 2].xyz, k, r->bound, idx, d2, NULL, &found) !=
                JF_OK) {
                jf_mpi_fail(m, "halo query failed");
                break;
            }
            size_t need = found + (e - g);
            if (need > mcap) {
                jf_halo_cand *nm = realloc(mc, need * sizeof *nm);
                if (!nm) {
                    jf_mpi_fail(m, "out of memory");
                    break;
                }
                mc = nm;
                mcap = need;
            }
            size_t mn = 0;
            for (size_t t = 0; t < found; t++)
                mc[mn++] = (jf_halo_cand){d2[t], own[idx[t]].gid, 0};
            for (size_t t = g; t < e; t++)
                mc[mn++] = (jf_halo_cand){back[t].d2, back[t].gid, (uint32_t)(t - g + 1)};
            qsort(mc, mn, sizeof *mc, jf__halo_cmp);
            for (size_t t = 0; t < mn && t < r->k; t++) {
                if (!mc[t].remote) continue;
                const arec *a = &back[g + mc[t].remote - 1];
                if (!hpt_push(m, halo, nhalo, &hcap, a->gid, a->xyz)) break;
            }
            g = e;
        }
    }
    if (*halo) {
        qsort(*halo, *nhalo, sizeof **halo, cmp_hpt);
        size_t w = 0;
        for (size_t j = 0; j < *nhalo; j++)
            if (!w || (*halo)[j].gid != (*halo)[w - 1].gid) (*halo)[w++] = (*halo)[j];
        *nhalo = w;
    }
out:
    jf_index_free(ix);
    free(boxes);
    free(xo);
    free(rq);
    free(nrq);
    free(ord);
    free(scount);
    free(at);
    free(qs);
    free(qr);
    free(ans);
    free(back);
    free(mc);
    free(idx);
    free(d2);
    free(xs);
}

/* ---- the whole load ------------------------------------------------------ */

void jf_mpi_load(jf_mpi *m, const char *path, const jf_row_layout *l, const jf_part_query *q,
                 int normals, int threads, jf_mpi_cloud *c)
{
    memset(c, 0, sizeof *c);
    c->total = l->count;
    prec *pts = NULL, *bad = NULL;
    hpt *halo = NULL;
    size_t npts = 0, nbad = 0, nhalo = 0;
    read_rows(m, path, l, normals, &pts, &npts, &bad, &nbad);
    jf__laz_close(l->laz); /* LAZ: the rows are read */
    if (jf_mpi_check(m)) goto out;
    double t0 = MPI_Wtime();
    /* one rank: its rows are the whole cloud, read in input order */
    if (m->size > 1) {
        partition(m, &pts, &npts);
        if (jf_mpi_check(m)) goto out;
        fetch_halo(m, pts, npts, q, threads, &halo, &nhalo, &c->fetched);
        if (jf_mpi_check(m)) goto out;
    }
    m->t_exchange = MPI_Wtime() - t0;

    /* own, non-finite and halo points merged by input index */
    size_t n = npts + nbad + nhalo;
    c->xyz = malloc((n ? n : 1) * 3 * sizeof *c->xyz);
    c->nrm = normals ? calloc((n ? n : 1) * 3, sizeof *c->nrm) : NULL;
    c->gid = malloc((n ? n : 1) * sizeof *c->gid);
    c->own = malloc(n ? n : 1);
    if (!c->xyz || (normals && !c->nrm) || !c->gid || !c->own) {
        jf_mpi_fail(m, "out of memory (%zu local points)", n);
    } else {
        size_t a = 0, b = 0, h = 0;
        for (size_t j = 0; j < n; j++) {
            uint32_t ga = a < npts ? pts[a].gid : UINT32_MAX, gb = b < nbad ? bad[b].gid : UINT32_MAX,
                     gh = h < nhalo ? halo[h].gid : UINT32_MAX;
            const prec *p = NULL;
            if (ga <= gb && ga <= gh && a < npts) p = &pts[a++];
            else if (gb <= gh && b < nbad) p = &bad[b++];
            if (p) {
                memcpy(c->xyz + 3 * j, p->xyz, sizeof(double[3]));
                if (c->nrm) memcpy(c->nrm + 3 * j, p->nrm, sizeof(double[3]));
                c->gid[j] = p->gid;
                c->own[j] = 1;
            } else {
                memcpy(c->xyz + 3 * j, halo[h].xyz, sizeof(double[3]));
                c->gid[j] = halo[h++].gid;
                c->own[j] = 0;
            }
        }
        c->n = n;
        c->nown = npts + nbad;
        c->nhalo = nhalo;
    }
    jf_mpi_check(m);
out:
    free(pts);
    free(bad);
    free(halo);
}
