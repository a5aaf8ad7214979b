/* Printed 95% intervals at every budget (issue 25): coverage over 100 seeds on systems with a
 * rarely reached part, at fixed walk counts, at round counts the test picks (a clock's stop),
 * and under --rel-err, with a binomial bound (at least 89 of 100: 95% coverage fails it with
 * probability under 2%).  An interval withheld is honest and counted so; an answer missing is
 * not.  Every system is generated here.
 *
 * metastable(leak): 40 states; cluster A (states 0..19, b = 1) has rows of M summing to exactly
 * 0.95, so every absorption score in A is 20; state 0 leaks `leak` into cluster B (states
 * 20..39, b = 10, rows summing to 0.9995), which a walk from state 0 reaches with probability
 * about `leak` and where it then scores about 2e4.  At leak 1e-4, B holds 9% of x_0; a sample of
 * 1000 walks has seen B with probability 0.1, and its sample variance is then 0 (absorption) or
 * small: the old CLT interval covered 13/100 at 1000 walks.
 *
 * laplace(m): the m^3 Laplacian (7-point, Dirichlet) by its Jacobi splitting, b a point source
 * at the centre, the unknown at a corner, which walks reach rarely (x_0 about 1e-3). */
#include "testutil.h"

#include "bench/gen.h"

/* The metastable chain (bench/gen.h), its b (40 entries, malloc'd) and x_0 by LAPACK. */
static ulam_csr *metastable(double leak, double **b, double *x0)
{
    ulam_csr *M;
    assert_int_equal(bench_metastable(leak, &M, b), 0);
    double x[40];
    assert_int_equal(ulam_direct_solve(M, *b, x, 0, NULL, NULL), ULAM_OK);
    *x0 = x[0];
    return M;
}

/* The m^3 Laplacian's Jacobi splitting M, bp (malloc'd) and x at the corner (state 0). */
static ulam_csr *laplace(int m, double **bp, double *x0)
{
    int64_t n = (int64_t)m * m * m, cap = 7 * n, nz = 0;
    int32_t *ti = malloc((size_t)cap * sizeof *ti), *tj = malloc((size_t)cap * sizeof *tj);
    double *tx = malloc((size_t)cap * sizeof *tx), *b = calloc((size_t)n, sizeof *b);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++)
            for (int k = 0; k < m; k++) {
                int32_t r = (int32_t)((i * m + j) * m + k);
                ti[nz] = r, tj[nz] = r, tx[nz++] = 6.0;
                const int d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
                for (int q = 0; q < 6; q++) {
                    int a = i + d[q][0], c = j + d[q][1], e = k + d[q][2];
                    if (a < 0 || c < 0 || e < 0 || a >= m || c >= m || e >= m) continue;
                    ti[nz] = r, tj[nz] = (int32_t)((a * m + c) * m + e), tx[nz++] = -1.0;
                }
            }
    b[((m / 2) * m + m / 2) * m + m / 2] = 1.0;
    ulam_csr *A, *M;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A), ULAM_OK);
    *bp = malloc((size_t)n * sizeof **bp);
    assert_int_equal(ulam_jacobi(A, b, 1.0, &M, *bp, NULL), ULAM_OK);
    double *x = malloc((size_t)n * sizeof *x);
    assert_int_equal(ulam_direct_solve(M, *bp, x, 0, NULL, NULL), ULAM_OK);
    *x0 = x[0];
    free(ti), free(tj), free(tx), free(b), free(x);
    ulam_csr_free(A);
    return M;
}

/* A run's verdict on x: 1 its interval covers x, 0 it misses, 2 withheld (NaN).  A zero-width
 * interval fails the test at once unless x is 0 exactly (certified). */
static int verdict(const ulam_walk_result *r, double x)
{
    if (isnan(r->ci95[0]) || isnan(r->ci95[1])) return 2;
    if (!(r->ci95[1] > r->ci95[0]) && x != 0.0)
        print_error("zero-width interval %.17g .. %.17g at x = %.17g (%lld walks)\n", r->ci95[0], r->ci95[1], x,
                    (long long)r->walks);
    assert_true(r->ci95[1] > r->ci95[0] || x == 0.0);
    return r->ci95[0] <= x && x <= r->ci95[1];
}

/* The count over 100 seeds: honest (covered or withheld) at least 89 (fail below). */
static void count(const char *what, int covered, int withheld, int R)
{
    int lower = (int)ceil(0.95 * R - 3 * sqrt(0.0475 * R)); /* 89 of 100 */
    print_message("%-44s covered %3d, withheld %3d of %d (honest at least %d)\n", what, covered, withheld, R, lower);
    if (test_case_all()) assert_true(covered + withheld >= lower);
}

/* Case 1 at fixed budgets: collision at 100, 1000 and 10^4 walks, absorption at 1000. */
static void test_metastable_fixed(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = metastable(1e-4, &b, &x);
    static const struct { int est; int64_t walks; } cases[] = {
        {ULAM_COLLISION, 100}, {ULAM_COLLISION, 1000}, {ULAM_COLLISION, 10000}, {ULAM_ABSORPTION, 1000}};
    for (int c = 0; c < 4; c++) {
        int v[3] = {0, 0, 0};
        for (int s = 0; s < 100; s++) {
            if (!test_case(1000L * c + s)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = cases[c].est, o.stop.max_walks = cases[c].walks, o.exec.seed = 1 + (uint64_t)s;
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            v[verdict(&r, x)]++;
        }
        test_case_done();
        char what[64];
        snprintf(what, sizeof what, "metastable %s, %lld walks:", cases[c].est ? "absorption" : "collision",
                 (long long)cases[c].walks);
        count(what, v[1], v[2], 100);
    }
    ulam_csr_free(M), free(b);
}

/* Case 1 under the method auto chooses (pilots, then the chosen solver) at 1000 walks, where a
 * pilot that never reached B has variance 0 and the old choice preferred it (13/100). */
static void test_metastable_auto(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = metastable(1e-4, &b, &x);
    int v[3] = {0, 0, 0};
    for (int s = 0; s < 100; s++) {
        if (!test_case(s)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.stop.max_walks = 1000, o.exec.seed = 300 + (uint64_t)s;
        ulam_auto_result res;
        ulam_solver *sv = NULL;
        assert_int_equal(ulam_auto_solver(M, b, &o, NULL, &res, &sv, NULL), ULAM_OK);
        while (!ulam_solver_done(sv)) assert_int_equal(ulam_solver_iterate(sv), ULAM_OK);
        ulam_walk_result r;
        ulam_solver_result(sv, &r);
        v[verdict(&r, x)]++;
        ulam_solver_free(sv);
    }
    test_case_done();
    count("metastable auto, 1000 walks:", v[1], v[2], 100);
    ulam_csr_free(M), free(b);
}

/* Case 1 stopped after a number of rounds the test picks per seed (1 to 6: 1024 to 64512 walks),
 * as a clock would stop it, with max_seconds set so the run knows its stop is not fixed. */
static void test_metastable_rounds(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = metastable(1e-4, &b, &x);
    int v[3] = {0, 0, 0};
    for (int s = 0; s < 100; s++) {
        if (!test_case(s)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.stop.max_walks = 0, o.stop.max_seconds = 1e9, o.exec.seed = 100 + (uint64_t)s;
        ulam_solver *sv;
        assert_int_equal(ulam_solver_alloc(M, b, &o, &sv, NULL), ULAM_OK);
        for (int k = 0; k < 1 + s % 6; k++) assert_int_equal(ulam_solver_iterate(sv), ULAM_OK);
        ulam_walk_result r;
        ulam_solver_result(sv, &r);
        v[verdict(&r, x)]++;
        ulam_solver_free(sv);
    }
    test_case_done();
    count("metastable collision, 1 to 6 rounds:", v[1], v[2], 100);
    ulam_csr_free(M), free(b);
}

/* Case 2: the leak at 1e-5 (B holds under 1% of x_0, less than the target) under rel_err 0.1,
 * by absorption and by collision (whose stop the range term decides): every run met, its
 * interval covers. */
static void test_metastable_rel_err(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = metastable(1e-5, &b, &x);
    for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
        int v[3] = {0, 0, 0};
        double walks = 0;
        for (int s = 0; s < 100; s++) {
            if (!test_case(1000L * est + s)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = est, o.stop.max_walks = 0, o.stop.rel_err = 0.1, o.exec.seed = 1 + (uint64_t)s;
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            assert_true(r.rel_err_met);
            v[verdict(&r, x)]++;
            walks += (double)r.walks;
        }
        test_case_done();
        print_message("mean walks %.3g\n", walks / 100);
        count(est ? "metastable 1e-5, absorption, rel_err 0.1:" : "metastable 1e-5, collision, rel_err 0.1:", v[1],
              v[2], 100);
    }
    ulam_csr_free(M), free(b);
}

/* Cases 4 and 5: the 15^3 Laplacian's corner.  At 1000 walks (collision and absorption) the
 * intervals are honest; under rel_err 0.1 with a budget of 2^17 walks, no run ends on a zero
 * estimate with a zero-width interval or "out of reach". */
static void test_laplace_corner(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = laplace(15, &b, &x);
    print_message("x_corner = %.6g\n", x);
    for (int c = 0; c < 2; c++) {
        int v[3] = {0, 0, 0};
        for (int s = 0; s < 100; s++) {
            if (!test_case(1000L * c + s)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = c ? ULAM_ABSORPTION : ULAM_COLLISION, o.stop.max_walks = 1000, o.exec.seed = 1 + (uint64_t)s;
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            v[verdict(&r, x)]++;
        }
        test_case_done();
        count(c ? "laplace corner absorption, 1000 walks:" : "laplace corner collision, 1000 walks:", v[1], v[2], 100);
    }
    for (int s = 0; s < 10; s++) {
        if (!test_case(2000L + s)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.stop.max_walks = 1 << 17, o.stop.rel_err = 0.1, o.exec.seed = 1 + (uint64_t)s;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        print_message("rel_err seed %d: %.4g [%.4g, %.4g] %lld walks, met %d, out of reach %d (needs %.3g)\n", s,
                      r.estimate, r.ci95[0], r.ci95[1], (long long)r.walks, r.rel_err_met, r.out_of_reach, r.min_walks);
        assert_true(!(r.estimate == 0 && r.out_of_reach));
        assert_true(verdict(&r, x) != 0);
    }
    test_case_done();
    ulam_csr_free(M), free(b);
}

/* A sample that has not seen a reachable class gets an interval that is not zero-width and
 * still covers; an answer certified exact (nothing that scores reachable) gets [0, 0]. */
static void test_never_zero_width(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = metastable(1e-4, &b, &x);
    for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.estimator = est, o.stop.max_walks = 100, o.exec.seed = 3;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        print_message("100 walks, %s: %.6g [%.6g, %.6g], variance %g\n", est ? "absorption" : "collision", r.estimate,
                      r.ci95[0], r.ci95[1], r.variance);
        assert_true(r.ci95[1] - r.ci95[0] > 1.0 && r.ci95[0] <= x && x <= r.ci95[1]);
    }
    for (int i = 20; i < 40; i++) b[i] = 0.0; /* from B only B is reachable: x_20 = 0, certified */
    for (int i = 0; i < 20; i++) b[i] = 0.0;
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 25, o.stop.max_walks = 100;
    ulam_walk_result r;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
    assert_true(r.estimate == 0 && r.ci95[0] == 0 && r.ci95[1] == 0);
    ulam_csr_free(M), free(b);
}

/* The cost of --rel-err (issue 38 point 5: the printed 95% interval's half-width at most E |x|,
 * bought at most 3x the walks a CLT interval of that width needs, (1.96 / E)^2 var / x^2):
 * signed200 by collision at E = 0.01, where the scores' certified range is ~27 standard
 * deviations, seed 1; the oracle's variance from 2^18 walks of a fixed run.  The stitched
 * empirical-Bernstein interval this replaced stopped on the standard error: 1.6x var / (E x)^2
 * walks, and a printed half-width of 4-9 E |x|. */
static void test_rel_err_cost(void **state)
{
    (void)state;
    ulam_csr *M = must_read("matrices/signed200.mtx");
    int64_t n;
    double *b = must_read_vector("matrices/signed200_b.mtx", &n), *x = malloc((size_t)n * sizeof *x), E = 0.01;
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    ulam_walk_opts o = ulam_walk_defaults();
    o.estimator = ULAM_COLLISION, o.stop.max_walks = 1 << 18, o.exec.seed = 12345;
    ulam_walk_result r;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
    double oracle = 1.96 * 1.96 * r.variance / (E * x[0] * E * x[0]);
    o.stop.max_walks = 0, o.stop.rel_err = E, o.exec.seed = 1;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
    double half = (r.ci95[1] - r.ci95[0]) / 2;
    print_message("signed200 collision, rel_err %g: %lld walks, CLT oracle %.4g (%.3gx), half-width %.3g E |x|\n", E,
                  (long long)r.walks, oracle, (double)r.walks / oracle, half / (E * fabs(r.estimate)));
    assert_true(r.rel_err_met && r.ci95[0] <= x[0] && x[0] <= r.ci95[1]);
    assert_true(half <= E * fabs(r.estimate));
    assert_true((double)r.walks <= 3.0 * oracle);
    ulam_csr_free(M), free(b), free(x);
}

/* Cost case 6 (bench/gen.h, n = 2000): b = +-0.1 and one entry 1000 that walks from state 0
 * reach with weight ~1e-15.  Absorption walks pay for it in their range (x1000 of the oracle
 * var / (E x)^2 at E = 0.1 on the n = 2e4 system); the bidirectional row with a dense b pushes b
 * first (src/bpush.c) and its walks score a residual of at most 0.1: within 3x of the oracle at
 * seed 1, and its intervals cover over 100 seeds (at least 89).  The row refused a dense b before. */
static void test_push_b(void **state)
{
    (void)state;
    ulam_csr *M;
    double *b = NULL, E = 0.1;
    assert_int_equal(bench_case6(2000, 1e-6, 1000.0, 6, &M, &b), 0);
    double *xs = bench_neumann(M, b), x = xs[0];
    free(xs);
    ulam_walk_opts o = ulam_walk_defaults();
    o.estimator = ULAM_ABSORPTION, o.stop.max_walks = 1 << 18, o.exec.seed = 12345;
    ulam_walk_result r;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
    double oracle = r.variance / (E * x * E * x);
    ulam_method_opts mo = ulam_method_defaults();
    mo.method = ULAM_METHOD_BIDIRECTIONAL;
    ulam_auto_opts ao = ulam_auto_defaults();
    ao.pin_estimator = 1;
    int v[3] = {0, 0, 0};
    for (int s = 0; s < 100; s++) {
        if (!test_case(s)) continue;
        o.stop.max_walks = 0, o.stop.rel_err = E, o.exec.seed = 1 + (uint64_t)s;
        ulam_answer a;
        ulam_error err;
        int status = ulam_auto(M, b, &o, &ao, &mo, NULL, &a, &err);
        if (status) print_error("seed %d: %s\n", s + 1, err.msg);
        assert_int_equal(status, ULAM_OK);
        assert_int_equal(a.method, ULAM_METHOD_BIDIRECTIONAL);
        assert_true(a.walks.rel_err_met);
        if (s == 0) {
            print_message("case 6, n = 2000, push on b + absorption: %lld walks, oracle %.4g (%.3gx), push %lld ops\n",
                          (long long)a.walks.walks, oracle, (double)a.walks.walks / oracle,
                          (long long)a.bidir.plan.push.ops);
            assert_true((double)a.walks.walks <= 3.0 * fmax(oracle, 1024.0));
        }
        ulam_walk_result w = a.walks;
        w.ci95[0] = a.ci95[0], w.ci95[1] = a.ci95[1];
        v[verdict(&w, x)]++;
    }
    test_case_done();
    count("case 6 n = 2000, push on b, rel_err 0.1:", v[1], v[2], 100);
    ulam_csr_free(M), free(b);
}

/* Case 4, the noisy b: the 15^3 Laplacian's point source plus a small positive noise everywhere
 * (b_i + 10^-3 u_i, u uniform, seed 7), the corner unknown, method auto under rel_err 0.1 (a
 * budget of 2^17 walks): auto chose forward mode for the one corner unknown and about half the
 * runs, no forward walk having tallied it, returned no estimate (NaN).  Every run must answer
 * (a withheld interval is honest, a missing answer is not), and its interval cover or be
 * withheld. */
static void test_laplace_noisy_auto(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = laplace(15, &b, &x);
    int64_t n = 15 * 15 * 15;
    ulam_rng g;
    ulam_rng_seed(&g, 7, 0);
    for (int64_t i = 0; i < n; i++) b[i] += 1e-3 * ulam_rng_uniform(&g) / 6.0; /* Jacobi's b: A's over 6 */
    double *xs = malloc((size_t)n * sizeof *xs);
    assert_int_equal(ulam_direct_solve(M, b, xs, 0, NULL, NULL), ULAM_OK);
    x = xs[0];
    free(xs);
    int v[3] = {0, 0, 0}, missing = 0, forward = 0;
    for (int s = 0; s < 20; s++) {
        if (!test_case(3000L + s)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.stop.max_walks = 1 << 17, o.stop.rel_err = 0.1, o.exec.seed = 40 + (uint64_t)s;
        ulam_auto_result res;
        ulam_solver *sv = NULL;
        assert_int_equal(ulam_auto_solver(M, b, &o, NULL, &res, &sv, NULL), ULAM_OK);
        int status = ULAM_OK;
        while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
        assert_int_equal(status, ULAM_OK);
        ulam_walk_result r;
        ulam_solver_result(sv, &r);
        forward += res.chosen >= 0 && res.cand[res.chosen].mode == ULAM_FORWARD;
        if (!isfinite(r.estimate)) missing++;
        else v[verdict(&r, x)]++;
        ulam_solver_free(sv);
    }
    test_case_done();
    print_message("laplace noisy b, auto rel_err 0.1: x = %.6g, forward chosen %d, no estimate %d of 20\n", x, forward,
                  missing);
    assert_int_equal(missing, 0);
    count("laplace noisy b, auto rel_err 0.1:", v[1], v[2], 20);
    ulam_csr_free(M), free(b);
}

/* A random doubly substochastic M (n states, 8 weighted random permutations, every row and
 * column summing to 0.9, as matrices/randsub1000) with b_i = 0.5 + U(0, 1), or (signed) 8
 * random columns a row with random signs and rows of |M| summing to 0.8 (as signed200: its
 * column sums vary, so forward weights grow and only a second moment bounds their tallies) with
 * b_i = U(-0.5, 1); x by LAPACK (malloc'd). */
static ulam_csr *forward_system(int64_t n, int sign, uint64_t seed, double **bp, double **xp)
{
    int64_t nz = 8 * n;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj), *perm = malloc((size_t)n * sizeof *perm);
    double *tx = malloc((size_t)nz * sizeof *tx), w[8], sum = 0.0;
    ulam_rng g;
    ulam_rng_seed(&g, seed, 0);
    for (int k = 0; k < 8; k++) sum += w[k] = 0.1 + ulam_rng_uniform(&g);
    for (int k = 0; k < 8; k++) {
        bench_permutation(perm, n, &g);
        for (int64_t i = 0; i < n; i++) {
            int64_t e = k * n + i;
            ti[e] = (int32_t)i, tj[e] = sign ? (int32_t)ulam_rng_bounded(&g, (uint64_t)n) : perm[i];
            tx[e] = sign ? (0.1 + ulam_rng_uniform(&g)) * (ulam_rng_uniform(&g) < 0.5 ? -1.0 : 1.0) : 0.9 * w[k] / sum;
        }
    }
    if (sign) { /* rows of |M| to 0.8 (a column drawn twice in a row sums: |M|'s row sum only falls) */
        double *rs = calloc((size_t)n, sizeof *rs);
        for (int64_t e = 0; e < nz; e++) rs[ti[e]] += fabs(tx[e]);
        for (int64_t e = 0; e < nz; e++) tx[e] *= 0.8 / rs[ti[e]];
        free(rs);
    }
    ulam_csr *M;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M), ULAM_OK);
    double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
    for (int64_t i = 0; i < n; i++) b[i] = sign ? ulam_rng_uniform(&g) * 1.5 - 0.5 : 0.5 + ulam_rng_uniform(&g);
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    free(ti), free(tj), free(tx), free(perm);
    *bp = b, *xp = x;
    return M;
}

/* Forward-mode --rel-err's cost (issue 25: at most 3x the walks the variance asks, var / (E x)^2,
 * var the forward tallies' own from 2^17 walks): a forward walk starts with weight ||b||_1, so its
 * certified range against a small x_i asked 33x the oracle on randsub1000 at E = 0.1, and the
 * signed system (forward weights grow: a second-moment range) stopped "not met" at its first
 * round predicting 4e9 walks.  Both by collision at seed 1: met within 3 max(oracle, 1024) walks;
 * and over 100 seeds each (a few thousand walks a run) the printed intervals cover (at least 89). */
static void test_forward_rel_err(void **state)
{
    (void)state;
    for (int sign = 0; sign < 2; sign++) {
        int64_t n = sign ? 200 : 400;
        double *b, *x, E = 0.1;
        ulam_csr *M = forward_system(n, sign, 11 + (uint64_t)sign, &b, &x);
        ulam_walk_opts o = ulam_walk_defaults();
        o.mode = ULAM_FORWARD, o.query.index = 0, o.stop.max_walks = 1 << 17, o.exec.seed = 12345;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        double oracle = r.variance / (E * x[0] * E * x[0]);
        int v[3] = {0, 0, 0};
        for (int s = 0; s < 100; s++) {
            if (!test_case(4000L + 100L * sign + s)) continue;
            o.stop.max_walks = 0, o.stop.rel_err = E, o.exec.seed = 1 + (uint64_t)s;
            ulam_error err;
            int status = ulam_solve_walks(M, b, &o, &r, &err);
            if (status) print_error("seed %d: %s\n", s + 1, err.msg);
            assert_int_equal(status, ULAM_OK);
            if (s == 0) {
                print_message("%s n = %lld forward collision, rel_err %g: %s after %lld walks, oracle %.4g (%.3gx), "
                              "x_0 = %.6g, estimate %.6g\n", sign ? "signed" : "doubly substochastic", (long long)n, E,
                              r.rel_err_met ? "met" : "NOT met", (long long)r.walks, oracle, (double)r.walks / oracle,
                              x[0], r.estimate);
                assert_true(r.rel_err_met);
                assert_true((double)r.walks <= 3.0 * fmax(oracle, 1024.0));
            }
            v[verdict(&r, x[0])]++;
        }
        test_case_done();
        count(sign ? "signed forward rel_err 0.1:" : "doubly substochastic forward rel_err 0.1:", v[1], v[2], 100);
        ulam_csr_free(M), free(b), free(x);
    }
}

/* Forward expected-value walks print an interval (issue 38): a visit to state s tallies
 * w M_{i,s} at the unknown i, so one visit scores at most W max_s |M_{i,s}| and the collision
 * estimator's length-tail bounds apply.  Before, that per-visit score was taken as unbounded and
 * the interval was withheld on every seed.  Over 100 seeds, on the doubly substochastic and the
 * signed forward systems at 1000 and 10^4 walks and under rel_err 0.1, and on the metastable
 * chain (its rarely reached cluster) at 1000 walks: at least 89 of 100 intervals
 * printed and covering (before: 0 printed). */
static void test_forward_expected(void **state)
{
    (void)state;
    for (int k = 0; k < 3; k++) {
        double *b, *x, x0;
        ulam_csr *M = k < 2 ? forward_system(k ? 200 : 400, k, 11 + (uint64_t)k, &b, &x) : metastable(1e-4, &b, &x0);
        if (k < 2) x0 = x[0], free(x);
        for (int w = 0; w < (k < 2 ? 3 : 1); w++) { /* the chain: 1000 walks (its rel_err run needs ~1e9 steps) */
            int v[3] = {0, 0, 0}, R = 100;
            for (int s = 0; s < R; s++) {
                if (!test_case(9000L + 1000L * k + 100L * w + s)) continue;
                ulam_walk_opts o = ulam_walk_defaults();
                o.mode = ULAM_FORWARD, o.estimator = ULAM_EXPECTED, o.query.index = 0, o.exec.seed = 1 + (uint64_t)s;
                if (w < 2) o.stop.max_walks = w ? 10000 : 1000;
                else o.stop.max_walks = 0, o.stop.rel_err = 0.1;
                ulam_walk_result r;
                ulam_error err;
                int status = ulam_solve_walks(M, b, &o, &r, &err);
                if (status) print_error("case %d: %s\n", 9000 + 1000 * k + 100 * w + s, err.msg);
                assert_int_equal(status, ULAM_OK);
                v[verdict(&r, x0)]++;
            }
            test_case_done();
            char what[80];
            snprintf(what, sizeof what, "forward expected, %s, %s:", k == 0 ? "substochastic" : k == 1 ? "signed" : "metastable",
                     w == 0 ? "1000 walks" : w == 1 ? "10^4 walks" : "rel_err 0.1");
            int lower = (int)ceil(0.95 * R - 3 * sqrt(0.0475 * R));
            print_message("%-50s covered %3d, withheld %3d of %d (printed and covering at least %d)\n", what, v[1], v[2], R, lower);
            if (test_case_all()) assert_true(v[1] >= lower);
        }
        ulam_csr_free(M), free(b);
    }
}

/* Scale: b times 2^-1000 or 2^1000 is walked on b scaled by a power of 2 (exact), so a forward
 * --rel-err run must stop where the run on b stops, with the same walks and the interval scaled.
 * Before, the rule was checked on the result already scaled back (estimate 1e-300) against the
 * bounds of the walked scale (~1): the rule was never met, and the run walked to its budget
 * (10^9 by default, 48 s; here 2^20) "NOT met" where the run on b met at 1024 walks. */
static void test_forward_rel_err_scale(void **state)
{
    (void)state;
    int64_t n = 200;
    double *b, *x;
    ulam_csr *M = forward_system(n, 1, 12, &b, &x);
    double *bs = malloc((size_t)n * sizeof *bs);
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = ULAM_FORWARD, o.query.index = 0, o.stop.rel_err = 0.1, o.stop.max_walks = (int64_t)1 << 20, o.exec.seed = 7;
    ulam_walk_result r0, r;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r0, NULL), ULAM_OK);
    assert_true(r0.rel_err_met && r0.walks < o.stop.max_walks);
    for (int e = -1000; e <= 1000; e += 2000) {
        for (int64_t i = 0; i < n; i++) bs[i] = ldexp(b[i], e);
        assert_int_equal(ulam_solve_walks(M, bs, &o, &r, NULL), ULAM_OK);
        print_message("b 2^%d: %s after %lld walks (b: %lld)\n", e, r.rel_err_met ? "met" : "NOT met", (long long)r.walks,
                      (long long)r0.walks);
        assert_true(r.rel_err_met);
        assert_int_equal(r.walks, r0.walks);
        assert_true(r.estimate == ldexp(r0.estimate, e) && r.ci95[0] == ldexp(r0.ci95[0], e) && r.ci95[1] == ldexp(r0.ci95[1], e));
    }
    free(bs), ulam_csr_free(M), free(b), free(x);
}

/* est's walks over the CLT's count at rel_err 0.1 over 100 seeds (test cases case0 + seed), the
 * median (v: the verdicts), every run met within 0.1 |estimate|; the CLT count's variance from a
 * fixed run of 2^18 walks. */
static double rel_err_median_of(const ulam_csr *M, const double *b, double x, int est, long case0, const char *what, int v[3],
                                int R);

static double rel_err_median(const ulam_csr *M, const double *b, double x, int est, long case0, const char *what, int v[3])
{
    return rel_err_median_of(M, b, x, est, case0, what, v, 100);
}

/* rel_err_median over R <= 100 seeds. */
static double rel_err_median_of(const ulam_csr *M, const double *b, double x, int est, long case0, const char *what, int v[3],
                                int R)
{
    ulam_walk_opts o = ulam_walk_defaults();
    o.estimator = est, o.stop.max_walks = 1 << 18, o.exec.seed = 12345;
    ulam_walk_result r;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
    double clt = 1.96 * 1.96 * r.variance / (0.1 * x * 0.1 * x), ratio[100];
    int ran = 0;
    for (int s = 0; s < R; s++) {
        if (!test_case(case0 + s)) continue;
        o.stop.max_walks = 0, o.stop.rel_err = 0.1, o.exec.seed = 1 + (uint64_t)s;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        assert_true(r.rel_err_met && (r.ci95[1] - r.ci95[0]) / 2 <= 0.1 * fabs(r.estimate));
        v[verdict(&r, x)]++;
        ratio[ran++] = (double)r.walks / clt;
    }
    test_case_done();
    for (int i = 1; i < ran; i++) /* insertion sort: the median */
        for (int j = i; j > 0 && ratio[j] < ratio[j - 1]; j--) {
            double t = ratio[j];
            ratio[j] = ratio[j - 1], ratio[j - 1] = t;
        }
    print_message("%s, rel_err 0.1: CLT count %.4g, walks / CLT median %.3g (%.3g .. %.3g)\n", what, clt,
                  ran ? ratio[ran / 2] : NAN, ran ? ratio[0] : NAN, ran ? ratio[ran - 1] : NAN);
    return ran ? ratio[ran / 2] : NAN;
}

/* A zero running estimate (issue 25: "runs that cannot meet a target say so early ... never
 * spin silently"): upwind convection-diffusion 30 x 30 (bench/gen.h, c = 1) by its Jacobi
 * splitting, a point source at the centre, the upstream corner x_0 = 1.1e-11, which a walk
 * from it reaches about never (the flow carries it off the grid in ~1 step).  No walk scores,
 * so the rule cannot be met: before, a --rel-err 0.1 run walked to its budget (here 2^22) or,
 * alone, to the 10^9 cap (~400 s).  Now src/hit.c bounds the chance a walk scores at all, the
 * rule needs at least (1 / p - 1) / E^2 walks, and the run stops "not met" once that passes the
 * budget: within 2^20 walks in both cases, for collision and absorption, seeds 1..3, its printed
 * interval covering the exact x_0 (a direct solve) and its min_walks past the budget. */
static void test_zero_estimate_stops(void **state)
{
    (void)state;
    ulam_csr *A = bench_convdiff(30, 1.0), *M;
    double one[900], b[900], x[900];
    for (int i = 0; i < 900; i++) one[i] = i == 15 * 30 + 15 ? 1.0 : 0.0;
    assert_int_equal(ulam_jacobi(A, one, 1.0, &M, b, NULL), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    assert_true(x[0] > 0 && x[0] < 1e-10);
    for (int c = 0; c < 12; c++) {
        if (!test_case(5000L + c)) continue;
        int est = c % 2 ? ULAM_ABSORPTION : ULAM_COLLISION;
        int64_t budget = c / 6 ? 0 : (int64_t)1 << 22; /* a budget first: the old run fails fast */
        ulam_walk_opts o = ulam_walk_defaults();
        o.estimator = est, o.stop.rel_err = 0.1, o.stop.max_walks = budget, o.exec.seed = 1 + (uint64_t)(c / 2 % 3);
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        if (c % 6 == 0 || c % 6 == 1)
            print_message("convdiff upstream corner, %s, rel_err 0.1, %s: %lld walks, estimate %g, CI [%g, %g], "
                          "min_walks %.4g, out of reach %d\n", est ? "absorption" : "collision",
                          budget ? "budget 2^22" : "alone", (long long)r.walks, r.estimate, r.ci95[0], r.ci95[1],
                          r.min_walks, r.out_of_reach);
        assert_false(r.rel_err_met);
        assert_true(r.out_of_reach);
        assert_true(r.walks <= (int64_t)1 << 20);
        assert_true(r.min_walks > (budget ? (double)budget : 1e9));
        assert_true(r.ci95[0] <= x[0] && x[0] <= r.ci95[1]);
    }
    test_case_done();
    ulam_csr_free(A), ulam_csr_free(M);
}

static ulam_csr *hard38(int k, double **b, double *x0)
{
    ulam_csr *M = NULL;
    if (k == 0) assert_int_equal(bench_signed(200, 5, &M, b), 0);
    if (k == 1) assert_int_equal(bench_hub(200, 0.99, 5, &M, b), 0);
    if (k == 2) assert_int_equal(bench_convdiff_b(30, 5.0, 0.5, 5, &M, b), 0);
    double *x = malloc((size_t)M->nrows * sizeof *x);
    assert_int_equal(ulam_direct_solve(M, *b, x, 0, NULL, NULL), ULAM_OK);
    *x0 = x[0];
    free(x);
    return M;
}

/* Issue 38 point 5: --rel-err E means the printed interval's half-width is at most E |estimate|
 * (the stitched interval stopped on the standard error and printed 3-9 E |x|), bought at most 3x
 * the walks a CLT interval of that width needs, (1.96 / E)^2 var / x^2 (var from a fixed run of
 * 2^18 walks).  Collision walks on issue 38's systems: at E = 0.1 over 40 seeds each, every run
 * met with its half-width within E |estimate| and the intervals cover (honest at least 34 of 40:
 * 95% coverage fails that with probability under 2%); at E = 0.01, seed 1, the signed system and
 * the hub within 3x of the CLT oracle (convection-diffusion, whose certified range is ~400
 * standard deviations, is printed, not held to it: 4x). */
static void test_rel_err_width_hard(void **state)
{
    (void)state;
    static const char *name[3] = {"signed200", "hub0.99", "convdiff30"};
    for (int k = 0; k < 3; k++) {
        double *b, x;
        ulam_csr *M = hard38(k, &b, &x);
        ulam_walk_opts o = ulam_walk_defaults();
        o.stop.max_walks = 1 << 18, o.exec.seed = 12345;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        double var = r.variance;
        int v[3] = {0, 0, 0}, R = 40;
        for (int s = 0; s < R; s++) {
            if (!test_case(6000L + 100L * k + s)) continue;
            o.stop.max_walks = 0, o.stop.rel_err = 0.1, o.exec.seed = 1 + (uint64_t)s;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            double half = (r.ci95[1] - r.ci95[0]) / 2;
            if (!(r.rel_err_met && half <= 0.1 * fabs(r.estimate)))
                print_error("%s seed %d: met %d, half-width %.3g E |estimate|\n", name[k], s + 1, r.rel_err_met,
                            half / (0.1 * fabs(r.estimate)));
            assert_true(r.rel_err_met && half <= 0.1 * fabs(r.estimate));
            v[verdict(&r, x)]++;
        }
        test_case_done();
        char what[64];
        snprintf(what, sizeof what, "%s collision, rel_err 0.1:", name[k]);
        int lower = (int)ceil(0.95 * R - 3 * sqrt(0.0475 * R));
        print_message("%-44s covered %3d, withheld %3d of %d (honest at least %d)\n", what, v[1], v[2], R, lower);
        if (test_case_all()) assert_true(v[1] + v[2] >= lower);
        if (test_case(6500L + k)) {
            double E = 0.01, clt = 1.96 * 1.96 * var / (E * x * E * x);
            o.stop.rel_err = E, o.exec.seed = 1;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            print_message("%s collision, rel_err 0.01: %lld walks, CLT oracle %.4g (%.3gx), half-width %.3g E |x|\n",
                          name[k], (long long)r.walks, clt, (double)r.walks / clt,
                          (r.ci95[1] - r.ci95[0]) / 2 / (E * fabs(r.estimate)));
            assert_true(r.rel_err_met && (r.ci95[1] - r.ci95[0]) / 2 <= E * fabs(r.estimate));
            assert_true(r.ci95[0] <= x && x <= r.ci95[1]);
            if (k < 2) assert_true((double)r.walks <= 3.0 * clt);
        }
        test_case_done();
        ulam_csr_free(M), free(b);
    }
}

/* Issue 38 point 8 where the CLT's count is a few hundred walks: the hub at 0.99 under --rel-err
 * 0.1, collision (CLT count ~380) and absorption (~96), 100 seeds each.  The sequence holds at
 * every count, so the rule checks from a first round of 256 walks on, in rounds of the walks it
 * predicts, at least 16 (solve.c's REL_STEP): the median walks over the CLT's count at most 3
 * (before: a whole first block and whole blocks, 2048 walks or more for collision, 5.4x, and 1024
 * for absorption, 10.7x; then rounds of at least 64 walks, absorption 3.34x: 256 + 64 walks where
 * 256 + 16 do; collision 2.81x, 2.8 now), every run met within E |estimate|, and honest at least 89
 * of 100 (95% coverage fails that with probability under 1%). */
static void test_rel_err_small_counts(void **state)
{
    (void)state;
    double *b, x;
    ulam_csr *M = hard38(1, &b, &x);
    for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
        int v[3] = {0, 0, 0};
        double med = rel_err_median(M, b, x, est, 7000L + 100L * est, est ? "hub 0.99 absorption" : "hub 0.99 collision", v);
        if (test_case_all()) {
            count(est ? "hub 0.99, absorption, rel_err 0.1:" : "hub 0.99, collision, rel_err 0.1:", v[1], v[2], 100);
            assert_true(med <= 3.0);
        }
    }
    ulam_csr_free(M), free(b);
}

/* Collision on hard38's system k at rel_err 0.1 over 100 seeds from case case0 (rel_err_median):
 * honest at least 89 of 100 (count), the median walks over the CLT's count at most most. */
static void rel_err_held(int k, long case0, const char *name, double most)
{
    double *b, x;
    ulam_csr *M = hard38(k, &b, &x);
    int v[3] = {0, 0, 0};
    char what[64];
    snprintf(what, sizeof what, "%s collision", name);
    double med = rel_err_median(M, b, x, ULAM_COLLISION, case0, what, v);
    if (test_case_all()) {
        snprintf(what, sizeof what, "%s, collision, rel_err 0.1:", name);
        count(what, v[1], v[2], 100);
        assert_true(med <= most);
    }
    ulam_csr_free(M), free(b);
}

/* Issue 38 points 5 and 8: on upwind convection-diffusion 30 x 30 (cell Peclet 5 and 0.5, unknown
 * 1) the length tail's certificate has kappa = max v / min v ~ 1e12, so the range a --rel-err 0.1 run
 * clipped its collision scores at was ~400 standard deviations and the range term alone took 17x
 * the CLT's count of walks (median of 5 seeds).  The start's own tail (solve.c's tail_len) clips
 * at ~40: over 100 seeds every run met with its half-width within E |estimate|, honest at least
 * 89 of 100 (95% coverage fails that with probability under 1%), and the median walks over the
 * CLT's count at most 4 (it was 17). */
static void test_rel_err_convdiff(void **state)
{
    (void)state;
    rel_err_held(2, 7500L, "convdiff30", 4.0);
}

/* Issue 38 point 5 on the signed system (bench/gen.h's bench_signed, n = 200, rows of |M| at 0.8,
 * b = U(-0.5, 1), unknown 0): adjoint collision at rel_err 0.1 took 3.87x the CLT's count of walks
 * (bench_relerr, median of 5 seeds), its certified range 2 per_step (l + 1) at the l where the
 * length tail of |M| (0.8^k) leaves the bias share: ~30 steps where the walks average 4.  The
 * sequence now takes each walk's score over its first l + 1 visits, whose mean is off x by
 * |sum over k > l of (M^k b)_0|, certified from M's own signed powers (rho(M) ~ 0.35, not 0.8):
 * the same bias share at a third of the steps.  Over 100 seeds every run met with its half-width
 * within E |estimate|, honest at least 89 of 100, the median walks over the CLT's count at most 3. */
static void test_rel_err_signed(void **state)
{
    (void)state;
    rel_err_held(0, 7700L, "signed200", 3.0);
}

/* Issue 38 point 5 on the three clusters (bench/gen.h's bench_clusters at leak 1e-3, b on the last
 * cluster, unknown 0), absorption at rel_err 0.1: a walk scores only when it ends in the last
 * cluster, so the first ~3000 walks score nothing.  With no spread the plan bet from the prior
 * shrunk by the walks so far, near the cap (0.94), and the first hits, at the range's end, each
 * put psi(0.94) = 1.9 into the penalty: 35% of the final penalty from the first 3000 of 1.2e6
 * walks, 3.01x the CLT's count (bench_relerr, median of 5 seeds; here, against a CLT count from
 * 2^18 walks, 2.83 over these 30 seeds, 2.22 .. 4.02: it fails).  A rel_err run with no spread
 * yet now bets at the prior's variance alone (solve.c's cs_bet): over 30 seeds every run met with
 * its half-width within E |estimate|, honest at least 25 of 30 (95% coverage fails that with
 * probability under 1%; 30 of 30 cover), and the median walks over the CLT's count at most 2.5
 * (2.24 now, 2.04 .. 2.35). */
static void test_rel_err_clusters(void **state)
{
    (void)state;
    ulam_csr *M;
    double *b, x[60];
    assert_int_equal(bench_clusters(1e-3, &M, &b), 0);
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    int v[3] = {0, 0, 0}, R = 30;
    double med = rel_err_median_of(M, b, x[0], ULAM_ABSORPTION, 7800L, "clusters 1e-3 absorption", v, R);
    if (test_case_all()) {
        count("clusters 1e-3, absorption, rel_err 0.1:", v[1], v[2], R);
        assert_true(med <= 2.5);
    }
    ulam_csr_free(M), free(b);
}

/* Coverage at fixed budgets on issue 38's systems (collision, 100, 1000 and 10^4 walks, 40 seeds
 * each): the sequence tuned to the planned count holds there as at every count. */
static void test_fixed_hard(void **state)
{
    (void)state;
    static const char *name[3] = {"signed200", "hub0.99", "convdiff30"};
    for (int k = 0; k < 3; k++) {
        double *b, x;
        ulam_csr *M = hard38(k, &b, &x);
        for (int w = 0; w < 3; w++) {
            int v[3] = {0, 0, 0}, R = 40;
            for (int s = 0; s < R; s++) {
                if (!test_case(7000L + 1000L * k + 100L * w + s)) continue;
                ulam_walk_opts o = ulam_walk_defaults();
                o.stop.max_walks = w == 0 ? 100 : w == 1 ? 1000 : 10000, o.exec.seed = 1 + (uint64_t)s;
                ulam_walk_result r;
                assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
                v[verdict(&r, x)]++;
            }
            test_case_done();
            char what[64];
            snprintf(what, sizeof what, "%s collision, %d walks:", name[k], w == 0 ? 100 : w == 1 ? 1000 : 10000);
            int lower = (int)ceil(0.95 * R - 3 * sqrt(0.0475 * R));
            print_message("%-44s covered %3d, withheld %3d of %d (honest at least %d)\n", what, v[1], v[2], R, lower);
            if (test_case_all()) assert_true(v[1] + v[2] >= lower);
        }
        ulam_csr_free(M), free(b);
    }
}

/* A --rel-err target out of reach of a --walks budget (newuser18: --walks 50000 --rel-err 0.001 on
 * signed200 stopped at 1000 walks, 95% CI -1.10 .. 1.46, where --walks 10000 alone printed 0.096 ..
 * 0.154): the budget is walked, its bets planned for the budget once the target is past it, so the
 * interval is about the fixed count's; on issue 38's three systems at 10^4 walks and rel_err 0.001,
 * 40 seeds each: every run walks 10^4, honest at least 34 of 40, median half-width at most 1.5x
 * the fixed count's on the same seeds. */
static void test_rel_err_budget(void **state)
{
    (void)state;
    static const char *name[3] = {"signed200", "hub0.99", "convdiff30"};
    for (int k = 0; k < 3; k++) {
        double *b, x;
        ulam_csr *M = hard38(k, &b, &x);
        int v[3] = {0, 0, 0}, R = 40, m = 0;
        double hw[40], hf[40];
        for (int s = 0; s < R; s++) {
            if (!test_case(9000L + 100L * k + s)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.stop.max_walks = 10000, o.exec.seed = 1 + (uint64_t)s;
            ulam_walk_result f, r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &f, NULL), ULAM_OK);
            o.stop.rel_err = 0.001;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            assert_int_equal(r.walks, 10000);
            assert_false(r.rel_err_met);
            v[verdict(&r, x)]++;
            if (!isnan(r.ci95[0]) && !isnan(f.ci95[0]))
                hw[m] = 0.5 * (r.ci95[1] - r.ci95[0]), hf[m++] = 0.5 * (f.ci95[1] - f.ci95[0]);
        }
        test_case_done();
        int lower = (int)ceil(0.95 * R - 3 * sqrt(0.0475 * R));
        if (test_case_all()) {
            qsort(hw, (size_t)m, sizeof *hw, test_cmp_double), qsort(hf, (size_t)m, sizeof *hf, test_cmp_double);
            print_message("%-12s rel_err 0.001 within 10^4 walks: covered %2d, withheld %2d of %d (at least %d); median "
                          "half-width %.4g, fixed count's %.4g\n", name[k], v[1], v[2], R, lower, hw[m / 2], hf[m / 2]);
            assert_true(v[1] + v[2] >= lower);
            assert_true(m > R / 2 && hw[m / 2] <= 1.5 * hf[m / 2]);
        }
        ulam_csr_free(M), free(b);
    }
}

/* Fixed budgets narrow as the budget grows (issue 38): forward collision walks on a signed system,
 * whose weights have no bound, clip their scores by the second-moment certificate (a clip R costs
 * a bias of v2 / R).  Every block after the first took its truncation at an eighth of the planned
 * half-width, so R ~ 1e9 and those blocks' bets weighed nothing: the first block's bias (139 for
 * x = 0.57) stayed the interval's, and --walks 10^3, 10^4, 10^5 printed +-244, +-267, +-407.  At
 * seed 1 the half-width at 4W walks must be below 0.7 of the one at W (W = 1000, 4000, 16000:
 * the variance's own rate is 0.5); stopped after 2, 4 and 6 rounds as a clock stops a --time run,
 * each half-width below 0.7 of the one before; and over 100 seeds at 1000 and 10^4 walks and at
 * 1 to 6 rounds of a clock's stop the intervals cover (at least 89 of 100). */
static void test_fixed_narrows(void **state)
{
    (void)state;
    for (int k = 0; k < 2; k++) {
        double *b, *x = NULL, x0;
        ulam_csr *M = k == 0 ? hard38(0, &b, &x0) : forward_system(200, 1, 11, &b, &x);
        if (k == 1) x0 = x[0], free(x);
        double half[4];
        for (int w = 0; w < 4; w++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.mode = ULAM_FORWARD, o.query.index = 0, o.exec.seed = 1, o.stop.max_walks = 1000 << (2 * w);
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            half[w] = (r.ci95[1] - r.ci95[0]) / 2;
            print_message("%s forward collision, %6lld walks: x_0 %.4g, estimate %.4g, stderr %.3g, half-width %.4g\n",
                          k ? "signed forward 200" : "signed200", (long long)r.walks, x0, r.estimate, r.std_error, half[w]);
            assert_true(isfinite(half[w]) && half[w] > 0);
        }
        for (int w = 1; w < 4; w++) assert_true(half[w] < 0.7 * half[w - 1]);
        double th[3]; /* a clock's stop: 2, 4 and 6 rounds (3072, 15360, 64512 walks) under max_seconds */
        for (int w = 0; w < 3; w++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.mode = ULAM_FORWARD, o.query.index = 0, o.exec.seed = 1, o.stop.max_walks = 0, o.stop.max_seconds = 1e9;
            ulam_solver *sv;
            assert_int_equal(ulam_solver_alloc(M, b, &o, &sv, NULL), ULAM_OK);
            for (int q = 0; q < 2 + 2 * w; q++) assert_int_equal(ulam_solver_iterate(sv), ULAM_OK);
            ulam_walk_result r;
            ulam_solver_result(sv, &r);
            th[w] = (r.ci95[1] - r.ci95[0]) / 2;
            print_message("%s forward collision, %d rounds (%lld walks) of a clock's stop: half-width %.4g\n",
                          k ? "signed forward 200" : "signed200", 2 + 2 * w, (long long)r.walks, th[w]);
            assert_true(isfinite(th[w]) && th[w] > 0);
            ulam_solver_free(sv);
        }
        for (int w = 1; w < 3; w++) assert_true(th[w] < 0.7 * th[w - 1]);
        for (int w = 0; w < 3; w++) {
            int v[3] = {0, 0, 0}, R = 100;
            for (int s = 0; s < R; s++) {
                if (!test_case(12000L + 1000L * k + 100L * w + s)) continue;
                ulam_walk_opts o = ulam_walk_defaults();
                o.mode = ULAM_FORWARD, o.query.index = 0, o.exec.seed = 1 + (uint64_t)s;
                o.stop.max_walks = w == 0 ? 1000 : w == 1 ? 10000 : 0;
                if (w == 2) o.stop.max_seconds = 1e9;
                ulam_walk_result r;
                if (w < 2) assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
                else {
                    ulam_solver *sv;
                    assert_int_equal(ulam_solver_alloc(M, b, &o, &sv, NULL), ULAM_OK);
                    for (int q = 0; q < 1 + s % 6; q++) assert_int_equal(ulam_solver_iterate(sv), ULAM_OK);
                    ulam_solver_result(sv, &r);
                    ulam_solver_free(sv);
                }
                v[verdict(&r, x0)]++;
            }
            test_case_done();
            char what[64];
            snprintf(what, sizeof what, "%s forward collision, %s:", k ? "signed forward 200" : "signed200",
                     w == 0 ? "1000 walks" : w == 1 ? "10^4 walks" : "1 to 6 rounds");
            count(what, v[1], v[2], R);
        }
        ulam_csr_free(M), free(b);
    }
}

/* A signed system whose second-moment matrix has spectral radius 0.995: n states, 4 entries a row
 * at uniform columns with random signs, rows of |M| summing to S = sqrt(0.995 q) at the fixed
 * continuation q = 0.5, so every weight factor is S / q = 1.41 (weights grow without bound) and
 * M^ = (S / q) |M| has row sums S^2 / q = 0.995 (the fourth moment is infinite); b = U(-0.5, 1). */
static ulam_csr *near_one(int64_t n, uint64_t seed, double **bp, double *x0)
{
    int64_t nz = 4 * n;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx), *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
    ulam_rng g;
    ulam_rng_seed(&g, seed, 0);
    for (int64_t i = 0; i < n; i++) {
        double sum = 0.0;
        for (int k = 0; k < 4; k++) {
            int64_t e = 4 * i + k;
            ti[e] = (int32_t)i, tj[e] = (int32_t)ulam_rng_bounded(&g, (uint64_t)n);
            tx[e] = (0.1 + ulam_rng_uniform(&g)) * (ulam_rng_uniform(&g) < 0.5 ? -1.0 : 1.0), sum += fabs(tx[e]);
        }
        for (int k = 0; k < 4; k++) tx[4 * i + k] *= sqrt(0.995 * 0.5) / sum;
        b[i] = 1.5 * ulam_rng_uniform(&g) - 0.5;
    }
    ulam_csr *M;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    *x0 = x[0], *bp = b;
    free(ti), free(tj), free(tx), free(x);
    return M;
}

/* The second-moment certificate aimed at the walk's starts (issue 38): a certified v2 came from a
 * Collatz-Wielandt vector of M^ and Cauchy-Schwarz, max over rows, (1 - sqrt u)^-2: 3.5e6 on
 * signed200 forward collision against E[X^2] ~ 377, and --walks 10^5 printed +-23.7 at stderr
 * 0.061 (half-width / 1.96 se ~ 197).  Now: that half-width over 1.96 se below 6 on issue 38's
 * signed system (forward collision, 10^5 walks, seed 1); forward expected there (whose visits
 * score next to the index) covers over 100 seeds at 1000 and 10^4 walks.  And the intervals that stand on it
 * cover: on near_one (rho(M^) = 0.995, continuation 0.5) over 100 seeds, adjoint collision,
 * absorption and expected at 1000 and 10^4 walks, adjoint collision at --rel-err 0.1 (forward
 * walks there have rho(M^) > 1: the column sums vary; test_fixed_narrows counts signed forward runs),
 * every interval printed and at least 89 of 100 cover (95% coverage fails that with probability
 * under 2%). */
static void test_v2_aimed(void **state)
{
    (void)state;
    double *b, x0;
    ulam_csr *M = hard38(0, &b, &x0);
    if (test_case(13000L)) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.mode = ULAM_FORWARD, o.query.index = 0, o.exec.seed = 1, o.stop.max_walks = 100000;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        double h = (r.ci95[1] - r.ci95[0]) / 2;
        print_message("signed200 forward collision, 10^5 walks: x_0 %.4g, estimate %.4g +- %.3g, stderr %.3g: "
                      "half / 1.96 se %.2f\n", x0, r.estimate, h, r.std_error, h / (1.96 * r.std_error));
        assert_true(r.ci95[0] <= x0 && x0 <= r.ci95[1]);
        assert_true(h < 6.0 * 1.96 * r.std_error);
    }
    test_case_done();
    for (int w = 0; w < 2; w++) { /* forward expected: a visit scores w K_{j,index} (the certificate took 1 at the index) */
        int v[3] = {0, 0, 0}, R = 100;
        for (int s = 0; s < R; s++) {
            if (!test_case(13010L + 100L * w + s)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.mode = ULAM_FORWARD, o.estimator = ULAM_EXPECTED, o.query.index = 0, o.exec.seed = 1 + (uint64_t)s;
            o.stop.max_walks = w ? 10000 : 1000;
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            v[verdict(&r, x0)]++;
        }
        test_case_done();
        count(w ? "signed200 forward expected, 10^4 walks:" : "signed200 forward expected, 1000 walks:", v[1], v[2], R);
    }
    ulam_csr_free(M), free(b);
    M = near_one(100, 7, &b, &x0);
    static const struct { int mode, est; int64_t walks; double E; const char *what; } rows[] = {
        {ULAM_ADJOINT, ULAM_COLLISION, 1000, 0, "adjoint collision, 1000 walks"},
        {ULAM_ADJOINT, ULAM_COLLISION, 10000, 0, "adjoint collision, 10^4 walks"},
        {ULAM_ADJOINT, ULAM_ABSORPTION, 1000, 0, "adjoint absorption, 1000 walks"},
        {ULAM_ADJOINT, ULAM_ABSORPTION, 10000, 0, "adjoint absorption, 10^4 walks"},
        {ULAM_ADJOINT, ULAM_EXPECTED, 1000, 0, "adjoint expected, 1000 walks"},
        {ULAM_ADJOINT, ULAM_EXPECTED, 10000, 0, "adjoint expected, 10^4 walks"},
        {ULAM_ADJOINT, ULAM_COLLISION, 0, 0.1, "adjoint collision, rel-err 0.1"}};
    for (int k = 0; k < 7; k++) {
        int v[3] = {0, 0, 0}, R = 100;
        double hsum = 0.0;
        for (int s = 0; s < R; s++) {
            if (!test_case(13100L + 100L * k + s)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.mode = rows[k].mode, o.estimator = rows[k].est, o.kernel.continue_q = 0.5, o.query.index = 0;
            o.exec.seed = 1 + (uint64_t)s, o.stop.max_walks = rows[k].walks, o.stop.rel_err = rows[k].E;
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
            int vd = verdict(&r, x0);
            assert_true(vd != 2); /* printed */
            v[vd]++, hsum += (r.ci95[1] - r.ci95[0]) / 2 / (1.96 * r.std_error);
        }
        test_case_done();
        char what[64];
        snprintf(what, sizeof what, "near_one %s:", rows[k].what);
        print_message("%s mean half / 1.96 se %.2f\n", what, hsum / R);
        count(what, v[1], v[2], R);
    }
    ulam_csr_free(M), free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_never_zero_width), cmocka_unit_test(test_metastable_fixed),
                                       cmocka_unit_test(test_metastable_rounds), cmocka_unit_test(test_metastable_auto),
                                       cmocka_unit_test(test_metastable_rel_err), cmocka_unit_test(test_laplace_corner),
                                       cmocka_unit_test(test_rel_err_cost), cmocka_unit_test(test_push_b),
                                       cmocka_unit_test(test_laplace_noisy_auto), cmocka_unit_test(test_forward_rel_err), cmocka_unit_test(test_forward_rel_err_scale), cmocka_unit_test(test_forward_expected),
                                       cmocka_unit_test(test_zero_estimate_stops), cmocka_unit_test(test_rel_err_width_hard),
                                       cmocka_unit_test(test_fixed_hard), cmocka_unit_test(test_rel_err_budget), cmocka_unit_test(test_rel_err_small_counts),
                                       cmocka_unit_test(test_rel_err_convdiff), cmocka_unit_test(test_rel_err_signed), cmocka_unit_test(test_rel_err_clusters),
                                       cmocka_unit_test(test_fixed_narrows), cmocka_unit_test(test_v2_aimed)};
    return test_run(tests);
}
