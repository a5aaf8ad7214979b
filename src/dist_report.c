/* A partitioned run's answer in words (ulam_dist_fprint in ulam_dist.h): the lines `ulam solve
 * --partition` prints, to the caller's FILE *. */
#include "part.h"
#include "report.h"

#include <math.h>
#include <stdio.h>

/* "x[i]  estimate +- stderr (95% CI lo .. hi)" without a newline (i 1-based; ci NULL: forward
 * walks, whose components have no certified range on a partition; the variance is certified
 * finite, rho < 1). */
static void estimate_fprint(FILE *f, int64_t i, double est, double se, double rho, const ulam_dist_ci *ci, int ends)
{
    const char *none = ends ? "no walk reached it: the estimate is the push's part, the interval its end count's"
                            : "no walk reached it: the push's part alone";
    fprintf(f, "x[%lld]%*s%.10g", (long long)i, ulam__report_pad("x", i, 16), "", est);
    int d = ci ? ulam__report_ci_digits(ci->lo, ci->hi) : 0;
    if (ci && ci->lo == ci->hi && ci->lo == est)
        fprintf(f, " +- 0 (95%% CI %.10g .. %.10g: %s)", ci->lo, ci->hi, est == 0 ? "b is 0, x is exactly 0" : "exact");
    else if (!(rho < 1.0)) fprintf(f, " (no standard error: rho(M^) is not certified below 1)");
    else if (isnan(se) && ci && isfinite(ci->lo))
        fprintf(f, " (95%% CI %.*g .. %.*g; %s)", d, ci->lo, d, ci->hi, none);
    else if (isnan(se)) fprintf(f, " (%s)", none);
    else if (ci && isfinite(ci->lo)) ulam__report_pm_fprint(f, est, se, ci->lo, ci->hi);
    else if (ci) fprintf(f, " +- %.3g (standard error; no certified interval: no certified u < 1 for the walks' length tail or second moment)", se);
    else fprintf(f, " +- %.3g (standard error; no certified interval for forward walks on a partition)", se);
}

/* The answer lines above the summary: each query's, single source's (or forward mode's) top table,
 * MCSA's, the push's and the bound. */
static void answers_fprint(FILE *f, const ulam_dist_ask *a, const ulam_dist_answer *s, const char *queries,
                           const long *lines, const char *out, int verbosity)
{
    for (int64_t k = 0; queries && k < a->nq; k++) {
        estimate_fprint(f, a->index[k] + 1, s->res[k].estimate, s->res[k].std_error, s->rho, &s->ci[k], 0);
        uint64_t own = a->nq > 1 ? ulam_rng_substream(a->o.seed, ULAM_STREAM_QUERY, (uint64_t)k) : a->o.seed; /* docs/streams.md */
        if (s->ci[k].met) fprintf(f, "  %lld walks,", (long long)s->res[k].walks);
        fprintf(f, "  line %ld, seed %llu\n", lines[k], (unsigned long long)own);
    }
    for (int64_t j = 0; (a->mode == ULAM_DIST_SOURCE || a->mode == ULAM_DIST_FORWARD) && j < s->ntop; j++) {
        const ulam_dist_top *t = &s->tops[j];
        ulam_dist_ci ci = {t->lo, t->hi, INFINITY, 0.0, 0};
        estimate_fprint(f, t->i + 1, t->x, t->se, s->rho, isfinite(ci.lo) ? &ci : NULL, s->terminal), fputc('\n', f);
    }
    if (a->mode == ULAM_DIST_MCSA)
        fprintf(f, "x               %lld components by MCSA%s%s\nmcsa            %d iterations, residual %.3g of max |b| "
                   "(target %.3g)\n", (long long)s->n, out ? ", written to " : "", out ? out : "", s->iterations,
                s->residual, a->tol);
    if (a->mode == ULAM_DIST_SOURCE && verbosity >= 0)
        fprintf(f, "push            %d products with M, max |r| %.3g left to the walks\n", s->iterations, s->residual);
    if (a->mode == ULAM_DIST_MCSA || (a->mode == ULAM_DIST_FORWARD && a->bound)) {
        if (isfinite(s->worst))
            fprintf(f, "bound           every |x_i - x*_i| <= %.3g (certified from x's residual and rho(|M|) < 1)\n", s->worst);
        else fprintf(f, "bound           none certified (power iteration did not certify rho(|M|) below 1)\n");
    }
}

/* The summary below the answers. */
static void summary_fprint(FILE *f, const ulam_dist_ask *a, const ulam_dist_answer *s, const ulam_comm *c,
                           const char *queries, const char *out, double seconds, int verbosity)
{
    const ulam_dist_result *r = &s->r;
    int adjoint = a->mode == ULAM_DIST_ADJOINT, forward = a->mode == ULAM_DIST_FORWARD, nranks = c->nranks;
    int64_t nq = adjoint ? a->nq : 1, met = 0;
    const ulam_dist_ci *ci = adjoint || (forward && a->index && a->rel_err > 0) ? s->ci : NULL; /* forward: x_I's */
    if (queries) {
        if (verbosity >= 0) fprintf(f, "queries         %s, each above (walks below: each query's)\n", queries);
    } else if (adjoint || (forward && a->index)) /* forward: the watched component's line (its sequence) */
        estimate_fprint(f, a->index[0] + 1, r->estimate, r->std_error, s->rho, adjoint ? ci : s->ci, 0), fputc('\n', f);
    for (int64_t k = 0; ci && k < nq; k++) met += ci[k].met;
    if (a->rel_err > 0 && forward && met == nq) /* forward walks have no stop rule: a verdict after them */
        fprintf(f, "rel-err         met (target %.3g; judged on the interval after --walks %lld: forward walks have no "
                   "stop rule)\n", a->rel_err, (long long)a->o.walks);
    else if (a->rel_err > 0 && forward)
        fprintf(f, "rel-err         NOT met (target %.3g) in --walks %lld (judged on the interval after them: forward walks "
                   "have no stop rule)%s\n", a->rel_err, (long long)a->o.walks,
                ci && isfinite(ci[0].lo) ? "" : "; no certified interval: no certified u < 1 for the walks' length tail or "
                                                "second moment");
    else if (a->rel_err > 0 && met == nq)
        fprintf(f, "rel-err         met (target %.3g)%s\n", a->rel_err, queries ? " by every query" : "");
    else if (a->rel_err > 0)
        fprintf(f, "rel-err         NOT met (target %.3g) by %lld of %lld quer%s in --walks %lld%s\n", a->rel_err,
                (long long)(nq - met), (long long)nq, nq == 1 ? "y" : "ies", (long long)a->o.walks,
                ci && isfinite(ci[0].lo) ? "" : " (no certified interval: no certified u < 1 for the walks' length tail or second moment)");
    else if (forward) fprintf(f, "x               %lld components by forward walks%s%s\n", (long long)s->n, out ? ", written to " : "", out ? out : "");
    if (verbosity < 0) return;
    fprintf(f, "method          %s%s %s walks on %d rank%s, rows split by entries",
            a->mode == ULAM_DIST_MCSA ? "MCSA with " : a->mode == ULAM_DIST_SOURCE ? "push and " : "",
            adjoint ? "adjoint" : "forward", "collision", nranks, nranks == 1 ? "" : "s");
    if (s->terminal) fprintf(f, " (each interval: the walks' end count's 95%% interval and the certified range, overlapped)");
    if (c->sets > 1) fprintf(f, " within each of %d sets", c->sets);
    fprintf(f, "\n");
    if (s->rho < 1.0) fprintf(f, "variance        finite (rho(M^) <= %.6g, certified)\n", s->rho);
    else if (!adjoint) fprintf(f, "variance        not certified finite (rho(M^) bound %.4g): no error bar can be trusted\n", s->rho);
    fprintf(f, "walks           %lld (%lld steps; %lld cut at --max-steps)\n", (long long)r->walks, (long long)r->steps,
            (long long)r->cut);
    fprintf(f, "migration       %.4g of steps crossed ranks, %.3g bytes a step, %lld rounds\n",
            r->steps ? (double)r->crossings / (double)r->steps : 0.0, r->steps ? (double)r->bytes / (double)r->steps : 0.0,
            (long long)r->rounds);
    fprintf(f, "seconds         %.3g in all\n", seconds);
    if (verbosity < 1) return;
    fprintf(f, "ranks           rows");
    for (int k = 0; k < nranks; k++) fprintf(f, " %lld", (long long)s->ranks[k]);
    fprintf(f, "; peak RSS MiB");
    for (int k = 0; k < nranks; k++) fprintf(f, " %.1f", (double)s->ranks[nranks + k] / 1024.0);
    fprintf(f, "\n");
}

/* A partitioned run's answer in words (see ulam_dist.h). */
int ulam_dist_fprint(FILE *f, const ulam_dist_ask *ask, const ulam_dist_answer *ans, const ulam_comm *comm,
                     const char *queries, const long *lines, const char *out, double seconds, int verbosity)
{
    if (!f || !ask || !ans || !comm || (queries && !lines)) return ULAM_EINVAL;
    answers_fprint(f, ask, ans, queries, lines, out, verbosity);
    summary_fprint(f, ask, ans, comm, queries, out, seconds, verbosity);
    return ferror(f) ? ULAM_EIO : ULAM_OK;
}
