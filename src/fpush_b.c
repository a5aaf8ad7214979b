/* The push on b for forward walks with a relative-error target: Gauss-Seidel sweeps of the forward
 * push absorb b deterministically, and the forward walks tally only what they leave (FORA's split,
 * Wang, Yang, Xiao, Wei, Wei, Liu, KDD 2017, for any b rather than a point source).
 *
 * A forward walk starts with weight ||b||_1, so everything the rel_err rule certifies about its
 * score (src/stop.h) scales with ||b||_1: the range R of a single tally (||b||_1 times the weight
 * bound times the visits a walk of the truncated length can make) and the certified second moment
 * (||b||_1^2).  Against a small x_i the range term asks for walks in proportion to R / x_i however
 * rarely a walk comes back to i, 30x the variance's own need on randsub1000 at E = 0.1.  The
 * forward push keeps x = q + (I - M)^-1 r (q = 0, r = b at the start): pushing state j moves r_j
 * into q_j and adds M_kj r_j to r_k (column j of M, row j of Mt).  A sweep pushes every nonzero
 * residual in index order (src/sweep.c's push sweep: a residual a push adds ahead of the sweep is
 * pushed in the same sweep).
 * The walks then start from r with weight ||r||_1: their range, second moment and variance shrink
 * with it.  Sweeps go on while the walks' predicted work (the caller's cost model, at the push part
 * q_i as the scale of x_i) falls by more than a sweep costs, so the push never costs more than the
 * walks it saves, as predicted.  At a fixed budget (--walks, --time) the walks are paid for
 * whatever the push does, and a sweep that takes r to a share s of itself narrows the interval to
 * s of its width: walks from r would need 1/s^2 times the budget for that, so a sweep is made
 * while (1/s^2 - 1) budget exceeds its cost, with the push's work at most the cap (ULAM__FPUSH_B_CAP
 * times the walks' under --walks, half the time under --time) and not past b's rounding.  Valuing
 * a sweep only against the width the budget's walks from b reach stopped it at
 * ||r||_1 / ||b||_1 = 0.46 on randsub1000 (4 sweeps, +-17.4 at 4072 walks, collision, x_1 = 5.01)
 * where --rel-err 0.01 pushes 35.  r is fixed before any walk: q + the walks' estimate is unbiased
 * component by component, and the walks' interval shifted by q_i is x_i's. */
#include "fpush_b.h"
#include "sweep.h"

#include <float.h>
#include <math.h>

/* ||r||_1. */
static double norm1(const double *r, int64_t n)
{
    double s = 0.0;
    for (int64_t j = 0; j < n; j++) s += fabs(r[j]);
    return s;
}

/* Sweep r (b on entry) into q (zero on entry): under a rel_err target while the walks' work falls
 * by more than a sweep's; at a fixed budget while the walks that would narrow the interval as much
 * as the next sweep cost more than it, within the cap. */
int ulam__fpush_b(const ulam_csr *Mt, int64_t index, ulam__fpush_b_cost cost, void *ctx, double first, double budget,
                  double cap, double *q, double *r, ulam__fpush_b_info *info)
{
    int64_t n = Mt->nrows, nnz = ulam_csr_nnz(Mt);
    double rsum = norm1(r, n), step = (double)(2 * n + nnz), now;
    *info = (ulam__fpush_b_info){.r_sum0 = rsum, .r_sum = rsum, .work0 = cost(rsum, 0.0, ctx)};
    info->work = info->work0;
    if (!(ULAM_AUTO_READ * step <= first)) return ULAM_OK; /* q_i = 0 prices nothing: the first sweep on trust */
    for (int it = 0; it < ULAM__FPUSH_B_SWEEPS && rsum > 0; it++) {
        double last = rsum;
        int64_t pushed;
        info->ops += ulam__sweep_once(Mt, 0.0, q, r, &pushed);
        info->sweeps++;
        rsum = norm1(r, n);
        now = info->work = cost(rsum, q[index], ctx);
        if (budget > 0) {
            /* the next sweep takes the residual, and with it every term of the interval, from rsum to
               about rsum^2 / last (the last sweep's rate): the walks that would narrow it as much
               are the budget's times (last / rsum)^2 - 1, the rate's, whatever rsum is; never past
               the cap, nor once b is pushed to its rounding (a sweep then gains nothing real) */
            double rate = rsum / last, more = budget * (1.0 / (rate * rate) - 1.0);
            if (!(rate < 1.0) || !(more > ULAM_AUTO_READ * step) || ULAM_AUTO_READ * ((double)info->ops + step) > cap ||
                rsum <= ULAM__FPUSH_B_ROUNDING * DBL_EPSILON * info->r_sum0)
                break;
            continue;
        }
        /* the next sweep takes the residual from rsum to about rsum^2 / last: it pays when the
           walks' work it saves exceeds its own (NaN, with q_i still 0: unpriced, stop) */
        double save = now - cost(fmin(1.0, rsum / last) * rsum, q[index], ctx);
        if (!(save > ULAM_AUTO_READ * step)) break;
    }
    info->r_sum = rsum;
    return ULAM_OK;
}
