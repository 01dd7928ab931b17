/* gnuplot.h -- running gnuplot safely (src/cli/gnuplot.c): no shell, its
 * messages kept aside, and user text only inside single-quoted strings. */
#ifndef JF_CLI_GNUPLOT_H
#define JF_CLI_GNUPLOT_H
#include <stdio.h>
#include <sys/types.h>

typedef struct {
    FILE *in;   /* the script goes here                                  */
    FILE *log;  /* gnuplot's stdout and stderr (a PNG never reaches ours) */
    pid_t pid;
    int missing; /* jf_gp_open failed because gnuplot is not installed */
} jf_gp;

/* Starts gnuplot (found on PATH) reading its script from g->in; the
 * descriptors keep[0..nkeep-1] (pictures, > 2) are inherited by gnuplot,
 * no other of ours.  Returns 0, or -1 with msg filled (gnuplot missing,
 * fork/pipe failure). */
int jf_gp_open(jf_gp *g, const int *keep, int nkeep, char *msg, size_t len);
/* `set output` to descriptor fd (one of keep): gnuplot opens /dev/fd/fd,
 * the file jetfit opened, never a name another process could replace. */
void jf_gp_output(FILE *gp, int fd);
/* 0 if descriptor fd holds a whole PNG (signature first, IEND last, synced
 * to disk), else -1 with msg filled: gnuplot does not report a failed
 * write (a full disk leaves a cut-off picture and exit status 0). */
int jf_gp_png_whole(int fd, char *msg, size_t len);
/* Ends the script, waits for gnuplot; 0 when it exited with status 0,
 * else -1 and msg gets gnuplot's first error line (or why it died). */
int jf_gp_close(jf_gp *g, char *msg, size_t len);
/* Writes s as a gnuplot single-quoted string: gnuplot expands nothing
 * there (a double-quoted string would run `backquoted` commands); ' is
 * doubled (leading quotes joined on as "'", see gnuplot.c) and control
 * characters (a newline would end the command) become blanks.  The result
 * is a string expression: fine after set output, set title, plot's title. */
void jf_gp_quote(FILE *gp, const char *s);
#endif
