/*
 * io_wfile.c -- the buffered output file of every writer: a buffer (1 MiB,
 * one write(2) per flush) feeding a temporary beside the final file
 * (jf_tmpfile_open: exclusive, unpredictable name); jf_wf_close renames it
 * onto NAME on success and unlinks it on any failure, so no partial file
 * ever carries the final name.
 */
#define _POSIX_C_SOURCE 200809L
#include "io_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define BUF_CAP (1u << 20)

jf_status jf_wf_fail(jf_wfile *f, jf_status st, const char *fmt, ...)
{
    if (f->st != JF_OK)
        return f->st;
    f->st = st;
    char why[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    jf_io_fail(&f->err, st, f->final ? f->final : "(output)", 0, "%s", why);
    return st;
}

jf_status jf_wf_open(jf_wfile *f, const char *path, size_t min_cap)
{
    memset(f, 0, sizeof *f);
    f->fd = -1;
    f->t.fd = -1;
    f->t.slot = -1;
    f->final = strdup(path);
    f->cap = min_cap > BUF_CAP ? min_cap : BUF_CAP;
    f->buf = malloc(f->cap);
    if (!f->final || !f->buf)
        return jf_wf_fail(f, JF_ERR_NOMEM, "out of memory");
    jf_status st = jf_tmpfile_open(path, &f->t, &f->err);
    if (st != JF_OK)
        return f->st = st;
    f->fd = f->t.fd;
    return JF_OK;
}

/* Writes all of [p, p + n) to the file (short writes retried). */
static jf_status write_all(jf_wfile *f, const char *p, size_t n)
{
    size_t done = 0;
    while (f->st == JF_OK && done < n) {
        ssize_t w = write(f->fd, p + done, n - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return jf_wf_fail(f, JF_ERR_IO, "write failed: %s",
                              w < 0 ? strerror(errno) : "no progress");
        done += (size_t)w;
    }
    return f->st;
}

jf_status jf_wf_flush(jf_wfile *f)
{
    write_all(f, f->buf, f->len);
    f->len = 0;
    return f->st;
}

jf_status jf_wf_write(jf_wfile *f, const char *p, size_t n)
{
    if (jf_wf_flush(f) != JF_OK)
        return f->st;
    return write_all(f, p, n);
}

jf_status jf_wf_puts(jf_wfile *f, const char *s)
{
    size_t n = strlen(s);
    while (n) {
        char *o = jf_wf_room(f, 1);
        if (!o)
            return f->st;
        size_t k = f->cap - f->len < n ? f->cap - f->len : n;
        memcpy(o, s, k);
        f->len += k;
        s += k;
        n -= k;
    }
    return f->st;
}

/* Frees f; on success (st OK) renames the temporary onto the final name,
 * else removes it.  Returns the final status and fills err. */
jf_status jf_wf_close(jf_wfile *f, jf_error *err)
{
    jf_status st = f->st;
    if (st == JF_OK)
        st = jf_wf_flush(f);
    if (st == JF_OK) {
        st = jf_tmpfile_commit(&f->t, f->final, &f->err);
        f->st = st;
    } else {
        jf_tmpfile_discard(&f->t);
    }
    f->fd = -1;
    if (err)
        *err = f->err;
    if (err && st == JF_ERR_NOMEM && !f->err.msg[0])
        snprintf(err->msg, sizeof err->msg, "out of memory");
    free(f->final);
    free(f->buf);
    return st;
}
