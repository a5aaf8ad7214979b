/* The walk solver's privates (src/solve.c): restarts and reruns, set-up counts, the reach
 * and its bounds, construction on a reach and kept kernels.  Internal. */
#ifndef ULAM_SOLVE_H
#define ULAM_SOLVE_H

#include "internal.h"
#include "reach.h"

/* Restart a forward solver on right-hand side b (borrowed) with seed: the kernel is kept,
 * tallies, counts and stopping state are reset (src/solve.c; used by the outer iterations). */
int ulam__solver_restart(ulam_solver *s, const double *b, uint64_t seed, ulam_error *err);

/* Walk again with options o that differ from the solver's only in the estimator, the seed, the
 * stopping rules (max_walks, rel_err, max_seconds), interrupt, share, force, assume_finite and
 * rel_err_offset (else ULAM_EINVAL): the kernel rows built (rescored for a new estimator), the
 * reachable set, the score bounds met before, the guards and the workspace are kept; every tally,
 * count and stopping state is reset, so the walks that follow are those of a solver allocated with
 * o, bit for bit (src/solve.c; used by the method choice, src/auto.c).  Refusals as
 * ulam_solver_alloc's. */
int ulam__solver_rerun(ulam_solver *s, const ulam_walk_opts *o, ulam_error *err);

/* The walk solver's internal interface (src/solve.c).  Queries on a solver (ulam__solver_setup,
 * ulam__solver_range_walks) and its restarts (ulam__solver_restart, _rerun) are for any file
 * downstream of it; its construction and caching on what earlier solvers made
 * (ulam__solver_alloc_reached, ulam__solver_keep_kernel, _keep_kernel_fixed, ulam__solver_reached,
 * ulam__reach_all below) are called from the analysis (src/analysis.c, the one home of "reach
 * once, keep the kernel, hand out solvers"), and besides it only from the method choice's
 * pilots (src/auto.c: ulam__solver_alloc_reached with the analysis' bounds). */

/* The deterministic set-up work of a solver so far: kernel units built (*units, 16 bytes each: a
 * row's nonzeros + 3) and matrix entries read by reachability checks and score-bound passes
 * (*reads). */
void ulam__solver_setup(const ulam_solver *s, int64_t *units, int64_t *reads);

/* The bound on |sum over k > l of (K^k b)_index| from the start's signed tail (adjoint collision
 * from one start: the bias of a score over a history's first l + 1 visits), NAN without one; *part
 * the visits the sequence took of each history in the round planned last (0: whole scores). */
double ulam__solver_part_bias(const ulam_solver *s, int64_t l, int64_t *part);

/* The walks the rel_err rule's range term would need at estimate m and target E were every visit
 * to score at most per_visit (times the walk's weight), both signs when signs, under the
 * reachability bounds of a solver made with rel_err > 0 and b = 1 (src/solve.c; INFINITY
 * without a bound). */
double ulam__solver_range_walks(const ulam_solver *s, double per_visit, int signs, double m, double E);

struct ulam_kernel; /* src/kernel.h */


/* The reach of every state of K at continuation continue_q and exponent alpha with its bounds;
 * seen: n bytes of room, set to all ones (borrowed by R).  ULAM_OK, ULAM_ENOMEM, ULAM_ESYNTAX
 * (a corrupt row), ULAM_ERANGE (alpha's probabilities underflow). */
int ulam__reach_all(const ulam_csr *K, double continue_q, double alpha, char *seen, ulam__reach *R);

/* Add to R (made by ulam__reach_all for K, or read from a prepared file) the scores of b (n
 * entries, borrowed by R) over every state, so that a solver given R and this b reads neither K
 * nor b before walking: one pass over K and b.  ULAM_OK, or ULAM_EINVAL when R is not K's. */
int ulam__reach_b(const ulam_csr *K, const double *b, ulam__reach *R);

/* As ulam_solver_alloc (adjoint) with reach (borrowed until the solver is freed; NULL: search)
 * and kernel (NULL, or one of ulam__solver_keep_kernel, borrowed likewise)
 * the states walks can reach, from an earlier solver on the same M, start states and
 * continuation (ulam__solver_reached) or from ulam__reach_all: its rows were checked then, the
 * search is not made again, and with reach->bounds (for this M, continuation and exponent)
 * neither are the bounds of M alone. */
int ulam__solver_alloc_reached(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                               const ulam__reach *reach, struct ulam_kernel *kernel, ulam_solver **out,
                               ulam_error *err);

/* As ulam__solver_alloc_reached (no kept kernel) under a time limit that ends at deadline
 * (ulam_now; INFINITY: none; the earlier of it and opts' max_seconds from now): past it the
 * set-up takes the cheaper paths (the length tail's power iterations and the second moment's
 * iterations stop, their bounds looser but valid); and forward walks with a certified finite
 * variance at a fixed budget (max_walks, max_seconds, no rel_err) push b first too, as far as the
 * budget's walks gain by it (src/fpush_b.c; a rerun with another budget pushes again from b:
 * ulam_solver_alloc's walks start from b there, the raw method).  For the method choice's pilots
 * and run (src/auto.c). */
int ulam__solver_alloc_until(const ulam_csr *M, const double *b, const ulam_walk_opts *opts, const ulam__reach *reach,
                             double deadline, ulam_solver **out, ulam_error *err);

/* Set the time limit's end for the set-up that follows (deadline, INFINITY: none), and when t0
 * >= 0 and the solver has max_seconds, the time its walks' limit counts from (a rerun's walks
 * otherwise count from their first block: the caller's set-up then would not count). */
void ulam__solver_clock(ulam_solver *s, double t0, double deadline);

/* The kernel of an adjoint collision or absorption solver, kept for later solvers on the same M,
 * continuation, exponent and estimator with any b (ulam__solver_alloc_reached's kernel, rescored
 * to its b: rows already built are not built again, and walks take exactly the moves a new
 * kernel's would); the caller owns it from here (ulam__kernel_free, after this solver is freed).
 * NULL when it cannot be kept (forward, expected, a failed kernel, no memory, a borrowed one). */
struct ulam_kernel *ulam__solver_keep_kernel(ulam_solver *s);

/* As ulam__solver_keep_kernel for a b whose values the caller keeps as they are, passed again to
 * every later solver on the kernel: rescoring is then nothing at all, nothing is recorded (O(1)),
 * and the expected estimator's kernel keeps too. */
struct ulam_kernel *ulam__solver_keep_kernel_fixed(ulam_solver *s);

/* The states a solver's walks can reach (n flags; NULL unless its reachability check ran). */
const char *ulam__solver_reached(const ulam_solver *s);

/* The walk solver builds the rest of its kernel at once when walks have built 1 / ULAM__COMPLETE
 * of it row by row (src/solve.c: the rent-or-buy rule); the choice's work models predict it. */
enum { ULAM__COMPLETE = 4 };

/* A bound on the expected visits of a walk on |K| from s's starts (the length tail's certificate,
 * or the analog continuation's largest q), INFINITY without one. */
double ulam__solver_visits_bound(const ulam_solver *s);

/* Iterate s until a stopping rule holds, fill result (may be NULL) and, on failure, err; free s.
 * The status (src/solve.c: the rest of ulam_solve_walks). */
int ulam__solver_finish(ulam_solver *s, ulam_walk_result *result, ulam_error *err);

/* The defaults: analog continuation, exponent 1, rows built as reached, no weight window. */
ulam_kernel_opts ulam__kernel_defaults(void);

/* The defaults: seed 1, all cores, one process. */
ulam_exec_opts ulam__exec_defaults(void);

/* The defaults: x_0, walks starting there. */
ulam_query_opts ulam__query_defaults(void);

/* The defaults: refuse what is not certified, compute the guards, no prepared system. */
ulam_policy_opts ulam__policy_defaults(void);

/* The guards' verdicts the solver walks under, a plain struct to keep or store (the analysis
 * keeps them for its next solver; src/solve.c). */
void ulam__solver_guard(const ulam_solver *s, ulam_guard *g);

#endif
