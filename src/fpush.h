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

#endif
