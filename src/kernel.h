/* The walk kernel (internal): alias tables with termination folded in. */
#ifndef ULAM_KERNEL_H
#define ULAM_KERNEL_H

#include "internal.h"

/* Outcome code for "the walk terminates here". */
#define ULAM__TERMINATE INT32_MIN

/* One alias slot: take a when u < thresh, else b.  An outcome j >= 0 moves to j keeping the
 * sign; ~j (< 0) moves to j flipping the sign; ULAM__TERMINATE ends the walk. */
typedef struct {
    double thresh;
    int32_t a, b;
} ulam__slot;

/* Rows of slots (row i: ptr[i] .. ptr[i+1], one more than its nonzeros), the weight factor
 * S_i / q_i and the termination probability p*_i of each state. */
typedef struct ulam_kernel {
    int64_t n;
    int64_t *ptr;
    ulam__slot *slot;
    double *factor;
    double *pstar;
} ulam_kernel;

/* Vose's alias table of m outcomes out[] with probabilities p[] (sum 1) into s[0..m-1];
 * scaled, small and large are scratch arrays of m entries. */
void ulam__alias_build(const double *p, const int32_t *out, int64_t m, ulam__slot *s, double *scaled,
                       int64_t *small, int64_t *large);

/* Build the kernel of K (continue_q <= 0: analog). */
int ulam__kernel_build(const ulam_csr *K, double continue_q, ulam_kernel **out);

/* Free a kernel; accepts NULL. */
ulam_kernel *ulam__kernel_free(ulam_kernel *k);

/* Mark in seen[] every state reachable from those already marked. */
void ulam__kernel_reach(const ulam_kernel *k, char *seen);

/* One step from state i: returns the encoded outcome. */
static inline int32_t ulam__kernel_step(const ulam_kernel *k, int64_t i, ulam_rng *r)
{
    int64_t base = k->ptr[i], len = k->ptr[i + 1] - base;
    const ulam__slot *s = k->slot + base + (int64_t)ulam_rng_bounded(r, (uint64_t)len);
    return ulam_rng_uniform(r) < s->thresh ? s->a : s->b;
}

#endif
