/* laz_dump.c -- test helper: reads a file with jetfit's reader (any
 * format; LAZ decoded) and writes its point records, concatenated, to OUT,
 * so that a script can compare them with another decoder's.
 * usage: laz_dump IN OUT [THREADS].  Exit 1 with the reader's message.
 *        laz_dump -w IN OUT [THREADS]: IN through jetfit's table writer to
 *        OUT (.las or .laz: the input's records kept, nothing added).
 *        laz_dump -g FMT EXTRA N SEED OUT: a LAS file of laz_gen.h. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "laz_gen.h"

static int copy(const char *in, const char *out)
{
    jf_cloud c;
    jf_error e;
    if (jf_cloud_read(in, NULL, &c, &e) != JF_OK) {
        fprintf(stderr, "jetfit: %s\n", e.msg);
        return 1;
    }
    jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    jf_writer *w;
    jf_status st = jf_writer_open(out, cols, 3, c.n, 0, &w, &e);
    if (st == JF_OK) {
        if (jf_writer_attrs(w, &c.attrs) != JF_OK || jf_writer_rows(w, c.xyz, c.n, 0) != JF_OK)
            fprintf(stderr, "laz_dump: writer refused the rows\n");
        st = jf_writer_commit(w, &e);
    }
    if (st != JF_OK)
        fprintf(stderr, "jetfit: %s\n", e.msg);
    jf_cloud_free(&c);
    return st != JF_OK;
}

int main(int argc, char **argv)
{
    if (argc == 7 && !strcmp(argv[1], "-g")) {
        size_t len;
        unsigned char *b = lazgen_las((unsigned)atoi(argv[2]), (unsigned)atoi(argv[3]),
                                      (size_t)atol(argv[4]), (uint64_t)atoll(argv[5]), &len);
        FILE *f = fopen(argv[6], "wb");
        int ok = b && f && fwrite(b, 1, len, f) == len;
        if (f && fclose(f)) ok = 0;
        free(b);
        return !ok;
    }
    if (argc >= 4 && !strcmp(argv[1], "-w")) {
        if (argc > 4)
            omp_set_num_threads(atoi(argv[4]));
        return copy(argv[2], argv[3]);
    }
    if (argc < 3) {
        fprintf(stderr, "usage: laz_dump IN OUT [THREADS]\n");
        return 2;
    }
    if (argc > 3)
        omp_set_num_threads(atoi(argv[3]));
    jf_cloud c;
    jf_error e;
    if (jf_cloud_read(argv[1], NULL, &c, &e) != JF_OK) {
        fprintf(stderr, "jetfit: %s\n", e.msg);
        return 1;
    }
    FILE *f = fopen(argv[2], "wb");
    size_t len = c.n * c.attrs.stride;
    int ok = f && fwrite(c.attrs.rec, 1, len, f) == len;
    if (f && fclose(f) != 0)
        ok = 0;
    jf_cloud_free(&c);
    if (!ok) {
        fprintf(stderr, "laz_dump: cannot write %s\n", argv[2]);
        return 1;
    }
    return 0;
}
