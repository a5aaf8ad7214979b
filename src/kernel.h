/* The walk kernel (internal): one array of rows, each a header and its alias slots. */
#ifndef ULAM_KERNEL_H
#define ULAM_KERNEL_H

#include "internal.h"

/* Outcome code for "the walk terminates here". */
#define ULAM__TERMINATE INT32_MIN

/* One alias slot: with the 64-bit fraction u of the draw that picked it, take a when
 * u < thresh, else b.  An outcome r >= 0 moves to the row at unit r keeping the weight's
 * sign; ~r (< 0) moves there flipping it; ULAM__TERMINATE ends the walk. */
typedef struct {
    uint64_t thresh;
    int32_t a, b;
} ulam__slot;

/* A row's header, two units long, followed by its len alias slots: everything a step from
 * this state reads sits in one contiguous run of memory. */
typedef struct {
    double factor; /* S_i / q_i: the weight's factor on every move */
    double visit;  /* scored (times the weight) on every visit */
    double end;    /* scored (times the weight) when the walk terminates here */
    int32_t len;   /* alias slots (nonzeros + 1 for termination) */
    int32_t state; /* i */
} ulam__row;

#define ULAM__HEAD 2 /* units in a header */

/* The kernel: 16-byte units holding the rows; row i starts at unit at[i]; pstar[i] = 1 - q_i.
 * Offsets are int32, so a kernel holds under 2^31 units (32 GB). */
typedef struct ulam_kernel {
    int64_t n, units;
    ulam__slot *mem;
    int64_t *at;
    double *pstar;
} ulam_kernel;

/* Vose's alias table of m outcomes out[] with probabilities p[] (sum 1) into s[0..m-1];
 * scaled, small and large are scratch arrays of m entries. */
void ulam__alias_build(const double *p, const int32_t *out, int64_t m, ulam__slot *s, double *scaled,
                       int64_t *small, int64_t *large);

/* Build the kernel of K (continue_q <= 0: analog); visit and end scores start at 0. */
int ulam__kernel_build(const ulam_csr *K, double continue_q, ulam_kernel **out);

/* Free a kernel; accepts NULL. */
ulam_kernel *ulam__kernel_free(ulam_kernel *k);

/* Mark in seen[] every state reachable from those already marked; ULAM_OK or ULAM_ENOMEM. */
int ulam__kernel_reach(const ulam_kernel *k, char *seen);

/* The header of the row at unit u. */
static inline ulam__row *ulam__kernel_row(const ulam_kernel *k, int64_t u)
{
    return (ulam__row *)(void *)(k->mem + u);
}

/* Draw a slot of row h; *frac is to be compared with its threshold. */
static inline const ulam__slot *ulam__kernel_pick(const ulam__row *h, ulam_rng *r, uint64_t *frac)
{
    return (const ulam__slot *)(const void *)h + ULAM__HEAD + ulam__rng_index(r, (uint64_t)h->len, frac);
}

/* The row unit (or state, in a source table) an outcome other than ULAM__TERMINATE names;
 * o < 0 also flips the weight's sign. */
static inline int32_t ulam__outcome_target(int32_t o)
{
    return o < 0 ? ~o : o;
}

/* The outcome of slot s for fraction frac. */
static inline int32_t ulam__slot_outcome(const ulam__slot *s, uint64_t frac)
{
    return frac < s->thresh ? s->a : s->b;
}

#endif
