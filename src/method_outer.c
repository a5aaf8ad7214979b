/* The method table's outer-iteration rows (src/mcsa.c): richardson, gauss-seidel, sequential and
 * mcsa answer every unknown to a residual tolerance; asked for one entry they answer x_index with
 * no error bar, so the choice does not consider them for a query that wants one. */
#include "method_row.h"
#include "csr.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* The current iterate of outer iteration s (owned by it). */
static const double *outer_x(const ulam_outer *s)
{
    ulam_outer_info info;
    ulam_outer_get_info(s, &info);
    return info.x;
}

/* The name of row k, one of this file's (ULAM_METHOD_RICHARDSON to ULAM_METHOD_GMRES, in order). */
static const char *row_name(int k)
{
    static const ulam__method_type *const rows[] = {&ulam__method_richardson, &ulam__method_gauss_seidel,
                                                    &ulam__method_sequential, &ulam__method_mcsa,
                                                    &ulam__method_cg,         &ulam__method_gmres};
    return rows[k - ULAM_METHOD_RICHARDSON]->name;
}

/* Not for an entry query with an error bar (shared with the Krylov rows). */
static int applies(const ulam__query *q, int k, char *why, size_t len)
{
    (void)q;
    snprintf(why, len, "not considered: %s answers every unknown to a residual tolerance, with no error bar on one "
             "entry", row_name(k));
    return 0;
}

/* Never reached (applies is 0): no prediction. */
static int predict(ulam__query *q, int k, ulam_error *err)
{
    (void)q, (void)k, (void)err;
    return ULAM_OK;
}

/* Pinned: nothing to prepare (the run reads the options). */
static int pin(ulam__query *q, int k, ulam_error *err)
{
    (void)q, (void)k, (void)err;
    return ULAM_OK;
}

/* The outer iteration's options from the walk options: its defaults (MCSA's forward expected
 * walks), with the caller's seed, threads, continuation, cut, interrupt, share and force, and
 * max_walks (when set) as the cap on one correction's histories. */
static ulam_outer_opts outer_opts(const ulam_walk_opts *w, int method)
{
    ulam_outer_opts o = ulam_outer_defaults();
    o.method = method;
    o.walk.exec.seed = w->exec.seed, o.walk.exec.threads = w->exec.threads, o.walk.kernel.continue_q = w->kernel.continue_q;
    o.walk.stop.max_steps = w->stop.max_steps, o.walk.stop.interrupt = w->stop.interrupt, o.walk.exec.share = w->exec.share;
    o.walk.policy.force = w->policy.force;
    if (w->stop.max_walks > 0) o.max_histories = w->stop.max_walks;
    return o;
}

/* x_index's certified range from x's residual into a->ci95 (ulam_solution_bound; NaN where none
 * holds or memory is short: the answer stands without it). */
static void certified_range(const ulam_run *r, const double *x, ulam_answer *a)
{
    int64_t n = r->M->nrows;
    double *lo = malloc((size_t)n * sizeof *lo), *hi = malloc((size_t)n * sizeof *hi), worst;
    if (lo && hi && ulam_solution_bound(r->M, r->b, x, lo, hi, &worst, NULL) == ULAM_OK)
        a->ci95[0] = lo[r->o.query.index], a->ci95[1] = hi[r->o.query.index];
    free(lo), free(hi);
}

/* Iterate to the residual tolerance; x_index is the answer, with its certified range. */
static int finish_outer(ulam_run *r, ulam_answer *a, ulam_error *err)
{
    ulam_outer_opts o = outer_opts(&r->o, r->method - ULAM_METHOD_RICHARDSON);
    if (r->o.query.index < 0 || r->o.query.index >= r->M->nrows)
        return ulam__fail(err, ULAM_EINVAL, 0, r->o.query.index, "an index from 0 to %lld", (long long)r->M->nrows - 1);
    ulam_outer *s = NULL;
    int status = ulam_outer_alloc(r->M, r->b, &o, &s, err);
    int64_t histories = 0;
    while (!status && !ulam_outer_done(s)) {
        ulam_outer_step st = {.iteration = a->iterations, .residual = a->residual};
        status = ulam_outer_iterate(s, &st);
        a->iterations = st.iteration, a->residual = st.residual, histories += st.histories;
    }
    if (s) a->estimate = outer_x(s)[r->o.query.index];
    if (s && !status) certified_range(r, outer_x(s), a);
    a->walks.walks = histories;
    ulam_outer_free(s);
    return status;
}

/* Nothing kept. */
static void release(ulam_run *r)
{
    (void)r;
}

const ulam__method_type ulam__method_richardson = {"richardson", ULAM_ANSWERS_ALL, applies, predict, pin, finish_outer, release};
const ulam__method_type ulam__method_gauss_seidel = {"gauss-seidel", ULAM_ANSWERS_ALL, applies, predict, pin, finish_outer, release};
const ulam__method_type ulam__method_sequential = {"sequential", ULAM_ANSWERS_ALL, applies, predict, pin, finish_outer, release};
const ulam__method_type ulam__method_mcsa = {"mcsa", ULAM_ANSWERS_ALL, applies, predict, pin, finish_outer, release};

/* The Krylov peers to the outer iterations' tolerance (1e-8) and cap (100000). */
static int finish_krylov(ulam_run *r, ulam_answer *a, ulam_error *err)
{
    ulam_outer_opts d = ulam_outer_defaults();
    if (r->o.query.index < 0 || r->o.query.index >= r->M->nrows || r->M->nrows != r->M->ncols)
        return ulam__fail(err, ULAM_EINVAL, 0, r->o.query.index, "a square M and an index from 0 to %lld",
                          (long long)r->M->nrows - 1);
    if (r->method == ULAM_METHOD_CG && !ulam__csr_symmetric(r->M))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a symmetric M for cg (I - M symmetric positive definite): use gmres");
    double *x = calloc((size_t)r->M->nrows, sizeof *x);
    if (!x) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for x");
    int status = r->method == ULAM_METHOD_CG ? ulam_cg(r->M, r->b, d.tol, 100000, x, &a->iterations, &a->residual)
                                             : ulam_gmres(r->M, r->b, 30, d.tol, 100000, x, &a->iterations, &a->residual);
    a->estimate = x[r->o.query.index];
    if (!status) certified_range(r, x, a);
    free(x);
    if (status) ulam__fail(err, status, 0, -1, "a residual below %g within 100000 iterations", d.tol);
    return status;
}

const ulam__method_type ulam__method_cg = {"cg", ULAM_ANSWERS_ALL, applies, predict, pin, finish_krylov, release};
const ulam__method_type ulam__method_gmres = {"gmres", ULAM_ANSWERS_ALL, applies, predict, pin, finish_krylov, release};
