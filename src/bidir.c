/* Bidirectional estimate of one entry x_t of (I - M) x = e_s: a reverse push from t, then walks
 * from s that score the push's residual.
 *
 * The push leaves x_t = p_s + <r, x> (src/push.c), and <r, x> = r' (I - M)^-1 e_s
 * = e_s' (I - M')^-1 r is the unknown s of the system (M', r): the adjoint walk solver on M'
 * started at s with right-hand side r estimates it, unbiased, with its error bar, threads and
 * stopping rules.  r is fixed before any of those walks runs (the balance below looks only at
 * the push's work and a pilot on its own seed), so p_s + estimate is unbiased for x_t.
 *
 * Balance (as BiPPR balances times, here on work counts so the result is reproducible): a
 * collision walk scores at most rmax at each of its V visits, so its variance is about
 * rmax E[V] x; the walks needed for relative error e are N = rmax E[V] / (e^2 xhat) with
 * xhat = max(min_value, |p_s|), each costing E[V] steps.  rmax halves, pushing down to it,
 * while the push's work so far is below the walks' predicted work. */
#include "internal.h"
#include "push.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Pilot walks that measure E[V]; a walk step's cost in push operations (a push operation reads
 * one nonzero and updates one residual, a step on a built row draws from its alias table; on the
 * 10^6 R-MAT graph of bench_bidir a step that builds rows cost about 150 operations, while the
 * variance model predicted 3 to 80 times the walks needed: the two errors lean opposite ways and
 * the 1000-walk floor bound every query there, README); the walks before a relative-error rule
 * may stop (as the solver's). */
enum { PILOT = 256, MIN_WALKS = 1000 };
static const double STEP_COST = 1.0, DEFAULT_REL_ERR = 0.1;

/* The defaults. */
ulam_bidir_opts ulam_bidir_defaults(void)
{
    return (ulam_bidir_opts){.walk = ulam_walk_defaults()};
}

/* Check the options against M and Mt. */
static int check_opts(const ulam_csr *M, const ulam_csr *Mt, const ulam_bidir_opts *o, ulam_error *err)
{
    int64_t n = M->nrows;
    if (!Mt || Mt->nrows != n || Mt->ncols != n || ulam_csr_nnz(Mt) != ulam_csr_nnz(M))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "Mt, the transpose of M (%lld x %lld)", (long long)n,
                          (long long)n);
    if (o->target < 0 || o->target >= n)
        return ulam__fail(err, ULAM_EINVAL, 0, o->target, "a target from 0 to %lld", (long long)n - 1);
    if (o->source < 0 || o->source >= n)
        return ulam__fail(err, ULAM_EINVAL, 0, o->source, "a source from 0 to %lld", (long long)n - 1);
    if (!(o->rmax <= 0 || isfinite(o->rmax)) || !(o->min_value <= 0 || isfinite(o->min_value)) ||
        o->max_push_ops < 0 || isnan(o->rmax) || isnan(o->min_value))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a finite rmax, a finite min_value and max_push_ops >= 0");
    return ULAM_OK;
}

/* The walks' options: adjoint on M' from s, scoring r. */
static ulam_walk_opts walk_opts(const ulam_bidir_opts *o)
{
    ulam_walk_opts wo = o->walk;
    wo.mode = ULAM_ADJOINT;
    wo.index = o->source;
    return wo;
}

/* Mean visits per walk from s on Mt, by PILOT walks on a seed of their own. */
static int pilot(const ulam_csr *Mt, const double *scores, const ulam_bidir_opts *o, double *visits,
                 int64_t *walks, ulam_error *err)
{
    ulam_walk_opts po = walk_opts(o);
    po.estimator = ULAM_COLLISION;
    po.max_walks = PILOT, po.max_seconds = 0, po.share = NULL, po.whole_kernel = 0;
    po.threads = 1; /* one partial block: a thread team would only be woken (same result for any count) */
    po.seed = o->walk.seed ^ UINT64_C(0x9e3779b97f4a7c15);
    ulam_walk_result r;
    int status = ulam_solve(Mt, scores, &po, &r, err);
    if (status) return status;
    *walks = r.walks;
    *visits = r.walks > 0 ? 1.0 + (double)r.steps / (double)r.walks : 1.0;
    return ULAM_OK;
}

/* Walks needed at threshold rmax for the target (the balance's model). */
static double predicted_walks(const ulam_bidir_opts *o, double rmax, double visits, double xhat)
{
    if (o->walk.rel_err <= 0 && o->walk.max_walks > 0) return (double)o->walk.max_walks;
    double e = o->walk.rel_err > 0 ? o->walk.rel_err : DEFAULT_REL_ERR;
    return rmax * visits / (e * e * xhat);
}

/* Push from t: to o->rmax, or halving rmax while the push's work is below the walks' predicted work. */
static int push(ulam_push *w, const ulam_bidir_opts *o, double visits, int64_t cap, double *walks)
{
    if (o->rmax > 0) {
        *walks = NAN; /* no balance, no prediction */
        return ulam_push_run(w, o->rmax, cap);
    }
    const double *p = ulam_push_estimates(w);
    int64_t n = ulam__push_matrix(w)->nrows;
    double delta = o->min_value > 0 ? o->min_value : 1.0 / (double)n;
    double rmax = 1.0;
    int status = ulam_push_run(w, rmax, cap); /* r = e_t: nothing to push yet */
    for (;;) {
        ulam_push_info pi;
        ulam_push_report(w, &pi);
        *walks = predicted_walks(o, rmax, visits, fmax(delta, fabs(p[o->source])));
        if (status || pi.support == 0 || *walks <= MIN_WALKS || (double)pi.ops >= *walks * visits * STEP_COST)
            return status; /* below MIN_WALKS more pushing saves no walks */
        rmax /= 2;
        status = ulam_push_run(w, rmax, cap);
    }
}

/* Walks on Mt from s scoring r until a stopping rule holds; the result in *wr.  The solver's
 * rel_err rule (the one of ulam_solve) applies to the whole estimate push_part + <r, x>. */
static int walk(const ulam_csr *Mt, const double *r, const ulam_bidir_opts *o, double push_part,
                ulam_walk_result *wr, ulam_error *err)
{
    ulam_walk_opts wo = walk_opts(o);
    wo.rel_err_offset = push_part;
    ulam_solver *sv = NULL;
    int status = ulam_solver_alloc(Mt, r, &wo, &sv, err);
    if (status) return status;
    while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
    ulam_solver_result(sv, wr);
    if (status) ulam_solver_error(sv, err);
    ulam_solver_free(sv);
    return status;
}

/* Estimate x_t of (I - M) x = e_s. */
int ulam_bidir_solve(ulam_push *w, const ulam_csr *Mt, const ulam_bidir_opts *o, ulam_bidir_result *res,
                     ulam_error *err)
{
    ulam__clear(err);
    if (!w || !o || !res) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a push workspace, options and a result");
    memset(res, 0, sizeof *res);
    const ulam_csr *M = ulam__push_matrix(w);
    int status = check_opts(M, Mt, o, err);
    if (status) return status;
    double t0 = ulam_now();
    int64_t cap = o->max_push_ops > 0 ? o->max_push_ops : 100 * ulam_csr_nnz(M) + 1000000;
    ulam_push_start(w, o->target);
    if (o->rmax <= 0 && (status = pilot(Mt, ulam_push_residuals(w), o, &res->mean_visits, &res->pilot_walks, err)))
        return status;
    status = push(w, o, res->mean_visits, cap, &res->predicted_walks);
    ulam_push_report(w, &res->push);
    if (status == ULAM_ENOCONV)
        return ulam__fail(err, status, 0, -1, "a push within %lld operations (is rho(|M|) < 1?)", (long long)cap);
    res->push_part = ulam_push_estimates(w)[o->source];
    if (res->push.support > 0 &&
        (status = walk(Mt, ulam_push_residuals(w), o, res->push_part, &res->walks, err)))
        return status;
    res->estimate = res->push_part + res->walks.estimate;
    res->std_error = res->walks.std_error;
    res->ci95[0] = res->push_part + res->walks.ci95[0];
    res->ci95[1] = res->push_part + res->walks.ci95[1];
    res->seconds = ulam_now() - t0;
    return ULAM_OK;
}
