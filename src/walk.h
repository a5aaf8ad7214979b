/* Adjoint and forward walkers (internal). */
#ifndef ULAM_WALK_H
#define ULAM_WALK_H

#include "kernel.h"
#include "stats.h"

/* A (state, tally) pair a forward history emits when it ends. */
typedef struct {
    int32_t state;
    double value;
} ulam__tally;

/* Growable list of tallies (one per block). */
typedef struct {
    ulam__tally *t;
    int64_t len, cap;
} ulam__tallies;

/* Everything a walker reads: shared, read-only during a run.  What a visit or a termination
 * scores lives in the kernel's row headers (visit, end). */
typedef struct {
    ulam_kernel *k;        /* its rows are built as walks reach them */
    int64_t start;         /* adjoint: the start row's unit */
    double score0;         /* adjoint: added to every history (b_i for the expected estimator) */
    const ulam_csr *mt;    /* forward expected estimator: M' (column s of M is row s) */
    ulam__slot *src;       /* forward: alias table of |b| over n outcomes (encoded states) */
    double bnorm1;         /* forward: ||b||_1 */
    int expected;          /* forward: scatter expected tallies */
    double roulette, split;
    int64_t max_steps;
    int lanes; /* adjoint histories interleaved (1 to 32) */
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
} ulam__scratch;

/* What a block of histories produced. */
typedef struct {
    ulam__moments m; /* adjoint scores */
    ulam__tallies t; /* forward tallies */
    int64_t walks, steps, cut, nonfinite;
    double maxsq; /* adjoint: the largest score^2 */
    int complete; /* 0 when interrupted or out of memory */
    int nomem;    /* a tally list could not grow: the run fails with ULAM_ENOMEM */
} ulam__block;

/* Run count adjoint histories drawing from r into out (reset first). */
void ulam__adjoint_block(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                         ulam__block *out);

/* Run count forward histories drawing from r into out (reset first). */
void ulam__forward_block(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                         ulam__block *out);

#endif
