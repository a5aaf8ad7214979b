/* Spectral radius estimates against matrices whose spectra are known exactly. */
#include "testutil.h"

/* Build from triplets or fail. */
static ulam_csr *build(int64_t n, int64_t nz, const int32_t *i, const int32_t *j, const double *x)
{
    ulam_csr *A = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, i, j, x, &A), ULAM_OK);
    return A;
}

/* Radius with a tight tolerance; must converge. */
static double radius(const ulam_csr *A, int use_abs)
{
    ulam_spectral_opts o = ulam_spectral_defaults();
    o.tol = 1e-10;
    o.max_restarts = 2000;
    ulam_radius r;
    assert_int_equal(ulam_spectral_radius(A, use_abs, &o, &r), ULAM_OK);
    assert_true(r.converged);
    assert_true(r.residual <= 1e-10);
    return r.rho;
}

/* Diagonal: the radius is the largest |d_i|, here a negative one. */
static void test_diagonal(void **state)
{
    (void)state;
    enum { N = 300 };
    int32_t i[N];
    double d[N];
    for (int k = 0; k < N; k++) i[k] = k, d[k] = 0.2 + 0.7 * k / N;
    d[17] = -0.97;
    ulam_csr *A = build(N, N, i, i, d);
    assert_close(radius(A, 0), 0.97, 1e-8);
    assert_close(radius(A, 1), 0.97, 1e-8);
    ulam_csr_free(A);
}

/* Signed circulant a P + c P' (P the cyclic shift): lambda_k = a w^k + c w^-k, so with
 * a = 0.6, c = -0.3 the dominant eigenvalues are a complex pair on an ellipse; rho(|C|) = 0.9. */
static ulam_csr *circulant(int n, double *exact)
{
    int32_t *i = malloc(2 * (size_t)n * sizeof *i), *j = malloc(2 * (size_t)n * sizeof *j);
    double *x = malloc(2 * (size_t)n * sizeof *x);
    *exact = 0;
    for (int k = 0; k < n; k++) {
        i[2 * k] = k, j[2 * k] = (k + 1) % n, x[2 * k] = 0.6;
        i[2 * k + 1] = k, j[2 * k + 1] = (k + n - 1) % n, x[2 * k + 1] = -0.3;
        double t = 2 * M_PI * k / n;
        *exact = fmax(*exact, hypot(0.6 * cos(t) - 0.3 * cos(t), 0.6 * sin(t) + 0.3 * sin(t)));
    }
    ulam_csr *A = build(n, 2 * n, i, j, x);
    free(i), free(j), free(x);
    return A;
}

/* n = 101: the radius of the complex pair, and of |C|. */
static void test_circulant(void **state)
{
    (void)state;
    double exact;
    ulam_csr *A = circulant(101, &exact);
    assert_close(exact, 0.8999032512582203, 1e-13); /* computed independently */
    assert_close(radius(A, 0), exact, 1e-8);
    assert_close(radius(A, 1), 0.9, 1e-8);
    ulam_csr_free(A);
}

/* n = 1001: the top moduli differ by 1e-6 relative, too clustered for Arnoldi to converge
 * in its cap; the estimate must say so, and (C is normal, so Ritz values lie in the convex
 * hull of the spectrum) must not exceed the true radius. */
static void test_clustered_reports_not_converged(void **state)
{
    (void)state;
    double exact;
    ulam_csr *A = circulant(1001, &exact);
    assert_close(exact, 0.8999990150107934, 1e-13); /* computed independently */
    ulam_radius r;
    assert_int_equal(ulam_spectral_radius(A, 0, NULL, &r), ULAM_OK);
    assert_false(r.converged);
    assert_true(r.residual > ulam_spectral_defaults().tol);
    assert_true(r.rho <= exact + 1e-12 && r.rho > 0.8);
    ulam_csr_free(A);
}

/* s P for a random stochastic P (8 entries per row): rho = s exactly. */
static void test_scaled_stochastic(void **state)
{
    (void)state;
    for (int c = 0; c < 5; c++) { /* case c is seeded by c */
        if (!test_case(c)) continue;
        enum { N = 500, K = 8 };
        static int32_t i[N * K], j[N * K];
        static double x[N * K];
        ulam_rng r;
        ulam_rng_seed(&r, (uint64_t)c, 3);
        double s = 0.5 + 0.1 * c;
        for (int row = 0; row < N; row++) {
            double sum = 0;
            for (int q = 0; q < K; q++) {
                i[row * K + q] = row;
                j[row * K + q] = (int32_t)ulam_rng_bounded(&r, N);
                sum += x[row * K + q] = 0.05 + ulam_rng_uniform(&r);
            }
            for (int q = 0; q < K; q++) x[row * K + q] *= s / sum;
        }
        ulam_csr *A = build(N, N * K, i, j, x);
        assert_close(radius(A, 0), s, 1e-8);
        assert_close(radius(A, 1), s, 1e-8);
        ulam_csr_free(A);
    }
    test_case_done();
}

/* Block diagonal of 2 x 2 rotations r (cos t, -sin t; sin t, cos t): eigenvalues r e^{+-it};
 * one block of radius 0.95 dominates the rest (radii 0.5 .. 0.9). */
static void test_rotation_blocks(void **state)
{
    (void)state;
    enum { B = 100, N = 2 * B };
    int32_t i[4 * B], j[4 * B];
    double x[4 * B];
    for (int k = 0; k < B; k++) {
        double rr = k == 42 ? 0.95 : 0.5 + 0.4 * k / B, t = 0.3 + 0.02 * k;
        int32_t a = 2 * k, b = 2 * k + 1;
        double v[4] = {rr * cos(t), -rr * sin(t), rr * sin(t), rr * cos(t)};
        int32_t ii[4] = {a, a, b, b}, jj[4] = {a, b, a, b};
        for (int q = 0; q < 4; q++) i[4 * k + q] = ii[q], j[4 * k + q] = jj[q], x[4 * k + q] = v[q];
    }
    ulam_csr *A = build(N, 4 * B, i, j, x);
    assert_close(radius(A, 0), 0.95, 1e-8);
    ulam_csr_free(A);
}

/* Nilpotent and zero matrices have radius 0; tiny matrices are exact. */
static void test_degenerate(void **state)
{
    (void)state;
    int32_t i[3] = {1, 2, 3}, j[3] = {0, 1, 2};
    double x[3] = {1, 1, 1};
    ulam_csr *A = build(4, 3, i, j, x); /* shift: nilpotent, one 4 x 4 Jordan block */
    ulam_radius r;
    assert_int_equal(ulam_spectral_radius(A, 0, NULL, &r), ULAM_OK);
    assert_close(r.rho, 0.0, 1e-12); /* dgeev on the exact Hessenberg form finds 0 */
    ulam_csr_free(A);
    ulam_csr *Z = build(5, 0, i, j, x);
    assert_int_equal(ulam_spectral_radius(Z, 1, NULL, &r), ULAM_OK);
    assert_close(r.rho, 0.0, 0);
    ulam_csr_free(Z);
}

/* The committed systems: the lecture chain against dense eigenvalues, Poisson's Jacobi
 * matrix against cos(pi / 21). */
static void test_committed(void **state)
{
    (void)state;
    ulam_csr *A = must_read("matrices/poisson20.mtx");
    double b[400] = {0}, bp[400];
    ulam_csr *M = NULL;
    assert_int_equal(ulam_jacobi(A, b, 1.0, &M, bp, NULL), ULAM_OK);
    assert_close(radius(M, 0), cos(M_PI / 21), 1e-8);
    assert_close(radius(M, 1), cos(M_PI / 21), 1e-8);
    ulam_csr_free(A), ulam_csr_free(M);
}

/* Power iteration on |A| (the guards' rho(|M|), iterated to the tolerance) must bracket the exact
 * radius and land within 1e-3 (relative) of it. */
static void check_power(const ulam_csr *A, double exact)
{
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS, go.tight = 1;
    ulam_guard g;
    assert_int_equal(ulam_guard_check(A, 0.0, &go, &g, NULL), ULAM_OK);
    const ulam_power p = g.abs;
    if (!(p.lower <= exact * (1 + 1e-12) && exact <= p.upper * (1 + 1e-12)))
        print_error("bounds [%.12g, %.12g] miss %.12g\n", p.lower, p.upper, exact);
    assert_true(p.lower <= exact * (1 + 1e-12) && exact <= p.upper * (1 + 1e-12));
    if (!p.converged) print_error("not converged: rho %.12g after %d iterations\n", p.rho, p.iterations);
    assert_close(p.rho, exact, 1e-3 * exact + 1e-4); /* relative, or absolute below tol */
    assert_true(p.converged);
}

/* Known Perron roots: a diagonal, a circulant, scaled stochastic matrices, Poisson's Jacobi
 * matrix (bipartite: -rho is an eigenvalue too, which the shifted iteration damps). */
static void test_power_known(void **state)
{
    (void)state;
    enum { N = 300 };
    int32_t i[N];
    double d[N], exact;
    for (int k = 0; k < N; k++) i[k] = k, d[k] = 0.2 + 0.7 * k / N;
    d[17] = -0.97;
    ulam_csr *A = build(N, N, i, i, d);
    check_power(A, 0.97);
    ulam_csr_free(A);
    A = circulant(101, &exact);
    check_power(A, 0.9); /* |C| = 0.6 P + 0.3 P' */
    ulam_csr_free(A);
    ulam_csr *P = must_read("matrices/poisson20.mtx");
    double b[400] = {0}, bp[400];
    ulam_csr *M = NULL;
    assert_int_equal(ulam_jacobi(P, b, 1.0, &M, bp, NULL), ULAM_OK);
    check_power(M, cos(M_PI / 21));
    ulam_csr_free(M);
    assert_int_equal(ulam_jacobi(P, b, 0.5, &M, bp, NULL), ULAM_OK);
    check_power(M, 0.5 + 0.5 * cos(M_PI / 21)); /* 1 - w + w rho(|J|) */
    ulam_csr_free(M), ulam_csr_free(P);
    int32_t si[3] = {1, 2, 3}, sj[3] = {0, 1, 2};
    double ones[3] = {1, 1, 1};
    A = build(4, 3, si, sj, ones); /* nilpotent */
    check_power(A, 0.0);
    ulam_csr_free(A);
}

/* The guards' three radii and verdicts on committed systems. */
static void test_guard(void **state)
{
    (void)state;
    ulam_csr *M = must_read("matrices/randsub1000.mtx");
    ulam_guard g;
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    assert_close(g.abs.rho, 0.9, 1e-9); /* doubly substochastic: analog M^ = |M| both ways */
    assert_close(g.hat[ULAM_ADJOINT].rho, 0.9, 1e-9);
    assert_close(g.hat[ULAM_FORWARD].rho, 0.9, 1e-9);
    assert_int_equal(g.verdict_abs, ULAM_VERDICT_OK);
    assert_int_equal(ulam_guard_check(M, 0.5, NULL, &g, NULL), ULAM_OK);
    assert_close(g.hat[ULAM_ADJOINT].rho, 0.81 / 0.5, 1e-9); /* M^ = diag(S / Q) |M| */
    assert_int_equal(g.verdict_abs, ULAM_VERDICT_OK);
    assert_int_equal(g.verdict_hat[ULAM_ADJOINT], ULAM_VERDICT_FAIL);
    ulam_csr_free(M);
    M = must_read("matrices/divergent200.mtx");
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    assert_close(g.abs.rho, 1.1, 1e-9);
    assert_true(g.abs.lower >= 1.0); /* certified */
    assert_int_equal(g.verdict_abs, ULAM_VERDICT_FAIL);
    ulam_csr_free(M);
}

/* Radii within 1e-3 of 1 on either side, where 1000 power iterations do not converge: a
 * verdict is certified only by bounds on one side of 1, otherwise it is unknown (never the
 * side the unconverged estimate happens to fall on). */
static void test_guard_near_one(void **state)
{
    (void)state;
    static const double radii[] = {1.0005, 1.0009, 0.9995, 0.9991};
    for (int k = 0; k < 4; k++) {
        if (!test_case(k)) continue;
        ulam_csr *M = near_one_matrix(300, radii[k]);
        ulam_guard g;
        assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
        int v = g.verdict_abs, certain = radii[k] > 1 ? ULAM_VERDICT_FAIL : ULAM_VERDICT_EDGE;
        if (!(g.abs.lower <= radii[k] * (1 + 1e-12) && radii[k] <= g.abs.upper * (1 + 1e-12)) ||
            (v != certain && v != ULAM_VERDICT_UNKNOWN))
            print_error("case %d: rho %.6g: verdict %d, bounds [%.6g, %.6g], estimate %.6g, %d iterations\n", k,
                        radii[k], v, g.abs.lower, g.abs.upper, g.abs.rho, g.abs.iterations);
        assert_true(g.abs.lower <= radii[k] * (1 + 1e-12) && radii[k] <= g.abs.upper * (1 + 1e-12));
        assert_true(v == certain || v == ULAM_VERDICT_UNKNOWN);
        if (v == ULAM_VERDICT_FAIL) assert_true(g.abs.lower >= 1.0);
        if (v == ULAM_VERDICT_EDGE) assert_true(g.abs.upper < 1.0);
        ulam_csr_free(M);
    }
    test_case_done();
    ulam_power p = {.rho = 0.995, .lower = 0.99, .upper = 1.001}; /* straddles 1: not certified */
    assert_int_equal(ulam_verdict_of(&p), ULAM_VERDICT_UNKNOWN);
    p = (ulam_power){.rho = 0.989, .lower = 0.985, .upper = 1.001001};
    assert_int_equal(ulam_verdict_of(&p), ULAM_VERDICT_UNKNOWN);
    p = (ulam_power){.rho = 0.995, .lower = 0.9, .upper = 0.999};
    assert_int_equal(ulam_verdict_of(&p), ULAM_VERDICT_EDGE);
    p = (ulam_power){.rho = 1.0, .lower = 1.0, .upper = 1.3};
    assert_int_equal(ulam_verdict_of(&p), ULAM_VERDICT_FAIL);
}

/* Column sums at most 1 with some below 1, every state reachable from those: rho < 1 strictly
 * (a certificate without iterating to it).  5-point Jacobi on a 200 x 200 grid: rho =
 * cos(pi / 201) = 0.99988, whose Collatz-Wielandt upper bound stays at 1 for thousands of
 * iterations; a closed pair of states with column sums 1 has rho = 1 and is not certified. */
static void test_guard_reach_certificate(void **state)
{
    (void)state;
    enum { L = 200, N = L * L };
    int32_t *ti = malloc(4 * N * sizeof *ti), *tj = malloc(4 * N * sizeof *tj);
    double *tx = malloc(4 * N * sizeof *tx);
    int64_t nz = 0;
    for (int r = 0; r < L; r++)
        for (int c = 0; c < L; c++) {
            int nb[4][2] = {{r - 1, c}, {r + 1, c}, {r, c - 1}, {r, c + 1}};
            for (int k = 0; k < 4; k++)
                if (nb[k][0] >= 0 && nb[k][0] < L && nb[k][1] >= 0 && nb[k][1] < L)
                    ti[nz] = r * L + c, tj[nz] = nb[k][0] * L + nb[k][1], tx[nz++] = 0.25;
        }
    ulam_csr *M = build(N, nz, ti, tj, tx);
    ulam_guard g;
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    print_message("grid 200 x 200: rho(|M|) in [%.6g, %.17g), %d iterations\n", g.abs.lower, g.abs.upper, g.abs.iterations);
    assert_int_equal(g.verdict_abs, ULAM_VERDICT_EDGE);
    assert_int_equal(g.verdict_hat[ULAM_ADJOINT], ULAM_VERDICT_EDGE);
    assert_true(g.abs.upper < 1.0 && g.abs.lower <= cos(M_PI / (L + 1)) && g.abs.iterations <= 20);
    ulam_csr_free(M);
    int32_t ci[4] = {0, 1, 2, 3}, cj[4] = {1, 0, 0, 2};
    double cx[4] = {1.0, 1.0, 0.0, 0.5};
    cx[2] = 1e-300; /* column 0 sums to 1 + 1e-300 (1 in double): no certificate, rho = 1 */
    M = build(4, 4, ci, cj, cx);
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    assert_true(g.verdict_abs == ULAM_VERDICT_FAIL || g.verdict_abs == ULAM_VERDICT_UNKNOWN);
    ulam_csr_free(M);
    free(ti), free(tj), free(tx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_diagonal),       cmocka_unit_test(test_circulant),
        cmocka_unit_test(test_clustered_reports_not_converged),
        cmocka_unit_test(test_scaled_stochastic), cmocka_unit_test(test_rotation_blocks),
        cmocka_unit_test(test_degenerate),     cmocka_unit_test(test_committed),
        cmocka_unit_test(test_power_known),
        cmocka_unit_test(test_guard),          cmocka_unit_test(test_guard_near_one),
        cmocka_unit_test(test_guard_reach_certificate),
    };
    return test_run(tests);
}
