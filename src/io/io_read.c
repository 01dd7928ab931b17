/*
 * io_read.c -- jf_cloud_read: picks the reader from the extension, maps the
 * file, and holds the pieces every reader shares (messages, exact number
 * parsing, growable arrays).
 *
 * design: the file is read whole (never mapped: issue 11) and the reader
 * parses the byte range in place: no copy, no allocation per token, no
 * reading past the end.  A binary PLY point cloud is read in chunks
 * straight into the coordinates instead (io_ply.c, jf__read_ply_chunked),
 * so that a 10^8-point file is not held twice; a large text table in
 * pieces of whole lines (jf_pieces, io_xyz.c's jf__read_xyz_fd).  Counts
 * read from headers are checked against the bytes left before anything
 * is allocated from them.
 */
#define _POSIX_C_SOURCE 200809L
#include "io_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

const unsigned char jf_sep_class[256] = {
    ['\t'] = 1, ['\v'] = 1, ['\f'] = 1, ['\r'] = 1, [' '] = 1,
    [','] = 2, [';'] = 2};

void jf_read_opts_init(jf_read_opts *o)
{
    if (!o)
        return;
    memset(o, 0, sizeof *o); /* padding too: the options compare whole */
    for (int i = 0; i < 6; i++)
        o->columns[i] = -1;
    o->bad_rows = 0;
    o->no_attrs = 0;
    o->threads = 0;
    o->progress = NULL;
    o->progress_user = NULL;
}

void jf_cloud_free(jf_cloud *c)
{
    if (!c)
        return;
    free(c->xyz);
    free(c->nrm);
    free(c->face_off);
    free(c->face_idx);
    free(c->scan);
    free(c->scanner);
    jf_attrs_free(&c->attrs);
    memset(c, 0, sizeof *c);
}

jf_status jf_io_fail(jf_error *err, jf_status st, const char *name,
                     size_t line, const char *fmt, ...)
{
    if (!err)
        return st;
    int k = line ? snprintf(err->msg, sizeof err->msg, "%s:%zu: ", name, line)
                 : snprintf(err->msg, sizeof err->msg, "%s: ", name);
    if (k < 0 || (size_t)k >= sizeof err->msg)
        return st;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg + k, sizeof err->msg - (size_t)k, fmt, ap);
    va_end(ap);
    /* one line: a control character from the file must not break it */
    for (char *q = err->msg; *q; q++)
        if ((unsigned char)*q < 0x20)
            *q = ' ';
    return st;
}

jf_format jf_format_from_path(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (!dot || (slash && dot < slash))
        return JF_FMT_UNKNOWN;
    char ext[8];
    size_t n = strlen(dot + 1);
    if (n == 0 || n >= sizeof ext)
        return JF_FMT_UNKNOWN;
    for (size_t i = 0; i <= n; i++) {
        char ch = dot[1 + i];
        ext[i] = (ch >= 'A' && ch <= 'Z') ? (char)(ch - 'A' + 'a') : ch;
    }
    if (!strcmp(ext, "ply"))
        return JF_FMT_PLY;
    if (!strcmp(ext, "xyz") || !strcmp(ext, "txt"))
        return JF_FMT_XYZ;
    if (!strcmp(ext, "pts"))
        return JF_FMT_PTS;
    if (!strcmp(ext, "csv"))
        return JF_FMT_CSV;
    if (!strcmp(ext, "off"))
        return JF_FMT_OFF;
    if (!strcmp(ext, "las") || !strcmp(ext, "laz"))
        return JF_FMT_LAS;
    if (!strcmp(ext, "ptx"))
        return JF_FMT_PTX;
    if (!strcmp(ext, "e57"))
        return JF_FMT_E57;
    return JF_FMT_UNKNOWN;
}

/* ---- numbers ---------------------------------------------------------- */

/* 10^0 .. 10^22 are exact doubles (Clinger's fast path). */
static const double jf_pow10[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static int slow_double(const char *s, const char *e, double *out)
{
    char tmp[512];
    size_t n = (size_t)(e - s);
    if (n == 0 || n >= sizeof tmp)
        return 0;
    memcpy(tmp, s, n);
    tmp[n] = '\0';
    char *end = NULL;
    errno = 0;
    double v = strtod(tmp, &end);
    if (end != tmp + n)
        return 0;
    /* ERANGE: overflow gives +-HUGE_VAL (= inf), underflow a denormal or
     * 0 -- both the nearest double, which is what the file means. */
    *out = v;
    return 1;
}

/* m 10^e10 correctly rounded, for m < 2^64, |e10| <= 27, by exact 128-bit
 * integer arithmetic (the digits a %.17g writer produces); 0 if the result
 * would be subnormal (left to strtod). */
static int wide_double(uint64_t m, int e10, double *out)
{
    if (m == 0)
        return 0;
    if (e10 >= 0) {
        /* m 5^e < 2^127: exact; one rounding in the conversion */
        unsigned __int128 p = (unsigned __int128)m * jf_pow5(e10);
        *out = ldexp((double)p, e10);
        return 1;
    }
    int k = -e10, lz = __builtin_clzll(m);
    uint64_t d = jf_pow5(k);
    /* q = floor(m 2^(lz+63) / 5^k) has >= 64 bits; a sticky last bit for a
     * non-zero remainder makes the one rounding to 53 bits exact */
    unsigned __int128 num = (unsigned __int128)(m << lz) << 63;
    unsigned __int128 q = num / d;
    q |= (num % d) != 0;
    double v = (double)q;
    int sh = lz + 63 + k;
    if (ilogb(v) - sh < -1021)
        return 0;
    *out = ldexp(v, -sh);
    return 1;
}

/* Eight ASCII digits at p as their value, or -1 (fast_float's SWAR test
 * and three multiplies; little-endian loads). */
static inline int64_t eight_digits(const char *p)
{
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    uint64_t x;
    memcpy(&x, p, sizeof x);
    if (((x & 0xF0F0F0F0F0F0F0F0ULL) |
         (((x + 0x0606060606060606ULL) & 0xF0F0F0F0F0F0F0F0ULL) >> 4)) != 0x3333333333333333ULL)
        return -1;
    x -= 0x3030303030303030ULL;
    x = x * 10 + (x >> 8);
    x = (((x & 0x000000FF000000FFULL) * (100 + (1000000ULL << 32))) +
         (((x >> 16) & 0x000000FF000000FFULL) * (1 + (10000ULL << 32)))) >> 32;
    return (int64_t)(uint32_t)x;
#else
    (void)p;
    return -1;
#endif
}

/* Digits at *pp into m (at most 19 significant: *nd counts them), eight
 * at a time once m is non-zero; *cnt counts every digit, *taken those
 * taken (fraction: the exponent's decrement).  0 if strtod must decide
 * (a 20th significant digit, or more than 400 digits). */
static inline int digit_run(const char **pp, const char *e, uint64_t *m, int *nd, int *cnt,
                            int *taken)
{
    const char *p = *pp;
    for (;;) {
        int64_t v8;
        if (*m != 0 && *nd <= 11 && e - p >= 8 && (v8 = eight_digits(p)) >= 0) {
            *m = *m * 100000000u + (uint64_t)v8;
            *nd += 8, *taken += 8, p += 8;
            if ((*cnt += 8) > 400)
                return 0;
            continue;
        }
        if (p >= e || (unsigned)(*p - '0') >= 10)
            break;
        if (*nd >= 19)
            return 0;
        *m = *m * 10 + (uint64_t)(*p - '0');
        *nd += (*m != 0);
        (*taken)++, p++;
        if (++*cnt > 400) /* bounds the exponent; strtod decides */
            return 0;
    }
    *pp = p;
    return 1;
}

/* The decimal number at the start of [s, e) in the one-rounding and
 * Eisel-Lemire ranges: its end, or NULL (nan, inf, hex, 20+ digits, no
 * digits, a malformed exponent, subnormal results: strtod's cases). */
const char *jf_scan_double(const char *s, const char *e, double *out)
{
    const char *p = s;
    int neg = 0;
    if (p < e && (*p == '-' || *p == '+'))
        neg = (*p++ == '-');
    uint64_t m = 0;
    int nd = 0, exp10 = 0, digits = 0, ip = 0, fp = 0;
    if (!digit_run(&p, e, &m, &nd, &digits, &ip))
        return NULL;
    if (p < e && *p == '.') {
        p++;
        if (!digit_run(&p, e, &m, &nd, &digits, &fp))
            return NULL;
        exp10 = -fp;
    }
    if (!digits)
        return NULL;
    if (p < e && (*p == 'e' || *p == 'E')) {
        p++;
        int eneg = 0, ev = 0, ed = 0;
        if (p < e && (*p == '-' || *p == '+'))
            eneg = (*p++ == '-');
        while (p < e && (unsigned)(*p - '0') < 10 && ed < 6) {
            ev = ev * 10 + (*p++ - '0');
            ed++;
        }
        if (!ed || (p < e && (unsigned)(*p - '0') < 10))
            return NULL;
        exp10 += eneg ? -ev : ev;
    }
    if (m > ((uint64_t)1 << 53) || exp10 > 22 || exp10 < -22) {
        double v;
        if (!jf__lemire(m, exp10, &v) &&
            (exp10 < -27 || exp10 > 27 || !wide_double(m, exp10, &v)))
            return NULL;
        *out = neg ? -v : v;
        return p;
    }
    double v = (double)m;
    v = exp10 >= 0 ? v * jf_pow10[exp10] : v / jf_pow10[-exp10];
    *out = neg ? -v : v;
    return p;
}

int jf_parse_double(const char *s, const char *e, double *out)
{
    /* the whole token or strtod (hex floats, nan, inf, long mantissas) */
    double v;
    if (jf_scan_double(s, e, &v) == e) {
        *out = v;
        return 1;
    }
    return slow_double(s, e, out);
}

int jf_parse_size(const char *s, const char *e, uint64_t max, uint64_t *out)
{
    if (s < e && *s == '+')
        s++;
    if (s >= e)
        return 0;
    uint64_t v = 0;
    for (const char *p = s; p < e; p++) {
        unsigned d = (unsigned)(*p - '0');
        if (d >= 10 || v > (max - d) / 10)
            return 0;
        v = v * 10 + d;
    }
    *out = v;
    return 1;
}

/* ---- growable arrays -------------------------------------------------- */

static int grow(void **v, size_t *cap, size_t want, size_t elem)
{
    if (want <= *cap)
        return 1;
    size_t nc = *cap ? *cap : 64;
    while (nc < want) {
        if (nc > SIZE_MAX / 2 / elem)
            return 0;
        nc *= 2;
    }
    void *q = realloc(*v, nc * elem);
    if (!q)
        return 0;
    *v = q;
    *cap = nc;
    return 1;
}

int jf_dvec_reserve(jf_dvec *a, size_t cap)
{
    return grow((void **)&a->v, &a->cap, cap, sizeof *a->v);
}

int jf_uvec_reserve(jf_uvec *a, size_t cap)
{
    return grow((void **)&a->v, &a->cap, cap, sizeof *a->v);
}

int jf_zvec_reserve(size_t **v, size_t *cap, size_t want)
{
    return grow((void **)v, cap, want, sizeof **v);
}

/* ---- a text file in pieces (jf_pieces, io_internal.h) ----------------- */

/* Reads n bytes at offset off into b: 0, or the errno (-1: the file ended). */
static int read_at(int fd, char *b, size_t n, size_t off, size_t *got)
{
    size_t g = 0;
    while (g < n) {
        ssize_t r = pread(fd, b + g, n - g > (1u << 30) ? (1u << 30) : n - g, (off_t)(off + g));
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0) {
            *got = g;
            return r < 0 ? (errno ? errno : EIO) : -1;
        }
        g += (size_t)r;
    }
    *got = g;
    return 0;
}

static jf_status io_error(jf_pieces *p, int e, jf_error *err)
{
    jf_status st = e > 0 ? jf_io_fail(err, JF_ERR_IO, p->name, 0, "read failed: %s",
                                      strerror(e))
                         : jf_io_fail(err, JF_ERR_IO, p->name, 0,
                                      "the file shrank while it was read (%zu of %zu bytes)",
                                      p->got, p->len);
    p->len = p->got; /* nothing more is read */
    return st;
}

/* The line of the NUL at file offset z: the file's '\n' before it, read
 * again (a message only). */
static size_t nul_line(int fd, size_t z)
{
    char b[65536];
    size_t line = 1, g;
    for (size_t off = 0; off < z; off += sizeof b) {
        size_t n = z - off < sizeof b ? z - off : sizeof b;
        (void)read_at(fd, b, n, off, &g);
        for (const char *q = b; (q = memchr(q, '\n', (size_t)(b + g - q))) != NULL; q++)
            line++;
    }
    return line;
}

/* The rest of the file through b (n bytes of room): an I/O error first,
 * then the first NUL (*z: its offset, or SIZE_MAX). */
static int read_rest(jf_pieces *p, char *b, size_t n, size_t *z)
{
    while (p->got < p->len) {
        size_t want = p->len - p->got < n ? p->len - p->got : n, g;
        int e = read_at(p->fd, b, want, p->got, &g);
        const char *q = *z == SIZE_MAX ? memchr(b, '\0', g) : NULL;
        if (q)
            *z = p->got + (size_t)(q - b);
        p->got += g;
        if (e)
            return e;
    }
    return 0;
}

jf_status jf__pieces_drain(jf_pieces *p, jf_error *err)
{
    if (p->got >= p->len || !p->buf)
        return JF_OK;
    size_t z = SIZE_MAX;
    int e = read_rest(p, p->buf, p->cap, &z);
    if (e)
        return io_error(p, e, err);
    if (z != SIZE_MAX)
        return jf_io_fail(err, JF_ERR_FORMAT, p->name, nul_line(p->fd, z),
                          "a NUL byte (binary data in a text file?)");
    return JF_OK;
}

jf_status jf__pieces_next(jf_pieces *p, jf_error *err)
{
    /* the partial last line to the front */
    size_t keep = p->have - p->re;
    if (p->re) {
        memmove(p->buf, p->buf + p->re, keep);
        p->off += p->re;
    }
    p->have = keep;
    p->re = 0;
    while (p->got < p->len) {
        size_t want = p->len - p->got < p->piece ? p->len - p->got : p->piece, g;
        if (p->have + want > p->cap) { /* a line longer than a piece */
            size_t nc = p->cap ? 2 * p->cap : p->piece + (p->piece >> 2);
            while (nc < p->have + want)
                nc *= 2;
            char *nb = p->buf ? realloc(p->buf, nc) : jf__big_alloc(nc);
            if (!nb) {
                p->len = p->got;
                return jf_io_fail(err, JF_ERR_NOMEM, p->name, 0,
                                  "out of memory reading %zu bytes", nc);
            }
            p->buf = nb;
            p->cap = nc;
        }
        char *b = p->buf + p->have;
        int e = read_at(p->fd, b, want, p->got, &g);
        p->got += g;
        if (e)
            return io_error(p, e, err);
        /* a NUL is named as such (jf_cloud_read_mem), after the read of
         * the whole file succeeds */
        const char *q = memchr(b, '\0', want);
        if (q) {
            size_t z = p->got - want + (size_t)(q - b);
            if ((e = read_rest(p, p->buf, p->cap, &z)) != 0)
                return io_error(p, e, err);
            return jf_io_fail(err, JF_ERR_FORMAT, p->name, nul_line(p->fd, z),
                              "a NUL byte (binary data in a text file?)");
        }
        p->have += want;
        for (size_t i = p->have; i > p->have - want; i--)
            if (p->buf[i - 1] == '\n') {
                p->re = i;
                return JF_OK;
            }
    }
    p->re = p->have; /* the end of the file: the rest */
    return JF_OK;
}

/* ---- entry points ----------------------------------------------------- */

jf_status jf_cloud_read_mem(const char *buf, size_t len, jf_format fmt,
                            const char *name, const jf_read_opts *o,
                            jf_cloud *c, jf_error *err)
{
    jf_read_opts def;
    if (!o) {
        jf_read_opts_init(&def);
        o = &def;
    }
    if (!name)
        name = "(memory)";
    if (!c || (!buf && len))
        return jf_io_fail(err, JF_ERR_INVALID, name, 0, "invalid argument");
    memset(c, 0, sizeof *c);
    if (err)
        err->msg[0] = '\0';
    if (len == 0)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "empty file");
    if (fmt == JF_FMT_XYZ || fmt == JF_FMT_PTS || fmt == JF_FMT_CSV || fmt == JF_FMT_OFF ||
        fmt == JF_FMT_PTX) {
        /* a NUL is named as such, not reported as a strange number */
        const char *z = memchr(buf, '\0', len);
        if (z) {
            size_t line = 1;
            for (const char *q = buf; (q = memchr(q, '\n', (size_t)(z - q))) != NULL; q++)
                line++;
            return jf_io_fail(err, JF_ERR_FORMAT, name, line,
                              "a NUL byte (binary data in a text file?)");
        }
    }
    if (o->progress)
        o->progress(o->progress_user, JF_PHASE_READ, 0, len);
    jf_status st;
    switch (fmt) {
    case JF_FMT_PLY:
        st = jf_read_ply(buf, len, name, o, c, err);
        break;
    case JF_FMT_XYZ:
    case JF_FMT_PTS:
    case JF_FMT_CSV:
        st = jf_read_xyz(buf, len, fmt, name, o, c, err);
        break;
    case JF_FMT_OFF:
        st = jf_read_off(buf, len, name, c, err);
        break;
    case JF_FMT_LAS:
        st = jf_read_las(buf, len, name, o, c, err);
        break;
    case JF_FMT_PTX:
        st = jf_read_ptx(buf, len, name, o, c, err);
        break;
    case JF_FMT_E57:
        st = jf_read_e57(buf, len, name, o, c, err);
        break;
    default:
        st = jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                        "unknown file extension (expected .ply, .xyz, .pts, "
                        ".txt, .csv, .off, .las, .ptx or .e57)");
    }
    /* a header announcing 0 vertices is as useless as an empty file */
    if (st == JF_OK && c->n == 0)
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no points in the file");
    if (st != JF_OK)
        jf_cloud_free(c);
    else if (o->progress)
        o->progress(o->progress_user, JF_PHASE_READ, len, len);
    return st;
}

jf_status jf_cloud_read(const char *path, const jf_read_opts *o,
                        jf_cloud *c, jf_error *err)
{
    if (err)
        err->msg[0] = '\0';
    if (!c)
        return jf_io_fail(err, JF_ERR_INVALID, path ? path : "(null)", 0,
                          "invalid argument");
    memset(c, 0, sizeof *c);
    if (!path)
        return jf_io_fail(err, JF_ERR_INVALID, "(null)", 0, "no file name");
    jf_format fmt = jf_format_from_path(path);
    if (fmt == JF_FMT_UNKNOWN)
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, path, 0,
                          "unknown file extension (expected .ply, .xyz, "
                          ".pts, .txt, .csv, .off, .las, .ptx or .e57)");
    /* O_NONBLOCK: a FIFO or device must not block the open; only regular
     * files are read.  The file is read (not mapped): a file that shrinks
     * while it is read is an I/O error, never a SIGBUS. */
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd < 0)
        return jf_io_fail(err, JF_ERR_IO, path, 0, "cannot open: %s",
                          strerror(errno));
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        return jf_io_fail(err, JF_ERR_IO, path, 0,
                          "not a regular file (a folder, FIFO or device)");
    }
    size_t len = (size_t)sb.st_size;
    if (len == 0) {
        close(fd);
        return jf_io_fail(err, JF_ERR_FORMAT, path, 0, "empty file");
    }
    if (fmt == JF_FMT_PLY) {
        /* binary point clouds without a second copy (io_ply.c) */
        if (o && o->progress)
            o->progress(o->progress_user, JF_PHASE_READ, 0, len);
        jf_status cs = jf__read_ply_chunked(fd, len, path, o, c, err);
        if (cs != JF_ERR_UNSUPPORTED) {
            close(fd);
            if (cs == JF_OK && o && o->progress)
                o->progress(o->progress_user, JF_PHASE_READ, len, len);
            return cs;
        }
    }
    if (fmt == JF_FMT_XYZ || fmt == JF_FMT_PTS || fmt == JF_FMT_CSV) {
        /* text tables in pieces, without an image of the file (io_xyz.c) */
        int declined = 0;
        jf_status xs = jf__read_xyz_fd(fd, len, fmt, path, o, c, err, &declined);
        if (!declined) {
            close(fd);
            return xs;
        }
    }
    char *buf = jf__big_alloc(len);
    if (!buf) {
        close(fd);
        return jf_io_fail(err, JF_ERR_NOMEM, path, 0,
                          "out of memory reading %zu bytes", len);
    }
    /* a large file in slices of at least 16 MiB on the threads: the
     * kernel's copy into fresh pages is most of a text read's serial part */
    int nt = o && o->threads > 0 ? o->threads : jf_default_threads(NULL);
    if ((size_t)nt > len / ((size_t)16 << 20))
        nt = (int)(len / ((size_t)16 << 20));
    nt = nt < 1 ? 1 : nt;
    const size_t slice = (len + (size_t)nt - 1) / (size_t)nt;
    size_t got = 0;
    int e = 0;
#pragma omp parallel for num_threads(nt) reduction(+ : got) if (nt > 1)
    for (int k = 0; k < nt; k++) {
        size_t a = slice * (size_t)k, b = a + slice < len ? a + slice : len, g = a;
        while (g < b) {
            ssize_t r = pread(fd, buf + g, b - g > (1u << 30) ? (1u << 30) : b - g, (off_t)g);
            if (r < 0 && errno == EINTR)
                continue;
            if (r <= 0) {
                if (r < 0)
                    __atomic_store_n(&e, errno, __ATOMIC_RELAXED);
                break;
            }
            g += (size_t)r;
        }
        got += g - a;
    }
    close(fd);
    if (got < len) {
        free(buf);
        if (e)
            return jf_io_fail(err, JF_ERR_IO, path, 0, "read failed: %s", strerror(e));
        return jf_io_fail(err, JF_ERR_IO, path, 0,
                          "the file shrank while it was read (%zu of %zu bytes)", got, len);
    }
    jf_status st = jf_cloud_read_mem(buf, len, fmt, path, o, c, err);
    free(buf);
    return st;
}
