/* las_columns.c -- the Extra Bytes type of jetfit's real-valued result
 * columns in a .las or .laz output (LAS 1.4 R15 table 24: 10 double, 9
 * float), for the writer's callers (the Python binding; the command's
 * --las-columns makes the same choice).  A .laz takes compact unless told:
 * floats, the unit vectors' components (nx ... d2z) rounded to multiples
 * of 2^-16, because LASzip codes each extra byte as a difference from the
 * previous point's and low mantissa bytes are noise (docs/formats.md#laz). */
#include <string.h>
#include <strings.h>

#include "io_internal.h"

void jf__las_columns(const char *path, int mode, jf_column *cols, size_t ncols)
{
    size_t l = strlen(path);
    if (!mode) mode = l >= 4 && !strcasecmp(path + l - 4, ".laz") ? JF_LASCOL_COMPACT
                                                                  : JF_LASCOL_DOUBLE;
    for (size_t j = 3; mode > JF_LASCOL_DOUBLE && j < ncols; j++) {
        const char *n = cols[j].name;
        int unit = (n[0] == 'n' && n[1] && strchr("xyz", n[1]) && !n[2]) ||
                   (n[0] == 'd' && (n[1] == '1' || n[1] == '2') && n[2] && strchr("xyz", n[2]) &&
                    !n[3]);
        if (cols[j].type == JF_COL_F64)
            cols[j].type = mode == JF_LASCOL_COMPACT && unit ? JF_COL_F32_Q16 : JF_COL_F32;
    }
}
