/* cmd.h -- the subcommands of the jetfit command (src/cmd_*.c).  Each takes
 * its own argv (argv[0] is the subcommand name), prints its own errors to
 * stderr and returns the process exit status. */
#ifndef JF_CMD_H
#define JF_CMD_H
int jf_cmd_estimate(int argc, char **argv);    /* cmd_estimate.c    */
int jf_cmd_generate(int argc, char **argv);    /* cmd_generate.c    */
int jf_cmd_convergence(int argc, char **argv); /* cmd_convergence.c */
int jf_cmd_render(int argc, char **argv);      /* cmd_render.c      */
int jf_cmd_eval(int argc, char **argv);        /* cmd_eval.c        */
int jf_cmd_study(int argc, char **argv);       /* cmd_study.c       */
int jf_cmd_view(int argc, char **argv);        /* cmd_view.c        */

/* JF_PT_* flags that say how a point was fitted, not that anything went
 * wrong (auto's choice, a selected scale, the natural normal's source, an
 * umbilic): a point with no other flag counts as ok in estimate's summary
 * and in study's cells (with jetfit.h) */
#define JF_CLI_HOW_FLAGS                                                                   \
    (JF_PT_AUTO | JF_PT_AUTO_CAPPED | JF_PT_AUTO_WEIGHTED | JF_PT_AUTO_SPREAD |           \
     JF_PT_SCALE_SELECTED | JF_PT_NORMAL_POLES | JF_PT_NORMAL_MINCIRC | JF_PT_NORMAL_INPUT | \
     JF_PT_NORMAL_JET | JF_PT_NORMAL_PCA | JF_PT_UMBILIC)
#endif
