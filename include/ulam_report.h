/* ulam_report.h: a result as JSON, written to a caller's FILE * (as CSparse's cs_print and GSL's
 * _fprintf write to one): the JSON schema of a walk result has one home, shared by the command
 * line (ulam solve --json) and any other front end.  The library opens, closes and prints to no
 * stream of its own. */
#ifndef ULAM_REPORT_H
#define ULAM_REPORT_H

#include <stdio.h>

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Write the member "key": v to f (null when v is not finite, else %.17g, which reads back as
 * the same double), followed by ", " unless last; key NULL writes the bare number alone. */
void ulam_json_number(FILE *f, const char *key, double v, int last);

/* Write the member "key": "v" to f, v escaped (quotes, backslashes, control characters), followed
 * by ", " unless last. */
void ulam_json_string(FILE *f, const char *key, const char *v, int last);

/* Write the members of walks r run with options o under the guards g (NULL: their radii are not
 * written) to f, each followed by ", ": "estimate", "stderr", "ci95" ([lo, hi], null unless the
 * variance is certified finite), "variance_finite", "rho_abs..." and "rho_hat..." (the radius of
 * o's mode), "kernel_alpha", the tail, the rel_err rule's outcome (with a target), "unreached"
 * (forward), the walks' counts and rates, "method", "mode", "estimator", "seed", "threads".  The
 * caller opens and closes the object and adds its own members around them (ulam solve --json:
 * "index" before, "ranks" and the timings after). */
void ulam_walk_result_json(FILE *f, const ulam_walk_opts *o, const ulam_walk_result *r, const ulam_guard *g);

/* The formats of ulam_choice_fprint. */
enum ulam_report_format { ULAM_REPORT_BRIEF = 0, ULAM_REPORT_VERBOSE = 1, ULAM_REPORT_JSON = 2 };

/* Write what --method auto chose (ulam_auto_start's ch) to f: BRIEF, one line (what was chosen
 * among how many); VERBOSE, the choice and a line a candidate (mode, estimator, continuation,
 * exponent, rho(M^), pilots, predicted walks and work); JSON, the member "auto": {...} followed
 * by ", " (the candidates, 1-based "chosen" and "closest", the pilots' share of the work).  With
 * bidir, the bidirectional row's plan and why it was or was not chosen too. */
void ulam_choice_fprint(FILE *f, const ulam_choice *ch, int bidir, int format);

#ifdef __cplusplus
}
#endif

#endif
