/* ulam radiosity's photometric options: luminaires from IES LM-63 and EULUMDAT files placed in the
 * scene, illuminance in lux and luminance in cd/m2, the EN 12464-1 work plane.  Thin over
 * ulam_photometry.h: the direct light of the luminaires is exact (point sources, shadow rays);
 * what the surfaces reflect of it is each patch's mean direct illuminance times its reflectance,
 * added to the patch's emission, solved by the radiosity machinery the command already runs. */
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
int cli_photo_option(cli_photo *p, const char *cmd, const char *name, const char *arg)
{
    p->active = 1;
    if (!p->metres) p->metres = 1.0, p->maintenance = 1.0;
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
        p->unit_given = 1;
        static const char *const names[] = {"m", "cm", "mm", "in", "ft", "km"};
        static const double metres[] = {1.0, 0.01, 0.001, 0.0254, 0.3048, 1000.0};
        for (int k = 0; k < 6; k++)
            if (!strcmp(arg, names[k])) return p->metres = metres[k], 0;
        return cli_parse_real(cmd, "--unit (m, cm, mm, in, ft, km, or metres a unit)", arg, 1e-15, 1e15, &p->metres);
    }
    if (!strcmp(name, "maintenance")) return cli_parse_real(cmd, "--maintenance", arg, 1e-6, 1.0, &p->maintenance);
    /* en12464 */
    char buf[512];
    const char *colon = strchr(arg, ':');
    if (strlen(arg) >= sizeof buf || !colon || strchr(colon + 1, ':'))
        return cli_usage_error(cmd, "--en12464 expects x0,y0,z0:x1,y1,z1 (opposite corners of the room at work-plane "
                                    "height), got '%s'", arg);
    memcpy(buf, arg, (size_t)(colon - arg)), buf[colon - arg] = 0;
    if (cli_parse_numbers(buf, 3, p->c0) || cli_parse_numbers(colon + 1, 3, p->c1))
        return cli_usage_error(cmd, "--en12464 expects x0,y0,z0:x1,y1,z1 (finite numbers), got '%s'", arg);
    p->en12464 = 1;
    return 0;
}

/* --en12464's grid; 0 or an exit code. */
int cli_photo_finish(cli_photo *p, const char *cmd, int grid_given, ulam_rad_grid *g, int *grid)
{
    if (!p->en12464) return 0;
    if (grid_given) return cli_usage_error(cmd, "--en12464 makes its own grid: not with --grid");
    ulam_error err;
    if (ulam_rad_grid_en12464(p->c0, p->c1, p->metres, 0.5, g, &err))
        return cli_usage_error(cmd, "--en12464: %s (scene unit %g m)", err.msg, p->metres);
    *grid = 1;
    double a = 0.0, b = 0.0;
    for (int k = 0; k < 3; k++) a += g->u[k] * g->u[k], b += g->v[k] * g->v[k];
    a = sqrt(a) * p->metres, b = sqrt(b) * p->metres;
    snprintf(p->en_desc, sizeof p->en_desc, "grid %d x %d at the cells' centres over %.4g x %.4g m (0.5 m wall band out; "
             "p = 0.2 x 5^log10(%.4g) = %.4g m)", g->nu, g->nv, a, b, fmax(a, b), ulam_en12464_spacing(fmax(a, b)));
    return 0;
}

/* Read the luminaires and light the scene; 0 or an exit code. */
int cli_photo_light(cli_photo *p, const ulam_tracer *t, ulam_scene *s, const char *scene, int threads,
                    double max_seconds)
{
    if (!p->active) return 0;
    ulam_error err;
    p->gonio = calloc((size_t)p->nlum + 1, sizeof *p->gonio);
    p->H = calloc((size_t)s->npatches + 1, sizeof *p->H);
    p->ke = malloc(((size_t)s->npatches * 3 + 1) * sizeof *p->ke);
    if (!p->gonio || !p->H || !p->ke) {
        err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for the luminaires"};
        return cli_report(scene, &err);
    }
    memcpy(p->ke, s->emit, (size_t)s->npatches * 3 * sizeof *p->ke);
    for (int k = 0; k < p->nlum; k++) {
        char path[4096];
        const char *at = strrchr(p->spec[k], '@');
        snprintf(path, sizeof path, "%.*s", (int)(at - p->spec[k]), p->spec[k]);
        if (ulam_gonio_read(path, &p->gonio[k], &err)) return cli_report(path, &err);
        p->lum[k].gonio = p->gonio[k], p->lum[k].scale = p->maintenance;
    }
    if (!p->nlum) return 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, size = 0.0;
    for (int64_t v = 0; v < s->nverts; v++)
        for (int c = 0; c < 3; c++) lo[c] = fmin(lo[c], s->vert[3 * v + c]), hi[c] = fmax(hi[c], s->vert[3 * v + c]);
    for (int c = 0; c < 3; c++) size = fmax(size, hi[c] - lo[c]);
    if (!p->unit_given && size > 200.0 && cli_rank == 0) /* lux need metres: a 200 m room is rare, a mm one common */
        fprintf(stderr, "ulam radiosity: warning: %s: the scene is %.4g units across, read as metres (lux from the "
                        "luminaires scale as 1 / unit^2): give --unit mm or cm if it is drawn in those\n", scene, size);
    double tri = 0.0; /* fan triangles: q^2 shadow rays each a luminaire, about 2 10^7 in all, q in 2 .. 8 */
    for (int64_t i = 0; i < s->npatches; i++) tri += (double)(s->start[i + 1] - s->start[i] - 2);
    p->q = (int)fmax(2.0, fmin(8.0, floor(sqrt(2e7 / fmax(1.0, tri * p->nlum)))));
    int64_t lit = 0;
    cli_catch_sigint(); /* a first bounce of 2 10^7 shadow rays ignored Ctrl-C and --time */
    int st = ulam_luminaire_patch_illuminance_stop(t, p->lum, p->nlum, p->metres, p->q, threads, &cli_interrupted,
                                                   max_seconds, p->H, &lit, &err);
    cli_release_sigint();
    if (st) return cli_report(scene, &err);
    if (lit < s->npatches) {
        fprintf(stderr, "ulam: %s: error: %s during the luminaires' direct light (%lld of %lld patches lit): "
                        "nothing to print%s\n", scene, cli_interrupted ? "interrupted" : "--time ran out",
                (long long)lit, (long long)s->npatches, cli_interrupted ? "" : " (raise --time)");
        return cli_interrupted ? EXIT_INTERRUPTED : cli_exit_code(ULAM_ENOCONV);
    }
    p->onto = 0.0;
    for (int64_t i = 0; i < s->npatches; i++) {
        p->onto += s->area[i] * p->metres * p->metres * p->H[i];
        for (int c = 0; c < 3; c++) s->emit[3 * i + c] += s->rho[3 * i + c] * p->H[i];
    }
    return 0;
}

/* Add the direct light to the points; the scene's own emission back. */
void cli_photo_points(cli_photo *p, const ulam_tracer *t, ulam_scene *s, ulam_rad_point *pts, int64_t n)
{
    if (!p->active) return;
    for (int64_t k = 0; p->nlum && k < n; k++) {
        ulam_rad_point *r = &pts[k];
        if (!r->run.walks) continue; /* not reached (interrupted) */
        double E = ulam_luminaire_illuminance(t, p->lum, p->nlum, p->metres, r->x, r->n, r->patch);
        for (int c = 0; c < 3; c++) {
            r->irradiance[c] += E, r->run.ci95[c][0] += E, r->run.ci95[c][1] += E;
            if (r->patch >= 0) r->radiosity[c] += s->rho[3 * r->patch + c] * (E - p->H[r->patch]);
        }
    }
    memcpy(s->emit, p->ke, (size_t)s->npatches * 3 * sizeof *p->ke);
}

/* The luminaires' lines. */
static void luminaires_text(const cli_photo *p)
{
    printf("photometry   scene unit %g m: illuminance in lx, luminance in cd/m2 (Y = 0.2126 R + 0.7152 G + 0.0722 B; "
           "Ke read as lm/m2)\n", p->metres);
    for (int k = 0; k < p->nlum; k++) {
        const ulam_luminaire *l = &p->lum[k];
        double rated = ulam_gonio_rated_flux(l->gonio);
        printf("luminaire %-3d %s: %.6g lm (its table x %g)", k + 1, p->spec[k], ulam_gonio_flux(l->gonio) * l->scale,
               l->scale);
        if (isfinite(rated)) printf(", lamps rated %.6g lm", rated);
        printf("\n");
    }
    if (p->nlum)
        printf("flux         %.6g lm onto the surfaces (direct; each patch's mean by a %d x %d midpoint rule a "
               "triangle, its Kd times that its emission)\n", p->onto, p->q, p->q);
}

/* The points' photometric lines or JSON. */
void cli_photo_report(const cli_photo *p, const ulam_scene *s, const ulam_rad_point *pts, int nat, int64_t ngrid,
                      int json, const double luma[3], void (*Y)(const ulam_rad_point *, double *, double *),
                      void (*Yci)(const ulam_rad_point *, double *, double *))
{
    if (!p->active) return;
    int64_t n = nat + ngrid;
    double *E = malloc(((size_t)ngrid + 1) * sizeof *E), *se = malloc(((size_t)ngrid + 1) * sizeof *se);
    ulam_uniformity u;
    int have_u = 0;
    if (E && se && ngrid && Y) {
        for (int64_t k = 0; k < ngrid; k++) Y(&pts[nat + k], &E[k], &se[k]);
        have_u = !ulam_uniformity_compute(E, se, ngrid, 0.95, &u);
    }
    if (json) {
        printf("\"photometry\": {");
        cli_json_number("metres_per_unit", p->metres, 0);
        printf("\"luminaires\": [");
        for (int k = 0; k < p->nlum; k++) {
            printf("%s{", k ? ", " : "");
            cli_json_string("spec", p->spec[k], 0);
            cli_json_number("flux_lm", ulam_gonio_flux(p->lum[k].gonio) * p->lum[k].scale, 0);
            cli_json_number("rated_lm", ulam_gonio_rated_flux(p->lum[k].gonio), 1);
            printf("}");
        }
        printf("], ");
        cli_json_number("flux_onto_surfaces_lm", p->nlum ? p->onto : 0.0, 0);
        printf("\"points\": [");
    } else {
        luminaires_text(p);
    }
    for (int64_t k = 0; k < n; k++) {
        if ((k >= nat && !json) || !pts) break;
        const ulam_rad_point *r = &pts[k];
        double y, ys, lo, hi, L = NAN, Llo = NAN, Lhi = NAN;
        Y(r, &y, &ys);
        Yci(r, &lo, &hi);
        if (r->patch >= 0) { /* L = B_Y / pi, B = E + rho H: its interval rho maps from H's */
            L = Llo = Lhi = 0.0;
            for (int c = 0; c < 3; c++) {
                double e = s->emit[3 * r->patch + c], rho = s->rho[3 * r->patch + c];
                L += luma[c] * r->radiosity[c] / M_PI;
                Llo += luma[c] * (e + rho * r->run.ci95[c][0]) / M_PI, Lhi += luma[c] * (e + rho * r->run.ci95[c][1]) / M_PI;
            }
        }
        if (json) {
            printf("%s{", k ? ", " : "");
            cli_json_number("illuminance_lx", y, 0);
            cli_json_number("illuminance_lx_stderr", ys, 0);
            cli_json_number("illuminance_lx_ci95_lo", lo, 0), cli_json_number("illuminance_lx_ci95_hi", hi, 0);
            cli_json_number("luminance_cd_m2", L, 0);
            cli_json_number("luminance_cd_m2_ci95_lo", Llo, 0), cli_json_number("luminance_cd_m2_ci95_hi", Lhi, 1);
            printf("}");
        } else {
            printf("point %-6lld E %.6g lx +- %.3g (95%% CI %.6g .. %.6g)", (long long)k + 1, y, ys, lo, hi);
            if (r->patch >= 0) printf(", L %.6g cd/m2 (95%% CI %.6g .. %.6g)", L, Llo, Lhi);
            printf("\n");
        }
    }
    if (json) {
        printf("]");
        if (have_u) {
            printf(", \"workplane\": {");
            cli_json_number("level", u.level, 0);
            cli_json_number("mean_lx", u.mean, 0), cli_json_number("mean_lx_lo", u.mean_lo, 0);
            cli_json_number("mean_lx_hi", u.mean_hi, 0);
            cli_json_number("min_lx", u.min, 0), cli_json_number("min_lx_lo", u.min_lo, 0);
            cli_json_number("min_lx_hi", u.min_hi, 0);
            cli_json_number("max_lx", u.max, 0), cli_json_number("max_lx_lo", u.max_lo, 0);
            cli_json_number("max_lx_hi", u.max_hi, 0);
            cli_json_number("u0", u.u0, 0), cli_json_number("u0_lo", u.u0_lo, 0), cli_json_number("u0_hi", u.u0_hi, 1);
            printf("}");
        }
        printf("}, ");
    } else if (have_u) {
        if (p->en12464) printf("EN 12464-1   %s\n", p->en_desc);
        printf("%-12s %lld points: E mean %.6g lx (%.6g .. %.6g), E min %.6g lx (%.6g .. %.6g), E max %.6g lx "
               "(%.6g .. %.6g)\n",
               p->en12464 ? "EN 12464-1" : "work plane", (long long)ngrid, u.mean, u.mean_lo, u.mean_hi, u.min,
               u.min_lo, u.min_hi, u.max, u.max_lo, u.max_hi);
        printf("             U0 = E min / E mean %.4f (%.4f .. %.4f); intervals hold together at 95%% (Bonferroni "
               "over the points)\n",
               u.u0, u.u0_lo, u.u0_hi);
    }
    free(E), free(se);
}

/* A patch run's photometric lines. */
void cli_photo_report_patch(const cli_photo *p, const double *B, const double luma[3], int image)
{
    if (!p->active) return;
    luminaires_text(p);
    if (B) printf("luminance    %.6g cd/m2 (B_Y / pi)\n", (luma[0] * B[0] + luma[1] * B[1] + luma[2] * B[2]) / M_PI);
    if (image) printf("image        linear values (PFM, HDR) in cd/m2: the luminance B / pi\n");
}

/* The luminance an image shows: B / pi (cd/m2 from lm/m2). */
void cli_photo_luminance(const cli_photo *p, const double *B, const double *se, int64_t n, double **L, double **Lse)
{
    *L = *Lse = NULL;
    if (!p->active || !B) return;
    *L = malloc(((size_t)n * 3 + 1) * sizeof **L);
    *Lse = se ? malloc(((size_t)n * 3 + 1) * sizeof **Lse) : NULL;
    if (!*L || (se && !*Lse)) {
        free(*L), free(*Lse);
        *L = *Lse = NULL;
        return;
    }
    for (int64_t k = 0; k < 3 * n; k++) {
        (*L)[k] = B[k] / M_PI;
        if (se) (*Lse)[k] = se[k] / M_PI;
    }
}

/* Free what p holds. */
void cli_photo_free(cli_photo *p)
{
    for (int k = 0; p->gonio && k < p->nlum; k++) ulam_gonio_free(p->gonio[k]);
    free(p->gonio), free(p->spec), free(p->lum), free(p->H), free(p->ke);
    memset(p, 0, sizeof *p);
}
