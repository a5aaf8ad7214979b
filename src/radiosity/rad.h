/* Radiosity internals shared by scene, rays, form factors, patch walks and images. */
#ifndef ULAM_RAD_H
#define ULAM_RAD_H

#include "../internal.h"
#include "ulam_photometry.h"
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
/* A value and its index (a polygon's share of the mesh error, a patch's pilot brightness). */
typedef struct {
    double r;
    int64_t i;
} ulam__ranked;

/* Largest r first, ties by index (qsort). */
static inline int ulam__ranked_desc(const void *a, const void *b)
{
    const ulam__ranked *x = a, *y = b;
    if (x->r != y->r) return x->r > y->r ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

static inline double ulam__max3(const double *v)
{
    return fmax(v[0], fmax(v[1], v[2]));
}

/* Newell's normal of polygon v[idx[0..n)] (length = twice the area) and its longest edge. */
void ulam__polygon_normal(const double *vert, const int32_t *idx, int64_t n, double normal[3],
                          double *longest);

/* The area centroid of polygon vert[idx[0..n)] (scene.c). */
void ulam__polygon_centroid(const double *vert, const int32_t *idx, int64_t n, double c[3]);

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

/* ulam__tracer_cast_front, and where on the patch: fan triangle k (vertices 0, k, k + 1) and the
 * barycentric u, v of its vertices k and k + 1. */
int64_t ulam__tracer_cast_front_uv(const ulam_tracer *t, const double org[3], const double dir[3], int64_t *k, double *u,
                                   double *v);

/* Where a ray landed: its length and the cosines at its two ends (at the patch it left, and
 * at the patch it reached, positive on its front). */
typedef struct {
    double dist, cos_from, cos_to;
} ulam__hit;

/* ulam_tracer_shoot, and where the ray lands (h may be NULL). */
int64_t ulam__tracer_shoot_hit(const ulam_tracer *t, int64_t p, ulam_rng *r, ulam__hit *h);

/* A uniform point of patch p. */
void ulam__tracer_point(const ulam_tracer *t, int64_t p, ulam_rng *r, double pt[3]);

/* A shadow ray: nonzero when the segment from a point x with unit normal n on patch self (-1: on
 * no patch) to y (on patch l) leaves x's front, reaches l's front and meets no other patch on the
 * way; *h gets its length and cosines. */
int ulam__tracer_sees_from(const ulam_tracer *t, const double x[3], const double n[3], int64_t self, int64_t l,
                           const double y[3], ulam__hit *h);

/* The first patch other than self (-1: none) the ray org + t dir (dir unit, t > 0) hits, or -1;
 * *front is 1 on its front side, *dist its distance. */
int64_t ulam__tracer_ray(const ulam_tracer *t, const double org[3], const double dir[3], int64_t self, int *front,
                         double *dist);

/* The sizes of scene a tracer takes (half the largest side of its bounding box): Embree sees it
 * at size 1, and the doubles of areas, distances and form factors stay far from overflow. */
#define ULAM__TRACER_SIZE_MIN 1e-60
#define ULAM__TRACER_SIZE_MAX 1e60

/* How far from the scene's centre, in scene sizes, a ray may start (a point, a sensor, an eye). */
#define ULAM__TRACER_REACH 1e6

/* The scene's size (half the largest side of its bounding box) and (centre non-NULL) the
 * centre of that box. */
double ulam__tracer_size(const ulam_tracer *t, double centre[3]);

/* Nonzero when x is within ULAM__TRACER_REACH scene sizes of the scene's centre. */
int ulam__tracer_reaches(const ulam_tracer *t, const double x[3]);

/* ULAM_OK, or ULAM_ERANGE for a camera whose eye is past ULAM__TRACER_REACH (image.c). */
int ulam__camera_check(const ulam_tracer *t, const ulam_camera *cam);

/* The scene a tracer was built on. */
const ulam_scene *ulam__tracer_scene(const ulam_tracer *t);

/* Restart a gathering solver at patch p (rel_err, seed and max_seconds replaced), its
 * statistics cleared and its workspace kept. */
void ulam__rad_solver_restart(ulam_rad_solver *s, int64_t p, double rel_err, uint64_t seed, double max_seconds);

/* Move point solver s to x (normal n, as ulam_rad_point_alloc's) with seed and max_seconds, its
 * statistics cleared, its scene-wide score bounds and workspace kept (sensor grids). */
int ulam__rad_point_restart(ulam_rad_solver *s, const double x[3], const double n[3], uint64_t seed, double max_seconds,
                            ulam_error *err);

/* Emitters of one emission and one normal (a subdivided lamp), boxed: what the score bounds
 * of ulam__lights_vertex_bound read.  In a scene of more than ULAM__LIGHT_GROUPS_EXACT such
 * groups (every patch lit differently: luminaires' first bounce) a group holds the emitters of one
 * normal whose power a unit area S = sum_c E_c lies in [2^k, 2^(k+1)) (merged): E then is the
 * largest of each channel, chroma the largest E_c / S, smin and smax S's range; past 4 times as
 * many, a group holds one power bucket of any normals (merged 2: no geometric bound, G unbounded). */
typedef struct {
    double E[3], n[3], lo[3], hi[3];
    double chroma[3], smin, smax;
    int merged, bucket;
} ulam__light_group;

/* The most groups of one emission and normal before emitters are grouped by normal and power. */
#define ULAM__LIGHT_GROUPS_EXACT 64

/* The emitters as a light source for next-event estimation (lights.c). */
typedef struct {
    int64_t *emitter; /* the emitting patches */
    double *cdf;      /* their cumulative power A sum_c E */
    int64_t nem;
    double ptot;      /* the total */
    ulam__light_group *group; /* the emitters grouped by emission and normal */
    int64_t ngroups;
} ulam__lights;

/* The emitters of s; ULAM_OK or ULAM_ENOMEM. */
int ulam__lights_build(const ulam_scene *s, ulam__lights *L);

/* Free the table's arrays (the struct is the caller's). */
void ulam__lights_free(ulam__lights *L);

/* The emitter drawn in proportion to power from u in [0, 1). */
int64_t ulam__lights_pick(const ulam__lights *L, double u);

/* A light sample at x (unit normal n, on patch self or -1) toward emitter l: a uniform point y of
 * l and W E_l G / p_L w_L added to score when seen; the shadow rays cast (0 or 1). */
int ulam__lights_score(const ulam_tracer *t, const ulam__lights *L, int estimator, int64_t l, const double x[3],
                       const double n[3], int64_t self, const double W[3], ulam_rng *r, double score[3]);

/* The MIS weight of a walk's cosine ray that landed (h) on emitter j. */
double ulam__lights_hit_weight(const ulam__lights *L, const ulam_scene *s, int estimator, int64_t j,
                               const ulam__hit *h);

/* Certified bounds per channel and unit weight on one next-event vertex at patch p, or (p < 0)
 * the point pt with unit normal n: light, the largest light sample (before reflectance); hit,
 * the largest MIS-weighted landing of its cosine ray on an emitter. */
void ulam__lights_vertex_parts(const ulam__lights *L, const ulam_scene *s, int estimator, int64_t p, const double *pt,
                               const double n[3], double light[3], double hit[3]);

/* A certified bound per channel on one next-event vertex's score (weights <= 1) at patch p, or
 * (p < 0) the point pt with unit normal n: rho_p (reflect, a patch) or 1 times the largest light
 * sample plus the largest MIS-weighted landing on an emitter; INFINITY for light sampling alone
 * near an emitter it may touch. */
void ulam__lights_vertex_bound(const ulam__lights *L, const ulam_scene *s, int estimator, int64_t p, const double *pt,
                               const double n[3], int reflect, double out[3]);

/* A point walk's weight window (point.c): Russian roulette at the k-th landing once its largest
 * weight is below ULAM__POINT_WMIN gamma^k (gamma = ulam__point_gamma(rho)), so that vertex k
 * weighs at most max(rho^k, ULAM__POINT_WMIN gamma^k). */
#define ULAM__POINT_WMIN 0.1

/* The rate at which a point walk's weight floor falls, for largest reflectance rho < 1. */
double ulam__point_gamma(double rho);

/* What a point walk's score range is made of (patchwalk.c fills it, ulam__point_range reads
 * it), per channel and unit weight: light0 and hit0 at the walk's own point; light and hit the
 * largest at a patch (ulam__lights_vertex_parts; collision: hit the largest E), lr and hr the
 * largest times the patch's reflectance; rho the largest reflectance; black nonzero when every
 * emitter has reflectance 0. */
typedef struct {
    double light0[3], hit0[3], light[3], hit[3], lr[3], hr[3], rho;
    int black;
} ulam__point_bounds;

/* A certified range [0, R] for channel c of one point walk's score (INFINITY: none, light
 * sampling alone beside an emitter). */
double ulam__point_range(const ulam__point_bounds *b, int c);

/* How far off its patch, in scene sizes, a point walk from a point on the surfaces starts
 * (ulam__point_start): 2^-16, 2^8 float roundings of Embree's unit-box frame. */
#define ULAM__POINT_NUDGE 0x1p-16

/* Where a point walk from x (unit normal n, on patch p or -1) starts: nudged off the patch's
 * plane and into its interior, so that no neighbour sharing an edge or vertex with p touches
 * the ray's origin (point.c). */
void ulam__point_start(const ulam_tracer *t, const double x[3], const double n[3], int64_t p, double out[3]);

/* A certified bound on what channel c of one point walk can miss when cut at max_steps (the bias
 * of the walks' mean, low; point.c). */
double ulam__point_tail(const ulam__point_bounds *b, int c, int64_t max_steps);

/* A point walk (point.c): one walk from x (unit normal n, on patch self or -1) on the continuous
 * surfaces (uniform: each landing moved to a uniform point of its patch, a patch walk), its
 * weight floor falling at gamma (ulam__point_gamma): its RGB irradiance score; *rays gets the
 * rays cast, *cut 1 when cut at max_steps or (every 65536 steps) by *interrupt (may be NULL). */
void ulam__point_walk(const ulam_tracer *t, const ulam__lights *L, int estimator, int64_t max_steps, double gamma,
                      int uniform, const double x[3], const double n[3], int64_t self, const volatile int *interrupt,
                      ulam_rng *r, double score[3], int64_t *rays, int64_t *cut);

/* Allocate an empty scene with room for the given counts (arrays uninitialised). */
ulam_scene *ulam__scene_alloc(int64_t npatches, int64_t nverts, int64_t nidx, int64_t ngroups);

/* The index of s's group label, or -1 (src/radiosity/scene.c). */
int64_t ulam__scene_group(const ulam_scene *s, const char *label);

/* Copy s's group labels into o (made with s->ngroups); on failure o is freed (src/radiosity/scene.c). */
int ulam__scene_copy_groups(ulam_scene *o, const ulam_scene *s);

/* Library-internal (not exported: the run, ulam_radiosity_run.h, or one reader calls them; their
 * names kept ulam_ for the estimator files that call them). */
/* A cosine-distributed ray leaving a uniform point of patch p: the patch it reaches
 * (front side) is j with probability exactly F_pj; -1 when it leaves the scene or hits a
 * back side (the light is lost).  Draws from r. */
int64_t ulam_tracer_shoot(const ulam_tracer *t, int64_t p, ulam_rng *r);

/* The relative target of walks on the assembled M at a patch under --matrix-walk --rel-err E,
 * so that the answer's error, the walks' and the sampled F's combined, meets E: E' =
 * sqrt(E^2 - (ff_se / |B|)^2), ff_se being F's standard error at the patch and B the direct
 * solution there (src/stop.c's rule); 0 when F's error alone reaches E (more walks cannot meet
 * it: more form-factor rays can); E when F's error is unknown (ff_known 0). */
double ulam_rad_walk_target(double rel_err, double ff_se, double B, int ff_known);

/* The mesh error of every patch p (ulam_rad_mesh_error with opts, opts->index = p, seeded by
 * ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, p)) against B (3 a patch) into out (3 a
 * patch; NaN for the patches an interrupt left).  ULAM_OK or patch p's failure (err->index = p). */
int ulam_rad_mesh_errors(const ulam_tracer *t, const ulam_rad_opts *opts, const double *B, double *out,
                         ulam_error *err);

/* Write linear float RGB (3 a pixel, rows top first) as a PFM file (Portable Float Map,
 * little-endian), atomically. */
int ulam_pfm_write(const char *path, int width, int height, const float *rgb);

/* Read an IES LM-63 file (TILT=NONE or INCLUDE; type C photometry; candela times the
 * multiplier, the ballast factor and the ballast-lamp factor).  Errors: the line and what was
 * expected (ULAM_ESYNTAX, ULAM_ERANGE, ULAM_EUNSUPPORTED for type A or B photometry or a TILT
 * file; ULAM_EIO). */
int ulam_gonio_read_ies(const char *path, ulam_gonio **out, ulam_error *err);

/* Read a EULUMDAT file (.ldt: symmetry 0 to 4, intensities in cd/klm times the conversion
 * factor and the first lamp set's flux / 1000).  Errors as ulam_gonio_read_ies's. */
int ulam_gonio_read_ldt(const char *path, ulam_gonio **out, ulam_error *err);

/* ulam_luminaire_patch_illuminance that can be stopped: once *interrupt (may be NULL) is nonzero or
 * max_seconds (> 0; 0: no limit) have passed, the patches not yet lit are left NaN; *lit (may be
 * NULL) gets the patches lit (npatches when it ran to the end).  ULAM_OK when stopped. */
int ulam_luminaire_patch_illuminance_stop(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, double metres,
                                          int q, int threads, const volatile int *interrupt, double max_seconds,
                                          double *H, int64_t *lit, ulam_error *err);

#endif
