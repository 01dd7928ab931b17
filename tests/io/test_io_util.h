/* test_io_util.h -- the I/O suites' temporary folder (one per test, made by
 * the fixture setup, removed by teardown) and fixture files written into
 * it.  Each suite names its folder: tmpdir_setup("/tmp/jf_io_read_XXXXXX"). */
#ifndef JF_TEST_IO_UTIL_H
#define JF_TEST_IO_UTIL_H
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char tmpdir[64];

/* Writes `len` bytes into tmpdir/name; returns the path (static buffer). */
static inline const char *fixture(const char *name, const void *data, size_t len)
{
    static char path[256];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fwrite(data, 1, len, f), len);
    fclose(f);
    return path;
}

static inline void tmpdir_setup(const char *pattern)
{
    snprintf(tmpdir, sizeof tmpdir, "%s", pattern);
    ck_assert_ptr_nonnull(mkdtemp(tmpdir));
}

static inline void teardown(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    ck_assert_int_eq(system(cmd), 0);
}
#endif
