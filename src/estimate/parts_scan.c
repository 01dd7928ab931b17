/* parts_scan.c -- the cloud's coordinates (jf_xyz_src: in memory or a
 * file) read in chunks on the threads, for the bounded-memory estimate's
 * scans (parts_run.c, parts_halo.c). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <omp.h>

#include "parts_run.h"

size_t jf__chunk_len(const reader *rd, size_t ch)
{
    const size_t first = ch * JF_SRC_CHUNK;
    return rd->n - first < JF_SRC_CHUNK ? rd->n - first : JF_SRC_CHUNK;
}

/* Chunk ch's coordinates (chunk_len points), or NULL after a failure. */
const double *jf__chunk_xyz(reader *rd, size_t ch)
{
    const size_t first = ch * JF_SRC_CHUNK, m = jf__chunk_len(rd, ch);
    if (rd->s->xyz) return rd->s->xyz + 3 * first;
    if (__atomic_load_n(&rd->fail, __ATOMIC_RELAXED)) return NULL;
    const int t = omp_get_thread_num();
    const jf_row_layout *l = rd->s->l;
    /* rows of three doubles: read straight into the coordinates */
    unsigned char *p = rd->plain ? (unsigned char *)rd->xyz[t] : rd->raw[t];
    size_t left = m * l->row;
    uint64_t at = l->vertex_off + (uint64_t)first * l->row;
    while (left) {
        ssize_t k = pread(rd->s->fd, p, left, (off_t)at);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) {
#pragma omp critical(jf_parts_reader)
            if (!rd->fail) {
                rd->fail = 1;
                rd->io_row = first + (size_t)(at - l->vertex_off - (uint64_t)first * l->row) / l->row;
                rd->io_errno = k < 0 ? errno : 0;
            }
            return NULL;
        }
        p += k, left -= (size_t)k, at += (uint64_t)k;
    }
    if (!rd->plain) jf__layout_rows(rd->raw[t], m, l, rd->xyz[t], NULL);
    return rd->xyz[t];
}

jf_status jf__reader_open(reader *rd, const jf_xyz_src *s, size_t n, int nt)
{
    memset(rd, 0, sizeof *rd);
    rd->s = s, rd->n = n, rd->nt = nt;
    rd->nch = (n + JF_SRC_CHUNK - 1) / JF_SRC_CHUNK;
    if (s->xyz) return JF_OK;
    rd->xyz = calloc((size_t)nt, sizeof *rd->xyz);
    rd->raw = calloc((size_t)nt, sizeof *rd->raw);
    rd->plain = jf__layout_plain_xyz(s->l);
    if (!rd->xyz || !rd->raw) return JF_ERR_NOMEM;
    for (int t = 0; t < nt; t++) {
        rd->xyz[t] = malloc(JF_SRC_CHUNK * 3 * sizeof(double));
        rd->raw[t] = rd->plain ? NULL : malloc(JF_SRC_CHUNK * s->l->row);
        if (!rd->xyz[t] || (!rd->plain && !rd->raw[t])) return JF_ERR_NOMEM;
    }
    return JF_OK;
}

void jf__reader_close(reader *rd)
{
    for (int t = 0; rd->xyz && t < rd->nt; t++) free(rd->xyz[t]);
    for (int t = 0; rd->raw && t < rd->nt; t++) free(rd->raw[t]);
    free(rd->xyz);
    free(rd->raw);
}

/* JF_ERR_IO with the file, the vertex and the reason after a failed read. */
jf_status jf__reader_status(const reader *rd, jf_error *err)
{
    if (!rd->fail) return JF_OK;
    if (err)
        snprintf(err->msg, sizeof err->msg, "read failed at vertex %zu: %s", rd->io_row,
                 rd->io_errno ? strerror(rd->io_errno) : "the file shrank while it was read");
    return JF_ERR_IO;
}

/* The points of part a (input order) and their coordinates. */
size_t jf__gather(reader *rd, const int32_t *part, int32_t a, uint32_t *ids, double *xyz,
                     size_t *cnt)
{
    /* on the threads, in input order: count per chunk, then fill from
     * each chunk's offset (cnt: nch + 1 entries) */
    const size_t nch = rd->nch;
    cnt[0] = 0;
#pragma omp parallel for num_threads(rd->nt) schedule(dynamic, 16)
    for (size_t ch = 0; ch < nch; ch++) {
        size_t k = 0, beg = ch * JF_SRC_CHUNK, end = beg + jf__chunk_len(rd, ch);
        for (size_t i = beg; i < end; i++) k += part[i] == a;
        cnt[ch + 1] = k;
    }
    for (size_t ch = 0; ch < nch; ch++) cnt[ch + 1] += cnt[ch];
#pragma omp parallel for num_threads(rd->nt) schedule(dynamic, 1)
    for (size_t ch = 0; ch < nch; ch++) {
        if (cnt[ch + 1] == cnt[ch]) continue; /* none of a's: not read */
        const double *x = jf__chunk_xyz(rd, ch);
        if (!x) continue;
        size_t m = cnt[ch], beg = ch * JF_SRC_CHUNK, end = beg + jf__chunk_len(rd, ch);
        for (size_t i = beg; i < end; i++)
            if (part[i] == a) {
                ids[m] = (uint32_t)i;
                memcpy(xyz + 3 * m, x + 3 * (i - beg), sizeof(double[3]));
                m++;
            }
    }
    return cnt[nch];
}

