/* The variance guard of partitioned walks: a certified upper bound on rho(M^) by power iteration
 * on the rows each rank holds (see ulam_dist_radius in ulam_dist.h). */
#include "part.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* One step: y = M^ v on this rank's rows (v NULL: all ones), the Collatz-Wielandt ratio's largest value (each row's
 * sum rounded up by its (length + 2) roundings) into *cw and y's largest into *top. */
static void step(const ulam_part *p, const ulam__rows *A, const double *v, double *y, double *cw, double *top)
{
    *cw = 0.0, *top = 0.0;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        double S = A->rowsum[i], f = S > 1.0 ? S : 1.0, s = 0.0; /* S / min(1, S) */
        int64_t len = A->rowptr[i + 1] - A->rowptr[i];
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) s += fabs(A->val[q]) * (v ? v[A->col[q]] : 1.0);
        s *= f * (1.0 + (double)(len + 3) * DBL_EPSILON);
        y[i] = s;
        double r = v ? s / v[p->first + i] : s;
        if (r > *cw) *cw = r;
        if (s > *top) *top = s;
    }
}

/* Power iteration on M^ (see ulam_dist_radius) into *best; with keep, also this rank's rows of
 * the iterate v whose Collatz-Wielandt bound is *best (keep[0 .. rows)) and the least entry of
 * that v over the ranks (*vmin). */
static int power(const ulam_part *p, const ulam_comm *comm, const ulam__rows *A, int iters, double *best_out, double *keep,
                 double *vmin, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    double *v = NULL, *y = malloc(((size_t)rows + 1) * sizeof *y); /* v: the whole iterate, once the row sums do not do */
    if (!y) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the power iteration (%lld doubles)", (long long)rows);
    double best = INFINITY;
    int status = ULAM_OK;
    for (int k = 0; k < iters && !(best < 1.0); k++) {
        double cw, top;
        step(p, A, k ? v : NULL, y, &cw, &top);
        if (ulam__dist_largest(comm, &cw) || ulam__dist_largest(comm, &top)) {
            status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
            break;
        }
        if (cw < best) {
            best = cw;
            double lo = INFINITY; /* the least entry as a largest of -v: ulam__dist_largest takes nonnegatives */
            for (int64_t i = 0; keep && i < rows; i++) keep[i] = k ? v[p->first + i] : 1.0, lo = fmin(lo, keep[i]);
            double inv = rows ? 1.0 / lo : 0.0;
            if (keep && ulam__dist_largest(comm, &inv)) {
                status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
                break;
            }
            if (keep) *vmin = 1.0 / inv; /* rounded: the caller's ratios take a margin */
        }
        if (best < 1.0 || !(top > 0.0) || !isfinite(top)) break; /* certified; or M^ v = 0, or overflow */
        if (!v && !(v = malloc((size_t)p->n * sizeof *v))) {
            status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the power iteration (%lld doubles)", (long long)p->n);
            break;
        }
        for (int64_t i = 0; i < rows; i++) y[i] = y[i] / top + 1e-6; /* kept positive: any positive v gives a valid bound */
        if (ulam__dist_gather(p, comm, y, v)) status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
        if (status) break;
    }
    free(v), free(y);
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

/* The length tail of adjoint walks (part.h). */
int ulam__dist_tail(const ulam_part *p, const ulam_comm *comm, int iters, const int64_t *index, int64_t nq,
                    ulam__dist_cert *cert, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    const ulam__rows *A = &p->m;
    *cert = (ulam__dist_cert){.u = INFINITY};
    double smax = 0.0, bmax = 0.0;
    for (int64_t i = 0; i < rows; i++) smax = fmax(smax, A->rowsum[i]), bmax = fmax(bmax, fabs(p->b[i]));
    if (ulam__dist_largest(comm, &smax) || ulam__dist_largest(comm, &bmax))
        return ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    cert->bmax = bmax;
    cert->c = calloc((size_t)nq, sizeof *cert->c);
    if (!cert->c) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld queries", (long long)nq);
    if (smax > 1.0 || bmax == 0.0) return ULAM_OK; /* weights that grow: no length bound bounds a score; b = 0: x = 0 */
    double *keep = malloc(((size_t)rows + 1) * sizeof *keep), u = INFINITY, vmin = 0.0;
    int64_t *bits = calloc((size_t)nq, sizeof *bits);
    int status = keep && bits ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the power iteration");
    if (!status) status = power(p, comm, A, iters, &u, keep, &vmin, err);
    for (int64_t k = 0; !status && k < nq; k++) /* v at each query's start, from the rank that owns it (exact: one owner) */
        if (index[k] >= p->first && index[k] < p->last && p->set == 0) memcpy(&bits[k], &keep[index[k] - p->first], 8);
    if (!status && comm->nranks > 1 && comm->sum(comm->ctx, bits, (int)nq))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    for (int64_t k = 0; !status && k < nq; k++) {
        double vk;
        memcpy(&vk, &bits[k], 8);
        cert->c[k] = vk / vmin * (1.0 + 4.0 * DBL_EPSILON); /* v_i / min v, rounded up */
    }
    if (!status && u < 1.0) cert->u = u;
    free(keep), free(bits);
    return status;
}
