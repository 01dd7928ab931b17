/*
 * fuzz_xyz.c -- libFuzzer harness for the text table reader (.xyz/.txt,
 * .pts, .csv).  The first byte picks the format and the column selection
 * (default, or x y z [nx ny nz] at small positions); the rest is the file.
 */
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    static const jf_format fmts[3] = {JF_FMT_XYZ, JF_FMT_PTS, JF_FMT_CSV};
    unsigned sel = data[0];
    jf_read_opts o;
    jf_read_opts_init(&o);
    if (sel & 4) /* x y z at columns (sel>>3)&3 .. +2 */
        for (int k = 0; k < 3; k++)
            o.columns[k] = (int)((sel >> 3) & 3) + k;
    if (sel & 32) /* normals right after */
        for (int k = 0; k < 3; k++)
            o.columns[3 + k] = (int)((sel >> 6) & 3) + k;
    jf_fuzz_check(data + 1, size - 1, fmts[sel % 3], &o);
    return 0;
}
