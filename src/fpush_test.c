/* A unit test of src/fpush.c built with the module (tests/meson.build's module units): the
 * sweep push's own counts (rounds, whole sweeps, pulls, the negative residual cut), which only
 * the private ulam__fpush_solve reports, read beside the coverage they come with.  It includes
 * internal.h, where ulam__fpush_solve and ulam__sweep_info are declared; the tests in tests/
 * include public headers only (the rest of single source is tests/test_fpush.c).
 *
 * Each case draws the heavy-tailed Zipf digraph of tests/zipf_graph.h (M = 0.85 P', so
 * x = (I - M)^-1 e_s, pi = 0.15 x) or an R-MAT one, and the exact column by a long power
 * iteration, and counts, over seeds, the components whose printed 95% interval holds the exact
 * value: the pooled count k of N passes 0.95 N - 4 sqrt(0.95 0.05 N) and 0.9 N. */
#include "internal.h"
#include "cache.h"
#include "fpush.h"
#include "sweep.h"
#include "testutil.h"
#include "zipf_graph.h"

/* k of N covered passes the binomial bound of the header. */
static int coverage_ok(int64_t k, int64_t N)
{
    double Nd = (double)N;
    return (double)k >= 0.95 * Nd - 4.0 * sqrt(0.95 * 0.05 * Nd) && (double)k >= 0.9 * Nd;
}

/* Over the components with pi = 0.15 x_i >= 1/n: how many (*b), covered by their interval (*c),
 * estimated within 10% (*w); every estimate inside its interval. */
static void count_big(int64_t n, const double *x, const double *est, const double *lo, const double *hi, int64_t *b,
                      int64_t *c, int64_t *w)
{
    *b = *c = *w = 0;
    for (int64_t i = 0; i < n; i++) {
        if (!(lo[i] <= est[i] && est[i] <= hi[i])) print_error("component %lld: %.17g in [%.17g, %.17g]?\n", (long long)i, est[i], lo[i], hi[i]);
        assert_true(lo[i] <= est[i] && est[i] <= hi[i]);
        if (0.15 * x[i] < 1.0 / (double)n) continue;
        ++*b;
        *c += lo[i] <= x[i] && x[i] <= hi[i];
        *w += fabs(est[i] - x[i]) <= 0.1 * x[i];
    }
}

/* One run of seed from s under the relative-error rule (E = 0.1 on every pi >= 1/n, so delta =
 * 1 / (0.15 n)), against x, the exact column: every such component within 10% (their count added
 * to *big, those their interval covers to *covered); the walks in *info, the sweep push in *sw. */
static void rule_run(const ulam_csr *M, const ulam_csr *Mt, int64_t s, const double *x, int seed, const char *name,
                     ulam_fpush_info *info, ulam__sweep_info *sw, int64_t *big, int64_t *covered)
{
    int64_t n = M->nrows, b, c, w;
    double *est = malloc((size_t)n * sizeof *est), *lo = malloc((size_t)n * sizeof *lo), *hi = malloc((size_t)n * sizeof *hi);
    ulam_fpush_opts o = ulam_fpush_defaults();
    o.source = s, o.walk.exec.seed = (uint64_t)seed, o.min_value = 1.0 / (0.15 * (double)n), o.walk.stop.max_walks = 0;
    ulam_error err;
    assert_int_equal(ulam__fpush_solve(M, Mt, &o, est, NULL, lo, hi, info, sw, &err), ULAM_OK);
    count_big(n, x, est, lo, hi, &b, &c, &w);
    print_message("%s seed %d: %lld rounds (%lld sweeps), %lld ops, r_sum %.3g, negative residual %.3g, %lld walks: "
                  "%lld of %lld covered, %lld within 10%%\n", name, seed, (long long)sw->rounds, (long long)sw->sweeps,
                  (long long)sw->ops, sw->r_sum, sw->r_neg, (long long)info->walks, (long long)c, (long long)b, (long long)w);
    assert_int_equal(w, b);
    *big += b, *covered += c;
    free(est), free(lo), free(hi);
}

/* The relative-error rule (E = 0.1 on every pi >= 1/n): the push goes round the active list and
 * then sweeps (the counters say so), every component with pi >= 1/n is within 10% of the exact
 * value, and the intervals cover at the claimed rate over 8 seeds. */
static void test_fpush_rule(void **state)
{
    (void)state;
    int64_t n = 3000, s = 2, big = 0, covered = 0;
    ulam_csr *M = zipf_graph(n, 2.1, 0.75, 0.85, 1), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = zipf_graph_column(M, s);
    for (int seed = 1; seed <= 8; seed++) {
        if (!test_case(seed)) continue;
        ulam_fpush_info info;
        ulam__sweep_info sw;
        int64_t before = big;
        rule_run(M, Mt, s, x, seed, "Zipf", &info, &sw, &big, &covered);
        assert_true(sw.sweeps >= 1 && sw.rounds > sw.sweeps); /* list rounds first, then whole sweeps */
        assert_true(sw.pulls == sw.sweeps && sw.nonneg);     /* M >= 0: the sweeps pull along M's rows */
        assert_true(info.walks > 0 && info.push.r_sum > 0);
        assert_true(big - before >= 20);
    }
    test_case_done();
    if (test_case_all()) assert_true(coverage_ok(covered, big));
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* An R-MAT digraph (a = 0.57, b = c = 0.19, d = 0.05, 8 n edges on n = 2^L states, relabelled at
 * random, multi-edges summed; with fix, each state with no out-edge given one to a state drawn
 * uniformly, as tests/bench/bench_rmat_write.c does), M = alpha P'. */
static ulam_csr *rmat_graph_fix(int L, double alpha, uint64_t seed, int fix)
{
    int64_t n = (int64_t)1 << L, m = 8 * n, *out = calloc((size_t)n, sizeof *out);
    int32_t *ti = malloc((size_t)(m + n) * sizeof *ti), *tj = malloc((size_t)(m + n) * sizeof *tj);
    int32_t *perm = malloc((size_t)n * sizeof *perm);
    double *tx = malloc((size_t)(m + n) * sizeof *tx);
    ulam_csr *M = NULL;
    ulam_rng r;
    ulam_rng_seed(&r, seed, 4);
    for (int64_t i = 0; i < n; i++) perm[i] = (int32_t)i;
    for (int64_t k = n - 1; k > 0; k--) {
        int64_t j = (int64_t)ulam_rng_bounded(&r, (uint64_t)(k + 1));
        int32_t t = perm[k];
        perm[k] = perm[j], perm[j] = t;
    }
    for (int64_t e = 0; e < m; e++) {
        int64_t u = 0, v = 0;
        for (int l = 0; l < L; l++) {
            double q = ulam_rng_uniform(&r);
            u = 2 * u + (q >= 0.76), v = 2 * v + ((q >= 0.57 && q < 0.76) || q >= 0.95);
        }
        ti[e] = perm[v], tj[e] = perm[u], out[perm[u]]++; /* an edge u -> v: M_vu */
    }
    for (int64_t u = 0, m0 = m; fix && u < m0 / 8; u++)
        if (!out[u]) ti[m] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n), tj[m++] = (int32_t)u, out[u] = 1;
    for (int64_t e = 0; e < m; e++) tx[e] = alpha / (double)out[tj[e]];
    if (ulam_csr_from_triplets(n, n, m, ti, tj, tx, &M)) M = NULL;
    free(out), free(ti), free(tj), free(perm), free(tx);
    return M;
}

/* rmat_graph_fix without the fix: states with no out-edge keep none. */
static ulam_csr *rmat_graph(int L, double alpha, uint64_t seed)
{
    return rmat_graph_fix(L, alpha, seed, 0);
}

/* The relative-error rule on R-MAT 2^12, where the over-relaxed sweeps and the two plain ones
 * leave a negative residual of roundings only: it is cut (the KL intervals, every lower end
 * lowered by its bound), every pi >= 1/n is within 10%, and the intervals cover at the claimed
 * rate over 8 seeds. */
static void test_fpush_rmat_cut(void **state)
{
    (void)state;
    ulam_csr *M = rmat_graph(12, 0.85, 5), *Mt = NULL;
    assert_non_null(M);
    int64_t n = M->nrows, s = 0, big = 0, covered = 0;
    while (M->rowptr[s + 1] == M->rowptr[s] || s == 0) s++; /* a state with in-edges, past 0 */
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    while (Mt->rowptr[s + 1] == Mt->rowptr[s]) s++; /* and out-edges */
    double *x = zipf_graph_column(M, s), delta = 1.0 / (0.15 * (double)n);
    for (int seed = 1; seed <= 8; seed++) {
        if (!test_case(seed)) continue;
        ulam_fpush_info info;
        ulam__sweep_info sw;
        rule_run(M, Mt, s, x, seed, "R-MAT", &info, &sw, &big, &covered);
        assert_true(sw.pulls > 2 && sw.nonneg);
        assert_true(sw.r_neg / 0.15 <= 0.01 * 0.1 * delta); /* cut: the KL path */
    }
    test_case_done();
    if (test_case_all()) assert_true(coverage_ok(covered, big));
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* The k-th largest of x (n entries; k <= n). */
static double kth_of(const double *x, int64_t n, int64_t k)
{
    double *v = malloc((size_t)n * sizeof *v);
    memcpy(v, x, (size_t)n * sizeof *v);
    for (int64_t t = 0; t < k; t++) /* k small: k passes */
        for (int64_t i = t + 1; i < n; i++)
            if (v[i] > v[t]) {
                double u = v[t];
                v[t] = v[i], v[i] = u;
            }
    double r = v[k - 1];
    free(v);
    return r;
}

/* The top-K target (ulam_fpush_top with no min_value, issue 43): on R-MAT 2^15 from a source
 * whose mass spreads through a hub, the floor planned is at most the exact K-th largest x_i (a
 * certified lower bound: the K-th largest p_i + r_i+ after the push) and above 1 / n; the push
 * and walks' work (push operations + walk steps x the default step cost 150) is under 3/4 of a
 * run planned for every x_i >= 1 / n (ulam_fpush_top's plan before: the same run, ratio 1; here
 * 0.56: 2.8e6 operations and 4 900 steps against 6.3e6); the K intervals printed cover the
 * exact values at the claimed rate over 16 seeds. */
static void test_fpush_topk(void **state)
{
    (void)state;
    ulam_csr *M = rmat_graph(15, 0.85, 7), *Mt = NULL;
    assert_non_null(M);
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    int64_t n = M->nrows, K = 20, s = 0, idx[20], covered = 0, shown = 0;
    while (Mt->rowptr[s + 1] - Mt->rowptr[s] < 2) s++; /* a state with out-edges */
    double *x = zipf_graph_column(M, s), *est = malloc((size_t)n * sizeof *est), lo[20], hi[20];
    double xk = kth_of(x, n, K);
    for (int seed = 1; seed <= 16; seed++) {
        if (!test_case(seed)) continue;
        ulam_fpush_opts o = ulam_fpush_defaults();
        o.source = s, o.walk.exec.seed = (uint64_t)seed;
        ulam_fpush_info info, all;
        ulam_error err;
        assert_int_equal(ulam_fpush_top(M, Mt, &o, K, est, idx, NULL, lo, hi, &info, &err), ULAM_OK);
        o.min_value = 1.0 / (double)n; /* the old plan: every x_i >= 1 / n */
        assert_int_equal(ulam_fpush_top(M, Mt, &o, K, est, idx, NULL, lo, hi, &all, &err), ULAM_OK);
        double work = (double)info.push.ops + 150.0 * (double)info.steps, old = (double)all.push.ops + 150.0 * (double)all.steps;
        assert_int_equal(ulam_fpush_top(M, Mt, &(ulam_fpush_opts){.source = s, .rel_err = 0.1, .walk = o.walk}, K, est, idx,
                                        NULL, lo, hi, &info, &err), ULAM_OK);
        int64_t c = 0;
        for (int64_t t = 0; t < K; t++) c += lo[t] <= x[idx[t]] && x[idx[t]] <= hi[t];
        print_message("seed %d: floor %.4g (K-th largest x %.4g), %lld ops + %lld steps: work %.3g, planned at 1/n %.3g; "
                      "%lld of %lld covered\n", seed, info.min_value, xk, (long long)info.push.ops, (long long)info.steps,
                      work, old, (long long)c, (long long)K);
        assert_true(info.min_value <= xk && info.min_value > 1.0 / (double)n);
        assert_true(work < 0.75 * old);
        covered += c, shown += K;
    }
    test_case_done();
    if (test_case_all()) assert_true(coverage_ok(covered, shown));
    free(x), free(est);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* The top-K target where the push goes global (R-MAT 2^16 with its states' missing out-edges
 * added, as the prepared benchmark graphs are; M = 0.85 P', top 100): the over-relaxed sweeps
 * leave a negative residual (source 1: 1.99e-4 times 1 / (1 - alpha), against the cut's 5.3e-6,
 * 1% of E times the floor), which the walks took with their signs (empirical Bernstein: 2896
 * walks); pushed (push_negative), it is 7.3e-9, cut, and the walks score 0 or R0 (the KL
 * intervals: 1448 walks; on the prepared R-MAT 2^18 source 101 11585 walks before, 5792 after;
 * 2^20 92681, 8192; 2^24: the certified floor fell to 1 / n, and the run planned 10^8 walks).  The
 * floor stays at most the exact K-th largest x_i and the printed intervals cover the exact values
 * at the claimed rate over 8 seeds. */
static void test_fpush_topk_negative(void **state)
{
    (void)state;
    ulam_csr *M = rmat_graph_fix(16, 0.85, 3, 1), *Mt = NULL;
    assert_non_null(M);
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    int64_t n = M->nrows, K = 100, s = 0, idx[100], covered = 0, shown = 0;
    while (Mt->rowptr[s + 1] - Mt->rowptr[s] < 2) s++; /* a state with out-edges */
    double *x = zipf_graph_column(M, s), *est = malloc((size_t)n * sizeof *est), lo[100], hi[100];
    double xk = kth_of(x, n, K);
    for (int seed = 1; seed <= 8; seed++) {
        if (!test_case(seed)) continue;
        ulam_fpush_opts o = ulam_fpush_defaults();
        o.source = s, o.walk.exec.seed = (uint64_t)seed;
        ulam_fpush_info info;
        ulam__sweep_info sw;
        ulam_error err;
        assert_int_equal(ulam__fpush_top(M, Mt, &o, K, est, idx, NULL, lo, hi, &info, &sw, &err), ULAM_OK);
        int64_t c = 0;
        for (int64_t t = 0; t < K; t++) c += lo[t] <= x[idx[t]] && x[idx[t]] <= hi[t];
        print_message("seed %d: %lld sweeps, negative residual %.3g (cut at %.3g), floor %.4g (K-th largest x %.4g), %lld "
                      "walks; %lld of %lld covered\n", seed, (long long)sw.sweeps, sw.r_neg / 0.15,
                      0.01 * 0.1 * info.min_value, info.min_value, xk, (long long)info.walks, (long long)c, (long long)K);
        assert_true(sw.sweeps > 0 && sw.nonneg);
        assert_true(sw.r_neg / 0.15 <= 0.01 * 0.1 * info.min_value); /* cut: the KL path */
        assert_true(info.min_value <= xk && info.min_value > 0.5 * xk);
        covered += c, shown += K;
    }
    test_case_done();
    if (test_case_all()) assert_true(coverage_ok(covered, shown));
    free(x), free(est);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* The kB of the process's resident set in the mapping that starts at map (/proc/self/smaps). */
static long long mapping_rss_kb(const void *map)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    char line[512];
    int in = 0;
    long long kb = -1;
    while (f && fgets(line, sizeof line, f)) {
        unsigned long long a, b;
        if (sscanf(line, "%llx-%llx ", &a, &b) == 2 && strchr(line, ' ') && line[strlen(line) - 1] == '\n' &&
            strncmp(line, "Rss", 3)) {
            in = a == (unsigned long long)(uintptr_t)map;
            continue;
        }
        if (in && sscanf(line, "Rss: %lld kB", &kb) == 1) break;
    }
    if (f) fclose(f);
    return kb;
}

/* A prepared file larger than its keep (issue 43: 2^24 nodes, a 6.5 GB file, within 2 GiB), read
 * lazily by a top-100 query whose push goes global (R-MAT 2^16 as the benchmark graphs are, the
 * over-relaxed sweeps, then walks): the whole passes (the check, the sweeps, the negative push)
 * give back each stretch of rows once done, the walks read short rows of M^T by pread and trims
 * give the rest back, so the mapping's resident set after the query stays under 1/8 of the file,
 * with the answer bit for bit the one on M in memory.  With the default keep (the file kept
 * mapped whole, as before), the same query leaves most of the file resident. */
static void test_fpush_lazy_release(void **state)
{
    (void)state;
    ulam_csr *M = rmat_graph_fix(16, 0.85, 3, 1), *Mt = NULL;
    assert_non_null(M);
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    int64_t n = M->nrows, K = 100, s = 0, idx[100], idx2[100];
    while (Mt->rowptr[s + 1] - Mt->rowptr[s] < 2) s++; /* a state with out-edges */
    ulam_guard g;
    char path[] = "/tmp/ulam_test_releaseXXXXXX";
    must_prepare(M, path, &g);
    double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y);
    double se[100], lo[100], hi[100], se2[100], lo2[100], hi2[100];
    ulam_fpush_opts o = ulam_fpush_defaults();
    o.source = s, o.walk.exec.seed = 3, o.walk.policy.guard = &g;
    ulam_fpush_info info, info2;
    ulam__sweep_info sw;
    ulam_error err;
    assert_int_equal(ulam__fpush_top(M, Mt, &o, K, x, idx, se, lo, hi, &info, &sw, &err), ULAM_OK);
    assert_true(sw.pulls > 0 && info.walks > 0);
    for (int keep = 0; keep < 2; keep++) { /* given back (keep 0 bytes); the default keep */
        ulam_system *sys = NULL;
        assert_int_equal(ulam_system_open(path, NULL, &sys, &err), ULAM_OK);
        if (keep == 0) { /* the whole check alone gives its stretches back */
            ulam__system_set_keep(sys, 0);
            assert_int_equal(ulam_system_check(sys, &err), ULAM_OK);
            ulam_system_info sc;
            ulam_system_get_info(sys, &sc);
            long long ck = mapping_rss_kb(sc.map);
            print_message("after the whole check: %lld kB resident of %lld kB\n", ck, (long long)(sc.map_bytes >> 10));
            assert_true(ck >= 0 && ck * 1024 * 8 < (long long)sc.map_bytes);
        }
        const ulam_csr *LM = NULL;
        assert_int_equal(ulam_system_lazy(sys, &LM, NULL), ULAM_OK);
        ulam_fpush_opts ol = o;
        ol.walk.policy.system = sys;
        assert_int_equal(ulam_fpush_top(LM, NULL, &ol, K, y, idx2, se2, lo2, hi2, &info2, &err), ULAM_OK);
        ulam_system_info si;
        ulam_system_get_info(sys, &si);
        long long kb = mapping_rss_kb(si.map);
        print_message("keep %s: %lld walks; the mapping's resident set %lld kB of %lld kB\n", keep ? "default" : "0",
                      (long long)info2.walks, kb, (long long)(si.map_bytes >> 10));
        assert_int_equal(info2.walks, info.walks);
        assert_memory_equal(idx2, idx, sizeof idx);
        assert_memory_equal(se2, se, sizeof se), assert_memory_equal(lo2, lo, sizeof lo), assert_memory_equal(hi2, hi, sizeof hi);
        assert_true(kb >= 0);
        if (keep == 0) assert_true(kb * 1024 * 8 < (long long)si.map_bytes);
        else assert_true(kb * 1024 * 2 > (long long)si.map_bytes);
        ulam_system_free(sys);
    }
    remove(path);
    free(x), free(y);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fpush_rule),
        cmocka_unit_test(test_fpush_rmat_cut),
        cmocka_unit_test(test_fpush_topk_negative),
        cmocka_unit_test(test_fpush_topk),
        cmocka_unit_test(test_fpush_lazy_release),
    };
    return test_run(tests);
}
