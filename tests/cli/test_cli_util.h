/* test_cli_util.h -- helpers of the end-to-end tests of `jetfit estimate`
 * (tests/test_cli_*.c): run the built binary, make fixtures in a temporary
 * folder, read outputs back with jf_eval_table_read. */
#ifndef JF_TEST_CLI_UTIL_H
#define JF_TEST_CLI_UTIL_H

#include <fcntl.h>
#include <poll.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <dirent.h>

#include "jetfit.h"

#define JETFIT_BIN JF_BUILD_DIR "/jetfit"

static char cli_dir[256];     /* the test's temporary folder       */
static char cli_err[8192];    /* stderr of the last run            */

static inline void cli_setup(void)
{
    snprintf(cli_dir, sizeof cli_dir, "/tmp/jf_cli_XXXXXX");
    if (!mkdtemp(cli_dir)) {
        perror("mkdtemp");
        exit(2);
    }
}

/* rm -rf path (a test folder holding folders). */
static inline void cli_rm_rf(const char *path)
{
    fflush(NULL);
    pid_t p = fork();
    if (p == 0) {
        execl("/bin/rm", "rm", "-rf", path, (char *)NULL);
        _exit(127);
    }
    waitpid(p, NULL, 0);
}

/* Removes the test's folder and everything in it (study folders too). */
static inline void cli_teardown(void) { cli_rm_rf(cli_dir); }

/* 1 if path holds a whole PNG: the signature first and the IEND chunk last
 * (ISO/IEC 15948 §5.2, §11.2.5), read independently of jetfit. */
static inline int cli_whole_png(const char *path)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    unsigned char a[8], b[12];
    int ok = fread(a, 1, 8, f) == 8 && fseek(f, -12, SEEK_END) == 0 && fread(b, 1, 12, f) == 12 &&
             !memcmp(a, sig, 8) && !memcmp(b, iend, 12);
    fclose(f);
    return ok;
}

/* cli_dir "/" name, in a rotating static buffer (8 live paths). */
static inline const char *cli_path(const char *name)
{
    static char buf[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", cli_dir, name);
    return buf[k];
}

static inline int cli_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Number of entries in cli_dir (to see that no temporary was left). */
static inline int cli_count_files(void)
{
    int n = 0;
    DIR *d = opendir(cli_dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    if (d) closedir(d);
    return n;
}

/* Fills argv with `jetfit FIRST ...` from a NULL-terminated list (at most
 * 62 arguments kept), itself NULL-terminated. */
static inline void cli_argv(const char *argv[64], const char *first, va_list ap)
{
    int argc = 0;
    argv[argc++] = JETFIT_BIN;
    for (const char *a = first; a && argc < 63; a = va_arg(ap, const char *)) argv[argc++] = a;
    argv[argc] = NULL;
}

/* Runs `jetfit ARGS...` with stdin from in (NULL: inherited), stdout to
 * out (NULL: /dev/null) and, when tmpdir is not NULL, TMPDIR=tmpdir; stderr
 * captured in cli_err.  Returns the exit status (or 128 + signal). */
static inline int cli_vrun(const char *in, const char *out, const char *tmpdir, const char *first,
                           va_list ap)
{
    const char *argv[64];
    cli_argv(argv, first, ap);
    char errpath[512];
    snprintf(errpath, sizeof errpath, "%s.stderr", cli_dir);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int fe = open(errpath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int fo = out ? open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644) : open("/dev/null", O_WRONLY);
        int fi = in ? open(in, O_RDONLY) : 0;
        if (fe < 0 || fo < 0 || fi < 0) _exit(126);
        if (in) dup2(fi, 0);
        dup2(fe, 2);
        dup2(fo, 1);
        if (tmpdir) setenv("TMPDIR", tmpdir, 1);
        execv(JETFIT_BIN, (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    cli_err[0] = '\0';
    FILE *f = fopen(errpath, "r");
    if (f) {
        size_t m = fread(cli_err, 1, sizeof cli_err - 1, f);
        cli_err[m] = '\0';
        fclose(f);
    }
    unlink(errpath);
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

/* Runs `jetfit ARGS...` (NULL-terminated), stdout to /dev/null, stderr
 * captured in cli_err.  Returns the exit status (or 128 + signal). */
static inline int cli_run(const char *first, ...)
{
    va_list ap;
    va_start(ap, first);
    int st = cli_vrun(NULL, NULL, NULL, first, ap);
    va_end(ap);
    return st;
}

/* cli_run with stdin from in (NULL: /dev/null), stdout to out (NULL:
 * /dev/null) and TMPDIR=tmpdir unless NULL. */
static inline int cli_run_io(const char *in, const char *out, const char *tmpdir,
                             const char *first, ...)
{
    va_list ap;
    va_start(ap, first);
    int st = cli_vrun(in ? in : "/dev/null", out, tmpdir, first, ap);
    va_end(ap);
    return st;
}

/* glibc declares these only under _XOPEN_SOURCE, which check.h's
 * includes may already have settled: declare them here. */
int posix_openpt(int flags);
int grantpt(int fd);
int unlockpt(int fd);
char *ptsname(int fd);

/* Runs `jetfit ARGS...` with stderr on a pseudo-terminal (isatty(2) is
 * true: the progress line is drawn); what it wrote is in cli_err. */
static inline int cli_run_tty(const char *first, ...)
{
    const char *argv[64];
    va_list ap;
    va_start(ap, first);
    cli_argv(argv, first, ap);
    va_end(ap);
    int m = posix_openpt(O_RDWR | O_NOCTTY);
    if (m < 0 || grantpt(m) || unlockpt(m)) return -1;
    const char *slave = ptsname(m);
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        int s = open(slave, O_RDWR | O_NOCTTY), fo = open("/dev/null", O_WRONLY);
        if (s < 0 || fo < 0) _exit(126);
        dup2(s, 2);
        dup2(fo, 1);
        execv(JETFIT_BIN, (char *const *)argv);
        _exit(127);
    }
    size_t used = 0;
    int status = 0, exited = 0;
    for (;;) { /* read until the child is gone and nothing is left */
        struct pollfd pf = {m, POLLIN, 0};
        int ready = poll(&pf, 1, 200);
        if (ready > 0 && (pf.revents & POLLIN)) {
            ssize_t r = read(m, cli_err + used, sizeof cli_err - 1 - used);
            if (r <= 0) break;
            used += (size_t)r;
            if (used == sizeof cli_err - 1) used = 0; /* keep the tail */
            continue;
        }
        if (ready > 0 && !(pf.revents & POLLIN)) break; /* hang-up */
        if (exited) break;
        exited = waitpid(pid, &status, WNOHANG) == pid;
    }
    cli_err[used] = '\0';
    if (!exited) waitpid(pid, &status, 0);
    close(m);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

static inline void cli_write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) exit(2);
    fputs(text, f);
    fclose(f);
}

/* Fibonacci sphere: n points, radius R, centre c. */
static inline void cli_sphere(size_t n, double R, const double c[3], double *xyz)
{
    const double ga = M_PI * (3.0 - sqrt(5.0));
    for (size_t i = 0; i < n; i++) {
        double z = 1 - 2 * ((double)i + 0.5) / (double)n, rr = sqrt(1 - z * z);
        xyz[3 * i] = c[0] + R * rr * cos(ga * (double)i);
        xyz[3 * i + 1] = c[1] + R * rr * sin(ga * (double)i);
        xyz[3 * i + 2] = c[2] + R * z;
    }
}

/* The §6.1 surface z = 0.1 exp(2x + y - y^2) on a jittered grid, in a
 * shuffled order (so input order is not the spatial order). */
static inline void cli_surface61(size_t side, double *xyz, unsigned long long seed)
{
    size_t n = side * side;
    double h = 1.0 / (double)side;
    for (size_t i = 0; i < n; i++) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        double dx = (double)(seed >> 11) / 9007199254740992.0;
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        double dy = (double)(seed >> 11) / 9007199254740992.0;
        double x = -0.5 + h * ((double)(i % side) + 0.9 * dx);
        double y = -0.5 + h * ((double)(i / side) + 0.9 * dy);
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = 0.1 * exp(2 * x + y - y * y);
    }
    for (size_t i = n; i > 1; i--) { /* Fisher-Yates */
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        size_t j = (size_t)((seed >> 11) % i);
        for (int k = 0; k < 3; k++) {
            double t = xyz[3 * (i - 1) + k];
            xyz[3 * (i - 1) + k] = xyz[3 * j + k];
            xyz[3 * j + k] = t;
        }
    }
}

/* Writes x y z [nx ny nz] as .xyz text with %.17g (exact). */
static inline void cli_write_xyz(const char *path, const double *xyz, const double *nrm, size_t n)
{
    FILE *f = fopen(path, "w");
    if (!f) exit(2);
    for (size_t i = 0; i < n; i++) {
        fprintf(f, "%.17g %.17g %.17g", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        if (nrm) fprintf(f, " %.17g %.17g %.17g", nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
        fputc('\n', f);
    }
    fclose(f);
}

static inline void put_be64(FILE *f, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    for (int b = 7; b >= 0; b--) fputc((int)((u >> (8 * b)) & 0xff), f);
}

/* Writes a PLY of x y z doubles: fmt 0 ascii, 1 binary LE, 2 binary BE,
 * with an extra float property and a comment to be skipped. */
static inline void cli_write_ply(const char *path, const double *xyz, size_t n, int fmt)
{
    static const char *const names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    FILE *f = fopen(path, "wb");
    if (!f) exit(2);
    fprintf(f, "ply\nformat %s 1.0\ncomment made by test_cli\nelement vertex %zu\n"
               "property double x\nproperty double y\nproperty double z\n"
               "property float quality\nend_header\n", names[fmt], n);
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        float q = 0.5f;
        if (fmt == 0) {
            fprintf(f, "%.17g %.17g %.17g 0.5\n", p[0], p[1], p[2]);
        } else if (fmt == 1) {
            fwrite(p, sizeof(double), 3, f); /* the test machines are LE */
            fwrite(&q, sizeof q, 1, f);
        } else {
            for (int j = 0; j < 3; j++) put_be64(f, p[j]);
            uint32_t u;
            memcpy(&u, &q, 4);
            for (int b = 3; b >= 0; b--) fputc((int)((u >> (8 * b)) & 0xff), f);
        }
    }
    fclose(f);
}

/* Reads an output table; aborts the test process on failure. */
static inline void cli_read(const char *path, jf_eval_table *t)
{
    jf_error e = {{0}};
    if (jf_eval_table_read(path, t, &e) != JF_OK) {
        fprintf(stderr, "cannot read %s: %s\n", path, e.msg);
        exit(2);
    }
}

/* Value of column `name` in row i. */
static inline double cli_val(const jf_eval_table *t, size_t i, const char *name)
{
    int c = jf_eval_table_col(t, name);
    if (c < 0) {
        fprintf(stderr, "no column %s\n", name);
        exit(2);
    }
    return t->v[i * t->ncols + (size_t)c];
}

#endif
