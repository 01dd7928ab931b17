/*
 * fuzz_ptx.c -- libFuzzer harness for the PTX reader (tests/fuzz/README.md).
 * Beyond the common checks: a successful read has at least one scan, a
 * scan index for every row (non-decreasing, below nscans: scans follow
 * each other in the file) and a finite scanner position per scan (the
 * reader refuses a non-finite header number); a failed read leaves no
 * scan arrays behind.
 */
#include <math.h>

#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    jf_fuzz_check(data, size, JF_FMT_PTX, NULL);

    jf_cloud c;
    jf_error e;
    if (jf_cloud_read_mem((const char *)data, size, JF_FMT_PTX, "fuzz", NULL, &c, &e) != JF_OK) {
        if (c.scan || c.scanner || c.nscans)
            abort();
        return 0;
    }
    if (!c.nscans || !c.scan || !c.scanner)
        abort();
    for (size_t i = 0; i < c.n; i++)
        if (c.scan[i] >= c.nscans || (i && c.scan[i] < c.scan[i - 1]))
            abort();
    if (c.scan[c.n - 1] != c.nscans - 1) /* no scan without rows */
        abort();
    for (size_t k = 0; k < 3 * c.nscans; k++)
        if (!isfinite(c.scanner[k]))
            abort();
    jf_cloud_free(&c);
    return 0;
}
