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

/* What a caller (the bidirectional planner: its memo, src/bidir.h) keeps with an analysis: NULL
 * until ulam__analysis_keep; m is dropped with drop when the analysis is freed (or another is
 * kept), before the rest of the analysis. */
void *ulam__analysis_kept(const ulam_analysis *a);
void ulam__analysis_keep(ulam_analysis *a, void *m, void (*drop)(void *));

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
