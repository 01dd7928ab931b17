/* test_text_gen.h -- what the text readers' suites (test_io_text_par,
 * test_io_text_pieces) share: a growing text they generate rows into
 * (its lines counted), and the bit-for-bit comparison of two clouds. */
#ifndef JF_TEST_TEXT_GEN_H
#define JF_TEST_TEXT_GEN_H
#include <check.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

typedef struct {
    char *s;
    size_t n, cap, lines; /* lines: '\n' written */
} text;

static void put(text *t, const char *fmt, ...)
{
    va_list ap, aq;
    va_start(ap, fmt);
    va_copy(aq, ap);
    int k = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    ck_assert_int_ge(k, 0);
    if (t->n + (size_t)k + 1 > t->cap) {
        t->cap = 2 * (t->n + (size_t)k + 1);
        t->s = realloc(t->s, t->cap);
        ck_assert_ptr_nonnull(t->s);
    }
    vsnprintf(t->s + t->n, (size_t)k + 1, fmt, aq);
    va_end(aq);
    for (size_t i = t->n; i < t->n + (size_t)k; i++)
        t->lines += t->s[i] == '\n';
    t->n += (size_t)k;
}

/* a and b the same cloud, bit for bit (NaN rows included). */
static void same_cloud(const jf_cloud *a, const jf_cloud *b)
{
    ck_assert_uint_eq(a->n, b->n);
    ck_assert_uint_eq(a->nbad, b->nbad);
    ck_assert_int_eq(memcmp(a->bad_line, b->bad_line, sizeof a->bad_line), 0);
    ck_assert_int_eq(memcmp(a->xyz, b->xyz, 3 * a->n * sizeof(double)), 0);
    ck_assert_int_eq(!a->nrm, !b->nrm);
    if (a->nrm)
        ck_assert_int_eq(memcmp(a->nrm, b->nrm, 3 * a->n * sizeof(double)), 0);
    ck_assert_uint_eq(a->attrs.nattrs, b->attrs.nattrs);
    ck_assert_uint_eq(a->attrs.stride, b->attrs.stride);
    for (size_t k = 0; k < a->attrs.nattrs; k++) {
        ck_assert_str_eq(a->attrs.attr[k].name, b->attrs.attr[k].name);
        ck_assert_int_eq(a->attrs.attr[k].type, b->attrs.attr[k].type);
    }
    if (a->attrs.nattrs)
        ck_assert_int_eq(memcmp(a->attrs.rec, b->attrs.rec, a->n * a->attrs.stride), 0);
}
#endif
