/* Forward push by whole sweeps (SpeedPPR's PowForPush: Wu, Gan, Wei, Wen, Xiao, "Unifying the
 * global and local approaches: an efficient power iteration with forward push", SIGMOD 2021).
 *
 * x = (I - M)^-1 e_s kept as x = p + (I - M)^-1 r.  Pushing state j moves r_j into p_j and adds
 * M_kj r_j to r_k for every k (row j of M'): the invariant is unchanged.  While few states hold
 * residual, the pushes go round a list of them (each round pushes the list as it stood, the
 * states it wakes join the next round); once the list holds n / 16 states, every round is a
 * sweep over the states in order, pushing each nonzero residual where it lies (Gauss-Seidel
 * order: a residual a sweep adds ahead of itself is pushed in the same sweep), which reads M' in
 * storage order instead of chasing a queue.  Rounds go on while the walks' work the residual
 * would leave falls by more than a round costs (the caller's cost model, push operations). */
#include "internal.h"

#include <math.h>
#include <stdlib.h>

/* Push state j; the operations it took. */
static int64_t push_one(const ulam_csr *Mt, int64_t j, double *p, double *r, int32_t *next, int64_t *nnext,
                        unsigned char *mark)
{
    double rj = r[j];
    p[j] += rj;
    r[j] = 0.0;
    int64_t a = Mt->rowptr[j], b = Mt->rowptr[j + 1];
    for (int64_t k = a; k < b; k++) {
        int64_t c = Mt->colidx[k];
        r[c] += Mt->val[k] * rj;
        if (next && !mark[c]) mark[c] = 1, next[(*nnext)++] = (int32_t)c;
    }
    return b - a + 1;
}

/* Forward push from s on M (given as its transpose Mt) into p and r (n entries, zero). */
int ulam__sweep_push(const ulam_csr *Mt, int64_t s, double rmax, ulam__sweep_cost cost, void *ctx, int64_t max_ops,
                     double *p, double *r, ulam__sweep_info *info)
{
    int64_t n = Mt->nrows, nnz = ulam_csr_nnz(Mt);
    *info = (ulam__sweep_info){0};
    int32_t *list = ulam__malloc((size_t)n, sizeof *list), *next = ulam__malloc((size_t)n, sizeof *next);
    unsigned char *mark = ulam__calloc((size_t)n, 1);
    if (!list || !next || !mark) {
        free(list), free(next), free(mark);
        return ULAM_ENOMEM;
    }
    double thr = rmax > 0 ? rmax : 0.0; /* push |r_j| > thr */
    r[s] = 1.0;
    list[0] = (int32_t)s;
    int64_t nlist = 1, ops = 0;
    double rsum = 1.0;
    int status = ULAM_OK, sweeping = 0;
    for (;;) {
        int64_t round_ops = 0, pushed = 0;
        if (!sweeping) {
            int64_t nnext = 0;
            for (int64_t q = 0; q < nlist; q++) mark[list[q]] = 0;
            for (int64_t q = 0; q < nlist; q++) {
                int64_t j = list[q];
                if (!(fabs(r[j]) > thr)) continue;
                round_ops += push_one(Mt, j, p, r, next, &nnext, mark), pushed++;
            }
            for (int64_t q = 0; q < nlist; q++) /* states left under the threshold stay listed */
                if (r[list[q]] != 0.0 && !mark[list[q]]) mark[list[q]] = 1, next[nnext++] = list[q];
            int32_t *t = list;
            list = next, next = t, nlist = nnext;
        } else {
            for (int64_t j = 0; j < n; j++)
                if (fabs(r[j]) > thr) round_ops += push_one(Mt, j, p, r, NULL, NULL, NULL), pushed++;
            round_ops += n;
            info->sweeps++;
        }
        info->rounds++;
        info->pushes += pushed;
        ops += round_ops;
        double before = rsum;
        rsum = 0.0;
        if (sweeping) {
            int64_t active = 0;
            for (int64_t j = 0; j < n; j++) rsum += fabs(r[j]), active += r[j] != 0.0;
            ops += n;
            if (active < n / 16) { /* few states hold residual again: back to the list */
                nlist = 0;
                for (int64_t j = 0; j < n; j++)
                    if (r[j] != 0.0) mark[j] = 1, list[nlist++] = (int32_t)j;
                sweeping = 0;
            }
        } else {
            for (int64_t q = 0; q < nlist; q++) rsum += fabs(r[list[q]]);
            if (nlist >= n / 16) sweeping = 1;
        }
        if (pushed == 0 || rsum == 0.0) break;
        if (max_ops > 0 && ops > max_ops) {
            status = ULAM_ENOCONV;
            break;
        }
        if (!cost) continue; /* rmax alone decides */
        /* one more round like this one takes the residual from rsum to rsum^2 / before */
        double rho = before > 0 ? rsum / before : 1.0, next_ops = sweeping ? (double)(nnz + 2 * n) : (double)round_ops;
        if (!(cost(rsum, ctx) - cost(rho * rsum, ctx) > next_ops)) break;
    }
    info->ops = ops;
    info->r_sum = rsum;
    for (int64_t j = 0; j < n; j++) info->support += r[j] != 0.0;
    free(list), free(next), free(mark);
    return status;
}
