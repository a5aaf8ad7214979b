/* The Krylov start for the push on b (src/bkrylov.c).  Internal. */
#ifndef ULAM_BKRYLOV_H
#define ULAM_BKRYLOV_H

#include "internal.h"

/* q from conjugate gradients on (I - M) q = b (M symmetric, n = M->nrows entries) to relative
 * residual tol within max_iter products (q = 0 where CG gives nothing finite), r = b - (I - M) q
 * as computed, *delta the largest bound on r's rounding (src/bkrylov.c), *iters CG's products.
 * x = q + (I - M)^-1 r up to (I - |M|)^-1 delta.  ULAM_OK or ULAM_ENOMEM. */
int ulam__bkrylov(const ulam_csr *M, const double *b, double tol, int max_iter, double *q, double *r, double *delta,
                  int *iters);

/* 1 / (1 - S) for S the largest row sum of |M| (rounded up) when below 1, else INFINITY: a bound
 * on the expected visits of a walk on |M| (src/bkrylov.c). */
double ulam__bkrylov_visits(const ulam_csr *M);

#endif
