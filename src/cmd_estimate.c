/* cmd_estimate.c -- `jetfit estimate` (placeholder until its issue lands). */
#include <stdio.h>

#include "cmd.h"

int jf_cmd_estimate(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "jetfit estimate: not implemented yet\n");
    return 2;
}
