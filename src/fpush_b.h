/* The push on b for forward walks (src/fpush_b.c).  Internal. */
#ifndef ULAM_FPUSH_B_H
#define ULAM_FPUSH_B_H

#include "internal.h"

/* The forward walks' predicted work (units of ULAM_AUTO_*) on a residual of l1 norm r_sum, the
 * push part q_i of the watched x_i taken as its scale (src/fpush_b.c's cost model). */
typedef double (*ulam__fpush_b_cost)(double r_sum, double q_i, void *ctx);

/* What the push on b for forward walks did: sweeps, operations (a state read a sweep, a push its
 * column's entries + 1), ||r||_1 before and after, the walks' predicted work before and after. */
typedef struct {
    int sweeps;
    int64_t ops;
    double r_sum0, r_sum, work0, work;
} ulam__fpush_b_info;
#define ULAM__FPUSH_B_SWEEPS 1000 /* the most sweeps (the cost model stops them long before) */
#define ULAM__FPUSH_B_CAP 4.0      /* at a fixed number of walks, the push's work at most this times theirs */
#define ULAM__FPUSH_B_TIME 0.5     /* under a time limit, the push's work at most this share of the time's */
#define ULAM__FPUSH_B_ROUNDING 64.0 /* b pushed to its rounding: ||r||_1 at most this many DBL_EPSILON of ||b||_1 */

/* The push on b for forward walks (src/fpush_b.c): Gauss-Seidel sweeps of the forward push on Mt,
 * M's transpose, r (b on entry) into q (zero on entry), x = q + (I - M)^-1 r holding throughout;
 * the first sweep when its reads cost at most `first` units.  budget 0 (a rel_err target): while
 * the walks' work cost(||r||_1, q[index]) falls by more than a sweep costs.  budget > 0 (units
 * of the walks' work a fixed budget buys): while the walks that would narrow the interval as much
 * as the next sweep cost more than it, the push's units at most cap, b not yet pushed to its
 * rounding.  ULAM_OK. */
int ulam__fpush_b(const ulam_csr *Mt, int64_t index, ulam__fpush_b_cost cost, void *ctx, double first, double budget,
                  double cap, double *q, double *r, ulam__fpush_b_info *info);

#endif
