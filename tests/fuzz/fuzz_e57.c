/*
 * fuzz_e57.c -- libFuzzer harness for the E57 reader (tests/fuzz/README.md).
 * The first byte picks the mode: odd, the rest is "repaired" before it is
 * read -- padded to whole 1024-byte pages, the header's file length set
 * and every page's CRC-32C recomputed -- so mutations reach the XML and
 * the binary sections instead of stopping at the first page checksum;
 * even, the rest is read as it is (the checksum and length checks).
 * Beyond the common checks: a successful read has a scan index below
 * nscans for every row, scans in file order, finite scanner positions; a
 * failed read leaves no scan arrays behind.
 */
#include <math.h>

#include "e57.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    const uint8_t *b = data + 1;
    size_t n = size - 1;
    uint8_t *fixed = NULL;
    if ((data[0] & 1) && n >= 48 && n <= (1u << 22)) {
        size_t len = (n + 1023) / 1024 * 1024;
        fixed = calloc(len, 1);
        if (!fixed)
            return 0;
        memcpy(fixed, b, n);
        for (int k = 0; k < 8; k++)
            fixed[16 + k] = (uint8_t)((uint64_t)len >> (8 * k));
        for (size_t p = 0; p < len; p += 1024) {
            uint32_t c = jf__e57_crc32c(fixed + p, 1020);
            fixed[p + 1020] = (uint8_t)(c >> 24), fixed[p + 1021] = (uint8_t)(c >> 16);
            fixed[p + 1022] = (uint8_t)(c >> 8), fixed[p + 1023] = (uint8_t)c;
        }
        b = fixed;
        n = len;
    }
    jf_fuzz_check(b, n, JF_FMT_E57, NULL);

    jf_cloud c;
    jf_error e;
    if (jf_cloud_read_mem((const char *)b, n, JF_FMT_E57, "fuzz", NULL, &c, &e) != JF_OK) {
        if (c.scan || c.scanner || c.nscans || c.attrs.rec)
            abort();
        free(fixed);
        return 0;
    }
    if (!c.nscans || !c.scan || !c.scanner)
        abort();
    for (size_t i = 0; i < c.n; i++)
        if (c.scan[i] >= c.nscans || (i && c.scan[i] < c.scan[i - 1]))
            abort();
    for (size_t k = 0; k < 3 * c.nscans; k++)
        if (!isfinite(c.scanner[k]))
            abort();
    jf_cloud_free(&c);
    free(fixed);
    return 0;
}
