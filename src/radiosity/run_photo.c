/* A radiosity run's photometry (ulam_radiosity_run.h): luminaires from IES LM-63 and EULUMDAT
 * files placed in the scene, illuminance in lux and luminance in cd/m2, the EN 12464-1 work
 * plane.  The direct light of the luminaires is exact (point sources, shadow rays); what the
 * surfaces reflect of it is each patch's mean direct illuminance times its reflectance, added to
 * the patch's emission and solved by the run's radiosity machinery. */
#include "runstate.h"

#include "rad.h"

#include <stdlib.h>
#include <string.h>

/* Read the luminaires and light the scene; ULAM_OK, a status (written) or
 * ULAM_RAD_RUN_INTERRUPTED. */
int ulam__run_photo_light(ulam_rad_run *r)
{
    const args *a = r->a;
    photo *p = &r->ph;
    ulam_scene *s = r->s;
    if (!a->photo) return ULAM_OK;
    p->active = 1, p->spec = a->spec, p->nlum = a->nlum, p->metres = a->metres, p->maintenance = a->maintenance;
    p->unit_given = a->unit_given, p->en12464 = a->en12464;
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the luminaires"};
    p->gonio = calloc((size_t)p->nlum + 1, sizeof *p->gonio);
    p->lum = malloc(((size_t)p->nlum + 1) * sizeof *p->lum);
    p->H = calloc((size_t)s->npatches + 1, sizeof *p->H);
    p->ke = malloc(((size_t)s->npatches * 3 + 1) * sizeof *p->ke);
    if (!p->gonio || !p->lum || !p->H || !p->ke) return ulam__run_error(a, a->scene, &err);
    memcpy(p->ke, s->emit, (size_t)s->npatches * 3 * sizeof *p->ke);
    for (int k = 0; k < p->nlum; k++) {
        char path[4096];
        const char *at = strrchr(p->spec[k], '@');
        snprintf(path, sizeof path, "%.*s", (int)(at - p->spec[k]), p->spec[k]);
        if (ulam_gonio_read(path, &p->gonio[k], &err)) return ulam__run_error(a, path, &err);
        p->lum[k] = a->lum[k], p->lum[k].gonio = p->gonio[k], p->lum[k].scale = p->maintenance;
    }
    if (!p->nlum) return ULAM_OK;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, size = 0.0;
    for (int64_t v = 0; v < s->nverts; v++)
        for (int c = 0; c < 3; c++) lo[c] = fmin(lo[c], s->vert[3 * v + c]), hi[c] = fmax(hi[c], s->vert[3 * v + c]);
    for (int c = 0; c < 3; c++) size = fmax(size, hi[c] - lo[c]);
    if (!p->unit_given && size > 200.0 && a->rank == 0) /* lux need metres: a 200 m room is rare, a mm one common */
        ulam__run_log(a, "ulam radiosity: warning: %s: the scene is %.4g units across, read as metres (lux from the "
                         "luminaires scale as 1 / unit^2): give --unit mm or cm if it is drawn in those\n", a->scene, size);
    double tri = 0.0; /* fan triangles: q^2 shadow rays each a luminaire, about 2 10^7 in all, q in 2 .. 8 */
    for (int64_t i = 0; i < s->npatches; i++) tri += (double)(s->start[i + 1] - s->start[i] - 2);
    p->q = (int)fmax(2.0, fmin(8.0, floor(sqrt(2e7 / fmax(1.0, tri * p->nlum)))));
    int64_t lit = 0;
    if (a->catch_interrupt) a->catch_interrupt(1); /* a first bounce of 2 10^7 shadow rays ignored Ctrl-C and --time */
    int st = ulam_luminaire_patch_illuminance_stop(r->t, p->lum, p->nlum, p->metres, p->q, a->o.exec.threads,
                                                   a->o.stop.interrupt, ulam__run_time_left(a, a->o.stop.max_seconds),
                                                   p->H, &lit, &err);
    if (a->catch_interrupt) a->catch_interrupt(0);
    if (st) return ulam__run_error(a, a->scene, &err);
    if (lit < s->npatches) {
        int stopped = a->o.stop.interrupt && *a->o.stop.interrupt;
        ulam__run_log(a, "ulam: %s: error: %s during the luminaires' direct light (%lld of %lld patches lit): "
                         "nothing to print%s\n", a->scene, stopped ? "interrupted" : "--time ran out",
                      (long long)lit, (long long)s->npatches, stopped ? "" : " (raise --time)");
        return stopped ? ULAM_RAD_RUN_INTERRUPTED : ULAM_ENOCONV;
    }
    p->onto = 0.0;
    for (int64_t i = 0; i < s->npatches; i++) {
        p->onto += s->area[i] * p->metres * p->metres * p->H[i];
        for (int c = 0; c < 3; c++) s->emit[3 * i + c] += s->rho[3 * i + c] * p->H[i];
    }
    return ULAM_OK;
}

/* Add the direct light to the points; the scene's own emission back. */
void ulam__run_photo_points(ulam_rad_run *run)
{
    photo *p = &run->ph;
    ulam_scene *s = run->s;
    if (!p->active) return;
    for (int64_t k = 0; p->nlum && k < run->q.n; k++) {
        ulam_rad_point *r = &run->q.pts[k];
        if (!r->run.walks) continue; /* not reached (interrupted) */
        double E = ulam_luminaire_illuminance(run->t, p->lum, p->nlum, p->metres, r->x, r->n, r->patch);
        for (int c = 0; c < 3; c++) {
            r->irradiance[c] += E, r->run.ci95[c][0] += E, r->run.ci95[c][1] += E;
            if (r->patch >= 0) r->radiosity[c] += s->rho[3 * r->patch + c] * (E - p->H[r->patch]);
        }
    }
    memcpy(s->emit, p->ke, (size_t)s->npatches * 3 * sizeof *p->ke);
}

/* The luminaires' lines. */
static void luminaires_text(FILE *f, const photo *p)
{
    fprintf(f, "photometry   scene unit %g m: illuminance in lx, luminance in cd/m2 (Y = 0.2126 R + 0.7152 G + 0.0722 B; "
               "Ke read as lm/m2)\n", p->metres);
    for (int k = 0; k < p->nlum; k++) {
        const ulam_luminaire *l = &p->lum[k];
        double rated = ulam_gonio_rated_flux(l->gonio);
        fprintf(f, "luminaire %-3d %s: %.6g lm (its table x %g)", k + 1, p->spec[k], ulam_gonio_flux(l->gonio) * l->scale,
                l->scale);
        if (isfinite(rated)) fprintf(f, ", lamps rated %.6g lm", rated);
        fprintf(f, "\n");
    }
    if (p->nlum)
        fprintf(f, "flux         %.6g lm onto the surfaces (direct; each patch's mean by a %d x %d midpoint rule a "
                   "triangle, its Kd times that its emission)\n", p->onto, p->q, p->q);
}

/* The EN 12464-1 grid described. */
static void en_desc(FILE *f, const photo *p, const ulam_rad_grid *g)
{
    double a = 0.0, b = 0.0;
    for (int k = 0; k < 3; k++) a += g->u[k] * g->u[k], b += g->v[k] * g->v[k];
    a = sqrt(a) * p->metres, b = sqrt(b) * p->metres;
    fprintf(f, "EN 12464-1   grid %d x %d at the cells' centres over %.4g x %.4g m (0.5 m wall band out; p = 0.2 x "
               "5^log10(%.4g) = %.4g m)\n", g->nu, g->nv, a, b, fmax(a, b), ulam_en12464_spacing(fmax(a, b)));
}

/* The points' photometric lines or JSON (a patch run's JSON: the luminaires). */
void ulam__run_photo_report(FILE *f, const ulam_rad_run *r, int json)
{
    const photo *p = &r->ph;
    const ulam_scene *s = r->s;
    const ulam_rad_point *pts = r->pointed ? r->q.pts : NULL;
    int nat = r->pointed ? r->a->nat : 0;
    int64_t ngrid = r->pointed ? r->q.ngrid : 0;
    const double *luma = ulam_rad_luma();
    void (*Y)(const ulam_rad_point *, double *, double *) = r->pointed ? ulam_rad_illuminance : NULL;
    void (*Yci)(const ulam_rad_point *, double *, double *) = ulam_rad_illuminance_ci;
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
        fprintf(f, "\"photometry\": {");
        ulam_json_number(f, "metres_per_unit", p->metres, 0);
        fprintf(f, "\"luminaires\": [");
        for (int k = 0; k < p->nlum; k++) {
            fprintf(f, "%s{", k ? ", " : "");
            ulam_json_string(f, "spec", p->spec[k], 0);
            ulam_json_number(f, "flux_lm", ulam_gonio_flux(p->lum[k].gonio) * p->lum[k].scale, 0);
            ulam_json_number(f, "rated_lm", ulam_gonio_rated_flux(p->lum[k].gonio), 1);
            fprintf(f, "}");
        }
        fprintf(f, "], ");
        ulam_json_number(f, "flux_onto_surfaces_lm", p->nlum ? p->onto : 0.0, 0);
        fprintf(f, "\"points\": [");
    } else {
        luminaires_text(f, p);
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
            fprintf(f, "%s{", k ? ", " : "");
            ulam_json_number(f, "illuminance_lx", y, 0);
            ulam_json_number(f, "illuminance_lx_stderr", ys, 0);
            ulam_json_number(f, "illuminance_lx_ci95_lo", lo, 0), ulam_json_number(f, "illuminance_lx_ci95_hi", hi, 0);
            ulam_json_number(f, "luminance_cd_m2", L, 0);
            ulam_json_number(f, "luminance_cd_m2_ci95_lo", Llo, 0), ulam_json_number(f, "luminance_cd_m2_ci95_hi", Lhi, 1);
            fprintf(f, "}");
        } else {
            fprintf(f, "point %-6lld E %.6g lx +- %.3g (95%% CI %.6g .. %.6g)", (long long)k + 1, y, ys, lo, hi);
            if (r->patch >= 0) fprintf(f, ", L %.6g cd/m2 (95%% CI %.6g .. %.6g)", L, Llo, Lhi);
            fprintf(f, "\n");
        }
    }
    if (json) {
        fprintf(f, "]");
        if (have_u) {
            fprintf(f, ", \"workplane\": {");
            ulam_json_number(f, "level", u.level, 0);
            ulam_json_number(f, "mean_lx", u.mean, 0), ulam_json_number(f, "mean_lx_lo", u.mean_lo, 0);
            ulam_json_number(f, "mean_lx_hi", u.mean_hi, 0);
            ulam_json_number(f, "min_lx", u.min, 0), ulam_json_number(f, "min_lx_lo", u.min_lo, 0);
            ulam_json_number(f, "min_lx_hi", u.min_hi, 0);
            ulam_json_number(f, "max_lx", u.max, 0), ulam_json_number(f, "max_lx_lo", u.max_lo, 0);
            ulam_json_number(f, "max_lx_hi", u.max_hi, 0);
            ulam_json_number(f, "u0", u.u0, 0), ulam_json_number(f, "u0_lo", u.u0_lo, 0), ulam_json_number(f, "u0_hi", u.u0_hi, 1);
            fprintf(f, "}");
        }
        fprintf(f, "}, ");
    } else if (have_u) {
        if (p->en12464) en_desc(f, p, &r->a->g);
        fprintf(f, "%-12s %lld points: E mean %.6g lx (%.6g .. %.6g), E min %.6g lx (%.6g .. %.6g), E max %.6g lx "
               "(%.6g .. %.6g)\n",
               p->en12464 ? "EN 12464-1" : "work plane", (long long)ngrid, u.mean, u.mean_lo, u.mean_hi, u.min,
               u.min_lo, u.min_hi, u.max, u.max_lo, u.max_hi);
        fprintf(f, "             U0 = E min / E mean %.4f (%.4f .. %.4f); intervals hold together at 95%% (Bonferroni "
               "over the points)\n",
               u.u0, u.u0_lo, u.u0_hi);
    }
    free(E), free(se);
}

/* A patch run's photometric lines. */
void ulam__run_photo_report_patch(FILE *f, const ulam_rad_run *r, const double *B)
{
    const photo *p = &r->ph;
    const double *luma = ulam_rad_luma();
    int image = r->r.image_written;
    if (!p->active) return;
    luminaires_text(f, p);
    if (B) fprintf(f, "luminance    %.6g cd/m2 (B_Y / pi)\n", (luma[0] * B[0] + luma[1] * B[1] + luma[2] * B[2]) / M_PI);
    if (image) fprintf(f, "image        linear values (PFM, HDR) in cd/m2: the luminance B / pi\n");
}

/* The luminance an image shows: B / pi (cd/m2 from lm/m2) into r->L and r->Lse (se given);
 * otherwise, or out of memory, both NULL. */
void ulam__run_photo_luminance(ulam_rad_run *r, const double *B, const double *se)
{
    const photo *p = &r->ph;
    int64_t n = r->s->npatches;
    double **L = &r->L, **Lse = &r->Lse;
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
void ulam__run_photo_free(photo *p)
{
    for (int k = 0; p->gonio && k < p->nlum; k++) ulam_gonio_free(p->gonio[k]);
    free(p->gonio), free(p->lum), free(p->H), free(p->ke);
}
