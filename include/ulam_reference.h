/* ulam_reference.h: the reference solve a random-walk answer is checked against (ulam solve
 * --check, ulam direct, and any other front end): which direct solver, and its fallback, decided
 * in one place. */
#ifndef ULAM_REFERENCE_H
#define ULAM_REFERENCE_H

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What the reference solve of M will be and need, before it starts. */
typedef struct ulam_reference_info {
    int sparse;   /* 1: the sparse LU (UMFPACK), 0: the dense LU (LAPACK) */
    int umfpack;  /* nonzero when libulam was built with UMFPACK and libumfpack loads */
    double bytes; /* the LU's memory: dense, ulam_direct_bytes(n) (INFINITY past size_t); sparse,
                     UMFPACK's bound on its peak (NAN unless estimated) */
    double flops; /* the factorisation's: dense 2/3 n^3; sparse UMFPACK's estimate (NAN unless
                     estimated) */
} ulam_reference_info;

/* Plan the reference solve of M into *p: lu 1 or 0 asks for the sparse or the dense LU, lu -1
 * chooses: sparse when UMFPACK is there and M is large (n > 1000: a dense LU takes over a second
 * from n of a few thousand) and sparse (under 5% nonzeros).  With estimate nonzero a sparse plan
 * gets UMFPACK's bounds from its symbolic analysis (a fraction of the factorisation's time;
 * ULAM_EUNSUPPORTED without UMFPACK).  M may be NULL: p->umfpack alone (sparse is lu > 0).
 * ULAM_OK, ULAM_EINVAL (p NULL) or the estimate's status with err filled. */
int ulam_reference_plan(const ulam_csr *M, int lu, int estimate, ulam_reference_info *p, ulam_error *err);

/* Solve (I - M) x = b (x: n entries) by the LU ulam_reference_plan(M, lu, ...) names, within
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
