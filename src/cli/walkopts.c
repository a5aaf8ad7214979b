/* The walk options the walking commands share (solve, solve --source, solve --method, radiosity),
 * parsed in one place by their long name: a command lists the ones it takes in its longopts as
 * CLI_WALK_OPTION("name") and hands each to cli_walk_option. */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Parse walk option --name's value into o: 0 handled, 1 not a walk option, else an exit code
 * (the bad value reported as command's usage error).  Adding a walk option is one line here. */
int cli_walk_option(const char *command, const char *name, const char *value, ulam_walk_opts *o)
{
    const char *cmd = command;
    int64_t v;
    int rc;
    if (!strcmp(name, "walks")) { /* past 10^15 (years at 10^7 walks a second): refused, not started */
        double v = strtod(value, NULL);
        if (v > 1e15 && isfinite(v))
            return cli_usage_error(cmd, "--walks %s: more than 10^15 walks would take years (at 10^7 walks a second, "
                                   "about %.3g years): bound the run with --rel-err E or --time S", value, v / 1e7 / 31557600);
        return cli_parse_int(cmd, "--walks", value, 1, (int64_t)1e15, &o->stop.max_walks);
    }
    if (!strcmp(name, "tol")) name = "rel-err"; /* the iterations' spelling of the same target */
    if (!strcmp(name, "alpha")) /* deprecated: read as PageRank's alpha, which is --pagerank */
        fprintf(stderr, "ulam %s: note: --alpha is deprecated: the kernel exponent is --kernel-exponent (PageRank's "
                        "damping is --pagerank)\n", cmd);
    if (!strcmp(name, "rel-err")) return cli_parse_real(cmd, "--rel-err", value, 1e-12, 1.0, &o->stop.rel_err);
    if (!strcmp(name, "time")) return cli_parse_real(cmd, "--time", value, 1e-6, 1e9, &o->stop.max_seconds);
    if (!strcmp(name, "continue") && !strcmp(value, "analog")) return o->kernel.continue_q = 0.0, 0; /* min(1, S_i) */
    if (!strcmp(name, "continue")) return cli_parse_real(cmd, "--continue", value, 1e-9, 1 - 1e-12, &o->kernel.continue_q);
    if (!strcmp(name, "roulette")) return cli_parse_real(cmd, "--roulette", value, 1e-300, 1e300, &o->kernel.roulette);
    if (!strcmp(name, "split")) return cli_parse_real(cmd, "--split", value, 1e-300, 1e300, &o->kernel.split);
    if (!strcmp(name, "max-steps")) return cli_parse_int(cmd, "--max-steps", value, 1, INT64_MAX / 2, &o->stop.max_steps);
    if (!strcmp(name, "alpha") || !strcmp(name, "kernel-exponent"))
        return cli_parse_real(cmd, name[0] == 'a' ? "--alpha" : "--kernel-exponent", value, 0.0, 1000.0, &o->kernel.kernel_alpha);
    if (!strcmp(name, "seed")) {
        if (!(rc = cli_parse_int(cmd, "--seed", value, 0, INT64_MAX, &v))) o->exec.seed = (uint64_t)v;
        return rc;
    }
    if (!strcmp(name, "threads")) {
        if (!(rc = cli_parse_int(cmd, "--threads", value, 1, 1024, &v))) o->exec.threads = (int)v;
        return rc;
    }
    if (!strcmp(name, "estimator")) {
        if ((o->estimator = cli_lookup(value, cli_estimator_names, 3)) >= 0) return 0;
        return cli_choose(cmd, "--estimator", value, cli_estimator_names, 3, "collision, absorption or expected"), EXIT_USAGE;
    }
    if (!strcmp(name, "mode")) {
        if ((o->mode = cli_lookup(value, cli_mode_names, 2)) >= 0) return 0;
        return cli_choose(cmd, "--mode", value, cli_mode_names, 2, "adjoint or forward"), EXIT_USAGE;
    }
    return 1;
}

/* The default budget once the options are parsed: 100000 walks when no stopping rule (--walks,
 * --rel-err, --time) was given (the command cleared o->max_walks before parsing). */
void cli_walk_budget(ulam_walk_opts *o)
{
    if (!o->stop.max_walks && !(o->stop.rel_err > 0) && !(o->stop.max_seconds > 0)) o->stop.max_walks = 100000;
}
