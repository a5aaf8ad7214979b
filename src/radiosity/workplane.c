/* The lighting engineer's work plane: the EN 12464-1 calculation grid (spacing p = 0.2 x
 * 5^log10(d) m, d the longer side, a 0.5 m wall band left out) and the illuminance statistics
 * it is judged by (the mean, E_min, E_max and the uniformity U0 = E_min / E mean), with
 * intervals that hold together (Bonferroni over the grid's points). */
#include "photo.h"

#include <string.h>

/* EN 12464-1's grid spacing for a side of d metres. */
double ulam_en12464_spacing(double d)
{
    return d > 0 ? fmin(10.0, 0.2 * pow(5.0, log10(d))) : NAN;
}

/* The EN 12464-1 grid of the rectangle c0 .. c1 less the wall band. */
int ulam_rad_grid_en12464(const double c0[3], const double c1[3], double metres, double band, ulam_rad_grid *g,
                          ulam_error *err)
{
    ulam__clear(err);
    if (!c0 || !c1 || !g || !(metres > 0) || !isfinite(metres) || !(band >= 0) || !isfinite(band))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "two corners, metres > 0, a band >= 0 and an output");
    int flat = -1, eq = 0;
    for (int k = 0; k < 3; k++) {
        if (!isfinite(c0[k]) || !isfinite(c1[k])) return ulam__fail(err, ULAM_EINVAL, 0, -1, "finite corners");
        if (c0[k] == c1[k]) flat = k, eq++;
    }
    if (eq != 1)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "corners equal in exactly one coordinate (the work plane's)");
    int ax[2], m = 0;
    for (int k = 0; k < 3; k++)
        if (k != flat) ax[m++] = k;
    double lo[2], hi[2], side[2], b = band / metres; /* in scene units */
    for (int i = 0; i < 2; i++) {
        lo[i] = fmin(c0[ax[i]], c1[ax[i]]) + b, hi[i] = fmax(c0[ax[i]], c1[ax[i]]) - b;
        side[i] = (hi[i] - lo[i]) * metres;
        if (!(side[i] > 0))
            return ulam__fail(err, ULAM_EINVAL, 0, -1, "a work plane wider than twice the %g m wall band (%g m along "
                                                       "axis %c)",
                              band, fabs(c1[ax[i]] - c0[ax[i]]) * metres, "xyz"[ax[i]]);
    }
    double d = fmax(side[0], side[1]), p = ulam_en12464_spacing(d);
    double n0 = ceil(side[0] / p * (1.0 - 1e-12)), n1 = ceil(side[1] / p * (1.0 - 1e-12));
    if (n0 * n1 > ULAM_RAD_GRID_MAX)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a grid of at most %d points, got %.0f x %.0f", ULAM_RAD_GRID_MAX, n0,
                          n1);
    memset(g, 0, sizeof *g);
    g->origin[flat] = c0[flat], g->origin[ax[0]] = lo[0], g->origin[ax[1]] = lo[1];
    g->u[ax[0]] = hi[0] - lo[0], g->v[ax[1]] = hi[1] - lo[1];
    g->normal[flat] = 1.0;
    g->nu = (int)fmax(1.0, n0), g->nv = (int)fmax(1.0, n1);
    return ULAM_OK;
}

/* The standard normal quantile at 1 - a (0 < a < 1/2): bisection on erfc. */
static double upper_quantile(double a)
{
    double lo = 0.0, hi = 40.0;
    for (int k = 0; k < 200; k++) {
        double mid = 0.5 * (lo + hi);
        if (0.5 * erfc(mid / M_SQRT2) > a) lo = mid;
        else hi = mid;
    }
    return hi;
}

/* The statistics of n estimates with simultaneous intervals at level. */
int ulam_uniformity_compute(const double *E, const double *se, int64_t n, double level, ulam_uniformity *u)
{
    if (!E || !se || !u || n < 1 || !(level > 0 && level < 1)) return ULAM_EINVAL;
    for (int64_t k = 0; k < n; k++)
        if (!isfinite(E[k]) || !isfinite(se[k]) || E[k] < 0 || se[k] < 0) return ULAM_EINVAL;
    double z = upper_quantile((1.0 - level) / (2.0 * (double)n));
    memset(u, 0, sizeof *u);
    u->n = n, u->level = level, u->min = u->min_lo = u->min_hi = INFINITY;
    u->max = u->max_lo = u->max_hi = -INFINITY;
    for (int64_t k = 0; k < n; k++) {
        double a = fmax(0.0, E[k] - z * se[k]), b = E[k] + z * se[k];
        u->mean += E[k], u->mean_lo += a, u->mean_hi += b;
        u->min = fmin(u->min, E[k]), u->min_lo = fmin(u->min_lo, a), u->min_hi = fmin(u->min_hi, b);
        u->max = fmax(u->max, E[k]), u->max_lo = fmax(u->max_lo, a), u->max_hi = fmax(u->max_hi, b);
    }
    u->mean /= (double)n, u->mean_lo /= (double)n, u->mean_hi /= (double)n;
    u->u0 = u->mean > 0 ? u->min / u->mean : NAN;
    u->u0_lo = u->mean_hi > 0 ? u->min_lo / u->mean_hi : NAN;
    u->u0_hi = u->mean_lo > 0 ? fmin(1.0, u->min_hi / u->mean_lo) : u->mean_hi > 0 ? 1.0 : NAN;
    return ULAM_OK;
}
