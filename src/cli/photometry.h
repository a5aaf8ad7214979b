/* ulam radiosity's photometric options (--luminaire, --unit, --maintenance, --en12464) parsed into
 * a run's options (src/cli/photometry.c; the run lights and reports: ulam_radiosity_run.h). */
#ifndef ULAM_CLI_PHOTOMETRY_H
#define ULAM_CLI_PHOTOMETRY_H

#include "ulam_radiosity_run.h"

/* The luminaires as given (the run's options point into them) and --en12464's corners. */
typedef struct cli_photo {
    const char **spec; /* --luminaire FILE@x,y,z[,nx,ny,nz[,cx,cy,cz]] as given */
    ulam_luminaire *lum;
    int nlum;
    double c0[3], c1[3];
} cli_photo;

/* The usage lines of the photometric options. */
extern const char *const cli_photo_usage;

/* One photometric option (name without dashes: luminaire, unit, maintenance, en12464) into p and
 * o; 0 or an exit code. */
int cli_photo_option(cli_photo *p, ulam_rad_run_opts *o, const char *cmd, const char *name, const char *arg);

/* After parsing: the luminaires into o, --en12464's grid into o->g; 0 or an exit code. */
int cli_photo_finish(const cli_photo *p, ulam_rad_run_opts *o, const char *cmd);

/* Free what p holds. */
void cli_photo_free(cli_photo *p);

#endif
