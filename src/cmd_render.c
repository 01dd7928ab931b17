/* cmd_render.c -- `jetfit render` (placeholder until its issue lands). */
#include <stdio.h>

#include "cmd.h"

int jf_cmd_render(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "jetfit render: not implemented yet\n");
    return 2;
}
