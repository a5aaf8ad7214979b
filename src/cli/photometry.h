/* ulam radiosity's photometric options (--luminaire, --unit, --maintenance, --en12464): luminaires
 * from IES and EULUMDAT files placed in the scene, lux and cd/m2 in the answers, the EN 12464-1
 * work plane (src/cli/photometry.c). */
#ifndef ULAM_CLI_PHOTOMETRY_H
#define ULAM_CLI_PHOTOMETRY_H

#include "ulam_photometry.h"

#include <stdint.h>

/* What the photometric options asked, and what they made. */
typedef struct cli_photo {
    int active;              /* any photometric option given */
    const char **spec;       /* --luminaire FILE@x,y,z[,nx,ny,nz[,cx,cy,cz]] as given */
    int nlum;
    ulam_gonio **gonio;      /* read tables, one a luminaire */
    ulam_luminaire *lum;
    double metres;           /* --unit: metres a scene unit (1 unless given) */
    int unit_given;
    double maintenance;      /* --maintenance: multiplies every luminaire (1) */
    int en12464;             /* --en12464 C0:C1 given */
    double c0[3], c1[3];
    char en_desc[256];       /* its grid, described */
    double *H;               /* every patch's mean direct illuminance (lx) */
    double *ke;              /* the scene's own emission (3 a patch) */
    double onto;             /* luminous flux onto the surfaces (lm) */
    int q;                   /* the midpoint rule's q x q a fan triangle */
} cli_photo;

/* The usage lines of the photometric options. */
extern const char *const cli_photo_usage;

/* One photometric option (name without dashes: luminaire, unit, maintenance, en12464); 0 or an
 * exit code. */
int cli_photo_option(cli_photo *p, const char *cmd, const char *name, const char *arg);

/* After parsing: --en12464's grid into *g (and *grid set); 0 or an exit code. */
int cli_photo_finish(cli_photo *p, const char *cmd, int grid_given, ulam_rad_grid *g, int *grid);

/* Read the luminaires, light the scene s (tracer t on it): every patch's mean direct illuminance,
 * the reflected part rho H added to its emission (the scene's own kept), on `threads` threads (0:
 * all cores, --threads), within max_seconds (> 0; 0: no limit) and until Ctrl-C: stopped before the
 * last patch, nothing is printed (the light is not all there) and the exit says why; 0 or an exit
 * code. */
int cli_photo_light(cli_photo *p, const ulam_tracer *t, ulam_scene *s, const char *scene, int threads,
                    double max_seconds);

/* Point answers pts[0..n) (on the lit scene): add each point's direct illuminance
 * (exact) to its irradiance and interval and rho times it to its radiosity, and put the scene's
 * own emission back (what the points' intervals are printed with). */
void cli_photo_points(cli_photo *p, const ulam_tracer *t, ulam_scene *s, ulam_rad_point *pts, int64_t n);

/* Text lines (or, json, a "photometry": {...} key) for the points: illuminance (lx) and luminance
 * (cd/m2) of each, the EN 12464-1 statistics over the grid's ngrid points after nat --at points;
 * Y and its interval by the caller's functions. */
void cli_photo_report(const cli_photo *p, const ulam_scene *s, const ulam_rad_point *pts, int nat, int64_t ngrid,
                      int json, const double luma[3], void (*Y)(const ulam_rad_point *, double *, double *),
                      void (*Yci)(const ulam_rad_point *, double *, double *));

/* Text lines for a patch run (the luminaires, their flux; the patch's luminance B_Y / pi; what an
 * image written holds). */
void cli_photo_report_patch(const cli_photo *p, const double *B, const double luma[3], int image);

/* Photometric runs: *L (and *Lse when se is given) new arrays of B / pi and se / pi (3 * n: the
 * luminance in cd/m2 an image shows); otherwise, or out of memory, both NULL. */
void cli_photo_luminance(const cli_photo *p, const double *B, const double *se, int64_t n, double **L, double **Lse);

/* Free what p holds. */
void cli_photo_free(cli_photo *p);

#endif
