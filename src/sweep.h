/* The sweep push (src/sweep.c).  Internal. */
#ifndef ULAM_SWEEP_H
#define ULAM_SWEEP_H

#include "internal.h"

/* What a sweep push did (src/sweep.c): rounds over a list of states or whole sweeps (sweeps of
 * them), pushes, operations (a push costs its row's entries + 1, a sweep n more), the residual's
 * sum of |r| and the states it is on. */
typedef struct {
    int64_t rounds, sweeps, pushes, ops, support;
    double r_sum;
    int64_t pulls; /* sweeps made by pulling (ulam__sweep_push_pull) */
    int nonneg;    /* 1: M was read whole and has no negative entry (r >= 0 then); 0: not known */
    double r_neg;  /* the mass of r's negative entries after pull sweeps (over-relaxed ones overshoot; roundings) */
    int64_t chain; /* > 0: the most roundings any p_i or r_i went through (a queue push: its operations), in
                      place of the rounds' count times a row's */
    double delta;  /* > 0: the floor the top-K target planned (fpush.c's push_top) */
} ulam__sweep_info;

/* The walks' work (push operations) a residual of mass r_sum would leave. */
typedef double (*ulam__sweep_cost)(double r_sum, void *ctx);

/* One push sweep of Mt's states in order: every |r_j| > thr pushed (p_j += r_j, r_j = 0, and
 * M_kj r_j added to r_k); the operations (n, and each push's row entries + 1), the pushes in
 * *pushed. */
int64_t ulam__sweep_once(const ulam_csr *Mt, double thr, double *p, double *r, int64_t *pushed);

/* Forward push of x = (I - M)^-1 e_s on M given as its transpose Mt, into p and r (n entries
 * each, zero on entry; x = p + (I - M)^-1 r after): rounds over the states holding residual, then
 * whole sweeps in order once n / 16 hold it, pushing every |r_j| > rmax, until none is left or
 * (cost given) one more round would save less walk work than it costs.  ULAM_OK, ULAM_ENOMEM,
 * ULAM_ENOCONV past max_ops (> 0) operations (p and r still valid).  With M (NULL: none) and
 * M >= 0 the whole sweeps pull along M's rows (the same Gauss-Seidel sweeps, read like a matrix-vector product), r formed once
 * at the end; then (info->nonneg) csum and cmax (n entries each, or NULL) hold the sum and the
 * largest entry of each row of Mt. */
int ulam__sweep_push_pull(const ulam_csr *M, const ulam_csr *Mt, int64_t s, double rmax, ulam__sweep_cost cost,
                          void *ctx, int64_t max_ops, double *p, double *r, double *csum, double *cmax,
                          ulam__sweep_info *info);

#endif
