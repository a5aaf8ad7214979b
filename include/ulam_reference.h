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
    int cg;       /* the iterative reference past the memory limit: 1 conjugate gradients (M
                     symmetric, so I - M is positive definite when rho(M) < 1), 0 GMRES(50) */
    int64_t products; /* its default cap on products with M: about 4e10 flops' worth, 4e10 /
                         (nnz + 10 n) for CG, 4e10 / (nnz + 110 n) for GMRES(50) (its Gram-Schmidt),
                         at least 1000 (0 when M is NULL) */
} ulam_reference_info;

/* The iterative reference's goal (in) and what it reached (out): past the LU's memory limit
 * (src/reference.c) CG or GMRES(50) is run in rounds of iterative refinement, each round a
 * Krylov solve of the correction from the residual recomputed, until the certified range of
 * x[index] (ulam_solution_bound's, its Collatz-Wielandt vector computed once) is within
 * +- half_width: no fixed residual tolerance, so none beyond reach (1e-12 is past kappa eps for a
 * 500 x 500 Poisson grid).  It stops early when a round no longer halves the range (the
 * rounding's floor) or at the cap. */
typedef struct ulam_reference_goal {
    int64_t index;        /* in: the component judged, from 0; -1 every component (the widest) */
    double half_width;    /* in: the certified half-width wanted; <= 0 or NaN: the narrowest
                             reachable (until a round no longer halves it) */
    int64_t max_products; /* in: cap on products with M in the solves (0: the plan's products) */
    int cg;               /* out: 1 conjugate gradients, 0 GMRES(50) */
    int met;              /* out: the range reached is within half_width (or the floor asked for) */
    int capped;           /* out: the solves stopped at the cap */
    int certified;        /* out: 0 when no vector certifies rho(|M|) < 1: one solve to a relative
                             residual of 1e-10 (CG) or 1e-8 (GMRES), no range */
    double reached;       /* out: the certified half-width reached (INFINITY when not certified) */
    double lo, hi;        /* out: x*[index]'s certified range (NaN for index -1 or uncertified) */
    int64_t products;     /* out: products with M in the solves */
    int64_t cap;          /* out: the cap they ran under */
    int64_t certificate;  /* out: products the certificate took */
    int rounds;           /* out: refinement rounds */
} ulam_reference_goal;

/* Plan the reference solve of M into *p: lu 1 or 0 asks for the sparse or the dense LU, lu -1
 * chooses: sparse when UMFPACK is there and M is large (n > 1000: a dense LU takes over a second
 * from n of a few thousand) and sparse (under 5% nonzeros).  With estimate nonzero a sparse plan
 * gets UMFPACK's bounds from its symbolic analysis (a fraction of the factorisation's time;
 * ULAM_EUNSUPPORTED without UMFPACK).  M may be NULL: p->umfpack alone (sparse is lu > 0).
 * ULAM_OK, ULAM_EINVAL (p NULL) or the estimate's status with err filled. */
int ulam_reference_plan(const ulam_csr *M, int lu, int estimate, ulam_reference_info *p, ulam_error *err);

/* Solve (I - M) x = b (x: n entries) by the LU ulam_reference_plan(M, lu, ...) names, within
 * max_bytes; with iterative non-NULL, when the LU would pass max_bytes (ULAM_EMEMLIMIT), by CG
 * (M symmetric) or GMRES(50) to the goal *iterative names instead (see ulam_reference_goal),
 * which gets what was reached.  *how (may be NULL) gets "sparse LU", "dense LU", "CG" or
 * "GMRES(50)"; info the LU's figures (iterative: the final ||r||_inf / ||b||_inf and seconds).
 * ULAM_OK or the solver's status with err filled; ULAM_ENOCONV when the iterative goal was not
 * met (the cap, the rounding's floor, or no certificate), x and *iterative then still filled
 * with the best reached. */
int ulam_reference_solve(const ulam_csr *M, const double *b, int lu, size_t max_bytes,
                         ulam_reference_goal *iterative, double *x, ulam_direct_info *info, const char **how,
                         ulam_error *err);

#ifdef __cplusplus
}
#endif

#endif
