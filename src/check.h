/* Argument checks (src/check.c): options, vector lengths, a CSR matrix's structure.  Internal. */
#ifndef ULAM_CHECK_H
#define ULAM_CHECK_H

#include "internal.h"

/* Argument checks (src/check.c): ULAM_OK, or ULAM_EINVAL with err naming the field and what was
 * expected.  Every finite-valued option must be finite and in its range; walk options also have
 * their counts checked (max_walks, max_steps, threads). */
int ulam__walk_opts_check(const ulam_walk_opts *o, ulam_error *err);
int ulam__power_opts_check(const ulam_power_opts *o, ulam_error *err);
int ulam__guard_opts_check(const ulam_guard_opts *o, ulam_error *err);
int ulam__spectral_opts_check(const ulam_spectral_opts *o, ulam_error *err);

/* A real argument: finite and lo <= v <= hi, else ULAM_EINVAL naming it and its range in words. */
int ulam__real_check(double v, double lo, double hi, const char *name, const char *range, ulam_error *err);

/* A vector x of len entries where a call reads n: ULAM_EINVAL (NULL) or ULAM_EDIM. */
int ulam__length_check(const double *x, int64_t len, int64_t n, const char *name, ulam_error *err);

/* The structure of A, so that reading every row stays in bounds: sizes, rowptr[0] = 0, row
 * pointers rising to nnz, column indices in [0, ncols) (values are not read).  ULAM_OK,
 * ULAM_EINVAL (sizes, missing arrays), ULAM_ESYNTAX (row pointers) or ULAM_EINDEX (a column),
 * err->index naming the row.  One O(n + nnz) pass: every function that reads all of a matrix it
 * is given calls it first; a lazy reader (the walk kernel, a prepared file's blocks) checks the
 * rows it touches with ulam__csr_check_rows instead. */
int ulam__csr_check_structure(const ulam_csr *A, ulam_error *err);

#endif
