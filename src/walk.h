/* Adjoint and forward walkers (internal). */
#ifndef ULAM_WALK_H
#define ULAM_WALK_H

#include "kernel.h"

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

/* Everything a walker reads: shared, read-only during a run. */
typedef struct {
    const ulam_kernel *k;
    const double *b;       /* right-hand side (adjoint scores) */
    const double *mb;      /* M b (adjoint expected estimator) */
    const ulam_csr *mt;    /* M' (forward expected estimator: column s of M) */
    const ulam__slot *src; /* forward: alias table of |b| over n outcomes */
    double bnorm1;         /* forward: ||b||_1 */
    int estimator;
    double roulette, split;
    int64_t max_steps;
} ulam__walker;

/* Per-thread scratch: the split stack and the forward history tally. */
typedef struct {
    int32_t *stack_s;
    double *stack_w;
    int64_t stack_cap;
    double *hist;     /* forward: this history's tally per state */
    int64_t *touched; /* forward: states with a tally in this history */
    unsigned char *mark; /* forward: mark[s] != 0 when s is in touched[] */
    int64_t ntouched;
} ulam__scratch;

/* What one history did. */
typedef struct {
    int64_t steps;
    int cut, nonfinite;
} ulam__history;

/* One adjoint history from start: its score. */
double ulam__adjoint_history(const ulam__walker *w, int64_t start, ulam_rng *r, ulam__scratch *sc,
                             ulam__history *h);

/* One forward history: appends its (state, tally) pairs to out; ULAM_ENOMEM on failure. */
int ulam__forward_history(const ulam__walker *w, ulam_rng *r, ulam__scratch *sc, ulam__tallies *out,
                          ulam__history *h);

#endif
