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

/* The formats of the writers: BRIEF, a few lines; VERBOSE, everything; JSON, one object; QUIET,
 * the answer line (or the table's rows) alone; CHECK, --check's line alone (written once the
 * reference solve is done, after the rest was flushed). */
enum ulam_report_format {
    ULAM_REPORT_BRIEF = 0,
    ULAM_REPORT_VERBOSE = 1,
    ULAM_REPORT_JSON = 2,
    ULAM_REPORT_QUIET = 3,
    ULAM_REPORT_CHECK = 4
};

/* Write what --method auto chose (ulam_auto_start's ch) to f: BRIEF, one line (what was chosen
 * among how many); VERBOSE, the choice and a line a candidate (mode, estimator, continuation,
 * exponent, rho(M^), pilots, predicted walks and work); JSON, the member "auto": {...} followed
 * by ", " (the candidates, 1-based "chosen" and "closest", the pilots' share of the work).  With
 * bidir, the bidirectional row's plan and why it was or was not chosen too. */
void ulam_choice_fprint(FILE *f, const ulam_choice *ch, int bidir, int format);

/* A guard's verdict (ULAM_VERDICT_*) in words: "below 1", "at or above 1", ... */
const char *ulam_verdict_word(int verdict);

/* What an outer iteration (ulam solve --method richardson ... gmres) reports besides its steps. */
typedef struct ulam_outer_report {
    int method;        /* its row of the method table (ULAM_METHOD_RICHARDSON ... ULAM_METHOD_GMRES) */
    int estimator;     /* the walks' (ULAM_COLLISION, ...) */
    double tol, eps1;  /* the residual tolerance; the corrections' first relative error */
    uint64_t seed;
    int threads, ranks;
    const ulam_outer_step *steps; /* the iterations (NULL for the Krylov methods) */
    int nsteps, iterations, restart, status, converged, rejected;
    double residual, seconds;
    int64_t index;     /* 1-based x[index] to show (0: none) */
    const double *x;   /* the solution (NULL: none) */
    const char *answer_name; /* the name x[index] pads as ("x", or "pi" for PageRank) */
    int check;         /* err_direct holds the relative error against a direct solve */
    double err_direct;
    ulam_guard g;      /* the guards (their radii shown when the method walks) */
} ulam_outer_report;

/* Write r to f: its totals as text lines (format ULAM_REPORT_BRIEF or _VERBOSE; the iterations'
 * lines are the caller's, as they end), or one JSON object with the history (ULAM_REPORT_JSON). */
void ulam_outer_report_fprint(FILE *f, const ulam_outer_report *r, int format);

/* The format only ulam_walk_report_fprint has: a first round's warnings. */
enum ulam_walk_report_format { ULAM_REPORT_WARN = 5 };

/* A walk run (ulam solve's walks row) as its report shows it: the result and what the caller
 * measured around it. */
typedef struct ulam_walk_report {
    const ulam_walk_opts *opts;     /* the options the walks ran with (mode, estimator, seed, rules) */
    const ulam_walk_result *result; /* what they found */
    const ulam_guard *guard;        /* the guards (their radii; NULL: not written) */
    const ulam_choice *choice;      /* what --method auto chose (NULL: nothing was chosen) */
    int64_t n;                      /* the unknowns (forward walks' "unreached ... of n") */
    int64_t node_base;              /* added to opts->query.index to name the unknown (1: 1-based) */
    const char *answer_name;        /* the unknown's name, "x" (NULL too) or "pi" (PageRank: a line saying so) */
    int ranks;                      /* the processes that walked (JSON "ranks") */
    double load_seconds, guard_seconds, kernel_seconds; /* reading the inputs; the guards; the set-up */
    double total_seconds;           /* the whole run so far (BRIEF's "in all") */
    int check;                      /* direct, direct_seconds, direct_method hold a direct solve's x_index */
    double direct, direct_seconds;
    const char *direct_method;      /* "dense LU", "sparse LU", ... */
    const char *prefix;             /* WARN: the start of each line ("ulam: M.mtx: "; NULL: none) */
} ulam_walk_report;

/* Write r to f: BRIEF, the answer line (x[i] with its interval, or why there is none), the method
 * in words, the walks, the seconds and the rel_err rule's outcome; VERBOSE, every line (steps,
 * variance, figure of merit, guards, tail, timings and the process's peak memory); QUIET, the
 * answer line alone; JSON, one object ("index", ulam_walk_result_json's members, the timings,
 * the direct solve with check, the choice, "interrupted") and a newline; CHECK, the line
 * "direct ..., z = ..." (with check); WARN, after a first round of walks, a line "warning: ..."
 * (after r->prefix) for a run bounded by a walk count that would take over an hour at that pace,
 * and for a rel_err rule that cannot be met or needs walks out of reach (nothing else). */
void ulam_walk_report_fprint(FILE *f, const ulam_walk_report *r, int format);

#ifdef __cplusplus
}
#endif

#endif
