/* Shared by the benchmarks that check against an exact column: (I - M)^-1 e_s by the library's
 * Gauss-Seidel iteration (gen.h's bench_gauss_seidel: public headers only). */
#ifndef ULAM_BENCH_EXACT_H
#define ULAM_BENCH_EXACT_H

#include "gen.h"

/* x = (I - M)^-1 e_s by Gauss-Seidel until no entry moves by more than 1e-15; the sweeps done
 * (b: n entries of scratch, e_s; old: n more). */
static inline int bench_exact_column(const ulam_csr *M, int64_t s, double *x, double *old, double *b)
{
    memset(b, 0, (size_t)M->nrows * sizeof *b);
    b[s] = 1.0;
    return bench_gauss_seidel(M, b, -1, 1e-15, 2000, x, old);
}

#endif
