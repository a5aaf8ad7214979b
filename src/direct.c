/* The reference: a dense LU solve of (I - M) x = b with OpenBLAS's LAPACKE_dgesv. */
#include "direct.h"
#include "check.h"
#include "dynload.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Bytes the dense n x n solve needs (matrix, pivots, right-hand side), 0 on overflow. */
size_t ulam_direct_bytes(int64_t n)
{
    if (n < 0 || (uint64_t)n > SIZE_MAX / (uint64_t)(n ? n : 1) / sizeof(double)) return 0;
    size_t nn = (size_t)n * (size_t)n * sizeof(double);
    size_t extra = (size_t)n * (sizeof(double) + sizeof(lapack_int));
    return nn > SIZE_MAX - extra ? 0 : nn + extra;
}

/* Column-major dense I - M into a (n x n). */
static void assemble(const ulam_csr *M, double *a)
{
    int64_t n = M->nrows;
    memset(a, 0, (size_t)n * (size_t)n * sizeof *a);
    for (int64_t i = 0; i < n; i++) {
        a[i + i * n] = 1.0;
        for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++)
            a[i + (int64_t)M->colidx[k] * n] -= M->val[k];
    }
}

/* ||b - (I - M) x||_inf / ||b||_inf, computed from the sparse M (the dense and sparse solves). */
double ulam__direct_residual(const ulam_csr *M, const double *b, const double *x)
{
    double rmax = 0.0, bmax = 0.0;
    for (int64_t i = 0; i < M->nrows; i++) {
        double r = b[i] - x[i];
        for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++) r += M->val[k] * x[M->colidx[k]];
        rmax = fmax(rmax, fabs(r));
        bmax = fmax(bmax, fabs(b[i]));
    }
    return bmax > 0.0 ? rmax / bmax : rmax;
}

/* Check the arguments of a direct solve (dense or sparse): M, b and x given, M square and a
 * sound CSR; clears err first. */
int ulam__direct_args(const ulam_csr *M, const double *b, const double *x, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !b || !x) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, b and x");
    if (M->nrows != M->ncols)
        return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M, got %lld x %lld",
                          (long long)M->nrows, (long long)M->ncols);
    return ulam__csr_check_structure(M, err); /* src/check.c */
}

/* Solve (I - M) x = b densely. */
int ulam_direct_solve(const ulam_csr *M, const double *b, double *x, size_t max_bytes,
                      ulam_direct_info *info, ulam_error *err)
{
    int bad = ulam__direct_args(M, b, x, err);
    if (bad) return bad;
    double t0 = ulam_now();
    int64_t n = M->nrows;
    size_t bytes = ulam_direct_bytes(n);
    if (bytes == 0 || n > (int64_t)INT32_MAX)
        return ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "a dense matrix whose size fits in memory (n = %lld)",
                          (long long)n);
    if (max_bytes && bytes > max_bytes)
        return ulam__fail(err, ULAM_EMEMLIMIT, 0, -1,
                          "at most %.3g GiB for the dense matrix; n = %lld needs %.3g GiB",
                          (double)max_bytes / 1073741824.0, (long long)n, (double)bytes / 1073741824.0);
    const ulam__lapacke_api *L = ulam__lapacke(err); /* src/dynload.c: opened on first use */
    if (!L) return err ? err->status : ULAM_EIO;
    double *a = ulam__malloc((size_t)n * (size_t)n, sizeof *a);
    lapack_int *ipiv = ulam__malloc((size_t)n, sizeof *ipiv);
    if (!a || !ipiv) {
        free(a);
        free(ipiv);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "%.3g GiB for the dense matrix",
                          (double)bytes / 1073741824.0);
    }
    assemble(M, a);
    double anorm = L->dlange(LAPACK_COL_MAJOR, '1', (lapack_int)n, (lapack_int)n, a, (lapack_int)n);
    memcpy(x, b, (size_t)n * sizeof *x);
    lapack_int lerr = L->dgesv(LAPACK_COL_MAJOR, (lapack_int)n, 1, a, (lapack_int)n, ipiv, x, (lapack_int)n);
    double rcond = 0.0;
    if (lerr == 0) L->dgecon(LAPACK_COL_MAJOR, '1', (lapack_int)n, a, (lapack_int)n, anorm, &rcond);
    free(a);
    free(ipiv);
    if (lerr > 0)
        return ulam__fail(err, ULAM_ESINGULAR, 0, lerr - 1,
                          "a nonsingular I - M: U(%d,%d) is exactly zero", (int)lerr, (int)lerr);
    if (lerr < 0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "valid LAPACK arguments (%d)", (int)lerr);
    for (int64_t i = 0; i < n; i++)
        if (!isfinite(x[i]))
            return ulam__fail(err, ULAM_ESINGULAR, 0, i, "a finite solution: I - M is numerically singular");
    if (info) {
        info->rcond = rcond;
        info->residual = ulam__direct_residual(M, b, x);
        info->bytes = bytes;
        info->seconds = ulam_now() - t0;
    }
    return ULAM_OK;
}
