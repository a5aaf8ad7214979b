/* Point walks: the light at a point of the continuous surfaces, with no mesh in the answer.
 * The irradiance H(x) = int B(y) G(x, y) V(x, y) dA_y at a point x with unit normal n
 * (G = cos cos_y / (pi r^2)), B = E + rho H on the surfaces, is the path integral of the
 * lecture: a walk leaves x, and at every vertex v (x first, then each point its cosine ray
 * lands on, the point itself and not a uniform point of its patch) it takes one next-event
 * light sample (lights.c), its own cosine ray landing on an emitter counting by multiple
 * importance sampling against it, so each vertex's direct light is counted once.  A landing
 * point y on patch j carries the walk on with its weights multiplied by rho_jc, and Russian
 * roulette only once they are small (a weight window whose floor falls): at the k-th landing,
 * when w = max_c W_c rho_jc is below f_k = ULAM__POINT_WMIN gamma^k, the walk continues with
 * probability w / f_k, its weights divided by that (E[W] unchanged, so the estimate stays
 * unbiased).  So vertex k weighs at most max(rho^k, f_k), rho the scene's largest reflectance,
 * whatever the path, and one walk's score has a finite certified range (ulam__point_range),
 * where roulette with q = max_c rho_c (weights rho / q, 1 on a grey surface) counted every
 * vertex at full weight up to a truncation.  Then B(x) = E + rho H(x) on the patch x lies on.
 * A patch walk (patchwalk.c) is the same walk from a uniform point of its patch with every
 * landing moved to a uniform point of the patch it reached (the patch-averaged F of the
 * discrete equation B = E + diag(rho) F B); its range is the same sum, its own vertex's bound
 * being its patch's. */
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

/* Where a point walk from x (unit normal n, on patch p or -1) starts: a point on a patch may sit
 * on an edge or vertex it shares with other patches, where a ray leaving it meets a neighbour at
 * distance 0 (a coplanar one from behind, ending the walk dark; a wall across a concave edge
 * from wherever the float origin rounded to).  The answer there is the surface's limit from
 * the inside of the patch, so the walk starts ULAM__POINT_NUDGE scene sizes off the patch's
 * plane along n and as far (at most half way) toward the patch's centroid, inside it: every
 * neighbour is then at a distance 2^8 times the origin's float rounding, on the side it is
 * on, and the answer moves by that share of its variation over the scene (far below its
 * error bar).  A sensor off the surfaces starts where it is. */
void ulam__point_start(const ulam_tracer *t, const double x[3], const double n[3], int64_t p, double out[3])
{
    const ulam_scene *s = ulam__tracer_scene(t);
    double delta = ULAM__POINT_NUDGE * ulam__tracer_size(t, NULL), c[3], d[3];
    for (int k = 0; k < 3; k++) out[k] = x[k];
    if (p < 0) return;
    ulam_scene_centroid(s, p, c);
    ulam__sub3(c, x, d);
    double len = sqrt(ulam__dot3(d, d)), step = len > 0 ? fmin(delta, 0.5 * len) / len : 0.0;
    for (int k = 0; k < 3; k++) out[k] += step * d[k] + delta * n[k];
}

/* One walk from x: its RGB irradiance score (uniform: each landing moves to a uniform point of
 * the patch it landed on, the patch walks' discrete equation). */
void ulam__point_walk(const ulam_tracer *t, const ulam__lights *L, int estimator, int64_t max_steps, double gamma,
                      int uniform, const double x0[3], const double n0[3], int64_t self, const volatile int *interrupt,
                      ulam_rng *r, double score[3], int64_t *rays, int64_t *cut)
{
    const ulam_scene *s = ulam__tracer_scene(t);
    int light = estimator != ULAM_RAD_COLLISION && L->nem > 0;
    double W[3] = {1, 1, 1}, floor = ULAM__POINT_WMIN, x[3] = {x0[0], x0[1], x0[2]}, n[3] = {n0[0], n0[1], n0[2]};
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
        floor *= gamma;
        for (int c = 0; c < 3; c++) W[c] *= rho[c], w = fmax(w, W[c]);
        if (w < floor) { /* Russian roulette once the weights are below the floor */
            if (!(ulam__rng_uniform(r) * floor < w)) return;
            for (int c = 0; c < 3; c++) W[c] *= floor / w;
        }
        if (step >= max_steps || ((step & 0xffff) == 0xffff && interrupt && *interrupt)) {
            *cut = 1; /* at max_steps, or interrupted inside a walk of 65536 steps and more */
            return;
        }
        for (int k = 0; k < 3; k++) x[k] += dist * d[k], n[k] = s->normal[3 * j + k];
        if (uniform) ulam__tracer_point(t, j, r, x);
        onto_plane(s, j, x);
        self = j;
    }
}

/* The rate gamma = (1 + rho) / 2 at which a point walk's weight floor falls (ulam__point_walk):
 * above rho, the largest reflectance, so that every walk ends; below 1, so that its weights'
 * sum is finite. */
double ulam__point_gamma(double rho)
{
    return 0.5 * (1.0 + rho);
}

/* Sum over k >= 1 of max(rho^(k-1) a, f_k b), f_k = WMIN gamma^k, for 0 <= a <= gamma b and
 * rho < gamma: the terms are rho^(k-1) a while that is the larger (it falls faster), then
 * f_k b, a geometric tail. */
static double part_sum(double rho, double gamma, double a, double b)
{
    double k = 1.0; /* the first k where f_k b takes over: rho^(k-1) a <= f_k b */
    if (a > ULAM__POINT_WMIN * gamma * b) {
        if (!(b > 0)) return a / (1.0 - rho);
        if (rho == 0.0) k = 2.0;
        else k = fmax(2.0, ceil((log(a) - log(ULAM__POINT_WMIN * b) - log(rho)) / (log(gamma) - log(rho))));
        /* by the closed form, then to the exact first k (a loop to it ran 4.6e7 steps at rho 1 - 1e-7) */
        while (k > 2.0 && pow(rho, k - 2.0) * a <= ULAM__POINT_WMIN * pow(gamma, k - 1.0) * b) k -= 1.0;
        while (pow(rho, k - 1.0) * a > ULAM__POINT_WMIN * pow(gamma, k) * b) k += 1.0;
    }
    double head = rho == 0.0 ? (k > 1.0 ? a : 0.0) : a * (1.0 - pow(rho, k - 1.0)) / (1.0 - rho);
    return head + b * ULAM__POINT_WMIN * pow(gamma, k) / (1.0 - gamma);
}

/* A certified bound on what channel c of one walk (ulam__point_walk) can miss when cut at
 * max_steps K: the walk has scored its vertices 0 .. K (each a light sample and the landing of
 * its cosine ray), so the rest is at most the sum over k > K of vertex k's bound in
 * ulam__point_range, max(rho^(k-1) lr_c, f_k l_c) + max(rho^(k-1) hr_c, f_k h_c) <= rho^(k-1)
 * (lr_c + hr_c) + f_k (l_c + h_c), whose geometric tails are rho^K (lr_c + hr_c) / (1 - rho) +
 * WMIN gamma^(K+1) (l_c + h_c) / (1 - gamma).  The mean of the walks is biased low by at most
 * that (0 for a walk that cannot be cut short of anything: rho^K underflows on a dull scene). */
double ulam__point_tail(const ulam__point_bounds *b, int c, int64_t max_steps)
{
    double a = b->lr[c] + b->hr[c], f = b->light[c] + b->hit[c];
    if (a + f == 0.0) return 0.0;
    if (!isfinite(a + f) || !(b->rho < 1.0)) return INFINITY;
    double g = ulam__point_gamma(b->rho), K = (double)max_steps;
    return (a > 0 ? a * pow(b->rho, K) / (1.0 - b->rho) : 0.0) + ULAM__POINT_WMIN * pow(g, K + 1.0) * f / (1.0 - g);
}

/* A certified range of channel c of one walk's score (ulam__point_walk): every score lies in
 * [0, R].  Why:
 * - Weights.  W_0 = 1; at the k-th landing, on patch j, W <- W rho_j, and roulette (when
 *   max_c W_c < f_k = WMIN gamma^k) sets max_c W_c = f_k: by induction max_c W_kc <= w_k =
 *   max(rho^k, f_k), rho the largest reflectance (rho f_(k-1) < f_k as rho < gamma).
 * - Vertex k >= 1 lies on the patch j its walk landed on; it takes one light sample and casts one
 *   cosine ray that may land on an emitter, each scoring at most W_kc times lights.c's bound at
 *   j (light_jc, hit_jc).  Without roulette there, W_kc = W_(k-1)c rho_jc <= w_(k-1) rho_jc;
 *   with it W_kc <= f_k.  So its light sample scores at most max(w_(k-1) lr_c, f_k l_c) =
 *   max(rho^(k-1) lr_c, f_k l_c) (as f_(k-1) lr_c <= f_(k-1) rho l_c < f_k l_c), lr_c =
 *   max_j rho_jc light_jc, l_c = max_j light_jc; its landing likewise with hr, h.  Vertex 0,
 *   the point itself, scores at most light0_c + hit0_c.
 * - Landings on a black emitter (rho 0) end the walk, so when every emitter is black a walk
 *   scores at most one landing: max(hit0_c, hr_c, f_1 h_c).
 * - So R = light0_c + part_sum(lr_c, l_c) + (black ? max(hit0_c, hr_c, f_1 h_c) :
 *   hit0_c + part_sum(hr_c, h_c)), finite with no truncation: no walk is cut and no bias is
 *   added.  (Roulette with q = max_c rho_c, weights rho / q, 1 on a grey surface, has no finite
 *   range: it was truncated at K vertices, R = first + (l_c + h_c)(K + 1), plus a bias.) */
double ulam__point_range(const ulam__point_bounds *b, int c)
{
    double first = b->light0[c] + b->hit0[c];
    if (b->light[c] + b->hit[c] == 0.0) return first;
    if (!isfinite(b->light[c] + b->hit[c]) || !isfinite(first) || !(b->rho < 1.0)) return INFINITY;
    double g = ulam__point_gamma(b->rho);
    double hits = b->black ? fmax(b->hit0[c], fmax(b->hr[c], ULAM__POINT_WMIN * g * b->hit[c]))
                           : b->hit0[c] + part_sum(b->rho, g, b->hr[c], b->hit[c]);
    return b->light0[c] + part_sum(b->rho, g, b->lr[c], b->light[c]) + hits;
}
