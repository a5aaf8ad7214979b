/* The mesh's error of a patch query: a patch walk answers the discrete system, one value for
 * the whole patch (its mean if the mesh were fine); the surface's own radiosity varies over the
 * patch and the coarse mesh's other patches bias it.  Point queries (point.c) at quadrature
 * points of the patch (its area centroid, then the points half way from it to each vertex)
 * give the continuous surface's radiosity there; the largest difference from the patch's value
 * is the mesh error shown beside the Monte Carlo error. */
#include "rad.h"

#include <string.h>

/* Quadrature point k of patch p: the centroid (k = 0), else half way to vertex k - 1. */
static void quad_point(const ulam_scene *s, int64_t p, int k, double x[3])
{
    ulam_scene_centroid(s, p, x);
    if (k == 0) return;
    const double *v = s->vert + 3 * s->vidx[s->start[p] + k - 1];
    for (int d = 0; d < 3; d++) x[d] = 0.5 * (x[d] + v[d]);
}

/* The mesh error of patch opts->index whose patch query gave B (3 channels). */
int ulam_rad_mesh_error(const ulam_tracer *t, const ulam_rad_opts *opts, const double B[3], ulam_rad_mesh *out,
                        ulam_error *err)
{
    ulam__clear(err);
    if (!t || !opts || !B || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, options, B and an output");
    const ulam_scene *s = ulam__tracer_scene(t);
    int64_t p = opts->index;
    if (p < 0 || p >= s->npatches)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a patch from 0 to %lld", (long long)s->npatches - 1);
    memset(out, 0, sizeof *out);
    int64_t nv = s->start[p + 1] - s->start[p];
    out->npoints = (int)(1 + (nv < ULAM_RAD_MESH_POINTS - 1 ? nv : ULAM_RAD_MESH_POINTS - 1));
    double t0 = ulam_now();
    for (int k = 0; k < out->npoints; k++) {
        ulam_rad_opts o = *opts;
        if (opts->stop.max_seconds > 0) { /* the time limit is all the points': what is left, shared */
            o.stop.max_seconds = (opts->stop.max_seconds - (ulam_now() - t0)) / (out->npoints - k);
            if (!(o.stop.max_seconds > 0)) o.stop.max_seconds = 1e-9; /* one block still runs: an estimate */
        }
        o.exec.seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, (uint64_t)k); /* docs/streams.md */
        double x[3];
        quad_point(s, p, k, x);
        ulam_rad_point pt;
        int status = ulam_rad_point_query(t, &o, x, s->normal + 3 * p, &pt, err);
        if (status) return status;
        out->walks += pt.run.walks, out->rays += pt.run.rays;
        out->interrupted |= pt.run.interrupted;
        for (int c = 0; c < 3; c++) {
            out->point[k][c] = pt.radiosity[c], out->point_se[k][c] = pt.radiosity_se[c];
            out->mean[c] += pt.radiosity[c] / out->npoints;
            out->mean_se[c] += pt.radiosity_se[c] * pt.radiosity_se[c] / ((double)out->npoints * out->npoints);
            double d = fabs(B[c] - pt.radiosity[c]);
            if (k == 0 || d > out->error[c]) out->error[c] = d, out->error_se[c] = pt.radiosity_se[c];
        }
        if (pt.run.interrupted) break;
    }
    for (int c = 0; c < 3; c++) out->mean_se[c] = sqrt(out->mean_se[c]);
    out->seconds = ulam_now() - t0;
    return ULAM_OK;
}

/* See ulam_radiosity.h. */
int ulam_rad_mesh_errors(const ulam_tracer *t, const ulam_rad_opts *opts, const double *B, double *out,
                         ulam_error *err)
{
    ulam__clear(err);
    if (!t || !opts || !B || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, options, B and an output");
    const ulam_scene *s = ulam__tracer_scene(t);
    int interrupted = 0;
    for (int64_t p = 0; p < s->npatches; p++) {
        ulam_rad_mesh m = {.interrupted = 1};
        ulam_rad_opts o = *opts;
        o.index = p, o.exec.seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, (uint64_t)p);
        int status = interrupted ? ULAM_OK : ulam_rad_mesh_error(t, &o, B + 3 * p, &m, err);
        if (status) {
            if (err) err->index = p;
            return status;
        }
        interrupted |= m.interrupted;
        for (int c = 0; c < 3; c++) out[3 * p + c] = m.interrupted ? NAN : m.error[c];
    }
    return ULAM_OK;
}
