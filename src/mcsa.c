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
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Stall windows: iterations without a new smallest residual, with and without walks. */
enum { STALL_WALKS = 5, STALL_PLAIN = 100 };

struct ulam_outer {
    ulam_outer_opts o;
    const ulam_csr *M;
    const double *b;
    int64_t n;
    double *x, *r, *y, *delta, *se; /* iterate, residual, M x, correction, its stderr */
    double bnorm, residual, best;
    ulam_solver *sv; /* forward walks, built at the first correction */
    int iter, since_best, stall, done, converged, status;
};

/* The defaults. */
ulam_outer_opts ulam_outer_defaults(void)
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
    free(s->x), free(s->r), free(s->y), free(s->delta), free(s->se);
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
    ulam_outer *s = calloc(1, sizeof *s);
    size_t n = (size_t)M->nrows;
    if (!s) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the iteration");
    s->o = o, s->M = M, s->b = b, s->n = M->nrows;
    s->x = ulam__calloc(n, sizeof *s->x), s->r = ulam__malloc(n, sizeof *s->r);
    s->y = ulam__malloc(n, sizeof *s->y);
    if (walks(o.method)) s->delta = ulam__malloc(n, sizeof *s->delta), s->se = ulam__malloc(n, sizeof *s->se);
    if (!s->x || !s->r || !s->y || (walks(o.method) && (!s->delta || !s->se))) {
        ulam_outer_free(s);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the iteration's vectors");
    }
    s->bnorm = norm2(b, s->n);
    s->residual = s->best = residual(s); /* 1: x = 0 */
    s->stall = o.stall ? o.stall : walks(o.method) ? STALL_WALKS : STALL_PLAIN;
    *out = s;
    return ULAM_OK;
}

/* The seed of iteration l's walks: drawn from the stream (seed, l). */
static uint64_t iteration_seed(uint64_t seed, int l)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, (uint64_t)l);
    return ulam_rng_next(&r);
}

/* ||stderr||_1 / ||delta||_1 of the walks so far, into delta and se. */
static double rel_sd(ulam_outer *s)
{
    ulam_solver_vectors(s->sv, s->delta, s->se);
    double a = 0.0, d = 0.0;
    for (int64_t i = 0; i < s->n; i++) a += s->se[i], d += fabs(s->delta[i]);
    return d > 0 ? a / d : INFINITY;
}

/* delta ~ (I - M)^-1 r by forward walks in batches until the rule holds; x += delta. */
static int correct(ulam_outer *s, ulam_outer_step *st)
{
    ulam_walk_opts w = s->o.walk;
    w.mode = ULAM_FORWARD, w.index = 0;
    w.max_walks = s->o.max_histories, w.rel_err = 0.0, w.max_seconds = 0.0;
    w.seed = iteration_seed(s->o.walk.seed, s->iter);
    int status = s->sv ? ulam__solver_restart(s->sv, s->r, w.seed, NULL)
                       : ulam_solver_alloc(s->M, s->r, &w, &s->sv, NULL);
    if (status) return status;
    double rsd = INFINITY;
    while (!status && !ulam_solver_done(s->sv)) {
        status = ulam_solver_iterate(s->sv);
        if (!status && (rsd = rel_sd(s)) < s->o.eps1) break;
    }
    ulam_walk_result wr;
    ulam_solver_result(s->sv, &wr);
    st->histories = wr.walks, st->steps = wr.steps, st->cut = wr.cut;
    st->rel_sd = rsd, st->walk_seconds = wr.seconds;
    if (status) return status;
    if (wr.interrupted) s->done = 1; /* the correction so far is still a correction */
    for (int64_t i = 0; i < s->n; i++) s->x[i] += s->delta[i];
    return ULAM_OK;
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
        ulam_gauss_seidel_sweep(s->M, s->b, s->x);
        break;
    case ULAM_MCSA:
        for (int64_t i = 0; i < s->n; i++) s->x[i] += s->r[i];
        residual(s);
        status = correct(s, &st);
        break;
    default:
        status = correct(s, &st);
    }
    if (!status) s->residual = residual(s);
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

/* Nonzero once converged. */
int ulam_outer_converged(const ulam_outer *s)
{
    return s && s->converged;
}

/* The current iterate. */
const double *ulam_outer_x(const ulam_outer *s)
{
    return s ? s->x : NULL;
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
    if (status == ULAM_ESTALL)
        ulam__fail(err, status, 0, -1, "a residual that keeps decreasing (it made no new low for %d "
                   "iterations at %.3g: is rho(M^) < 1 and eps1 small enough?)", s->stall, s->best);
    else if (status == ULAM_ENOCONV)
        ulam__fail(err, status, 0, -1, "convergence within %d iterations (residual %.3g)", s->o.max_iter,
                   s->residual);
    else if (status == ULAM_ENONFINITE)
        ulam__fail(err, status, 0, -1, "a finite residual and finite walk scores");
    else if (status)
        ulam__fail(err, status, 0, -1, "memory for the walks");
    ulam_outer_free(s);
    return status;
}
