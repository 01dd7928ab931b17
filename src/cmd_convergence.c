/* cmd_convergence.c -- `jetfit convergence` (placeholder until its issue lands). */
#include <stdio.h>

#include "cmd.h"

int jf_cmd_convergence(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "jetfit convergence: not implemented yet\n");
    return 2;
}
