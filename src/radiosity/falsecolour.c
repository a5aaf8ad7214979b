/* False-colour pictures of a sensor grid: each cell a square coloured by its value on a
 * perceptually ordered ramp (blue, cyan, green, yellow, red) from lo to hi, with a scale bar on
 * the right labelled at lo, the middle and hi in a built-in 3 x 5 pixel font (no font library). */
#include "rad.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { BAR = 24, GAP = 8, TEXT = 64, FONT = 2 }; /* bar width, gaps, label column, font scale */

/* The 3 x 5 glyphs of "0123456789.-e+" (row-major, 3 bits a row, top row first). */
static const char glyph_chars[] = "0123456789.-e+";
static const unsigned char glyphs[14][5] = {
    {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1}, {7, 4, 7, 1, 7},
    {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7}, {0, 0, 0, 0, 2}, {0, 0, 7, 0, 0},
    {0, 7, 5, 6, 3}, {0, 2, 7, 2, 0}};

/* The ramp's colour at u in [0, 1]. */
static void ramp(double u, unsigned char rgb[3])
{
    static const double stop[5][3] = {{0.05, 0.1, 0.6}, {0.0, 0.7, 0.9}, {0.1, 0.8, 0.2}, {1.0, 0.9, 0.1}, {0.9, 0.1, 0.05}};
    u = u > 0 ? (u < 1 ? u : 1) : 0;
    double x = u * 4.0;
    int k = x >= 4.0 ? 3 : (int)x;
    double f = x - k;
    for (int c = 0; c < 3; c++) rgb[c] = (unsigned char)lround(255.0 * ((1 - f) * stop[k][c] + f * stop[k + 1][c]));
}

/* Write text at (x, y) (its top left) in black. */
static void text(unsigned char *img, int w, int h, int x, int y, const char *s)
{
    for (; *s; s++, x += 4 * FONT) {
        const char *g = strchr(glyph_chars, *s);
        if (!g || !*s) continue;
        for (int r = 0; r < 5 * FONT; r++)
            for (int c = 0; c < 3 * FONT; c++) {
                int px = x + c, py = y + r;
                if (px < 0 || py < 0 || px >= w || py >= h) continue;
                if (glyphs[g - glyph_chars][r / FONT] & (4 >> (c / FONT)))
                    memset(img + 3 * ((size_t)py * (size_t)w + (size_t)px), 0, 3);
            }
    }
}

/* The picture's size for a grid of nu x nv cells of cw x ch pixels. */
void ulam_falsecolour_size(int nu, int nv, int cw, int ch, int *width, int *height)
{
    *width = nu * cw + GAP + BAR + GAP + TEXT;
    *height = nv * ch > 5 * FONT * 8 ? nv * ch : 5 * FONT * 8;
}

/* Paint the grid v (nu x nv, v[j nu + i], j = 0 at the bottom; cells cw x ch pixels) and its
 * scale bar into rgb. */
int ulam_falsecolour(const double *v, int nu, int nv, int cw, int ch, double lo, double hi, unsigned char *rgb)
{
    if (!v || !rgb || nu < 1 || nv < 1 || cw < 1 || ch < 1 || !isfinite(lo) || !isfinite(hi) || !(hi > lo))
        return ULAM_EINVAL;
    int w, h;
    ulam_falsecolour_size(nu, nv, cw, ch, &w, &h);
    memset(rgb, 255, (size_t)w * (size_t)h * 3);
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            unsigned char c[3];
            double x = v[(size_t)j * (size_t)nu + (size_t)i];
            if (isfinite(x)) ramp((x - lo) / (hi - lo), c);
            else c[0] = c[1] = c[2] = 128; /* no value: grey */
            for (int y = (nv - 1 - j) * ch; y < (nv - j) * ch; y++)
                for (int k = i * cw; k < (i + 1) * cw; k++) memcpy(rgb + 3 * ((size_t)y * (size_t)w + (size_t)k), c, 3);
        }
    int x0 = nu * cw + GAP, top = 5 * FONT, bottom = h - 5 * FONT - 1;
    for (int y = top; y <= bottom; y++) {
        unsigned char c[3];
        ramp((double)(bottom - y) / (double)(bottom - top), c);
        for (int k = x0; k < x0 + BAR; k++) memcpy(rgb + 3 * ((size_t)y * (size_t)w + (size_t)k), c, 3);
    }
    for (int m = 0; m <= 2; m++) { /* labels at lo, the middle and hi */
        char buf[32];
        double val = lo + 0.5 * m * (hi - lo);
        snprintf(buf, sizeof buf, "%.3g", val);
        int y = bottom - (int)lround(0.5 * m * (bottom - top)) - 5 * FONT / 2;
        text(rgb, w, h, x0 + BAR + GAP, y, buf);
        for (int k = x0 + BAR; k < x0 + BAR + GAP / 2; k++) /* a tick */
            memset(rgb + 3 * ((size_t)(bottom - (int)lround(0.5 * m * (bottom - top))) * (size_t)w + (size_t)k), 0, 3);
    }
    return ULAM_OK;
}
