/* libFuzzer target: the Matrix Market reader, matrices and vectors, on arbitrary bytes.
 * Built with -Dfuzz=true (clang); the same entry point replays the committed corpus in the
 * normal test suite (replay.c). */
#define _GNU_SOURCE /* memfd_create */
#include "ulam.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

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
    fclose(f);
    int fd = memfd_create("fuzz", 0); /* the vector reader takes a path: the bytes in memory, by name */
    if (fd < 0) return 0;
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    double *x = NULL;
    int64_t n = 0;
    if (write(fd, data, size) == (ssize_t)size) ulam_mm_read_vector(path, &x, &n, &err);
    free(x);
    close(fd);
    return 0;
}
