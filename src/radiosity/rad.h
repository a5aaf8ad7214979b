/* Radiosity internals shared by scene, rays, form factors, patch walks and images. */
#ifndef ULAM_RAD_H
#define ULAM_RAD_H

#include "../internal.h"
#include "ulam_radiosity.h"

#include <math.h>

/* a - b, a x b, a . b for 3-vectors. */
static inline void ulam__sub3(const double *a, const double *b, double *o)
{
    o[0] = a[0] - b[0], o[1] = a[1] - b[1], o[2] = a[2] - b[2];
}
static inline void ulam__cross3(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static inline double ulam__dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The largest channel of an RGB triple. */
static inline double ulam__max3(const double *v)
{
    return fmax(v[0], fmax(v[1], v[2]));
}

/* Newell's normal of polygon v[idx[0..n)] (length = twice the area) and its longest edge. */
void ulam__polygon_normal(const double *vert, const int32_t *idx, int64_t n, double normal[3],
                          double *longest);

/* Area, unit normal of every patch (after the vertex lists are set). */
void ulam__scene_geometry(ulam_scene *s);

/* The share of patch p's area in its first fan triangle when it is a quad (else 1). */
double ulam__first_share(const ulam_scene *s, int64_t p);

/* A uniform point of patch p (area-weighted fan triangle, then uniform in it); share is
 * ulam__first_share(s, p). */
void ulam__patch_point(const ulam_scene *s, int64_t p, double share, ulam_rng *r, double pt[3]);

/* A cosine-distributed unit direction about unit normal n. */
void ulam__cosine_dir(const double n[3], ulam_rng *r, double d[3]);

/* The first patch whose front the ray org + t dir hits, back sides seen through (a camera
 * outside a closed room sees into it), or -1. */
int64_t ulam__tracer_cast_front(const ulam_tracer *t, const double org[3], const double dir[3]);

/* Where a ray landed: its length and the cosines at its two ends (at the patch it left, and
 * at the patch it reached, positive on its front). */
typedef struct {
    double dist, cos_from, cos_to;
} ulam__hit;

/* ulam_tracer_shoot, and where the ray lands (h may be NULL). */
int64_t ulam__tracer_shoot_hit(const ulam_tracer *t, int64_t p, ulam_rng *r, ulam__hit *h);

/* A uniform point of patch p. */
void ulam__tracer_point(const ulam_tracer *t, int64_t p, ulam_rng *r, double pt[3]);

/* A shadow ray: nonzero when the segment from x (on patch p) to y (on patch l) leaves p's front,
 * reaches l's front and meets no other patch on the way; *h gets its length and cosines. */
int ulam__tracer_sees(const ulam_tracer *t, int64_t p, const double x[3], int64_t l, const double y[3], ulam__hit *h);

/* The scene a tracer was built on. */
const ulam_scene *ulam__tracer_scene(const ulam_tracer *t);

/* Restart a gathering solver at patch p (rel_err, seed and max_seconds replaced), its
 * statistics cleared and its workspace kept. */
void ulam__rad_solver_restart(ulam_rad_solver *s, int64_t p, double rel_err, uint64_t seed, double max_seconds);

/* Allocate an empty scene with room for the given counts (arrays uninitialised). */
ulam_scene *ulam__scene_alloc(int64_t npatches, int64_t nverts, int64_t nidx, int64_t ngroups);

#endif
