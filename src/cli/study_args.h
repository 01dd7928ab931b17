/* study_args.h -- `jetfit study`'s command line (src/cli/study_args.c):
 * the lists, the base estimate options, every setting parsed and
 * validated before any work, and what cmd_study.c loads for INPUT mode. */
#ifndef JF_STUDY_ARGS_H
#define JF_STUDY_ARGS_H

#include "jetfit.h"
#include "opts.h"
#include "study.h"
#include "surfaces.h"

#define JF_STUDY_DEFAULT_N 10000

typedef struct {
    jf_study s;
    const char *dir, *nb_text, *deg_text, *flags_text, *metrics_text;
    const char *in_fmt;          /* --input-format (INPUT '-' needs it) */
    char input_id[160];          /* INPUT's identity for study.def, taken
                                    while it is read (study_def.c)      */
    char **strat_block, **flags_block;
    jf_surface surf;
    int is_surface, mesh, quiet, resume;
    size_t npoints;              /* --n                                */
    size_t ndraw;                /* points of each draw (cmd_study.c)  */
    jf_cli_est base;             /* options outside --flags           */
    char base_text[2048];        /* them as given (study.def), --threads
                                    left out: results do not depend on it */
    jf_estimate_opts *setting;   /* strategy x degree x flags, in the
                                    order of jf_study_setting         */
    int nsetting;
    /* INPUT mode (cmd_study.c loads them) */
    jf_cloud cloud;
    double *truth; /* 5 per row: nx ny nz k1 k2 */
    int truth_k;
    size_t *sel, nsel;
} jf_study_args;

/* Parses argv into *c (zeroed by the caller).  0; -1 after --help
 * (printed); or the exit status of a bad option (2), its line printed. */
int jf_study_args_parse(jf_study_args *c, int argc, char **argv);

/* study_def.c: DIR/study.def, what defines the study (its file says
 * which lines).  make: the text for c (-1 with msg: an unreadable file);
 * write: onto DIR/study.def (atomic); check: 0 if DIR/study.def says the
 * same, else -1 with one line naming what differs (or that it is
 * missing). */
/* "SIZE bytes, fnv1a64 HASH" of the file at path into out; -1 with msg. */
int jf_study_def_identity(const char *path, char *out, size_t len, char *msg, size_t mlen);
int jf_study_def_make(const jf_study_args *c, char *def, size_t len, char *msg, size_t mlen);
int jf_study_def_write(const char *dir, const char *def, char *msg, size_t len);
int jf_study_def_check(const char *dir, const char *def, char *msg, size_t len);

/* Frees what parse and cmd_study.c allocated. */
void jf_study_args_free(jf_study_args *c);

#endif
