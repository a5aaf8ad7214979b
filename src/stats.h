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
 * sample has seen a rare large score only a few times.  INFINITY below two observations, 0
 * when every observation is alike. */
double ulam__moments_variance_rel_error(const ulam__moments *m);

/* The mean and sample variance (n - 1 denominator, never negative) of n observations given by
 * their sum and sum of squares (forward tallies, shooting tallies: components that most
 * observations leave at 0 are kept as sums, not moments); mean 0 and variance 0 below n = 1
 * and n = 2. */
void ulam__sums_moments(double n, double sum, double sumsq, double *mean, double *variance);

/* The fewest walks a --rel-err run makes before the rules that give up (out of reach, cuts) may
 * stop it (the rule itself is src/stop.h's). */
#define ULAM__REL_MIN 1000
/* The fewest walks at which the matrix solver's rel_err rule is checked (its first round): the
 * sequence holds at every count, so a run may meet its target there; the least walks a
 * prediction of that rule's (auto, bidirectional, the push on b) may give. */
#define ULAM__REL_FIRST 256
/* A --rel-err run that still has no interval (a score past the certified range: it stays past)
 * when it has run this many times the walks the rule asks for stops, not met, instead of
 * walking on to the 1e9 cap (r500's expected estimator at E = 0.01 spun 1e9 walks, 92 s). */
#define ULAM__NO_CI_SPAN 1024.0


/* The range R of a single walk's score the rule uses: range when finite (a bounded score);
 * else, for scores that add per_step at most at each visit (weights bounded), with the walk's
 * expected remaining weight after k steps at most kappa qmax^k (kappa 1 and qmax the largest
 * continuation; or a Collatz-Wielandt certificate of |K|: kappa = max v / min v, qmax = u with
 * |K| v <= u v), the range of walks of at most l steps, l chosen so that longer walks add at
 * most E m to the mean (kappa per_step qmax^(l+1) / (1 - qmax) <= E m), doubled when scores
 * take both signs; INFINITY when no bound holds (qmax >= 1, per_step or kappa infinite); 0
 * when nothing scores (range 0 or per_step 0). */
double ulam__score_range(double range, double per_step, double qmax, double kappa, int signs, double m, double E);

/* The range R from a certified bound v2 on a single score's second moment, when no bound on
 * the score itself holds (weights that can grow along cycles): scores above T = v2 / (E m)
 * add at most E[|X| 1{|X| > T}] <= v2 / T = E m to the mean (Markov's inequality on X^2), so the
 * rule takes the range of the scores up to T, doubled when they take both signs; INFINITY
 * without a bound. */
double ulam__moment_range(double v2, int signs, double m, double E);

/* The bound on the bias of walks cut after max_steps steps, from the same length tail:
 * kappa per_step qmax^max_steps / (1 - qmax); INFINITY without a tail bound, 0 when nothing
 * scores.  The rel_err rule holds with cut walks only when this is at most ULAM__CUT_SHARE of
 * E |m|. */
double ulam__cut_bound(double per_step, double qmax, double kappa, int64_t max_steps);
#define ULAM__CUT_SHARE 0.1

#endif
