/* Random test systems shared by the example programs (public API only, fixed seeds). */
#ifndef ULAM_EXAMPLES_SYSTEMS_H
#define ULAM_EXAMPLES_SYSTEMS_H

#include <stdlib.h>

#include "ulam.h"

/* Build an n x n CSR matrix from triplets and free the triplet arrays. */
static inline ulam_csr *build(int64_t n, int64_t nz, int32_t *ti, int32_t *tj, double *tx)
{
    ulam_csr *M = NULL;
    ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M);
    free(ti);
    free(tj);
    free(tx);
    return M;
}

/* A random matrix with k distinct random columns per row; row i's |values| sum to rowsum;
 * signed != 0 gives each entry a random sign. */
static inline ulam_csr *random_sparse(int64_t n, int k, double rowsum, int signed_, uint64_t seed)
{
    int64_t nz = n * k;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    ulam_rng r;
    ulam_rng_seed(&r, seed, 0);
    for (int64_t i = 0; i < n; i++) {
        double sum = 0;
        int64_t base = i * k;
        for (int m = 0; m < k; m++) {
            int32_t j;
            int fresh;
            do { /* distinct columns within the row */
                j = (int32_t)ulam_rng_bounded(&r, (uint64_t)n);
                fresh = 1;
                for (int q = 0; q < m; q++) fresh &= tj[base + q] != j;
            } while (!fresh && k < n);
            ti[base + m] = (int32_t)i;
            tj[base + m] = j;
            tx[base + m] = 0.1 + ulam_rng_uniform(&r);
            sum += tx[base + m];
        }
        for (int m = 0; m < k; m++) {
            tx[base + m] *= rowsum / sum;
            if (signed_ && ulam_rng_uniform(&r) < 0.5) tx[base + m] = -tx[base + m];
        }
    }
    return build(n, nz, ti, tj, tx);
}

/* A doubly substochastic M = sum_k w_k P_k over k random permutations P_k, weights w_k > 0
 * summing to s: every row and every column sums to s, so adjoint and forward analog walks
 * both keep weight 1 (coinciding entries are summed). */
static inline ulam_csr *random_doubly(int64_t n, int k, double s, uint64_t seed)
{
    int64_t nz = n * k;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx), sum = 0, *w = malloc((size_t)k * sizeof *w);
    int32_t *perm = malloc((size_t)n * sizeof *perm);
    ulam_rng r;
    ulam_rng_seed(&r, seed, 3);
    for (int q = 0; q < k; q++) sum += w[q] = 0.2 + ulam_rng_uniform(&r);
    for (int q = 0; q < k; q++) {
        for (int64_t i = 0; i < n; i++) perm[i] = (int32_t)i;
        for (int64_t i = n - 1; i > 0; i--) { /* Fisher-Yates */
            int64_t j = (int64_t)ulam_rng_bounded(&r, (uint64_t)i + 1);
            int32_t t = perm[i];
            perm[i] = perm[j], perm[j] = t;
        }
        for (int64_t i = 0; i < n; i++)
            ti[q * n + i] = (int32_t)i, tj[q * n + i] = perm[i], tx[q * n + i] = s * w[q] / sum;
    }
    free(w), free(perm);
    return build(n, nz, ti, tj, tx);
}

/* A vector of n uniform values in [lo, hi). */
static inline double *random_vector(int64_t n, double lo, double hi, uint64_t seed)
{
    double *b = malloc((size_t)n * sizeof *b);
    ulam_rng r;
    ulam_rng_seed(&r, seed, 1);
    for (int64_t i = 0; i < n; i++) b[i] = lo + (hi - lo) * ulam_rng_uniform(&r);
    return b;
}

/* A copy of A with every value times s. */
static inline ulam_csr *scaled_copy(const ulam_csr *A, double s)
{
    ulam_csr *M = ulam_csr_alloc(A->nrows, A->ncols, ulam_csr_nnz(A));
    if (!M) return NULL;
    for (int64_t i = 0; i <= A->nrows; i++) M->rowptr[i] = A->rowptr[i];
    for (int64_t q = 0; q < ulam_csr_nnz(A); q++) M->colidx[q] = A->colidx[q], M->val[q] = s * A->val[q];
    return M;
}

/* A radiosity-like dense M = diag(rho) F: n patches on a circle's two arcs, F_ij proportional to
 * 1 / (1 + d_ij^2) with unit row sums, reflectances in [0.3, 0.8] (genmat --radiosity; the study's
 * and bench_auto's dense system). */
static inline ulam_csr *radiosity_like(int64_t n, uint64_t seed)
{
    int64_t nz = n * (n - 1), k = 0;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    ulam_rng r;
    ulam_rng_seed(&r, seed, 2);
    for (int64_t i = 0; i < n; i++) {
        double rho = 0.3 + 0.5 * ulam_rng_uniform(&r), sum = 0;
        int64_t base = k;
        for (int64_t j = 0; j < n; j++) {
            if (j == i) continue;
            double d = (double)(i - j) / (double)n * 8.0;
            ti[k] = (int32_t)i, tj[k] = (int32_t)j, tx[k] = 1.0 / (1.0 + d * d);
            sum += tx[k++];
        }
        for (int64_t q = base; q < k; q++) tx[q] *= rho / sum;
    }
    return build(n, k, ti, tj, tx);
}

/* Emission: a few bright patches, the rest dark. */
static inline double *emitters(int64_t n)
{
    double *b = calloc((size_t)n, sizeof *b);
    for (int64_t i = 0; i < n; i += n / 5) b[i] = 10.0;
    return b;
}

#endif
