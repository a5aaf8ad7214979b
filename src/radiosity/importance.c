/* The view's importance of every patch: the adjoint of the radiosity system with the picture as
 * its source (Hanrahan, Salzman & Aupperle 1991; Smits, Arvo & Salesin 1992).  A picture's mean
 * hit pixel is P = sum_p S_p B_p, S_p the share of hit pixels that see patch p; with
 * B = E + diag(rho) F B, P = sum_p Y_p E_p for Y = S + (diag(rho) F)^T Y, so an error d in
 * B_p moves the picture by Y_p d: Y says where the mesh must be fine.  S is counted exactly;
 * (diag(rho) F)^T Y - S by walks that start at a seen patch j in proportion to S_j, go on with
 * probability rho_j (the mean of the channels) to the patch k a cosine ray from a uniform point
 * of j reaches (probability F_jk: weight rho_j F_jk / (rho_j F_jk) = 1), and count each
 * landing: E[landings at p] / walks = Y_p - S_p. */
#include "rad.h"

#include <stdlib.h>

/* The view's importance Y (npatches) of the camera's width x height picture. */
int ulam_rad_importance(const ulam_tracer *t, const ulam_camera *cam, int width, int height, int64_t walks,
                        uint64_t seed, double *Y, ulam_error *err)
{
    ulam__clear(err);
    if (!t || !cam || !Y || walks < 0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, a camera, walks >= 0 and Y");
    const ulam_scene *s = ulam__tracer_scene(t);
    int64_t n = s->npatches, *pix = ulam__malloc((size_t)n, sizeof *pix);
    double *cdf = ulam__malloc((size_t)n, sizeof *cdf);
    if (!pix || !cdf) {
        free(pix), free(cdf);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld patches' importance", (long long)n);
    }
    int status = ulam_view_pixels(t, cam, width, height, pix);
    if (status) {
        free(pix), free(cdf);
        return ulam__fail(err, status, 0, -1, "camera rays for a %d x %d picture", width, height);
    }
    double hit = 0.0;
    for (int64_t p = 0; p < n; p++) hit += (double)pix[p], cdf[p] = hit;
    for (int64_t p = 0; p < n; p++) Y[p] = hit > 0 ? (double)pix[p] / hit : 0.0;
    ulam_rng r;
    ulam_rng_seed(&r, seed, 0);
    for (int64_t w = 0; w < walks && hit > 0; w++) {
        double u = ulam__rng_uniform(&r) * hit;
        int64_t lo = 0, hi = n - 1; /* the first patch whose cdf passes u */
        while (lo < hi) {
            int64_t mid = lo + (hi - lo) / 2;
            if (cdf[mid] > u) hi = mid;
            else lo = mid + 1;
        }
        for (int64_t j = lo, step = 0; step < 100000; step++) {
            const double *rho = s->rho + 3 * j;
            if (ulam__rng_uniform(&r) >= (rho[0] + rho[1] + rho[2]) / 3.0) break;
            if ((j = ulam_tracer_shoot(t, j, &r)) < 0) break;
            Y[j] += 1.0 / (double)walks;
        }
    }
    free(pix), free(cdf);
    return ULAM_OK;
}
