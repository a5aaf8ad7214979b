/* A certified range of the exact solution around any x, from x's residual (one machine; the
 * partitioned system's is src/dist_outer.c's ulam_dist_bound): the answer of an outer iteration,
 * a Krylov peer or a direct solve gets an interval with no sampling in it. */
#include "bound.h"
#include "spectral.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

/* r = b - (I - M) x as computed, and e[i] (may be NULL) a bound on r_i's rounding: r_i rounds its m + 1
 * terms (b_i, x_i and the m products M_ik x_k) and their sum, so it is off from the exact residual by
 * at most 2 (m + 2) u s_i, s_i = |b_i| + |x_i| + sum |M_ik x_k| (u = DBL_EPSILON / 2; a factor 2 past the
 * first-order gamma_(m+2) for its higher terms, plus m + 2 of the least normal for underflow).
 * Returns 1 when every entry of M is nonnegative, 0 when not, -1 when an r_i or e_i is not finite. */
int ulam__residual(const ulam_csr *M, const double *b, const double *x, double *r, double *e)
{
    int nonneg = 1;
    for (int64_t i = 0; i < M->nrows; i++) {
        double s = b[i] - x[i], a = fabs(b[i]) + fabs(x[i]);
        int64_t m = M->rowptr[i + 1] - M->rowptr[i];
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) {
            double t = M->val[q] * x[M->colidx[q]];
            s += t, a += fabs(t);
            nonneg &= M->val[q] >= 0.0;
        }
        double d = 2.0 * ulam__push_rounding((double)(m + 2), a) + (double)(m + 2) * DBL_MIN;
        if (!isfinite(s) || !isfinite(d)) return -1;
        r[i] = s;
        if (e) e[i] = d;
    }
    return nonneg;
}

/* The largest row sum of |M|, rounded up (a Collatz-Wielandt bound for v = 1). */
double ulam__row_sum_max(const ulam_csr *M)
{
    double top = 0.0;
    for (int64_t i = 0; i < M->nrows; i++) {
        double s = 0.0;
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += fabs(M->val[q]);
        top = fmax(top, s * (1.0 + (double)(M->rowptr[i + 1] - M->rowptr[i] + 2) * DBL_EPSILON));
    }
    return top;
}

/* The largest of p[i] / v[i] (v NULL: all ones), rounded up. */
static double ratio_max(const double *p, const double *v, int64_t n)
{
    double top = 0.0;
    for (int64_t i = 0; i < n; i++) top = fmax(top, v ? p[i] / v[i] : p[i]);
    return top * (1.0 + 2.0 * DBL_EPSILON);
}

/* The Collatz-Wielandt vector of the certified range: *u the row sums' bound when the rows of |M|
 * sum below 1 (*h NULL: v = 1), else the expected lengths' certificate (src/spectral.c: h ~ (I -
 * |M|)^-1 1, one product checks it) in a new *h; *u >= 1 when none holds; *products (may be NULL)
 * gets the certificate's products.  ULAM_OK or ULAM_ENOMEM. */
int ulam__bound_vector(const ulam_csr *M, double **h, double *u, int64_t *products)
{
    int64_t n = M->nrows, spent = 0;
    double kappa;
    *h = NULL, *u = ulam__row_sum_max(M);
    if (products) *products = 0;
    if (*u < 1.0) return ULAM_OK;
    char *seen = ulam__malloc((size_t)n + 1, 1);
    *h = ulam__malloc((size_t)n + 1, sizeof **h);
    if (!seen || !*h) return free(seen), free(*h), *h = NULL, ULAM_ENOMEM;
    for (int64_t i = 0; i < n; i++) seen[i] = 1;
    int64_t cap = 4 * (int64_t)sqrt((double)n) + 2000;
    int status = ulam__length_certificate(M, seen, (int)cap, u, &kappa, &spent, *h);
    free(seen);
    if (products) *products = spent;
    if (status == ULAM_ENOMEM) return free(*h), *h = NULL, ULAM_ENOMEM;
    if (!(*u < 1.0)) free(*h), *h = NULL, *u = 1.0;
    return ULAM_OK;
}

/* The certified range around x from the vector of ulam__bound_vector (h, u: u >= 1 certifies
 * nothing: NaN ends, *worst INFINITY); 1 when certified, 0 when not, -1 when the residual is not
 * finite, -2 without memory. */
int ulam__bound_range(const ulam_csr *M, const double *b, const double *x, const double *h, double u, double *lo,
                      double *hi, double *worst)
{
    int64_t n = M->nrows;
    double *pos = ulam__malloc((size_t)n + 1, sizeof *pos), *neg = ulam__malloc((size_t)n + 1, sizeof *neg);
    if (!pos || !neg) return free(pos), free(neg), -2;
    int nonneg = ulam__residual(M, b, x, pos, neg);
    if (nonneg < 0) return free(pos), free(neg), -1;
    for (int64_t i = 0; i < n; i++) { /* the exact residual's positive and negative parts, bounded above */
        double r = pos[i], e = neg[i];
        pos[i] = fmax(r + e, 0.0) * (1.0 + DBL_EPSILON), neg[i] = fmax(e - r, 0.0) * (1.0 + DBL_EPSILON);
    }
    /* x* - x = sum_k M^k r.  A v > 0 with |M| v <= u v, u < 1, gives |M|^k |r| <= max_j (|r_j| / v_j) u^k v,
       so |x*_i - x_i| <= max_j (|r_j| / v_j) v_i / (1 - u); with M >= 0 the sum keeps r's signs (above
       by its positive part, below by its negative part).  v = 1 when the rows of |M| sum below 1, else the
       expected lengths' certificate (h). */
    int certified = u < 1.0;
    double k = (1.0 + 8.0 * DBL_EPSILON) / (1.0 - u);
    double above = certified ? ratio_max(pos, h, n) : INFINITY, below = certified ? ratio_max(neg, h, n) : INFINITY;
    if (!nonneg) above = below = fmax(above, below);
    *worst = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double v = h ? h[i] : 1.0, slack = 2.0 * DBL_EPSILON * fabs(x[i]);
        lo[i] = certified ? x[i] - (below * v * k + slack) : NAN;
        hi[i] = certified ? x[i] + (above * v * k + slack) : NAN;
        *worst = certified ? fmax(*worst, 0.5 * (hi[i] - lo[i])) : INFINITY;
    }
    free(pos), free(neg);
    return certified;
}

/* A certified range of the exact solution around x (see ulam.h). */
int ulam_solution_bound(const ulam_csr *M, const double *b, const double *x, double *lo, double *hi, double *worst,
                        ulam_error *err)
{
    ulam__clear(err);
    if (!M || !b || !x || !lo || !hi || !worst) return ulam__fail(err, ULAM_EINVAL, 0, -1, "M, b, x, lo, hi and worst");
    if (M->nrows != M->ncols) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a square M");
    int64_t n = M->nrows;
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(x[i]) || !isfinite(b[i])) return ulam__fail(err, ULAM_EINVAL, 0, i, "a finite x and b");
    double *h = NULL, u;
    if (ulam__bound_vector(M, &h, &u, NULL)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the certificate");
    int certified = ulam__bound_range(M, b, x, h, u, lo, hi, worst);
    free(h);
    if (certified == -2) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for 2 x %lld doubles", (long long)n);
    if (certified < 0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an x whose residual is finite");
    return certified ? ULAM_OK
                     : ulam__fail(err, ULAM_EDIVERGE, 0, -1, "a Collatz-Wielandt vector certifying rho(|M|) below 1 (the rows "
                                  "of |M| sum to %.6g at most, and the expected lengths' certificate did not hold)",
                                  ulam__row_sum_max(M));
}
