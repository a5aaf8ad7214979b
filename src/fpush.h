/* Single source's privates (src/fpush.c).  Internal. */
#ifndef ULAM_FPUSH_H
#define ULAM_FPUSH_H

#include "internal.h"
#include "sweep.h"

/* ulam_fpush_solve with the sweep push's counts in sw (may be NULL; zero when ||M||_1 >= 1 and
 * the queue push ran) (src/fpush.c). */
int ulam__fpush_solve(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, double *x, double *std_error,
                      double *lo, double *hi, ulam_fpush_info *info, ulam__sweep_info *sw, ulam_error *err);

/* ulam_fpush_top with the sweep push's counts in sw (may be NULL) (src/fpush.c). */
int ulam__fpush_top(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, int64_t k, double *x,
                    int64_t *index, double *std_error, double *lo, double *hi, ulam_fpush_info *info, ulam__sweep_info *sw,
                    ulam_error *err);

/* Whether a dense LU of I - M (n states, nnz entries, ||M||_1 = alpha) costs at most a sixteenth of
 * one e-fold of the push's sweeps, 1 / (1 - alpha) of them (src/fpush_dense.c). */
int ulam__fpush_dense_pays(int64_t n, int64_t nnz, double alpha);

/* x = (I - M)^-1 e_s by a dense LU; *r_sum gets ||e_s - (I - M) x||_1 as computed, *bound the
 * certified max_i |x_i - exact x_i| (alpha = ||M||_1 < 1); ULAM_OK or the LU's status, err filled
 * (src/fpush_dense.c). */
int ulam__fpush_dense(const ulam_csr *M, int64_t s, double alpha, double *x, double *r_sum, double *bound,
                      ulam_error *err);

#endif
