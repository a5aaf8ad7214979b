/* One query of a batch on one analysis (ulam_analysis_query, include/ulam_report.h): the engine of
 * ulam solve --queries, so that any caller answers a query file's lines as the command line does.
 * An `I` line walks on the analysis' kept kernel for b; an `S I` line (b = e_S) is a bidirectional
 * estimate on the analysis' transpose, under M^T's guards, derived from M's or computed once. */
#include "ulam_report.h"
#include "internal.h"

/* M^T's guards into *gt from M's g (rho(|M^T|) = rho(|M|); the adjoint kernel of M^T is M's
 * forward one) when g has the forward radius at exponent 1, else computed on Mt; once: a gt with
 * its radii kept is left as it is.  0 or a status (err set). */
static int transpose_guard(const ulam_guard *g, const ulam_csr *Mt, double q, ulam_guard *gt, ulam_error *err)
{
    if (gt->computed & ULAM_GUARD_ADJOINT) return 0;
    if (g && (g->computed & ULAM_GUARD_FORWARD) && g->kernel_alpha == 1.0) {
        *gt = *g;
        gt->hat[ULAM_ADJOINT] = g->hat[ULAM_FORWARD], gt->hat[ULAM_FORWARD] = g->hat[ULAM_ADJOINT];
        gt->verdict_hat[ULAM_ADJOINT] = g->verdict_hat[ULAM_FORWARD];
        gt->verdict_hat[ULAM_FORWARD] = g->verdict_hat[ULAM_ADJOINT];
        gt->computed = ULAM_GUARD_ABS | ULAM_GUARD_ADJOINT | ((g->computed & ULAM_GUARD_ADJOINT) ? ULAM_GUARD_FORWARD : 0);
        return 0;
    }
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_ADJOINT;
    return ulam_guard_check(Mt, q, &go, gt, err);
}

/* The walks o names on the analysis' kept kernel, to their end (ulam_analysis_solver): the status,
 * r filled (as far as they went) and err on failure. */
static int walks_on(ulam_analysis *an, const double *b, const ulam_walk_opts *o, ulam_walk_result *r, ulam_error *err)
{
    ulam_solver *sv = NULL;
    int status = ulam_analysis_solver(an, b, o, &sv, err);
    while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
    if (sv) ulam_solver_result(sv, r);
    if (status && sv) ulam_solver_error(sv, err);
    ulam_solver_free(sv);
    return status;
}

/* See ulam_report.h. */
int ulam_analysis_query(ulam_analysis *a, const double *b, const ulam_walk_opts *o, ulam_guard *gt,
                        ulam_query_report *q, int *interrupted, ulam_error *err)
{
    ulam_error own;
    if (!err) err = &own; /* the transpose's status is read from it */
    ulam__clear(err);
    if (!a || !o || !q || !interrupted || (q->source < 0 ? !b : !gt))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis, options, a report, b (or M^T's guards) and a flag");
    double t0 = ulam_now();
    int status;
    *interrupted = 0;
    q->seed = o->exec.seed;
    if (q->source < 0) {
        ulam_walk_opts w = *o;
        w.query.index = q->index;
        ulam_walk_result r;
        if (!(status = walks_on(a, b, &w, &r, err))) {
            q->estimate = r.estimate, q->std_error = r.std_error, q->ci95[0] = r.ci95[0], q->ci95[1] = r.ci95[1];
            q->rel_err_met = r.rel_err_met, q->walks = r.walks, *interrupted = r.interrupted;
        }
    } else {
        const ulam_csr *Mt = ulam_analysis_transpose(a, err);
        if (!Mt) return err->status;
        if ((status = transpose_guard(o->policy.guard, Mt, o->kernel.continue_q, gt, err))) return status;
        ulam_bidir_opts bo = ulam_bidir_defaults();
        bo.walk = *o;
        bo.walk.policy.guard = gt;
        bo.source = q->source, bo.target = q->index, bo.reach_all = 1, bo.keep_kernel = 1;
        ulam_bidir_result r;
        if (!(status = ulam_analysis_bidir(a, &bo, &r, err))) { /* its transpose, push workspace and plans */
            q->estimate = r.estimate, q->std_error = r.std_error, q->ci95[0] = r.ci95[0], q->ci95[1] = r.ci95[1];
            q->rel_err_met = r.walks.rel_err_met || r.walks.walks == 0, q->walks = r.walks.walks;
            *interrupted = r.walks.interrupted;
        }
    }
    q->seconds = ulam_now() - t0;
    return status;
}
