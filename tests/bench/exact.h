/* Shared by the benchmarks that check against an exact column: (I - M)^-1 e_s by the library's
 * private Gauss-Seidel sweep (so apart from gen.h, whose helpers need only the public header). */
#ifndef ULAM_BENCH_EXACT_H
#define ULAM_BENCH_EXACT_H

#include "gen.h"
#include "../../src/internal.h" /* ulam__gauss_seidel_sweep */

/* x = (I - M)^-1 e_s by Gauss-Seidel until no entry moves by more than 1e-15; the sweeps done. */
static inline int bench_exact_column(const ulam_csr *M, int64_t s, double *x, double *old, double *b)
{
    int64_t n = M->nrows;
    memset(x, 0, (size_t)n * sizeof *x);
    memset(b, 0, (size_t)n * sizeof *b);
    b[s] = 1.0;
    int sweeps = 0;
    for (double change = INFINITY; change > 1e-15 && sweeps < 2000; sweeps++) {
        memcpy(old, x, (size_t)n * sizeof *x);
        ulam__gauss_seidel_sweep(M, b, x);
        change = 0;
        for (int64_t i = 0; i < n; i++) change = fmax(change, fabs(x[i] - old[i]));
    }
    return sweeps;
}

#endif
