/* The walk options the walking commands share (solve, solve --source, solve --method, radiosity),
 * parsed in one place by their long name: a command lists the ones it takes in its longopts as
 * CLI_WALK_OPTION("name") and hands each to cli_walk_option. */
#include "cli.h"

#include <stdio.h>
#include <string.h>

/* Parse walk option --name's value into o through the library's table (src/options.c): 0
 * handled, 1 not a walk option, else an exit code (the bad value reported as command's usage
 * error).  Adding a walk option is a row there. */
int cli_walk_option(const char *command, const char *name, const char *value, ulam_walk_opts *o)
{
    if (!strcmp(name, "alpha")) /* deprecated: read as PageRank's alpha, which is --pagerank */
        fprintf(stderr, "ulam %s: note: --alpha is deprecated: the kernel exponent is --kernel-exponent (PageRank's "
                        "damping is --pagerank)\n", command);
    ulam_error err;
    int status = ulam_options_set(ULAM_OPTIONS_WALK, o, name, value, &err);
    return status == ULAM_ENOTFOUND ? 1 : status ? cli_usage_error(command, "%s", err.msg) : 0;
}

/* The default budget once the options are parsed: 100000 walks when no stopping rule (--walks,
 * --rel-err, --time) was given (the command cleared o->max_walks before parsing). */
void cli_walk_budget(ulam_walk_opts *o)
{
    if (!o->stop.max_walks && !(o->stop.rel_err > 0) && !(o->stop.max_seconds > 0)) o->stop.max_walks = 100000;
}
