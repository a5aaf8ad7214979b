/* CSR construction, transposition, products, statistics and the Jacobi splitting. */
#include "testutil.h"

#include <string.h>

enum { NCASES = 20 };

/* Random triplets (with duplicates and zeros) for case k: the case index is the seed. */
static int64_t random_triplets(int k, int64_t *n, int32_t **ti, int32_t **tj, double **tx)
{
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)k, 7);
    *n = 1 + (int64_t)ulam_rng_bounded(&r, 40);
    int64_t nz = (int64_t)ulam_rng_bounded(&r, (uint64_t)(*n * *n) + 1);
    *ti = malloc((size_t)(nz + 1) * sizeof **ti);
    *tj = malloc((size_t)(nz + 1) * sizeof **tj);
    *tx = malloc((size_t)(nz + 1) * sizeof **tx);
    for (int64_t q = 0; q < nz; q++) {
        (*ti)[q] = (int32_t)ulam_rng_bounded(&r, (uint64_t)*n);
        (*tj)[q] = (int32_t)ulam_rng_bounded(&r, (uint64_t)*n);
        (*tx)[q] = ulam_rng_uniform(&r) < 0.1 ? 0.0 : ulam_rng_uniform(&r) - 0.5;
    }
    return nz;
}

/* from_triplets equals dense accumulation, rows sorted, no zeros stored. */
/* A's dense row-major copy into d (nrows x ncols). */
static void to_dense(const ulam_csr *A, double *d)
{
    for (int64_t i = 0; i < A->nrows * A->ncols; i++) d[i] = 0.0;
    for (int64_t i = 0; i < A->nrows; i++)
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) d[i * A->ncols + A->colidx[q]] = A->val[q];
}

static void test_from_triplets(void **state)
{
    (void)state;
    for (int k = 0; k < NCASES; k++) {
        if (!test_case(k)) continue;
        int64_t n;
        int32_t *ti, *tj;
        double *tx;
        int64_t nz = random_triplets(k, &n, &ti, &tj, &tx);
        double *dense = calloc((size_t)(n * n), sizeof *dense);
        for (int64_t q = 0; q < nz; q++) dense[ti[q] * n + tj[q]] += tx[q];
        ulam_csr *A = NULL;
        assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A), ULAM_OK);
        double *got = malloc((size_t)(n * n) * sizeof *got);
        to_dense(A, got);
        for (int64_t i = 0; i < n * n; i++) assert_close(got[i], dense[i], 1e-12);
        for (int64_t i = 0; i < n; i++)
            for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) {
                assert_true(A->val[q] != 0.0);
                if (q > A->rowptr[i]) assert_true(A->colidx[q - 1] < A->colidx[q]);
            }
        ulam_csr_free(A);
        free(ti), free(tj), free(tx), free(dense), free(got);
    }
    test_case_done();
}

/* Transposing swaps entries, and twice gives the matrix back. */
static void test_transpose(void **state)
{
    (void)state;
    for (int k = 0; k < NCASES; k++) {
        if (!test_case(k)) continue;
        int64_t n;
        int32_t *ti, *tj;
        double *tx;
        int64_t nz = random_triplets(k, &n, &ti, &tj, &tx);
        ulam_csr *A = NULL, *T = NULL, *TT = NULL;
        assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A), ULAM_OK);
        assert_int_equal(ulam_csr_transpose(A, &T), ULAM_OK);
        assert_int_equal(ulam_csr_transpose(T, &TT), ULAM_OK);
        for (int64_t i = 0; i < n; i++)
            for (int64_t j = 0; j < n; j++) assert_close(csr_get(T, j, i), csr_get(A, i, j), 0);
        assert_csr_same(A, TT);
        ulam_csr_free(A), ulam_csr_free(T), ulam_csr_free(TT);
        free(ti), free(tj), free(tx);
    }
    test_case_done();
}

/* y = A x and y = |A| x against the dense products. */
static void test_matvec(void **state)
{
    (void)state;
    ulam_csr *A = must_read("matrices/signed200.mtx");
    int64_t n = A->nrows;
    double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y),
           *ya = malloc((size_t)n * sizeof *ya), *d = malloc((size_t)(n * n) * sizeof *d);
    for (int64_t i = 0; i < n; i++) x[i] = sin((double)i);
    to_dense(A, d);
    ulam_csr_matvec(A, 0, x, y);
    ulam_csr_matvec(A, 1, x, ya);
    for (int64_t i = 0; i < n; i++) {
        double s = 0, sa = 0;
        for (int64_t j = 0; j < n; j++) s += d[i * n + j] * x[j], sa += fabs(d[i * n + j]) * x[j];
        assert_close(y[i], s, 1e-12);
        assert_close(ya[i], sa, 1e-12);
    }
    free(x), free(y), free(ya), free(d);
    ulam_csr_free(A);
}

/* The lecture chain's statistics, checked by hand. */
static void test_stats(void **state)
{
    (void)state;
    ulam_csr *M = must_read("matrices/chain4.mtx");
    ulam_csr_stats st;
    assert_int_equal(ulam_csr_stats_compute(M, &st), ULAM_OK);
    assert_int_equal(st.n, 4);
    assert_int_equal(st.nnz, 9);
    assert_int_equal(st.row_nnz_min, 2);
    assert_int_equal(st.row_nnz_max, 3);
    assert_close(st.row_nnz_mean, 2.25, 1e-15);
    assert_true(st.nonnegative);
    assert_true(st.substochastic);
    assert_close(st.abs_rowsum_min, 0.6, 1e-15);
    assert_close(st.abs_rowsum_max, 0.8, 1e-15);
    ulam_csr_free(M);
    ulam_csr *S = must_read("matrices/signed200.mtx");
    ulam_csr_stats_compute(S, &st);
    assert_false(st.nonnegative);
    assert_false(st.substochastic);
    ulam_csr_free(S);
}

/* Jacobi on the Poisson matrix: off-diagonals 1/4, b / 4; damping puts 1 - omega on the diagonal. */
static void test_jacobi(void **state)
{
    (void)state;
    ulam_csr *A = must_read("matrices/poisson20.mtx");
    int64_t n = A->nrows;
    double *b = malloc((size_t)n * sizeof *b), *bp = malloc((size_t)n * sizeof *bp);
    for (int64_t i = 0; i < n; i++) b[i] = (double)i;
    ulam_csr *M = NULL;
    assert_int_equal(ulam_jacobi(A, b, 1.0, &M, bp, NULL), ULAM_OK);
    assert_int_equal(ulam_csr_nnz(M), ulam_csr_nnz(A) - n);
    assert_close(csr_get(M, 0, 1), 0.25, 0);
    assert_close(csr_get(M, 21, 1), 0.25, 0);
    assert_close(bp[7], 7.0 / 4.0, 0);
    ulam_csr_free(M);
    assert_int_equal(ulam_jacobi(A, b, 0.8, &M, bp, NULL), ULAM_OK);
    assert_close(csr_get(M, 5, 5), 0.2, 1e-15);
    assert_close(csr_get(M, 0, 1), 0.2, 1e-15);
    assert_close(bp[8], 0.8 * 8.0 / 4.0, 1e-15);
    ulam_csr_free(M);
    free(b), free(bp);
    ulam_csr_free(A);
}

/* A zero diagonal names its row; a rectangular A is refused. */
static void test_jacobi_errors(void **state)
{
    (void)state;
    ulam_csr *A = must_read("tests/data/zero_diagonal.mtx");
    double b[3] = {1, 1, 1}, bp[3];
    ulam_csr *M = NULL;
    ulam_error err;
    assert_int_equal(ulam_jacobi(A, b, 1.0, &M, bp, &err), ULAM_EZERODIAG);
    assert_null(M);
    assert_int_equal(err.index, 1);
    ulam_csr_free(A);
    A = must_read("tests/data/nonsquare.mtx");
    assert_int_equal(ulam_jacobi(A, b, 1.0, &M, bp, &err), ULAM_ENOTSQUARE);
    ulam_csr_free(A);
}

/* Bad triplets are refused; _free accepts NULL. */
static void test_invalid(void **state)
{
    (void)state;
    int32_t i[1] = {3}, j[1] = {0};
    double x[1] = {1};
    ulam_csr *A = NULL;
    assert_int_equal(ulam_csr_from_triplets(3, 3, 1, i, j, x, &A), ULAM_EINVAL);
    assert_null(A);
    assert_null(ulam_csr_free(NULL));
    assert_null(ulam_csr_alloc(-1, 3, 0));
    assert_null(ulam_csr_alloc(3, 3, INT64_MAX));     /* nnz x sizeof overflows size_t */
    assert_null(ulam_csr_alloc(3, 3, INT64_MAX / 8)); /* fits size_t, no such memory */
    assert_null(ulam_csr_alloc((int64_t)1 << 40, 3, 0)); /* past ULAM_MAX_DIM */
    assert_string_equal(ulam_strerror(ULAM_OK), "success");
    assert_string_equal(ulam_strerror(-5), "unknown status");
    for (int s = 0; s < ULAM_NSTATUS; s++) assert_true(strlen(ulam_strerror(s)) > 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_from_triplets), cmocka_unit_test(test_transpose),
        cmocka_unit_test(test_matvec),        cmocka_unit_test(test_stats),
        cmocka_unit_test(test_jacobi),        cmocka_unit_test(test_jacobi_errors),
        cmocka_unit_test(test_invalid),
    };
    return test_run(tests);
}
