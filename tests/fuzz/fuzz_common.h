/*
 * fuzz_common.h -- shared body of the libFuzzer harnesses: parse the bytes
 * with one reader (in memory, exactly `size` bytes so ASan sees any read
 * past the end) and check what a successful read promises.
 */
#ifndef JF_FUZZ_COMMON_H
#define JF_FUZZ_COMMON_H

#include <stdlib.h>
#include <string.h>

#include "io_internal.h"

static void jf_fuzz_check(const uint8_t *data, size_t size, jf_format fmt,
                          const jf_read_opts *o)
{
    jf_cloud c;
    jf_error e;
    jf_status st = jf_cloud_read_mem((const char *)data, size, fmt, "fuzz", o,
                                     &c, &e);
    if (st != JF_OK) {
        /* failure: an empty cloud and a one-line message naming the file */
        if (c.xyz || c.nrm || c.face_off || c.face_idx || c.n || c.nfaces ||
            strncmp(e.msg, "fuzz", 4) != 0 || strchr(e.msg, '\n'))
            abort();
        return;
    }
    if (c.n && !c.xyz)
        abort();
    if (c.nfaces) {
        if (!c.face_off || !c.face_idx || c.face_off[0] != 0)
            abort();
        for (size_t f = 0; f < c.nfaces; f++) {
            if (c.face_off[f + 1] < c.face_off[f] + 3)
                abort();
            for (size_t k = c.face_off[f]; k < c.face_off[f + 1]; k++)
                if (c.face_idx[k] >= c.n)
                    abort();
        }
    }
    /* touch every value so ASan checks the arrays' extent */
    volatile double sum = 0;
    for (size_t i = 0; i < 3 * c.n; i++)
        sum += c.xyz[i] + (c.nrm ? c.nrm[i] : 0);
    /* the attributes (issue 13.4): every description inside its record,
     * every value readable */
    const jf_attrs *a = &c.attrs;
    if (a->nattrs && (!a->rec || !a->attr))
        abort();
    for (size_t j = 0; j < a->nattrs; j++) {
        static const unsigned sz[10] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
        const jf_attr *at = &a->attr[j];
        if ((unsigned)at->type > JF_ATTR_F64 || at->offset + sz[at->type] > a->stride ||
            at->shift + at->bits > 8 || !memchr(at->name, '\0', sizeof at->name))
            abort();
        for (size_t i = 0; i < c.n; i++)
            sum += jf_attr_get(a, j, i);
    }
    (void)sum;
    jf_cloud_free(&c);
}

#endif
