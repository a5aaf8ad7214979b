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
    const double *lo, *hi; /* each x_i's certified range (ulam_solution_bound; NULL: none certified) */
    double worst;      /* their largest half-width */
} ulam_outer_report;

/* Write r to f: its totals as text lines, x_index first when r->index is set (format
 * ULAM_REPORT_BRIEF or _VERBOSE; _QUIET: that line alone; the iterations' lines are the caller's,
 * as they end), or one JSON object with the history (ULAM_REPORT_JSON). */
void ulam_outer_report_fprint(FILE *f, const ulam_outer_report *r, int format);

/* What a bidirectional solve of one x_t (ulam_analysis_bidir, or the bidirectional row of
 * ulam_run_finish) or a single-source estimate of every x_i (ulam_fpush_top) reports: the caller
 * fills it (zero what it does not know) and ulam_report_fprint writes it. */
typedef struct ulam_bidir_report {
    const ulam_bidir_opts *opts;     /* the point query's options (NULL: the single-source table) */
    const ulam_bidir_result *result; /* its answer (scaled to pi with pagerank) */
    const ulam_guard *guard;         /* M's guards, forward kernel (NULL: not computed; JSON radii null) */
    const ulam_choice *choice;       /* --method auto's choice (NULL: the row was pinned) */
    int dense;                       /* 1: the push on b and walks from t (ulam_choice.bidir_route) */
    double bmax;                     /* max |b| (the push on b's line) */
    double pagerank;                 /* alpha when the answer is PageRank's pi = (1 - alpha) x (0: none) */
    const char *seeds;               /* the personalisation's seed set as given (NULL: a source, or uniform) */
    const char *answer_name;         /* what the answer is called (NULL: "x") */
    int64_t node_base;               /* the number state 0 is shown as (0 or 1) */
    int check;                       /* 1: direct holds a direct solve's value of the answer */
    double direct, direct_seconds;
    const char *direct_method;       /* "dense LU", "sparse LU" (NULL: "LU") */
    double transpose_seconds, load_seconds, guard_seconds;
    int ranks;                       /* MPI ranks (0: 1) */
    /* the single-source table (opts NULL): */
    const ulam_fpush_info *top;      /* the estimate (residual_bound scaled as the estimates are) */
    int64_t n, source;               /* the states, and the 1-based source (0: seeds or uniform) */
    int64_t rows;                    /* the rows shown, largest first */
    const int64_t *order;            /* their 0-based states */
    const double *x, *direct_x;      /* every state's estimate, and direct value (NULL: no --check) */
    const double *se, *lo, *hi;      /* the rows' standard errors and 95% intervals (NaN: none) */
    double cpu_seconds;              /* the push and walks' CPU time */
} ulam_bidir_report;

/* Its formats (ulam_report_fprint, ULAM_REPORT_BIDIR): text (ULAM_REPORT_BRIEF, _VERBOSE, _QUIET:
 * the answer line or the table's rows alone), one JSON object (ULAM_REPORT_JSON, with --check's
 * members when r->check), or --check's line alone (ULAM_REPORT_CHECK); the text writes --check's
 * line last when r->check. */

/* What ulam info reports on M (ulam_report_fprint's ULAM_REPORT_INFO): its statistics, rho(M),
 * the guards' radii and the Neumann series' verdict; for a Jacobi splitting with omega <= 1 (text
 * only), the table of rho(M) and rho(|M|) at the dampings 1, 0.9, ..., 0.5 (from J's radii, and
 * for a signed J Arnoldi on each damped splitting of A). */
typedef struct ulam_info_report {
    const char *matrix;            /* the file M came from, as named */
    int jacobi;                    /* M = I - omega D^-1 A, the Jacobi splitting of the file's A */
    double omega;                  /* its damping (1: plain Jacobi) */
    ulam_csr_stats st;             /* ulam_csr_stats_compute(M) */
    ulam_radius rho;               /* rho(M) (ulam_spectral_radius) */
    ulam_guard g;                  /* the guards (ulam_guard_check, tight) */
    const ulam_csr *A;             /* A, for a signed J's damping table (NULL: no table for a signed J) */
    const ulam_spectral_opts *so;  /* the options of the damped splittings' Arnoldi (NULL: defaults) */
} ulam_info_report;

/* A direct solve as ulam direct reports it (ULAM_REPORT_DIRECT): text (ULAM_REPORT_BRIEF; _QUIET: the
 * answer lines alone) or JSON. */
typedef struct ulam_direct_report {
    int64_t n;
    const double *x;               /* the solution */
    int64_t index;                 /* 1-based x[index] to show alone; 0: the first ten unless list is 0 */
    int list;                      /* with index 0, write the first ten entries (0: the caller writes x elsewhere) */
    int sparse;                    /* the LU was sparse (UMFPACK), else dense (LAPACK) */
    ulam_direct_info info;
    const char *answer_name;       /* the name x[index] prints as ("x", or "pi" for PageRank) */
    int64_t node_base;             /* what the first state prints as: 1, or 0 for an edge list's ids */
} ulam_direct_report;

/* One answer of a batch of queries (ULAM_REPORT_QUERY): one line of text, or one JSON object. */
typedef struct ulam_query_report {
    int64_t query;                 /* its 0-based place in the batch */
    long line;                     /* its line in the query file */
    int64_t source, index;         /* 0-based; source -1: b is the system's */
    double estimate, std_error, ci95[2]; /* ci95 NaN: no interval */
    int rel_err_met;
    int64_t walks;
    double seconds;
    uint64_t seed;                 /* the query's own seed */
    const char *answer_name;       /* as in ulam_direct_report */
    int64_t node_base;
} ulam_query_report;

/* Answer one query of a batch on analysis a, as ulam solve --queries does (src/queries.c), into q
 * for ulam_report_fprint's ULAM_REPORT_QUERY: the caller sets q->source and q->index (0-based) and
 * its own members (query, line, answer_name, node_base); this sets the estimate, std_error, ci95,
 * rel_err_met, walks, seconds and seed (o->exec.seed: a batch's query k takes
 * ulam_rng_substream(seed, ULAM_STREAM_QUERY, k)).  source < 0: x_index of (I - M) x = b by o's
 * adjoint walks (b: a's b, ulam_analysis_opts.b, to walk on a's kept kernel); else x_index with
 * b = e_source by the bidirectional method on a's transpose under M^T's guards *gt, caller-owned
 * and zeroed before the first query: derived from o->policy.guard (M's) when it holds the forward
 * radius at exponent 1, else computed on M^T, then kept.  *interrupted: o's interrupt stopped the
 * walks (q is then not an answer).  ULAM_OK, ULAM_EINVAL, or the walks' and guards' statuses. */
int ulam_analysis_query(ulam_analysis *a, const double *b, const ulam_walk_opts *o, ulam_guard *gt,
                        ulam_query_report *q, int *interrupted, ulam_error *err);

/* A prepared system file as ulam prepare reports it (ULAM_REPORT_PREPARE; text only: BRIEF and
 * VERBOSE write the same four lines, path and sizes, rho(|M|) with its verdict, the row and column
 * sums of |M|, the seconds; another format is ULAM_EINVAL). */
typedef struct ulam_prepare_report {
    const char *path;              /* the file written, as named */
    int64_t n, nnz;                /* M's order and nonzeros */
    int with_b, jacobi, transpose; /* the file holds b; M is a Jacobi splitting; it holds M^T too */
    const ulam_certificate *cert;  /* the guards' certificate written with M */
    double load_seconds, guard_seconds; /* reading the inputs; the certificate */
} ulam_prepare_report;

/* The kinds of ulam_report_fprint, a row each in its table (src/report_kind.c). */
enum ulam_report_kind {
    ULAM_REPORT_INFO = 1,   /* ulam_info_report: ulam info */
    ULAM_REPORT_DIRECT = 2, /* ulam_direct_report: ulam direct */
    ULAM_REPORT_QUERY = 3,  /* ulam_query_report: one line of ulam solve --queries */
    ULAM_REPORT_BIDIR = 4,  /* ulam_bidir_report: a bidirectional solve, or the single-source table */
    ULAM_REPORT_WALK = 5,   /* ulam_walk_report: ulam solve's walks */
    ULAM_REPORT_PREPARE = 6 /* ulam_prepare_report: ulam prepare */
};

/* Write report, the struct kind names, to f in format (enum ulam_report_format; the walk report
 * also ULAM_REPORT_WARN), as the command line prints it (see each struct for what its formats
 * write).  ULAM_OK; ULAM_EINVAL (NULL, an unknown kind, a report missing what it must hold: a
 * walk report's options and result, a bidirectional report's point or table), writing nothing;
 * or the damping table's failure (ULAM_ENOMEM). */
int ulam_report_fprint(FILE *f, int kind, const void *report, int format);

/* The format only the walk report has: a first round's warnings. */
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

/* Its formats (ulam_report_fprint, ULAM_REPORT_WALK): BRIEF, the answer line (x[i] with its interval, or why there is none), the method
 * in words, the walks, the seconds and the rel_err rule's outcome; VERBOSE, every line (steps,
 * variance, figure of merit, guards, tail, timings and the process's peak memory); QUIET, the
 * answer line alone; JSON, one object ("index", ulam_walk_result_json's members, the timings,
 * the direct solve with check, the choice, "interrupted") and a newline; CHECK, the line
 * "direct ..., z = ..." (with check); WARN, after a first round of walks, a line "warning: ..."
 * (after r->prefix) for a run bounded by a walk count that would take over an hour at that pace,
 * and for a rel_err rule that cannot be met or needs walks out of reach (nothing else). */

#ifdef __cplusplus
}
#endif

#endif
