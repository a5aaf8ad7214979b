/* Running moments: Welford's update and Chan's merge, so block results combine exactly in
 * a fixed order whatever the number of threads. */
#include "stats.h"

/* Add one observation. */
void ulam__moments_add(ulam__moments *m, double x)
{
    m->n++;
    double d = x - m->mean;
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
    double d = b->mean - a->mean;
    a->mean += d * ((double)b->n / (double)n);
    a->m2 += b->m2 + d * d * ((double)a->n * (double)b->n / (double)n);
    a->n = n;
}

/* Sample variance. */
double ulam__moments_variance(const ulam__moments *m)
{
    return m->n > 1 ? m->m2 / (double)(m->n - 1) : 0.0;
}
