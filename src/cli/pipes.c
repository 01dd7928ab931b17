/* pipes.c -- standard input and output, formats named on the command line
 * (pipes.h).  The readers take a file (they seek, and a binary PLY is read
 * a chunk at a time); the writers put rows in place in a file.  So a pipe
 * goes through a file in a private folder (mkdtemp(3), mode 0700, in
 * $TMPDIR): standard input is copied there first, standard output gets the
 * finished file.  A name with the wrong extension is reached through a
 * symbolic link with the right one; messages are rewritten to name what
 * the user gave. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pipes.h"

static const char *const formats[] = {"ply", "xyz", "txt", "pts", "csv", "off", "las", "laz", "ptx", "e57"};

int jf_cli_format_ok(const char *fmt)
{
    for (size_t k = 0; fmt && k < sizeof formats / sizeof formats[0]; k++)
        if (!strcmp(fmt, formats[k])) return 1;
    return 0;
}

static jf_status fail(jf_error *err, jf_status st, const char *fmt, const char *a, const char *b)
{
    if (err) snprintf(err->msg, sizeof err->msg, fmt, a, b);
    return st;
}

/* A private folder in $TMPDIR (or /tmp); 0 or -1. */
static int private_dir(char *dir, size_t len)
{
    const char *t = getenv("TMPDIR");
    if (!t || !*t) t = "/tmp";
    if ((size_t)snprintf(dir, len, "%s/jetfit.XXXXXX", t) >= len) return -1;
    return mkdtemp(dir) ? 0 : -1;
}

/* Copies fd `from` to fd `to` whole; 0 or errno. */
static int copy_fd(int from, int to)
{
    char buf[1 << 16];
    for (;;) {
        ssize_t r = read(from, buf, sizeof buf);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return errno;
        if (r == 0) return 0;
        for (ssize_t o = 0; o < r;) {
            ssize_t w = write(to, buf + o, (size_t)(r - o));
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) return w < 0 ? errno : EIO;
            o += w;
        }
    }
}

/* In err->msg, every "tmp" becomes "shown". */
static void rename_in_msg(jf_error *err, const char *tmp, const char *shown)
{
    if (!err) return;
    char out[sizeof err->msg];
    size_t u = 0, lt = strlen(tmp), ls = strlen(shown);
    for (const char *p = err->msg; *p && u + 1 < sizeof out;) {
        if (!strncmp(p, tmp, lt) && u + ls + 1 < sizeof out) {
            memcpy(out + u, shown, ls);
            u += ls, p += lt;
        } else {
            out[u++] = *p++;
        }
    }
    out[u] = '\0';
    memcpy(err->msg, out, u + 1);
}

jf_status jf_cli_in_begin(jf_cli_in *r, const char *path, const char *fmt, jf_error *err)
{
    memset(r, 0, sizeof *r);
    int in_std = !strcmp(path, "-");
    r->shown = in_std ? "(standard input)" : path;
    if (!in_std && !fmt) {
        r->path = path;
        return JF_OK;
    }
    if (!fmt)
        return fail(err, JF_ERR_INVALID, "%s: standard input has no extension: give "
                                         "--input-format FMT (ply, xyz, txt, pts, csv, off, las, laz, ptx, e57)%s",
                    r->shown, "");
    if (!jf_cli_format_ok(fmt))
        return fail(err, JF_ERR_INVALID, "--input-format '%s': expected ply, xyz, txt, pts, csv, "
                                         "off, las or ptx%s", fmt, "");
    if (private_dir(r->dir, sizeof r->dir))
        return fail(err, JF_ERR_IO, "%s: cannot make a temporary folder: %s", r->shown, strerror(errno));
    snprintf(r->tmp, sizeof r->tmp, "%s/input.%s", r->dir, fmt);
    r->path = r->tmp;
    jf_status st = JF_OK;
    if (in_std) {
        int fd = open(r->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        int e = fd < 0 ? errno : copy_fd(0, fd);
        if (fd >= 0 && close(fd) && !e) e = errno;
        if (e) st = fail(err, JF_ERR_IO, "%s: cannot spool to a temporary file: %s", r->shown, strerror(e));
    } else {
        /* the reader opens the file itself: a link keeps its checks */
        char abs[PATH_MAX];
        if (path[0] != '/' && getcwd(abs, sizeof abs)) {
            size_t l = strlen(abs);
            snprintf(abs + l, sizeof abs - l, "/%s", path);
        } else {
            snprintf(abs, sizeof abs, "%s", path);
        }
        if (symlink(abs, r->tmp))
            st = fail(err, JF_ERR_IO, "%s: cannot link: %s", r->shown, strerror(errno));
    }
    if (st != JF_OK) jf_cli_in_end(r, NULL);
    return st;
}

void jf_cli_in_end(jf_cli_in *r, jf_error *err)
{
    if (!r->dir[0]) return;
    if (err && err->msg[0]) rename_in_msg(err, r->tmp, r->shown);
    unlink(r->tmp);
    rmdir(r->dir);
    r->dir[0] = '\0';
}

jf_status jf_cli_cloud_read(const char *path, const char *fmt, const jf_read_opts *o,
                            jf_cloud *c, jf_error *err)
{
    jf_cli_in r;
    jf_status st = jf_cli_in_begin(&r, path, fmt, err);
    if (st == JF_OK) st = jf_cloud_read(r.path, o, c, err);
    jf_cli_in_end(&r, st == JF_OK ? NULL : err);
    return st;
}

jf_status jf_cli_out_begin(jf_cli_out *w, const char *out, const char *fmt, jf_error *err)
{
    memset(w, 0, sizeof *w);
    w->out = out;
    int to_std = !strcmp(out, "-");
    if (!to_std && !fmt) {
        snprintf(w->path, sizeof w->path, "%s", out);
        if (strlen(out) >= sizeof w->path) w->path[0] = '\0';
        return w->path[0] ? JF_OK : fail(err, JF_ERR_INVALID, "%s: name too long%s", out, "");
    }
    if (!fmt)
        return fail(err, JF_ERR_INVALID, "-o -: standard output has no extension: give "
                                         "--output-format FMT (ply, csv, xyz, txt, las)%s%s", "", "");
    if (!jf_cli_format_ok(fmt) || !strcmp(fmt, "pts") || !strcmp(fmt, "ptx"))
        return fail(err, JF_ERR_INVALID, "--output-format '%s': expected ply, csv, xyz, txt, "
                                         "las or off (meshes)%s", fmt, "");
    if (to_std) {
        if (private_dir(w->dir, sizeof w->dir))
            return fail(err, JF_ERR_IO, "%s: cannot make a temporary folder: %s", "-o -",
                        strerror(errno));
    } else {
        /* beside OUT, so that the last step is one rename(2) */
        const char *slash = strrchr(out, '/');
        int dl = slash ? (int)(slash - out) : 1;
        if ((size_t)snprintf(w->dir, sizeof w->dir, "%.*s/.jetfit.XXXXXX", dl,
                             slash ? out : ".") >= sizeof w->dir || !mkdtemp(w->dir)) {
            w->dir[0] = '\0';
            return fail(err, JF_ERR_IO, "%s: cannot make a temporary folder beside it: %s", out,
                        strerror(errno));
        }
    }
    snprintf(w->path, sizeof w->path, "%s/output.%s", w->dir, fmt);
    return JF_OK;
}

void jf_cli_out_msg(const jf_cli_out *w, jf_error *err)
{
    if (w->dir[0]) rename_in_msg(err, w->path, !strcmp(w->out, "-") ? "(standard output)" : w->out);
}

jf_status jf_cli_out_finish(jf_cli_out *w, int ok, jf_error *err)
{
    if (!w->dir[0]) return JF_OK;
    jf_status st = JF_OK;
    if (ok && !strcmp(w->out, "-")) {
        /* removed before the copy: a reader that stops early (head) kills
         * us with SIGPIPE mid-copy, and nothing must be left behind */
        int fd = open(w->path, O_RDONLY | O_CLOEXEC);
        unlink(w->path);
        rmdir(w->dir);
        int e = fd < 0 ? errno : copy_fd(fd, 1);
        if (fd >= 0) close(fd);
        if (e) st = fail(err, JF_ERR_IO, "standard output: write failed: %s%s", strerror(e), "");
    } else if (ok && rename(w->path, w->out)) {
        st = fail(err, JF_ERR_IO, "%s: cannot rename the finished file onto it: %s", w->out,
                  strerror(errno));
    }
    unlink(w->path);
    rmdir(w->dir);
    w->dir[0] = '\0';
    return st;
}
