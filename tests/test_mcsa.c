/* Outer iterations on the exact residual: Richardson's count on the paper's Poisson problem,
 * sequential Monte Carlo and MCSA against LAPACK, their stopping rules (tolerance, cap,
 * stall), thread identity, refused options, and the Krylov peers. */
#include "testutil.h"

#include <string.h>

typedef test_sys sys;

/* Where outer iteration it stands. */
static ulam_outer_info outer_info(const ulam_outer *it)
{
    ulam_outer_info info;
    ulam_outer_get_info(it, &info);
    return info;
}

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
        o.walk.exec.threads = 2;
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
        o.walk.exec.threads = 1;
        assert_int_equal(run(&s, &o, x1, a, 32, &ka), ULAM_OK);
        o.walk.exec.threads = 2;
        assert_int_equal(run(&s, &o, x2, b, 32, &kb), ULAM_OK);
        assert_int_equal(ka, kb);
        assert_memory_equal(x1, x2, (size_t)s.n * sizeof *x1);
        for (int i = 0; i < ka; i++) {
            assert_int_equal(a[i].histories, b[i].histories);
            assert_int_equal(a[i].steps, b[i].steps);
            assert_memory_equal(&a[i].residual, &b[i].residual, sizeof a[i].residual);
        }
        o.walk.exec.seed = 2; /* another seed: other walks */
        assert_int_equal(run(&s, &o, x2, b, 32, &kb), ULAM_OK);
        assert_true(memcmp(x1, x2, (size_t)s.n * sizeof *x1) != 0);
    }
    free(x1), free(x2);
    unload(&s);
}

/* Infinite variance (a fixed continuation q = 0.3 with row sums 0.9: rho(M^) = 0.81 / 0.3 =
 * 2.7) is refused before any walk (ULAM_EINFVAR).  A correction that the history cap keeps
 * from lowering the residual (poisson900 at 1000 histories) ends the run with ULAM_ESTALL
 * at once; the stall window ends a run whose residual makes no new low (Richardson on the
 * rho = 1.1 system: its last low plus the window), never looping. */
static void test_stall(void **state)
{
    (void)state;
    sys s = load("randsub1000", 0);
    double *x = malloc((size_t)s.n * sizeof *x);
    ulam_outer_opts o = ulam_outer_defaults();
    o.walk.kernel.continue_q = 0.3;
    o.walk.estimator = ULAM_COLLISION;
    o.max_histories = 20000;
    o.walk.exec.threads = 2;
    ulam_outer_step st[64];
    int k = -1;
    ulam_error err;
    assert_int_equal(ulam_outer_solve(s.M, s.b, &o, x, st, 64, &k, &err), ULAM_EINFVAR);
    assert_int_equal(k, -1); /* refused before any iteration */
    unload(&s);
    assert_string_equal(ulam_strerror(ULAM_ESTALL), "the residual stopped decreasing");
    s = load("poisson900", 1);
    o = ulam_outer_defaults();
    o.max_histories = 1000;
    o.walk.exec.threads = 2;
    assert_int_equal(ulam_outer_solve(s.M, s.b, &o, x, st, 64, &k, &err), ULAM_ESTALL);
    print_message("poisson900 at 1000 histories: %d iterations, residual %.3g: %s\n", k, st[k - 1].residual, err.msg);
    assert_true(k <= 3 && st[k - 1].residual < 1);
    assert_non_null(strstr(err.msg, "lowers the residual"));
    unload(&s);
    s = load("divergent200", 0);
    o = ulam_outer_defaults();
    o.method = ULAM_RICHARDSON;
    int kw[2];
    for (int w = 0; w < 2; w++) { /* the residual's last low is at the same iteration m: m + window */
        o.stall = 2 + 3 * w;
        assert_int_equal(ulam_outer_solve(s.M, s.b, &o, x, st, 64, &kw[w], &err), ULAM_ESTALL);
        assert_true(kw[w] <= 40);
    }
    assert_int_equal(kw[1] - kw[0], 3);
    free(x);
    unload(&s);
}

/* A nonsymmetric n-state system with rho(M) = rho exactly (power iteration to 1e-13): d entries
 * a row at distinct random columns, weights u^3 (so column sums vary widely and the forward
 * kernel's second moment rho(M^) exceeds 1); b_i ~ U(0, 1).  *b is malloc'd. */
static ulam_csr *skewed_system(int32_t n, int d, double rho, uint64_t seed, double **b)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 25);
    int32_t *ti = malloc((size_t)n * d * sizeof *ti), *tj = malloc((size_t)n * d * sizeof *tj);
    double *tx = malloc((size_t)n * d * sizeof *tx);
    int64_t nz = 0;
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < d; k++) {
            int32_t j;
            int again;
            do { /* distinct columns in the row */
                j = (int32_t)ulam_rng_bounded(&r, (uint64_t)n), again = 0;
                for (int64_t q = nz - k; q < nz; q++) again |= tj[q] == j;
            } while (again);
            double u = ulam_rng_uniform(&r);
            ti[nz] = i, tj[nz] = j, tx[nz++] = u * u * u;
        }
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M), ULAM_OK);
    double *v = malloc((size_t)n * sizeof *v), *w = malloc((size_t)n * sizeof *w), lam = 0;
    for (int32_t i = 0; i < n; i++) v[i] = 1.0;
    for (int it = 0; it < 5000; it++) { /* Perron root: M irreducible with d = 10 */
        ulam_csr_matvec(M, 0, v, w);
        double s1 = 0, s0 = 0;
        for (int32_t i = 0; i < n; i++) s1 += w[i], s0 += v[i];
        double l = s1 / s0;
        for (int32_t i = 0; i < n; i++) v[i] = w[i] / s1 * n;
        if (fabs(l - lam) < 1e-13 * l) break;
        lam = l;
    }
    for (int64_t q = 0; q < nz; q++) M->val[q] *= rho / lam;
    *b = malloc((size_t)n * sizeof **b);
    for (int32_t i = 0; i < n; i++) (*b)[i] = ulam_rng_uniform(&r);
    free(ti), free(tj), free(tx), free(v), free(w);
    return M;
}

/* Issue 25 case 8: on a 100-state nonsymmetric system with rho(M) = 0.99 whose forward
 * variance is infinite, both walk methods are refused up front (ULAM_EINFVAR, before any
 * walk; they used to warn and walk the first correction for minutes), assume_finite does not
 * override a certified infinite variance, and the deterministic methods still run. */
static void test_infinite_variance_refused(void **state)
{
    (void)state;
    double *b;
    ulam_csr *M = skewed_system(100, 10, 0.99, 8, &b);
    ulam_guard g;
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    print_message("rho(|M|) in [%.4g, %.4g], forward rho(M^) in [%.4g, %.4g]\n", g.abs.lower, g.abs.upper,
                  g.hat[ULAM_FORWARD].lower, g.hat[ULAM_FORWARD].upper);
    assert_true(g.abs.upper < 1 && g.abs.lower > 0.98);
    assert_int_equal(ulam_guard_variance(&g, ULAM_FORWARD), 0);
    for (int m = ULAM_SEQUENTIAL; m <= ULAM_MCSA; m++)
        for (int assume = 0; assume < 2; assume++) {
            ulam_outer_opts o = ulam_outer_defaults();
            o.method = m;
            o.walk.policy.assume_finite = assume;
            o.walk.policy.guard = assume ? &g : NULL; /* given or computed: the same verdict */
            ulam_outer *it = (ulam_outer *)M;
            ulam_error err;
            assert_int_equal(ulam_outer_alloc(M, b, &o, &it, &err), ULAM_EINFVAR);
            assert_null(it);
            assert_non_null(strstr(err.msg, "rho(M^) of the forward kernel"));
            assert_non_null(strstr(err.msg, "infinite"));
        }
    ulam_outer_opts o = ulam_outer_defaults();
    o.method = ULAM_GAUSS_SEIDEL;
    o.tol = 1e-6;
    int k;
    ulam_error err;
    assert_int_equal(ulam_outer_solve(M, b, &o, NULL, NULL, 0, &k, &err), ULAM_OK);
    ulam_csr_free(M);
    free(b);
}

/* The Jacobi splitting of the L x L five-point Laplacian (M_ij = 1/4 between neighbours), b = 1/4. */
static ulam_csr *poisson_jacobi(int32_t L, double **b)
{
    int64_t n = (int64_t)L * L, nz = 0;
    int32_t *ti = malloc(4 * (size_t)n * sizeof *ti), *tj = malloc(4 * (size_t)n * sizeof *tj);
    double *tx = malloc(4 * (size_t)n * sizeof *tx);
    for (int32_t i = 0; i < L; i++)
        for (int32_t j = 0; j < L; j++) {
            static const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
            for (int k = 0; k < 4; k++)
                if (i + di[k] >= 0 && i + di[k] < L && j + dj[k] >= 0 && j + dj[k] < L)
                    ti[nz] = i * L + j, tj[nz] = (i + di[k]) * L + j + dj[k], tx[nz++] = 0.25;
        }
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M), ULAM_OK);
    *b = malloc((size_t)n * sizeof **b);
    for (int64_t i = 0; i < n; i++) (*b)[i] = 0.25;
    free(ti), free(tj), free(tx);
    return M;
}

/* Issue 25 case 8: on 2-D Poisson with Jacobi at n = 10^4 the first correction of 3072
 * histories made the residual 22x worse and was kept (1 -> 22 -> 24).  Now no iteration
 * raises the residual: a correction that would is rejected, and when the count its variance
 * predicts is beyond 100x what the eps1 rule took, the run stops at once with ULAM_ESTALL and
 * a sentence saying so (bounded time: one correction's walks). */
static void test_poisson_never_worse(void **state)
{
    (void)state;
    double *b;
    ulam_csr *M = poisson_jacobi(100, &b);
    double *x = malloc(10000 * sizeof *x);
    for (int m = ULAM_SEQUENTIAL; m <= ULAM_MCSA; m++) {
        if (!test_case(m)) continue;
        ulam_outer_opts o = ulam_outer_defaults();
        o.method = m;
        o.walk.exec.threads = 2;
        ulam_outer *it = NULL;
        ulam_error err;
        assert_int_equal(ulam_outer_alloc(M, b, &o, &it, &err), ULAM_OK);
        double prev = 1.0;
        int k = 0, status = ULAM_OK;
        ulam_outer_step st;
        while (!ulam_outer_done(it)) {
            status = ulam_outer_iterate(it, &st);
            k++;
            print_message("method %d iteration %d: residual %.4g, %lld histories, rejected %d\n", m, k, st.residual,
                          (long long)st.histories, outer_info(it).rejected);
            assert_true(st.residual <= prev); /* never worse than before the iteration */
            prev = st.residual;
        }
        assert_int_equal(ulam_outer_error(it, &err), status);
        print_message("  %s: %s\n", ulam_strerror(status), err.msg);
        assert_true(status == ULAM_OK || status == ULAM_ESTALL);
        if (status == ULAM_ESTALL) {
            assert_true(outer_info(it).rejected >= 1);
            assert_non_null(strstr(err.msg, "lowers the residual"));
            assert_true(k <= 3);
        }
        ulam_outer_free(it);
    }
    test_case_done();
    free(x), free(b);
    ulam_csr_free(M);
}

/* A correction rejected on the way is redone with more histories and the run still converges:
 * the 20 x 20 Poisson problem at a loose eps1 = 0.9, each iteration's residual below the last. */
static void test_rejected_redone(void **state)
{
    (void)state;
    sys s = load("poisson20", 1);
    for (int m = ULAM_SEQUENTIAL; m <= ULAM_MCSA; m++) {
        if (!test_case(m)) continue;
        ulam_outer_opts o = ulam_outer_defaults();
        o.method = m;
        o.eps1 = 0.9;
        o.tol = 1e-4;
        o.walk.exec.threads = 2;
        ulam_outer *it = NULL;
        assert_int_equal(ulam_outer_alloc(s.M, s.b, &o, &it, NULL), ULAM_OK);
        double prev = 1.0;
        int status = ULAM_OK;
        ulam_outer_step st;
        while (!ulam_outer_done(it)) {
            status = ulam_outer_iterate(it, &st);
            assert_true(st.residual < prev);
            prev = st.residual;
        }
        print_message("method %d: %s after %d iterations, residual %.3g, %d rejected\n", m, ulam_strerror(status),
                      st.iteration, st.residual, outer_info(it).rejected);
        assert_int_equal(status, ULAM_OK);
        assert_true(outer_info(it).converged);
        assert_true(outer_info(it).rejected >= 1);
        ulam_outer_free(it);
    }
    test_case_done();
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
    ulam_csr_stats st;
    assert_int_equal(ulam_csr_stats_compute(p.M, &st), ULAM_OK);
    assert_true(st.symmetric);
    assert_int_equal(ulam_csr_stats_compute(r.M, &st), ULAM_OK);
    assert_false(st.symmetric);
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
        cmocka_unit_test(test_krylov),            cmocka_unit_test(test_infinite_variance_refused),
        cmocka_unit_test(test_poisson_never_worse), cmocka_unit_test(test_rejected_redone),
    };
    return test_run(tests);
}
