/* A certified range of the exact solution around any x, from x's residual (one machine; the
 * partitioned system's is src/dist_outer.c's ulam_dist_bound): the answer of an outer iteration,
 * a Krylov peer or a direct solve gets an interval with no sampling in it. */
#include "internal.h"
#include "spectral.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

/* The residual r = b - (I - M) x with each row's rounding e bounded: pos[i] >= max(r_i, 0) and
 * neg[i] >= max(-r_i, 0) of the exact residual; returns 1 when every entry of M is nonnegative. */
static int residual_parts(const ulam_csr *M, const double *b, const double *x, double *pos, double *neg)
{
    int nonneg = 1;
    for (int64_t i = 0; i < M->nrows; i++) {
        double s = 0.0, a = 0.0;
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) {
            double t = M->val[q] * x[M->colidx[q]];
            s += t, a += fabs(t);
            nonneg &= M->val[q] >= 0.0;
        }
        double r = b[i] - x[i] + s; /* (len + 3) roundings, each at most DBL_EPSILON / 2 of the sizes summed */
        double e = (double)(M->rowptr[i + 1] - M->rowptr[i] + 4) * DBL_EPSILON * (fabs(b[i]) + fabs(x[i]) + a);
        pos[i] = fmax(r + e, 0.0) * (1.0 + DBL_EPSILON), neg[i] = fmax(e - r, 0.0) * (1.0 + DBL_EPSILON);
    }
    return nonneg;
}

/* The largest row sum of |M|, rounded up (a Collatz-Wielandt bound for v = 1). */
static double row_sum_max(const ulam_csr *M)
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
    double *pos = ulam__malloc((size_t)n + 1, sizeof *pos), *neg = ulam__malloc((size_t)n + 1, sizeof *neg);
    double *h = NULL;
    if (!pos || !neg) return free(pos), free(neg), ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for 2 x %lld doubles", (long long)n);
    int nonneg = residual_parts(M, b, x, pos, neg);
    /* x* - x = sum_k M^k r.  A v > 0 with |M| v <= u v, u < 1, gives |M|^k |r| <= max_j (|r_j| / v_j) u^k v,
       so |x*_i - x_i| <= max_j (|r_j| / v_j) v_i / (1 - u); with M >= 0 the sum keeps r's signs (above
       by its positive part, below by its negative part).  v = 1 when the rows of |M| sum below 1, else the
       expected lengths' certificate (src/spectral.c: h ~ (I - |M|)^-1 1, one product checks it). */
    double rows = row_sum_max(M), u = rows;
    if (!(u < 1.0)) {
        char *seen = ulam__malloc((size_t)n + 1, 1);
        h = ulam__malloc((size_t)n + 1, sizeof *h);
        int64_t products = 0;
        double kappa;
        if (seen && h) {
            for (int64_t i = 0; i < n; i++) seen[i] = 1;
            int64_t cap = 4 * (int64_t)sqrt((double)n) + 2000;
            if (ulam__length_certificate(M, seen, (int)cap, &u, &kappa, &products, h) == ULAM_ENOMEM) u = NAN;
        } else u = NAN;
        free(seen);
        if (isnan(u)) return free(pos), free(neg), free(h), ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the certificate");
    }
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
    free(pos), free(neg), free(h);
    return certified ? ULAM_OK
                     : ulam__fail(err, ULAM_EDIVERGE, 0, -1, "a Collatz-Wielandt vector certifying rho(|M|) below 1 (the rows "
                                  "of |M| sum to %.6g at most, and the expected lengths' certificate did not hold)", rows);
}
