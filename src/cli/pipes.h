/* pipes.h -- standard input and output for the commands, and files whose
 * extension does not name their format (src/cli/pipes.c): "-" as INPUT,
 * "-o -", --input-format FMT, --output-format FMT. */
#ifndef JF_CLI_PIPES_H
#define JF_CLI_PIPES_H

#include "jetfit.h"

/* 1 if FMT is a format name the readers (or writers) know: ply, xyz,
 * txt, pts, csv, off, las, ptx. */
int jf_cli_format_ok(const char *fmt);

/* An input for a reader that takes a path: PATH itself, or standard
 * input ("-") copied to a private file, or PATH linked under the
 * extension FMT names.  begin: r->path is what to read; end: removes the
 * private file and, when err holds a message, names PATH in it. */
typedef struct {
    const char *path, *shown;
    char dir[256], tmp[300];
} jf_cli_in;

jf_status jf_cli_in_begin(jf_cli_in *r, const char *path, const char *fmt, jf_error *err);
void jf_cli_in_end(jf_cli_in *r, jf_error *err);

/* jf_cloud_read for PATH ("-": standard input, spooled to a private
 * temporary first, as the readers need to seek) in format FMT (NULL: from
 * the extension).  Messages name PATH ("(standard input)" for "-"). */
jf_status jf_cli_cloud_read(const char *path, const char *fmt, const jf_read_opts *o,
                            jf_cloud *c, jf_error *err);

/* Where a writer should write for the output OUT ("-": standard output)
 * in format FMT (NULL: from the extension): OUT itself, or a file in a
 * private folder that jf_cli_out_finish then copies to standard output
 * or renames onto OUT. */
typedef struct {
    const char *out;
    char dir[256], path[300]; /* dir[0] == 0: writing OUT itself */
} jf_cli_out;

jf_status jf_cli_out_begin(jf_cli_out *w, const char *out, const char *fmt, jf_error *err);
/* Rewrites the private file's name in a writer's message to OUT's. */
void jf_cli_out_msg(const jf_cli_out *w, jf_error *err);
/* ok: the writer committed; copy or rename.  Always removes the private
 * folder.  JF_OK, or JF_ERR_IO with err naming OUT. */
jf_status jf_cli_out_finish(jf_cli_out *w, int ok, jf_error *err);

#endif
