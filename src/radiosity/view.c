/* Images that solve only what is seen ("don't solve if not seen"): the camera's primary rays
 * find the patches in view and their pixel counts, and only those are gathered, each to a
 * relative error that loosens as its share of the picture shrinks.  The cost is the seen
 * patches' walks (and one O(npatches) pass over the counts), not the scene's size. */
#include "rad.h"

#include <stdlib.h>

/* Check a view gather's arguments. */
static int check_view(const ulam_tracer *t, const ulam_camera *cam, int w, int h, double coverage,
                      const ulam_rad_opts *o, const double *B, const double *se, ulam_error *err)
{
    if (!t || !cam || !o || !B || !se) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, camera, options and outputs");
    if (w < 1 || h < 1 || !(cam->focal > 0) || !(cam->film > 0))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a picture of at least 1 x 1 and a camera with focal and film > 0");
    if (ulam__camera_check(t, cam))
        return ulam__fail(err, ULAM_ERANGE, 0, -1, "a camera eye within %g scene sizes of the scene", ULAM__TRACER_REACH);
    if (!(coverage >= 0 && coverage <= 1)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a coverage exponent in [0, 1]");
    if (o->mode != ULAM_ADJOINT || !(o->stop.rel_err > 0))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "gathering (adjoint) with rel_err > 0");
    return ULAM_OK;
}

/* Gather the patches a camera sees. */
int ulam_view_gather(const ulam_tracer *t, const ulam_camera *cam, int width, int height, double coverage,
                     const ulam_rad_opts *opts, double *B, double *se, ulam_view_info *info, ulam_error *err)
{
    ulam__clear(err);
    int status = check_view(t, cam, width, height, coverage, opts, B, se, err);
    if (status) return status;
    const ulam_scene *s = ulam__tracer_scene(t);
    int64_t n = s->npatches, *pix = ulam__malloc((size_t)n, sizeof *pix), most = 0;
    ulam_view_info in = {.npatches = n, .camera_rays = (int64_t)width * height};
    double t0 = ulam_now();
    if (!pix) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the pixel counts");
    if ((status = ulam_view_pixels(t, cam, width, height, pix))) {
        free(pix);
        return ulam__fail(err, status, 0, -1, "camera rays for a %d x %d picture", width, height);
    }
    int64_t first = -1;
    for (int64_t p = 0; p < n; p++) {
        for (int c = 0; c < 3; c++) B[3 * p + c] = 0.0, se[3 * p + c] = NAN;
        if (!pix[p]) continue;
        in.seen++, in.pixels_hit += pix[p];
        most = pix[p] > most ? pix[p] : most;
        if (first < 0) first = p;
    }
    ulam_rad_opts o = *opts;
    o.index = first >= 0 ? first : 0;
    ulam_rad_solver *sv = NULL;
    if (first >= 0 && (status = ulam_rad_solver_alloc(t, &o, &sv, err))) {
        free(pix);
        return status;
    }
    for (int64_t p = first; p >= 0 && p < n && !status; p++) {
        if (!pix[p]) continue;
        double left = opts->stop.max_seconds > 0 ? opts->stop.max_seconds - (ulam_now() - t0) : 0.0;
        if (opts->stop.max_seconds > 0 && left <= 0) { /* out of time: the rest unsolved */
            for (int c = 0; c < 3; c++) se[3 * p + c] = INFINITY;
            in.unmet++;
            continue;
        }
        double target = opts->stop.rel_err * pow((double)most / (double)pix[p], coverage);
        uint64_t seed = ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, (uint64_t)p); /* docs/streams.md */
        ulam__rad_solver_restart(sv, p, target, seed, left);
        while (!status && !ulam_rad_solver_done(sv)) status = ulam_rad_solver_iterate(sv);
        ulam_rad_result res;
        ulam_rad_solver_result(sv, &res);
        int met = 1;
        for (int c = 0; c < 3; c++) {
            B[3 * p + c] = res.radiosity[c], se[3 * p + c] = res.std_error[c];
            met &= res.radiosity[c] == 0 || res.std_error[c] <= target * fabs(res.radiosity[c]);
        }
        in.unmet += !met && !res.zero;
        in.walks += res.walks, in.rays += res.rays, in.cut += res.cut, in.threads = res.threads;
        if (res.interrupted) {
            in.interrupted = 1;
            break;
        }
    }
    ulam_rad_solver_free(sv);
    free(pix);
    in.seconds = ulam_now() - t0;
    if (info) *info = in;
    if (status) return ulam__fail(err, status, 0, -1, "finite scores");
    return ULAM_OK;
}
