/* The analysis: what queries on one M share, made once and held across them (CSparse's cs_sqr
 * before cs_lu): the guards, the bounds over every state the rel_err rule and absorption need
 * (ulam__reach_all, or the prepared file's stored copy), the shared b's scores, a kept walk
 * kernel per estimator, and for point sources and sparse b (the bidirectional estimator) the
 * transpose (the prepared file's stored M^T when it has one), the push workspace and a place for
 * the planner's memo (src/bidir.c: the planner takes these from here, as CSparse's cs_lu takes
 * cs_sqr's result, and walks on M^T through an analysis of M^T: ulam__analysis_walks).  Each is
 * made at the first query that needs it, so a single query from a prepared file reads only the
 * rows its walks reach.  This file is the one home of "reach once, keep the kernel, hand out
 * solvers": the walk solver's construction and caching calls (ulam__solver_alloc_reached,
 * ulam__solver_keep_kernel*, ulam__solver_reached, ulam__reach_all) are made here. */
#include "analysis.h"
#include "defaults.h"
#include "cache.h"
#include "kernel.h"
#include "push.h"
#include "solve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ulam_analysis {
    const ulam_csr *M;    /* borrowed */
    double continue_q;    /* normalised: 0 analog */
    double alpha;
    const double *b;      /* the shared b (borrowed; NULL: none) */
    const ulam_system *sys;
    int shared_bounds;    /* ulam_analysis_opts.shared_bounds */
    ulam_guard g;         /* the guards so far (g.computed: which radii) */
    int guard_from;       /* 0 none, 1 certificate, 2 computed */
    ulam__reach R;        /* the bounds over every state (R.bounds 0: not yet) */
    char *seen;           /* n ones: R.seen */
    int bounds_from, b_from;
    ulam_kernel *k[3];    /* per estimator: the kept kernel of adjoint queries on b (or of an
                             internal caller's fixed b: ULAM__WALKS_FIXED) */
    ulam_kernel *kr;      /* ULAM__WALKS_KEEP: the last internal walks' kernel, rescored to any b */
    char *found;          /* ULAM__WALKS_FIND: the states earlier walks found they reach (n flags) */
    int have_found;
    ulam__reach F;        /* over found: what ULAM__WALKS_FOUND walks are given */
    ulam_csr *T;          /* the transpose made here (NULL: not made) */
    const ulam_csr *Tuse; /* the transpose: T or the prepared file's stored one (NULL until asked) */
    ulam_push *push;      /* the push workspace on M (NULL until asked) */
    ulam__bidir *bidir;   /* the bidirectional planner's memo on push and Tuse (NULL until made:
                             ulam__analysis_bidir; src/bidir.c fills it) */
    double seconds;
};

/* The defaults. */
ulam_analysis_opts ulam__analysis_defaults(void)
{
    return (ulam_analysis_opts){.size = sizeof(ulam_analysis_opts), .continue_q = 0.0, .kernel_alpha = 1.0};
}

/* An analysis of M under opts. */
int ulam_analysis_alloc(const ulam_csr *M, const ulam_analysis_opts *opts, ulam_analysis **out, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix and an output");
    *out = NULL;
    ulam_analysis_opts o = ulam_analysis_defaults();
    if (opts) { /* the fields the caller's size holds */
        size_t sz = opts->size && opts->size < sizeof o ? opts->size : sizeof o;
        memcpy(&o, opts, sz);
    }
    if (M->nrows != M->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    if ((o.continue_q > 0 && !(o.continue_q < 1)) || !(o.kernel_alpha >= 0) || !isfinite(o.kernel_alpha))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a continuation below 1 and a finite kernel exponent >= 0");
    ulam_analysis *a = calloc(1, sizeof *a);
    if (!a) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an analysis");
    a->M = M, a->continue_q = o.continue_q > 0 ? o.continue_q : 0.0, a->alpha = o.kernel_alpha;
    const ulam_csr *mapped = NULL;
    if (o.system) ulam_system_lazy(o.system, &mapped, NULL);
    a->b = o.b, a->sys = mapped == M ? o.system : NULL;
    a->shared_bounds = o.shared_bounds != 0;
    *out = a;
    return ULAM_OK;
}

/* Free an analysis. */
ulam_analysis *ulam_analysis_free(ulam_analysis *a)
{
    if (!a) return NULL;
    ulam__bidir_free(a->bidir); /* first: it may hold an analysis of the transpose */
    for (int e = 0; e < 3; e++) ulam__kernel_free(a->k[e]);
    ulam__kernel_free(a->kr);
    free(a->found);
    ulam__push_free(a->push);
    ulam_csr_free(a->T);
    free(a->seen);
    free(a);
    return NULL;
}

/* The guards a query in mode `mode` needs, from the certificate or computed (kept). */
static int take_guard(ulam_analysis *a, int mode, ulam_error *err)
{
    int need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(mode);
    if ((a->g.computed & need) == need) return ULAM_OK;
    double t0 = ulam_now();
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = need | a->g.computed;
    go.kernel_alpha = a->alpha;
    int status = ULAM_OK;
    ulam_system_info si;
    ulam_system_get_info(a->sys, &si);
    if (a->sys && !ulam_certificate_guard(si.cert, a->continue_q, &go, &a->g)) a->guard_from = 1;
    else if (!(status = ulam_guard_check(a->M, a->continue_q, &go, &a->g, err))) a->guard_from = 2;
    a->seconds += ulam_now() - t0;
    return status;
}

/* The bounds over every state by one pass over M (ulam__reach_all; kept in a->R): ULAM_OK,
 * ULAM_ENOMEM, or the pass's status (a corrupt row, alpha's probabilities underflowing). */
static int pass_all(ulam_analysis *a)
{
    if (!a->seen && !(a->seen = ulam__malloc((size_t)a->M->nrows, 1))) return ULAM_ENOMEM;
    int status = ulam__reach_all(a->M, a->continue_q, a->alpha, a->seen, &a->R);
    if (status) a->R.bounds = 0;
    else a->bounds_from = 2, a->R.shared = a->shared_bounds;
    return status;
}

/* The bounds over every state, with b's scores when b is the shared one: the prepared file's,
 * else one pass over M (kept); NULL when memory runs out or a row is corrupt (the solver then
 * searches the start's reach itself, and reports what it finds). */
static const ulam__reach *take_bounds(ulam_analysis *a)
{
    double t0 = ulam_now();
    if (!a->R.bounds) {
        if (a->sys && ulam__system_bounds(a->sys, a->continue_q, a->alpha, &a->R)) { /* seen NULL: every state */
            a->bounds_from = 1, a->R.shared = a->shared_bounds;
            if (a->R.b && a->R.b == a->b) a->b_from = 1;
            else a->R.b = NULL;
        } else if ((a->sys && !ulam_system_matrix(a->sys)) || pass_all(a)) {
            return NULL; /* a damaged file (the pass would read all of it), no memory or a corrupt row:
                            the solver searches */
        }
    }
    const double *sb = NULL;
    if (a->sys) ulam_system_lazy(a->sys, NULL, &sb);
    if (a->b && !a->R.b && (a->b != sb || ulam_system_rhs(a->sys, NULL)) && !ulam__reach_b(a->M, a->b, &a->R))
        a->b_from = 2; /* (a file's b verified whole first: the pass reads all of it) */
    a->seconds += ulam_now() - t0;
    return &a->R;
}

/* A solver for one query using what a holds. */
int ulam_analysis_solver(ulam_analysis *a, const double *b, const ulam_walk_opts *opts, ulam_solver **out,
                         ulam_error *err)
{
    ulam__clear(err);
    if (!a || !b || !opts || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis, b, options and an output");
    *out = NULL;
    ulam_walk_opts o = *opts;
    if ((o.kernel.continue_q > 0 ? o.kernel.continue_q : 0.0) != a->continue_q || o.kernel.kernel_alpha != a->alpha)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the analysis' continuation %g and kernel exponent %g",
                          a->continue_q, a->alpha);
    o.kernel.continue_q = a->continue_q;
    if (!o.policy.system && a->sys) o.policy.system = a->sys; /* the file's blocks verified as the walks reach them */
    int status;
    if (!o.policy.guard) {
        if (o.mode != ULAM_ADJOINT && o.mode != ULAM_FORWARD) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a mode");
        if ((status = take_guard(a, o.mode, err))) return status;
        o.policy.guard = &a->g;
    }
    int adj = o.mode == ULAM_ADJOINT, shared = adj && a->b && b == a->b && !o.query.nstarts;
    int e = o.estimator >= ULAM_COLLISION && o.estimator <= ULAM_EXPECTED ? o.estimator : -1;
    ulam__reach stored;
    int cheap = a->sys && ulam__system_bounds(a->sys, a->continue_q, a->alpha, &stored); /* the file's: no pass */
    /* every run prints an interval on the score range (stop.h): at a fixed budget too the file's
       bounds spare the solver its pass over all the start reaches */
    const ulam__reach *R = adj && (o.estimator == ULAM_ABSORPTION || o.stop.rel_err > 0 || cheap) ? take_bounds(a) : NULL;
    ulam_kernel *k = shared && e >= 0 ? a->k[e] : NULL;
    status = ulam__solver_alloc_reached(a->M, b, &o, R, k, out, err);
    if (!status && shared && e >= 0 && !k) a->k[e] = ulam__solver_keep_kernel_fixed(*out);
    return status;
}

/* The slot of an internal caller's kept kernel: a->k[estimator] for a fixed b, else a->kr (NULL:
 * an estimator out of range). */
static ulam_kernel **kernel_slot(ulam_analysis *a, const ulam_walk_opts *o, int how)
{
    if (!(how & ULAM__WALKS_FIXED)) return &a->kr;
    return o->estimator >= ULAM_COLLISION && o->estimator <= ULAM_EXPECTED ? &a->k[o->estimator] : NULL;
}

/* Keep the states s found its walks reach in a->found (have_found 0: none, or no memory). */
static void keep_found(ulam_analysis *a, const ulam_solver *s)
{
    const char *r = ulam__solver_reached(s);
    a->have_found = 0;
    if (!r || (!a->found && !(a->found = ulam__malloc((size_t)a->M->nrows, 1)))) return;
    memcpy(a->found, r, (size_t)a->M->nrows);
    a->F = (ulam__reach){.seen = a->found};
    a->have_found = 1;
}

/* Walks on a's matrix run to their end with what a lends and keeps (see internal.h). */
int ulam__analysis_walks(ulam_analysis *a, const double *b, const ulam_walk_opts *o, int how, ulam_walk_result *result,
                         ulam_guard *guard, ulam_solver **out, ulam_error *err)
{
    if (out) *out = NULL;
    if (!a || !b || !o) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis, b and options");
    if ((o->kernel.continue_q > 0 ? o->kernel.continue_q : 0.0) != a->continue_q || o->kernel.kernel_alpha != a->alpha)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the analysis' continuation %g and kernel exponent %g",
                          a->continue_q, a->alpha);
    int status = how & ULAM__WALKS_ALL ? ulam__analysis_bounds_all(a, err) : ULAM_OK;
    if (status) return status;
    if (how & ULAM__WALKS_FIND) a->have_found = 0;
    const ulam__reach *reach = how & ULAM__WALKS_ALL ? &a->R : (how & ULAM__WALKS_FOUND) && a->have_found ? &a->F : NULL;
    ulam_kernel **slot = kernel_slot(a, o, how), *k = slot ? *slot : NULL;
    if (k && (!(how & ULAM__WALKS_KEEP) || k->K != a->M || k->continue_q != o->kernel.continue_q ||
              k->alpha != o->kernel.kernel_alpha || k->scores.estimator != o->estimator ||
              ((how & ULAM__WALKS_FIXED) && k->scores.b != b)))
        *slot = k = ulam__kernel_free(k); /* not made for these walks */
    ulam_solver *s = NULL;
    if ((status = ulam__solver_alloc_reached(a->M, b, o, reach, k, &s, err))) {
        if (k) *slot = ulam__kernel_free(k); /* a failed kernel is not kept */
        return status;
    }
    while (!status && !ulam_solver_done(s)) status = ulam_solver_iterate(s);
    if (result) ulam_solver_result(s, result);
    if (guard) ulam__solver_guard(s, guard);
    if (status) ulam_solver_error(s, err);
    if ((how & ULAM__WALKS_FIND) && !status) keep_found(a, s);
    if (slot && !k && (how & ULAM__WALKS_KEEP) && !status)
        *slot = how & ULAM__WALKS_FIXED ? ulam__solver_keep_kernel_fixed(s)
                : o->estimator != ULAM_EXPECTED ? ulam__solver_keep_kernel(s) : NULL;
    if (out) *out = s; /* after a failure the caller only frees it: it never reads a dropped kernel */
    else ulam_solver_free(s);
    if (k && status) *slot = ulam__kernel_free(k);
    return status;
}

/* a's guards in o (the walks' pins) when they pin a's own kernel (see internal.h). */
int ulam__analysis_pin_guard(ulam_analysis *a, const ulam_walk_opts *base, ulam_auto_opts *o, ulam_error *err)
{
    ulam__clear(err);
    if (!a || !base) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis and options");
    int mine = o->pin_continue && o->pin_alpha && o->pin_mode && base->mode == ULAM_ADJOINT &&
               (base->kernel.continue_q > 0 ? base->kernel.continue_q : 0.0) == a->continue_q && base->kernel.kernel_alpha == a->alpha;
    if (mine && !o->guard) {
        int status = take_guard(a, ULAM_ADJOINT, err);
        if (status) return status;
        o->guard = &a->g;
    }
    return ULAM_OK;
}

/* M's transpose, made once (the prepared file's when it stores one); *seconds (may be NULL): the
 * time spent making it in this call (0 when a had it). */
const ulam_csr *ulam__analysis_transpose(ulam_analysis *a, double *seconds, ulam_error *err)
{
    ulam__clear(err);
    if (seconds) *seconds = 0.0;
    if (!a) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis"), NULL;
    if (a->Tuse) return a->Tuse;
    double t0 = ulam_now();
    const ulam_csr *stored = a->sys ? ulam_system_transpose(a->sys) : NULL; /* prepare --transpose */
    if (stored && (stored->nrows != a->M->nrows || ulam_csr_nnz(stored) != ulam_csr_nnz(a->M))) stored = NULL;
    if (!stored && ulam_csr_transpose(a->M, &a->T))
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the transpose"), NULL;
    a->Tuse = stored ? stored : a->T;
    double dt = ulam_now() - t0;
    a->seconds += dt;
    if (seconds) *seconds = dt;
    return a->Tuse;
}

/* M's transpose, made once. */
const ulam_csr *ulam_analysis_transpose(ulam_analysis *a, ulam_error *err)
{
    return ulam__analysis_transpose(a, NULL, err);
}

/* The push workspace on M, made once. */
ulam_push *ulam__analysis_push(ulam_analysis *a, ulam_error *err)
{
    ulam__clear(err);
    if (!a) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis"), NULL;
    if (!a->push && ulam__push_alloc(a->M, &a->push))
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a push workspace"), NULL;
    return a->push;
}

/* The matrix a is made for. */
const ulam_csr *ulam__analysis_matrix(const ulam_analysis *a)
{
    return a->M;
}

/* The kernel a is made for: its continuation (0: analog) and exponent. */
void ulam__analysis_kernel(const ulam_analysis *a, double *continue_q, double *alpha)
{
    *continue_q = a->continue_q, *alpha = a->alpha;
}

/* An empty memo. */
ulam__bidir *ulam__bidir_alloc(void)
{
    return calloc(1, sizeof(ulam__bidir));
}

/* Free a memo. */
ulam__bidir *ulam__bidir_free(ulam__bidir *m)
{
    if (!m) return NULL;
    free(m->idx), free(m->val), free(m->ones);
    ulam_analysis_free(m->at);
    free(m);
    return NULL;
}


/* a's memo of the bidirectional planner (made at the first call). */
ulam__bidir *ulam__analysis_bidir(ulam_analysis *a, ulam_error *err)
{
    if (!a->bidir && !(a->bidir = ulam__bidir_alloc()))
        ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the plan's memo");
    return a->bidir;
}

/* 1 when a's queries share its bounds over every state (ulam_analysis_opts.shared_bounds). */
int ulam__analysis_shares_bounds(const ulam_analysis *a)
{
    return a && a->shared_bounds;
}

/* a's bounds over every state with the shared b's scores (see internal.h). */
const ulam__reach *ulam__analysis_bounds(ulam_analysis *a)
{
    return take_bounds(a);
}

/* a's bounds over every state (see internal.h). */
int ulam__analysis_bounds_all(ulam_analysis *a, ulam_error *err)
{
    if (a->R.bounds) return ULAM_OK;
    if (a->sys) /* the file's, or a pass once its every block is verified */
        return take_bounds(a) ? ULAM_OK : ulam__fail(err, ULAM_ESYNTAX, 0, -1, "an intact prepared file and memory "
                                                     "for the walks' reach");
    double t0 = ulam_now();
    int status = pass_all(a);
    a->seconds += ulam_now() - t0;
    if (!status) return ULAM_OK;
    return status == ULAM_ENOMEM ? ulam__fail(err, status, 0, -1, "memory for the walks' reach")
                                 : ulam__fail(err, status, 0, -1, "rows with columns in range and finite, nonzero "
                                              "values (the matrix is corrupt)");
}

/* What a holds so far. */
void ulam_analysis_get_info(const ulam_analysis *a, ulam_analysis_info *info)
{
    if (!info) return;
    memset(info, 0, sizeof *info);
    if (!a) return;
    info->bounds = a->R.bounds ? a->bounds_from : 0;
    info->b_scores = a->b_from, info->guard = a->guard_from, info->seconds = a->seconds;
    for (int e = 0; e < 3; e++) info->kernel_rows += a->k[e] ? atomic_load(&a->k[e]->built) : 0;
}
