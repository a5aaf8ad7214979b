/* Adjoint and forward walkers (internal). */
#ifndef ULAM_WALK_H
#define ULAM_WALK_H

#include "kernel.h"
#include "round.h"
#include "stats.h"

/* A state's tallies over a block of forward histories: their sum and their sum of squares
 * (the block adds its histories in order; the solver adds blocks in order). */
typedef struct {
    int32_t state;
    double value, square;
} ulam__tally;

/* Everything a walker reads: shared, read-only during a run.  What a visit or a termination
 * scores lives in the kernel's row headers (visit, end). */
typedef struct {
    ulam_kernel *k;        /* its rows are built as walks reach them */
    int64_t start;         /* adjoint: the start row's unit */
    double score0;         /* adjoint: added to every history (b_i for the expected estimator) */
    int64_t nstarts;       /* adjoint with a start distribution: its states (0: start at start) */
    ulam__slot *start_src; /* their alias table: outcome j (~j: negative weight) */
    int32_t *start_units;  /* their rows' units */
    double *start_b;       /* their b (expected: added times the weight), else 0 */
    double start_norm;     /* the start weight's size, sum of |start_weights| */
    const ulam_csr *mt;    /* forward expected estimator: M' (column s of M is row s) */
    ulam__slot *src;       /* forward: alias table of |b| over n outcomes (encoded states) */
    double bnorm1;         /* forward: ||b||_1 */
    int expected;          /* forward: scatter expected tallies */
    int64_t watch;         /* forward: the component whose per-history moments a block keeps */
    double roulette, split;
    int64_t max_steps;
    int lanes; /* adjoint histories interleaved (1 to 32) */
    double clip; /* > 0: a block also keeps the moments of its scores clipped to [-clip, clip] (the
                    confidence sequence's, src/stop.h); 0: none */
    int64_t part_steps; /* > 0 (adjoint, no window): those clipped moments take a history's score over its
                           first part_steps visits (steps 0 .. part_steps - 1) in place of its whole score */
    volatile const int *interrupt;
} ulam__walker;

/* Per-thread scratch: the split stacks, the forward history tally, and room to build a row
 * of the kernel when a walk first reaches it. */
typedef struct {
    ulam__kscratch *ks;
    int32_t *stack_s; /* row units */
    double *stack_w;
    int64_t stack_cap;
    double *hist;        /* forward: this history's tally per state */
    int64_t *touched;    /* forward: states with a tally in this history */
    unsigned char *mark; /* forward: mark[s] != 0 when s is in touched[] */
    int64_t ntouched;
    double *bsum, *bsq;   /* forward: this block's sums of history tallies and of their squares */
    int64_t *btouched;    /* forward: states with a tally in this block, in first-tally order */
    unsigned char *bmark; /* forward: bmark[s] != 0 when s is in btouched[] */
    int64_t nbtouched;
} ulam__scratch;

#define ULAM__SUB_WALKS 64 /* the histories of a block's part (by start order) */
#define ULAM__SUBS 16      /* a block's parts (the last one takes the histories past them) */

/* What a block of histories produced. */
typedef struct {
    ulam__block_head h; /* the round driver's part (forward: one ulam__tally per state the block
                           reached; the walks, complete and nomem) */
    ulam__moments m; /* adjoint scores */
    ulam__moments watched; /* forward: the watched component's history tallies (histories that
                              tallied it; the others count as zeros when merged) */
    ulam__moments clipped; /* the scores (forward: the watched tallies) clipped to [-clip, clip] */
    ulam__moments sub[ULAM__SUBS]; /* clipped as well, by start order: histories q ULAM__SUB_WALKS .. in sub[q]
                                       (the confidence sequence bets on each of a first block's parts
                                       from the parts before it) */
    int64_t steps, cut;
    double maxsq; /* the largest score^2 (forward: of the watched component) */
} ulam__block;

/* Run count adjoint histories drawing from r into out (reset first). */
void ulam__adjoint_block(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                         ulam__block *out);

/* Run count forward histories drawing from r into out (reset first). */
void ulam__forward_block(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                         ulam__block *out);

#endif
