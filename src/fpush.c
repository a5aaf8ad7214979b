/* Single source, every target: x = (I - M)^-1 e_s by a forward push and forward walks on what
 * it leaves (FORA: Wang, Yang, Xiao, Wei, Wei, Liu, "FORA: simple and effective approximate
 * single-source personalized PageRank", KDD 2017).
 *
 * The reverse push of src/push.c on M' from s is M's forward push from s: it leaves
 * x = p + (I - M)^-1 r (the push's invariant for M', read by columns), with every |r_j| <= rmax.
 * The forward walk solver on M with right-hand side r estimates every component of
 * (I - M)^-1 r at once, with a standard error each.  r is fixed before any walk, so p + the
 * walks' estimate is unbiased component by component.
 *
 * Walks: a fixed count, or FORA's count for relative error E on every component of at least
 * delta with failure probability 1/n, W = ||r||_1 (2E/3 + 2) ln(2n) / (E^2 delta).  Balance:
 * rmax halves from 1 while the push's operations are below W V step_cost (V the visits a walk
 * makes, 1 / (1 - ||M||_1) from the guards' one-pass bound).  Intervals: p_i + the walks' normal
 * interval where the walks saw two values at i; where they did not (one score or none: the
 * sample says nothing about what it missed), the certified bound of the walk part,
 * |(I - M)^-1 r|_i <= ||r||_1 / (1 - ||M||_1); every interval clipped to p_i -+ that bound. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The defaults. */
ulam_fpush_opts ulam_fpush_defaults(void)
{
    ulam_fpush_opts o = {.rel_err = 0.1, .walk = ulam_walk_defaults()};
    o.walk.mode = ULAM_FORWARD;
    return o;
}

/* Check the options. */
static int check(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *o, ulam_error *err)
{
    int64_t n = M->nrows;
    if (M->ncols != n) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    if (!Mt || Mt->nrows != n || Mt->ncols != n || ulam_csr_nnz(Mt) != ulam_csr_nnz(M))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "Mt, the transpose of M (%lld x %lld)", (long long)n, (long long)n);
    if (o->source < 0 || o->source >= n)
        return ulam__fail(err, ULAM_EINVAL, 0, o->source, "a source from 0 to %lld", (long long)n - 1);
    if (!(o->rel_err > 0 && o->rel_err < 1) || o->walks < 0 || !isfinite(o->rmax) || !isfinite(o->min_value) ||
        !isfinite(o->step_cost))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "rel_err in (0, 1), walks >= 0, a finite rmax, min_value and "
                                                   "step_cost");
    return ulam__walk_opts_check(&o->walk, err); /* src/check.c */
}

/* FORA's walk count for the residual mass rsum (or the fixed count). */
static double walk_count(const ulam_fpush_opts *o, double rsum, int64_t n)
{
    if (o->walks > 0) return (double)o->walks;
    double E = o->rel_err, delta = o->min_value > 0 ? o->min_value : 1.0 / (double)n;
    return ceil(rsum * (2.0 * E / 3.0 + 2.0) * log(2.0 * (double)n) / (E * E * delta));
}

/* Estimate every component of x = (I - M)^-1 e_source. */
int ulam_fpush_solve(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, double *x, double *std_error,
                     double *lo, double *hi, ulam_fpush_info *info, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !opts || !x || !info) return ulam__fail(err, ULAM_EINVAL, 0, -1, "M, options, x and info");
    int status = check(M, Mt, opts, err);
    if (status) return status;
    memset(info, 0, sizeof *info);
    ulam_fpush_opts o = *opts;
    int64_t n = M->nrows;
    double t0 = ulam_now();
    ulam_guard g;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_FORWARD;
    if (o.walk.policy.guard) g = *o.walk.policy.guard;
    else if ((status = ulam_guard_check(M, o.walk.kernel.continue_q, &go, &g, err))) return status;
    double c = g.abs.colsum_max; /* ||M||_1 */
    double D1 = c < 1.0 ? 1.0 / (1.0 - c) : INFINITY; /* ||(I - M)^-1||_1 */
    info->mean_visits = isfinite(D1) ? D1 : 1.0 / fmax(1e-3, 1.0 - fmin(g.abs.upper, 0.999));
    double cost = o.step_cost > 0 && isfinite(o.step_cost) ? o.step_cost : ULAM_BIDIR_STEP_COST;
    ulam_push *w = NULL;
    if ((status = ulam_push_alloc(Mt, &w))) return ulam__fail(err, status, 0, -1, "memory for the push");
    ulam_push_start(w, o.source);
    double rmax = o.rmax > 0 ? o.rmax : 1.0, W;
    int64_t cap = 100 * ulam_csr_nnz(M) + 1000000;
    status = ulam_push_run(w, rmax, cap);
    for (;;) {
        ulam_push_report(w, &info->push);
        W = info->push.support ? walk_count(&o, info->push.r_sum, n) : 0.0;
        if (o.rmax > 0 || status || info->push.support == 0 || (double)info->push.ops >= W * info->mean_visits * cost)
            break;
        rmax /= 2;
        status = ulam_push_run(w, rmax, cap);
    }
    info->rmax = rmax;
    info->push_seconds = info->push.seconds;
    if (status) {
        ulam_push_free(w);
        return ulam__fail(err, status, 0, -1, "a push within %lld operations (is rho(|M|) < 1?)", (long long)cap);
    }
    const double *p = ulam_push_estimates(w), *r = ulam_push_residuals(w);
    double *xw = ulam__calloc((size_t)n, sizeof *xw), *se = ulam__calloc((size_t)n, sizeof *se);
    if (!xw || !se) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walks' estimates");
    info->residual_bound = info->push.r_sum * D1;
    if (!status && info->push.support > 0) {
        ulam_walk_opts wo = o.walk;
        wo.mode = ULAM_FORWARD, wo.query.index = o.source, wo.stop.rel_err = 0, wo.policy.guard = &g;
        wo.stop.max_walks = (int64_t)fmin(fmax(W, 1.0), 4e18);
        ulam_solver *sv = NULL;
        status = ulam_solver_alloc(M, r, &wo, &sv, err);
        while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
        if (status && sv) ulam_solver_error(sv, err);
        if (!status) {
            ulam_walk_result wr;
            ulam_solver_result(sv, &wr);
            ulam_solver_vectors(sv, xw, se);
            info->walks = wr.walks, info->steps = wr.steps, info->walk_seconds = wr.seconds;
            info->interrupted = wr.interrupted;
        }
        ulam_solver_free(sv);
    }
    if (!status) {
        double D = info->residual_bound;
        for (int64_t i = 0; i < n; i++) {
            x[i] = p[i] + xw[i];
            if (std_error) std_error[i] = se[i];
            double a = x[i] - 1.959963984540054 * se[i], b = x[i] + 1.959963984540054 * se[i];
            if (!(se[i] > 0) && D > 0) a = p[i] - D, b = p[i] + D; /* the walks saw one value at i, or none */
            if (isfinite(D)) a = fmax(a, p[i] - D), b = fmin(b, p[i] + D);
            if (!isfinite(a) || !isfinite(b)) a = b = NAN; /* nothing certifies one */
            if (lo) lo[i] = a;
            if (hi) hi[i] = b;
        }
    }
    free(xw), free(se);
    ulam_push_free(w);
    info->seconds = ulam_now() - t0;
    return status;
}
