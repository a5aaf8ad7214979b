/* ulam_reference.h: the reference solve a random-walk answer is checked against (ulam solve
 * --check, ulam direct, and any other front end): which direct solver, and its fallback, decided
 * in one place. */
#ifndef ULAM_REFERENCE_H
#define ULAM_REFERENCE_H

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when the reference solve of M is the sparse LU (UMFPACK), 0 the dense (LAPACK): lu 1 or 0
 * asks for one, lu -1 chooses: sparse when UMFPACK is there and M is large (n > 1000: a dense LU
 * takes over a second from n of a few thousand) and sparse (under 5% nonzeros). */
int ulam_reference_sparse(const ulam_csr *M, int lu);

/* Solve (I - M) x = b (x: n entries) by the LU ulam_reference_sparse(M, lu) names, within
 * max_bytes; with gmres, when the LU would pass max_bytes (ULAM_EMEMLIMIT), by GMRES(50) to a
 * relative residual of 1e-12 instead.  *how (may be NULL) gets "sparse LU", "dense LU" or
 * "GMRES"; info the LU's figures (GMRES: its residual and seconds).  ULAM_OK or the solver's
 * status with err filled. */
int ulam_reference_solve(const ulam_csr *M, const double *b, int lu, size_t max_bytes, int gmres, double *x,
                         ulam_direct_info *info, const char **how, ulam_error *err);

#ifdef __cplusplus
}
#endif

#endif
