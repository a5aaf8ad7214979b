/* What is wrong with a scene that answers 0: whether it has emitters at all, and whether its
 * faces look inside out.  Cosine rays leave uniform points of patches drawn by area, from their
 * fronts and, as many, from their backs: in a room whose normals face in, the fronts' rays land
 * on other fronts and the backs' rays leave the scene; with the winding reversed the fronts'
 * rays leave and the backs' land on other backs (OBJ faces are counter-clockwise seen from their
 * lit front).  The emitters' own
 * fronts are tallied apart: a lamp whose every ray leaves the scene lights nothing in it. */
#include "rad.h"

#include <stdlib.h>

/* Count rays from uniform points of patches drawn by area (cdf), from their fronts (sign 1) or
 * backs (-1): landed on a front, on a back, left the scene; emitters only when lamps is set. */
static void cast_rays(const ulam_tracer *t, const double *cdf, int64_t rays, int sign, int lamps, ulam_rng *r,
                      int64_t count[3])
{
    const ulam_scene *s = ulam__tracer_scene(t);
    int64_t n = s->npatches;
    for (int64_t k = 0; k < rays; k++) {
        double u = ulam__rng_uniform(r) * cdf[n - 1], x[3], nn[3], d[3], dist;
        int64_t lo = 0, hi = n - 1;
        while (lo < hi) { /* the first patch whose cumulative area passes u */
            int64_t mid = lo + (hi - lo) / 2;
            if (cdf[mid] > u) hi = mid;
            else lo = mid + 1;
        }
        if (lamps && !(ulam__max3(s->emit + 3 * lo) > 0)) continue;
        ulam__tracer_point(t, lo, r, x);
        for (int c = 0; c < 3; c++) nn[c] = sign * s->normal[3 * lo + c];
        ulam__cosine_dir(nn, r, d);
        int front = 0;
        int64_t j = ulam__tracer_ray(t, x, d, lo, &front, &dist);
        count[j < 0 ? 2 : front ? 0 : 1]++;
    }
}

/* Emitters, and where rays from the patches' fronts and backs land. */
int ulam_rad_scene_diagnose(const ulam_tracer *t, int64_t rays, uint64_t seed, ulam_rad_scene_diag *out)
{
    if (!t || !out || rays < 1) return ULAM_EINVAL;
    const ulam_scene *s = ulam__tracer_scene(t);
    *out = (ulam_rad_scene_diag){0};
    double *cdf = ulam__malloc((size_t)s->npatches, sizeof *cdf), acc = 0.0, lamp_area = 0.0;
    if (!cdf) return ULAM_ENOMEM;
    for (int64_t p = 0; p < s->npatches; p++) {
        cdf[p] = acc += s->area[p];
        if (ulam__max3(s->emit + 3 * p) > 0) out->emitters++, lamp_area += s->area[p];
    }
    ulam_rng r;
    ulam_rng_seed(&r, seed, 0);
    cast_rays(t, cdf, rays, 1, 0, &r, out->front);
    cast_rays(t, cdf, rays, -1, 0, &r, out->back);
    if (out->emitters) /* about rays lamp rays: the draws that land on a lamp */
        cast_rays(t, cdf, (int64_t)fmin((double)rays * acc / lamp_area, 64.0 * (double)rays), 1, 1, &r, out->lamp);
    free(cdf);
    return ULAM_OK;
}
