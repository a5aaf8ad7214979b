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

/* The push on b for forward walks (src/fpush_b.c): Gauss-Seidel sweeps of the forward push on Mt,
 * M's transpose, r (b on entry) into q (zero on entry), x = q + (I - M)^-1 r holding throughout,
 * while the walks' work cost(||r||_1, q[index]) falls by more than a sweep costs; the first sweep
 * when its reads cost at most `first` units.  ULAM_OK. */
int ulam__fpush_b(const ulam_csr *Mt, int64_t index, ulam__fpush_b_cost cost, void *ctx, double first, double *q,
                  double *r, ulam__fpush_b_info *info);

#endif
