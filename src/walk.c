/* Adjoint and forward random walks, their estimators, Russian roulette and splitting.
 *
 * Adjoint (one x_i): start at i with weight 1 (or at j ~ |c_j| / ||c||_1 with weight
 * sign(c_j) ||c||_1 for <c, x>).  Collision scores sum_m w_m b_{i_m} over every
 * visited state; absorption scores w_k b_{i_k} / p*_{i_k} where the walk ends; expected scores
 * b_i + sum_m w_m (M b)_{i_m}, the exact expectation of the next step's score.  The kernel
 * keeps these per-state scores in its row headers (visit and end), so one loop serves all
 * three; a walker enters a row (building it on the first visit) before it reads it.
 * Forward (every x_i): a source j ~ |b_j| / ||b||_1 with weight ||b||_1 sign(b_j), steps on the
 * kernel of M'; collision tallies w at every visited state, absorption w / p* where the walk
 * ends, expected w M_{k s} at every neighbour k of each visited state s (plus b, added later).
 * The weight window: below `roulette` a particle survives with probability |w| / W at weight
 * W; above `split` it becomes ceil(|w| / W) copies of w / copies.  Both keep every estimator
 * unbiased.
 *
 * Adjoint histories run w->lanes at a time, interleaved: each pass first draws every lane's
 * alias slot (and prefetches it), then reads every lane's slot and moves (prefetching the
 * next row), so the memory latency of one lane's step hides behind the others' work.  Lanes
 * share the block's generator in a fixed order, so a block's result does not depend on
 * timing. */
#include "walk.h"

#include <math.h>
#include <stdlib.h>

enum { LANES = 32 }; /* at most; the solver picks 16 for kernels that fit in cache */

/* The walk loops are compiled twice, for the kernel's per-row factor (exponent 1, fac NULL) and
 * for per-move factors, so the common case pays nothing for the other. */
#if defined(__GNUC__)
#define WALK_INLINE __attribute__((always_inline)) inline
#else
#define WALK_INLINE inline
#endif

/* Ask for the cache line at p ahead of its use. */
static inline void prefetch(const void *p)
{
#if defined(__GNUC__)
    __builtin_prefetch(p, 0, 3);
#else
    (void)p;
#endif
}

/* A particle stack: one lane's share of the scratch stacks. */
typedef struct {
    int32_t *s;
    double *w;
    int64_t top, cap;
} stack;

/* The weight window after a move to row u; 0 when roulette killed the particle. */
static int window(const ulam__walker *w, int32_t u, double *wt, ulam_rng *r, stack *st)
{
    double a = fabs(*wt);
    if (w->roulette > 0 && a < w->roulette) {
        if (ulam__rng_uniform(r) * w->roulette >= a) return 0;
        *wt = copysign(w->roulette, *wt);
    } else if (w->split > 0 && a > w->split) {
        double want = ceil(a / w->split);
        int64_t room = st->cap - st->top + 1;
        int64_t m = want < (double)room ? (int64_t)want : room;
        if (m > 1) {
            *wt /= (double)m;
            for (int64_t c = 1; c < m; c++) {
                st->s[st->top] = u;
                st->w[st->top++] = *wt;
            }
        }
    }
    return 1;
}

/* Take the move to outcome o (read from the alias slot s) with weight factor f: the weight gets the
 * factor and the move's sign; returns the target row's unit. */
static inline int32_t target(ulam_kernel *k, ulam__slot *s, uint64_t frac, int32_t o, double f, double *wt,
                             ulam__kscratch *ks)
{
    *wt *= o < 0 ? -f : f;
    return ulam__kernel_target(k, s, frac, o, ks);
}

/* One adjoint lane: the particle it carries and its history so far. */
typedef struct {
    ulam__row *h;  /* the particle's row */
    ulam__slot *s; /* the slot drawn for its next step */
    uint64_t frac;
    double w, score;
    double part; /* the score over its first w->part_steps visits, NAN until it has made them */
    int64_t len; /* steps in this history */
    int64_t id;  /* the history's start order in its block */
    stack st;
} lane;

/* Start a new history in lane x: at the start, or at one drawn from the start distribution
 * (with its signed weight). */
static void lane_start(const ulam__walker *w, lane *x, ulam_rng *r)
{
    x->h = ulam__kernel_row(w->k, w->start);
    x->w = 1.0;
    x->score = w->score0;
    if (w->nstarts > 0) {
        uint64_t frac;
        ulam__slot *sl = w->start_src + ulam__rng_index(r, (uint64_t)w->nstarts, &frac); /* sets frac first */
        int32_t o = ulam__slot_outcome(sl, frac);
        int32_t j = ulam__outcome_target(o);
        x->h = ulam__kernel_row(w->k, w->start_units[j]);
        x->w = o < 0 ? -w->start_norm : w->start_norm;
        x->score = x->w * w->start_b[j];
    }
    x->part = NAN;
    x->len = 0;
    x->st.top = 0;
}

/* Lane x's particle has ended: 1 if another of its history's particles is waiting. */
static int lane_pop(const ulam__walker *w, lane *x)
{
    if (x->st.top == 0) return 0;
    x->st.top--;
    x->h = ulam__kernel_row(w->k, x->st.s[x->st.top]);
    x->w = x->st.w[x->st.top];
    prefetch(x->h);
    return 1;
}

/* What every step reads of the walker, copied into the block's locals: the outcomes are read
 * with acquire (a row a walk resolves may have been built by another thread), which forbids the
 * compiler to keep values it loaded from shared memory across them, so reading these through
 * the walker would reload them on every step. */
typedef struct {
    ulam__slot *mem;
    double (*fac)[2]; /* the moves' own factors (kernel exponent != 1), or NULL */
    int64_t max_steps;
    int64_t part_steps; /* the walker's */
    int window; /* roulette or splitting in force */
} step_consts;

/* Lane x's step: 1 while its particle lives on. */
static WALK_INLINE int lane_move(const ulam__walker *w, step_consts c, lane *x, ulam_rng *r, ulam__kscratch *ks,
                            ulam__block *out)
{
    int32_t o = ulam__slot_outcome(x->s, x->frac);
    if (o == ULAM__TERMINATE) {
        x->score += x->w * x->h->end;
        return 0;
    }
    int32_t u = target(w->k, x->s, x->frac, o, ulam__move_weight(c.fac, c.mem, x->h, x->s, x->frac), &x->w, ks);
    x->h = (ulam__row *)(void *)(c.mem + u);
    prefetch(x->h);
    out->steps++;
    if (++x->len > c.max_steps) { /* cut: the rest of the history is dropped */
        out->cut++;
        x->st.top = 0;
        return 0;
    }
    return !c.window || window(w, u, &x->w, r, &x->st);
}

/* x clipped to [-c, c] (c > 0), else x. */
static WALK_INLINE double clip(double x, double c)
{
    return c > 0 ? fmax(-c, fmin(c, x)) : x;
}

/* The part of a block that history id (in start order) counts in. */
static inline int sub_of(int64_t id)
{
    return id / ULAM__SUB_WALKS < ULAM__SUBS ? (int)(id / ULAM__SUB_WALKS) : ULAM__SUBS - 1;
}

/* Record history id's score (a non-finite one is counted, never averaged); the clipped moments
 * take part in its place when it is not NAN (w->part_steps: the history made that many visits). */
static void record(const ulam__walker *w, ulam__block *out, double score, double part, int64_t id)
{
    if (isfinite(score)) {
        double c = clip(isnan(part) ? score : part, w->clip);
        ulam__moments_add(&out->m, score);
        ulam__moments_add(&out->clipped, c);
        if (w->clip > 0) ulam__moments_add(&out->sub[sub_of(id)], c);
        out->maxsq = fmax(out->maxsq, score * score);
    } else {
        out->h.nonfinite++;
    }
    out->h.walks++;
}

/* Run count adjoint histories, w->lanes at a time, counting into a local block (the caller's
 * blocks sit side by side in memory, and writing them on every step would share cache lines
 * between threads); fac: the kernel's per-move factors or NULL. */
static WALK_INLINE void adjoint_lanes(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                                      ulam__block *out, double (*fac)[2])
{
    ulam__block acc = {.h = {.tally = out->h.tally, .cap = out->h.cap}};
    lane L[LANES];
    int lanes = w->lanes < 1 ? 1 : w->lanes > LANES ? LANES : w->lanes;
    int64_t cap = sc->stack_cap / lanes, started = 0;
    int act = 0;
    const step_consts c = {w->k->mem, fac, w->max_steps, w->part_steps, w->roulette > 0 || w->split > 0};
    for (; act < lanes && started < count; act++, started++) {
        L[act].st = (stack){sc->stack_s + act * cap, sc->stack_w + act * cap, 0, cap};
        lane_start(w, &L[act], r);
        L[act].id = started;
    }
    while (act > 0) {
        for (int l = 0; l < act; l++) {
            lane *x = &L[l];
            x->score += x->w * x->h->visit;
            if (x->len + 1 == c.part_steps) x->part = x->score; /* the first part_steps visits */
            x->s = ulam__kernel_pick(x->h, r, &x->frac);
            prefetch(x->s);
        }
        for (int l = 0; l < act;) {
            lane *x = &L[l];
            if (lane_move(w, c, x, r, sc->ks, &acc) || lane_pop(w, x)) {
                l++;
                continue;
            }
            record(w, &acc, x->score, x->part, x->id);
            if (started < count) {
                if ((started & 63) == 0 && w->interrupt && *w->interrupt) break;
                lane_start(w, x, r);
                x->id = started++;
                l++;
            } else {
                stack keep = x->st; /* the lane that moves in brings its own stack */
                *x = L[--act];
                L[act].st = keep;
            }
        }
        if (started < count && w->interrupt && *w->interrupt) break;
    }
    acc.h.complete = act == 0;
    *out = acc;
}

/* Run count adjoint histories (see adjoint_lanes). */
void ulam__adjoint_block(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                         ulam__block *out)
{
    if (w->k->fac) adjoint_lanes(w, count, r, sc, out, w->k->fac);
    else adjoint_lanes(w, count, r, sc, out, NULL);
}

/* Add v to state s's tally for this history. */
static WALK_INLINE void tally(ulam__scratch *sc, int32_t s, double v)
{
    if (!sc->mark[s]) {
        sc->mark[s] = 1;
        sc->touched[sc->ntouched++] = s;
    }
    sc->hist[s] += v;
}

/* Add this history's tallies to the block's sums (and the watched component's moments) and
 * clear them. */
static WALK_INLINE void emit(const ulam__walker *w, ulam__scratch *sc, ulam__block *out)
{
    for (int64_t q = 0; q < sc->ntouched; q++) {
        int64_t s = sc->touched[q];
        double v = sc->hist[s];
        if (!sc->bmark[s]) {
            sc->bmark[s] = 1;
            sc->btouched[sc->nbtouched++] = s;
        }
        sc->bsum[s] += v, sc->bsq[s] += v * v;
        if (s == w->watch) {
            ulam__moments_add(&out->watched, v), ulam__moments_add(&out->clipped, clip(v, w->clip)),
                out->maxsq = fmax(out->maxsq, v * v);
            if (w->clip > 0) ulam__moments_add(&out->sub[sub_of(out->h.walks - 1)], clip(v, w->clip)); /* one at a time */
        }
        sc->hist[s] = 0.0;
        sc->mark[s] = 0;
    }
    sc->ntouched = 0;
}

/* Move the block's sums to its tally list (one per state reached) and clear them. */
static int flush(ulam__scratch *sc, ulam__block_head *out)
{
    int st = ulam__grow(&out->tally, &out->cap, out->len + sc->nbtouched, sizeof(ulam__tally)) ? ULAM_ENOMEM : ULAM_OK;
    ulam__tally *t = out->tally;
    for (int64_t q = 0; q < sc->nbtouched; q++) {
        int64_t s = sc->btouched[q];
        if (!st) t[out->len++] = (ulam__tally){(int32_t)s, sc->bsum[s], sc->bsq[s]};
        sc->bsum[s] = sc->bsq[s] = 0.0;
        sc->bmark[s] = 0;
    }
    sc->nbtouched = 0;
    return st;
}

/* Tally a visit to row h with weight wt. */
static WALK_INLINE void forward_visit(const ulam__walker *w, ulam__scratch *sc, const ulam__row *h, double wt)
{
    if (h->visit != 0.0) tally(sc, h->state, wt * h->visit);
    if (w->expected)
        for (int64_t q = w->mt->rowptr[h->state]; q < w->mt->rowptr[h->state + 1]; q++)
            tally(sc, w->mt->colidx[q], wt * w->mt->val[q]);
}

/* One forward history: its tallies go to the block's sums (emit); fac: the kernel's per-move
 * factors or NULL. */
static WALK_INLINE void forward_history(const ulam__walker *w, ulam_rng *r, ulam__scratch *sc, ulam__block *out,
                                   double (*fac)[2])
{
    ulam_kernel *k = w->k;
    ulam__slot *mem = k->mem; /* a local: see step_consts */
    uint64_t frac;
    ulam__slot *src = w->src + ulam__rng_index(r, (uint64_t)k->n, &frac);
    int32_t o = ulam__slot_outcome(src, frac);
    stack st = {sc->stack_s, sc->stack_w, 1, sc->stack_cap};
    st.s[0] = ulam__kernel_unit(k, ulam__outcome_target(o), sc->ks);
    st.w[0] = o < 0 ? -w->bnorm1 : w->bnorm1;
    int64_t len = 0;
    while (st.top > 0) {
        st.top--;
        ulam__row *h = ulam__kernel_row(k, st.s[st.top]);
        double wt = st.w[st.top];
        for (;;) {
            forward_visit(w, sc, h, wt);
            ulam__slot *sl = ulam__kernel_pick(h, r, &frac); /* sets frac */
            o = ulam__slot_outcome(sl, frac);
            if (o == ULAM__TERMINATE) {
                if (h->end != 0.0) tally(sc, h->state, wt * h->end);
                break;
            }
            int32_t u = target(k, sl, frac, o, ulam__move_weight(fac, mem, h, sl, frac), &wt, sc->ks);
            h = ulam__kernel_row(k, u);
            out->steps++;
            if (++len > w->max_steps || !isfinite(wt)) {
                out->cut += len > w->max_steps;
                out->h.nonfinite += !isfinite(wt);
                st.top = 0;
                break;
            }
            if (!window(w, u, &wt, r, &st)) break;
        }
    }
    out->h.walks++;
    emit(w, sc, out);
}

/* Run count forward histories, one at a time, counting into a local block. */
void ulam__forward_block(const ulam__walker *w, int64_t count, ulam_rng *r, ulam__scratch *sc,
                         ulam__block *out)
{
    ulam__block acc = {.h = {.tally = out->h.tally, .cap = out->h.cap}};
    int64_t c = 0;
    for (; c < count; c++) {
        if (w->k->fac) forward_history(w, r, sc, &acc, w->k->fac);
        else forward_history(w, r, sc, &acc, NULL);
        if ((c & 63) == 63 && w->interrupt && *w->interrupt) break;
    }
    acc.h.nomem = flush(sc, &acc.h) != ULAM_OK; /* out of memory: the run must fail, not stop short */
    acc.h.complete = c == count && !acc.h.nomem;
    *out = acc;
}
