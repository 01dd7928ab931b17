/* fuzz_ply_layout.c -- libFuzzer harness for jf__ply_layout, the binary
 * PLY header check of jetfit-mpi (tests/fuzz/README.md): the input is the
 * file's first bytes and its whole length at once. */
#include <stdint.h>
#include <string.h>

#include "io_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    jf_row_layout l;
    jf_error err;
    memset(&err, 0, sizeof err);
    if (jf__ply_layout((const char *)data, size, size, "f.ply", &l, &err) == JF_OK) {
        /* a layout it accepts fits in the file */
        if (l.vertex_off > size || (l.row && l.count > (size - l.vertex_off) / l.row + 1))
            __builtin_trap();
    }
    return 0;
}
