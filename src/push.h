/* The push workspace's internal accessors (src/push.c): facts about the push itself, nothing of
 * what is built on it. */
#ifndef ULAM_PUSH_H
#define ULAM_PUSH_H

#include "internal.h"

/* The matrix a workspace pushes on. */
const ulam_csr *ulam__push_matrix(const ulam_push *w);

/* A count that changes whenever the workspace's state changes (ulam__push_start, ulam__push_run):
 * a plan that recorded it describes the push in place while it is unchanged. */
uint64_t ulam__push_stamp(const ulam_push *w);


/* A workspace for pushes on the square matrix M, which is borrowed until the workspace is freed. */
int ulam__push_alloc(const ulam_csr *M, ulam_push **out);

/* The same for an M whose caller vouches for its structure (rows it reads stay in bounds): no
 * pass over M, so a push that stays local reads only the rows it pushes. */
int ulam__push_alloc_trusted(const ulam_csr *M, ulam_push **out);

/* The states whose p or r may be nonzero (*count of them; the rest are 0). */
const int32_t *ulam__push_touched(const ulam_push *w, int64_t *count);

/* Free a workspace; accepts and returns NULL. */
ulam_push *ulam__push_free(ulam_push *w);

/* Start over for target t (0-based): p = 0, r = e_t; ULAM_EINVAL when t is out of range. */
int ulam__push_start(ulam_push *w, int64_t target);

/* Push every state with |r_j| > rmax until none is left (FIFO order); ULAM_EINVAL for rmax <= 0 or
 * no start; ULAM_ENOCONV when the work passes max_ops (> 0; 0 is no cap), the invariant intact. */
int ulam__push_run(ulam_push *w, double rmax, int64_t max_ops);

/* Have ulam__push_run check row j with verify(ctx, j, &bad) before it pushes it (a lazily read
 * file's block check: cheap once done); a nonzero return stops the run with ULAM_ESYNTAX and
 * ulam__push_bad_row gives the row the check named (-1: none). */
void ulam__push_set_verify(ulam_push *w, int (*verify)(const void *ctx, int64_t j, int64_t *bad), const void *ctx);
int64_t ulam__push_bad_row(const ulam_push *w);

/* The dense estimates p and residuals r (n entries each, owned by the workspace). */
const double *ulam__push_estimates(const ulam_push *w);

const double *ulam__push_residuals(const ulam_push *w);

/* Fill *info about the pushes since the last start. */
void ulam__push_report(const ulam_push *w, ulam_push_info *info);

#endif
