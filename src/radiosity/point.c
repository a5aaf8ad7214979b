/* Point walks: the light at a point of the continuous surfaces, with no mesh in the answer.
 * The irradiance H(x) = int B(y) G(x, y) V(x, y) dA_y at a point x with unit normal n
 * (G = cos cos_y / (pi r^2)), B = E + rho H on the surfaces, is the path integral of the
 * lecture: a walk leaves x, and at every vertex v (x first, then each point its cosine ray
 * lands on, the point itself and not a uniform point of its patch) it takes one next-event
 * light sample (lights.c), its own cosine ray landing on an emitter counting by multiple
 * importance sampling against it, so each vertex's direct light is counted once.  A landing
 * point y on patch j carries the walk on with its weights multiplied by rho_jc, and Russian
 * roulette only once they are small (a weight window): when w = max_c W_c rho_jc falls below
 * ULAM__POINT_WMIN the walk continues with probability w / ULAM__POINT_WMIN, its weights
 * divided by that (E[W] unchanged, so the estimate stays unbiased).  So the weight of vertex k
 * is at most max(rho^k, ULAM__POINT_WMIN), rho the scene's largest reflectance, whatever the
 * path: the certified range of one walk's score (patchwalk.c's point_range) falls with the
 * bounces instead of counting every vertex at full weight, as roulette with q = max_c rho_c
 * (weights rho / q, 1 on a grey surface) had to.  Then B(x) = E + rho H(x) on the patch x lies
 * on. */
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
void ulam__point_walk(const ulam_tracer *t, const ulam__lights *L, int estimator, int64_t max_steps,
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
        double w = 0.0;
        for (int c = 0; c < 3; c++) W[c] *= rho[c], w = fmax(w, W[c]);
        if (w < ULAM__POINT_WMIN) { /* Russian roulette once the weights are small */
            if (!(ulam__rng_uniform(r) * ULAM__POINT_WMIN < w)) return;
            for (int c = 0; c < 3; c++) W[c] *= ULAM__POINT_WMIN / w;
        }
        if (step >= max_steps) {
            *cut = 1;
            return;
        }
        for (int k = 0; k < 3; k++) x[k] += dist * d[k], n[k] = s->normal[3 * j + k];
        onto_plane(s, j, x);
        self = j;
    }
}

/* Sum over k = 1 .. K of max(w_(k-1) a, WMIN b), w_k = max(rho^k, WMIN), for 0 <= a <= b: what
 * vertices 1 .. K of a point walk can score in one part (ulam__point_range). */
static double part_sum(double rho, double K, double a, double b)
{
    double sum = 0.0, w = 1.0, k = 1.0;
    for (; k <= K && w * a > ULAM__POINT_WMIN * b; k++, w *= rho) sum += w * a; /* here w_(k-1) = rho^(k-1) */
    return sum + fmax(K - k + 1.0, 0.0) * ULAM__POINT_WMIN * b;
}

/* A certified range of channel c of one walk's score (ulam__point_walk), its vertices past K
 * left out.  Why it holds:
 * - Weights.  W_0 = 1; at a landing on patch j, W <- W rho_j, and roulette (when max_c W_c <
 *   WMIN) sets max_c W_c = WMIN: by induction max_c W_kc <= w_k = max(rho^k, WMIN), rho the
 *   largest reflectance.
 * - Vertex k >= 1 lies on the patch j its walk landed on; it takes one light sample and casts one
 *   cosine ray that may land on an emitter, each scoring at most W_kc times lights.c's bound at
 *   j (light_jc, hit_jc).  Without roulette there W_kc = W_(k-1)c rho_jc <= w_(k-1) rho_jc;
 *   with it W_kc <= WMIN.  So its light sample scores at most max(w_(k-1) lr_c, WMIN l_c),
 *   lr_c = max_j rho_jc light_jc and l_c = max_j light_jc, and its landing likewise with hr,
 *   h.  Vertex 0, the point itself, scores at most light0_c + hit0_c.
 * - Landings on a black emitter (rho 0) end the walk, so when every emitter is black a walk
 *   scores at most one landing: max(hit0_c, hr_c, WMIN h_c).
 * - Truncation.  Roulette keeps E[W_kc | W_(k-1), j] = W_(k-1)c rho_jc, so vertex k adds at most
 *   rho^(k-1) (lr_c + hr_c) to the mean, and the vertices past K at most
 *   (lr_c + hr_c) rho^K / (1 - rho) <= E m for K = ceil(log((lr_c + hr_c) / (E m (1 - rho))) /
 *   log(1 / rho)): the bias the interval adds (channel_range).  The scores of vertices 0 .. K
 *   then lie in [0, R], R = light0_c + part_sum(lr_c, l_c) + (black ? max(hit0_c, hr_c, WMIN h_c)
 *   : hit0_c + part_sum(hr_c, h_c)).  (Roulette with q = max_c rho_c, weights rho / q, 1 on a
 *   grey surface, had R = first + (l_c + h_c)(K + 1).) */
double ulam__point_range(const ulam__point_bounds *b, int c, double m, double E)
{
    double vr = b->lr[c] + b->hr[c], first = b->light0[c] + b->hit0[c];
    if (b->light[c] + b->hit[c] == 0.0) return first;
    if (!isfinite(b->light[c] + b->hit[c]) || !isfinite(first) || !(m > 0) || !(E > 0) || !(b->rho < 1.0)) return INFINITY;
    double K = b->rho > 0 && vr > 0 ? fmax(1.0, ceil(log(vr / (E * m * (1.0 - b->rho))) / log(1.0 / b->rho))) : 1.0;
    double hits = b->black ? fmax(b->hit0[c], fmax(b->hr[c], ULAM__POINT_WMIN * b->hit[c]))
                           : b->hit0[c] + part_sum(b->rho, K, b->hr[c], b->hit[c]);
    return b->light0[c] + part_sum(b->rho, K, b->lr[c], b->light[c]) + hits;
}
