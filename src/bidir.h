/* The bidirectional estimator's memory across queries (internal; src/bidir.c): the last plan
 * made on a push workspace, the pilot's scores and guards, and an analysis of M' (src/analysis.c)
 * that hands out every walk of the estimator and keeps what later walks share: the bounds over
 * every state of M' (reach_all), the kept kernels (keep_kernel) and the reach a pilot found.  Its
 * owner is the analysis of M (ulam__analysis_keep: one with its transpose and push workspace, for
 * queries made through it), or a bare push workspace for ulam_bidir_plan and ulam_bidir_solve
 * (kept with it: ulam__push_keep). */
#ifndef ULAM_BIDIR_H
#define ULAM_BIDIR_H

#include "internal.h"

typedef struct ulam__bidir ulam__bidir;

/* ulam_bidir_plan and ulam_bidir_solve on an analysis' transpose, push workspace and planner's
 * memo (made at the first call and kept), for any kernel: the memo reuses a plan only for the
 * same options, continuation and exponent among them (src/bidir.c). */
int ulam__bidir_plan_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_plan_info *plan, ulam_error *err);
int ulam__bidir_solve_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_result *res, ulam_error *err);

/* Which route the bidirectional row takes for x of (I - M) x = b (n entries) under the walks'
 * pins ao (NULL: none) and options o: 0 the reverse push from the index and collision walks from
 * b (a sparse b, nothing pinned it cannot honour), 1 the push on b and walks from the index with
 * the walks' own estimator and exponent (a dense b, or an estimator or exponent pinned). */
int ulam__method_bidir_route(const double *b, int64_t n, const ulam_auto_opts *ao, const ulam_walk_opts *o);

#endif
