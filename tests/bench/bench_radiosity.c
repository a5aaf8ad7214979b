/* Benchmark: one patch of the Cornell box to 1% relative error by gathering walks that cast
 * rays, against forming F by ray casting and solving the three channels with LAPACK.
 *
 * The box is subdivided to about 2,000, 10,000 and 40,000 patches.  The walk answers the
 * floor's middle patch (the label's patch containing its area centroid) with the collision estimator,
 * stopping at 1% on every channel.  The direct route forms F with 1000 rays a patch and calls
 * ulam_radiosity_direct (skipped when the dense matrix exceeds 4 GB); its own error at the
 * patch from the noise of F is reported, with the rays a patch it would need for 1% and the
 * time that projects to.  Usage: bench_radiosity [scene.obj] (run from the source root). */
#include "ulam.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "examples/scenes/cornell_box.obj";
    ulam_scene *s0 = NULL;
    ulam_error err;
    if (ulam_scene_read_obj(path, &s0, &err)) {
        fprintf(stderr, "%s:%ld: %s\n", path, err.line, err.msg);
        return 1;
    }
    const int64_t targets[3] = {2000, 10000, 40000}, ff_rays = 1000;
    printf("Cornell box, one patch (floor, middle) to 1%% relative error on R, G and B\n\n");
    printf("| patches | walk s | walks | rays | M rays/s | F (1000 rays/patch) s | LAPACK s | direct total s "
           "| speed-up | direct's own error | rays/patch for 1%% | direct at 1%%, projected s |\n");
    printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int k = 0; k < 3; k++) {
        ulam_scene *s = subdivided(s0, targets[k]);
        ulam_tracer *t = NULL;
        int64_t p = 0;
        if (!s || ulam_tracer_alloc(s, &t, &err) || ulam_scene_find(s, "floor", &p)) return 1;
        ulam_walk_opts o = ulam_walk_defaults();
        o.index = p, o.max_walks = 0, o.rel_err = 0.01, o.seed = 1;
        ulam_rad_solver *sv = NULL;
        if (ulam_rad_solver_alloc(t, &o, &sv, &err)) return 1;
        while (!ulam_rad_solver_done(sv)) ulam_rad_solver_iterate(sv);
        ulam_rad_result r;
        ulam_rad_solver_result(sv, &r);
        ulam_rad_solver_free(sv);
        printf("| %lld | %.3f | %lld | %lld | %.2f |", (long long)s->npatches, r.seconds, (long long)r.walks,
               (long long)r.rays, (double)r.rays / r.seconds / 1e6);
        size_t bytes = ulam_direct_bytes(s->npatches);
        if (bytes == 0 || bytes > ((size_t)4 << 30)) {
            printf(" not run | %.1f GB dense: over the 4 GB limit | | | | | |\n", (double)bytes / 1e9);
        } else {
            ulam_csr *F = NULL;
            double t0 = ulam_now();
            if (ulam_form_factors(t, ff_rays, 1, 0, &F, &err)) return 1;
            double tf = ulam_now() - t0;
            double *B = malloc((size_t)(3 * s->npatches) * sizeof *B), se[3];
            ulam_direct_info info;
            if (ulam_radiosity_direct(s, F, 0, B, &info, &err)) return 1;
            ulam_radiosity_direct_error(s, F, ff_rays, B, p, 0, se, &err);
            double rel = 0;
            for (int c = 0; c < 3; c++) rel = fmax(rel, se[c] / B[3 * p + c]);
            double need = (double)ff_rays * (rel / 0.01) * (rel / 0.01);
            double total = tf + info.seconds, projected = tf * need / (double)ff_rays + info.seconds;
            printf(" %.2f | %.2f | %.2f | %.0fx | %.1f%% | %.3g | %.3g (%.0fx) |\n", tf, info.seconds, total,
                   total / r.seconds, 100 * rel, need, projected, projected / r.seconds);
            free(B);
            ulam_csr_free(F);
        }
        fflush(stdout);
        ulam_tracer_free(t);
        ulam_scene_free(s);
    }
    ulam_scene_free(s0);
    return 0;
}
