/* test_las_bytes.h -- little-endian byte helpers of the suites that build
 * LAS files by hand (test_io_las, test_io_las_edges, test_io_attrs), and
 * the record lengths of point formats 0-10 (LAS 1.4 R15, Tables 7-17). */
#ifndef JF_TEST_LAS_BYTES_H
#define JF_TEST_LAS_BYTES_H
#include <stdint.h>
#include <string.h>

static const unsigned base_len[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static inline void put16(unsigned char *p, unsigned v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8);
}
static inline void put32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static inline void put64(unsigned char *p, uint64_t v)
{
    for (int k = 0; k < 8; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static inline void putd(unsigned char *p, double d)
{
    uint64_t b;
    memcpy(&b, &d, 8);
    put64(p, b);
}
static inline uint16_t g16(const unsigned char *p) { return (uint16_t)(p[0] | p[1] << 8); }
static inline uint32_t g32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t g64(const unsigned char *p) { return g32(p) | (uint64_t)g32(p + 4) << 32; }
static inline double getd(const unsigned char *p)
{
    uint64_t b = g64(p);
    double d;
    memcpy(&d, &b, 8);
    return d;
}
#endif
