/* The push on b for one entry x_i of (I - M) x = b with a dense b: a forward push absorbs b's
 * large entries deterministically, and adjoint walks from i score only what it leaves.
 *
 * The walks' certified range R (src/stop.h) grows with max |b| over the states they can reach,
 * however rarely they reach them; the rel_err rule pays for R (its range term) even when the
 * variance is small.  The forward push keeps x = q + (I - M)^-1 r (q = 0, r = b at the start):
 * pushing state j moves r_j into q_j and spreads it down column j of M (r_k += M_kj r_j), which
 * leaves both sides unchanged.  States with |r_j| > rmax wait in a FIFO queue.  Then
 * x_i = q_i + [(I - M)^-1 r]_i, the second term by the adjoint walk solver on M with right-hand
 * side r (R now rmax times the walks' bound on weighted visits), with rel_err_offset q_i so the
 * rule measures the relative error of the whole x_i.  r is fixed before any walk: q_i + the
 * walks' estimate is unbiased, and the walks' interval shifted by q_i is the interval of x_i.
 * (The importance of b_j to x_i is the adjoint solution ((I - M)^-1)_ij: a large b_j that walks
 * from i rarely reach is worth little to x_i, and the push takes it out of their range.) */
#include "bpush.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Push r (n entries, q alongside) on Mt, the transpose of M, until every |r_j| <= rmax or the
 * operations (nonzeros read, plus one a push) pass max_ops; *ops counts them, *pushes the states
 * pushed.  ULAM_OK (the invariant holds either way), ULAM_ENOMEM. */
int ulam__bpush(const ulam_csr *Mt, double rmax, int64_t max_ops, double *q, double *r, int64_t *ops, int64_t *pushes)
{
    int64_t n = Mt->nrows, head = 0, len = 0;
    int32_t *queue = malloc((size_t)(n > 0 ? n : 1) * sizeof *queue);
    unsigned char *in = calloc((size_t)(n > 0 ? n : 1), 1);
    if (!queue || !in) return free(queue), free(in), ULAM_ENOMEM;
    for (int64_t j = 0; j < n; j++)
        if (fabs(r[j]) > rmax) queue[len++] = (int32_t)j, in[j] = 1;
    while (len > 0 && *ops < max_ops) {
        int32_t j = queue[head];
        head = head + 1 == n ? 0 : head + 1, len--, in[j] = 0;
        double v = r[j];
        q[j] += v, r[j] = 0.0;
        for (int64_t p = Mt->rowptr[j]; p < Mt->rowptr[j + 1]; p++) {
            int32_t k = Mt->colidx[p];
            r[k] += Mt->val[p] * v;
            if (!in[k] && fabs(r[k]) > rmax) {
                int64_t at = head + len;
                queue[at >= n ? at - n : at] = k, len++, in[k] = 1;
            }
        }
        *ops += 1 + (Mt->rowptr[j + 1] - Mt->rowptr[j]), *pushes += 1;
    }
    free(queue), free(in);
    return ULAM_OK;
}

/* What the push left in q and r (n entries) into pi: support, r_sum and r_max of r, touched the
 * states with q_j or r_j nonzero. */
void ulam__bpush_residual(const double *q, const double *r, int64_t n, ulam_push_info *pi)
{
    pi->support = pi->touched = 0, pi->r_sum = pi->r_max = 0.0;
    for (int64_t j = 0; j < n; j++) {
        double a = fabs(r[j]);
        pi->support += a > 0, pi->touched += a > 0 || q[j] != 0.0;
        pi->r_sum += a, pi->r_max = fmax(pi->r_max, a);
    }
}

/* max |r_j|. */
double ulam__bpush_max(const double *r, int64_t n)
{
    double m = 0.0;
    for (int64_t j = 0; j < n; j++) m = fmax(m, fabs(r[j]));
    return m;
}
