/* Pieces of variance studies an embedding program needs to repeat one: the method grid (what
 * each of the study's method names means as walk options) and the exact value a study scores
 * against (LAPACK, or Gauss-Seidel run until x_I settles); and the study itself (ulam_study_*):
 * every method at every budget, repeats runs each, scored against that value. */
#include "study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The current iterate of outer iteration s (owned by it). */
static const double *outer_x(const ulam_outer *s)
{
    ulam_outer_info info;
    ulam_outer_get_info(s, &info);
    return info.x;
}

/* The grid, k = 9 mode + 3 estimator + window. */
static const ulam_study_method methods[ULAM_STUDY_METHODS] = {
    {"adjoint-collision-plain", ULAM_ADJOINT, ULAM_COLLISION, ULAM_WINDOW_PLAIN},
    {"adjoint-collision-roulette", ULAM_ADJOINT, ULAM_COLLISION, ULAM_WINDOW_ROULETTE},
    {"adjoint-collision-split", ULAM_ADJOINT, ULAM_COLLISION, ULAM_WINDOW_SPLIT},
    {"adjoint-absorption-plain", ULAM_ADJOINT, ULAM_ABSORPTION, ULAM_WINDOW_PLAIN},
    {"adjoint-absorption-roulette", ULAM_ADJOINT, ULAM_ABSORPTION, ULAM_WINDOW_ROULETTE},
    {"adjoint-absorption-split", ULAM_ADJOINT, ULAM_ABSORPTION, ULAM_WINDOW_SPLIT},
    {"adjoint-expected-plain", ULAM_ADJOINT, ULAM_EXPECTED, ULAM_WINDOW_PLAIN},
    {"adjoint-expected-roulette", ULAM_ADJOINT, ULAM_EXPECTED, ULAM_WINDOW_ROULETTE},
    {"adjoint-expected-split", ULAM_ADJOINT, ULAM_EXPECTED, ULAM_WINDOW_SPLIT},
    {"forward-collision-plain", ULAM_FORWARD, ULAM_COLLISION, ULAM_WINDOW_PLAIN},
    {"forward-collision-roulette", ULAM_FORWARD, ULAM_COLLISION, ULAM_WINDOW_ROULETTE},
    {"forward-collision-split", ULAM_FORWARD, ULAM_COLLISION, ULAM_WINDOW_SPLIT},
    {"forward-absorption-plain", ULAM_FORWARD, ULAM_ABSORPTION, ULAM_WINDOW_PLAIN},
    {"forward-absorption-roulette", ULAM_FORWARD, ULAM_ABSORPTION, ULAM_WINDOW_ROULETTE},
    {"forward-absorption-split", ULAM_FORWARD, ULAM_ABSORPTION, ULAM_WINDOW_SPLIT},
    {"forward-expected-plain", ULAM_FORWARD, ULAM_EXPECTED, ULAM_WINDOW_PLAIN},
    {"forward-expected-roulette", ULAM_FORWARD, ULAM_EXPECTED, ULAM_WINDOW_ROULETTE},
    {"forward-expected-split", ULAM_FORWARD, ULAM_EXPECTED, ULAM_WINDOW_SPLIT},
};

/* Method k of the grid, or NULL out of range. */
const ulam_study_method *ulam_study_method_get(int k)
{
    return k >= 0 && k < ULAM_STUDY_METHODS ? &methods[k] : NULL;
}

/* The index of the method named name, or -1. */
int ulam_study_method_find(const char *name)
{
    for (int k = 0; name && k < ULAM_STUDY_METHODS; k++)
        if (!strcmp(name, methods[k].name)) return k;
    return -1;
}

/* Set o's mode, estimator and weight window for method k on b. */
int ulam__study_method_opts(int k, const double *b, int64_t n, ulam_walk_opts *o)
{
    const ulam_study_method *m = ulam_study_method_get(k);
    if (!m || !o || (m->mode == ULAM_FORWARD && (!b || n < 0))) return ULAM_EINVAL;
    double w0 = m->mode == ULAM_FORWARD ? 0.0 : 1.0; /* forward particles start at ||b||_1 */
    if (m->mode == ULAM_FORWARD)
        for (int64_t i = 0; i < n; i++) w0 += fabs(b[i]);
    o->mode = m->mode, o->estimator = m->estimator;
    o->kernel.roulette = m->window >= ULAM_WINDOW_ROULETTE ? 0.5 * w0 : 0.0;
    o->kernel.split = m->window == ULAM_WINDOW_SPLIT ? 2.0 * w0 : 0.0;
    return ULAM_OK;
}

/* The exact x_index a study scores against. */
int ulam__study_reference(const ulam_csr *M, const double *b, int64_t index, ulam_study_ref *ref, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !b || !ref || M->nrows != M->ncols || index < 0 || index >= M->nrows)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a square matrix, b and an index in range");
    int64_t n = M->nrows;
    double *x = ulam__calloc((size_t)n, sizeof *x), *xd = NULL;
    if (!x) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the reference solve");
    *ref = (ulam_study_ref){0};
    ref->sweeps = ulam__gauss_seidel_settle(M, b, x, index, 1e-16, 12, 100000);
    ref->exact = ref->settled = x[index];
    ulam_direct_info info;
    if (n <= ULAM_STUDY_DIRECT_MAX && (xd = ulam__malloc((size_t)n, sizeof *xd)) &&
        !ulam_direct_solve(M, b, xd, 0, &info, NULL)) { /* LAPACK failing leaves Gauss-Seidel's */
        ref->direct = 1, ref->direct_seconds = info.seconds, ref->exact = xd[index];
    }
    free(x), free(xd);
    return ULAM_OK;
}

/* The 95% Wilson score interval of covered / runs. */
void ulam_study_coverage_interval(int covered, int runs, double *lo, double *hi)
{
    if (runs <= 0) {
        *lo = 0.0, *hi = 1.0;
        return;
    }
    double n = runs, p = covered / n, z = ULAM_Z95, z2 = z * z;
    double mid = (p + z2 / (2 * n)) / (1 + z2 / n), half = z * sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n);
    *lo = covered <= 0 ? 0.0 : fmax(0.0, mid - half), *hi = covered >= runs ? 1.0 : fmin(1.0, mid + half); /* exact ends */
}

/* See ulam.h. */
ulam_study_params ulam_study_defaults(void)
{
    static const double budgets[] = {100, 1000, 10000, 100000, 1000000};
    return (ulam_study_params){.budgets = budgets, .nbudgets = 5, .repeats = 30, .seed = 1};
}

/* Flat index of (method, budget, repeat). */
static size_t at(const ulam_study *s, int m, int b, int r)
{
    return ((size_t)m * MAXBUDGET + (size_t)b) * (size_t)s->p.repeats + (size_t)r;
}

/* Nonzero when p describes a study this file can run. */
static int params_ok(const ulam_study_params *p)
{
    if (!p || !p->budgets || p->nbudgets < 1 || p->nbudgets > MAXBUDGET || p->repeats < 2 || p->repeats > MAXREPEAT ||
        p->threads < 0 || (p->methods && (p->nmethods < 1 || p->nmethods > ULAM_STUDY_METHODS)))
        return 0;
    for (int k = 0; p->methods && k < p->nmethods; k++)
        if (!ulam_study_method_get(p->methods[k])) return 0;
    for (int b = 0; b < p->nbudgets; b++)
        if (!(p->budgets[b] > 0 && isfinite(p->budgets[b]))) return 0;
    return 1;
}

/* Refuse what the guards or the solver refuse, flag a variance not certified finite. */
static void screen(ulam_study *s)
{
    const ulam_guard *g = &s->g;
    for (int k = 0; k < ULAM_STUDY_METHODS; k++) {
        ulam_study_screen *m = &s->screen[k];
        if (!m->on) continue;
        const ulam_study_method *me = ulam_study_method_get(k);
        if (g->verdict_abs >= ULAM_VERDICT_FAIL) {
            snprintf(m->why, sizeof m->why, "rho(|M|) in [%.4g, %.4g] is not certified below 1: the walks may diverge",
                     g->abs.lower, g->abs.upper);
        } else {
            ulam_walk_opts o = ulam_walk_defaults();
            ulam_error err;
            ulam__study_method_opts(k, s->b, s->M->nrows, &o);
            o.kernel.roulette = o.kernel.split = 0, o.query.index = s->index, o.stop.max_walks = 1; /* unwindowed */
            o.policy.guard = g;
            ulam_solver *sv = NULL;
            if (ulam_solver_alloc(s->M, s->b, &o, &sv, &err))
                snprintf(m->why, sizeof m->why, "%s: expected %s", ulam_strerror(err.status), err.msg);
            ulam_solver_free(sv);
        }
        m->infinite = ulam_guard_variance(g, me->mode) != 1;
    }
}

/* See ulam.h. */
int ulam_study_alloc(const ulam_csr *M, const double *b, int64_t index, const ulam_study_params *p,
                     ulam_study **out, ulam_error *err)
{
    ulam__clear(err);
    if (out) *out = NULL;
    if (!M || !b || !out || M->nrows != M->ncols || index < 0 || index >= M->nrows || !params_ok(p))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a square matrix, b, an index in range and study parameters "
                          "(1..16 finite positive budgets, 2..4096 repeats, methods of the grid)");
    ulam_study *s = ulam__calloc(1, sizeof *s);
    size_t cells = (size_t)ULAM_STUDY_METHODS * MAXBUDGET * (size_t)p->repeats;
    if (s) s->run = ulam__calloc(cells, sizeof *s->run), s->done = ulam__calloc(cells, 1);
    if (!s || !s->run || !s->done) {
        ulam_study_free(s);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the study's runs");
    }
    s->M = M, s->b = b, s->index = index, s->p = *p;
    for (int k = 0; k < p->nbudgets; k++) s->budget[k] = p->budgets[k];
    s->p.budgets = s->budget, s->p.methods = NULL;
    for (int k = 0; k < ULAM_STUDY_METHODS; k++) s->screen[k].on = !p->methods;
    for (int k = 0; p->methods && k < p->nmethods; k++) s->screen[p->methods[k]].on = 1;
    int status = ulam_guard_check(M, 0.0, NULL, &s->g, err);
    if (!status) status = ulam__study_reference(M, b, index, &s->ref, err);
    if (status) {
        ulam_study_free(s);
        return status;
    }
    screen(s);
    *out = s;
    return ULAM_OK;
}

/* See ulam.h. */
ulam_study *ulam_study_free(ulam_study *s)
{
    if (!s) return NULL;
    free(s->run), free(s->done), free(s);
    return NULL;
}

/* See ulam.h. */
int ulam_study_screen_get(const ulam_study *s, int k, ulam_study_screen *out)
{
    if (!s || !out || !ulam_study_method_get(k)) return ULAM_EINVAL;
    *out = s->screen[k];
    return ULAM_OK;
}

/* See ulam.h. */
const ulam_study_ref *ulam_study_exact(const ulam_study *s)
{
    return s ? &s->ref : NULL;
}

/* See ulam.h. */
const ulam_guard *ulam_study_guard(const ulam_study *s)
{
    return s ? &s->g : NULL;
}

/* Nonzero when method m is chosen and not refused. */
static int runs(const ulam_study *s, int m)
{
    return s->screen[m].on && !s->screen[m].why[0];
}

/* The next run not done, budgets outer, methods, repeats inner: 1 with (*m, *b, *r), else 0. */
static int next(const ulam_study *s, int *m, int *b, int *r)
{
    for (*b = 0; *b < s->p.nbudgets; ++*b)
        for (*m = 0; *m < ULAM_STUDY_METHODS; ++*m)
            for (*r = 0; runs(s, *m) && *r < s->p.repeats; ++*r)
                if (!s->done[at(s, *m, *b, *r)]) return 1;
    return 0;
}

/* See ulam.h. */
int ulam_study_done(const ulam_study *s)
{
    int m, b, r;
    return !s || !next(s, &m, &b, &r);
}

/* The seed of run (m, b, r): k = (m << 24) + (b << 16) + r, the same whatever --repeats. */
static uint64_t run_seed(const ulam_study *s, int m, int b, int r)
{
    uint64_t k = ((uint64_t)m << 24) + ((uint64_t)b << 16) + (uint64_t)r;
    return ulam_rng_substream(s->p.seed, ULAM_STREAM_STUDY, k);
}

/* Fill the derived fields of a run (seed, error, coverage, cell end) and record it. */
static void record(ulam_study *s, ulam_study_run *run)
{
    int m = run->method, b = run->budget, r = run->repeat;
    run->budget_value = s->budget[b], run->seed = run_seed(s, m, b, r), run->interrupted = 0;
    if (!run->has_estimate) run->estimate = run->std_error = run->abs_error = NAN, run->covered = 0;
    else run->abs_error = fabs(run->estimate - s->ref.exact), run->covered = run->abs_error <= ULAM_Z95 * run->std_error;
    s->run[at(s, m, b, r)] = *run, s->done[at(s, m, b, r)] = 1;
    run->last_in_cell = 1;
    for (int k = 0; k < s->p.repeats; k++) run->last_in_cell &= s->done[at(s, m, b, k)];
    s->run[at(s, m, b, r)].last_in_cell = run->last_in_cell;
}

/* See ulam.h.  A run that ends with no estimate (the solver refused or failed, fewer than 2 walks,
 * or no standard error: forward walks that never reached x_I) is recorded as a failure of the
 * method at that budget: never dropped, so that every cell counts all its runs. */
int ulam_study_iterate(ulam_study *s, ulam_study_run *run, ulam_error *err)
{
    ulam__clear(err);
    int m, b, r;
    if (!s || !run || !next(s, &m, &b, &r)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a study with runs left");
    ulam_walk_opts o = ulam_walk_defaults();
    ulam__study_method_opts(m, s->b, s->M->nrows, &o);
    o.query.index = s->index, o.exec.threads = s->p.threads, o.exec.seed = run_seed(s, m, b, r);
    o.stop.interrupt = s->p.interrupt, o.exec.share = s->p.share, o.policy.guard = &s->g, o.policy.force = 1;
    if (s->p.time_budgets) o.stop.max_walks = 0, o.stop.max_seconds = s->budget[b];
    else o.stop.max_walks = (int64_t)s->budget[b];
    ulam_walk_result res;
    int status = ulam_solve_walks(s->M, s->b, &o, &res, NULL);
    *run = (ulam_study_run){.method = m, .budget = b, .repeat = r, .budget_value = s->budget[b], .seed = o.exec.seed,
                            .status = status, .walks = res.walks, .steps = res.steps,
                            .seconds = isfinite(res.seconds) ? res.seconds : 0.0};
    if (res.interrupted || (s->p.interrupt && *s->p.interrupt)) {
        run->interrupted = 1; /* not a run: it is made again */
        return ULAM_OK;
    }
    run->has_estimate = !status && res.walks >= 2 && isfinite(res.std_error) && isfinite(res.estimate);
    run->estimate = res.estimate, run->std_error = res.std_error;
    record(s, run);
    return ULAM_OK;
}

/* See ulam.h. */
int ulam_study_run_all(ulam_study *s, void (*fn)(const ulam_study_run *run, void *arg), void *arg, ulam_error *err)
{
    ulam__clear(err);
    if (!s) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a study");
    while (!ulam_study_done(s) && !(s->p.interrupt && *s->p.interrupt)) {
        ulam_study_run run;
        int status = ulam_study_iterate(s, &run, err);
        if (status) return status;
        if (run.interrupted) break;
        if (fn) fn(&run, arg);
    }
    return ULAM_OK;
}

/* See ulam.h. */
int ulam_study_run_get(const ulam_study *s, int method, int budget, int repeat, ulam_study_run *run)
{
    if (!s || !run || !ulam_study_method_get(method) || budget < 0 || budget >= s->p.nbudgets || repeat < 0 ||
        repeat >= s->p.repeats || !s->done[at(s, method, budget, repeat)])
        return 0;
    *run = s->run[at(s, method, budget, repeat)];
    return 1;
}

/* See ulam.h. */
int ulam_study_restore(ulam_study *s, const ulam_study_run *run)
{
    if (!s || !run || !ulam_study_method_get(run->method) || !runs(s, run->method) || run->budget < 0 ||
        run->budget >= s->p.nbudgets || run->repeat < 0 || run->repeat >= s->p.repeats ||
        s->done[at(s, run->method, run->budget, run->repeat)])
        return ULAM_EINVAL;
    ulam_study_run r = *run;
    record(s, &r);
    return ULAM_OK;
}

/* See ulam.h.  RMSE and stderr over the runs with an estimate, coverage and seconds over all. */
int ulam_study_cell_get(const ulam_study *s, int k, int b, ulam_study_cell *out)
{
    if (!out) return 0;
    *out = (ulam_study_cell){0};
    if (!s || !ulam_study_method_get(k) || b < 0 || b >= s->p.nbudgets) return 0;
    double se2 = 0, se = 0, t = 0;
    int n = 0, covered = 0, failed = 0;
    for (int r = 0; r < s->p.repeats; r++) {
        if (!s->done[at(s, k, b, r)]) continue;
        const ulam_study_run *u = &s->run[at(s, k, b, r)];
        n++, t += u->seconds;
        if (!u->has_estimate) {
            failed++;
            continue;
        }
        double e = u->estimate - s->ref.exact;
        se2 += e * e, se += u->std_error;
        covered += fabs(e) <= ULAM_Z95 * u->std_error;
    }
    if (!n) return 0;
    double N = n, G = n - failed > 0 ? n - failed : NAN;
    *out = (ulam_study_cell){.runs = n, .failed = failed, .rmse = sqrt(se2 / G), .mean_stderr = se / G,
                             .coverage = covered / N, .seconds = t / N};
    out->honesty = out->mean_stderr > 0 ? out->rmse / out->mean_stderr : INFINITY;
    out->work = failed ? INFINITY : out->rmse * out->rmse * out->seconds;
    return n;
}

/* See ulam.h.  A walk budget costs the method's measured seconds per walk over its finished runs,
 * so the tenfold budgets still to come weigh tenfold. */
double ulam_study_seconds_left(const ulam_study *s)
{
    if (!s) return 0.0;
    double spw[ULAM_STUDY_METHODS], dearest = 0.0, left = 0.0;
    for (int m = 0; m < ULAM_STUDY_METHODS; m++) {
        double t = 0.0, w = 0.0;
        for (int b = 0; b < s->p.nbudgets; b++)
            for (int r = 0; r < s->p.repeats; r++)
                if (s->screen[m].on && s->done[at(s, m, b, r)]) t += s->run[at(s, m, b, r)].seconds, w += s->budget[b];
        spw[m] = w > 0 ? t / w : NAN;
        if (spw[m] > dearest) dearest = spw[m];
    }
    for (int m = 0; m < ULAM_STUDY_METHODS; m++)
        for (int b = 0; b < s->p.nbudgets; b++)
            for (int r = 0; r < s->p.repeats; r++)
                if (runs(s, m) && !s->done[at(s, m, b, r)])
                    left += s->p.time_budgets ? s->budget[b] : s->budget[b] * (isnan(spw[m]) ? dearest : spw[m]);
    return left;
}

/* See ulam.h. */
int ulam_study_winner(const ulam_study *s, int b, ulam_study_cell *out)
{
    int best = -1;
    ulam_study_cell bc = {0}, c;
    for (int m = 0; s && m < ULAM_STUDY_METHODS; m++)
        if (runs(s, m) && !s->screen[m].infinite && ulam_study_cell_get(s, m, b, &c) && (best < 0 || c.work < bc.work))
            best = m, bc = c;
    if (out) *out = bc;
    return best;
}

/* See ulam.h. */
int ulam_study_forward_walks(const ulam_study *s)
{
    return s && (s->g.verdict_abs == ULAM_VERDICT_OK || s->g.verdict_abs == ULAM_VERDICT_EDGE) &&
           ulam_guard_variance(&s->g, ULAM_FORWARD) == 1;
}

/* Nonzero once the study's interrupt is set. */
static int stopped(const ulam_study *s)
{
    return s->p.interrupt && *s->p.interrupt;
}

/* Sequential MC's and MCSA's lines: one run each, its error on x_index against its seconds. */
static void outer_lines(const ulam_study *s, double reference_time,
                        void (*fn)(const char *kind, double seconds, double error, void *arg), void *arg)
{
    int64_t n = s->M->nrows;
    for (int m = ULAM_SEQUENTIAL; m <= ULAM_MCSA && ulam_study_forward_walks(s) && reference_time > 0; m++) {
        ulam_outer_opts o = ulam_outer_defaults();
        o.method = m, o.tol = 1e-10, o.walk.exec.seed = s->p.seed, o.walk.exec.threads = s->p.threads;
        o.walk.stop.interrupt = s->p.interrupt, o.max_histories = 20 * n > 1000000 ? 20 * n : 1000000;
        ulam_outer *it = NULL;
        if (ulam_outer_alloc(s->M, s->b, &o, &it, NULL)) continue;
        double t = 0;
        while (!ulam_outer_done(it) && t < reference_time && !stopped(s)) {
            ulam_outer_step step;
            ulam_outer_iterate(it, &step);
            t += step.seconds;
            fn(m == ULAM_MCSA ? "mcsa" : "sequential", t, fabs(outer_x(it)[s->index] - s->ref.exact), arg);
        }
        ulam_outer_free(it);
    }
}

/* See ulam.h. */
int ulam_study_reference_lines(const ulam_study *s, double reference_time,
                               void (*fn)(const char *kind, double seconds, double error, void *arg), void *arg,
                               ulam_error *err)
{
    ulam__clear(err);
    if (!s || !fn) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a study and a function for the points");
    int64_t n = s->M->nrows, I = s->index;
    double *x = ulam__calloc((size_t)n, sizeof *x), exact = s->ref.exact;
    if (!x) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the reference solves");
    if (s->ref.direct) fn("lapack", s->ref.direct_seconds, fabs(exact - s->ref.settled), arg);
    double t = 0;
    for (int k = 1; k <= 100000; k++) {
        double t0 = ulam_now();
        ulam__gauss_seidel_sweep(s->M, s->b, x);
        t += ulam_now() - t0;
        double e = fabs(x[I] - exact);
        if ((k & (k - 1)) == 0 || e <= 1e-9 * fabs(exact)) fn("gs", t, e, arg);
        if (!(e > 1e-9 * fabs(exact))) break;
    }
    outer_lines(s, reference_time, fn, arg);
    ulam_csr_stats st;
    int cg = !ulam_csr_stats_compute(s->M, &st) && st.symmetric;
    for (int k = 1; k <= 10 && !stopped(s); k++) { /* a solve's time: the mean of repeats over >= 1 ms (one solve
                                                      of a small system is microseconds, the first ones many times
                                                      the rest: the line ran backwards) */
        int its, reps = 0, status;
        double res, t0 = ulam_now();
        do {
            status = cg ? ulam_cg(s->M, s->b, pow(10.0, -k), 100000, x, &its, &res)
                        : ulam_gmres(s->M, s->b, 30, pow(10.0, -k), 100000, x, &its, &res);
            t = ulam_now() - t0;
        } while (++reps < 1000 && t < 1e-3 && (status == ULAM_OK || status == ULAM_ENOCONV));
        if (status == ULAM_OK || status == ULAM_ENOCONV) fn(cg ? "cg" : "gmres", t / reps, fabs(x[I] - exact), arg);
    }
    free(x);
    return ULAM_OK;
}
