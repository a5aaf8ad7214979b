/* Pieces of variance studies: the Gauss-Seidel reference, cell summaries, and the
 * collision-absorption law of the lecture notes with its exact variances. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>

/* One Gauss-Seidel sweep on x = M x + b. */
void ulam_gauss_seidel_sweep(const ulam_csr *M, const double *b, double *x)
{
    for (int64_t i = 0; i < M->nrows; i++) {
        double s = b[i];
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += M->val[q] * x[M->colidx[q]];
        x[i] = s;
    }
}

/* Gauss-Seidel sweeps on x until x_index settles; the sweeps made. */
int ulam_gauss_seidel_settle(const ulam_csr *M, const double *b, double *x, int64_t index, double rel_tol,
                             int min_sweeps, int max_sweeps)
{
    int k = 0;
    while (k < max_sweeps) {
        double old = x[index];
        ulam_gauss_seidel_sweep(M, b, x);
        k++;
        if (k >= min_sweeps && fabs(x[index] - old) <= rel_tol * fabs(x[index])) break;
    }
    return k;
}

/* Summarise n runs against the exact value. */
void ulam_cell_summary(int n, const double *estimate, const double *std_error, const double *seconds,
                       double exact, ulam_cell *out)
{
    double se2 = 0, se = 0, t = 0;
    int covered = 0;
    for (int k = 0; k < n; k++) {
        double e = estimate[k] - exact;
        se2 += e * e, se += std_error[k], t += seconds[k];
        covered += fabs(e) <= ULAM_Z95 * std_error[k];
    }
    double N = n > 0 ? n : 1;
    *out = (ulam_cell){.runs = n, .rmse = sqrt(se2 / N), .mean_stderr = se / N, .coverage = covered / N,
                       .seconds = t / N};
    out->honesty = out->mean_stderr > 0 ? out->rmse / out->mean_stderr : INFINITY;
    out->work = out->rmse * out->rmse * out->seconds;
}

/* Exact variances of the two forward estimators at the start state (h = 1). */
void ulam_law_variances(double pstar, double s, double *var_collision, double *var_absorption)
{
    *var_collision = (1 - s) / (s * s);
    *var_absorption = pstar > 0 ? 1 / (pstar * s) - 1 / (s * s) : INFINITY;
}

/* The forward kernel's transition matrix P (P_jk = q_j |M_kj| / S_j) with row j zeroed, and
 * its column j in c; the row sum S_j in *Sj. */
static int kernel_without(const ulam_csr *M, int64_t j, ulam_csr **Q, double *c, double *pj, double *Sj)
{
    ulam_csr *K = NULL;
    int status = ulam_csr_transpose(M, &K);
    if (status) return status;
    for (int64_t i = 0; i < K->nrows; i++) {
        double S = 0;
        for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) S += fabs(K->val[q]);
        double qi = ulam__continuation(S, 0.0);
        if (i == j) *Sj = S;
        c[i] = 0;
        for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) {
            double p = S > 0 ? qi * fabs(K->val[q]) / S : 0.0;
            if (i == j) pj[K->colidx[q]] += p;
            if (i == j || K->colidx[q] == j) {
                if (i != j) c[i] += p;
                p = 0.0;
            }
            K->val[q] = p;
        }
    }
    *Q = K;
    return ULAM_OK;
}

/* s = 1 - sum_k P_jk h_k, h the probabilities of hitting j (h_j = 1). */
int ulam_law_noreturn(const ulam_csr *M, int64_t j, double *s, double *pstar, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !s || !pstar || M->nrows != M->ncols || j < 0 || j >= M->nrows)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a square matrix and a state in range");
    int64_t n = M->nrows;
    double *c = ulam__calloc((size_t)n, sizeof *c), *pj = ulam__calloc((size_t)n, sizeof *pj);
    double *h = ulam__malloc((size_t)n, sizeof *h), Sj = 0;
    ulam_csr *Q = NULL;
    int status = c && pj && h ? kernel_without(M, j, &Q, c, pj, &Sj) : ULAM_ENOMEM;
    if (!status) status = ulam_direct_solve(Q, c, h, 0, NULL, err);
    if (!status) {
        double back = 0;
        for (int64_t k = 0; k < n; k++) back += pj[k] * (k == j ? 1.0 : h[k]);
        *s = 1 - back;
        *pstar = 1 - ulam__continuation(Sj, 0.0);
    }
    ulam_csr_free(Q);
    free(c), free(pj), free(h);
    return status ? ulam__fail(err, status, 0, j, "a chain whose hitting probabilities are defined") : ULAM_OK;
}
