/* The residual with its rounding bounded, and the row sums of |M|: the certified range's pieces
 * (src/bound.c), also the Krylov start's (src/bkrylov.c).  Internal. */
#ifndef ULAM_BOUND_H
#define ULAM_BOUND_H

#include "internal.h"

/* r = b - (I - M) x as computed and e[i] (e may be NULL) a bound on r_i's rounding, 2 (m + 2) u s_i
 * (m: row i's entries, s_i = |b_i| + |x_i| + sum |M_ik x_k|, u = DBL_EPSILON / 2) plus m + 2 of the
 * least normal; 1 when every entry of M is nonnegative, 0 when not, -1 when an r_i or e_i is not
 * finite (r then partly written). */
int ulam__residual(const ulam_csr *M, const double *b, const double *x, double *r, double *e);

/* The largest row sum of |M|, rounded up. */
double ulam__row_sum_max(const ulam_csr *M);

/* The Collatz-Wielandt vector of the certified range (v = 1: *h NULL, or the expected lengths'
 * certificate in a new *h) and its factor *u (>= 1: none holds); *products (may be NULL) the
 * certificate's.  ULAM_OK or ULAM_ENOMEM. */
int ulam__bound_vector(const ulam_csr *M, double **h, double *u, int64_t *products);

/* The certified range [lo, hi] around x and its largest half-width *worst from that vector; 1
 * certified, 0 not (NaN ends, INFINITY), -1 a non-finite residual, -2 no memory. */
int ulam__bound_range(const ulam_csr *M, const double *b, const double *x, const double *h, double u, double *lo,
                      double *hi, double *worst);

#endif
