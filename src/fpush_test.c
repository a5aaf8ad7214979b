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
 * random, multi-edges summed), M = alpha P'. */
static ulam_csr *rmat_graph(int L, double alpha, uint64_t seed)
{
    int64_t n = (int64_t)1 << L, m = 8 * n, *out = calloc((size_t)n, sizeof *out);
    int32_t *ti = malloc((size_t)m * sizeof *ti), *tj = malloc((size_t)m * sizeof *tj), *perm = malloc((size_t)n * sizeof *perm);
    double *tx = malloc((size_t)m * sizeof *tx);
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
    for (int64_t e = 0; e < m; e++) tx[e] = alpha / (double)out[tj[e]];
    if (ulam_csr_from_triplets(n, n, m, ti, tj, tx, &M)) M = NULL;
    free(out), free(ti), free(tj), free(perm), free(tx);
    return M;
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fpush_rule),
        cmocka_unit_test(test_fpush_rmat_cut),
    };
    return test_run(tests);
}
