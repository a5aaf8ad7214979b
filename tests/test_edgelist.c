/* Edge lists (src/edgelist.c): the same CSR as the Matrix Market file of the graph, the id base,
 * every malformed line named, and the reader's choice between the two formats. */
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* Write text to a temporary file named with suffix; its path in path (size 64). */
static void write_temp(char *path, const char *suffix, const char *text)
{
    snprintf(path, 64, "/tmp/ulam_edgelist_%d_%s", (int)getpid(), suffix);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* A SNAP-style 0-based list and the 1-based Matrix Market of it give the same CSR. */
static void test_same_as_matrix_market(void **state)
{
    (void)state;
    ulam_csr *A = NULL, *B = NULL;
    ulam_error err;
    int64_t base = -1;
    assert_int_equal(ulam_edgelist_read("tests/data/graph7.txt", &A, &base, &err), ULAM_OK);
    assert_int_equal(ulam_mm_read_matrix("tests/data/graph7.mtx", &B, &err), ULAM_OK);
    assert_int_equal(base, 0);
    assert_int_equal(A->nrows, 7);
    assert_int_equal(A->nrows, B->nrows);
    assert_int_equal(A->rowptr[A->nrows], B->rowptr[B->nrows]);
    assert_memory_equal(A->rowptr, B->rowptr, (size_t)(A->nrows + 1) * sizeof *A->rowptr);
    assert_memory_equal(A->colidx, B->colidx, (size_t)A->rowptr[A->nrows] * sizeof *A->colidx);
    assert_memory_equal(A->val, B->val, (size_t)A->rowptr[A->nrows] * sizeof *A->val);
    ulam_csr_free(A), ulam_csr_free(B);
    assert_int_equal(ulam_edgelist_is_file("tests/data/graph7.txt"), 1);
    assert_int_equal(ulam_edgelist_is_file("tests/data/graph7.mtx"), 0);
    assert_int_equal(ulam_edgelist_is_file("tests/data/no_banner.mtx"), 0); /* named .mtx: the MM reader's error */
    char path[64]; /* a Matrix Market file named .txt: its banner decides, and the edge-list reader refuses it */
    write_temp(path, "mm.txt", "%%MatrixMarket matrix coordinate pattern general\n2 2 1\n1 2\n");
    assert_int_equal(ulam_edgelist_is_file(path), 0);
    assert_int_equal(ulam_edgelist_read(path, &A, NULL, &err), ULAM_ESYNTAX);
    assert_int_equal(err.line, 1);
    unlink(path);
}

/* 1-based ids, commas, CR LF, weights, duplicates summed, a trailing comment, no final newline. */
static void test_forms(void **state)
{
    (void)state;
    char path[64];
    write_temp(path, "forms.csv", "% a comment\r\n1,2,0.5\r\n  2\t3  # trailing\r\n\r\n1 2 0.25\r\n3 1 2");
    ulam_csr *A = NULL;
    ulam_error err;
    int64_t base = -1;
    assert_int_equal(ulam_edgelist_read(path, &A, &base, &err), ULAM_OK);
    assert_int_equal(base, 1);
    assert_int_equal(A->nrows, 3);
    assert_int_equal(A->rowptr[3], 3);
    assert_int_equal(A->colidx[0], 1);
    assert_true(A->val[0] == 0.75); /* 0.5 + 0.25 */
    assert_true(A->val[2] == 2.0);
    ulam_csr_free(A);
    assert_int_equal(ulam_edgelist_is_file(path), 1);
    unlink(path);
}

/* Each malformed input: its status and the line named. */
static void test_bad(void **state)
{
    (void)state;
    static const struct {
        const char *text;
        int status;
        long line;
    } cases[] = {
        {"# only comments\n\n", ULAM_EEMPTY, 2},
        {"1 2\n2 3\n3 two\n", ULAM_ESYNTAX, 3},
        {"1 2\n2\n", ULAM_ESYNTAX, 2},
        {"1 2 3 4\n", ULAM_ESYNTAX, 1},
        {"1 -2\n", ULAM_ESYNTAX, 1},
        {"1 2 -1\n", ULAM_ERANGE, 1},
        {"1 2 nan\n", ULAM_ERANGE, 1},
        {"1 2\n3 99999999999\n", ULAM_ESYNTAX, 2},
        {"1 2\n2 2000000000\n", ULAM_EOVERFLOW, 0}, /* 2e9 nodes for 2 edges */
        {"1 2\n2 3\0 junk\n", ULAM_ESYNTAX, 2},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char path[64];
        snprintf(path, sizeof path, "/tmp/ulam_edgelist_%d_bad.txt", (int)getpid());
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        size_t len = strlen(cases[k].text);
        if (k == sizeof cases / sizeof cases[0] - 1) len = sizeof "1 2\n2 3\0 junk\n" - 1; /* the NUL case: past the NUL */
        fwrite(cases[k].text, 1, len, f);
        fclose(f);
        ulam_csr *A = NULL;
        ulam_error err;
        int status = ulam_edgelist_read(path, &A, NULL, &err);
        if (status != cases[k].status || err.line != cases[k].line)
            fail_msg("case %zu: status %d line %ld (%s), want %d line %ld", k, status, err.line, err.msg, cases[k].status,
                     cases[k].line);
        assert_null(A);
        unlink(path);
    }
    ulam_csr *A = NULL;
    ulam_error err;
    assert_int_equal(ulam_edgelist_read("tests/data/does_not_exist.txt", &A, NULL, &err), ULAM_EIO);
    assert_int_equal(ulam_edgelist_read("tests/data", &A, NULL, &err), ULAM_EIO);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_as_matrix_market),
        cmocka_unit_test(test_forms),
        cmocka_unit_test(test_bad),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
