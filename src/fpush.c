/* Single source, every target: x = (I - M)^-1 e_s by a forward push and forward walks on what
 * it leaves (FORA: Wang, Yang, Xiao, Wei, Wei, Liu, "FORA: simple and effective approximate
 * single-source personalized PageRank", KDD 2017).
 *
 * The reverse push of src/push.c on M' from s is M's forward push from s: it leaves
 * x = p + (I - M)^-1 r (the push's invariant for M', read by columns), with every |r_j| <= rmax.
 * The forward walk solver on M with right-hand side r estimates every component of
 * (I - M)^-1 r at once, with a standard error each.  r is fixed before any walk, so p + the
 * walks' estimate is unbiased component by component.
 *
 * Walks: a fixed count, or FORA's count for relative error E on every component of at least
 * delta with failure probability 1/n, W = ||r||_1 (2E/3 + 2) ln(2n) / (E^2 delta).  Balance:
 * rmax halves from 1 while the push's operations are below W V step_cost (V the visits a walk
 * makes, 1 / (1 - ||M||_1) from the guards' one-pass bound).  Intervals: p_i + the walks' normal
 * interval where the walks saw two values at i; where they did not (one score or none: the
 * sample says nothing about what it missed), the certified bound of the walk part,
 * |(I - M)^-1 r|_i <= ||r||_1 / (1 - ||M||_1); every interval clipped to p_i -+ that bound.
 *
 * For ||M||_1 < 1 the sweep push (src/sweep.c) and terminal walks: each walk scores 0 or R0 at
 * every component, so where M, r >= 0 a component's interval is src/stop.c's KL (Chernoff-
 * Hoeffding) interval of its hit count, stitched over the checkpoints the rule may stop at; with
 * signs, each component's own plug-in empirical-Bernstein confidence sequence (cs_set).  A component no walk reached gets p_i + [0, about 3.7 R0 /
 * N] against the empirical-Bernstein 9.6 R0 / N, so the same accuracy takes ~2.6x fewer walks.
 * ulam_fpush_top's k components are chosen by their estimates: their lower ends at delta k / n
 * (ulam__stop_lower_index). */
#include "fpush.h"
#include "fpush_dense.h"
#include "cache.h"
#include "defaults.h"
#include "check.h"
#include "push.h"
#include "stop.h"
#include "sweep.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ULAM__FPUSH_STEP_COST 150.0 /* push operations one terminal-walk step costs (R-MAT 2^20, a 2-core VM at load 5-7,
                                      2026-12-02, thread CPU: 0.4-0.6 us a step with ULAM__FPUSH_LANES walks in flight,
                                      ~4 ns a pull-sweep operation; 300 before the lanes, 1.8 us a step; side by side over
                                      3 sources, solve CPU 1.03-1.05 s at 150 (one 1.47 outlier), 1.18-1.19 s at 50, 100
                                      and 300 within noise of 150) */
#define ULAM__FPUSH_RANGE_SHARE 0.8 /* the share of E delta the first checkpoint leaves the interval's range term */
#define ULAM__FPUSH_BLOCK 64        /* states per block of the start's running sums */
#define ULAM__FPUSH_KL_KEPT 1024    /* hit counts whose interval a checkpoint keeps (the rest computed each time) */
#define ULAM__FPUSH_CUT_SHARE 0.01  /* the largest negative residual cut from r, times 1 / (1 - alpha), as a share of E delta */
#define ULAM__FPUSH_CS_SPLITS 3     /* a fixed count of walks with signed scores is walked in blocks ending at 1/8, 1/4,
                                      1/2 of it and at it: each block's bets set from the blocks before (one block
                                      would bet as if the variance were the largest) */
#define ULAM__FPUSH_LOCAL_SHARE 16 /* the top-K target's queue push gives way to the sweeps once its operations pass
                                      nnz / this (a sixteenth of a sweep: a queue push's operation reads at random) */
#define ULAM__FPUSH_TIME_PUSH 0.25 /* the share of the time left after the set-up that the top-K target's queue push may take (the walks the rest) */
#define ULAM__FPUSH_TIME_NEXT 4.0   /* a halving of rmax costs up to this many times the round before (R-MAT 2^24, source
                                       101: 3.1e5 -> 1.4e6 operations in one halving) */
#define ULAM__FPUSH_TIME_OPS 16     /* with a deadline the queue push stays local to nnz / ULAM__FPUSH_LOCAL_SHARE times this */
#define ULAM__FPUSH_NEG_PASSES 32     /* passes of push_negative at most (its operations: a sweep's at most) */
#define ULAM__FPUSH_LANES 16        /* walks in flight at once (walk_many) */
#define ULAM__FPUSH_HIT_FIRST 4096  /* walks' ends a block's hit table first has room for; walk_many doubles it as
                                       walks end at new states (a block planned for 10^7 walks on R-MAT 2^24 set a
                                       2^25-slot table, 128 MiB, before its first walk: half of a --time 3 run's
                                       walking second went to that memset) */
#define ULAM__FPUSH_TRIM_EVERY 256  /* rows a queue push checks between trims of a large file's mapping
                                      (ulam__system_trim: a read of /proc/self/statm) */
#define ULAM__FPUSH_TRIM_WALKS 256  /* walks launched between trims: of a released file the walks map only M^T's row
                                      pointers (8 (n + 1) bytes; every entry is read by pread), so a trim is a guard;
                                      (R-MAT 2^24, source 101: with hubs' entries read in place through the mapping,
                                      trims every 8 walks took the walks from 0.77 s to 55 s, each refaulting the hubs
                                      in 2 MiB spans) */
#define ULAM__FPUSH_STORE_ROW 64    /* a large file's rows of at most this many entries are read by pread into the walks'
                                      store on the first visit; longer ones (hubs) an entry at a time by pread as a
                                      walk draws it, until a visit count pays for reading the row whole
                                      (ULAM__FPUSH_STORE_VISITS) while the long rows stored take at most
                                      ULAM__FPUSH_STORE_HUBS bytes */
#define ULAM__FPUSH_STORE_HUBS ((int64_t)512 << 20)
#define ULAM__FPUSH_STORE_VISITS(d) (2 + (d) / 4096) /* visits of a long row of d entries before it is stored:
                                      a pread of one entry ~5-10 us on this VM, of a row ~12 d bytes at a few GB/s */
#define ULAM__FPUSH_SKEW 16.0       /* rows drawn from by rejection up to this many tries on average, beyond by the
                                      running sums (R-MAT 2^20, source 990665, 2026-12-02, load 2.2-2.7, median of 5:
                                      walk loop 121 ms at 2 (2.6e6 running sums built for 117 562 steps), 84 at 4,
                                      56 at 8, 47 at 16 (2.4e5 sums), 44 with no running sums at all; with the tries
                                      overlapped across lanes 36-45 ms at 16, 35-38 at 64; a row's sums cost its whole
                                      degree to build and first touch, a try one read in the row) */

/* The defaults. */
ulam_fpush_opts ulam__fpush_defaults(void)
{
    ulam_fpush_opts o = {.rel_err = 0.1, .walk = ulam_walk_defaults()};
    o.walk.mode = ULAM_FORWARD;
    return o;
}

/* Check the options. */
static int check(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *o, ulam_error *err)
{
    int64_t n = M->nrows;
    if (M->ncols != n) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    if (!Mt || Mt->nrows != n || Mt->ncols != n || ulam_csr_nnz(Mt) != ulam_csr_nnz(M))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "Mt, the transpose of M (%lld x %lld)", (long long)n, (long long)n);
    if (o->source < 0 || o->source >= n)
        return ulam__fail(err, ULAM_EINVAL, 0, o->source, "a source from 0 to %lld", (long long)n - 1);
    if (!(o->rel_err > 0 && o->rel_err < 1) || o->walks < 0 || !isfinite(o->rmax) || !isfinite(o->min_value) ||
        !isfinite(o->step_cost))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "rel_err in (0, 1), walks >= 0, a finite rmax, min_value and "
                                                   "step_cost");
    return ulam__walk_opts_check(&o->walk, err); /* src/check.c */
}

/* FORA's walk count for the residual mass rsum (or the fixed count). */
static double walk_count(const ulam_fpush_opts *o, double rsum, int64_t n)
{
    if (o->walks > 0) return (double)o->walks;
    double E = o->rel_err, delta = o->min_value > 0 ? o->min_value : 1.0 / (double)n;
    return ceil(rsum * (2.0 * E / 3.0 + 2.0) * log(2.0 * (double)n) / (E * E * delta));
}

/* The queue push and the walk solver on its residual, for ||M||_1 >= 1 (no terminal walks). */
static int solve_queue(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, ulam_guard g, double *x,
                       double *std_error, double *lo, double *hi, ulam_fpush_info *info, ulam_error *err)
{
    int status = ULAM_OK;
    ulam_fpush_opts o = *opts;
    int64_t n = M->nrows;
    double t0 = ulam_now();
    double c = g.abs.colsum_max; /* ||M||_1 */
    double D1 = c < 1.0 ? 1.0 / (1.0 - c) : INFINITY; /* ||(I - M)^-1||_1 */
    info->mean_visits = isfinite(D1) ? D1 : 1.0 / fmax(1e-3, 1.0 - fmin(g.abs.upper, 0.999));
    double cost = o.step_cost > 0 && isfinite(o.step_cost) ? o.step_cost : ULAM_BIDIR_STEP_COST;
    ulam_push *w = NULL;
    if ((status = ulam__push_alloc(Mt, &w))) return ulam__fail(err, status, 0, -1, "memory for the push");
    ulam__push_start(w, o.source);
    double rmax = o.rmax > 0 ? o.rmax : 1.0, W;
    int64_t cap = 100 * ulam_csr_nnz(M) + 1000000;
    status = ulam__push_run(w, rmax, cap);
    for (;;) {
        ulam__push_report(w, &info->push);
        W = info->push.support ? walk_count(&o, info->push.r_sum, n) : 0.0;
        if (o.rmax > 0 || status || info->push.support == 0 || (double)info->push.ops >= W * info->mean_visits * cost)
            break;
        rmax /= 2;
        status = ulam__push_run(w, rmax, cap);
    }
    info->rmax = rmax;
    info->push_seconds = info->push.seconds;
    if (status) {
        ulam__push_free(w);
        return ulam__fail(err, status, 0, -1, "a push within %lld operations (is rho(|M|) < 1?)", (long long)cap);
    }
    const double *p = ulam__push_estimates(w), *r = ulam__push_residuals(w);
    double *xw = ulam__calloc((size_t)n, sizeof *xw), *se = ulam__calloc((size_t)n, sizeof *se), ws[2] = {NAN, NAN};
    if (!xw || !se) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walks' estimates");
    info->residual_bound = info->push.r_sum * D1;
    if (!status && info->push.support > 0) {
        ulam_walk_opts wo = o.walk;
        wo.mode = ULAM_FORWARD, wo.query.index = o.source, wo.stop.rel_err = 0, wo.policy.guard = &g;
        wo.stop.max_walks = (int64_t)fmin(fmax(W, 1.0), 4e18);
        ulam_solver *sv = NULL;
        status = ulam_solver_alloc(M, r, &wo, &sv, err);
        while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
        if (status && sv) ulam_solver_error(sv, err);
        if (!status) {
            ulam_walk_result wr;
            ulam_solver_result(sv, &wr);
            ulam_solver_vectors(sv, xw, se);
            ws[0] = wr.ci95[0], ws[1] = wr.ci95[1]; /* the watched x_S's: the confidence sequence's */
            info->walks = wr.walks, info->steps = wr.steps, info->walk_seconds = wr.seconds;
            info->interrupted = wr.interrupted;
        }
        ulam_solver_free(sv);
    }
    if (!status) {
        /* the certified intervals: the push's exact part plus the walks' part, at most D = ||r||_1
           ||(I - M)^-1||_1 (finite here only when the push left nothing to walk); the watched x_S
           also the walk solver's confidence sequence on its certified range.  Other components get
           none: the walks' -+ 1.96 stderr is the CLT's, not certified (a preferential-attachment
           graph's top 200 at 100 walks: 72.8% covered) */
        double D = info->push.support > 0 ? info->residual_bound : 0.0; /* nothing left: exact */
        for (int64_t i = 0; i < n; i++) {
            x[i] = p[i] + xw[i];
            if (std_error) std_error[i] = se[i];
            double a = p[i] - D, b = p[i] + D;
            if (i == o.source && info->push.support > 0) a = fmax(a, p[i] + ws[0]), b = fmin(b, p[i] + ws[1]);
            if (!isfinite(a) || !isfinite(b)) a = b = NAN; /* nothing certifies one */
            if (lo) lo[i] = a;
            if (hi) hi[i] = b;
        }
    }
    free(xw), free(se);
    ulam__push_free(w);
    info->seconds = ulam_now() - t0;
    return status;
}

/* The walks' plan: residual mass, kernel norm alpha = ||M||_1 < 1, target and costs. */
typedef struct {
    double alpha, E, delta, visits, step_cost;
    double llo;    /* the lower ends' extra log: ln(n / K) for ulam_fpush_top's K of n (ulam__stop_lower_index), else 0 */
    int64_t fixed; /* > 0: this many walks */
    const double *p; /* the top-K target (walk_work_top): the push's estimates, n, K, the residual at the last */
    int64_t n, K;    /* raise of the floor, and the buffer raise_floor gathers in */
    double last, *buf;
    int64_t cap;
} plan;

/* The checkpoints: the walks stop at the ends of src/stop.c's epochs from the first, k0, whose
 * end leaves room for relative error E at x = delta (the interval's range term at most
 * ULAM__FPUSH_RANGE_SHARE E delta at stitching index 1; the variance term, small where the push
 * left little of x_i to the walks, is checked at each checkpoint).  k0 depends on the residual alone, known before any walk, so the
 * checkpoints k0, k0 + 1, ... are fixed in advance and stitched among themselves: the one at
 * epoch k0 + j - 1 takes stitching index j, delta_j = delta / (j (j + 1)). */
static int64_t epoch_end(int k)
{
    int64_t m = (int64_t)floor(ULAM__STOP_N0 * pow(2.0, (k - 1) / 2.0));
    while (ulam__stop_epoch(m + 1) == k) m++;
    while (m > 2 && ulam__stop_epoch(m) > k) m--;
    return m;
}

/* The upper end of the interval of a component no walk ended at, N walks, R0 a hit's score,
 * stitching index k (src/stop.c's KL interval; 0: a count fixed in advance). */
static double none_hi(int64_t N, int k, double R0)
{
    double lo, hi;
    ulam__stop_kl_interval(N, 0.0, k, &lo, &hi);
    return R0 * hi;
}

/* k0 for walk scores of range R (kl: scores 0 or R, the KL interval; else, signed scores in
 * [-R / 2, R / 2], the plug-in sequence's range term at its largest bet). */
static int first_epoch(double R, double E, double delta, int kl)
{
    double L = ulam__stop_log(1), room = ULAM__FPUSH_RANGE_SHARE * E * delta;
    int k = 1;
    (void)L;
    while (k < 200 && !(kl ? none_hi(epoch_end(k), 1, R) <= room : ulam__cs_range_width(R / 2.0, (double)epoch_end(k)) <= room))
        k++;
    return k;
}

/* The walks' work (push operations) a residual of mass r_sum leaves (ulam__sweep_cost): the
 * walk count whose interval for a component no walk ended at is ULAM__FPUSH_RANGE_SHARE E delta
 * wide at stitching index 1 (the KL interval of scores 0 or R0: M >= 0 makes r >= 0), or, when
 * more, whose KL interval is within -+ E delta at a component x_i = delta whose walk part is the
 * residual's share r_sum of it (half-width sqrt(2 c w R0 / N) at w = r_sum delta, c with ln(n / K)
 * more for the lower ends of a top-K query: ulam__stop_lower_index; R-MAT 2^22, source 101, r_sum 0.122:
 * 54 000 walks predicted, 46 340 walked, against 15 800 without it; the range term
 * alone took R-MAT 2^22's --min-value 0.001 to 5.9e6 walks after a push left r_sum ~ 0.3), at
 * least one block (a fixed count: that count in proportion to r_sum, the accuracy it buys). */
static double walk_work(double r_sum, void *ctx)
{
    const plan *pl = ctx;
    double R = r_sum / (1.0 - pl->alpha), c = log(2.0 / ULAM__STOP_DELTA) + log(2.0); /* N (1 - e^(-c/N)) ~ c */
    double range = c * R / (ULAM__FPUSH_RANGE_SHARE * pl->E * pl->delta) + 1.0;
    double var = 2.0 * (c + pl->llo) * R * fmin(1.0, r_sum) / (pl->E * pl->E * pl->delta); /* the variance term */
    double N = pl->fixed > 0 ? (double)pl->fixed * r_sum : fmax(ULAM__STOP_N0, fmax(range, var));
    return N * pl->visits * pl->step_cost;
}

/* The running sums of |r| at the start of each block of ULAM__FPUSH_BLOCK states (nb + 1 of them,
 * the last ||r||_1 as summed here). */
static void block_sums(const double *r, int64_t n, double *bsum)
{
    double acc = 0.0;
    int64_t b = 0;
    for (int64_t j = 0; j < n; j++) {
        if (j % ULAM__FPUSH_BLOCK == 0) bsum[b++] = acc;
        acc += fabs(r[j]);
    }
    bsum[b] = acc;
}

/* The walk state: the start's block sums, per-row sums met so far, terminal counts. */
typedef struct {
    const ulam_csr *Mt;
    const double *r;
    const double *bsum; /* block_sums of r */
    int64_t nb, n;
    int64_t k;
    double alpha;
    double *cs, *mx, *cum;
    int64_t cum_used; /* entries of cum taken */
    uint64_t *known; /* a bit a state: row_sums done */
    int pre; /* cs and mx filled by the sweep push */
    int32_t *hit;       /* the states some walk ended at, in the order first ended at (nhit of them) */
    int32_t *hc;        /* their counts: hc[2q], hc[2q + 1] walks that ended at hit[q] with score +R0, -R0 */
    int32_t *slot;      /* open addressing (linear probing) from a state to its q; -1: empty */
    int64_t nhit, hmax; /* hit and hc hold hmax states; slot has 2 hmax or more (a power of 2) */
    int64_t hcap, steps;
    const ulam_system *sys; /* a lazily read file whose stored M^T is Mt: each row's block verified on the first visit */
    int status;             /* ULAM_ESYNTAX once a block failed (bad: a row of it), ULAM_EIO on a failed read,
                               ULAM_ENOMEM; the walks then stop */
    int64_t bad;
    const ulam_system *store_of; /* a released mapping (ulam__system_releases): rows read by pread, never through
                                    the mapping: short ones on the first visit into the store (scol, sval from
                                    soff[j]), long ones an entry a step until stored (store_row), so the walks'
                                    resident set is the rows they keep, not every page near them; NULL: rows read
                                    in place */
    int32_t *scol;
    double *sval;
    int64_t *soff, sused, shub; /* shub: the entries of long rows stored */
} walker;

/* Row j of M' (column j of M) as a walk reads it, on its first visit: read into w's store
 * (w->store_of), the sum and largest of its |entries| (read here unless w->pre: the sweep push
 * left them), its bit in known set, and when drawing an entry by rejection would take more than
 * ULAM__FPUSH_SKEW tries on average, the running sums of |entries| for a binary search, appended
 * to cum at cum_used (so cum's pages are touched only as far as rows need it; a first touch is
 * dear), mx_j then -1 - their offset in cum instead of the largest entry (negative: sums built).
 * known is a bit a state (n / 8 bytes: its pages are few).  ULAM_OK, ULAM_EIO (a failed read) or
 * ULAM_ENOMEM. */
static int row_sums(walker *w, int64_t j)
{
    const ulam_csr *Mt = w->Mt;
    int64_t a = Mt->rowptr[j], d = Mt->rowptr[j + 1] - a;
    const double *val = Mt->val + a;
    double *cs = w->cs, *mx = w->mx, *tmp = NULL;
    if (w->store_of && d > ULAM__FPUSH_STORE_ROW) {
        w->soff[j] = -1; /* its entries read by pread as walks draw them (lane_entry; -1 - soff[j] its visits,
                            store_row), its values here only when its sums need them: never through the mapping */
        if (!w->pre || mx[j] * (double)d > ULAM__FPUSH_SKEW * cs[j]) {
            if (!(tmp = malloc((size_t)d * sizeof *tmp))) return ULAM_ENOMEM;
            if (ulam__system_tr_read(w->store_of, j, 0, d, NULL, tmp)) {
                free(tmp);
                return ULAM_EIO;
            }
        }
        val = tmp;
    } else if (w->store_of) {
        if (ulam__system_tr_read(w->store_of, j, 0, d, w->scol + w->sused, w->sval + w->sused)) return ULAM_EIO;
        val = w->sval + w->sused, w->soff[j] = w->sused, w->sused += d;
    }
    if (!w->pre) {
        double s = 0.0, m = 0.0;
        for (int64_t e = 0; e < d; e++) {
            double v = fabs(val[e]);
            s += v, m = v > m ? v : m;
        }
        cs[j] = s, mx[j] = m;
    }
    w->known[j >> 6] |= (uint64_t)1 << (j & 63);
    if (mx[j] * (double)d > ULAM__FPUSH_SKEW * cs[j]) {
        double c = 0.0, *cu = w->cum + w->cum_used;
        for (int64_t e = 0; e < d; e++) c += fabs(val[e]), cu[e] = c;
        mx[j] = -1.0 - (double)w->cum_used, w->cum_used += d;
    }
    free(tmp);
    return ULAM_OK;
}

/* A visit to long row j (d entries) of a released file not stored (w->soff[j] < 0) counted; at
 * ULAM__FPUSH_STORE_VISITS(d) visits, room left, the row read whole into the store.  0, or -1 on a
 * failed read. */
static int store_row(walker *w, int64_t j, int64_t d)
{
    if (--w->soff[j] > -1 - ULAM__FPUSH_STORE_VISITS(d) || (w->shub + d) * 12 > ULAM__FPUSH_STORE_HUBS) return 0;
    if (ulam__system_tr_read(w->store_of, j, 0, d, w->scol + w->sused, w->sval + w->sused)) return -1;
    w->soff[j] = w->sused, w->sused += d, w->shub += d;
    return 0;
}

/* The slot of state j in w's table: where its q is, or the empty slot where it goes. */
static int64_t hit_slot(const walker *w, int64_t j)
{
    int64_t m = w->hcap - 1, t = (int64_t)(((uint64_t)j * 0x9E3779B97F4A7C15u) >> 20) & m;
    while (w->slot[t] >= 0 && w->hit[w->slot[t]] != j) t = (t + 1) & m;
    return t;
}

/* Room in w's hit list and table for more walks' ends (each adds at most one state, at most n
 * in all): the hit counts take memory in proportion to the states walks ended at, not to n
 * (a dense count of n states, 4 MiB on R-MAT 2^20, took ~12 ms to zero in 4 KiB pages for
 * ~15 000 states ended at); ULAM_OK or ULAM_ENOMEM (w as it was). */
static int hit_room(walker *w, int64_t more)
{
    int64_t need = w->nhit + more < w->n ? w->nhit + more : w->n, cap = w->hcap ? w->hcap : 64;
    if (need <= w->hmax) return ULAM_OK;
    int64_t hm = w->hmax;
    if (ulam__grow(&w->hit, &hm, need, sizeof *w->hit)) return ULAM_ENOMEM;
    hm = w->hmax;
    if (ulam__grow(&w->hc, &hm, need, 2 * sizeof *w->hc)) return ULAM_ENOMEM; /* the same doublings: hit's room */
    while (cap < 2 * need) cap *= 2;
    if (cap > w->hcap) {
        int32_t *t = ulam__malloc((size_t)cap, sizeof *t);
        if (!t) return ULAM_ENOMEM;
        memset(t, 0xff, (size_t)cap * sizeof *t); /* -1: empty */
        free(w->slot);
        w->slot = t, w->hcap = cap;
        for (int64_t q = 0; q < w->nhit; q++) w->slot[hit_slot(w, w->hit[q])] = (int32_t)q;
    }
    w->hmax = hm;
    return ULAM_OK;
}

/* The q of state j in w's hit list, -1 when no walk ended at it. */
static int64_t hit_index(const walker *w, int64_t j)
{
    return w->hcap ? w->slot[hit_slot(w, j)] : -1;
}

/* The KL intervals (src/stop.c) of hit counts below ULAM__FPUSH_KL_KEPT at one checkpoint. */
typedef struct {
    int64_t N;
    int k;
    double lo[ULAM__FPUSH_KL_KEPT], hi[ULAM__FPUSH_KL_KEPT];
    unsigned char have[ULAM__FPUSH_KL_KEPT];
} kl_kept;

/* The interval R0 [lo, hi] for ((I - M)^-1 r)_i from h of N walks ending at i (scores 0 or R0),
 * at stitching index k (0: a count fixed in advance). */
static void hits_interval(kl_kept *c, int64_t N, int k, int64_t h, double R0, double *lo, double *hi)
{
    if (c->N != N || c->k != k) memset(c->have, 0, sizeof c->have), c->N = N, c->k = k;
    double a, b;
    if (h < ULAM__FPUSH_KL_KEPT && c->have[h]) {
        a = c->lo[h], b = c->hi[h];
    } else {
        ulam__stop_kl_interval(N, (double)h / (double)N, k, &a, &b);
        if (h < ULAM__FPUSH_KL_KEPT) c->lo[h] = a, c->hi[h] = b, c->have[h] = 1;
    }
    *lo = R0 * a, *hi = R0 * b;
}

/* Whether an interval [a, b] around est meets relative error E at delta: b < delta (x_i >= delta
 * only if the interval misses it), or est within E max(a, delta) of both ends (so within E x_i of
 * any x_i >= delta inside it). */
static int interval_met(double a, double b, double est, double E, double delta)
{
    return b < delta || fmax(est - a, b - est) <= E * fmax(a, delta);
}

/* rule_met for scores 0 or R0 (M, r >= 0): the KL intervals, every lower end lowered by cut
 * (the bound on the part of x_i the negative residual cut from r takes away) and taken at index
 * klo from cl (ulam__stop_lower_index; cl NULL: c's). */
static int rule_met_kl(const walker *w, kl_kept *c, kl_kept *cl, const double *p, int64_t N, int k, int klo, double R0,
                       double E, double delta, double cut)
{
    double lo, hi, h2;
    hits_interval(c, N, k, 0, R0, &lo, &hi);
    if (!(hi <= E * delta && cut <= E * delta)) return 0; /* a component no walk ended at, p_i just under delta */
    for (int64_t q = 0; q < w->nhit; q++) {
        int64_t i = w->hit[q];
        hits_interval(c, N, k, w->hc[2 * q], R0, &lo, &hi);
        if (cl) hits_interval(cl, N, klo, w->hc[2 * q], R0, &lo, &h2);
        if (!interval_met(p[i] + lo - cut, p[i] + hi, p[i] + R0 * (double)w->hc[2 * q] / (double)N, E, delta)) return 0;
    }
    return 1;
}

/* Terminal walks: from j drawn with probability |r_j| / ||r||_1, stop and score at the state it
 * is at with probability 1 - alpha, else move along column j of M with probability |M_kj| (die,
 * scoring 0, with the rest, alpha - sum_k |M_kj|); the score's sign is r_j's times the signs of
 * the entries it crossed.  The chance to end at i is (1 - alpha) ((I - M)^-1 |r|)_i / ||r||_1
 * (for M, r >= 0; signed: the expectation), so score R0 = ||r||_1 / (1 - alpha) at the end
 * estimates ((I - M)^-1 r)_i for every i at once, every score within [-R0, R0]. */

/* A walk's first state. */
static int64_t walk_start(const walker *w, ulam_rng *rng)
{
    int64_t j = -1;
    while (j < 0) { /* the block by bisection of the running sums, the state by a scan of the block */
        double u = ulam__rng_uniform(rng) * w->bsum[w->nb], acc;
        int64_t l = 0, h = w->nb - 1;
        while (l < h) {
            int64_t m = l + (h - l + 1) / 2;
            if (w->bsum[m] <= u) l = m;
            else h = m - 1;
        }
        acc = w->bsum[l];
        for (int64_t i = l * ULAM__FPUSH_BLOCK, e = i + ULAM__FPUSH_BLOCK < w->n ? i + ULAM__FPUSH_BLOCK : w->n; i < e; i++)
            if (u < (acc += fabs(w->r[i]))) {
                j = i;
                break;
            }
    } /* none: u rounded onto ||r||_1, drawn again */
    return j;
}

/* A walk in flight: at state j (neg: its score's sign is negative), the uniform u that decides
 * its next move drawn on arrival; phase 0: j's row sums prefetched; 1: the entry e of row j
 * (at a) it moves along prefetched, taken if f mx_j <= |M_ej| (rejection; f = 0: taken). */
typedef struct {
    int64_t j, d, e;     /* at j, row j's d entries at col and val (in Mt or w's store) */
    const int32_t *col;
    const double *val;
    double u, f;
    int neg, phase, on;
    int pr;     /* row j a released file's long row (w->soff[j] < 0): entry e read by pread into ce, ve */
    int32_t ce;
    double ve;
} lane;

/* Entry e of the row lane L is on made ready for lane_move: prefetched, or (L->pr) read by pread;
 * 0, or -1 on a failed read. */
static int lane_entry(const walker *w, lane *L)
{
    if (L->pr) return ulam__system_tr_read(w->store_of, L->j, L->e, 1, &L->ce, &L->ve);
    __builtin_prefetch(&L->val[L->e]), __builtin_prefetch(&L->col[L->e]);
    return 0;
}

/* Arrive at state j: draw the move's uniform, prefetch what the next phase reads. */
static void lane_arrive(const walker *w, ulam_rng *rng, lane *L, int64_t j)
{
    L->j = j, L->u = ulam__rng_uniform(rng), L->phase = 0;
    __builtin_prefetch(&w->Mt->rowptr[j]), __builtin_prefetch(&w->known[j >> 6]), __builtin_prefetch(&w->cs[j]);
    __builtin_prefetch(&w->mx[j]);
}

/* Phase 0: stop and score (the walk ends), die, or choose the entry of row j to move along
 * (binary search of the running sums, or the first candidate of the rejection draw) and
 * prefetch it; 0 when the walk ended. */
static int lane_choose(walker *w, lane *L)
{
    const ulam_csr *Mt = w->Mt;
    int64_t j = L->j;
    double stop = 1.0 - w->alpha, v = L->u - stop;
    if (L->u < stop) {
        int64_t t = hit_slot(w, j), q = w->slot[t];
        if (q < 0) q = w->slot[t] = (int32_t)w->nhit, w->hit[w->nhit++] = (int32_t)j, w->hc[2 * q] = w->hc[2 * q + 1] = 0;
        w->hc[2 * q + L->neg]++;
        return 0;
    }
    if (!(w->known[j >> 6] >> (j & 63) & 1) && w->sys && ulam__system_tr_verify(w->sys, j, j + 1, NULL)) {
        w->status = ULAM_ESYNTAX, w->bad = j; /* a damaged block: the walk ends unscored, the run fails */
        return 0;
    }
    int rs = !(w->known[j >> 6] >> (j & 63) & 1) ? row_sums(w, j) : ULAM_OK; /* on the first visit */
    if (rs) {
        w->status = rs, w->bad = j; /* an unreadable file or no memory: the walk ends unscored, the run fails */
        return 0;
    }
    if (!(v < w->cs[j])) return 0; /* the walk dies */
    int64_t a = Mt->rowptr[j], d = Mt->rowptr[j + 1] - a, e;
    if (w->store_of && w->soff[j] < 0 && store_row(w, j, d)) {
        w->status = ULAM_EIO, w->bad = j;
        return 0;
    }
    L->col = Mt->colidx + a, L->val = Mt->val + a, L->d = d;
    L->pr = w->store_of && w->soff[j] < 0;
    if (w->store_of && w->soff[j] >= 0) L->col = w->scol + w->soff[j], L->val = w->sval + w->soff[j];
    if (w->mx[j] < 0) { /* the first entry whose running sum exceeds v */
        const double *cu = w->cum + (int64_t)(-1.0 - w->mx[j]);
        int64_t l = 0, h = d - 1;
        while (l < h) {
            int64_t mid = l + (h - l) / 2;
            if (cu[mid] > v) h = mid;
            else l = mid + 1;
        }
        e = l, L->f = 0.0;
    } else { /* the first candidate of the rejection draw, and its coin from the same uniform */
        double t = v / w->cs[j] * (double)d;
        e = (int64_t)t;
        if (e >= d) e = d - 1;
        L->f = t - (double)e;
    }
    L->e = e, L->phase = 1;
    if (lane_entry(w, L)) {
        w->status = ULAM_EIO, w->bad = j;
        return 0;
    }
    return 1;
}

/* Phase 1: accept the entry and move along it, or (rejection: entry e with probability
 * |M_ej| / sum) draw the next candidate and its coin, prefetch it and stay in phase 1, so a
 * walk's tries overlap the other lanes' reads as its steps do.  0 when the walk ended (a failed
 * read: w->status). */
static int lane_move(walker *w, ulam_rng *rng, lane *L)
{
    int64_t j = L->j, e = L->e;
    double v = L->pr ? L->ve : L->val[e];
    if (L->f * w->mx[j] > fabs(v)) {
        uint64_t frac;
        L->e = (int64_t)ulam__rng_index(rng, (uint64_t)L->d, &frac);
        L->f = (double)frac * 0x1.0p-64;
        if (lane_entry(w, L)) {
            w->status = ULAM_EIO, w->bad = j;
            return 0;
        }
        return 1;
    }
    L->neg ^= v < 0;
    w->steps++;
    lane_arrive(w, rng, L, L->pr ? L->ce : L->col[e]);
    return 1;
}

/* count walks, ULAM__FPUSH_LANES of them in flight (round robin, one phase each, what a lane
 * reads next prefetched while the others go on: their memory reads overlap, where one walk's
 * are a chain).  Every walk launched is walked to its end, and walks launch in order, so the
 * first count walks are taken whatever their lengths.  The walks made: count, or fewer when
 * *interrupt is set (checked every 1024 launches) or the clock passes until (ulam_now(), every 16: a
 * walk whose rows are read cold can take milliseconds). */
static int64_t walk_many(walker *w, ulam_rng *rng, int64_t count, const volatile int *interrupt, double until)
{
    lane L[ULAM__FPUSH_LANES] = {{0}};
    int64_t launched = 0;
    int more = count > 0;
    for (;;) {
        int busy = 0;
        for (int l = 0; l < ULAM__FPUSH_LANES; l++) {
            if (L[l].on) {
                if (L[l].phase == 0) L[l].on = lane_choose(w, &L[l]);
                else L[l].on = lane_move(w, rng, &L[l]);
            }
            if (!L[l].on && more && w->nhit + ULAM__FPUSH_LANES >= w->hmax && w->hmax < w->n &&
                hit_room(w, w->hmax + ULAM__FPUSH_LANES)) { /* room for every walk in flight to end somewhere new */
                w->status = ULAM_ENOMEM, w->bad = -1, more = 0;
            }
            if (!L[l].on && more) {
                int64_t j = walk_start(w, rng);
                L[l].on = 1, L[l].neg = w->r[j] < 0, launched++;
                lane_arrive(w, rng, &L[l], j);
                more = launched < count && !((launched & 1023) == 0 && interrupt && *interrupt) && !w->status &&
                       !((launched & 15) == 0 && ulam_now() > until);
                if (w->store_of && launched % ULAM__FPUSH_TRIM_WALKS == 0) ulam__system_trim(w->store_of);
            }
            busy |= L[l].on;
        }
        if (!busy) return launched;
    }
}

/* Signed scores (M or r with negative entries): each component's walk scores, R0 times the sign of
 * a walk that ended at it (0 for one that did not), are independent across walks, identically
 * distributed and in [-R0, R0], so each gets src/stop.c's predictable plug-in empirical-Bernstein
 * sequence (Waudby-Smith and Ramdas 2023), fed a block of walks (a checkpoint's) at a time and
 * valid at every walk count at once: no stitching over checkpoints.  Its bet for a block is set
 * from the blocks before it (a target half-width E max(|x_i|, delta), or for a fixed count, the
 * count), so predictable.  Every component no walk has ended at has the same past, all zeros,
 * hence the same sequence (none); a component first ended at in a block starts from none's state
 * before that block (none's bet was its bet).  The lower ends take ln(2 n / (delta K)) (the
 * false-coverage rate of ulam_fpush_top's K of n, as ulam__stop_lower_index), the upper ln(2 / delta). */
typedef struct {
    ulam__cs *q;   /* per state ended at, in w's hit order */
    int32_t *prev; /* w's counts at the block's start, 2 a state */
    int64_t nq, qmax, pmax;
    ulam__cs none; /* a state no walk has ended at */
    double llo, lhi;
} cs_set;

/* The walks' mean and sample variance at the q-th state ended at, N walks, hit scores -+R0. */
static void cs_moments(const walker *w, int64_t q, int64_t N, double R0, double *mean, double *var)
{
    double Nd = (double)N, h = (double)(w->hc[2 * q] + w->hc[2 * q + 1]);
    *mean = N > 0 ? R0 * (double)(w->hc[2 * q] - w->hc[2 * q + 1]) / Nd : 0.0;
    *var = N > 1 ? fmax(0.0, (R0 * R0 * h - Nd * *mean * *mean) / (Nd - 1.0)) : 0.0;
}

/* Plan every sequence's next block after N walks (p: the push's estimates; nplan > 0: a fixed
 * count, else target E at delta). */
static void cs_plan_all(cs_set *S, const walker *w, const double *p, int64_t N, double R0, double E, double delta,
                        double nplan)
{
    for (int64_t q = 0; q < S->nq; q++) {
        double mean, var;
        cs_moments(w, q, N, R0, &mean, &var);
        ulam__cs_plan(&S->q[q], N, mean, var, R0, 0.0, nplan > 0 ? 0.0 : E * fmax(fabs(p[w->hit[q]] + mean), delta), nplan);
    }
    ulam__cs_plan(&S->none, N, 0.0, 0.0, R0, 0.0, nplan > 0 ? 0.0 : E * delta, nplan);
}

/* Add the block of `made` walks just walked to every sequence; ULAM_OK or ULAM_ENOMEM. */
static int cs_add_all(cs_set *S, const walker *w, int64_t made, double R0)
{
    if (ulam__grow(&S->q, &S->qmax, w->nhit, sizeof *S->q) || ulam__grow(&S->prev, &S->pmax, w->nhit, 2 * sizeof *S->prev))
        return ULAM_ENOMEM;
    for (int64_t q = S->nq; q < w->nhit; q++) S->q[q] = S->none, S->prev[2 * q] = S->prev[2 * q + 1] = 0;
    S->nq = w->nhit;
    double Nb = (double)made;
    for (int64_t q = 0; q < S->nq && made > 0; q++) {
        int64_t hp = w->hc[2 * q] - S->prev[2 * q], hm = w->hc[2 * q + 1] - S->prev[2 * q + 1];
        double mean = R0 * (double)(hp - hm) / Nb, m2 = fmax(0.0, R0 * R0 * (double)(hp + hm) - Nb * mean * mean);
        ulam__cs_add(&S->q[q], made, mean, m2, hp + hm > 0 ? R0 : 0.0);
        S->prev[2 * q] = w->hc[2 * q], S->prev[2 * q + 1] = w->hc[2 * q + 1];
    }
    ulam__cs_add(&S->none, made, 0.0, 0.0, 0.0);
    return ULAM_OK;
}

/* Whether N walks meet relative error E at every component whose interval reaches delta: its
 * sequence's 95% interval within -+ E max(|x_i|, delta) (p: the push's estimates). */
static int cs_rule_met(const cs_set *S, const walker *w, const double *p, int64_t N, double R0, double E, double delta)
{
    ulam__stop_ci ci;
    ulam__cs_interval_sides(&S->none, 0.0, 0.0, S->llo, S->lhi, &ci);
    if (!(ci.kind == ULAM__STOP_EB && ci.half <= E * delta)) return 0; /* a component no walk ended at */
    for (int64_t q = 0; q < w->nhit; q++) {
        int64_t i = w->hit[q];
        double mean, var;
        cs_moments(w, q, N, R0, &mean, &var);
        ulam__cs_interval_sides(&S->q[q], mean, 0.0, S->llo, S->lhi, &ci);
        if (ci.lo + p[i] > delta || ci.hi + p[i] >= delta)
            if (!(ci.kind == ULAM__STOP_EB && ci.half <= E * fmax(fabs(p[i] + mean), delta))) return 0;
    }
    return 1;
}

/* The allowance for the push's rounding, relative to |p_i|: each of its rounds or sweeps recomputes
 * or pushes into p_i through at most a row of M (d entries, each a rounding), and an error in p
 * carries through (I - M)^-1 at most 1 / (1 - alpha) times: (rounds + 1) (d + 2) u / (1 - alpha),
 * d the longest row (4e-11 on R-MAT 2^20; far below any interval the walks give, but a push that
 * leaves no residual no longer prints a zero-width interval for a p_i that is only rounded).  A
 * queue push (swi->chain: its operations) adds nonnegative terms where M >= 0, each addition a
 * factor within 1 -+ u, and no value goes through more additions than the push made: (chain + 2) u
 * / (1 - alpha). */
static double rounding_allowance(const ulam_csr *M, const ulam__sweep_info *swi, double alpha,
                                 const ulam__sweep_release *rel)
{
    if (swi->chain > 0) return ((double)swi->chain + 2.0) * (DBL_EPSILON / 2.0) / (1.0 - alpha);
    int64_t d = 0;
    for (int64_t i = 0; i < M->nrows; i++) {
        d = M->rowptr[i + 1] - M->rowptr[i] > d ? M->rowptr[i + 1] - M->rowptr[i] : d;
        ulam__sweep_done(rel, M, i, M->nrows);
    }
    return ((double)swi->rounds + 1.0) * ((double)d + 2.0) * (DBL_EPSILON / 2.0) / (1.0 - alpha);
}

/* What the walks' ends give each component: the walks (N, stitching index k, KL index kk when
 * not k), scores' range R and largest R0, sgn (signed scores: empirical Bernstein), the cut,
 * residual_bound D, the interval of a component no walk ended at and its standard error se0, the
 * allowance fp for the push's rounding (relative to |p_i|), and nonneg (M >= 0: x >= 0, every
 * lower end at least 0). */
typedef struct {
    const walker *w;
    kl_kept *kept, *kept_lo; /* kept_lo: the lower ends' KL intervals at klo (NULL: klo is kk or k) */
    const cs_set *cs;        /* signed scores: the plug-in sequences */
    int64_t N;
    int k, kk, klo, sgn, nonneg;
    double R, R0, cut, D, se0, fp;
    ulam__stop_ci none;
} ends;

/* Finish the interval [*l, *h] of a component with p_i = p and estimate est: none from the walks
 * (NaN) becomes p -+ D, it is clipped to p -+ D where D is finite, widened by fp |p| either side,
 * and when x >= 0 its lower end is at least min(est, 0) (so est stays inside); NaN kept where D
 * is not finite.  No branch on the component but the selects. */
static inline void finish(const ends *c, double p, double est, double *l, double *h)
{
    double D = c->D, f = c->fp * fabs(p), floor = c->nonneg ? 0.0 : -INFINITY, a = *l, b = *h;
    if (isfinite(D)) { /* both ends NaN or neither, so no fmax/fmin NaN rule is needed */
        if (isnan(a)) a = p - D, b = p + D; /* no interval from the walks */
        a = a > p - D ? a : p - D;
        b = b < p + D ? b : p + D;
    }
    a -= f, b += f;
    *l = !(a < floor) ? a : est < floor ? est : floor, *h = b;
}

/* The outputs of n components no walk ended at, x_i = p_i (x holds p; p_i + 0, never -0, as p
 * starts at +0): standard error c->se0, interval [p_i + a - cut, p_i + b] finished (finish). */
static void none_fill(const ends *c, const double *x, double *std_error, double *lo, double *hi, int64_t n)
{
    double a = c->none.lo - c->cut, b = c->none.hi;
    if (std_error)
        for (int64_t i = 0; i < n; i++) std_error[i] = c->se0;
    if (!lo && !hi) return;
    for (int64_t i = 0; i < n; i++) {
        double p = x[i], l = p + a, h = p + b;
        finish(c, p, p, &l, &h);
        if (lo) lo[i] = l;
        if (hi) hi[i] = h;
    }
}

/* The walks' mean at the q-th state ended at. */
static double ends_mean(const ends *c, int64_t q)
{
    const walker *w = c->w;
    return c->R0 * (double)(w->hc[2 * q] - w->hc[2 * q + 1]) / (double)c->N;
}

/* The outputs of a component with p_i = p and the q-th state ended at (q < 0: none ended at
 * it): the walks' mean (returned), standard error *se and interval [*a, *b]. */
static double ends_component(const ends *c, double p, int64_t q, double *se, double *a, double *b)
{
    const walker *w = c->w;
    int64_t N = c->N, h = q >= 0 && N > 0 ? w->hc[2 * q] + w->hc[2 * q + 1] : 0;
    double Nd = (double)N, R0 = c->R0, mean = 0.0, var = 0.0;
    if (h == 0) { /* the common interval, as none_fill gives it */
        none_fill(c, &p, se, a, b, 1);
        return 0.0;
    }
    ulam__stop_ci ci = c->none;
    mean = ends_mean(c, q);
    var = N > 1 ? fmax(0.0, (R0 * R0 * (double)h - Nd * mean * mean) / (Nd - 1.0)) : 0.0;
    if (!c->sgn) {
        hits_interval(c->kept, N, c->kk < 0 ? c->k : c->kk, h, R0, &ci.lo, &ci.hi);
        double up;
        if (c->kept_lo) hits_interval(c->kept_lo, N, c->klo, h, R0, &ci.lo, &up);
    } else {
        ulam__cs_interval_sides(&c->cs->q[q], mean, 0.0, c->cs->llo, c->cs->lhi, &ci);
    }
    *a = p + ci.lo - c->cut, *b = p + ci.hi;
    *se = N > 1 ? sqrt(var / Nd) : c->se0;
    finish(c, p, p + mean, a, b);
    return mean;
}

/* Whether estimate u at i ranks before v at j: larger first, ties by smaller index, NaN last. */
static int ranks_before(double u, int64_t i, double v, int64_t j)
{
    if (isnan(u) || isnan(v)) return isnan(u) == isnan(v) ? i < j : !isnan(u);
    return u > v || (u == v && i < j);
}

/* Whether slot a of the heap (idx, key) ranks before slot b (ranks_before; idx NULL: by key
 * alone, ties equal). */
static int slot_before(const int64_t *idx, const double *key, int64_t a, int64_t b)
{
    return ranks_before(key[a], idx ? idx[a] : 0, key[b], idx ? idx[b] : 0);
}

/* Restore the heap order below slot t of the k-entry heap (idx, key; idx may be NULL): each
 * entry ranks after neither child, so the root ranks last. */
static void sift_down(int64_t *idx, double *key, int64_t k, int64_t t)
{
    for (;;) {
        int64_t c = 2 * t + 1;
        if (c >= k) return;
        if (c + 1 < k && slot_before(idx, key, c, c + 1)) c++; /* the child ranking last */
        if (!slot_before(idx, key, t, c)) return;
        double tk = key[t];
        key[t] = key[c], key[c] = tk;
        if (idx) {
            int64_t ti = idx[t];
            idx[t] = idx[c], idx[c] = ti;
        }
        t = c;
    }
}

/* The k (1 <= k <= n) components of largest x_i as a heap in (index, key), its root the k-th
 * by rank (ranks_before); index NULL: the values alone, and key may be x itself (the heap then
 * in x[0 .. k), x reordered).  One pass over n: O(n + changes log k). */
static void heap_top(const double *x, int64_t n, int64_t k, int64_t *index, double *key)
{
    for (int64_t i = 0; i < n; i++) {
        double u = x[i];
        if (i < k) {
            key[i] = u;
            if (index) index[i] = i;
            if (i == k - 1)
                for (int64_t t = k / 2; t-- > 0;) sift_down(index, key, k, t);
        } else if (ranks_before(u, index ? i : 0, key[0], index ? index[0] : 0)) {
            key[0] = u;
            if (index) index[0] = i;
            sift_down(index, key, k, 0);
        }
    }
}

/* The k (<= n) components of largest x_i into index, by rank (ranks_before); key: k entries of
 * scratch.  The heap of the k best (heap_top), then sorted: O(n + changes log k + k log k). */
static void select_top(const double *x, int64_t n, int64_t k, int64_t *index, double *key)
{
    if (k <= 0) return;
    heap_top(x, n, k, index, key);
    for (int64_t m = k - 1; m > 0; m--) { /* the last-ranked to the end, each in turn */
        int64_t ti = index[0];
        double tk = key[0];
        index[0] = index[m], key[0] = key[m], index[m] = ti, key[m] = tk;
        sift_down(index, key, m, 0);
    }
}

/* The K-th largest (1 <= K <= m) of v[0 .. m), v reordered: the root of the K best's heap
 * (heap_top, in place). */
static double kth_largest(double *v, int64_t m, int64_t K)
{
    heap_top(v, m, K, NULL, v);
    return v[0];
}

/* The K-th largest of p_i + max(r_i, 0) over the n states (r NULL: p_i alone) when above delta,
 * else delta: the values above delta gathered into *buf (*cap entries, grown), so a floor near
 * the top takes a few entries, not n. */
static double raise_floor(const double *p, const double *r, int64_t n, int64_t K, double delta, double **buf, int64_t *cap)
{
    int64_t m = 0;
    for (int64_t i = 0; i < n; i++) {
        double v = p[i] + (r && r[i] > 0 ? r[i] : 0.0);
        if (!(v > delta)) continue;
        if (m == *cap && ulam__grow(buf, cap, m + 1, sizeof **buf)) return delta; /* no memory: the floor stays */
        (*buf)[m++] = v;
    }
    return m >= K ? kth_largest(*buf, m, K) : delta;
}

/* The sweep push's cost model for the top-K target (walk_work at a floor raised as the push
 * goes): each time the residual has halved, delta is raised to the K-th largest p_i (pl->p; a
 * plan, not a bound: over-relaxed sweeps may overshoot x_i; solve_sweep certifies the floor the
 * walks take). */
static double walk_work_top(double r_sum, void *ctx)
{
    plan *pl = ctx;
    if (r_sum <= 0.5 * pl->last) pl->last = r_sum, pl->delta = raise_floor(pl->p, NULL, pl->n, pl->K, pl->delta, &pl->buf, &pl->cap);
    return walk_work(r_sum, ctx);
}

/* A lazily read file as the queue push checks its rows: the rows checked so far. */
typedef struct {
    const ulam_system *sys;
    int64_t calls;
} tr_checker;

/* The check of row j of a lazily read file's stored M^T before a push reads it (ulam__push_set_verify);
 * every ULAM__FPUSH_TRIM_EVERY rows, the file's mapping trimmed (ulam__system_trim). */
static int tr_row_ok(const void *ctx, int64_t j, int64_t *bad)
{
    tr_checker *c = (tr_checker *)(uintptr_t)ctx; /* push_top's own, not const */
    ulam_error e;
    int status = ulam__system_tr_verify(c->sys, j, j + 1, &e);
    if (status) *bad = e.index;
    if (++c->calls % ULAM__FPUSH_TRIM_EVERY == 0) ulam__system_trim(c->sys);
    return status;
}

/* The top-K target's push (FORA's top-k, Wang et al. 2017): the queue push from s (src/push.c),
 * which reads only the rows it pushes, with rmax halving from 1; after each run the floor delta
 * is the K-th largest p_i (floor when given > 0 instead: the caller's min_value; at least 1 / n)
 * -- where M >= 0, x_i >= p_i, so the K-th largest x_i is at least the K-th largest p_i, and the
 * relative target at delta covers every one of the K largest x_i -- and the halving stops once
 * the push's operations reach the walks' predicted work at that delta (walk_work), or that work is
 * the walks' least (ULAM__STOP_N0 walks: a smaller residual saves none; a source whose mass stays
 * in a small part of the graph stops here, not in sweeps of all of it).  x and r
 * (zero on entry) get p and the residual, swi the counts and delta; *local 0 instead (x and r
 * untouched, pl->delta the floor so far) once the push's operations pass nnz /
 * ULAM__FPUSH_LOCAL_SHARE: the residual has spread, and whole sweeps do better than a queue.
 * With a deadline (until finite: max_seconds) it stays local (a sweep cannot stop between rows)
 * and halves no further once the next round, ULAM__FPUSH_TIME_NEXT times the last, would pass
 * until, or its operations pass ULAM__FPUSH_TIME_OPS times that share. */
static int push_top(const ulam_csr *Mt, const ulam_system *sys, int64_t s, int64_t K, double floor, plan *pl, int64_t cap,
                    double until, double *x, double *r, ulam__sweep_info *swi, int *local, ulam_error *err)
{
    int64_t m = 0, vmax = 0;
    ulam_push *w = NULL;
    double *v = NULL, rmax = 1.0;
    ulam_push_info pi = {0};
    int status = ulam__push_alloc_trusted(Mt, &w);
    tr_checker chk = {.sys = sys};
    *local = 1;
    if (!status && sys) ulam__push_set_verify(w, tr_row_ok, &chk);
    if (!status) status = ulam__push_start(w, s);
    const int32_t *t = NULL;
    while (!status) {
        double tr = ulam_now();
        if ((status = ulam__push_run(w, rmax, cap))) {
            if (status == ULAM_ESYNTAX && sys) ulam__system_tr_verify(sys, ulam__push_bad_row(w), ulam__push_bad_row(w) + 1, err);
            break;
        }
        t = ulam__push_touched(w, &m);
        ulam__push_report(w, &pi);
        int late = isfinite(until) && ulam_now() + ULAM__FPUSH_TIME_NEXT * (ulam_now() - tr) > until; /* the next round */
        if (pi.ops >= ulam_csr_nnz(Mt) / ULAM__FPUSH_LOCAL_SHARE && !isfinite(until)) {
            *local = 0;
            break;
        }
        const double *p = ulam__push_estimates(w), *rr = ulam__push_residuals(w);
        if (floor > 0) {
            pl->delta = floor;
        } else if (ulam__grow(&v, &vmax, m, sizeof *v)) {
            status = ULAM_ENOMEM;
            break;
        } else {
            for (int64_t q = 0; q < m; q++) v[q] = p[t[q]] + rr[t[q]];
            pl->delta = fmax(pl->delta, m >= K ? kth_largest(v, m, K) : 0.0);
        }
        double ww = walk_work(pi.r_sum, pl);
        if (pi.support == 0 || (double)pi.ops >= ww || ww <= walk_work(0.0, pl)) break; /* the walks at their least */
        if (late || pi.ops >= ulam_csr_nnz(Mt) / ULAM__FPUSH_LOCAL_SHARE * ULAM__FPUSH_TIME_OPS) break; /* the time's */
        rmax /= 2;
    }
    if (!status && *local) {
        const double *p = ulam__push_estimates(w), *rr = ulam__push_residuals(w);
        for (int64_t q = 0; q < m; q++) x[t[q]] = p[t[q]], r[t[q]] = rr[t[q]], swi->r_neg += rr[t[q]] < 0 ? -rr[t[q]] : 0.0;
        swi->rounds = 1, swi->pushes = pi.pushes, swi->ops = pi.ops, swi->support = pi.support, swi->r_sum = pi.r_sum;
        swi->chain = pi.ops, swi->delta = pl->delta;
    }
    free(v);
    ulam__push_free(w);
    return status;
}

/* The whole passes' hook on a lazily read file (ulam__sweep_release): rows [r0, r1) of A given back. */
static void release_rows(const void *ctx, const ulam_csr *A, int64_t r0, int64_t r1)
{
    ulam__system_release(ctx, A, r0, r1);
}

/* The list rounds' hook on a lazily read file (ulam__sweep_release): its mapping trimmed. */
static void trim_file(const void *ctx)
{
    ulam__system_trim(ctx);
}

/* Push the negative residual the over-relaxed sweeps left (M >= 0): every r_j < 0 moves into p_j
 * and along row j of M' (r_k += M'_jk r_j), a pass at a time, while its mass times d1 = 1 / (1 - alpha)
 * is above want and the passes' operations stay within max_ops.  x = p + (I - M)^-1 r stays exact,
 * ||r||_1 does not grow, and the negative mass shrinks by alpha a pass at least (more where it lands
 * on a positive residual).  swi's r_neg, r_sum, support, pushes, ops and rounds (one a pass: the
 * rounding allowance) are kept up to date. */
static void push_negative(const ulam_csr *Mt, double *p, double *r, double d1, double want, int64_t max_ops,
                          const ulam__sweep_release *rel, ulam__sweep_info *swi)
{
    int64_t n = Mt->nrows, ops = 0;
    for (int pass = 0; pass < ULAM__FPUSH_NEG_PASSES && swi->r_neg * d1 > want && ops < max_ops; pass++) {
        for (int64_t j = 0; j < n; j++) {
            double rj = r[j];
            ulam__sweep_done(rel, Mt, j, n);
            if (!(rj < 0)) continue;
            p[j] += rj, r[j] = 0.0;
            for (int64_t e = Mt->rowptr[j]; e < Mt->rowptr[j + 1]; e++) r[Mt->colidx[e]] += Mt->val[e] * rj;
            ops += Mt->rowptr[j + 1] - Mt->rowptr[j] + 1, swi->pushes++;
        }
        double neg = 0.0, sum = 0.0;
        int64_t support = 0;
        for (int64_t j = 0; j < n; j++) neg += r[j] < 0 ? -r[j] : 0.0, sum += fabs(r[j]), support += r[j] != 0.0;
        swi->r_neg = neg, swi->r_sum = sum, swi->support = support, swi->rounds++;
    }
    swi->ops += ops;
}

/* The queue push's deadline: ULAM__FPUSH_TIME_PUSH of the time left before the walks' deadline
 * until, counted from now (after the set-up, which under load can take a quarter of --time: the
 * push then stopped before its first operation and the walks carried the whole residual). */
static double push_until(double until)
{
    double now = ulam_now();
    return isfinite(until) ? now + ULAM__FPUSH_TIME_PUSH * fmax(0.0, until - now) : INFINITY;
}

/* Sweep push and terminal walks on its residual, for ||M||_1 < 1; top >= 0: std_error, lo and
 * hi only for the top components of largest estimate, listed in index (select_top). */
static int solve_sweep(const ulam_csr *M, const ulam_csr *Mt, const ulam_system *lz, const ulam_fpush_opts *o,
                       const ulam_guard *g, double *x, int64_t top, int64_t *index, double *std_error, double *lo, double *hi, ulam_fpush_info *info,
                       ulam__sweep_info *swi, ulam_error *err)
{
    int64_t n = M->nrows;
    double t0 = ulam_now(), alpha = g->abs.colsum_max, D1 = 1.0 / (1.0 - alpha);
    plan pl = {.alpha = alpha, .E = o->rel_err, .delta = o->min_value > 0 ? o->min_value : 1.0 / (double)n,
               .visits = D1, .step_cost = o->step_cost > 0 ? o->step_cost : ULAM__FPUSH_STEP_COST, .fixed = o->walks,
               .llo = top > 0 && top < n ? log((double)n / (double)top) : 0.0};
    info->mean_visits = D1;
    memset(x, 0, (size_t)n * sizeof *x);
    size_t bytes = (size_t)n * sizeof(double); /* r, and cs and mx (filled whole by the pull sweeps' set-up) */
    double *r = ulam__alloc_big((size_t)n, sizeof *r); /* 2 MiB aligned: a malloc block's unaligned head stays in 4 KiB pages */
    if (r) memset(r, 0, bytes);
    walker w = {.Mt = Mt, .r = r, .alpha = alpha, .sys = lz};
    w.cs = ulam__alloc_big((size_t)n, sizeof *w.cs), w.mx = ulam__alloc_big((size_t)n, sizeof *w.mx);
    if (!r || !w.cs || !w.mx) {
        free(r), free(w.cs), free(w.mx);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the residual");
    }
    int64_t cap = 100 * ulam_csr_nnz(M) + 1000000;
    int status = ULAM_OK, local = 0;
    ulam__sweep_release rel = {.fn = release_rows, .trim = trim_file, .ctx = lz}; /* a large file's pages given back as passes go */
    const ulam__sweep_release *relp = ulam__system_releases(lz) ? &rel : NULL;
    double T = o->walk.stop.max_seconds, until = T > 0 ? t0 + T : INFINITY; /* the walks' deadline */
    if (top > 0 && top < n && !(o->rmax > 0) && o->walks <= 0) /* the top-K target: a local push, the floor planned */
        status = push_top(Mt, lz, o->source, top, o->min_value, &pl, cap, push_until(until), x, r, swi, &local, err);
    if (status == ULAM_ESYNTAX) { /* a damaged block of the file, named in err */
        free(r), free(w.cs), free(w.mx);
        return status;
    }
    if (!status && !local && lz) status = ulam_system_check(lz, err); /* the sweeps read all of M and M^T */
    if (status == ULAM_ESYNTAX) {
        free(r), free(w.cs), free(w.mx);
        return status;
    }
    int topk = top > 0 && top < n && !(o->min_value > 0) && o->walks <= 0; /* the floor planned from the push */
    pl.p = x, pl.n = n, pl.K = top, pl.last = 1.0;
    if (!status && !local)
        status = ulam__sweep_push_pull(M, Mt, o->source, o->rmax, o->rmax > 0 ? NULL : topk ? walk_work_top : walk_work, &pl,
                                       cap, x, r, w.cs, w.mx, relp, swi);
    free(pl.buf), pl.buf = NULL, pl.cap = 0;
    if (status == ULAM_ENOCONV) status = ULAM_OK; /* ||M||_1 < 1: the cap only ends the push; the walks take the rest */
    if (status) {
        free(r), free(w.cs), free(w.mx);
        return ulam__fail(err, status, 0, -1, "a push within %lld operations", (long long)cap);
    }
    int sgn = 0; /* the sweep push read M whole when it pulled: M >= 0 */
    if (lz && local) { /* the file's values by pread: none of them mapped */
        int v = ulam__system_nonneg(lz);
        if (v < 0) {
            free(r), free(w.cs), free(w.mx);
            return ulam__fail(err, ULAM_EIO, 0, -1, "a readable prepared file");
        }
        sgn = !v;
    }
    for (int64_t e = 0; e < ulam_csr_nnz(Mt) && !sgn && !swi->nonneg && !(lz && local); e++) sgn = Mt->val[e] < 0;
    int mpos = !sgn; /* M >= 0, so x >= 0 */
    if (!status && topk && mpos && !local && swi->r_neg > 0) /* what the floor and the cut below would lose to it */
        push_negative(Mt, x, r, D1, 0.5 * ULAM__FPUSH_CUT_SHARE * pl.E * pl.delta, ulam_csr_nnz(Mt), relp, swi);
    if (!status && topk) { /* the walks' floor, certified: M >= 0 gives x_i >= p_i + r_i+ - r_neg / (1 - alpha) (the
                              over-relaxed sweeps' negative residual: R-MAT 2^20, source 101, 2.2e-4, floor 3.3e-4
                              where the plan's was 1.8e-3) */
        double f = 1.0 / (double)n;
        if (mpos) f = fmax(f, raise_floor(x, r, n, top, swi->r_neg * D1, &pl.buf, &pl.cap) - swi->r_neg * D1);
        pl.delta = f;
        free(pl.buf), pl.buf = NULL, pl.cap = 0;
    }
    /* a negative residual small beside the target (roundings; what over-relaxed sweeps left, R-MAT) is
     * cut from r: x_i = p_i + ((I - M)^-1 r+)_i - [0, cut], lower ends lowered by cut; a larger one is
     * walked with its signs */
    double cut = 0.0;
    if (swi->r_neg > 0 && swi->r_neg * D1 <= ULAM__FPUSH_CUT_SHARE * pl.E * pl.delta) {
        swi->support = 0;
        for (int64_t j = 0; j < n; j++) r[j] = r[j] < 0 ? 0.0 : r[j], swi->support += r[j] != 0.0;
        cut = swi->r_neg * D1, swi->r_sum -= swi->r_neg;
    }
    info->push = (ulam_push_info){.target = o->source, .pushes = swi->pushes, .ops = swi->ops,
                                  .touched = n, .r_sum = swi->r_sum, .support = swi->support};
    for (int64_t j = 0; j < n; j++) info->push.r_max = fmax(info->push.r_max, fabs(r[j]));
    info->push.rmax = info->rmax = o->rmax > 0 ? o->rmax : info->push.r_max;
    info->push_seconds = info->push.seconds = ulam_now() - t0;
    double R0 = swi->r_sum / (1.0 - alpha), t1 = ulam_now();
    info->residual_bound = swi->r_sum * D1 + cut;
    w.k = swi->support, w.pre = swi->nonneg;
    double *bsum = NULL;
    for (int64_t j = 0; j < n && !sgn; j++) sgn = r[j] < 0;
    double R = sgn ? 2.0 * R0 : R0; /* the scores' range */
    int64_t N = 0;
    int k = 1, kk = -1; /* kk: the KL interval's index when not k */
    int64_t K = top > 0 && top < n ? top : n; /* the components whose intervals are given (ulam__stop_lower_index) */
    cs_set S = {.llo = log(2.0 / ULAM__STOP_DELTA) + log((double)n / (double)K), .lhi = log(2.0 / ULAM__STOP_DELTA)};
    kl_kept *kept = sgn ? NULL : ulam__malloc(1, sizeof *kept), *kept_lo = sgn || K >= n ? NULL : ulam__malloc(1, sizeof *kept_lo);
    if (kept) kept->N = -1;
    if (kept_lo) kept_lo->N = -1;
    if (w.k > 0) {
        w.n = n, w.nb = (n + ULAM__FPUSH_BLOCK - 1) / ULAM__FPUSH_BLOCK;
        bsum = ulam__malloc((size_t)w.nb + 1, sizeof *bsum);
        w.cum = ulam__alloc_big((size_t)ulam_csr_nnz(Mt) + 1, sizeof *w.cum); /* filled from its start: 2 MiB pages from it */
        w.known = ulam__calloc(((size_t)n + 63) / 64, sizeof *w.known);
        if (relp) { /* rows by pread into a store, filled from its start as rows are first visited */
            w.store_of = lz;
            w.scol = ulam__alloc_big((size_t)ulam_csr_nnz(Mt) + 1, sizeof *w.scol);
            w.sval = ulam__alloc_big((size_t)ulam_csr_nnz(Mt) + 1, sizeof *w.sval);
            w.soff = ulam__alloc_big((size_t)n, sizeof *w.soff);
        }
        if (!bsum || !w.cum || !w.known || (sgn ? 0 : !kept || (K < n && !kept_lo)) ||
            (relp && (!w.scol || !w.sval || !w.soff)))
            status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walks");
    }
    if (!status && w.k > 0) {
        block_sums(r, n, bsum);
        w.bsum = bsum;
        ulam_rng rng;
        ulam_rng_seed(&rng, o->walk.exec.seed, 0);
        int64_t cap_w = o->walk.stop.max_walks > 0 ? o->walk.stop.max_walks : INT32_MAX;
        if (cap_w > INT32_MAX) cap_w = INT32_MAX;
        int k0 = first_epoch(R, pl.E, pl.delta, !sgn), planned = 1, seg = sgn && o->walks > 0 ? ULAM__FPUSH_CS_SPLITS : 0;
        for (;;) { /* checkpoint k (stitching index) at the end of epoch k0 + k - 1 */
            int64_t target = o->walks > 0 ? o->walks >> seg : epoch_end(k0 + k - 1);
            if (target > cap_w) target = cap_w, planned = o->walks > 0 && o->walks == cap_w;
            if (N < target && hit_room(&w, target - N < ULAM__FPUSH_HIT_FIRST ? target - N : ULAM__FPUSH_HIT_FIRST)) {
                status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walks' ends");
                break;
            }
            if (sgn) cs_plan_all(&S, &w, x, N, R0, pl.E, pl.delta, o->walks > 0 ? (double)o->walks : 0.0);
            int64_t made = N < target ? walk_many(&w, &rng, target - N, o->walk.stop.interrupt, until) : 0;
            if (w.status == ULAM_ENOMEM && w.bad < 0) {
                status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walks' ends");
                break;
            }
            if (w.status == ULAM_ENOMEM) {
                status = ulam__fail(err, ULAM_ENOMEM, 0, w.bad, "memory for row %lld of M^T's values", (long long)w.bad + 1);
                break;
            }
            if (w.status == ULAM_EIO) {
                status = ulam__fail(err, ULAM_EIO, 0, w.bad, "a readable prepared file (row %lld of its M^T)",
                                    (long long)w.bad + 1);
                break;
            }
            if (w.status) {
                status = ulam__system_tr_verify(lz, w.bad, w.bad + 1, err);
                break;
            }
            if (made < target - N) info->interrupted = w.status || (o->walk.stop.interrupt && *o->walk.stop.interrupt) ? 1 : 2,
                                   planned = 0; /* 2: the deadline */
            N += made;
            if (sgn && cs_add_all(&S, &w, made, R0)) {
                status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walks' sequences");
                break;
            }
            if (o->walks > 0 && seg > 0 && planned && N < cap_w) { /* the fixed count's next block */
                seg--;
                continue;
            }
            if (!planned || o->walks > 0 || N >= cap_w) break;
            if (sgn ? cs_rule_met(&S, &w, x, N, R0, pl.E, pl.delta)
                    : rule_met_kl(&w, kept, kept_lo, x, N, k, ulam__stop_lower_index(k, K, n), R0, pl.E, pl.delta, cut))
                break;
            k++;
        }
        ulam__system_trim(w.store_of); /* the walks done: what they mapped given back */
        if (!planned) /* stopped between checkpoints: the next index */
            k = ulam__stop_epoch(N) > k0 ? ulam__stop_epoch(N) - k0 + 2 : k + 1;
        else if (o->walks > 0)
            kk = 0; /* a count fixed in advance: the KL interval at delta itself */
    }
    double *key = !status && top > 0 ? ulam__malloc((size_t)top, sizeof *key) : NULL, *pv = NULL;
    if (!status && top > 0 && !key) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the top components");
    if (!status) {
        int klo = ulam__stop_lower_index(sgn || kk < 0 ? k : kk, K, n);
        ends c = {.w = &w, .cs = &S, .kept = kept, .kept_lo = kept_lo, .N = N, .k = k, .kk = kk, .klo = klo, .sgn = sgn, .nonneg = mpos,
                  .R = R, .R0 = R0, .cut = cut, .D = info->residual_bound, .se0 = N > 1 ? 0.0 : (w.k > 0 ? NAN : 0.0),
                  .fp = rounding_allowance(M, swi, alpha, relp)};
        if (N >= 2 && sgn) ulam__cs_interval_sides(&S.none, 0.0, 0.0, S.llo, S.lhi, &c.none);
        else if (N >= 2) ulam__stop_interval(N, 0.0, 0.0, R, 0.0, 0.0, R0, k, &c.none); /* its ends: the KL interval's, below */
        else c.none = (ulam__stop_ci){.lo = w.k > 0 ? NAN : 0.0, .hi = w.k > 0 ? NAN : 0.0};
        if (!sgn && N >= 1) hits_interval(kept, N, kk < 0 ? k : kk, 0, R0, &c.none.lo, &c.none.hi);
        double s, a, b;
        int64_t nh = N > 0 ? w.nhit : 0;
        if (top < 0) { /* every component: the common interval, then the states some walk ended at */
            none_fill(&c, x, std_error, lo, hi, n);
            for (int64_t q = 0; q < nh; q++) {
                int64_t i = w.hit[q];
                double mean = ends_component(&c, x[i], q, &s, &a, &b);
                if (std_error) std_error[i] = s;
                if (lo) lo[i] = a;
                if (hi) hi[i] = b;
                x[i] += mean;
            }
        } else if (!(pv = ulam__malloc(nh > 0 ? (size_t)nh : 1, sizeof *pv))) {
            status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the top components");
        } else { /* x = p + the walks' means (p kept for the states ended at), the top ones, their outputs */
            for (int64_t q = 0; q < nh; q++) pv[q] = x[w.hit[q]], x[w.hit[q]] += ends_mean(&c, q);
            select_top(x, n, top, index, key);
            for (int64_t t = 0; t < top; t++) {
                int64_t q = nh > 0 ? hit_index(&w, index[t]) : -1;
                ends_component(&c, q >= 0 ? pv[q] : x[index[t]], q, &s, &a, &b);
                if (std_error) std_error[t] = s;
                if (lo) lo[t] = a;
                if (hi) hi[t] = b;
            }
        }
        info->walks = N, info->steps = w.steps, info->walk_seconds = ulam_now() - t1;
    }
    free(key), free(pv);
    free(bsum), free(w.cs), free(w.mx), free(w.cum), free(w.hit), free(w.hc), free(w.slot), free(w.known);
    free(w.scol), free(w.sval), free(w.soff);
    free(r), free(kept), free(kept_lo), free(S.q), free(S.prev);
    info->rel_err = pl.E, info->min_value = pl.delta;
    info->seconds = ulam_now() - t0;
    return status;
}

/* The queue path's outputs for the top components (select_top): every component's into
 * scratch, then theirs gathered. */
static int solve_queue_top(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, ulam_guard g, double *x,
                           int64_t top, int64_t *index, double *std_error, double *lo, double *hi, ulam_fpush_info *info,
                           ulam_error *err)
{
    size_t n = (size_t)M->nrows;
    double *se = ulam__malloc(n, sizeof *se), *a = ulam__malloc(n, sizeof *a), *b = ulam__malloc(n, sizeof *b);
    double *key = ulam__malloc(top > 0 ? (size_t)top : 1, sizeof *key);
    int status = se && a && b && key ? solve_queue(M, Mt, opts, g, x, se, a, b, info, err)
                                     : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for every component");
    if (!status) select_top(x, M->nrows, top, index, key);
    for (int64_t t = 0; !status && t < top; t++) {
        if (std_error) std_error[t] = se[index[t]];
        if (lo) lo[t] = a[index[t]];
        if (hi) hi[t] = b[index[t]];
    }
    free(se), free(a), free(b), free(key);
    return status;
}

/* A query given opts->walk.policy.system = sys (ulam_system_lazy's M): M must be sys's, and Mt NULL
 * takes sys's stored M^T as it is, so the push and the walks verify each block of it as they first
 * read a row of it (src/cache.h), the sweeps and any pass over all of M the whole file first; a
 * file with no M^T is verified whole and M transposed into *own (*Mt then).  A status. */
static int lazy_of(const ulam_system *sys, const ulam_csr *M, const ulam_csr **Mt, ulam_csr **own, ulam_error *err)
{
    const ulam_csr *SM = NULL;
    ulam_system_lazy(sys, &SM, NULL);
    if (M != SM) return ulam__fail(err, ULAM_EINVAL, 0, -1, "the matrix of opts->walk.policy.system (ulam_system_lazy's) as M");
    if (*Mt || (*Mt = ulam__system_tr(sys))) return ULAM_OK;
    int status = ulam_system_check(sys, err); /* no M^T stored: M whole, transposed */
    return status ? status : ulam_csr_transpose(M, own);
}

/* The dense route (src/fpush_dense.c) for a small system with ||M||_1 = alpha near 1: x exact
 * but for the LU's residual, every interval x_i -+ its certified bound, standard errors 0; top >= 0:
 * the outputs of the top components (select_top).  ULAM_OK, or nonzero (no LAPACK, a singular LU:
 * the push and walks run instead; info untouched but for its clearing). */
static int solve_dense(const ulam_csr *M, const ulam_fpush_opts *o, double alpha, double *x, int64_t top, int64_t *index,
                       double *std_error, double *lo, double *hi, ulam_fpush_info *info)
{
    int64_t n = M->nrows;
    double t0 = ulam_now(), r_sum, D, *key = top > 0 ? ulam__malloc((size_t)top, sizeof *key) : NULL;
    ulam_error e;
    if (top > 0 && !key) return ULAM_ENOMEM;
    int status = ulam__fpush_dense(M, o->source, alpha, x, &r_sum, &D, &e);
    if (!status) {
        int64_t m = top >= 0 ? top : n;
        if (top > 0) select_top(x, n, top, index, key);
        for (int64_t t = 0; t < m; t++) {
            double p = x[top >= 0 ? index[t] : t];
            if (std_error) std_error[t] = 0.0;
            if (lo) lo[t] = p - D;
            if (hi) hi[t] = p + D;
        }
        *info = (ulam_fpush_info){.dense = 1, .mean_visits = 1.0 / (1.0 - alpha), .residual_bound = D,
                                  .rel_err = o->rel_err, .min_value = o->min_value > 0 ? o->min_value : 1.0 / (double)n,
                                  .push = {.target = o->source, .touched = n, .r_sum = r_sum}};
        info->seconds = info->push_seconds = info->push.seconds = ulam_now() - t0;
    }
    free(key);
    return status;
}

/* ulam__fpush_solve, or with top >= 0 ulam_fpush_top's outputs (std_error, lo, hi: top entries). */
static int fpush(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, double *x, int64_t top,
                 int64_t *index, double *std_error, double *lo, double *hi, ulam_fpush_info *info, ulam__sweep_info *sw,
                 ulam_error *err)
{
    ulam__clear(err);
    if (!M || !opts || !x || !info) return ulam__fail(err, ULAM_EINVAL, 0, -1, "M, options, x and info");
    if (top >= 0 && (top > M->nrows || (top > 0 && !index)))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "k from 0 to n (%lld) and an index array", (long long)M->nrows);
    const ulam_system *sys = opts->walk.policy.system, *lz = NULL; /* a lazily read file: see lazy_of */
    ulam_csr *own = NULL;
    int status = sys ? lazy_of(sys, M, &Mt, &own, err) : ULAM_OK;
    if (own) Mt = own;
    if (!status) status = check(M, Mt, opts, err);
    if (status) {
        ulam_csr_free(own);
        return status;
    }
    memset(info, 0, sizeof *info);
    ulam__sweep_info swi = {0};
    ulam_guard g;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_FORWARD;
    if (opts->walk.policy.guard) g = *opts->walk.policy.guard;
    else if (!sys || !(status = ulam_system_check(sys, err))) /* a pass over all of M */
        status = ulam_guard_check(M, opts->walk.kernel.continue_q, &go, &g, err);
    lz = !status && sys && Mt == ulam__system_tr(sys) && g.abs.colsum_max < 1.0 ? sys : NULL; /* else whole, first */
    if (!status && sys && !lz) status = ulam_system_check(sys, err);
    if (status)
        ;
    else if (g.abs.colsum_max < 1.0 && !lz && opts->walks <= 0 && !(opts->rmax > 0) &&
             ulam__fpush_dense_pays(M->nrows, ulam_csr_nnz(M), g.abs.colsum_max) &&
             !(status = solve_dense(M, opts, g.abs.colsum_max, x, top, index, std_error, lo, hi, info)))
        ;
    else if (g.abs.colsum_max < 1.0)
        status = solve_sweep(M, Mt, lz, opts, &g, x, top, index, std_error, lo, hi, info, &swi, err);
    else if (top >= 0)
        status = solve_queue_top(M, Mt, opts, g, x, top, index, std_error, lo, hi, info, err);
    else
        status = solve_queue(M, Mt, opts, g, x, std_error, lo, hi, info, err);
    if (sw) *sw = swi;
    ulam_csr_free(own);
    return status;
}

/* Estimate every component of x = (I - M)^-1 e_source; sw (may be NULL) gets the sweep push's
 * counts (zero when the queue push ran). */
int ulam__fpush_solve(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, double *x, double *std_error,
                      double *lo, double *hi, ulam_fpush_info *info, ulam__sweep_info *sw, ulam_error *err)
{
    return fpush(M, Mt, opts, x, -1, NULL, std_error, lo, hi, info, sw, err);
}

/* Estimate every component of x = (I - M)^-1 e_source. */
int ulam_fpush_solve(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, double *x, double *std_error,
                     double *lo, double *hi, ulam_fpush_info *info, ulam_error *err)
{
    return fpush(M, Mt, opts, x, -1, NULL, std_error, lo, hi, info, NULL, err);
}

/* ulam_fpush_top with the sweep push's counts (see src/fpush.h). */
int ulam__fpush_top(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, int64_t k, double *x,
                    int64_t *index, double *std_error, double *lo, double *hi, ulam_fpush_info *info, ulam__sweep_info *sw,
                    ulam_error *err)
{
    if (k < 0) {
        ulam__clear(err);
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "k >= 0 components");
    }
    return fpush(M, Mt, opts, x, k, index, std_error, lo, hi, info, sw, err);
}

/* Estimate every component of x = (I - M)^-1 e_source, and the k largest with their standard
 * errors and intervals. */
int ulam_fpush_top(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, int64_t k, double *x,
                   int64_t *index, double *std_error, double *lo, double *hi, ulam_fpush_info *info, ulam_error *err)
{
    return ulam__fpush_top(M, Mt, opts, k, x, index, std_error, lo, hi, info, NULL, err);
}
