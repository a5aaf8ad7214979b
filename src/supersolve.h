/* supersolve.h: a certified upper bound z >= m on the solution of m = r + A m (r >= 0, A >= 0
 * entrywise), found by lazy iterates and checked by one product; the caller gives A's product
 * (on one machine, or a rank's rows with a halo) and what a candidate is worth.  Private
 * (src/supersolve.c); used by the second moments of src/solve.c and src/dist_moment.c. */
#ifndef ULAM_SUPERSOLVE_H
#define ULAM_SUPERSOLVE_H

#include "internal.h"

/* What the search needs of A and of its caller.  Rows are the n held here; seen (NULL: all)
 * marks the rows that take part (others stay 0).  z candidates are m + bb (res + phi), res =
 * r + A m - m >= 0 (rounded up), stored times zscale. */
typedef struct ulam__super {
    void *ctx;
    int64_t n;
    const char *seen;
    double deadline; /* past it (ulam_now), the search ends once a candidate holds; INFINITY: none */
    double zscale;
    /* y = r + A v on the rows held here (r NULL: 0), each row's sum rounded up; nonzero: failed */
    int (*product)(void *ctx, const double *r, const double *v, double *y);
    /* x[0..k) replaced by their largest over all ranks; NULL on one machine; nonzero: failed */
    int (*largest)(void *ctx, double *x, int k);
    /* what candidate m + bb (res + phi) is worth here (the least is kept; combined by largest) */
    double (*worth)(void *ctx, const double *m, const double *res, double phi, double bb);
    /* each candidate that holds (NULL: not wanted) */
    void (*offer)(void *ctx, const double *m, const double *res, double phi, double bb);
} ulam__super;

/* Search for the certified z of least worth (written to z only where it improves; the caller
 * sets z first), its worth in *best (INFINITY: none held), products counted in *iterations
 * (NULL: not).  Nonzero on memory or a failed product or exchange. */
int ulam__super_solve(const ulam__super *s, const double *r, double *z, double *best, int *iterations);

#endif
