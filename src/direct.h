/* The direct solve's privates (src/direct.c).  Internal. */
#ifndef ULAM_DIRECT_H
#define ULAM_DIRECT_H

#include "internal.h"

/* ||b - (I - M) x||_inf / ||b||_inf from the sparse M (src/direct.c). */
double ulam__direct_residual(const ulam_csr *M, const double *b, const double *x);


/* The arguments of a direct solve checked: M, b, x given, M square and a sound CSR (src/direct.c). */
int ulam__direct_args(const ulam_csr *M, const double *b, const double *x, ulam_error *err);

/* Solve (I - M) x = b by UMFPACK's sparse LU within max_bytes (0: no limit; UMFPACK's estimate
 * of its peak is checked first: ULAM_EMEMLIMIT); ULAM_ESINGULAR for a singular I - M,
 * ULAM_EUNSUPPORTED without UMFPACK; info may be NULL (src/sparse_direct.c; the reference
 * solve's sparse route). */
int ulam__direct_sparse(const ulam_csr *M, const double *b, double *x, size_t max_bytes, ulam_direct_info *info,
                        ulam_error *err);

/* UMFPACK's estimates of the sparse LU's peak memory (*bytes) and flops (*flops) from its
 * symbolic analysis; ULAM_EUNSUPPORTED without UMFPACK (src/sparse_direct.c). */
int ulam__direct_sparse_estimate(const ulam_csr *M, double *bytes, double *flops, ulam_error *err);

/* Nonzero when libulam was built with UMFPACK and libumfpack loads (src/sparse_direct.c). */
int ulam__direct_sparse_available(void);

#endif
