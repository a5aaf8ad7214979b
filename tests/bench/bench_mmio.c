/* Benchmark: Matrix Market parse speed on a 10^7-nonzero file (target >= 50 MB/s).
 * Writes the file to a temporary directory (values with 17 significant digits, as
 * ulam_mm_write_matrix produces), reads it back three times and prints a table. */
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ulam.h"

int main(void)
{
    const int64_t n = 1250000, k = 8, nnz = n * k;
    char path[] = "/tmp/ulam_bench_mmioXXXXXX";
    int fd = mkstemp(path);
    if (fd < 0) return 1;
    FILE *f = fdopen(fd, "w");
    ulam_rng r;
    ulam_rng_seed(&r, 1, 0);
    fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n%lld %lld %lld\n", (long long)n,
            (long long)n, (long long)nnz);
    for (int64_t i = 0; i < n; i++)
        for (int64_t q = 0; q < k; q++)
            fprintf(f, "%lld %llu %.17g\n", (long long)i + 1,
                    (unsigned long long)ulam_rng_bounded(&r, (uint64_t)n) + 1, ulam_rng_uniform(&r) / 8);
    fclose(f);
    struct stat st;
    stat(path, &st);
    double mb = (double)st.st_size / 1e6, best = 1e30;
    printf("%-28s %10s %10s %10s %10s\n", "benchmark", "MB", "nnz", "seconds", "MB/s");
    for (int rep = 0; rep < 3; rep++) {
        ulam_csr *A = NULL;
        double t0 = ulam_now();
        int s = ulam_mm_read_matrix(path, &A, NULL);
        double t = ulam_now() - t0;
        if (s) {
            fprintf(stderr, "read failed: %s\n", ulam_strerror(s));
            remove(path);
            return 1;
        }
        if (t < best) best = t;
        printf("%-28s %10.1f %10lld %10.3f %10.1f\n", "mm_read (10^7 nnz)", mb,
               (long long)ulam_csr_nnz(A), t, mb / t);
        ulam_csr_free(A);
    }
    remove(path);
    printf("best: %.1f MB/s (target >= 50 MB/s): %s\n", mb / best, mb / best >= 50 ? "met" : "MISSED");
    return 0;
}
