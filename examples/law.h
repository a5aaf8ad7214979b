/* The collision-absorption law of the lecture notes (README: "The collision-absorption law"),
 * for examples/law.c and its test in tests/test_walk.c: the exact variances of a forward analog
 * walk's two estimators at its start state, and the no-return probability s by a linear solve. */
#ifndef ULAM_EXAMPLES_LAW_H
#define ULAM_EXAMPLES_LAW_H

#include <math.h>
#include <stdlib.h>

#include "ulam.h"

/* For a forward analog walk started at state j and counting particles at j, with termination
 * probability p*_j = pstar and no-return probability s: visits are geometric, so
 * Var(collision) = (1 - s) / s^2 and Var(absorption) = 1 / (p* s) - 1 / s^2 (collision is no
 * worse iff p* <= s / (2 - s)).  Writes the two variances. */
static inline void law_variances(double pstar, double s, double *var_collision, double *var_absorption)
{
    *var_collision = (1 - s) / (s * s);
    *var_absorption = pstar > 0 ? 1 / (pstar * s) - 1 / (s * s) : INFINITY;
}

/* The analog continuation of a state whose row of |K| sums to S (ulam_walk_opts.continue_q <= 0). */
static inline double law_continuation(double S)
{
    return S == 0.0 ? 0.0 : S < 1.0 ? S : 1.0;
}

/* The forward kernel's transition matrix P (P_jk = q_j |M_kj| / S_j) with row j and column j
 * zeroed into *Q, its column j in c, row j in pj; the row sum S_j in *Sj.  A library status. */
static inline int law_kernel_without(const ulam_csr *M, int64_t j, ulam_csr **Q, double *c, double *pj, double *Sj)
{
    ulam_csr *K = NULL;
    int status = ulam_csr_transpose(M, &K);
    if (status) return status;
    for (int64_t i = 0; i < K->nrows; i++) {
        double S = 0;
        for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) S += fabs(K->val[q]);
        double qi = law_continuation(S);
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

/* The no-return probability *s of state j of the forward kernel of M (walks on the rows of M',
 * analog q): 1 - sum_k P_jk h_k with h the hitting probabilities of j (a linear solve); its
 * termination probability in *pstar.  ULAM_OK, ULAM_EINVAL, ULAM_ENOMEM or ULAM_ESINGULAR. */
static inline int law_noreturn(const ulam_csr *M, int64_t j, double *s, double *pstar)
{
    if (!M || !s || !pstar || M->nrows != M->ncols || j < 0 || j >= M->nrows) return ULAM_EINVAL;
    int64_t n = M->nrows;
    double *c = calloc((size_t)n, sizeof *c), *pj = calloc((size_t)n, sizeof *pj);
    double *h = malloc((size_t)n * sizeof *h), Sj = 0;
    ulam_csr *Q = NULL;
    int status = c && pj && h ? law_kernel_without(M, j, &Q, c, pj, &Sj) : ULAM_ENOMEM;
    if (!status) status = ulam_direct_solve(Q, c, h, 0, NULL, NULL);
    if (!status) {
        double back = 0;
        for (int64_t k = 0; k < n; k++) back += pj[k] * (k == j ? 1.0 : h[k]);
        *s = 1 - back;
        *pstar = 1 - law_continuation(Sj);
    }
    ulam_csr_free(Q);
    free(c), free(pj), free(h);
    return status;
}

#endif
