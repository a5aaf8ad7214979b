/* ulam_radiosity_run.h: one radiosity run as `ulam radiosity` makes it, a library object any front
 * end (the CLI, Python) can drive: the scene read and subdivided (refused before any ray when
 * --max-mem cannot hold it), adapted (--mesh-target), lit by luminaires, then the walks the options
 * ask for (a patch, the whole scene, the view, point queries and sensor grids), the form factors
 * and the LAPACK solve, the mesh errors, and the reports: text or JSON, the CSV rows and the
 * pictures.  The library never writes to stdout and never exits: reports go to the caller's FILE *,
 * warnings and error lines to opts->log (NULL: none), and each call returns a status.
 *
 * Primary: ulam_rad_run_defaults, ulam_rad_run_alloc, ulam_rad_run_solve, ulam_rad_run_print,
 * ulam_rad_run_free.  Secondary: ulam_rad_run_write, ulam_rad_unit_metres. */
#ifndef ULAM_RADIOSITY_RUN_H
#define ULAM_RADIOSITY_RUN_H

#include "ulam_photometry.h"
#include "ulam_radiosity.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What a run is asked (ulam radiosity's options, by the same names). */
typedef struct ulam_rad_run_opts {
    const char *scene;      /* the OBJ file */
    const char *patch;      /* --patch: a 1-based number or a label, or NULL */
    const char *patches;    /* --patches: --mode final's (and --list's) patches, comma-separated labels,
                               1-based numbers and ranges K-L; NULL: every patch */
    const char *image, *out; /* --image (PNG), --out (CSV): the paths reports name and pictures go to */
    const char *pfm, *hdr;   /* the PFM and Radiance .hdr beside --image (NULL: not written) */
    double subdivide, exposure;
    int64_t ff_rays;
    int direct, check, matrix_walk, json, width, height, all, list;
    int est, mis;           /* 0 collision, 1 absorption, 2 next-event; 0 power, 1 balance, 2 none (-1: not given) */
    int view, no_mesh, samples, flat; /* --view-gather, --no-mesh-error, --samples, --flat */
    int final;              /* --mode final: every patch by ulam_rad_final (o.mode is then ULAM_FORWARD) */
    int64_t mesh_walks;     /* --mesh-error N */
    double mesh_target;     /* --mesh-target E (0: none) */
    int64_t max_patches;    /* --max-patches (0: not given) */
    const double *at;       /* --at: 6 a point (the normal NaN when not given) */
    int nat;
    int grid;               /* a sensor grid (g) */
    ulam_rad_grid g;
    double coverage, share;
    int camera_given;       /* cam given, else one framing the scene */
    ulam_camera cam;
    size_t max_mem;
    ulam_walk_opts o;       /* walks: mode, estimator (resolved), stop, exec */
    /* photometry: luminaires placed in the scene (spec[k] as given, FILE@x,...), the unit */
    int photo;              /* any photometric option given */
    const char *const *spec;
    const ulam_luminaire *lum;
    int nlum;
    double metres, maintenance; /* metres a scene unit; the maintenance factor */
    int unit_given, en12464;    /* --en12464: g is its grid */
    /* the caller's side */
    FILE *log;              /* warnings and error lines (NULL: none) */
    int rank;               /* warnings and the patch CSV from rank 0 only */
    double started;         /* ulam_now() when the run began: --time counts the whole run */
    void (*catch_interrupt)(int on);  /* around the walks (NULL: none) */
    void (*hold_signals)(int on);     /* around the writing of the pictures (NULL: none) */
    void (*progress)(void *ctx, const ulam_walk_opts *o, int what, int64_t walks, double estimate, double se);
                            /* ray walks' progress (o: their rules): 0 start, 1 show, 2 end */
    void *progress_ctx;
} ulam_rad_run_opts;

/* The command's defaults: 1000 form-factor rays, 512 x 512, 4 samples, coverage 0.25, 4 GiB,
 * estimator and MIS not given, the walk defaults without a walk count, log NULL. */
ulam_rad_run_opts ulam_rad_run_defaults(void);

/* An opaque run. */
typedef struct ulam_rad_run ulam_rad_run;

/* Usage-type failure of ulam_rad_run_alloc or _solve: a --patch or point the scene does not hold
 * (the line written to opts->log). */
#define ULAM_RAD_RUN_USAGE (-1)
/* ulam_rad_run_alloc stopped by opts->o.stop.interrupt while the luminaires lit the scene. */
#define ULAM_RAD_RUN_INTERRUPTED (-2)

/* Read, subdivide or adapt, check the memory, build the tracer and light the scene (with
 * opts->list, stop after the mesh).  The run keeps opts' strings and arrays (scene, patch, paths,
 * at, spec, lum): they outlive it.  *out is set even on failure (free it).  ULAM_OK, a status
 * (its line written to opts->log) or one of the two above. */
int ulam_rad_run_alloc(const ulam_rad_run_opts *opts, ulam_rad_run **out);

/* Run the walks and solves the options ask; *interrupted gets whether Ctrl-C or --time cut them
 * short (nothing is then written).  ULAM_OK, a status or ULAM_RAD_RUN_USAGE (the line written). */
int ulam_rad_run_solve(ulam_rad_run *r, int *interrupted);

/* What ulam_rad_run_write writes. */
enum ulam_rad_run_file {
    ULAM_RAD_RUN_CSV,  /* --out's rows (one a patch, or one a grid sensor) into f: the caller opens and
                          commits the file, and the report then names it */
    ULAM_RAD_RUN_IMAGE /* --image's PNG with its PFM and HDR (or the grid's false-colour PNG), to the
                          paths of the options (f unused) */
};

/* Write one of the run's files; ULAM_OK or a status (its line written to opts->log). */
int ulam_rad_run_write(ulam_rad_run *r, int what, FILE *f);

/* The report, text or (opts->json) one JSON object, into f. */
void ulam_rad_run_print(const ulam_rad_run *r, FILE *f);

/* Whether the --rel-err target the report states was met (after ulam_rad_run_solve): 1 met, 0 NOT met
 * (the report says so: the patch's, the whole scene's or --patches' rule, every channel of matrix
 * walks, --view-gather's seen patches, or a zero answer that can never meet it), -1 no target or
 * none the run states (--at, --grid, --list, --direct, forward matrix walks).  The command exits 5
 * on 0, as ulam solve does. */
int ulam_rad_run_rel_err_met(const ulam_rad_run *r);

/* Free a run (NULL accepted). */
void ulam_rad_run_free(ulam_rad_run *r);

/* Metres a scene unit named m, cm, mm, in, ft or km; ULAM_OK or ULAM_ENOTFOUND. */
int ulam_rad_unit_metres(const char *name, double *metres);

#ifdef __cplusplus
}
#endif

#endif /* ULAM_RADIOSITY_RUN_H */
