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
    free(L->emitter), free(L->cdf);
    L->emitter = NULL, L->cdf = NULL, L->nem = 0, L->ptot = 0.0;
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
    return ULAM_OK;
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
double ulam__mis_weight(int estimator, double a, double b, int light)
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
