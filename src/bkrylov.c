/* A Krylov start for the push on b (src/method_bidir.c's dense route): where M is symmetric,
 * conjugate gradients give an approximate solution q of (I - M) x = b in a few hundred products,
 * and the residual r = b - (I - M) q is computed from it; then x = q + (I - M)^-1 r holds for any
 * q, and the adjoint walks from the index score only r (a control variate).  On a 2-D Poisson
 * grid by its Jacobi splitting (rho(M) = cos(pi h)) the push on b converges at the Jacobi rate
 * (10^5 sweeps on a 500 x 500 grid) and never pays, while CG's residual falls 10^4-fold in about
 * 500 products; the walks' variance and range fall with max|r|.
 *
 * r is computed in floating point: r_j rounds each of its m + 1 terms (b_j, q_j and the m
 * products M_jk q_k) and their sum, so it is off from the exact b - (I - M) q by at most
 * delta_j = 2 (m + 2) u s_j, s_j = |b_j| + |q_j| + sum |M_jk q_k| (u = DBL_EPSILON / 2; a factor
 * 2 past the first-order gamma_(m+2) for its higher terms and underflow, plus m + 2 of the least
 * normal).  The walks estimate [(I - M)^-1 r~]_i, which differs from the true residual's part by
 * |[(I - M)^-1 (r - r~)]_i| <= [(I - |M|)^-1 delta]_i <= max delta times the expected visits of
 * a walk on |M| from i (the walk solver's certified length tail, ulam__solver_visits_bound):
 * the caller widens the interval by that. */
#include "bkrylov.h"
#include "bound.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* q from CG on (I - M) q = b to relative residual tol within max_iter products (q = 0 when it
 * fails), r = b - (I - M) q as computed and *delta the largest bound on its rounding; *iters
 * the products CG spent.  M must be symmetric (the caller checks).  ULAM_OK or ULAM_ENOMEM. */
int ulam__bkrylov(const ulam_csr *M, const double *b, double tol, int max_iter, double *q, double *r, double *delta,
                  int *iters)
{
    int64_t n = M->nrows;
    double res = NAN;
    *iters = 0, *delta = 0.0;
    memset(q, 0, (size_t)n * sizeof *q);
    int status = ulam_cg(M, b, tol, max_iter, q, iters, &res);
    if (status == ULAM_ENOMEM) return status;
    if (status != ULAM_OK && status != ULAM_ENOCONV) memset(q, 0, (size_t)n * sizeof *q); /* no usable q */
    double *e = ulam__malloc((size_t)n + 1, sizeof *e), dmax = 0.0;
    if (!e) return ULAM_ENOMEM;
    if (ulam__residual(M, b, q, r, e) < 0) { /* an overflowing q: fall back to no start */
        memset(q, 0, (size_t)n * sizeof *q);
        memcpy(r, b, (size_t)n * sizeof *r);
        free(e);
        *delta = 0.0;
        return ULAM_OK;
    }
    for (int64_t j = 0; j < n; j++) dmax = fmax(dmax, e[j]);
    free(e);
    *delta = dmax;
    return ULAM_OK;
}

/* A bound on the expected visits of a walk on |M| from any state by its largest row sum S of
 * |M| (src/bound.c): 1 / (1 - S) when S < 1, else INFINITY (the walk solver's length tail then, if any). */
double ulam__bkrylov_visits(const ulam_csr *M)
{
    double S = ulam__row_sum_max(M);
    return S < 1.0 ? 1.0 / (1.0 - S) : INFINITY;
}
