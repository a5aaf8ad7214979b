/* The reference solve (include/ulam_reference.h): sparse or dense LU, GMRES past the memory
 * limit. */
#include "ulam_reference.h"
#include "direct.h"

#include <math.h>

/* Whether the reference solve of M is the sparse LU. */
static int reference_sparse(const ulam_csr *M, int lu)
{
    if (lu >= 0 || !M) return lu > 0;
    int64_t n = M->nrows;
    return ulam__direct_sparse_available() && n > 1000 && (double)M->rowptr[n] < 0.05 * (double)n * (double)n;
}

/* What the reference solve of M will be and need, before it starts. */
int ulam_reference_plan(const ulam_csr *M, int lu, int estimate, ulam_reference_info *p, ulam_error *err)
{
    ulam__clear(err);
    if (!p) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a place for the plan");
    *p = (ulam_reference_info){.sparse = reference_sparse(M, lu), .umfpack = ulam__direct_sparse_available(),
                               .bytes = NAN, .flops = NAN};
    if (!M) return ULAM_OK;
    double n = (double)M->nrows;
    if (!p->sparse) {
        size_t bytes = ulam_direct_bytes(M->nrows);
        p->bytes = bytes ? (double)bytes : INFINITY, p->flops = 2.0 / 3.0 * n * n * n;
        return ULAM_OK;
    }
    return estimate ? ulam__direct_sparse_estimate(M, &p->bytes, &p->flops, err) : ULAM_OK;
}

/* Solve (I - M) x = b for reference. */
int ulam_reference_solve(const ulam_csr *M, const double *b, int lu, size_t max_bytes, int gmres, double *x,
                         ulam_direct_info *info, const char **how, ulam_error *err)
{
    if (!M || !b || !x || !info || !err) {
        if (err) *err = (ulam_error){.status = ULAM_EINVAL, .index = -1, .msg = "a matrix, b, x and info"};
        return ULAM_EINVAL;
    }
    int sparse = reference_sparse(M, lu), it;
    if (how) *how = sparse ? "sparse LU" : "dense LU";
    int status = sparse ? ulam__direct_sparse(M, b, x, max_bytes, info, err) : ulam_direct_solve(M, b, x, max_bytes, info, err);
    if (status != ULAM_EMEMLIMIT || !gmres) return status;
    double t0 = ulam_now();
    if (how) *how = "GMRES";
    status = ulam_gmres(M, b, 50, 1e-12, 10000000, x, &it, &info->residual);
    info->seconds = ulam_now() - t0;
    if (status) *err = (ulam_error){.status = status, .index = -1, .msg = "GMRES to converge (the LU would pass the memory limit)"};
    return status;
}
