/* The variance guard of partitioned walks: a certified upper bound on rho(M^) by power iteration
 * on the rows each rank holds (see ulam_dist_radius in ulam_dist.h). */
#include "part.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* One step: y = M^ v on this rank's rows (own NULL: v all ones; else v at its rows own, at its
 * halo gv), the Collatz-Wielandt ratio's largest value (each row's sum rounded up by its
 * (length + 2) roundings) into *cw and y's largest into *top. */
static void step(const ulam_part *p, const ulam__rows *A, const ulam__halo *h, const double *own, const double *gv, double *y,
                 double *cw, double *top)
{
    *cw = 0.0, *top = 0.0;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        double S = A->rowsum[i], f = S > 1.0 ? S : 1.0, s = 0.0; /* S / min(1, S) */
        int64_t len = A->rowptr[i + 1] - A->rowptr[i];
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++)
            s += fabs(A->val[q]) * (own ? ulam__halo_at(p, A, h, own, gv, q) : 1.0);
        s *= f * (1.0 + (double)(len + 3) * DBL_EPSILON);
        y[i] = s;
        double r = own ? s / own[i] : s;
        if (r > *cw) *cw = r;
        if (s > *top) *top = s;
    }
}

/* Power iteration on M^ (see ulam_dist_radius) into *best; with keep, also this rank's rows of
 * the iterate v whose Collatz-Wielandt bound is *best (keep[0 .. rows)) and the least entry of
 * that v over the ranks (*vmin), iterating past 1 until 20 steps gain less than 1% of 1 - best.  Each rank holds v at its rows and their halo only. */
static int power(const ulam_part *p, const ulam_comm *comm, const ulam__rows *A, int iters, double *best_out, double *keep,
                 double *vmin, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    double *own = NULL, *gv = NULL, *y = malloc(((size_t)rows + 1) * sizeof *y); /* own, gv: once the row sums do not do */
    if (!y) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the power iteration (%lld doubles)", (long long)rows);
    ulam__halo h = {0};
    double best = INFINITY;
    int status = ULAM_OK, made = 0;
    double before = INFINITY; /* keep: the best 20 steps ago (the tail wants u well below 1, not just below) */
    for (int k = 0; k < iters && (keep ? !(best < 1.0 && before - best < 0.01 * (1.0 - best)) : !(best < 1.0)); k++) {
        double cw, top;
        if (k % 20 == 0) before = k ? best : INFINITY;
        step(p, A, &h, k ? own : NULL, gv, y, &cw, &top);
        if (ulam__dist_largest(comm, &cw) || ulam__dist_largest(comm, &top)) {
            status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
            break;
        }
        if (cw < best) {
            best = cw;
            double lo = INFINITY; /* the least entry as a largest of 1 / v: ulam__dist_largest takes nonnegatives */
            for (int64_t i = 0; keep && i < rows; i++) keep[i] = k ? own[i] : 1.0, lo = fmin(lo, keep[i]);
            double inv = rows ? 1.0 / lo : 0.0;
            if (keep && ulam__dist_largest(comm, &inv)) {
                status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
                break;
            }
            if (keep) *vmin = 1.0 / inv; /* rounded: the caller's ratios take a margin */
        }
        if ((best < 1.0 && !keep) || !(top > 0.0) || !isfinite(top)) break; /* certified; or M^ v = 0, or overflow */
        if (!made) { /* the halo, once: every rank gets here together (the same best and top) */
            made = 1;
            int64_t bad = ulam__halo_make(p, comm, A, &h);
            own = malloc(((size_t)rows + 1) * sizeof *own), gv = malloc(((size_t)h.nghost + 1) * sizeof *gv);
            bad |= !own || !gv;
            if (comm->nranks > 1 && comm->sum(comm->ctx, &bad, 1)) bad = 1; /* all stop together */
            if (bad) {
                status = ulam__fail(err, ULAM_ENOMEM, 0, -1,
                                    "memory for the power iteration's halo and an exchange that succeeds");
                break;
            }
        }
        for (int64_t i = 0; i < rows; i++) own[i] = y[i] / top + 1e-6; /* kept positive: any positive v gives a valid bound */
        if (ulam__halo_swap(p, comm, &h, own, gv)) status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
        if (status) break;
    }
    ulam__halo_free(&h);
    free(own), free(gv), free(y);
    if (!status) *best_out = best;
    return status;
}

/* A certified upper bound on rho(M^) of the partitioned walks. */
int ulam_dist_radius(const ulam_part *p, const ulam_comm *comm, int forward, int iters, double *upper, ulam_error *err)
{
    ulam__clear(err);
    if (!p || !comm || !upper || iters < 1) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part, a comm, a result, iters >= 1");
    const ulam__rows *A = forward ? &p->t : &p->m;
    if (!A->rowptr) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part holding the rows of %s", forward ? "M'" : "M");
    return power(p, comm, A, iters, upper, NULL, NULL, err);
}

/* The length tail of adjoint walks, or of forward walks with total >= 0 (part.h). */
int ulam__dist_tail(const ulam_part *p, const ulam_comm *comm, int iters, const int64_t *index, int64_t nq, double total,
                    ulam__dist_cert *cert, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    int fwd = total >= 0.0;
    const ulam__rows *A = fwd ? &p->t : &p->m;
    *cert = (ulam__dist_cert){.u = INFINITY};
    double smax = 0.0, bmax = 0.0;
    for (int64_t i = 0; i < rows; i++) smax = fmax(smax, A->rowsum[i]), bmax = fmax(bmax, fabs(p->b[i]));
    if (ulam__dist_largest(comm, &smax) || ulam__dist_largest(comm, &bmax))
        return ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    cert->bmax = fwd ? (bmax > 0.0 ? total : 0.0) : bmax; /* forward: every weight is +-||b||_1 while rows are <= 1 */
    cert->c = calloc((size_t)nq, sizeof *cert->c);
    if (!cert->c) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld queries", (long long)nq);
    if (bmax == 0.0) return ULAM_OK; /* b = 0: x = 0 */
    cert->second = smax > 1.0;       /* weights that grow: no length bound bounds a score, a second moment may */
    double *keep = malloc(((size_t)rows + 1) * sizeof *keep), u = INFINITY, vmin = 0.0;
    int64_t *bits = calloc((size_t)nq, sizeof *bits);
    int status = keep && bits ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the power iteration");
    if (!status) status = power(p, comm, A, iters, &u, keep, &vmin, err);
    for (int64_t k = 0; !status && k < nq; k++) /* v at each query's start, from the rank that owns it (exact: one owner) */
        if (index[k] >= p->first && index[k] < p->last && p->set == 0) memcpy(&bits[k], &keep[index[k] - p->first], 8);
    if (!status && comm->nranks > 1 && comm->sum(comm->ctx, bits, (int)nq))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    double g = 0.0; /* adjoint, second: max b_i^2 / v_i, so b^2 <= g v; forward: max v_j where b_j != 0 (the starts) */
    for (int64_t i = 0; !status && (cert->second || fwd) && i < rows; i++)
        g = fmax(g, fwd ? (p->b[i] != 0.0 ? keep[i] : 0.0) : p->b[i] * p->b[i] / keep[i]);
    if (!status && (cert->second || fwd) && ulam__dist_largest(comm, &g))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    for (int64_t k = 0; !status && k < nq; k++) {
        double vk;
        memcpy(&vk, &bits[k], 8);
        if (fwd) /* a walk from j is alive after t steps w.p. <= u^t v_j / min v; E w_t^2 [s_t = i] <= total^2 u^t v_j / v_i */
            cert->c[k] = (cert->second ? g / vk : g / vmin) * (1.0 + 8.0 * DBL_EPSILON);
        else
            cert->c[k] = cert->second ? vk * g / (bmax * bmax) * (1.0 + 8.0 * DBL_EPSILON) : vk / vmin * (1.0 + 4.0 * DBL_EPSILON);
    }
    if (!status && u < 1.0) cert->u = u;
    if (!status && cert->second && u < 1.0) { /* the second moment aimed at each start (forward: at the row watched) */
        cert->v2 = malloc(((size_t)nq + 1) * sizeof *cert->v2);
        if (!cert->v2) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld queries", (long long)nq);
        else if (!fwd) status = ulam__dist_moment(p, comm, index, nq, cert->v2, err);
        for (int64_t k = 0; !status && fwd && k < nq; k++) status = ulam__dist_moment_forward(p, comm, index[k], &cert->v2[k], err);
    }
    free(keep), free(bits);
    return status;
}

/* A Collatz-Wielandt certificate of |M| on the part's rows of M: u < 1 (INFINITY when none) with
 * |M| v <= u v for a positive v, and c[i] >= v_i / min v at this rank's rows (M^ >= |M| entry by
 * entry, so power's bound on M^ holds for |M|). */
int ulam__dist_cw(const ulam_part *p, const ulam_comm *comm, int iters, double *u, double *c, ulam_error *err)
{
    double vmin = 0.0;
    *u = INFINITY;
    int status = power(p, comm, &p->m, iters, u, c, &vmin, err);
    for (int64_t i = 0; !status && i < p->last - p->first; i++) c[i] = c[i] / vmin * (1.0 + 4.0 * DBL_EPSILON);
    if (!status && !(*u < 1.0)) *u = INFINITY;
    return status;
}
