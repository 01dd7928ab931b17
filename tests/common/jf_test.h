/* jf_test.h -- what the Check suites share (one copy, issue 24.6): the
 * runner of a suite and the reproducible generators the suites draw their
 * inputs from.  Each suite keeps its own seed, so its inputs do not depend
 * on any other suite. */
#ifndef JF_TEST_H
#define JF_TEST_H

#include <check.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

/* Runs every case of s (Check's normal output, its summary line); the
 * process's exit status: 0 if all passed, else 1. */
static inline int jf_test_run(Suite *s)
{
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? 1 : 0;
}

/* Runs s, whose cases tagged `tool` (tcase_set_tags) need an optional
 * tool (have: 1 when it is here).  ctest runs those cases as a test of
 * their own (CK_INCLUDE_TAGS=tool, see jf_tool_case in
 * tests/CMakeLists.txt) and the rest without them (CK_EXCLUDE_TAGS), so a
 * missing tool is a reported skip (the reason, exit status 77) of that
 * test, never a pass; run by hand, the suite says SKIP and leaves them
 * out. */
static inline int jf_test_run_tool(Suite *s, const char *tool, int have, const char *reason)
{
    const char *only = getenv("CK_INCLUDE_TAGS");
    if (!have) {
        printf("SKIP cases tagged %s: %s\n", tool, reason);
        if (only && !strcmp(only, tool)) return 77; /* s: freed by the exit */
        setenv("CK_EXCLUDE_TAGS", tool, 1);
    }
    return jf_test_run(s);
}

/* The whole file at path, malloc'd and NUL-ended (*len, when len is not
 * NULL: its size); NULL if it cannot be read. */
static inline void *jf_test_slurp(const char *path, size_t *len)
{
    if (len) *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    long n = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    char *b = n >= 0 && fseek(f, 0, SEEK_SET) == 0 ? (char *)malloc((size_t)n + 1) : NULL;
    if (b && fread(b, 1, (size_t)n, f) != (size_t)n) {
        free(b);
        b = NULL;
    }
    fclose(f);
    if (!b) return NULL;
    b[n] = '\0';
    if (len) *len = (size_t)n;
    return b;
}

/* jf_test_slurp that fails the test, naming the file, when it cannot read it. */
static inline char *jf_test_must_slurp(const char *path, size_t *len)
{
    char *b = (char *)jf_test_slurp(path, len);
    ck_assert_msg(b != NULL, "cannot read %s", path);
    return b;
}

/* 1 if the files at a and b can be read and hold the same bytes, at least
 * one (two empty outputs prove nothing). */
static inline int jf_test_same_files(const char *a, const char *b)
{
    size_t la, lb;
    char *x = (char *)jf_test_slurp(a, &la), *y = (char *)jf_test_slurp(b, &lb);
    int same = x && y && la == lb && la > 0 && !memcmp(x, y, la);
    free(x);
    free(y);
    return same;
}

/* Fails the test unless a and b hold the same bytes; what names the case. */
static inline void jf_test_assert_same_files(const char *what, const char *a, const char *b)
{
    size_t la, lb;
    char *x = (char *)jf_test_slurp(a, &la), *y = (char *)jf_test_slurp(b, &lb);
    ck_assert_msg(x && y && la == lb && !memcmp(x, y, la), "%s: %s and %s differ (%zu, %zu bytes)",
                  what, a, b, la, lb);
    free(x);
    free(y);
}

/* splitmix64 (Steele, Lea & Flood 2014): the next 64 bits of *state. */
/* A jf_estimate_opts.phase hook: the largest total of JF_PHASE_INDEX
 * into *(size_t *)user -- jf_estimate_parts reports each part's index
 * with the part's own and halo points, so this is the largest part. */
static inline void jf_test_most_indexed(void *user, jf_phase ph, size_t done, size_t total)
{
    (void)done;
    size_t *most = (size_t *)user; /* C++ tests include this too */
    if (ph == JF_PHASE_INDEX && total > *most) *most = total;
}

static inline uint64_t jf_splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* xorshift64* (Vigna 2016): the next 64 bits of *state (never 0). */
static inline uint64_t jf_xorshift64s(uint64_t *state)
{
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    return *state * 2685821657736338717ULL;
}

/* xorshift64 (Marsaglia 2003, shifts 13, 7, 17): the next state. */
static inline uint64_t jf_xorshift64(uint64_t *state)
{
    *state ^= *state << 13, *state ^= *state >> 7, *state ^= *state << 17;
    return *state;
}

/* A double in [0, 1) from the top 53 bits of a 64-bit draw. */
static inline double jf_unit(uint64_t bits) { return (double)(bits >> 11) * 0x1.0p-53; }

#endif
