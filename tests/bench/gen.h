/* Shared by the benchmark programs: reproducible test systems and memory readings. */
#ifndef ULAM_BENCH_GEN_H
#define ULAM_BENCH_GEN_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ulam.h"

/* Radiosity-like M: n x n, 8 nonzeros a row at columns drawn uniformly (stream (n, 0)),
 * values 0.1 + U(0, 1) scaled so every row sums to 0.9, so rho(|M|) = rho(M) = 0.9 exactly
 * (the Perron root of a matrix with constant row sums). */
static inline ulam_csr *bench_random_csr(int64_t n)
{
    const int k = 8;
    ulam_csr *M = ulam_csr_alloc(n, n, n * k);
    if (!M) return NULL;
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)n, 0);
    for (int64_t i = 0; i < n; i++) {
        M->rowptr[i + 1] = (i + 1) * k;
        double sum = 0;
        for (int q = 0; q < k; q++) {
            M->colidx[i * k + q] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n);
            sum += M->val[i * k + q] = 0.1 + ulam_rng_uniform(&r);
        }
        for (int q = 0; q < k; q++) M->val[i * k + q] *= 0.9 / sum;
    }
    return M; /* a column drawn twice in a row is harmless for walking and solving */
}

/* b_i = 0.5 + U(0, 1) from stream (n, 1). */
static inline double *bench_random_rhs(int64_t n)
{
    double *b = malloc((size_t)n * sizeof *b);
    if (!b) return NULL;
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)n, 1);
    for (int64_t i = 0; i < n; i++) b[i] = 0.5 + ulam_rng_uniform(&r);
    return b;
}

/* Resident set size of this process now, in bytes (/proc/self/statm); 0 if unreadable. */
static inline double bench_rss(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2) res = 0;
        fclose(f);
    }
    return (double)res * (double)sysconf(_SC_PAGESIZE);
}

/* Peak resident set size of this process so far, in bytes (VmHWM); 0 if unreadable. */
static inline double bench_peak_rss(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) kb = atof(line + 6);
    if (f) fclose(f);
    return kb * 1024.0;
}

/* Bytes of a CSR matrix's three arrays. */
static inline double bench_csr_bytes(const ulam_csr *M)
{
    return (double)(M->nrows + 1) * 8.0 + (double)M->rowptr[M->nrows] * 12.0;
}

#endif
