/* Bidirectional estimate of one entry x_t of (I - M) x = b for b = e_s or a sparse b: a reverse
 * push from t, then walks from b's states that score the push's residual.
 *
 * The push leaves x_t = <p, b> + <r, x> (src/push.c), and <r, x> = r' (I - M)^-1 b
 * = b' (I - M')^-1 r: the adjoint walk solver on M' with right-hand side r, started at s (or at
 * b's state j with probability |b_j| / ||b||_1 and weight sign(b_j) ||b||_1, its start
 * distribution) estimates it, unbiased, with its error bar, threads and stopping rules.  r is
 * fixed before any of those walks runs (the balance below looks only at the push's work, a
 * pilot and a probe on seeds of their own), so <p, b> + estimate is unbiased for x_t.
 *
 * Plan and balance (as BiPPR balances times, here on work counts so the result is
 * reproducible): a collision walk scores at most rmax at each of its V visits, so its variance
 * is about ||b||_1 rmax E[V] x, and the walk solver's rel_err rule needs at least the walks of its
 * range term for scores of rmax a visit (the solver's own bounds over the states the walks
 * reach, taken from the pilot's solver); the walks needed are the largest of those and the
 * rule's floor, each costing E[V] visits of step_cost push operations.  rmax halves, pushing
 * down to it, while the push's work so far is below the walks' predicted work (at a fixed walk
 * count: below what those walks cost), for |x_t| about the largest of min_value, p_s and a
 * probe's lower bound (see push()).  The interval: honest_interval.  ulam__bidir_plan does this and leaves the
 * pushed workspace with a memo of the plan (bidir.h: the analysis', or one kept with a bare push
 * workspace), which ulam__bidir_solve reuses for the same options and the push as the plan left it
 * instead of pushing again.  Every walk here (pilot, probe, estimate) is handed out by an
 * analysis of M' the memo holds (ulam__analysis_walks), which keeps what later walks share: the
 * bounds over every state (reach_all), the kernel rows (keep_kernel) and the reach a pilot found. */
#include "bidir.h"
#include "defaults.h"
#include "analysis.h"
#include "check.h"
#include "push.h"
#include "solve.h"
#include "stats.h"
#include "stop.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Pilot walks that measure E[V]; the target a run stopped by time alone is planned for.  A walk
 * visit's cost in push operations is ulam_bidir_opts.step_cost (a push operation reads one
 * nonzero and updates one residual, a step draws from a row's alias table and scores it). */
enum { PILOT = 256, PROBE = 1024 };
static const double DEFAULT_REL_ERR = 0.1;

/* The balance's cost of a walk visit in push operations. */
static double step_cost(const ulam_bidir_opts *o)
{
    return o->step_cost > 0 && isfinite(o->step_cost) ? o->step_cost : ULAM_BIDIR_STEP_COST;
}

/* The defaults. */
ulam_bidir_opts ulam__bidir_defaults(void)
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
    if (o->nb == 0 && (o->source < 0 || o->source >= n))
        return ulam__fail(err, ULAM_EINVAL, 0, o->source, "a source from 0 to %lld", (long long)n - 1);
    if (o->nb < 0 || (o->nb > 0 && (!o->b_index || !o->b_value)))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "nb >= 0 entries of b with their indices and values");
    double norm = 0.0;
    for (int64_t j = 0; j < o->nb; j++) {
        if (o->b_index[j] < 0 || o->b_index[j] >= n || !isfinite(o->b_value[j]))
            return ulam__fail(err, ULAM_EINVAL, 0, j, "entries of b at states 0 to %lld with finite values",
                              (long long)n - 1);
        norm += fabs(o->b_value[j]);
    }
    if (o->nb > 0 && !(norm > 0 && isfinite(norm)))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a sparse b with a finite nonzero ||b||_1");
    if (!isfinite(o->rmax) || !isfinite(o->min_value) || o->max_push_ops < 0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a finite rmax, a finite min_value and max_push_ops >= 0");
    return ulam__walk_opts_check(&o->walk, err); /* src/check.c */
}

/* Check a call's arguments (M: w's matrix; out: where its answer goes); err cleared first. */
static int check_call(const ulam_csr *M, ulam_push *w, const ulam_csr *Mt, const ulam_bidir_opts *o, const void *out,
                      ulam_error *err)
{
    ulam__clear(err);
    if (!w || !o || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a push workspace, options and a place for the answer");
    return check_opts(M, Mt, o, err);
}

/* The walk solver's message about walks on M' (adjoint there) said of M: "adjoint" and "forward"
 * swapped, the walks named (a refusal named the mode backwards: "rho(M^) of the adjoint kernel is
 * in [1.087, 1.336]" where on M the adjoint radius is 0.99 and the forward one 1.318). */
static void name_on_M(ulam_error *err)
{
    if (!err) return;
    static const char *const word[2] = {"adjoint", "forward"};
    char out[sizeof err->msg];
    int len = snprintf(out, sizeof out, "the walks from b are forward walks on M: ");
    for (const char *p = err->msg; *p && len < (int)sizeof out - 1;) {
        int w = strncmp(p, word[0], 7) == 0 ? 0 : strncmp(p, word[1], 7) == 0 ? 1 : -1;
        if (w >= 0) len += snprintf(out + len, sizeof out - (size_t)len, "%s", word[1 - w]), p += 7;
        else out[len++] = *p++;
    }
    out[len < (int)sizeof out ? len : (int)sizeof out - 1] = '\0';
    memcpy(err->msg, out, sizeof out);
}

/* The walks' options: adjoint on M' from s (or from b's entries), scoring r. */
static ulam_walk_opts walk_opts(const ulam_bidir_opts *o)
{
    ulam_walk_opts wo = o->walk;
    wo.mode = ULAM_ADJOINT;
    wo.query.index = o->nb > 0 ? o->b_index[0] : o->source;
    wo.query.nstarts = o->nb, wo.query.starts = o->b_index, wo.query.start_weights = o->b_value;
    return wo;
}

/* <v, b> for the dense v (v_s for b = e_s). */
static double dot_b(const double *v, const ulam_bidir_opts *o)
{
    if (o->nb == 0) return v[o->source];
    double sum = 0.0;
    for (int64_t j = 0; j < o->nb; j++) sum += o->b_value[j] * v[o->b_index[j]];
    return sum;
}

/* sum_j |b_j v_j| (|v_s| for b = e_s). */
static double dot_abs_b(const double *v, const ulam_bidir_opts *o)
{
    if (o->nb == 0) return fabs(v[o->source]);
    double sum = 0.0;
    for (int64_t j = 0; j < o->nb; j++) sum += fabs(o->b_value[j] * v[o->b_index[j]]);
    return sum;
}

/* ||b||_1 (1 for e_s). */
static double norm_b(const ulam_bidir_opts *o)
{
    double sum = o->nb == 0 ? 1.0 : 0.0;
    for (int64_t j = 0; j < o->nb; j++) sum += fabs(o->b_value[j]);
    return sum;
}

/* Nonzero when a plan made for (Mt, a) is the plan of (Mt2, b): every option it read agrees. */
static int same_plan(const ulam__bidir *m, const ulam_csr *Mt, const ulam_bidir_opts *b)
{
    const ulam_bidir_opts *a = &m->o;
    const ulam_walk_opts *x = &a->walk, *y = &b->walk;
    if (a->nb != b->nb || (b->nb > 0 && (memcmp(m->idx, b->b_index, (size_t)b->nb * sizeof *m->idx) ||
                                         memcmp(m->val, b->b_value, (size_t)b->nb * sizeof *m->val))))
        return 0;
    return m->Mt == Mt && a->reach_all == b->reach_all && a->target == b->target &&
           (b->nb > 0 || a->source == b->source) && a->rmax == b->rmax && a->min_value == b->min_value &&
           a->max_push_ops == b->max_push_ops && step_cost(a) == step_cost(b) && x->exec.seed == y->exec.seed &&
           x->stop.rel_err == y->stop.rel_err && x->stop.max_walks == y->stop.max_walks && x->kernel.continue_q == y->kernel.continue_q &&
           x->kernel.kernel_alpha == y->kernel.kernel_alpha && x->estimator == y->estimator &&
           x->kernel.roulette == y->kernel.roulette && x->kernel.split == y->kernel.split && x->stop.max_steps == y->stop.max_steps &&
           x->policy.force == y->policy.force && x->policy.assume_finite == y->policy.assume_finite && x->policy.guard == y->policy.guard;
}

/* The pilot's solver: PILOT collision walks from s on Mt (at's matrix) on a seed of their own,
 * scoring 1 at every visit (ones: n of them), with rel_err when the walks have one so that the
 * solver computes its reachability bounds for scores of at most 1 a visit (the balance scales
 * them to rmax); under at's bounds over every state (reach_all), else searching the states its
 * walks reach and keeping them in at for the estimate's walks; with keep_kernel the pilot's
 * kernel (scoring ones) is kept in at for later pilots. */
static int pilot(ulam_analysis *at, const double *ones, const ulam_bidir_opts *o, ulam_solver **out, ulam_error *err)
{
    ulam_walk_opts po = walk_opts(o);
    po.estimator = ULAM_COLLISION;
    po.stop.max_walks = PILOT, po.stop.max_seconds = 0, po.exec.share = NULL, po.kernel.whole_kernel = 0;
    po.exec.threads = 1; /* one partial block: a thread team would only be woken (same result for any count) */
    po.exec.seed = ulam_rng_substream(o->walk.exec.seed, ULAM_STREAM_PILOT, UINT64_C(1) << 32); /* docs/streams.md */
    po.stop.interrupt = NULL;
    int how = ULAM__WALKS_FIXED | (o->reach_all ? ULAM__WALKS_ALL : ULAM__WALKS_FIND) | (o->keep_kernel ? ULAM__WALKS_KEEP : 0);
    return ulam__analysis_walks(at, ones, &po, how, NULL, NULL, out, err);
}

/* Whether b's entries take both signs (then <p, b> and x_t may cancel far below 1 / n). */
static int mixed_signs(const ulam_bidir_opts *o)
{
    int pos = 0, neg = 0;
    for (int64_t j = 0; j < o->nb; j++) pos |= o->b_value[j] > 0, neg |= o->b_value[j] < 0;
    return pos && neg;
}

/* Walks the stopping rule is predicted to need at threshold rmax for a score variance about
 * ||b||_1 rmax E[V] min(xhat, ||b||_1 rmax E[V]) (E[score^2] <= max|score| E|score|, both at most
 * about ||b||_1 rmax E[V]: deep pushes, where xhat alone over-predicted 18x on randsub1000's
 * x_7 for sparse3_b at rmax 7.6e-6) and |x| about xden (the balance's model, ulam__bidir_plan in ulam.h;
 * the rule is the confidence sequence's, stop.h: 2 ln(2 / delta) var / (E x)^2 walks for its
 * variance term); pilot: its solver (NULL: none). */
static double predicted_walks(const ulam_bidir_opts *o, const ulam_solver *pilot, double rmax, double visits,
                              double xhat, double xden)
{
    const ulam_walk_opts *wo = &o->walk;
    if (wo->stop.rel_err <= 0 && wo->stop.max_walks > 0) return (double)wo->stop.max_walks;
    double E = wo->stop.rel_err > 0 ? wo->stop.rel_err : DEFAULT_REL_ERR;
    double top = norm_b(o) * rmax * visits; /* about the largest |score|, so E|score| <= it too */
    double n = fmax((double)ULAM__REL_FIRST, ulam__cs_var_walks(xden, top * fmin(xhat, top), E));
    double range = wo->stop.rel_err > 0 && pilot ? ulam__solver_range_walks(pilot, rmax, 0, xden, E) : 0.0;
    if (isfinite(range)) n = fmax(n, range); /* else the rule bounds the score through its second moment, which
                                               depends on r: not predicted */
    return wo->stop.max_walks > 0 ? fmin(n, (double)wo->stop.max_walks) : n;
}

static int walk(const ulam_csr *Mt, const double *r, const ulam_bidir_opts *o, double push_part,
                ulam__bidir *memo, ulam_walk_result *wr, ulam_guard *g, ulam_error *err);

/* A lower bound on |x_t| from a probe: PROBE walks on a seed of their own scoring the residual
 * as it stands (p_s + their estimate, less two standard errors; 0 when they say nothing).  The
 * final walks run after the push ends on their own seed, so x_t's estimate stays unbiased. */
static double probe(const ulam_csr *Mt, ulam_push *w, const ulam_bidir_opts *o, ulam__bidir *memo)
{
    ulam_bidir_opts po = *o;
    po.walk.stop.rel_err = 0, po.walk.stop.max_walks = PROBE, po.walk.stop.max_seconds = 0, po.walk.stop.interrupt = NULL;
    po.walk.exec.share = NULL, po.walk.exec.threads = 1;
    po.walk.exec.seed = ulam_rng_substream(o->walk.exec.seed, ULAM_STREAM_PROBE, 0); /* docs/streams.md */
    ulam_walk_result wr;
    ulam_guard g;
    double part = dot_b(ulam__push_estimates(w), o);
    if (walk(Mt, ulam__push_residuals(w), &po, part, memo, &wr, &g, NULL) || !(wr.variance > 0)) return 0.0;
    return fmax(0.0, fabs(part + wr.estimate) - 2.0 * wr.std_error);
}

/* Push from t: to o->rmax, or halving rmax while the push's work is below the walks' predicted
 * work; the plan's rmax, push and predicted walks filled in.  The walks are predicted for |x_t|
 * about xhat = the largest of min_value (1 / n), |p_s| and, once the push has spent what the
 * rule's floor of walks costs, a probe's lower bound: planning for 1 / n alone over-predicted the
 * walks a median 2.2x (p90 12x) on the Zipf family of bench_bidir, and the push went on. */
static int push(ulam_push *w, const ulam_csr *Mt, ulam__bidir *memo, const ulam_bidir_opts *o,
                const ulam_solver *pl, int64_t cap, ulam_bidir_plan_info *plan)
{
    const double *p = ulam__push_estimates(w);
    int64_t n = Mt->nrows;
    double delta = o->min_value > 0 ? o->min_value : 1.0 / (double)n, V = plan->mean_visits, cost = step_cost(o);
    double rmax = o->rmax > 0 ? o->rmax : 1.0, walks, seen = 0.0;
    int fixed = o->walk.stop.rel_err <= 0 && o->walk.stop.max_walks > 0; /* walks known without V */
    int probed = fixed || !(o->walk.stop.rel_err > 0) || o->min_value > 0; /* a given min_value is the plan's */
    int signs = mixed_signs(o) && !(o->min_value > 0);
    int status = ulam__push_run(w, rmax, cap); /* balanced: r = e_t, nothing to push yet */
    for (;;) {
        ulam__push_report(w, &plan->push);
        /* the variance at the largest of the |x| scales; with b of both signs |x| itself at what the
           push and the probe have seen (randsub1000's x_7 = -5.1e-4 for sparse3_b, |<p, b>| 4.3e-4, was
           taken as 1 / n = 1e-3: the run walked 4x the walks predicted, beside the rule's 7.4x) */
        double xhat = fmax(fmax(delta, seen), fabs(dot_b(p, o))), xs = fmax(seen, fabs(dot_b(p, o)));
        walks = predicted_walks(o, pl, rmax, V, xhat, signs && xs > 0 ? xs : xhat);
        if (!probed && o->rmax <= 0 && !status && plan->push.support > 0 && walks > ULAM__REL_MIN &&
            (double)plan->push.ops >= ULAM__REL_MIN * V * cost) {
            probed = 1, seen = probe(Mt, w, o, memo), plan->probe = seen;
            continue;
        }
        if (o->rmax > 0 || status || plan->push.support == 0 || (!fixed && walks <= ULAM__REL_MIN) ||
            (double)plan->push.ops >= walks * V * cost || rmax < 0x1p-64 * fmax(delta, fabs(dot_b(p, o))))
            break; /* at the rule's floor more pushing saves no walks; at a fixed walk count it
                      lowers their variance instead, and the push may spend what they do, down to a
                      residual 2^-64 of x_t (below its rounding: on a 50-node PageRank graph
                      100000 walks' work outran the push, which halved rmax into denormals and
                      hit its operation cap) */
        rmax /= 2;
        status = ulam__push_run(w, rmax, cap);
    }
    plan->rmax = rmax;
    plan->push_part = dot_b(p, o);
    plan->predicted_walks = plan->push.support == 0 ? 0.0 : o->rmax > 0 && !fixed ? NAN : walks;
    return status;
}

/* The memo's analysis of Mt for o's continuation and exponent (made again for another Mt or
 * kernel: what it kept was made for the old one); NULL with err filled when memory runs out. */
static ulam_analysis *walks_on(ulam__bidir *memo, const ulam_csr *Mt, const ulam_bidir_opts *o, ulam_error *err)
{
    const ulam_kernel_opts *k = &o->walk.kernel;
    double q = k->continue_q > 0 ? k->continue_q : 0.0;
    if (memo->at && memo->at_K == Mt && memo->at_q == q && memo->at_alpha == k->kernel_alpha) return memo->at;
    memo->at = ulam_analysis_free(memo->at);
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.continue_q = q, ao.kernel_alpha = k->kernel_alpha;
    if (ulam_analysis_alloc(Mt, &ao, &memo->at, err)) return NULL;
    memo->at_K = Mt, memo->at_q = q, memo->at_alpha = k->kernel_alpha;
    return memo->at;
}

/* Plan x_t's estimate on w with memo: the push and the walks' predicted cost (see ulam.h). */
static int plan_on(const ulam_csr *M, const ulam_csr *Mt, ulam_push *w, ulam__bidir *memo, const ulam_bidir_opts *o,
                     ulam_bidir_plan_info *plan, ulam_error *err)
{
    int status = check_call(M, w, Mt, o, plan, err);
    if (status) return status;
    memset(plan, 0, sizeof *plan);
    double t0 = ulam_now();
    int64_t cap = o->max_push_ops > 0 ? o->max_push_ops : 100 * ulam_csr_nnz(M) + 1000000;
    ulam__push_start(w, o->target);
    memo->valid = 0; /* until this plan is whole */
    ulam_solver *pl = NULL;
    plan->target = o->target, plan->balanced = !(o->rmax > 0), plan->mean_visits = 1.0, plan->step_cost = step_cost(o);
    memo->have_guard = memo->found = 0;
    if (plan->balanced && !memo->ones) {
        if (!(memo->ones = ulam__malloc((size_t)M->nrows, sizeof *memo->ones)))
            return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the pilot's scores");
        for (int64_t i = 0; i < M->nrows; i++) memo->ones[i] = 1.0;
    }
    ulam_analysis *at = walks_on(memo, Mt, o, err);
    if (!at) return ULAM_ENOMEM;
    if (o->reach_all && (status = ulam__analysis_bounds_all(at, err))) return status; /* before any work */
    if (plan->balanced) {
        status = pilot(at, memo->ones, o, &pl, err);
        if (status) {
            ulam_solver_free(pl);
            return status;
        }
        ulam_walk_result r;
        ulam_solver_result(pl, &r);
        plan->pilot_walks = r.walks, plan->pilot_steps = r.steps;
        plan->mean_visits = r.walks > 0 ? 1.0 + (double)r.steps / (double)r.walks : 1.0;
        ulam__solver_guard(pl, &memo->guard);
        memo->have_guard = 1;
        memo->found = !o->reach_all; /* the walks' reach, kept in at: the estimate's solver need not search again */
    }
    status = push(w, Mt, memo, o, pl, cap, plan);
    if (pl) ulam__solver_setup(pl, &plan->pilot_units, &plan->pilot_reads);
    ulam_solver_free(pl);
    if (status == ULAM_ENOCONV)
        return ulam__fail(err, status, 0, -1, "a push within %lld operations (is rho(|M|) < 1?)", (long long)cap);
    double pilot_visits = (double)(plan->pilot_walks + plan->pilot_steps);
    plan->predicted_work = plan->balanced || plan->predicted_walks == 0.0
                               ? (double)plan->push.ops + plan->step_cost * (pilot_visits + plan->predicted_walks * plan->mean_visits)
                               : NAN; /* rmax given: no pilot measured V */
    plan->seconds = ulam_now() - t0;
    if (o->nb > memo->cap) { /* keep b's entries: the options point at the caller's */
        int64_t *idx = realloc(memo->idx, (size_t)o->nb * sizeof *idx);
        if (idx) memo->idx = idx;
        double *val = idx ? realloc(memo->val, (size_t)o->nb * sizeof *val) : NULL;
        if (val) memo->val = val, memo->cap = o->nb;
    }
    if (o->nb > memo->cap) return ULAM_OK; /* no room to remember b: a solve plans again */
    if (o->nb > 0) {
        memcpy(memo->idx, o->b_index, (size_t)o->nb * sizeof *memo->idx);
        memcpy(memo->val, o->b_value, (size_t)o->nb * sizeof *memo->val);
    }
    memo->o = *o, memo->Mt = Mt, memo->plan = *plan, memo->valid = 1;
    memo->w = w, memo->stamp = ulam__push_stamp(w);
    return ULAM_OK;
}

/* Walks on Mt from s scoring r until a stopping rule holds; the result in *wr.  The solver's
 * rel_err rule (the one of ulam_solve_walks) applies to the whole estimate push_part + <r, x>;
 * memo: the pilot's guards on Mt, and its analysis of Mt hands out the walks: under every state's
 * bounds (reach_all), or the states this plan's pilot found the walks reach, with the kernel rows
 * earlier walks built (keep_kernel). */
static int walk(const ulam_csr *Mt, const double *r, const ulam_bidir_opts *o, double push_part,
                ulam__bidir *memo, ulam_walk_result *wr, ulam_guard *g, ulam_error *err)
{
    memset(wr, 0, sizeof *wr);
    ulam_walk_opts wo = walk_opts(o);
    wo.stop.rel_err_offset = push_part;
    if (!wo.policy.guard && memo->have_guard) wo.policy.guard = &memo->guard;
    ulam_analysis *at = walks_on(memo, Mt, o, err);
    if (!at) return ULAM_ENOMEM;
    int how = (o->reach_all ? ULAM__WALKS_ALL : memo->found ? ULAM__WALKS_FOUND : 0) | (o->keep_kernel ? ULAM__WALKS_KEEP : 0);
    int status = ulam__analysis_walks(at, r, &wo, how, wr, g, NULL, err); /* the solver searches should x_t be 0 */
    if (status == ULAM_EINFVAR) name_on_M(err);
    return status;
}

/* The certified bound D on the walk part: |<r, x>| <= max|r| ||x||_1 <= max|r| ||b||_1 /
 * (1 - ||M||_1), ||M||_1 the largest row sum of |Mt| (the guards' one-pass bound); INFINITY when
 * that is not below 1 or was not computed. */
static double walk_part_bound(const ulam_push_info *push, const ulam_guard *g, const ulam_bidir_opts *o)
{
    double c = g ? g->abs.rowsum_max : INFINITY;
    return g && (g->computed & ULAM_GUARD_ABS) && c < 1.0 ? push->r_max * norm_b(o) / (1.0 - c) : INFINITY;
}

/* The interval of x_t: the walk solver's own (its confidence sequence on the certified range of
 * one walk's score, src/stop.h, or withheld), except that, without a certified score bound or
 * range (tail_bound: the length tail's clip or the second moment's), a sample of one repeated
 * score (the walks saw nothing else: its variance says nothing about what they missed) gets the
 * certified bound D of the walk part instead; either is clipped to
 * push_part -+ D.  Never zero-width while a residual is left unless D = 0. */
static void honest_interval(ulam_bidir_result *res, double D, const ulam_walk_opts *wo)
{
    const ulam_walk_result *w = &res->walks;
    double lo = res->push_part + w->ci95[0], hi = res->push_part + w->ci95[1];
    (void)wo;
    if (!(w->walks > 0 && (isfinite(w->score_bound) || isfinite(w->tail_bound))) && w->walks > 0 && !(w->variance > 0))
        lo = res->push_part - D, hi = res->push_part + D; /* NaN-free: D may be INFINITY (no bound) */
    if (isfinite(D)) lo = fmax(lo, res->push_part - D), hi = fmin(hi, res->push_part + D);
    if (!isfinite(lo) || !isfinite(hi)) lo = hi = NAN; /* withheld: nothing certifies one */
    res->ci95[0] = lo, res->ci95[1] = hi;
}

/* The allowance for the arithmetic's error: each push operation rounds p_j += r_j or
 * r_k += M_kj r_j, so <p, b> + <r, x> misses x_t by roundings that add up over the push; the
 * interval is widened either side by (ops + nb + 2) u sum_j |p_j b_j| (u the unit roundoff: a
 * generous allowance, 4e-11 against the 8e-17 they added up to on a 2000-state PageRank graph
 * after 8e5 operations, and far below any interval the walks give), so a push taken down to
 * rounding does not print a zero-width interval beside x_t. */
static double rounding_allowance(const ulam_push *w, const ulam_push_info *push, const ulam_bidir_opts *o)
{
    return ulam__push_rounding((double)push->ops + (double)o->nb + 2.0, dot_abs_b(ulam__push_estimates(w), o));
}

/* A rel_err target's outcome as the printed interval gives it: met when that interval is finite
 * and its half-width is within E |x_t|.  The walk rule judged its own interval of push_part +
 * <r, x>, whose truncation bias floors at 1e-6 |push_part + <r, x>| (plan_terms), before the clip
 * to push_part -+ D and the rounding allowance; a push that left no residual ran no walks and no
 * rule.  Either said NOT met beside an interval within the target (chain4 at E = 1e-12: +-2.8e-13
 * against 2.9e-12, exit 5; dag5's exact x).  Met here, the walks' "stopped early" and predicted
 * count no longer apply (min_walks: the walks run, which sufficed). */
static void rel_err_outcome(ulam_bidir_result *res, double E)
{
    ulam_walk_result *w = &res->walks;
    w->rel_err_met = ulam__stop_printed_met(res->ci95[0], res->ci95[1], res->estimate, E);
    if (w->rel_err_met) w->out_of_reach = 0, w->min_walks = fmin(w->min_walks, (double)w->walks);
}

/* Estimate x_t of (I - M) x = b (e_s or a sparse b) on w with memo. */
static int solve_on(const ulam_csr *M, const ulam_csr *Mt, ulam_push *w, ulam__bidir *memo, const ulam_bidir_opts *o,
                      ulam_bidir_result *res, ulam_error *err)
{
    int status = check_call(M, w, Mt, o, res, err);
    if (status) return status;
    memset(res, 0, sizeof *res);
    if (memo->valid && memo->w == w && memo->stamp == ulam__push_stamp(w) && same_plan(memo, Mt, o))
        res->plan = memo->plan, res->plan_reused = 1;
    else if ((status = plan_on(M, Mt, w, memo, o, &res->plan, err))) return status;
    double t0 = ulam_now();
    ulam__push_report(w, &res->push);
    res->push_part = res->plan.push_part;
    ulam_guard g = {0};
    if (res->push.support > 0 && (status = walk(Mt, ulam__push_residuals(w), o, res->push_part, memo, &res->walks, &g, err)))
        return status;
    res->estimate = res->push_part + res->walks.estimate;
    res->std_error = res->walks.std_error;
    res->ci95[0] = res->push_part + res->walks.ci95[0];
    res->ci95[1] = res->push_part + res->walks.ci95[1];
    if (res->push.support > 0) {
        ulam_walk_opts wo = walk_opts(o);
        honest_interval(res, walk_part_bound(&res->push, &g, o), &wo);
    }
    double fp = rounding_allowance(w, &res->push, o);
    res->ci95[0] -= fp, res->ci95[1] += fp; /* NaN (withheld) stays NaN */
    if (o->walk.stop.rel_err > 0) rel_err_outcome(res, o->walk.stop.rel_err);
    res->seconds = res->plan.seconds + (ulam_now() - t0);
    return ULAM_OK;
}

/* Plan x_t's estimate on a bare push workspace with the caller's memo (see bidir.h). */
int ulam__bidir_plan(ulam_push *w, ulam__bidir *memo, const ulam_csr *Mt, const ulam_bidir_opts *o,
                     ulam_bidir_plan_info *plan, ulam_error *err)
{
    if (w && !memo) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a memo for the plan");
    return plan_on(w ? ulam__push_matrix(w) : NULL, Mt, w, memo, o, plan, err);
}

/* Estimate x_t on a bare push workspace with the caller's memo (see bidir.h). */
int ulam__bidir_solve(ulam_push *w, ulam__bidir *memo, const ulam_csr *Mt, const ulam_bidir_opts *o,
                      ulam_bidir_result *res, ulam_error *err)
{
    if (w && !memo) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a memo for the plan");
    return solve_on(w ? ulam__push_matrix(w) : NULL, Mt, w, memo, o, res, err);
}

/* The analysis' transpose, push workspace and memo (made at the first call); 0 or a status. */
static int take(ulam_analysis *a, const ulam_csr **Mt, ulam_push **w, ulam__bidir **memo, ulam_error *err)
{
    if (!a) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis");
    if (!(*Mt = ulam__analysis_transpose(a, NULL, err)) || !(*w = ulam__analysis_push(a, err))) return ULAM_ENOMEM;
    return (*memo = ulam__analysis_bidir(a, err)) ? ULAM_OK : ULAM_ENOMEM;
}

/* Plan on an analysis (any kernel: the memo keys its plans on the options). */
int ulam__bidir_plan_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_plan_info *plan, ulam_error *err)
{
    const ulam_csr *Mt;
    ulam_push *w;
    ulam__bidir *m;
    int status = take(a, &Mt, &w, &m, err);
    return status ? status : plan_on(ulam__analysis_matrix(a), Mt, w, m, o, plan, err);
}

/* Estimate on an analysis (any kernel). */
int ulam__bidir_solve_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_result *res, ulam_error *err)
{
    const ulam_csr *Mt;
    ulam_push *w;
    ulam__bidir *m;
    int status = take(a, &Mt, &w, &m, err);
    return status ? status : solve_on(ulam__analysis_matrix(a), Mt, w, m, o, res, err);
}

/* Estimate on an analysis of its own kernel (see ulam.h). */
int ulam_analysis_bidir(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_result *res, ulam_error *err)
{
    ulam__clear(err);
    if (!a || !o || !res) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis, options and a place for the answer");
    double q, alpha;
    ulam__analysis_kernel(a, &q, &alpha);
    const ulam_kernel_opts *k = &o->walk.kernel;
    if ((k->continue_q > 0 ? k->continue_q : 0.0) != q || k->kernel_alpha != alpha)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the analysis' continuation %g and kernel exponent %g", q, alpha);
    return ulam__bidir_solve_on(a, o, res, err);
}
