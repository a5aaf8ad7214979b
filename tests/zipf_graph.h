/* A heavy-tailed digraph (issue 25 case 3, issue 29 point 3): n states, state i has out-degree
 * 1 + Zipf(a) (P(d = k) ~ k^-a, k >= 1, capped at n - 1), each edge's head drawn with weight
 * (rank + 1)^-beta over a random ranking of the states (a few states collect most in-links).
 * P is the row-stochastic walk (1 / d_i an edge, duplicate edges summed) and M = c P' (so the
 * walks of the bidirectional estimator, on M' = c P, follow out-edges; x = (I - M)^-1 e_s is
 * personalized PageRank / (1 - c)).  Header-only, shared by tests and benchmarks. */
#ifndef ULAM_ZIPF_GRAPH_H
#define ULAM_ZIPF_GRAPH_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "ulam.h"

/* Index of the first cumulative weight > u * total (cum increasing, m entries). */
static inline int64_t zipf_graph_search(const double *cum, int64_t m, double u)
{
    double v = u * cum[m - 1];
    int64_t lo = 0, hi = m - 1;
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (cum[mid] > v) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

/* M = c P' of the graph above (NULL when out of memory); seed picks it. */
static inline ulam_csr *zipf_graph(int64_t n, double a, double beta, double c, uint64_t seed)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 29);
    int64_t kmax = n - 1 < 100000 ? n - 1 : 100000;
    double *deg = malloc((size_t)kmax * sizeof *deg), *head = malloc((size_t)n * sizeof *head);
    int64_t *perm = malloc((size_t)n * sizeof *perm), *d = malloc((size_t)n * sizeof *d), nz = 0;
    ulam_csr *M = NULL;
    if (!deg || !head || !perm || !d) goto done;
    for (int64_t k = 0; k < kmax; k++) deg[k] = (k ? deg[k - 1] : 0) + pow((double)(k + 1), -a);
    for (int64_t k = 0; k < n; k++) head[k] = (k ? head[k - 1] : 0) + pow((double)(k + 1), -beta), perm[k] = k;
    for (int64_t k = n - 1; k > 0; k--) { /* the ranking: a random permutation */
        int64_t j = (int64_t)ulam_rng_bounded(&r, (uint64_t)(k + 1)), t = perm[k];
        perm[k] = perm[j], perm[j] = t;
    }
    for (int64_t i = 0; i < n; i++) nz += d[i] = 2 + zipf_graph_search(deg, kmax, ulam_rng_uniform(&r)); /* 1 + Zipf(a), Zipf >= 1 */
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    if (ti && tj && tx) {
        int64_t e = 0;
        for (int64_t i = 0; i < n; i++)
            for (int64_t q = 0; q < d[i]; q++, e++) {
                int64_t j;
                do j = perm[zipf_graph_search(head, n, ulam_rng_uniform(&r))];
                while (j == i);
                ti[e] = (int32_t)j, tj[e] = (int32_t)i, tx[e] = c / (double)d[i]; /* M_ji = c P_ij */
            }
        if (ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M)) M = NULL;
    }
    free(ti), free(tj), free(tx);
done:
    free(deg), free(head), free(perm), free(d);
    return M;
}

/* x = (I - M)^-1 e_s by the iteration x <- e_s + M x to a change below 1e-15 ||x||_1 (rho(M) = c:
 * about 200 products at c = 0.85); a new array. */
static inline double *zipf_graph_column(const ulam_csr *M, int64_t s)
{
    int64_t n = M->nrows;
    double *x = calloc((size_t)n, sizeof *x), *y = malloc((size_t)n * sizeof *y);
    for (int it = 0; x && y && it < 10000; it++) {
        ulam_csr_matvec(M, 0, x, y);
        y[s] += 1.0;
        double dif = 0, tot = 0;
        for (int64_t i = 0; i < n; i++) dif += fabs(y[i] - x[i]), tot += fabs(y[i]), x[i] = y[i];
        if (dif <= 1e-15 * tot) break;
    }
    free(y);
    return x;
}

#endif
