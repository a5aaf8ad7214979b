/* Running moments (internal): Welford's update, Chan's exact pairwise merge. */
#ifndef ULAM_STATS_H
#define ULAM_STATS_H

#include <stdint.h>

typedef struct {
    int64_t n;
    double mean, m2; /* m2: sum of squared deviations from the mean */
    double m3, m4;   /* sums of cubed and fourth-power deviations (Pebay's updates) */
} ulam__moments;

/* Add one observation (B. P. Welford, Technometrics 4(3), 1962). */
void ulam__moments_add(ulam__moments *m, double x);

/* Merge b into a (Chan, Golub and LeVeque, "Updating formulae and a pairwise algorithm for
 * computing sample variances", 1979). */
void ulam__moments_merge(ulam__moments *a, const ulam__moments *b);

/* Sample variance (n - 1 denominator); 0 when n < 2. */
double ulam__moments_variance(const ulam__moments *m);

/* The relative standard error of the sample variance itself, sqrt((mu4 - s^4) / n) / s^2 from
 * the fourth central moment (P. Pebay, "Formulas for robust, one-pass parallel computation of
 * covariances and arbitrary-order statistical moments", Sandia SAND2008-6212): large while the
 * sample has seen a rare large score only a few times.  INFINITY when the variance is 0. */
double ulam__moments_variance_rel_error(const ulam__moments *m);

#endif
