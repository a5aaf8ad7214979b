/* Running moments (internal): Welford's update, Chan's exact pairwise merge. */
#ifndef ULAM_STATS_H
#define ULAM_STATS_H

#include <stdint.h>

typedef struct {
    int64_t n;
    double mean, m2; /* m2: sum of squared deviations from the mean */
} ulam__moments;

/* Add one observation (B. P. Welford, Technometrics 4(3), 1962). */
void ulam__moments_add(ulam__moments *m, double x);

/* Merge b into a (Chan, Golub and LeVeque, "Updating formulae and a pairwise algorithm for
 * computing sample variances", 1979). */
void ulam__moments_merge(ulam__moments *a, const ulam__moments *b);

/* Sample variance (n - 1 denominator); 0 when n < 2. */
double ulam__moments_variance(const ulam__moments *m);

#endif
