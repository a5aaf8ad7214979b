/* Sensor grids: the lighting designer's standard output, irradiance at the centres of the cells
 * of a rectangle on a work plane, each point a point query (point.c's walks) with its own seed
 * stream, so a point's answer depends neither on the threads nor on the other points.  The
 * sensors share one solver: its emitter table and the scene-wide part of its certified score
 * range (a pass over every patch, the same for every sensor) are made once, and each sensor
 * adds only its own vertex's bound (ulam__rad_point_restart). */
#include "rad.h"

#include <string.h>

/* The centre of cell (i, j) of grid g. */
void ulam_rad_grid_point(const ulam_rad_grid *g, int i, int j, double x[3])
{
    double a = (i + 0.5) / g->nu, b = (j + 0.5) / g->nv;
    for (int k = 0; k < 3; k++) x[k] = g->origin[k] + a * g->u[k] + b * g->v[k];
}

/* Check a grid: sizes >= 1, finite vectors, a unit normal. */
static int check_grid(const ulam_rad_grid *g, ulam_error *err)
{
    if (g->nu < 1 || g->nv < 1 || (int64_t)g->nu * g->nv > ULAM_RAD_GRID_MAX)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a grid of 1 to %d points", ULAM_RAD_GRID_MAX);
    double len = 0.0;
    for (int k = 0; k < 3; k++) {
        if (!isfinite(g->origin[k]) || !isfinite(g->u[k]) || !isfinite(g->v[k]) || !isfinite(g->normal[k]))
            return ulam__fail(err, ULAM_EINVAL, 0, -1, "a grid with finite corners and normal");
        len += g->normal[k] * g->normal[k];
    }
    if (!(fabs(len - 1.0) < 1e-9)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a grid with a unit normal");
    return ULAM_OK;
}

/* Every point of grid g (out: nu * nv, row j = 0 first, i fastest). */
int ulam_rad_grid_solve(const ulam_tracer *t, const ulam_rad_opts *opts, const ulam_rad_grid *g, ulam_rad_point *out,
                        ulam_error *err)
{
    ulam__clear(err);
    if (!t || !opts || !g || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, options, a grid and an output");
    int status = check_grid(g, err);
    if (status) return status;
    double t0 = ulam_now();
    ulam_rad_solver *sv = NULL;
    for (int j = 0; j < g->nv && !status; j++)
        for (int i = 0; i < g->nu && !status; i++) {
            int64_t k = (int64_t)j * g->nu + i;
            ulam_rad_opts o = *opts;
            o.exec.seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, (uint64_t)k); /* docs/streams.md */
            if (opts->stop.max_seconds > 0) { /* the time limit is the whole grid's */
                o.stop.max_seconds = opts->stop.max_seconds - (ulam_now() - t0);
                if (!(o.stop.max_seconds > 0)) o.stop.max_seconds = 1e-9; /* one block still runs: an estimate */
            }
            double x[3];
            ulam_rad_grid_point(g, i, j, x);
            status = sv ? ulam__rad_point_restart(sv, x, g->normal, o.exec.seed, o.stop.max_seconds, err)
                        : ulam_rad_point_alloc(t, &o, x, g->normal, &sv, err);
            while (!status && !ulam_rad_solver_done(sv))
                if ((status = ulam_rad_solver_iterate(sv))) ulam__fail(err, status, 0, -1, "finite scores");
            if (status) break;
            ulam_rad_point_result(sv, &out[k]);
            if (out[k].run.interrupted) { /* the rest are left empty */
                for (int64_t m = k + 1; m < (int64_t)g->nu * g->nv; m++) memset(&out[m], 0, sizeof out[m]);
                j = g->nv;
                break;
            }
        }
    ulam_rad_solver_free(sv);
    return status;
}

/* See ulam_radiosity.h. */
int ulam_rad_points_solve(const ulam_tracer *t, const ulam_rad_opts *opts, const double *at, int64_t n,
                          ulam_rad_point *out, ulam_error *err)
{
    ulam__clear(err);
    if (!t || !opts || (n > 0 && (!at || !out)) || n < 0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, options, points and an output");
    for (int64_t k = 0; k < n; k++) {
        ulam_rad_opts o = *opts;
        o.exec.seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, (uint64_t)k); /* each its own walks */
        const double *x = at + 6 * k;
        int status = ulam_rad_point_query(t, &o, x, isnan(x[3]) ? NULL : x + 3, &out[k], err);
        if (status) {
            if (err) err->index = k;
            return status;
        }
        if (out[k].run.interrupted) { /* the rest are left empty */
            memset(out + k + 1, 0, (size_t)(n - k - 1) * sizeof *out);
            break;
        }
    }
    return ULAM_OK;
}

/* Rec. 709's luminance weights. */
static const double luma[3] = {0.2126, 0.7152, 0.0722};

/* See ulam_radiosity.h. */
const double *ulam_rad_luma(void)
{
    return luma;
}

/* See ulam_radiosity.h. */
void ulam_rad_illuminance(const ulam_rad_point *r, double *Y, double *se)
{
    *Y = *se = 0.0;
    for (int c = 0; c < 3; c++) *Y += luma[c] * r->irradiance[c], *se += luma[c] * r->irradiance_se[c];
}

/* See ulam_radiosity.h.  It holds because it contains the interval src/stop.c would give on the
 * walks' Y scores: their range is at most sum_c l_c R_c, their bias sum_c l_c of the channels', and
 * their sample standard deviation at most sum_c l_c s_c (the sample covariance is positive
 * semidefinite), so each term of that half-width is at most the weighted sum of the channels';
 * floored at 0 (every score >= 0). */
void ulam_rad_illuminance_ci(const ulam_rad_point *r, double *lo, double *hi)
{
    double Y = 0.0, h = 0.0;
    for (int c = 0; c < 3; c++) Y += luma[c] * r->irradiance[c], h += luma[c] * (r->run.ci95[c][1] - r->irradiance[c]);
    *lo = isfinite(h) ? fmax(Y - h, 0.0) : NAN, *hi = isfinite(h) ? Y + h : NAN;
}

/* See ulam_radiosity.h. */
int ulam_rad_grid_stats(const ulam_rad_point *pts, int64_t n, ulam_rad_grid_summary *out)
{
    if (!pts || n < 1 || !out) return ULAM_EINVAL;
    double Ymin = INFINITY, Ysum = 0.0, worst = 0.0;
    *out = (ulam_rad_grid_summary){0};
    for (int64_t k = 0; k < n; k++) {
        double Y, se;
        ulam_rad_illuminance(&pts[k], &Y, &se);
        Ymin = fmin(Ymin, Y), Ysum += Y;
        if (Y > 0) worst = fmax(worst, se / Y);
        out->walks += pts[k].run.walks, out->rays += pts[k].run.rays;
    }
    out->min = Ymin, out->mean = Ysum / (double)n, out->worst = worst;
    out->uniformity = Ysum > 0 ? Ymin / out->mean : NAN;
    return ULAM_OK;
}
