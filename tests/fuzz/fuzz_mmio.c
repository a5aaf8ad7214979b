/* libFuzzer target: the Matrix Market reader, matrices and vectors, on arbitrary bytes.
 * Built with -Dfuzz=true (clang); the same entry point replays the committed corpus in the
 * normal test suite (replay.c). */
#include "ulam.h"

#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0) return 0;
    FILE *f = fmemopen((void *)data, size, "r");
    if (!f) return 0;
    ulam_csr *A = NULL;
    ulam_error err;
    if (ulam_mm_read_matrix_opts(f, "fuzz", NULL, &A, &err) == ULAM_OK) {
        ulam_csr_stats st;
        ulam_csr_stats_compute(A, &st);
    }
    ulam_csr_free(A);
    rewind(f);
    double *x = NULL;
    int64_t n = 0;
    ulam_mm_read_vector_file(f, "fuzz", &x, &n, &err);
    free(x);
    fclose(f);
    return 0;
}
