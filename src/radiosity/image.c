/* Pictures of a solution: one ray per pixel from a pinhole camera, the hit patch's radiosity,
 * exposure and the sRGB curve, written as PNG with libpng. */
#include "rad.h"

#include <png.h>
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

/* The patch each pixel centre sees (-1: nothing). */
static void cast_pixels(const ulam_tracer *t, const ulam_camera *cam, int w, int h, int64_t *hit)
{
    double f[3] = {cam->dir[0], cam->dir[1], cam->dir[2]}, up[3] = {cam->up[0], cam->up[1], cam->up[2]}, right[3];
    normalise(f);
    ulam__cross3(f, up, right);
    normalise(right);
    ulam__cross3(right, f, up);
    double pitch = cam->film / (double)w;
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double sx = ((double)x + 0.5 - 0.5 * w) * pitch, sy = (0.5 * h - (double)y - 0.5) * pitch, d[3];
            for (int k = 0; k < 3; k++) d[k] = cam->focal * f[k] + sx * right[k] + sy * up[k];
            normalise(d);
            int front = 0;
            int64_t p = ulam_tracer_cast(t, cam->eye, d, &front);
            hit[(size_t)y * (size_t)w + (size_t)x] = front ? p : -1;
        }
}

/* Render B as 8-bit sRGB. */
int ulam_render(const ulam_tracer *t, const double *B, const ulam_camera *cam, int width, int height,
                double exposure, unsigned char *rgb, double *used)
{
    if (!t || !B || !cam || !rgb || width < 1 || height < 1 || !(cam->focal > 0) || !(cam->film > 0))
        return ULAM_EINVAL;
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
    if (!(exposure > 0)) { /* 1 / the 99th percentile over pixels of patches that do not emit */
        size_t m = 0;
        for (size_t k = 0; k < np; k++)
            if (hit[k] >= 0 && ulam__max3(s->emit + 3 * hit[k]) == 0) lum[m++] = ulam__max3(B + 3 * hit[k]);
        qsort(lum, m, sizeof *lum, cmp_double);
        double top = m ? lum[(size_t)(0.99 * (double)(m - 1))] : 0.0;
        exposure = top > 0 && isfinite(top) ? 1.0 / top : 1.0;
    }
    for (size_t k = 0; k < np; k++)
        for (int c = 0; c < 3; c++) rgb[3 * k + c] = hit[k] >= 0 ? srgb_byte(exposure * B[3 * hit[k] + c]) : 0;
    if (used) *used = exposure;
    free(hit), free(lum);
    return ULAM_OK;
}

/* Write the PNG stream to f; 0 or ULAM_EIO (libpng reports by longjmp). */
static int png_stream(FILE *f, int width, int height, const unsigned char *rgb)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        return ULAM_ENOMEM;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return ULAM_EIO;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < height; y++) png_write_row(png, rgb + (size_t)y * (size_t)width * 3);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return ULAM_OK;
}

/* Write an RGB image as PNG, atomically. */
int ulam_png_write(const char *path, int width, int height, const unsigned char *rgb)
{
    if (!path || !rgb || width < 1 || height < 1) return ULAM_EINVAL;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    if ((status = png_stream(o.f, width, height, rgb))) {
        ulam_outfile_abort(&o);
        return status;
    }
    return ulam_outfile_commit(&o);
}
