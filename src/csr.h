/* The CSR matrix's privates (src/csr.c).  Internal. */
#ifndef ULAM_CSR_H
#define ULAM_CSR_H

#include "internal.h"

/* Sort every row of A by column (with `threads` threads), sum duplicates and drop zeros,
 * compacting A in place. */
int ulam__csr_canonicalize(ulam_csr *A, int threads);

/* A deep copy of A. */
int ulam__csr_copy(const ulam_csr *A, ulam_csr **out);

/* Dense row-major copy of A into a caller buffer of nrows*ncols doubles. */
int ulam__csr_to_dense(const ulam_csr *A, double *dense);

/* Nonzero when M equals its transpose exactly (columns sorted; ulam_csr_stats' symmetric). */
int ulam__csr_symmetric(const ulam_csr *M);

#endif
