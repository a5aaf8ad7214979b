/* Point walks: the light at a point of the continuous surfaces, with no mesh in the answer.
 * The irradiance H(x) = int B(y) G(x, y) V(x, y) dA_y at a point x with unit normal n
 * (G = cos cos_y / (pi r^2)), B = E + rho H on the surfaces, is the path integral of the
 * lecture: a walk leaves x, and at every vertex v (x first, then each point its cosine ray
 * lands on, the point itself and not a uniform point of its patch) it takes one next-event
 * light sample (lights.c), its own cosine ray landing on an emitter counting by multiple
 * importance sampling against it, so each vertex's direct light is counted once.  A landing
 * point y on patch j carries the walk on with Russian roulette: it continues with
 * q_j = max_c rho_jc, its weights multiplied by rho_jc / q_j (E[w] unchanged).  Then
 * B(x) = E + rho H(x) on the patch x lies on. */
#include "rad.h"

/* Move y onto the plane of patch j (the hit point's float rounding, so that the next ray leaves
 * j's plane from it and cannot meet a coplanar neighbour at distance 0). */
static void onto_plane(const ulam_scene *s, int64_t j, double y[3])
{
    const double *n = s->normal + 3 * j, *v = s->vert + 3 * s->vidx[s->start[j]];
    double d[3];
    ulam__sub3(y, v, d);
    double h = ulam__dot3(d, n);
    for (int k = 0; k < 3; k++) y[k] -= h * n[k];
}

/* One walk from x: its RGB irradiance score. */
void ulam__point_walk(const ulam_tracer *t, const ulam__lights *L, const double *q, int estimator, int64_t max_steps,
                      const double x0[3], const double n0[3], int64_t self, ulam_rng *r, double score[3],
                      int64_t *rays, int64_t *cut)
{
    const ulam_scene *s = ulam__tracer_scene(t);
    int light = estimator != ULAM_RAD_COLLISION && L->nem > 0;
    double W[3] = {1, 1, 1}, x[3] = {x0[0], x0[1], x0[2]}, n[3] = {n0[0], n0[1], n0[2]};
    score[0] = score[1] = score[2] = 0.0;
    for (int64_t step = 0;; step++) {
        if (light) *rays += ulam__lights_score(t, L, estimator, ulam__lights_pick(L, ulam__rng_uniform(r)), x, n, self,
                                               W, r, score);
        double d[3], dist = 0.0;
        int front = 0;
        ulam__cosine_dir(n, r, d);
        int64_t j = ulam__tracer_ray(t, x, d, self, &front, &dist);
        ++*rays;
        if (j < 0 || !front) return; /* left the scene, or a back side: no light comes back */
        const double *E = s->emit + 3 * j, *rho = s->rho + 3 * j;
        if (E[0] + E[1] + E[2] > 0) {
            ulam__hit h = {dist, ulam__dot3(d, n), -ulam__dot3(d, s->normal + 3 * j)};
            double w = L->nem > 0 ? ulam__lights_hit_weight(L, s, estimator, j, &h) : 1.0;
            for (int c = 0; c < 3; c++) score[c] += W[c] * E[c] * w;
        }
        if (ulam__rng_uniform(r) >= q[j]) return; /* Russian roulette at the landing point */
        if (step >= max_steps) {
            *cut = 1;
            return;
        }
        for (int c = 0; c < 3; c++) W[c] *= rho[c] / q[j];
        for (int k = 0; k < 3; k++) x[k] += dist * d[k], n[k] = s->normal[3 * j + k];
        onto_plane(s, j, x);
        self = j;
    }
}
