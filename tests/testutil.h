/* Helpers shared by the tests; like the tests, it includes only the public header. */
#ifndef ULAM_TESTUTIL_H
#define ULAM_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "ulam.h"

/* Fail unless |a - b| <= tol (cmocka 1.1 has no assert_double_equal). */
#define assert_close(a, b, tol) assert_close_((a), (b), (tol), #a, __FILE__, __LINE__)

static inline void assert_close_(double a, double b, double tol, const char *expr, const char *file,
                                 int line)
{
    if (!(fabs(a - b) <= tol)) {
        print_error("%s = %.17g, expected %.17g within %g (off by %.3g)\n", expr, a, b, tol, fabs(a - b));
        _fail(file, line);
    }
}

/* Path of a file under the source tree (tests run with the source root as cwd). */
static inline const char *src_path(const char *rel)
{
    static char buf[4][1024];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s", rel);
    return buf[k];
}

/* Read a matrix that must parse. */
static inline ulam_csr *must_read(const char *rel)
{
    ulam_csr *A = NULL;
    ulam_error err;
    int s = ulam_mm_read_matrix(src_path(rel), &A, &err);
    if (s) print_error("%s:%ld: %s: %s\n", rel, err.line, ulam_strerror(s), err.msg);
    assert_int_equal(s, ULAM_OK);
    return A;
}

/* Read a vector that must parse. */
static inline double *must_read_vector(const char *rel, int64_t *n)
{
    double *x = NULL;
    ulam_error err;
    int s = ulam_mm_read_vector(src_path(rel), &x, n, &err);
    if (s) print_error("%s:%ld: %s: %s\n", rel, err.line, ulam_strerror(s), err.msg);
    assert_int_equal(s, ULAM_OK);
    return x;
}

/* Value of A(i, j), 0 when not stored. */
static inline double csr_get(const ulam_csr *A, int64_t i, int64_t j)
{
    for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
        if (A->colidx[k] == j) return A->val[k];
    return 0.0;
}

/* Fail unless A and B are the same matrix, array for array. */
static inline void assert_csr_same(const ulam_csr *A, const ulam_csr *B)
{
    assert_int_equal(A->nrows, B->nrows);
    assert_int_equal(A->ncols, B->ncols);
    assert_int_equal(ulam_csr_nnz(A), ulam_csr_nnz(B));
    assert_memory_equal(A->rowptr, B->rowptr, (size_t)(A->nrows + 1) * sizeof *A->rowptr);
    assert_memory_equal(A->colidx, B->colidx, (size_t)ulam_csr_nnz(A) * sizeof *A->colidx);
    assert_memory_equal(A->val, B->val, (size_t)ulam_csr_nnz(A) * sizeof *A->val);
}

#endif
