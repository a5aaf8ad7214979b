/* The radiosity run's private parts, shared by its engine (run.c), reports (run_report.c),
 * pictures (run_image.c), photometry (run_photo.c) and its log, errors and clock (run_log.c). */
#ifndef ULAM_RAD_RUN_H
#define ULAM_RAD_RUN_H

#include "ulam_radiosity_run.h"
#include "ulam_report.h"

/* The run's options by the CLI's name for them. */
typedef ulam_rad_run_opts args;

/* What the walks found. */
typedef struct {
    double B[3], se[3], se_walk[3]; /* se: with --matrix-walk, the walk's and F's noise combined */
    int64_t walks, steps, cut; /* cut: walks stopped at --max-steps */
    int64_t channel_walks[3]; /* --matrix-walk: each channel's walks (walks is their sum) */
    int ff_limited[3];        /* --matrix-walk --rel-err: F's error alone is past the target */
    double seconds;
    int threads, interrupted;
    int zero;    /* --rel-err could never be met: every channel exactly 0, zero variance */
    int rel_err_met;  /* ray walks: the run stopped because the --rel-err rule holds */
    double min_walks; /* ray walks: the walks the rule needs at this estimate */
    double ci95[3][2]; /* ray walks: each channel's 95% interval (NaN: none certified) */
    double *all, *all_se; /* shooting: 3 per patch each */
    int whole;                 /* shooting --rel-err without --patch: the whole scene's rule */
    ulam_rad_scene_rule scene; /* its state at the end */
    int64_t unreached[8];      /* the first patches no particle reached */
    double *half;              /* --mode final: every patch's 95% half-width (3 each) */
    double half_rel[2];        /* --mode final: half-width / B (worst channel), median and 90% over the
                                  lit chosen patches (NaN: none lit) */
} walked;

/* Every patch's values for --out and --all (NULL arrays: not known): the answer (the walks' if
 * they covered every patch, else the direct one) with its standard error, and the direct
 * answer beside walks. */
typedef struct {
    const double *B, *se, *Bd, *sed;
    const double *mesh; /* --mesh-error: every patch's mesh error (3 each), or NULL */
    const double *half; /* --mode final: every patch's 95% half-width (3 each), or NULL */
    const unsigned char *want; /* --patches: the rows to write (NULL: every patch) */
} patch_values;

/* What the run found, as text or JSON. */
typedef struct {
    const ulam_scene *s;
    int64_t patch, faces;
    const ulam_csr *F;
    ulam_ff_report ff;
    double ff_seconds, direct_seconds, exposure;
    int image_written, out_written;
    patch_values pv;
    const double *Bdirect;
    double direct_se[3]; /* at the patch, from the noise of F (--check, --matrix-walk) */
    int ff_se_known;     /* direct_se was computed (--matrix-walk: unless --max-mem refused it) */
    double *direct_se_all; /* every patch's (--out, --all), NULL when not computed */
    const double *w_all_se_conditional; /* matrix forward walks whose se lack F's noise, or NULL */
    const walked *w;
    ulam_view_info view; /* --view-gather */
    int mesh_known;      /* mesh holds the patch's mesh error (ray gathering at --patch) */
    int mesh_no_time;    /* the mesh error was not estimated: the walks spent --time */
    ulam_rad_mesh mesh;
    int adapted, view_importance; /* --mesh-target: adapt holds what it did (by the view's importance) */
    ulam_rad_adapt_info adapt;
    int64_t adapt_cap; /* the most patches it could make (--max-patches, or what --max-mem holds) */
    int diag_known;    /* the answer is exactly 0 and diag says why (scene_notes) */
    ulam_rad_scene_diag diag;
} report;

/* The photometric state: the options, the read tables, every patch's direct light. */
typedef struct {
    int active;
    const char *const *spec;
    int nlum;
    ulam_gonio **gonio;      /* read tables, one a luminaire */
    ulam_luminaire *lum;     /* the caller's, with their tables and scale */
    double metres, maintenance;
    int unit_given, en12464;
    double *H;               /* every patch's mean direct illuminance (lx) */
    double *ke;              /* the scene's own emission (3 a patch) */
    double onto;             /* luminous flux onto the surfaces (lm) */
    int q;                   /* the midpoint rule's q x q a fan triangle */
} photo;

/* Point queries (--at, --grid). */
typedef struct {
    ulam_rad_point *pts;
    int64_t ngrid, n;
    int interrupted, known; /* known: diag says why a point reads exactly 0 */
    double seconds, hi;     /* hi: the grid picture's top */
    ulam_rad_scene_diag diag;
} points;

struct ulam_rad_run {
    args opts;
    const args *a;
    ulam_scene *s;
    ulam_tracer *t;
    ulam_csr *F;
    double *Bd, *mesh_all, *L, *Lse;
    walked w;
    report r;
    points q;
    photo ph;
    int listed, pointed; /* --list: the mesh only; --at or --grid: points */
    unsigned char *want; /* --patches: a flag a patch (NULL: every patch) */
    int64_t nwant;       /* the patches chosen */
};

/* The rays scene_diagnosis casts from the fronts (and as many from the backs). */
enum { ULAM__RAD_DIAG_RAYS = 4096 };

/* The seconds left of budget counted from a->started (budget itself when not > 0). */
double ulam__run_time_left(const args *a, double budget);

/* Write a warning or error line to a->log (printf's format; nothing without a log). */
void ulam__run_log(const args *a, const char *fmt, ...);

/* Write "ulam: FILE[:LINE]: error: what[: expected msg]" for err to a->log; err->status. */
int ulam__run_error(const args *a, const char *file, const ulam_error *err);

/* The radiosity options of a's walk options. */
ulam_rad_opts ulam__run_rad_opts(const ulam_walk_opts *o);

/* Nonzero when every channel of v is exactly 0 with a zero standard error se. */
int ulam__run_zero(const double v[3], const double se[3]);

/* The camera asked for, or the one framing the scene. */
ulam_camera ulam__run_camera(const args *a, const ulam_scene *s);

/* Photometry (run_photo.c): read the luminaires and light the scene; add their direct light to
 * points; the luminance B / pi an image shows; the reports' photometric lines; free. */
int ulam__run_photo_light(ulam_rad_run *r);
void ulam__run_photo_points(ulam_rad_run *r);
void ulam__run_photo_luminance(ulam_rad_run *r, const double *B, const double *se);
void ulam__run_photo_report(FILE *f, const ulam_rad_run *r, int json);
void ulam__run_photo_report_patch(FILE *f, const ulam_rad_run *r, const double *B);
void ulam__run_photo_free(photo *p);

/* --out's CSV rows (run_report.c). */
void ulam__run_write_csv(ulam_rad_run *run, FILE *f);

#endif
