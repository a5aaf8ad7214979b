/* Pictures of a solution: one ray per pixel from a pinhole camera, the hit patch's radiosity,
 * exposure and the sRGB curve, written as PNG with libpng. */
#include "rad.h"
#include "../dynload.h"

#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

/* The Cornell box camera. */
ulam_camera ulam_camera_cornell(void)
{
    return (ulam_camera){.eye = {278, 273, -800}, .dir = {0, 0, 1}, .up = {0, 1, 0}, .focal = 35, .film = 25};
}

/* The sRGB transfer curve of a linear value in [0, 1], as a byte. */
static unsigned char srgb_byte(double v)
{
    v = v > 0 ? (v < 1 ? v : 1) : 0;
    double e = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (unsigned char)lround(255.0 * e);
}

/* Order of two doubles for qsort. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Unit vector of v in place; 0 if v is zero. */
static int normalise(double v[3])
{
    double l = sqrt(ulam__dot3(v, v));
    if (!(l > 0)) return 0;
    for (int k = 0; k < 3; k++) v[k] /= l;
    return 1;
}

/* A camera's orthonormal frame and film pitch for a width-pixel image. */
typedef struct {
    double f[3], up[3], right[3], focal, pitch;
    int w, h;
} film;

/* The frame of cam for a w x h image. */
static film film_make(const ulam_camera *cam, int w, int h)
{
    film m = {{cam->dir[0], cam->dir[1], cam->dir[2]}, {cam->up[0], cam->up[1], cam->up[2]}, {0, 0, 0},
              cam->focal, cam->film / (double)w, w, h};
    normalise(m.f);
    ulam__cross3(m.f, m.up, m.right);
    normalise(m.right);
    ulam__cross3(m.right, m.f, m.up);
    return m;
}

/* Unit direction through pixel (x, y) at offset (jx, jy) in [0,1)^2 from its top-left corner. */
static void film_ray(const film *m, int x, double jx, int y, double jy, double d[3])
{
    double sx = ((double)x + jx - 0.5 * m->w) * m->pitch, sy = (0.5 * m->h - (double)y - jy) * m->pitch;
    for (int k = 0; k < 3; k++) d[k] = m->focal * m->f[k] + sx * m->right[k] + sy * m->up[k];
    normalise(d);
}

/* The patch each pixel centre sees (-1: nothing); back sides are seen through. */
static void cast_pixels(const ulam_tracer *t, const ulam_camera *cam, int w, int h, int64_t *hit)
{
    film m = film_make(cam, w, h);
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double d[3];
            film_ray(&m, x, 0.5, y, 0.5, d);
            hit[(size_t)y * (size_t)w + (size_t)x] = ulam__tracer_cast_front(t, cam->eye, d);
        }
}

/* ULAM_OK, or ULAM_ERANGE for a camera whose eye Embree cannot start rays at (more than
 * ULAM__TRACER_REACH scene sizes from the scene, where floats abort its ray checks). */
int ulam__camera_check(const ulam_tracer *t, const ulam_camera *cam)
{
    return ulam__tracer_reaches(t, cam->eye) ? ULAM_OK : ULAM_ERANGE;
}

/* How many pixel centres see each patch's front. */
int ulam_view_pixels(const ulam_tracer *t, const ulam_camera *cam, int width, int height, int64_t *pixels)
{
    if (!t || !cam || !pixels || width < 1 || height < 1 || !(cam->focal > 0) || !(cam->film > 0)) return ULAM_EINVAL;
    if (ulam__camera_check(t, cam)) return ULAM_ERANGE;
    size_t np = (size_t)width * (size_t)height;
    if (np > SIZE_MAX / 8 / 3) return ULAM_EOVERFLOW;
    int64_t *hit = ulam__malloc(np, sizeof *hit);
    if (!hit) return ULAM_ENOMEM;
    cast_pixels(t, cam, width, height, hit);
    memset(pixels, 0, (size_t)ulam__tracer_scene(t)->npatches * sizeof *pixels);
    for (size_t k = 0; k < np; k++)
        if (hit[k] >= 0) pixels[hit[k]]++;
    free(hit);
    return ULAM_OK;
}

/* A camera that frames the scene's bounding box: looking along +z at its centre from the -z
 * side, up +y, with the Cornell lens (35 mm, 25 mm film), just far enough (3% margin) that the
 * box's near face fills the wider of the two directions of a width x height picture; the
 * deeper parts of the box then appear smaller and are in view too. */
ulam_camera ulam_camera_frame(const ulam_scene *s, int width, int height)
{
    ulam_camera cam = ulam_camera_cornell();
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int64_t v = 0; s && v < s->nverts; v++)
        for (int d = 0; d < 3; d++) lo[d] = fmin(lo[d], s->vert[3 * v + d]), hi[d] = fmax(hi[d], s->vert[3 * v + d]);
    if (!s || !s->nverts || width < 1 || height < 1) return cam;
    double tx = 0.5 * cam.film / cam.focal, ty = tx * (double)height / (double)width, e[3];
    ulam__sub3(hi, lo, e);
    double d = 1.03 * fmax(0.5 * e[0] / tx, 0.5 * e[1] / ty);
    d = fmax(d, 1e-3 * sqrt(ulam__dot3(e, e)) + 1e-300); /* a scene flat in x and y */
    cam.eye[0] = 0.5 * (lo[0] + hi[0]), cam.eye[1] = 0.5 * (lo[1] + hi[1]), cam.eye[2] = lo[2] - d;
    return cam;
}

/* Render B as 8-bit sRGB. */
int ulam_render(const ulam_tracer *t, const double *B, const ulam_camera *cam, int width, int height,
                double exposure, unsigned char *rgb, ulam_render_info *info)
{
    if (info) *info = (ulam_render_info){0};
    if (!t || !B || !cam || !rgb || width < 1 || height < 1 || !(cam->focal > 0) || !(cam->film > 0))
        return ULAM_EINVAL;
    if (ulam__camera_check(t, cam)) return ULAM_ERANGE;
    const ulam_scene *s = ulam__tracer_scene(t);
    for (int64_t k = 0; k < 3 * s->npatches; k++)
        if (!isfinite(B[k])) return ULAM_ENONFINITE; /* no picture of a failed solve */
    size_t np = (size_t)width * (size_t)height;
    if (np > SIZE_MAX / 8 / 3) return ULAM_EOVERFLOW;
    int64_t *hit = ulam__malloc(np, sizeof *hit);
    double *lum = ulam__malloc(np, sizeof *lum);
    if (!hit || !lum) {
        free(hit), free(lum);
        return ULAM_ENOMEM;
    }
    cast_pixels(t, cam, width, height, hit);
    ulam_render_info in = {.exposure = exposure, .exposure_set = exposure > 0};
    for (int all = 0; all < 2 && !(in.exposure > 0); all++) { /* 1 / the 99th percentile over pixels
                                                                * of patches that do not emit, else all */
        size_t m = 0;
        for (size_t k = 0; k < np; k++)
            if (hit[k] >= 0 && (all || ulam__max3(s->emit + 3 * hit[k]) == 0)) lum[m++] = ulam__max3(B + 3 * hit[k]);
        qsort(lum, m, sizeof *lum, cmp_double);
        double top = m ? lum[(size_t)(0.99 * (double)(m - 1))] : 0.0;
        if (top > 0 && isfinite(top)) in.exposure = 1.0 / top, in.exposure_set = 1;
    }
    if (!(in.exposure > 0)) in.exposure = 1.0;
    for (size_t k = 0; k < np; k++) {
        in.pixels_hit += hit[k] >= 0;
        in.pixels_emitter += hit[k] >= 0 && ulam__max3(s->emit + 3 * hit[k]) > 0;
    }
    for (size_t k = 0; k < np; k++)
        for (int c = 0; c < 3; c++) rgb[3 * k + c] = hit[k] >= 0 ? srgb_byte(in.exposure * B[3 * hit[k] + c]) : 0;
    if (info) *info = in;
    free(hit), free(lum);
    return ULAM_OK;
}

/* A patch corner: its place in vidx, vertex and face, to group the corners that share a vertex
 * on one face of the OBJ file. */
typedef struct {
    int64_t i, v, face;
} corner;

/* Order corners by vertex, then face. */
static int cmp_corner(const void *a, const void *b)
{
    const corner *x = a, *y = b;
    if (x->v != y->v) return (x->v > y->v) - (x->v < y->v);
    return (x->face > y->face) - (x->face < y->face);
}

/* Radiosity at every patch corner (3 per vidx entry): the area-weighted mean of B over the
 * patches of the same OBJ face sharing that vertex (a face's subdivision is smoothed, a crease
 * between faces is kept); NULL when out of memory. */
static double *corner_values(const ulam_scene *s, const double *B)
{
    int64_t n = s->start[s->npatches];
    corner *c = ulam__malloc((size_t)n, sizeof *c);
    double *val = ulam__malloc((size_t)n, 3 * sizeof *val);
    int64_t *owner = ulam__malloc((size_t)n, sizeof *owner);
    if (!c || !val || !owner) {
        free(c), free(val), free(owner);
        return NULL;
    }
    for (int64_t p = 0; p < s->npatches; p++)
        for (int64_t i = s->start[p]; i < s->start[p + 1]; i++) owner[i] = p;
    for (int64_t i = 0; i < n; i++) c[i] = (corner){i, s->vidx[i], s->face[owner[i]]};
    qsort(c, (size_t)n, sizeof *c, cmp_corner);
    for (int64_t a = 0, b; a < n; a = b) {
        double sum[3] = {0, 0, 0}, A = 0;
        for (b = a; b < n && c[b].v == c[a].v && c[b].face == c[a].face; b++) {
            int64_t p = owner[c[b].i];
            A += s->area[p];
            for (int k = 0; k < 3; k++) sum[k] += s->area[p] * B[3 * p + k];
        }
        for (int64_t j = a; j < b; j++)
            for (int k = 0; k < 3; k++) val[3 * c[j].i + k] = A > 0 ? sum[k] / A : 0.0;
    }
    free(c), free(owner);
    return val;
}

/* Render B with jittered rays and, if smooth, radiosity interpolated from the patch corners. */
int ulam_render_hdr(const ulam_tracer *t, const double *B, const ulam_camera *cam, int width, int height, int samples,
                    int smooth, uint64_t seed, double exposure, float *hdr, unsigned char *rgb, ulam_render_info *info)
{
    if (info) *info = (ulam_render_info){0};
    if (!t || !B || !cam || !hdr || width < 1 || height < 1 || samples < 1 || !(cam->focal > 0) || !(cam->film > 0))
        return ULAM_EINVAL;
    if (ulam__camera_check(t, cam)) return ULAM_ERANGE;
    const ulam_scene *s = ulam__tracer_scene(t);
    for (int64_t k = 0; k < 3 * s->npatches; k++)
        if (!isfinite(B[k])) return ULAM_ENONFINITE;
    size_t np = (size_t)width * (size_t)height;
    if (np > SIZE_MAX / 8 / 3) return ULAM_EOVERFLOW;
    double *cv = smooth ? corner_values(s, B) : NULL, *lum = ulam__malloc(np, sizeof *lum);
    unsigned char *lit = ulam__malloc(np, 2); /* per pixel: any sample hit a patch, and an emitter */
    if ((smooth && !cv) || !lum || !lit) {
        free(cv), free(lum), free(lit);
        return ULAM_ENOMEM;
    }
    film fm = film_make(cam, width, height);
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            size_t k = (size_t)y * (size_t)width + (size_t)x;
            ulam_rng r;
            ulam_rng_seed(&r, seed, (uint64_t)k);
            double acc[3] = {0, 0, 0};
            lit[2 * k] = lit[2 * k + 1] = 0;
            for (int m = 0; m < samples; m++) {
                double jx = samples > 1 ? ulam__rng_uniform(&r) : 0.5, jy = samples > 1 ? ulam__rng_uniform(&r) : 0.5;
                double d[3];
                film_ray(&fm, x, jx, y, jy, d);
                int64_t tri = 0;
                double u = 0, v = 0;
                int64_t p = ulam__tracer_cast_front_uv(t, cam->eye, d, &tri, &u, &v);
                if (p < 0) continue;
                lit[2 * k] = 1, lit[2 * k + 1] |= ulam__max3(s->emit + 3 * p) > 0;
                for (int c = 0; c < 3; c++) {
                    double val = B[3 * p + c];
                    if (cv) {
                        int64_t i0 = s->start[p], i1 = i0 + tri, i2 = i1 + 1;
                        val = (1 - u - v) * cv[3 * i0 + c] + u * cv[3 * i1 + c] + v * cv[3 * i2 + c];
                    }
                    acc[c] += val;
                }
            }
            for (int c = 0; c < 3; c++) hdr[3 * k + c] = (float)(acc[c] / samples);
        }
    ulam_render_info in = {.exposure = exposure, .exposure_set = exposure > 0};
    for (int all = 0; all < 2 && !(in.exposure > 0); all++) { /* as ulam_render: 1 / the 99th percentile */
        size_t m = 0;
        for (size_t k = 0; k < np; k++)
            if (lit[2 * k] && (all || !lit[2 * k + 1]))
                lum[m++] = fmax(hdr[3 * k], fmax(hdr[3 * k + 1], hdr[3 * k + 2]));
        qsort(lum, m, sizeof *lum, cmp_double);
        double top = m ? lum[(size_t)(0.99 * (double)(m - 1))] : 0.0;
        if (top > 0 && isfinite(top)) in.exposure = 1.0 / top, in.exposure_set = 1;
    }
    if (!(in.exposure > 0)) in.exposure = 1.0;
    for (size_t k = 0; k < np; k++) {
        in.pixels_hit += lit[2 * k], in.pixels_emitter += lit[2 * k + 1];
        for (int c = 0; rgb && c < 3; c++) rgb[3 * k + c] = srgb_byte(in.exposure * hdr[3 * k + c]);
    }
    if (info) *info = in;
    free(cv), free(lum), free(lit);
    return ULAM_OK;
}

/* Write a float RGB image as PFM (little-endian, rows bottom first), atomically. */
int ulam_pfm_write(const char *path, int width, int height, const float *rgb)
{
    if (!path || !rgb || width < 1 || height < 1) return ULAM_EINVAL;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    int ok = fprintf(o.f, "PF\n%d %d\n-1.0\n", width, height) > 0;
    for (int y = height - 1; ok && y >= 0; y--) /* floats are little-endian on every platform ulam builds on */
        ok = fwrite(rgb + (size_t)y * (size_t)width * 3, sizeof(float), (size_t)width * 3, o.f) == (size_t)width * 3;
    if (!ok) {
        ulam_outfile_abort(&o);
        return ULAM_EIO;
    }
    return ulam_outfile_commit(&o);
}

/* The Radiance RGBE bytes of linear RGB c: a shared exponent e with the largest channel's
 * mantissa in [0.5, 1) scaled to 256; all zero below 1e-32 (and for a negative or NaN value). */
static void rgbe(const float *c, unsigned char out[4])
{
    double v = fmax(c[0], fmax(c[1], c[2]));
    if (!(v >= 1e-32) || !isfinite(v)) {
        out[0] = out[1] = out[2] = out[3] = 0;
        return;
    }
    int e;
    double f = frexp(v, &e) * 256.0 / v;
    for (int k = 0; k < 3; k++) out[k] = (unsigned char)(c[k] > 0 ? c[k] * f : 0.0);
    out[3] = (unsigned char)(e + 128 < 0 ? 0 : e + 128 > 255 ? 255 : e + 128);
}

/* Write a float RGB image as a Radiance .hdr file (flat RGBE scanlines, top first), atomically. */
int ulam_hdr_write(const char *path, int width, int height, const float *rgb)
{
    if (!path || !rgb || width < 1 || height < 1) return ULAM_EINVAL;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    int ok = fprintf(o.f, "#?RADIANCE\n# ulam radiosity\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n", height, width) > 0;
    for (size_t i = 0; ok && i < (size_t)width * (size_t)height; i++) {
        unsigned char b[4];
        rgbe(rgb + 3 * i, b);
        ok = fwrite(b, 1, 4, o.f) == 4;
    }
    if (!ok) {
        ulam_outfile_abort(&o);
        return ULAM_EIO;
    }
    return ulam_outfile_commit(&o);
}

/* Write the PNG stream to f with libpng's functions P; 0 or ULAM_EIO (libpng reports by longjmp). */
static int png_stream(const ulam__png_api *P, FILE *f, int width, int height, const unsigned char *rgb)
{
    png_structp png = P->create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? P->create_info_struct(png) : NULL;
    if (!info) {
        P->destroy_write_struct(&png, NULL);
        return ULAM_ENOMEM;
    }
    if (setjmp(*P->set_longjmp_fn(png, longjmp, sizeof(jmp_buf)))) { /* png_jmpbuf(png) */
        P->destroy_write_struct(&png, &info);
        return ULAM_EIO;
    }
    P->init_io(png, f);
    P->set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    P->set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    P->write_info(png, info);
    for (int y = 0; y < height; y++) P->write_row(png, rgb + (size_t)y * (size_t)width * 3);
    P->write_end(png, NULL);
    P->destroy_write_struct(&png, &info);
    return ULAM_OK;
}

/* Write an RGB image as PNG, atomically. */
int ulam_png_write(const char *path, int width, int height, const unsigned char *rgb)
{
    if (!path || !rgb || width < 1 || height < 1) return ULAM_EINVAL;
    const ulam__png_api *P = ulam__png(NULL); /* src/dynload.c: opened on first use */
    if (!P) return ULAM_EIO;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    if ((status = png_stream(P, o.f, width, height, rgb))) {
        ulam_outfile_abort(&o);
        return status;
    }
    return ulam_outfile_commit(&o);
}
