/* ulam radiosity's photometric options (--luminaire, --unit, --maintenance, --en12464) parsed into
 * the run's options; the run (libulam_radiosity's run_photo.c) lights the scene and reports. */
#include "photometry.h"

#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const cli_photo_usage =
    "Photometry (lux, lumens, candela):\n"
    "  --luminaire FILE@x,y,z[,nx,ny,nz[,cx,cy,cz]]  a luminaire from an IES LM-63 (.ies) or EULUMDAT\n"
    "                    (.ldt) file at x,y,z (scene units), its nadir (gamma = 0) along n\n"
    "                    (default 0,-1,0: +y is up), its C0 plane toward c (default +x or +z);\n"
    "                    repeat for more.  Direct light by shadow rays (exact), reflected light\n"
    "                    through the radiosity solution (each patch's mean direct illuminance x Kd\n"
    "                    becomes its emission: subdivide for a finer first bounce)\n"
    "  --unit U          the scene's unit: m (default), cm, mm, in, ft, or metres as a number;\n"
    "                    illuminance is then in lux (lm/m2), luminance in cd/m2, Ke read as\n"
    "                    luminous exitance in lm/m2\n"
    "  --maintenance F   multiply every luminaire by F in (0, 1] (the maintenance factor)\n"
    "  --en12464 x0,y0,z0:x1,y1,z1  the EN 12464-1 work-plane grid of that rectangle (the room at\n"
    "                    work-plane height): a 0.5 m wall band left out, spacing p = 0.2 x\n"
    "                    5^log10(d) m; prints E mean, E min, E max and U0 = E min / E mean with\n"
    "                    simultaneous 95% intervals (--out and --image as for --grid)\n";

/* --luminaire's numbers after the last '@' (3, 6 or 9) into l; 0 or -1. */
static int placement(const char *s, ulam_luminaire *l)
{
    double x[9];
    int n = !cli_parse_numbers(s, 9, x) ? 9 : !cli_parse_numbers(s, 6, x) ? 6 : !cli_parse_numbers(s, 3, x) ? 3 : 0;
    if (!n) return -1;
    *l = ulam_luminaire_defaults();
    for (int k = 0; k < 3; k++) {
        l->pos[k] = x[k];
        if (n >= 6) l->nadir[k] = x[3 + k];
    }
    if (n == 9) {
        for (int k = 0; k < 3; k++) l->c0[k] = x[6 + k];
    } else { /* +x, or +z when the nadir is along x */
        double nn = sqrt(l->nadir[0] * l->nadir[0] + l->nadir[1] * l->nadir[1] + l->nadir[2] * l->nadir[2]);
        if (!(nn > 0)) return -1;
        if (fabs(l->nadir[0]) > 0.9 * nn) l->c0[0] = 0.0, l->c0[2] = 1.0;
    }
    double c[3] = {l->nadir[1] * l->c0[2] - l->nadir[2] * l->c0[1], l->nadir[2] * l->c0[0] - l->nadir[0] * l->c0[2],
                   l->nadir[0] * l->c0[1] - l->nadir[1] * l->c0[0]};
    return c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 0 ? 0 : -1; /* a C0 axis across the nadir */
}

/* One photometric option; 0 or an exit code. */
int cli_photo_option(cli_photo *p, ulam_rad_run_opts *o, const char *cmd, const char *name, const char *arg)
{
    o->photo = 1;
    if (!o->metres) o->metres = 1.0, o->maintenance = 1.0;
    if (!strcmp(name, "luminaire")) {
        const char *at = strrchr(arg, '@');
        ulam_luminaire l;
        if (!at || at == arg || at - arg >= 4096 || placement(at + 1, &l))
            return cli_usage_error(cmd, "--luminaire expects FILE@x,y,z or FILE@x,y,z,nx,ny,nz or "
                                        "FILE@x,y,z,nx,ny,nz,cx,cy,cz (a path under 4 KiB, finite numbers, a nonzero "
                                        "nadir and a C0 axis across it), got '%.200s'",
                                   arg);
        if (p->nlum >= 10000) return cli_usage_error(cmd, "at most 10000 luminaires");
        const char **sp = realloc(p->spec, (size_t)(p->nlum + 1) * sizeof *sp);
        if (sp) p->spec = sp;
        ulam_luminaire *lm = sp ? realloc(p->lum, (size_t)(p->nlum + 1) * sizeof *lm) : NULL;
        if (lm) p->lum = lm;
        if (!sp || !lm) return cli_usage_error(cmd, "no memory for --luminaire %s", arg);
        p->spec[p->nlum] = arg, p->lum[p->nlum++] = l;
        return 0;
    }
    if (!strcmp(name, "unit")) {
        o->unit_given = 1;
        if (!ulam_rad_unit_metres(arg, &o->metres)) return 0;
        return cli_parse_real(cmd, "--unit (m, cm, mm, in, ft, km, or metres a unit)", arg, 1e-15, 1e15, &o->metres);
    }
    if (!strcmp(name, "maintenance")) return cli_parse_real(cmd, "--maintenance", arg, 1e-6, 1.0, &o->maintenance);
    /* en12464 */
    char buf[512];
    const char *colon = strchr(arg, ':');
    if (strlen(arg) >= sizeof buf || !colon || strchr(colon + 1, ':'))
        return cli_usage_error(cmd, "--en12464 expects x0,y0,z0:x1,y1,z1 (opposite corners of the room at work-plane "
                                    "height), got '%s'", arg);
    memcpy(buf, arg, (size_t)(colon - arg)), buf[colon - arg] = 0;
    if (cli_parse_numbers(buf, 3, p->c0) || cli_parse_numbers(colon + 1, 3, p->c1))
        return cli_usage_error(cmd, "--en12464 expects x0,y0,z0:x1,y1,z1 (finite numbers), got '%s'", arg);
    o->en12464 = 1;
    return 0;
}

/* --en12464's grid; 0 or an exit code. */
int cli_photo_finish(const cli_photo *p, ulam_rad_run_opts *o, const char *cmd)
{
    o->spec = p->spec, o->lum = p->lum, o->nlum = p->nlum;
    if (!o->en12464) return 0;
    if (o->grid) return cli_usage_error(cmd, "--en12464 makes its own grid: not with --grid");
    ulam_error err;
    if (ulam_rad_grid_en12464(p->c0, p->c1, o->metres, 0.5, &o->g, &err))
        return cli_usage_error(cmd, "--en12464: %s (scene unit %g m)", err.msg, o->metres);
    o->grid = 1;
    return 0;
}

/* Free what p holds. */
void cli_photo_free(cli_photo *p)
{
    free(p->spec), free(p->lum);
    memset(p, 0, sizeof *p);
}
