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
 * would leave falls by more than a round costs (the caller's cost model, push operations).
 *
 * Given M itself (its rows: each state's in-neighbours) and M >= 0, a sweep pulls instead of
 * pushing: p_i <- e_s,i + sum_j M_ij p_j for i in order, the same Gauss-Seidel sweep (p_i + r_i,
 * r_i = e_s,i + (M p)_i - p_i being the residual the push would move) read like a sparse
 * matrix-vector product, with no scattered writes.  When the caller's cost model decides (no
 * rmax), the pull sweeps are over-relaxed (SOR: p_i moves ULAM__SWEEP_OMEGA times its residual,
 * which contracts faster but may overshoot, leaving r_i < 0), and once the model would stop,
 * ULAM__SWEEP_SETTLE plain sweeps follow, after which r >= 0 on some graphs but for roundings
 * (R-MAT), not on others; r is left signed, its negative mass reported (r_neg).  r is not kept during pull sweeps (its storage
 * holds c_i = sum_k M_ki unless the caller gives room for them, to keep for its walks): its sum is, as 1 - sum_i p_i (1 - c_i) (r >= 0 when M >= 0), and r
 * itself is formed once at the end (one more product), negative roundings of a zero residual
 * included (at most 1e-16 of (M p)_i). */
#include "sweep.h"

#define ULAM__SWEEP_OMEGA 1.2 /* over-relaxation of the pull sweeps (R-MAT 2^20, M = 0.85 P': ||r||_1 1.8e-3 after 12
                                 sweeps at 1.2, 2.5e-3 after 18 at 1; the contraction 0.57 a sweep against 0.705) */
#define ULAM__SWEEP_SETTLE 2  /* plain sweeps after the over-relaxed ones (the negative residual an overshoot leaves:
                                 4.5e-4 at 1.2 after 10 sweeps, 1.9e-9 after one plain sweep, ~1e-17 after two) */

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

/* One push sweep over the states in order: push every |r_j| > thr (a residual a push adds ahead
 * of the sweep is pushed in the same sweep); the operations (n, and each push's row entries + 1),
 * the pushes in *pushed. */
static int64_t sweep_once(const ulam_csr *Mt, double thr, double *p, double *r, int64_t *pushed,
                          const ulam__sweep_release *rel)
{
    int64_t n = Mt->nrows, ops = n, k = 0;
    for (int64_t j = 0; j < n; j++) {
        if (fabs(r[j]) > thr) ops += push_one(Mt, j, p, r, NULL, NULL, NULL), k++;
        ulam__sweep_done(rel, Mt, j, n);
    }
    *pushed = k;
    return ops;
}
int64_t ulam__sweep_once(const ulam_csr *Mt, double thr, double *p, double *r, int64_t *pushed)
{
    return sweep_once(Mt, thr, p, r, pushed, NULL);
}

/* The pull sweeps' view of M: M and its column sums c (rows of Mt; kept in r's storage, which
 * the pull sweeps do not use). */
typedef struct {
    const ulam_csr *M;
    double *c;
    const ulam__sweep_release *rel; /* the hook each pass over M calls (NULL: none) */
} pull;

/* (M p)_i. */
static inline double pull_row(const ulam_csr *M, const double *p, int64_t i)
{
    double s = 0.0;
    for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++) s += M->val[k] * p[M->colidx[k]];
    return s;
}

/* Read Mt once for the pull sweeps, c_j (into csum, or r when NULL) and the largest entry of row
 * j of Mt (into cmax when not NULL): 1; 0 when M has a negative entry (no pull: r made again as
 * e_s + M p - p). */
static int pull_setup(const ulam_csr *M, const ulam_csr *Mt, int64_t s, const double *p, double *r, double *csum,
                      double *cmax, pull *pl)
{
    int64_t n = Mt->nrows;
    const ulam__sweep_release *rel = pl->rel;
    double *c = csum ? csum : r;
    for (int64_t j = 0; j < n; j++) {
        double sum = 0.0, mx = 0.0;
        for (int64_t k = Mt->rowptr[j]; k < Mt->rowptr[j + 1]; k++) {
            double v = Mt->val[k];
            if (v < 0) {
                for (int64_t i = 0; i < n; i++) r[i] = pull_row(M, p, i) + (i == s ? 1.0 : 0.0) - p[i], ulam__sweep_done(rel, M, i, n);
                return 0;
            }
            sum += v, mx = v > mx ? v : mx;
        }
        c[j] = sum;
        if (cmax) cmax[j] = mx;
        ulam__sweep_done(rel, Mt, j, n);
    }
    pl->M = M, pl->c = c;
    return 1;
}

/* One Gauss-Seidel pull sweep, over-relaxed by omega (p_i moves omega times its residual; updates
 * of more than thr either way: after an overshoot a plain sweep moves p_i down); the updates
 * made; *rsum (the residual's signed sum) falls with them. */
static int64_t pull_sweep(const pull *pl, int64_t s, double thr, double omega, double *p, double *rsum)
{
    int64_t n = pl->M->nrows, pushed = 0;
    double fall = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double v = pull_row(pl->M, p, i) + (i == s ? 1.0 : 0.0), d = v - p[i];
        ulam__sweep_done(pl->rel, pl->M, i, n);
        if (!(fabs(d) > thr)) continue;
        p[i] = omega > 1.0 ? p[i] + omega * d : v, pushed++;
        fall += (omega > 1.0 ? omega * d : d) * (1.0 - pl->c[i]);
    }
    *rsum -= fall;
    return pushed;
}

/* r = e_s + M p - p, its negative entries' mass in *neg; ||r||_1. */
static double pull_residual(const pull *pl, int64_t s, const double *p, double *r, double *neg)
{
    int64_t n = pl->M->nrows;
    double sum = 0.0;
    *neg = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double v = pull_row(pl->M, p, i) + (i == s ? 1.0 : 0.0) - p[i];
        ulam__sweep_done(pl->rel, pl->M, i, n);
        r[i] = v;
        if (v < 0) *neg -= v;
        sum += fabs(v);
    }
    return sum;
}

/* Forward push from s on M (given as its transpose Mt, and as itself or NULL) into p and r. */
int ulam__sweep_push_pull(const ulam_csr *M, const ulam_csr *Mt, int64_t s, double rmax, ulam__sweep_cost cost,
                          void *ctx, int64_t max_ops, double *p, double *r, double *csum, double *cmax,
                          const ulam__sweep_release *rel, ulam__sweep_info *info)
{
    int64_t n = Mt->nrows, nnz = ulam_csr_nnz(Mt);
    *info = (ulam__sweep_info){0};
    int32_t *list = ulam__malloc((size_t)n, sizeof *list), *next = ulam__malloc((size_t)n, sizeof *next);
    unsigned char *mark = ulam__calloc((size_t)n, 1);
    pull pl = {.rel = rel};
    if (!list || !next || !mark) {
        free(list), free(next), free(mark);
        return ULAM_ENOMEM;
    }
    double thr = rmax > 0 ? rmax : 0.0; /* push |r_j| > thr */
    r[s] = 1.0;
    list[0] = (int32_t)s;
    int64_t nlist = 1, ops = 0;
    double rsum = 1.0;
    int status = ULAM_OK, sweeping = 0, pulling = 0, settle = 0;
    double omega = cost && thr == 0.0 ? ULAM__SWEEP_OMEGA : 1.0; /* pull sweeps' over-relaxation, 1 while settling */
    for (;;) {
        int64_t round_ops = 0, pushed = 0;
        double before = rsum;
        if (!sweeping) {
            int64_t nnext = 0;
            for (int64_t q = 0; q < nlist; q++) mark[list[q]] = 0;
            for (int64_t q = 0; q < nlist; q++) {
                int64_t j = list[q];
                if (!(fabs(r[j]) > thr)) continue;
                round_ops += push_one(Mt, j, p, r, next, &nnext, mark), pushed++;
                if (rel && rel->trim && pushed % ULAM__SWEEP_TRIM_EVERY == 0) rel->trim(rel->ctx);
            }
            for (int64_t q = 0; q < nlist; q++) /* states left under the threshold stay listed */
                if (r[list[q]] != 0.0 && !mark[list[q]]) mark[list[q]] = 1, next[nnext++] = list[q];
            int32_t *t = list;
            list = next, next = t, nlist = nnext;
        } else if (pulling) {
            pushed = pull_sweep(&pl, s, thr, omega, p, &rsum);
            round_ops = nnz + n;
            info->sweeps++, info->pulls++;
        } else {
            round_ops = sweep_once(Mt, thr, p, r, &pushed, rel);
            info->sweeps++;
        }
        info->rounds++;
        info->pushes += pushed;
        ops += round_ops;
        if (pulling) {
            /* rsum kept by pull_sweep */
        } else if (sweeping) {
            int64_t active = 0;
            rsum = 0.0;
            for (int64_t j = 0; j < n; j++) rsum += fabs(r[j]), active += r[j] != 0.0;
            ops += n;
            if (active < n / 16) { /* few states hold residual again: back to the list */
                nlist = 0;
                for (int64_t j = 0; j < n; j++)
                    if (r[j] != 0.0) mark[j] = 1, list[nlist++] = (int32_t)j;
                sweeping = 0;
            }
        } else {
            rsum = 0.0;
            for (int64_t q = 0; q < nlist; q++) rsum += fabs(r[list[q]]);
            if (nlist >= n / 16) {
                sweeping = 1;
                if (M && pull_setup(M, Mt, s, p, r, csum, cmax, &pl)) { /* from here on r is implicit: rsum as 1 - sum_i p_i (1 - c_i) */
                    pulling = 1, ops += nnz;
                    rsum = 1.0;
                    for (int64_t i = 0; i < n; i++) rsum -= p[i] * (1.0 - pl.c[i]);
                }
            }
        }
        if (pushed == 0 || !(rsum > 0.0)) {
            if (!pulling || omega == 1.0) break;
            omega = 1.0, settle = ULAM__SWEEP_SETTLE; /* an overshoot took r's sum to 0 or below (a DAG in
                                                         order: one sweep is exact, 1.2 of it overshoots): settle */
            continue;
        }
        if (max_ops > 0 && ops > max_ops) {
            status = ULAM_ENOCONV;
            break;
        }
        if (!cost) continue; /* rmax alone decides */
        if (settle > 0) {
            if (--settle == 0) break;
            continue;
        }
        /* one more round like this one takes the residual from rsum to rsum^2 / before */
        double rho = before > 0 ? rsum / before : 1.0, next_ops = sweeping ? (double)(nnz + 2 * n) : (double)round_ops;
        if (!(cost(rsum, ctx) - cost(rho * rsum, ctx) > next_ops)) {
            if (!pulling || omega == 1.0) break;
            omega = 1.0, settle = ULAM__SWEEP_SETTLE; /* plain sweeps leave r >= 0 again */
        }
    }
    if (pulling) rsum = pull_residual(&pl, s, p, r, &info->r_neg), ops += nnz + n; /* c in r is not needed after */
    info->ops = ops;
    info->r_sum = rsum;
    info->nonneg = pl.c != NULL;
    for (int64_t j = 0; j < n; j++) info->support += r[j] != 0.0;
    free(list), free(next), free(mark);
    return status;
}

