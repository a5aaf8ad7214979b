/* Outer iterations on the exact residual: Richardson's count on the paper's Poisson problem,
 * sequential Monte Carlo and MCSA against LAPACK, their stopping rules (tolerance, cap,
 * stall), thread identity, refused options, and the Krylov peers. */
#include "testutil.h"

#include <string.h>

typedef test_sys sys;

/* Load matrices/NAME.mtx and its b (with the Jacobi splitting when jacobi), solved with LAPACK. */
static sys load(const char *name, int jacobi)
{
    return test_sys_load_split(name, jacobi);
}

/* The rho = 0.9 random system scaled to row and column sums 0.5 (short walks: cheap enough for
 * valgrind), its LAPACK solution recomputed. */
static sys load_half(void)
{
    sys s = load("randsub1000", 0);
    for (int64_t q = 0; q < ulam_csr_nnz(s.M); q++) s.M->val[q] *= 0.5 / 0.9;
    assert_int_equal(ulam_direct_solve(s.M, s.b, s.x, 0, NULL, NULL), ULAM_OK);
    return s;
}

/* Free a loaded system. */
static void unload(sys *s)
{
    test_sys_free(s);
}

/* ||x - x_LAPACK||_2 / ||x_LAPACK||_2. */
static double rel_error(const sys *s, const double *x)
{
    double num = 0, den = 0;
    for (int64_t i = 0; i < s->n; i++) num += (x[i] - s->x[i]) * (x[i] - s->x[i]), den += s->x[i] * s->x[i];
    return sqrt(num / den);
}

/* Run an outer iteration into x; returns its status, *k the iterations. */
static int run(const sys *s, const ulam_outer_opts *o, double *x, ulam_outer_step *steps, int cap, int *k)
{
    ulam_error err;
    int st = ulam_outer_solve(s->M, s->b, o, x, steps, cap, k, &err);
    if (st) print_message("ulam_outer_solve: %s: %s\n", ulam_strerror(st), err.msg);
    return st;
}

/* The paper's Richardson row: 3133 iterations on the 2-D Poisson problem with Jacobi.  Its
 * count is that of a 10^-7 reduction (f is the lowest eigenvector of the discrete Laplacian,
 * so the residual falls by exactly rho = cos(pi / 31) an iteration: 10^-7 takes 3134, the
 * 10^-8 the paper states 3582). */
static void test_richardson_paper(void **state)
{
    (void)state;
    sys s = load("poisson900", 1);
    double *x = malloc((size_t)s.n * sizeof *x);
    ulam_outer_opts o = ulam_outer_defaults();
    o.method = ULAM_RICHARDSON;
    int k;
    o.tol = 1e-7;
    assert_int_equal(run(&s, &o, x, NULL, 0, &k), ULAM_OK);
    print_message("Richardson to 1e-7: %d iterations (paper 3133), error %.3g\n", k, rel_error(&s, x));
    assert_in_range(k, 3131, 3135);
    o.tol = 1e-8;
    assert_int_equal(run(&s, &o, x, NULL, 0, &k), ULAM_OK);
    double n_exact = ceil(log(1e-8) / log(cos(M_PI / 31))); /* rho^k <= 1e-8 */
    print_message("Richardson to 1e-8: %d iterations (rho^k <= 1e-8 at k = %.0f), error %.3g\n", k, n_exact,
                  rel_error(&s, x));
    assert_in_range(k, (int)n_exact - 1, (int)n_exact + 1);
    assert_true(rel_error(&s, x) <= 2e-7);
    free(x);
    unload(&s);
}

/* Gauss-Seidel and both Monte Carlo methods reach 1e-8 on a rho = 0.5 system, their residual
 * recomputed here exactly, and their solution within 2e-7 of LAPACK; the Monte Carlo methods
 * in a handful of iterations, each iteration's correction meeting the eps1 rule. */
static void test_methods_converge(void **state)
{
    (void)state;
    sys s = load_half();
    double *x = malloc((size_t)s.n * sizeof *x), *y = malloc((size_t)s.n * sizeof *y);
    static const int methods[] = {ULAM_GAUSS_SEIDEL, ULAM_SEQUENTIAL, ULAM_MCSA};
    for (int c = 0; c < 3; c++) {
        if (!test_case(c)) continue;
        ulam_outer_opts o = ulam_outer_defaults();
        o.method = methods[c];
        o.walk.threads = 2;
        ulam_outer_step st[256];
        int k;
        assert_int_equal(run(&s, &o, x, st, 256, &k), ULAM_OK);
        assert_true(k <= 256);
        ulam_csr_matvec(s.M, 0, x, y);
        double rr = 0, bb = 0;
        for (int64_t i = 0; i < s.n; i++) rr += pow(s.b[i] - x[i] + y[i], 2), bb += s.b[i] * s.b[i];
        print_message("case %d (method %d): %d iterations, residual %.3g, error %.3g\n", c, o.method, k,
                      sqrt(rr / bb), rel_error(&s, x));
        assert_true(sqrt(rr / bb) <= 1e-8);
        assert_close(st[k - 1].residual, sqrt(rr / bb), 1e-12);
        assert_true(rel_error(&s, x) <= 2e-7);
        if (o.method == ULAM_GAUSS_SEIDEL) continue;
        assert_in_range(k, 4, 12);
        for (int i = 0; i < k; i++) {
            assert_true(st[i].histories >= 1024 && st[i].histories < o.max_histories);
            assert_true(st[i].rel_sd < o.eps1);
            assert_int_equal(st[i].iteration, i + 1);
        }
    }
    test_case_done();
    free(x), free(y);
    unload(&s);
}

/* One thread and two give the same iterates, residuals and history counts, bit for bit. */
static void test_threads_identical(void **state)
{
    (void)state;
    sys s = load_half();
    double *x1 = malloc((size_t)s.n * sizeof *x1), *x2 = malloc((size_t)s.n * sizeof *x2);
    for (int m = ULAM_SEQUENTIAL; m <= ULAM_MCSA; m++) {
        ulam_outer_opts o = ulam_outer_defaults();
        o.method = m;
        o.tol = 1e-6;
        ulam_outer_step a[32], b[32];
        int ka, kb;
        o.walk.threads = 1;
        assert_int_equal(run(&s, &o, x1, a, 32, &ka), ULAM_OK);
        o.walk.threads = 2;
        assert_int_equal(run(&s, &o, x2, b, 32, &kb), ULAM_OK);
        assert_int_equal(ka, kb);
        assert_memory_equal(x1, x2, (size_t)s.n * sizeof *x1);
        for (int i = 0; i < ka; i++) {
            assert_int_equal(a[i].histories, b[i].histories);
            assert_int_equal(a[i].steps, b[i].steps);
            assert_memory_equal(&a[i].residual, &b[i].residual, sizeof a[i].residual);
        }
        o.walk.seed = 2; /* another seed: other walks */
        assert_int_equal(run(&s, &o, x2, b, 32, &kb), ULAM_OK);
        assert_true(memcmp(x1, x2, (size_t)s.n * sizeof *x1) != 0);
    }
    free(x1), free(x2);
    unload(&s);
}

/* Infinite variance (a fixed continuation q = 0.3 with row sums 0.9: rho(M^) = 0.81 / 0.3 =
 * 2.7): the corrections are noise that no history count tames, the residual stops falling,
 * and the run ends with ULAM_ESTALL after the stall window, never looping. */
static void test_stall(void **state)
{
    (void)state;
    sys s = load("randsub1000", 0);
    double *x = malloc((size_t)s.n * sizeof *x);
    ulam_outer_opts o = ulam_outer_defaults();
    o.walk.continue_q = 0.3;
    o.walk.estimator = ULAM_COLLISION;
    o.max_histories = 20000;
    o.walk.threads = 2;
    ulam_outer_step st[64];
    int k;
    assert_int_equal(run(&s, &o, x, st, 64, &k), ULAM_ESTALL);
    print_message("stalled after %d iterations at residual %.3g\n", k, st[k - 1].residual);
    assert_true(k <= 40);
    assert_true(st[k - 1].residual > 1e-8);
    assert_string_equal(ulam_strerror(ULAM_ESTALL), "the residual stopped decreasing");
    /* the stall window is the option: 2 iterations without a new low end it sooner */
    o.stall = 2;
    int k2;
    assert_int_equal(run(&s, &o, x, st, 64, &k2), ULAM_ESTALL);
    assert_true(k2 <= k);
    free(x);
    unload(&s);
}

/* The iteration cap ends a run that would go on, with ULAM_ENOCONV after exactly max_iter. */
static void test_max_iter(void **state)
{
    (void)state;
    sys s = load("poisson900", 1);
    double *x = malloc((size_t)s.n * sizeof *x);
    ulam_outer_opts o = ulam_outer_defaults();
    o.method = ULAM_RICHARDSON;
    o.max_iter = 7;
    ulam_outer_step st[8];
    int k;
    assert_int_equal(run(&s, &o, x, st, 8, &k), ULAM_ENOCONV);
    assert_int_equal(k, 7);
    assert_close(st[6].residual, pow(cos(M_PI / 31), 7), 1e-12); /* b is an eigenvector */
    free(x);
    unload(&s);
}

/* Options out of range and b = 0 are refused with a sentence; nothing is allocated. */
static void test_bad_options(void **state)
{
    (void)state;
    sys s = load("chain4", 0);
    ulam_outer *it = (ulam_outer *)&s; /* must be reset to NULL on failure */
    ulam_error err;
    static const double tols[] = {0.0, 1.0, -1e-3, 2.0, NAN};
    for (int c = 0; c < 5; c++) {
        if (!test_case(c)) continue;
        ulam_outer_opts o = ulam_outer_defaults();
        o.tol = tols[c];
        assert_int_equal(ulam_outer_alloc(s.M, s.b, &o, &it, &err), ULAM_EINVAL);
        assert_null(it);
        assert_non_null(strstr(err.msg, "tolerance in (0, 1)"));
    }
    test_case_done();
    ulam_outer_opts o = ulam_outer_defaults();
    o.max_iter = -1;
    assert_int_equal(ulam_outer_alloc(s.M, s.b, &o, &it, &err), ULAM_EINVAL);
    o = ulam_outer_defaults();
    o.eps1 = 1.0;
    assert_int_equal(ulam_outer_alloc(s.M, s.b, &o, &it, &err), ULAM_EINVAL);
    assert_non_null(strstr(err.msg, "eps1"));
    o = ulam_outer_defaults();
    o.method = 9;
    assert_int_equal(ulam_outer_alloc(s.M, s.b, &o, &it, &err), ULAM_EINVAL);
    o = ulam_outer_defaults();
    double *zero = calloc((size_t)s.n, sizeof *zero);
    assert_int_equal(ulam_outer_alloc(s.M, zero, &o, &it, &err), ULAM_EINVAL);
    assert_non_null(strstr(err.msg, "b != 0"));
    assert_null(ulam_outer_free(NULL));
    assert_int_equal(ulam_outer_iterate(NULL, NULL), ULAM_EINVAL);
    free(zero);
    unload(&s);
}

/* Krylov peers: CG on the symmetric Poisson system (20 x 20, b = 1, Jacobi-split, so I - M = A / 4;
 * not the 30 x 30 one, whose b is an eigenvector and takes CG one step) and GMRES on
 * the nonsymmetric rho = 0.9 system reach 1e-8 in the true residual; CG's count is bounded by
 * the classical sqrt(kappa) estimate, GMRES(n) never restarts and needs at most n products.
 * SciPy's counts on the same matrices are compared in tests/krylov_test.py. */
static void test_krylov(void **state)
{
    (void)state;
    sys p = load("poisson20", 1), r = load("randsub1000", 0);
    assert_true(ulam_csr_symmetric(p.M));
    assert_false(ulam_csr_symmetric(r.M));
    double *x = malloc((size_t)r.n * sizeof *x), res;
    int k;
    assert_int_equal(ulam_cg(p.M, p.b, 1e-8, 1000, x, &k, &res), ULAM_OK);
    double kappa = (1 + cos(M_PI / 21)) / (1 - cos(M_PI / 21));
    print_message("CG: %d iterations, residual %.3g, error %.3g (kappa %.0f)\n", k, res, rel_error(&p, x), kappa);
    assert_true(res <= 1e-8 && rel_error(&p, x) <= 2e-7);
    assert_true(k <= 1 + 0.5 * sqrt(kappa) * log(2 / 1e-8) * 1.5); /* sqrt(kappa) bound, energy-to-2-norm slack */
    assert_int_equal(ulam_gmres(r.M, r.b, 30, 1e-8, 1000, x, &k, &res), ULAM_OK);
    print_message("GMRES(30): %d iterations, residual %.3g, error %.3g\n", k, res, rel_error(&r, x));
    assert_true(res <= 1e-8 && rel_error(&r, x) <= 2e-7);
    assert_int_equal(ulam_gmres(r.M, r.b, 30, 1e-8, 3, x, &k, &res), ULAM_ENOCONV);
    assert_int_equal(k, 3);
    free(x);
    unload(&p), unload(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_richardson_paper), cmocka_unit_test(test_methods_converge),
        cmocka_unit_test(test_threads_identical), cmocka_unit_test(test_stall),
        cmocka_unit_test(test_max_iter),          cmocka_unit_test(test_bad_options),
        cmocka_unit_test(test_krylov),
    };
    return test_run(tests);
}
