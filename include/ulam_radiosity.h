/* ulam_radiosity.h: the radiosity front end of ulam, B = E + diag(rho) F B for a scene of
 * diffuse patches: OBJ + MTL scenes, Embree 3 ray casting, form factors, the LAPACK solve,
 * patch walks that sample F by rays (gathering, shooting, next-event), view gathering and PNG
 * images.  Built with meson's 'radiosity' feature (Embree 3 and libpng); the conventions of
 * ulam.h apply (status codes, ulam_error, const inputs, _free accepts NULL, the ABI habit:
 * structs the caller fills start from their defaults function, handles are opaque).
 *
 * The API by rank (as in ulam.h; each section banner below names the ranks it holds):
 *   primary: ulam_scene_read_obj, ulam_scene_find, ulam_scene_free, ulam_tracer_alloc,
 *     ulam_tracer_free, ulam_rad_defaults, ulam_rad_solver_alloc, _iterate, _done, _result, _vectors, _free,
 *     ulam_ff_estimate, ulam_rad_direct, ulam_camera_cornell, ulam_camera_frame,
 *     ulam_render, ulam_png_write;
 *   secondary: ulam_scene_subdivide, ulam_scene_centroid, ulam_scene_label_centroid,
 *     ulam_tracer_cast, ulam_ff_report_compute, ulam_rad_system,
 *     ulam_rad_direct_error, ulam_rad_direct_errors, ulam_view_gather, ulam_view_pixels,
 *     ulam_rad_solver_whole, ulam_rad_solver_scene;
 *   tertiary: ulam_tracer_resolution, ulam_ff_parallel_rectangles,
 *     ulam_ff_perpendicular_rectangles (exact references for tests). */
#ifndef ULAM_RADIOSITY_H
#define ULAM_RADIOSITY_H

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- scenes */
/* Primary: ulam_scene, ulam_scene_read_obj, ulam_scene_find, ulam_scene_free.  Secondary:
 * ulam_scene_subdivide, ulam_scene_centroid, ulam_scene_label_centroid. */

/* A scene of planar convex patches with diffuse RGB reflectance and emission: the radiosity
 * equation B = E + diag(rho) F B per colour channel.  Plain data; arrays of 3 hold RGB or
 * xyz per patch, patch p's polygon is vidx[start[p] .. start[p+1]) (counter-clockwise seen
 * from the side its normal points to, the side that emits and reflects). */
typedef struct ulam_scene {
    int64_t npatches, nverts;
    double *vert;    /* 3 * nverts coordinates */
    int64_t *start;  /* npatches + 1 */
    int32_t *vidx;   /* start[npatches] vertex indices */
    double *normal;  /* 3 * npatches unit normals */
    double *area;    /* npatches */
    double *rho;     /* 3 * npatches reflectances in [0, 1) */
    double *emit;    /* 3 * npatches emissions (radiosity units) */
    int64_t *face;   /* npatches: the face of the OBJ file a patch came from (0-based) */
    int64_t nfaces;
    int32_t *group;  /* npatches: index into groups (the o / g name in force), -1 for none */
    int64_t ngroups;
    char **groups;
} ulam_scene;

/* Read a Wavefront OBJ file (v; f with 3 or more vertices, v, v/t, v/t/n or v//n, negative
 * indices relative; o, g; usemtl; mtllib, relative to the OBJ's folder) and its MTL files
 * (newmtl; Kd = reflectance in [0, 1), Ke = emission >= 0).  One patch per face.  Errors
 * carry the line, and err->file names the MTL file when the error is in one. */
int ulam_scene_read_obj(const char *path, ulam_scene **out, ulam_error *err);

/* A non-diffuse MTL statement ulam_scene_read_obj_notes ignored: the first of its keyword in a
 * material (Ks not 0, Ns, d not 1, Tr not 0, illum above 2, Tf not 1, map_*, bump, Pr, ...;
 * the material is rendered matte with its Kd and Ke). */
typedef struct ulam_mtl_note {
    char *file;     /* the MTL file */
    long line;
    char keyword[16];
    char *material;
} ulam_mtl_note;

/* ulam_scene_read_obj, and the non-diffuse MTL statements ignored (*notes: a new array of
 * *nnotes, in file order; NULL and 0 when none or on failure; free with ulam_mtl_notes_free). */
int ulam_scene_read_obj_notes(const char *path, ulam_scene **out, ulam_mtl_note **notes, int64_t *nnotes,
                              ulam_error *err);

/* Free notes (n of them); accepts NULL. */
void ulam_mtl_notes_free(ulam_mtl_note *notes, int64_t n);

/* Split every patch into patches no longer than max_side on a side (quads into a grid,
 * triangles into m^2 similar triangles, larger polygons through a fan); face and group
 * are kept. */
int ulam_scene_subdivide(const ulam_scene *s, double max_side, ulam_scene **out);

/* What ulam_scene_subdivide(s, max_side) would make, counted without making it (so that a memory
 * limit can refuse it first): *patches, *vertices, *triangles (the ray tracer's) and *bytes of
 * the new scene's arrays (any may be NULL).  ULAM_OK, ULAM_EINVAL, or ULAM_EOVERFLOW when the
 * patches or vertices pass INT32_MAX (the counts are still given). */
int ulam_scene_subdivide_plan(const ulam_scene *s, double max_side, double *patches, double *vertices,
                              double *triangles, double *bytes);

/* Free a scene; accepts and returns NULL. */
ulam_scene *ulam_scene_free(ulam_scene *s);

/* The patch a label names: the patch of group label that contains the group's area centroid
 * (the lowest-numbered one when the centroid is on a shared edge); when none contains it (a
 * label that is not flat, like a block, whose centroid is inside it), the patch of that label
 * whose area centroid is nearest.  Does not depend on the subdivision but through the patch
 * sizes.  ULAM_ENOTFOUND when no patch has that label. */
int ulam_scene_find(const ulam_scene *s, const char *label, int64_t *patch);

/* The lowest-numbered patch that point x lies in (within rel times the patch's size of its
 * plane and of every edge), or -1 (a point on no patch, or s NULL). */
int64_t ulam_scene_locate(const ulam_scene *s, const double x[3], double rel);

/* The area centroid of patch p. */
void ulam_scene_centroid(const ulam_scene *s, int64_t p, double c[3]);

/* The area centroid of the patches labelled label; ULAM_ENOTFOUND when there are none. */
int ulam_scene_label_centroid(const ulam_scene *s, const char *label, double c[3]);

/* ---------------------------------------------------------------- rays */
/* Primary: ulam_tracer_alloc, ulam_tracer_free.  Secondary: ulam_tracer_cast.
 * Tertiary: ulam_tracer_resolution. */

/* A ray caster over a scene (Embree 3): opaque. */
typedef struct ulam_tracer ulam_tracer;

/* Build the ray-casting structure for s (which must outlive it).  Embree sees the scene
 * centred and in units of half its bounding box's largest side, so any size is cast alike;
 * ULAM_ERANGE for a scene of that half-side outside 1e-60 .. 1e60. */
int ulam_tracer_alloc(const ulam_scene *s, ulam_tracer **out, ulam_error *err);

/* Free a tracer; accepts and returns NULL. */
ulam_tracer *ulam_tracer_free(ulam_tracer *t);

/* How finely ray casting resolves the scene: Embree works in float (relative to the scene's
 * centre, in units of its size), so a patch far from the centre and small is resolved only to the float step there;
 * the largest (float step at the patch) / sqrt(its area) over the patches, that patch in
 * *patch (may be NULL).  Above 10^-3 the geometry that rays see is off by more than 0.1% of a
 * patch. */
double ulam_tracer_resolution(const ulam_tracer *t, int64_t *patch);

/* The patch the ray org + t dir (t > 0, dir unit) first hits, or -1 when it leaves the
 * scene or starts more than 10^6 scene sizes (half the bounding box's largest side) from the
 * scene's centre, where Embree's floats cannot take it; *front (may be NULL) is 1 when it hits
 * the patch's front side. */
int64_t ulam_tracer_cast(const ulam_tracer *t, const double org[3], const double dir[3],
                         int *front);


/* What rays say about a scene (ulam_rad_scene_diagnose): the emitting patches, and where
 * cosine rays from uniform points of patches drawn by area land, from their fronts, from their
 * backs and from the emitters' fronts: [0] on a patch's front, [1] on a back, [2] nowhere (they
 * left the scene). */
typedef struct {
    int64_t emitters;
    int64_t front[3], back[3], lamp[3];
} ulam_rad_scene_diag;

/* Diagnose a scene that answers 0: rays cosine rays from the fronts and as many from the backs
 * (stream seed); in a room whose normals face in, the fronts' rays land on fronts and the backs'
 * leave; with the winding reversed the fronts' leave and the backs' land on backs.  ULAM_OK,
 * ULAM_EINVAL, ULAM_ENOMEM. */
int ulam_rad_scene_diagnose(const ulam_tracer *t, int64_t rays, uint64_t seed, ulam_rad_scene_diag *out);

/* ---------------------------------------------------------------- form factors and the direct solve */
/* Primary: ulam_ff_estimate, ulam_rad_direct.  Secondary: ulam_ff_report_compute, ulam_rad_system,
 * ulam_rad_direct_error, ulam_rad_direct_errors.  Tertiary: the exact ulam_ff_*_rectangles. */

/* Form factors F_ij estimated by casting `rays` cosine-distributed rays from uniform points of
 * each patch i (the share that reaches j); stream (seed, i) for patch i, so F does not
 * depend on the number of threads (0: all cores). */
int ulam_ff_estimate(const ulam_tracer *t, int64_t rays, uint64_t seed, int threads,
                     ulam_csr **F, ulam_error *err);

/* How well an estimated F obeys the laws of form factors. */
typedef struct ulam_ff_report {
    double reciprocity; /* sum |A_i F_ij - A_j F_ji| / sum A_i F_ij over pairs i < j, j < i */
    double rowsum_min, rowsum_max, rowsum_mean; /* 1 in a closed scene */
    int64_t nnz;
} ulam_ff_report;

/* Fill *r for F on s. */
int ulam_ff_report_compute(const ulam_scene *s, const ulam_csr *F, ulam_ff_report *r);

/* Exact form factor between directly opposed parallel a x b rectangles at distance c
 * (Howell's catalogue, C-11). */
double ulam_ff_parallel_rectangles(double a, double b, double c);

/* Exact form factor from a w x l rectangle to an h x l rectangle perpendicular to it that
 * shares its edge of length l (Howell's catalogue, C-14). */
double ulam_ff_perpendicular_rectangles(double w, double h, double l);

/* The radiosity system of channel c: M = diag(rho_c) F (new *M) and b = E_c (npatches). */
int ulam_rad_system(const ulam_scene *s, const ulam_csr *F, int channel, ulam_csr **M,
                    double *b);


/* Solve the three channels' systems with LAPACKE_dgesv into B (3 * npatches, RGB per patch);
 * refuses with ULAM_EMEMLIMIT like ulam_direct_solve.  info (may be NULL) sums the three. */
int ulam_rad_direct(const ulam_scene *s, const ulam_csr *F, size_t max_bytes, double *B,
                    ulam_direct_info *info, ulam_error *err);

/* The standard error of the direct solution B (from ulam_rad_direct on an F estimated
 * with `rays` rays a patch) at patch p, per channel: the first-order propagation of the
 * multinomial noise of each row of F, se^2 = sum_k (G_pk rho_k)^2 v_k / rays with
 * G = (I - M)^-1 (one transposed LAPACK solve a channel) and v_k = sum_j F_kj B_j^2 -
 * (sum_j F_kj B_j)^2, plus, for each patch j whose own rays say by reciprocity that F_kj is
 * larger than row k saw (a small bright lamp none of row k's rays hit), (A_j F_jk / A_k -
 * F_kj) (B_j - sum_j F_kj B_j)^2, and for each emitter l facing k that neither's rays met,
 * 0.5 / (rays (1 + A_k / A_l)) (B_l - sum_j F_kj B_j)^2. */
int ulam_rad_direct_error(const ulam_scene *s, const ulam_csr *F, int64_t rays, const double *B,
                          int64_t p, size_t max_bytes, double se[3], ulam_error *err);

/* The same at every patch (se: 3 * npatches): G = (I - M)^-1 whole by one LAPACKE_dgesv with
 * npatches right-hand sides a channel, so two dense matrices (ULAM_EMEMLIMIT past max_bytes). */
int ulam_rad_direct_errors(const ulam_scene *s, const ulam_csr *F, int64_t rays, const double *B,
                           size_t max_bytes, double *se, ulam_error *err);

/* ---------------------------------------------------------------- patch walks */
/* All primary but ulam_rad_solver_whole and ulam_rad_solver_scene (secondary). */

/* The radiosity estimators: opts->estimator of ulam_rad_solver_alloc and ulam_rad_point_alloc
 * is one of these (its own enum, not ulam.h's ulam_estimator; 0, ulam_rad_defaults()'s, is
 * next-event with MIS).
 *
 * Next-event (gathering and point walks): at every patch p a walk visits with weights W, a point y is drawn on an emitter l (l in
 * proportion to its power A_l sum_c E_lc, y uniform on it) and a uniform point x on p; one
 * shadow ray scores W rho_p E_l cos cos_l A_l / (pi r^2 P_l) (P_l: l's share of the power)
 * when y is visible from x and both face each other.  The walk's own cosine rays that reach an
 * emitter are combined with it by multiple importance sampling (Veach's power heuristic,
 * exponent 2, or the balance heuristic), or not counted at all (light sampling alone, which
 * has infinite variance at a patch that shares an edge with a light). */
enum ulam_rad_estimator {
    ULAM_RAD_NEXT_EVENT = 0,         /* light sampling + the walk's hits, power heuristic (default) */
    ULAM_RAD_NEXT_EVENT_BALANCE = 1, /* the same, balance heuristic */
    ULAM_RAD_NEXT_EVENT_LIGHT = 2,   /* light sampling alone */
    ULAM_RAD_COLLISION = 3,          /* score emission at every patch reached (shooting: tally every
                                        reflection); point walks: the walk's emitter hits alone */
    ULAM_RAD_ABSORPTION = 4          /* score where the walk stops (patch walks only) */
};

/* Points within this share of a patch's size of it lie on it (ulam_scene_locate's rel for
 * point walks). */
#define ULAM_RAD_LOCATE_REL 1e-6

/* What a patch walk run has found: RGB radiosity of the patch opts->index. */
typedef struct ulam_rad_result {
    double radiosity[3];
    double std_error[3];
    int64_t walks;    /* histories (gathering walks or shot particles) */
    int64_t rays;     /* rays cast */
    int64_t cut;      /* walks cut at max_steps */
    double max_share; /* the largest single score^2 / sum of scores^2 (channel sum) */
    double seconds;
    int threads, interrupted;
    int zero; /* rel_err could never be met: every channel exactly 0 with zero variance after
               * the first round (no walk scored); the run stopped there */
    double min_walks;          /* with rel_err: the walks a confidence sequence tuned to the target
                                  needs at this estimate (src/stop.c; largest over channels) */
    double variance_rel_error; /* with rel_err: the largest relative standard error of a
                                  channel's variance (fourth moment; reported, not a stop rule) */
    int rel_err_met;           /* the run stopped because the rel_err rule holds: every nonzero
                                  channel's ci95 half-width at most rel_err times its estimate */
    double ci95[3][2];         /* each channel's 95% interval (src/stop.c's confidence sequence on
                                  the certified score range, valid at every walk count); NaN .. NaN
                                  where none is certified */
} ulam_rad_result;

/* How patch walks run and when they stop: radiosity's own options (the matrix walks' kernel,
 * query and guard parts do not apply: patch walks continue with the patch's largest reflectance
 * and follow the form factors).  Start from ulam_rad_defaults(). */
typedef struct ulam_rad_opts {
    int mode;            /* ULAM_ADJOINT gathers at patch index, ULAM_FORWARD shoots */
    int estimator;       /* enum ulam_rad_estimator */
    int64_t index;       /* the patch (0-based); point walks do not read it */
    ulam_stop_opts stop; /* walks, rel_err, time, walk cap, interrupt */
    ulam_exec_opts exec; /* seed, threads, processes */
} ulam_rad_opts;

/* The defaults: gathering at patch 0 with next-event estimation, and ulam_walk_defaults()'s stop and
 * exec parts (10^5 walks, walk cap 10^6 steps, seed 1, all cores). */
ulam_rad_opts ulam_rad_defaults(void);

/* An opaque patch-walk solver: walks that sample F by ray casting, never forming it. */
typedef struct ulam_rad_solver ulam_rad_solver;

/* Prepare walks on scene t (the tracer's): opts->mode ULAM_ADJOINT gathers at patch
 * opts->index (continuation max_c rho_c of the patch, weights rho_c / q), ULAM_FORWARD
 * shoots particles from the emitters in proportion to power and tallies every patch;
 * opts->estimator one of enum ulam_rad_estimator (shooting: ULAM_RAD_COLLISION or
 * ULAM_RAD_ABSORPTION; next-event's rays count the shadow rays too); the stopping rules, seed,
 * threads and interrupt of opts->stop and opts->exec. */
int ulam_rad_solver_alloc(const ulam_tracer *t, const ulam_rad_opts *opts, ulam_rad_solver **out,
                          ulam_error *err);

/* A point query's answer (ulam_rad_point_result). */
typedef struct ulam_rad_point {
    double x[3], n[3];        /* the point (on its patch's plane) and the unit normal used */
    int64_t patch;            /* the patch the point lies on (0-based), or -1: a sensor off the surfaces */
    double irradiance[3];     /* H = int B G V dA: the light arriving per unit area (radiosity units) */
    double irradiance_se[3];
    double radiosity[3];      /* B = E + rho H of the patch's material; NaN off the surfaces */
    double radiosity_se[3];   /* rho times H's */
    ulam_rad_result run;      /* walks, rays, cut, seconds, rel_err ...; its radiosity[] and
                                 std_error[] are H's */
} ulam_rad_point;

/* Prepare point walks (point.c) from x, on the continuous surfaces (no mesh in the answer): the
 * light sample and the cosine ray at every vertex are taken from the vertex itself, not a
 * uniform point of its patch.  n NULL: x must lie on a patch (ulam_scene_locate with
 * ULAM_RAD_LOCATE_REL), whose normal it takes; n given: a sensor facing n anywhere (on a patch,
 * n must be the patch's).  opts as ulam_rad_solver_alloc's, gathering, estimator next-event (any
 * of the three) or ULAM_RAD_COLLISION; opts->index is not read; rel_err is held on the
 * irradiance.  Iterate, done and free as for patch walks; ulam_rad_solver_result gives H. */
int ulam_rad_point_alloc(const ulam_tracer *t, const ulam_rad_opts *opts, const double x[3], const double n[3],
                         ulam_rad_solver **out, ulam_error *err);

/* A point solver's answer so far; ULAM_EINVAL for a patch solver. */
int ulam_rad_point_result(const ulam_rad_solver *s, ulam_rad_point *r);

/* One point query run to its end: ulam_rad_point_alloc, iterate until done, the result. */
int ulam_rad_point_query(const ulam_tracer *t, const ulam_rad_opts *opts, const double x[3], const double n[3],
                         ulam_rad_point *r, ulam_error *err);

/* A sensor grid: the centres of nu x nv cells of the rectangle origin + a u + b v (a, b in
 * [0, 1]), every sensor facing the unit normal (a work plane: the lighting designer's grid). */
typedef struct ulam_rad_grid {
    double origin[3], u[3], v[3], normal[3];
    int nu, nv;
} ulam_rad_grid;

/* The most points a grid may have. */
#define ULAM_RAD_GRID_MAX 1000000

/* The centre of cell (i, j): origin + (i + 1/2) / nu u + (j + 1/2) / nv v. */
void ulam_rad_grid_point(const ulam_rad_grid *g, int i, int j, double x[3]);

/* Point queries (ulam_rad_point_query) at every sensor of g, out[j nu + i] for cell (i, j), each
 * with opts (rel_err, max_walks per point; max_seconds for the whole grid) and the seed drawn
 * from stream (opts->exec.seed, j nu + i).  Interrupted: the points not reached are zeroed (their
 * run.walks 0).  ULAM_EINVAL for a grid without points, not finite or with a normal not unit. */
int ulam_rad_grid_solve(const ulam_tracer *t, const ulam_rad_opts *opts, const ulam_rad_grid *g, ulam_rad_point *out,
                        ulam_error *err);

/* Point queries (ulam_rad_point_query with opts) at n given points: at[6 k .. 6 k + 2] the point,
 * at[6 k + 3 .. 6 k + 5] its sensor's unit normal (at[6 k + 3] NaN: on a patch, its normal), out[k]
 * its answer, point k seeded by ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, k) so it
 * depends on no other point.  Interrupted: the points not reached are zeroed (run.walks 0).
 * ULAM_OK, or point k's failure (err->index = k). */
int ulam_rad_points_solve(const ulam_tracer *t, const ulam_rad_opts *opts, const double *at, int64_t n,
                          ulam_rad_point *out, ulam_error *err);

/* The luminance weights of R, G and B (Rec. 709: 0.2126, 0.7152, 0.0722): Y = sum_c w_c X_c. */
const double *ulam_rad_luma(void);

/* A point's illuminance Y = sum_c w_c H_c (ulam_rad_luma; in the scene's units) and a bound on its
 * standard error, the channels' added (they come from the same walks). */
void ulam_rad_illuminance(const ulam_rad_point *r, double *Y, double *se);

/* A 95% interval [*lo, *hi] for a point's illuminance, Y +- sum_c w_c h_c (h_c channel c's
 * half-width), floored at 0; NaN .. NaN unless every channel has one. */
void ulam_rad_illuminance_ci(const ulam_rad_point *r, double *lo, double *hi);

/* What a work plane's sensors say together (ulam_rad_grid_stats). */
typedef struct ulam_rad_grid_summary {
    double min, mean;   /* the sensors' illuminance */
    double uniformity;  /* min / mean (NaN when the mean is not positive) */
    double worst;       /* the largest relative standard-error bound, over the sensors with Y > 0 */
    int64_t walks, rays;
} ulam_rad_grid_summary;

/* The summary of n sensors' answers (n >= 1); ULAM_OK or ULAM_EINVAL. */
int ulam_rad_grid_stats(const ulam_rad_point *pts, int64_t n, ulam_rad_grid_summary *out);

/* The most quadrature points of a mesh-error estimate: the centroid and up to 8 vertex halves. */
#define ULAM_RAD_MESH_POINTS 9

/* The mesh's error of a patch query (ulam_rad_mesh_error). */
typedef struct ulam_rad_mesh {
    int npoints;                                    /* quadrature points used, the centroid first */
    double point[ULAM_RAD_MESH_POINTS][3];          /* the surface's radiosity B(x_k) there */
    double point_se[ULAM_RAD_MESH_POINTS][3];
    double mean[3], mean_se[3];                     /* their mean (a quadrature of the patch's mean) */
    double error[3];    /* max_k |B_patch - B(x_k)|: the mesh error beside the Monte Carlo error */
    double error_se[3]; /* the standard error of that point's B(x_k) */
    int64_t walks, rays;
    double seconds;
    int interrupted;
} ulam_rad_mesh;

/* The mesh error of the patch query of patch opts->index that answered B (RGB): point queries
 * (ulam_rad_point_query with opts, each its seed from stream (opts->exec.seed, k + 1)) on the
 * continuous surfaces at the patch's area centroid and half way from it to each of its first 8
 * vertices, against B.  opts->stop.max_seconds is for all the points (each gets what is left
 * shared among the points left; one block of walks still runs when nothing is). */
int ulam_rad_mesh_error(const ulam_tracer *t, const ulam_rad_opts *opts, const double B[3], ulam_rad_mesh *out,
                        ulam_error *err);

/* Run one round of walks (rounds grow 1, 2, 4 ... 32 blocks of 256 walks as walks accumulate,
 * whatever the thread count); ULAM_OK, or the status that ends the run: ULAM_ENONFINITE,
 * ULAM_ENOMEM (shooting's tallies), ULAM_EIO (the share's allgather). */
int ulam_rad_solver_iterate(ulam_rad_solver *s);

/* Nonzero once a stopping rule is met (rel_err: every nonzero channel; or every channel is
 * exactly 0 with zero variance, when the result's zero is set). */
int ulam_rad_solver_done(const ulam_rad_solver *s);

/* The result so far. */
void ulam_rad_solver_result(const ulam_rad_solver *s, ulam_rad_result *r);

/* Shooting: every patch's RGB radiosity and standard error (3 * npatches each; either may be
 * NULL).  Gathering: ULAM_EINVAL. */
int ulam_rad_solver_vectors(const ulam_rad_solver *s, double *B, double *std_error);

/* Free; accepts and returns NULL. */
ulam_rad_solver *ulam_rad_solver_free(ulam_rad_solver *s);

/* The whole scene under shooting's rel_err rule (ulam_rad_solver_whole, ulam_rad_solver_scene). */
typedef struct ulam_rad_scene_rule {
    int64_t lit;          /* patches light is on: an emitter, or a patch some particle reached */
    int64_t met;          /* of them, those whose every channel meets rel_err (as at one patch: its
                             95% interval's half-width at most E B) */
    int64_t unreached;    /* patches that reflect (rho > 0) and emit nothing that no particle reached
                             (light may still reach them: 3 / walks bounds the share of particles that do) */
    double lit_area, met_area;
    double worst_se;      /* the largest relative standard error se / B over the lit patches' channels */
    double worst_half;    /* the largest relative 95% half-width (each patch's confidence sequence) */
    int64_t worst_patch;  /* its patch (0-based), -1 when none is lit */
    double share;         /* the rule's share (ulam_rad_solver_whole), 0 when not set */
} ulam_rad_scene_rule;

/* Shooting: stop by opts->stop.rel_err when the lit patches (ulam_rad_scene_rule's) that meet it
 * hold at least share (in (0, 1]; 1: every lit patch) of the lit area, instead of when patch
 * opts->index does; patches no particle reached do not hold the run (ulam_rad_solver_scene names
 * them).  Call before the first iterate.  ULAM_EINVAL for a gathering or point solver, or a share
 * outside (0, 1]. */
int ulam_rad_solver_whole(ulam_rad_solver *s, double share);

/* Shooting: the whole scene's state under opts->stop.rel_err so far (met counts 0 without
 * rel_err), and the first max patches no particle reached (0-based, in order) into unreached (may
 * be NULL when max is 0).  ULAM_EINVAL for a gathering or point solver. */
int ulam_rad_solver_scene(const ulam_rad_solver *s, ulam_rad_scene_rule *out, int64_t *unreached, int64_t max);

/* ---------------------------------------------------------------- radiosity modes */
/* Secondary: ulam_rad_mode_find, ulam_rad_mode_name, ulam_rad_final. */

/* The mode of final gathering over a shooting pilot (ulam_rad_final), beside ULAM_ADJOINT
 * (gather, one patch) and ULAM_FORWARD (shoot, every patch). */
#define ULAM_RAD_FINAL 2

/* The radiosity modes by name (src/radiosity/modes.c: one row each): "gather" ULAM_ADJOINT,
 * "shoot" ULAM_FORWARD, "final" ULAM_RAD_FINAL; -1 for an unknown name. */
int ulam_rad_mode_find(const char *name);

/* A mode's name and one-line summary (summary may be NULL); NULL for an unknown mode. */
const char *ulam_rad_mode_name(int mode, const char **summary);

/* What a final gather did (ulam_rad_final). */
typedef struct ulam_rad_final_info {
    int64_t particles, particle_rays; /* the pilot's shooting */
    int64_t samples, rays;            /* the gather's samples (two rays each) */
    int64_t gathered;                 /* patches gathered (those that reflect and were reached in time) */
    ulam_rad_scene_rule scene;        /* the whole scene's rule at rel_err (ulam_rad_scene_rule's
                                         meaning; unreached: no sample scored, or the stop came first) */
    int64_t unreached[8];             /* the first unreached patches (0-based; -1 past scene.unreached) */
    int met;                          /* rel_err met on share of the lit area */
    double pilot_seconds, seconds;
    int threads, interrupted;         /* interrupted: by opts->stop.interrupt (max_seconds is a rule:
                                         the patches it left are NaN and unreached) */
} ulam_rad_final_info;

/* Every patch's radiosity by final gathering over a shooting pilot (the method of large scenes,
 * docs/radiosity.md): 16 independent shooting runs of pilot / 16 particles (pilot 0: 4 a patch,
 * at least 65536) estimate the reflected radiosity; then every patch that reflects gathers from
 * uniform points: a light sample (an emitter drawn by its unoccluded transfer to the patch, MIS
 * with the cosine ray) and a cosine ray whose landing scores its patch's emission and the pilot's
 * reflected radiosity.  half: the 95% half-width, the samples' confidence sequence (stop.h, on
 * the range certified given the pilot, valid at every count) at 97.5% plus the pilot runs' part
 * (Student's t on 15 degrees of freedom) at 97.5%; se the central-limit standard error beside it.
 * opts->stop.rel_err E > 0: each patch stops once every channel's half-width is at most E B
 * (passes to 64, 256, 1024 ... samples a patch, at most max_walks, 0: 10^6); E = 0: max_walks
 * samples a patch (0: 64).  max_seconds for the whole (the pilot at most a quarter), interrupt.
 * Patch p's samples draw from stream (seed, ULAM_STREAM_POINT, p), the pilot's run g from (seed,
 * ULAM_STREAM_PILOT, g): the answer does not depend on threads.  B, se, half: 3 * npatches (NaN
 * where the stop came first).  info may be NULL.  ULAM_EUNDEFINED for a scene without emitters. */
int ulam_rad_final(const ulam_tracer *t, const ulam_rad_opts *opts, int64_t pilot, double share, double *B, double *se,
                   double *half, ulam_rad_final_info *info, ulam_error *err);

/* ulam_rad_final on the patches with want[p] != 0 only (want: npatches flags; NULL: all), the
 * importance of a work plane: the pilot still shoots the whole scene, the others are left NaN
 * and out of the whole scene's rule (info->scene counts the wanted). */
int ulam_rad_final_some(const ulam_tracer *t, const ulam_rad_opts *opts, int64_t pilot, double share,
                        const unsigned char *want, double *B, double *se, double *half, ulam_rad_final_info *info,
                        ulam_error *err);

/* ---------------------------------------------------------------- images */
/* Primary: ulam_camera_cornell, ulam_camera_frame, ulam_render, ulam_png_write.  Secondary:
 * ulam_view_pixels, ulam_view_gather. */

/* A pinhole camera.  Start from ulam_camera_cornell() or ulam_camera_frame() (ulam.h's ABI
 * habit). */
typedef struct ulam_camera {
    double eye[3], dir[3], up[3];
    double focal, film; /* focal length and film width, same unit (mm) */
} ulam_camera;

/* The Cornell box camera: eye (278, 273, -800), looking along +z, 35 mm lens, 25 mm film. */
ulam_camera ulam_camera_cornell(void);

/* A camera framing the scene's bounding box for a width x height picture: looking along +z at
 * its centre from the -z side, up +y, the Cornell lens, as near as lets the box's near face
 * fill the picture (3% margin).  On the Cornell box: eye (278, 274.4, -802). */
ulam_camera ulam_camera_frame(const ulam_scene *s, int width, int height);

/* What a render saw. */
typedef struct ulam_render_info {
    double exposure;        /* the exposure used */
    int exposure_set;       /* given, or set from the pixels (0: nothing lit in view, 1 used) */
    int64_t pixels_hit;     /* pixels that see a patch's front */
    int64_t pixels_emitter; /* of them, pixels that see an emitter (0: no emitter in view) */
} ulam_render_info;

/* Render B (3 * npatches) as width x height 8-bit sRGB (3 bytes a pixel, rows top first):
 * one ray per pixel centre, the radiosity of the first patch whose front it meets (back sides
 * are seen through, so a camera outside a closed room sees in) times exposure, clamped,
 * sRGB-encoded (flat shading).  exposure <= 0 picks 1 / (the 99th percentile of the largest
 * channel over the pixels of patches that do not emit; over all pixels when those are all
 * black or absent); *info (may be NULL) says what was used
 * and seen.  ULAM_ENONFINITE if any of B is not finite, ULAM_EOVERFLOW if the image cannot be
 * sized. */
int ulam_render(const ulam_tracer *t, const double *B, const ulam_camera *cam, int width,
                int height, double exposure, unsigned char *rgb, ulam_render_info *info);

/* Render B (3 * npatches) with `samples` jittered rays a pixel (1: the pixel centre; each pixel's
 * jitter from stream (seed, pixel)) and, when smooth, the radiosity interpolated across each
 * hit patch from its corners (a corner's value: the area-weighted mean of B over the patches of
 * the same OBJ face sharing that vertex, so subdivision is smoothed and creases between faces
 * kept): linear RGB floats in hdr (3 a pixel, rows top first) and, when rgb is not NULL, the
 * 8-bit sRGB picture with ulam_render's exposure rule.  Errors as ulam_render's. */
int ulam_render_hdr(const ulam_tracer *t, const double *B, const ulam_camera *cam, int width, int height, int samples,
                    int smooth, uint64_t seed, double exposure, float *hdr, unsigned char *rgb, ulam_render_info *info);


/* Write linear float RGB (3 a pixel, rows top first) as a Radiance .hdr file (RGBE, flat
 * scanlines: 8 bits of mantissa a channel under a shared exponent), atomically. */
int ulam_hdr_write(const char *path, int width, int height, const float *rgb);

/* How many pixel centres of a width x height picture see each patch's front (pixels:
 * npatches), with the rays of ulam_render. */
int ulam_view_pixels(const ulam_tracer *t, const ulam_camera *cam, int width, int height, int64_t *pixels);

/* What a view gather did. */
typedef struct ulam_view_info {
    int64_t npatches, seen; /* patches in the scene, and those some pixel sees */
    int64_t pixels_hit;     /* pixels that see a patch */
    int64_t camera_rays;    /* width * height */
    int64_t walks, rays;    /* gathering walks and their rays (shadow rays included) */
    int64_t unmet;          /* seen patches that stopped short of their target (budget, time) */
    int64_t cut;            /* walks cut at max_steps */
    double seconds;         /* all of it, camera rays included */
    int threads, interrupted;
} ulam_view_info;

/* Images that solve only what is seen: cast the camera's primary rays (ulam_view_pixels), then
 * gather every patch some pixel sees, and no other, each with its own solver run (opts: the
 * gathering estimator, seed, threads, max_walks a patch, max_steps, interrupt; max_seconds
 * for the whole) to relative error opts->stop.rel_err (n_max / n_p)^coverage on every nonzero
 * channel, n_p its pixels and n_max the most any patch has: coverage 0 holds every seen
 * patch to rel_err; 0.25 minimises the walks for a given pixel-summed squared error
 * (sum_p n_p se_p^2 at cost sum_p 1 / se_p^2: se_p ~ n_p^-1/4).  Patch p's walks use the seed
 * drawn from stream (opts->exec.seed, p), so the result does not depend on threads.  B and se
 * (3 * npatches) get the seen patches' answers; unseen patches get B 0 and se NaN. */
int ulam_view_gather(const ulam_tracer *t, const ulam_camera *cam, int width, int height, double coverage,
                     const ulam_rad_opts *opts, double *B, double *se, ulam_view_info *info, ulam_error *err);

/* ---------------------------------------------------------------- adaptive subdivision */
/* Secondary: ulam_rad_importance, ulam_rad_adapt. */

/* The view's importance of every patch (Y: npatches), the adjoint of the radiosity system with
 * the picture as its source: Y = S + (diag(rho) F)^T Y, S_p the share of the picture's hit
 * pixels that see patch p (ulam_view_pixels' rays), so the mean hit pixel is sum_p Y_p E_p and
 * an error d on patch p's radiosity moves it by Y_p d.  S exactly; the rest by `walks` walks
 * from the seen patches (in proportion to S, continuing with the mean of rho, each landing
 * counted: Hanrahan-Salzman-Aupperle 1991, Smits-Arvo-Salesin 1992), from stream (seed, 0).
 * All 0 when the camera sees no patch. */
int ulam_rad_importance(const ulam_tracer *t, const ulam_camera *cam, int width, int height, int64_t walks,
                        uint64_t seed, double *Y, ulam_error *err);

/* What adaptive subdivision did (ulam_rad_adapt). */
typedef struct ulam_rad_adapt_info {
    int64_t patches_in, patches; /* the tracer's scene's patches, and the mesh made */
    int64_t splits, rounds;      /* patches split, rounds that split any */
    int64_t points, walks, rays; /* point queries made, their walks and rays */
    double error0, error;        /* the mesh error (below) of the tracer's mesh and of the mesh made
                                    (interrupted: the round that was cut is undone, the mesh made
                                    is the last one measured whole; NaN both when the first
                                    round was cut, the tracer's scene then copied) */
    double target, seconds;
    int met;         /* error <= target */
    int capped;      /* stopped by max_patches (or no patch left large enough to split) */
    int interrupted; /* opts->interrupt or max_seconds */
} ulam_rad_adapt_info;

/* Adaptive, importance-driven subdivision of the tracer's scene: the mesh error of a patch p,
 * e_p, is the RMS of the continuous surface's radiosity about its mean over the patch, from
 * point queries (ulam_rad_point_query with opts, no mesh in their answers) at the patch's area
 * centroid and half way to each vertex, weight 2/3, and at the nodes on its boundary (its
 * vertices and the midpoints finer neighbours put on its edges, each measured once), weight 1/3
 * by length (the points' noise and one SD of its spread removed, scaled to a linear field's RMS
 * over the area); the mesh's error is max over channels of sum_p Y_p e_p / sum_p Y_p mean_p,
 * Y_p the importance of p
 * (importance: one a patch of the tracer's scene, e.g. ulam_rad_importance's, a child getting
 * its area's share; NULL: the area, every surface alike).  While it is above target, the
 * patches of largest Y_p e_p are split (triangles and quads into 4 at their edge midpoints,
 * shared by neighbours; larger polygons into their fan) and their children measured, until
 * target is met, the mesh would pass max_patches, or opts->interrupt / max_seconds stops it.
 * Point k of the i-th polygon measured draws its seed from stream (opts->seed, 16 i + k), the
 * node at vertex v from (opts->seed, 16 v + 15).
 * *out gets the mesh made (faces, groups and materials kept; the tracer's scene when nothing
 * was split is copied).  info may be NULL. */
int ulam_rad_adapt(const ulam_tracer *t, const ulam_rad_opts *opts, const double *importance, double target,
                   int64_t max_patches, ulam_scene **out, ulam_rad_adapt_info *info, ulam_error *err);

/* The size of ulam_falsecolour's picture of an nu x nv grid of cells of cw x ch pixels (the
 * scale bar and its labels to the right). */
void ulam_falsecolour_size(int nu, int nv, int cw, int ch, int *width, int *height);

/* A false-colour picture of grid values v (v[j nu + i], row j = 0 at the bottom; NaN: grey)
 * from lo (blue) to hi (red) in cells of cw x ch pixels, with a labelled scale bar, into rgb (3 bytes a pixel of
 * ulam_falsecolour_size, rows top first); ULAM_EINVAL unless lo < hi are finite. */
int ulam_falsecolour(const double *v, int nu, int nv, int cw, int ch, double lo, double hi, unsigned char *rgb);

/* Write an 8-bit RGB image as PNG (libpng), atomically. */
int ulam_png_write(const char *path, int width, int height, const unsigned char *rgb);

#ifdef __cplusplus
}
#endif

#endif /* ULAM_RADIOSITY_H */
