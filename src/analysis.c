/* The analysis: what queries on one M share, made once and held across them (CSparse's cs_sqr
 * before cs_lu): the guards, the bounds over every state the rel_err rule and absorption need
 * (ulam__reach_all, or the prepared file's stored copy), the shared b's scores, a kept walk
 * kernel per estimator, and for point sources and sparse b (the bidirectional estimator) the
 * transpose (the prepared file's stored M^T when it has one), the push workspace and a place for
 * the planner's memo (src/bidir.h: the planner takes these from here, as CSparse's cs_lu takes
 * cs_sqr's result).  Each is made at the first query that needs it, so a single query from a
 * prepared file reads only the rows its walks reach. */
#include "bidir.h"
#include "kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct ulam_analysis {
    const ulam_csr *M;    /* borrowed */
    double continue_q;    /* normalised: 0 analog */
    double alpha;
    const double *b;      /* the shared b (borrowed; NULL: none) */
    const ulam_system *sys;
    ulam_guard g;         /* the guards so far (g.computed: which radii) */
    int guard_from;       /* 0 none, 1 certificate, 2 computed */
    ulam__reach R;        /* the bounds over every state (R.bounds 0: not yet) */
    char *seen;           /* n ones: R.seen */
    int bounds_from, b_from;
    ulam_kernel *k[3];    /* per estimator: the kept kernel of adjoint queries on b */
    ulam_csr *T;          /* the transpose made here (NULL: not made) */
    const ulam_csr *Tuse; /* the transpose: T or the prepared file's stored one (NULL until asked) */
    ulam_push *push;      /* the push workspace on M (NULL until asked) */
    ulam__bidir *bidir;   /* the bidirectional planner's memo on push and Tuse (NULL until asked) */
    double seconds;
};

/* The defaults. */
ulam_analysis_opts ulam_analysis_defaults(void)
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
    *out = a;
    return ULAM_OK;
}

/* Free an analysis. */
ulam_analysis *ulam_analysis_free(ulam_analysis *a)
{
    if (!a) return NULL;
    for (int e = 0; e < 3; e++) ulam__kernel_free(a->k[e]);
    ulam__bidir_free(a->bidir);
    ulam_push_free(a->push);
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
    if (a->sys && !ulam_certificate_guard(ulam_system_certificate(a->sys), a->continue_q, &go, &a->g)) a->guard_from = 1;
    else if (!(status = ulam_guard_check(a->M, a->continue_q, &go, &a->g, err))) a->guard_from = 2;
    a->seconds += ulam_now() - t0;
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
            a->bounds_from = 1;
            if (a->R.b && a->R.b == a->b) a->b_from = 1;
            else a->R.b = NULL;
        } else if ((a->sys && !ulam_system_matrix(a->sys)) || !(a->seen = ulam__malloc((size_t)a->M->nrows, 1))) {
            return NULL; /* a damaged file (the pass would read all of it) or no memory: the solver searches */
        } else if (!ulam__reach_all(a->M, a->continue_q, a->alpha, a->seen, &a->R)) {
            a->bounds_from = 2;
        } else {
            a->R.bounds = 0;
            return NULL;
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

/* One query to its end. */
int ulam_analysis_solve(ulam_analysis *a, const double *b, const ulam_walk_opts *opts, ulam_walk_result *result,
                        ulam_error *err)
{
    ulam_solver *s = NULL;
    int status = ulam_analysis_solver(a, b, opts, &s, err);
    return status ? status : ulam__solver_finish(s, result, err);
}

/* The walks' pins o (from ao, or the defaults) with a's guards when they pin a's own kernel. */
static int auto_pins(ulam_analysis *a, const ulam_walk_opts *base, const ulam_auto_opts *ao, ulam_auto_opts *o,
                     ulam_error *err)
{
    ulam__clear(err);
    if (!a || !base) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis and options");
    *o = ao ? *ao : ulam_auto_defaults();
    int mine = o->pin_continue && o->pin_alpha && o->pin_mode && base->mode == ULAM_ADJOINT &&
               (base->kernel.continue_q > 0 ? base->kernel.continue_q : 0.0) == a->continue_q && base->kernel.kernel_alpha == a->alpha;
    if (mine && !o->guard) {
        int status = take_guard(a, ULAM_ADJOINT, err);
        if (status) return status;
        o->guard = &a->g;
    }
    return ULAM_OK;
}

/* The walks' choice on a's bounds. */
int ulam_analysis_auto(ulam_analysis *a, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                       ulam_auto_result *res, ulam_solver **out, ulam_error *err)
{
    ulam_auto_opts o;
    int status = auto_pins(a, base, ao, &o, err);
    return status ? status : ulam__auto_solver_reach(a->M, b, base, &o, take_bounds(a), res, out, err);
}

/* The method table's choice, its walks row on a's bounds. */
int ulam_analysis_auto_start(ulam_analysis *a, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                             const ulam_method_opts *mo, ulam_choice *ch, ulam_run **out, ulam_error *err)
{
    ulam_auto_opts p;
    int status = auto_pins(a, o, ao, &p, err);
    return status ? status : ulam__auto_start_reach(a->M, b, o, &p, mo, take_bounds(a), a, ch, out, err);
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
ulam_push *ulam_analysis_push(ulam_analysis *a, ulam_error *err)
{
    ulam__clear(err);
    if (!a) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis"), NULL;
    if (!a->push && ulam_push_alloc(a->M, &a->push))
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

/* Where a keeps the bidirectional planner's memo (NULL until the planner makes it; a frees it). */
ulam__bidir **ulam__analysis_bidir_memo(ulam_analysis *a)
{
    return &a->bidir;
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
