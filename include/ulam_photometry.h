/* ulam_photometry.h: photometry for ulam's radiosity front end, as lighting engineers work:
 * luminaires from IES LM-63 (LM-63-2002 and its predecessors' layout) and EULUMDAT (.ldt) files
 * as one goniometric intensity table (type C: C planes, gamma from the nadir, candela),
 * luminaires placed in a scene, their direct illuminance in lux by shadow rays and their flux
 * onto the patches (the reflected part then goes through the radiosity machinery as emission),
 * the EN 12464-1 work-plane grid and the uniformity U0 = E_min / E_mean with an interval.
 * Built with the radiosity feature; ulam.h's conventions apply.
 *
 * The API by rank:
 *   primary: ulam_gonio_read, ulam_gonio_free, ulam_gonio_flux, ulam_luminaire_defaults,
 *     ulam_luminaire_illuminance, ulam_luminaire_patch_illuminance, ulam_rad_grid_en12464,
 *     ulam_uniformity_compute;
 *   secondary: ulam_gonio_intensity,
 *     ulam_gonio_rated_flux, ulam_gonio_size, ulam_luminaire_intensity, ulam_en12464_spacing. */
#ifndef ULAM_PHOTOMETRY_H
#define ULAM_PHOTOMETRY_H

#include "ulam_radiosity.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A goniometric intensity table (photometry type C): intensity I(C, gamma) in candela, C the
 * azimuth of the half-plane (degrees, counter-clockwise seen from above the luminaire, C = 0
 * along its C0 axis), gamma the angle from the nadir (0 straight down, 180 straight up);
 * the file's symmetry unfolded to the full circle of C, bilinear between the table's angles,
 * 0 outside its gamma range.  Opaque. */
typedef struct ulam_gonio ulam_gonio;

/* The most angles of either kind, and the most candela values, a table may have. */
#define ULAM_GONIO_MAX_ANGLES 3601
#define ULAM_GONIO_MAX_VALUES 2000000



/* Read either: EULUMDAT when the name ends in .ldt (any case), else IES. */
int ulam_gonio_read(const char *path, ulam_gonio **out, ulam_error *err);

/* Free; accepts and returns NULL. */
ulam_gonio *ulam_gonio_free(ulam_gonio *g);

/* I(C, gamma) in cd (degrees; C taken modulo 360, gamma clamped to [0, 180]). */
double ulam_gonio_intensity(const ulam_gonio *g, double c_deg, double gamma_deg);

/* The luminous flux of the table in lm: the integral of I over the sphere, exact for the
 * bilinear interpolation (trapezoid across C, the piecewise-linear integral of I sin gamma). */
double ulam_gonio_flux(const ulam_gonio *g);

/* The lamps' flux the file states in lm (IES: lamps times lumens a lamp; EULUMDAT: the first
 * lamp set's), NaN when it states none (IES absolute photometry, lumens -1). */
double ulam_gonio_rated_flux(const ulam_gonio *g);

/* The table's size after unfolding the symmetry: C planes (*nc) and gamma angles (*ng). */
void ulam_gonio_size(const ulam_gonio *g, int *nc, int *ng);

/* A luminaire placed in a scene (caller's struct; start from ulam_luminaire_defaults()). */
typedef struct ulam_luminaire {
    const ulam_gonio *gonio; /* its table (the caller's, outliving the luminaire) */
    double pos[3];           /* its photometric centre, scene units */
    double nadir[3];         /* the direction of gamma = 0 (nonzero; need not be unit) */
    double c0[3];            /* the C = 0 half-plane: its part perpendicular to nadir (nonzero) */
    double scale;            /* multiplies the intensities (maintenance factor, dimming) */
} ulam_luminaire;

/* At the origin, nadir (0, -1, 0) (the examples' scenes have +y up), C0 along +x, scale 1. */
ulam_luminaire ulam_luminaire_defaults(void);

/* The intensity in cd of l toward unit direction d (scene axes); NaN for a luminaire without a
 * table or with nadir and c0 parallel or zero. */
double ulam_luminaire_intensity(const ulam_luminaire *l, const double d[3]);

/* The direct illuminance in lux at x with unit normal n (on patch self, or -1) from the nl
 * luminaires l, the scene's unit being `metres` metres: sum over the luminaires that a shadow ray
 * from x reaches unblocked of I(toward x) cos / r^2 (r in metres; a point source, exact, no
 * noise).  NaN for bad arguments. */
double ulam_luminaire_illuminance(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, double metres,
                                  const double x[3], const double n[3], int64_t self);

/* Every patch's mean direct illuminance in lux (H: npatches), by the midpoint rule on a q x q
 * split of each fan triangle (q^2 equal sub-triangles, their centroids; q in 1..64), on `threads`
 * threads (0: all cores; the answer does not depend on them).  The luminous flux the patches
 * receive is sum_p A_p metres^2 H_p.  ULAM_EINVAL for bad arguments. */
int ulam_luminaire_patch_illuminance(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, double metres, int q,
                                     int threads, double *H, ulam_error *err);

/* The EN 12464-1 calculation grid of a work plane: the rectangle with opposite corners c0 and c1
 * (equal in exactly one coordinate, its plane; scene units) less a band of `band` metres along
 * its edges (the wall band, 0.5 m; 0: none), the grid spacing p = 0.2 * 5^log10(d) m (d the
 * longer side of what is left, in metres; p at most 10 m), ceil(side / p) cells on each side
 * (spacing at most p), the sensors at the cells' centres facing + the plane's axis.
 * ULAM_EINVAL when nothing is left inside the band or the grid passes ULAM_RAD_GRID_MAX. */
/* EN 12464-1's maximum grid spacing for a side of d metres: p = 0.2 x 5^log10(d) m, at most
 * 10 m (NaN unless d > 0). */
double ulam_en12464_spacing(double d);

int ulam_rad_grid_en12464(const double c0[3], const double c1[3], double metres, double band, ulam_rad_grid *g,
                          ulam_error *err);

/* A grid's illuminance statistics with simultaneous intervals (ulam_uniformity). */
typedef struct ulam_uniformity {
    int64_t n;
    double mean, min, max, u0;    /* E mean, E_min, E_max, U0 = E_min / E mean */
    double mean_lo, mean_hi;      /* the intervals, all holding together at `level` */
    double min_lo, min_hi, max_lo, max_hi, u0_lo, u0_hi;
    double level;
} ulam_uniformity;

/* From n estimates E[k] with standard errors se[k] (0: exact): the mean, min, max and U0, and
 * intervals that hold together with probability at least level: each point's E[k] -+ z se[k]
 * with z the normal quantile at 1 - (1 - level) / (2 n) (Bonferroni), whence the min's, the
 * max's and the mean's ends, and U0 in [min_lo / mean_hi, min_hi / mean_lo].  ULAM_EINVAL for
 * n < 1, a level outside (0, 1), or an estimate or error not finite or negative. */
int ulam_uniformity_compute(const double *E, const double *se, int64_t n, double level, ulam_uniformity *u);

#ifdef __cplusplus
}
#endif

#endif /* ULAM_PHOTOMETRY_H */
