/* ulam_study: variance studies of the walk methods (libulam_study, pkg-config ulam_study).
 *
 * A study runs every walk method of a grid (mode x estimator x weight window) at a grid of
 * budgets, repeated on seeds of their own (ulam_rng_substream(seed, ULAM_STREAM_STUDY, k)), and
 * compares each run with the exact value: the error, the reported error bar, their ratio (the
 * honesty), the coverage of the 95% interval, the work.  `ulam study` and Python's
 * ulam.System.study drive it; they parse, print and chart.  A library of its own, on top of
 * libulam (whose conventions it follows: statuses, ulam_error, caller-owned output, _free
 * accepting NULL), as the radiosity front end is: what a study needs of the solver's internals
 * it holds privately.  All tertiary. */
#ifndef ULAM_STUDY_H
#define ULAM_STUDY_H

#include <stdio.h>

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* All tertiary. */

/* The weight windows of a study's methods: none, Russian roulette below 0.5 w0, or roulette and
 * splitting above 2 w0 (w0 the starting weight: 1 adjoint, ||b||_1 forward). */
enum ulam_window { ULAM_WINDOW_PLAIN, ULAM_WINDOW_ROULETTE, ULAM_WINDOW_SPLIT };

/* A study's method grid: mode x estimator x window, 18 methods. */
enum { ULAM_STUDY_METHODS = 18 };

/* One method of the grid. */
typedef struct ulam_study_method {
    const char *name; /* "mode-estimator-window", e.g. "adjoint-collision-plain" */
    int mode;         /* ULAM_ADJOINT or ULAM_FORWARD */
    int estimator;    /* ULAM_COLLISION, ULAM_ABSORPTION or ULAM_EXPECTED */
    int window;       /* enum ulam_window */
} ulam_study_method;

/* Method k (0 <= k < ULAM_STUDY_METHODS; k = 9 mode + 3 estimator + window), or NULL. */
const ulam_study_method *ulam_study_method_get(int k);

/* The index of the method named name, or -1. */
int ulam_study_method_find(const char *name);

/* The 95% Wilson score interval [*lo, *hi] of a coverage: covered of runs intervals held the exact
 * value (runs > 0; else [0, 1]). */
void ulam_study_coverage_interval(int covered, int runs, double *lo, double *hi);

/* Up to this n a study's exact value is LAPACK's. */
#define ULAM_STUDY_DIRECT_MAX 8000

/* The exact value a study scores its runs against. */
typedef struct ulam_study_ref {
    double exact;          /* x_index: LAPACK's when direct, else settled */
    double settled;        /* Gauss-Seidel from x = 0 until x_index settles (1e-16 relative, after
                              at least 12 sweeps, at most 10^5) */
    int sweeps;            /* the sweeps it made */
    int direct;            /* 1: n <= ULAM_STUDY_DIRECT_MAX and the LAPACK solve succeeded */
    double direct_seconds; /* that solve's time */
} ulam_study_ref;

/* A variance study: every chosen method of the grid at every budget, repeats runs each, scored
 * against the exact x_index (LAPACK when small, else Gauss-Seidel settled).  Run k = (method << 24) + (budget << 16) +
 * repeat walks with seed ulam_rng_substream(seed, ULAM_STREAM_STUDY, k). */
typedef struct ulam_study ulam_study;

/* What a study runs (ulam_study_defaults, then set what differs). */
typedef struct ulam_study_params {
    const int *methods;      /* grid indices (ulam_study_method_find), nmethods of them; NULL: all 18 */
    int nmethods;
    const double *budgets;   /* walks per run (whole numbers), or seconds when time_budgets */
    int nbudgets;            /* 1 .. 16 */
    int time_budgets;        /* 1: budgets are seconds a run */
    int repeats;             /* runs per method and budget, 2 .. 4096 */
    uint64_t seed;           /* the base seed of every run */
    int threads;             /* threads a run (0: all cores) */
    const volatile int *interrupt; /* nonzero stops the run under way (not recorded); may be NULL */
    const ulam_share *share; /* walks shared across MPI ranks (ulam_walk_opts.exec.share); NULL: none */
} ulam_study_params;

/* One run of a study: which, with what seed, and what it gave. */
typedef struct ulam_study_run {
    int method, budget, repeat; /* grid index, budget index, repeat */
    double budget_value;        /* walks or seconds */
    uint64_t seed;              /* its walks' seed */
    int status;                 /* the solve's status (ULAM_OK) */
    int has_estimate;           /* 0: no estimate (refused, failed, < 2 walks, no stderr): a failure */
    double estimate, std_error, abs_error, seconds; /* NaN estimate and stderr without one */
    int64_t walks, steps;
    int covered;                /* |estimate - exact| <= 1.96 stderr */
    int last_in_cell;           /* the cell (method, budget) has every run once this one is done */
    int interrupted;            /* stopped by p->interrupt: not recorded (made again by the next call) */
} ulam_study_run;

/* A method's screening: refused (why non-empty) or run, flagged when rho(M^) is not certified
 * below 1 (its error bars mean nothing). */
typedef struct ulam_study_screen {
    int on;        /* chosen */
    int infinite;  /* variance not certified finite */
    char why[320]; /* non-empty: refused, and why */
} ulam_study_screen;

/* What the runs of one method at one budget say, against the exact value. */
typedef struct ulam_study_cell {
    int runs;           /* every finished run, those with no estimate too */
    int failed;         /* runs that ended with no estimate */
    double rmse;        /* sqrt(mean (estimate - exact)^2) over the runs with an estimate */
    double mean_stderr; /* the mean reported standard error */
    double honesty;     /* rmse / mean_stderr: 1 when the error bars are honest */
    double coverage;    /* share of runs whose 95% interval holds the exact value (a failed run holds nothing) */
    double seconds;     /* mean seconds per run */
    double work;        /* rmse^2 x seconds (lower is better; infinite with a failed run) */
} ulam_study_cell;

/* The defaults: all 18 methods, walk budgets 100 .. 10^6 (tenfold), 30 repeats, seed 1. */
ulam_study_params ulam_study_defaults(void);

/* A study of x_index (0-based) of (I - M) x = b (M and b borrowed until ulam_study_free): checks
 * p, runs the guards once (ulam_guard_check), screens each chosen method (refused when the guards
 * or the solver refuse it) and computes the exact value.  ULAM_OK, ULAM_EINVAL, ULAM_ENOMEM, or the
 * guards' status. */
int ulam_study_alloc(const ulam_csr *M, const double *b, int64_t index, const ulam_study_params *p,
                     ulam_study **out, ulam_error *err);

/* Free s (NULL allowed); returns NULL. */
ulam_study *ulam_study_free(ulam_study *s);

/* Method k's screening into *out; ULAM_OK or ULAM_EINVAL (k out of range). */
int ulam_study_screen_get(const ulam_study *s, int k, ulam_study_screen *out);

/* The exact value and how it was found. */
const ulam_study_ref *ulam_study_exact(const ulam_study *s);

/* The guards' verdicts the study ran under. */
const ulam_guard *ulam_study_guard(const ulam_study *s);

/* 1 when every run of the chosen, unrefused methods is done. */
int ulam_study_done(const ulam_study *s);

/* Run the next run not yet done (budgets outer, methods, repeats inner) into *run; ULAM_OK (a
 * run that ends with no estimate is recorded, as a failure; one stopped by p->interrupt is not:
 * run->interrupted), ULAM_ENOMEM, or ULAM_EINVAL when s is done. */
int ulam_study_iterate(ulam_study *s, ulam_study_run *run, ulam_error *err);

/* Every run not yet done, until p->interrupt; each recorded run goes to fn(run, arg) when fn is
 * not NULL.  ULAM_OK (ulam_study_done says whether all ran) or ulam_study_iterate's failure. */
int ulam_study_run_all(ulam_study *s, void (*fn)(const ulam_study_run *run, void *arg), void *arg, ulam_error *err);

/* Run (method, budget, repeat) into *run when done (1), else 0. */
int ulam_study_run_get(const ulam_study *s, int method, int budget, int repeat, ulam_study_run *run);

/* Record an earlier run (a resumed file's row: method, budget, repeat, has_estimate, estimate,
 * std_error, seconds, walks and steps read; seed, abs_error and covered derived).  ULAM_OK, or
 * ULAM_EINVAL (out of range, a method not run, or that run already done). */
int ulam_study_restore(ulam_study *s, const ulam_study_run *run);

/* The summary of method k's finished runs at budget b into *out; the runs it summarises (0: none,
 * *out zeroed). */
int ulam_study_cell_get(const ulam_study *s, int k, int b, ulam_study_cell *out);

/* The seconds the runs not yet done will take, from the measured seconds per walk of each method
 * (a method not yet measured: the dearest measured); a time budget is its own cost. */
double ulam_study_seconds_left(const ulam_study *s);

/* The winner at budget b: the method with the least work (RMSE^2 x seconds) among those run with
 * a certified finite variance and finished runs at b, its cell into *out; the method, or -1 when
 * none has finished runs at b.  A winner whose work is infinite (every such cell has a run with
 * no estimate) is no winner: the caller says so. */
int ulam_study_winner(const ulam_study *s, int b, ulam_study_cell *out);

/* 1 when forward walks on M have a certified finite variance (rho(|M|) and the forward rho(M^)
 * below 1): the outer iterations' reference lines can walk. */
int ulam_study_forward_walks(const ulam_study *s);

/* The reference lines a study's charts draw beside its runs, each point to fn(kind, seconds,
 * error on x_index, arg) in this order: "lapack" (when the exact value is LAPACK's: its seconds,
 * its difference from Gauss-Seidel's settled value), "gs" (Gauss-Seidel from x = 0 at sweeps 1,
 * 2, 4, ... and the sweep its error falls to 1e-9 |x|), "sequential" and "mcsa" (one run each,
 * seed p->seed, tolerance 1e-10, for at most reference_time seconds; only when
 * ulam_study_forward_walks and reference_time > 0), then "cg" when M is symmetric, else "gmres"
 * (GMRES(30)), at tolerances 1e-1 .. 1e-10 (a solve's seconds: the mean of repeats over at least
 * 1 ms).  p->interrupt stops them.  ULAM_OK, ULAM_EINVAL or ULAM_ENOMEM. */
int ulam_study_reference_lines(const ulam_study *s, double reference_time,
                               void (*fn)(const char *kind, double seconds, double error, void *arg), void *arg,
                               ulam_error *err);

/* What ulam_study_fprint writes (the files and text of `ulam study`; the caller opens, names and
 * closes the stream). */
enum ulam_study_report {
    ULAM_STUDY_RUNS_CSV = 0,    /* runs.csv: a row per finished run (ulam_study_runs_read reads it back) */
    ULAM_STUDY_SUMMARY_CSV = 1, /* summary.csv: a row per (method, budget) cell */
    ULAM_STUDY_BARS_CSV = 2,    /* bars.csv: per method at its largest budget, the coverage's Wilson interval */
    ULAM_STUDY_QUESTION = 3,    /* question.txt: the question's fingerprint, a "field value" line each */
    ULAM_STUDY_TEXT = 4,        /* the winner at each budget, the failures and the refused methods */
    ULAM_STUDY_CHART_COLLISION = 5, /* a gnuplot script (reading the CSVs in its directory): RMSE against */
    ULAM_STUDY_CHART_ABSORPTION = 6, /* seconds of one estimator's methods (nothing when none runs) */
    ULAM_STUDY_CHART_EXPECTED = 7,
    ULAM_STUDY_CHART_WORK = 8,      /* RMSE^2 x seconds at the largest budget, from bars.csv (log
                                       scale: nothing when none is above 0, as when every run is exact) */
    ULAM_STUDY_CHART_COVERAGE = 9   /* the coverage with its binomial interval, from bars.csv */
};

/* What a report says that the study does not know. */
typedef struct ulam_study_report_opts {
    int jacobi;            /* M = I - omega D^-1 A was made from A (the question's fields) */
    double omega;
    double reference_time; /* seconds of each one-run reference line (0: none; the RMSE charts' legend) */
    int partial;           /* interrupted: the text and the charts say so */
} ulam_study_report_opts;

/* Write report kind of s to f (ro NULL: no Jacobi, not partial, no reference lines).  ULAM_OK,
 * ULAM_EINVAL, or ULAM_EIO when f has an error. */
int ulam_study_fprint(FILE *f, const ulam_study *s, int kind, const ulam_study_report_opts *ro);

/* Restore the runs of an earlier runs.csv read from f (ulam_study_fprint's ULAM_STUDY_RUNS_CSV)
 * that belong to s's grid and are not done yet; a torn last line ends the reading.  The number
 * restored. */
int ulam_study_runs_read(ulam_study *s, FILE *f);

#ifdef __cplusplus
}
#endif

#endif /* ULAM_STUDY_H */
