/* A radiosity run's pictures (ulam_radiosity_run.h): the rendered solution (PNG, PFM and Radiance
 * .hdr) with its warnings, and a sensor grid's false-colour picture. */
#include "runstate.h"

#include "rad.h"

#include <stdlib.h>

/* Hold or release the caller's signals around a file the library writes. */
static void hold(const args *a, int on)
{
    if (a->hold_signals) a->hold_signals(on);
}

/* --grid --image: the false-colour picture of the illuminance, 0 to the largest; ULAM_OK or a status (written). */
static int write_grid_png(const args *a, const char *path, const ulam_rad_grid *g, const ulam_rad_point *pts, double *hi)
{
    size_t n = (size_t)g->nu * (size_t)g->nv;
    double *Y = malloc(n * sizeof *Y), se;
    /* cells in the grid's proportions, the longer side of the picture 480 pixels */
    double lu = sqrt(g->u[0] * g->u[0] + g->u[1] * g->u[1] + g->u[2] * g->u[2]) / g->nu;
    double lv = sqrt(g->v[0] * g->v[0] + g->v[1] * g->v[1] + g->v[2] * g->v[2]) / g->nv;
    double scale = 480.0 / fmax(lu * g->nu, lv * g->nv);
    int cw = (int)fmax(2.0, round(lu * scale)), ch = (int)fmax(2.0, round(lv * scale)), w, h;
    int status = Y ? ULAM_OK : ULAM_ENOMEM;
    *hi = 0.0;
    for (size_t k = 0; Y && k < n; k++) {
        ulam_rad_illuminance(&pts[k], &Y[k], &se);
        *hi = fmax(*hi, Y[k]);
    }
    if (!(*hi > 0)) *hi = 1.0;
    ulam_falsecolour_size(g->nu, g->nv, cw, ch, &w, &h);
    unsigned char *rgb = Y ? malloc((size_t)w * (size_t)h * 3) : NULL;
    if (!status) status = rgb ? ulam_falsecolour(Y, g->nu, g->nv, cw, ch, 0.0, *hi, rgb) : ULAM_ENOMEM;
    if (!status) {
        hold(a, 1); /* its temporary file is the library's: a signal waits until it is gone */
        status = ulam_png_write(path, w, h, rgb);
        hold(a, 0);
    }
    free(Y), free(rgb);
    if (!status) return ULAM_OK;
    ulam_error err = {.status = status, .msg = "a writable PNG file"};
    return ulam__run_error(a, path, &err);
}

/* Warn when the picture's patches are noisy: the pixel-weighted mean, over the pixels that see a
 * patch, of its largest relative standard error over the lit channels, above 5%. */
static void noise_warning(const args *a, const ulam_tracer *t, const ulam_scene *s, const ulam_camera *cam,
                          const double *B, const double *se)
{
    int64_t *pix = malloc((size_t)s->npatches * sizeof *pix), seen = 0;
    if (!pix || ulam_view_pixels(t, cam, a->width, a->height, pix)) {
        free(pix);
        return;
    }
    double sum = 0.0, n = 0.0;
    for (int64_t p = 0; p < s->npatches; p++) {
        if (!pix[p]) continue;
        double rel = 0.0;
        for (int c = 0; c < 3; c++)
            if (B[3 * p + c] > 0) rel = fmax(rel, se[3 * p + c] / B[3 * p + c]);
        sum += (double)pix[p] * rel, n += (double)pix[p], seen++;
    }
    free(pix);
    if (n > 0 && sum / n > 0.05 && a->rank == 0)
        ulam__run_log(a, "ulam radiosity: warning: %s: the %lld patches in view carry %.0f%% relative error (pixel-weighted "
                        "mean): the picture will be salt-and-pepper noise; more --walks (the error falls as "
                        "1/sqrt(walks)), or --view-gather --rel-err\n", a->image, (long long)seen, 100.0 * sum / n);
}

/* Render B into a->image, warning when the picture cannot show the light; ULAM_OK or a status (written). */
static int write_image(const args *a, const ulam_tracer *t, const ulam_scene *s, const double *B, const double *se,
                       double *used)
{
    size_t np = (size_t)a->width * (size_t)a->height;
    unsigned char *rgb = malloc(np * 3);
    float *hdr = malloc(np * 3 * sizeof *hdr);
    ulam_camera cam = ulam__run_camera(a, s);
    ulam_render_info info;
    int status = rgb && hdr ? ulam_render_hdr(t, B, &cam, a->width, a->height, a->samples, !a->flat, a->o.exec.seed,
                                              a->exposure, hdr, rgb, &info)
                            : ULAM_ENOMEM;
    if (!status) { /* its temporary file is the library's: a signal waits until it is gone */
        hold(a, 1);
        status = ulam_png_write(a->image, a->width, a->height, rgb);
        hold(a, 0);
    }
    static const char *const what[] = {"a writable PFM file", "a writable Radiance .hdr file"};
    for (int k = 0; k < 2 && !status; k++) { /* the PFM and the Radiance .hdr beside the PNG */
        if (!(k ? a->hdr : a->pfm)) continue;
        hold(a, 1);
        status = k ? ulam_hdr_write(a->hdr, a->width, a->height, hdr) : ulam_pfm_write(a->pfm, a->width, a->height, hdr);
        hold(a, 0);
        if (status) {
            free(rgb), free(hdr);
            ulam_error err = {.status = status};
            snprintf(err.msg, sizeof err.msg, "%s", what[k]);
            return ulam__run_error(a, k ? a->hdr : a->pfm, &err);
        }
    }
    free(rgb), free(hdr);
    if (status == ULAM_ERANGE) {
        ulam_error err = {.status = status, .msg = "--camera: an eye within a million scene sizes of the scene"};
        return ulam__run_error(a, a->image, &err);
    }
    if (status) {
        ulam_error err = {.status = status, .msg = "a writable PNG file"};
        return ulam__run_error(a, a->image, &err);
    }
    *used = info.exposure;
    if (se) noise_warning(a, t, s, &cam, B, se);
    if (!info.pixels_hit)
        ulam__run_log(a, "ulam radiosity: warning: %s: the camera sees no patch's front (try --camera)\n", a->image);
    else if (!info.pixels_emitter)
        ulam__run_log(a, "ulam radiosity: warning: %s: no emitter is in view of the camera\n", a->image);
    if (info.pixels_hit && !info.exposure_set)
        ulam__run_log(a, "ulam radiosity: warning: %s: nothing lit is in view, so the exposure cannot be set "
                        "(1 used; give --exposure or --camera)\n", a->image);
    return 0;
}

/* One of the run's files (ulam_radiosity_run.h): the CSV rows, or the pictures. */
int ulam_rad_run_write(ulam_rad_run *r, int what, FILE *f)
{
    const args *a = r->a;
    if (what == ULAM_RAD_RUN_CSV) return f ? (ulam__run_write_csv(r, f), ULAM_OK) : ULAM_EINVAL;
    if (r->pointed) return write_grid_png(a, a->image, &a->g, r->q.pts + a->nat, &r->q.hi);
    const double *B = r->w.all ? r->w.all : r->Bd, *se = r->w.all ? r->w.all_se : NULL;
    ulam__run_photo_luminance(r, B, se); /* photometric: the picture's luminance B / pi, cd/m2 */
    int st = write_image(a, r->t, r->s, r->L ? r->L : B, r->Lse ? r->Lse : se, &r->r.exposure);
    r->r.image_written = !st;
    return st;
}
