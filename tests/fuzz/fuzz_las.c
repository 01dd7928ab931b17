/* fuzz_las.c -- libFuzzer harness for the LAS reader (tests/fuzz/README.md) */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    jf_fuzz_check(data, size, JF_FMT_LAS, NULL);
    return 0;
}
