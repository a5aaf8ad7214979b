/* The forward push on b (src/bpush.c).  Internal. */
#ifndef ULAM_BPUSH_H
#define ULAM_BPUSH_H

#include "internal.h"

/* The forward push on b (src/bpush.c): push r (q alongside; x = q + (I - M)^-1 r holds before and
 * after) on Mt, M's transpose, until every |r_j| <= rmax or *ops (nonzeros read, plus one a push)
 * passes max_ops; *pushes counts the states pushed.  ULAM_OK or ULAM_ENOMEM. */
int ulam__bpush(const ulam_csr *Mt, double rmax, int64_t max_ops, double *q, double *r, int64_t *ops, int64_t *pushes);

/* What the push left (n entries of q and r) into pi's support, touched, r_sum and r_max. */
void ulam__bpush_residual(const double *q, const double *r, int64_t n, ulam_push_info *pi);

/* max_j |r_j| over n entries. */
double ulam__bpush_max(const double *r, int64_t n);

#endif
