/* Adjoint and forward random walks, their estimators, Russian roulette and splitting.
 *
 * Adjoint (one x_i): start at i with weight 1.  Collision scores sum_m w_m b_{i_m} over every
 * visited state; absorption scores w_k b_{i_k} / p*_{i_k} where the walk ends; expected scores
 * b_i + sum_m w_m (M b)_{i_m}, the exact expectation of the next step's score.
 * Forward (every x_i): a source j ~ |b_j| / ||b||_1 with weight ||b||_1 sign(b_j), steps on the
 * kernel of M'; collision tallies w at every visited state, absorption w / p* where the walk
 * ends, expected w M_{k s} at every neighbour k of each visited state s (plus b, added later).
 * The weight window: below `roulette` a particle survives with probability |w| / W at weight
 * W; above `split` it becomes ceil(|w| / W) copies of w / copies.  Both keep every estimator
 * unbiased. */
#include "walk.h"

#include <math.h>
#include <stdlib.h>

/* Push a particle; the caller guarantees room. */
static void push(ulam__scratch *sc, int64_t *top, int32_t s, double wt)
{
    sc->stack_s[*top] = s;
    sc->stack_w[*top] = wt;
    (*top)++;
}

/* The weight window after a move; 0 when roulette killed the particle. */
static int window(const ulam__walker *w, int32_t s, double *wt, ulam_rng *r, ulam__scratch *sc,
                  int64_t *top)
{
    double a = fabs(*wt);
    if (w->roulette > 0 && a < w->roulette) {
        if (ulam_rng_uniform(r) * w->roulette >= a) return 0;
        *wt = copysign(w->roulette, *wt);
    } else if (w->split > 0 && a > w->split) {
        double want = ceil(a / w->split);
        int64_t room = sc->stack_cap - *top + 1;
        int64_t m = want < (double)room ? (int64_t)want : room;
        if (m > 1) {
            *wt /= (double)m;
            for (int64_t c = 1; c < m; c++) push(sc, top, s, *wt);
        }
    }
    return 1;
}

/* Move from s along outcome o: update weight and state. */
static inline int32_t move(const ulam_kernel *k, int32_t s, int32_t o, double *wt)
{
    *wt *= k->factor[s];
    if (o < 0) {
        *wt = -*wt;
        return ~o;
    }
    return o;
}

/* One adjoint history from start: its score. */
double ulam__adjoint_history(const ulam__walker *w, int64_t start, ulam_rng *r, ulam__scratch *sc,
                             ulam__history *h)
{
    const ulam_kernel *k = w->k;
    const double *b = w->b;
    double score = w->estimator == ULAM_EXPECTED ? b[start] : 0.0;
    int64_t top = 0, len = 0;
    push(sc, &top, (int32_t)start, 1.0);
    while (top > 0) {
        top--;
        int32_t s = sc->stack_s[top];
        double wt = sc->stack_w[top];
        for (;;) {
            if (w->estimator == ULAM_COLLISION) score += wt * b[s];
            else if (w->estimator == ULAM_EXPECTED) score += wt * w->mb[s];
            int32_t o = ulam__kernel_step(k, s, r);
            if (o == ULAM__TERMINATE) {
                if (w->estimator == ULAM_ABSORPTION) score += wt * b[s] / k->pstar[s];
                break;
            }
            s = move(k, s, o, &wt);
            h->steps++;
            if (++len > w->max_steps) {
                h->cut = 1;
                return score;
            }
            if (!isfinite(wt)) {
                h->nonfinite = 1;
                return score;
            }
            if (!window(w, s, &wt, r, sc, &top)) break;
        }
    }
    if (!isfinite(score)) h->nonfinite = 1;
    return score;
}

/* Add v to state s's tally for this history. */
static void tally(ulam__scratch *sc, int32_t s, double v)
{
    if (!sc->mark[s]) {
        sc->mark[s] = 1;
        sc->touched[sc->ntouched++] = s;
    }
    sc->hist[s] += v;
}

/* Move this history's tallies to out and clear them. */
static int emit(ulam__scratch *sc, ulam__tallies *out)
{
    if (out->len + sc->ntouched > out->cap) {
        int64_t cap = out->cap ? out->cap : 1024;
        while (cap < out->len + sc->ntouched) cap *= 2;
        ulam__tally *t = realloc(out->t, (size_t)cap * sizeof *t);
        if (!t) return ULAM_ENOMEM;
        out->t = t;
        out->cap = cap;
    }
    for (int64_t q = 0; q < sc->ntouched; q++) {
        int64_t s = sc->touched[q];
        out->t[out->len++] = (ulam__tally){(int32_t)s, sc->hist[s]};
        sc->hist[s] = 0.0;
        sc->mark[s] = 0;
    }
    sc->ntouched = 0;
    return ULAM_OK;
}

/* One forward history: appends its (state, tally) pairs to out. */
int ulam__forward_history(const ulam__walker *w, ulam_rng *r, ulam__scratch *sc, ulam__tallies *out,
                          ulam__history *h)
{
    const ulam_kernel *k = w->k;
    const ulam__slot *src = w->src + ulam_rng_bounded(r, (uint64_t)k->n);
    int32_t o = ulam_rng_uniform(r) < src->thresh ? src->a : src->b;
    int32_t s0 = o < 0 ? ~o : o;
    int64_t top = 0, len = 0;
    push(sc, &top, s0, o < 0 ? -w->bnorm1 : w->bnorm1);
    while (top > 0) {
        top--;
        int32_t s = sc->stack_s[top];
        double wt = sc->stack_w[top];
        for (;;) {
            if (w->estimator == ULAM_COLLISION) tally(sc, s, wt);
            else if (w->estimator == ULAM_EXPECTED)
                for (int64_t q = w->mt->rowptr[s]; q < w->mt->rowptr[s + 1]; q++)
                    tally(sc, w->mt->colidx[q], wt * w->mt->val[q]);
            o = ulam__kernel_step(k, s, r);
            if (o == ULAM__TERMINATE) {
                if (w->estimator == ULAM_ABSORPTION) tally(sc, s, wt / k->pstar[s]);
                break;
            }
            s = move(k, s, o, &wt);
            h->steps++;
            if (++len > w->max_steps) {
                h->cut = 1;
                top = 0;
                break;
            }
            if (!isfinite(wt)) {
                h->nonfinite = 1;
                top = 0;
                break;
            }
            if (!window(w, s, &wt, r, sc, &top)) break;
        }
    }
    return emit(sc, out);
}
