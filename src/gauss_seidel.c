/* Gauss-Seidel sweeps on x = M x + b: the outer iterations' Gauss-Seidel row (mcsa.c) and the
 * exact value a study scores against (study.c) both sweep here. */
#include "ulam.h"

#include <math.h>

/* One Gauss-Seidel sweep on x = M x + b. */
void ulam__gauss_seidel_sweep(const ulam_csr *M, const double *b, double *x)
{
    for (int64_t i = 0; i < M->nrows; i++) {
        double s = b[i];
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += M->val[q] * x[M->colidx[q]];
        x[i] = s;
    }
}

/* Gauss-Seidel sweeps on x until x_index settles; the sweeps made. */
int ulam__gauss_seidel_settle(const ulam_csr *M, const double *b, double *x, int64_t index, double rel_tol,
                             int min_sweeps, int max_sweeps)
{
    int k = 0;
    while (k < max_sweeps) {
        double old = x[index];
        ulam__gauss_seidel_sweep(M, b, x);
        k++;
        if (k >= min_sweeps && fabs(x[index] - old) <= rel_tol * fabs(x[index])) break;
    }
    return k;
}
