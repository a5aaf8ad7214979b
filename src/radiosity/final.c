/* Final gathering over a shooting pilot (mode "final"): every patch's radiosity to a relative
 * target at once, for scenes of many patches where shooting alone needs a particle a patch per
 * bounce (issue 40's hall: ~10^5 patches).
 *
 * 1. Pilot: G = ULAM__FINAL_GROUPS independent shooting runs (patchwalk.c, collision tallies),
 *    run g seeded from stream (seed, ULAM_STREAM_PILOT, g), give every patch's reflected
 *    radiosity R^g_j = B^g_j - E_j; each R^g is unbiased for R.
 * 2. Gather at every patch i that reflects: a sample is a uniform point x of i and two rays.
 *    A light sample picks emitter l with probability pi_l (final_table: half by the unoccluded
 *    transfer between the centroids, half by its bound, so that every emitter that can light
 *    the patch keeps a share), y uniform on l, and scores
 *    E_l G(x, y) A_l / pi_l w_L when y is seen.  A cosine ray from x lands on j at y with area
 *    density G(x, y); it scores E_j w_C (w_L, w_C: Veach's power heuristic of the two densities)
 *    plus R^g_j for each pilot run g.  The sample's score in run g is
 *    s^g = E_i + rho_i (light + hit + R^g_j); s = mean_g s^g.
 *    Given the pilot, mean s is unbiased for E_i + rho_i (D_i + sum_j F_ij Rbar_j) and the pilot
 *    is unbiased for R, so B_i's estimate is unbiased.
 * 3. Its interval, 95% in two parts by the union bound: the samples' part is stop.h's confidence
 *    sequence (valid at every count, so each patch may stop whenever it meets rel_err) on the
 *    scores less E_i at 97.5%, their range certified given the pilot: rho_i times the largest
 *    light sample (the power heuristic keeps E_l G / p_L w_L at most E_l / 2, and at most
 *    E_l Gmax A_l / pi_l with Gmax = 1 / (pi d^2), d the least distance between the patches'
 *    bounding spheres), the largest weighted emitter hit (E_j min(1, (Gmax A_j / pi_j)^2)) and
 *    the patch's clip of the pilot's mean reflected radiosity (final_cap: the brightest pilot
 *    patches clipped where the form-factor bound F_ij <= A_j Gmax makes the certified bias
 *    small; a floor far from the hall's bright few clips them all), the bias added to the
 *    half-width; the pilot's part, given the rays, is t sqrt(V2)
 *    at 97.5%, V2 = var_g(mean_k s^g) / G (the G runs are independent), t Student's quantile on
 *    G - 1 degrees of freedom.  Patches run blocks of ULAM__FINAL_BLOCK samples in passes to
 *    64, 256, 1024 ... samples (so that a time limit leaves the patches balanced), each stopping
 *    once every channel's half-width is at most rel_err B, or once the pilot's part alone takes
 *    0.9 of that (a larger pilot is needed there).  se is the central-limit standard
 *    error sqrt(V1 + V2) (V1 = var(s) / K), printed beside the interval.
 * Patch i's samples draw from stream (seed, ULAM_STREAM_POINT, i), so the answer does not depend
 * on the threads. */
#include "rad.h"
#include "../stop.h"

#include <stdlib.h>
#include <string.h>

/* Pilot runs, first-pass samples a patch, samples a block, and above how many emitters the
 * light sample is drawn by power alone (the per-patch table would cost emitters a patch). */
#define ULAM__FINAL_GROUPS 16
#define ULAM__FINAL_K0 64
#define ULAM__FINAL_BLOCK 32
#define ULAM__FINAL_EMITTERS_GEOM 1024
#define ULAM__FINAL_BRIGHT 1024 /* the brightest pilot patches a patch may clip (final_cap) */
#define ULAM__FINAL_KPLAN 1024  /* the samples a patch plans for (its cap's trade, its first block) */

/* Student's t on 15 degrees of freedom (G - 1) at 98.75%: the pilot's half of the 95%. */
static const double t9875 = 2.489880;

/* A patch's sums: samples, sum and sum of squares of s per channel, sum of s^g per run, the
 * sequences of s - E_i and their certified ranges. */
typedef struct {
    int64_t k, rays;
    double s1[3], s2[3], g[ULAM__FINAL_GROUPS][3];
    ulam__cs cs[3];
    double A[3], bias[3]; /* bias: the most the clipping of the pilot's bright patches takes off */
    double cap;           /* the pilot's mean reflected radiosity is clipped here at this patch */
    ulam_rng r;
    int state; /* 0 not started, 1 running, 2 finished (met, capped, exact or dark) */
} final_acc;

/* What every sample reads. */
typedef struct {
    const ulam_tracer *t;
    const ulam_scene *s;
    ulam__lights L;
    int32_t *eidx;   /* npatches: the emitter's index in L, -1 */
    float *R;        /* G * 3 * npatches: the pilot runs' reflected radiosity */
    double *power;   /* nem: A_l sum_c E_lc */
    double *ec;      /* 4 * nem: the emitters' centroids and bounding radii */
    double Rmax[3];  /* the largest mean_g R^g_j a channel, rounded up */
    int64_t *bright; /* the nbright brightest patches by max_c mean_g R^g_j, descending, their */
    double *btop;    /* values (nbright + 1: the next one's, 0 past the last) and balls (4 each) */
    double *bball;
    int64_t nbright;
} final_ctx;

/* Patch p's centroid c and the radius of a ball about it holding p. */
static double patch_ball(const ulam_scene *s, int64_t p, double c[3])
{
    double r2 = 0.0;
    ulam_scene_centroid(s, p, c);
    for (int64_t k = s->start[p]; k < s->start[p + 1]; k++) {
        double d[3];
        ulam__sub3(s->vert + 3 * s->vidx[k], c, d);
        r2 = fmax(r2, ulam__dot3(d, d));
    }
    return sqrt(r2);
}

/* An upper bound on G(x, y) = cos cos / (pi r^2) for x in the ball (ci, ri) on a plane of normal
 * ni and y in the ball (cj, rj) on a plane of normal nj: each cosine at most (its side's
 * centre offset + ri + rj) / d and 1, r at least d, the gap between the balls (INFINITY when
 * they meet); 0 when either ball lies wholly behind the other's plane. */
static double g_bound2(const double ci[3], double ri, const double ni[3], const double cj[3], double rj,
                       const double nj[3])
{
    double d[3];
    ulam__sub3(cj, ci, d);
    double u = ulam__dot3(d, ni), v = -ulam__dot3(d, nj);
    if (u < -rj || v < -ri) return 0.0;
    double gap = sqrt(ulam__dot3(d, d)) - ri - rj;
    if (!(gap > 0)) return INFINITY;
    return fmin(1.0, (u + ri + rj) / gap) * fmin(1.0, (v + ri + rj) / gap) / (M_PI * gap * gap);
}

/* g_bound2 for patch p's ball (c, r, normal n) and emitter k. */
static double g_bound(const final_ctx *x, int64_t k, const double c[3], double r, const double n[3])
{
    return g_bound2(c, r, n, x->ec + 4 * k, x->ec[4 * k + 3], x->s->normal + 3 * x->L.emitter[k]);
}

/* Patch p's per-emitter pick probabilities (pi, nem) and their cumulative sums (cdf), and the
 * certified range of its scores less E_p (a->A, per channel).  pi_k is half in proportion to
 * S_l A_l G(c_p, c_l) (the centroids' unoccluded transfer, S_l = sum_c E_lc) and half to S_l A_l
 * Gmax_k (g_bound), so that E_l Gmax_k A_l / pi_k <= 2 sum_k S_k A_k Gmax_k: the light sample's
 * bound is about the patch's unoccluded irradiance; emitters whose balls meet the patch's get
 * their power's share instead (their bound: the power heuristic's E_l / 2). */
static void final_table(const final_ctx *x, int64_t p, double *pi, double *cdf, final_acc *a)
{
    const ulam_scene *s = x->s;
    int64_t nem = x->L.nem;
    double c[3], geo = 0.0, bnd = 0.0, r = patch_ball(s, p, c);
    const double *n = s->normal + 3 * p;
    int geom = nem <= ULAM__FINAL_EMITTERS_GEOM, near = 0;
    for (int64_t k = 0; k < nem && geom; k++) {
        int64_t l = x->L.emitter[k];
        double d[3], gb = g_bound(x, k, c, r, n);
        ulam__sub3(x->ec + 4 * k, c, d);
        double r2 = ulam__dot3(d, d), u = ulam__dot3(d, n), v = -ulam__dot3(d, s->normal + 3 * l);
        pi[k] = r2 > 0 && u > 0 && v > 0 ? x->power[k] * u * v / (r2 * r2) : 0.0;
        cdf[k] = isfinite(gb) ? x->power[k] * gb : 0.0;
        near |= isinf(gb);
        geo += pi[k], bnd += cdf[k];
    }
    double acc = 0.0, light[3] = {0, 0, 0}, hit[3] = {0, 0, 0};
    for (int64_t k = 0; k < nem; k++) {
        double pw = x->power[k] / x->L.ptot, w = 0.0, parts = 0.0;
        if (geom && geo > 0) w += pi[k] / geo, parts++;
        if (geom && bnd > 0) w += cdf[k] / bnd, parts++;
        if (!geom || near || parts == 0) w += pw, parts++;
        pi[k] = w / parts;
    }
    for (int64_t k = 0; k < nem; k++) {
        int64_t l = x->L.emitter[k];
        double gb = geom ? g_bound(x, k, c, r, n) : INFINITY;
        double q = gb == 0.0 ? 0.0 : pi[k] > 0 ? gb * s->area[l] / pi[k] : INFINITY; /* Gmax / p_L */
        cdf[k] = (acc += pi[k]);
        for (int ch = 0; ch < 3; ch++) {
            double E = s->emit[3 * l + ch];
            light[ch] = fmax(light[ch], E * fmin(q, 0.5)), hit[ch] = fmax(hit[ch], E * fmin(1.0, q * q));
        }
    }
    for (int ch = 0; ch < 3; ch++) a->A[ch] = s->rho[3 * p + ch] * (light[ch] + hit[ch] + fmin(x->Rmax[ch], a->cap));
}

/* Patch p's clip of the pilot's landing scores (a->cap) and the most it takes off p's mean
 * (a->bias): clipping the k brightest pilot patches at the next one's value C takes off
 * rho_p sum_j F_pj (Rbar_j - C)+ <= rho_p sum_j f_j (top_j - C), f_j = min(1, A_j / A_p,
 * A_j Gmax(p, j)) (F_pj <= 1, reciprocity, and G's bound g_bound2); the range it leaves costs
 * about C L / (lambda_max K) at K samples (the sequence's range term, stop.h).  The k (0 .. the
 * nbright brightest) least in C kappa + bias, kappa that cost at the kplan samples planned: a
 * patch far from the bright few (a floor under lamps seen at a grazing angle) clips them all
 * for little. */
static void final_cap(const final_ctx *x, int64_t p, final_acc *a, double kplan)
{
    const ulam_scene *s = x->s;
    double c[3], r = patch_ball(s, p, c), w0 = 0.0, w1 = 0.0, kappa = log(2.0 / (ULAM__STOP_DELTA / 2)) / (ULAM__CS_LMAX * kplan);
    double best = x->nbright > 0 ? x->btop[0] * kappa : INFINITY, bias = 0.0;
    a->cap = INFINITY;
    for (int64_t k = 0; k < x->nbright; k++) {
        int64_t j = x->bright[k];
        double f = j == p ? 0.0
                          : fmin(fmin(1.0, s->area[j] / s->area[p]),
                                 s->area[j] * g_bound2(c, r, s->normal + 3 * p, x->bball + 4 * k, x->bball[4 * k + 3], s->normal + 3 * j));
        w0 += f, w1 += f * x->btop[k];
        double C = x->btop[k + 1], b = fmax(0.0, w1 - C * w0);
        if (b >= best) break; /* the bias only grows with k */
        if (C * kappa + b < best) best = C * kappa + b, a->cap = C, bias = b;
    }
    for (int ch = 0; ch < 3; ch++) a->bias[ch] = s->rho[3 * p + ch] * bias * (1 + 1e-6); /* float sums rounded up */
}

/* The index k with cdf[k - 1] <= u < cdf[k] (u in [0, cdf[nem - 1])). */
static int64_t final_pick(const double *cdf, int64_t nem, double u)
{
    int64_t lo = 0, hi = nem - 1;
    while (lo < hi) {
        int64_t m = lo + (hi - lo) / 2;
        if (u < cdf[m]) hi = m;
        else lo = m + 1;
    }
    return lo;
}

/* The power heuristic's weight of density a against b. */
static double power_weight(double a, double b)
{
    return a * a / (a * a + b * b);
}

/* One sample at patch p into a (pi, cdf: p's table). */
static void final_sample(const final_ctx *x, int64_t p, const double *pi, const double *cdf, final_acc *a, double blk[3][3])
{
    const ulam_scene *s = x->s;
    const double *n = s->normal + 3 * p, *rho = s->rho + 3 * p, *E = s->emit + 3 * p;
    double pt[3], dir[3], direct[3] = {0, 0, 0};
    ulam__tracer_point(x->t, p, &a->r, pt);
    if (x->L.nem > 0) { /* the light sample */
        int64_t k = final_pick(cdf, x->L.nem, ulam_rng_uniform(&a->r) * cdf[x->L.nem - 1]), l = x->L.emitter[k];
        double y[3];
        ulam__hit h;
        ulam__tracer_point(x->t, l, &a->r, y);
        a->rays++;
        if (ulam__tracer_sees_from(x->t, pt, n, p, l, y, &h)) {
            double G = h.cos_from * h.cos_to / (M_PI * h.dist * h.dist), pL = pi[k] / s->area[l], w = power_weight(pL, G);
            for (int c = 0; c < 3; c++) direct[c] += s->emit[3 * l + c] * G / pL * w;
        }
    }
    int front = 0;
    double dist = 0.0;
    ulam__cosine_dir(n, &a->r, dir);
    int64_t j = ulam__tracer_ray(x->t, pt, dir, p, &front, &dist);
    a->rays++;
    if (j >= 0 && !front) j = -1; /* a back side: the light is lost */
    if (j >= 0 && x->eidx[j] >= 0) { /* the cosine ray on an emitter, weighed against the light sample */
        double cto = -ulam__dot3(dir, s->normal + 3 * j), G = ulam__dot3(dir, n) * cto / (M_PI * dist * dist);
        double pL = pi[x->eidx[j]] / s->area[j], w = G > 0 ? power_weight(G, pL) : 0.0;
        for (int c = 0; c < 3; c++) direct[c] += s->emit[3 * j + c] * w;
    }
    for (int c = 0; c < 3; c++) {
        double Rbar = 0.0;
        for (int g = 0; g < ULAM__FINAL_GROUPS; g++) {
            double R = j >= 0 ? (double)x->R[((size_t)g * (size_t)s->npatches + (size_t)j) * 3 + (size_t)c] : 0.0;
            a->g[g][c] += E[c] + rho[c] * (direct[c] + R);
            Rbar += R;
        }
        Rbar = fmin(Rbar / ULAM__FINAL_GROUPS, a->cap); /* the brightest clipped (final_cap, a->bias) */
        double y = rho[c] * (direct[c] + Rbar), v = E[c] + y;
        a->s1[c] += v, a->s2[c] += v * v;
        blk[c][0] += y, blk[c][1] += y * y, blk[c][2] = fmax(blk[c][2], y);
    }
    a->k++;
}

/* Patch a's estimate, central-limit standard error sqrt(V1 + V2) and 95% half-width (the
 * sequence's at 97.5% plus the pilot's t sqrt(V2)) in channel c; E its emission. */
static void final_estimate(const final_acc *a, int c, double E, double *B, double *se, double *half, double *fixed)
{
    double K = (double)a->k, m = a->s1[c] / K, v1 = K > 1 ? fmax(0.0, a->s2[c] - K * m * m) / (K * (K - 1)) : INFINITY,
           v2 = 0.0, mu = 0.0;
    for (int g = 0; g < ULAM__FINAL_GROUPS; g++) mu += a->g[g][c] / K;
    mu /= ULAM__FINAL_GROUPS; /* the unclipped pilot's: its runs' spread is the pilot's noise */
    for (int g = 0; g < ULAM__FINAL_GROUPS; g++) {
        double d = a->g[g][c] / K - mu;
        v2 += d * d;
    }
    v2 /= (double)ULAM__FINAL_GROUPS * (ULAM__FINAL_GROUPS - 1);
    *B = m;
    *se = sqrt(v1 + v2);
    if (fixed) *fixed = t9875 * sqrt(v2) + a->bias[c]; /* the pilot's part: more samples do not shrink it much */
    if (a->A[c] == 0.0) { /* nothing but the emission can score: exact */
        *half = 0.0;
        return;
    }
    ulam__stop_ci ci;
    double L = log(2.0 / (ULAM__STOP_DELTA / 2)); /* each side's ln(1 / delta_side) at 97.5% two-sided */
    ulam__cs_interval_sides(&a->cs[c], m - E, 0.0, L, L, &ci);
    *half = ci.kind == ULAM__STOP_EB ? ci.half + t9875 * sqrt(v2) + a->bias[c] : INFINITY;
}

/* 1 when every channel of patch a (emission E) that can score has its half-width at most rel_err
 * times its estimate (a channel still at 0: times the brightest); -1 when, past 256 samples, the
 * pilot's part alone (final_estimate's fixed) takes 0.9 of that in a channel (more samples
 * cannot meet it); else 0. */
static int final_met(const final_acc *a, const double *E, double rel_err)
{
    double B[3], se[3], half[3], fixed[3], bright = 0.0;
    for (int c = 0; c < 3; c++) final_estimate(a, c, E[c], &B[c], &se[c], &half[c], &fixed[c]), bright = fmax(bright, B[c]);
    if (!(bright > 0)) return 0;
    int met = 1;
    for (int c = 0; c < 3; c++) {
        double goal = rel_err * (B[c] > 0 ? B[c] : bright);
        if (a->A[c] > 0 && a->k >= 256 && fixed[c] >= 0.9 * goal) return -1;
        if (a->A[c] > 0 && !(half[c] <= goal)) met = 0;
    }
    return met;
}

/* Run patch p's blocks until it has `upto` samples or (rel_err > 0) meets rel_err. */
static void final_run(const final_ctx *x, int64_t p, const double *pi, const double *cdf, final_acc *a, int64_t upto,
                      double rel_err, int64_t cap)
{
    const double *E = x->s->emit + 3 * p;
    while (a->k < upto) {
        int64_t nb = upto - a->k < ULAM__FINAL_BLOCK ? upto - a->k : ULAM__FINAL_BLOCK;
        double blk[3][3] = {{0}};
        for (int c = 0; c < 3; c++) { /* plan the block from the samples so far */
            double K = (double)a->k, m = K > 0 ? a->s1[c] / K - E[c] : 0.0,
                   v = K > 1 ? fmax(0.0, a->s2[c] - K * (m + E[c]) * (m + E[c])) / (K - 1) : 0.0;
            double h = rel_err > 0 && K > 0 && m + E[c] > 0 ? 0.8 * rel_err * (m + E[c]) - a->bias[c] : 0.0;
            ulam__cs_plan(&a->cs[c], a->k, m, v, a->A[c], 0.0, h > 0 ? h : 0.0,
                          rel_err > 0 && cap > ULAM__FINAL_KPLAN ? ULAM__FINAL_KPLAN : (double)cap);
        }
        for (int64_t k = 0; k < nb; k++) final_sample(x, p, pi, cdf, a, blk);
        for (int c = 0; c < 3; c++) {
            double mean = blk[c][0] / (double)nb;
            ulam__cs_add(&a->cs[c], nb, mean, fmax(0.0, blk[c][1] - (double)nb * mean * mean), blk[c][2]);
        }
        if (rel_err > 0 && final_met(a, E, rel_err)) { /* met, or out of the samples' reach */
            a->state = 2;
            return;
        }
    }
}

/* The pilot: G shooting runs of particles / G each (at most max_seconds between them). */
static int final_pilot(final_ctx *x, const ulam_rad_opts *o, int64_t particles, double max_seconds,
                       ulam_rad_final_info *in, ulam_error *err)
{
    const ulam_scene *s = x->s;
    int64_t n = s->npatches, each = (particles + ULAM__FINAL_GROUPS - 1) / ULAM__FINAL_GROUPS;
    double *B = ulam__malloc((size_t)(3 * n), sizeof *B), t0 = ulam_now();
    if (!B) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the pilot");
    int status = ULAM_OK;
    for (int g = 0; g < ULAM__FINAL_GROUPS && !status; g++) {
        ulam_rad_opts p = *o;
        ulam_rad_solver *sv = NULL;
        p.mode = ULAM_FORWARD, p.estimator = ULAM_RAD_COLLISION, p.index = 0;
        p.stop.rel_err = 0.0, p.stop.max_walks = each;
        p.stop.max_seconds = max_seconds > 0 ? fmax(1e-3, (max_seconds - (ulam_now() - t0)) / (ULAM__FINAL_GROUPS - g)) : 0.0;
        p.exec.seed = ulam_rng_substream(o->exec.seed, ULAM_STREAM_PILOT, (uint64_t)g); /* docs/streams.md */
        if ((status = ulam_rad_solver_alloc(x->t, &p, &sv, err))) break;
        while (!status && !ulam_rad_solver_done(sv)) status = ulam_rad_solver_iterate(sv);
        ulam_rad_result r;
        ulam_rad_solver_result(sv, &r);
        in->particles += r.walks, in->particle_rays += r.rays;
        in->interrupted |= r.interrupted && o->stop.interrupt && *o->stop.interrupt;
        if (!status) status = ulam_rad_solver_vectors(sv, B, NULL);
        for (int64_t i = 0; i < 3 * n && !status; i++)
            x->R[(size_t)g * (size_t)(3 * n) + (size_t)i] = (float)fmax(0.0, B[i] - s->emit[i]);
        ulam_rad_solver_free(sv);
        if (status) ulam__fail(err, status, 0, -1, "the pilot's shooting");
    }
    ulam__ranked *top = status ? NULL : ulam__malloc((size_t)n, sizeof *top);
    int64_t nb = n < ULAM__FINAL_BRIGHT ? n : ULAM__FINAL_BRIGHT;
    x->bright = ulam__malloc((size_t)nb, sizeof *x->bright);
    x->btop = ulam__malloc((size_t)nb + 1, sizeof *x->btop);
    x->bball = ulam__malloc((size_t)(4 * nb), sizeof *x->bball);
    if (!status && (!top || !x->bright || !x->btop || !x->bball)) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the pilot");
    for (int64_t j = 0; j < n && !status; j++) {
        top[j].r = 0.0, top[j].i = j;
        for (int c = 0; c < 3; c++) {
            double m = 0.0;
            for (int g = 0; g < ULAM__FINAL_GROUPS; g++) m += x->R[((size_t)g * (size_t)n + (size_t)j) * 3 + (size_t)c];
            m = m / ULAM__FINAL_GROUPS * (1 + 1e-6); /* float sums rounded up */
            top[j].r = fmax(top[j].r, m), x->Rmax[c] = fmax(x->Rmax[c], m);
        }
    }
    if (!status) { /* the brightest nb with their balls (final_cap) */
        qsort(top, (size_t)n, sizeof *top, ulam__ranked_desc);
        for (int64_t k = 0; k < nb; k++) {
            x->bright[k] = top[k].i, x->btop[k] = top[k].r;
            x->bball[4 * k + 3] = patch_ball(s, top[k].i, x->bball + 4 * k);
        }
        x->btop[nb] = nb < n ? top[nb].r : 0.0;
        x->nbright = nb;
    }
    free(top);
    free(B);
    return status;
}

/* The whole scene's rule from the patches' answers: a patch is lit when it emits or a sample
 * scored on it; unreached when it reflects, emits nothing, and no sample scored (or the stop came
 * first: NaN); lit patches meet E when every nonzero channel's 95% half-width is at most E B. */
static void final_rule(const ulam_scene *s, const unsigned char *want, const double *B, const double *se, const double *half,
                       double E, double share, ulam_rad_scene_rule *q, int64_t first[8])
{
    memset(q, 0, sizeof *q);
    for (int k = 0; k < 8; k++) first[k] = -1;
    q->worst_patch = -1, q->share = share;
    for (int64_t p = 0; p < s->npatches; p++) {
        if (want && !want[p]) continue;
        double bright = 0.0, worst = 0.0, wse = 0.0;
        int met = 1;
        for (int c = 0; c < 3; c++) {
            double b = B[3 * p + c];
            bright = fmax(bright, b);
            if (b > 0)
                worst = fmax(worst, half[3 * p + c] / b), wse = fmax(wse, se[3 * p + c] / b),
                met &= half[3 * p + c] <= E * b;
        }
        if (isnan(B[3 * p]) || !(bright > 0)) {
            if (ulam__max3(s->rho + 3 * p) > 0 && q->unreached < 8) first[q->unreached] = p;
            q->unreached += ulam__max3(s->rho + 3 * p) > 0;
            continue;
        }
        q->lit++, q->lit_area += s->area[p];
        if (met && E > 0) q->met++, q->met_area += s->area[p];
        q->worst_se = fmax(q->worst_se, wse);
        if (q->worst_patch < 0 || worst > q->worst_half) q->worst_half = worst, q->worst_patch = p;
    }
}

/* Every patch's radiosity by final gathering over a shooting pilot. */
int ulam_rad_final(const ulam_tracer *t, const ulam_rad_opts *opts, int64_t pilot, double share, double *B, double *se,
                   double *half, ulam_rad_final_info *info, ulam_error *err)
{
    return ulam_rad_final_some(t, opts, pilot, share, NULL, B, se, half, info, err);
}

/* The wanted patches' radiosity by final gathering over a shooting pilot. */
int ulam_rad_final_some(const ulam_tracer *t, const ulam_rad_opts *opts, int64_t pilot, double share,
                        const unsigned char *want, double *B, double *se, double *half, ulam_rad_final_info *info,
                        ulam_error *err)
{
    ulam_rad_final_info in;
    memset(&in, 0, sizeof in);
    if (!t || !opts || !B || !se || !half || pilot < 0 || !(share > 0 && share <= 1))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, options, B, se and half, pilot >= 0 and share in (0, 1]");
    if (!(opts->stop.rel_err >= 0) || opts->stop.max_walks < 0 || !(opts->stop.max_seconds >= 0))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "rel_err >= 0, max_walks >= 0, max_seconds >= 0");
    double t0 = ulam_now();
    final_ctx x = {.t = t, .s = ulam__tracer_scene(t)};
    const ulam_scene *s = x.s;
    int64_t n = s->npatches;
    if (ulam__lights_build(s, &x.L)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the emitters");
    if (x.L.nem == 0) {
        ulam__lights_free(&x.L);
        return ulam__fail(err, ULAM_EUNDEFINED, 0, -1, "an emitting patch (Ke > 0) to shoot from");
    }
    if (pilot == 0) pilot = n * 4 > 65536 ? n * 4 : 65536;
    x.eidx = ulam__malloc((size_t)n, sizeof *x.eidx);
    x.R = ulam__malloc((size_t)ULAM__FINAL_GROUPS * (size_t)(3 * n), sizeof *x.R);
    x.power = ulam__malloc((size_t)x.L.nem, sizeof *x.power);
    x.ec = ulam__malloc((size_t)(4 * x.L.nem), sizeof *x.ec);
    final_acc *acc = ulam__calloc((size_t)n, sizeof *acc);
    int status = x.eidx && x.R && x.power && x.ec && acc ? ULAM_OK
                                                         : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the gather");
    if (!status) {
        for (int64_t p = 0; p < n; p++) x.eidx[p] = -1;
        for (int64_t k = 0; k < x.L.nem; k++) {
            int64_t l = x.L.emitter[k];
            x.eidx[l] = (int32_t)k;
            x.power[k] = s->area[l] * (s->emit[3 * l] + s->emit[3 * l + 1] + s->emit[3 * l + 2]);
            x.ec[4 * k + 3] = patch_ball(s, l, x.ec + 4 * k);
        }
        double budget = opts->stop.max_seconds;
        status = final_pilot(&x, opts, pilot, budget > 0 ? budget / 4 : 0.0, &in, err);
    }
    in.pilot_seconds = ulam_now() - t0;
    double E = opts->stop.rel_err;
    int64_t cap = opts->stop.max_walks > 0 ? opts->stop.max_walks : E > 0 ? 1000000 : ULAM__FINAL_K0;
    int threads = ulam__threads(opts->exec.threads), stop = in.interrupted, active = 1;
    for (int64_t upto = E > 0 ? ULAM__FINAL_K0 : cap; !status && !stop && active; upto *= 4) {
        int nomem = 0;
        active = 0;
        if (upto > cap) upto = cap;
#pragma omp parallel num_threads(threads) if (threads > 1)
        {
            double *pi = malloc((size_t)x.L.nem * sizeof *pi), *cdf = malloc((size_t)x.L.nem * sizeof *cdf);
            if (!pi || !cdf) {
#pragma omp atomic write
                nomem = 1;
            }
#pragma omp for schedule(dynamic, 16)
            for (int64_t p = 0; p < n; p++) {
                int halt;
#pragma omp atomic read
                halt = stop;
                final_acc *a = &acc[p];
                if (halt || nomem || a->state == 2 || (want && !want[p])) continue;
                if (a->state == 0) {
                    ulam_rng_seed(&a->r, ulam_rng_substream(opts->exec.seed, ULAM_STREAM_POINT, (uint64_t)p), 0);
                    a->state = ulam__max3(s->rho + 3 * p) == 0.0 ? 2 : 1; /* rho 0: B = E exactly */
                    if (a->state == 2) continue;
                    final_cap(&x, p, a, E > 0 && cap > ULAM__FINAL_KPLAN ? ULAM__FINAL_KPLAN : (double)cap);
                }
                final_table(&x, p, pi, cdf, a);
                final_run(&x, p, pi, cdf, a, upto, E, cap);
                if (a->k >= cap) a->state = 2;
                if (a->state == 1) {
#pragma omp atomic write
                    active = 1;
                }
                if ((opts->stop.interrupt && *opts->stop.interrupt) ||
                    (opts->stop.max_seconds > 0 && ulam_now() - t0 > opts->stop.max_seconds)) {
#pragma omp atomic write
                    stop = 1;
                }
            }
            free(pi), free(cdf);
        }
        if (nomem) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the gather");
        if (upto == cap) break;
    }
    in.interrupted |= stop && opts->stop.interrupt && *opts->stop.interrupt; /* Ctrl-C; max_seconds is a rule */
    for (int64_t p = 0; p < n && !status; p++) {
        const final_acc *a = &acc[p];
        in.samples += a->k, in.rays += a->rays;
        for (int c = 0; c < 3; c++) {
            int64_t j = 3 * p + c;
            if (a->state == 0) B[j] = se[j] = half[j] = NAN; /* not reached before the stop */
            else if (a->k == 0) B[j] = s->emit[j], se[j] = half[j] = 0.0;
            else final_estimate(a, c, s->emit[j], &B[j], &se[j], &half[j], NULL);
        }
        in.gathered += a->k > 0;
    }
    if (!status) {
        final_rule(s, want, B, se, half, E, share, &in.scene, in.unreached);
        in.met = E > 0 && in.scene.met_area >= share * in.scene.lit_area * (1.0 - 1e-12) && in.scene.lit > 0;
    }
    in.seconds = ulam_now() - t0;
    in.threads = threads;
    if (info) *info = in;
    ulam__lights_free(&x.L);
    free(x.eidx), free(x.R), free(x.power), free(x.ec), free(x.bright), free(x.btop), free(x.bball), free(acc);
    return status;
}
