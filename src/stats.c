/* Running moments: Welford's update and Chan's merge, so block results combine exactly in
 * a fixed order whatever the number of threads; the third and fourth central sums by Pebay's
 * formulas (the mean and m2 arithmetic is Welford's and Chan's unchanged). */
#include "stats.h"

#include <math.h>

/* Add one observation. */
void ulam__moments_add(ulam__moments *m, double x)
{
    double n1 = (double)m->n, n = n1 + 1.0;
    double d = x - m->mean, dn = d / n, dn2 = dn * dn, t = d * dn * n1;
    m->m4 += t * dn2 * (n * n - 3.0 * n + 3.0) + 6.0 * dn2 * m->m2 - 4.0 * dn * m->m3;
    m->m3 += t * dn * (n - 2.0) - 3.0 * dn * m->m2;
    m->n++;
    m->mean += d / (double)m->n;
    m->m2 += d * (x - m->mean);
}

/* Merge b into a. */
void ulam__moments_merge(ulam__moments *a, const ulam__moments *b)
{
    if (b->n == 0) return;
    if (a->n == 0) {
        *a = *b;
        return;
    }
    int64_t n = a->n + b->n;
    double d = b->mean - a->mean, na = (double)a->n, nb = (double)b->n, N = (double)n;
    double m4 = a->m4 + b->m4 + d * d * d * d * na * nb * (na * na - na * nb + nb * nb) / (N * N * N) +
                6.0 * d * d * (na * na * b->m2 + nb * nb * a->m2) / (N * N) + 4.0 * d * (na * b->m3 - nb * a->m3) / N;
    double m3 = a->m3 + b->m3 + d * d * d * na * nb * (na - nb) / (N * N) + 3.0 * d * (na * b->m2 - nb * a->m2) / N;
    a->mean += d * ((double)b->n / (double)n);
    a->m2 += b->m2 + d * d * ((double)a->n * (double)b->n / (double)n);
    a->m3 = m3, a->m4 = m4;
    a->n = n;
}

/* Sample variance. */
double ulam__moments_variance(const ulam__moments *m)
{
    return m->n > 1 ? m->m2 / (double)(m->n - 1) : 0.0;
}

/* Relative standard error of the sample variance from the fourth moment. */
double ulam__moments_variance_rel_error(const ulam__moments *m)
{
    if (m->n < 2) return INFINITY;
    if (!(m->m2 > 0)) return 0.0; /* every score alike: the sample variance 0 varies by nothing */
    double N = (double)m->n, s2 = m->m2 / (N - 1.0), mu4 = m->m4 / N;
    return sqrt(fmax(0.0, mu4 - s2 * s2) / N) / s2;
}

/* The range of a single score the rel_err rule uses. */
double ulam__score_range(double range, double per_step, double qmax, double kappa, int signs, double m, double E)
{
    if (isfinite(range) || range == 0.0) return range;
    if (per_step == 0.0) return 0.0;
    if (!isfinite(per_step) || !(qmax < 1.0) || !isfinite(kappa) || !(m > 0) || !(E > 0)) return INFINITY;
    double steps = qmax > 0 ? ceil(log(kappa * per_step / (E * m * (1.0 - qmax))) / log(1.0 / qmax)) : 0.0;
    return per_step * fmax(1.0, steps + 1.0) * (signs ? 2.0 : 1.0);
}

/* The range the rule uses from a bound on the second moment. */
double ulam__moment_range(double v2, int signs, double m, double E)
{
    if (!isfinite(v2) || !(m > 0) || !(E > 0)) return INFINITY;
    return v2 / (E * m) * (signs ? 2.0 : 1.0);
}

/* The most the walks cut after max_steps steps can move the mean. */
double ulam__cut_bound(double per_step, double qmax, double kappa, int64_t max_steps)
{
    if (per_step == 0.0) return 0.0;
    if (!isfinite(per_step) || !(qmax < 1.0) || !isfinite(kappa)) return INFINITY;
    return kappa * per_step * pow(qmax, (double)max_steps) / (1.0 - qmax);
}

/* Mean and sample variance from a sum and a sum of squares. */
void ulam__sums_moments(double n, double sum, double sumsq, double *mean, double *variance)
{
    double m = n > 0 ? sum / n : 0.0;
    *mean = m;
    *variance = n > 1 ? fmax(0.0, (sumsq - n * m * m) / (n - 1)) : 0.0;
}
