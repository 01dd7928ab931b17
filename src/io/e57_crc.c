/*
 * e57_crc.c -- the paged physical layout of an E57 file (ASTM E2807,
 * section 7.2 "physical page structure"): the file is a sequence of
 * 1024-byte pages, each 1020 bytes of data followed by the CRC-32C
 * (Castagnoli polynomial 0x1EDC6F41, reflected, stored big endian) of
 * those 1020 bytes.  Offsets in the header and the XML are physical; the
 * readers work on the "logical" image, the pages' data concatenated.
 *
 * design: every page's checksum is verified while its data is copied to
 * the logical image (one pass; slicing-by-8 tables, about 8x the
 * byte-at-a-time loop), so a damaged page is named before anything reads
 * from it.
 */
#include "e57.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* crc_tab[k][b]: the CRC of byte b followed by k zero bytes (slicing-by-8). */
static uint32_t crc_tab[8][256];
static pthread_once_t crc_once = PTHREAD_ONCE_INIT;

static void crc_init(void)
{
    for (uint32_t b = 0; b < 256; b++) {
        uint32_t c = b;
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0x82F63B78u & (0u - (c & 1u))); /* reflected 0x1EDC6F41 */
        crc_tab[0][b] = c;
    }
    for (int k = 1; k < 8; k++)
        for (int b = 0; b < 256; b++)
            crc_tab[k][b] = (crc_tab[k - 1][b] >> 8) ^ crc_tab[0][crc_tab[k - 1][b] & 0xff];
}

uint32_t jf__e57_crc32c(const unsigned char *p, size_t n)
{
    pthread_once(&crc_once, crc_init); /* readers may run in several threads */
    uint32_t c = 0xFFFFFFFFu;
    while (n >= 8) {
        uint32_t lo = c ^ ((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                           (uint32_t)p[3] << 24);
        c = crc_tab[7][lo & 0xff] ^ crc_tab[6][(lo >> 8) & 0xff] ^
            crc_tab[5][(lo >> 16) & 0xff] ^ crc_tab[4][lo >> 24] ^ crc_tab[3][p[4]] ^
            crc_tab[2][p[5]] ^ crc_tab[1][p[6]] ^ crc_tab[0][p[7]];
        p += 8;
        n -= 8;
    }
    while (n--)
        c = (c >> 8) ^ crc_tab[0][(c ^ *p++) & 0xff];
    return c ^ 0xFFFFFFFFu;
}

jf_status jf__e57_unpage(const unsigned char *buf, size_t len, const char *name,
                         unsigned char **logical, size_t *loglen, jf_error *err)
{
    *logical = NULL;
    *loglen = 0;
    if (len % JF_E57_PAGE)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "the file's %zu bytes are not whole "
                          "1024-byte pages (truncated?)", len);
    size_t pages = len / JF_E57_PAGE;
    unsigned char *out = malloc(pages * JF_E57_DATA + 16);
    if (!out)
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %zu pages", pages);
    for (size_t k = 0; k < pages; k++) {
        const unsigned char *pg = buf + k * JF_E57_PAGE;
        uint32_t want = (uint32_t)pg[1020] << 24 | (uint32_t)pg[1021] << 16 |
                        (uint32_t)pg[1022] << 8 | pg[1023];
        uint32_t got = jf__e57_crc32c(pg, JF_E57_DATA);
        if (got != want) {
            free(out);
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "page %zu (bytes %zu-%zu): checksum "
                              "mismatch (stored %08x, computed %08x): the file is damaged",
                              k, k * JF_E57_PAGE, k * JF_E57_PAGE + JF_E57_PAGE - 1,
                              (unsigned)want, (unsigned)got);
        }
        memcpy(out + k * JF_E57_DATA, pg, JF_E57_DATA);
    }
    memset(out + pages * JF_E57_DATA, 0, 16); /* the bit unpacker's over-read pad */
    *logical = out;
    *loglen = pages * JF_E57_DATA;
    return JF_OK;
}

int jf__e57_logical(uint64_t phys, size_t *log)
{
    if (phys % JF_E57_PAGE >= JF_E57_DATA || phys / JF_E57_PAGE > SIZE_MAX / JF_E57_PAGE)
        return 0; /* an offset inside a checksum */
    *log = (size_t)(phys / JF_E57_PAGE * JF_E57_DATA + phys % JF_E57_PAGE);
    return 1;
}
