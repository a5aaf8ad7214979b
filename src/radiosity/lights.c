/* Next-event estimation: the emitters as a light source to sample (an emitter l in proportion
 * to its power A_l sum_c E_lc, a uniform point y on it: area density p_L(y) = sum_c E_lc / P,
 * P the total), the shadow ray from a point x to y, and the weights that combine a light
 * sample with a walk's own cosine ray that lands on an emitter (area density
 * p_C(y) = G(x, y) = cos cos_l / (pi r^2)) by multiple importance sampling: Veach's power
 * heuristic (exponent 2), the balance heuristic, or light sampling alone.  Used by the patch
 * walks (x uniform on a patch) and the point walks (x the point itself). */
#include "rad.h"

#include <stdlib.h>

/* Free the table's arrays (the struct itself is the caller's). */
void ulam__lights_free(ulam__lights *L)
{
    free(L->emitter), free(L->cdf), free(L->group);
    L->emitter = NULL, L->cdf = NULL, L->group = NULL, L->nem = 0, L->ngroups = 0, L->ptot = 0.0;
}

/* Group of emitter l in L (merged 0: the one of its emission and normal; 1: of its normal and
 * power bucket; 2: of its power bucket), made when new; -1 no memory. */
static int64_t group_of(const ulam_scene *s, ulam__lights *L, int64_t l, int merged)
{
    const double *E = s->emit + 3 * l, *n = s->normal + 3 * l;
    double S = E[0] + E[1] + E[2];
    int bucket = merged ? ilogb(S) : 0;
    int64_t g = 0;
    while (g < L->ngroups &&
           !((merged ? L->group[g].bucket == bucket
                     : L->group[g].E[0] == E[0] && L->group[g].E[1] == E[1] && L->group[g].E[2] == E[2]) &&
             (merged == 2 ||
              fabs(L->group[g].n[0] - n[0]) + fabs(L->group[g].n[1] - n[1]) + fabs(L->group[g].n[2] - n[2]) < 1e-9)))
        g++;
    if (g == L->ngroups) {
        ulam__light_group *G = realloc(L->group, (size_t)(g + 1) * sizeof *G);
        if (!G) return -1;
        L->group = G, L->ngroups = g + 1;
        for (int c = 0; c < 3; c++)
            G[g].E[c] = E[c], G[g].n[c] = n[c], G[g].lo[c] = INFINITY, G[g].hi[c] = -INFINITY, G[g].chroma[c] = E[c] / S;
        G[g].smin = G[g].smax = S, G[g].merged = merged, G[g].bucket = bucket;
    }
    ulam__light_group *G = L->group + g;
    for (int c = 0; c < 3; c++) G->E[c] = fmax(G->E[c], E[c]), G->chroma[c] = fmax(G->chroma[c], E[c] / S);
    G->smin = fmin(G->smin, S), G->smax = fmax(G->smax, S);
    return g;
}

/* The emitters' groups (group_of: by emission and normal; by normal and power once there are more
 * than ULAM__LIGHT_GROUPS_EXACT; by power alone past 4 times that, many normals) and their boxes;
 * ULAM_OK or ULAM_ENOMEM. */
static int group(const ulam_scene *s, ulam__lights *L)
{
    for (int merged = 0; merged < 3; merged++) {
        int64_t cap = merged == 0 ? ULAM__LIGHT_GROUPS_EXACT : merged == 1 ? 4 * ULAM__LIGHT_GROUPS_EXACT : INT64_MAX;
        free(L->group), L->group = NULL, L->ngroups = 0;
        int64_t k = 0;
        for (; k < L->nem && L->ngroups <= cap; k++) {
            int64_t l = L->emitter[k], g = group_of(s, L, l, merged);
            if (g < 0) {
                ulam__lights_free(L);
                return ULAM_ENOMEM;
            }
            for (int64_t j = s->start[l]; j < s->start[l + 1]; j++)
                for (int c = 0; c < 3; c++) {
                    double v = s->vert[3 * s->vidx[j] + c];
                    L->group[g].lo[c] = fmin(L->group[g].lo[c], v), L->group[g].hi[c] = fmax(L->group[g].hi[c], v);
                }
        }
        if (L->ngroups <= cap) break;
    }
    return ULAM_OK;
}

/* The emitters of s and their cumulative power (channel sums); ULAM_OK or ULAM_ENOMEM. */
int ulam__lights_build(const ulam_scene *s, ulam__lights *L)
{
    int64_t n = s->npatches;
    L->nem = 0, L->ptot = 0.0;
    L->emitter = ulam__malloc((size_t)n, sizeof *L->emitter);
    L->cdf = ulam__malloc((size_t)n, sizeof *L->cdf);
    if (!L->emitter || !L->cdf) {
        ulam__lights_free(L);
        return ULAM_ENOMEM;
    }
    for (int64_t p = 0; p < n; p++) {
        const double *E = s->emit + 3 * p;
        double phi = s->area[p] * (E[0] + E[1] + E[2]);
        if (phi > 0) {
            L->ptot += phi;
            L->emitter[L->nem] = p;
            L->cdf[L->nem++] = L->ptot;
        }
    }
    return group(s, L);
}

/* The emitter drawn in proportion to power from u in [0, 1). */
int64_t ulam__lights_pick(const ulam__lights *L, double u)
{
    int64_t lo = 0, hi = L->nem - 1;
    u *= L->ptot;
    while (lo < hi) { /* the first emitter whose cumulative power exceeds u */
        int64_t mid = lo + (hi - lo) / 2;
        if (L->cdf[mid] > u) hi = mid;
        else lo = mid + 1;
    }
    return L->emitter[lo];
}

/* The weight of a strategy of density a against the other's b: the power heuristic (exponent 2),
 * the balance heuristic, or for light sampling alone 1 (light) and 0 (the walk's hit); collision
 * (the walk's hits alone) the reverse.  In the ratio form a density a = inf gets weight 1. */
static double ulam__mis_weight(int estimator, double a, double b, int light)
{
    if (estimator == ULAM_RAD_NEXT_EVENT_LIGHT) return light ? 1.0 : 0.0;
    if (estimator == ULAM_RAD_COLLISION) return light ? 0.0 : 1.0;
    double r = b / a;
    return estimator == ULAM_RAD_NEXT_EVENT_BALANCE ? 1.0 / (1.0 + r) : 1.0 / (1.0 + r * r);
}

/* A light sample at x (unit normal n, on patch self or -1) toward emitter l (drawn by
 * ulam__lights_pick): a uniform point y of l, and W E_l G / p_L w_L added to score when y is
 * seen; returns the shadow rays cast (0 or 1). */
int ulam__lights_score(const ulam_tracer *t, const ulam__lights *L, int estimator, int64_t l, const double x[3],
                       const double n[3], int64_t self, const double W[3], ulam_rng *r, double score[3])
{
    const ulam_scene *s = ulam__tracer_scene(t);
    double y[3];
    ulam__tracer_point(t, l, r, y);
    ulam__hit h;
    int seen = ulam__tracer_sees_from(t, x, n, self, l, y, &h);
    int cast = h.cos_from > 0 && h.cos_to > 0 && self != l;
    if (!seen) return cast;
    const double *E = s->emit + 3 * l;
    double pl = (E[0] + E[1] + E[2]) / L->ptot, G = h.cos_from * h.cos_to / (M_PI * h.dist * h.dist);
    double f = G / pl * ulam__mis_weight(estimator, pl, G, 1);
    for (int c = 0; c < 3; c++) score[c] += W[c] * E[c] * f;
    return cast;
}

/* The weight of a walk's cosine ray that landed (h) on emitter j, against light sampling. */
double ulam__lights_hit_weight(const ulam__lights *L, const ulam_scene *s, int estimator, int64_t j,
                               const ulam__hit *h)
{
    const double *E = s->emit + 3 * j;
    double pc = h->cos_from * h->cos_to / (M_PI * h->dist * h->dist);
    return ulam__mis_weight(estimator, pc, (E[0] + E[1] + E[2]) / L->ptot, 0);
}

/* The least and largest v . u over the vertices of patch p (or, p < 0, the one point pt). */
static void project(const ulam_scene *s, int64_t p, const double *pt, const double u[3], double *lo, double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    int64_t a = p < 0 ? 0 : s->start[p], b = p < 0 ? 1 : s->start[p + 1];
    for (int64_t k = a; k < b; k++) {
        double d = ulam__dot3(p < 0 ? pt : s->vert + 3 * s->vidx[k], u);
        *lo = fmin(*lo, d), *hi = fmax(*hi, d);
    }
}

/* The least and largest v . u over the box of group G. */
static void project_box(const ulam__light_group *G, const double u[3], double *lo, double *hi)
{
    double c = 0.0, h = 0.0;
    for (int i = 0; i < 3; i++) c += 0.5 * (G->lo[i] + G->hi[i]) * u[i], h += 0.5 * (G->hi[i] - G->lo[i]) * fabs(u[i]);
    *lo = c - h, *hi = c + h;
}

/* An upper bound on G(x, y) = cos cos_y / (pi r^2) over x on patch p (or, p < 0, the point pt
 * with normal n) and y on an emitter of group G (within its box, facing along its normal), both
 * facing each other: 0 when the box lies wholly on or behind x's plane or x's patch wholly on or
 * behind the emitters' plane (no pair faces); else, for d > 0 a lower bound on their distance
 * r (the widest gap along x's normal, against the emitters' normal, along the line between the
 * centres: separating axes of convex sets; and the least |v| with v . n >= the first gap and
 * v . (-n_l) >= the second, both positive, which is sqrt((a^2 + b^2 - 2 c a b) / (1 - c^2)),
 * c = -n . n_l, where both of its Lagrange multipliers are >= 0),
 * min(1, A / d) min(1, B / d) / (pi d^2), A and B the largest distances of y from x's plane
 * and of x from the emitters' plane: cos = (y - x) . n / r <= A / r, cos_y <= B / r, each <= 1,
 * and that bound falls with r >= d; INFINITY without such a d. */
static double g_max(const ulam_scene *s, int64_t p, const double *pt, const double n[3], const ulam__light_group *G)
{
    double lo_p, hi_p, lo_l, hi_l, cp[3] = {0, 0, 0}, u[3], size = 0.0; /* the box's diagonal: the scene's unit */
    for (int i = 0; i < 3; i++) size += (G->hi[i] - G->lo[i]) * (G->hi[i] - G->lo[i]);
    size = sqrt(size);
    project(s, p, pt, n, &lo_p, &hi_p);
    project_box(G, n, &lo_l, &hi_l);
    if (hi_l - lo_p <= 1e-12 * (fmax(fabs(lo_p), fabs(hi_l)) + size)) return 0.0; /* on or behind x's plane */
    double gx = lo_l - hi_p, A = hi_l - lo_p;
    project(s, p, pt, G->n, &lo_p, &hi_p);
    project_box(G, G->n, &lo_l, &hi_l);
    if (hi_p - lo_l <= 1e-12 * (fmax(fabs(hi_p), fabs(lo_l)) + size)) return 0.0; /* x behind the emitters' plane */
    double gl = lo_p - hi_l, B = hi_p - lo_l, gap = fmax(gx, gl); /* gl along -n_l */
    double c = -ulam__dot3(n, G->n);
    if (gx > 0 && gl > 0 && fabs(c) < 1.0 - 1e-9 && gx - c * gl >= 0 && gl - c * gx >= 0)
        gap = fmax(gap, sqrt(fmax(0.0, (gx * gx + gl * gl - 2.0 * c * gx * gl) / (1.0 - c * c))) * (1.0 - 1e-12));
    int64_t a = p < 0 ? 0 : s->start[p], b = p < 0 ? 1 : s->start[p + 1];
    for (int64_t k = a; k < b; k++)
        for (int i = 0; i < 3; i++) cp[i] += (p < 0 ? pt : s->vert + 3 * s->vidx[k])[i] / (double)(b - a);
    for (int i = 0; i < 3; i++) u[i] = 0.5 * (G->lo[i] + G->hi[i]) - cp[i];
    double len = sqrt(ulam__dot3(u, u));
    if (len > 0) {
        for (int i = 0; i < 3; i++) u[i] /= len;
        project(s, p, pt, u, &lo_p, &hi_p);
        project_box(G, u, &lo_l, &hi_l);
        gap = fmax(gap, lo_l - hi_p);
    }
    if (!(gap > 0)) return INFINITY;
    return fmin(1.0, A / gap) * fmin(1.0, B / gap) / (M_PI * gap * gap);
}

/* The most one light sample (light) or one landing of the walk's cosine ray on an emitter
 * (!light) can score per unit of W E_l, for area densities p_L = pl and p_C = G <= gmax: the
 * light sample scores G / pl w_L (the balance heuristic's and light sampling's rise with G; the
 * power heuristic's G pl / (pl^2 + G^2) peaks at G = pl), the landing w_C (rising with G). */
static double score_factor(int estimator, double pl, double gmax, int light)
{
    if (gmax == 0.0) return 0.0;
    if (!light) return ulam__mis_weight(estimator, gmax, pl, 0);
    if (estimator == ULAM_RAD_COLLISION) return 0.0;
    if (!isfinite(gmax)) return estimator == ULAM_RAD_NEXT_EVENT_LIGHT ? INFINITY : estimator == ULAM_RAD_NEXT_EVENT ? 0.5 : 1.0;
    double g = estimator == ULAM_RAD_NEXT_EVENT ? fmin(gmax, pl) : gmax;
    return g / pl * ulam__mis_weight(estimator, pl, g, 1);
}

/* Certified bounds, per channel and per unit of weight W, on one vertex of a next-event walk at
 * patch p (or, p < 0, the point pt with normal n): light, the largest light sample (before any
 * reflectance), and hit, the largest landing of the vertex's cosine ray on an emitter, weighted
 * against light sampling; over every group of emitters (score_factor at g_max).  INFINITY
 * where light sampling alone meets an emitter it may touch (1 / r^2 unbounded). */
void ulam__lights_vertex_parts(const ulam__lights *L, const ulam_scene *s, int estimator, int64_t p, const double *pt,
                               const double n[3], double light[3], double hit[3])
{
    for (int c = 0; c < 3; c++) light[c] = hit[c] = 0.0;
    for (int64_t k = 0; k < L->ngroups; k++) {
        const ulam__light_group *G = &L->group[k];
        const double *E = G->E;
        double g = G->merged == 2 ? INFINITY : g_max(s, p, pt, n, G); /* many normals: no geometry bound */
        if (!G->merged) {
            double pl = (E[0] + E[1] + E[2]) / L->ptot;
            double fl = score_factor(estimator, pl, g, 1), fh = score_factor(estimator, pl, g, 0);
            for (int c = 0; c < 3; c++) light[c] = fmax(light[c], E[c] * fl), hit[c] = fmax(hit[c], E[c] * fh);
            continue;
        }
        /* a merged group: a member of power S (chroma_c S in channel c, pl = S / ptot) scores at
         * most chroma_c S score_factor(S / ptot) by light sampling, which rises with S under every
         * heuristic (power: ptot g' pl^2 / (pl^2 + g'^2), g' = min(gmax, pl); balance: ptot g pl /
         * (pl + g); light alone: ptot g), so smax bounds it; and at most E_c w_C(gmax, pl) by a
         * landing, w_C falling with pl, so the largest E_c and smin bound it */
        double fl = score_factor(estimator, G->smax / L->ptot, g, 1), fh = score_factor(estimator, G->smin / L->ptot, g, 0);
        for (int c = 0; c < 3; c++)
            light[c] = fmax(light[c], G->chroma[c] * G->smax * fl), hit[c] = fmax(hit[c], E[c] * fh);
    }
}

/* A certified bound, per channel, on what one vertex of a next-event walk at patch p (or, p < 0,
 * the point pt with normal n) scores with weights W <= 1: rho_pc (1 at the point or with
 * reflect 0) times the largest light sample plus the largest weighted landing on an emitter
 * (ulam__lights_vertex_parts). */
void ulam__lights_vertex_bound(const ulam__lights *L, const ulam_scene *s, int estimator, int64_t p, const double *pt,
                               const double n[3], int reflect, double out[3])
{
    double lmax[3], hmax[3];
    ulam__lights_vertex_parts(L, s, estimator, p, pt, n, lmax, hmax);
    for (int c = 0; c < 3; c++) out[c] = (reflect && p >= 0 ? s->rho[3 * p + c] : 1.0) * lmax[c] + hmax[c];
}
