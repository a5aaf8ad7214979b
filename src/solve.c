/* The walk solver: budget, threads, stopping, interruption.
 *
 * Walks run in blocks of BLOCK walks, ROUND blocks per round; block q draws from the stream
 * (seed, q) (one splitmix64 seeding per block, not per walk).  Threads take blocks
 * dynamically, but every block's result is stored by its index and merged in index order
 * (Chan's formula for the adjoint score, per-state sums for forward tallies), so the result is
 * bit-for-bit the same for any number of threads.  Stopping rules are checked between rounds; an interrupt or the time limit
 * also stops blocks that have not started. */
#include "solve.h"
#include "defaults.h"
#include "cache.h"
#include "check.h"
#include "fpush_b.h"
#include "guard.h"
#include "hit.h"
#include "round.h"
#include "spectral.h"
#include "stats.h"
#include "stop.h"
#include "supersolve.h"
#include "walk.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* Walks per block, blocks per round, split-stack entries per thread; kernels up to CACHED
 * bytes walk 16 histories interleaved, larger ones 32 (measured best on a machine with a 2 MiB
 * L2).  CACHED is a fixed tunable (docs/tunables.md), not the running machine's L2: a block's
 * interleaved histories draw from the block's one generator in lane order, so the lane count
 * decides which numbers each history draws, and a threshold measured at start-up would give one
 * seed different walks on machines with different caches.
 * Once walks have built 1 / COMPLETE of the kernel row by row, the rest is built at once: a
 * row built at a first visit costs about 3 times one built in the whole streaming pass
 * (measured, n = 10^6 .. 10^7), so by then the run has spent on row-by-row building about
 * what the pass costs (the rent-or-buy rule), and a run that far will likely reach the rest. */
/* A largest continuation past which the length tail's certificate is sought too (a row sum
 * of 1 - 1e-16 bounds nothing useful). */
#define TAIL_Q 0.99

enum { BLOCK = 1024, ROUND = 64, STACK = 8192, CACHED = 2 << 20, COMPLETE = ULAM__COMPLETE };
/* A --rel-err run's first round: walks of block 0's stream (the rest of it left unrun: round.h's
 * skip), and the fewest walks a later round makes; the confidence sequence holds at every count,
 * so the rule may stop after any round (a first round of a whole block made every run at least
 * 1024 walks, 10.7 times the CLT's count at E = 0.1 on the hub at 0.99; later rounds of at least
 * 64 walks stopped its absorption runs at 320 walks, 3.34 times, where 272 do, 2.84 times). */
/* REL_TAIL: once the sequence predicts the stop within walks / REL_TAIL, a round is that sixty-fourth
 * of the walks so far (rounds past the stop cost walks, never width: a round of walks / 16 stopped
 * E = 0.01 runs at 0.98 E |x|, 4% more walks than the target asks; bench_relerr, docs/error-bars.md);
 * a round of 8 blocks or more still runs on every thread from 2^19 walks on. */
enum { REL_FIRST = ULAM__REL_FIRST, REL_STEP = 16, REL_TAIL = 64 };

/* The lesser of a and b. */
static int64_t imin64(int64_t a, int64_t b)
{
    return a < b ? a : b;
}


struct ulam_solver {
    ulam_walk_opts o;
    int64_t n;
    ulam_kernel *k;
    int k_borrowed; /* k is the caller's (ulam__solver_alloc_reached) or was kept (ulam__solver_keep_kernel) */
    ulam__walker w;
    const double *b; /* the caller's, borrowed like M (or bs, or pr) */
    double *pq, *pr; /* forward: the push on b's part and residual (src/fpush_b.c; owned; NULL: none):
                        the walks start from pr, every estimate adds pq */
    ulam__fpush_b_info push; /* what that push did */
    const double *b0; /* b before the push (pr in place of it: a rerun's push starts again from b0) */
    double push_plan; /* the budget the push was planned for (push_plan(); -1: none planned yet) */
    int push_fixed;   /* fixed budgets push too (the method choice's solvers: ulam__solver_alloc_until) */
    double *hitv;    /* rel_err with no score yet: src/hit.c's bound on each state's chance to score (NULL: none) */
    char *hitt;      /* and the states where a walk scores */
    int64_t *hits, nhits; /* and the reachable states it sweeps, ascending */
    int64_t hit_reads; /* entries its sweeps read */
    int hit_sweep, hit_done;
    double hit_walks; /* the least walks the rule can then need, (1 / p - 1) / E^2 (0: not computed) */
    double *bs;      /* b 2^-bexp when b is far from 1 (ulam__b_exponent; owned), else NULL */
    int bexp;        /* the estimates found on bs are times 2^bexp */
    int overflow;    /* the run ended because its estimate was not finite */
    ulam_csr *mt;
    ulam__slot *src;
    ulam__slot *start_src; /* adjoint with nstarts: the start distribution (walker.start_*) */
    int32_t *start_units;
    double *start_b;
    ulam__rows_check rc; /* opts->system's verification, made before rows are first read (fn NULL: none) */
    const ulam__reach *given; /* the states walks can reach given by the caller (ulam__solver_alloc_reached;
                                 NULL: none), with K's own bounds over them when given->bounds */
    int threads;
    ulam__scratch *scratch; /* one per thread */
    ulam__kscratch *ks;     /* one per thread: room to build a kernel row */
    ulam__block *blocks;   /* one per block of a round */
    /* accumulated */
    ulam__moments adj;
    ulam__moments watched; /* forward: the moments of component o.index's history tallies */
    double *sum, *sumsq; /* forward per-state sums of history tallies */
    ulam_guard g;        /* the verdicts, checked before walking */
    int var_finite;      /* 1, 0 or -1 (ulam_guard_variance, or 1 by assume_finite) */
    double bound, range; /* the largest |score| a walk can make; the scores' range (INFINITY: none) */
    double per_step, qmax; /* collision, expected: the largest |score| of one visit, the largest
                              continuation over reachable states (walk length tail q^l) */
    double tail_u, kappa;  /* the length tail (Collatz-Wielandt): |K| v <= tail_u v over reachable
                              states, kappa = max v / min v (tail_u 1: none) */
    double *tailT;         /* adjoint collision: tailT[l] >= sum over k > l of (|K|^k 1)_index (tail_len) */
    int64_t tailT_n, tailT_at; /* its length (0: none) and the index it was made from */
    double *tailS;         /* with tailT: tailS[l] >= |sum over k > l of (K^k b)_index|, the bias of a score over
                              its first l + 1 visits (signed: M's own powers, not |M|'s) */
    const double *tailS_b; /* the b it was made with */
    double visit;          /* the start weight times the largest |score| of one visit */
    double weight;         /* the weight bound W over reachable states (INFINITY with splitting) */
    double v2;             /* a certified bound on E[score^2] (INFINITY: none) */
    int signs;             /* scores may take both signs */
    ulam_power rho4;       /* rho(M4) of the walk kernel ([0, INFINITY] until computed) */
    int rho4_done;         /* rho4 computed */
    int fourth;            /* the fourth moment: 1 finite, 0 infinite, -1 unknown (take_fourth) */
    char *seen;            /* the states walks can reach as searched here (kept for a rerun; NULL until needed) */
    const char *reached;   /* seen, or the caller's given->seen (NULL until needed) */
    double *fac;           /* kernel exponent != 1: each move's weight factor over them (kept) */
    int64_t reach_nnz;     /* entries of M over the reachable rows (0 until computed) */
    int64_t setup_work;    /* entries read by reachability checks and score-bound passes so far */
    int passed;            /* the bounds pass over the reachable rows is done (kept for a rerun): */
    struct {
        double vmax, gmax, g2max; /* the largest |score| of one visit, of a single score, of g^2 / p* */
        int64_t bad;              /* absorption: a reachable scoring state with p* = 0 (-1: none) */
    } pass[3];             /* per estimator */
    double pass_w0, pass_W, pass_qmax; /* the start weight, the weight bound, the largest q */
    int pass_signs;
    int pass_only;         /* given bounds: the one estimator the pass read K for (-1: every one) */
    int tail_done, v2_done[3]; /* length_tail's and second_moment's results kept: */
    double tail_uc, tail_kc, v2c[3];
    const ulam_csr *M;     /* borrowed */
    ulam__run run;      /* walks, time, ending (round.c) */
    int64_t steps, cut;
    double maxsq; /* the largest single score^2 (forward: of the reported component) */
    int met, cut_stop, out_of_reach;
    int walks_given; /* the caller set stop.max_walks: its budget is walked even when the rel_err target is
                        out of its reach (that stop is for the 1e9 cap), unless no walk has scored yet and
                        the budget is too short to see a score (then more walks would show nothing) */
    int budget_plan; /* walks_given and the target past the budget: the next blocks' bets are planned for the
                        budget, as a fixed count's (plan_terms), not for a width it cannot reach */
    int epoch; /* the last epoch (stop.h) the rel_err rule was checked at */
    ulam__cs cs; /* the confidence sequence (stop.h), fed a block at a time in block order */
    double clip_b; /* the bias bound of the round's clipped scores (their limit: w.clip) */
    double deadline; /* a time limit's end (ulam_now; INFINITY: none): set-up past it takes the cheaper
                        paths (length_tail, second_moment) */
};

/* The defaults. */
ulam_walk_opts ulam__walk_defaults(void)
{
    return (ulam_walk_opts){.mode = ULAM_ADJOINT, .estimator = ULAM_COLLISION, .kernel = ulam__kernel_defaults(),
                            .stop = ulam__stop_defaults(), .exec = ulam__exec_defaults(),
                            .query = ulam__query_defaults(), .policy = ulam__policy_defaults()};
}

/* The kernel's defaults: analog, exponent 1, rows built as reached, no window. */
ulam_kernel_opts ulam__kernel_defaults(void)
{
    return (ulam_kernel_opts){.kernel_alpha = 1.0};
}

/* The execution defaults: seed 1, all cores, one process. */
ulam_exec_opts ulam__exec_defaults(void)
{
    return (ulam_exec_opts){.seed = 1};
}

/* The query defaults: x_0. */
ulam_query_opts ulam__query_defaults(void)
{
    return (ulam_query_opts){.index = 0};
}

/* The policy defaults: refuse the uncertified, compute the guards. */
ulam_policy_opts ulam__policy_defaults(void)
{
    return (ulam_policy_opts){.force = 0};
}

/* Free a solver; accepts and returns NULL. */
ulam_solver *ulam_solver_free(ulam_solver *s)
{
    if (!s) return NULL;
    if (!s->k_borrowed) ulam__kernel_free(s->k);
    free(s->src), free(s->sum), free(s->sumsq), free(s->seen), free(s->fac), free(s->bs), free(s->pq), free(s->pr);
    free(s->hitv), free(s->hitt), free(s->hits), free(s->tailT), free(s->tailS);
    free(s->start_src), free(s->start_units), free(s->start_b);
    ulam_csr_free(s->mt);
    if (s->scratch)
        for (int t = 0; t < s->threads; t++) {
            free(s->scratch[t].stack_s), free(s->scratch[t].stack_w);
            free(s->scratch[t].hist), free(s->scratch[t].touched), free(s->scratch[t].mark);
            free(s->scratch[t].bsum), free(s->scratch[t].bsq), free(s->scratch[t].btouched), free(s->scratch[t].bmark);
        }
    if (s->ks)
        for (int t = 0; t < s->threads; t++) ulam__kscratch_free(&s->ks[t]);
    if (s->blocks)
        for (int q = 0; q < ROUND; q++) free(s->blocks[q].h.tally);
    free(s->scratch), free(s->ks), free(s->blocks);
    free(s);
    return NULL;
}

/* Check the options against M. */
static int check_opts(const ulam_csr *M, const ulam_walk_opts *o, ulam_error *err)
{
    if (M->nrows != M->ncols)
        return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    int bad = ulam__walk_opts_check(o, err); /* src/check.c: every finite-valued option first */
    if (bad) return bad;
    if (o->mode != ULAM_ADJOINT && o->mode != ULAM_FORWARD)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "mode adjoint or forward");
    if (o->estimator < ULAM_COLLISION || o->estimator > ULAM_EXPECTED)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "estimator collision, absorption or expected");
    if (o->query.index < 0 || o->query.index >= M->nrows)
        return ulam__fail(err, ULAM_EINVAL, 0, o->query.index, "an index from 0 to %lld", (long long)M->nrows - 1);
    if (o->query.nstarts < 0 || (o->query.nstarts > 0 && (o->mode != ULAM_ADJOINT || !o->query.starts || !o->query.start_weights ||
                                              o->query.nstarts > INT32_MAX)))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "start states and weights in adjoint mode");
    double S = 0.0;
    for (int64_t j = 0; j < o->query.nstarts; j++) {
        if (o->query.starts[j] < 0 || o->query.starts[j] >= M->nrows || !isfinite(o->query.start_weights[j]))
            return ulam__fail(err, ULAM_EINVAL, 0, j, "start states from 0 to %lld with finite weights",
                              (long long)M->nrows - 1);
        S += fabs(o->query.start_weights[j]);
    }
    if (o->query.nstarts > 0 && !(S > 0 && isfinite(S)))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "start weights with a finite nonzero sum of |weights|");
    if (o->kernel.continue_q > 0 && !(o->kernel.continue_q < 1))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a continuation probability below 1");
    if (!(o->kernel.kernel_alpha >= 0) || !isfinite(o->kernel.kernel_alpha))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a kernel exponent alpha that is finite and >= 0 (got %g)",
                          o->kernel.kernel_alpha);
    if (o->kernel.roulette < 0 || o->kernel.split < 0 || (o->kernel.split > 0 && o->kernel.roulette > 0 && o->kernel.split <= o->kernel.roulette))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "0 < roulette W < split W (or either off)");
    return ulam__budgets_check(o, err);
}

/* The size of a walk's start weight: 1 adjoint (the sum of |start weights| with a start
 * distribution), ||b||_1 forward. */
static double start_weight(const ulam_walk_opts *o, const double *b, int64_t n)
{
    double w0 = 0.0;
    if (o->mode == ULAM_FORWARD)
        for (int64_t i = 0; i < n; i++) w0 += fabs(b[i]);
    else
        for (int64_t j = 0; j < o->query.nstarts; j++) w0 += fabs(o->query.start_weights[j]);
    return o->mode == ULAM_ADJOINT && o->query.nstarts == 0 ? 1.0 : w0;
}

/* Refuse a split weight below the start weight (1 adjoint, ||b||_1 forward): every walk would
 * split at once into ceil(w0 / W) copies (a split weight of 1e-7 on chain4: 1e7 copies a walk,
 * 11 s for 1000 walks), which is unbiased but no longer the run asked for. */
static int check_split(const ulam_csr *M, const double *b, const ulam_walk_opts *o, ulam_error *err)
{
    if (!(o->kernel.split > 0)) return ULAM_OK;
    double w0 = start_weight(o, b, M->nrows);
    if (o->kernel.split >= w0) return ULAM_OK;
    return ulam__fail(err, ULAM_EINVAL, 0, -1,
                      "a split weight of at least the start weight %.6g (%s), not %g: below it every walk splits "
                      "into ceil(%.6g / W) copies at its first step",
                      w0, o->mode == ULAM_ADJOINT ? "1 in adjoint mode" : "||b||_1 in forward mode", o->kernel.split, w0);
}

/* The sum of |K| over row i. */
static double row_sum(const ulam_csr *K, int64_t i)
{
    double S = 0.0;
    for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) S += fabs(K->val[q]);
    return S;
}

/* The largest product of weight factors S / q (fac: each move's own, kernel exponent != 1)
 * along any path among the seen states (the weight a walk can reach, as a multiple of the
 * weight it had anywhere on its way): a longest path fixpoint, 1 when no factor exceeds 1;
 * INFINITY when it does not settle within SWEEPS passes (a cycle that grows weights, or paths
 * too long to follow).  Growth below a relative 1e-12 a pass is ignored (rounding of factors
 * of exactly 1). */
static double weight_growth(const ulam_csr *K, double continue_q, const double *fac, const char *seen)
{
    enum { SWEEPS = 64 };
    int64_t n = K->nrows;
    double *A = ulam__malloc((size_t)n, sizeof *A), best = 1.0;
    if (!A) return INFINITY;
    for (int64_t i = 0; i < n; i++) A[i] = 1.0;
    int changed = 1;
    for (int sweep = 0; sweep < SWEEPS && changed; sweep++) {
        changed = 0;
        for (int64_t i = 0; i < n; i++) {
            if (!seen[i]) continue;
            double a = fac ? 0.0 : A[i] * ulam__factor(row_sum(K, i), continue_q);
            for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) {
                if (fac) a = A[i] * fac[k];
                if (K->val[k] != 0.0 && a > A[K->colidx[k]] * (1.0 + 1e-12)) A[K->colidx[k]] = a, changed = 1;
            }
        }
    }
    for (int64_t i = 0; i < n; i++) best = fmax(best, seen[i] ? A[i] : 1.0);
    free(A);
    return changed ? INFINITY : best;
}

/* A Collatz-Wielandt certificate of the walk's length tail over the seen states (closed under
 * K's moves): a positive v with |K| v <= u v there, so a walk's expected remaining |weight|
 * after k steps, w0 (|K|^k 1)_i, is at most w0 kappa u^k, kappa = max v / min v.  v is a
 * power iterate of I + |K| from 1 (the shift converges on periodic chains, a cycle of two
 * states, where iterates of |K| alone oscillate), floored at floor times its largest entry
 * (so kappa <= 1 / floor); the smallest u over ITER iterations is kept.  *u = 1
 * (no certificate) when none is below 1 or memory runs out.  second: the same for the
 * walk's second-moment matrix M^ = diag(S / q) |K| (E[w_k^2] = w0^2 (M^^k 1)_i, no roulette). */
/* The expected steps a length tail of u and kappa allows (INFINITY for none). */
static double tail_steps(double u, double kappa)
{
    return u < 1.0 && isfinite(kappa) ? 1.0 / (1.0 - u) + log(fmax(kappa, 1.0)) / -log(u) : INFINITY;
}

/* The expected lengths' certificate (ulam__length_certificate) in place of *u, *kappa when it
 * allows shorter walks. */
static void length_certificate(const ulam_csr *K, const char *seen, double *u, double *kappa, int *iterations)
{
    double u2, k2;
    int64_t products = 0, n = K->nrows;
    int64_t cap = 4 * (int64_t)sqrt((double)n) + 2000;
    if (ulam__length_certificate(K, seen, (int)cap, &u2, &k2, &products, NULL) == ULAM_OK &&
        tail_steps(u2, k2) < tail_steps(*u, *kappa))
        *u = u2, *kappa = k2;
    *iterations += (int)products;
}

/* Under a time limit (deadline finite) the expected lengths' certificate comes first and, when
 * it holds, the power iterations run only while the clock is before the deadline (they are the
 * optional stage then: a 500 x 500 Poisson grid's 300 took 0.6 s and certified nothing the
 * certificate does not; any iterate is a valid certificate, so stopping early only loosens it). */
static void length_tail(const ulam_csr *K, const char *seen, double continue_q, int second, double floor,
                        double deadline, double *u, double *kappa, int *iterations)
{
    enum { ITER = 300 };
    int64_t n = K->nrows;
    int timed = isfinite(deadline);
    double *v = ulam__malloc((size_t)n, sizeof *v), *y = ulam__malloc((size_t)n, sizeof *y), u0 = 1.0, k0 = INFINITY;
    *u = 1.0, *kappa = INFINITY;
    if (timed && !second) length_certificate(K, seen, &u0, &k0, iterations);
    for (int64_t i = 0; v && y && i < n; i++) v[i] = 1.0;
    for (int it = 0; v && y && it < ITER && !(timed && u0 < 1.0 && ulam_now() >= deadline); it++) {
        double ratio = 0.0, ymax = 0.0, vmin = INFINITY, vmax = 0.0;
        for (int64_t i = 0; i < n; i++) {
            if (!seen[i]) continue;
            double t = 0.0;
            for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) t += fabs(K->val[k]) * v[K->colidx[k]];
            y[i] = t = second ? t * ulam__factor(row_sum(K, i), continue_q) : t;
            ratio = fmax(ratio, t / v[i]), ymax = fmax(ymax, t + v[i]);
            vmin = fmin(vmin, v[i]), vmax = fmax(vmax, v[i]);
        }
        ++*iterations;
        if (ratio < *u) *u = ratio, *kappa = vmax / vmin;
        else if (it >= 100 && *u < 1.0 && ratio >= *u * (1.0 - 1e-6)) break; /* no longer improving */
        if (!(ymax > 0)) break;
        for (int64_t i = 0; i < n; i++)
            if (seen[i]) v[i] = fmax((y[i] + v[i]) / ymax, floor);
    }
    free(v), free(y);
    if (timed && tail_steps(u0, k0) < tail_steps(*u, *kappa)) *u = u0, *kappa = k0;
    else if (!timed && !second && !(*u < TAIL_Q))
        length_certificate(K, seen, u, kappa, iterations); /* long walks: the expected lengths' certificate, when shorter */
}

/* y = r + A v over the seen states, A = |K| times each move's factor (fac) or its row's (f), or
 * |K| alone when both are NULL. */
static void moment_product(const ulam_csr *K, const double *fac, const double *f, const char *seen, const double *r,
                           const double *v, double *y)
{
    for (int64_t i = 0; i < K->nrows; i++) {
        if (!seen[i]) continue;
        double t = 0.0;
        for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) t += fabs(K->val[k]) * (fac ? fac[k] : 1.0) * v[K->colidx[k]];
        y[i] = (r ? r[i] : 0.0) + (f && !fac ? t * f[i] : t);
    }
}

/* What moment_solve's search needs: A (|K|, times fac or f as in moment_product) on the seen
 * states, and the starts pi its candidates are aimed at. */
typedef struct {
    const ulam_csr *K;
    const double *fac, *f, *pi;
    const char *seen;
} moment_ctx;

/* y = r + A v (src/supersolve.h's product). */
static int moment_apply(void *ctx, const double *r, const double *v, double *y)
{
    const moment_ctx *c = ctx;
    moment_product(c->K, c->fac, c->f, c->seen, r, v, y);
    return 0;
}

/* pi . (m + bb (res + phi)), rounded up (src/supersolve.h's worth). */
static double moment_worth(void *ctx, const double *m, const double *res, double phi, double bb)
{
    const moment_ctx *c = ctx;
    double pm = 0.0, pe = 0.0;
    for (int64_t i = 0; i < c->K->nrows; i++) pm += c->seen[i] ? c->pi[i] * m[i] : 0.0;
    for (int64_t i = 0; bb > 0 && i < c->K->nrows; i++) pe += c->seen[i] ? c->pi[i] * (res[i] + phi) : 0.0;
    return (pm + bb * pe) * (1.0 + 1e-9);
}

/* A certified upper bound on the solution m = r + A m (r >= 0, A as in moment_product) over
 * the seen states, aimed at the starts pi: src/supersolve.c's z of least pi . z over ITER
 * iterations (fewer: 40 bring nothing, or past deadline), kept in z; returns pi . z
 * (INFINITY: none certified, or out of memory). */
static double moment_solve(const ulam_csr *K, const double *fac, const double *f, const char *seen, const double *r,
                           const double *pi, double deadline, double *z, int *iterations)
{
    moment_ctx c = {K, fac, f, pi, seen};
    ulam__super s = {&c, K->nrows, seen, deadline, 1.0, moment_apply, NULL, moment_worth, NULL};
    double best = INFINITY;
    for (int64_t i = 0; i < K->nrows; i++) z[i] = 0.0;
    if (ulam__super_solve(&s, r, z, &best, iterations)) return INFINITY;
    return best;
}

/* The second moment of Y = sum over a walk's visits of |w| a_j (a_j: what a visit at j can
 * score, so |X| <= Y), aimed at the walk's starts pi (weight w0): m_j = E[Y^2 | a start at j,
 * weight 1] solves m = r + M^ m with r = a^2 + 2 a (|K| h), h = E[Y | j] = a + |K| h (the next
 * weight's mean |K_jk| / (q p_jk) q p_jk, its square's mean M^), and E[X^2] <= w0^2 pi . m;
 * absorption (one score g_j / p*_j at the end): r = g.  h and m by moment_solve's certified
 * upper bounds (h >= the true one makes r larger: still a bound).  INFINITY when none holds. */
static double second_moment_aimed(const ulam_csr *K, const double *fac, const double *f, const char *seen,
                                  const double *a, const double *g, const double *pi, int absorb, double w0,
                                  double deadline, int *iterations)
{
    int64_t n = K->nrows;
    double *h = ulam__malloc((size_t)n, sizeof *h), *r = ulam__malloc((size_t)n, sizeof *r), *z = ulam__malloc((size_t)n, sizeof *z);
    double best = INFINITY, asum = 0.0;
    for (int64_t i = 0; h && r && z && i < n; i++) asum += seen[i] ? a[i] : 0.0;
    for (int64_t i = 0; h && r && z && i < n; i++) r[i] = seen[i] && asum > 0 ? a[i] / asum : 0.0; /* aim h at where it is used */
    if (h && r && z && asum > 0 && isfinite(asum) &&
        (absorb || isfinite(moment_solve(K, NULL, NULL, seen, a, r, deadline, h, iterations)))) {
        for (int64_t i = 0; i < n; i++) r[i] = !seen[i] ? 0.0 : absorb ? g[i] : a[i] * (2.0 * h[i] - a[i]);
        best = w0 * w0 * moment_solve(K, fac, f, seen, r, pi, deadline, z, iterations);
    }
    free(h), free(r), free(z);
    return best;
}

/* A certified bound on E[X^2] of a walk's score X (collision, expected, absorption; no roulette,
 * no splitting) from the second-moment matrix M^ = diag(S / q) |K| over the seen states:
 * E[w_k^2 at j] = w0^2 (M^^k)_{start j}, so with g_j what a visit at j can add squared (b_j^2,
 * (|(M b)_j| + |b_start|)^2, forward 1 at the index; absorption b_j^2 / p*_j), a positive z
 * with M^ z <= u z and g <= c z gives (M^^k g)_start <= c u^k z_start, and by Cauchy-Schwarz
 * with weights u^(k/2), E[X^2] <= w0^2 c z_start / (1 - sqrt u)^2 (absorption, one score a
 * walk: w0^2 c z_start / (1 - u)).  z: iterates of I + M^ from g (so it fits the states that
 * score), floored at a few shares of its largest entry, the best bound kept; INFINITY when none
 * has u < 1.  At kernel exponent != 1, M^_ij = |K_ij| fac_ij, fac the moves' own factors.
 * The bound aimed at the starts (second_moment_aimed, from the same per-visit scores) comes
 * first and the smaller of the two is kept: it is usually far tighter (signed200 forward
 * collision: 424.5 against 3.5e6). */
static double second_moment(const ulam_solver *s, const ulam_csr *K, const double *fac, const char *seen, double w0,
                            int *iterations)
{
    enum { ITER = 300 };
    int64_t n = K->nrows;
    int adj = s->o.mode == ULAM_ADJOINT, absorb = s->o.estimator == ULAM_ABSORPTION, late = 0;
    double *g = ulam__malloc((size_t)n, sizeof *g), *v = ulam__malloc((size_t)n, sizeof *v);
    double *y = ulam__malloc((size_t)n, sizeof *y), *f = ulam__malloc((size_t)n, sizeof *f), best = INFINITY;
    double *av = ulam__calloc((size_t)n, sizeof *av), *pi = ulam__calloc((size_t)n, sizeof *pi);
    double b0 = 0.0, gmax = 0.0;
    for (int64_t j = 0; adj && s->o.estimator == ULAM_EXPECTED && j < (s->o.query.nstarts ? s->o.query.nstarts : 1); j++)
        b0 = fmax(b0, fabs(s->b[s->o.query.nstarts ? s->o.query.starts[j] : s->o.query.index]));
    for (int64_t i = 0; g && v && y && f && av && pi && i < n; i++) {
        g[i] = 0.0;
        if (!seen[i]) continue;
        double S = row_sum(K, i), q = ulam__continuation(S, s->o.kernel.continue_q), c = 0.0;
        f[i] = ulam__factor(S, s->o.kernel.continue_q);
        for (int64_t k = K->rowptr[i]; adj && s->o.estimator == ULAM_EXPECTED && k < K->rowptr[i + 1]; k++)
            c += K->val[k] * s->b[K->colidx[k]];
        for (int64_t k = K->rowptr[i]; !adj && s->o.estimator == ULAM_EXPECTED && k < K->rowptr[i + 1]; k++)
            if (K->colidx[k] == s->o.query.index) c = fmax(c, fabs(K->val[k])); /* forward expected: K_{i,index} */
        double a = adj ? (s->o.estimator == ULAM_EXPECTED ? fabs(c) + b0 : fabs(s->b[i]))
                       : s->o.estimator == ULAM_EXPECTED ? c : i == s->o.query.index;
        g[i] = absorb ? (a != 0.0 ? a * a / (1.0 - q) : 0.0) : a * a;
        gmax = fmax(gmax, g[i]), av[i] = a;
    }
    for (int64_t i = 0; av && pi && i < n; i++) /* the starts' shares */
        pi[i] = adj ? (!s->o.query.nstarts && i == s->o.query.index) : fabs(s->b[i]) / w0;
    for (int64_t j = 0; av && pi && adj && j < s->o.query.nstarts; j++) pi[s->o.query.starts[j]] += fabs(s->o.query.start_weights[j]) / w0;
    if (g && v && y && f && av && pi && gmax > 0 && isfinite(gmax)) /* aimed at the starts: usually far tighter */
        best = second_moment_aimed(K, fac, f, seen, av, g, pi, absorb, w0, s->deadline, iterations);
    static const double floors[] = {1e-30, 1e-6, 1e-3, 1e-2, 0.1};
    for (int fl = 0; g && v && y && f && gmax > 0 && isfinite(gmax) && fl < 5 && !late; fl++) {
        for (int64_t i = 0; i < n; i++) v[i] = seen[i] ? fmax(g[i] / gmax, floors[fl]) : 1.0;
        for (int it = 0, last = 0; it < ITER && it - last < 30; it++) { /* until 30 iterations bring nothing */
            if ((late = isfinite(best) && ulam_now() >= s->deadline)) break; /* a time limit: any bound holds, looser */
            double u = 0.0, c = 0.0, z0 = 0.0, ymax = 0.0;
            ++*iterations;
            for (int64_t i = 0; i < n; i++) {
                if (!seen[i]) continue;
                double t = 0.0;
                for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++)
                    t += fabs(K->val[k]) * (fac ? fac[k] : 1.0) * v[K->colidx[k]];
                y[i] = fac ? t : t * f[i];
                u = fmax(u, y[i] / v[i]), c = fmax(c, g[i] / v[i]), ymax = fmax(ymax, y[i] + v[i]);
                z0 += adj ? (i == s->o.query.index && !s->o.query.nstarts ? v[i] : 0.0) : fabs(s->b[i]) / w0 * v[i];
            }
            for (int64_t j = 0; adj && j < s->o.query.nstarts; j++) z0 += fabs(s->o.query.start_weights[j]) / w0 * v[s->o.query.starts[j]];
            if (u < 1.0) {
                double d = absorb ? 1.0 - u : (1.0 - sqrt(u)) * (1.0 - sqrt(u)), bound = w0 * w0 * c * z0 / d;
                if (bound < best * (1.0 - 1e-3)) last = it;
                best = fmin(best, bound);
            }
            for (int64_t i = 0; i < n; i++)
                if (seen[i]) v[i] = fmax((y[i] + v[i]) / ymax, floors[fl]);
        }
    }
    free(g), free(v), free(y), free(f), free(av), free(pi);
    return best;
}

/* The weight factors |K_ij| / (q_i p_ij) of the moves of the seen rows of K at kernel exponent
 * alpha != 1, one per entry (0 in the other rows; infinite where a probability underflows);
 * NULL when out of memory. */
static double *move_factors(const ulam_csr *K, const char *seen, double continue_q, double alpha)
{
    int64_t nnz = K->rowptr[K->nrows];
    double *f = ulam__calloc((size_t)nnz, sizeof *f), *pm = ulam__malloc((size_t)nnz, sizeof *pm);
    for (int64_t i = 0; f && pm && i < K->nrows; i++) {
        double q = seen[i] ? ulam__kernel_q(K, i, continue_q) : 0.0;
        if (q > 0) (void)ulam__kernel_moves(K, i, q, alpha, pm + K->rowptr[i], f + K->rowptr[i]);
    }
    if (!pm) free(f), f = NULL;
    free(pm);
    return f;
}

/* Over the seen states of K: the largest weight factor S / q (fac: each move's own, kernel
 * exponent != 1) and continuation, and whether K has a negative entry (R->fbig, qmax, neg). */
static void kernel_bounds(const ulam_csr *K, const char *seen, double continue_q, const double *fac, ulam__reach *R)
{
    double fbig = 0.0, qmax = 0.0;
    int neg = 0;
    for (int64_t i = 0; i < K->nrows; i++) {
        if (!seen[i]) continue;
        double S = row_sum(K, i);
        if (!fac) fbig = fmax(fbig, ulam__factor(S, continue_q));
        qmax = fmax(qmax, ulam__continuation(S, continue_q));
        for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) {
            neg |= K->val[k] < 0;
            if (fac) fbig = fmax(fbig, fac[k]);
        }
    }
    R->fbig = fbig, R->qmax = qmax, R->neg = neg;
}

/* Verify every row of a prepared system before a pass over all of M reads them (ULAM_OK without
 * one; blocks verified before are not read again). */
static int verify_all(const ulam_csr *M, const ulam_walk_opts *o, const ulam__rows_check *rc, ulam_error *err)
{
    int64_t bad = -1;
    if (!ulam__rows_verify(rc, 0, M->nrows, &bad)) return ULAM_OK;
    return o->policy.system && ulam__system_row_error(o->policy.system, bad, err) ? ULAM_ESYNTAX
                                                                    : ulam__fail(err, ULAM_ESYNTAX, 0, bad, "an intact prepared file");
}

/* The caller's bounds of K alone over the given states (ulam__reach_all), when they were made
 * for this K, continuation and exponent; NULL otherwise. */
static const ulam__reach *given_bounds(const ulam_solver *s, const ulam_csr *K)
{
    const ulam__reach *g = s->given;
    return g && g->bounds && g->K == K && g->continue_q == fmax(s->o.kernel.continue_q, 0.0) && g->alpha == s->o.kernel.kernel_alpha
               ? g
               : NULL;
}

/* The entries of K over the reachable rows (s->reach_nnz). */
static void count_reached(ulam_solver *s, const ulam_csr *K)
{
    s->reach_nnz = 0;
    for (int64_t i = 0; i < s->n; i++)
        if (s->reached[i]) s->reach_nnz += K->rowptr[i + 1] - K->rowptr[i];
}

/* The reachable states as flags: the caller's every-state bounds may come without them (a
 * prepared file's, R->seen NULL), made here (n ones, kept in s->seen) only for a pass that reads
 * them; ULAM_OK or ULAM_ENOMEM. */
static int reached_flags(ulam_solver *s, ulam_error *err)
{
    if (s->reached) return ULAM_OK;
    int status = verify_all(s->M, &s->o, &s->rc, err); /* the pass that wants them reads every row */
    if (status) return status;
    if (!(s->seen = ulam__malloc((size_t)s->n, 1))) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a reachability check");
    memset(s->seen, 1, (size_t)s->n);
    s->reached = s->seen;
    return ULAM_OK;
}

/* The states walks can reach (s->reached: searched once and kept in s->seen, or the caller's)
 * and their entries (s->reach_nnz). */
static int reach(ulam_solver *s, const ulam_csr *K, ulam_error *err)
{
    if (s->reached) return ULAM_OK;
    if (s->given) { /* the caller's reach (an earlier solver's search, or ulam__reach_all), read where it is;
                       NULL with every-state bounds: every state (reached_flags makes the flags if needed) */
        s->reached = s->given->seen;
        if (given_bounds(s, K)) s->reach_nnz = K->rowptr[K->nrows]; /* every state's (ulam__reach_all): not counted */
        else if (!s->reached) return reached_flags(s, err);
        else count_reached(s, K);
        return ULAM_OK;
    }
    char *seen = ulam__calloc((size_t)s->n, 1);
    if (!seen) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a reachability check");
    if (s->o.mode == ULAM_ADJOINT && !s->o.query.nstarts) seen[s->o.query.index] = 1;
    for (int64_t j = 0; s->o.mode == ULAM_ADJOINT && j < s->o.query.nstarts; j++) seen[s->o.query.starts[j]] = 1;
    if (s->o.mode == ULAM_FORWARD)
        for (int64_t i = 0; i < s->n; i++) seen[i] = s->b[i] != 0.0;
    int64_t bad = -1;
    int status = ulam__kernel_reach(K, s->o.kernel.continue_q, seen, &s->rc, &bad);
    if (status == ULAM_ESYNTAX && s->o.policy.system && ulam__system_row_error(s->o.policy.system, bad, err)) {
        free(seen);
        return ULAM_ESYNTAX; /* a damaged block of the prepared file, named */
    }
    if (status) {
        free(seen);
        return status == ULAM_ENOMEM ? ulam__fail(err, status, 0, -1, "memory for a reachability check")
                                     : ulam__fail(err, status, 0, -1, "rows with columns in range and finite, "
                                                  "nonzero values (the matrix is corrupt)");
    }
    s->reached = s->seen = seen;
    count_reached(s, K);
    s->setup_work += s->reach_nnz;
    return ULAM_OK;
}

/* The one pass over the reachable rows that every estimator's score bounds come from (kept):
 * for each estimator the largest visit score, single score and g^2 / p*, and absorption's first
 * scoring state with p* = 0; the weight bound and the scores' signs.  With the caller's bounds
 * of K (given_bounds) the weight factor, continuation, sign and growth of K are theirs, and the
 * pass reads only what this run's estimator needs (s->pass_only): the rows where b scores
 * (absorption: their p*; collision: nothing of K), or for the expected estimator every row's
 * (M b)_i; the other estimators' bounds are left INFINITY and check_reach passes again should
 * one of them run. */
static int bounds_pass(ulam_solver *s, const ulam_csr *K, ulam_error *err)
{
    const ulam__reach *given = given_bounds(s, K);
    int adj = s->o.mode == ULAM_ADJOINT, only = given ? s->o.estimator : -1;
    int summary = given && adj && given->b && given->b == s->b; /* b's scores over every state: read nothing */
    int status = summary ? ULAM_OK : reached_flags(s, err);
    if (status) return status;
    const char *seen = s->reached;
    double *fac = NULL; /* kernel exponent != 1: each move's own weight factor (kept: s->fac) */
    if (!given && s->o.kernel.kernel_alpha != 1.0 &&
        !(fac = s->fac = move_factors(K, seen, s->o.kernel.continue_q, s->o.kernel.kernel_alpha)))
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the kernel's weight factors");
    int pos = 0, neg = given ? given->neg : 0, any = 0, anyexp = 0;
    int need_q = !given || only == ULAM_ABSORPTION, need_c = adj && (!given || only == ULAM_EXPECTED);
    int need_j = !adj && (!given || only == ULAM_EXPECTED); /* forward expected: a visit to i scores K_{i,index} */
    int64_t bad = -1, reads = 0;
    double w0 = 1.0, fbig = given ? given->fbig : 0.0, gabs = 0.0, g2abs = 0.0, vb = 0.0, vexp = 0.0;
    double qmax = given ? given->qmax : 0.0;
    if (summary) {
        only = -1, vb = given->bmax, vexp = given->kbmax, gabs = given->gabs, g2abs = given->g2abs;
        bad = given->bad, any = given->bmax > 0, pos = given->bpos, neg |= given->bneg;
    }
    for (int64_t i = 0; !summary && i < s->n; i++) {
        if (!seen[i] || (given && only != ULAM_EXPECTED && s->b[i] == 0.0)) continue; /* scores nothing here */
        double S = need_q ? row_sum(K, i) : 0.0, q = need_q ? ulam__continuation(S, s->o.kernel.continue_q) : 0.0, c = 0.0;
        if (need_q || need_c || need_j) reads += K->rowptr[i + 1] - K->rowptr[i];
        if (!given) {
            if (!fac) fbig = fmax(fbig, ulam__factor(S, s->o.kernel.continue_q));
            qmax = fmax(qmax, q);
        }
        for (int64_t k = K->rowptr[i]; (!given || need_c || need_j) && k < K->rowptr[i + 1]; k++) {
            if (!given || need_c) neg |= K->val[k] < 0; /* the forward column scan under given bounds keeps theirs */
            if (fac) fbig = fmax(fbig, fac[k]);
            if (need_c) c += K->val[k] * s->b[K->colidx[k]];
            else if (need_j && K->colidx[k] == s->o.query.index) c = fmax(c, fabs(K->val[k]));
        }
        if ((adj ? s->b[i] != 0.0 : 1) && q >= 1.0 && bad < 0) bad = i;
        /* what one visit scores: b_i (collision), (M b)_i (expected); forward, at the index: 1
         * (collision), |K_{i,index}| = |M_{index,i}| (expected: the visit tallies w M_{k,i} at
         * every neighbour k) */
        vb = fmax(vb, adj ? fabs(s->b[i]) : i == s->o.query.index ? 1.0 : 0.0);
        vexp = fmax(vexp, fabs(c));
        anyexp |= !adj && c > 0.0; /* forward expected scores next to the index too */
        int scores = adj ? s->b[i] != 0.0 : i == s->o.query.index;
        if (!scores) continue;
        double g = adj ? fabs(s->b[i]) : 1.0;
        any = 1;
        gabs = fmax(gabs, q < 1.0 ? g / (1.0 - q) : INFINITY);
        g2abs = fmax(g2abs, q < 1.0 ? g * g / (1.0 - q) : INFINITY);
        if (adj) pos |= s->b[i] > 0, neg |= s->b[i] < 0;
    }
    if (!adj)
        for (int64_t i = 0; i < s->n; i++) pos |= s->b[i] > 0, neg |= s->b[i] < 0;
    for (int64_t j = 0; adj && j < s->o.query.nstarts; j++) /* signed start weights (conservative: both may show) */
        pos |= s->o.query.start_weights[j] > 0, neg |= s->o.query.start_weights[j] < 0;
    double G = given ? given->growth : fbig > 1.0 ? weight_growth(K, s->o.kernel.continue_q, fac, seen) : 1.0;
    w0 = start_weight(&s->o, s->b, s->n);
    for (int e = ULAM_COLLISION; e <= ULAM_EXPECTED; e++) {
        int absorb = e == ULAM_ABSORPTION;
        s->pass[e].vmax = e == ULAM_EXPECTED ? vexp : vb;
        int scored = any || (e == ULAM_EXPECTED && anyexp);
        s->pass[e].gmax = absorb ? gabs : scored ? INFINITY : 0.0;
        s->pass[e].g2max = absorb ? g2abs : scored ? INFINITY : 0.0;
        s->pass[e].bad = absorb ? bad : -1;
        if (only >= 0 && e != only) /* not read: never an optimistic bound (check_reach passes again) */
            s->pass[e].vmax = s->pass[e].gmax = s->pass[e].g2max = INFINITY;
    }
    s->pass_w0 = w0;
    s->pass_W = !(s->o.kernel.split > 0) ? (s->o.kernel.roulette > w0 ? s->o.kernel.roulette : w0) * G : INFINITY;
    s->pass_qmax = qmax;
    s->pass_signs = pos && neg;
    s->passed = 1, s->pass_only = only;
    s->setup_work += given ? reads : s->reach_nnz;
    return ULAM_OK;
}

/* The length tail seen from the start state itself (adjoint, one start): a_k = (|K|^k 1)_i, the
 * expected |weight| a walk from i still has after k steps over the start weight, by propagating
 * e_i' |K|^k over the states it reaches (a_k is its sum), for k up to the first of: the mass gone,
 * a work budget of max(16 nnz, 2^21) reads, 4096 steps, the set-up's deadline (n <= 2^20: five
 * arrays of n, 36 MB at most); the rest past the last k by the certified
 * tails (every state's (|K|^j 1) <= min(qmax^j, kappa u^j)).  tailT[l] = sum over k > l of a_k
 * with that rest, rounded up: the bias of a truncation after l steps is at most per_step tailT[l]
 * (ulam__score_range's bound with kappa u^k in place of a_k, which it never exceeds).  On an
 * advective grid (convection-diffusion 30 x 30, cell Peclet 5) kappa = max v / min v is 1e12:
 * the range the rule clipped at was 414 standard deviations. */
static void tail_len(ulam_solver *s, const ulam_csr *K)
{
    enum { LMAX = 4096 };
    free(s->tailT), s->tailT = NULL, s->tailT_n = 0;
    free(s->tailS), s->tailS = NULL, s->tailS_b = NULL;
    int64_t n = K->nrows, i = s->o.query.index, reads = 0, budget = 16 * ulam_csr_nnz(K);
    double G = fmin(s->qmax < 1.0 ? s->qmax / (1.0 - s->qmax) : INFINITY,
                    s->tail_u < 1.0 && isfinite(s->kappa) ? s->kappa * s->tail_u / (1.0 - s->tail_u) : INFINITY);
    if (budget < (1 << 21)) budget = 1 << 21;
    if (!isfinite(G) || i < 0 || i >= n || n > (1 << 20)) return;
    double *r = ulam__calloc((size_t)n, sizeof *r), *y = ulam__calloc((size_t)n, sizeof *y), *a = ulam__malloc(LMAX + 1, sizeof *a);
    double *rs = ulam__calloc((size_t)n, sizeof *rs), *ys = ulam__calloc((size_t)n, sizeof *ys);
    double *z = ulam__malloc(LMAX + 1, sizeof *z), *ez = ulam__malloc(LMAX + 1, sizeof *ez);
    int64_t *on = ulam__malloc((size_t)n, sizeof *on), *nx = ulam__malloc((size_t)n, sizeof *nx), non = 1, L = 0;
    char *mk = ulam__calloc((size_t)n, 1);
    const double u = 0x1p-53 * 1.01; /* a rounding's relative size, with room for gamma_m = m u / (1 - m u) */
    double P = 1.0; /* prod of (1 + gamma) over the steps so far: the propagation's relative rounding */
    if (!r || !y || !a || !rs || !ys || !z || !ez || !on || !nx || !mk) goto done;
    r[i] = rs[i] = 1.0, on[0] = i, a[0] = 1.0, z[0] = s->b[i], ez[0] = 0.0;
    while (L < LMAX && a[L] > 0 && reads < budget && !(isfinite(s->deadline) && ulam_now() >= s->deadline)) { /* r |K|, rs K */
        int64_t nn = 0, step = 0;
        for (int64_t q = 0; q < non; q++) {
            int64_t w = on[q];
            for (int64_t k = K->rowptr[w]; k < K->rowptr[w + 1]; k++) {
                int64_t v = K->colidx[k];
                if (!mk[v]) mk[v] = 1, nx[nn++] = v;
                y[v] += r[w] * fabs(K->val[k]), ys[v] += rs[w] * K->val[k];
            }
            step += K->rowptr[w + 1] - K->rowptr[w];
            r[w] = rs[w] = 0.0;
        }
        double sum = 0.0, dot = 0.0;
        for (int64_t q = 0; q < nn; q++) {
            int64_t v = nx[q];
            sum += y[v], r[v] = y[v], y[v] = 0.0, mk[v] = 0;
            rs[v] = ys[v], ys[v] = 0.0, dot += rs[v] * s->b[v];
        }
        /* rs = e_i' K^(L+1) with |error| <= (P - 1) e_i' |K|^(L+1) entrywise (each entry a sum of at most
           step products: gamma_(step + 1)), and its dot with b within gamma_(nn + 1) of the exact one's
           |.| sum: |z - (K^(L+1) b)_i| <= ((P - 1) + d P) (|K|^(L+1) |b|)_i, at most that times
           per_step a_(L+1) P (1 + d) (a's sums err as rs's do), doubled for the second order */
        P *= 1.0 + (double)(step + 2) * u;
        double d = (double)(nn + 2) * u;
        reads += step;
        int64_t *t = on;
        on = nx, nx = t, non = nn, a[++L] = sum, z[L] = dot;
        ez[L] = 2.0 * ((P - 1.0) + d * P) * P * (1.0 + d) * s->per_step * sum;
    }
    s->tailT = ulam__malloc((size_t)L + 1, sizeof *s->tailT);
    s->tailS = ulam__malloc((size_t)L + 1, sizeof *s->tailS);
    if (!s->tailT || !s->tailS) {
        free(s->tailT), free(s->tailS), s->tailT = s->tailS = NULL;
        goto done;
    }
    double rest = a[L] * G; /* past step L */
    for (int64_t l = L; l >= 0; l--) {
        s->tailT[l] = rest * (1.0 + 1e-9); /* the sums' rounding */
        rest += a[l];
    }
    /* the signed tail: |sum over l < k <= L of z_k| plus each z_k's error, the sum's own rounding
       (gamma_L of the |z| summed) and past L the |K| tail's bound, per_step tailT[L] */
    double S = 0.0, Z = 0.0, Ez = 0.0, past = s->per_step * s->tailT[L];
    for (int64_t l = L; l >= 0; l--) {
        s->tailS[l] = (fabs(S) + Ez + 2.0 * (double)(L + 2) * u * Z + past) * (1.0 + 1e-9);
        S += z[l], Z += fabs(z[l]), Ez += ez[l];
    }
    s->tailT_n = L + 1, s->tailT_at = i, s->tailS_b = s->b, s->setup_work += 2 * reads;
done:
    free(r), free(y), free(a), free(rs), free(ys), free(z), free(ez), free(on), free(nx), free(mk);
}

/* Over the states walks can reach: absorption's p* > 0 wherever it scores (else ULAM_EUNDEFINED
 * naming the state), and the bound on a single score and the scores' range (s->bound, s->range):
 * 0 when nothing that scores is reachable; for absorption W |g_i| / p*_i, W the weight bound
 * (the start weight, or the roulette weight when larger, times the largest product of factors
 * S / q along a path, weight_growth; unbounded with splitting); the per-visit score and
 * continuation tail for collision and expected (s->per_step, s->qmax, and past qmax = 1 the
 * certificate of length_tail).  The reachable set, the pass and the certificates are kept, so a
 * rerun with another estimator reads M again only for what it has not computed. */
static int check_reach(ulam_solver *s, const ulam_csr *K, ulam_error *err)
{
    int status = reach(s, K, err);
    if (status) return status;
    if (s->passed && s->pass_only >= 0 && s->pass_only != s->o.estimator) s->passed = 0; /* made for another */
    if (!s->passed && (status = bounds_pass(s, K, err))) return status;
    const ulam__reach *given = given_bounds(s, K);
    int e = s->o.estimator, absorb = e == ULAM_ABSORPTION, adj = s->o.mode == ULAM_ADJOINT, it = 0;
    double vmax = s->pass[e].vmax, Wmax = s->pass_W, w0 = s->pass_w0;
    if (s->pass[e].bad >= 0)
        return ulam__fail(err, ULAM_EUNDEFINED, 0, s->pass[e].bad,
                          "p* > 0 wherever the absorption estimator scores; state %lld (1-based) is "
                          "reachable and never terminates (its row sum of |%s| is >= 1): use the "
                          "collision estimator or --continue Q",
                          (long long)s->pass[e].bad + 1, adj ? "M" : "M' (column of M)");
    s->tail_u = 1.0, s->kappa = INFINITY, s->visit = w0 * vmax, s->v2 = INFINITY;
    if (vmax > 0 && (!(s->pass_qmax < TAIL_Q) || (!isfinite(Wmax) && s->o.stop.rel_err > 0))) {
        if (!s->tail_done && given && given->tail) /* the caller's certificate over the same states */
            s->tail_uc = given->tail_u, s->tail_kc = given->kappa, s->tail_done = 1;
        if (!s->tail_done && (status = reached_flags(s, err))) return status;
        if (!s->tail_done) /* kappa enters by its log */
            length_tail(K, s->reached, s->o.kernel.continue_q, 0, 1e-30, s->deadline, &s->tail_uc, &s->tail_kc, &it),
                s->tail_done = 1;
        s->tail_u = s->tail_uc, s->kappa = s->tail_kc;
    }
    if (vmax > 0 && !isfinite(Wmax) && !(s->o.kernel.roulette > 0) && !(s->o.kernel.split > 0) &&
        (absorb ? isfinite(s->pass[e].g2max) : isfinite(vmax))) {
        if (!s->v2_done[e] && (status = reached_flags(s, err))) return status;
        if (!s->v2_done[e] && s->o.kernel.kernel_alpha != 1.0 && !s->fac &&
            !(s->fac = move_factors(K, s->reached, s->o.kernel.continue_q, s->o.kernel.kernel_alpha))) /* given bounds: not made */
            return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the kernel's weight factors");
        if (!s->v2_done[e]) s->v2c[e] = second_moment(s, K, s->fac, s->reached, w0, &it), s->v2_done[e] = 1;
        s->v2 = s->v2c[e];
    }
    s->setup_work += (int64_t)it * s->reach_nnz;
    double W = Wmax, gmax = s->pass[e].gmax;
    s->weight = W;
    s->signs = s->pass_signs;
    s->bound = gmax > 0 ? W * gmax : 0.0;
    s->range = s->bound * (s->signs ? 2.0 : 1.0);
    s->per_step = vmax > 0 ? W * vmax : 0.0;
    s->qmax = s->pass_qmax;
    if (adj && e == ULAM_COLLISION && !s->o.policy.system && !(given && given->shared) && !s->o.query.nstarts &&
        !isfinite(s->range) && s->per_step > 0 && isfinite(s->per_step) &&
        !(s->tailT_n && s->tailT_at == s->o.query.index))
        tail_len(s, K); /* no memory: none, the certificates' bound as before.  Not on a prepared file (read
                           lazily: only the rows walks reach) nor on an analysis' shared bounds (every query
                           alike, file or memory); bounds lent otherwise do not skip it, so a lent run equals
                           a directly built one bit for bit (analysis_test) */
    return ULAM_OK;
}

/* The reach of every state of K, with K's own bounds over it (see internal.h). */
int ulam__reach_all(const ulam_csr *K, double continue_q, double alpha, char *seen, ulam__reach *R)
{
    memset(seen, 1, (size_t)K->nrows);
    *R = (ulam__reach){.seen = seen, .bounds = 1, .K = K, .continue_q = fmax(continue_q, 0.0), .alpha = alpha,
                       .tail_u = 1.0, .kappa = INFINITY, .bad = -1};
    int status = ulam__kernel_reach(K, continue_q, seen, NULL, NULL); /* every row checked */
    if (status) return status;
    double *fac = NULL;
    if (alpha != 1.0 && !(fac = move_factors(K, seen, continue_q, alpha))) return ULAM_ENOMEM;
    kernel_bounds(K, seen, continue_q, fac, R);
    R->growth = R->fbig > 1.0 ? weight_growth(K, continue_q, fac, seen) : 1.0;
    if (!(R->qmax < TAIL_Q) || !isfinite(R->growth)) { /* the tail certificate check_reach would need */
        int it = 0;
        length_tail(K, seen, continue_q, 0, 1e-30, INFINITY, &R->tail_u, &R->kappa, &it);
        R->tail = 1;
    }
    free(fac);
    return ULAM_OK;
}

/* The scores of b over every state of K (see internal.h): bounds_pass's per-state quantities at
 * every state, as a pass over a reach of every state would find them. */
int ulam__reach_b(const ulam_csr *K, const double *b, ulam__reach *R)
{
    if (!K || !b || !R || !R->bounds || R->K != K) return ULAM_EINVAL;
    double bmax = 0.0, kbmax = 0.0, gabs = 0.0, g2abs = 0.0;
    int64_t bad = -1;
    int pos = 0, neg = 0;
    for (int64_t i = 0; i < K->nrows; i++) {
        double S = 0.0, c = 0.0, g = fabs(b[i]);
        for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) S += fabs(K->val[k]), c += K->val[k] * b[K->colidx[k]];
        double q = ulam__continuation(S, R->continue_q);
        bmax = fmax(bmax, g), kbmax = fmax(kbmax, fabs(c));
        pos |= b[i] > 0, neg |= b[i] < 0;
        if (g == 0.0) continue;
        if (q >= 1.0 && bad < 0) bad = i;
        gabs = fmax(gabs, q < 1.0 ? g / (1.0 - q) : INFINITY);
        g2abs = fmax(g2abs, q < 1.0 ? g * g / (1.0 - q) : INFINITY);
    }
    R->b = b, R->bmax = bmax, R->kbmax = kbmax, R->gabs = gabs, R->g2abs = g2abs, R->bad = bad;
    R->bpos = pos, R->bneg = neg;
    return ULAM_OK;
}

/* Refuse a rel_err target no bound on a single score can certify (nothing else ends the run):
 * absorption with weights that can grow without bound (a cycle of factors S / q > 1, or
 * splitting); collision and expected with such weights, or a continuation of 1 (qmax = 1) and
 * no Collatz-Wielandt certificate below 1. */
static int check_bounded(const ulam_solver *s, ulam_error *err)
{
    if (s->bound == 0.0 || s->per_step == 0.0) return ULAM_OK;
    int absorb = s->o.estimator == ULAM_ABSORPTION;
    double t = s->qmax < 1.0 ? s->qmax : s->tail_u;
    if (isfinite(s->v2) || (absorb ? isfinite(s->range) : isfinite(s->per_step) && t < 1.0)) return ULAM_OK;
    const char *why = s->o.kernel.split > 0 ? "splitting leaves the weights without a bound"
                      : !isfinite(s->per_step) ? "a reachable cycle of weight factors S/q > 1 lets weights grow without "
                                                 "bound, and no second-moment certificate holds"
                                               : "a reachable row of |M| sums to 1 or more and no Collatz-Wielandt vector "
                                                 "certifies the walk's length tail below 1";
    return ulam__fail(err, ULAM_EINFVAR, 0, -1, "a bound on a single walk's score (%s)", why);
}

/* Nonzero when a single score is bounded, so every moment of it is finite: nothing scores;
 * absorption's score bound (one score a walk, W max |g| / p*); collision and expected with
 * bounded weights (per_step) and a walk length with a geometric tail: qmax < 1, or at
 * exponent 1, where every factor S / q is at least 1 so a weight never shrinks and a walk is
 * alive after k steps with probability at most E|w_k| / w0 <= kappa u^k, the length tail's
 * certificate (at another exponent factors below 1 break that argument: not counted). */
static int score_bounded(const ulam_solver *s)
{
    if (s->bound == 0.0 || s->per_step == 0.0) return 1;
    if (s->o.estimator == ULAM_ABSORPTION) return isfinite(s->range);
    return isfinite(s->per_step) &&
           (s->qmax < 1.0 || (s->o.kernel.kernel_alpha == 1.0 && s->tail_u < 1.0 && isfinite(s->kappa)));
}

/* The fourth-moment verdict of a rel_err run (after check_reach): 1 when the score is bounded,
 * else rho(M4) of K, computed once (only here: a bounded score needs no pass over K), below 1
 * (1), at least 1 (0) or straddling it (-1); -1 without rel_err. */
static int take_fourth(ulam_solver *s, const ulam_csr *K, ulam_error *err)
{
    s->fourth = -1;
    if (!(s->o.stop.rel_err > 0)) return ULAM_OK;
    if (score_bounded(s)) return s->fourth = 1, ULAM_OK;
    if (!s->rho4_done) {
        int status = s->o.mode == ULAM_ADJOINT ? verify_all(s->M, &s->o, &s->rc, err) : ULAM_OK; /* it reads all of K */
        if (status) return status;
        status = ulam__guard_fourth(K, s->o.kernel.continue_q, s->o.kernel.kernel_alpha,
                                        s->g.computed & ULAM_GUARD_ABS ? &s->g.abs : NULL, &s->rho4, err);
        if (status) return status;
        s->rho4_done = 1;
    }
    s->fourth = s->rho4.upper < 1.0 ? 1 : s->rho4.lower >= 1.0 ? 0 : -1;
    return ULAM_OK;
}

/* Refuse a rel_err target (asked alone: the caller checks) whose score has no bound, no
 * certified finite fourth moment and no certified second moment: the rule's check on the
 * variance's own relative error trusts a sample fourth moment, which then errs low
 * (tests/test_kernel.c: the variance's spread over seeds 1.7 times what the runs report), and
 * nothing else would end the run (with v2 the rule stands on v2 and skips that check).
 * The message names a mode or exponent 1 whose rho(M4) is below 1 when one is. */
static int check_fourth(const ulam_csr *M, const ulam_solver *s, ulam_error *err)
{
    const ulam_walk_opts *o = &s->o;
    if (s->fourth == 1 || isfinite(s->v2) || !(o->stop.rel_err > 0)) return ULAM_OK; /* v2: the rule stands on it */
    char also[96] = "; no other mode or alpha 1 has it below 1";
    ulam_csr *T = NULL;
    if (!verify_all(M, o, &s->rc, NULL) && !ulam_csr_transpose(M, &T)) {
        const int modes[3] = {1 - o->mode, o->mode, 1 - o->mode};
        const double alphas[3] = {o->kernel.kernel_alpha, 1.0, 1.0};
        for (int c = 0; c < (o->kernel.kernel_alpha != 1.0 ? 3 : 1); c++) {
            ulam_power p;
            if (!ulam__guard_fourth(modes[c] == ULAM_ADJOINT ? M : T, o->kernel.continue_q, alphas[c], NULL, &p, NULL) &&
                p.upper < 1.0) {
                snprintf(also, sizeof also, "; %s at alpha %g has it finite, %.3g < 1",
                         modes[c] == ULAM_ADJOINT ? "adjoint" : "forward", alphas[c], p.upper);
                break;
            }
        }
    }
    ulam_csr_free(T);
    return ulam__fail(err, ULAM_EINFVAR, 0, -1,
                      "a finite fourth moment for a relative-error target: scores unbounded (%s), rho(M4) of the %s "
                      "kernel at alpha %g in [%.4g, %.4g] (%s): variance_rel_error errs low%s",
                      isfinite(s->weight) ? "no certified length tail" : "weights grow on cycles",
                      o->mode == ULAM_ADJOINT ? "adjoint" : "forward", o->kernel.kernel_alpha, s->rho4.lower, s->rho4.upper,
                      s->fourth == 0 ? ">= 1: infinite" : "straddles 1: unknown", also);
}

/* The score bounds of this run's estimator (check_reach, when absorption or a rel_err target needs
 * them), and with rel_err alone the refusal of a
 * target no bound certifies (check_bounded). */
static int take_bounds(ulam_solver *s, const ulam_csr *K, int rel_alone, ulam_error *err)
{
    s->bound = s->range = s->per_step = s->visit = s->v2 = s->kappa = s->weight = INFINITY;
    s->qmax = s->tail_u = 1.0;
    s->signs = 0;
    int status = check_reach(s, K, err); /* every run: the printed interval needs the range (stop.h) */
    if (!status) status = take_fourth(s, K, err);
    if (!status && rel_alone) status = check_bounded(s, err);
    return !status && rel_alone ? check_fourth(s->M, s, err) : status;
}

/* The guards' verdicts for this run: opts->guard when it holds them, else computed (rho(|M|)
 * and this mode's rho(M^), stopped once certified). */
static int take_guard(const ulam_csr *M, const ulam_walk_opts *o, const ulam__rows_check *rc, ulam_guard *g,
                      ulam_error *err)
{
    int need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(o->mode);
    if (ulam__guard_fits(o->policy.guard, o->kernel.continue_q, o->kernel.kernel_alpha, need)) { /* src/guard.c */
        *g = *o->policy.guard;
        return ULAM_OK;
    }
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = need;
    go.kernel_alpha = o->kernel.kernel_alpha;
    int status = verify_all(M, o, rc, err); /* the guards read all of M */
    return status ? status : ulam_guard_check(M, o->kernel.continue_q, &go, g, err);
}

/* Refuse what the verdicts refuse: walks not certified to converge (unless force), a
 * relative-error target the variance cannot honour with nothing else to end the run. */
static int check_verdicts(const ulam_csr *M, ulam_solver *s, ulam_error *err)
{
    const ulam_walk_opts *o = &s->o;
    const ulam_power *a = &s->g.abs, *h = &s->g.hat[o->mode];
    if (s->g.verdict_abs >= ULAM_VERDICT_FAIL && !o->policy.force)
        return ulam__fail(err, ULAM_EDIVERGE, 0, -1,
                          "rho(|M|) certified below 1; its bounds are [%.6g, %.6g]%s: the walks' expected score "
                          "may be a divergent series (force walks anyway)", a->lower, a->upper,
                          s->g.verdict_abs == ULAM_VERDICT_FAIL ? "" : ", not certain either way");
    s->var_finite = ulam_guard_variance(&s->g, o->mode);
    if (s->var_finite < 0 && o->policy.assume_finite) s->var_finite = 1;
    if (s->var_finite == 1 || !(o->stop.rel_err > 0) || o->stop.max_walks > 0 || o->stop.max_seconds > 0) return ULAM_OK;
    int other = 1 - o->mode;
    ulam_guard og = s->g;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_HAT(other);
    go.kernel_alpha = o->kernel.kernel_alpha;
    if (!(og.computed & go.need) && ulam_guard_check(M, o->kernel.continue_q, &go, &og, NULL)) og.verdict_hat[other] = ULAM_VERDICT_UNKNOWN;
    char also[96] = "; the other mode's is not certified finite either";
    if (ulam_guard_variance(&og, other) == 1)
        snprintf(also, sizeof also, "; the %s mode's is finite, %.4g < 1", other == ULAM_ADJOINT ? "adjoint" : "forward",
                 og.hat[other].upper);
    char alpha[48] = "";
    if (o->kernel.kernel_alpha != 1.0) snprintf(alpha, sizeof alpha, " at kernel exponent alpha = %g", o->kernel.kernel_alpha);
    return ulam__fail(err, ULAM_EINFVAR, 0, -1,
                      "a finite variance for a relative-error target: rho(M^) of the %s kernel%s is in [%.4g, %.4g] (%s)%s",
                      o->mode == ULAM_ADJOINT ? "adjoint" : "forward", alpha, h->lower, h->upper,
                      s->var_finite == 0 ? ">= 1: infinite" : "straddles 1: unknown", also);
}

/* The forward source distribution |b| / ||b||_1 as an alias table; sets *bnorm1. */
static int build_source(ulam_solver *s, double *bnorm1)
{
    int64_t n = s->n;
    double *p = ulam__malloc((size_t)n, sizeof *p), *scaled = ulam__malloc((size_t)n, sizeof *scaled);
    int32_t *out = ulam__malloc((size_t)n, sizeof *out);
    int64_t *small = ulam__malloc((size_t)n, sizeof *small), *large = ulam__malloc((size_t)n, sizeof *large);
    s->src = ulam__malloc((size_t)n, sizeof *s->src);
    int status = ULAM_ENOMEM;
    if (p && scaled && out && small && large && s->src) {
        double norm = 0.0;
        for (int64_t i = 0; i < n; i++) norm += fabs(s->b[i]);
        *bnorm1 = norm;
        for (int64_t i = 0; i < n; i++) {
            p[i] = norm > 0 ? fabs(s->b[i]) / norm : 1.0 / (double)n;
            out[i] = s->b[i] < 0 ? ~(int32_t)i : (int32_t)i;
        }
        ulam__alias_build(p, out, n, s->src, scaled, small, large);
        status = ULAM_OK;
    }
    free(p), free(scaled), free(out), free(small), free(large);
    return status;
}

/* The adjoint start distribution |c_j| / ||c||_1 over the nstarts start states as an alias table,
 * their rows' units and (expected estimator) their b. */
static int build_starts(ulam_solver *s)
{
    int64_t k = s->o.query.nstarts;
    double *p = ulam__malloc((size_t)k, sizeof *p), *scaled = ulam__malloc((size_t)k, sizeof *scaled);
    int32_t *out = ulam__malloc((size_t)k, sizeof *out);
    int64_t *small = ulam__malloc((size_t)k, sizeof *small), *large = ulam__malloc((size_t)k, sizeof *large);
    s->start_src = ulam__malloc((size_t)k, sizeof *s->start_src);
    s->start_units = ulam__malloc((size_t)k, sizeof *s->start_units);
    s->start_b = ulam__malloc((size_t)k, sizeof *s->start_b);
    int status = ULAM_ENOMEM;
    if (p && scaled && out && small && large && s->start_src && s->start_units && s->start_b) {
        double norm = start_weight(&s->o, s->b, s->n);
        for (int64_t j = 0; j < k; j++) {
            p[j] = fabs(s->o.query.start_weights[j]) / norm;
            out[j] = s->o.query.start_weights[j] < 0 ? ~(int32_t)j : (int32_t)j;
            s->start_units[j] = ulam__kernel_unit(s->k, s->o.query.starts[j], &s->ks[0]);
            s->start_b[j] = s->o.estimator == ULAM_EXPECTED ? s->b[s->o.query.starts[j]] : 0.0;
        }
        ulam__alias_build(p, out, k, s->start_src, scaled, small, large);
        s->w.nstarts = k, s->w.start_src = s->start_src, s->w.start_units = s->start_units;
        s->w.start_b = s->start_b, s->w.start_norm = norm;
        status = ULAM_OK;
    }
    free(p), free(scaled), free(out), free(small), free(large);
    return status;
}

/* Allocate per-thread scratch and per-block results. */
static int alloc_work(ulam_solver *s)
{
    s->scratch = calloc((size_t)s->threads, sizeof *s->scratch);
    s->ks = calloc((size_t)s->threads, sizeof *s->ks);
    s->blocks = calloc(ROUND, sizeof *s->blocks);
    if (!s->scratch || !s->ks || !s->blocks) return ULAM_ENOMEM;
    for (int t = 0; t < s->threads; t++) {
        ulam__scratch *sc = &s->scratch[t];
        sc->stack_cap = STACK;
        sc->stack_s = ulam__malloc(STACK, sizeof *sc->stack_s);
        sc->stack_w = ulam__malloc(STACK, sizeof *sc->stack_w);
        sc->ks = &s->ks[t];
        if (!sc->stack_s || !sc->stack_w || ulam__kscratch_alloc(s->k, sc->ks)) return ULAM_ENOMEM;
        if (s->o.mode == ULAM_FORWARD) {
            sc->hist = ulam__calloc((size_t)s->n, sizeof *sc->hist);
            sc->touched = ulam__malloc((size_t)s->n, sizeof *sc->touched);
            sc->mark = ulam__calloc((size_t)s->n, 1);
            sc->bsum = ulam__calloc((size_t)s->n, sizeof *sc->bsum);
            sc->bsq = ulam__calloc((size_t)s->n, sizeof *sc->bsq);
            sc->btouched = ulam__malloc((size_t)s->n, sizeof *sc->btouched);
            sc->bmark = ulam__calloc((size_t)s->n, 1);
            if (!sc->hist || !sc->touched || !sc->mark || !sc->bsum || !sc->bsq || !sc->btouched || !sc->bmark)
                return ULAM_ENOMEM;
        }
    }
    if (s->o.mode == ULAM_FORWARD) {
        s->sum = ulam__calloc((size_t)s->n, sizeof *s->sum);
        s->sumsq = ulam__calloc((size_t)s->n, sizeof *s->sumsq);
        if (!s->sum || !s->sumsq) return ULAM_ENOMEM;
    }
    return ULAM_OK;
}

/* The kernel's failure (a corrupt row of a mapped file, a non-finite score or no memory to
 * build a row) as a status with err filled; ULAM_OK when it has none. */
static int kernel_failure(const ulam_kernel *k, const ulam_system *sys, ulam_error *err)
{
    int status = atomic_load(&k->status);
    if (!status) return ULAM_OK;
    int64_t i = atomic_load(&k->bad);
    if (status == ULAM_ESYNTAX && sys && i >= 0 && ulam__system_row_error(sys, i, err)) return status; /* named */
    if (status == ULAM_ENOMEM) return ulam__fail(err, status, 0, i, "memory to build a walk kernel row");
    if (status == ULAM_ERANGE)
        return ulam__fail(err, status, 0, i, "row %lld (1-based) with every move's probability |K_ij|^alpha / "
                          "sum_k |K_ik|^alpha at least 2^-40 / its length at kernel exponent alpha = %g (its entries "
                          "are too uneven for this alpha: a lower one samples them)", (long long)i + 1, k->alpha);
    return ulam__fail(err, status, 0, i, "row %lld (1-based) with its range in rowptr, columns in range and "
                      "finite, nonzero values and score (the matrix is corrupt)", (long long)i + 1);
}

/* The expected steps of a walk by the length tail (qmax, or the certificate's u and kappa; 1
 * without either). */
static double mean_steps(const ulam_solver *s)
{
    if (s->qmax < 1.0) return 1.0 / (1.0 - s->qmax);
    double t = tail_steps(s->tail_u, s->kappa);
    return isfinite(t) ? t : 1.0;
}

/* A bound on sum over k >= 0 of (|K|^k 1)_i at the walks' starts i (the expected visits of a walk
 * on |K|, what a perturbation of the scores by at most d a visit moves the answer by, over d): by
 * the length tail's certificate, or with the analog continuation by its largest q; INFINITY
 * without either (src/bkrylov.c's rounding allowance). */
double ulam__solver_visits_bound(const ulam_solver *s)
{
    double t = s->tail_u < 1.0 ? tail_steps(s->tail_u, s->kappa) + 1.0 : INFINITY;
    if (!(s->o.kernel.continue_q > 0) && s->qmax < 1.0) t = fmin(t, 1.0 / (1.0 - s->qmax));
    return isfinite(t) ? t : INFINITY;
}

/* The push on b's cost model (src/fpush_b.c): the forward walks' predicted work on a residual of
 * l1 norm r_sum, with the bounds made on b (a forward walk's weight, and so its range and second
 * moment, scale with the l1 norm of what it starts from): the rule's range term at |x_i| ~ |q_i|
 * (ulam__solver_range_walks), at least ULAM__REL_FIRST walks (the rule's first check), each its expected steps plus a start
 * and a tally a visit; 0 with nothing left to walk. */
typedef struct {
    const ulam_solver *s;
    double bnorm1, per_walk, budget;
} push_ctx;

/* At a fixed budget (budget > 0 units of walks' work: --walks, --time) the model is instead the
 * work that would take walks from r_sum to the half-width the budget's walks from b reach: each
 * walk's weight, and so the interval's range and standard-error terms, scales with the l1 norm
 * it starts from, so that work is the budget times (r_sum / ||b||_1)^2 (reported only: the
 * sweeps are then chosen by the narrowing each buys, src/fpush_b.c). */
static double push_cost(double r_sum, double q_i, void *ctx)
{
    const push_ctx *c = ctx;
    if (r_sum == 0.0) return 0.0;
    if (c->budget > 0) return c->budget * (r_sum / c->bnorm1) * (r_sum / c->bnorm1);
    double E = c->s->o.stop.rel_err, m = fabs(q_i + c->s->o.stop.rel_err_offset);
    return fmax((double)ULAM__REL_FIRST, ulam__solver_range_walks(c->s, r_sum / c->bnorm1, 0, m, E)) * c->per_walk;
}

/* The budget a forward push is planned for: 0 under a rel_err target (its own model), else for
 * the method choice's solvers (push_fixed) with the variance certified finite (else there is no
 * bar to narrow) the walks' work a fixed budget buys in units (max_walks walks of per_walk, or
 * max_seconds at the work model's rate, the less); 0 without either. */
static double push_plan(const ulam_solver *s, double per_walk)
{
    const ulam_stop_opts *st = &s->o.stop;
    if (st->rel_err > 0 || !s->push_fixed || s->var_finite != 1) return 0.0;
    double w = st->max_walks > 0 ? (double)st->max_walks * per_walk : INFINITY;
    if (st->max_seconds > 0) w = fmin(w, st->max_seconds / ULAM_AUTO_UNIT_SECONDS);
    return isfinite(w) ? w : 0.0;
}

/* The most units a push for a fixed budget may take (src/fpush_b.c): ULAM__FPUSH_B_CAP times the
 * walks' work under max_walks, ULAM__FPUSH_B_TIME of the time's under max_seconds, the less. */
static double push_cap(const ulam_solver *s, double per_walk)
{
    const ulam_stop_opts *st = &s->o.stop;
    double c = st->max_walks > 0 ? ULAM__FPUSH_B_CAP * (double)st->max_walks * per_walk : INFINITY;
    if (st->max_seconds > 0) c = fmin(c, ULAM__FPUSH_B_TIME * st->max_seconds / ULAM_AUTO_UNIT_SECONDS);
    return c;
}

/* Forward walks (no weight window) with a rel_err target or a fixed budget: push b down while
 * that lowers the walks' predicted work (src/fpush_b.c; push_cost's two models), then walk from
 * the residual, its source table and score bounds made anew (*bnorm1 its l1 norm); rel_alone as
 * take_bounds. */
static int push_b(ulam_solver *s, int rel_alone, double *bnorm1, ulam_error *err)
{
    const ulam_walk_opts *o = &s->o;
    double V = mean_steps(s), pw = V + ULAM_AUTO_WALK + ULAM_AUTO_TALLY * (V + 1.0), plan = push_plan(s, pw);
    s->push_plan = plan;
    if (o->mode != ULAM_FORWARD || !(o->stop.rel_err > 0 || plan > 0) || o->kernel.roulette > 0 || o->kernel.split > 0 ||
        !(*bnorm1 > 0) || !isfinite(*bnorm1))
        return ULAM_OK;
    push_ctx c = {s, *bnorm1, pw, plan};
    s->pq = ulam__calloc((size_t)s->n, sizeof *s->pq), s->pr = ulam__malloc((size_t)s->n, sizeof *s->pr);
    if (!s->pq || !s->pr) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the push on b");
    memcpy(s->pr, s->b, (size_t)s->n * sizeof *s->pr);
    ulam__fpush_b(s->mt, o->query.index, push_cost, &c, plan > 0 ? plan / 2 : ULAM__REL_MIN * c.per_walk, plan,
                  plan > 0 ? push_cap(s, pw) : INFINITY, s->pq, s->pr, &s->push);
    s->setup_work += s->push.ops;
    if (s->push.sweeps == 0) { /* not worth a sweep: the walks start from b */
        free(s->pq), free(s->pr);
        s->pq = s->pr = NULL;
        return ULAM_OK;
    }
    s->b0 = s->b, s->b = s->pr;
    free(s->src), free(s->seen), free(s->fac); /* the source, reachable set and score bounds depend on b */
    s->src = NULL, s->seen = NULL, s->reached = NULL, s->fac = NULL;
    s->passed = s->tail_done = 0;
    memset(s->v2_done, 0, sizeof s->v2_done);
    if (build_source(s, bnorm1)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the source table");
    return take_bounds(s, s->mt, rel_alone, err);
}

/* Prepare walks on (I - M) x = b; reach: the states they can reach, computed before (NULL: search);
 * kernel: a kept kernel to walk on, rescored to b (NULL: a new one). */
static int solver_alloc(const ulam_csr *M, const double *b, const ulam_walk_opts *opts, const ulam__reach *reach,
                        ulam_kernel *kernel, double deadline, int push_fixed, ulam_solver **out, ulam_error *err)
{
    double t_alloc = ulam_now(); /* a time limit counts the set-up below (guards, reach, bounds, push) */
    ulam__clear(err);
    if (!M || !b || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, b and an output");
    *out = NULL;
    ulam_walk_opts o = opts ? *opts : ulam_walk_defaults();
    int status = check_opts(M, &o, err);
    if (status) return status;
    ulam__rows_check rc = {0};
    if (o.policy.system && (status = ulam__system_rows_check(o.policy.system, M, b, &rc, err))) return status;
    if ((o.mode == ULAM_FORWARD || o.kernel.whole_kernel || (reach && reach->seen)) && (status = verify_all(M, &o, &rc, err)))
        return status; /* these read all of M (and forward, all of b) */
    if ((status = check_split(M, b, &o, err))) return status;
    if (o.mode == ULAM_FORWARD && (status = ulam__csr_check_structure(M, err))) /* src/check.c: M' is made */
        return status; /* (adjoint: the guards' pass checks M, or the kernel each row it builds) */
    double bnorm1 = 0.0;
    ulam_solver *s = calloc(1, sizeof *s);
    if (!s) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the solver");
    s->o = o;
    s->b = b;
    s->push_plan = -1.0, s->push_fixed = push_fixed;
    s->deadline = fmin(deadline, o.stop.max_seconds > 0 ? t_alloc + o.stop.max_seconds : INFINITY);
    if (o.exec.share && o.exec.share->nranks > 1) s->deadline = INFINITY; /* every rank's bounds the same: no clock */
    /* b far from 1: walk on b 2^-e and scale what they find (exact), so x = 6.7e307 is answered
       and no score's square underflows (b = 1e-300: a standard error of 0); not with a kernel
       scored to b, nor on a prepared file's lazy path (adjoint with guards or a reach given reads
       only the b_i its walks reach); a reach's summary of b is then not this b's (bounds_pass) */
    int lazy = o.mode == ULAM_ADJOINT && o.policy.system && (o.policy.guard || reach);
    s->bexp = !kernel && !lazy && o.stop.rel_err_offset == 0.0 &&
                      (o.mode == ULAM_ADJOINT || !(o.kernel.roulette > 0 || o.kernel.split > 0))
                  ? ulam__b_exponent(b, M->nrows) : 0;
    if (s->bexp && !(s->b = b = s->bs = ulam__b_scaled(b, M->nrows, s->bexp))) goto nomem;
    s->n = M->nrows;
    s->given = o.mode == ULAM_ADJOINT ? reach : NULL;
    s->M = M;
    s->rc = rc;
    if ((status = take_guard(M, &o, &rc, &s->g, err)) || (status = check_verdicts(M, s, err))) {
        ulam_solver_free(s);
        return status;
    }
    s->walks_given = o.stop.max_walks > 0;
    s->o.stop.max_walks = ulam__walk_cap(&o);
    s->threads = ulam__threads(o.exec.threads);
    const ulam_csr *K = M;
    if (o.mode == ULAM_FORWARD) {
        if (ulam_csr_transpose(M, &s->mt) || build_source(s, &bnorm1)) goto nomem;
        K = s->mt;
    }
    ulam__scores sc = {o.mode == ULAM_ADJOINT ? b : NULL, o.estimator};
    if (kernel && (o.mode != ULAM_ADJOINT || kernel->K != K || kernel->continue_q != o.kernel.continue_q ||
                   kernel->alpha != o.kernel.kernel_alpha || kernel->scores.estimator != o.estimator)) {
        ulam_solver_free(s);
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a kept kernel made for this M, mode, continuation and estimator");
    }
    if (kernel) {
        s->k = kernel, s->k_borrowed = 1;
        if ((status = ulam__kernel_rescore_b(kernel, b))) {
            status = kernel_failure(kernel, o.policy.system, err);
            ulam_solver_free(s);
            return status ? status : ulam__fail(err, ULAM_EINVAL, 0, -1, "a kept kernel (ulam__solver_keep_kernel)");
        }
    } else if ((status = ulam__kernel_alloc(K, o.kernel.continue_q, o.kernel.kernel_alpha, sc, &s->k)) == ULAM_EOVERFLOW) {
        ulam_solver_free(s);
        return ulam__fail(err, status, 0, -1, "a walk kernel of under 2^30 units (3 n + nnz < 1073741824)");
    }
    if (status) goto nomem;
    if (!kernel && ulam__kernel_set_check(s->k, &rc)) goto nomem;
    s->rho4 = (ulam_power){.rho = NAN, .upper = INFINITY, .rowsum_max = INFINITY, .colsum_max = INFINITY};
    if ((status = take_bounds(s, K, o.stop.rel_err > 0 && o.stop.max_walks == 0 && o.stop.max_seconds == 0, err))) {
        ulam_solver_free(s);
        return status;
    }
    if ((status = take_fourth(s, K, err)) ||
        (o.stop.max_walks == 0 && o.stop.max_seconds == 0 && (status = check_fourth(M, s, err))) ||
        (status = push_b(s, o.stop.rel_err > 0 && o.stop.max_walks == 0 && o.stop.max_seconds == 0, &bnorm1, err))) {
        ulam_solver_free(s);
        return status;
    }
    if (alloc_work(s)) goto nomem;
    if (o.kernel.whole_kernel) ulam__kernel_complete(s->k, s->threads, s->ks);
    s->w = (ulam__walker){.k = s->k, .mt = s->mt, .src = s->src,
                          .bnorm1 = bnorm1, .roulette = o.kernel.roulette, .split = o.kernel.split,
                          .max_steps = o.stop.max_steps, .interrupt = o.stop.interrupt,
                          .lanes = s->k->cap * (int64_t)sizeof(ulam__slot) <= CACHED ? 16 : 32};
    if (o.mode == ULAM_ADJOINT) s->w.start = ulam__kernel_unit(s->k, o.query.index, &s->ks[0]);
    if (o.query.nstarts > 0 && build_starts(s)) goto nomem;
    if (o.mode == ULAM_ADJOINT && o.estimator == ULAM_EXPECTED) s->w.score0 = s->b[o.query.index];
    if (o.mode == ULAM_FORWARD && o.estimator == ULAM_EXPECTED) s->w.expected = 1;
    s->w.watch = o.mode == ULAM_FORWARD ? o.query.index : -1;
    if ((status = kernel_failure(s->k, s->o.policy.system, err))) {
        ulam_solver_free(s);
        return status;
    }
    ulam__run_reset(&s->run);
    if (o.stop.max_seconds > 0) s->run.t0 = t_alloc;
    *out = s;
    return ULAM_OK;
nomem:
    ulam_solver_free(s);
    return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walk kernel and workspace");
}

/* Prepare walks on (I - M) x = b. */
int ulam_solver_alloc(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                      ulam_solver **out, ulam_error *err)
{
    return solver_alloc(M, b, opts, NULL, NULL, INFINITY, 0, out, err);
}

/* As ulam_solver_alloc with the reachable states and a kept kernel (both borrowed). */
int ulam__solver_alloc_reached(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                               const ulam__reach *reach, ulam_kernel *kernel, ulam_solver **out, ulam_error *err)
{
    return solver_alloc(M, b, opts, reach, kernel, INFINITY, 0, out, err);
}

/* As ulam__solver_alloc_reached, its set-up taking the cheaper paths past deadline (see solve.h). */
int ulam__solver_alloc_until(const ulam_csr *M, const double *b, const ulam_walk_opts *opts, const ulam__reach *reach,
                             double deadline, ulam_solver **out, ulam_error *err)
{
    return solver_alloc(M, b, opts, reach, NULL, deadline, 1, out, err);
}

/* A time limit's end for the set-up that follows (deadline, INFINITY: none) and the time the
 * walks' limit counts from (t0 >= 0; < 0: left as it is) (see solve.h). */
void ulam__solver_clock(ulam_solver *s, double t0, double deadline)
{
    s->deadline = deadline;
    if (t0 >= 0 && s->o.stop.max_seconds > 0) s->run.t0 = t0;
}

/* The solver's kernel, kept for later solvers (see internal.h). */
ulam_kernel *ulam__solver_keep_kernel(ulam_solver *s)
{
    if (!s || s->k_borrowed || s->o.mode != ULAM_ADJOINT || s->bexp || ulam__kernel_keep(s->k)) return NULL; /* bexp: scored to b 2^-bexp */
    s->k_borrowed = 1;
    return s->k;
}

/* The solver's kernel, kept for later solvers with the same b, unchanged (see internal.h). */
ulam_kernel *ulam__solver_keep_kernel_fixed(ulam_solver *s)
{
    if (!s || s->k_borrowed || s->o.mode != ULAM_ADJOINT || s->bexp || atomic_load(&s->k->status)) return NULL;
    s->k_borrowed = 1, s->k->fixed = 1; /* nothing recorded: only this b, unchanged, rescores (a no-op) */
    return s->k;
}

/* The states the solver's walks can reach (NULL unless its reachability check ran). */
const char *ulam__solver_reached(const ulam_solver *s)
{
    return s->given ? s->given->seen : s->seen;
}

/* Run walks [first, first + count) as block q on thread t (ctx: the solver). */
static void run_block(void *ctx, int q, int64_t first, int64_t count, int t)
{
    ulam_solver *s = ctx;
    ulam__block *br = &s->blocks[q];
    br->h.complete = 0;
    br->h.walks = 0;
    if (!ulam__mine(s->o.exec.share, first / BLOCK) || !ulam__block_may_start(&s->o, s->run.t0, first)) return;
    ulam_rng r;
    ulam_rng_seed(&r, s->o.exec.seed, (uint64_t)(first / BLOCK));
    if (s->o.mode == ULAM_ADJOINT) ulam__adjoint_block(&s->w, count, &r, &s->scratch[t], br);
    else ulam__forward_block(&s->w, count, &r, &s->scratch[t], br);
}

static void cs_plan(ulam_solver *s);
static void cs_plan_from(ulam_solver *s, const ulam__moments *run);
static void round_clip(ulam_solver *s);

/* Feed the sequence the run's first block br a part at a time (walk.h's ULAM__SUB_WALKS histories
 * in start order; forward: with the zeros of the histories that did not tally the watched
 * component), each bet planned from the parts before it: a block of 1024 scores with no earlier
 * one to plan from bet as if the variance were the largest possible (a --walks 1000 run printed
 * 10 times the width of the 4096-walk one, Poisson 70 x 70 centre). */
static void cs_first(ulam_solver *s, const ulam__block *br)
{
    ulam__moments run = {0};
    for (int q = 0; q < ULAM__SUBS; q++) {
        ulam__moments c = br->sub[q];
        if (s->o.mode == ULAM_FORWARD) {
            int64_t first = (int64_t)q * ULAM__SUB_WALKS, left = br->h.walks - first;
            int64_t walks = q == ULAM__SUBS - 1 ? left : left < ULAM__SUB_WALKS ? left : ULAM__SUB_WALKS;
            ulam__moments zeros = {.n = walks > c.n ? walks - c.n : 0};
            ulam__moments_merge(&c, &zeros);
        }
        if (c.n == 0) continue;
        cs_plan_from(s, &run);
        ulam__cs_add4(&s->cs, c.n, c.mean, c.m2, c.m3, c.m4, 0.0);
        ulam__moments_merge(&run, &c);
    }
}

/* Merge completed block q into the totals (ctx: the solver; forward: the watched component's
 * moments count the block's histories that did not tally it as zeros; the walk and non-finite
 * counts are the round driver's). */
static void merge_block(void *ctx, int q)
{
    ulam_solver *s = ctx;
    const ulam__block *br = &s->blocks[q];
    int parts = s->cs.n == 0 && s->w.clip > 0;
    if (parts) cs_first(s, br); /* the first block, a part at a time */
    else cs_plan(s); /* from the blocks before this one alone */
    if (s->o.mode == ULAM_ADJOINT && !parts) ulam__cs_add4(&s->cs, br->clipped.n, br->clipped.mean, br->clipped.m2, br->clipped.m3, br->clipped.m4, 0.0);
    ulam__moments_merge(&s->adj, &br->m);
    s->maxsq = fmax(s->maxsq, br->maxsq);
    ulam__moments w = br->watched;
    const ulam__tally *t = br->h.tally;
    for (int64_t q = 0; q < br->h.len; q++) {
        s->sum[t[q].state] += t[q].value;
        s->sumsq[t[q].state] += t[q].square;
    }
    if (s->o.mode == ULAM_FORWARD) {
        ulam__moments zeros = {.n = br->h.walks - w.n};
        ulam__moments_merge(&w, &zeros);
        ulam__moments c = br->clipped;
        ulam__moments_merge(&c, &zeros);
        if (!parts) ulam__cs_add4(&s->cs, c.n, c.mean, c.m2, c.m3, c.m4, 0.0);
        ulam__moments_merge(&s->watched, &w);
    }
    s->steps += br->steps;
    s->cut += br->cut;
}

/* Before a round (ctx: the solver): once walks have built 1 / COMPLETE of the kernel, build the
 * rest at once. */
static void begin_round(void *ctx)
{
    ulam_solver *s = ctx;
    round_clip(s);
    if (atomic_load(&s->k->built) < s->n && atomic_load(&s->k->top) * COMPLETE > s->k->cap)
        ulam__kernel_complete(s->k, s->threads, s->ks);
}

/* A corrupt row a walk found fails the run (ctx: the solver). */
static int kernel_status(void *ctx)
{
    const ulam_solver *s = ctx;
    return atomic_load(&s->k->status);
}

static void result(const ulam_solver *s, ulam_walk_result *r, int count_unreached, int walked);

static void interval(const ulam_solver *s, const ulam_walk_result *r, double *R, ulam__stop_ci *ci);

/* Nonzero when the rel_err rule holds for r (see ulam_solve_walks in ulam.h): the run's 95% interval
 * (stop.h) meeting ulam__stop_rel_met (stderr <= E |m|, and the whole half-width, range and bias
 * terms included, within 2 sqrt(2 L) E |m|), after ULAM__REL_FIRST walks, forward with
 * the watched component tallied, and walks cut at max_steps moving it by at most
 * ULAM__CUT_SHARE E |m|; x certified 0 (nothing that scores is reachable) meets it at once. */
static int rel_err_met(const ulam_solver *s, const ulam_walk_result *r)
{
    double E = s->o.stop.rel_err, m = fabs(r->estimate + s->o.stop.rel_err_offset), R;
    if (!(E > 0) || s->var_finite != 1 || r->walks < REL_FIRST) return 0;
    if (s->bound == 0.0 || s->per_step == 0.0) return 1; /* nothing that scores is reachable: x is 0 */
    if (m == 0 || (s->o.mode == ULAM_FORWARD && s->sumsq[s->o.query.index] == 0)) return 0;
    if (!(r->cut_bound <= ULAM__CUT_SHARE * E * m)) return 0;
    ulam__stop_ci ci;
    interval(s, r, &R, &ci);
    return ci.kind == ULAM__STOP_EXACT || (ci.kind == ULAM__STOP_EB && ci.half <= E * m);
}

/* Under bounds over every state (ulam__reach_all), an estimate still exactly 0 once the rule
 * could hold: search the starts' own reach, whose bounds are what a solver without given bounds
 * has from the start (nothing that scores reachable certifies x = 0; looser bounds would leave
 * the rule unmet to the walk cap).  The search's bounds hold for the run as the others did, and
 * are at least as tight, so the rule may only stop it sooner from here on.  1 when it searched
 * (a failure ends the run with its status). */
static int search_reach(ulam_solver *s, const ulam_walk_result *r)
{
    if (!s->given || !s->given->bounds || !(s->o.stop.rel_err > 0) || s->run.walks < REL_FIRST ||
        r->estimate + s->o.stop.rel_err_offset != 0.0 || s->o.mode != ULAM_ADJOINT)
        return 0;
    s->given = NULL;
    free(s->seen), free(s->fac); /* the given reach and what was kept over it (as ulam__solver_restart) */
    s->seen = NULL, s->reached = NULL, s->fac = NULL;
    s->passed = s->tail_done = 0;
    memset(s->v2_done, 0, sizeof s->v2_done);
    ulam_error err;
    int status = check_reach(s, s->k->K, &err);
    if (!status) status = take_fourth(s, s->k->K, &err); /* as take_bounds: the bounds may now be bounded */
    if (status) s->run.done = 1, s->run.status = status;
    return 1;
}

/* A rel_err run no walk has scored in yet (its estimate 0 and no score seen): the least walks
 * the rule can need, (1 / p - 1) / E^2 with p the chance a walk scores at all (src/hit.c's
 * bound: at the start state, or averaged over the starts or the forward sources), into
 * s->hit_walks; the bound's sweeps go on while their reads stay within the walks' steps so far
 * (at least 16 passes over the reachable rows) and the count is within the walk budget.  Only
 * where the walks' reachable set is known and a score is a visit's or an ending's (collision,
 * absorption; no splitting, which lets copies of one walk score). */
static void zero_bound(ulam_solver *s, const ulam_walk_result *r)
{
    const ulam_walk_opts *o = &s->o;
    int fwd = o->mode == ULAM_FORWARD;
    if (!(o->stop.rel_err > 0) || r->walks < ULAM__REL_MIN || r->estimate + o->stop.rel_err_offset != 0.0 ||
        s->maxsq != 0.0 || !s->reached || o->kernel.split > 0 || o->estimator == ULAM_EXPECTED || s->hit_done == 2)
        return;
    const ulam_csr *K = fwd ? s->mt : s->k->K;
    if (!s->hitv) { /* touching (and reading b at) the reachable states alone */
        s->hitv = ulam__malloc((size_t)s->n, sizeof *s->hitv), s->hitt = ulam__calloc((size_t)s->n, 1);
        for (int64_t i = 0; i < s->n; i++) s->nhits += s->reached[i] != 0;
        s->hits = ulam__malloc((size_t)(s->nhits > 0 ? s->nhits : 1), sizeof *s->hits);
        if (!s->hitv || !s->hitt || !s->hits) {
            s->hit_done = 2; /* no memory: no bound (the run goes on as before) */
            return;
        }
        for (int64_t i = 0, k = 0; i < s->n; i++)
            if (s->reached[i]) s->hits[k++] = i, s->hitv[i] = 1.0, s->hitt[i] = fwd ? i == o->query.index : s->b[i] != 0.0;
    }
    double E = o->stop.rel_err, budget = fmax(16.0 * (double)(s->reach_nnz > 0 ? s->reach_nnz : ulam_csr_nnz(K)),
                                             (double)s->steps);
    for (;;) {
        double p = 0.0, norm = 0.0;
        if (fwd) /* the sources are reachable */
            for (int64_t j = 0; j < s->n; j++) p += s->b[j] != 0.0 ? fabs(s->b[j]) * s->hitv[j] : 0.0, norm += fabs(s->b[j]);
        else if (o->query.nstarts)
            for (int64_t j = 0; j < o->query.nstarts; j++)
                p += fabs(o->query.start_weights[j]) * s->hitv[o->query.starts[j]], norm += fabs(o->query.start_weights[j]);
        else
            p = s->hitv[o->query.index], norm = 1.0;
        p = fmin(1.0, p / norm * (1.0 + 1e-9)); /* the sweeps' rounding */
        s->hit_walks = p > 0 ? (1.0 / p - 1.0) / (E * E) : INFINITY;
        if (s->hit_done || s->hit_walks > (double)o->stop.max_walks || (double)s->hit_reads >= budget) return;
        s->hit_reads += ulam__hit_sweeps(K, s->hits, s->nhits, o->kernel.continue_q, o->kernel.kernel_alpha, s->hitt,
                                         o->estimator == ULAM_ABSORPTION, s->hitv, 1, &s->hit_sweep, &s->hit_done);
    }
}

/* Run one round of walks. */
int ulam_solver_iterate(ulam_solver *s)
{
    if (!s) return ULAM_EINVAL;
    if (s->run.done) return s->run.status;
    static const ulam__blocks B = {BLOCK, ROUND, run_block, sizeof(ulam__block), sizeof(ulam__tally), merge_block,
                                   begin_round, kernel_status, 1};
    if (s->o.stop.rel_err > 0 && s->run.walks == 0) s->run.want = REL_FIRST;
    ulam__round_step(&B, &s->o, s->threads, s, s->blocks, &s->run);
    ulam_walk_result r;
    result(s, &r, 0, 1); /* the rules compare it with bounds made on the walked b */
    if (!s->run.status && !isfinite(ldexp(r.estimate, s->bexp)) && s->run.walks > 0) /* beyond the largest double */
        s->run.status = ULAM_ENONFINITE, s->run.done = s->overflow = 1;
    if (!s->run.status && search_reach(s, &r)) {
        if (s->run.status) return s->run.status; /* the search failed */
        result(s, &r, 0, 1);
    }
    s->run.want = 0;
    if (s->o.stop.rel_err > 0 && s->run.walks > 0) { /* the next round no longer than the stop is near */
        const ulam__moments *mom = s->o.mode == ULAM_ADJOINT ? &s->adj : &s->watched;
        double m = fabs(r.estimate + s->o.stop.rel_err_offset);
        double left = ulam__cs_walks_left(&s->cs, mom->mean, ulam__moments_variance(mom), r.cut_bound, s->o.stop.rel_err * m);
        s->run.want = isfinite(left) && left > 0 ? (int64_t)fmin(fmax(fmax(left, (double)s->run.walks / REL_TAIL), REL_STEP), 1e15)
                                                 : 0; /* 1e15: past any budget, inside int64_t */
        if (s->run.walks < ULAM__REL_MIN) /* at most on to the walks the rules that give up (out of reach, cuts) */
            s->run.want = s->run.want > 0 ? imin64(s->run.want, ULAM__REL_MIN - s->run.walks) /* judge from */
                                          : ULAM__REL_MIN - s->run.walks;
    }
    int k = ulam__stop_epoch(s->run.walks), check = k > s->epoch; /* the rule checks once an epoch (stop.h) */
    if (check && s->o.stop.rel_err > 0 && s->run.walks >= ULAM__REL_MIN) s->epoch = k;
    if (check) zero_bound(s, &r);
    if (check && s->walks_given && s->o.stop.rel_err > 0 && s->run.walks >= ULAM__REL_MIN && isfinite(r.min_walks) &&
        r.min_walks > (double)s->o.stop.max_walks)
        s->budget_plan = 1; /* the target past --walks: its walks planned as a fixed count's from here (predictable) */
    if (rel_err_met(s, &r)) s->run.done = s->met = 1; /* every round: the sequence holds at every count */
    else if (check && s->o.stop.rel_err > 0 && s->hit_walks > (double)s->o.stop.max_walks && s->maxsq == 0.0 &&
             r.estimate + s->o.stop.rel_err_offset == 0.0 && !(s->o.stop.max_seconds > 0))
        s->run.done = s->out_of_reach = 1; /* no score yet, and the rule needs more walks than the budget before one */
    else if (s->o.stop.rel_err > 0 && s->run.walks >= ULAM__REL_MIN && fabs(r.estimate + s->o.stop.rel_err_offset) > 0 &&
             !(r.cut_bound <= ULAM__CUT_SHARE * s->o.stop.rel_err * fabs(r.estimate + s->o.stop.rel_err_offset)))
        s->run.done = s->cut_stop = 1; /* the cuts' bias may exceed the target: more walks cannot help */
    else if (s->o.stop.rel_err > 0 && s->var_finite == 1 && s->run.walks >= ULAM__REL_MIN && !(s->o.stop.max_seconds > 0) &&
             !s->walks_given &&
             fabs(r.estimate + s->o.stop.rel_err_offset) > 0 && isfinite(r.tail_bound) && r.min_walks > (double)s->o.stop.max_walks)
        s->run.done = s->out_of_reach = 1; /* the walks the target needs are past the budget or the cap */
    else if (s->o.stop.rel_err > 0 && s->run.walks >= ULAM__REL_MIN && !isfinite(r.ci95[0]) && r.min_walks > 0 &&
             isfinite(r.min_walks) && (double)s->run.walks > ULAM__NO_CI_SPAN * fmax(r.min_walks, ULAM__REL_MIN))
        s->run.done = s->out_of_reach = 1; /* still no interval (a score past the certified range) long after
                                               the walks the rule asked for: more walks would only spin */
    return s->run.status;
}

/* Nonzero once a stopping rule is met. */
int ulam_solver_done(const ulam_solver *s)
{
    return !s || s->run.done;
}

/* Forward estimate and standard error of component i from the sums; the error is NaN when no
 * walk has tallied it (unreached: 0 +- 0 would claim certainty). */
static void forward_component(const ulam_solver *s, int64_t i, double *est, double *se, double *var)
{
    double N = (double)s->run.walks, mean, v;
    ulam__sums_moments(N, s->sum[i], s->sumsq[i], &mean, &v);
    *est = mean + (s->o.estimator == ULAM_EXPECTED ? s->b[i] : 0.0) + (s->pq ? s->pq[i] : 0.0);
    *var = v;
    *se = N > 0 ? sqrt(v / N) : INFINITY;
    if (s->sum[i] == 0.0 && s->sumsq[i] == 0.0) *se = NAN; /* no walk tallied it: no estimate */
}

/* Nonzero when the sequence may take a history's score over its first l + 1 visits (the walker's
 * part_steps; round_clip), whose mean is off x by at most tailS[l]: adjoint collision from one
 * start with no roulette or splitting (one particle a history, its weight the product of the
 * moves' factors: E[w_k b_(j_k)] = (K^k b)_i) and the start's signed tail made for this b; scores
 * of both signs only.  Without signs the part's tail is still tighter where b is sparse, but the
 * printed interval holds the plain mean, whose rest the part leaves out: on the three clusters
 * (M >= 0, b on the last cluster, rare long visits there past the part) that stretch took the
 * rule 15.7x the CLT's walks where the whole scores take 2.4x, 3 of 5 runs not met. */
static int part_route(const ulam_solver *s)
{
    return s->signs && s->tailS && s->tailS_b == s->b && s->tailT_at == s->o.query.index && s->o.mode == ULAM_ADJOINT &&
           s->o.estimator == ULAM_COLLISION && !s->o.query.nstarts && !(s->o.kernel.roulette > 0) &&
           !(s->o.kernel.split > 0);
}

/* The range of a single score the rel_err rule uses at estimate m and target E: the bound on a
 * score (absorption); for collision and expected, whose scores grow with the walk's length, the
 * range of walks of at most l steps, l the length past which walks can add no more than E |m|
 * to the mean: visits score at most per_step and a walk is alive after k steps with
 * probability at most qmax^k, so the rest adds at most per_step qmax^(l+1) / (1 - qmax).
 * Adjoint collision from one start, when own: also the l at which the start's own tail
 * (tail_len) adds at most E |m|, when shorter.  INFINITY when no bound holds (qmax = 1, weights that can grow). */
static double score_range(const ulam_solver *s, double m, double E, int own)
{
    if (s->bound == 0.0) return s->range;
    double R = fmin(ulam__score_range(s->range, s->per_step, s->qmax, 1.0, s->signs, m, E),
                    ulam__score_range(s->range, s->per_step, s->tail_u, s->kappa, s->signs, m, E));
    if (own && s->tailT_n && s->tailT_at == s->o.query.index && s->o.mode == ULAM_ADJOINT && s->o.estimator == ULAM_COLLISION &&
        !s->o.query.nstarts && !isfinite(s->range) && m > 0 && E > 0) /* tail_len: the start's own tail */
        for (int64_t l = 0; l < s->tailT_n; l++)
            if (s->per_step * s->tailT[l] <= E * m || (part_route(s) && s->tailS[l] <= E * m)) {
                R = fmin(R, s->per_step * (double)(l + 1) * (s->signs ? 2.0 : 1.0));
                break;
            }
    return isfinite(R) ? R : ulam__moment_range(s->v2, s->signs, m, E);
}

/* The walks the rel_err rule's range term would need at estimate m and target E if a visit
 * scored at most per_visit times the walk's weight (absorption: a termination per_visit / p*),
 * both signs when signs, under this solver's reachability bounds, which must have been made for
 * scores of at most 1 a visit (b = 1; check_reach runs for rel_err > 0 or absorption): the
 * per-visit route of score_range, or the second moment's scaled by per_visit^2; INFINITY when
 * neither gives a bound.  The walks are the confidence sequence's at variance 0 (stop.h's
 * ulam__cs_walks_needed at the limit A = R, R / 2 with signs, as score_limit), the rule the run
 * stops on; the empirical-Bernstein rule's range term before predicted about half of them.  For a
 * planner that knows the scores only after these walks' set-up (src/bidir.c: the push's residual). */
double ulam__solver_range_walks(const ulam_solver *s, double per_visit, int signs, double m, double E)
{
    if (!(per_visit > 0)) return 0.0;
    signs = signs || s->signs;
    int q = s->qmax < 1.0, absorb = s->o.estimator == ULAM_ABSORPTION;
    double R = absorb ? (q ? s->weight * per_visit / (1.0 - s->qmax) * (signs ? 2.0 : 1.0) : INFINITY)
                      : ulam__score_range(INFINITY, s->weight * per_visit, q ? s->qmax : s->tail_u, q ? 1.0 : s->kappa,
                                          signs, m, E);
    if (!isfinite(R) && !absorb) R = ulam__moment_range(s->v2 * per_visit * per_visit, signs, m, E);
    if (!isfinite(R)) return INFINITY;
    return ulam__cs_walks_needed(m, 0.0, signs ? R / 2.0 : R, 0.0, E); /* the sequence's range term (score_limit's A) */
}

/* The most the walks cut at max_steps can have moved the mean (0 without cuts). */
static double cut_bound(const ulam_solver *s)
{
    if (s->cut == 0) return 0.0;
    return fmin(ulam__cut_bound(s->per_step, s->qmax, 1.0, s->o.stop.max_steps),
                ulam__cut_bound(s->visit, s->tail_u, s->kappa, s->o.stop.max_steps));
}

/* The scale the truncation's bias is measured against: |m|, or with an estimate of 0 the most
 * |x| can be by the same bounds (a visit's score over the length tail; sqrt(v2)); INFINITY
 * without one. */
static double bias_scale(const ulam_solver *s, double m)
{
    if (m > 0) return m;
    double X = fmin(s->qmax < 1.0 ? s->per_step / (1.0 - s->qmax) : INFINITY,
                    s->tail_u < 1.0 ? s->per_step * s->kappa / (1.0 - s->tail_u) : INFINITY);
    return isfinite(X) && X > 0 ? X : isfinite(s->v2) && s->v2 > 0 ? sqrt(s->v2) : INFINITY;
}

/* The estimate the walks' moments make (forward: with b_i for expected and the push's part). */
static double moments_estimate(const ulam_solver *s)
{
    double e, se, v;
    if (s->o.mode == ULAM_ADJOINT) return s->adj.mean;
    forward_component(s, s->o.query.index, &e, &se, &v);
    return e;
}

/* The limit of |score| a range R of a single score's random part gives: the adjoint expected
 * estimator's score0 (b_i, added to every score) plus R, or R / 2 either side of it with signs. */
static double score_limit(const ulam_solver *s, double R)
{
    return fabs(s->w.score0) + (s->signs ? R / 2.0 : R);
}

/* The walks the first block's truncation is planned over: the first round's (BLOCK); at a fixed
 * count (fixed) all nplan of them, as the later blocks plan; under a time limit without a target
 * the walks the work model (ULAM_AUTO_*: a walk's expected steps, start and tallies) says the time
 * left buys, at most max_walks, at least BLOCK (not across ranks: their plans must agree, their
 * clocks need not).  A first block planned for more walks than the run makes bets smaller (a
 * larger range), so weighs less against the later blocks; one planned for fewer keeps its bias
 * in the interval at its weight to the end (signed forward 200, --time 1: the first block's bias,
 * 139 for x = 0.57, about half of the +-12.6). */
static double first_walks(const ulam_solver *s, double nplan, int fixed)
{
    const ulam_stop_opts *st = &s->o.stop;
    if (fixed) return nplan;
    if (!(st->max_seconds > 0) || st->rel_err > 0 || !(s->run.t0 >= 0) || (s->o.exec.share && s->o.exec.share->nranks > 1))
        return fmin(nplan, (double)BLOCK);
    double V = mean_steps(s), left = st->max_seconds - (ulam_now() - s->run.t0);
    double n = left / ULAM_AUTO_UNIT_SECONDS / (V + ULAM_AUTO_WALK + ULAM_AUTO_TALLY * (V + 1.0));
    if (st->max_walks > 0) n = fmin(n, (double)st->max_walks);
    return isfinite(n) && n > BLOCK ? n : (double)BLOCK;
}

/* The plan for the next block from the run so far (stop.h's ulam__cs): the half-width aimed at,
 * h (rel_err: E |m|; else 0 and the planned walk count nplan: max_walks for a count fixed in
 * advance, else four times the walks so far); the range Rt of a single score (score_range: the
 * width of its random part), for scores without a bound at a truncation whose bias b is an
 * eighth of h (or of 2.7 sigma / sqrt(nplan); under rel_err the share of h from 1/4 to 1/64 that
 * ulam__cs_walks_needed says meets it soonest; without a target the grid's truncation whose bias
 * and range term over nplan walks add up least when that is less), kept between 1e-6 and max(ULAM__STOP_TAIL, E / 4)
 * of |m| (with no estimate yet, of the least of bias_scale's bound on |x| and a visit's largest
 * score: a loose bound on |x| would give the first blocks a bias that outweighs the rest); and the limit A of |score| (the adjoint expected estimator adds b_i,
 * score0, to every score, so a score past |b_i| + R, not R, is past the range).  grid 0: h and
 * nplan alone are asked for (a block's bet: its limit and bias are the round's), the grids'
 * searches skipped (4-5% of a run's instructions when made for every block).  target 1: the
 * target's plan even after a --walks budget took over the bets (budget_plan): the walks the
 * target needs (min_walks) are the target's, whatever the blocks were bet for. */
static void plan_terms(const ulam_solver *s, int grid, int target, double *Rt, double *A, double *b, double *h, double *nplan)
{
    const ulam__moments *mom = s->o.mode == ULAM_ADJOINT ? &s->adj : &s->watched;
    double E = s->o.stop.rel_err > 0 ? s->o.stop.rel_err : 0.0, mabs = fabs(moments_estimate(s) + s->o.stop.rel_err_offset);
    double m = mabs > 0 ? mabs : fmin(bias_scale(s, 0.0), s->per_step), var = ulam__moments_variance(mom), N = (double)mom->n;
    int truncated = !(s->bound == 0.0 || s->per_step == 0.0 || isfinite(s->range));
    int fixed = (!(E > 0) || (s->budget_plan && !target)) && !(s->o.stop.max_seconds > 0) && s->o.stop.max_walks > 0;
    *nplan = fixed ? (double)s->o.stop.max_walks : fmax(4.0 * N, 4096.0);
    *h = E > 0 && mabs > 0 && !fixed ? E * mabs : 0.0;
    double hp = *h > 0 ? *h : 2.7 * sqrt(var / *nplan), cap = fmax(ULAM__STOP_TAIL, E / 4.0) * m;
    double t = truncated && isfinite(m) && m > 0 ? fmin(cap, fmax(hp / 8.0, 1e-6 * m)) : 0.0;
    *Rt = !truncated ? score_range(s, 1.0, 1.0, 1) : t > 0 ? score_range(s, m, t / m, 1) : INFINITY;
    double X = bias_scale(s, 0.0), n1 = first_walks(s, *nplan, fixed), least = INFINITY, t0 = 1e-6 * m;
    for (int pass = 0; pass < 2; pass++) /* under rel_err a second pass: the least bias within 5% of the least */
        for (int j = 0; grid && truncated && N == 0 && isfinite(X) && X > t0 && t0 > 0 && j <= 4 * log2(X / t0); j++) {
            /* no estimate yet: the truncation whose bias and range term over the first round's walks (a
               bet at its largest; a fixed budget: over all its walks, as the later blocks plan, so the
               first block's bias is theirs and its weight no more than theirs: signed forward 200 at
               10^4 walks +-92 -> +-76, at 10^5 +-28 -> +-24) add up least, whatever x is (a bias of a millionth of a visit's score
               tripled the range of the first block: a --walks 1000 run's half-width was 0.16 x against
               0.048 x at 4096, Poisson 70 x 70 centre); under rel_err a bias of at most E X / 16 and,
               the sum being flat near its least, the smallest bias within 5% of it (the first block's
               bias stays in the sequence's weighted bias to the end: at E = 0.01 the least sum's bias,
               near E x, took 10% more walks, hub at 0.99) */
            /* not the start's own tail here: a tight clip gives the first blocks a small scale, so a
               large bet weight, and the bias X t / X of a loose X: weighted in to the end (a sticky chain
               at E = 0.1 took 2.0e7 walks for 2.8e6, the 12^3 Laplacian's corner at E = 0.01 2.07-2.49
               the CLT's count for 2.07-2.12) */
            double tj = X * exp2(-0.25 * j), Rj = score_range(s, X, tj / X, 0);
            double Aj = score_limit(s, Rj), wj = ulam__cs_range_width(Aj, n1) + tj;
            if (!isfinite(Rj) || (E > 0 && tj > E * X / 16.0)) continue;
            if (pass == 0 && wj < least) least = wj, t = tj, *Rt = Rj;
            if (pass == 1 && E > 0 && wj <= 1.05 * least) t = tj, *Rt = Rj;
        }
    if (grid && truncated && N > 0 && !(*h > 0) && isfinite(X) && X > t0 && t0 > 0) {
        /* a budget, no target: hp / 8 or the grid's truncation whose bias and range term over the
           planned walks add up least.  Where the range grows as 1 / t (the second moment's route:
           weights without a bound) hp / 8 took R to 1e9 and every later block's bet to nothing, so
           the first block's bias (139 for x = 0.57) stayed the interval's (signed forward 200:
           +-244 at 1e3 walks, +-407 at 1e5) */
        double At = score_limit(s, *Rt);
        double best = isfinite(*Rt) ? ulam__cs_range_width(At, *nplan) + t : INFINITY;
        for (int j = 0; j <= 4 * log2(X / t0); j++) {
            double tj = X * exp2(-0.25 * j), Rj = score_range(s, m, tj / m, 1);
            double Aj = score_limit(s, Rj), wj = ulam__cs_range_width(Aj, *nplan) + tj;
            if (isfinite(Rj) && wj < best) best = wj, t = tj, *Rt = Rj;
        }
    }
    for (int j = 2; truncated && *h > 0 && j <= 6; j++) { /* rel_err: the share of h (1/4 .. 1/64) that meets it soonest */
        double tj = fmin(cap, fmax(*h / (double)(1 << j), 1e-6 * m)), Rj = score_range(s, m, tj / m, 1);
        double Aj = score_limit(s, Rj), At = score_limit(s, *Rt);
        if (ulam__cs_walks_needed(mabs, var, Aj, tj, E) < ulam__cs_walks_needed(mabs, var, At, t, E)) t = tj, *Rt = Rj;
    }
    *A = isfinite(*Rt) ? score_limit(s, *Rt) : INFINITY;
    *b = truncated ? t : 0.0;
}

/* Before a round: the limit its blocks clip their scores at for the sequence, and the bias
 * bound that clipping leaves (plan_terms: a score past the range comes from a walk longer than
 * the truncation, or above the second moment's threshold, and clipping it moves it no more than
 * cutting that walk would); no clipping without a range. */
static void round_clip(ulam_solver *s)
{
    double Rt, A, b, h, nplan;
    plan_terms(s, 1, 0, &Rt, &A, &b, &h, &nplan);
    s->w.clip = isfinite(A) && A > 0 ? A : 0.0, s->clip_b = b;
    /* every length route's range is per_step (l + 1) (twice with signs) for walks cut after l steps,
       whose bias bound (an E|rest| bound, or tailS's |E rest|) is at most b: the sequence may take
       each history's first l + 1 visits, whose scores lie in [-A, A] unclipped; only where a
       length route set the range (b > 0: plan_terms truncated): a range from the start's reach
       (search_reach, s->range finite) has no bias bound for the visits a part leaves out */
    double j = s->per_step * (s->signs ? 2.0 : 1.0), l1 = s->w.clip > 0 && j > 0 ? nearbyint(Rt / j) : 0.0;
    s->w.part_steps = part_route(s) && s->w.score0 == 0.0 && b > 0.0 && l1 >= 1.0 && l1 < 1e15 && fabs(Rt - j * l1) <= 1e-9 * Rt
                          ? (int64_t)l1 : 0;
}

/* ulam__cs_plan4 from the sample mom; under rel_err a sample of zeros alone (nothing has scored:
 * no estimate, so no target, and a plan for four times the walks so far) bets as one with no
 * walks, at the prior's variance alone: from the prior shrunk by the walks so far it bet near the
 * cap, and the first hits, at the range's end, each put psi(0.94) = 1.9 in the penalty to the end
 * (three clusters, absorption at E = 0.1: 35% of the final penalty from the first 3000 of 1.2e6
 * walks; walks / CLT 3.01 -> 1.96 with REL_TAIL, docs/error-bars.md). */
static void cs_bet(ulam_solver *s, const ulam__moments *mom, double A, double b, double h, double nplan)
{
    double var = ulam__moments_variance(mom);
    int64_t n = s->o.stop.rel_err > 0 && !(var > 0) && mom->mean == 0.0 ? 0 : mom->n; /* every score 0 */
    ulam__cs_plan4(&s->cs, n, mom->mean, var, mom->m3, mom->m4, A, b, h > b ? h - b : 0.0, nplan);
}

/* Plan the sequence's next block from the run so far (plan_terms) at the round's limit. */
static void cs_plan(ulam_solver *s)
{
    const ulam__moments *mom = s->o.mode == ULAM_ADJOINT ? &s->adj : &s->watched;
    double Rt, A, b, h, nplan;
    plan_terms(s, 0, 0, &Rt, &A, &b, &h, &nplan);
    A = s->w.clip > 0 ? s->w.clip : INFINITY, b = s->clip_b;
    cs_bet(s, mom, A, b, h, nplan);
}

/* Plan the sequence's next part of the first block from the parts so far (run): as cs_plan, with
 * run's moments in place of the run's (none yet) and under rel_err the half-width aimed at from
 * run's mean. */
static void cs_plan_from(ulam_solver *s, const ulam__moments *run)
{
    double Rt, A, b, h, nplan, E = s->o.stop.rel_err;
    plan_terms(s, 0, 0, &Rt, &A, &b, &h, &nplan);
    A = s->w.clip > 0 ? s->w.clip : INFINITY, b = s->clip_b;
    if (!(h > 0) && E > 0 && run->n >= 2) h = E * fabs(run->mean + s->o.stop.rel_err_offset);
    cs_bet(s, run, A, b, h, nplan);
}

/* The forward push on b's rounding at x_i (src/fpush_b.c): each of its operations rounds once or
 * twice (q_j += r_j; r_k += M_kj r_j), at most DBL_EPSILON / 2 of what it adds, so q_i and the
 * residual the walks start from miss x = q + (I - M)^-1 r by roundings that add up over the push;
 * bounded as bidir.c's rounding_allowance, by the operations (+ 2 for the walks' mean and its sum
 * with q_i) times DBL_EPSILON / 2 of |q_i| (the pushed part's size: with M of one sign every add is
 * of q_i's sign; with cancellations it may miss).  A push to b's rounding (radiosity100,
 * --walks 10^4: ||r||_1 / ||b||_1 = 1e-14, the walks' interval ~1e-15 of x_i) printed intervals
 * 1-2 ulp from LAPACK's x_i without it (6 of 68 runs). */
static double push_rounding(const ulam_solver *s, int64_t i)
{
    return ulam__push_rounding((double)s->push.ops + 2.0, fabs(s->pq[i]));
}

/* The run's 95% interval so far: the confidence sequence's (stop.h, ulam__cs), valid at every
 * walk count, widened by the cuts' bias, and the range R the next block is planned at; zero
 * width when nothing that scores is reachable (R = 0); none while the variance is not
 * certified finite. */
static void interval(const ulam_solver *s, const ulam_walk_result *r, double *R, ulam__stop_ci *ci)
{
    double A, b, h, nplan;
    plan_terms(s, 1, 0, R, &A, &b, &h, &nplan);
    if (*R == 0.0) ulam__stop_interval(r->walks, r->estimate, 0.0, 0.0, 0.0, 0.0, 0.0, 0, ci);
    else {
        double m0 = s->o.mode == ULAM_ADJOINT ? s->adj.mean : s->watched.mean, shift = r->estimate - m0;
        ulam__cs_interval(&s->cs, m0, r->cut_bound, ci);
        ci->lo += shift, ci->hi += shift; /* forward: b_i (expected) and the push's part */
    }
    if (s->pq && (ci->kind == ULAM__STOP_EB || ci->kind == ULAM__STOP_EXACT)) { /* the push's roundings */
        double fp = push_rounding(s, s->o.query.index);
        ci->lo -= fp, ci->hi += fp, ci->half += fp;
    }
    if (s->var_finite != 1 && ci->kind != ULAM__STOP_EXACT) ci->kind = ULAM__STOP_NONE, ci->lo = ci->hi = NAN;
    if (ci->kind == ULAM__STOP_EB && r->estimate != 0.0 && s->maxsq < ULAM__STOP_TINY) /* a b not rescaled (a prepared
        file's, read lazily) far below 1: b = 1e-300 printed '+- 0' and the range term alone, 22 of 50 seeds covered */
        ci->kind = ULAM__STOP_NONE, ci->lo = ci->hi = NAN;
    if (ci->kind != ULAM__STOP_EB && ci->kind != ULAM__STOP_EXACT) ci->half = INFINITY;
}

/* The result so far; the forward count of unreached components (O(n)) when asked; walked: at the
 * scale the walks ran on (b 2^-bexp, the scale of the solver's bounds: what the rules compare),
 * else at b's. */
static void result(const ulam_solver *s, ulam_walk_result *r, int count_unreached, int walked)
{
    memset(r, 0, sizeof *r);
    if (!s) return;
    double sumsq;
    const ulam__moments *mom = s->o.mode == ULAM_ADJOINT ? &s->adj : &s->watched;
    if (s->o.mode == ULAM_ADJOINT) {
        r->estimate = s->adj.mean;
        r->variance = ulam__moments_variance(&s->adj);
        r->std_error = s->adj.n > 0 ? sqrt(r->variance / (double)s->adj.n) : INFINITY;
        sumsq = s->adj.m2 + (double)s->adj.n * s->adj.mean * s->adj.mean;
    } else {
        forward_component(s, s->o.query.index, &r->estimate, &r->std_error, &r->variance);
        sumsq = s->sumsq[s->o.query.index];
        for (int64_t i = 0; count_unreached && i < s->n; i++) r->unreached += s->sum[i] == 0.0 && s->sumsq[i] == 0.0;
    }
    r->max_share = sumsq > 0 ? fmin(1.0, s->maxsq / sumsq) : 0.0;
    r->variance_finite = s->var_finite;
    r->variance_rel_error = ulam__moments_variance_rel_error(mom);
    double m = fabs(r->estimate + s->o.stop.rel_err_offset), N = (double)s->run.walks, R;
    r->walks = s->run.walks;
    r->score_bound = s->bound;
    r->cut_bound = cut_bound(s);
    ulam__stop_ci ci;
    interval(s, r, &R, &ci);
    r->tail_bound = R == 0.0 ? 0.0 : N > 0 && m > 0 ? R / (N * m) : INFINITY;
    if (s->o.stop.rel_err > 0) { /* a sequence tuned to the target from the start, at the planned range */
        double E = s->o.stop.rel_err, A, b, h, nplan, Rp;
        plan_terms(s, 1, 1, &Rp, &A, &b, &h, &nplan);
        r->min_walks = R == 0.0 ? 0.0 : ulam__cs_walks_needed(m, r->variance, A, b + r->cut_bound, E);
        if (s->met) r->min_walks = fmin(r->min_walks, (double)r->walks); /* it held there */
        if (m == 0 && s->maxsq == 0.0 && s->hit_walks > 0 && ci.kind != ULAM__STOP_EXACT)
            r->min_walks = s->hit_walks; /* no score yet: src/hit.c (not over an x certified exactly) */
    }
    r->cut_stop = s->cut_stop;
    r->out_of_reach = s->out_of_reach;
    r->rel_err_met = s->met;
    r->ci95[0] = ci.lo, r->ci95[1] = ci.hi; /* NaN: none (stop.h says why) */
    r->steps = s->steps;
    r->cut = s->cut;
    r->rows = atomic_load(&s->k->built);
    r->seconds = s->run.seconds;
    r->threads = s->threads;
    r->interrupted = s->run.interrupted;
    r->rho4 = s->rho4;
    r->fourth_finite = s->fourth;
    r->push_sweeps = s->pq ? s->push.sweeps : 0, r->push_ops = s->pq ? s->push.ops : 0;
    r->push_residual = s->pq && s->push.r_sum0 > 0 ? s->push.r_sum / s->push.r_sum0 : 1.0;
    if (s->bexp && !walked) { /* walked on b 2^-bexp: back to b's scale (exact) */
        int e = s->bexp;
        r->estimate = ldexp(r->estimate, e), r->std_error = ldexp(r->std_error, e);
        r->ci95[0] = ldexp(r->ci95[0], e), r->ci95[1] = ldexp(r->ci95[1], e);
        r->variance = ldexp(r->variance, 2 * e);
        r->score_bound = ldexp(r->score_bound, e), r->cut_bound = ldexp(r->cut_bound, e);
    }
}

/* The result so far. */
void ulam_solver_result(const ulam_solver *s, ulam_walk_result *r)
{
    result(s, r, 1, 0);
}

/* The guards' verdicts the solver walks under. */
void ulam__solver_guard(const ulam_solver *s, ulam_guard *g)
{
    if (s && g) *g = s->g;
}

/* Forward mode: every component's estimate and standard error. */
int ulam_solver_vectors(const ulam_solver *s, double *x, double *std_error)
{
    if (!s || s->o.mode != ULAM_FORWARD) return ULAM_EINVAL;
    int bad = 0;
    for (int64_t i = 0; i < s->n; i++) {
        double e, se, v;
        forward_component(s, i, &e, &se, &v);
        e = ldexp(e, s->bexp), se = ldexp(se, s->bexp); /* walked on b 2^-bexp */
        if (x) x[i] = e;
        if (std_error) std_error[i] = se;
        if (!isfinite(e)) bad = 1;
    }
    return bad ? ULAM_ENONFINITE : ULAM_OK; /* an estimate beyond the largest double */
}

/* The walks the options name, in one call. */
int ulam_solve_walks(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                     ulam_walk_result *result, ulam_error *err)
{
    ulam_solver *s = NULL;
    ulam_walk_opts o;
    if (opts) o = ulam__lift_default_cap(opts);
    int status = ulam_solver_alloc(M, b, opts ? &o : NULL, &s, err);
    return status ? status : ulam__solver_finish(s, result, err);
}

/* Iterate s until done, report into result (may be NULL) and err, free s; the status. */
int ulam__solver_finish(ulam_solver *s, ulam_walk_result *result, ulam_error *err)
{
    int status = ULAM_OK;
    while (!status && !ulam_solver_done(s)) status = ulam_solver_iterate(s);
    if (result) ulam_solver_result(s, result);
    if (status) ulam_solver_error(s, err);
    ulam_solver_free(s);
    return status;
}

/* Why the run failed, with err filled; ULAM_OK while it has not. */
int ulam_solver_error(const ulam_solver *s, ulam_error *err)
{
    ulam__clear(err);
    if (!s || !s->run.status) return ULAM_OK;
    int status = kernel_failure(s->k, s->o.policy.system, err);
    if (status) return status;
    int st = s->run.status;
    switch (st) {
    case ULAM_ENONFINITE:
        if (s->overflow)
            return ulam__fail(err, st, 0, s->o.query.index, "an estimate a double can hold: x[%lld] (1-based) exceeds "
                              "1.8e308 (the walks' mean of scores overflows; b's scale is 2^%d)",
                              (long long)s->o.query.index + 1, s->bexp);
        return ulam__fail(err, st, 0, -1, "finite weights and scores (a walk produced NaN or Inf)");
    case ULAM_ENOMEM: return ulam__fail(err, st, 0, -1, "memory for the walks' tallies");
    case ULAM_EIO: return ulam__fail(err, st, 0, -1, "an exchange of walk results between processes (allgather failed)");
    default: return ulam__fail(err, st, 0, -1, "walks that run to their end");
    }
}

/* Reset every tally, count and stopping state (the kernel, the bounds and the workspace stay). */
static void reset(ulam_solver *s)
{
    if (s->sum) memset(s->sum, 0, (size_t)s->n * sizeof *s->sum);
    if (s->sumsq) memset(s->sumsq, 0, (size_t)s->n * sizeof *s->sumsq);
    s->adj = s->watched = (ulam__moments){0};
    s->steps = s->cut = 0;
    s->maxsq = 0.0;
    ulam__run_reset(&s->run);
    s->met = s->cut_stop = s->out_of_reach = s->epoch = s->budget_plan = 0;
    s->cs = (ulam__cs){0};
    free(s->hitv), free(s->hitt), free(s->hits); /* made for this b and estimator */
    s->hitv = NULL, s->hitt = NULL, s->hits = NULL, s->nhits = 0, s->hit_reads = 0, s->hit_sweep = s->hit_done = 0, s->hit_walks = 0.0;
}

/* Restart a forward solver on a new right-hand side b (borrowed like the first) with a new
 * seed: the kernel and workspace are kept (the kernel of a forward walk does not depend on b),
 * the source table is rebuilt and every tally, count and stopping state is reset. */
int ulam__solver_restart(ulam_solver *s, const double *b, uint64_t seed, ulam_error *err)
{
    ulam__clear(err);
    if (!s || !b || s->o.mode != ULAM_FORWARD) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a forward solver and b");
    free(s->src), free(s->pq), free(s->pr); /* a push on the first b is not this b's */
    s->src = NULL, s->pq = s->pr = NULL;
    s->b = b;
    for (int64_t i = 0; s->bexp && i < s->n; i++) s->bs[i] = ldexp(b[i], -s->bexp); /* as the first b */
    if (s->bexp) s->b = s->bs;
    s->o.exec.seed = seed;
    double bnorm1 = 0.0;
    if (build_source(s, &bnorm1)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the source table");
    free(s->seen), free(s->fac); /* the reachable set and the score bounds depend on b */
    s->seen = NULL, s->reached = NULL, s->fac = NULL;
    s->passed = s->tail_done = 0;
    memset(s->v2_done, 0, sizeof s->v2_done);
    {
        int status = check_reach(s, s->mt, err); /* the score bounds depend on b */
        if (!status) status = take_fourth(s, s->mt, err); /* and so may whether they are bounded */
        if (status) return status;
    }
    s->w.src = s->src;
    s->w.bnorm1 = bnorm1;
    reset(s);
    return ULAM_OK;
}

/* A forward rerun whose budget plans another push than the one made (the method choice's pilots
 * plan for their few walks): b as it was, then the push for this budget, as a solver allocated
 * with these options makes it. */
static int repush(ulam_solver *s, int rel_alone, ulam_error *err)
{
    double V = mean_steps(s), bnorm1 = 0.0;
    if (s->push_plan < 0 || push_plan(s, V + ULAM_AUTO_WALK + ULAM_AUTO_TALLY * (V + 1.0)) == s->push_plan) return ULAM_OK;
    int status = ULAM_OK;
    if (s->pq) { /* undo the push: b, its source table and its bounds */
        free(s->pq), free(s->pr), free(s->src), free(s->seen), free(s->fac);
        s->pq = s->pr = NULL, s->src = NULL, s->seen = NULL, s->reached = NULL, s->fac = NULL;
        s->b = s->b0;
        s->passed = s->tail_done = 0;
        memset(s->v2_done, 0, sizeof s->v2_done);
        if (build_source(s, &bnorm1)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the source table");
        if ((status = take_bounds(s, s->mt, rel_alone, err))) return status;
    } else {
        for (int64_t i = 0; i < s->n; i++) bnorm1 += fabs(s->b[i]);
    }
    if ((status = push_b(s, rel_alone, &bnorm1, err))) return status;
    s->w.src = s->src, s->w.bnorm1 = bnorm1;
    return ULAM_OK;
}

/* Walk again with options o that differ from the solver's only in the estimator, the seed, the
 * stopping rules, interrupt, share, force, assume_finite and rel_err_offset. */
int ulam__solver_rerun(ulam_solver *s, const ulam_walk_opts *opts, ulam_error *err)
{
    ulam__clear(err);
    if (!s || !opts) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a solver and options");
    ulam_walk_opts o = *opts;
    double q0 = s->o.kernel.continue_q > 0 ? s->o.kernel.continue_q : 0.0, q1 = o.kernel.continue_q > 0 ? o.kernel.continue_q : 0.0;
    if (o.mode != s->o.mode || o.query.index != s->o.query.index || q0 != q1 || o.kernel.roulette != s->o.kernel.roulette ||
        o.kernel.split != s->o.kernel.split || o.stop.max_steps != s->o.stop.max_steps || o.kernel.kernel_alpha != s->o.kernel.kernel_alpha ||
        ulam__threads(o.exec.threads) != s->threads || o.query.nstarts || s->o.query.nstarts)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the solver's mode, index, continuation, kernel exponent, weight "
                                                   "window, max_steps and threads (and one start state)");
    int status = check_opts(s->M, &o, err);
    if (status) return status;
    if (atomic_load(&s->k->status)) return kernel_failure(s->k, s->o.policy.system, err);
    int rescore = o.estimator != s->o.estimator;
    if (rescore && s->k_borrowed) /* a kept kernel is its keeper's, for its estimator */
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a solver that owns its kernel to change the estimator");
    s->o = o;
    if ((status = check_verdicts(s->M, s, err))) return status;
    s->walks_given = o.stop.max_walks > 0;
    s->o.stop.max_walks = ulam__walk_cap(&o);
    if (rescore && (status = ulam__kernel_rescore(s->k, o.estimator))) return kernel_failure(s->k, s->o.policy.system, err);
    if (rescore && o.mode == ULAM_ADJOINT) { /* the start row current (rescoring may leave rows to the walks) */
        s->w.start = ulam__kernel_unit(s->k, o.query.index, &s->ks[0]);
        if (atomic_load(&s->k->status)) return kernel_failure(s->k, s->o.policy.system, err);
    }
    s->w.interrupt = o.stop.interrupt;
    s->w.score0 = o.mode == ULAM_ADJOINT && o.estimator == ULAM_EXPECTED ? s->b[o.query.index] : 0.0;
    s->w.expected = o.mode == ULAM_FORWARD && o.estimator == ULAM_EXPECTED;
    int rel_alone = o.stop.rel_err > 0 && o.stop.max_walks == 0 && o.stop.max_seconds == 0;
    if ((status = take_bounds(s, o.mode == ULAM_FORWARD ? s->mt : s->M, rel_alone, err))) return status;
    if (o.mode == ULAM_FORWARD && (status = repush(s, rel_alone, err))) return status;
    reset(s);
    return ULAM_OK;
}

/* The deterministic work a solver has done on set-up: kernel units built, and entries read by
 * reachability checks and score-bound passes. */
void ulam__solver_setup(const ulam_solver *s, int64_t *units, int64_t *reads)
{
    *units = atomic_load(&s->k->top);
    *reads = s->setup_work;
}

/* The start's signed tail (tail_len): the bound on |sum over k > l of (K^k b)_index|, NAN past it
 * or without one; *part the visits the sequence takes of each history in the round planned last
 * (0: whole scores). */
double ulam__solver_part_bias(const ulam_solver *s, int64_t l, int64_t *part)
{
    *part = s->w.part_steps;
    return part_route(s) && l >= 0 && l < s->tailT_n ? s->tailS[l] : NAN;
}
