/*
 * bench_io.c -- speed and peak memory of the writers and readers on N
 * generated points (default 10^7), beside naive stdio peers measured in
 * the same run: fprintf("%.17g") for writing text, fscanf("%lf") for
 * reading it; LAS (format 0, written and read by jetfit) against our
 * binary PLY reader and writer.
 *
 *   bench_io [N] [DIR]      (files DIR/jf_bench.*; removed at the end)
 *
 * Each step runs in its own forked child so its peak memory (ru_maxrss,
 * from wait4) is its own; the points array (24 bytes/point) is part of
 * every step's peak, and a read's peak includes the mapped file (page
 * cache).  "seconds" is wall time (the machine may be shared), "cpu s"
 * the step's own CPU time, points/s = N / seconds, MB/s = the file's size
 * (10^6 bytes) / seconds.  Also the table writer on 10^6 rows x 28 columns
 * (the estimate command's widest output) as binary PLY and CSV.  E57
 * (issue 26): the same points as one scan of single-precision Cartesian
 * floats (as scanners write them), written by the tests' E57 writer
 * (tests/io/e57_write.h, not timed against anything) and read by jetfit,
 * against reading them as LAS format 0 (uncompressed) in the same run.
 * Text read and written on all threads (blocks: io_xyz.c, jf_writer_rows)
 * against one thread, in the same run.
 */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "jetfit.h"

#include "e57_write.h"

static size_t N = 10000000;
static char dir[512] = "/tmp";

static double cpu0; /* CPU seconds of this process at the last now() */

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Wall clock; also notes the CPU clock, so that the second call of a
 * "t = now(); ...; t = now() - t" pair leaves the step's CPU time in
 * step_cpu. */
static double step_cpu;
static int ticking;
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    double c = cpu_now();
    if (ticking)
        step_cpu = c - cpu0;
    cpu0 = c;
    ticking = !ticking;
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* N points on a wavy surface, full-precision doubles (17 digits in text) */
static double *gen(size_t n)
{
    double *p = malloc(3 * n * sizeof *p);
    if (!p)
        exit(2);
    uint64_t s = 42;
    for (size_t i = 0; i < n; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        double u = (double)(s >> 11) * 0x1p-53;
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        double v = (double)(s >> 11) * 0x1p-53;
        p[3 * i] = 100 * u;
        p[3 * i + 1] = 100 * v;
        p[3 * i + 2] = sin(u * 20) * cos(v * 20);
    }
    return p;
}

static void path(char *out, const char *ext)
{
    snprintf(out, 600, "%s/jf_bench.%s", dir, ext);
}

/* ---- the steps (run in a child; return seconds, or < 0 on failure) ---- */

static double write_cloud(const char *ext, int ascii)
{
    jf_cloud c = {0};
    c.n = N;
    c.xyz = gen(N);
    char p[600];
    path(p, ext);
    jf_error e;
    double t = now();
    jf_status st = jf_cloud_write(p, &c, ascii, &e);
    t = now() - t;
    if (st != JF_OK)
        fprintf(stderr, "%s\n", e.msg);
    free(c.xyz);
    return st == JF_OK ? t : -1;
}

static double write_fprintf(void)
{
    double *x = gen(N);
    char p[600];
    path(p, "peer.xyz");
    double t = now();
    FILE *f = fopen(p, "w");
    if (!f)
        return -1;
    for (size_t i = 0; i < N; i++)
        fprintf(f, "%.17g %.17g %.17g\n", x[3 * i], x[3 * i + 1],
                x[3 * i + 2]);
    int bad = fclose(f) != 0;
    t = now() - t;
    free(x);
    return bad ? -1 : t;
}

/* threads: the text parser's (0: all cores) */
static double read_cloud(const char *ext, int threads)
{
    char p[600];
    path(p, ext);
    jf_cloud c;
    jf_error e;
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.threads = threads;
    double t = now();
    jf_status st = jf_cloud_read(p, &o, &c, &e);
    t = now() - t;
    if (st != JF_OK) {
        fprintf(stderr, "%s\n", e.msg);
        return -1;
    }
    /* must equal the generated points bit for bit; LAS within half its
     * scale step (1e-7 m for this 100 m cloud: io_las_write.c) */
    double *x = gen(N);
    int same = c.n == N;
    if (same && strcmp(ext, "e57") == 0) { /* single floats */
        for (size_t i = 0; i < 3 * N && same; i++)
            same = c.xyz[i] == (double)(float)x[i];
    } else if (same && strcmp(ext, "las") == 0) {
        for (size_t i = 0; i < 3 * N && same; i++)
            same = fabs(c.xyz[i] - x[i]) <= 0.5e-7 * (1 + 1e-6) + 1e-15 * fabs(x[i]);
    } else if (same) {
        same = !memcmp(x, c.xyz, 3 * N * sizeof *x);
    }
    free(x);
    jf_cloud_free(&c);
    if (!same)
        fprintf(stderr, "%s: read back differs\n", p);
    return same ? t : -1;
}

/* One scan of x y z as single floats, 21000-byte stream pieces a packet. */
static double write_e57(void)
{
    double *x = gen(N);
    ew_field f[3] = {{"cartesianX", EW_FLOAT, 0, 0, 0, x, 3},
                     {"cartesianY", EW_FLOAT, 0, 0, 0, x + 1, 3},
                     {"cartesianZ", EW_FLOAT, 0, 0, 0, x + 2, 3}};
    ew_scan s = {{1, 0, 0, 0}, {0, 0, 0}, N, f, 3};
    double t = now();
    size_t len;
    unsigned char *b = ew_make(&s, 1, 21000, NULL, &len);
    char p[600];
    path(p, "e57");
    int bad = ew_save(p, b, len);
    t = now() - t;
    free(b);
    free(x);
    return bad ? -1 : t;
}

/* The points as .xyz through the table writer on `threads` threads
 * (jf_cloud_write's bytes: test_io_write). */
static double write_xyz_threads(int threads)
{
    double *x = gen(N);
    jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    char p[600];
    path(p, "1t.xyz");
    jf_writer *w;
    jf_error e;
    double t = now();
    if (jf_writer_open(p, cols, 3, N, 0, &w, &e) != JF_OK)
        return -1;
    jf_writer_rows(w, x, N, threads);
    jf_status st = jf_writer_commit(w, &e);
    t = now() - t;
    free(x);
    return st == JF_OK ? t : -1;
}

static double read_fscanf(void)
{
    char p[600];
    path(p, "xyz");
    double t = now();
    FILE *f = fopen(p, "r");
    if (!f)
        return -1;
    size_t n = 0, cap = 1024;
    double *x = malloc(3 * cap * sizeof *x);
    int ch = fgetc(f);
    if (ch == '#') /* our header line */
        while ((ch = fgetc(f)) != EOF && ch != '\n')
            ;
    else
        ungetc(ch, f);
    while (x && fscanf(f, "%lf %lf %lf", &x[3 * n], &x[3 * n + 1],
                       &x[3 * n + 2]) == 3) {
        if (++n == cap) {
            cap *= 2;
            x = realloc(x, 3 * cap * sizeof *x);
        }
    }
    fclose(f);
    t = now() - t;
    int ok = n == N;
    free(x);
    return ok ? t : -1;
}

static double write_table(const char *ext)
{
    size_t rows = N / 10, ncols = 28;
    jf_column cols[28];
    char names[28][8];
    for (size_t j = 0; j < ncols; j++) {
        snprintf(names[j], sizeof names[j], "c%zu", j);
        cols[j].name = names[j];
        cols[j].type = j >= 23 && j != 25 && j != 26 ? JF_COL_I32
                                                      : JF_COL_F64;
    }
    double *x = gen(rows * 10); /* 30 values per row to pick from */
    char p[600];
    path(p, ext);
    jf_writer *w;
    jf_error e;
    double t = now();
    if (jf_writer_open(p, cols, ncols, rows, 0, &w, &e) != JF_OK)
        return -1;
    for (size_t i = 0; i < rows; i++)
        jf_writer_row(w, x + 30 * i);
    jf_status st = jf_writer_commit(w, &e);
    t = now() - t;
    free(x);
    return st == JF_OK ? t : -1;
}

/* ---- driver ------------------------------------------------------------ */

typedef struct {
    const char *what;
    int kind;
    const char *ext;
    int ascii;
    size_t count; /* 0: N points per run; else N / 10 rows (the tables) */
} step;

static double run(const step *s)
{
    switch (s->kind) {
    case 0: return write_cloud(s->ext, s->ascii);
    case 1: return write_fprintf();
    case 2: return read_cloud(s->ext, 0);
    case 6: return read_cloud(s->ext, 1);
    case 7: return write_xyz_threads(1);
    case 3: return read_fscanf();
    case 5: return write_e57();
    default: return write_table(s->ext);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1)
        N = strtoull(argv[1], NULL, 10);
    if (argc > 2)
        snprintf(dir, sizeof dir, "%s", argv[2]);
    if (N < 10)
        N = 10;
    const step steps[] = {
        {"write binary PLY (jetfit)", 0, "ply", 0, 0},
        {"write ascii PLY (jetfit)", 0, "a.ply", 1, 0},
        {"write xyz (jetfit)", 0, "xyz", 0, 0},
        {"write xyz (peer: fprintf %.17g)", 1, "peer.xyz", 0, 0},
        {"write LAS format 0 (jetfit)", 0, "las", 0, 0},
        {"read binary PLY (jetfit)", 2, "ply", 0, 0},
        {"read ascii PLY (jetfit)", 2, "a.ply", 0, 0},
        {"read xyz (jetfit)", 2, "xyz", 0, 0},
        {"read xyz (peer: fscanf %lf)", 3, "xyz", 0, 0},
        {"read LAS format 0 (jetfit)", 2, "las", 0, 0},
        {"table N/10 x 28 cols, binary PLY", 4, "t.ply", 0, 1},
        {"table N/10 x 28 cols, CSV", 4, "t.csv", 0, 1},
        {"write E57 float (tests' writer)", 5, "e57", 0, 0},
        {"read E57 float (jetfit)", 2, "e57", 0, 0},
        {"read xyz (jetfit, 1 thread)", 6, "xyz", 0, 0},
        {"write xyz (jetfit, 1 thread)", 7, "1t.xyz", 0, 0},
    };
    size_t nsteps = sizeof steps / sizeof *steps;
    double secs[20], cpus[20];
    printf("bench_io: N = %zu points, files in %s\n", N, dir);
    printf("%-36s %9s %9s %14s %9s %10s\n", "step", "seconds", "cpu s",
           "points/s", "MB/s", "peak MiB");
    for (size_t i = 0; i < nsteps; i++) {
        int fd[2];
        if (pipe(fd) != 0)
            return 2;
        pid_t pid = fork();
        if (pid == 0) {
            close(fd[0]);
            double t[2];
            t[0] = run(&steps[i]);
            t[1] = step_cpu;
            if (write(fd[1], t, sizeof t) != sizeof t)
                _exit(3);
            _exit(0);
        }
        close(fd[1]);
        double tt[2] = {-1, -1};
        if (read(fd[0], tt, sizeof tt) != sizeof tt)
            tt[0] = -1;
        double t = tt[0];
        close(fd[0]);
        int status;
        struct rusage ru;
        wait4(pid, &status, 0, &ru);
        size_t count = steps[i].count ? N / 10 : N;
        secs[i] = t;
        cpus[i] = tt[1];
        char p[600];
        path(p, steps[i].ext);
        struct stat sb;
        double mb = stat(p, &sb) == 0 ? (double)sb.st_size / 1e6 : NAN;
        if (t < 0)
            printf("%-36s %9s\n", steps[i].what, "FAILED");
        else /* cpu: the step alone (user + system) */
            printf("%-36s %9.2f %9.2f %14.0f %9.1f %10.0f\n", steps[i].what, t,
                   tt[1], (double)count / t, mb / t, (double)ru.ru_maxrss / 1024.0);
        fflush(stdout);
    }
    if (secs[2] > 0 && secs[3] > 0)
        printf("write xyz: jetfit is %.2fx the speed of fprintf\n",
               secs[3] / secs[2]);
    if (secs[7] > 0 && secs[8] > 0)
        printf("read xyz: jetfit is %.2fx the speed of fscanf\n",
               secs[8] / secs[7]);
    if (secs[5] > 0 && secs[8] > 0)
        printf("read binary PLY: %.2fx the speed of fscanf on xyz\n",
               secs[8] / secs[5]);
    /* points/s ratios (the same N points), by wall and by CPU time (on a
     * shared machine the wall time of file I/O is the noisier); LAS
     * records are 20 bytes, PLY rows 24, so MB/s ratios are 5/6 of these */
    if (secs[0] > 0 && secs[4] > 0 && cpus[4] > 0)
        printf("write LAS: %.2fx the points/s of write binary PLY (CPU time: %.2fx)\n",
               secs[0] / secs[4], cpus[0] / cpus[4]);
    if (secs[5] > 0 && secs[9] > 0 && cpus[9] > 0)
        printf("read LAS: %.2fx the points/s of read binary PLY (CPU time: %.2fx)\n",
               secs[5] / secs[9], cpus[5] / cpus[9]);
    if (secs[9] > 0 && secs[13] > 0 && cpus[9] > 0)
        printf("read E57 float: %.2fx the time of read LAS (CPU time: %.2fx; goal <= 2x)\n",
               secs[13] / secs[9], cpus[13] / cpus[9]);
    /* text in blocks on the threads (issue 28.3): against one thread */
    if (secs[7] > 0 && secs[14] > 0)
        printf("read xyz: all threads %.2fx the speed of 1 thread\n", secs[14] / secs[7]);
    if (secs[2] > 0 && secs[15] > 0)
        printf("write xyz: all threads %.2fx the speed of 1 thread\n", secs[15] / secs[2]);
    static const char *const exts[] = {"ply", "a.ply", "xyz", "peer.xyz",
                                       "las", "t.ply", "t.csv", "e57", "1t.xyz"};
    for (size_t i = 0; i < sizeof exts / sizeof *exts; i++) {
        char p[600];
        path(p, exts[i]);
        unlink(p);
    }
    return 0;
}
