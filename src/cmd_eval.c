/* cmd_eval.c -- `jetfit eval` (placeholder until its issue lands). */
#include <stdio.h>

#include "cmd.h"

int jf_cmd_eval(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "jetfit eval: not implemented yet\n");
    return 2;
}
