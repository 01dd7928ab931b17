/* fuzz_laz.c -- libFuzzer harness for the LAZ reader (tests/fuzz/README.md):
 * the bytes are a file read as LAS; the seeds (corpus/laz) are real LAZ
 * files, so mutations land in the laszip VLR, the chunk table and the
 * arithmetic-coded chunks (pointwise v2 and layered v3). */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    jf_fuzz_check(data, size, JF_FMT_LAS, NULL);
    return 0;
}
