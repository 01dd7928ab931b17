/*
 * io_tmpfile.c -- output files that appear whole or not at all.
 *
 * Design: the temporary is created beside the final file (same file system,
 * so rename(2) is atomic) under an unpredictable name, exclusively
 * (O_CREAT|O_EXCL|O_NOFOLLOW: a planted file or link at that name makes the
 * open fail and another name is drawn, never followed).  Its name is
 * ".BASE.XXXXXXXXXX.tmp" with BASE cut to 200 bytes, so a final name near the
 * 255-byte limit still gets a temporary.  An output path that is a symbolic
 * link is written through to its target, as cp(1) does: the link stays and
 * the target is replaced.  The new file keeps the mode of the file it
 * replaces, or gets 0666 less the umask.  Every open temporary is listed in
 * a fixed table so that a signal handler can remove them
 * (jf_tmpfiles_remove_all: unlink(2) only, async-signal-safe).  An
 * existing output that is not a regular file (a FIFO, a device) is
 * refused; at commit the temporary's name must still be our file.
 */
#define _GNU_SOURCE /* getrandom, O_NOFOLLOW */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io_internal.h"

#define SLOTS 64
static struct {
    int claimed;                 /* taken by a writer (atomic)           */
    volatile sig_atomic_t live;  /* path is complete and may be removed   */
    char path[PATH_MAX];
} slots[SLOTS];

void jf_tmpfiles_remove_all(void)
{
    for (int i = 0; i < SLOTS; i++)
        if (slots[i].live)
            unlink(slots[i].path);
}

static int slot_take(const char *path)
{
    if (strlen(path) >= PATH_MAX)
        return -1;
    for (int i = 0; i < SLOTS; i++) {
        int zero = 0;
        if (__atomic_compare_exchange_n(&slots[i].claimed, &zero, 1, 0, __ATOMIC_ACQ_REL,
                                        __ATOMIC_RELAXED)) {
            strcpy(slots[i].path, path);
            __atomic_thread_fence(__ATOMIC_SEQ_CST);
            slots[i].live = 1;
            return i;
        }
    }
    return -1; /* more than SLOTS outputs at once: still correct, not listed */
}

static void slot_drop(int i)
{
    if (i < 0)
        return;
    slots[i].live = 0;
    __atomic_thread_fence(__ATOMIC_SEQ_CST);
    __atomic_store_n(&slots[i].claimed, 0, __ATOMIC_RELEASE);
}

/* The file a write to `path` must replace: path itself, or the end of its
 * chain of symbolic links (relative links resolved from the link's folder).
 * Malloc'd; NULL with errno on failure. */
static char *write_target(const char *path)
{
    char *cur = strdup(path);
    for (int hop = 0; cur && hop < 40; hop++) {
        struct stat sb;
        if (lstat(cur, &sb) != 0 || !S_ISLNK(sb.st_mode))
            return cur;
        char link[PATH_MAX];
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0) {
            free(cur);
            return NULL;
        }
        link[n] = '\0';
        const char *slash = strrchr(cur, '/');
        size_t dirlen = link[0] == '/' || !slash ? 0 : (size_t)(slash - cur + 1);
        char *next = malloc(dirlen + (size_t)n + 1);
        if (next) {
            memcpy(next, cur, dirlen);
            memcpy(next + dirlen, link, (size_t)n + 1);
        }
        free(cur);
        cur = next;
    }
    if (cur) {
        free(cur);
        errno = ELOOP;
    }
    return NULL;
}

jf_status jf_tmpfile_open(const char *final, jf_tmpfile *t, jf_error *err)
{
    memset(t, 0, sizeof *t);
    t->fd = -1;
    t->slot = -1;
    const char *name = final ? final : "(null)";
    if (!final || !*final)
        return jf_io_fail(err, JF_ERR_INVALID, name, 0, "no file name");
    t->target = write_target(final);
    if (!t->target)
        return jf_io_fail(err, JF_ERR_IO, name, 0, "cannot follow the link: %s",
                          strerror(errno));
    const char *slash = strrchr(t->target, '/');
    size_t dirlen = slash ? (size_t)(slash - t->target + 1) : 0;
    const char *base = t->target + dirlen;
    if (!*base || !strcmp(base, ".") || !strcmp(base, "..")) {
        jf_tmpfile_discard(t);
        return jf_io_fail(err, JF_ERR_INVALID, name, 0, "not a file name");
    }
    struct stat old;
    int replacing = stat(t->target, &old) == 0;
    if (replacing && S_ISDIR(old.st_mode)) {
        jf_tmpfile_discard(t);
        return jf_io_fail(err, JF_ERR_IO, name, 0, "is a directory");
    }
    /* a FIFO, device or socket would be replaced by a plain file (issue
     * 33.12): refused, since the output is written whole then renamed */
    if (replacing && !S_ISREG(old.st_mode)) {
        const char *what = S_ISFIFO(old.st_mode) ? "a FIFO" : S_ISSOCK(old.st_mode) ? "a socket"
                                                                                 : "a device";
        jf_tmpfile_discard(t);
        return jf_io_fail(err, JF_ERR_IO, name, 0,
                          "is %s, not a regular file: jetfit writes a whole file and renames it "
                          "into place", what);
    }
    size_t blen = strlen(base) > 200 ? 200 : strlen(base);
    size_t cap = dirlen + blen + 32;
    t->tmp = malloc(cap);
    if (!t->tmp) {
        jf_tmpfile_discard(t);
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    }
    static const char abc[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    for (int attempt = 0; attempt < 100; attempt++) {
        unsigned char rnd[10];
        if (getrandom(rnd, sizeof rnd, 0) != (ssize_t)sizeof rnd) {
            /* no entropy source: time and pid still differ per attempt */
            unsigned long long s = (unsigned long long)time(NULL) * 6364136223846793005ULL
                                   ^ (unsigned long long)getpid() << 20 ^ (unsigned)attempt;
            for (size_t k = 0; k < sizeof rnd; k++, s >>= 6)
                rnd[k] = (unsigned char)s;
        }
        char suf[11];
        for (size_t k = 0; k < sizeof rnd; k++)
            suf[k] = abc[rnd[k] % (sizeof abc - 1)];
        suf[10] = '\0';
        snprintf(t->tmp, cap, "%.*s.%.*s.%s.tmp", (int)dirlen, t->target, (int)blen, base, suf);
        t->fd = open(t->tmp, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (t->fd >= 0 || errno != EEXIST)
            break;
    }
    if (t->fd < 0) {
        int e = errno;
        free(t->tmp);
        t->tmp = NULL;
        jf_tmpfile_discard(t);
        return jf_io_fail(err, JF_ERR_IO, name, 0, "cannot create a file in its folder: %s",
                          strerror(e));
    }
    t->slot = slot_take(t->tmp);
    if (replacing && fchmod(t->fd, old.st_mode & 07777) != 0) {
        int e = errno;
        jf_tmpfile_discard(t);
        return jf_io_fail(err, JF_ERR_IO, name, 0, "cannot keep its permissions: %s",
                          strerror(e));
    }
    return JF_OK;
}

jf_status jf_tmpfile_commit(jf_tmpfile *t, const char *final, jf_error *err)
{
    const char *name = final ? final : "(output)";
    jf_status st = JF_OK;
    /* the name must still be our file: another process with write access
     * to the folder may have put a link there (issue 33.2), and the
     * rename would make that link the output */
    struct stat a = {0}, b;
    const int known = t->fd >= 0;
    if (t->fd >= 0 && (fstat(t->fd, &a) != 0 || lstat(t->tmp, &b) != 0 ||
                       a.st_dev != b.st_dev || a.st_ino != b.st_ino)) {
        st = jf_io_fail(err, JF_ERR_IO, name, 0,
                        "its temporary %s was replaced by another process", t->tmp);
        close(t->fd);
        t->fd = -1;
    }
    /* a second descriptor holds our inode until the check after the
     * rename: closed, a replaced temporary's inode number could be reused
     * by the link put in its place, which the check would then take for ours */
    const int hold = t->fd >= 0 ? dup(t->fd) : -1;
    if (t->fd >= 0 && close(t->fd) != 0)
        st = jf_io_fail(err, JF_ERR_IO, name, 0, "close failed: %s", strerror(errno));
    t->fd = -1;
    if (st == JF_OK && known && hold < 0)
        st = jf_io_fail(err, JF_ERR_IO, name, 0, "cannot duplicate its descriptor: %s",
                        strerror(errno));
    if (st == JF_OK && rename(t->tmp, t->target) != 0)
        st = jf_io_fail(err, JF_ERR_IO, name, 0, "cannot rename the finished file onto it: %s",
                        strerror(errno));
    /* the name may have been swapped between the check and the rename:
     * then what the rename put in place is not our file, and it goes */
    struct stat c;
    if (st == JF_OK && known &&
        (lstat(t->target, &c) != 0 || !S_ISREG(c.st_mode) || c.st_dev != a.st_dev ||
         c.st_ino != a.st_ino)) {
        unlink(t->target);
        st = jf_io_fail(err, JF_ERR_IO, name, 0,
                        "its temporary %s was replaced by another process", t->tmp);
    }
    if (hold >= 0 && close(hold) != 0 && st == JF_OK) { /* the last close: NFS reports here */
        unlink(t->target);
        st = jf_io_fail(err, JF_ERR_IO, name, 0, "close failed: %s", strerror(errno));
    }
    if (st != JF_OK)
        unlink(t->tmp);
    slot_drop(t->slot);
    t->slot = -1;
    free(t->tmp);
    free(t->target);
    t->tmp = t->target = NULL;
    return st;
}

void jf_tmpfile_discard(jf_tmpfile *t)
{
    if (!t)
        return;
    if (t->fd >= 0)
        close(t->fd);
    t->fd = -1;
    if (t->tmp)
        unlink(t->tmp);
    slot_drop(t->slot);
    t->slot = -1;
    free(t->tmp);
    free(t->target);
    t->tmp = t->target = NULL;
}

int jf_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}
