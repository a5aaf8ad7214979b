/* Error bars a user can bet on: --rel-err runs on systems with rare high scores, counted over
 * seeds with binomial bounds.  Its own suite ('stats'): a few hundred runs of up to 10^6 walks,
 * too slow for valgrind, fine under ASan.
 *
 * The system (rare_system in testutil.h): absorption scores b / p* = 1000 at three rare states
 * that a walk ends at with probability about 7e-4, holding 25% of x; with the old rule (stop at
 * stderr <= E |estimate| after 1000 walks) coverage was 44/100, 44/100 and 78/100 at E = 0.1,
 * 0.03 and 0.01, with the mean 11%, 11% and 4% low. */
#include "testutil.h"

/* x_i and the exact per-walk variance of adjoint absorption from i (analog kernel, every row
 * sum below 1: M^ = M, so (I - M) v = b o b / p* and Var = v_i - x_i^2). */
static void exact(const ulam_csr *M, const double *b, int64_t i, double *x, double *var)
{
    int64_t n = M->nrows;
    double *xs = malloc((size_t)n * sizeof *xs), *r = malloc((size_t)n * sizeof *r), *v = malloc((size_t)n * sizeof *v);
    for (int64_t k = 0; k < n; k++) {
        double S = 0;
        for (int64_t q = M->rowptr[k]; q < M->rowptr[k + 1]; q++) S += M->val[q];
        r[k] = b[k] * b[k] / (1 - S);
    }
    assert_int_equal(ulam_direct_solve(M, b, xs, 0, NULL, NULL), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, r, v, 0, NULL, NULL), ULAM_OK);
    *x = xs[i], *var = v[i] - xs[i] * xs[i];
    free(xs), free(r), free(v);
}

/* Coverage of the printed 95% interval >= 90% (binomial: fail below 0.9 R - 2 sqrt(0.09 R))
 * and |mean bias| < the mean reported stderr, at E = 0.1, 0.03, 0.01. */
static void test_rel_err_rare_scores(void **state)
{
    (void)state;
    static const struct { double E; int seeds; } cases[] = {{0.1, 100}, {0.03, 100}, {0.01, 20}};
    double *b, x, var;
    ulam_csr *M = rare_system(200, 0.01, 10, 0.0175, 1, &b);
    exact(M, b, 3, &x, &var);
    print_message("x_4 = %.6g, per-walk variance %.6g (absorption)\n", x, var);
    for (int k = 0; k < 3; k++) {
        int covered = 0, R = cases[k].seeds;
        double bias = 0, se = 0, walks = 0;
        for (int s = 0; s < R; s++) { /* case (k, s) reruns exactly */
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = ULAM_ABSORPTION, o.index = 3, o.max_walks = 0, o.rel_err = cases[k].E;
            o.seed = 1000 + (uint64_t)s;
            ulam_walk_result r;
            assert_int_equal(ulam_solve(M, b, &o, &r, NULL), ULAM_OK);
            assert_true(r.rel_err_met && r.variance_finite == 1);
            assert_true(r.std_error <= cases[k].E * fabs(r.estimate) && r.walks >= r.min_walks);
            covered += fabs(r.estimate - x) <= 1.959963984540054 * r.std_error;
            bias += r.estimate - x, se += r.std_error, walks += (double)r.walks;
        }
        bias /= R, se /= R;
        int lower = (int)floor(0.9 * R - 2 * sqrt(0.09 * R));
        print_message("E = %g: covered %d / %d (at least %d), mean bias %.3g (%.2f%%), mean stderr %.3g, mean walks %.3g\n",
                      cases[k].E, covered, R, lower, bias, 100 * bias / x, se, walks / R);
        if (covered < lower || !(fabs(bias) < se)) print_error("case %d fails\n", k);
        assert_true(covered >= lower);
        assert_true(fabs(bias) < se);
    }
    ulam_csr_free(M), free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_rel_err_rare_scores)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
