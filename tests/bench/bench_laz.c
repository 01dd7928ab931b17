/*
 * bench_laz.c -- LAZ decoding speed (issue 25): reading FILE.laz with one
 * thread and with all threads, against reading the same points from the
 * uncompressed LAS file they stand for (written here), and against
 * laz-perf's decoder (npm, WASM, under node) on the same file in the same
 * run when node and laz-perf are there.
 *
 *   bench_laz FILE.laz [REPEATS [NODE_MODULES]]
 *   bench_laz --tile IN N OUT.laz
 *
 * --tile makes a benchmark file of a real one: IN's records (a LAS or LAZ
 * tile) repeated, each copy moved east by the tile's width and later by
 * its GPS time span, until N points, written by jetfit's LAZ writer (no
 * LAZ file of 10^6 points is in the repositories; this keeps a real
 * file's field statistics).
 *
 * Each figure is the best of REPEATS (default 5) wall times of a whole
 * read, in a child process of its own (its peak RSS is the figure's:
 * the cloud made, x y z and records, and the decoder's buffers) (jf_cloud_read: file read, chunks decoded, records and x y z made);
 * points/s = points / seconds; "CPU s" is the process's CPU time for that
 * read (all threads; on a shared machine the steadier figure).  laz-perf's figure is its decoding loop
 * alone (the file already in memory), so the ratio flatters laz-perf.
 * NODE_MODULES defaults to tests/node_modules of the source tree
 * (.ci/install-deps puts laz-perf there).
 */
#define _GNU_SOURCE
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "jetfit.h"

/* the source tree's tests/ (benchmarks get the data folder's path) */
#define TESTS_DIR JF_TEST_DATA "/../tests"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Best wall time of `reps` reads of path (and in *cpu_s the CPU time of
 * that read, all threads); the point count in *n. */
static double best_read(const char *path, int reps, size_t *n, double *cpu_s)
{
    double best = 1e30;
    for (int r = 0; r < reps; r++) {
        jf_cloud c;
        jf_error e;
        double c0 = cpu(), t = now();
        if (jf_cloud_read(path, NULL, &c, &e) != JF_OK) {
            fprintf(stderr, "bench_laz: %s\n", e.msg);
            exit(1);
        }
        t = now() - t;
        double cs = cpu() - c0;
        *n = c.n;
        jf_cloud_free(&c);
        if (t < best)
            best = t, *cpu_s = cs;
    }
    return best;
}

static uint32_t g32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static void p32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void p64(unsigned char *p, uint64_t v)
{
    for (int k = 0; k < 8; k++) p[k] = (unsigned char)(v >> (8 * k));
}

static int tile(const char *in, size_t n, const char *out)
{
    jf_cloud c;
    jf_error e;
    if (jf_cloud_read(in, NULL, &c, &e) != JF_OK || !c.attrs.las_head || !c.n) {
        fprintf(stderr, "bench_laz: %s\n", c.attrs.las_head ? e.msg : "not a LAS/LAZ input");
        return 1;
    }
    const unsigned char *h = c.attrs.las_head;
    unsigned fmt = h[104] & 0x3f;
    size_t rl = c.attrs.stride, gps = fmt >= 6 ? 22 : fmt == 1 || fmt == 3 || fmt == 4 || fmt == 5 ? 20 : 0;
    int32_t xmin = INT32_MAX, xmax = INT32_MIN;
    double tmin = 1e300, tmax = -1e300;
    for (size_t i = 0; i < c.n; i++) {
        const unsigned char *r = c.attrs.rec + i * rl;
        int32_t x = (int32_t)g32(r);
        xmin = x < xmin ? x : xmin, xmax = x > xmax ? x : xmax;
        if (gps) {
            double t;
            memcpy(&t, r + gps, 8);
            tmin = t < tmin ? t : tmin, tmax = t > tmax ? t : tmax;
        }
    }
    /* a LAS file: the input's header and VLRs (count patched), the copies */
    size_t hl = c.attrs.las_head_len;
    unsigned char *b = malloc(hl + n * rl);
    if (!b) return 1;
    memcpy(b, h, hl);
    p32(b + 96, (uint32_t)hl);
    p32(b + 107, fmt < 6 ? (uint32_t)n : 0);
    if (b[25] >= 4) p64(b + 247, n), memset(b + 235, 0, 12);
    for (size_t i = 0; i < n; i++) {
        size_t copy = i / c.n;
        unsigned char *r = b + hl + i * rl;
        memcpy(r, c.attrs.rec + (i % c.n) * rl, rl);
        p32(r, (uint32_t)((int64_t)(int32_t)g32(r) + (int64_t)copy * ((int64_t)xmax - xmin + 1)));
        if (gps) {
            double t;
            memcpy(&t, r + gps, 8);
            t += (double)copy * (tmax - tmin + 1.0);
            memcpy(r + gps, &t, 8);
        }
    }
    char las[] = "/tmp/jf_bench_tile_XXXXXX.las";
    int fd = mkstemps(las, 4);
    FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    int ok = f && fwrite(b, 1, hl + n * rl, f) == hl + n * rl;
    if (f && fclose(f)) ok = 0;
    free(b);
    jf_cloud_free(&c);
    jf_cloud t;
    if (!ok || jf_cloud_read(las, NULL, &t, &e) != JF_OK) {
        fprintf(stderr, "bench_laz: tiled file: %s\n", ok ? e.msg : "cannot write");
        unlink(las);
        return 1;
    }
    unlink(las);
    jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    jf_writer *w;
    jf_status st = jf_writer_open(out, cols, 3, t.n, 0, &w, &e);
    if (st == JF_OK) {
        jf_writer_attrs(w, &t.attrs);
        jf_writer_rows(w, t.xyz, t.n, 0);
        st = jf_writer_commit(w, &e);
    }
    if (st != JF_OK) fprintf(stderr, "bench_laz: %s\n", e.msg);
    else printf("bench_laz: %s: %zu points of format %u\n", out, t.n, fmt);
    jf_cloud_free(&t);
    return st != JF_OK;
}

/* The LAS file the LAZ stands for: header and VLRs, records, EVLRs. */
static int write_las(const char *laz, const char *las)
{
    jf_cloud c;
    jf_error e;
    if (jf_cloud_read(laz, NULL, &c, &e) != JF_OK) {
        fprintf(stderr, "bench_laz: %s\n", e.msg);
        return 1;
    }
    FILE *f = fopen(las, "wb");
    if (!f || fwrite(c.attrs.las_head, 1, c.attrs.las_head_len, f) != c.attrs.las_head_len ||
        fwrite(c.attrs.rec, c.attrs.stride, c.n, f) != c.n ||
        (c.attrs.las_evlr_len &&
         fwrite(c.attrs.las_evlr, 1, c.attrs.las_evlr_len, f) != c.attrs.las_evlr_len) ||
        fclose(f) != 0) {
        fprintf(stderr, "bench_laz: cannot write %s\n", las);
        return 1;
    }
    jf_cloud_free(&c);
    return 0;
}

/* argv run as a child process (each figure in its own process, so that
 * its peak resident set is its own); its output in out, its peak RSS in
 * MB; 0 when it failed.  quiet: its stderr dropped (node without
 * laz-perf is a note, not an error). */
static int run(char *const argv[], char *out, size_t outlen, double *rss_mb, int quiet)
{
    int fd[2];
    if (pipe(fd))
        return 0;
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fd[1], 1);
        close(fd[0]), close(fd[1]);
        if (quiet && !freopen("/dev/null", "w", stderr))
            _exit(127);
        execvp(argv[0], argv);
        _exit(127);
    }
    close(fd[1]);
    size_t got = 0;
    ssize_t k;
    while (got + 1 < outlen && (k = read(fd[0], out + got, outlen - 1 - got)) > 0)
        got += (size_t)k;
    out[got] = '\0';
    close(fd[0]);
    int status = 0;
    struct rusage ru;
    if (pid < 0 || wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) ||
        WEXITSTATUS(status))
        return 0;
    *rss_mb = (double)ru.ru_maxrss / 1024.0;
    return 1;
}

/* One figure: `self --read FILE THREADS REPS` in a child. */
static int measure(const char *self, const char *file, int threads, int reps, double *t,
                   double *c, size_t *n, double *rss)
{
    char th[16], rp[16], out[256];
    snprintf(th, sizeof th, "%d", threads), snprintf(rp, sizeof rp, "%d", reps);
    char *const argv[] = {(char *)self, "--read", (char *)file, th, rp, NULL};
    return run(argv, out, sizeof out, rss, 0) && sscanf(out, "%lf %lf %zu", t, c, n) == 3;
}

int main(int argc, char **argv)
{
    if (argc == 5 && !strcmp(argv[1], "--tile"))
        return tile(argv[2], (size_t)atol(argv[3]), argv[4]);
    if (argc == 5 && !strcmp(argv[1], "--read")) { /* a child of measure() */
        size_t n = 0;
        double cs = 0;
        omp_set_num_threads(atoi(argv[3]));
        double t = best_read(argv[2], atoi(argv[4]), &n, &cs);
        printf("%.6f %.6f %zu\n", t, cs, n);
        return 0;
    }
    if (argc == 4 && !strcmp(argv[1], "--las"))
        return write_las(argv[2], argv[3]);
    if (argc < 2) {
        fprintf(stderr, "usage: bench_laz FILE.laz [REPEATS [NODE_MODULES]]\n"
                        "       bench_laz --tile IN N OUT.laz\n");
        return 2;
    }
    const char *laz = argv[1];
    int reps = argc > 2 ? atoi(argv[2]) : 5;
    const char *modules = argc > 3 ? argv[3] : TESTS_DIR "/node_modules";
    /* the parent runs no OpenMP region: every read is in a fresh child */
    char self[4096];
    ssize_t sl = readlink("/proc/self/exe", self, sizeof self - 1);
    if (sl <= 0) {
        fprintf(stderr, "bench_laz: cannot find its own executable\n");
        return 1;
    }
    self[sl] = '\0';
    int all = omp_get_max_threads();
    size_t n = 0, n2 = 0;
    double t1, c1, r1, tn, cn, rn, tl, cl, rl, rs;
    char las[] = "/tmp/jf_bench_laz_XXXXXX.las", out[256];
    int fd = mkstemps(las, 4);
    if (fd < 0)
        return 1;
    close(fd);
    char *const wr[] = {self, "--las", (char *)laz, las, NULL};
    if (!measure(self, laz, 1, reps, &t1, &c1, &n, &r1) ||
        !measure(self, laz, all, reps, &tn, &cn, &n, &rn) || !run(wr, out, sizeof out, &rs, 0) ||
        !measure(self, las, all, reps, &tl, &cl, &n2, &rl)) {
        fprintf(stderr, "bench_laz: a read failed\n");
        unlink(las);
        return 1;
    }
    unlink(las);
    printf("file: %s, %zu points, best of %d\n", laz, n, reps);
    printf("| read | threads | seconds | CPU s | points/s | peak RSS (MB) |\n"
           "|---|---|---|---|---|---|\n");
    printf("| LAS, the same records (jetfit) | %d | %.4f | %.4f | %.3g | %.0f |\n", all, tl, cl,
           n2 / tl, rl);
    printf("| LAZ (jetfit) | 1 | %.4f | %.4f | %.3g | %.0f |\n", t1, c1, n / t1, r1);
    printf("| LAZ (jetfit) | %d | %.4f | %.4f | %.3g | %.0f |\n", all, tn, cn, n / tn, rn);
    char script[4096], rp[16];
    snprintf(script, sizeof script, "%s/bench/lazperf_bench.js", TESTS_DIR);
    snprintf(rp, sizeof rp, "%d", reps);
    char *const node[] = {"node", script, (char *)modules, (char *)laz, rp, NULL};
    double tp = 0, cp = 0, rp_mb = 0;
    size_t np = 0;
    if (run(node, out, sizeof out, &rp_mb, 1) &&
        sscanf(out, "lazperf %lf %lf %zu", &tp, &cp, &np) == 3 && np == n)
        printf("| LAZ (laz-perf %s, WASM under node, decode loop only) | 1 | %.4f | %.4f | "
               "%.3g | %.0f |\n", "0.0.7", tp, cp, n / tp, rp_mb);
    else
        tp = 0, printf("(laz-perf: not run -- no node or no laz-perf in %s)\n", modules);
    printf("LAZ %d threads / one thread: %.2fx the points/s\n", all, t1 / tn);
    printf("LAZ one thread / LAS: %.2fx the time\n", t1 / tl);
    if (tp > 0)
        printf("LAZ one thread (jetfit) / laz-perf: %.2fx the points/s, %.2fx per CPU second\n",
               tp / t1, cp / c1);
    return 0;
}
