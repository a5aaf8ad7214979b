/* The method table's bidirectional row: a reverse push from the index and walks from a sparse b
 * (src/bidir.c), or with a dense b the push on b and walks from the index scoring its residual
 * (src/bpush.c), considered by the choice against the walks' leader (rent or buy: it needs M's
 * transpose) with its push capped at half the leader's predicted work, chosen when its own
 * predicted work is below the leader's.  At a fixed budget (--walks, the default 10^5, or --time)
 * the push on b is considered too, where the range term of the walks' interval would dominate
 * (fixed_predict).  The transpose, the push workspace and the plan memo are
 * an analysis' (src/analysis.c): the caller's (ulam_analysis_start), made once for all its
 * queries, or one of the run's own. */
#include "analysis.h"
#include "bidir.h"
#include "bkrylov.h"
#include "bpush.h"
#include "csr.h"
#include "method_row.h"
#include "solve.h"
#include "stats.h"
#include "stop.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The densest b the reverse-push route takes: nonzeros at most max(16, n / 10). */
int64_t ulam_method_sparse_limit(int64_t n)
{
    return n / 10 > 16 ? n / 10 : 16;
}

/* b's nonzeros, counted up to cap (a prepared b is read no further than the answer needs). */
static int64_t nonzeros_upto(const double *b, int64_t n, int64_t cap)
{
    int64_t k = 0;
    for (int64_t i = 0; i < n && k < cap; i++) k += b[i] != 0.0;
    return k;
}

/* b's nonzeros. */
static int64_t nonzeros(const double *b, int64_t n)
{
    return nonzeros_upto(b, n, INT64_MAX);
}

/* The route: 1 the push on b (dense b, or an estimator or exponent pinned), 0 the reverse push. */
int ulam__method_bidir_route(const double *b, int64_t n, const ulam_auto_opts *ao, const ulam_walk_opts *o)
{
    if (!b || !o) return 0;
    int64_t limit = ulam_method_sparse_limit(n);
    return nonzeros_upto(b, n, limit + 1) > limit ||
           (ao && (ao->pin_estimator || (ao->pin_alpha && o->kernel.kernel_alpha != 1.0)));
}

static int index_walks(const ulam_choice *ch);

/* An adjoint query with a rel_err target (or a fixed budget and a b for the push on b), nothing
 * pinned it cannot honour, a walk leader to compare with whose predicted work W exceeds nnz(M)/4,
 * and a nonzero b. */
static int applies(const ulam__query *q, int k, char *why, size_t len)
{
    const ulam_walk_opts *o = q->o;
    const ulam_auto_result *au = &q->ch->walks;
    int64_t n = q->M->nrows, nb = nonzeros_upto(q->b, n, 1); /* whether b is zero */
    const char *pinned = o->mode == ULAM_FORWARD ? "forward mode (--mode forward, --out, --errors)"
                         : o->kernel.roulette > 0 || o->kernel.split > 0 ? "--roulette or --split (bidirectional takes neither)"
                                                           : NULL;
    double nnz = (double)ulam_csr_nnz(q->M), W = q->ch->leader_work;
    if (pinned) snprintf(why, len, "not considered: %s", pinned);
    else if (ulam__method_excluded(q, k, why, len)) return 0;
    else if (!(o->stop.rel_err > 0) && !ulam__method_bidir_route(q->b, n, q->ao, o) && !index_walks(q->ch))
        snprintf(why, len, "not considered: no --rel-err target with a sparse b and no certified walks from the index "
                           "for the push on b (without a target auto compares variance x work a walk, which the "
                           "reverse push has no figure for)");
    else if (au->chosen < 0) snprintf(why, len, "not considered: no certified walk method to compare with");
    else if (nb == 0) snprintf(why, len, "not considered: b is zero");
    else if (!(W > nnz / 4))
        snprintf(why, len, "not considered: the walks' predicted work %.3g is below nnz(M)/4 = %.3g (the transpose "
                           "alone would cost more)", W, nnz / 4);
    else return 1;
    return 0;
}

/* The plan's predicted work in the units of the walks' work model (ULAM_AUTO_*, one walk step),
 * so that it compares with the walk leader's: the plan counts a push operation (one nonzero of M
 * read, one residual updated) and a walk visit as one operation each; here a push operation
 * counts as a matrix entry read (ULAM_AUTO_READ), a walk as its steps (V - 1) plus its start and
 * record (ULAM_AUTO_WALK), the kernel rows on M' the pilot built and those the estimate's walks
 * would build (as many a walk; the whole kernel once they pass 1 / ULAM__COMPLETE of it,
 * as the solver does) ULAM_AUTO_BUILD each, its reachability and bound reads twice (pilot and
 * estimate), and the transpose (2 nnz reads) and the guards on M' (twice: the pilot's and the
 * report's, as many reads as guard g's) that the walks do not need. */
static double work(const ulam_csr *M, const ulam_bidir_plan_info *p, const ulam_guard *g)
{
    double nnz = (double)ulam_csr_nnz(M), walks = (double)p->pilot_walks + p->predicted_walks;
    double cap = nnz + 3.0 * (double)M->nrows, u = (double)p->pilot_units;
    double est = p->pilot_walks > 0 ? fmin(cap, u * p->predicted_walks / (double)p->pilot_walks) : cap;
    if (est * ULAM__COMPLETE > cap) est = cap;
    double guard = (1.0 + g->abs.iterations + g->hat[ULAM_ADJOINT].iterations) * nnz;
    return ULAM_AUTO_READ * ((double)p->push.ops + 2.0 * (double)p->pilot_reads + 2.0 * nnz + 2.0 * guard) +
           walks * (p->mean_visits - 1.0 + ULAM_AUTO_WALK) + ULAM_AUTO_BUILD * (u + est);
}

/* Free what the run keeps for bidirectional (an analysis of its own with it). */
static void release(ulam_run *r)
{
    free(r->idx), free(r->val), free(r->bq), free(r->br);
    r->bq = r->br = NULL;
    r->bkiters = 0, r->bdelta = 0.0, r->bvisits = INFINITY;
    if (r->own_an) ulam_analysis_free(r->an);
    r->an = NULL, r->own_an = 0, r->Mt = NULL;
    r->idx = NULL, r->val = NULL;
    r->bo.b_index = NULL, r->bo.b_value = NULL;
}

/* The analysis' transpose in r->Mt (the query's analysis, or one the run makes), its making time
 * in the choice (0 when the analysis had it); 0 or a status. */
static int transpose(ulam__query *q, ulam_error *err)
{
    ulam_run *r = q->run;
    ulam_error e;
    if (!r->an && q->an) r->an = q->an;
    else if (!r->an) { /* the run's own: the default kernel (the row's plans key on the options' own) */
        int status = ulam_analysis_alloc(q->M, NULL, &r->an, &e);
        if (status) return ulam__fail(err, status, 0, -1, "memory for the transpose and the push");
        r->own_an = 1;
    }
    if (!(r->Mt = ulam__analysis_transpose(r->an, &q->ch->transpose_seconds, &e)))
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the transpose and the push");
    return ULAM_OK;
}

/* The options, b's nonzeros and the analysis' transpose (walk: the walks' options). */
static int setup(ulam__query *q, const ulam_walk_opts *walk, ulam_error *err)
{
    ulam_run *r = q->run;
    int64_t n = q->M->nrows, nb = nonzeros(q->b, n);
    r->bo = ulam_bidir_defaults();
    r->bo.walk = *walk;
    r->bo.target = walk->query.index;
    r->idx = malloc((size_t)(nb ? nb : 1) * sizeof *r->idx), r->val = malloc((size_t)(nb ? nb : 1) * sizeof *r->val);
    int status = r->idx && r->val ? transpose(q, err) : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the transpose and the push");
    if (status) {
        release(r);
        return status;
    }
    for (int64_t i = 0, j = 0; i < n; i++)
        if (q->b[i] != 0.0) r->idx[j] = i, r->val[j++] = q->b[i];
    r->bo.nb = nb, r->bo.b_index = r->idx, r->bo.b_value = r->val;
    return ULAM_OK;
}

/* Pilot walks of the dense route: one round of the walk solver on the residual; at a fixed
 * budget, at most FIXED_ROUNDS rounds of push and pilot. */
enum { DENSE_PILOT = 1024, FIXED_ROUNDS = 4 };
/* A fixed budget's walks led by their variance: the push on b is piloted where the range term is at least
 * VARLED_SHARE of the variance term, its first round within 1 / VARLED_CAP of the push's cap (fixed_predict). */
#define VARLED_SHARE 0.125
enum { VARLED_CAP = 8 };

/* The dense route's walks' options: adjoint from the index with kernel c's estimator,
 * continuation and exponent (c NULL: o's), the push part q_i as the rule's offset. */
static ulam_walk_opts dense_walk_opts(const ulam_walk_opts *o, const ulam_auto_candidate *c, double qi)
{
    ulam_walk_opts wo = *o;
    wo.mode = ULAM_ADJOINT, wo.query.nstarts = 0, wo.query.starts = NULL, wo.query.start_weights = NULL, wo.policy.guard = NULL;
    if (c) wo.estimator = c->estimator, wo.kernel.continue_q = c->continue_q, wo.kernel.kernel_alpha = c->kernel_alpha;
    wo.stop.rel_err_offset = o->stop.rel_err_offset + qi;
    return wo;
}

/* The rule's rmax: max|b| nv / N (N the walks the rule predicts on b, nv = var / (E m)^2 those
 * the variance alone asks: the range term, linear in max|r|, then asks about what the variance
 * does). */
static double rule_rmax(const double *b, int64_t n, double var, double m, double N, double E)
{
    double bmax = ulam__bpush_max(b, n), nv = var / (E * m * E * m);
    return isfinite(N) && N > 0 && nv > 0 ? bmax * fmin(1.0, nv / N) : bmax;
}

/* The |x| a pilot round on the residual predicts the walks at: its mean |q_i + estimate| (mt,
 * standard error se) when that is at least 4 standard errors from 0, else the largest |x| it and
 * the walk candidate c (NULL: none; its pilots estimate the same x) allow, the least |mean| + 2
 * standard errors, at which the prediction is a lower bound (as src/auto.c's scale_of).  Before,
 * a mean of noise was believed: randsub1000's x_7 for sparse3_b with the expected estimator
 * pinned, a pilot mean of -2.3e-6 +- 5.8e-4 (x = -5.1e-4) predicted 1.2e12 walks at E = 0.02, 1.1e5
 * times the 1.1e7 at 0.04. */
static double pilot_scale(double mt, double se, const ulam_auto_candidate *c, double off)
{
    if (mt >= 4.0 * se) return mt;
    double m = mt + 2.0 * se;
    if (c && c->pilot_walks > 1 && c->variance > 0 && isfinite(c->estimate))
        m = fmin(m, fabs(c->estimate + off) + 2.0 * sqrt(c->variance / (double)c->pilot_walks));
    return m > 0 && isfinite(m) ? m : isfinite(se) ? mt : INFINITY; /* a pilot with no standard error
                                                                         (no history ended): no scale, a lower bound */
}

/* The Krylov start's tolerance on ||r||_2 / ||b||_2: E / 64 under a rel_err target E (the
 * residual's walks then carry a small part of x's noise), 1e-6 at a fixed budget. */
static double krylov_tol(double E)
{
    return E > 0 ? fmin(1e-3, E / 64.0) : 1e-6;
}

/* The work of `iters` CG products on M in matrix entries read (a product and five vector passes). */
static double krylov_ops(const ulam_csr *M, int iters)
{
    return (double)iters * ((double)ulam_csr_nnz(M) + 5.0 * (double)M->nrows);
}

/* The CG products the Krylov start may spend (half the push's cap max_ops; at most 10^5), or 0
 * for none: M not symmetric (CG asks a symmetric I - M; the push alone then), or a cap below 16
 * products. */
static int krylov_iters(const ulam_csr *M, int64_t max_ops)
{
    double per = krylov_ops(M, 1), it = (double)max_ops / per;
    if (!(it >= 16.0) || !ulam__csr_symmetric(M)) return 0;
    return it > 1e5 ? 100000 : (int)it;
}

/* The dense route (b has more nonzeros than ulam_method_sparse_limit): the transpose, b pushed
 * down to rmax within max_ops, and a pilot round of the walks on the residual (into *wr), whose
 * rule (src/stop.c, on the residual's own range) predicts the walks; the plan in ch->bidir.  c:
 * the kernel the walks run with (NULL: o's).  Called again on the same run, the push goes on
 * from where it stopped (its operations counted from the first call, max_ops theirs in all) and
 * a new pilot runs on the new residual. */
static int dense_plan(ulam__query *q, const ulam_walk_opts *o, const ulam_auto_candidate *c, double rmax,
                      int64_t max_ops, ulam_walk_result *wr_out, ulam_error *err)
{
    ulam_run *r = q->run;
    ulam_bidir_plan_info *pl = &q->ch->bidir;
    int64_t n = q->M->nrows, ops = 0, pushes = 0, nnz = ulam_csr_nnz(q->M), pw = 0, ps = 0;
    double E = o->stop.rel_err, t0 = ulam_now(), push_s = 0.0;
    int status = ULAM_OK;
    if (r->bq && r->br) { /* going on */
        ops = pl->push.ops, pushes = pl->push.pushes, push_s = pl->push.seconds;
        pw = pl->pilot_walks, ps = pl->pilot_steps, t0 -= pl->seconds;
    } else {
        memset(pl, 0, sizeof *pl);
        r->bq = calloc((size_t)n, sizeof *r->bq), r->br = malloc((size_t)n * sizeof *r->br);
        status = r->bq && r->br ? transpose(q, err) : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the transpose and the push on b");
        if (status) return release(r), status;
        memcpy(r->br, q->b, (size_t)n * sizeof *r->br);
        r->bkiters = 0, r->bdelta = 0.0, r->bvisits = INFINITY;
        int it = krylov_iters(q->M, max_ops);
        if (it > 0) { /* a Krylov start: q from CG, the push and the walks on its residual */
            double tk = ulam_now();
            if ((status = ulam__bkrylov(q->M, q->b, krylov_tol(E), it, r->bq, r->br, &r->bdelta, &r->bkiters)))
                return release(r), ulam__fail(err, status, 0, -1, "memory for the Krylov start");
            push_s += ulam_now() - tk;
            r->bvisits = ulam__bkrylov_visits(q->M);
        }
    }
again:;
    double tp = ulam_now();
    if ((status = ulam__bpush(r->Mt, rmax, max_ops, r->bq, r->br, &ops, &pushes)))
        return release(r), ulam__fail(err, status, 0, -1, "memory for the push on b");
    push_s += ulam_now() - tp;
    double qi = r->bq[o->query.index];
    r->bwo = dense_walk_opts(o, c, qi);
    ulam_walk_opts po = r->bwo;
    po.stop.max_walks = DENSE_PILOT, po.stop.max_seconds = 0, po.stop.interrupt = NULL, po.exec.share = NULL;
    po.exec.seed = ulam_rng_substream(o->exec.seed, ULAM_STREAM_PILOT, (UINT64_C(1) << 32) + 1); /* docs/streams.md */
    ulam_solver *sv = NULL;
    ulam_walk_result wr;
    status = ulam_solver_alloc(q->M, r->br, &po, &sv, err);
    while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
    if (!status) ulam_solver_result(sv, &wr);
    if (!status && r->bkiters > 0) r->bvisits = fmin(r->bvisits, ulam__solver_visits_bound(sv));
    ulam_solver_free(sv);
    if (status) return status;
    if (r->bkiters > 0 && !isfinite(r->bdelta * r->bvisits)) { /* no bound on the start's rounding's reach (no
        length tail, rows of |M| summing to 1 or more): the push from q = 0, as without the start */
        memset(r->bq, 0, (size_t)n * sizeof *r->bq), memcpy(r->br, q->b, (size_t)n * sizeof *r->br);
        r->bkiters = 0, r->bdelta = 0.0, ops = pushes = 0;
        goto again;
    }
    if (wr_out) *wr_out = wr;
    double mt = fabs(qi + wr.estimate + o->stop.rel_err_offset), V = wr.walks ? (double)wr.steps / (double)wr.walks : 0.0;
    double m = pilot_scale(mt, wr.std_error, c, o->stop.rel_err_offset);
    /* the rule's walks (the sequence's, stop.h) at scale m: the pilot's own prediction where its mean
       resolves |x|, else at least its terms carried to m (each falls at least as (mt / m)^2) */
    double need = E > 0 ? fmax((double)ULAM__REL_FIRST, fmax(m == mt ? wr.min_walks : wr.min_walks * (mt / m) * (mt / m),
                                                           ulam__cs_var_walks(m, wr.variance, E)))
                        : (double)o->stop.max_walks; /* a fixed budget: fixed_predict sets it */
    r->blower = m != mt;
    mt = m;
    pl->target = o->query.index, pl->rmax = rmax, pl->balanced = 1, pl->push_part = qi;
    pl->push = (ulam_push_info){.target = o->query.index, .rmax = rmax, .pushes = pushes, .ops = ops, .seconds = push_s};
    ulam__bpush_residual(r->bq, r->br, n, &pl->push);
    pl->push.krylov = r->bkiters;
    pl->pilot_walks = pw + wr.walks, pl->pilot_steps = ps + wr.steps, pl->mean_visits = V + 1.0;
    pl->predicted_walks = mt > 0 ? need : INFINITY, pl->step_cost = 1.0;
    pl->predicted_work = ULAM_AUTO_READ * ((double)ops + 2.0 * (double)nnz + krylov_ops(q->M, r->bkiters)) +
                         ((double)pl->pilot_walks + pl->predicted_walks) * (V + ULAM_AUTO_WALK);
    pl->seconds = ulam_now() - t0;
    r->bplan = *pl;
    return ULAM_OK;
}

/* A pilot round (DENSE_PILOT walks) of o's walks on b, on pilot k's seed (docs/streams.md), into *wr. */
static int pilot_on(const ulam_csr *M, const double *b, const ulam_walk_opts *o, uint64_t k, ulam_walk_result *wr,
                    ulam_error *err)
{
    ulam_walk_opts po = *o;
    po.stop.max_walks = DENSE_PILOT, po.stop.max_seconds = 0, po.stop.interrupt = NULL, po.exec.share = NULL;
    po.exec.seed = ulam_rng_substream(o->exec.seed, ULAM_STREAM_PILOT, k);
    ulam_solver *sv = NULL;
    int status = ulam_solver_alloc(M, b, &po, &sv, err);
    while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
    if (!status) ulam_solver_result(sv, wr);
    ulam_solver_free(sv);
    return status;
}

/* The range of a pilot's single score: tail_bound walks |estimate + off| (off: its options'
 * rel_err_offset, which tail_bound's scale held; the residual's walks carry q_i there). */
static double pilot_range(const ulam_walk_result *w, double off)
{
    return w->tail_bound * (double)w->walks * fabs(w->estimate + off);
}

/* The 95% interval n walks would give at a pilot's variance and range (pilot_range at off), at
 * a count fixed in advance (src/stop.h): *ci, whose half is INFINITY when the pilot has no range. */
static void interval_at(const ulam_walk_result *w, double off, double n, ulam__stop_ci *ci)
{
    double R = pilot_range(w, off);
    *ci = (ulam__stop_ci){.half = INFINITY, .var_term = INFINITY, .range_term = INFINITY};
    if (R >= 0 && isfinite(R) && n >= 2 && n < 4e18 && isfinite(w->variance))
        ulam__stop_interval((int64_t)n, w->estimate, w->variance, R, 0.0, 0.0, INFINITY, 0, ci);
}

/* A pilot round of the walks leader on b (pilot k's seed, docs/streams.md) on its own solver, which is then set
 * back to the run's options (ulam__solver_rerun: the same walks as before, bit for bit; its rows,
 * reachable set and bounds are reused, so the pilot costs its walks alone), into *wr. */
static int leader_pilot(ulam_run *r, uint64_t k, ulam_walk_result *wr, ulam_error *err)
{
    ulam_walk_opts po = r->o;
    po.stop.max_walks = DENSE_PILOT, po.stop.max_seconds = 0, po.stop.interrupt = NULL, po.exec.share = NULL;
    po.exec.seed = ulam_rng_substream(r->o.exec.seed, ULAM_STREAM_PILOT, k);
    int status = ulam__solver_rerun(r->sv, &po, err);
    while (!status && !ulam_solver_done(r->sv)) status = ulam_solver_iterate(r->sv);
    if (!status) ulam_solver_result(r->sv, wr);
    int back = ulam__solver_rerun(r->sv, &r->o, NULL);
    return status ? status : back;
}

/* A fixed budget (a walk count, or --time: the walks the work it buys pays for, src/method_walks.c): the leader's
 * interval at that budget, predicted from a pilot of its own walks on b; where its range term
 * leads (a large b_j the walks reach rarely), b pushed down to rmax = max|b| times the variance
 * term over the range term (the range term, linear in max|r|, then about the variance term)
 * within W / 2 operations, and the walks on the residual piloted; while the residual's range
 * term still leads (the push lowers the variance too), rmax goes down by the same rule and the
 * push on (FIXED_ROUNDS at most).  Predicted work: the walks the residual needs for the leader's
 * interval at the budget (the push, transpose and pilots are spent by then either way); chosen,
 * it runs the budget's walks (a narrower interval at the same count). */
static int fixed_predict(ulam__query *q, int k, double W, ulam_error *err)
{
    ulam_choice *ch = q->ch;
    ulam_method_verdict *v = &ch->method[k];
    const ulam_auto_candidate *c = &ch->walks.cand[ch->walks.chosen];
    double N = q->o->stop.max_walks > 0 ? (double)q->o->stop.max_walks : floor(W / c->work_per_walk);
    ulam_walk_result wb, wr;
    int status = q->run->sv ? leader_pilot(q->run, (UINT64_C(1) << 32) + 3, &wb, err) : ULAM_EINVAL;
    if (status) return status == ULAM_ENOMEM ? status : ULAM_OK; /* the leader's own run will say why */
    ulam__stop_ci cb, cr;
    interval_at(&wb, q->o->stop.rel_err_offset, N, &cb);
    /* a pilot on b that saw no score (a sparse b the walks reach rarely) has no variance and no range
       to go by, and a zero variance must not be believed: the walks' interval is then planned from the
       residual's walks below, whose range scaled by max|b| / max|r| bounds theirs */
    double scale = wb.estimate * wb.push_residual; /* a forward leader's walks start from the push's residual: */
    int blind = wb.walks > 0 && !(wb.variance > 1e-12 * scale * scale) && q->o->stop.rel_err_offset == 0.0;
    /* (every score alike up to rounding: a variance of 3.1e-33 against an actual 3.6e8 was believed; the
       rounding is the residual's, ||r||_1 / ||b||_1 of b's: chain4's x_3, absorption pinned, seed 7, 10^5
       walks, a forward leader pushed to its rounding was taken for blind, and bidirectional was piloted
       (1024 walks) to lose at -+0.03 against the walks' -+1.6e-15) */
    /* led by the variance, but with a range term of at least VARLED_SHARE of it (rare large scores: the push
       that takes the large b_j out lowers the variance too; metastable40's x_1 at 10^5 walks, range 0.034
       against 0.098, and the push printed -+0.016 against the walks' -+0.034): one round of push at most
       cap / VARLED_CAP operations, and on while each round narrows the predicted interval by a quarter */
    int varled = !blind && !(cb.range_term > cb.var_term) && cb.range_term >= VARLED_SHARE * cb.var_term;
    if (!blind && ((!(cb.range_term > cb.var_term) && !varled) || !isfinite(cb.half))) {
        snprintf(v->why, sizeof v->why, "not considered: at %.3g walks the walks' interval is not led by its range "
                 "term (%.3g, variance term %.3g): a push on b would narrow it little", N, cb.range_term, cb.var_term);
        return ULAM_OK;
    }
    double bmax = ulam__bpush_max(q->b, q->M->nrows);
    double rmax = blind ? 0.5 * bmax : varled ? bmax / 16.0 : bmax * cb.var_term / cb.range_term, prev = cb.half;
    int64_t cap = W / 2 < 1 ? 1 : W / 2 < 1e18 ? (int64_t)(W / 2) : INT64_MAX;
    int64_t rcap = varled && cap / VARLED_CAP > 0 ? cap / VARLED_CAP : cap;
    ulam_bidir_plan_info *pl = &ch->bidir;
    for (int round = 1;; round++) { /* the push also lowers the variance: while the residual's range term still
                                       leads, on down (a pilot a round, FIXED_ROUNDS at most) */
        if ((status = dense_plan(q, q->o, c, rmax, rcap, &wr, err)) == ULAM_ENOMEM) return status;
        ch->bidir_opts = ulam_bidir_defaults(), ch->bidir_opts.walk = q->run->bwo, ch->bidir_opts.target = q->o->query.index;
        if (status) {
            snprintf(v->why, sizeof v->why, "refused: %.250s", err->msg);
            return ULAM_OK;
        }
        interval_at(&wr, q->run->bwo.stop.rel_err_offset, N, &cr);
        if (blind && !(cb.var_term > 0 && isfinite(cb.half))) { /* the walks on b: the residual's range scaled to b,
            at a variance of the rule of three (a score of that size in at most 3 / n of the pilot's n walks, 95%) */
            double Rb = pilot_range(&wr, q->run->bwo.stop.rel_err_offset) * bmax / pl->push.r_max;
            if (isfinite(Rb) && Rb > 0 && N >= 2 && N < 4e18)
                ulam__stop_interval((int64_t)N, 0.0, Rb * Rb * 3.0 / (double)wb.walks, Rb, 0.0, 0.0, INFINITY, 0, &cb);
        }
        if (round >= FIXED_ROUNDS || pl->push.ops >= cap || !(pl->push.r_max > 0)) break;
        if (blind && !(cb.var_term > 0 && isfinite(cb.half))) { /* the residual's walks saw nothing either: push on */
            rmax = pl->push.r_max / 16.0;
            continue;
        }
        if (varled || !(cr.range_term > cr.var_term)) { /* led by the variance (the residual's, once its range term no
            longer leads: metastable40 at 10^4 walks): on while a round narrows the predicted interval by a quarter */
            if (varled && !(cr.half < 0.75 * prev)) break;
            varled = 1, prev = cr.half, rmax = pl->push.r_max / 16.0, rcap = rcap > cap / 4 ? cap : 4 * rcap;
            continue;
        }
        rmax = fmin(0.5 * rmax, pl->push.r_max * cr.var_term / cr.range_term);
    }
    pl->predicted_walks = N;
    if (!(cr.half < cb.half)) {
        snprintf(v->why, sizeof v->why, "lost: at %.3g walks its interval is predicted -+ %.3g, the walks' -+ %.3g", N,
                 cr.half, cb.half);
        return ULAM_OK;
    }
    double lo_n = 2.0, hi_n = N; /* the least walks whose interval on the residual is the leader's */
    for (int it = 0; it < 64 && hi_n - lo_n > 1.0; it++) {
        double mid = floor(0.5 * (lo_n + hi_n));
        interval_at(&wr, q->run->bwo.stop.rel_err_offset, mid, &cr);
        if (cr.half <= cb.half) hi_n = mid;
        else lo_n = mid;
    }
    double V = wr.walks ? (double)wr.steps / (double)wr.walks : 0.0;
    pl->predicted_work = hi_n * (V + ULAM_AUTO_WALK); /* from here: the push and pilots are spent either way */
    q->run->bplan = *pl;
    v->predicted_work = pl->predicted_work;
    return ULAM_OK;
}

/* Whether the walks the push on b would run from the index (adjoint, with the chosen walk
 * candidate's estimator, continuation and exponent) are a certified candidate. */
static int index_walks(const ulam_choice *ch)
{
    const ulam_auto_result *w = &ch->walks;
    if (w->chosen < 0) return 0;
    const ulam_auto_candidate *c = &w->cand[w->chosen];
    for (int k = 0; k < w->ncand; k++) {
        const ulam_auto_candidate *a = &w->cand[k];
        if (a->mode == ULAM_ADJOINT && a->estimator == c->estimator && a->continue_q == c->continue_q &&
            a->kernel_alpha == c->kernel_alpha)
            return a->certified;
    }
    return 0;
}

/* Whether the walks' pins hold the push on b (an estimator, or an exponent other than 1). */
static int pinned(const ulam__query *q)
{
    return q->ao && (q->ao->pin_estimator || (q->ao->pin_alpha && q->o->kernel.kernel_alpha != 1.0));
}

/* The push on b's plan (the chosen walk candidate's kernel, the push capped at W / 2) and its
 * predicted work, or why it is refused; at a fixed budget, fixed_predict's. */
static int predict_push_on_b(ulam__query *q, int k, ulam_error *err)
{
    ulam_choice *ch = q->ch;
    double W = ch->leader_work;
    if (ulam__b_exponent(q->b, q->M->nrows)) { /* its residual walks carry q_i as an offset: not rescaled */
        snprintf(ch->method[k].why, sizeof ch->method[k].why, "not considered: max|b| is outside 2^-256 .. 2^256 "
                 "(the walks on the push's residual could not be rescaled: their squares would underflow)");
        return ULAM_OK;
    }
    if (!(q->o->stop.rel_err > 0)) return fixed_predict(q, k, W, err);
    const ulam_auto_candidate *c = &ch->walks.cand[ch->walks.chosen];
    double m = fabs(c->estimate + q->o->stop.rel_err_offset);
    int64_t cap = W / 2 < 1 ? 1 : W / 2 < 1e18 ? (int64_t)(W / 2) : INT64_MAX;
    double rmax = rule_rmax(q->b, q->M->nrows, c->variance, m, c->predicted_walks, q->o->stop.rel_err);
    int status = dense_plan(q, q->o, c, rmax, cap, NULL, err);
    if (status == ULAM_ENOMEM) return status;
    ch->bidir_opts = ulam_bidir_defaults(), ch->bidir_opts.walk = q->run->bwo, ch->bidir_opts.target = q->o->query.index;
    if (status) snprintf(ch->method[k].why, sizeof ch->method[k].why, "refused: %.250s", err->msg);
    else if (q->run->blower) /* a lower bound shows no saving over the leader, which runs either way */
        snprintf(ch->method[k].why, sizeof ch->method[k].why, "lost: its pilot does not resolve |x|, so its prediction "
                 "is a lower bound, no saving over the walks");
    else ch->method[k].predicted_work = ch->bidir.predicted_work;
    return ULAM_OK;
}

/* Plan with the push capped at W / 2 and predict the work; kept in the run.  A dense b takes
 * the push on b, unless no walks from the index are certified (PageRank's M = alpha P' at a
 * low-degree target, whose adjoint rho(M^) is far above 1): then the reverse push from the
 * index and walks from b's distribution, as for a sparse b; a sparse b whose walks (forward on
 * M) have no certified finite variance takes the push on b when the walks from the index are
 * certified, and is refused otherwise. */
static int predict(ulam__query *q, int k, ulam_error *err)
{
    ulam_choice *ch = q->ch;
    ulam_run *r = q->run;
    double W = ch->leader_work;
    int fixed = !(q->o->stop.rel_err > 0); /* a fixed budget: the push on b for a sparse b too (the reverse push
                                              has no figure to compare there) */
    if ((fixed || ulam__method_bidir_route(q->b, q->M->nrows, q->ao, q->o)) && (index_walks(ch) || pinned(q)))
        return predict_push_on_b(q, k, err);
    ulam_walk_opts walk = *q->o;
    walk.estimator = ULAM_COLLISION, walk.kernel.kernel_alpha = 1.0;
    walk.policy.guard = NULL, walk.stop.interrupt = NULL, walk.exec.share = NULL;
    int status = setup(q, &walk, err);
    if (status) return status;
    r->bo.max_push_ops = W / 2 < 1 ? 1 : W / 2 < 1e18 ? (int64_t)(W / 2) : 0; /* W infinite: the default cap */
    ulam_error e;
    ulam_method_verdict *v = &ch->method[k];
    ulam_guard_opts go = ulam_guard_defaults();
    ulam_guard g;
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(ULAM_ADJOINT); /* the walks from b: adjoint on M' */
    if ((status = ulam_guard_check(r->Mt, walk.kernel.continue_q, &go, &g, &e)) == ULAM_ENOMEM) {
        release(r);
        *err = e;
        return status;
    }
    if ((status || ulam_guard_variance(&g, ULAM_ADJOINT) != 1) && index_walks(ch))
        return predict_push_on_b(q, k, err); /* the walks from the index are certified: push b to them */
    if (status || ulam_guard_variance(&g, ULAM_ADJOINT) != 1) { /* its rel_err run would be refused: no veto */
        snprintf(v->why, sizeof v->why, "refused: its walks from b (forward on M) have rho(M^) in [%.4g, %.4g], "
                                        "not certified below 1", g.hat[ULAM_ADJOINT].lower, g.hat[ULAM_ADJOINT].upper);
        return ULAM_OK;
    }
    status = ulam__bidir_plan_on(r->an, &r->bo, &ch->bidir, &e);
    ch->bidir_opts = r->bo;
    if (status == ULAM_ENOCONV) {
        snprintf(v->why, sizeof v->why, "dropped: its push passed W/2 = %lld operations", (long long)r->bo.max_push_ops);
        return ULAM_OK;
    }
    if (status == ULAM_ENOMEM) {
        release(r);
        *err = e;
        return status;
    }
    if (status) {
        snprintf(v->why, sizeof v->why, "refused: %.250s", e.msg);
        return ULAM_OK;
    }
    v->predicted_work = work(q->M, &ch->bidir, &ch->walks.guard);
    if (q->o->stop.rel_err > 0 && !isfinite(W) && ch->bidir.push_part == 0.0 && !(ch->bidir.probe > 0)) {
        v->predicted_work = INFINITY; /* as a walk pilot that saw nothing predicts nothing: the plan's walks
                                         rest on its |x_t| >= min_value floor alone */
        snprintf(v->why, sizeof v->why, "not predicted: no walk pilot, push or probe has seen x_t (its plan "
                                        "assumes |x_t| >= %.3g)", r->bo.min_value > 0 ? r->bo.min_value : 1.0 / (double)q->M->nrows);
    }
    return ULAM_OK;
}

/* Pinned: the options as given, b's nonzeros as the sparse b, or b = e_S as the point source S (no
 * plan yet: the solve makes it). */
static int pin(ulam__query *q, int k, ulam_error *err)
{
    (void)k;
    int64_t n = q->M->nrows, nb = nonzeros(q->b, n);
    if (nb == 0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a nonzero b (b is zero, so x is 0)");
    if (ulam__method_bidir_route(q->b, n, q->ao, q->o)) { /* the push on b, planned from a pilot round on b */
        if (!(q->o->stop.rel_err > 0) && !(q->o->stop.max_walks > 0))
            return ulam__fail(err, ULAM_EINVAL, 0, -1, "a --rel-err target or a walk count for bidirectional with a "
                                                       "dense b (more than max(16, n/10) = %lld nonzeros)",
                              (long long)ulam_method_sparse_limit(n));
        ulam_walk_opts po = dense_walk_opts(q->o, NULL, 0.0);
        ulam_walk_result wr;
        int status = pilot_on(q->M, q->b, &po, (UINT64_C(1) << 32) + 2, &wr, err);
        if (status) return status;
        double m = fabs(wr.estimate + q->o->stop.rel_err_offset), rmax;
        if (q->o->stop.rel_err > 0) {
            rmax = rule_rmax(q->b, n, wr.variance, m, wr.min_walks, q->o->stop.rel_err);
        } else { /* a walk count: as fixed_predict, the range term brought to about the variance term's */
            ulam__stop_ci ci;
            interval_at(&wr, q->o->stop.rel_err_offset, (double)q->o->stop.max_walks, &ci);
            rmax = ulam__bpush_max(q->b, n) * (ci.range_term > ci.var_term && isfinite(ci.half) ? ci.var_term / ci.range_term : 1.0);
        }
        status = dense_plan(q, q->o, NULL, rmax, 100 * ulam_csr_nnz(q->M) + 1000000, NULL, err);
        q->ch->bidir_opts = ulam_bidir_defaults(), q->ch->bidir_opts.walk = q->run->bwo;
        return status;
    }
    int status = setup(q, q->o, err);
    if (!status && nb == 1 && q->b[q->run->idx[0]] == 1.0) /* b = e_S: a point source, as `ulam solve --source S` */
        q->run->bo.source = q->run->idx[0], q->run->bo.nb = 0;
    q->ch->bidir_opts = q->run->bo;
    return status;
}

/* The push and the walks (the plan reused when predicted). */
static int finish(ulam_run *r, ulam_answer *a, ulam_error *err)
{
    if (r->br) { /* dense b: the walks from the index on the push's residual, q_i added */
        ulam_bidir_result *br = &a->bidir;
        r->bwo.stop.interrupt = r->o.stop.interrupt, r->bwo.exec.share = r->o.exec.share;
        int status = ulam_solve_walks(r->M, r->br, &r->bwo, &br->walks, err);
        if (status) return status;
        double qi = r->bq[r->bwo.query.index];
        br->push_part = qi, br->estimate = qi + br->walks.estimate, br->std_error = br->walks.std_error;
        /* the push's arithmetic: each operation rounds q_j += r_j and r_k += M_kj r_j, which leave
         * x = q + (I - M)^-1 r true only to roundings that add up over the push; the interval is
         * widened either side by (ops + 2) u |q_i| and the sum's own rounding u |x_i| (as bidir.c's
         * rounding_allowance), so a push taken down to rounding (residual walks' stderr ~1e-17)
         * does not print a zero-width point beside x_i */
        double fp = ulam__push_rounding((double)r->bplan.push.ops + 2.0, fabs(qi)) + DBL_EPSILON * fabs(br->estimate);
        if (r->bkiters > 0 && r->bdelta > 0) /* the Krylov start's residual as rounded (src/bkrylov.c) */
            fp += r->bdelta * r->bvisits;
        br->ci95[0] = qi + br->walks.ci95[0] - fp, br->ci95[1] = qi + br->walks.ci95[1] + fp;
        br->plan = r->bplan, br->push = r->bplan.push;
        br->seconds = br->walks.seconds + r->bplan.seconds;
        a->walks = br->walks, a->opts = r->bwo;
        a->estimate = br->estimate, a->std_error = br->std_error, a->ci95[0] = br->ci95[0], a->ci95[1] = br->ci95[1];
        return ULAM_OK;
    }
    r->bo.walk.stop.interrupt = r->o.stop.interrupt, r->bo.walk.exec.share = r->o.exec.share;
    int status = ulam__bidir_solve_on(r->an, &r->bo, &a->bidir, err);
    if (status) return status;
    a->walks = a->bidir.walks;
    a->opts = r->bo.walk;
    a->estimate = a->bidir.estimate, a->std_error = a->bidir.std_error;
    a->ci95[0] = a->bidir.ci95[0], a->ci95[1] = a->bidir.ci95[1];
    return ULAM_OK;
}

const ulam__method_type ulam__method_bidir = {"bidirectional", ULAM_ANSWERS_ENTRY, applies, predict, pin, finish, release};
