/* Single source by a dense LU, for a small system whose push would be long: with ||M||_1 = alpha
 * near 1 the forward push's residual falls by about a factor e per 1 / (1 - alpha) sweeps and a
 * terminal walk takes 1 / (1 - alpha) steps (PageRank at alpha = 1 - 1e-7 on 7 nodes: 10^7 steps
 * a walk), while the LU's n^3 / 3 operations do not depend on alpha.
 *
 * Certified as the push is: p from the LU, the residual r = e_s - (I - M) p formed in floating
 * point with each entry's rounding bounded (src/bound.c's ulam__residual), so x = p + (I - M)^-1 r exactly and every
 * |x_i - p_i| <= ||r||_1 / (1 - ||M||_1), no walk needed. */
#include "fpush_dense.h"
#include "bound.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#define ULAM__FPUSH_DENSE_MAX 2048 /* states at most (a 32 MiB dense matrix, ~3e9 operations) */
#define ULAM__FPUSH_DENSE_SHARE 16 /* the LU when it costs at most this share of one e-fold of the push: where the
                                      push is quick (7 nodes at alpha 0.85: ~700 operations, well under 1 ms) it and
                                      its walks keep the system; 1 - alpha = 1e-7 takes 10^7 sweeps an e-fold */

/* See src/fpush.h. */
int ulam__fpush_dense_pays(int64_t n, int64_t nnz, double alpha)
{
    if (n > ULAM__FPUSH_DENSE_MAX || !(alpha < 1.0)) return 0;
    double lu = (double)n * (double)n * (double)n / 3.0 + 2.0 * (double)nnz; /* the LU, the residual */
    return lu * ULAM__FPUSH_DENSE_SHARE < ((double)nnz + 2.0 * (double)n) / (1.0 - alpha); /* an e-fold's sweeps */
}

/* See src/fpush.h. */
int ulam__fpush_dense(const ulam_csr *M, int64_t s, double alpha, double *x, double *r_sum, double *bound,
                      ulam_error *err)
{
    int64_t n = M->nrows;
    double *b = ulam__calloc((size_t)n, sizeof *b);
    if (!b) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the dense solve");
    b[s] = 1.0;
    int status = ulam_direct_solve(M, b, x, 0, NULL, err);
    double sum = 0.0, round = 0.0, *r = status ? NULL : ulam__malloc((size_t)n + 1, sizeof *r),
           *e = status ? NULL : ulam__malloc((size_t)n + 1, sizeof *e);
    if (!status && (!r || !e)) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the dense solve's residual");
    if (!status && ulam__residual(M, b, x, r, e) < 0) status = ulam__fail(err, ULAM_ENONFINITE, 0, -1, "a finite dense solve");
    for (int64_t i = 0; !status && i < n; i++) sum += fabs(r[i]), round += e[i];
    free(b), free(r), free(e);
    if (status) return status;
    double sums = 1.0 + ulam__push_rounding(2.0 * (double)n + 4.0, 1.0); /* the two sums' and the quotient's roundings */
    *r_sum = sum;
    *bound = (sum + round) * sums / (1.0 - alpha);
    if (!isfinite(*bound)) return ulam__fail(err, ULAM_ENONFINITE, 0, -1, "a finite dense solve");
    return ULAM_OK;
}
