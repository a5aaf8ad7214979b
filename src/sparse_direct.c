/* The reference for large systems: a sparse LU solve of (I - M) x = b with UMFPACK (SuiteSparse).
 * I - M in CSR is the CSC of its transpose, so UMFPACK factors that and solves the transposed
 * system (UMFPACK_At); no copy of M in another layout is made beyond I - M itself. */
#include "direct.h"
#include "dynload.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef ULAM_UMFPACK

/* Sort the row segment (col, val)[0..len) by column and merge duplicates; returns the new length. */
static int64_t sort_row(SuiteSparse_long *col, double *val, int64_t len)
{
    for (int64_t i = 1; i < len; i++) { /* insertion sort: rows are short and nearly sorted */
        SuiteSparse_long c = col[i];
        double v = val[i];
        int64_t j = i;
        for (; j > 0 && col[j - 1] > c; j--) col[j] = col[j - 1], val[j] = val[j - 1];
        col[j] = c, val[j] = v;
    }
    int64_t out = 0;
    for (int64_t i = 0; i < len; i++) {
        if (out > 0 && col[out - 1] == col[i]) val[out - 1] += val[i];
        else col[out] = col[i], val[out] = val[i], out++;
    }
    return out;
}

/* I - M as compressed rows with sorted, distinct columns (p, c, v owned by the caller); a status. */
static int assemble(const ulam_csr *M, SuiteSparse_long **p, SuiteSparse_long **c, double **v)
{
    int64_t n = M->nrows, nnz = M->rowptr[n] + n;
    *p = ulam__malloc((size_t)n + 1, sizeof **p);
    *c = ulam__malloc((size_t)nnz, sizeof **c);
    *v = ulam__malloc((size_t)nnz, sizeof **v);
    if (!*p || !*c || !*v) return ULAM_ENOMEM;
    int64_t at = 0;
    for (int64_t i = 0; i < n; i++) {
        int64_t start = at;
        (*c)[at] = (SuiteSparse_long)i, (*v)[at++] = 1.0;
        for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++)
            (*c)[at] = M->colidx[k], (*v)[at++] = -M->val[k];
        at = start + sort_row(*c + start, *v + start, at - start);
        (*p)[i] = (SuiteSparse_long)start;
    }
    (*p)[n] = (SuiteSparse_long)at;
    return ULAM_OK;
}

/* Factor and solve; a status with err filled. */
static int factor_solve(int64_t n, const SuiteSparse_long *p, const SuiteSparse_long *c, const double *v,
                        const double *b, double *x, size_t max_bytes, ulam_direct_info *info, ulam_error *err)
{
    const ulam__umfpack_api *U = ulam__umfpack(err); /* src/dynload.c: opened on first use */
    if (!U) return err ? err->status : ULAM_EIO;
    double control[UMFPACK_CONTROL], stat[UMFPACK_INFO];
    void *symbolic = NULL, *numeric = NULL;
    U->defaults(control);
    SuiteSparse_long sn = (SuiteSparse_long)n;
    int st = (int)U->symbolic(sn, sn, p, c, v, &symbolic, control, stat);
    if (st == UMFPACK_ERROR_out_of_memory) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for UMFPACK's analysis");
    if (st != UMFPACK_OK) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix UMFPACK accepts (status %d)", st);
    double peak = stat[UMFPACK_PEAK_MEMORY_ESTIMATE] * stat[UMFPACK_SIZE_OF_UNIT];
    if (max_bytes && peak > (double)max_bytes) {
        U->free_symbolic(&symbolic);
        return ulam__fail(err, ULAM_EMEMLIMIT, 0, -1, "at most %.3g GiB for the sparse LU; UMFPACK estimates %.3g GiB",
                          (double)max_bytes / 1073741824.0, peak / 1073741824.0);
    }
    st = (int)U->numeric(p, c, v, symbolic, &numeric, control, stat);
    U->free_symbolic(&symbolic);
    if (st == UMFPACK_WARNING_singular_matrix || st == UMFPACK_ERROR_out_of_memory || st < 0) {
        U->free_numeric(&numeric);
        if (st == UMFPACK_ERROR_out_of_memory) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the sparse LU factors");
        if (st == UMFPACK_WARNING_singular_matrix)
            return ulam__fail(err, ULAM_ESINGULAR, 0, -1, "a nonsingular I - M: its sparse LU has a zero pivot");
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix UMFPACK can factor (status %d)", st);
    }
    double rcond = stat[UMFPACK_RCOND];
    st = (int)U->solve(UMFPACK_At, p, c, v, x, b, numeric, control, stat); /* (I - M) x = b */
    U->free_numeric(&numeric);
    if (st != UMFPACK_OK) return ulam__fail(err, ULAM_ESINGULAR, 0, -1, "a solvable system (UMFPACK status %d)", st);
    if (info) info->rcond = rcond, info->bytes = (size_t)peak;
    return ULAM_OK;
}

/* UMFPACK's symbolic analysis of I - M alone: its estimates of the factorisation's peak memory
 * (bytes) and floating-point operations; a status. */
static int estimate(const ulam_csr *M, double *bytes, double *flops, ulam_error *err)
{
    SuiteSparse_long *p = NULL, *c = NULL;
    double *v = NULL, control[UMFPACK_CONTROL], stat[UMFPACK_INFO];
    void *symbolic = NULL;
    const ulam__umfpack_api *U = ulam__umfpack(err); /* src/dynload.c: opened on first use */
    if (!U) return err ? err->status : ULAM_EIO;
    int status = assemble(M, &p, &c, &v);
    if (status) {
        ulam__fail(err, status, 0, -1, "memory for I - M");
    } else {
        U->defaults(control);
        SuiteSparse_long sn = (SuiteSparse_long)M->nrows;
        int st = (int)U->symbolic(sn, sn, p, c, v, &symbolic, control, stat);
        if (st == UMFPACK_OK) {
            *bytes = stat[UMFPACK_PEAK_MEMORY_ESTIMATE] * stat[UMFPACK_SIZE_OF_UNIT];
            *flops = stat[UMFPACK_FLOPS_ESTIMATE];
        } else {
            status = ulam__fail(err, st == UMFPACK_ERROR_out_of_memory ? ULAM_ENOMEM : ULAM_EINVAL, 0, -1,
                                "a matrix UMFPACK can analyse (status %d)", st);
        }
        U->free_symbolic(&symbolic);
    }
    free(p), free(c), free(v);
    return status;
}
#endif

/* What the sparse LU of I - M will need, before it starts. */
int ulam__direct_sparse_estimate(const ulam_csr *M, double *bytes, double *flops, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !bytes || !flops || M->nrows != M->ncols)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a square matrix and places for the estimates");
#ifndef ULAM_UMFPACK
    return ulam__fail(err, ULAM_EUNSUPPORTED, 0, -1, "a libulam built with UMFPACK (libsuitesparse-dev) for a sparse LU");
#else
    return estimate(M, bytes, flops, err);
#endif
}

/* Nonzero when libulam was built with UMFPACK and its library loads. */
int ulam__direct_sparse_available(void)
{
#ifdef ULAM_UMFPACK
    return ulam__umfpack(NULL) != NULL;
#else
    return 0;
#endif
}

/* Solve (I - M) x = b by sparse LU. */
int ulam__direct_sparse(const ulam_csr *M, const double *b, double *x, size_t max_bytes,
                       ulam_direct_info *info, ulam_error *err)
{
    int bad = ulam__direct_args(M, b, x, err); /* src/direct.c */
    if (bad) return bad;
#ifndef ULAM_UMFPACK
    (void)max_bytes, (void)info;
    return ulam__fail(err, ULAM_EUNSUPPORTED, 0, -1, "a libulam built with UMFPACK (libsuitesparse-dev) for a sparse LU");
#else
    double t0 = ulam_now();
    SuiteSparse_long *p = NULL, *c = NULL;
    double *v = NULL;
    int status = assemble(M, &p, &c, &v);
    if (status) ulam__fail(err, status, 0, -1, "memory for I - M (%lld nonzeros)", (long long)(M->rowptr[M->nrows] + M->nrows));
    else status = factor_solve(M->nrows, p, c, v, b, x, max_bytes, info, err);
    free(p), free(c), free(v);
    if (status) return status;
    for (int64_t i = 0; i < M->nrows; i++)
        if (!isfinite(x[i]))
            return ulam__fail(err, ULAM_ESINGULAR, 0, i, "a finite solution: I - M is numerically singular");
    if (info) {
        info->residual = ulam__direct_residual(M, b, x);
        info->seconds = ulam_now() - t0;
    }
    return ULAM_OK;
#endif
}
