/* The LAPACK reference solve: a hand-checked system, residuals, and every refusal. */
#include "testutil.h"

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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
