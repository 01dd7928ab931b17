/* laz_dump.c -- test helper: reads a file with jetfit's reader (any
 * format; LAZ decoded) and writes its point records, concatenated, to OUT,
 * so that a script can compare them with another decoder's.
 * usage: laz_dump IN OUT [THREADS].  Exit 1 with the reader's message. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "jetfit.h"

int main(int argc, char **argv)
{
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
