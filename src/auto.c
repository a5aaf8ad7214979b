/* Choosing the walk method: mode x estimator x continuation, screened by the guards, raced by pilots
 * and compared by a deterministic work model.
 *
 * A candidate qualifies when the guards certify its variance finite: the Collatz-Wielandt upper
 * bounds of rho(|M|) and of rho(M^) of its own kernel are below 1 (every estimator's second moment
 * is a series in M^, src/guard.c).  Candidates of one kernel (mode, continuation) share one
 * solver: its rows, reachable set and score bounds are built once and the rows rescored for each
 * estimator (ulam__solver_rerun).  Pilots race in stages of doubling walks; the choice compares
 * predicted work in units of the work model, counted from the pilots' steps, walks and the
 * kernel's size, never from a clock, so it is the same for any thread count, process count and
 * machine load.  The estimate then comes from fresh walks on the caller's seed with the chosen
 * candidate's solver: the choice is a function of the pilots alone, which are independent of
 * those walks, so it cannot bias them (README: reusing the pilot's walks would). */
#include "auto.h"
#include "defaults.h"
#include "analysis.h"
#include "check.h"
#include "solve.h"
#include "stats.h"
#include "stop.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ULAM__AUTO_RESOLVE 4.0 /* a pilot mean this many standard errors from 0 resolves |x| (to about 25%) */
#define ULAM__AUTO_GROW 64     /* an unresolved leader's pilots grow to this many times pilot_max */

enum { KERNELS = 6, GROUPS = 12 }; /* guards: 2 continuations x 3 exponents; kernels: x 2 modes */

/* One kernel's solver and the work it has done (guards excluded). */
typedef struct {
    ulam_solver *sv;      /* NULL until a candidate of the kernel is allocated */
    int64_t units, reads; /* set-up work so far (ulam__solver_setup) */
    int64_t walks;        /* pilot walks it has run, every estimator */
    int started;
} group;

/* The choice's workspace. */
typedef struct {
    const ulam_csr *M;
    const double *b;
    ulam_walk_opts base;
    ulam_auto_opts a;
    ulam_auto_result *res;
    group g[GROUPS];
    int gi[ULAM_AUTO_MAX];          /* each candidate's group */
    ulam__moments mom[ULAM_AUTO_MAX]; /* pooled pilot scores */
    double steps[ULAM_AUTO_MAX], min_walks[ULAM_AUTO_MAX];
    double range[ULAM_AUTO_MAX]; /* the range R of a single score its pilot's interval used (INFINITY: none known) */
    int tail_ok[ULAM_AUTO_MAX];
    double guard_reads[KERNELS];    /* per continuation and exponent: iq * 3 + ia */
    ulam_guard guard[KERNELS];
    int nq, na;
    double qs[2], as[3];
    int leader;
    const ulam__reach *reach;       /* bounds over every state for one kernel (an analysis'; NULL: none) */
    double deadline;                /* a time limit's end (ulam_now; INFINITY: none) */
    double stage_seconds;           /* the last pilot stage's time (under a time limit) */
} chooser;

/* A solver for o, on the caller's bounds when they were made for its kernel (adjoint, this
 * continuation and exponent): its set-up then reads no more than its walks do. */
static int alloc_solver(const chooser *c, const ulam_walk_opts *o, ulam_solver **out, ulam_error *err)
{
    const ulam__reach *R = c->reach;
    int fits = R && o->mode == ULAM_ADJOINT && (o->kernel.continue_q > 0 ? o->kernel.continue_q : 0.0) == R->continue_q &&
               o->kernel.kernel_alpha == R->alpha;
    return ulam__solver_alloc_until(c->M, c->b, o, fits ? R : NULL, c->deadline, out, err);
}

/* The default options. */
ulam_auto_opts ulam__auto_defaults(void)
{
    return (ulam_auto_opts){.continue_q = 0.9, .pilot_walks = 128, .pilot_max = 1024, .pilot_share = 0.2};
}

/* Matrix entries a guard's radii read: one pass for the sums, one per power iteration. */
static double guard_reads(const ulam_csr *M, const ulam_guard *g)
{
    double it = 1.0;
    if (g->computed & ULAM_GUARD_ABS) it += g->abs.iterations;
    if (g->computed & ULAM_GUARD_ADJOINT) it += g->hat[0].iterations;
    if (g->computed & ULAM_GUARD_FORWARD) it += g->hat[1].iterations;
    return it * (double)ulam_csr_nnz(M);
}

/* Compute the guard radii `need` of continuation and exponent kk (iq * 3 + ia) not yet computed. */
static int guard_need(chooser *c, int kk, int need, ulam_error *err)
{
    ulam_guard *g = &c->guard[kk];
    if ((g->computed & need) == need) return ULAM_OK;
    const ulam_guard *given = c->a.guard;
    if (!g->computed && given && (given->continue_q > 0 ? given->continue_q : 0.0) == c->qs[kk / 3] &&
        given->kernel_alpha == c->as[kk % 3] && (given->computed & need) == need) {
        *g = *given; /* no pass over M */
        return ULAM_OK;
    }
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = need & ~g->computed;
    go.kernel_alpha = c->as[kk % 3];
    ulam_guard h;
    int status = c->base.policy.system ? ulam_system_check(c->base.policy.system, err) : ULAM_OK; /* a lazily read file: whole now */
    if (!status) status = ulam_guard_check(c->M, c->qs[kk / 3], &go, &h, err);
    if (status) return status;
    if (!g->computed) *g = h;
    else
        for (int m = 0; m < 2; m++)
            if (h.computed & ULAM_GUARD_HAT(m)) g->hat[m] = h.hat[m], g->verdict_hat[m] = h.verdict_hat[m];
    g->computed |= h.computed;
    c->guard_reads[kk] += guard_reads(c->M, &h);
    return ULAM_OK;
}

/* The walks after which the rel_err rule is checked that first reach n: the solver's rounds of
 * 1, 2, 4 ... 64 blocks of 1024 (totals 1, 3, 7 ... 127 blocks, then 64 more a round). */
static double rounded_walks(double n)
{
    double b = ceil(n / 1024), t = 1;
    if (!(b < 1e15)) return INFINITY;
    while (t < b && t < 127) t = 2 * t + 1;
    return 1024 * (t >= b ? t : 127 + 64 * ceil((b - 127) / 64));
}

/* The work units of one walk of candidate k with the pilots' mean steps (forward: tallies per
 * visit, for expected the column's nonzeros). */
static double work_per_walk(const chooser *c, int k)
{
    const ulam_auto_candidate *a = &c->res->cand[k];
    double steps = a->steps_per_walk, t = 0.0;
    if (a->mode == ULAM_FORWARD)
        t = a->estimator == ULAM_ABSORPTION ? 1.0
            : a->estimator == ULAM_COLLISION ? steps + 1.0
                                             : (steps + 1.0) * (double)ulam_csr_nnz(c->M) / (double)c->M->nrows;
    return steps + ULAM_AUTO_WALK + ULAM_AUTO_TALLY * t;
}

/* Candidate k's variance for the comparisons: every candidate estimates the same x_i, so a pilot
 * mean further than 2 of its standard errors from the most precise other pilot's has missed part
 * of its scores' spread (a skewed score, rare large values, otherwise looks cheapest exactly when
 * its pilot missed them): its variance is raised to what puts the difference at 2 standard errors. */
static double variance_of(const ulam_auto_result *res, int k)
{
    const ulam_auto_candidate *a = &res->cand[k];
    double best = INFINITY, m = NAN;
    for (int j = 0; j < res->ncand; j++) {
        const ulam_auto_candidate *o = &res->cand[j];
        if (j == k || !o->pilot_walks || !isfinite(o->estimate) || !(o->variance > 0)) continue;
        double se2 = o->variance / (double)o->pilot_walks;
        if (se2 < best) best = se2, m = o->estimate;
    }
    double d = a->estimate - m, n = (double)a->pilot_walks;
    return isnan(m) ? a->variance : fmax(a->variance, n * d * d / 4.0);
}

/* Candidate k's pilot mean |estimate + offset| and its standard error (the comparison variance
 * over its pilot walks; INFINITY below 2 walks). */
static double pilot_se(const ulam_auto_result *res, int k)
{
    double n = (double)res->cand[k].pilot_walks;
    return n > 1 ? sqrt(variance_of(res, k) / n) : INFINITY;
}

/* Whether candidate k's pilot mean resolves |x|: at least ULAM__AUTO_RESOLVE of its standard
 * errors from 0 (a prediction var / (E m)^2 at a mean of noise alone is a guess: case 7's 128
 * walks of variance 110 put |m| near 1 where |x| = 1e-3, and predicted 1.5e4 walks where the
 * rule needs 1.1e9). */
static int resolved(const ulam_auto_result *res, int k, double offset)
{
    return fabs(res->cand[k].estimate + offset) >= ULAM__AUTO_RESOLVE * pilot_se(res, k);
}

/* The scale |x| candidate k's rel_err prediction is made at: its pilot mean when that resolves
 * |x|; else the largest |x| the pilots allow, min over every piloted candidate with spread of
 * |mean| + 2 standard errors (they all estimate the same x), at which the prediction is a lower
 * bound on the walks the rule needs.  Spread of its own, not variance_of's: a forward pilot that
 * has not tallied the component (mean 0, variance 0) gets a variance from its distance to the
 * others' mean, and its 0 + 2 se (3.7e-5 for x = -5.1e-4, randsub1000's x_7 for sparse3_b) set
 * every unresolved prediction 200x high once forward kernels were piloted. */
static double scale_of(const ulam_auto_result *res, int k, double offset)
{
    double m = fabs(res->cand[k].estimate + offset);
    if (resolved(res, k, offset)) return m;
    double cap = m + 2.0 * pilot_se(res, k);
    for (int j = 0; j < res->ncand; j++)
        if (res->cand[j].pilot_walks > 1 && res->cand[j].variance > 0 && isfinite(res->cand[j].estimate))
            cap = fmin(cap, fabs(res->cand[j].estimate + offset) + 2.0 * pilot_se(res, j));
    return cap;
}

/* Whether candidate k's predicted walks are a lower bound (its pilot mean does not resolve |x|). */
static int lower_bound(const ulam_auto_result *res, int k, double rel_err_offset)
{
    if (!res || k < 0 || k >= res->ncand || res->cand[k].pilot_walks < 2 || !res->by_work) return 0;
    return !resolved(res, k, rel_err_offset);
}

/* Candidate k's predicted walks and work at variance var (the pooled one, or a bound of it). */
static double predict(const chooser *c, int k, double var, double *walks)
{
    const ulam_auto_candidate *a = &c->res->cand[k];
    const group *g = &c->g[c->gi[k]];
    double E = c->base.stop.rel_err, N;
    if (E > 0) {
        double off = c->base.stop.rel_err_offset, m = fabs(a->estimate + off);
        int exact = resolved(c->res, k, off);
        if (!c->tail_ok[k]) N = INFINITY; /* no bound on a single score: the rule cannot stop */
        else if (m == 0 && !(a->variance > 0)) N = INFINITY; /* a pilot that saw nothing predicts nothing */
        else {
            m = scale_of(c->res, k, off); /* unresolved: the largest |x| the pilots allow, a lower bound */
            /* the rule's own prediction (stop.h) holds its range term: a pilot without spread is no
               evidence of a small variance.  The rule is the confidence sequence's (the half-width
               at most E |m|): its variance term alone asks 2 ln(2 / delta) var / (E m)^2, 7.4 times
               the var / (E m)^2 predicted here before (issue 38: a leader predicted >= 4.1e6 walks
               ran 3.7e7) */
            N = fmax((double)ULAM__REL_FIRST, ulam__cs_var_walks(m, var, E)); /* the rule's first check */
            if (exact) N = fmax(N, c->min_walks[k]); /* the pilot's own prediction (its variance, range and bias) */
            if (isfinite(c->range[k])) /* the rule's at this variance: the range term shares the half-width */
                N = fmax(N, ulam__cs_walks_needed(m, var, c->range[k], 0.0, E));
        }
        N = rounded_walks(N);
        if (c->base.stop.max_walks > 0) N = fmin(N, (double)c->base.stop.max_walks);
    } else {
        N = c->base.stop.max_walks > 0 ? (double)c->base.stop.max_walks : NAN;
    }
    *walks = N;
    double cap = (double)ulam_csr_nnz(c->M) + 3.0 * (double)c->M->nrows, u = (double)g->units;
    double reach = g->walks > 0 ? fmin(cap, u * N / (double)g->walks) : cap;
    if (reach * ULAM__COMPLETE > cap) reach = cap; /* the solver then builds the rest at once */
    return N * work_per_walk(c, k) + ULAM_AUTO_BUILD * fmax(0.0, reach - u);
}

/* An upper confidence bound on candidate k's variance from its pilot's sample variance var and
 * the range R of its scores (Maurer and Pontil, COLT 2009, Theorem 10: sigma <= sqrt(var) +
 * R sqrt(2 ln(1 / delta) / (n - 1)) with probability 1 - delta, here 0.05): a pilot without
 * spread is no evidence of a small variance when unseen scores could still be large.  Without
 * a known R, var itself, and a pilot without spread counts as nothing known (INFINITY). */
static double honest_variance(const chooser *c, int k, double var)
{
    double n = (double)c->res->cand[k].pilot_walks, R = c->range[k];
    if (!isfinite(R)) return var > 0 && c->res->cand[k].variance > 0 ? var : INFINITY; /* spread of its own */
    double sd = sqrt(var) + (n > 1 ? R * sqrt(2.0 * log(20.0) / (n - 1.0)) : INFINITY);
    return sd * sd;
}

/* The key candidates are compared by: predicted work with rel_err, else the cost (at the
 * variance scaled by `scale`). */
static double key(const chooser *c, int k, double scale)
{
    const ulam_auto_candidate *a = &c->res->cand[k];
    if (a->mode == ULAM_FORWARD && a->estimate == 0 && a->variance == 0)
        return INFINITY; /* no forward pilot walk has tallied the component yet: nothing is known */
    double var = variance_of(c->res, k) * scale, walks;
    if (c->base.stop.rel_err > 0) return predict(c, k, var, &walks);
    return honest_variance(c, k, var) * work_per_walk(c, k);
}

/* The set-up work the run of candidate k reuses: its continuation's guards and its kernel's
 * set-up. */
static double reused(const chooser *c, int k)
{
    const group *g = &c->g[c->gi[k]];
    return c->guard_reads[c->gi[k] % KERNELS] + ULAM_AUTO_READ * (double)g->reads + ULAM_AUTO_BUILD * (double)g->units;
}

/* Everything spent so far: guards, kernels' set-up, pilot walks. */
static double spent(const chooser *c)
{
    double w = 0.0;
    for (int kk = 0; kk < KERNELS; kk++) w += c->guard_reads[kk];
    for (int i = 0; i < GROUPS; i++) w += ULAM_AUTO_READ * (double)c->g[i].reads + ULAM_AUTO_BUILD * (double)c->g[i].units;
    for (int k = 0; k < c->res->ncand; k++) {
        const ulam_auto_candidate *a = &c->res->cand[k];
        if (a->pilot_walks) w += (double)a->pilot_walks * work_per_walk(c, k);
    }
    return w;
}

/* The leader's predicted run as a single method (its set-up included); under a time limit at most
 * the work the time buys at the work model's rate (a constant, not this machine's: no clock is
 * read), and that work when no walk count is predicted (--time alone: the prediction was NaN,
 * the overhead share never passed its cap, and --time 0.05 on a 24^3 Laplacian piloted six
 * kernels, 2e8 units). */
static double leader_work(const chooser *c)
{
    double full = c->res->cand[c->leader].predicted_work + reused(c, c->leader), S = c->base.stop.max_seconds;
    if (!(S > 0)) return full;
    double buys = S / ULAM_AUTO_UNIT_SECONDS;
    return isnan(full) ? buys : fmin(full, buys);
}

/* The pilots' overhead (what the leader's run would not reuse) over the leader's predicted run
 * (leader_work): piloting stops at ao->pilot_share. */
static double overhead_share(const chooser *c)
{
    if (c->leader < 0) return 0.0;
    double r = reused(c, c->leader), full = leader_work(c);
    return full > 0 ? (spent(c) - r) / full : INFINITY;
}

/* Refresh candidate k's pooled figures and predictions. */
static void refresh(chooser *c, int k)
{
    ulam_auto_candidate *a = &c->res->cand[k];
    a->estimate = c->mom[k].mean;
    a->variance = ulam__moments_variance(&c->mom[k]);
    a->steps_per_walk = a->pilot_walks ? c->steps[k] / (double)a->pilot_walks : 0.0;
    a->work_per_walk = work_per_walk(c, k);
    a->cost = variance_of(c->res, k) * a->work_per_walk;
    a->predicted_work = predict(c, k, variance_of(c->res, k), &a->predicted_walks);
    a->predicted_seconds = a->predicted_work * ULAM_AUTO_UNIT_SECONDS;
}

/* The pilot options of candidate k at a stage of n walks. */
static ulam_walk_opts pilot_opts(const chooser *c, int k, int stage, int64_t n)
{
    const ulam_auto_candidate *a = &c->res->cand[k];
    ulam_walk_opts o = c->base;
    o.mode = a->mode, o.estimator = a->estimator, o.kernel.continue_q = a->continue_q;
    o.stop.max_walks = n, o.stop.max_seconds = 0, o.stop.interrupt = NULL, o.exec.share = NULL, o.kernel.whole_kernel = 0;
    o.exec.seed = ulam_rng_substream(c->base.exec.seed, ULAM_STREAM_PILOT, (uint64_t)(64 * k + stage)); /* streams.md */
    o.kernel.kernel_alpha = a->kernel_alpha;
    o.policy.guard = &c->guard[c->gi[k] % KERNELS];
    return o;
}

/* Run candidate k's pilot of stage `stage` (n walks) on its kernel's solver; ULAM_OK (also when
 * the solver refused it: its state says so) or ULAM_ENOMEM. */
static int pilot(chooser *c, int k, int stage, int64_t n)
{
    ulam_auto_candidate *a = &c->res->cand[k];
    group *g = &c->g[c->gi[k]];
    ulam_walk_opts o = pilot_opts(c, k, stage, n);
    int status = g->sv ? ulam__solver_rerun(g->sv, &o, NULL) : alloc_solver(c, &o, &g->sv, NULL);
    g->started = g->sv != NULL;
    if (g->sv) ulam__solver_setup(g->sv, &g->units, &g->reads);
    if (status == ULAM_ENOMEM) return status;
    if (status) {
        a->status = status, a->state = ULAM_AUTO_REFUSED;
        return ULAM_OK;
    }
    while (!status && !ulam_solver_done(g->sv)) status = ulam_solver_iterate(g->sv);
    ulam_walk_result r;
    ulam_solver_result(g->sv, &r);
    ulam__solver_setup(g->sv, &g->units, &g->reads);
    if (status == ULAM_ENOMEM) return status;
    if (status) {
        a->status = status, a->state = ULAM_AUTO_REFUSED;
        return ULAM_OK;
    }
    g->walks += r.walks;
    ulam__moments m = {.n = r.walks, .mean = r.estimate, .m2 = r.variance * (double)(r.walks - 1)};
    ulam__moments_merge(&c->mom[k], &m);
    a->pilot_walks += r.walks;
    c->steps[k] += (double)r.steps;
    a->stages = stage + 1;
    /* the range term scales as R / |m|: carry it to the pooled mean */
    double mp = fabs(c->mom[k].mean + c->base.stop.rel_err_offset), ms = fabs(r.estimate + c->base.stop.rel_err_offset);
    c->min_walks[k] = r.min_walks > 0 && mp > 0 ? r.min_walks * ms / mp : r.min_walks;
    c->tail_ok[k] = isfinite(r.tail_bound) || r.estimate == 0;
    c->range[k] = r.tail_bound == 0.0 ? 0.0 : isfinite(r.tail_bound) && ms > 0 ? r.tail_bound * (double)r.walks * ms : INFINITY;
    /* the variance's own error at the pooled count (it falls as 1 / sqrt(n)) */
    a->variance_rel_error = r.variance_rel_error * sqrt((double)r.walks / (double)a->pilot_walks);
    if (a->mode == ULAM_FORWARD && isnan(r.std_error)) c->tail_ok[k] = 0; /* never reached the component */
    a->state = ULAM_AUTO_FINALIST;
    refresh(c, k);
    return ULAM_OK;
}

/* Whether some finalist's pilot had a certified range of a single score (its run prints an
 * interval). */
static int any_ranged(const chooser *c)
{
    for (int k = 0; k < c->res->ncand; k++)
        if (c->res->cand[k].state == ULAM_AUTO_FINALIST && c->tail_ok[k]) return 1;
    return 0;
}

/* The finalist of least key (-1: none), among those with a certified range when any has one:
 * a candidate whose run can print no interval never wins over one whose run can. */
static int lead(const chooser *c)
{
    int best = -1, ranged = any_ranged(c);
    for (int k = 0; k < c->res->ncand; k++) {
        if (c->res->cand[k].state != ULAM_AUTO_FINALIST || (ranged && !c->tail_ok[k])) continue;
        if (best < 0 || key(c, k, 1.0) < key(c, best, 1.0)) best = k;
    }
    return best;
}

/* The work a new kernel's start would cost, predicted from the kernels started so far (their
 * set-up), plus for forward the transpose and its guard (as many reads as the adjoint one's). */
static double start_cost(const chooser *c, int gi)
{
    double w = 0.0;
    for (int i = 0; i < GROUPS; i++)
        if (c->g[i].started) w = fmax(w, ULAM_AUTO_READ * (double)c->g[i].reads + ULAM_AUTO_BUILD * (double)c->g[i].units);
    if (gi >= KERNELS) w += 2.0 * ULAM_AUTO_READ * (double)ulam_csr_nnz(c->M);
    if (gi >= KERNELS && !(c->guard[gi % KERNELS].computed & ULAM_GUARD_FORWARD)) w += c->guard_reads[gi % KERNELS];
    return w;
}

/* The candidates, less what is pinned: adjoint before forward, analog before the fixed
 * continuation, kernel exponent 1 before 0 and 2, then collision, absorption, expected. */
static void list(chooser *c)
{
    ulam_auto_result *res = c->res;
    for (int mode = ULAM_ADJOINT; mode <= ULAM_FORWARD; mode++)
        for (int iq = 0; iq < c->nq; iq++)
            for (int ia = 0; ia < c->na; ia++)
                for (int est = ULAM_COLLISION; est <= ULAM_EXPECTED; est++) {
                    if ((c->a.pin_mode && mode != c->base.mode) || (c->a.pin_estimator && est != c->base.estimator))
                        continue;
                    int k = res->ncand++;
                    res->cand[k] = (ulam_auto_candidate){.mode = mode, .estimator = est, .continue_q = c->qs[iq],
                                                         .kernel_alpha = c->as[ia], .hat = {.upper = INFINITY},
                                                         .cost = INFINITY, .predicted_walks = NAN,
                                                         .predicted_work = INFINITY, .predicted_seconds = NAN};
                    c->gi[k] = mode * KERNELS + iq * 3 + ia;
                }
}

/* Screen candidate k with its continuation's guard (computing its mode's radius if needed). */
static int screen(chooser *c, int k, ulam_error *err)
{
    ulam_auto_candidate *a = &c->res->cand[k];
    int kk = c->gi[k] % KERNELS, status = guard_need(c, kk, ULAM_GUARD_ABS | ULAM_GUARD_HAT(a->mode), err);
    if (status) return status;
    a->hat = c->guard[kk].hat[a->mode];
    c->res->abs = c->guard[kk].abs;
    a->certified = c->guard[kk].abs.upper < 1 && a->hat.upper < 1;
    return ULAM_OK;
}

/* Whether a time limit leaves no room for more pilots: its end is past, or nearer than twice
 * the last stage took (a stage doubles the walks).  Under --time the pilots then stop where the
 * clock is, not where the work model would (the choice depends on the machine's speed only there;
 * --time 0.05 on a 24^3 Laplacian spent 0.23 s on set-up, under load). */
static int late(const chooser *c)
{
    return isfinite(c->deadline) && ulam_now() + 2.0 * c->stage_seconds >= c->deadline;
}

/* Stage 0: screen and pilot each candidate in order, skipping new kernels past the budget. */
static int first_stage(chooser *c, ulam_error *err)
{
    ulam_auto_result *res = c->res;
    for (int k = 0; k < res->ncand; k++) {
        ulam_auto_candidate *a = &res->cand[k];
        group *g = &c->g[c->gi[k]];
        if (c->leader >= 0 && !g->started &&
            (overhead_share(c) + start_cost(c, c->gi[k]) / leader_work(c) > c->a.pilot_share || late(c))) {
            a->state = ULAM_AUTO_SKIPPED; /* screened only when its guard is known already */
            int kk = c->gi[k] % KERNELS;
            if (c->guard[kk].computed & ULAM_GUARD_HAT(a->mode)) {
                a->hat = c->guard[kk].hat[a->mode];
                a->certified = c->guard[kk].abs.upper < 1 && a->hat.upper < 1;
            }
            continue;
        }
        int status = screen(c, k, err);
        if (status) return status;
        if (!a->certified) {
            a->state = ULAM_AUTO_UNCERTIFIED;
            continue;
        }
        if (c->leader >= 0 && g->started && (overhead_share(c) > c->a.pilot_share || late(c))) {
            a->state = ULAM_AUTO_SKIPPED;
            continue;
        }
        double t = ulam_now();
        if ((status = pilot(c, k, 0, c->a.pilot_walks))) return ulam__fail(err, status, 0, -1, "memory for a pilot");
        c->stage_seconds = ulam_now() - t;
        c->leader = lead(c);
    }
    return ULAM_OK;
}

/* Drop the finalists clearly worse than the leader; the number left. */
static int drop(chooser *c)
{
    int left = 0;
    const ulam_auto_candidate *L = &c->res->cand[c->leader];
    /* a leader whose pilot does not resolve |x| predicts a lower bound: nothing is clearly worse than it */
    double high = lower_bound(c->res, c->leader, c->base.stop.rel_err_offset)
                      ? INFINITY : key(c, c->leader, 1.0 + 2.0 * fmin(L->variance_rel_error, 1e6));
    for (int k = 0; k < c->res->ncand; k++) {
        ulam_auto_candidate *a = &c->res->cand[k];
        if (a->state != ULAM_AUTO_FINALIST) continue;
        if (k != c->leader && (key(c, k, 1.0 / (1.0 + 2.0 * a->variance_rel_error)) > high ||
                               (c->tail_ok[c->leader] && !c->tail_ok[k])))
            a->state = ULAM_AUTO_DROPPED;
        else left++;
    }
    return left;
}

/* The pilot stages after the first: the survivors' walks double until the leader is clear, the
 * stage's pilots reach ao->pilot_max or the overhead ao->pilot_share. */
static int race(chooser *c, ulam_error *err)
{
    int64_t n = c->a.pilot_walks;
    for (int stage = 1; c->leader >= 0; stage++) {
        c->res->stages = stage;
        /* a leader whose pilot does not resolve |x| predicts a lower bound: its pilots grow on, past
           pilot_max up to ULAM__AUTO_GROW times it, while the overhead share allows */
        int open = c->base.stop.rel_err > 0 && !resolved(c->res, c->leader, c->base.stop.rel_err_offset);
        if ((drop(c) <= 1 && !open) || 2 * n > c->a.pilot_max * (open ? ULAM__AUTO_GROW : 1) ||
            overhead_share(c) >= c->a.pilot_share || late(c))
            return ULAM_OK;
        n *= 2;
        double more = 0.0, full = leader_work(c);
        for (int k = 0; k < c->res->ncand; k++)
            if (c->res->cand[k].state == ULAM_AUTO_FINALIST) more += (double)n * c->res->cand[k].work_per_walk;
        if (overhead_share(c) + more / full > c->a.pilot_share) return ULAM_OK;
        double t = ulam_now();
        for (int k = 0; k < c->res->ncand; k++) {
            if (c->res->cand[k].state != ULAM_AUTO_FINALIST) continue;
            int status = pilot(c, k, stage, n);
            if (status) return ulam__fail(err, status, 0, -1, "memory for a pilot");
        }
        c->stage_seconds = ulam_now() - t;
        c->leader = lead(c);
    }
    return ULAM_OK;
}

/* With no candidate certified: every radius the candidates need, and the closest (least rho(M^)). */
static int closest(chooser *c, ulam_error *err)
{
    ulam_auto_result *res = c->res;
    for (int k = 0; k < res->ncand; k++) {
        if (res->chosen < 0) {
            int status = screen(c, k, err);
            if (status) return status;
        }
        if (isfinite(res->cand[k].hat.upper) && (res->closest < 0 || res->cand[k].hat.rho < res->cand[res->closest].hat.rho))
            res->closest = k;
    }
    return ULAM_OK;
}

/* Check the inputs and options. */
static int check(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *a,
                 ulam_auto_result *res, ulam_error *err)
{
    if (!M || !b || !base || !res) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, b, options and a result");
    if (!(a->continue_q > 0 && a->continue_q < 1) || a->pilot_walks < 1 || a->pilot_max < a->pilot_walks ||
        !(a->pilot_share > 0) || !isfinite(a->pilot_share))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a fixed continuation in (0, 1), pilot walks >= 1, pilot_max >= "
                                                   "pilot walks and a pilot share > 0");
    if (M->nrows != M->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    int bad = ulam__walk_opts_check(base, err); /* src/check.c: the options, then M's structure */
    /* a prepared file read lazily (policy.system) verifies each block as the walks reach it */
    if (bad || (!base->policy.system && (bad = ulam__csr_check_structure(M, err)))) return bad;
    if (base->query.index < 0 || base->query.index >= M->nrows)
        return ulam__fail(err, ULAM_EINVAL, 0, base->query.index, "an index from 0 to %lld", (long long)M->nrows - 1);
    return ULAM_OK;
}

/* Free the kernels' solvers but the one kept (kept: -1 none). */
static void free_groups(chooser *c, int kept)
{
    for (int i = 0; i < GROUPS; i++)
        if (i != kept) c->g[i].sv = ulam_solver_free(c->g[i].sv);
}

/* Screen, race, choose, and hand out the solver to run. */
int ulam_auto_solver(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                     ulam_auto_result *res, ulam_solver **out, ulam_error *err)
{
    return ulam__auto_solver_reach(M, b, base, ao, NULL, res, out, err);
}

/* As ulam_auto_solver on the caller's bounds over every state for one kernel (see internal.h). */
int ulam__auto_solver_reach(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                            const ulam__reach *reach, ulam_auto_result *res, ulam_solver **out, ulam_error *err)
{
    ulam__clear(err);
    if (out) *out = NULL;
    ulam_auto_opts a = ao ? *ao : ulam_auto_defaults();
    int status = check(M, b, base, &a, res, err);
    if (status) return status;
    memset(res, 0, sizeof *res);
    res->chosen = res->closest = -1;
    res->by_work = base->stop.rel_err > 0;
    double t0 = ulam_now();
    chooser *c = calloc(1, sizeof *c);
    if (!c) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the choice");
    c->M = M, c->b = b, c->base = *base, c->a = a, c->res = res, c->leader = -1, c->reach = reach;
    c->deadline = base->stop.max_seconds > 0 ? t0 + base->stop.max_seconds : INFINITY; /* the set-up counts, */
    if (base->exec.share && base->exec.share->nranks > 1) c->deadline = INFINITY; /* but every rank chooses alike */
    c->qs[0] = a.pin_continue ? base->kernel.continue_q : 0.0, c->qs[1] = a.continue_q;
    c->nq = a.pin_continue ? 1 : 2;
    c->as[0] = a.pin_alpha ? base->kernel.kernel_alpha : 1.0, c->as[1] = 0.0, c->as[2] = 2.0;
    c->na = a.pin_alpha ? 1 : 3;
    list(c);
    if (!(status = first_stage(c, err)) && !(status = race(c, err))) {
        for (int j = 0; j < res->ncand; j++)
            if (res->cand[j].pilot_walks) refresh(c, j); /* at every pilot's final figures */
        res->chosen = c->leader;
        status = closest(c, err);
    }
    int k = res->chosen >= 0 ? res->chosen : res->closest;
    if (!status && res->chosen >= 0) res->cand[res->chosen].state = ULAM_AUTO_CHOSEN;
    res->pilot_work = spent(c);
    res->reused_work = res->chosen >= 0 ? reused(c, res->chosen) : 0.0;
    if (k >= 0) res->guard = c->guard[c->gi[k] % KERNELS];
    if (!status && out && k >= 0) {
        ulam_walk_opts o = *base;
        o.mode = res->cand[k].mode, o.estimator = res->cand[k].estimator, o.kernel.continue_q = res->cand[k].continue_q;
        o.kernel.kernel_alpha = res->cand[k].kernel_alpha;
        o.policy.guard = &c->guard[c->gi[k] % KERNELS];
        group *g = &c->g[c->gi[k]];
        if (g->sv) {
            ulam__solver_clock(g->sv, -1.0, c->deadline);
            status = ulam__solver_rerun(g->sv, &o, err);
            if (!status) *out = g->sv, g->sv = NULL;
        } else {
            status = alloc_solver(c, &o, out, err);
        }
        if (!status && isfinite(c->deadline)) ulam__solver_clock(*out, t0, c->deadline); /* the walks' limit counts the choice */
    }
    for (int k = 0; k < res->ncand; k++) res->cand[k].predicted_lower = lower_bound(res, k, base->stop.rel_err_offset);
    free_groups(c, -1);
    free(c);
    res->seconds = ulam_now() - t0;
    return status;
}
