/* Stability guards: the spectral radii that say whether a walk's answer means anything.
 *
 * A walk on K (K = M for adjoint walks, M' for forward walks) continues from i with
 * probability q_i, moves to j with probability p_ij and multiplies its weight by
 * K_ij / (q_i p_ij).  Its expected score is the Neumann series sum_k K^k b, which the walks
 * reproduce term by term only if sum_k |K|^k |b| converges: rho(|M|) < 1 (the same for M').
 * Its second moment v solves (I - M^) v = r with M^_ij = K_ij^2 / (q_i p_ij) and
 *   collision:  r = b o b + 2 b o (x - b)
 *   absorption: r = b o b / p*      (a state that scores needs p* > 0: checked by the solver)
 *   expected:   r = c o c + 2 c o (y - c), c = M b
 * (o: elementwise; derived in tests/test_walk.c), so every estimator's variance is finite iff
 * the series sum_k M^^k r converges: rho(M^) < 1.  For the analog kernel (p_ij = |K_ij| / S_i)
 * M^ = diag(S / q) |K|; a fixed q = Q gives diag(S / Q) |K|.  With K = M', rho(diag(c) |M'|)
 * = rho(|M| diag(c)), c the column factors, so no transpose is formed.
 *
 * The radii of these nonnegative matrices come from power iteration with Collatz-Wielandt
 * bounds, which certify a verdict whenever the bracket lies on one side of 1. */
#include "internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

/* The default options. */
ulam_power_opts ulam_power_defaults(void)
{
    return (ulam_power_opts){.tol = 1e-4, .max_iter = 1000};
}

/* y = diag(left) |A| xr (threaded only where the product is big enough to pay for it). */
static void apply(const ulam_csr *A, const double *left, const double *xr, double *y)
{
#pragma omp parallel for schedule(static) if (ulam_csr_nnz(A) > 200000)
    for (int64_t i = 0; i < A->nrows; i++) {
        double s = 0.0;
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) s += fabs(A->val[q]) * xr[A->colidx[q]];
        y[i] = left ? left[i] * s : s;
    }
}

/* One power step's bookkeeping: the bounds and estimate from x and y = A x, then x <- the
 * shifted, normalised iterate y + rho x (the shift damps eigenvalues on the circle |z| = rho
 * other than rho itself, such as the -rho of bipartite matrices). */
static double step(int64_t n, double *x, const double *y, double *lo, double *hi)
{
    double sx = 0.0, sy = 0.0, mx = 0.0;
    *lo = INFINITY, *hi = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double r = y[i] / x[i];
        *lo = fmin(*lo, r), *hi = fmax(*hi, r);
        sx += x[i], sy += y[i];
    }
    double est = sy / sx;
    for (int64_t i = 0; i < n; i++) mx = fmax(mx, x[i] = y[i] + est * x[i]);
    for (int64_t i = 0; i < n; i++) x[i] = mx > 0 ? fmax(x[i] / mx, 1e-200) : 1.0;
    return est;
}

/* rho(diag(left) |A| diag(right)) by shifted power iteration with Collatz-Wielandt bounds. */
int ulam_spectral_power(const ulam_csr *A, const double *left, const double *right,
                        const ulam_power_opts *opts, ulam_power *out, ulam_error *err)
{
    ulam__clear(err);
    if (!A || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix and an output");
    if (A->nrows != A->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix");
    ulam_power_opts o = opts ? *opts : ulam_power_defaults();
    int64_t n = A->nrows;
    double t0 = ulam_now();
    double *x = ulam__malloc((size_t)n, sizeof *x), *y = ulam__malloc((size_t)n, sizeof *y);
    double *xr = right ? ulam__malloc((size_t)n, sizeof *xr) : x;
    if (!x || !y || !xr) {
        free(x), free(y);
        if (right) free(xr);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for three vectors of %lld", (long long)n);
    }
    *out = (ulam_power){.lower = 0.0, .upper = INFINITY};
    for (int64_t i = 0; i < n; i++) x[i] = 1.0;
    int stable = 0;
    double prev = -1.0, change = INFINITY;
    while (out->iterations < o.max_iter && !out->converged && n > 0) {
        if (right)
            for (int64_t i = 0; i < n; i++) xr[i] = right[i] * x[i];
        apply(A, left, xr, y);
        double lo, hi;
        out->rho = step(n, x, y, &lo, &hi);
        out->iterations++;
        out->lower = fmax(out->lower, lo), out->upper = fmin(out->upper, hi);
        /* the changes shrink geometrically at about `ratio`: the ones still to come add up to ahead */
        double c = fabs(out->rho - prev), ratio = c / change;
        double ahead = prev >= 0 && isfinite(change) && ratio < 1 ? c * ratio / (1 - ratio) : INFINITY;
        stable = ahead <= o.tol * out->rho ? stable + 1 : 0;
        prev = out->rho, change = c;
        out->converged = out->upper - out->lower <= o.tol * out->upper || stable >= 5 || out->upper <= o.tol;
    }
    if (n == 0) out->upper = 0.0, out->converged = 1;
    out->rho = fmin(fmax(out->rho, out->lower), out->upper);
    out->seconds = ulam_now() - t0;
    free(x), free(y);
    if (right) free(xr);
    return ULAM_OK;
}

/* Fine, near the edge or failing: certified bounds first, then the estimate. */
int ulam_verdict_of(const ulam_power *p)
{
    if (p->upper < 0.99) return ULAM_VERDICT_OK;
    if (p->lower >= 1.0 || p->rho >= 1.0) return ULAM_VERDICT_FAIL;
    return p->rho >= 0.99 ? ULAM_VERDICT_EDGE : ULAM_VERDICT_OK;
}

/* The kernel factors S_i / q_i of the rows (cols == 0) or columns (cols != 0) of |M|. */
static double *factors(const ulam_csr *M, double continue_q, int cols)
{
    int64_t n = M->nrows;
    double *f = ulam__calloc((size_t)n, sizeof *f);
    if (!f) return NULL;
    for (int64_t i = 0; i < n; i++)
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) f[cols ? M->colidx[q] : i] += fabs(M->val[q]);
    for (int64_t i = 0; i < n; i++) {
        double qi = ulam__continuation(f[i], continue_q);
        f[i] = qi > 0 ? f[i] / qi : 0.0;
    }
    return f;
}

/* Nonzero when all n factors are 1: diag(f) |M| is then |M|, and so is its radius. */
static int all_ones(const double *f, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (f[i] != 1.0) return 0;
    return 1;
}

/* rho of the second-moment matrix with factors f (left of |M| for rows, right for columns):
 * rho(|M|) itself, taking no time, when every factor is 1 (an analog kernel of rows or
 * columns summing to at most 1), for the power iteration would repeat it exactly. */
static int hat_power(const ulam_csr *M, const double *f, int cols, const ulam_power_opts *opts,
                     const ulam_power *abs, ulam_power *out, ulam_error *err)
{
    if (all_ones(f, M->nrows)) {
        *out = *abs;
        out->seconds = 0.0;
        return ULAM_OK;
    }
    return ulam_spectral_power(M, cols ? NULL : f, cols ? f : NULL, opts, out, err);
}

/* The three radii and their verdicts. */
int ulam_guard_check(const ulam_csr *M, double continue_q, const ulam_power_opts *opts,
                     ulam_guard *g, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !g) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix and an output");
    if (M->nrows != M->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    double *fr = factors(M, continue_q, 0), *fc = factors(M, continue_q, 1);
    int status = fr && fc ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the kernel factors");
    if (!status) status = ulam_spectral_power(M, NULL, NULL, opts, &g->abs, err);
    if (!status) status = hat_power(M, fr, 0, opts, &g->abs, &g->hat[ULAM_ADJOINT], err);
    if (!status) status = hat_power(M, fc, 1, opts, &g->abs, &g->hat[ULAM_FORWARD], err);
    free(fr), free(fc);
    if (status) return status;
    g->verdict_abs = ulam_verdict_of(&g->abs);
    for (int m = 0; m < 2; m++) g->verdict_hat[m] = ulam_verdict_of(&g->hat[m]);
    return ULAM_OK;
}
