/* The LAPACK reference solve: a hand-checked system, residuals, and every refusal; the sparse
 * (UMFPACK) one against it; PageRank's matrix; the study's reference (LAPACK or Gauss-Seidel), its
 * method grid and its coverage interval. */
#include "testutil.h"
#include "ulam_reference.h"
#include "ulam_study.h"

#include <math.h>
#include <string.h>

/* M = [0 .5 0; .25 0 .25; 0 .5 0], b = (1, 2, 3): x = (3, 4, 5) and rcond_1 = 3/16 by hand. */
static void test_hand_checked(void **state)
{
    (void)state;
    int32_t i[4] = {0, 1, 1, 2}, j[4] = {1, 0, 2, 1};
    double v[4] = {0.5, 0.25, 0.25, 0.5}, b[3] = {1, 2, 3}, x[3];
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(3, 3, 4, i, j, v, &M), ULAM_OK);
    ulam_direct_info info;
    assert_int_equal(ulam_direct_solve(M, b, x, 0, &info, NULL), ULAM_OK);
    assert_close(x[0], 3.0, 1e-14);
    assert_close(x[1], 4.0, 1e-14);
    assert_close(x[2], 5.0, 1e-14);
    assert_close(info.rcond, 3.0 / 16.0, 1e-12);
    assert_true(info.residual < 1e-15);
    assert_true(info.seconds >= 0.0);
    ulam_csr_free(M);
}

/* Every committed system solves to a residual at rounding level. */
static void test_residuals(void **state)
{
    (void)state;
    static const char *const names[] = {"chain4", "randsub1000", "radiosity100", "signed200",
                                        "signed_edge200", "divergent200"};
    char mp[256], bpath[256];
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        if (!test_case((long)k)) continue;
        snprintf(mp, sizeof mp, "matrices/%s.mtx", names[k]);
        snprintf(bpath, sizeof bpath, "matrices/%s_b.mtx", names[k]);
        ulam_csr *M = must_read(mp);
        int64_t n;
        double *b = must_read_vector(bpath, &n);
        assert_int_equal(n, M->nrows);
        double *x = malloc((size_t)n * sizeof *x);
        ulam_direct_info info;
        assert_int_equal(ulam_direct_solve(M, b, x, 0, &info, NULL), ULAM_OK);
        assert_true(info.residual < 1e-12);
        assert_true(info.rcond > 1e-6 && info.rcond <= 1.0);
        free(x), free(b);
        ulam_csr_free(M);
    }
    test_case_done();
}

/* Jacobi splitting of the Poisson system: x of (I - M) x = b' solves A x = b. */
static void test_jacobi_poisson(void **state)
{
    (void)state;
    ulam_csr *A = must_read("matrices/poisson20.mtx");
    int64_t n;
    double *b = must_read_vector("matrices/poisson20_b.mtx", &n);
    double *bp = malloc((size_t)n * sizeof *bp), *x = malloc((size_t)n * sizeof *x),
           *ax = malloc((size_t)n * sizeof *ax);
    ulam_csr *M = NULL;
    assert_int_equal(ulam_jacobi(A, b, 1.0, &M, bp, NULL), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, bp, x, 0, NULL, NULL), ULAM_OK);
    ulam_csr_matvec(A, 0, x, ax);
    for (int64_t i = 0; i < n; i++) assert_close(ax[i], b[i], 1e-10);
    free(b), free(bp), free(x), free(ax);
    ulam_csr_free(A), ulam_csr_free(M);
}

/* ulam_solution_bound: a certified range around any x holds the exact solution and is as narrow as
 * the residual allows.  x = LAPACK's solution plus a perturbation of size d (a sine, both signs):
 * every range holds LAPACK's x (to its rounding, 1e-12 relative), its half-width is at least d's
 * effect and, on systems whose certificate is tight, within 100x of it.  randsub1000 (rows of |M|
 * below 1: v = 1), poisson20 by its Jacobi splitting (interior rows of M sum to exactly 1: the
 * expected lengths' certificate), signed200 (signed M); divergent200 (rho(|M|) = 1.1) is refused
 * with NaN ends, a non-finite x with its row. */
static void test_solution_bound(void **state)
{
    (void)state;
    const char *names[] = {"randsub1000", "poisson20", "signed200"};
    for (int k = 0; k < 3; k++) {
        char mp[96], bpath[96];
        snprintf(mp, sizeof mp, "matrices/%s.mtx", names[k]), snprintf(bpath, sizeof bpath, "matrices/%s_b.mtx", names[k]);
        ulam_csr *M = must_read(mp);
        int64_t n;
        double *b = must_read_vector(bpath, &n), *bp = malloc((size_t)n * sizeof *bp);
        if (k == 1) { /* the Jacobi splitting */
            ulam_csr *J = NULL;
            assert_int_equal(ulam_jacobi(M, b, 1.0, &J, bp, NULL), ULAM_OK);
            ulam_csr_free(M), M = J;
        } else memcpy(bp, b, (size_t)n * sizeof *bp);
        double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y);
        double *lo = malloc((size_t)n * sizeof *lo), *hi = malloc((size_t)n * sizeof *hi), worst;
        assert_int_equal(ulam_direct_solve(M, bp, x, 0, NULL, NULL), ULAM_OK);
        for (int d = 0; d < 3; d++) {
            double size = d == 0 ? 0.0 : d == 1 ? 1e-9 : 1e-3, top = 0.0;
            for (int64_t i = 0; i < n; i++) y[i] = x[i] + size * sin(0.37 * (double)i + 1.0), top = fmax(top, fabs(x[i]));
            assert_int_equal(ulam_solution_bound(M, bp, y, lo, hi, &worst, NULL), ULAM_OK);
            int held = 0;
            for (int64_t i = 0; i < n; i++) {
                double slack = 1e-12 * top; /* LAPACK's own rounding */
                held += lo[i] - slack <= x[i] && x[i] <= hi[i] + slack && lo[i] <= y[i] && y[i] <= hi[i];
            }
            print_message("%s, perturbation %g: every x_i within %g, %lld of %lld ranges hold x\n", names[k], size, worst,
                          (long long)held, (long long)n);
            assert_int_equal(held, n);
            if (d == 2) assert_true(worst >= 0.5 * size && (k != 0 || worst <= 100.0 * size));
        }
        free(b), free(bp), free(x), free(y), free(lo), free(hi);
        ulam_csr_free(M);
    }
    ulam_csr *M = must_read("matrices/divergent200.mtx");
    int64_t n;
    double *b = must_read_vector("matrices/divergent200_b.mtx", &n), *x = calloc((size_t)n, sizeof *x);
    double *lo = malloc((size_t)n * sizeof *lo), *hi = malloc((size_t)n * sizeof *hi), worst = 0;
    ulam_error err;
    assert_int_equal(ulam_solution_bound(M, b, x, lo, hi, &worst, &err), ULAM_EDIVERGE);
    assert_true(isnan(lo[0]) && isnan(hi[n - 1]) && worst == INFINITY);
    x[5] = NAN;
    assert_int_equal(ulam_solution_bound(M, b, x, lo, hi, &worst, &err), ULAM_EINVAL);
    assert_int_equal(err.index, 5);
    assert_int_equal(ulam_solution_bound(M, b, NULL, lo, hi, &worst, &err), ULAM_EINVAL);
    free(b), free(x), free(lo), free(hi);
    ulam_csr_free(M);
}

/* A singular I - M is reported as such, not as numbers. */
static void test_singular(void **state)
{
    (void)state;
    ulam_csr *M = must_read("tests/data/singular.mtx");
    double b[3] = {1, 1, 1}, x[3];
    ulam_error err;
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, &err), ULAM_ESINGULAR);
    assert_int_equal(err.status, ULAM_ESINGULAR);
    assert_true(err.index >= 0);
    ulam_csr_free(M);
}

/* The memory limit refuses before allocating and says what it would need. */
static void test_memory_limit(void **state)
{
    (void)state;
    ulam_csr *M = must_read("matrices/randsub1000.mtx");
    double *b = calloc(1000, sizeof *b), *x = calloc(1000, sizeof *x);
    ulam_error err;
    assert_int_equal(ulam_direct_solve(M, b, x, 1 << 20, NULL, &err), ULAM_EMEMLIMIT);
    assert_non_null(strstr(err.msg, "needs"));
    assert_true(ulam_direct_bytes(1000) >= 8000000);
    assert_int_equal(ulam_direct_bytes(INT64_MAX / 2), 0); /* n*n overflows: no size */
    free(b), free(x);
    ulam_csr_free(M);
}

/* The sparse LU agrees with the dense one on every committed system (unsorted, duplicate-free CSR
 * with the diagonal merged), refuses a singular I - M and a too-small memory limit, and its
 * estimate bounds what it needs; without UMFPACK every call says so. */
static void test_sparse(void **state)
{
    (void)state;
    static const char *const names[] = {"chain4", "randsub1000", "radiosity100", "signed200", "poisson900"};
    char mp[256], bpath[256];
    ulam_error err;
    ulam_reference_info plan;
    ulam_direct_info info;
    assert_int_equal(ulam_reference_plan(NULL, 1, 0, &plan, NULL), ULAM_OK);
    if (!plan.umfpack) {
        ulam_csr *M = must_read("matrices/chain4.mtx");
        double b[4] = {1, 1, 1, 1}, x[4];
        assert_int_equal(ulam_reference_solve(M, b, 1, 0, 0, x, &info, NULL, &err), ULAM_EUNSUPPORTED);
        assert_int_equal(ulam_reference_plan(M, 1, 1, &plan, &err), ULAM_EUNSUPPORTED);
        ulam_csr_free(M);
        return;
    }
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        snprintf(mp, sizeof mp, "matrices/%s.mtx", names[k]);
        snprintf(bpath, sizeof bpath, "matrices/%s_b.mtx", names[k]);
        ulam_csr *M = must_read(mp);
        int64_t n;
        double *b = must_read_vector(bpath, &n);
        double *x = malloc((size_t)n * sizeof *x), *xs = malloc((size_t)n * sizeof *xs);
        const char *how = NULL;
        assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
        assert_int_equal(ulam_reference_solve(M, b, 1, 0, 0, xs, &info, &how, &err), ULAM_OK);
        assert_string_equal(how, "sparse LU");
        for (int64_t i = 0; i < n; i++) assert_close(xs[i], x[i], 1e-10 * (1 + fabs(x[i])));
        assert_true(info.residual < 1e-12 && info.seconds >= 0);
        assert_int_equal(ulam_reference_plan(M, 1, 1, &plan, NULL), ULAM_OK);
        assert_true(plan.sparse && plan.bytes >= (double)info.bytes && plan.bytes > 0 && plan.flops >= 0);
        assert_int_equal(ulam_reference_solve(M, b, 1, 16, 0, xs, &info, NULL, &err), ULAM_EMEMLIMIT);
        free(x), free(xs), free(b);
        ulam_csr_free(M);
    }
    ulam_csr *S = must_read("tests/data/singular.mtx");
    double b3[3] = {1, 1, 1}, x3[3];
    assert_int_equal(ulam_reference_solve(S, b3, 1, 0, 0, x3, &info, NULL, &err), ULAM_ESINGULAR);
    ulam_csr_free(S);
}

/* PageRank's M = alpha P^T: column j of M is alpha times node j's out-edges normalised (a dangling
 * node's column is zero), and a negative weight is refused naming its row. */
static void test_pagerank_matrix(void **state)
{
    (void)state;
    int32_t i[5] = {0, 0, 1, 2, 2}, j[5] = {1, 2, 2, 0, 3};
    double v[5] = {1, 3, 2, 1, 1};
    ulam_csr *A = NULL, *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(4, 4, 5, i, j, v, &A), ULAM_OK);
    assert_int_equal(ulam_pagerank_matrix(A, 0.85, &M, NULL), ULAM_OK);
    double dense[4][4] = {{0}};
    for (int64_t r = 0; r < 4; r++)
        for (int64_t k = M->rowptr[r]; k < M->rowptr[r + 1]; k++) dense[r][M->colidx[k]] += M->val[k];
    assert_close(dense[1][0], 0.85 * 0.25, 1e-15); /* 0 -> 1 of weight 1 among 4 */
    assert_close(dense[2][0], 0.85 * 0.75, 1e-15);
    assert_close(dense[2][1], 0.85, 1e-15);
    assert_close(dense[0][2], 0.85 * 0.5, 1e-15);
    assert_close(dense[3][2], 0.85 * 0.5, 1e-15);
    for (int r = 0; r < 4; r++) assert_close(dense[r][3], 0.0, 0.0); /* node 4 dangles */
    ulam_csr_free(M);
    A->val[3] = -1;
    ulam_error err;
    assert_int_equal(ulam_pagerank_matrix(A, 0.85, &M, &err), ULAM_EINVAL);
    assert_int_equal(err.index, 2);
    assert_int_equal(ulam_pagerank_matrix(A, 1.0, &M, NULL), ULAM_EINVAL);
    ulam_csr_free(A);
}

/* The Wilson interval: 19/20 is [0.764, 0.991] (the textbook value), 0/10 starts at 0 and 10/10
 * ends at 1, and it always holds k / n. */
static void test_coverage_interval(void **state)
{
    (void)state;
    double lo, hi;
    ulam_study_coverage_interval(19, 20, &lo, &hi);
    assert_close(lo, 0.7639, 1e-4);
    assert_close(hi, 0.9911, 1e-4);
    ulam_study_coverage_interval(0, 10, &lo, &hi);
    assert_true(lo == 0.0 && hi > 0.2 && hi < 0.35);
    ulam_study_coverage_interval(10, 10, &lo, &hi);
    assert_true(hi == 1.0 && lo > 0.65 && lo < 0.8);
    for (int k = 0; k <= 30; k++) {
        ulam_study_coverage_interval(k, 30, &lo, &hi);
        assert_true(lo <= k / 30.0 && k / 30.0 <= hi);
    }
}

/* A rectangular matrix is refused. */
static void test_not_square(void **state)
{
    (void)state;
    ulam_csr *M = must_read("tests/data/nonsquare.mtx");
    double b[3] = {1, 1, 1}, x[3];
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_ENOTSQUARE);
    ulam_csr_free(M);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand_checked), cmocka_unit_test(test_residuals),
        cmocka_unit_test(test_jacobi_poisson), cmocka_unit_test(test_singular),
        cmocka_unit_test(test_memory_limit), cmocka_unit_test(test_not_square),
        cmocka_unit_test(test_sparse), cmocka_unit_test(test_pagerank_matrix),
        cmocka_unit_test(test_coverage_interval), cmocka_unit_test(test_solution_bound),
    };
    return test_run(tests);
}
