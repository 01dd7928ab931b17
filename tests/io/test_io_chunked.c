/* test_io_chunked.c -- binary PLY point clouds are read a chunk at a time
 * straight into the coordinate arrays (issue 12.1: no file image beside
 * them).  The chunked path must give the same bits and the same refusals
 * as the whole-file parser (jf_cloud_read_mem on the file's bytes): files
 * over several 4 MiB chunks, both byte orders, mixed property types, an
 * element before and after the vertices, normals, a trailing newline, a
 * truncated file, a count too small for the data, and a mesh (which takes
 * the whole-file path). */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <fcntl.h>
#include <unistd.h>

#include "io_internal.h"
#include "test_io_util.h"
#include "jf_test.h"

static void put(unsigned char **o, const void *v, size_t n, int big)
{
    const unsigned char *b = v;
    for (size_t i = 0; i < n; i++) (*o)[i] = big ? b[n - 1 - i] : b[i];
    *o += n;
}

/* A binary PLY: element `camera` (2 rows: float, uchar) before `vertex`
 * (float x, uchar flag, double y, double z, [float nx ny nz]), and an
 * element `extra` (1 row, int) after.  n vertices.  Returns malloc'd
 * bytes, *len. */
static unsigned char *make_ply(size_t n, int big, int normals, const char *tail, size_t *len)
{
    char head[1024];
    int hl = snprintf(head, sizeof head,
                      "ply\nformat %s 1.0\ncomment chunked\nelement camera 2\n"
                      "property float fx\nproperty uchar k\nelement vertex %zu\n"
                      "property float x\nproperty uchar flag\nproperty double y\n"
                      "property double z\n%selement extra 1\nproperty int e\nend_header\n",
                      big ? "binary_big_endian" : "binary_little_endian", n,
                      normals ? "property float nx\nproperty float ny\nproperty float nz\n" : "");
    size_t row = 4 + 1 + 8 + 8 + (normals ? 12 : 0);
    size_t cap = (size_t)hl + 2 * 5 + n * row + 4 + strlen(tail);
    unsigned char *b = malloc(cap), *o = b;
    memcpy(o, head, (size_t)hl);
    o += hl;
    for (int k = 0; k < 2; k++) {
        float f = 1.5f * (float)k;
        unsigned char u = 7;
        put(&o, &f, 4, big);
        put(&o, &u, 1, big);
    }
    for (size_t i = 0; i < n; i++) {
        float x = (float)i * 0.25f - 3.0f;
        unsigned char flag = (unsigned char)i;
        double y = sin((double)i), z = i == 17 ? NAN : 1e-3 * (double)i;
        put(&o, &x, 4, big);
        put(&o, &flag, 1, big);
        put(&o, &y, 8, big);
        put(&o, &z, 8, big);
        if (normals) {
            float nn[3] = {0.5f, -0.25f, (float)i};
            for (int k = 0; k < 3; k++) put(&o, &nn[k], 4, big);
        }
    }
    int32_t e = -5;
    put(&o, &e, 4, big);
    memcpy(o, tail, strlen(tail));
    o += strlen(tail);
    *len = (size_t)(o - b);
    return b;
}

/* Which path the file takes: the chunked reader's own answer. */
static jf_status chunked(const unsigned char *bytes, size_t len)
{
    const char *path = fixture("d.ply", bytes, len);
    int fd = open(path, O_RDONLY);
    ck_assert_int_ge(fd, 0);
    jf_cloud c = {0};
    jf_error err;
    jf_status st = jf__read_ply_chunked(fd, len, path, NULL, &c, &err);
    close(fd);
    jf_cloud_free(&c);
    return st;
}

static void same_cloud(const jf_cloud *a, const jf_cloud *b)
{
    ck_assert_uint_eq(a->n, b->n);
    ck_assert_int_eq(memcmp(a->xyz, b->xyz, 3 * a->n * sizeof(double)), 0);
    ck_assert_int_eq(!a->nrm, !b->nrm);
    if (a->nrm) ck_assert_int_eq(memcmp(a->nrm, b->nrm, 3 * a->n * sizeof(double)), 0);
    ck_assert_uint_eq(a->nfaces, b->nfaces);
    /* the attributes (flag [, nx ny nz]) too: same layout, same bytes */
    ck_assert_uint_eq(a->attrs.nattrs, b->attrs.nattrs);
    ck_assert_uint_eq(a->attrs.stride, b->attrs.stride);
    for (size_t j = 0; j < a->attrs.nattrs; j++)
        ck_assert_int_eq(memcmp(&a->attrs.attr[j], &b->attrs.attr[j], sizeof(jf_attr)), 0);
    if (a->attrs.nattrs)
        ck_assert_int_eq(memcmp(a->attrs.rec, b->attrs.rec, a->n * a->attrs.stride), 0);
}

/* The file read by jf_cloud_read (chunked when it qualifies) and its
 * bytes by the whole-file parser: same status, message and arrays. */
static void check_same(const unsigned char *bytes, size_t len)
{
    const char *path = fixture("c.ply", bytes, len);
    jf_cloud a, b;
    jf_error ea, eb;
    jf_status sa = jf_cloud_read(path, NULL, &a, &ea);
    jf_status sb = jf_cloud_read_mem((const char *)bytes, len, JF_FMT_PLY, path, NULL, &b, &eb);
    ck_assert_int_eq(sa, sb);
    if (sa == JF_OK)
        same_cloud(&a, &b);
    else
        ck_assert_str_eq(ea.msg, eb.msg);
    jf_cloud_free(&a);
    jf_cloud_free(&b);
}

/* Read progress, in bytes: non-decreasing, from 0 to the file's length. */
static size_t nrep, reps[64][2];
static void on_read(void *user, jf_phase ph, size_t done, size_t total)
{
    (void)user;
    ck_assert_int_eq(ph, JF_PHASE_READ);
    if (nrep < 64) reps[nrep][0] = done, reps[nrep++][1] = total;
}

START_TEST(chunked_equals_whole)
{
    tmpdir_setup("/tmp/jf_io_chunked_XXXXXX");
    /* 250000 rows of 21 or 33 bytes: 5-8 MiB, two chunks or more */
    for (int big = 0; big < 2; big++)
        for (int normals = 0; normals < 2; normals++) {
            size_t len;
            unsigned char *b = make_ply(250000, big, normals, "", &len);
            check_same(b, len);
            ck_assert_int_eq(chunked(b, len), JF_OK);
            jf_cloud c;
            jf_error err;
            ck_assert_int_eq(jf_cloud_read(fixture("c.ply", b, len), NULL, &c, &err), JF_OK);
            /* the values themselves, not only agreement; flag carried */
            ck_assert_str_eq(c.attrs.attr[0].name, "flag");
            ck_assert(jf_attr_get(&c.attrs, 0, 1000) == (double)(unsigned char)1000);
            ck_assert(c.xyz[3 * 1000] == 1000 * 0.25 - 3.0);
            ck_assert(c.xyz[3 * 1000 + 1] == sin(1000.0));
            ck_assert(isnan(c.xyz[3 * 17 + 2]));
            ck_assert(c.xyz[3 * 249999 + 2] == 1e-3 * 249999.0);
            if (normals) ck_assert(c.nrm[3 * 249999 + 2] == (double)(float)249999);
            jf_cloud_free(&c);
            /* progress chunk by chunk (4 MiB), not only at the start and end */
            jf_read_opts ro;
            jf_read_opts_init(&ro);
            ro.progress = on_read;
            nrep = 0;
            ck_assert_int_eq(jf_cloud_read(fixture("c.ply", b, len), &ro, &c, &err), JF_OK);
            jf_cloud_free(&c);
            size_t mid = 0;
            for (size_t k = 0; k < nrep; k++) {
                ck_assert_uint_eq(reps[k][1], len);
                if (k) ck_assert_uint_ge(reps[k][0], reps[k - 1][0]);
                mid += reps[k][0] > 0 && reps[k][0] < len;
            }
            ck_assert_uint_ge(nrep, 3);
            ck_assert_uint_eq(reps[0][0], 0);
            ck_assert_uint_eq(reps[nrep - 1][0], len);
            ck_assert_uint_ge(mid, 1);
            free(b);
        }
    /* a trailing newline is tolerated; more bytes than a row are not */
    size_t len;
    unsigned char *b = make_ply(1000, 0, 0, "\n", &len);
    check_same(b, len);
    ck_assert_int_eq(chunked(b, len), JF_OK);
    free(b);
    b = make_ply(1000, 0, 0, "0123456789abcdefghijklmnopqrstuvwxyz", &len);
    check_same(b, len);
    ck_assert_int_eq(chunked(b, len), JF_ERR_UNSUPPORTED);
    free(b);
    /* truncated: the whole-file parser names the row */
    b = make_ply(1000, 1, 1, "", &len);
    check_same(b, len - 40);
    free(b);
    /* a mesh (a face list) and an ascii file go the whole-file way */
    static const char mesh[] = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\n"
                               "end_header\n";
    unsigned char m[sizeof mesh - 1 + 36 + 13], *o = m + sizeof mesh - 1;
    memcpy(m, mesh, sizeof mesh - 1);
    for (int i = 0; i < 9; i++) {
        float f = (float)(i % 4);
        put(&o, &f, 4, 0);
    }
    *o++ = 3;
    for (int32_t i = 0; i < 3; i++) put(&o, &i, 4, 0);
    check_same(m, sizeof m);
    ck_assert_int_eq(chunked(m, sizeof m), JF_ERR_UNSUPPORTED);
    jf_cloud c;
    jf_error err;
    ck_assert_int_eq(jf_cloud_read(fixture("c.ply", m, sizeof m), NULL, &c, &err), JF_OK);
    ck_assert_uint_eq(c.nfaces, 1);
    jf_cloud_free(&c);
    static const char zero[] = "ply\nformat binary_little_endian 1.0\nelement vertex 0\n"
                               "property double x\nproperty double y\nproperty double z\n"
                               "end_header\n";
    check_same((const unsigned char *)zero, sizeof zero - 1);
    teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_chunked");
    TCase *t = tcase_create("chunked");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, chunked_equals_whole);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
