/* test_io_phases.c -- the progress hooks (jf_phase_fn) of the estimate
 * (index, fit; per part in jf_estimate_parts) and of the table writer
 * (write): the phases in order, counts non-decreasing and ending at their
 * totals, always on the calling thread; and positioned rows formatted on
 * 1 or 4 threads give the same bytes in every text format. */
#include <check.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

#include "jf_test.h"
#include "test_io_util.h"

#define NPTS 20000

/* Every report, in order. */
typedef struct {
    int phase;
    size_t done, total;
} report;

typedef struct {
    report r[100000];
    size_t n;
    pthread_t caller;
    int other_thread;
} log_t;

static log_t lg;

static void hook(void *user, jf_phase ph, size_t done, size_t total)
{
    log_t *l = user;
    if (!pthread_equal(pthread_self(), l->caller))
        l->other_thread = 1;
    if (l->n < sizeof l->r / sizeof l->r[0])
        l->r[l->n++] = (report){(int)ph, done, total};
}

/* Runs of one phase in the log: each non-decreasing with a fixed total,
 * ending at done == total.  Returns the runs' phases in order (at most
 * 64) and their totals. */
static int runs(const log_t *l, int *ph, size_t *tot)
{
    int k = 0;
    for (size_t i = 0; i < l->n; i++) {
        const report *r = &l->r[i];
        int fresh = i == 0 || r->phase != l->r[i - 1].phase ||
                    (l->r[i - 1].done == l->r[i - 1].total && r->done < l->r[i - 1].done);
        if (fresh) {
            if (i)
                ck_assert_uint_eq(l->r[i - 1].done, l->r[i - 1].total); /* ended */
            ck_assert_int_lt(k, 64);
            ph[k] = r->phase;
            tot[k++] = r->total;
        } else {
            ck_assert_uint_ge(r->done, l->r[i - 1].done);
            ck_assert_uint_eq(r->total, l->r[i - 1].total);
        }
        ck_assert_uint_le(r->done, r->total);
    }
    ck_assert_uint_gt(l->n, 0);
    ck_assert_uint_eq(l->r[l->n - 1].done, l->r[l->n - 1].total);
    return k;
}

static double *cloud(void)
{
    double *p = malloc(3 * NPTS * sizeof *p);
    uint64_t s = 77;
    for (size_t i = 0; i < NPTS; i++) {
        double x = jf_unit(jf_splitmix64(&s)) - 0.5, y = jf_unit(jf_splitmix64(&s)) - 0.5;
        p[3 * i] = x, p[3 * i + 1] = y, p[3 * i + 2] = 0.5 * (x * x - 2 * y * y);
    }
    return p;
}

static jf_status sink(void *user, const uint32_t *idx, jf_result *res, size_t m)
{
    (void)idx, (void)res;
    __atomic_add_fetch((size_t *)user, m, __ATOMIC_RELAXED);
    return JF_OK;
}

/* Whole cloud: INDEX 0 then n, then FIT up to n; parts: that per part,
 * the parts' FIT totals being the points they fit. */
START_TEST(estimate_phases)
{
    jf_cloud c = {0};
    c.n = NPTS;
    c.xyz = cloud();
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.kind = JF_NB_KNN;
    o.nb.k = 16;
    o.params.degree = 2;
    o.threads = 3;
    o.phase = hook;
    o.phase_user = &lg;
    int ph[64];
    size_t tot[64], got = 0;
    jf_error e;
    memset(&lg, 0, sizeof lg);
    lg.caller = pthread_self();
    ck_assert_int_eq(jf_estimate_blocks(&c, &o, sink, &got, &e), JF_OK);
    ck_assert_uint_eq(got, NPTS);
    ck_assert_int_eq(lg.other_thread, 0);
    ck_assert_int_eq(runs(&lg, ph, tot), 2);
    ck_assert_int_eq(ph[0], JF_PHASE_INDEX);
    ck_assert_int_eq(ph[1], JF_PHASE_FIT);
    ck_assert_uint_eq(tot[0], NPTS);
    ck_assert_uint_eq(tot[1], NPTS);
    ck_assert_uint_eq(lg.r[0].done, 0);

    /* the fit reports as it goes: with one thread every block is the
     * caller's (with three, a slow run, as under valgrind, may leave the
     * caller only one or two blocks) */
    o.threads = 1;
    memset(&lg, 0, sizeof lg);
    lg.caller = pthread_self();
    got = 0;
    ck_assert_int_eq(jf_estimate_blocks(&c, &o, sink, &got, &e), JF_OK);
    ck_assert_uint_eq(got, NPTS);
    ck_assert_int_eq(runs(&lg, ph, tot), 2);
    ck_assert_uint_gt(lg.n, 4);
    o.threads = 3;

    memset(&lg, 0, sizeof lg);
    lg.caller = pthread_self();
    got = 0;
    ck_assert_int_eq(jf_estimate_parts(&c, &o, 3, sink, &got, &e), JF_OK);
    ck_assert_uint_eq(got, NPTS);
    ck_assert_int_eq(lg.other_thread, 0);
    int k = runs(&lg, ph, tot);
    ck_assert_int_ge(k, 6);
    size_t own = 0;
    for (int j = 0; j < k; j++)
        if (ph[j] == JF_PHASE_FIT)
            own += tot[j];
    ck_assert_uint_ge(own, NPTS); /* own points and their halos */
    free(c.xyz);
}
END_TEST

static void setup(void) { tmpdir_setup("/tmp/jf_io_phases_XXXXXX"); }

/* Positioned rows, in a scrambled order, through commit: WRITE reports
 * up to nrows; the bytes of 1 and 4 threads agree, and agree with rows
 * written one by one. */
START_TEST(writer_phases_and_bytes)
{
    const size_t n = 30000;
    jf_column cols[4] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"f", JF_COL_F32},
                         {"status", JF_COL_I32}};
    double *v = malloc(4 * n * sizeof *v);
    uint32_t *rows = malloc(n * sizeof *rows);
    uint64_t s = 3;
    for (size_t i = 0; i < n; i++) {
        v[4 * i] = (jf_unit(jf_splitmix64(&s)) - 0.5) * 1e4;
        v[4 * i + 1] = i % 101 == 0 ? NAN : jf_unit(jf_splitmix64(&s));
        v[4 * i + 2] = jf_unit(jf_splitmix64(&s));
        v[4 * i + 3] = (double)(i % 7);
        rows[i] = (uint32_t)i;
    }
    for (size_t i = n - 1; i > 0; i--) { /* Fisher-Yates */
        size_t j = jf_splitmix64(&s) % (i + 1);
        uint32_t t = rows[i];
        rows[i] = rows[j], rows[j] = t;
    }
    double *pv = malloc(4 * n * sizeof *pv);
    for (size_t i = 0; i < n; i++)
        memcpy(pv + 4 * i, v + 4 * (size_t)rows[i], 4 * sizeof(double));
    static const char *const ext[3] = {"csv", "xyz", "ply"};
    for (int f = 0; f < 3; f++) {
        char ref[512], p1[512], p4[512];
        snprintf(ref, sizeof ref, "%s/ref.%s", tmpdir, ext[f]);
        snprintf(p1, sizeof p1, "%s/t1.%s", tmpdir, ext[f]);
        snprintf(p4, sizeof p4, "%s/t4.%s", tmpdir, ext[f]);
        jf_writer *w;
        jf_error e;
        ck_assert_int_eq(jf_writer_open(ref, cols, 4, n, 1, &w, &e), JF_OK);
        for (size_t i = 0; i < n; i++)
            ck_assert_int_eq(jf_writer_row(w, v + 4 * i), JF_OK);
        ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
        for (int t = 1; t <= 4; t += 3) {
            memset(&lg, 0, sizeof lg);
            lg.caller = pthread_self();
            ck_assert_int_eq(jf_writer_open(t == 1 ? p1 : p4, cols, 4, n, 1, &w, &e), JF_OK);
            jf_writer_progress(w, hook, &lg);
            ck_assert_int_eq(jf_writer_begin_put(w, t), JF_OK);
            for (size_t i = 0; i < n; i += 1000)
                ck_assert_int_eq(jf_writer_put(w, rows + i, pv + 4 * i, n - i < 1000 ? n - i : 1000),
                                 JF_OK);
            ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
            int ph[64];
            size_t tot[64];
            ck_assert_int_eq(runs(&lg, ph, tot), 1);
            ck_assert_int_eq(ph[0], JF_PHASE_WRITE);
            ck_assert_uint_eq(tot[0], n);
            ck_assert_int_eq(lg.other_thread, 0);
        }
        size_t la, lb, lc;
        char *a = jf_test_must_slurp(ref, &la), *b = jf_test_must_slurp(p1, &lb), *c = jf_test_must_slurp(p4, &lc);
        ck_assert_uint_eq(la, lb);
        ck_assert_uint_eq(la, lc);
        ck_assert(!memcmp(a, b, la));
        ck_assert(!memcmp(a, c, la));
        free(a), free(b), free(c);
    }
    free(v);
    free(pv);
    free(rows);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_phases");
    TCase *tc = tcase_create("hooks");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, estimate_phases);
    tcase_add_test(tc, writer_phases_and_bytes);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
