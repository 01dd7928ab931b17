/*
 * io_spool.c -- rows that arrive in any order, given back in row order
 * (the table writer's positioned rows, jf_writer_put; issue 12.1).
 *
 * design: a bucket sort through a temporary file beside the output.
 *  1. The nrows rows are cut into buckets of consecutive row numbers, each
 *     holding about BUCKET_BYTES of values (so one bucket fits in memory
 *     at the end).  Bucket b owns a fixed region of the spool file, sized
 *     for exactly its rows: an entry is the row number (8 bytes) and the
 *     row's ncols doubles.
 *  2. put: each row is appended to its bucket's staging buffer (one mutex
 *     per bucket: any thread may put); a full buffer goes to the bucket's
 *     region with one pwrite(2).  Writes are large and sequential within a
 *     region whatever the order the rows come in -- a row-per-pwrite
 *     scatter into the output instead costs a system call per row, and on
 *     a file larger than the page cache a disk read per row (the page
 *     must be read back before a partial write into it).
 *  3. drain: bucket after bucket, its region is read back in chunks and
 *     each entry copied to its row's place in a bucket-sized buffer; a row
 *     missing or given twice is an error; the buffer goes to the caller in
 *     row order (the writer formats it with jf_writer_rows, so the bytes
 *     are those of a whole-array write).
 * The spool is a jf_tmpfile: removed on failure, on free, and by a signal
 * handler (jf_tmpfiles_remove_all).  Memory: buckets x STAGE bytes of
 * staging plus one bucket's values during the drain.
 */
#define _POSIX_C_SOURCE 200809L
#include "io_internal.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define BUCKET_BYTES ((size_t)32 << 20) /* values of one bucket: 4x at most */
#define STAGE ((size_t)64 << 10)        /* staging bytes per bucket        */

typedef struct {
    pthread_mutex_t mu;
    char *stage;
    size_t used;       /* bytes staged                                  */
    size_t written;    /* bytes already in the region                   */
} bucket;

struct jf_spool {
    jf_tmpfile t;
    size_t nrows, ncols, entry, per, nb;   /* per: rows per bucket      */
    size_t stage;                          /* staging bytes per bucket  */
    bucket *b;
    int err;           /* first failure: errno, -1 bad row (atomic)     */
};

int jf__pwrite_all(int fd, const void *buf, size_t n, size_t at)
{
    const char *p = buf;
    while (n) {
        ssize_t k = pwrite(fd, p, n, (off_t)at);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return k < 0 ? errno : EIO;
        p += k, n -= (size_t)k, at += (size_t)k;
    }
    return 0;
}

static void fail(jf_spool *s, int e)
{
    int zero = 0;
    __atomic_compare_exchange_n(&s->err, &zero, e ? e : EIO, 0, __ATOMIC_ACQ_REL,
                                __ATOMIC_RELAXED);
}

/* Rows in bucket k. */
static size_t rows_in(const jf_spool *s, size_t k)
{
    size_t lo = k * s->per;
    return s->nrows - lo < s->per ? s->nrows - lo : s->per;
}

/* Bucket size: staging (buckets x STAGE) and the drain's bucket cost
 * about the same at sqrt(values x STAGE), their least sum: 11 MiB each at
 * 10^7 rows of 24 columns, 112 MiB at 10^9; clamped to 1..BUCKET_BYTES
 * MiB above that. */
size_t jf__spool_bucket(size_t nrows, size_t ncols)
{
    double b = sqrt((double)nrows * (double)ncols * 8.0 * (double)STAGE);
    if (b < (double)(1 << 20))
        b = (double)(1 << 20);
    if (b > (double)BUCKET_BYTES * 4)
        b = (double)BUCKET_BYTES * 4;
    return (size_t)b;
}

size_t jf__spool_bytes(size_t nrows, size_t ncols)
{
    size_t b = jf__spool_bucket(nrows, ncols), per = b / (8 * ncols) ? b / (8 * ncols) : 1;
    size_t nb = nrows ? (nrows + per - 1) / per : 0, entry = 8 + 8 * ncols;
    size_t stage = per * entry / 4 < STAGE ? per * entry / 4 : STAGE;
    size_t rows = per < nrows ? per : nrows;
    /* staging while rows come; at the drain one bucket's values, its
     * 'seen' bytes and a read chunk (the writer's own buffers apart) */
    size_t fill = nb * (stage + entry + sizeof(bucket)), drain = rows * (8 * ncols + 1) + 4096 * entry;
    return fill > drain ? fill : drain;
}

jf_status jf__spool_open(const char *final, size_t nrows, size_t ncols, size_t bucket_bytes,
                         jf_spool **out, jf_error *err)
{
    *out = NULL;
    jf_spool *s = calloc(1, sizeof *s);
    if (!s)
        return jf_io_fail(err, JF_ERR_NOMEM, final, 0, "out of memory");
    s->nrows = nrows;
    s->ncols = ncols;
    s->entry = 8 + 8 * ncols;
    if (!bucket_bytes)
        bucket_bytes = jf__spool_bucket(nrows, ncols);
    s->per = bucket_bytes / (8 * ncols) ? bucket_bytes / (8 * ncols) : 1;
    /* a quarter of a bucket's region at most: small buckets flush too */
    size_t q = s->per * s->entry / 4;
    s->stage = (STAGE < q ? STAGE : q) / s->entry * s->entry;
    if (s->stage < s->entry)
        s->stage = s->entry;
    s->nb = nrows ? (nrows + s->per - 1) / s->per : 0;
    s->b = calloc(s->nb ? s->nb : 1, sizeof *s->b);
    s->t.fd = -1;
    s->t.slot = -1;
    if (!s->b) {
        free(s);
        return jf_io_fail(err, JF_ERR_NOMEM, final, 0, "out of memory");
    }
    jf_status st = JF_OK;
    for (size_t k = 0; k < s->nb; k++) {
        pthread_mutex_init(&s->b[k].mu, NULL);
        s->b[k].stage = malloc(s->stage);
        if (!s->b[k].stage)
            st = JF_ERR_NOMEM;
    }
    if (st != JF_OK) {
        jf__spool_free(s);
        return jf_io_fail(err, st, final, 0, "out of memory (row spool)");
    }
    if ((st = jf_tmpfile_open(final, &s->t, err)) != JF_OK) {
        jf__spool_free(s);
        return st;
    }
    *out = s;
    return JF_OK;
}

/* Writes bucket k's staged bytes to its region (caller holds its lock). */
static int flush_bucket(jf_spool *s, size_t k)
{
    bucket *b = &s->b[k];
    size_t cap = rows_in(s, k) * s->entry;
    if (b->written + b->used > cap)
        return -1; /* a row given twice: more entries than rows */
    int e = jf__pwrite_all(s->t.fd, b->stage, b->used, k * s->per * s->entry + b->written);
    b->written += b->used;
    b->used = 0;
    return e;
}

jf_status jf__spool_put(jf_spool *s, const uint32_t *rows, const double *vals, size_t m)
{
    if (__atomic_load_n(&s->err, __ATOMIC_ACQUIRE))
        return JF_ERR_IO;
    const size_t cap = s->stage;
    for (size_t j = 0; j < m; j++) {
        if (rows[j] >= s->nrows) {
            fail(s, -1);
            return JF_ERR_INVALID;
        }
        size_t k = rows[j] / s->per;
        bucket *b = &s->b[k];
        int e = 0;
        pthread_mutex_lock(&b->mu);
        if (b->used + s->entry > cap)
            e = flush_bucket(s, k);
        if (!e) {
            uint64_t r = rows[j];
            memcpy(b->stage + b->used, &r, 8);
            memcpy(b->stage + b->used + 8, vals + j * s->ncols, 8 * s->ncols);
            b->used += s->entry;
        }
        pthread_mutex_unlock(&b->mu);
        if (e) {
            fail(s, e);
            return e == -1 ? JF_ERR_INVALID : JF_ERR_IO;
        }
    }
    return JF_OK;
}

static int pread_all(int fd, char *p, size_t n, size_t at)
{
    while (n) {
        ssize_t k = pread(fd, p, n, (off_t)at);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return k < 0 ? errno : EIO;
        p += k, n -= (size_t)k, at += (size_t)k;
    }
    return 0;
}

jf_status jf__spool_drain(jf_spool *s, jf_status (*emit)(void *, const double *, size_t),
                          void *user, const char *name, jf_error *err)
{
    int e = __atomic_load_n(&s->err, __ATOMIC_ACQUIRE);
    for (size_t k = 0; !e && k < s->nb; k++) {
        e = flush_bucket(s, k);
        if (!e && s->b[k].written != rows_in(s, k) * s->entry)
            e = -1; /* rows missing */
        free(s->b[k].stage);
        s->b[k].stage = NULL;
    }
    if (e)
        return jf_io_fail(err, e == -1 ? JF_ERR_INVALID : JF_ERR_IO, name, 0, "%s",
                          e == -1 ? "rows missing or given twice"
                                  : e == ENOMEM ? "out of memory" : strerror(e));
    const size_t chunk = 4096;
    double *v = malloc((s->per < s->nrows ? s->per : (s->nrows ? s->nrows : 1)) * s->ncols *
                       sizeof *v);
    char *in = malloc(chunk * s->entry);
    unsigned char *seen = malloc(s->per < s->nrows ? s->per : (s->nrows ? s->nrows : 1));
    jf_status st = JF_OK;
    if (!v || !in || !seen)
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory (row spool)");
    for (size_t k = 0; st == JF_OK && k < s->nb; k++) {
        size_t nr = rows_in(s, k), lo = k * s->per, base = lo * s->entry;
        memset(seen, 0, nr);
        for (size_t r0 = 0; st == JF_OK && r0 < nr; r0 += chunk) {
            size_t c = nr - r0 < chunk ? nr - r0 : chunk;
            if ((e = pread_all(s->t.fd, in, c * s->entry, base + r0 * s->entry)) != 0) {
                st = jf_io_fail(err, JF_ERR_IO, name, 0, "reading the row spool back: %s",
                                strerror(e));
                break;
            }
            for (size_t q = 0; q < c; q++) {
                uint64_t r;
                memcpy(&r, in + q * s->entry, 8);
                if (r < lo || r - lo >= nr || seen[r - lo]) {
                    st = jf_io_fail(err, JF_ERR_INVALID, name, 0, "rows missing or given twice");
                    break;
                }
                seen[r - lo] = 1;
                memcpy(v + (r - lo) * s->ncols, in + q * s->entry + 8, 8 * s->ncols);
            }
        }
        if (st == JF_OK)
            st = emit(user, v, nr);
    }
    free(v);
    free(in);
    free(seen);
    return st;
}

void jf__spool_free(jf_spool *s)
{
    if (!s)
        return;
    jf_tmpfile_discard(&s->t);
    for (size_t k = 0; k < s->nb; k++) {
        pthread_mutex_destroy(&s->b[k].mu);
        free(s->b[k].stage);
    }
    free(s->b);
    free(s);
}
