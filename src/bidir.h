/* The bidirectional estimator's memory across queries (internal; src/bidir.c): the last plan
 * made on a push workspace, the pilot's scores and guards, and an analysis of M' (src/analysis.c)
 * that hands out every walk of the estimator and keeps what later walks share: the bounds over
 * every state of M' (reach_all), the kept kernels (keep_kernel) and the reach a pilot found.  Its
 * owner is the analysis of M (one with its transpose and push workspace, for
 * queries made through it: ulam__analysis_bidir), or the caller of ulam__bidir_plan and
 * ulam__bidir_solve on a bare push workspace. */
#ifndef ULAM_BIDIR_H
#define ULAM_BIDIR_H

#include "analysis.h"

/* ulam__bidir_plan and ulam__bidir_solve on an analysis' transpose, push workspace and planner's
 * memo (made at the first call and kept), for any kernel: the memo reuses a plan only for the
 * same options, continuation and exponent among them (src/bidir.c). */
int ulam__bidir_plan_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_plan_info *plan, ulam_error *err);
int ulam__bidir_solve_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_result *res, ulam_error *err);

/* Which route the bidirectional row takes for x of (I - M) x = b (n entries) under the walks'
 * pins ao (NULL: none) and options o: 0 the reverse push from the index and collision walks from
 * b (a sparse b, nothing pinned it cannot honour), 1 the push on b and walks from the index with
 * the walks' own estimator and exponent (a dense b, or an estimator or exponent pinned). */
int ulam__method_bidir_route(const double *b, int64_t n, const ulam_auto_opts *ao, const ulam_walk_opts *o);

/* Plan a bidirectional estimate without its walks: start the push at o->target and, when o->rmax
 * <= 0, run a pilot of 256 walks on a seed of its own (o->walk.seed mixed) and halve rmax from 1,
 * pushing down to it, while the push's operations are below the walks' predicted work (walks
 * predicted by the stopping rule's terms: its 1000-walk floor, the variance ||b||_1 rmax V /
 * (E^2 x^), and for a rel_err target E the range term the walk solver's own bounds (the pilot's
 * solver, over the states the walks reach) give for scores of at most rmax a visit, when they
 * give one; x^ = max(min_value, |<p, b>|); E = 0.1 for a run stopped by time alone); with
 * o->rmax > 0 push to it.  w is left pushed, and memo (the caller's: ulam__bidir_alloc, freed
 * after w; may be NULL only with w NULL) remembers the plan: ulam__bidir_solve with the
 * same options (target, b, rmax, min_value, max_push_ops and the walk options the pilot and
 * prediction read) uses that push and pilot as they are, until ulam__push_start or ulam__push_run
 * changes the workspace.  The push's operations are exact; the walks are a model's prediction:
 * the solver runs what its rule needs, in whole rounds, fewer or more (on the R-MAT benchmark the
 * median prediction was 1.8e4 walks where 7168 ran; x^ far above |x| predicts too few).
 * Statuses as ulam__bidir_solve. */
int ulam__bidir_plan(ulam_push *w, ulam__bidir *memo, const ulam_csr *Mt, const ulam_bidir_opts *o,
                     ulam_bidir_plan_info *plan, ulam_error *err);

/* Estimate x_t of (I - M) x = b (e_s, or o's sparse b) with push workspace w (on M) and Mt, the
 * transpose of M (borrowed;
 * computing it is one O(nnz) pass the caller makes once for any number of queries): the plan of
 * ulam__bidir_plan (reused when w holds it for these options), then walks from s on Mt scoring the
 * residual (from b's states, in proportion to |b_j|) until o->walk's stopping rules hold.  ULAM_OK, ULAM_EINVAL (bad options, index out of
 * range, Mt not n x n with M's nnz), ULAM_ENOCONV (push cap), the walk solver's statuses. */
int ulam__bidir_solve(ulam_push *w, ulam__bidir *memo, const ulam_csr *Mt, const ulam_bidir_opts *o,
                      ulam_bidir_result *res, ulam_error *err);

#endif
