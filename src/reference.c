/* The reference solve (include/ulam_reference.h): sparse or dense LU, GMRES past the memory
 * limit. */
#include "ulam_reference.h"

/* Whether the reference solve of M is the sparse LU. */
int ulam_reference_sparse(const ulam_csr *M, int lu)
{
    if (lu >= 0 || !M) return lu > 0;
    int64_t n = M->nrows;
    return ulam_direct_sparse_available() && n > 1000 && (double)M->rowptr[n] < 0.05 * (double)n * (double)n;
}

/* Solve (I - M) x = b for reference. */
int ulam_reference_solve(const ulam_csr *M, const double *b, int lu, size_t max_bytes, int gmres, double *x,
                         ulam_direct_info *info, const char **how, ulam_error *err)
{
    if (!M || !b || !x || !info || !err) {
        if (err) *err = (ulam_error){.status = ULAM_EINVAL, .index = -1, .msg = "a matrix, b, x and info"};
        return ULAM_EINVAL;
    }
    int sparse = ulam_reference_sparse(M, lu), it;
    if (how) *how = sparse ? "sparse LU" : "dense LU";
    int status = sparse ? ulam_direct_sparse(M, b, x, max_bytes, info, err) : ulam_direct_solve(M, b, x, max_bytes, info, err);
    if (status != ULAM_EMEMLIMIT || !gmres) return status;
    double t0 = ulam_now();
    if (how) *how = "GMRES";
    status = ulam_gmres(M, b, 50, 1e-12, 10000000, x, &it, &info->residual);
    info->seconds = ulam_now() - t0;
    if (status) *err = (ulam_error){.status = status, .index = -1, .msg = "GMRES to converge (the LU would pass the memory limit)"};
    return status;
}
