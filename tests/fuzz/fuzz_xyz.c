/*
 * fuzz_xyz.c -- libFuzzer harness for the text table reader (.xyz/.txt,
 * .pts, .csv).  The first byte picks the format and the column selection
 * (default, or x y z [nx ny nz] at small positions); the rest is the file.
 * Each input is read twice, with bad_rows = error and = skip (--bad-rows):
 * a file the strict read accepts reads the same, bit for bit, under skip
 * with nothing skipped; a skip read keeps a parsable row, lists its bad
 * lines in increasing order, and every bad row is NaN.  Both modes are
 * also read on one thread and on three in blocks of a few bytes, and
 * from a file in pieces of a few bytes: the same status, message and
 * cloud.
 */
#include "fuzz_common.h"
#include "io_internal.h"

#include <stdio.h>
#include <unistd.h>

/* Aborts unless both reads gave the same status and message, or the
 * same cloud bit for bit (names: the attributes' names and types too);
 * frees both clouds. */
static void same_result(jf_status sa, jf_status sb, jf_cloud *a, jf_cloud *b,
                        const jf_error *ea, const jf_error *eb, int names)
{
    if (sa != sb || (sa != JF_OK && strcmp(ea->msg, eb->msg)))
        abort();
    if (sa != JF_OK)
        return;
    if (a->n != b->n || a->nbad != b->nbad ||
        memcmp(a->bad_line, b->bad_line, sizeof a->bad_line) || memcmp(a->xyz, b->xyz, 3 * a->n * sizeof(double)) || !!a->nrm != !!b->nrm ||
        (a->nrm && memcmp(a->nrm, b->nrm, 3 * a->n * sizeof(double))) ||
        a->attrs.nattrs != b->attrs.nattrs || a->attrs.stride != b->attrs.stride ||
        (a->attrs.nattrs && memcmp(a->attrs.rec, b->attrs.rec, a->n * a->attrs.stride)))
        abort();
    for (size_t k = 0; names && k < a->attrs.nattrs; k++)
        if (strcmp(a->attrs.attr[k].name, b->attrs.attr[k].name) ||
            a->attrs.attr[k].type != b->attrs.attr[k].type)
            abort();
    jf_cloud_free(a);
    jf_cloud_free(b);
}

/* One thread against three with blocks of a few bytes (io_xyz.c's
 * parallel blocks): the same status, message and cloud, bit for bit. */
static void same_threads(const uint8_t *d, size_t n, jf_format f, jf_read_opts o)
{
    jf_cloud a, b;
    jf_error ea, eb;
    o.threads = 1;
    jf_status sa = jf_cloud_read_mem((const char *)d, n, f, "fuzz", &o, &a, &ea);
    o.threads = 3;
    jf__xyz_block_bytes(8 + n % 61);
    jf_status sb = jf_cloud_read_mem((const char *)d, n, f, "fuzz", &o, &b, &eb);
    jf__xyz_block_bytes(0);
    same_result(sa, sb, &a, &b, &ea, &eb, 0);
}

/* The file read in pieces of a few bytes (jf_cloud_read, io_xyz.c's
 * jf__read_xyz_fd) against the whole read of its bytes: the same status,
 * message and cloud, bit for bit. */
static void same_pieces(const uint8_t *d, size_t n, jf_format f, jf_read_opts o)
{
    static const char *const ext[3] = {"xyz", "pts", "csv"};
    char path[64];
    snprintf(path, sizeof path, "/tmp/fuzz_xyz_%d.%s", (int)getpid(),
             ext[f == JF_FMT_XYZ ? 0 : f == JF_FMT_PTS ? 1 : 2]);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return;
    size_t w = fwrite(d, 1, n, fp);
    if (fclose(fp) != 0 || w != n)
        return;
    jf_cloud a, b;
    jf_error ea, eb;
    o.threads = 1 + (int)(n % 2);
    jf__xyz_piece_bytes(1 + n % 23);
    jf__xyz_block_bytes(8 + n % 61);
    jf_status sa = jf_cloud_read(path, &o, &a, &ea);
    jf__xyz_piece_bytes(0);
    jf__xyz_block_bytes(0);
    o.threads = 1;
    jf_status sb = n ? jf_cloud_read_mem((const char *)d, n, f, path, &o, &b, &eb)
                     : jf_cloud_read(path, &o, &b, &eb);
    remove(path);
    same_result(sa, sb, &a, &b, &ea, &eb, 1);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    static const jf_format fmts[3] = {JF_FMT_XYZ, JF_FMT_PTS, JF_FMT_CSV};
    unsigned sel = data[0];
    jf_read_opts o;
    jf_read_opts_init(&o);
    if (sel & 4) /* x y z at columns (sel>>3)&3 .. +2 */
        for (int k = 0; k < 3; k++)
            o.columns[k] = (int)((sel >> 3) & 3) + k;
    if (sel & 32) /* normals right after */
        for (int k = 0; k < 3; k++)
            o.columns[3 + k] = (int)((sel >> 6) & 3) + k;
    jf_fuzz_check(data + 1, size - 1, fmts[sel % 3], &o);
    same_threads(data + 1, size - 1, fmts[sel % 3], o);
    o.bad_rows = 1;
    same_threads(data + 1, size - 1, fmts[sel % 3], o);
    same_pieces(data + 1, size - 1, fmts[sel % 3], o);
    o.bad_rows = 0;
    same_pieces(data + 1, size - 1, fmts[sel % 3], o);

    jf_cloud a, b;
    jf_error e;
    jf_status sa = jf_cloud_read_mem((const char *)data + 1, size - 1, fmts[sel % 3], "fuzz", &o,
                                     &a, &e);
    o.bad_rows = 1;
    jf_status sb = jf_cloud_read_mem((const char *)data + 1, size - 1, fmts[sel % 3], "fuzz", &o,
                                     &b, &e);
    if (sb != JF_OK && (b.xyz || b.n || strncmp(e.msg, "fuzz", 4) || strchr(e.msg, '\n')))
        abort();
    if (sa == JF_OK &&
        (sb != JF_OK || b.nbad || b.n != a.n || !!a.nrm != !!b.nrm ||
         memcmp(a.xyz, b.xyz, 3 * a.n * sizeof(double)) ||
         (a.nrm && memcmp(a.nrm, b.nrm, 3 * a.n * sizeof(double)))))
        abort();
    if (sb == JF_OK) {
        if (b.nbad >= b.n)
            abort();
        size_t shown = b.nbad < 10 ? b.nbad : 10;
        for (size_t k = 0; k < shown; k++)
            if (b.bad_line[k] < 1 || (k && b.bad_line[k] <= b.bad_line[k - 1]))
                abort();
        size_t nan_rows = 0;
        for (size_t i = 0; i < b.n; i++)
            nan_rows += b.xyz[3 * i] != b.xyz[3 * i]; /* NaN */
        if (nan_rows < b.nbad)
            abort();
    }
    if (sa == JF_OK)
        jf_cloud_free(&a);
    if (sb == JF_OK)
        jf_cloud_free(&b);
    return 0;
}
