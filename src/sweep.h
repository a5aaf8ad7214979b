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

/* A hook a whole pass calls once it is done with rows [r0, r1) of A (in stretches of
 * ULAM__SWEEP_STRETCH rows, in order): a mapped file's pages given back (src/cache.c's
 * ulam__system_release); and one the rounds over a list of states call every
 * ULAM__SWEEP_TRIM_EVERY pushes (they read rows at random: src/cache.c's ulam__system_trim).
 * NULL: none. */
typedef struct {
    void (*fn)(const void *ctx, const ulam_csr *A, int64_t r0, int64_t r1);
    void (*trim)(const void *ctx);
    const void *ctx;
} ulam__sweep_release;

#define ULAM__SWEEP_TRIM_EVERY 256

#define ULAM__SWEEP_STRETCH ((int64_t)1 << 16)

/* Call rel's hook once row i of A (n rows) is done, when i ends a stretch or A. */
static inline void ulam__sweep_done(const ulam__sweep_release *rel, const ulam_csr *A, int64_t i, int64_t n)
{
    if (rel && rel->fn && ((i + 1) % ULAM__SWEEP_STRETCH == 0 || i + 1 == n))
        rel->fn(rel->ctx, A, i / ULAM__SWEEP_STRETCH * ULAM__SWEEP_STRETCH, i + 1);
}

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
 * largest entry of each row of Mt.  rel (may be NULL): the whole sweeps' hook (ulam__sweep_release). */
int ulam__sweep_push_pull(const ulam_csr *M, const ulam_csr *Mt, int64_t s, double rmax, ulam__sweep_cost cost,
                          void *ctx, int64_t max_ops, double *p, double *r, double *csum, double *cmax,
                          const ulam__sweep_release *rel, ulam__sweep_info *info);

#endif
