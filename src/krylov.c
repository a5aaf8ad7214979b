/* Krylov peers for (I - M) x = b: conjugate gradients (Hestenes and Stiefel 1952) and
 * restarted GMRES (Saad and Schultz 1986) with modified Gram-Schmidt and Givens rotations,
 * as in Saad, "Iterative Methods for Sparse Linear Systems", 2nd ed., Algorithms 6.9 and 6.11.
 * Both start from x = 0 and stop on ||b - (I - M) x||_2 / ||b||_2 <= tol, the true residual
 * checked again at the end. */
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Dot product in index order. */
static double dot(const double *a, const double *b, int64_t n)
{
    double s = 0.0;
    for (int64_t i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* y = (I - M) x. */
static void apply(const ulam_csr *M, const double *x, double *y)
{
    ulam_csr_matvec(M, 0, x, y);
    for (int64_t i = 0; i < M->nrows; i++) y[i] = x[i] - y[i];
}

/* ||b - (I - M) x||_2 / ||b||_2, using w as scratch. */
static double true_residual(const ulam_csr *M, const double *b, const double *x, double *w, double bnorm)
{
    apply(M, x, w);
    for (int64_t i = 0; i < M->nrows; i++) w[i] = b[i] - w[i];
    return sqrt(dot(w, w, M->nrows)) / bnorm;
}

/* Conjugate gradients (b scaled by the caller: see ulam_cg). */
static int cg(const ulam_csr *M, const double *b, double tol, int max_iter, double *x, int *iterations,
              double *residual)
{
    if (!M || !b || !x || M->nrows != M->ncols || !(tol > 0) || !isfinite(tol) || max_iter < 1) return ULAM_EINVAL;
    if (ulam__csr_check_structure(M, NULL)) return ULAM_EINVAL; /* src/check.c */
    int64_t n = M->nrows;
    double *r = ulam__malloc((size_t)n, sizeof *r), *p = ulam__malloc((size_t)n, sizeof *p);
    double *q = ulam__malloc((size_t)n, sizeof *q);
    if (!r || !p || !q) {
        free(r), free(p), free(q);
        return ULAM_ENOMEM;
    }
    double bnorm = sqrt(dot(b, b, n));
    memset(x, 0, (size_t)n * sizeof *x);
    memcpy(r, b, (size_t)n * sizeof *r);
    memcpy(p, b, (size_t)n * sizeof *p);
    double rr = bnorm * bnorm, rel = bnorm > 0 ? 1.0 : 0.0;
    int k = 0;
    while (rel > tol && k < max_iter) {
        apply(M, p, q);
        double pq = dot(p, q, n);
        if (!(pq > 0)) break; /* not positive definite along p */
        double alpha = rr / pq;
        for (int64_t i = 0; i < n; i++) x[i] += alpha * p[i], r[i] -= alpha * q[i];
        double rr1 = dot(r, r, n);
        for (int64_t i = 0; i < n; i++) p[i] = r[i] + rr1 / rr * p[i];
        rr = rr1;
        rel = sqrt(rr) / bnorm;
        k++;
    }
    double tr = bnorm > 0 ? true_residual(M, b, x, q, bnorm) : 0.0;
    free(r), free(p), free(q);
    if (iterations) *iterations = k;
    if (residual) *residual = tr;
    return tr <= tol ? ULAM_OK : ULAM_ENOCONV;
}

/* Apply the Givens rotation (c, s) to the pair (a, b). */
static void rotate(double c, double s, double *a, double *b)
{
    double t = c * *a + s * *b;
    *b = -s * *a + c * *b;
    *a = t;
}

/* Restarted GMRES(m) (b scaled by the caller: see ulam_gmres). */
static int gmres(const ulam_csr *M, const double *b, int m, double tol, int max_iter, double *x, int *iterations,
                 double *residual)
{
    if (!M || !b || !x || M->nrows != M->ncols || !(tol > 0) || !isfinite(tol) || max_iter < 1 || m < 1)
        return ULAM_EINVAL;
    if (ulam__csr_check_structure(M, NULL)) return ULAM_EINVAL; /* src/check.c */
    int64_t n = M->nrows;
    double *V = ulam__malloc((size_t)n * (size_t)(m + 1), sizeof *V), *w = ulam__malloc((size_t)n, sizeof *w);
    double *H = ulam__calloc((size_t)(m + 1) * (size_t)m, sizeof *H); /* column-major, (m+1) x m */
    double *cs = ulam__malloc((size_t)m, sizeof *cs), *sn = ulam__malloc((size_t)m, sizeof *sn);
    double *g = ulam__malloc((size_t)m + 1, sizeof *g), *yv = ulam__malloc((size_t)m, sizeof *yv);
    if (!V || !w || !H || !cs || !sn || !g || !yv) {
        free(V), free(w), free(H), free(cs), free(sn), free(g), free(yv);
        return ULAM_ENOMEM;
    }
    double bnorm = sqrt(dot(b, b, n));
    memset(x, 0, (size_t)n * sizeof *x);
    int k = 0;
    double rel = bnorm > 0 ? 1.0 : 0.0;
    while (rel > tol && k < max_iter) {
        /* v0 = r / ||r|| from the true residual of the current x */
        apply(M, x, w);
        for (int64_t i = 0; i < n; i++) V[i] = b[i] - w[i];
        double beta = sqrt(dot(V, V, n));
        if (beta == 0) break;
        for (int64_t i = 0; i < n; i++) V[i] /= beta;
        memset(g, 0, ((size_t)m + 1) * sizeof *g);
        g[0] = beta;
        int j = 0;
        for (; j < m && k < max_iter; j++) {
            double *vj = V + (size_t)j * (size_t)n, *vn = V + (size_t)(j + 1) * (size_t)n, *h = H + (size_t)j * (size_t)(m + 1);
            apply(M, vj, vn);
            k++;
            for (int i = 0; i <= j; i++) { /* modified Gram-Schmidt */
                const double *vi = V + (size_t)i * (size_t)n;
                h[i] = dot(vn, vi, n);
                for (int64_t t = 0; t < n; t++) vn[t] -= h[i] * vi[t];
            }
            double hn = h[j + 1] = sqrt(dot(vn, vn, n)); /* kept: the rotation below zeroes h[j + 1] */
            if (hn > 0)
                for (int64_t t = 0; t < n; t++) vn[t] /= hn;
            for (int i = 0; i < j; i++) rotate(cs[i], sn[i], &h[i], &h[i + 1]);
            double d = hypot(h[j], h[j + 1]);
            cs[j] = d > 0 ? h[j] / d : 1.0, sn[j] = d > 0 ? h[j + 1] / d : 0.0;
            rotate(cs[j], sn[j], &h[j], &h[j + 1]);
            rotate(cs[j], sn[j], &g[j], &g[j + 1]);
            rel = fabs(g[j + 1]) / bnorm;
            if (rel <= tol || hn == 0.0) { /* converged, or the Krylov space is invariant */
                j++;
                break;
            }
        }
        for (int i = j - 1; i >= 0; i--) { /* back substitution: H y = g */
            double s = g[i];
            for (int t = i + 1; t < j; t++) s -= H[(size_t)t * (size_t)(m + 1) + (size_t)i] * yv[t];
            yv[i] = s / H[(size_t)i * (size_t)(m + 1) + (size_t)i];
        }
        for (int i = 0; i < j; i++)
            for (int64_t t = 0; t < n; t++) x[t] += yv[i] * V[(size_t)i * (size_t)n + (size_t)t];
        rel = true_residual(M, b, x, w, bnorm);
    }
    double tr = bnorm > 0 ? true_residual(M, b, x, w, bnorm) : 0.0;
    free(V), free(w), free(H), free(cs), free(sn), free(g), free(yv);
    if (iterations) *iterations = k;
    if (residual) *residual = tr;
    return tr <= tol ? ULAM_OK : ULAM_ENOCONV;
}

/* Run cg (restart 0) or gmres on b 2^-e when b is far from 1 (its norms would overflow or
 * underflow), then x 2^e (both exact); ULAM_ENONFINITE when x or the residual is not finite. */
static int scaled(const ulam_csr *M, const double *b, int restart, double tol, int max_iter, double *x,
                  int *iterations, double *residual)
{
    int64_t n = M->nrows;
    int e = ulam__b_exponent(b, n);
    double *bs = e ? ulam__b_scaled(b, n, e) : NULL, res = NAN;
    if (e && !bs) return ULAM_ENOMEM;
    int status = restart ? gmres(M, bs ? bs : b, restart, tol, max_iter, x, iterations, &res)
                         : cg(M, bs ? bs : b, tol, max_iter, x, iterations, &res);
    free(bs);
    if (status == ULAM_ENOMEM || status == ULAM_EINVAL) return status; /* x not written */
    if (residual) *residual = res;
    int bad = !isfinite(res);
    for (int64_t i = 0; i < n; i++) bad |= !isfinite(x[i] = ldexp(x[i], e));
    return bad ? ULAM_ENONFINITE : status;
}

/* Conjugate gradients on b scaled. */
int ulam_cg(const ulam_csr *M, const double *b, double tol, int max_iter, double *x, int *iterations,
            double *residual)
{
    if (!M || !b || !x || M->nrows != M->ncols) return ULAM_EINVAL;
    return scaled(M, b, 0, tol, max_iter, x, iterations, residual);
}

/* Restarted GMRES(m) on b scaled. */
int ulam_gmres(const ulam_csr *M, const double *b, int m, double tol, int max_iter, double *x, int *iterations,
               double *residual)
{
    if (!M || !b || !x || M->nrows != M->ncols || m < 1) return ULAM_EINVAL;
    return scaled(M, b, m, tol, max_iter, x, iterations, residual);
}
