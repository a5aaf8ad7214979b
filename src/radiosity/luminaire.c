/* Luminaires placed in a scene: a goniometric table (gonio.c) at a position with its nadir and
 * C0 axes, as a point source.  Its direct illuminance at a point is I(toward the point) cos / r^2
 * when a shadow ray reaches it unblocked (exact for a point source: no noise); a patch's mean
 * direct illuminance is the midpoint rule over a q x q split of its fan triangles.  The
 * reflected part is left to the radiosity machinery: a patch lit with mean illuminance H
 * reflects rho H, its emission in B = E + diag(rho) F B (the caller adds it). */
#include "photo.h"

#include <stdlib.h>
#include <string.h>

/* At the origin, nadir -y, C0 along +x, scale 1. */
ulam_luminaire ulam_luminaire_defaults(void)
{
    ulam_luminaire l;
    memset(&l, 0, sizeof l);
    l.nadir[1] = -1.0, l.c0[0] = 1.0, l.scale = 1.0;
    return l;
}

/* The luminaire's frame: z the unit nadir, x the unit C0 axis (perpendicular to z), y = (-z) x x
 * (C = 90: counter-clockwise from C0 seen from above); 0 or -1 when they do not make one. */
static int frame(const ulam_luminaire *l, double x[3], double y[3], double z[3])
{
    double nz = sqrt(ulam__dot3(l->nadir, l->nadir));
    if (!(nz > 0) || !isfinite(nz)) return -1;
    for (int k = 0; k < 3; k++) z[k] = l->nadir[k] / nz;
    double d = ulam__dot3(l->c0, z);
    for (int k = 0; k < 3; k++) x[k] = l->c0[k] - d * z[k];
    double nx = sqrt(ulam__dot3(x, x));
    if (!(nx > 1e-9 * sqrt(ulam__dot3(l->c0, l->c0))) || !isfinite(nx)) return -1;
    for (int k = 0; k < 3; k++) x[k] /= nx;
    double up[3] = {-z[0], -z[1], -z[2]};
    ulam__cross3(up, x, y);
    return 0;
}

/* I toward unit d in the frame (x, y, z). */
static double toward(const ulam_luminaire *l, const double x[3], const double y[3], const double z[3], const double d[3])
{
    double cz = fmax(-1.0, fmin(1.0, ulam__dot3(d, z)));
    double gamma = acos(cz) * 180.0 / M_PI, c = atan2(ulam__dot3(d, y), ulam__dot3(d, x)) * 180.0 / M_PI;
    return l->scale * ulam_gonio_intensity(l->gonio, c, gamma);
}

/* The intensity of l toward unit direction d, in cd. */
double ulam_luminaire_intensity(const ulam_luminaire *l, const double d[3])
{
    double x[3], y[3], z[3];
    if (!l || !l->gonio || !d || frame(l, x, y, z)) return NAN;
    return toward(l, x, y, z, d);
}

/* The direct illuminance at x (normal n, on patch self or -1) from luminaire l in frame (fx, fy,
 * fz), m metres a scene unit. */
static double one(const ulam_tracer *t, const ulam_luminaire *l, const double f[9], double m, const double x[3],
                  const double n[3], int64_t self)
{
    double d[3];
    ulam__sub3(l->pos, x, d);
    double r = sqrt(ulam__dot3(d, d));
    if (!(r > 0)) return 0.0;
    for (int k = 0; k < 3; k++) d[k] /= r;
    double cosx = ulam__dot3(d, n);
    if (!(cosx > 0)) return 0.0;
    /* a surface between blocks it; a hit within 1e-9 r of the start (a neighbour sharing the edge x
     * lies on) does not: the ray is cast again from just past it */
    double o[3] = {x[0], x[1], x[2]}, done = 0.0;
    for (int k = 0; k < 4; k++) {
        int front = 0;
        double dist = INFINITY;
        int64_t j = ulam__tracer_ray(t, o, d, k ? -1 : self, &front, &dist);
        if (j < 0 || done + dist >= r * (1.0 - 1e-9)) break;
        if (dist > 1e-9 * r) return 0.0;
        done += dist + 1e-9 * r;
        for (int i = 0; i < 3; i++) o[i] = x[i] + done * d[i];
    }
    double back[3] = {-d[0], -d[1], -d[2]};
    double I = toward(l, f, f + 3, f + 6, back);
    return I * cosx / (r * m * r * m);
}

/* The frames of the nl luminaires (9 each); ULAM_EINVAL unless every luminaire makes one. */
static int frames(const ulam_luminaire *l, int64_t nl, double *f)
{
    for (int64_t i = 0; i < nl; i++) {
        if (!l[i].gonio || frame(&l[i], f + 9 * i, f + 9 * i + 3, f + 9 * i + 6) || !(l[i].scale >= 0) ||
            !isfinite(l[i].scale))
            return ULAM_EINVAL;
        for (int k = 0; k < 3; k++)
            if (!isfinite(l[i].pos[k])) return ULAM_EINVAL;
    }
    return ULAM_OK;
}

/* The sum of the luminaires' direct illuminance at x, f their frames. */
static double sum(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, const double *f, double m,
                  const double x[3], const double n[3], int64_t self)
{
    double E = 0.0;
    for (int64_t i = 0; i < nl; i++) E += one(t, &l[i], f + 9 * i, m, x, n, self);
    return E;
}

/* The direct illuminance in lux at x. */
double ulam_luminaire_illuminance(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, double metres,
                                  const double x[3], const double n[3], int64_t self)
{
    if (!t || (!l && nl) || nl < 0 || nl > 1000000 || !x || !n || !(metres > 0) || !isfinite(metres)) return NAN;
    double small[9 * 8], *f = nl <= 8 ? small : ulam__malloc((size_t)nl * 9, sizeof *f);
    if (!f) return NAN;
    double E = frames(l, nl, f) ? NAN : sum(t, l, nl, f, metres, x, n, self);
    if (f != small) free(f);
    return E;
}

/* Every patch's mean direct illuminance in lux (the midpoint rule on q x q splits). */
int ulam_luminaire_patch_illuminance(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, double metres, int q,
                                     int threads, double *H, ulam_error *err)
{
    return ulam_luminaire_patch_illuminance_stop(t, l, nl, metres, q, threads, NULL, 0.0, H, NULL, err);
}

/* The same, stopping when *interrupt is set or max_seconds have passed. */
int ulam_luminaire_patch_illuminance_stop(const ulam_tracer *t, const ulam_luminaire *l, int64_t nl, double metres,
                                          int q, int threads, const volatile int *interrupt, double max_seconds,
                                          double *H, int64_t *lit, ulam_error *err)
{
    ulam__clear(err);
    if (lit) *lit = 0;
    if (!t || (!l && nl) || nl < 0 || nl > 1000000 || !H || !(metres > 0) || !isfinite(metres) || q < 1 || q > 64)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, luminaires, metres > 0, q in 1 .. 64 and an output");
    double *f = ulam__malloc((size_t)(nl ? nl : 1) * 9, sizeof *f);
    if (!f) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the luminaires' frames");
    if (frames(l, nl, f)) {
        free(f);
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "luminaires with a table, a finite position and scale, and "
                                                   "nadir and C0 axes that are not parallel");
    }
    const ulam_scene *s = ulam__tracer_scene(t);
    int nth = ulam__threads(threads), stop = 0;
    int64_t done = 0;
    double t0 = ulam_now();
#pragma omp parallel for schedule(dynamic, 16) num_threads(nth) reduction(+ : done)
    for (int64_t p = 0; p < s->npatches; p++) {
        int halt; /* a patch's q^2 nl shadow rays at most after the stop */
#pragma omp atomic read
        halt = stop;
        if (!halt && ((interrupt && *interrupt) || (max_seconds > 0 && ulam_now() - t0 >= max_seconds))) {
#pragma omp atomic write
            stop = 1;
            halt = 1;
        }
        if (halt) {
            H[p] = NAN;
            continue;
        }
        done++;
        const double *n = s->normal + 3 * p, *v0 = s->vert + 3 * s->vidx[s->start[p]];
        double acc = 0.0, area = 0.0;
        for (int64_t k = s->start[p] + 1; k + 1 < s->start[p + 1]; k++) {
            const double *v1 = s->vert + 3 * s->vidx[k], *v2 = s->vert + 3 * s->vidx[k + 1];
            double e1[3], e2[3], c[3];
            ulam__sub3(v1, v0, e1), ulam__sub3(v2, v0, e2), ulam__cross3(e1, e2, c);
            double a = 0.5 * sqrt(ulam__dot3(c, c)), tri = 0.0;
            for (int i = 0; i < q; i++) /* the q^2 sub-triangles' centroids: q(q+1)/2 up, q(q-1)/2 down */
                for (int j = 0; i + j < q; j++)
                    for (int down = 0; down < 2 && !(down && i + j > q - 2); down++) {
                        double u = (i + (down ? 2.0 : 1.0) / 3.0) / q, w = (j + (down ? 2.0 : 1.0) / 3.0) / q, x[3];
                        for (int m = 0; m < 3; m++) x[m] = v0[m] + u * e1[m] + w * e2[m];
                        tri += sum(t, l, nl, f, metres, x, n, p);
                    }
            acc += a * tri / ((double)q * q), area += a;
        }
        H[p] = area > 0 ? acc / area : 0.0;
    }
    free(f);
    if (lit) *lit = done;
    return ULAM_OK;
}
