/* The direct solve's privates (src/direct.c).  Internal. */
#ifndef ULAM_DIRECT_H
#define ULAM_DIRECT_H

#include "internal.h"

/* ||b - (I - M) x||_inf / ||b||_inf from the sparse M (src/direct.c). */
double ulam__direct_residual(const ulam_csr *M, const double *b, const double *x);


/* The arguments of a direct solve checked: M, b, x given, M square and a sound CSR (src/direct.c). */
int ulam__direct_args(const ulam_csr *M, const double *b, const double *x, ulam_error *err);

#endif
