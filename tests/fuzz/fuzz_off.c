/* fuzz_off.c -- libFuzzer harness for the OFF reader (tests/fuzz/README.md) */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    jf_fuzz_check(data, size, JF_FMT_OFF, NULL);
    return 0;
}
