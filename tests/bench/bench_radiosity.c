/* Benchmark: radiosity queries on the Cornell box, every route side by side in one run.
 *
 * 1. One patch (the floor's: the label's patch containing its area centroid) to 1% relative
 *    error on R, G and B at about 2,000, 10,000 and 40,000 patches: collision gathering and
 *    next-event gathering with MIS (power heuristic), against forming F by ray casting with
 *    1000 rays a patch and solving the three channels with LAPACK (measured where the dense
 *    matrix fits in 4 GB; beyond, extrapolated from the largest measured size: F's time in
 *    proportion to the patches, LAPACK's to their cube).
 * 2. Patches next to a light, a fixed number of walks for each estimator: the Cornell ceiling
 *    patch beside the light, and tests/data/rad/edge_lamp.obj (a wall sharing an edge with a
 *    lamp, exact answer 0.5 F(C-14)): the variance a walk, the largest score's share of the sum
 *    of squares, and (edge lamp) z against the exact answer.
 * 3. An image at about 40,000 patches (W x H, default 16x16): --view-gather at 1% on every
 *    seen patch (coverage 0), against shooting (a run of P particles, default 2,000,000,
 *    projected to the particles that bring every seen patch to 1%: P (worst rel. error / 1%)^2)
 *    and against the direct route (what it would need).
 * 4. (bench_radiosity points) A 10 x 10 sensor grid on the work plane (0.8 m) of an office of
 *    about 10^4 triangles (6 x 4 x 3 m, six ceiling panels, four desks; written by this program),
 *    every point to 2% (next-event point walks, 2 threads): seconds, walks, rays, worst point.
 * 5. (bench_radiosity points) A point query to 1% against a next-event patch query to 1% on the
 *    same scene (the patch holding the point): rays of each and their ratio (target <= 2), on the
 *    Cornell box floor centre (unsubdivided and at ~2,000 patches) and the office floor.
 * 6. (bench_radiosity hall) The hall of about 10^5 triangles (issue 40's whole-room case, written by
 *    this program): shooting for 60 s under the whole-scene rule, the floor's median error.
 *    6b (bench_radiosity hall-final [SECONDS [PILOT [floor [SAMPLES]]]]): final gathering over a
 *    shooting pilot (ulam_rad_final; with "floor", ulam_rad_final_some on the floor's patches
 *    only; with SAMPLES, that many a patch instead of --rel-err 0.05) for 60 s, the same floor
 *    figures and the printed interval's.
 *    2026-12-05, 2 threads of a shared 2-core machine at load 24.6 (each run got about 10 CPU
 *    seconds of its 60): shooting 2 592 923 particles, 4.60 M rays: floor 1.96 se / B median
 *    0.286, 3 719 floor patches at 0; final: pilot 361 845 particles (0.64 M rays, 15.7 s) and
 *    2 701 952 samples (5.40 M rays): floor 1.96 se / B median 0.121, but its printed 95%
 *    half-width / B median 6.80 (the pilot's part and the certified range at 64 samples a
 *    patch); 65 074 wall/ceiling patches not reached in time.  Goal (<= 0.05 in 60 s) not met.
 *    2026-12-05 after each patch's own clip of the pilot (final_cap), same machine, load 15-22:
 *    every patch, 60 s: 4.71 M samples (64 a patch), floor printed half-width / B median 0.985
 *    (was 19.3 in a run beside it: the certified range held the pilot's global maximum, 6.2 B at
 *    the floor's median), 1.96 se / B 0.095; the floor only (hall-final 60 0 floor), 60 s:
 *    pilot 378 155 particles (11.4 s), 9.39 M samples (235 a floor patch), printed half-width / B
 *    median 0.127 (10% 0.098, 90% 4.72: the patches beside the crates), 1.96 se / B 0.035;
 *    3 657 floor patches under the crates unreached (no light).  At 128 samples a floor patch
 *    (hall-final 600 0 floor 128): 0.218, 1.96 se / B 0.041.  The certified range (the light
 *    sample's bound ~1.1 B, the clip ~2.3 B) needs ~10^3 samples a patch for 0.05: 4 10^7
 *    samples, 8 10^7 rays, out of 60 s at this load (about 0.3 M rays a second).  Not met.
 * Usage: bench_radiosity [scene.obj [WxH [P]]] (run from the source root); bench_radiosity points;
 * bench_radiosity hall; bench_radiosity office|hall OUT.obj (write the scene and its .mtl). */
#include "ulam_radiosity.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The Cornell box subdivided to about target patches (bisection on the side length). */
static ulam_scene *subdivided(const ulam_scene *s, int64_t target)
{
    double lo = 1.0, hi = 600.0;
    ulam_scene *best = NULL;
    for (int it = 0; it < 30; it++) {
        double L = sqrt(lo * hi);
        ulam_scene *d = NULL;
        if (ulam_scene_subdivide(s, L, &d)) return NULL;
        int64_t n = d->npatches;
        if (!best || llabs(n - target) < llabs(best->npatches - target)) {
            ulam_scene_free(best);
            best = d;
        } else {
            ulam_scene_free(d);
        }
        if (llabs(n - target) * 50 < target) break; /* within 2% */
        if (n > target) lo = L;
        else hi = L;
    }
    return best;
}

/* Gather at patch p with estimator est until rel_err (or walks, when rel_err is 0). */
static ulam_rad_result gather(const ulam_tracer *t, int est, int64_t p, double rel_err, int64_t walks)
{
    ulam_rad_opts o = ulam_rad_defaults();
    o.index = p, o.estimator = est, o.stop.max_walks = walks, o.stop.rel_err = rel_err, o.exec.seed = 1;
    ulam_rad_solver *sv = NULL;
    ulam_rad_result r = {0};
    if (ulam_rad_solver_alloc(t, &o, &sv, NULL)) return r;
    while (!ulam_rad_solver_done(sv)) ulam_rad_solver_iterate(sv);
    ulam_rad_solver_result(sv, &r);
    ulam_rad_solver_free(sv);
    return r;
}

/* The largest relative standard error over the channels. */
static double worst_rel(const double *B, const double *se)
{
    double w = 0;
    for (int c = 0; c < 3; c++)
        if (B[c] != 0) w = fmax(w, se[c] / fabs(B[c]));
    return w;
}

/* The ceiling patch beside the light: nearest (by centroid) to the point just past the light's
 * largest-x edge, at the ceiling's height. */
static int64_t beside_light(const ulam_scene *s)
{
    double hi = -INFINITY, lc[3], cc[3];
    if (ulam_scene_label_centroid(s, "light", lc) || ulam_scene_label_centroid(s, "ceiling", cc)) return -1;
    for (int64_t p = 0; p < s->npatches; p++)
        if (s->group[p] >= 0 && !strcmp(s->groups[s->group[p]], "light"))
            for (int64_t k = s->start[p]; k < s->start[p + 1]; k++) hi = fmax(hi, s->vert[3 * s->vidx[k]]);
    int64_t best = -1;
    double bd = INFINITY;
    for (int64_t p = 0; p < s->npatches; p++) {
        if (s->group[p] < 0 || strcmp(s->groups[s->group[p]], "ceiling")) continue;
        double c[3];
        ulam_scene_centroid(s, p, c);
        double dx = c[0] - (hi + 0.5 * sqrt(s->area[p])), dz = c[2] - lc[2], d = dx * dx + dz * dz;
        if (d < bd) bd = d, best = p;
    }
    return best;
}

static const int ests[4] = {ULAM_RAD_COLLISION, ULAM_RAD_NEXT_EVENT, ULAM_RAD_NEXT_EVENT_BALANCE, ULAM_RAD_NEXT_EVENT_LIGHT};
static const char *const est_name[4] = {"collision", "next-event MIS power", "next-event MIS balance",
                                        "next-event light only"};

/* Part 2: the estimators at patch p, walks each; exact < 0 when unknown. */
static void near_light(const char *what, const ulam_tracer *t, int64_t p, int64_t walks, double exact)
{
    printf("\n%s (patch %lld), %lld walks each\n\n", what, (long long)p + 1, (long long)walks);
    printf("| estimator | R | stderr | variance a walk (R) | ratio to collision | largest share | rays | z vs exact |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    double v0 = 0;
    for (int k = 0; k < 4; k++) {
        ulam_rad_result r = gather(t, ests[k], p, 0, walks);
        double v = r.std_error[0] * r.std_error[0] * (double)r.walks;
        if (k == 0) v0 = v;
        printf("| %s | %.6g | %.3g | %.4g | %.3f | %.3g | %lld |", est_name[k], r.radiosity[0], r.std_error[0], v,
               v / v0, r.max_share, (long long)r.rays);
        if (exact >= 0) printf(" %+.2f |\n", (r.radiosity[0] - exact) / r.std_error[0]);
        else printf(" |\n");
        fflush(stdout);
    }
}

/* One rectangle p0 + a e1 + b e2 as cells no longer than h on a side, two triangles each, facing
 * e1 x e2; vertices counted from *nv. */
static void rect(FILE *f, const double p0[3], const double e1[3], const double e2[3], double h, long *nv)
{
    int m = (int)ceil(sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]) / h);
    int n = (int)ceil(sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]) / h);
    long base = *nv + 1;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= m; i++) {
            double a = (double)i / m, b = (double)j / n;
            fprintf(f, "v %.6f %.6f %.6f\n", p0[0] + a * e1[0] + b * e2[0], p0[1] + a * e1[1] + b * e2[1],
                    p0[2] + a * e1[2] + b * e2[2]);
        }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < m; i++) {
            long v = base + (long)j * (m + 1) + i, w = v + m + 1;
            fprintf(f, "f %ld %ld %ld\nf %ld %ld %ld\n", v, v + 1, w + 1, v, w + 1, w);
        }
    *nv += (long)(m + 1) * (n + 1);
}

/* An axis-aligned box [lo, hi] without its bottom, faces outward, as rect cells of h. */
static void box(FILE *f, const double lo[3], const double hi[3], double h, long *nv)
{
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    rect(f, (double[3]){lo[0], hi[1], lo[2]}, (double[3]){0, 0, dz}, (double[3]){dx, 0, 0}, h, nv); /* top, +y */
    rect(f, lo, (double[3]){0, 0, dz}, (double[3]){0, dy, 0}, h, nv);                            /* -x */
    rect(f, (double[3]){hi[0], lo[1], lo[2]}, (double[3]){0, dy, 0}, (double[3]){0, 0, dz}, h, nv); /* +x */
    rect(f, lo, (double[3]){0, dy, 0}, (double[3]){dx, 0, 0}, h, nv);                            /* -z */
    rect(f, (double[3]){lo[0], lo[1], hi[2]}, (double[3]){dx, 0, 0}, (double[3]){0, dy, 0}, h, nv); /* +z */
}

/* Open path (an OBJ) and the MTL beside it (path's extension replaced by .mtl), write mtl_text
 * into the MTL and the OBJ's header naming scene and the MTL; the OBJ, *m the MTL, or NULL with
 * neither left open. */
static FILE *open_scene(const char *path, const char *scene, const char *mtl_text, FILE **m)
{
    char mtl[4096];
    snprintf(mtl, sizeof mtl, "%s", path);
    char *dot = strrchr(mtl, '.');
    if (!dot || strlen(mtl) + 4 >= sizeof mtl) return NULL;
    strcpy(dot, ".mtl");
    FILE *f = fopen(path, "w");
    *m = f ? fopen(mtl, "w") : NULL;
    if (!*m) {
        if (f) fclose(f);
        return NULL;
    }
    fputs(mtl_text, *m);
    const char *base = strrchr(mtl, '/');
    fprintf(f, "# The %s of bench_radiosity (tests/bench/bench_radiosity.c)\nmtllib %s\n", scene, base ? base + 1 : mtl);
    return f;
}

/* Write the office: a 6 x 4 x 3 m room (y up; floor Kd 0.2, walls 0.5, ceiling 0.7), six
 * 0.6 x 0.6 m ceiling panels (Ke 20, Kd 0) 1 cm below it and four 1.4 x 0.7 m desks 0.72 m high
 * (Kd 0.4), in cells of 0.15 m: about 10^4 triangles.  0 or -1. */
static int write_office(const char *path)
{
    FILE *m = NULL, *f = open_scene(path, "office", "newmtl floor\nKd 0.2 0.2 0.2\nnewmtl wall\nKd 0.5 0.5 0.45\n"
                                    "newmtl ceiling\nKd 0.7 0.7 0.7\nnewmtl panel\nKd 0 0 0\nKe 20 20 18\n"
                                    "newmtl desk\nKd 0.4 0.3 0.2\n", &m);
    if (!f) return -1;
    const double W = 6, D = 4, H = 3, h = 0.15;
    long nv = 0;
    fprintf(f, "o floor\nusemtl floor\n");
    rect(f, (double[3]){0, 0, 0}, (double[3]){0, 0, D}, (double[3]){W, 0, 0}, h, &nv);
    fprintf(f, "o ceiling\nusemtl ceiling\n");
    rect(f, (double[3]){0, H, 0}, (double[3]){W, 0, 0}, (double[3]){0, 0, D}, h, &nv);
    fprintf(f, "o walls\nusemtl wall\n");
    rect(f, (double[3]){0, 0, 0}, (double[3]){0, H, 0}, (double[3]){0, 0, D}, h, &nv);
    rect(f, (double[3]){W, 0, 0}, (double[3]){0, 0, D}, (double[3]){0, H, 0}, h, &nv);
    rect(f, (double[3]){0, 0, 0}, (double[3]){W, 0, 0}, (double[3]){0, H, 0}, h, &nv);
    rect(f, (double[3]){0, 0, D}, (double[3]){0, H, 0}, (double[3]){W, 0, 0}, h, &nv);
    fprintf(f, "o panels\nusemtl panel\n");
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 2; k++)
            rect(f, (double[3]){1.2 + 1.8 * i, H - 0.01, 1.0 + 1.4 * k}, (double[3]){0.6, 0, 0}, (double[3]){0, 0, 0.6},
                 0.3, &nv);
    fprintf(f, "o desks\nusemtl desk\n");
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 2; k++)
            box(f, (double[3]){1.0 + 2.6 * i, 0, 0.8 + 1.7 * k}, (double[3]){2.4 + 2.6 * i, 0.72, 1.5 + 1.7 * k}, h, &nv);
    int bad = ferror(f) | ferror(m);
    bad |= fclose(f) | fclose(m);
    return bad ? -1 : 0;
}

/* Write the hall: a 30 x 15 x 6 m room (y up; floor Kd 0.3 in cells of 0.15 m, walls 0.5 and
 * ceiling 0.7 in cells of 0.2 m), 24 ceiling panels of 1 x 1 m (Ke 30, Kd 0) 1 cm below it, and
 * twelve 2 x 1 x 2 m crates (Kd 0.4, bottomless, 0.15 m cells) on the floor, the first over the
 * floor's first triangle (patch 1 under a box, as in issue 40's hall): about 10^5 triangles.  0
 * or -1. */
static int write_hall(const char *path)
{
    FILE *m = NULL, *f = open_scene(path, "hall", "newmtl floor\nKd 0.3 0.3 0.3\nnewmtl wall\nKd 0.5 0.5 0.5\n"
                                    "newmtl ceiling\nKd 0.7 0.7 0.7\nnewmtl panel\nKd 0 0 0\nKe 30 30 30\n"
                                    "newmtl crate\nKd 0.4 0.4 0.4\n", &m);
    if (!f) return -1;
    const double W = 30, D = 15, H = 6;
    long nv = 0;
    fprintf(f, "o floor\nusemtl floor\n");
    rect(f, (double[3]){0, 0, 0}, (double[3]){0, 0, D}, (double[3]){W, 0, 0}, 0.15, &nv);
    fprintf(f, "o ceiling\nusemtl ceiling\n");
    rect(f, (double[3]){0, H, 0}, (double[3]){W, 0, 0}, (double[3]){0, 0, D}, 0.2, &nv);
    fprintf(f, "o walls\nusemtl wall\n");
    rect(f, (double[3]){0, 0, 0}, (double[3]){0, H, 0}, (double[3]){0, 0, D}, 0.2, &nv);
    rect(f, (double[3]){W, 0, 0}, (double[3]){0, 0, D}, (double[3]){0, H, 0}, 0.2, &nv);
    rect(f, (double[3]){0, 0, 0}, (double[3]){W, 0, 0}, (double[3]){0, H, 0}, 0.2, &nv);
    rect(f, (double[3]){0, 0, D}, (double[3]){0, H, 0}, (double[3]){W, 0, 0}, 0.2, &nv);
    fprintf(f, "o panels\nusemtl panel\n");
    for (int i = 0; i < 6; i++)
        for (int k = 0; k < 4; k++)
            rect(f, (double[3]){2.0 + 5.0 * i, H - 0.01, 1.5 + 3.5 * k}, (double[3]){1, 0, 0}, (double[3]){0, 0, 1}, 0.5,
                 &nv);
    fprintf(f, "o crates\nusemtl crate\n");
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            double x = i == 0 && k == 0 ? 0.0 : 3.0 + 7.0 * i, z = i == 0 && k == 0 ? 0.0 : 2.0 + 4.5 * k;
            box(f, (double[3]){x, 0, z}, (double[3]){x + 2, 1, z + 2}, 0.15, &nv);
        }
    int bad = ferror(f) | ferror(m);
    bad |= fclose(f) | fclose(m);
    return bad ? -1 : 0;
}

/* The office's work-plane grid: 10 x 10 sensors at 0.8 m over x in [0.3, 5.7], z in [0.3, 3.7]. */
static ulam_rad_grid office_grid(void)
{
    return (ulam_rad_grid){.origin = {0.3, 0.8, 0.3}, .u = {5.4, 0, 0}, .v = {0, 0, 3.4}, .normal = {0, 1, 0},
                           .nu = 10, .nv = 10};
}

/* Part 5: a point query at x to 1% against the next-event patch query of the patch holding it. */
static void point_vs_patch(const char *what, const ulam_scene *s, const ulam_tracer *t, const double x[3])
{
    int64_t p = ulam_scene_locate(s, x, ULAM_RAD_LOCATE_REL);
    if (p < 0) return;
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = 0.01, o.stop.max_walks = 0, o.exec.seed = 1, o.exec.threads = 2;
    ulam_rad_point pt;
    if (ulam_rad_point_query(t, &o, x, NULL, &pt, NULL)) return;
    ulam_rad_result pa = gather(t, ULAM_RAD_NEXT_EVENT, p, 0.01, 0);
    printf("| %s | %lld | %.5g +- %.2g | %lld | %lld | %.4f | %.5g +- %.2g | %lld | %lld | %.4f | %.2f |\n", what,
           (long long)s->npatches, pt.radiosity[0], pt.radiosity_se[0], (long long)pt.run.walks,
           (long long)pt.run.rays, pt.run.seconds, pa.radiosity[0], pa.std_error[0], (long long)pa.walks,
           (long long)pa.rays, pa.seconds, (double)pt.run.rays / (double)pa.rays);
    fflush(stdout);
}

/* Parts 4 and 5. */
static int points_bench(void)
{
    const char *office = "build/bench_office.obj";
    ulam_scene *s = NULL, *c0 = NULL, *c1 = NULL;
    ulam_tracer *t = NULL, *tc0 = NULL, *tc1 = NULL;
    ulam_error err;
    if (write_office(office) || ulam_scene_read_obj(office, &s, &err) || ulam_tracer_alloc(s, &t, &err)) {
        fprintf(stderr, "%s: cannot write or read the office\n", office);
        return 1;
    }
    int64_t tri = s->start[s->npatches] - 2 * s->npatches;
    ulam_rad_grid g = office_grid();
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = 0.02, o.stop.max_walks = 0, o.exec.seed = 1, o.exec.threads = 2;
    ulam_rad_point *pts = malloc(100 * sizeof *pts);
    double t0 = ulam_now();
    if (!pts || ulam_rad_grid_solve(t, &o, &g, pts, &err)) return 1;
    double sec = ulam_now() - t0, worst = 0, lo = INFINITY, hi = 0;
    int64_t walks = 0, rays = 0, met = 0;
    for (int k = 0; k < 100; k++) {
        walks += pts[k].run.walks, rays += pts[k].run.rays, met += pts[k].run.rel_err_met;
        for (int c = 0; c < 3; c++)
            if (pts[k].irradiance[c] > 0) worst = fmax(worst, pts[k].irradiance_se[c] / pts[k].irradiance[c]);
        lo = fmin(lo, pts[k].irradiance[1]), hi = fmax(hi, pts[k].irradiance[1]);
    }
    printf("4. Office (%lld triangles, %lld patches), 10 x 10 work-plane grid at 0.8 m, every point to 2%%\n\n",
           (long long)tri, (long long)s->npatches);
    printf("| seconds (2 threads) | points met | walks | rays | worst relative error | H (G) min .. max |\n");
    printf("|---:|---:|---:|---:|---:|---:|\n");
    printf("| %.2f | %lld / 100 | %lld | %lld | %.4f | %.4g .. %.4g |\n\n", sec, (long long)met, (long long)walks,
           (long long)rays, worst, lo, hi);
    printf("5. A point query to 1%% against the next-event patch query (1%%) of the patch holding the point\n\n");
    printf("| scene | patches | point B (R) | walks | rays | s | patch B (R) | walks | rays | s | rays ratio |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    fflush(stdout);
    if (!ulam_scene_read_obj("examples/scenes/cornell_box.obj", &c0, &err) && !ulam_tracer_alloc(c0, &tc0, &err)) {
        double fc[3];
        ulam_scene_label_centroid(c0, "floor", fc);
        point_vs_patch("Cornell floor centre, no subdivision", c0, tc0, fc);
        if ((c1 = subdivided(c0, 2000)) && !ulam_tracer_alloc(c1, &tc1, &err))
            point_vs_patch("Cornell floor centre, ~2,000 patches", c1, tc1, fc);
    }
    point_vs_patch("office floor (3, 0, 2)", s, t, (double[3]){3.0 + 1e-3, 0, 2.0 + 1e-3});
    free(pts);
    ulam_tracer_free(t), ulam_tracer_free(tc0), ulam_tracer_free(tc1);
    ulam_scene_free(s), ulam_scene_free(c0), ulam_scene_free(c1);
    return 0;
}

/* Sort doubles ascending (qsort). */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Write the hall to build/ and read it with its tracer; 0 or 1. */
static int load_hall(ulam_scene **s, ulam_tracer **t)
{
    const char *hall = "build/bench_hall.obj";
    ulam_error err;
    if (!write_hall(hall) && !ulam_scene_read_obj(hall, s, &err) && !ulam_tracer_alloc(*s, t, &err)) return 0;
    fprintf(stderr, "%s: cannot write or read the hall\n", hall);
    return 1;
}

/* 6. The hall (write_hall, written to build/): shooting to --rel-err E = 0.05 / 1.96 on the whole
 * scene at share 0.5 for at most `seconds`; the floor patches' relative 95% half-widths (1.96 se /
 * B) at the end: the median, the tenth and ninetieth percentiles, the floor patches at 0, and the
 * whole-scene rule's counts. */
static int hall_bench(double seconds)
{
    ulam_scene *s = NULL;
    ulam_tracer *t = NULL;
    ulam_error err;
    if (load_hall(&s, &t)) return 1;
    ulam_rad_opts o = ulam_rad_defaults();
    o.mode = ULAM_FORWARD, o.estimator = ULAM_RAD_COLLISION, o.stop.rel_err = 0.05 / 1.96, o.stop.max_walks = 0;
    o.stop.max_seconds = seconds, o.exec.seed = 1, o.exec.threads = 2;
    ulam_rad_solver *sv = NULL;
    int64_t n = s->npatches, nf = 0, zero = 0;
    double *B = malloc(3 * (size_t)n * sizeof *B), *se = malloc(3 * (size_t)n * sizeof *se), *rel = malloc((size_t)n * sizeof *rel);
    if (!B || !se || !rel || ulam_rad_solver_alloc(t, &o, &sv, &err) || ulam_rad_solver_whole(sv, 0.5)) return 1;
    while (!ulam_rad_solver_done(sv))
        if (ulam_rad_solver_iterate(sv)) return 1;
    ulam_rad_result r;
    ulam_rad_scene_rule q;
    ulam_rad_solver_result(sv, &r);
    ulam_rad_solver_vectors(sv, B, se);
    ulam_rad_solver_scene(sv, &q, NULL, 0);
    for (int64_t p = 0; p < n; p++) {
        if (s->group[p] < 0 || strcmp(s->groups[s->group[p]], "floor")) continue;
        zero += B[3 * p + 1] == 0.0;
        rel[nf++] = B[3 * p + 1] > 0 ? 1.96 * se[3 * p + 1] / B[3 * p + 1] : INFINITY;
    }
    qsort(rel, (size_t)nf, sizeof *rel, cmp_double);
    printf("6. Hall (%lld patches, %lld on the floor), shooting to 1.96 se / B <= 5%% on half the lit area, at most "
           "%.0f s, 2 threads\n\n", (long long)n, (long long)nf, seconds);
    printf("   %lld particles, %lld rays, %.1f s (rule %s: %lld of %lld lit patches; %lld unreached)\n",
           (long long)r.walks, (long long)r.rays, r.seconds, r.rel_err_met ? "met" : "not met", (long long)q.met,
           (long long)q.lit, (long long)q.unreached);
    printf("   floor 1.96 se / B: median %.4f, 10%% %.4f, 90%% %.4f; %lld floor patches at 0\n\n", rel[nf / 2],
           rel[nf / 10], rel[9 * nf / 10], (long long)zero);
    free(B), free(se), free(rel);
    ulam_rad_solver_free(sv), ulam_tracer_free(t), ulam_scene_free(s);
    return 0;
}

/* 6b. The hall by final gathering over a shooting pilot (ulam_rad_final) to a 95% half-width <= 5% B on
 * every patch, at most `seconds`: the floor patches' relative 95% half-widths (the printed
 * interval's, and 1.96 se / B as 6 reads them) at the end. */
static int hall_final(double seconds, int64_t pilot, int floor_only, int64_t samples)
{
    ulam_scene *s = NULL;
    ulam_tracer *t = NULL;
    ulam_error err;
    if (load_hall(&s, &t)) return 1;
    ulam_rad_opts o = ulam_rad_defaults();
    o.stop.rel_err = samples > 0 ? 0.0 : 0.05, o.stop.max_walks = samples, o.stop.max_seconds = seconds, o.exec.seed = 1;
    o.exec.threads = 2;
    int64_t n = s->npatches, nf = 0, nan = 0;
    double *B = malloc(3 * (size_t)n * sizeof *B), *se = malloc(3 * (size_t)n * sizeof *se), *rel = malloc((size_t)n * sizeof *rel),
           *half = malloc(3 * (size_t)n * sizeof *half), *clt = malloc((size_t)n * sizeof *clt);
    unsigned char *want = floor_only ? malloc((size_t)n) : NULL;
    for (int64_t p = 0; p < n && want; p++) want[p] = s->group[p] >= 0 && !strcmp(s->groups[s->group[p]], "floor");
    ulam_rad_final_info in;
    if (!B || !se || !rel || !half || !clt || (floor_only && !want) ||
        ulam_rad_final_some(t, &o, pilot, 1.0, want, B, se, half, &in, &err))
        return 1;
    for (int64_t p = 0; p < n; p++) {
        if (s->group[p] < 0 || strcmp(s->groups[s->group[p]], "floor")) continue;
        nan += isnan(B[3 * p + 1]);
        clt[nf] = B[3 * p + 1] > 0 ? 1.96 * se[3 * p + 1] / B[3 * p + 1] : INFINITY;
        rel[nf++] = B[3 * p + 1] > 0 ? half[3 * p + 1] / B[3 * p + 1] : INFINITY;
    }
    qsort(rel, (size_t)nf, sizeof *rel, cmp_double);
    qsort(clt, (size_t)nf, sizeof *clt, cmp_double);
    printf("6b. Hall (%lld patches, %lld on the floor), final gathering over a shooting pilot to a 95%% half-width "
           "<= 5%% B on %s, at most %.0f s, 2 threads\n\n", (long long)n, (long long)nf,
           floor_only ? "the floor (ulam_rad_final_some)" : "every patch", seconds);
    printf("   pilot %lld particles, %lld rays, %.1f s; gather %lld samples, %lld rays; %.1f s in all (rule %s: %lld of "
           "%lld lit patches; %lld unreached)\n", (long long)in.particles, (long long)in.particle_rays, in.pilot_seconds,
           (long long)in.samples, (long long)in.rays, in.seconds, in.met ? "met" : "not met", (long long)in.scene.met,
           (long long)in.scene.lit, (long long)in.scene.unreached);
    printf("   floor 95%% half-width / B: median %.4f, 10%% %.4f, 90%% %.4f (1.96 se / B: median %.4f); %lld floor "
           "patches not reached in time\n\n", rel[nf / 2], rel[nf / 10], rel[9 * nf / 10], clt[nf / 2], (long long)nan);
    free(B), free(se), free(rel), free(half), free(clt), free(want);
    ulam_tracer_free(t), ulam_scene_free(s);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "hall-final")) return hall_final(argc > 2 ? atof(argv[2]) : 60.0, argc > 3 ? atoll(argv[3]) : 0,
                                                                    argc > 4 && !strcmp(argv[4], "floor"), argc > 5 ? atoll(argv[5]) : 0);
    if (argc > 1 && !strcmp(argv[1], "points")) return points_bench();
    if (argc > 2 && !strcmp(argv[1], "office")) return write_office(argv[2]) ? 1 : 0;
    if (argc > 2 && !strcmp(argv[1], "hall")) return write_hall(argv[2]) ? 1 : 0;
    if (argc > 1 && !strcmp(argv[1], "hall")) return hall_bench(60.0);
    const char *path = argc > 1 ? argv[1] : "examples/scenes/cornell_box.obj";
    int W = 16, H = 16;
    if (argc > 2 && (sscanf(argv[2], "%dx%d", &W, &H) != 2 || W < 1 || H < 1)) return 2;
    int64_t P = argc > 3 ? atoll(argv[3]) : 2000000;
    ulam_scene *s0 = NULL;
    ulam_error err;
    if (ulam_scene_read_obj(path, &s0, &err)) {
        fprintf(stderr, "%s:%ld: %s\n", path, err.line, err.msg);
        return 1;
    }
    const int64_t targets[3] = {2000, 10000, 40000}, ff_rays = 1000;
    printf("1. Cornell box, one patch (floor) to 1%% relative error on R, G and B\n\n");
    printf("| patches | collision s | rays | next-event s | rays | rays ratio | time ratio | F (1000 rays/patch) s "
           "| LAPACK s | direct total s | speed-up over collision | speed-up over next-event |\n");
    printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    double f_per_patch = 0, lapack_n = 0, lapack_s = 0;
    for (int k = 0; k < 3; k++) {
        ulam_scene *s = subdivided(s0, targets[k]);
        ulam_tracer *t = NULL;
        int64_t p = 0;
        if (!s || ulam_tracer_alloc(s, &t, &err) || ulam_scene_find(s, "floor", &p)) return 1;
        ulam_rad_result c = gather(t, ULAM_RAD_COLLISION, p, 0.01, 0), e = gather(t, ULAM_RAD_NEXT_EVENT, p, 0.01, 0);
        printf("| %lld | %.3f | %lld | %.4f | %lld | %.1f | %.1f |", (long long)s->npatches, c.seconds,
               (long long)c.rays, e.seconds, (long long)e.rays, (double)c.rays / (double)e.rays, c.seconds / e.seconds);
        size_t bytes = ulam_direct_bytes(s->npatches);
        if (bytes == 0 || bytes > ((size_t)4 << 30)) {
            double n = (double)s->npatches, tf = f_per_patch * n, tl = lapack_s * pow(n / lapack_n, 3);
            printf(" %.1f (extrapolated) | %.0f (extrapolated, n^3 from %.0f; %.1f GB dense) | %.0f | %.0fx | %.0fx |\n",
                   tf, tl, lapack_n, (double)bytes / 1e9, tf + tl, (tf + tl) / c.seconds, (tf + tl) / e.seconds);
        } else {
            ulam_csr *F = NULL;
            double t0 = ulam_now();
            if (ulam_ff_estimate(t, ff_rays, 1, 0, &F, &err)) return 1;
            double tf = ulam_now() - t0;
            double *B = malloc((size_t)(3 * s->npatches) * sizeof *B);
            ulam_direct_info info;
            if (ulam_rad_direct(s, F, 0, B, &info, &err)) return 1;
            double total = tf + info.seconds;
            f_per_patch = tf / (double)s->npatches, lapack_n = (double)s->npatches, lapack_s = info.seconds;
            printf(" %.2f | %.2f | %.2f | %.0fx | %.0fx |\n", tf, info.seconds, total, total / c.seconds,
                   total / e.seconds);
            free(B);
            ulam_csr_free(F);
        }
        fflush(stdout);
        ulam_tracer_free(t);
        ulam_scene_free(s);
    }
    { /* 2. next to a light */
        ulam_scene *s = subdivided(s0, 10000), *el = NULL;
        ulam_tracer *t = NULL, *te = NULL;
        int64_t q = s && !ulam_tracer_alloc(s, &t, &err) ? beside_light(s) : -1;
        if (q >= 0) near_light("2a. Cornell box at ~10,000 patches, the ceiling patch beside the light", t, q, 200000, -1);
        if (!ulam_scene_read_obj("tests/data/rad/edge_lamp.obj", &el, &err) && !ulam_tracer_alloc(el, &te, &err))
            near_light("2b. edge_lamp.obj: a wall sharing an edge with the lamp, exact 0.5 F(C-14)", te, 1, 200000,
                       0.5 * ulam_ff_perpendicular_rectangles(1, 1, 1));
        ulam_tracer_free(te), ulam_tracer_free(t);
        ulam_scene_free(el), ulam_scene_free(s);
    }

    /* 3. an image at ~40,000 patches */
    ulam_scene *s = subdivided(s0, 40000);
    ulam_tracer *t = NULL;
    if (!s || ulam_tracer_alloc(s, &t, &err)) return 1;
    int64_t n = s->npatches;
    ulam_camera cam = ulam_camera_frame(s, W, H);
    double *B = malloc((size_t)(3 * n) * sizeof *B), *se = malloc((size_t)(3 * n) * sizeof *se);
    double *Bs = malloc((size_t)(3 * n) * sizeof *Bs), *ses = malloc((size_t)(3 * n) * sizeof *ses);
    ulam_rad_opts o = ulam_rad_defaults();
    o.estimator = ULAM_RAD_NEXT_EVENT, o.stop.max_walks = 0, o.stop.rel_err = 0.01, o.exec.seed = 1;
    ulam_view_info vi;
    if (!B || !se || !Bs || !ses || ulam_view_gather(t, &cam, W, H, 0.0, &o, B, se, &vi, &err)) return 1;
    ulam_rad_opts so = ulam_rad_defaults();
    so.mode = ULAM_FORWARD, so.stop.max_walks = P, so.exec.seed = 1;
    ulam_rad_solver *sv = NULL;
    if (ulam_rad_solver_alloc(t, &so, &sv, &err)) return 1;
    while (!ulam_rad_solver_done(sv)) ulam_rad_solver_iterate(sv);
    ulam_rad_result sr;
    ulam_rad_solver_result(sv, &sr);
    ulam_rad_solver_vectors(sv, Bs, ses);
    ulam_rad_solver_free(sv);
    int64_t *pix = malloc((size_t)n * sizeof *pix);
    if (!pix || ulam_view_pixels(t, &cam, W, H, pix)) return 1;
    double worst = 0, worst_view = 0, *rel = malloc((size_t)n * sizeof *rel);
    int64_t m = 0;
    for (int64_t p = 0; p < n; p++) {
        if (!pix[p]) continue;
        double w = worst_rel(Bs + 3 * p, ses + 3 * p);
        worst = fmax(worst, w), rel[m++] = w;
        worst_view = fmax(worst_view, worst_rel(B + 3 * p, se + 3 * p));
    }
    double median = 0;
    if (m) { /* the median by a partial sort would do; m is small */
        for (int64_t i = 1; i < m; i++)
            for (int64_t j = i; j > 0 && rel[j - 1] > rel[j]; j--) {
                double x = rel[j];
                rel[j] = rel[j - 1], rel[j - 1] = x;
            }
        median = rel[m / 2];
    }
    double need = (double)P * (worst / 0.01) * (worst / 0.01), need_med = (double)P * (median / 0.01) * (median / 0.01);
    double proj = sr.seconds * need / (double)P, proj_med = sr.seconds * need_med / (double)P;
    printf("\n3. An image of the Cornell box at %lld patches, %dx%d, every seen patch to 1%%\n\n", (long long)n, W, H);
    printf("| route | patches solved | rays | seconds | worst seen patch's rel. error | ratio to view-gather |\n");
    printf("|---|---:|---:|---:|---:|---:|\n");
    printf("| --view-gather (next-event MIS, coverage 0) | %lld of %lld | %lld + %lld camera | %.2f | %.4f | 1 |\n",
           (long long)vi.seen, (long long)n, (long long)vi.rays, (long long)vi.camera_rays, vi.seconds, worst_view);
    printf("| shooting, %lld particles (measured) | all %lld | %lld | %.2f | %.3f (median %.3f) | %.2f |\n",
           (long long)P, (long long)n, (long long)sr.rays, sr.seconds, worst, median, sr.seconds / vi.seconds);
    printf("| shooting to 1%% on the worst seen patch (projected: %.3g particles) | all | %.3g | %.0f | 0.01 | %.0fx |\n",
           need, (double)sr.rays * need / (double)P, proj, proj / vi.seconds);
    printf("| shooting to 1%% on the median seen patch (projected: %.3g particles) | all | %.3g | %.0f | 0.01 | %.0fx |\n",
           need_med, (double)sr.rays * need_med / (double)P, proj_med, proj_med / vi.seconds);
    size_t bytes = ulam_direct_bytes(n);
    double tf = f_per_patch * (double)n, tl = lapack_s * pow((double)n / lapack_n, 3);
    printf("| direct: F (1000 rays/patch) + LAPACK (extrapolated from %.0f patches) | all | %.3g | %.0f | "
           "F's noise, not 1%% | %.0fx |\n", lapack_n, (double)n * ff_rays, tf + tl, (tf + tl) / vi.seconds);
    printf("\nThe direct route needs %.1f GB for one dense %lld x %lld matrix (ulam_direct_bytes), over the 4 GB "
           "default limit.\n", (double)bytes / 1e9, (long long)n, (long long)n);
    free(B), free(se), free(Bs), free(ses), free(pix), free(rel);
    ulam_tracer_free(t);
    ulam_scene_free(s);
    ulam_scene_free(s0);
    return 0;
}
