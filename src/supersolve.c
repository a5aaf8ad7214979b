/* The certified supersolution of m = r + A m (r >= 0, A >= 0): a z with r + A z <= z, so z >=
 * sum_k A^k r = m by induction, with no spectral condition.  m_k: lazy iterates m <- (m + r +
 * A m) / 2 from r (they rise to m; the lazy step settles on periodic chains); each fourth gives
 * candidates z = m_k + beta e with e = res + phi max(res), res = r + A m_k - m_k (the iterates'
 * increment, which turns towards A's Perron vector, so e - A e ~ (1 - rho) e and z ~ m), beta =
 * max res / (e - A e) where e > A e.  The products' rounding is covered by a relative 1e-10 on
 * A's sums and 1e-9 on beta.  One home for the second moments of src/solve.c (one machine, aimed
 * at the starts) and src/dist_moment.c (a rank's rows; only exact maxima cross ranks, so the
 * same bits at any rank count). */
#include "supersolve.h"

#include <math.h>
#include <stdlib.h>

enum { ITER = 400, NF = 5, STALL = 40 };
static const double phis[NF] = {0.0, 1e-12, 1e-8, 1e-4, 1e-2};

/* x[0..k) to their largest over ranks (nothing on one machine); nonzero: failed. */
static int largest(const ulam__super *s, double *x, int k)
{
    return s->largest ? s->largest(s->ctx, x, k) : 0;
}

/* Keep candidate (phi, bb) when its worth v improves on *best: z, *best, and *last (the
 * iterate of the last improvement by 0.1% or more). */
static void keep(const ulam__super *s, const double *m, const double *res, double phi, double bb, double v, double *z,
                 double *best, int it, int *last)
{
    if (!(isfinite(v) && v < *best)) return;
    if (v < *best * (1.0 - 1e-3)) *last = it;
    *best = v;
    for (int64_t i = 0; i < s->n; i++) z[i] = !s->seen || s->seen[i] ? (m[i] + bb * (res[i] + phi)) * s->zscale : 0.0;
}

/* The search (supersolve.h). */
int ulam__super_solve(const ulam__super *s, const double *r, double *z, double *best, int *iterations)
{
    int64_t n = s->n;
    size_t nr = (size_t)n + 1;
    double *m = ulam__malloc(nr, sizeof *m), *y = ulam__malloc(nr, sizeof *y), *res = ulam__malloc(nr, sizeof *res);
    double *ar = ulam__malloc(nr, sizeof *ar), *rs = ulam__malloc(nr, sizeof *rs), *one = ulam__malloc(nr, sizeof *one);
    int bad = !m || !y || !res || !ar || !rs || !one, counted = 0;
    *best = INFINITY;
    for (int64_t i = 0; !bad && i < n; i++) m[i] = !s->seen || s->seen[i] ? r[i] : 0.0, one[i] = 1.0, y[i] = 0.0;
    if (!bad) bad = s->product(s->ctx, NULL, one, rs); /* A's row sums */
    for (int it = 0, last = 0; !bad && it < ITER && it - last < STALL; it++) {
        if (isfinite(*best) && isfinite(s->deadline) && ulam_now() >= s->deadline) break;
        if ((bad = s->product(s->ctx, r, m, y))) break;
        counted++;
        double D = 0.0;
        for (int64_t i = 0; i < n; i++)
            res[i] = !s->seen || s->seen[i] ? fmax(y[i] * (1.0 + 1e-10) - m[i], 0.0) : 0.0, D = fmax(D, res[i]);
        /* a lazy step but every fourth iterate; on one machine a fixed point is seen at once */
        if (it % 4 != 3 && (s->largest || D > 0)) {
            for (int64_t i = 0; i < n; i++)
                if (!s->seen || s->seen[i]) m[i] += res[i] / 2.0 / (1.0 + 1e-10);
            continue;
        }
        if ((bad = largest(s, &D, 1)) || !isfinite(D)) break;
        if (!(D > 0)) { /* r + A m <= m already */
            double v = s->worth(s->ctx, m, res, 0.0, 0.0);
            if ((bad = largest(s, &v, 1))) break;
            if (s->offer) s->offer(s->ctx, m, res, 0.0, 0.0);
            keep(s, m, res, 0.0, 0.0, v, z, best, it, &last);
            break;
        }
        if ((bad = s->product(s->ctx, NULL, res, ar))) break;
        counted++;
        double beta[NF] = {0}, top[NF] = {0};
        for (int fl = 0; fl < NF; fl++) {
            double phi = phis[fl] * D;
            for (int64_t i = 0; i < n && isfinite(beta[fl]); i++) {
                if (s->seen && !s->seen[i]) continue;
                double e = res[i] + phi, gap = e - (ar[i] + phi * rs[i]) * (1.0 + 1e-10);
                if (!isfinite(m[i]) || !isfinite(e) || !isfinite(gap)) beta[fl] = INFINITY; /* overflow: none */
                else if (res[i] > 0) beta[fl] = gap > 0 ? fmax(beta[fl], res[i] / gap) : INFINITY;
                else if (gap < 0) beta[fl] = INFINITY;
            }
        }
        if ((bad = largest(s, beta, NF))) break;
        for (int fl = 0; fl < NF; fl++)
            top[fl] = isfinite(beta[fl]) ? s->worth(s->ctx, m, res, phis[fl] * D, beta[fl] * (1.0 + 1e-9)) : 0.0;
        if ((bad = largest(s, top, NF))) break;
        for (int fl = 0; fl < NF; fl++) {
            if (!isfinite(beta[fl])) continue;
            double phi = phis[fl] * D, bb = beta[fl] * (1.0 + 1e-9);
            if (s->offer) s->offer(s->ctx, m, res, phi, bb);
            keep(s, m, res, phi, bb, top[fl], z, best, it, &last);
        }
        for (int64_t i = 0; i < n; i++)
            if (!s->seen || s->seen[i]) m[i] += res[i] / 2.0 / (1.0 + 1e-10); /* not past the solution */
    }
    if (iterations) *iterations += counted;
    free(m), free(y), free(res), free(ar), free(rs), free(one);
    return bad;
}
