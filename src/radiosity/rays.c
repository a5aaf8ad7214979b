/* Ray casting with Embree 3: one triangle geometry (each patch a fan of triangles), the patch
 * from the hit primitive.  Self-intersection is avoided by identity, not by distance: a filter
 * function rejects every hit on the patch a ray leaves (a planar convex patch cannot be hit by
 * a ray leaving its front, so this is exact), and the ray starts at the sampled point itself.
 * Embree works in float, so vertices and origins are taken relative to the centre of the
 * scene's bounding box (computed in double) and in units of its half extent: a scene far from
 * the origin keeps the precision of one at the origin, and a scene of any size (1e13 or 1e-20)
 * meets Embree's float products (whose cubes overflow or underflow past ~1e12 and ~1e-12) at
 * size 1; distances come back in the scene's units. */
#include "rad.h"
#include "../dynload.h"

#include <float.h>
#include <stdlib.h>

struct ulam_tracer {
    const ulam_scene *s;
    const ulam__embree_api *E; /* Embree's functions (src/dynload.c: opened on first use) */
    RTCDevice dev;
    RTCScene scene;
    int64_t *prim_patch; /* triangle -> patch */
    double *share;       /* per patch: ulam__first_share */
    double centre[3];    /* of the bounding box: Embree's coordinates are relative to it */
    double scale;        /* its half extent: Embree's unit */
    double resolution;   /* the largest float step at a patch over the patch's size */
    int64_t coarsest;    /* the patch where it is */
};

/* An intersection context that knows the patch a ray leaves (-1: none). */
typedef struct {
    struct RTCIntersectContext ctx; /* first, so Embree's pointer is ours */
    const ulam_tracer *t;
    int64_t self;
    const double *cull; /* the ray's direction when back sides are passed through, or NULL */
} ray_context;

/* Free a tracer; accepts and returns NULL. */
ulam_tracer *ulam_tracer_free(ulam_tracer *t)
{
    if (!t) return NULL;
    if (t->scene) t->E->ReleaseScene(t->scene);
    if (t->dev) t->E->ReleaseDevice(t->dev);
    free(t->prim_patch);
    free(t->share);
    free(t);
    return NULL;
}

/* The scene a tracer was built on. */
const ulam_scene *ulam__tracer_scene(const ulam_tracer *t)
{
    return t->s;
}

/* The bounding box centre of the scene's vertices. */
static void scene_centre(const ulam_scene *s, double c[3])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int64_t v = 0; v < s->nverts; v++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], s->vert[3 * v + d]);
            hi[d] = fmax(hi[d], s->vert[3 * v + d]);
        }
    for (int d = 0; d < 3; d++) c[d] = s->nverts ? 0.5 * lo[d] + 0.5 * hi[d] : 0.0;
}

/* Half the largest side of the scene's bounding box (0 for an empty or point scene). */
static double scene_half_extent(const ulam_scene *s, const double c[3])
{
    double h = 0.0;
    for (int64_t v = 0; v < s->nverts; v++)
        for (int d = 0; d < 3; d++) h = fmax(h, fabs(s->vert[3 * v + d] - c[d]));
    return h;
}

/* Fill Embree's vertex and index buffers with the patches' fan triangles (relative to the
 * centre). */
static void fill_buffers(ulam_tracer *t, float *vb, unsigned *ib)
{
    const ulam_scene *s = t->s;
    for (int64_t v = 0; v < s->nverts; v++)
        for (int d = 0; d < 3; d++) vb[3 * v + d] = (float)((s->vert[3 * v + d] - t->centre[d]) / t->scale);
    int64_t tri = 0;
    for (int64_t p = 0; p < s->npatches; p++) {
        const int32_t *v = s->vidx + s->start[p];
        double far = 0.0; /* the largest centred coordinate of the patch */
        for (int64_t k = 0; k < s->start[p + 1] - s->start[p]; k++)
            for (int d = 0; d < 3; d++) far = fmax(far, fabs(s->vert[3 * v[k] + d] - t->centre[d]));
        double r = FLT_EPSILON * far / sqrt(s->area[p]);
        if (r > t->resolution) t->resolution = r, t->coarsest = p;
        for (int64_t k = 1; k + 1 < s->start[p + 1] - s->start[p]; k++, tri++) {
            ib[3 * tri] = (unsigned)v[0], ib[3 * tri + 1] = (unsigned)v[k], ib[3 * tri + 2] = (unsigned)v[k + 1];
            t->prim_patch[tri] = p;
        }
    }
}

/* How finely Embree's floats resolve the scene: the largest float step at a patch over the
 * patch's size, and that patch. */
double ulam_tracer_resolution(const ulam_tracer *t, int64_t *patch)
{
    if (patch) *patch = t ? t->coarsest : -1;
    return t ? t->resolution : NAN;
}

/* Embree's filter: reject hits on the patch the ray leaves, and (camera rays) on back sides
 * (primID is the hit's sixth SoA field, RTCHitN_primID, which rtcore_ray.h defines for C++ only). */
static void skip_self(const struct RTCFilterFunctionNArguments *a)
{
    const ray_context *rc = (const ray_context *)a->context;
    for (unsigned i = 0; i < a->N; i++) {
        if (!a->valid[i]) continue;
        int64_t p = rc->t->prim_patch[((const unsigned *)a->hit)[5 * a->N + i]];
        if (p == rc->self || (rc->cull && ulam__dot3(rc->cull, rc->t->s->normal + 3 * p) >= 0)) a->valid[i] = 0;
    }
}

/* Build the ray-casting structure for s. */
int ulam_tracer_alloc(const ulam_scene *s, ulam_tracer **out, ulam_error *err)
{
    ulam__clear(err);
    if (!s || !out || s->npatches < 1) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a scene with patches");
    *out = NULL;
    int64_t ntri = s->start[s->npatches] - 2 * s->npatches;
    if (ntri < 1 || ntri > (int64_t)UINT32_MAX / 4 || s->nverts > (int64_t)UINT32_MAX / 4)
        return ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "fewer than 2^30 triangles and vertices");
    double centre[3], half;
    scene_centre(s, centre);
    half = scene_half_extent(s, centre);
    if (!(half >= ULAM__TRACER_SIZE_MIN && half <= ULAM__TRACER_SIZE_MAX))
        return ulam__fail(err, ULAM_ERANGE, 0, -1, "a scene between %g and %g in size (this one's half extent is %g: "
                          "rescale its units)", ULAM__TRACER_SIZE_MIN, ULAM__TRACER_SIZE_MAX, half);
    const ulam__embree_api *E = ulam__embree(err);
    if (!E) return err ? err->status : ULAM_EDEVICE;
    ulam_tracer *t = calloc(1, sizeof *t);
    if (!t || !(t->prim_patch = ulam__malloc((size_t)ntri, sizeof *t->prim_patch)) ||
        !(t->share = ulam__malloc((size_t)s->npatches, sizeof *t->share))) {
        ulam_tracer_free(t);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the ray tracer");
    }
    t->s = s, t->E = E, t->scale = half;
    for (int d = 0; d < 3; d++) t->centre[d] = centre[d];
    for (int64_t p = 0; p < s->npatches; p++) t->share[p] = ulam__first_share(s, p);
    if (!(t->dev = t->E->NewDevice(NULL))) {
        ulam_tracer_free(t);
        return ulam__fail(err, ULAM_EDEVICE, 0, -1, "an Embree device (rtcNewDevice failed)");
    }
    t->scene = t->E->NewScene(t->dev);
    RTCGeometry g = t->E->NewGeometry(t->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = t->scene && g ? t->E->SetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), (size_t)s->nverts) : NULL;
    unsigned *ib = vb ? t->E->SetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                3 * sizeof(unsigned), (size_t)ntri) : NULL;
    if (!ib) {
        if (g) t->E->ReleaseGeometry(g);
        ulam_tracer_free(t);
        return ulam__fail(err, ULAM_EDEVICE, 0, -1, "Embree buffers for %lld triangles", (long long)ntri);
    }
    fill_buffers(t, vb, ib);
    t->E->SetGeometryIntersectFilterFunction(g, skip_self);
    t->E->CommitGeometry(g);
    t->E->AttachGeometry(t->scene, g);
    t->E->ReleaseGeometry(g);
    t->E->SetSceneFlags(t->scene, RTC_SCENE_FLAG_ROBUST);
    t->E->SetSceneBuildQuality(t->scene, RTC_BUILD_QUALITY_HIGH);
    t->E->CommitScene(t->scene);
    if (t->E->GetDeviceError(t->dev) != RTC_ERROR_NONE) {
        ulam_tracer_free(t);
        return ulam__fail(err, ULAM_EDEVICE, 0, -1, "an Embree scene (building it failed)");
    }
    *out = t;
    return ULAM_OK;
}

/* A ray's origin in Embree's frame (relative to the centre, in half extents). */
static void embree_origin(const ulam_tracer *t, const double org[3], struct RTCRay *ray)
{
    ray->org_x = (float)((org[0] - t->centre[0]) / t->scale), ray->org_y = (float)((org[1] - t->centre[1]) / t->scale);
    ray->org_z = (float)((org[2] - t->centre[2]) / t->scale);
}

/* The scene's size (half the largest side of its bounding box) and the centre of that box. */
double ulam__tracer_size(const ulam_tracer *t, double centre[3])
{
    if (centre)
        for (int d = 0; d < 3; d++) centre[d] = t->centre[d];
    return t->scale;
}

/* Nonzero when x is within ULAM__TRACER_REACH scene sizes of the scene's centre: a ray's origin
 * Embree can take. */
int ulam__tracer_reaches(const ulam_tracer *t, const double x[3])
{
    for (int d = 0; d < 3; d++)
        if (!(fabs(x[d] - t->centre[d]) <= ULAM__TRACER_REACH * t->scale)) return 0;
    return 1;
}

/* The first patch other than self the ray hits (with cull, the first whose front it hits), or -1;
 * *dist (may be NULL) its distance. */
static int64_t cast_from(const ulam_tracer *t, const double org[3], const double dir[3], int64_t self, int cull,
                         int *front, double *dist)
{
    ray_context rc = {.t = t, .self = self, .cull = cull ? dir : NULL};
    rtcInitIntersectContext(&rc.ctx);
    struct RTCRayHit rh;
    embree_origin(t, org, &rh.ray);
    rh.ray.dir_x = (float)dir[0], rh.ray.dir_y = (float)dir[1], rh.ray.dir_z = (float)dir[2];
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = INFINITY;
    rh.ray.time = 0.0f;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    t->E->Intersect1(t->scene, &rc.ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
    int64_t p = t->prim_patch[rh.hit.primID];
    if (front) *front = ulam__dot3(dir, t->s->normal + 3 * p) < 0;
    if (dist) *dist = (double)rh.ray.tfar * t->scale;
    return p;
}

/* The first patch the ray hits, or -1. */
int64_t ulam_tracer_cast(const ulam_tracer *t, const double org[3], const double dir[3], int *front)
{
    if (!ulam__tracer_reaches(t, org)) return -1; /* Embree's float checks abort on such an origin */
    return cast_from(t, org, dir, -1, 0, front, NULL);
}

/* The first patch whose front the ray hits (back sides are seen through), or -1. */
int64_t ulam__tracer_cast_front(const ulam_tracer *t, const double org[3], const double dir[3])
{
    return cast_from(t, org, dir, -1, 1, NULL, NULL);
}

/* The same, and where on the patch: its fan triangle k (vertices 0, k, k + 1 of the patch) and
 * the barycentric u, v of vertices k and k + 1 there. */
int64_t ulam__tracer_cast_front_uv(const ulam_tracer *t, const double org[3], const double dir[3], int64_t *k, double *u,
                                   double *v)
{
    ray_context rc = {.t = t, .self = -1, .cull = dir};
    rtcInitIntersectContext(&rc.ctx);
    struct RTCRayHit rh;
    embree_origin(t, org, &rh.ray);
    rh.ray.dir_x = (float)dir[0], rh.ray.dir_y = (float)dir[1], rh.ray.dir_z = (float)dir[2];
    rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.time = 0.0f, rh.ray.mask = ~0u, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    t->E->Intersect1(t->scene, &rc.ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
    int64_t p = t->prim_patch[rh.hit.primID];
    *k = (int64_t)rh.hit.primID - (t->s->start[p] - 2 * p) + 1; /* a patch of m vertices has m - 2 triangles */
    *u = rh.hit.u, *v = rh.hit.v;
    return p;
}

/* A cosine-distributed ray from a uniform point of patch p: the patch reached, front side. */
int64_t ulam_tracer_shoot(const ulam_tracer *t, int64_t p, ulam_rng *r)
{
    return ulam__tracer_shoot_hit(t, p, r, NULL);
}

/* The same, and where it lands (h may be NULL). */
int64_t ulam__tracer_shoot_hit(const ulam_tracer *t, int64_t p, ulam_rng *r, ulam__hit *h)
{
    double o[3], d[3], dist = 0.0;
    ulam__patch_point(t->s, p, t->share[p], r, o);
    ulam__cosine_dir(t->s->normal + 3 * p, r, d);
    int front = 0;
    int64_t j = cast_from(t, o, d, p, 0, &front, &dist);
    if (j < 0 || !front) return -1;
    if (h) {
        h->dist = dist;
        h->cos_from = ulam__dot3(d, t->s->normal + 3 * p);
        h->cos_to = -ulam__dot3(d, t->s->normal + 3 * j);
    }
    return j;
}

/* A uniform point of patch p. */
void ulam__tracer_point(const ulam_tracer *t, int64_t p, ulam_rng *r, double pt[3])
{
    ulam__patch_point(t->s, p, t->share[p], r, pt);
}

/* Nonzero when the segment from x (unit normal n, on patch self; -1: on no patch) to y (on patch l)
 * leaves x's front, reaches l's front and meets no other patch first; *h gets the distance and the
 * two cosines either way. */
int ulam__tracer_sees_from(const ulam_tracer *t, const double x[3], const double n[3], int64_t self, int64_t l,
                           const double y[3], ulam__hit *h)
{
    double d[3];
    ulam__sub3(y, x, d);
    double r = sqrt(ulam__dot3(d, d));
    h->dist = r, h->cos_from = h->cos_to = 0.0;
    if (!(r > 0)) return 0;
    for (int k = 0; k < 3; k++) d[k] /= r;
    h->cos_from = ulam__dot3(d, n);
    h->cos_to = -ulam__dot3(d, t->s->normal + 3 * l);
    if (!(h->cos_from > 0) || !(h->cos_to > 0) || self == l) return 0; /* from a back side, or at a light's back */
    return cast_from(t, x, d, self, 0, NULL, NULL) == l;
}

/* The ray org + t dir (dir unit) from a point on patch self (-1: none): the first other patch it
 * hits (-1: none), *front 1 when on its front, *dist the distance. */
int64_t ulam__tracer_ray(const ulam_tracer *t, const double org[3], const double dir[3], int64_t self, int *front,
                         double *dist)
{
    return cast_from(t, org, dir, self, 0, front, dist);
}
