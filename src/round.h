/* The round driver (src/round.c): blocks of walks run in rounds, their results merged in
 * block order, exchanged between processes, and the stopping rules every solver shares.  Used
 * by the matrix solver (src/solve.c) and the patch solver (src/radiosity/patchwalk.c). */
#ifndef ULAM_ROUND_H
#define ULAM_ROUND_H

#include "internal.h"

/* Nonzero when a block whose first walk is `first` may start: not interrupted and, unless it is
 * the run's first block (which always runs, so a time limit still yields an estimate), not out
 * of time (t0: when the run started). */
int ulam__block_may_start(const ulam_walk_opts *o, double t0, int64_t first);

/* What every block struct opens with, the part the round driver reads (Lua's CommonHeader): a
 * block struct embeds it as its first member, so the driver reads any solver's blocks through
 * it.  The tallies (tally_size bytes each, behind a pointer, a length and a capacity) are sent
 * between processes after the struct; walks and non-finite scores are what the block ran;
 * complete is 0 when it was interrupted, out of time or out of memory, and nomem 1 when a
 * tally list could not grow (the run fails with ULAM_ENOMEM). */
typedef struct {
    void *tally;
    int64_t len, cap;
    int64_t walks, nonfinite;
    int complete, nomem;
} ulam__block_head;

/* A block-parallel walk run as the round driver sees it: blocks of `block` walks, at most
 * `round` a round; block k runs as run(ctx, k, its first walk, its walk count, thread) and
 * leaves its result in the k-th struct of the caller's array, `size` bytes each, which opens
 * with a ulam__block_head; merge(ctx, k) adds the k-th completed block to the solver's own totals; begin(ctx), when
 * given, runs before each round inside its time (the matrix solver completes its kernel
 * there); failure(ctx), when given, is a status that fails the whole run once a round ran (a
 * corrupt matrix row), or ULAM_OK. */
typedef struct {
    int block, round;
    void (*run)(void *ctx, int k, int64_t first, int64_t count, int thread);
    size_t size, tally_size;
    void (*merge)(void *ctx, int k);
    void (*begin)(void *ctx);
    int (*failure)(void *ctx);
    int partial; /* nonzero: a round runs the walks `want` asks, its last block cut short (see ulam__run) */
} ulam__blocks;

/* Where a walk run stands between rounds, the part of a solver the round driver keeps: walks
 * merged (the next round starts there), of them non-finite scores, when the run started (t0,
 * -1 before its first round), seconds spent in rounds, and its ending: done once a stopping
 * rule is met or the run failed (status), interrupted by o->stop.interrupt.  Zeroed, with t0 = -1,
 * it is a run not yet started (ulam__run_reset). */
typedef struct {
    int64_t walks, nonfinite;
    double t0, seconds;
    int done, interrupted, status;
    int64_t want; /* the walks a rule (rel_err) predicts the run still needs, from its results so far
                     (0: no prediction): a round runs at most the blocks that many take, at least one;
                     with B->partial exactly that many walks (the last block's cut short) */
    int64_t skip; /* with B->partial, the walks of short blocks' streams left unrun: a block's first
                     walk (and so its stream, first / block) is walks + skip, every stream a block's
                     alone (a rule checks after a few walks of a block without the next round
                     reusing the rest of its stream) */
} ulam__run;

/* A run not yet started. */
void ulam__run_reset(ulam__run *run);

/* The step a solver's iterate takes, shared by matrix and patch walks so each stopping rule
 * but the relative error is written once: one round (ulam__round) after B->begin, then its
 * completed blocks merged in block order (B->merge; the first incomplete block, interrupted or
 * out of time, ends the run with what came before it), and run's ending updated: a failed
 * exchange, a block out of memory, B->failure or a non-finite score fail the run
 * (ULAM_ENONFINITE only when nothing else did); an interrupt, the walk budget (o->stop.max_walks)
 * or the time limit (o->stop.max_seconds) end it.  The solver then applies its own rel_err rule.
 * Returns run->status. */
int ulam__round_step(const ulam__blocks *B, const ulam_walk_opts *o, int threads, void *ctx, void *results,
                     ulam__run *run);

/* Nonzero when this process runs block q (always, without a share). */
int ulam__mine(const ulam_share *sh, int64_t q);

/* The options' budgets both solvers check first: nonnegative budgets, max_steps >= 1, and at
 * least one stopping rule (walks, rel_err, time or an interrupt flag); ULAM_OK or ULAM_EINVAL. */
int ulam__budgets_check(const ulam_walk_opts *o, ulam_error *err);

/* Options as ulam_solve and ulam_solve_walks take them: a rel_err target with max_walks left at
 * ulam__stop_defaults()'s (and no time limit) runs to the target, as the command line's --rel-err
 * does (max_walks 0: the cap ULAM_REL_ERR_CAP); others unchanged. */
ulam_walk_opts ulam__lift_default_cap(const ulam_walk_opts *o);

/* The walk cap of a run whose only stopping rule is rel_err: ULAM_REL_ERR_CAP (a target out of
 * reach still ends), else o->stop.max_walks. */
int64_t ulam__walk_cap(const ulam_walk_opts *o);

/* The defaults: 10^5 walks, walk cap 10^6 steps, every other rule off.  The 10^5 walks are the
 * budget of a run with no other rule: ulam_solve and ulam_solve_walks given a rel_err target with
 * max_walks left at this default (and no max_seconds) run to the target, capped at
 * ULAM_REL_ERR_CAP, as the command line's --rel-err does; another max_walks caps the target. */
ulam_stop_opts ulam__stop_defaults(void);

#endif /* ULAM_ROUND_H */
