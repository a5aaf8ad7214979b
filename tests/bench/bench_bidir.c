/* Single-pair queries on a heavy-tailed directed graph: bidirectional (push + walks) against pure
 * walks and against the push alone, each to 10% relative error, side by side in one run.
 *
 * Graph: R-MAT (Chakrabarti, Zhan, Faloutsos 2004; a = 0.57, b = c = 0.19, d = 0.05) with 2^L states
 * and 8 2^L edges, states relabelled by a random permutation, all from stream (L, 0).  M = 0.85 P'
 * with P the random-walk matrix of the out-edges (multi-edges counted), so x = (I - M)^-1 e_s is
 * personalized PageRank from s (over 0.15) and x_t of one pair is the BiPPR setting: the push from t
 * runs over in-edges (rows of M), the walks from s over out-edges (rows of M').
 * Pairs: SOURCES random sources with at least TARGETS states t != s of x_t >= 1/n, TARGETS of those
 * drawn uniformly; exact values from Gauss-Seidel converged to a change <= 1e-15 per sweep.
 * Methods, one thread each, all to relative error 10%:
 *   bidirectional  balanced rmax, stopped by rel_err 0.1 on the whole estimate;
 *   walks          the walk solver alone: adjoint on M' from s with b = e_t (walks from s counting
 *                  visits to t), the same stopping rule; capped at WALK_CAP seconds, a capped
 *                  pair's time projected as its set-up and walks so far plus the walks still
 *                  needed (variance / (10% x_t estimate)^2 - walks) at the least seconds a walk
 *                  over its rounds (the one-off row builds and kernel completion are counted once,
 *                  not scaled, and the rate is the walks' best: favourable to walks; marked *);
 *                  when no walk has reached t by the cap, from the bound Var(visits to t) >=
 *                  x_t - x_t^2 (visits are integers, so V^2 >= V): at least 100 (1 - x_t) / x_t
 *                  walks (a lower bound, marked !);
 *   push           push alone with rmax halving from 1 until |p_s - x_t| <= 10% x_t, checked
 *                  against the exact value (an oracle stop: a lower bound on what push alone
 *                  needs without knowing x_t); capped at PUSH_CAP seconds (a lower bound, marked).
 * Every query's figure is its CPU seconds (the columns bidir_s, walk1_s and push1_s; push_s and
 * walks_s are the bidirectional parts' wall seconds): on the shared machine a one-thread query's
 * wall time is mostly waiting for a core, which swamped the ratios.
 * The transpose M' and the walks' guards on it are computed once (their times are printed apart)
 * and given to every query of both walk methods: a query never repeats them.  The bidirectional
 * queries share one analysis of M (ulam_analysis_bidir: its transpose, made before the clock,
 * push workspace and plan memo) with reach_all (the walks' reachability bounds over every
 * state, made by the first query, its time counted there) and keep_kernel (kernel rows built by
 * earlier queries' walks and pilots are kept and rescored, not built again): per-graph work is
 * paid once, inside the queries' times.  The walks-alone peer builds its rows afresh each pair.
 * The cost of a walk visit in push operations, the balance's step_cost, is measured here: push
 * operations per second over walk visits per second (walks plus steps), both summed over the
 * bidirectional queries; and how far the plan's predicted work (push operations plus step_cost
 * visits) is from the work done.
 *
 * A second family (issue 29 point 3), `bench_bidir --zipf [N [SOURCES]]`: the heavy-tailed digraph
 * of tests/zipf_graph.h (N = 2 10^5 states, out-degrees 1 + Zipf(2.1), heads drawn with weight
 * rank^-0.75, M = 0.85 P'), SOURCES (default 10) random sources with one target each, drawn among
 * the states with 1/n <= pi_t <= 20/n, pi = 0.15 x the personalized PageRank; the same methods.
 * Usage: bench_bidir [L [SOURCES]] (default 20 and 20: n = 1048576, 100 pairs). */
#include "../../src/push.h" /* the push-alone peer: the reverse push has no public API (ulam_push is opaque) */
#include "exact.h"
#include "../zipf_graph.h"

#include <math.h>
#include <time.h>

enum { SOURCES = 20, TARGETS = 5, PAIRS = SOURCES * TARGETS };
static const double WALK_CAP = 2.0, PUSH_CAP = 5.0, REL = 0.1, ALPHA = 0.85;

/* One method's per-pair outcome. */
typedef struct {
    double seconds[PAIRS];
    int marked[PAIRS]; /* walks: projected; push: capped (a lower bound) */
    int covered, intervals;
    double other[PAIRS], walk[PAIRS]; /* bidirectional: push and walk seconds */
} series;

/* This process's CPU seconds (user + system): the fair figure on a shared machine, where a
 * one-thread query's wall time mostly waits for a core (at load 15, 5-10x its CPU time). */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* qsort order of doubles. */
static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile (nearest rank) of v[0..n). */
static double quantile(const double *v, int n, double q)
{
    double s[PAIRS];
    memcpy(s, v, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp);
    int k = (int)ceil(q * n) - 1;
    return s[k < 0 ? 0 : k];
}

/* A bidirectional query (rmax 0: balanced) on the analysis a. */
static int query(ulam_analysis *a, const ulam_guard *g, int64_t s, int64_t t, double rmax, double cap, uint64_t seed,
                 ulam_bidir_result *res)
{
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.walk.policy.guard = g;
    o.reach_all = 1;   /* the walks' bounds over every state, made at the first query, kept in a's memo for the rest */
    o.keep_kernel = 1; /* the walks' (and pilot's) kernel rows kept in a's memo, rescored to each query's residual */
    o.source = s, o.target = t, o.rmax = rmax;
    o.walk.stop.max_walks = 0, o.walk.stop.rel_err = REL, o.walk.stop.max_seconds = cap, o.walk.exec.threads = 1, o.walk.exec.seed = seed;
    o.walk.stop.max_steps = INT64_MAX / 4;
    ulam_error err;
    int st = ulam_analysis_bidir(a, &o, res, &err);
    if (st) fprintf(stderr, "bidir: pair (%lld, %lld): %s: %s\n", (long long)s, (long long)t, ulam_strerror(st), err.msg);
    return st;
}

/* Pure walks from s counting visits to t (e: zeros, n entries); seconds (projected when capped: *mark
 * 1, or 2 for a lower bound) and whether the 95% interval covers exact (-1: no interval). */
static double walks_alone(const ulam_csr *Mt, const ulam_guard *g, double *e, int64_t s, int64_t t, double exact,
                          uint64_t seed, int *mark, int *covers)
{
    ulam_walk_opts o = ulam_walk_defaults();
    o.policy.guard = g;
    o.query.index = s, o.exec.threads = 1, o.exec.seed = seed, o.stop.max_walks = 0, o.stop.max_seconds = WALK_CAP, o.stop.max_steps = INT64_MAX / 4;
    e[t] = 1.0;
    ulam_solver *sv = NULL;
    double t0 = ulam_now(), c0 = cpu_now(), rate = INFINITY;
    ulam_walk_result r = {0};
    int reached = 0;
    if (!ulam_solver_alloc(Mt, e, &o, &sv, NULL)) {
        while (!ulam_solver_done(sv) && !reached) {
            double s0 = r.seconds;
            int64_t w0 = r.walks;
            if (ulam_solver_iterate(sv)) break;
            ulam_solver_result(sv, &r);
            if (r.walks > w0) rate = fmin(rate, (r.seconds - s0) / (double)(r.walks - w0));
            reached = r.walks >= 1000 && r.variance > 0 && r.std_error <= REL * fabs(r.estimate);
        }
    }
    double wall = ulam_now() - t0, total = cpu_now() - c0;
    rate *= wall > 0 ? total / wall : 1.0; /* the walks' best wall rate in CPU seconds */
    ulam_solver_free(sv);
    e[t] = 0.0;
    *mark = 0, *covers = -1;
    if (reached) {
        *covers = r.ci95[0] <= exact && exact <= r.ci95[1];
        return total;
    }
    double need = r.variance > 0 ? r.variance / (REL * r.estimate * REL * r.estimate) : 100 * (1 - exact) / exact;
    *mark = r.variance > 0 ? 1 : 2;
    return total + fmax(0.0, need - (double)r.walks) * rate;
}

/* Push alone from t, rmax halving, until p_s is within REL of exact (or PUSH_CAP); seconds, *capped. */
static double push_alone(ulam_push *w, int64_t s, int64_t t, double exact, int *capped, double *rmax_reached)
{
    double c0 = cpu_now();
    ulam__push_start(w, t);
    ulam_push_info pi;
    for (double rmax = 1.0;; rmax /= 2) {
        ulam__push_run(w, rmax, 0);
        ulam__push_report(w, &pi);
        *rmax_reached = rmax;
        if (fabs(ulam__push_estimates(w)[s] - exact) <= REL * exact || pi.support == 0) {
            *capped = 0;
            return cpu_now() - c0;
        }
        if (pi.seconds > PUSH_CAP) {
            *capped = 1;
            return cpu_now() - c0;
        }
    }
}

/* Print one row of the table over the first np pairs. */
static void row(const char *name, const series *S, const series *ref, int np)
{
    int marked = 0;
    for (int k = 0; k < np; k++) marked += S->marked[k] > 0;
    double med = quantile(S->seconds, np, 0.5), p90 = quantile(S->seconds, np, 0.9);
    double rmed = med / quantile(ref->seconds, np, 0.5), rp90 = p90 / quantile(ref->seconds, np, 0.9);
    double ratio[PAIRS];
    for (int k = 0; k < np; k++) ratio[k] = S->seconds[k] / ref->seconds[k];
    printf("%-22s %10.4f %10.4f %9.1fx %9.1fx %12.1fx   ", name, med, p90, rmed, rp90, quantile(ratio, np, 0.5));
    if (S->intervals) printf("%3d/%-3d", S->covered, S->intervals);
    else printf("  -    ");
    printf("   %d\n", marked);
}

/* The largest row length of A. */
static int64_t max_row(const ulam_csr *A)
{
    int64_t m = 0;
    for (int64_t i = 0; i < A->nrows; i++) m = A->rowptr[i + 1] - A->rowptr[i] > m ? A->rowptr[i + 1] - A->rowptr[i] : m;
    return m;
}

int main(int argc, char **argv)
{
    int zipf = argc > 1 && !strcmp(argv[1], "--zipf");
    if (zipf) argc--, argv++;
    int L = argc > 1 ? atoi(argv[1]) : zipf ? 200000 : 20, nsrc = argc > 2 ? atoi(argv[2]) : zipf ? 10 : SOURCES;
    int tps = zipf ? 1 : TARGETS, np = nsrc * tps; /* targets per source, pairs */
    if ((zipf ? L < 1000 : L < 8 || L > 24) || nsrc < 1 || nsrc > SOURCES) {
        fprintf(stderr, "usage: bench_bidir [L [SOURCES]] or bench_bidir --zipf [N [SOURCES]], 8 <= L <= 24, "
                        "N >= 1000, 1 <= SOURCES <= %d\n", SOURCES);
        return 2;
    }
    double t0 = ulam_now();
    int64_t dangling = 0, maxin = 0, maxout = 0;
    ulam_csr *M = zipf ? zipf_graph(L, 2.1, 0.75, ALPHA, 1) : bench_rmat(L, ALPHA, &dangling, &maxin, &maxout);
    int64_t n = zipf ? L : (int64_t)1 << L;
    if (!M) return fprintf(stderr, "bidir: out of memory\n"), 1;
    if (zipf)
        printf("Zipf digraph: n = %lld, nnz(M) = %lld (out-degrees 1 + Zipf(2.1), heads by rank^-0.75, multi-edges "
               "merged), max in-neighbours %lld; built in %.1f s\n", (long long)n, (long long)ulam_csr_nnz(M),
               (long long)max_row(M), ulam_now() - t0);
    else
        printf("R-MAT 2^%d: n = %lld, nnz(M) = %lld (8n edges, multi-edges merged), %lld dangling, max in-degree %lld, "
               "max out-degree %lld; built in %.1f s\n", L, (long long)n, (long long)ulam_csr_nnz(M),
               (long long)dangling, (long long)maxin, (long long)maxout, ulam_now() - t0);
    t0 = ulam_now();
    ulam_push *w = NULL; /* the push-alone peer's workspace */
    ulam_analysis *an = NULL; /* the bidirectional queries' transpose, push workspace and plan memo */
    const ulam_csr *Mt = NULL;
    if (ulam_analysis_alloc(M, NULL, &an, NULL) || !(Mt = ulam_analysis_transpose(an, NULL)) || ulam__push_alloc(M, &w))
        return fprintf(stderr, "bidir: out of memory\n"), 1;
    printf("transpose M' (once, for every query): %.3f s\n", ulam_now() - t0);
    ulam_guard g; /* the walks' guards on M' (adjoint kernel), once for every query of either method */
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(ULAM_ADJOINT);
    t0 = ulam_now();
    if (ulam_guard_check(Mt, 0.0, &go, &g, NULL)) return fprintf(stderr, "bidir: guards failed\n"), 1;
    printf("guards on M' (once, for every query of both walk methods): %.3f s\n", ulam_now() - t0);
    double *x = malloc((size_t)n * sizeof *x), *old = malloc((size_t)n * sizeof *old), *b = malloc((size_t)n * sizeof *b);
    double *e = calloc((size_t)n, sizeof *e);
    int64_t *cand = malloc((size_t)n * sizeof *cand);
    if (!x || !old || !b || !e || !cand) return fprintf(stderr, "bidir: out of memory\n"), 1;
    static series bi, wk, pu;
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)L, 1);
    double gs_seconds = 0, sum_push_ops = 0, sum_steps = 0, sum_push_s = 0, sum_walk_s = 0, gs_max_sweeps = 0;
    double work_ratio[PAIRS], walks_ratio[PAIRS], step_cost = 0; /* predicted / done */
    double lo = zipf ? 1.0 / ((1 - ALPHA) * (double)n) : 1.0 / (double)n, hi = zipf ? 20 * lo : INFINITY;
    int k = 0;
    printf("\n%4s %8s %8s %12s %10s %9s %9s %9s %10s %10s %7s %9s %9s %9s\n", "pair", "s", "t", "exact", "bidir_s",
           "push_s", "walks_s", "rmax", "walks", "predicted", "z", "walk1_s", "push1_s", "push1_rmax");
    for (int src = 0; src < nsrc;) {
        int64_t s = (int64_t)ulam_rng_bounded(&r, (uint64_t)n);
        double g0 = ulam_now();
        int sweeps = bench_exact_column(M, s, x, old, b);
        gs_seconds += ulam_now() - g0;
        gs_max_sweeps = fmax(gs_max_sweeps, sweeps);
        int64_t nc = 0;
        for (int64_t i = 0; i < n; i++)
            if (i != s && x[i] >= lo && x[i] <= hi) cand[nc++] = i;
        if (nc < tps) continue; /* a source reaching too little: draw another */
        for (int q = 0; q < tps; q++, k++) {
            int64_t j = q + (int64_t)ulam_rng_bounded(&r, (uint64_t)(nc - q)); /* without replacement */
            int64_t t = cand[j];
            cand[j] = cand[q], cand[q] = t;
            ulam_bidir_result rb;
            double c0 = cpu_now();
            if (query(an, &g, s, t, 0, 0, (uint64_t)k + 1, &rb)) return 1;
            bi.seconds[k] = cpu_now() - c0, bi.other[k] = rb.push.seconds, bi.walk[k] = rb.walks.seconds;
            bi.covered += rb.ci95[0] <= x[t] && x[t] <= rb.ci95[1], bi.intervals++;
            sum_push_ops += (double)rb.push.ops, sum_steps += (double)(rb.walks.steps + rb.walks.walks);
            step_cost = rb.plan.step_cost;
            double done = (double)rb.push.ops + rb.plan.step_cost * (double)(rb.plan.pilot_walks + rb.plan.pilot_steps +
                                                                             rb.walks.walks + rb.walks.steps);
            work_ratio[k] = rb.plan.predicted_work / done;
            walks_ratio[k] = rb.plan.predicted_walks / fmax(1.0, (double)rb.walks.walks);
            sum_push_s += rb.push.seconds, sum_walk_s += rb.walks.seconds;
            int covers;
            wk.seconds[k] = walks_alone(Mt, &g, e, s, t, x[t], (uint64_t)k + 1, &wk.marked[k], &covers);
            if (covers >= 0) wk.covered += covers, wk.intervals++;
            double prmax;
            pu.seconds[k] = push_alone(w, s, t, x[t], &pu.marked[k], &prmax);
            printf("%4d %8lld %8lld %12.5g %10.5f %9.5f %9.5f %9.2g %10lld %10.3g %7.2f %9.4f%s %9.4f%s %9.2g\n", k + 1,
                   (long long)s + 1, (long long)t + 1, x[t], bi.seconds[k], rb.push.seconds, rb.walks.seconds, rb.push.rmax,
                   (long long)rb.walks.walks, rb.plan.predicted_walks, (rb.estimate - x[t]) / rb.std_error, wk.seconds[k],
                   wk.marked[k] == 2 ? "!" : wk.marked[k] ? "*" : " ", pu.seconds[k], pu.marked[k] ? ">" : " ", prmax);
            fflush(stdout);
        }
        src++;
    }
    printf("\nexact values: Gauss-Seidel, %.1f s for %d sources (up to %.0f sweeps)\n", gs_seconds, nsrc, gs_max_sweeps);
    printf("bidirectional work: push %.3g operations/s, walks %.3g visits/s (one thread): a visit costs %.2f push "
           "operations (the balance's step_cost: %.2f)\n", sum_push_ops / sum_push_s, sum_steps / sum_walk_s,
           (sum_push_ops / sum_push_s) / (sum_steps / sum_walk_s), step_cost);
    printf("the plan's prediction over what was done: work median %.2fx (p90 %.2fx), walks median %.2fx (p90 %.2fx)\n",
           quantile(work_ratio, np, 0.5), quantile(work_ratio, np, 0.9), quantile(walks_ratio, np, 0.5),
           quantile(walks_ratio, np, 0.9));
    printf("\n%d pairs at %.0f%% relative error, one thread; CPU seconds per query (median, 90th percentile), ratios to "
           "bidirectional\n", np, 100 * REL);
    printf("%-22s %10s %10s %10s %10s %13s   %-7s   %s\n", "method", "median", "p90", "med/bidir", "p90/bidir",
           "median ratio", "cover95", "marked");
    row("bidirectional", &bi, &bi, np);
    row("walks (*, ! projected)", &wk, &bi, np);
    row("push, oracle (> cap)", &pu, &bi, np);
    printf("bidirectional parts: push median %.4f s (p90 %.4f), walks median %.4f s (p90 %.4f); the rest is the "
           "pilot and the walk solver's set-up\n", quantile(bi.other, np, 0.5), quantile(bi.other, np, 0.9),
           quantile(bi.walk, np, 0.5), quantile(bi.walk, np, 0.9));
    free(x), free(old), free(b), free(e), free(cand);
    ulam__push_free(w), ulam_analysis_free(an);
    ulam_csr_free(M);
    return 0;
}
