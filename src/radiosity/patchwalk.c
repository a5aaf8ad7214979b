/* Patch walks: the radiosity equation B = E + diag(rho) F B solved by walks that sample F by
 * casting rays, never forming it.
 *
 * Gathering (adjoint) estimates B_i: a walk starts at patch i with weight 1 per channel and
 * moves to the patch its cosine-distributed ray from a uniform point of its patch reaches
 * (probability F_pj); a ray that leaves the scene or hits a back side ends it.  Collision and
 * next-event walks are point.c's weight-window walks (gather_window): B_i = E_i + rho_i H,
 * H the walk's score from a uniform point of i, every landing moved to a uniform point of the
 * patch it reached, so that the score has point.c's finite certified range (ulam__point_range)
 * times rho_i.  Collision scores W E_j where the walk lands on an emitter j.  Absorption
 * (gather) continues at p with probability q_p = max_c rho_pc, its weights times rho_pc / q_p,
 * and scores W E_p / (1 - q_p) where the walk stops by its coin.
 *
 * Shooting (forward) estimates every patch's reflected power R = P - A E from P = A E +
 * diag(rho) F' P (by reciprocity): a particle leaves an emitter chosen in proportion to its
 * power with weight Phi E_c / sum_c E_c and always casts its first ray (emission is not
 * reflection: a black lamp shoots as well as a grey one).  At the patch j it reaches, j
 * reflects rho_jc W_c (collision tallies that; absorption tallies it / (1 - q_j) where the
 * particle stops), and the particle survives with q_j, its weights becoming rho_jc W_c / q_j.
 * Then B_j = E_j + R_j / A_j.
 *
 * Next-event gathering (ULAM_RAD_NEXT_EVENT*, the default) scores E_i at the start and, at every patch p a
 * walk visits, one light sample: a point y on an emitter l drawn with area density
 * p_L(y) = sum_c E_lc / P (P = sum_l A_l sum_c E_lc) and a uniform point x of p, scoring
 * W rho_p E_l G(x, y) / p_L(y) w_L with G = cos cos_l / (pi r^2) when the shadow ray sees y.
 * The walk's cosine ray from p that lands on an emitter j at y scores W' E_j w_C, where
 * p_C(y) = G(x, y) is the area density of that landing point.  w_L + w_C = 1 (power or
 * balance heuristic of p_L and p_C; w_L = 1, w_C = 0 for light sampling alone), so each
 * patch's direct term rho_p sum_j F_pj E_j is counted once in expectation; x is uniform on p
 * in both strategies, so the expectation is the patch-averaged F_pj (README).  The light
 * sampling and its weights are lights.c's.
 *
 * A point solver (ulam_rad_point_alloc) runs point.c's walks from one point of the continuous
 * surfaces instead, with the same rounds, statistics and stopping rules.
 *
 * As in ulam_solve_walks, block k of walks draws from the stream (seed, k) and blocks merge in
 * index order: the result does not depend on the number of threads. */
#include "rad.h"
#include "../round.h"
#include "../solve.h"

#include "../stats.h"
#include "../stop.h"

#include <stdlib.h>
#include <string.h>

enum { RBLOCK = 256, RROUND = 32 };

/* A shooting history's tally at one patch. */
typedef struct {
    int32_t patch;
    double v[3];
} rad_tally;

/* What a block of walks produced. */
typedef struct {
    ulam__block_head h; /* the round driver's part: the shooting tallies (rad_tally), walks, ... */
    ulam__moments m[3]; /* gathering scores per channel */
    double sq, maxsq;   /* sum and largest square of the channel-summed score (of the patch) */
    double maxc[3];     /* the largest score per channel (gathering) */
    int64_t rays, cut;
} rad_block;

/* Shooting: one patch's channel since the sequence's plan: the clipped tallies' sum, sum of
 * squares and largest, and the clip limit of tally / area (INFINITY: none). */
typedef struct {
    double sum, sq, max, clip;
} rad_pend;

/* Per-thread scratch of a shooting history. */
typedef struct {
    double *hist; /* 3 per patch */
    int32_t *touched;
    unsigned char *mark;
    int64_t ntouched;
} rad_scratch;

struct ulam_rad_solver {
    ulam_walk_opts o;
    const ulam_tracer *t;
    const ulam_scene *s;
    int threads;
    double *q;            /* continuation per patch: max_c rho */
    double per_step[3], range[3], qmax; /* the score bounds of the rel_err rule (score_bounds) */
    ulam__point_bounds pb;              /* a point solver's (point_bounds) */
    ulam__lights L;       /* the emitters (shooting's source, next-event's lights) */
    int at;               /* a point solver: walks from at_x (normal at_n, on patch at_self or -1) */
    double at_x[3], at_n[3], at_start[3]; /* at_start: where its walks start (ulam__point_start) */
    int64_t at_self;
    rad_scratch *scratch;
    rad_block *blocks;
    ulam__moments m[3];
    double *sum, *sumsq; /* shooting: per patch and channel, of history tallies */
    double sq, maxsq, maxc[3];
    ulam__run run; /* walks, time, ending (round.c) */
    int64_t rays, cut;
    int zero, met;
    double w0[3];  /* shooting: the largest starting weight per channel (score_bounds) */
    double whole;  /* shooting: the whole-scene rule's area share (ulam_rad_solver_whole), 0: patch index's rule */
    ulam__cs cs[3]; /* gathering and points: each channel's confidence sequence (stop.h), on score - off */
    ulam__cs *pcs;  /* shooting: per patch and channel, the sequence of the tallies over the area */
    rad_pend *pend; /* shooting: per patch and channel, the tallies since the plan and their clip limit */
    int64_t round0; /* shooting: the walks at the current plan (the tallies since go to pcs at the next) */
    int64_t checked; /* shooting: the walks at the whole-scene rule's last check */
};

/* Free; accepts and returns NULL. */
ulam_rad_solver *ulam_rad_solver_free(ulam_rad_solver *s)
{
    if (!s) return NULL;
    if (s->scratch)
        for (int k = 0; k < s->threads; k++)
            free(s->scratch[k].hist), free(s->scratch[k].touched), free(s->scratch[k].mark);
    if (s->blocks)
        for (int k = 0; k < RROUND; k++) free(s->blocks[k].h.tally);
    ulam__lights_free(&s->L);
    free(s->q), free(s->scratch), free(s->blocks);
    free(s->sum), free(s->sumsq);
    free(s->pcs), free(s->pend);
    free(s);
    return NULL;
}

/* Nonzero for a next-event estimator. */
static int next_event(int estimator)
{
    return estimator == ULAM_RAD_NEXT_EVENT || estimator == ULAM_RAD_NEXT_EVENT_BALANCE ||
           estimator == ULAM_RAD_NEXT_EVENT_LIGHT;
}

/* Nonzero when the solver's walks are point.c's weight-window walks: a point solver's, and
 * gathering at a patch by next-event or collision (absorption keeps gather's roulette). */
static int window(const ulam_rad_solver *s)
{
    return s->at || (s->o.mode == ULAM_ADJOINT && s->o.estimator != ULAM_RAD_ABSORPTION);
}

/* The exact part of channel c's every score, which its sequence is fed without: gathering at a
 * patch by window walks scores E_i + rho_i H (the emission); else 0. */
static double score_offset(const ulam_rad_solver *s, int c)
{
    return window(s) && !s->at ? s->s->emit[3 * s->o.query.index + c] : 0.0;
}

/* Check the options for a patch walk (point: a point solver, whose index is not read). */
static int check_opts(const ulam_scene *sc, const ulam_walk_opts *o, int point, ulam_error *err)
{
    if (o->mode != ULAM_ADJOINT && o->mode != ULAM_FORWARD)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "mode gathering (adjoint) or shooting (forward)");
    if (o->mode == ULAM_FORWARD && o->estimator != ULAM_RAD_COLLISION && o->estimator != ULAM_RAD_ABSORPTION)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "shooting takes estimator ULAM_RAD_COLLISION or ULAM_RAD_ABSORPTION "
                                                   "(next-event, the default, is for gathering)");
    if (!next_event(o->estimator) && o->estimator != ULAM_RAD_COLLISION && (o->estimator != ULAM_RAD_ABSORPTION || point))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "an estimator of enum ulam_rad_estimator (point walks: next-event "
                                                   "or collision)");
    if (point && o->mode != ULAM_ADJOINT)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "point walks gather (mode adjoint)");
    if (!point && (o->query.index < 0 || o->query.index >= sc->npatches))
        return ulam__fail(err, ULAM_EINVAL, 0, o->query.index, "a patch from 0 to %lld", (long long)sc->npatches - 1);
    return ulam__budgets_check(o, err);
}

/* The emitters: shooting's source and next-event's lights. */
static int build_source(ulam_rad_solver *s, ulam_error *err)
{
    if (ulam__lights_build(s->s, &s->L)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the emitters");
    if (s->L.nem == 0 && s->o.mode == ULAM_FORWARD)
        return ulam__fail(err, ULAM_EUNDEFINED, 0, -1, "an emitting patch (Ke > 0) to shoot from");
    return ULAM_OK;
}

/* The own vertex's parts of a window walk's range (ulam__point_range): the light sample and the
 * landing at the point, or anywhere on the gathering patch (collision: no light sample, a
 * landing at most the largest emission). */
static void own_parts(ulam_rad_solver *s)
{
    const ulam_scene *sc = s->s;
    ulam__point_bounds *b = &s->pb;
    int64_t i = s->o.query.index;
    if (next_event(s->o.estimator)) {
        ulam__lights_vertex_parts(&s->L, sc, s->o.estimator, s->at ? -1 : i, s->at ? s->at_start : NULL,
                                  s->at ? s->at_n : sc->normal + 3 * i, b->light0, b->hit0);
        return;
    }
    for (int c = 0; c < 3; c++) b->light0[c] = 0.0, b->hit0[c] = 0.0;
    for (int64_t k = 0; k < s->L.nem; k++)
        for (int c = 0; c < 3; c++) b->hit0[c] = fmax(b->hit0[c], sc->emit[3 * s->L.emitter[k] + c]);
}

/* A window walk's parts of its range (ulam__point_range): its own vertex's light sample and
 * landing (own_parts), every other vertex's largest over the patches, the largest
 * reflectance, and whether every emitter is black (a landing on one ends the walk). */
static void point_bounds(ulam_rad_solver *s)
{
    const ulam_scene *sc = s->s;
    ulam__point_bounds *b = &s->pb;
    int nee = next_event(s->o.estimator);
    double emax[3] = {0, 0, 0};
    memset(b, 0, sizeof *b);
    b->black = 1;
    for (int64_t k = 0; k < s->L.nem; k++) {
        int64_t l = s->L.emitter[k];
        b->black &= s->q[l] == 0.0;
        for (int c = 0; c < 3; c++) emax[c] = fmax(emax[c], sc->emit[3 * l + c]);
    }
    for (int64_t p = 0; p < sc->npatches; p++) {
        double l[3] = {0, 0, 0}, h[3] = {emax[0], emax[1], emax[2]}; /* collision: a landing scores W E, no light sample */
        b->rho = fmax(b->rho, s->q[p]);
        if (nee) ulam__lights_vertex_parts(&s->L, sc, s->o.estimator, p, NULL, sc->normal + 3 * p, l, h);
        for (int c = 0; c < 3; c++) {
            double r = sc->rho[3 * p + c];
            b->light[c] = fmax(b->light[c], l[c]), b->hit[c] = fmax(b->hit[c], h[c]);
            b->lr[c] = fmax(b->lr[c], r * l[c]), b->hr[c] = fmax(b->hr[c], r * h[c]);
        }
    }
    own_parts(s);
}

/* The bounds of the rel_err rule (per channel: per_step, what one step can score; range, a
 * bound on a whole walk's score when one is known, else INFINITY and the walks' length is
 * truncated, stop.h; qmax the largest survival).  Every weight stays at most its start
 * (rho_c / q <= 1).  Gathering: collision scores at most max_p E_pc a visit; absorption at most
 * max_p E_pc / (1 - q_p) once; next-event at most lights.c's vertex bound a vertex (the MIS
 * weights cap the 1 / r^2 of a light sample near its light; light sampling alone is bounded
 * only where no patch can touch an emitter).  Window walks (gathering by collision or
 * next-event, point solvers) take their whole range from point_bounds; per_step still says
 * which channels can score and whether light sampling alone is bounded.
 * Shooting's tally at patch i: at most w0_c rho_ic a visit, w0_c = P max_l E_lc / sum_c E_lc
 * the largest starting weight (collision), or that / (1 - q_i) once (absorption). */
static void score_bounds(ulam_rad_solver *s)
{
    const ulam_scene *sc = s->s;
    int nee = next_event(s->o.estimator);
    s->qmax = 0.0;
    for (int c = 0; c < 3; c++) s->per_step[c] = s->range[c] = 0.0;
    for (int64_t p = 0; p < sc->npatches; p++) {
        s->qmax = fmax(s->qmax, s->q[p]);
        double b[3];
        if (nee) ulam__lights_vertex_bound(&s->L, sc, s->o.estimator, p, NULL, sc->normal + 3 * p, !s->at, b);
        for (int c = 0; c < 3; c++) {
            double E = sc->emit[3 * p + c];
            s->per_step[c] = fmax(s->per_step[c], nee ? b[c] : E);
            s->range[c] = fmax(s->range[c], E > 0 ? E / (1.0 - s->q[p]) : 0.0);
        }
    }
    if (window(s)) point_bounds(s);
    if (s->o.mode == ULAM_FORWARD) {
        for (int c = 0; c < 3; c++) {
            double w0 = 0.0, rho = sc->rho[3 * s->o.query.index + c], q = s->q[s->o.query.index];
            for (int64_t k = 0; k < s->L.nem; k++) {
                const double *E = sc->emit + 3 * s->L.emitter[k];
                w0 = fmax(w0, s->L.ptot * E[c] / (E[0] + E[1] + E[2]));
            }
            s->w0[c] = w0;
            s->per_step[c] = w0 * rho;
            s->range[c] = s->o.estimator == ULAM_RAD_ABSORPTION ? (w0 * rho > 0 ? w0 * rho / (1.0 - q) : 0.0) : INFINITY;
        }
        return;
    }
    for (int c = 0; c < 3; c++)
        if (s->o.estimator != ULAM_RAD_ABSORPTION) s->range[c] = s->per_step[c] > 0 ? INFINITY : 0.0;
}

/* ULAM_OK, or (rel_err with a channel whose scores have no certified bound: light sampling
 * alone beside an emitter) ULAM_EINVAL: the rule of stop.h would have no interval to stop on. */
static int check_bounded(const ulam_rad_solver *s, ulam_error *err)
{
    for (int c = 0; c < 3; c++)
        if (s->o.stop.rel_err > 0 && !isfinite(s->per_step[c]))
            return ulam__fail(err, ULAM_EINVAL, 0, -1, "a certified bound on the scores for rel_err (light sampling "
                                                       "alone has none where a patch may touch an emitter: "
                                                       "use next-event with MIS, or a walk budget)");
    return ULAM_OK;
}

/* Allocate per-thread scratch and per-block results. */
static int alloc_work(ulam_rad_solver *s)
{
    int64_t n = s->s->npatches;
    s->scratch = calloc((size_t)s->threads, sizeof *s->scratch);
    s->blocks = calloc(RROUND, sizeof *s->blocks);
    s->q = ulam__malloc((size_t)n, sizeof *s->q);
    if (!s->scratch || !s->blocks || !s->q) return ULAM_ENOMEM;
    for (int64_t p = 0; p < n; p++) s->q[p] = ulam__max3(s->s->rho + 3 * p);
    if (!s->at) score_bounds(s); /* a point solver's, once its point is known */
    if (s->o.mode == ULAM_ADJOINT) return ULAM_OK;
    for (int k = 0; k < s->threads; k++) {
        rad_scratch *sc = &s->scratch[k];
        sc->hist = ulam__calloc((size_t)(3 * n), sizeof *sc->hist);
        sc->touched = ulam__malloc((size_t)n, sizeof *sc->touched);
        sc->mark = ulam__calloc((size_t)n, 1);
        if (!sc->hist || !sc->touched || !sc->mark) return ULAM_ENOMEM;
    }
    s->sum = ulam__calloc((size_t)(3 * n), sizeof *s->sum);
    s->sumsq = ulam__calloc((size_t)(3 * n), sizeof *s->sumsq);
    s->pcs = ulam__calloc((size_t)(3 * n), sizeof *s->pcs);
    s->pend = ulam__calloc((size_t)(3 * n), sizeof *s->pend);
    for (int64_t k = 0; s->pend && k < 3 * n; k++) s->pend[k].clip = INFINITY;
    return s->sum && s->sumsq && s->pcs && s->pend ? ULAM_OK : ULAM_ENOMEM;
}

/* Prepare walks from patch opts->index, or (point) from a point. */
static int solver_alloc(const ulam_tracer *t, const ulam_rad_opts *opts, int point, ulam_rad_solver **out,
                        ulam_error *err)
{
    ulam__clear(err);
    if (!t || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer and an output");
    *out = NULL;
    ulam_rad_opts r = opts ? *opts : ulam_rad_defaults();
    ulam_walk_opts o = ulam_walk_defaults(); /* the round driver's view: the kernel's defaults are never read */
    o.mode = r.mode, o.estimator = r.estimator, o.query.index = r.index, o.stop = r.stop, o.exec = r.exec;
    int status = check_opts(ulam__tracer_scene(t), &o, point, err);
    if (status) return status;
    ulam_rad_solver *s = calloc(1, sizeof *s);
    if (!s) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the solver");
    s->o = o;
    s->t = t;
    s->s = ulam__tracer_scene(t);
    s->threads = ulam__threads(o.exec.threads);
    ulam__run_reset(&s->run);
    s->o.stop.max_walks = ulam__walk_cap(&o);
    s->at = point;
    if ((status = build_source(s, err))) {
        ulam_rad_solver_free(s);
        return status;
    }
    if (alloc_work(s)) {
        ulam_rad_solver_free(s);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the walk workspace");
    }
    if (!point && (status = check_bounded(s, err))) {
        ulam_rad_solver_free(s);
        return status;
    }
    *out = s;
    return ULAM_OK;
}

/* The radiosity defaults: gather at patch 0 by next-event estimation. */
ulam_rad_opts ulam_rad_defaults(void)
{
    return (ulam_rad_opts){.mode = ULAM_ADJOINT, .estimator = ULAM_RAD_NEXT_EVENT, .stop = ulam__stop_defaults(),
                           .exec = ulam__exec_defaults()};
}

/* Prepare patch walks. */
int ulam_rad_solver_alloc(const ulam_tracer *t, const ulam_rad_opts *opts, ulam_rad_solver **out,
                          ulam_error *err)
{
    return solver_alloc(t, opts, 0, out, err);
}

/* Check point x (normal n, or NULL: the patch's it lies on) and place it: *p the patch it lies
 * on or -1, xx the point on that patch's plane exactly, nn the unit normal. */
static int point_place(const ulam_tracer *t, const double x[3], const double n[3], int64_t *p, double xx[3],
                       double nn[3], ulam_error *err)
{
    const ulam_scene *sc = ulam__tracer_scene(t);
    double big = 0.0, m[3] = {0, 0, 0}, len = 0.0, c[3];
    for (int k = 0; k < 3; k++)
        if (!isfinite(x[k]) || (n && !isfinite(n[k]))) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a finite point and normal");
    for (int k = 0; k < 3 && n; k++) big = fmax(big, fabs(n[k]));
    for (int k = 0; k < 3 && big > 0; k++) m[k] = n[k] / big; /* scaled first: 1e200 squared overflows */
    len = sqrt(ulam__dot3(m, m));
    if (n && !(len > 0)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a nonzero normal");
    if (!ulam__tracer_reaches(t, x)) {
        double size = ulam__tracer_size(t, c);
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a point within %g scene sizes of the scene (its centre is %g %g %g, "
                          "its size %g)", ULAM__TRACER_REACH, c[0], c[1], c[2], size);
    }
    *p = ulam_scene_locate(sc, x, ULAM_RAD_LOCATE_REL);
    if (!n && *p < 0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a point on a patch (within %g of its size) or a normal for a "
                                                   "sensor off the surfaces", ULAM_RAD_LOCATE_REL);
    for (int k = 0; k < 3; k++) nn[k] = n ? m[k] / len : sc->normal[3 * *p + k], xx[k] = x[k];
    if (*p >= 0 && ulam__dot3(nn, sc->normal + 3 * *p) < 1.0 - 1e-9)
        return ulam__fail(err, ULAM_EINVAL, 0, *p, "the normal of patch %lld the point lies on (or no normal)",
                          (long long)*p + 1);
    if (*p >= 0) { /* onto the patch's plane exactly */
        const double *v = sc->vert + 3 * sc->vidx[sc->start[*p]], *pn = sc->normal + 3 * *p;
        double d[3];
        ulam__sub3(x, v, d);
        double h = ulam__dot3(d, pn);
        for (int k = 0; k < 3; k++) xx[k] -= h * pn[k];
    }
    return ULAM_OK;
}

/* Prepare walks from point x (normal n, or NULL: the patch's it lies on). */
int ulam_rad_point_alloc(const ulam_tracer *t, const ulam_rad_opts *opts, const double x[3], const double n[3],
                         ulam_rad_solver **out, ulam_error *err)
{
    ulam__clear(err);
    if (!t || !x || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer, a point and an output");
    *out = NULL;
    double xx[3], nn[3];
    int64_t p;
    int status = point_place(t, x, n, &p, xx, nn, err);
    if (status || (status = solver_alloc(t, opts, 1, out, err))) return status;
    ulam_rad_solver *s = *out;
    for (int k = 0; k < 3; k++) s->at_x[k] = xx[k], s->at_n[k] = nn[k];
    s->at_self = p;
    ulam__point_start(t, xx, nn, p, s->at_start);
    score_bounds(s); /* with the point's own first vertex */
    if ((status = check_bounded(s, err))) *out = ulam_rad_solver_free(s);
    return status;
}

/* Move point solver s to point x (normal n, as ulam_rad_point_alloc's) with seed and
 * max_seconds, its statistics cleared: the scene-wide parts of its score bounds (every patch's,
 * point_bounds) and its workspace are kept, only the point's own vertex's bound is made anew. */
int ulam__rad_point_restart(ulam_rad_solver *s, const double x[3], const double n[3], uint64_t seed, double max_seconds,
                            ulam_error *err)
{
    ulam__clear(err);
    if (!s || !s->at || !x) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a point solver and a point");
    double xx[3], nn[3];
    int64_t p;
    int status = point_place(s->t, x, n, &p, xx, nn, err);
    if (status) return status;
    for (int k = 0; k < 3; k++) s->at_x[k] = xx[k], s->at_n[k] = nn[k];
    s->at_self = p;
    ulam__point_start(s->t, xx, nn, p, s->at_start);
    ulam__rad_solver_restart(s, -1, s->o.stop.rel_err, seed, max_seconds);
    return ULAM_OK;
}

/* A point solver's answer: irradiance, and radiosity on the patch the point lies on. */
int ulam_rad_point_result(const ulam_rad_solver *s, ulam_rad_point *r)
{
    if (!s || !r || !s->at) return ULAM_EINVAL;
    memset(r, 0, sizeof *r);
    ulam_rad_solver_result(s, &r->run);
    r->patch = s->at_self;
    for (int c = 0; c < 3; c++) {
        r->irradiance[c] = r->run.radiosity[c], r->irradiance_se[c] = r->run.std_error[c];
        r->radiosity[c] = r->radiosity_se[c] = NAN;
        if (r->patch < 0) continue;
        double rho = s->s->rho[3 * r->patch + c];
        r->radiosity[c] = s->s->emit[3 * r->patch + c] + rho * r->irradiance[c];
        r->radiosity_se[c] = rho * r->irradiance_se[c];
    }
    for (int k = 0; k < 3; k++) r->x[k] = s->at_x[k], r->n[k] = s->at_n[k];
    return ULAM_OK;
}

/* Run a point solver to the end (ulam_rad_point_alloc, iterate, result, free). */
int ulam_rad_point_query(const ulam_tracer *t, const ulam_rad_opts *opts, const double x[3], const double n[3],
                         ulam_rad_point *r, ulam_error *err)
{
    ulam_rad_solver *s = NULL;
    int status = ulam_rad_point_alloc(t, opts, x, n, &s, err);
    if (status) return status;
    while (!status && !ulam_rad_solver_done(s)) status = ulam_rad_solver_iterate(s);
    if (!status) ulam_rad_point_result(s, r);
    else ulam__fail(err, status, 0, -1, "finite scores");
    ulam_rad_solver_free(s);
    return status;
}

/* One gathering walk from the patch: its RGB score. */
static void gather(const ulam_rad_solver *s, ulam_rng *r, double score[3], rad_block *br)
{
    const ulam_scene *sc = s->s;
    int absorb = s->o.estimator == ULAM_RAD_ABSORPTION;
    int64_t p = s->o.query.index;
    double W[3] = {1, 1, 1};
    score[0] = score[1] = score[2] = 0.0;
    for (int64_t step = 0;; step++) {
        const double *E = sc->emit + 3 * p, q = s->q[p];
        if (!absorb)
            for (int c = 0; c < 3; c++) score[c] += W[c] * E[c];
        if (ulam__rng_uniform(r) >= q) { /* stops here */
            if (absorb)
                for (int c = 0; c < 3; c++) score[c] += W[c] * E[c] / (1.0 - q);
            return;
        }
        if (step >= s->o.stop.max_steps) {
            br->cut++;
            return;
        }
        for (int c = 0; c < 3; c++) W[c] *= sc->rho[3 * p + c] / q;
        int64_t j = ulam_tracer_shoot(s->t, p, r);
        br->rays++;
        if (j < 0) return;
        p = j;
    }
}

/* One gathering walk from the patch by next-event or collision estimation: its emission, and
 * its reflectance times a window walk (point.c) from a uniform point of it whose landings move
 * to uniform points of the patches they reach (the patch-averaged F); a black patch walks not. */
static void gather_window(const ulam_rad_solver *s, ulam_rng *r, double score[3], rad_block *br)
{
    const ulam_scene *sc = s->s;
    int64_t i = s->o.query.index, cut = 0;
    const double *E = sc->emit + 3 * i, *rho = sc->rho + 3 * i;
    double x[3], H[3];
    for (int c = 0; c < 3; c++) score[c] = E[c];
    if (s->q[i] == 0.0) return;
    ulam__tracer_point(s->t, i, r, x);
    ulam__point_walk(s->t, &s->L, s->o.estimator, s->o.stop.max_steps, ulam__point_gamma(s->pb.rho), 1, x,
                     sc->normal + 3 * i, i, s->o.stop.interrupt, r, H, &br->rays, &cut);
    br->cut += cut;
    for (int c = 0; c < 3; c++) score[c] += rho[c] * H[c];
}

/* Add w to the history tally of patch p. */
static void tally(rad_scratch *sc, int64_t p, const double w[3], double scale)
{
    if (!sc->mark[p]) sc->mark[p] = 1, sc->touched[sc->ntouched++] = (int32_t)p;
    for (int c = 0; c < 3; c++) sc->hist[3 * p + c] += w[c] * scale;
}

/* One shooting history: tallies in sc.  Emission is not reflection: the particle always leaves
 * its emitter (the emitted power A E is known exactly and added in shot_component); at each
 * patch j it reaches, j reflects rho_j W, and survival there is decided by q_j. */
static void shoot(const ulam_rad_solver *s, ulam_rng *r, rad_scratch *sc, rad_block *br)
{
    const ulam_scene *scn = s->s;
    int absorb = s->o.estimator == ULAM_RAD_ABSORPTION;
    int64_t p = ulam__lights_pick(&s->L, ulam__rng_uniform(r));
    const double *E0 = scn->emit + 3 * p;
    double W[3], esum = E0[0] + E0[1] + E0[2];
    for (int c = 0; c < 3; c++) W[c] = s->L.ptot * E0[c] / esum;
    for (int64_t step = 0;; step++) {
        if (step >= s->o.stop.max_steps) {
            br->cut++;
            return;
        }
        int64_t j = ulam_tracer_shoot(s->t, p, r);
        br->rays++;
        if (j < 0) return;
        const double *rho = scn->rho + 3 * j;
        double q = s->q[j], R[3] = {W[0] * rho[0], W[1] * rho[1], W[2] * rho[2]}; /* reflected by j */
        if (!absorb) tally(sc, j, R, 1.0);
        if (ulam__rng_uniform(r) >= q) {
            if (absorb) tally(sc, j, R, 1.0 / (1.0 - q));
            return;
        }
        for (int c = 0; c < 3; c++) W[c] = R[c] / q;
        p = j;
    }
}

/* Move a finished shooting history's tallies into the block; 0 or ULAM_ENOMEM. */
static int flush_history(rad_scratch *sc, rad_block *br)
{
    ulam__block_head *h = &br->h;
    if (ulam__grow(&h->tally, &h->cap, h->len + sc->ntouched, sizeof(rad_tally))) return ULAM_ENOMEM;
    for (int64_t k = 0; k < sc->ntouched; k++) {
        int32_t p = sc->touched[k];
        rad_tally *e = (rad_tally *)h->tally + h->len++;
        e->patch = p;
        for (int c = 0; c < 3; c++) {
            e->v[c] = sc->hist[3 * p + c];
            if (!isfinite(e->v[c])) h->nonfinite++;
            sc->hist[3 * p + c] = 0.0;
        }
        sc->mark[p] = 0;
    }
    sc->ntouched = 0;
    return ULAM_OK;
}

/* Nonzero when a block must stop before its next walk: interrupted, or out of time.  A block
 * stops inside (one walk of 10^6 rays takes a second, a block of 256 of them minutes: --time 3
 * took 68 s), keeping the walks it finished: the run ends with them (ulam__round_step). */
static int block_must_stop(const ulam_rad_solver *s)
{
    if (s->o.stop.interrupt && *s->o.stop.interrupt) return 1;
    return s->o.stop.max_seconds > 0 && ulam_now() - s->run.t0 >= s->o.stop.max_seconds;
}

/* Run walks [first, first + count) as block k on thread th (ctx: the solver). */
static void run_block(void *ctx, int k, int64_t first, int64_t count, int th)
{
    const ulam_rad_solver *s = ctx;
    rad_block *br = &s->blocks[k];
    ulam__moments zero = {0};
    br->m[0] = br->m[1] = br->m[2] = zero;
    br->sq = br->maxsq = br->maxc[0] = br->maxc[1] = br->maxc[2] = 0.0;
    br->h.len = br->h.walks = br->rays = br->cut = br->h.nonfinite = 0;
    br->h.complete = br->h.nomem = 0;
    if (!ulam__mine(s->o.exec.share, first / RBLOCK) || !ulam__block_may_start(&s->o, s->run.t0, first)) return;
    ulam_rng r;
    ulam_rng_seed(&r, s->o.exec.seed, (uint64_t)(first / RBLOCK));
    for (int64_t w = 0; w < count; w++) {
        if (w > 0 && block_must_stop(s)) break; /* its walks so far stand: the run ends with them */
        if (s->o.mode == ULAM_ADJOINT) {
            double sc[3];
            if (s->at) {
                int64_t cut = 0;
                ulam__point_walk(s->t, &s->L, s->o.estimator, s->o.stop.max_steps, ulam__point_gamma(s->pb.rho), 0,
                                 s->at_start, s->at_n, s->at_self, s->o.stop.interrupt, &r, sc, &br->rays, &cut);
                br->cut += cut;
            } else if (window(s)) {
                gather_window(s, &r, sc, br);
            } else {
                gather(s, &r, sc, br);
            }
            for (int c = 0; c < 3; c++) {
                ulam__moments_add(&br->m[c], sc[c]);
                br->maxc[c] = fmax(br->maxc[c], sc[c]);
                if (!isfinite(sc[c])) br->h.nonfinite++;
            }
            double x = sc[0] + sc[1] + sc[2];
            br->sq += x * x;
            br->maxsq = fmax(br->maxsq, x * x);
        } else {
            shoot(s, &r, &s->scratch[th], br);
            for (int c = 0; c < 3; c++) /* the patch's tally, 0 when untouched: its moments for rel_err */
                ulam__moments_add(&br->m[c], s->scratch[th].hist[3 * s->o.query.index + c]);
            if (flush_history(&s->scratch[th], br)) {
                br->h.nomem = 1;
                return;
            }
        }
        br->h.walks++;
    }
    br->h.complete = 1;
}

static void cs_plan_gather(ulam_rad_solver *s);

/* Merge completed block k into the totals (ctx: the solver; the walk and non-finite counts are
 * the round driver's). */
static void merge_block(void *ctx, int k)
{
    ulam_rad_solver *s = ctx;
    const rad_block *br = &s->blocks[k];
    if (s->o.mode == ULAM_ADJOINT) cs_plan_gather(s); /* from the blocks merged before this one alone */
    for (int c = 0; c < 3 && s->o.mode == ULAM_ADJOINT; c++) {
        double off = score_offset(s, c);
        ulam__cs_add(&s->cs[c], br->m[c].n, br->m[c].mean - off, br->m[c].m2, br->m[c].n > 0 ? br->maxc[c] - off : 0.0);
    }
    for (int c = 0; c < 3; c++) ulam__moments_merge(&s->m[c], &br->m[c]);
    s->sq += br->sq;
    s->maxsq = fmax(s->maxsq, br->maxsq);
    for (int c = 0; c < 3; c++) s->maxc[c] = fmax(s->maxc[c], br->maxc[c]);
    for (int64_t k = 0; k < br->h.len; k++) {
        const rad_tally *e = (const rad_tally *)br->h.tally + k;
        for (int c = 0; c < 3; c++) {
            int64_t j = 3 * (int64_t)e->patch + c;
            rad_pend *q = &s->pend[j];
            double x = fmin(e->v[c] / s->s->area[e->patch], q->clip); /* over the area, clipped (cs_plan_shoot) */
            s->sum[j] += e->v[c];
            s->sumsq[j] += e->v[c] * e->v[c];
            q->sum += x, q->sq += x * x, q->max = fmax(q->max, x);
        }
        if (e->patch == s->o.query.index) {
            double x = e->v[0] + e->v[1] + e->v[2];
            s->sq += x * x;
            s->maxsq = fmax(s->maxsq, x * x);
        }
    }
    s->rays += br->rays;
    s->cut += br->cut;
}

static void result(const ulam_rad_solver *s, double mins[3], ulam_rad_result *r);

/* Nonzero when interval ci at estimate m meets relative target E: the printed half-width at most
 * E |m| (x certified exactly meets it at once); never at m = 0 otherwise. */
static int half_met(const ulam__stop_ci *ci, double m, double E)
{
    if (ci->kind == ULAM__STOP_EXACT) return E > 0;
    return ci->kind == ULAM__STOP_EB && E > 0 && m != 0.0 && ci->half <= E * fabs(m);
}

/* The walks a sequence planned for a fixed count or an open-ended run aims at (stop.h's nplan):
 * the count fixed in advance, else four times the walks so far (at least 4096). */
static double plan_walks(const ulam_rad_solver *s)
{
    int fixed = !(s->o.stop.rel_err > 0) && !(s->o.stop.max_seconds > 0) && s->o.stop.max_walks > 0;
    return fixed ? (double)s->o.stop.max_walks : fmax(4.0 * (double)s->run.walks, 4096.0);
}

/* Gathering and points: channel c's certified score range R (every score in [off, off + R],
 * score_offset) and the most the walks cut at max_steps can have moved the mean (cut): a window
 * walk's whole range (ulam__point_range, times the patch's reflectance) and tail
 * (ulam__point_tail), or one absorption walk's range (INFINITY: none, an emitter reflecting all). */
static void gather_range(const ulam_rad_solver *s, int c, double *R, double *cut)
{
    if (window(s)) {
        double R0 = ulam__point_range(&s->pb, c), rho = s->at ? 1.0 : s->s->rho[3 * s->o.query.index + c];
        double tail = ulam__point_tail(&s->pb, c, s->o.stop.max_steps);
        *R = rho > 0 ? rho * R0 : 0.0;
        *cut = rho > 0 && tail > 0 ? rho * tail : 0.0;
        return;
    }
    *R = s->range[c];
    *cut = s->cut > 0 && isfinite(*R) ? ulam__cut_bound(*R, s->qmax, 1.0, s->o.stop.max_steps) : 0.0;
}

/* Before a block of gathering (or point) walks is added: plan each channel's sequence (stop.h's ulam__cs)
 * from the walks so far, for scores less their exact offset in [0, R] (limit R): tuned to the
 * half-width E |m| - cut under rel_err once there is an estimate, else to the planned count. */
static void cs_plan_gather(ulam_rad_solver *s)
{
    double E = s->o.stop.rel_err, nplan = plan_walks(s);
    for (int c = 0; c < 3; c++) {
        double R, cut, off = score_offset(s, c), m = s->m[c].mean;
        gather_range(s, c, &R, &cut);
        double h = E > 0 && m != 0.0 ? E * fabs(m) - cut : 0.0;
        ulam__cs_plan(&s->cs[c], s->m[c].n, m - off, ulam__moments_variance(&s->m[c]), R, 0.0, h > 0 ? h : 0.0, nplan);
    }
}

/* Shooting: patch p's channel-c tallies over its area so far, their mean and variance. */
static void shot_moments(const ulam_rad_solver *s, int64_t j, double *mean, double *var)
{
    double A = s->s->area[j / 3];
    ulam__sums_moments((double)s->run.walks, s->sum[j], s->sumsq[j], mean, var);
    *mean /= A, *var /= A * A;
}

/* Shooting: the range R of one particle's tally at patch p in channel c over its area, truncated
 * (collision) where longer histories add at most t to its mean (w0_c rho_pc a visit, weights
 * never growing; by absorption that / (1 - q_p) once, no truncation); 0 when nothing can tally
 * there, INFINITY when no truncation is asked (t = 0) for a collision tally. */
static double shot_range(const ulam_rad_solver *s, int64_t p, int c, double t)
{
    double A = s->s->area[p], ps = s->w0[c] * s->s->rho[3 * p + c];
    if (!(ps > 0)) return 0.0;
    if (s->o.estimator == ULAM_RAD_ABSORPTION) return ps / (1.0 - s->q[p]) / A;
    return t > 0 ? ulam__score_range(INFINITY, ps, s->qmax, 1.0, 0, t * A, 1.0) / A : INFINITY;
}

/* Shooting: the most the particles cut at max_steps can have moved patch p's channel-c mean. */
static double shot_cut(const ulam_rad_solver *s, int64_t p, int c)
{
    double ps = s->w0[c] * s->s->rho[3 * p + c];
    return s->cut > 0 && ps > 0 ? ulam__cut_bound(ps, s->qmax, 1.0, s->o.stop.max_steps) / s->s->area[p] : 0.0;
}

/* Shooting: the truncation bias a collision tally is planned at for patch p's channel c of
 * radiosity estimate B (|B| > 0) and variance v: an eighth of the half-width aimed at (E |B|, or
 * without a target 2.7 sigma / sqrt(nplan)), between 1e-6 and max(ULAM__STOP_TAIL, E / 4) of
 * |B|; 0 without an estimate (the tally then has no range yet). */
static double shot_trunc(const ulam_rad_solver *s, double B, double v, double nplan)
{
    double E = s->o.stop.rel_err > 0 ? s->o.stop.rel_err : 0.0, b = fabs(B);
    if (!(b > 0) || s->o.estimator == ULAM_RAD_ABSORPTION) return 0.0;
    double h = E > 0 ? E * b : 2.7 * sqrt(v / nplan), cap = fmax(ULAM__STOP_TAIL, E / 4.0) * b;
    return fmin(cap, fmax(h / 8.0, 1e-6 * b));
}

/* Shooting, the first round at a budget (no estimate, no target yet) of collision tallies: the
 * truncation whose bias and range term over the round's n1 particles (a bet at its largest) add
 * up least, over biases u 2^(-j/4) / (1 - q_max) of a visit's score w0_c rho_pc / A_p (from the
 * bound 1 / (1 - q_max) on the tally's mean visits down to 1e-6 of it, as the matrix solver's
 * plan_terms), as the share u of a visit's score: the same for every patch (the range is a
 * visit's score times the visits of histories so truncated); 0 when none has a range. */
static double shot_first_share(const ulam_rad_solver *s, double n1)
{
    double u = 0.0, least = INFINITY;
    for (int j = 0; s->qmax < 1.0 && j <= 80; j++) {
        double uj = exp2(-0.25 * j) / (1.0 - s->qmax), Rj = ulam__score_range(INFINITY, 1.0, s->qmax, 1.0, 0, uj, 1.0);
        double wj = ulam__cs_range_width(Rj, n1) + uj;
        if (isfinite(Rj) && wj < least) least = wj, u = uj;
    }
    return u;
}

static void cs_add_shoot(ulam_rad_solver *s);

/* Before a round of shooting, once the particles have doubled since the last plan and grown by
 * one a patch, or grown fourfold (the planned count nplan is four times the particles so far), or
 * by 24 a patch (a plan costs O(patches), a round's particles may be fewer: replanning every round
 * tripled the CPU time of 3 10^5 particles on 80 270 patches): the tallies since that plan into
 * each sequence,
 * then every patch's and channel's sequence planned from the particles so far (the tallies over
 * the area, limit the range at the planned truncation, clipped there: a longer history's tally
 * clipped to it moves the mean no more than cutting the history would); the sums start anew. */
static void cs_plan_shoot(ulam_rad_solver *s)
{
    int64_t N = s->run.walks, since = N - s->round0, n = s->s->npatches;
    if (N > 0 && !(N >= 2 * s->round0 && since >= n) && N < 4 * s->round0 && since < 24 * n)
        return; /* the plan stands (predictable still) */
    cs_add_shoot(s);
    double E = s->o.stop.rel_err, nplan = plan_walks(s), u = 0.0;
    int first = s->run.walks == 0 && !(E > 0) && s->o.estimator != ULAM_RAD_ABSORPTION;
    if (first) u = shot_first_share(s, fmin(nplan, (double)RBLOCK)); /* a budget's first round (one block) */
    for (int64_t j = 0; j < 3 * s->s->npatches; j++) {
        double mean, v, B;
        shot_moments(s, j, &mean, &v);
        B = s->s->emit[j] + mean;
        double t = shot_trunc(s, B, v, nplan);
        if (B == 0.0 && first) /* else that round would weigh nothing: 256 particles would print no interval */
            t = u * s->w0[j % 3] * s->s->rho[j] / s->s->area[j / 3];
        double R = shot_range(s, j / 3, (int)(j % 3), t);
        double h = E > 0 && B != 0.0 ? E * fabs(B) - t : 0.0;
        s->pend[j] = (rad_pend){.clip = t > 0 && isfinite(R) ? R : INFINITY};
        ulam__cs_plan(&s->pcs[j], s->run.walks, mean, v, R, t, h > 0 ? h : 0.0, nplan);
    }
    s->round0 = s->run.walks;
}

/* Before a round (ctx: the solver): shooting's plans (stop.h: from earlier rounds alone; gathering
 * plans a block at a time as it merges them, merge_block). */
static void plan_round(void *ctx)
{
    ulam_rad_solver *s = ctx;
    if (s->o.mode == ULAM_FORWARD) cs_plan_shoot(s);
}

/* Shooting: every patch's and channel's clipped tallies since the plan (the particles that did
 * not reach it count 0) into its sequence, under that plan. */
static void cs_add_shoot(ulam_rad_solver *s)
{
    int64_t n = s->run.walks - s->round0;
    if (n <= 0) return;
    for (int64_t j = 0; j < 3 * s->s->npatches; j++) {
        const rad_pend *q = &s->pend[j];
        double mean = q->sum / (double)n;
        ulam__cs_add(&s->pcs[j], n, mean, fmax(0.0, q->sq - (double)n * mean * mean), q->max);
        s->pend[j] = (rad_pend){.clip = q->clip};
    }
    s->round0 = s->run.walks;
}

/* Shooting: the sequence of entry j (patch j / 3, channel j % 3) with the tallies since the plan
 * added (a copy: pieces added under one plan sum to the whole). */
static void shot_cs(const ulam_rad_solver *s, int64_t j, ulam__cs *cs)
{
    int64_t n = s->run.walks - s->round0;
    *cs = s->pcs[j];
    if (n <= 0) return;
    const rad_pend *q = &s->pend[j];
    double mean = q->sum / (double)n;
    ulam__cs_add(cs, n, mean, fmax(0.0, q->sq - (double)n * mean * mean), q->max);
}

/* Shooting: patch p's channel-c 95% interval (stop.h's confidence sequence on its tallies over
 * the area, the emission exact), at its estimate. */
static void shot_interval(const ulam_rad_solver *s, int64_t p, int c, ulam__stop_ci *ci)
{
    int64_t j = 3 * p + c;
    double mean, v, E = s->s->emit[j];
    shot_moments(s, j, &mean, &v);
    if (shot_range(s, p, c, 1.0) == 0.0) { /* nothing tallies here: B = E exactly */
        ulam__stop_interval(s->run.walks, E + mean, 0.0, 0.0, 0.0, 0.0, 0.0, 0, ci);
        return;
    }
    ulam__cs cs;
    shot_cs(s, j, &cs);
    ulam__cs_interval(&cs, mean, shot_cut(s, p, c), ci);
    ci->lo += E, ci->hi += E;
}

/* Channel c's 95% interval (stop.h's confidence sequence, valid at every walk count) at the
 * solver's estimate: on the walks' scores less their exact offset (gathering, points), or patch
 * index's tallies over its area (shooting).  A window walk's score past its certified range
 * leaves no interval from then on (and no stop by rel_err), as in ulam_solve's. */
static void channel_interval(const ulam_rad_solver *s, int c, ulam__stop_ci *ci)
{
    if (s->o.mode == ULAM_FORWARD) {
        shot_interval(s, s->o.query.index, c, ci);
        return;
    }
    double R, cut, off = score_offset(s, c), m = s->m[c].mean;
    gather_range(s, c, &R, &cut);
    if (R == 0.0) { /* nothing that scores is reachable: the offset exactly */
        ulam__stop_interval(s->run.walks, m, 0.0, 0.0, 0.0, 0.0, 0.0, 0, ci);
        return;
    }
    ulam__cs_interval(&s->cs[c], m - off, cut, ci);
    ci->lo += off, ci->hi += off;
}

/* Shooting: the particles a sequence tuned to target E at radiosity B of patch p's channel c
 * (tally variance v over the area) needs. */
static double shot_needed(const ulam_rad_solver *s, int64_t p, int c, double B, double v, double E)
{
    double t = s->o.estimator == ULAM_RAD_ABSORPTION ? 0.0 : E * fabs(B) / 8.0, R = shot_range(s, p, c, t);
    return R == 0.0 ? 0.0 : ulam__cs_walks_needed(B, v, R, t + shot_cut(s, p, c), E);
}

/* The walks the rel_err rule needs in channel c at estimate m: those of a sequence tuned to E
 * from the start (stop.h's ulam__cs_walks_needed). */
static double channel_min_walks(const ulam_rad_solver *s, int c, double m, double E)
{
    if (s->o.mode == ULAM_FORWARD) {
        double mean, v;
        shot_moments(s, 3 * s->o.query.index + c, &mean, &v);
        return shot_needed(s, s->o.query.index, c, m, v, E);
    }
    double R, cut;
    gather_range(s, c, &R, &cut);
    return R == 0.0 ? 0.0 : ulam__cs_walks_needed(m, ulam__moments_variance(&s->m[c]), R, cut, E);
}

/* With rel_err: the walks the rule needs in each channel, at its estimate, or for a channel
 * still at 0 that some walk could score in, at the brightest channel's (precise_enough); 0
 * otherwise (no rel_err, a channel nothing can score in). */
static void channel_mins(const ulam_rad_solver *s, const ulam_rad_result *r, double mins[3])
{
    double bright = 0.0;
    for (int c = 0; c < 3; c++) bright = fmax(bright, fabs(r->radiosity[c]));
    for (int c = 0; c < 3; c++) {
        mins[c] = 0.0;
        if (!(s->o.stop.rel_err > 0)) continue;
        if (r->radiosity[c] != 0.0) mins[c] = channel_min_walks(s, c, r->radiosity[c], s->o.stop.rel_err);
        else if (s->per_step[c] > 0 && bright > 0) mins[c] = channel_min_walks(s, c, bright, s->o.stop.rel_err);
    }
}

/* Nonzero when the rel_err rule holds in every nonzero channel (and one is nonzero): the
 * channel's printed 95% interval (channel_interval) at most E |m| on each side; a channel
 * still at 0 that some walk could score in blocks the stop until the walks a sequence would
 * need at the brightest channel's estimate have run (mins, channel_mins): only then would it
 * have seen any of its scores worth E times that. */
static int precise_enough(const ulam_rad_solver *s, const ulam_rad_result *r, const double mins[3], double rel_err)
{
    int any = 0;
    for (int c = 0; c < 3; c++) {
        if (r->radiosity[c] == 0.0 && s->per_step[c] > 0 && !((double)r->walks >= mins[c])) return 0;
        if (r->radiosity[c] == 0.0) continue;
        ulam__stop_ci ci;
        channel_interval(s, c, &ci);
        if (!half_met(&ci, r->radiosity[c], rel_err)) return 0;
        any = 1;
    }
    return any;
}

/* With rel_err on one answer (a patch or point): the further walks the slowest nonzero channel's
 * sequence needs to reach E |m| under its plan (ulam__cs_walks_left), at least an eighth of the
 * walks so far; 0 (no prediction) when one cannot say. */
static int64_t walks_wanted(const ulam_rad_solver *s, const ulam_rad_result *r)
{
    double E = s->o.stop.rel_err, most = 0.0;
    for (int c = 0; c < 3; c++) {
        double m = r->radiosity[c], left;
        if (m == 0.0) continue;
        if (s->o.mode == ULAM_FORWARD) {
            int64_t j = 3 * s->o.query.index + c;
            double mean, v;
            shot_moments(s, j, &mean, &v);
            ulam__cs cs;
            shot_cs(s, j, &cs);
            left = ulam__cs_walks_left(&cs, mean, v, shot_cut(s, s->o.query.index, c), E * fabs(m));
        } else {
            double R, cut;
            gather_range(s, c, &R, &cut);
            left = ulam__cs_walks_left(&s->cs[c], s->m[c].mean - score_offset(s, c), ulam__moments_variance(&s->m[c]),
                                       cut, E * fabs(m));
        }
        most = fmax(most, left);
    }
    return isfinite(most) && most > 0 ? (int64_t)fmax(most, (double)s->run.walks / 8.0) : 0;
}

/* Shooting: patch p under the rel_err rule at target E.  *kind: 0 dark (emits nothing,
 * reflects nothing: B = 0 exactly), 1 unreached (it reflects, emits nothing, and no particle has
 * reached it), 2 lit.  A lit patch's *se and *half are its largest relative standard error and
 * relative 95% half-width over the nonzero channels; returns 1 when every channel's printed
 * half-width is at most E |B| (a channel still at 0 that a particle could light waits, as
 * precise_enough's, for the walks a sequence needs at the brightest channel). */
static int shot_patch(const ulam_rad_solver *s, int64_t p, double E, int *kind, double *se, double *half)
{
    const ulam_scene *sc = s->s;
    double N = (double)s->run.walks, m[3], v[3], bright = 0.0;
    int reached = 0, emits = 0, reflects = 0, met = 1;
    for (int c = 0; c < 3; c++) {
        double mean;
        shot_moments(s, 3 * p + c, &mean, &v[c]);
        m[c] = sc->emit[3 * p + c] + mean;
        reached |= s->sum[3 * p + c] != 0.0, emits |= sc->emit[3 * p + c] > 0, reflects |= sc->rho[3 * p + c] > 0;
        bright = fmax(bright, fabs(m[c]));
    }
    *se = *half = 0.0;
    *kind = reached || emits ? 2 : reflects ? 1 : 0;
    if (*kind < 2) return *kind == 0;
    for (int c = 0; c < 3; c++) {
        if (m[c] == 0.0) {
            if (s->w0[c] * sc->rho[3 * p + c] > 0) met &= N >= shot_needed(s, p, c, bright, v[c], E);
            continue;
        }
        ulam__stop_ci ci;
        shot_interval(s, p, c, &ci);
        *se = fmax(*se, N > 1 ? sqrt(v[c] / N) / fabs(m[c]) : INFINITY);
        *half = fmax(*half, ci.half / fabs(m[c]));
        met &= half_met(&ci, m[c], E);
    }
    return met;
}

/* Shooting: the whole scene under the rel_err rule (ulam_rad_solver_scene); the first max
 * unreached patches into unreached (may be NULL). */
static void scene_state(const ulam_rad_solver *s, ulam_rad_scene_rule *r, int64_t *unreached, int64_t max)
{
    memset(r, 0, sizeof *r);
    r->worst_patch = -1;
    r->share = s->whole;
    for (int64_t p = 0; p < s->s->npatches; p++) {
        int kind;
        double se, half;
        int met = shot_patch(s, p, s->o.stop.rel_err, &kind, &se, &half);
        if (kind == 1) {
            if (unreached && r->unreached < max) unreached[r->unreached] = p;
            r->unreached++;
        }
        if (kind < 2) continue;
        r->lit++, r->lit_area += s->s->area[p];
        if (met) r->met++, r->met_area += s->s->area[p];
        r->worst_se = fmax(r->worst_se, se);
        if (r->worst_patch < 0 || half > r->worst_half) r->worst_half = half, r->worst_patch = p;
    }
}

/* Shooting under the whole-scene rule: 1 once the lit patches that meet rel_err hold the share
 * of the lit area (and some patch reflects light), -1 when after the first walks no particle
 * lit any patch (rel_err can never be met), else 0. */
static int scene_done(const ulam_rad_solver *s)
{
    ulam_rad_scene_rule r;
    scene_state(s, &r, NULL, 0);
    int any = 0;
    for (int64_t p = 0; p < 3 * s->s->npatches && !any; p++) any = s->sum[p] != 0.0;
    if (!any) return -1;
    return r.met_area >= s->whole * r.lit_area * (1.0 - 1e-12);
}

/* Nonzero when every channel is exactly 0 with zero variance: no walk scored, and a relative
 * error can never be met. */
static int all_zero(const ulam_rad_result *r)
{
    for (int c = 0; c < 3; c++)
        if (r->radiosity[c] != 0.0 || r->std_error[c] != 0.0) return 0;
    return 1;
}

/* Run one round of walks. */
int ulam_rad_solver_iterate(ulam_rad_solver *s)
{
    if (!s) return ULAM_EINVAL;
    if (s->run.done) return s->run.status;
    static const ulam__blocks B = {RBLOCK, RROUND, run_block, sizeof(rad_block), sizeof(rad_tally), merge_block,
                                   plan_round, NULL, 0};
    ulam__round_step(&B, &s->o, s->threads, s, s->blocks, &s->run);
    ulam_rad_result r;
    double mins[3];
    result(s, mins, &r);
    int check = s->o.stop.rel_err > 0 && r.walks >= ULAM__REL_MIN; /* every round: the sequences hold at every count */
    if (s->whole > 0) { /* the whole scene (ulam_rad_solver_whole) instead of patch index: checked
                           once the particles grew by an eighth (O(patches) a check) */
        int d = check && 8 * r.walks >= 9 * s->checked ? scene_done(s) : 0;
        if (check && 8 * r.walks >= 9 * s->checked) s->checked = r.walks;
        if (d > 0) s->run.done = s->met = 1;
        if (d < 0) s->run.done = s->zero = 1; /* no particle lit anything: can never be met */
        return s->run.status;
    }
    s->run.want = s->o.stop.rel_err > 0 && r.walks >= ULAM__REL_MIN ? walks_wanted(s, &r) : 0;
    if (check && precise_enough(s, &r, mins, s->o.stop.rel_err))
        s->run.done = s->met = 1;
    if (s->o.stop.rel_err > 0 && r.walks >= ULAM__REL_MIN && all_zero(&r)) s->run.done = s->zero = 1; /* can never be met */
    return s->run.status;
}

/* Restart a gathering solver at patch p with relative target rel_err and seed: the statistics
 * are cleared, the workspace kept (so that many patches cost no allocation). */
void ulam__rad_solver_restart(ulam_rad_solver *s, int64_t p, double rel_err, uint64_t seed, double max_seconds)
{
    ulam__moments zero = {0};
    s->o.query.index = p, s->o.stop.rel_err = rel_err, s->o.exec.seed = seed, s->o.stop.max_seconds = max_seconds;
    if (window(s)) own_parts(s); /* the new patch's or point's own vertex */
    s->m[0] = s->m[1] = s->m[2] = zero;
    memset(s->cs, 0, sizeof s->cs);
    s->sq = s->maxsq = s->maxc[0] = s->maxc[1] = s->maxc[2] = 0.0;
    s->rays = s->cut = 0;
    ulam__run_reset(&s->run);
    s->zero = s->met = 0;
}

/* Nonzero once a stopping rule is met. */
int ulam_rad_solver_done(const ulam_rad_solver *s)
{
    return !s || s->run.done;
}

/* Shooting estimate and standard error of patch p's radiosity in channel c. */
static void shot_component(const ulam_rad_solver *s, int64_t p, int c, double *est, double *se)
{
    double N = (double)s->run.walks, A = s->s->area[p], mean, v;
    ulam__sums_moments(N, s->sum[3 * p + c], s->sumsq[3 * p + c], &mean, &v);
    *est = s->s->emit[3 * p + c] + mean / A; /* the emission exactly, the reflected light by the walks */
    *se = N > 0 ? sqrt(v / N) / A : INFINITY;
}

/* The result so far, and the channels' walk minimums mins (channel_mins). */
static void result(const ulam_rad_solver *s, double mins[3], ulam_rad_result *r)
{
    memset(r, 0, sizeof *r);
    for (int c = 0; c < 3; c++) {
        if (s->o.mode == ULAM_ADJOINT) {
            r->radiosity[c] = s->m[c].mean;
            r->std_error[c] = s->m[c].n > 0 ? sqrt(ulam__moments_variance(&s->m[c]) / (double)s->m[c].n) : INFINITY;
        } else {
            shot_component(s, s->o.query.index, c, &r->radiosity[c], &r->std_error[c]);
        }
    }
    r->max_share = s->sq > 0 ? fmin(1.0, s->maxsq / s->sq) : 0.0;
    channel_mins(s, r, mins);
    for (int c = 0; c < 3 && s->o.stop.rel_err > 0; c++) {
        r->min_walks = fmax(r->min_walks, mins[c]); /* 0 in a channel where no minimum applies */
        if (s->m[c].mean != 0.0)
            r->variance_rel_error = fmax(r->variance_rel_error, ulam__moments_variance_rel_error(&s->m[c]));
    }
    r->walks = s->run.walks;
    r->rays = s->rays;
    r->cut = s->cut;
    r->seconds = s->run.seconds;
    r->threads = s->threads;
    r->interrupted = s->run.interrupted;
    r->zero = s->zero;
    r->rel_err_met = s->met;
    for (int c = 0; c < 3; c++) {
        ulam__stop_ci ci;
        channel_interval(s, c, &ci);
        /* every score is >= 0 (emission and reflectance are), so B >= 0 is certain */
        r->ci95[c][0] = r->walks > 1 && !isnan(ci.lo) ? fmax(ci.lo, 0.0) : NAN, r->ci95[c][1] = r->walks > 1 ? ci.hi : NAN;
    }
}

/* The result so far. */
void ulam_rad_solver_result(const ulam_rad_solver *s, ulam_rad_result *r)
{
    double mins[3];
    if (!s) {
        memset(r, 0, sizeof *r);
        return;
    }
    result(s, mins, r);
}

/* Shooting: every patch. */
int ulam_rad_solver_vectors(const ulam_rad_solver *s, double *B, double *std_error)
{
    if (!s || s->o.mode != ULAM_FORWARD) return ULAM_EINVAL;
    for (int64_t p = 0; p < s->s->npatches; p++)
        for (int c = 0; c < 3; c++) {
            double e, se;
            shot_component(s, p, c, &e, &se);
            if (B) B[3 * p + c] = e;
            if (std_error) std_error[3 * p + c] = se;
        }
    return ULAM_OK;
}

/* Shooting: hold rel_err on the whole scene. */
int ulam_rad_solver_whole(ulam_rad_solver *s, double share)
{
    if (!s || s->at || s->o.mode != ULAM_FORWARD || !(share > 0 && share <= 1)) return ULAM_EINVAL;
    s->whole = share;
    return ULAM_OK;
}

/* Shooting: the whole scene's state under rel_err. */
int ulam_rad_solver_scene(const ulam_rad_solver *s, ulam_rad_scene_rule *out, int64_t *unreached, int64_t max)
{
    if (!s || !out || s->at || s->o.mode != ULAM_FORWARD || max < 0 || (max > 0 && !unreached)) return ULAM_EINVAL;
    scene_state(s, out, unreached, max);
    return ULAM_OK;
}
