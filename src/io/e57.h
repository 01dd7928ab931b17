/*
 * e57.h -- the pieces of the E57 reader (ASTM E2807), internal: the paged
 * layout (e57_crc.c), the XML tree (e57_xml.c), CompressedVector binary
 * sections (e57_cv.c); io_e57.c puts them together.
 */
#ifndef JF_E57_H
#define JF_E57_H

#include "io_internal.h"

#include <stddef.h>
#include <stdint.h>

#define JF_E57_PAGE 1024 /* physical page: 1020 data bytes + CRC-32C */
#define JF_E57_DATA 1020

/* ---- e57_crc.c ---- */
/* CRC-32C (Castagnoli) of [p, p+n).  Thread-safe. */
uint32_t jf__e57_crc32c(const unsigned char *p, size_t n);
/* Checks every page's checksum and returns the logical image (*logical,
 * *loglen bytes, malloc'd, followed by 16 zero bytes); err names the first
 * bad page. */
jf_status jf__e57_unpage(const unsigned char *buf, size_t len, const char *name,
                         unsigned char **logical, size_t *loglen, jf_error *err);
/* Physical offset -> logical offset; 0 if phys is inside a checksum. */
int jf__e57_logical(uint64_t phys, size_t *log);

/* ---- e57_xml.c: the XML section as a tree ---- */
typedef struct {
    const char *name;   /* element name as written (prefix:name kept) */
    const char **attr;  /* name, value, name, value, ..., NULL        */
    const char *text;   /* character data (CDATA included), trimmed  */
    int parent, child, next; /* indices, -1 none                     */
    size_t line;        /* line of the start tag                      */
} jf_e57_node;

typedef struct {
    jf_e57_node *node;  /* node[0] is the root element                */
    size_t n;
    void *arena;        /* the strings (freed by jf__e57_xml_free)    */
} jf_e57_xml;

/* Parses [s, s+len) (expat).  Error: "NAME: XML line L: reason". */
jf_status jf__e57_xml_parse(const char *s, size_t len, const char *name, jf_e57_xml *x,
                            jf_error *err);
void jf__e57_xml_free(jf_e57_xml *x);
/* First child of node i named `name`, or -1. */
int jf__e57_child(const jf_e57_xml *x, int i, const char *name);
/* The value of attribute `name` of node i, or NULL. */
const char *jf__e57_attr(const jf_e57_xml *x, int i, const char *name);

/* ---- e57_cv.c: CompressedVector binary sections ---- */
enum { JF_E57_INT, JF_E57_SCALED, JF_E57_FLOAT, JF_E57_DOUBLE };

typedef struct {
    const char *name;   /* the prototype child's element name         */
    int kind;           /* JF_E57_*                                   */
    int64_t min, max;   /* Integer / ScaledInteger raw bounds          */
    double scale, offset; /* ScaledInteger: value = raw scale + offset */
    unsigned bits;      /* bit-packed width (0: the value is min)     */
    /* where the decoded values go: value k at dst + k stride, as
     * `type` (JF_ATTR_F64 for coordinates); dst NULL: skipped */
    unsigned char *dst;
    size_t stride;
    jf_attr_type type;
} jf_e57_field;

/* Bits of an Integer in [min, max] (E2807 8.4.6: ceil(log2(max-min+1))). */
unsigned jf__e57_bits(int64_t min, int64_t max);

/* Decodes `count` records of the CompressedVector whose binary section
 * starts at logical offset `sec` of [log, log+loglen) (16 readable bytes
 * past the end) into the fields' sinks.  `what` names the vector in
 * messages ("scan 2").  err "NAME: reason". */
jf_status jf__e57_cv_read(const unsigned char *log, size_t loglen, size_t sec,
                          jf_e57_field *f, size_t nf, uint64_t count, const char *name,
                          const char *what, jf_error *err);

#endif /* JF_E57_H */
