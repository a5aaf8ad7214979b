/* The single source's dense route (src/fpush_dense.c).  Internal. */
#ifndef ULAM_FPUSH_DENSE_H
#define ULAM_FPUSH_DENSE_H

#include "internal.h"

/* Whether a dense LU of I - M (n states, nnz entries, ||M||_1 = alpha) costs at most a sixteenth of
 * one e-fold of the push's sweeps, 1 / (1 - alpha) of them (src/fpush_dense.c). */
int ulam__fpush_dense_pays(int64_t n, int64_t nnz, double alpha);

/* x = (I - M)^-1 e_s by a dense LU; *r_sum gets ||e_s - (I - M) x||_1 as computed, *bound the
 * certified max_i |x_i - exact x_i| (alpha = ||M||_1 < 1); ULAM_OK or the LU's status, err filled
 * (src/fpush_dense.c). */
int ulam__fpush_dense(const ulam_csr *M, int64_t s, double alpha, double *x, double *r_sum, double *bound,
                      ulam_error *err);

#endif
