/* The analysis' privates (src/analysis.c): what it lends its friends (the methods, the
 * bidirectional planner, the writer of prepared files).  Internal. */
#ifndef ULAM_ANALYSIS_H
#define ULAM_ANALYSIS_H

#include "internal.h"
#include "solve.h"

/* The walks' pins o (the caller's, or ulam_auto_defaults()) given a's guards when they pin a's own
 * kernel (adjoint, a's continuation and exponent, no guard of their own): ULAM_OK, or the guards'
 * status (src/analysis.c; ulam_analysis_auto, ulam_analysis_start). */
int ulam__analysis_pin_guard(ulam_analysis *a, const ulam_walk_opts *base, ulam_auto_opts *o, ulam_error *err);

/* The analysis' transpose (ulam_analysis_transpose), with *seconds (may be NULL) the time this
 * call spent making it: 0 when the analysis had it (src/analysis.c). */
const ulam_csr *ulam__analysis_transpose(ulam_analysis *a, double *seconds, ulam_error *err);

/* The matrix and the kernel (continuation, 0 analog, and exponent) an analysis is made for. */
const ulam_csr *ulam__analysis_matrix(const ulam_analysis *a);
void ulam__analysis_kernel(const ulam_analysis *a, double *continue_q, double *alpha);

/* The bidirectional planner's memo (src/bidir.c fills it; an analysis owns one, and a caller
 * of the bare-workspace calls ulam__bidir_plan and ulam__bidir_solve its own): the last plan made on a push workspace (w, at its state stamp, for Mt and options o
 * with b's entries copied: idx, val, cap entries of room), what it found and the guards its
 * pilot computed; the pilot's scores, and the analysis of Mt the walks are handed out by (for one
 * continuation and exponent: made again for another), for later queries. */
typedef struct ulam__bidir {
    int valid;
    const ulam_push *w; /* the workspace it was made on, and its stamp then (ulam__push_stamp) */
    uint64_t stamp;
    const ulam_csr *Mt; /* the transpose it was made with */
    ulam_bidir_opts o;
    int64_t *idx;
    double *val;
    int64_t cap;
    ulam_bidir_plan_info plan;
    ulam_guard guard; /* the pilot's guards on Mt, for the walks (have_guard 0: none) */
    int have_guard;
    double *ones; /* n ones (NULL until a pilot needs them): the pilot's scores */
    int found;    /* 1: this plan's pilot searched the states its walks reach, kept by at (ULAM__WALKS_FIND) */
    ulam_analysis *at; /* the walks' analysis of Mt (NULL until walks need it): their bounds over every
                          state, kept kernels (fixed for the pilot's ones, rescored for the residual)
                          and the pilot's reach */
    const ulam_csr *at_K; /* what at was made for: its matrix, continuation (0: analog) and exponent */
    double at_q, at_alpha;
} ulam__bidir;

/* An empty memo (NULL: no memory), and its free (accepts NULL; src/analysis.c). */
ulam__bidir *ulam__bidir_alloc(void);
ulam__bidir *ulam__bidir_free(ulam__bidir *m);

/* The analysis' memo of the bidirectional planner, made at the first call and freed with the
 * analysis (before the rest of it: it holds an analysis of the transpose); NULL when memory runs
 * out (err filled). */
ulam__bidir *ulam__analysis_bidir(ulam_analysis *a, ulam_error *err);

/* What an analysis lends an internal caller's walks and keeps from them (ulam__analysis_walks). */
enum {
    ULAM__WALKS_ALL = 1,   /* walk under the bounds over every state (ulam__analysis_bounds_all) */
    ULAM__WALKS_FOUND = 2, /* else under the states the last ULAM__WALKS_FIND walks found they reach (the
                              caller's to pass only for walks from the same starts; none kept: search) */
    ULAM__WALKS_FIND = 4,  /* keep the states these walks find they reach, in place of the last ones */
    ULAM__WALKS_KEEP = 8,  /* walk on the kept kernel made for these walks (matrix, continuation, exponent,
                              estimator) and keep theirs when none was: rescored to each walks' b (not
                              the expected estimator's); without it the kept kernel is dropped */
    ULAM__WALKS_FIXED = 16 /* the kept kernel is the one for this b alone, whose values its owner keeps as
                              they are (one an estimator, ulam_analysis_solver's for the shared b) */
};

/* An analysis' bounds over every state with its shared b's scores (R->b: the analysis' b, NULL
 * when they could not be made), as its queries walk under them: a prepared file's, else one pass
 * over M (made once, kept); NULL when they cannot be made (no memory, a corrupt row, a damaged
 * file).  Borrowed from the analysis (src/cache.c stores them in a prepared file). */
const ulam__reach *ulam__analysis_bounds(ulam_analysis *a);

/* 1 when a's queries share its bounds over every state (ulam_analysis_opts.shared_bounds): the
 * method table's walks row then walks under them (src/method.c). */
int ulam__analysis_shares_bounds(const ulam_analysis *a);

/* The bounds over every state of an analysis' matrix (a prepared file's, else one pass,
 * ulam__reach_all; made once and kept): ULAM_OK, or the status and err (no memory, a corrupt
 * row, alpha's probabilities underflowing, a damaged file). */
int ulam__analysis_bounds_all(ulam_analysis *a, ulam_error *err);

/* Adjoint walks on a's matrix for b (borrowed until the solver is freed) under o (its kernel's
 * continuation and exponent a's, else ULAM_EINVAL; nothing else changed) run until a stopping
 * rule holds, with what how (ULAM__WALKS_*) says a lends them and keeps from them; the result and
 * guards (either may be NULL) filled, err on failure; the finished solver in *out (the caller
 * frees it; after a failure it may only free it), or freed here when out is NULL.  The walks
 * are those of ulam_solver_alloc with o, bit for bit, whatever a lends (src/analysis.c: the
 * bidirectional planner walks on M^T through an analysis of M^T). */
int ulam__analysis_walks(ulam_analysis *a, const double *b, const ulam_walk_opts *o, int how, ulam_walk_result *result,
                         ulam_guard *guard, ulam_solver **out, ulam_error *err);

/* A's push workspace on M, made at the first call and kept (ulam_analysis_bidir pushes on it);
 * NULL: no memory (err filled). */
ulam_push *ulam__analysis_push(ulam_analysis *a, ulam_error *err);

#endif
