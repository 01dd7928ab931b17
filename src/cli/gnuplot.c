/* gnuplot.c -- gnuplot as a child process without a shell (fork + execlp),
 * its script on a pipe, its output in an anonymous temporary file, so that
 * neither its messages nor a PNG ever reach the user's terminal; the
 * command prints one line of its own instead (issue 11).  Pictures go to
 * descriptors jetfit opened and gnuplot inherits ("/dev/fd/N"): gnuplot
 * never opens a name in the output folder, where another process could
 * swap the temporary for a link (issue 33.2).  gnuplot reports no failed
 * write (a full disk): jf_gp_png_whole checks the picture itself. */
#define _POSIX_C_SOURCE 200809L /* fdopen, fileno, pread */
#include "gnuplot.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

void jf_gp_quote(FILE *gp, const char *s)
{
    /* gnuplot 5.4 reads a string that starts with a doubled quote, as in
     * 'QQx' with Q a quote, as an empty one: leading quotes are joined on
     * as "'" (a double-quoted string holding no backquote expands nothing) */
    size_t lead = strspn(s, "'");
    if (lead)
        fputc('(', gp);
    for (size_t k = 0; k < lead; k++)
        fputs("\"'\".", gp);
    fputc('\'', gp);
    for (s += lead; *s; s++) {
        if (*s == '\'')
            fputc('\'', gp);
        fputc((unsigned char)*s < 0x20 || *s == 0x7f ? ' ' : *s, gp);
    }
    fputc('\'', gp);
    if (lead)
        fputc(')', gp);
}

void jf_gp_output(FILE *gp, int fd)
{
    fprintf(gp, "set output '/dev/fd/%d'\n", fd);
}

int jf_gp_png_whole(int fd, char *msg, size_t len)
{
    /* PNG (ISO/IEC 15948 §5.2, §11.2.5): an 8-byte signature first, the
     * empty IEND chunk (length 0, "IEND", its CRC) last */
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
    unsigned char a[8], b[12];
    struct stat sb;
    /* a write the disk refused late (delayed allocation) shows up here */
    if (fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
        snprintf(msg, len, "the picture could not be written: %s", strerror(errno));
        return -1;
    }
    if (fstat(fd, &sb) != 0 || sb.st_size < 20 || pread(fd, a, 8, 0) != 8 ||
        pread(fd, b, 12, sb.st_size - 12) != 12 || memcmp(a, sig, 8) || memcmp(b, iend, 12)) {
        snprintf(msg, len, "gnuplot wrote an incomplete picture (%lld bytes, no PNG end); "
                           "is the disk full?", (long long)(fstat(fd, &sb) ? -1 : sb.st_size));
        return -1;
    }
    return 0;
}

int jf_gp_open(jf_gp *g, const int *keep, int nkeep, char *msg, size_t len)
{
    memset(g, 0, sizeof *g);
    g->pid = -1;
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
        snprintf(msg, len, "gnuplot not found (Debian package gnuplot-nox)");
        g->missing = 1;
        return -1;
    }
    int fd[2];
    g->log = tmpfile();
    if (!g->log || pipe(fd) != 0) {
        snprintf(msg, len, "cannot run gnuplot: %s", strerror(errno));
        if (g->log)
            fclose(g->log);
        g->log = NULL;
        return -1;
    }
    fflush(NULL);
    g->pid = fork();
    if (g->pid == 0) {
        /* the picture descriptors stay open across exec (they are O_CLOEXEC
         * in jetfit); every other descriptor of ours closes */
        for (int k = 0; k < nkeep; k++)
            if (keep[k] > 2)
                fcntl(keep[k], F_SETFD, 0);
        dup2(fd[0], 0);
        dup2(fileno(g->log), 1);
        dup2(fileno(g->log), 2);
        close(fd[0]);
        close(fd[1]);
        execlp("gnuplot", "gnuplot", (char *)NULL);
        _exit(127);
    }
    close(fd[0]);
    g->in = g->pid > 0 ? fdopen(fd[1], "w") : NULL;
    if (!g->in) {
        snprintf(msg, len, "cannot run gnuplot: %s", strerror(errno));
        if (g->pid > 0) {
            close(fd[1]);
            waitpid(g->pid, NULL, 0);
        } else {
            close(fd[1]);
        }
        fclose(g->log);
        g->log = NULL;
        return -1;
    }
    return 0;
}

int jf_gp_close(jf_gp *g, char *msg, size_t len)
{
    /* gnuplot may exit early on an error: a write to its pipe must not kill us */
    struct sigaction ign, old;
    memset(&ign, 0, sizeof ign);
    ign.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &ign, &old);
    int bad = fclose(g->in) != 0;
    sigaction(SIGPIPE, &old, NULL);
    int status = 0;
    while (waitpid(g->pid, &status, 0) < 0 && errno == EINTR)
        ;
    int ok = !bad && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (!ok) {
        /* gnuplot's first line that says what went wrong */
        char line[512];
        const char *why = NULL;
        rewind(g->log);
        while (fgets(line, sizeof line, g->log))
            if (strstr(line, "rror") || strstr(line, "warning")) {
                line[strcspn(line, "\r\n")] = '\0';
                why = line;
                break;
            }
        if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
            snprintf(msg, len, "gnuplot could not be started");
        else
            snprintf(msg, len, "gnuplot failed%s%s", why ? ": " : "", why ? why : "");
    }
    fclose(g->log);
    g->log = NULL;
    g->in = NULL;
    return ok ? 0 : -1;
}
