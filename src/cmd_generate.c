/* cmd_generate.c -- `jetfit generate` (placeholder until its issue lands). */
#include <stdio.h>

#include "cmd.h"

int jf_cmd_generate(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "jetfit generate: not implemented yet\n");
    return 2;
}
