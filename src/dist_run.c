/* One partitioned run as `ulam solve --partition` asks it (ulam_dist_run in ulam_dist.h): the
 * variance guard, the mode's walks, the certified range around x, single source's top table
 * (and forward mode's, when asked) gathered to rank 0 and each rank's rows and peak memory.  src/dist_report.c writes it. */
#include "part.h"
#include "stop.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Each rank's rows and peak resident memory (KiB, ulam__peak_rss_kib), in rank order, into
 * v[0 .. 2 nranks) on every rank; nonzero when the sum fails. */
static int per_rank(const ulam_comm *c, int64_t rows, int64_t *v)
{
    memset(v, 0, (size_t)c->nranks * 2 * sizeof *v);
    v[c->rank] = rows;
    v[c->nranks + c->rank] = (int64_t)ulam__peak_rss_kib();
    return c->nranks > 1 && c->sum(c->ctx, v, 2 * c->nranks);
}

/* The certified range [lo, hi] of every x_i at this rank's rows (ulam_dist_bound; single source's
 * b is e_source, source 0-based, -1: the system's b) and its largest half-width *worst. */
static int bound(const ulam_part *p, const ulam_comm *c, int64_t source, const double *x, double *lo, double *hi,
                 double *worst, ulam_error *err)
{
    size_t rows = (size_t)(p->last - p->first) + 1;
    double *e = source >= 0 ? calloc(rows, sizeof *e) : NULL;
    if (source >= 0 && !e) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the bounds");
    if (e && source >= p->first && source < p->last) e[source - p->first] = 1.0;
    int status = ulam_dist_bound(p, c, e, x, 200, lo, hi, worst, err);
    free(e);
    return status;
}

/* Larger estimate first, then the smaller index (NaN last). */
static int by_estimate(const void *a, const void *b)
{
    const ulam_dist_top *p = a, *q = b;
    if (p->x != q->x) return isnan(p->x) ? 1 : isnan(q->x) ? -1 : p->x < q->x ? 1 : -1;
    return (p->i > q->i) - (p->i < q->i);
}

/* Each rank's K largest of its rows' components (rows of them from row first) to rank 0, whose
 * tops[0 .. *ntop) get the K largest of all; nonzero on failure. */
static int gather_top(const ulam_comm *c, const double *x, const double *se, const double *lo, const double *hi,
                      int64_t first, int64_t rows, int64_t K, ulam_dist_top *tops, int64_t *ntop)
{
    ulam_dist_top *e = malloc(((size_t)rows + 1) * sizeof *e);
    size_t *cnt = calloc((size_t)c->nranks * 2, sizeof *cnt);
    void *got = NULL;
    int bad = !e || !cnt;
    for (int64_t i = 0; !bad && i < rows; i++) e[i] = (ulam_dist_top){first + i, x[i], se[i], lo[i], hi[i]};
    if (!bad) qsort(e, (size_t)rows, sizeof *e, by_estimate);
    int64_t k = rows < K ? rows : K, all = k;
    if (!bad && c->nranks > 1) {
        cnt[0] = (size_t)k * sizeof *e;
        bad = c->exchange(c->ctx, e, cnt, &got, cnt + c->nranks);
        all = 0;
        for (int r = 0; !bad && r < c->nranks; r++) all += (int64_t)(cnt[c->nranks + r] / sizeof *e);
        if (!bad && c->rank == 0) qsort(got, (size_t)all, sizeof *e, by_estimate);
    }
    const ulam_dist_top *t = c->nranks > 1 ? got : e;
    *ntop = c->rank == 0 && !bad ? (all < K ? all : K) : 0;
    if (*ntop) memcpy(tops, t, (size_t)*ntop * sizeof *tops);
    free(e), free(cnt), free(got);
    return bad;
}

/* The mode's walks into ans (the radius already there). */
static int walks(const ulam_part *p, const ulam_comm *c, const ulam_dist_ask *a, ulam_dist_answer *ans, double *lo,
                 double *hi, ulam_error *err)
{
    int64_t rows = p->last - p->first, in_set0 = c->sets <= 1 || c->rank < c->nranks / c->sets; /* set 0's ranks hold x */
    ulam_dist_mcsa_info mi = {0};
    ulam_dist_source_info si = {0};
    double *sl = NULL, *sh = NULL; /* single source, forward's top table: the walks' 95% intervals */
    int status;
    if (a->mode == ULAM_DIST_ADJOINT) {
        status = ulam_dist_adjoint_ci(p, c, a->index, a->nq, &a->o, a->rel_err, ans->res, ans->ci, err);
        if (!status) ans->r = ans->res[0];
        return status;
    }
    if (a->mode == ULAM_DIST_MCSA) status = ulam__dist_mcsa(p, c, &a->o, a->tol, a->max_iter, ans->x, &mi, &ans->r, err);
    else if (a->mode == ULAM_DIST_SOURCE || (a->mode == ULAM_DIST_FORWARD && !a->index && ans->tops)) /* forward's top
                                                                     table: walks from b, no push (source -1) */
        status = (sl = malloc(((size_t)rows + 1) * sizeof *sl)) && (sh = malloc(((size_t)rows + 1) * sizeof *sh))
                     ? ulam__dist_source(p, c, a->mode == ULAM_DIST_SOURCE ? a->source : -1, &a->o, 1e-4,
                                         a->mode == ULAM_DIST_SOURCE ? 1000 : 0, a->top, ans->x, ans->se, sl, sh,
                                         &ans->terminal, &si, &ans->r, err)
                     : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the intervals");
    else status = ulam__dist_forward_ci(p, c, &a->o, a->index ? a->index[0] : -1, ans->x, ans->se, &ans->r,
                                        a->index ? ans->ci : NULL, err);
    if (!status && a->mode == ULAM_DIST_FORWARD && a->index && a->rel_err > 0) { /* no stop rule: judged after */
        const ulam_dist_ci *ci = ans->ci; /* the walks, on the interval the report prints */
        ans->ci[0].met = ulam__stop_printed_met(ci->lo, ci->hi, ans->r.estimate, a->rel_err);
    }
    ans->iterations = a->mode == ULAM_DIST_MCSA ? mi.iterations : a->mode == ULAM_DIST_SOURCE ? si.rounds : 0;
    ans->residual = a->mode == ULAM_DIST_MCSA ? mi.residual : a->mode == ULAM_DIST_SOURCE ? si.residual : 0.0;
    if (!status && (a->mode != ULAM_DIST_FORWARD || a->bound))
        status = bound(p, c, a->mode == ULAM_DIST_SOURCE ? a->source : -1, ans->x, lo, hi, &ans->worst, err);
    else for (int64_t i = 0; i < rows; i++) lo[i] = -INFINITY, hi[i] = INFINITY; /* forward: no range */
    for (int64_t i = 0; !status && sl && sh && i < rows; i++) /* the certified range and the walks' interval: their overlap */
        if (!(sl[i] > hi[i] || sh[i] < lo[i])) lo[i] = fmax(lo[i], sl[i]), hi[i] = fmin(hi[i], sh[i]);
    free(sl), free(sh);
    int top = a->mode == ULAM_DIST_SOURCE || (a->mode == ULAM_DIST_FORWARD && ans->tops); /* forward: tops asks */
    if (!status && top &&
        gather_top(c, ans->x, ans->se, lo, hi, p->first, in_set0 ? rows : 0, a->top, ans->tops, &ans->ntop))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    return status;
}

/* One partitioned run (see ulam_dist.h). */
int ulam_dist_run(const ulam_part *p, const ulam_comm *comm, const ulam_dist_ask *ask, ulam_dist_answer *ans,
                  ulam_error *err)
{
    ulam__clear(err);
    if (!p || !comm || !ask || !ans || !ans->ranks || ask->mode < ULAM_DIST_ADJOINT || ask->mode > ULAM_DIST_SOURCE)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part, a comm, an ask of a known mode and an answer with ranks");
    int forward = ask->mode != ULAM_DIST_ADJOINT;
    if (forward ? !ans->x || (ask->mode != ULAM_DIST_MCSA && !ans->se) || (ask->mode == ULAM_DIST_SOURCE && !ans->tops) ||
                      (ask->mode == ULAM_DIST_FORWARD && ask->index && !ans->ci) || (ans->tops && ask->top < 1)
                : !ans->res || !ans->ci)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the answer's arrays the mode fills");
    ans->n = p->n, ans->ntop = 0, ans->r = (ulam_dist_result){0};
    ans->rho = ans->worst = INFINITY, ans->iterations = 0, ans->residual = 0.0, ans->terminal = 0;
    size_t rows = (size_t)(p->last - p->first) + 1;
    double *lo = forward ? malloc(rows * sizeof *lo) : NULL, *hi = forward ? malloc(rows * sizeof *hi) : NULL;
    int status = forward && (!lo || !hi) ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the bounds")
                                         : ulam_dist_radius(p, comm, forward, 200, &ans->rho, err);
    if (!status) status = walks(p, comm, ask, ans, lo, hi, err);
    if (!status && per_rank(comm, p->last - p->first, ans->ranks))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    free(lo), free(hi);
    return status;
}
