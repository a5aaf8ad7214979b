/* Outer iterations that stop on the exact residual: Richardson, Gauss-Seidel, Halton's
 * sequential Monte Carlo and Monte Carlo Synthetic Acceleration (MCSA).
 *
 * The Monte Carlo methods feed the current residual r to forward walks, which estimate every
 * component of the correction delta ~ (I - M)^-1 r at once (the method Benzi, Evans,
 * Hamilton, Lupo Pasini and Slattery call "adjoint" in "Analysis of Monte Carlo accelerated
 * iterative methods for sparse linear systems", Numer. Linear Algebra Appl. 2017).  One walk
 * solver serves every iteration: a forward kernel does not depend on the source, so each
 * correction restarts it on the new residual with the seed of that iteration.  Its rounds are
 * the batches of the adaptive rule: walk until ||stderr||_1 / ||delta||_1 < eps1.  The walks
 * are bit-identical for any thread count, and so is everything else here (sequential sums). */
#include "check.h"
#include "defaults.h"
#include "guard.h"
#include "solve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Stall windows: iterations without a new smallest residual, with and without walks. */
enum { STALL_WALKS = 5, STALL_PLAIN = 100 };

/* A correction that raises the residual is rejected and its walks go on (the rejected ones
 * still count: they are unbiased) to more histories, the way the adaptive check of Benzi et al.
 * grows them by 10x.  Its noise falls as 1 / sqrt(histories), so a correction of N histories
 * that left the residual RATIO times what it was fed needs about N (RATIO / CONTRACT)^2 to
 * make it CONTRACT times smaller; a redo walks at least GROW_MIN N.  When that count exceeds
 * GROW_MAX times the histories the eps1 rule asked for (two of the paper's 10x checks) or the
 * history cap, the iteration cannot be made to contract at this price and the run stops
 * (ULAM_ESTALL, with the count it would need): bounded time, never a worse residual. */
#define CONTRACT 0.5
#define GROW_MIN 4.0
#define GROW_MAX 100.0

struct ulam_outer {
    ulam_outer_opts o;
    const ulam_csr *M;
    const double *b;
    int64_t n;
    double *x, *r, *y, *delta, *se; /* iterate, residual, M x, correction, its stderr */
    double *rf, *x0;  /* the residual the walks are fed, the iterate before their correction */
    double bnorm, residual, best;
    ulam_solver *sv; /* forward walks, built at the first correction */
    int iter, since_best, stall, done, converged, status;
    int rejected;              /* corrections rejected (each redone with more histories) */
    int64_t floor;             /* histories the next correction walks at least (0: eps1 alone) */
    int64_t need, took;        /* when a correction could not contract: the histories it would
                                  need, the histories it took */
    double ratio;              /* and the residual ratio it left */
    ulam_guard g;              /* the forward walks' guards, checked at alloc */
};

/* The defaults. */
ulam_outer_opts ulam__outer_defaults(void)
{
    ulam_outer_opts o = {.method = ULAM_MCSA, .tol = 1e-8, .eps1 = 0.1, .max_histories = 100000000};
    o.walk = ulam_walk_defaults();
    o.walk.mode = ULAM_FORWARD;
    o.walk.estimator = ULAM_EXPECTED;
    return o;
}

/* Nonzero when the method walks. */
static int walks(int method)
{
    return method == ULAM_SEQUENTIAL || method == ULAM_MCSA;
}

/* Free; accepts NULL. */
ulam_outer *ulam_outer_free(ulam_outer *s)
{
    if (!s) return NULL;
    ulam_solver_free(s->sv);
    free(s->x), free(s->r), free(s->y), free(s->delta), free(s->se), free(s->rf), free(s->x0);
    free(s);
    return NULL;
}

/* Euclidean norm, summed in index order. */
static double norm2(const double *v, int64_t n)
{
    double s = 0.0;
    for (int64_t i = 0; i < n; i++) s += v[i] * v[i];
    return sqrt(s);
}

/* r = b - (I - M) x, exactly (a sparse product); returns ||r||_2 / ||b||_2. */
static double residual(ulam_outer *s)
{
    ulam_csr_matvec(s->M, 0, s->x, s->y);
    for (int64_t i = 0; i < s->n; i++) s->r[i] = s->b[i] - s->x[i] + s->y[i];
    return norm2(s->r, s->n) / s->bnorm;
}

/* Check the options. */
static int check(const ulam_csr *M, const double *b, const ulam_outer_opts *o, ulam_error *err)
{
    if (M->nrows != M->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    int bad = ulam__csr_check_structure(M, err); /* src/check.c: M, and the walks' options */
    if (bad || (walks(o->method) && (bad = ulam__walk_opts_check(&o->walk, err)))) return bad;
    if (o->method < ULAM_RICHARDSON || o->method > ULAM_MCSA)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "method richardson, gauss-seidel, sequential or mcsa");
    if (!(o->tol > 0 && o->tol < 1)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tolerance in (0, 1)");
    if (o->max_iter < 0 || o->stall < 0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "max_iter >= 1 and stall >= 0");
    if (walks(o->method) && !(o->eps1 > 0 && o->eps1 < 1))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "an adaptive threshold eps1 in (0, 1)");
    if (walks(o->method) && o->max_histories < 1)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a history cap >= 1");
    if (norm2(b, M->nrows) == 0.0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "b != 0 (x = 0 solves b = 0)");
    return ULAM_OK;
}

/* The forward walks' guards: o->walk.guard when it holds rho(|M|) and the forward rho(M^) of
 * this kernel, else computed (stopped once certified). */
static int take_guard(const ulam_csr *M, const ulam_walk_opts *w, ulam_guard *g, ulam_error *err)
{
    int need = ULAM_GUARD_ABS | ULAM_GUARD_FORWARD;
    if (ulam__guard_fits(w->policy.guard, w->kernel.continue_q, w->kernel.kernel_alpha, need)) { /* src/guard.c */
        *g = *w->policy.guard;
        return ULAM_OK;
    }
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = need;
    go.kernel_alpha = w->kernel.kernel_alpha;
    return ulam_guard_check(M, w->kernel.continue_q, &go, g, err);
}

/* Refuse walks whose variance is not certified finite (unknown: unless assume_finite): no
 * history count makes such a correction reliable, and the eps1 rule would walk to the cap. */
static int check_variance(const ulam_guard *g, const ulam_walk_opts *w, ulam_error *err)
{
    int finite = ulam_guard_variance(g, ULAM_FORWARD);
    if (finite == 1 || (finite < 0 && w->policy.assume_finite)) return ULAM_OK;
    const ulam_power *h = &g->hat[ULAM_FORWARD];
    return ulam__fail(err, ULAM_EINFVAR, 0, -1,
                      "a finite variance for the correction walks: rho(M^) of the forward kernel is in [%.4g, %.4g] "
                      "(%s), so no number of histories makes a correction reliable (a Krylov method, gmres or cg, "
                      "needs no walks)", h->lower, h->upper,
                      finite == 0 ? ">= 1: infinite" : "straddles 1: unknown; assume_finite walks anyway");
}

/* Prepare the iteration. */
int ulam_outer_alloc(const ulam_csr *M, const double *b, const ulam_outer_opts *opts, ulam_outer **out,
                     ulam_error *err)
{
    ulam__clear(err);
    if (!M || !b || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, b and an output");
    *out = NULL;
    ulam_outer_opts o = opts ? *opts : ulam_outer_defaults();
    if (o.max_iter == 0) o.max_iter = walks(o.method) ? 1000 : 100000;
    int status = check(M, b, &o, err);
    if (status) return status;
    ulam_guard g = {0};
    if (walks(o.method) && ((status = take_guard(M, &o.walk, &g, err)) || (status = check_variance(&g, &o.walk, err))))
        return status;
    ulam_outer *s = calloc(1, sizeof *s);
    size_t n = (size_t)M->nrows;
    if (!s) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the iteration");
    s->o = o, s->M = M, s->b = b, s->n = M->nrows, s->g = g;
    if (walks(o.method)) s->o.walk.policy.guard = &s->g; /* the walks' solver takes these verdicts */
    s->x = ulam__calloc(n, sizeof *s->x), s->r = ulam__malloc(n, sizeof *s->r);
    s->y = ulam__malloc(n, sizeof *s->y);
    if (walks(o.method)) {
        s->delta = ulam__malloc(n, sizeof *s->delta), s->se = ulam__malloc(n, sizeof *s->se);
        s->rf = ulam__malloc(n, sizeof *s->rf), s->x0 = ulam__malloc(n, sizeof *s->x0);
    }
    if (!s->x || !s->r || !s->y || (walks(o.method) && (!s->delta || !s->se || !s->rf || !s->x0))) {
        ulam_outer_free(s);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the iteration's vectors");
    }
    s->bnorm = norm2(b, s->n);
    s->residual = s->best = residual(s); /* 1: x = 0 */
    s->stall = o.stall ? o.stall : walks(o.method) ? STALL_WALKS : STALL_PLAIN;
    *out = s;
    return ULAM_OK;
}

/* ||stderr||_1 / ||delta||_1 of the walks so far, into delta and se. */
static double rel_sd(ulam_outer *s)
{
    ulam_solver_vectors(s->sv, s->delta, s->se);
    double a = 0.0, d = 0.0;
    for (int64_t i = 0; i < s->n; i++) a += s->se[i], d += fabs(s->delta[i]);
    return d > 0 ? a / d : INFINITY;
}

/* Walk until ||stderr||_1 / ||delta||_1 < eps1 with at least atleast histories (or the
 * solver ends), the correction so far into delta; returns the status, *rsd the rule's value. */
static int walk_until(ulam_outer *s, int64_t atleast, double *rsd)
{
    int status = ULAM_OK;
    ulam_walk_result wr;
    while (!status && !ulam_solver_done(s->sv)) {
        status = ulam_solver_iterate(s->sv);
        if (status) break;
        *rsd = rel_sd(s);
        ulam_solver_result(s->sv, &wr);
        if (*rsd < s->o.eps1 && wr.walks >= atleast) break;
    }
    return status;
}

/* delta ~ (I - M)^-1 r by forward walks in batches until the eps1 rule holds; x += delta when
 * it lowers the residual, else the walks go on (see CONTRACT) or the run stops. */
static int correct(ulam_outer *s, double fed, ulam_outer_step *st)
{
    ulam_walk_opts w = s->o.walk;
    w.mode = ULAM_FORWARD, w.query.index = 0;
    w.stop.max_walks = s->o.max_histories, w.stop.rel_err = 0.0, w.stop.max_seconds = 0.0;
    w.exec.seed = ulam_rng_substream(s->o.walk.exec.seed, ULAM_STREAM_ITERATION, (uint64_t)s->iter); /* streams.md */
    memcpy(s->rf, s->r, (size_t)s->n * sizeof *s->rf); /* the walks' source: r is overwritten by trials */
    memcpy(s->x0, s->x, (size_t)s->n * sizeof *s->x0);
    int status = s->sv ? ulam__solver_restart(s->sv, s->rf, w.exec.seed, NULL)
                       : ulam_solver_alloc(s->M, s->rf, &w, &s->sv, NULL);
    if (status) return status;
    double rsd = INFINITY, first = 0;
    int64_t atleast = s->floor;
    ulam_walk_result wr;
    for (;;) {
        status = walk_until(s, atleast, &rsd);
        ulam_solver_result(s->sv, &wr);
        if (status) break;
        if (!first) first = (double)wr.walks; /* what the eps1 rule asked for */
        for (int64_t i = 0; i < s->n; i++) s->x[i] = s->x0[i] + s->delta[i];
        double ratio = residual(s) / fed;
        if (ratio < 1.0) { /* accepted; a grown count is where the next correction starts */
            s->floor = atleast > s->floor ? (int64_t)wr.walks : s->floor;
            break;
        }
        memcpy(s->x, s->x0, (size_t)s->n * sizeof *s->x); /* rejected */
        s->rejected++;
        double need = (double)wr.walks * fmax((ratio / CONTRACT) * (ratio / CONTRACT), GROW_MIN);
        if (wr.interrupted || ulam_solver_done(s->sv) || !isfinite(ratio) || need > GROW_MAX * first ||
            need > (double)s->o.max_histories) {
            s->need = isfinite(need) ? (int64_t)fmin(need, 9e18) : INT64_MAX, s->took = wr.walks, s->ratio = ratio;
            residual(s);
            if (!wr.interrupted) status = ULAM_ESTALL;
            break;
        }
        atleast = (int64_t)need;
    }
    st->histories = wr.walks, st->steps = wr.steps, st->cut = wr.cut;
    st->rel_sd = rsd, st->walk_seconds = wr.seconds;
    if (!status && wr.interrupted) s->done = 1; /* the correction so far is still a correction */
    return status;
}

/* Stop the run with status. */
static int finish(ulam_outer *s, int status)
{
    s->done = 1;
    s->status = status;
    return status;
}

/* One iteration. */
int ulam_outer_iterate(ulam_outer *s, ulam_outer_step *step)
{
    ulam_outer_step st = {0};
    if (!s) return ULAM_EINVAL;
    if (s->done) {
        if (step) *step = st;
        return s->status;
    }
    double t0 = ulam_now();
    int status = ULAM_OK;
    st.iteration = ++s->iter;
    switch (s->o.method) {
    case ULAM_RICHARDSON:
        for (int64_t i = 0; i < s->n; i++) s->x[i] += s->r[i]; /* x + r = M x + b */
        break;
    case ULAM_GAUSS_SEIDEL:
        ulam__gauss_seidel_sweep(s->M, s->b, s->x);
        break;
    case ULAM_MCSA:
        for (int64_t i = 0; i < s->n; i++) s->x[i] += s->r[i];
        status = correct(s, residual(s), &st);
        break;
    default:
        status = correct(s, s->residual, &st);
    }
    if (status != ULAM_ENOMEM) s->residual = residual(s);
    st.residual = s->residual;
    st.seconds = ulam_now() - t0;
    if (step) *step = st;
    if (status) return finish(s, status);
    if (!isfinite(s->residual)) return finish(s, ULAM_ENONFINITE);
    if (s->residual <= s->o.tol) {
        s->converged = 1;
        return finish(s, ULAM_OK);
    }
    if (s->residual < s->best) s->best = s->residual, s->since_best = 0;
    else if (++s->since_best >= s->stall) return finish(s, ULAM_ESTALL);
    if (s->iter >= s->o.max_iter) return finish(s, ULAM_ENOCONV);
    return ULAM_OK;
}

/* Nonzero once the run has ended. */
int ulam_outer_done(const ulam_outer *s)
{
    return !s || s->done;
}

/* Where s stands: its iterate, convergence and rejected corrections. */
void ulam_outer_get_info(const ulam_outer *s, ulam_outer_info *info)
{
    if (!info) return;
    *info = (ulam_outer_info){0};
    if (s) info->x = s->x, info->converged = s->converged, info->rejected = s->rejected;
}

/* Iterate until done. */
int ulam_outer_solve(const ulam_csr *M, const double *b, const ulam_outer_opts *opts, double *x,
                     ulam_outer_step *steps, int max_steps, int *nsteps, ulam_error *err)
{
    ulam_outer *s = NULL;
    int status = ulam_outer_alloc(M, b, opts, &s, err), k = 0;
    if (status) return status;
    while (!ulam_outer_done(s)) {
        ulam_outer_step st;
        status = ulam_outer_iterate(s, &st);
        if (steps && k < max_steps) steps[k] = st;
        k++;
    }
    if (x) memcpy(x, s->x, (size_t)s->n * sizeof *x);
    if (nsteps) *nsteps = k;
    ulam_outer_error(s, err);
    ulam_outer_free(s);
    return status;
}

/* Why the run ended, into err; returns its status. */
int ulam_outer_error(const ulam_outer *s, ulam_error *err)
{
    ulam__clear(err);
    if (!s) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an iteration");
    int status = s->status;
    if (status == ULAM_ESTALL && s->need)
        ulam__fail(err, status, 0, -1, "a correction that lowers the residual: iteration %d's made it %.3gx with %lld "
                   "histories; its variance asks ~%.2g (> %gx the eps1 rule's or the cap %lld), so walks "
                   "cannot make it contract (gmres or cg need none)", s->iter, s->ratio, (long long)s->took,
                   (double)s->need, GROW_MAX, (long long)s->o.max_histories);
    else if (status == ULAM_ESTALL)
        ulam__fail(err, status, 0, -1, "a residual that keeps decreasing (it made no new low for %d "
                   "iterations at %.3g: is rho(M^) < 1 and eps1 small enough?)", s->stall, s->best);
    else if (status == ULAM_ENOCONV)
        ulam__fail(err, status, 0, -1, "convergence within %d iterations (residual %.3g)", s->o.max_iter,
                   s->residual);
    else if (status == ULAM_ENONFINITE)
        ulam__fail(err, status, 0, -1, "a finite residual and finite walk scores");
    else if (status)
        ulam__fail(err, status, 0, -1, "memory for the walks");
    return status;
}
