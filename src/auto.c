/* Choosing the walk method: mode x estimator x continuation, screened by the guards and piloted.
 *
 * A candidate qualifies when the guards certify its variance finite: the Collatz-Wielandt upper
 * bounds of rho(|M|) and of rho(M^) of its own kernel are below 1 (every estimator's second moment
 * is a series in M^, src/guard.c).  Each qualifying candidate runs a short pilot on a seed of its
 * own; the least variance per walk x seconds per walk wins (the walks a target needs are
 * proportional to the variance, each costs its seconds).  The estimate then comes from fresh walks
 * on the caller's seed: the choice is a function of the pilots alone, which are independent of
 * those walks, so it cannot bias them. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const uint64_t PILOT_SEED = UINT64_C(0x5851f42d4c957f2d);

/* The default options. */
ulam_auto_opts ulam_auto_defaults(void)
{
    return (ulam_auto_opts){.continue_q = 0.9, .pilot_walks = 2048, .pilot_seconds = 0.02};
}

/* Run one candidate's pilot; its status (ULAM_OK or the solver's refusal).  Seconds per walk are
 * the least over the pilot's rounds (the first pays for building the rows it reaches and for
 * starting threads, which a long run amortises; the least is also the one a busy machine
 * disturbed least). */
static int pilot(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao, int k,
                 ulam_auto_candidate *c)
{
    ulam_walk_opts o = *base;
    o.mode = c->mode, o.estimator = c->estimator, o.continue_q = c->continue_q;
    o.max_walks = ao->pilot_walks, o.rel_err = 0, o.max_seconds = ao->pilot_seconds;
    o.seed = base->seed ^ (PILOT_SEED + (uint64_t)k);
    ulam_solver *sv = NULL;
    int status = ulam_solver_alloc(M, b, &o, &sv, NULL);
    if (status) return status;
    ulam_walk_result r = {0};
    double tau = INFINITY;
    while (!status && !ulam_solver_done(sv)) {
        double s0 = r.seconds;
        int64_t w0 = r.walks;
        status = ulam_solver_iterate(sv);
        ulam_solver_result(sv, &r);
        if (r.walks > w0) tau = fmin(tau, (r.seconds - s0) / (double)(r.walks - w0));
    }
    ulam_solver_free(sv);
    if (status) return status;
    c->pilot_walks = r.walks;
    c->estimate = r.estimate, c->variance = r.variance, c->seconds_per_walk = tau;
    /* a pilot whose walks all scored the same has seen nothing of the spread: no cost */
    c->cost = c->variance > 0 ? c->variance * tau : INFINITY;
    if (base->rel_err > 0 && c->estimate != 0 && c->variance > 0) {
        double e = base->rel_err * fabs(c->estimate);
        c->predicted_seconds = fmax(1000.0, c->variance / (e * e)) * tau;
    }
    return ULAM_OK;
}

/* Every process takes rank 0's choice. */
static int agree(const ulam_walk_opts *base, int *chosen)
{
    const ulam_share *sh = base->share;
    if (!sh || sh->nranks <= 1) return ULAM_OK;
    void *all = NULL;
    size_t total = 0;
    if (sh->allgather(sh->ctx, chosen, sizeof *chosen, &all, &total) || total < sizeof *chosen) {
        free(all);
        return ULAM_EIO;
    }
    memcpy(chosen, all, sizeof *chosen);
    free(all);
    return ULAM_OK;
}

/* Screen, pilot and choose. */
int ulam_auto_choose(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                     ulam_auto_result *res, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !b || !base || !res) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, b, options and a result");
    ulam_auto_opts a = ao ? *ao : ulam_auto_defaults();
    if (!(a.continue_q > 0 && a.continue_q < 1) || a.pilot_walks < 1 || !(a.pilot_seconds >= 0))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a fixed continuation in (0, 1), pilot walks >= 1, pilot seconds >= 0");
    memset(res, 0, sizeof *res);
    res->chosen = res->closest = -1;
    double t0 = ulam_now();
    double qs[2] = {a.pin_continue ? base->continue_q : 0.0, a.continue_q};
    int nq = a.pin_continue ? 1 : 2;
    for (int iq = 0; iq < nq; iq++) {
        ulam_guard g;
        int status = ulam_guard_check(M, qs[iq], NULL, &g, err);
        if (status) return status;
        res->abs = g.abs;
        for (int mode = ULAM_ADJOINT; mode <= ULAM_FORWARD; mode++)
            for (int est = ULAM_COLLISION; est <= ULAM_EXPECTED; est++) {
                if ((a.pin_mode && mode != base->mode) || (a.pin_estimator && est != base->estimator)) continue;
                ulam_auto_candidate *c = &res->cand[res->ncand++];
                *c = (ulam_auto_candidate){.mode = mode, .estimator = est, .continue_q = qs[iq], .hat = g.hat[mode],
                                           .cost = INFINITY, .predicted_seconds = NAN};
                c->certified = g.abs.upper < 1 && g.hat[mode].upper < 1;
            }
    }
    for (int k = 0; k < res->ncand; k++) {
        ulam_auto_candidate *c = &res->cand[k];
        if (res->closest < 0 || c->hat.rho < res->cand[res->closest].hat.rho) res->closest = k;
        if (!c->certified) continue;
        c->status = pilot(M, b, base, &a, k, c);
        if (c->status == ULAM_ENOMEM) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a pilot");
        if (!c->status && isfinite(c->cost) && (res->chosen < 0 || c->cost < res->cand[res->chosen].cost))
            res->chosen = k;
    }
    for (int k = 0; k < res->ncand && res->chosen < 0; k++) /* every pilot without spread: the fastest */
        if (res->cand[k].pilot_walks && (res->chosen < 0 || res->cand[k].seconds_per_walk < res->cand[res->chosen].seconds_per_walk))
            res->chosen = k;
    if (agree(base, &res->chosen)) return ulam__fail(err, ULAM_EIO, 0, -1, "the processes to agree on a choice");
    res->seconds = ulam_now() - t0;
    return ULAM_OK;
}
