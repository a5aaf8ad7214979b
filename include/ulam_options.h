/* ulam_options.h: the options of the walks, the outer iterations and the bidirectional solve by
 * name, one vocabulary for C, the command line (ulam solve --rel-err 0.01) and Python
 * (rel_err=0.01): each name is a row of one table (src/options.c) with the field it sets, its
 * type, its range and a help line, as PETSc's options database names a solver's settings.
 * Names are the command line's long options without the dashes ("rel-err", "max-steps"); an
 * underscore stands for a dash ("rel_err"). */
#ifndef ULAM_OPTIONS_H
#define ULAM_OPTIONS_H

#include <stdio.h>

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The option structs a table row may set. */
enum ulam_options_kind { ULAM_OPTIONS_WALK = ULAM_KIND_WALK, ULAM_OPTIONS_OUTER = ULAM_KIND_OUTER, ULAM_OPTIONS_BIDIR = ULAM_KIND_BIDIR };

/* Set option name of opts, a ulam_walk_opts, ulam_outer_opts or ulam_bidir_opts as kind says,
 * from its text value, checked against the option's range.  The walk options: "walks",
 * "rel-err", "time", "seed", "threads", "continue" (a number, or "analog"), "kernel-exponent",
 * "roulette", "split", "max-steps", "estimator", "mode"; an outer iteration's own: "tol",
 * "max-iter", "eps1", "max-histories", "stall"; a bidirectional solve's own: "rmax",
 * "min-value", "step-cost" (any other name of those two goes to their walk options).  ULAM_OK;
 * ULAM_ENOTFOUND for a name that is none of kind's options; ULAM_EINVAL for a bad value (or a
 * NULL argument), err->msg the sentence that names the option and what it expects ("--walks
 * expects an integer from 1 to ..., got 'x'"; an enum's with the closest name: "(did you mean
 * 'collision'?)").  opts is untouched unless ULAM_OK. */
int ulam_options_set(int kind, void *opts, const char *name, const char *value, ulam_error *err);

/* Parse value, the text of option opt (named in the message as given, "--walks"), as an integer
 * in [lo, hi] (1e6 and 2.5e3 are read as whole numbers) into *out: ULAM_OK, or ULAM_EINVAL with
 * err->msg the sentence ("--walks expects an integer from 1 to 10, got 'x'"). */
int ulam_options_parse_int(const char *opt, const char *value, int64_t lo, int64_t hi, int64_t *out,
                           ulam_error *err);

/* The same for a finite real in [lo, hi]. */
int ulam_options_parse_real(const char *opt, const char *value, double lo, double hi, double *out,
                            ulam_error *err);

/* The name among names[0..n) closest to word (a prefix of 3 or more letters, or within a third
 * of its length in edits), or NULL: the "did you mean" of a misspelt name. */
const char *ulam_options_suggest(const char *word, const char *const *names, int n);

/* Write the help of topic to f: a command of ulam ("info", "solve", "direct", "study",
 * "prepare"), a solve method's own ("bidirectional", "mcsa"), or "ulam" (the commands).  ULAM_OK,
 * ULAM_EINVAL (no such topic) or ULAM_EIO (f has an error). */
int ulam_options_help(FILE *f, const char *topic);

#ifdef __cplusplus
}
#endif

#endif
