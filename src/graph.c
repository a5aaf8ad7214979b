/* Systems as graph users hold them: PageRank's (I - alpha P^T) x = (1 - alpha) / n from an
 * adjacency matrix, P = D^-1 A the random surfer's row-stochastic transition matrix. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>

/* M = alpha P^T for the adjacency matrix A (A_ij >= 0: an edge i -> j of that weight); a row of
 * no out-edges (dangling) stays zero: its surfer leaves the graph, and x is PageRank up to the
 * dangling mass.  ULAM_OK, or a status with err filled. */
int ulam_pagerank_matrix(const ulam_csr *A, double alpha, ulam_csr **M, ulam_error *err)
{
    ulam__clear(err);
    if (!A || !M || !(alpha > 0.0 && alpha < 1.0))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "an adjacency matrix and a damping alpha in (0, 1)");
    *M = NULL;
    if (A->nrows != A->ncols)
        return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square adjacency matrix, got %lld x %lld",
                          (long long)A->nrows, (long long)A->ncols);
    int64_t n = A->nrows;
    ulam_csr *P = ulam_csr_alloc(n, n, A->rowptr[n]);
    if (!P) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the transition matrix");
    for (int64_t i = 0; i <= n; i++) P->rowptr[i] = A->rowptr[i];
    for (int64_t i = 0; i < n; i++) {
        double out = 0.0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) {
            if (!(A->val[k] >= 0.0)) {
                ulam_csr_free(P);
                return ulam__fail(err, ULAM_EINVAL, 0, i, "edge weights >= 0 in an adjacency matrix (row %lld)",
                                  (long long)i + 1);
            }
            out += A->val[k];
        }
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            P->colidx[k] = A->colidx[k], P->val[k] = out > 0.0 ? alpha * A->val[k] / out : 0.0;
    }
    int status = ulam_csr_transpose(P, M);
    ulam_csr_free(P);
    if (status) return ulam__fail(err, status, 0, -1, "memory for the transposed transition matrix");
    return ULAM_OK;
}
