/* Reverse local push on the adjoint equation y = e_t + M' y (y_j = ((I - M)^-1)_tj).
 *
 * The workspace keeps estimates p and residuals r with the invariant
 *     y = p + (I - M')^-1 r,   so for any b:  x_t = <p, b> + <r, x>   with (I - M) x = b.
 * Pushing state j moves r_j into p_j and spreads it over row j of M (r_k += M_jk r_j); both
 * sides of the invariant are unchanged (up to rounding).  States whose residual exceeds rmax
 * wait in a FIFO queue, each at most once; p and r are dense arrays of n, zero outside a list
 * of touched states, so a new target costs the states the last one touched, not n. */
#include "push.h"
#include "check.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

struct ulam_push {
    const ulam_csr *M; /* borrowed */
    int64_t n, target;
    double *p, *r;
    int32_t *touched; /* states with p or r possibly nonzero, ntouched of them */
    int64_t ntouched;
    unsigned char *mark; /* bit 1: in touched, bit 2: in the queue */
    int32_t *queue;      /* circular, n slots */
    int64_t head, len;
    double rmax;
    int64_t pushes, ops;
    double seconds;
    uint64_t stamp; /* changed by every start and run: what a plan made on this state recorded */
    int (*verify)(const void *ctx, int64_t j, int64_t *bad); /* row j checked before its first push (NULL: none) */
    const void *vctx;
    int64_t bad; /* the row whose check failed (-1: none) */
};

/* Free a push workspace; accepts and returns NULL. */
ulam_push *ulam__push_free(ulam_push *w)
{
    if (!w) return NULL;
    free(w->p), free(w->r), free(w->touched), free(w->mark), free(w->queue);
    free(w);
    return NULL;
}

/* A workspace for pushes on the square matrix M (borrowed until freed), M's structure checked
 * whole first when check is set. */
static int alloc(const ulam_csr *M, int check, ulam_push **out)
{
    if (!M || !out) return ULAM_EINVAL;
    *out = NULL;
    if (M->nrows != M->ncols) return ULAM_ENOTSQUARE;
    int bad = check ? ulam__csr_check_structure(M, NULL) : ULAM_OK; /* src/check.c */
    if (bad) return bad;
    ulam_push *w = calloc(1, sizeof *w);
    if (!w) return ULAM_ENOMEM;
    w->M = M, w->n = M->nrows, w->target = -1, w->bad = -1;
    size_t n = (size_t)M->nrows;
    w->p = ulam__alloc_big(n, sizeof *w->p); /* 2 MiB pages from 2 MiB up: a push reads them at random */
    w->r = ulam__alloc_big(n, sizeof *w->r);
    if (w->p) memset(w->p, 0, n * sizeof *w->p);
    if (w->r) memset(w->r, 0, n * sizeof *w->r);
    w->touched = ulam__malloc(n, sizeof *w->touched);
    w->mark = ulam__calloc(n, 1);
    w->queue = ulam__malloc(n, sizeof *w->queue);
    if (!w->p || !w->r || !w->touched || !w->mark || !w->queue) {
        ulam__push_free(w);
        return ULAM_ENOMEM;
    }
    *out = w;
    return ULAM_OK;
}

/* A workspace for pushes on the square matrix M (borrowed until freed), its structure checked. */
int ulam__push_alloc(const ulam_csr *M, ulam_push **out)
{
    return alloc(M, 1, out);
}

/* A workspace for pushes on M whose caller vouches for its structure: no pass over M. */
int ulam__push_alloc_trusted(const ulam_csr *M, ulam_push **out)
{
    return alloc(M, 0, out);
}

/* Add state j to the touched list if it is not there. */
static void touch(ulam_push *w, int64_t j)
{
    if (w->mark[j] & 1) return;
    w->mark[j] |= 1;
    w->touched[w->ntouched++] = (int32_t)j;
}

/* Queue state j if its residual exceeds rmax and it is not queued. */
static void enqueue(ulam_push *w, int64_t j)
{
    if ((w->mark[j] & 2) || !(fabs(w->r[j]) > w->rmax)) return;
    w->mark[j] |= 2;
    w->queue[(w->head + w->len++) % w->n] = (int32_t)j;
}

/* Start over for target t: p = 0, r = e_t. */
int ulam__push_start(ulam_push *w, int64_t target)
{
    if (!w || target < 0 || target >= w->n) return ULAM_EINVAL;
    for (int64_t q = 0; q < w->ntouched; q++) {
        int32_t j = w->touched[q];
        w->p[j] = w->r[j] = 0.0;
        w->mark[j] = 0;
    }
    w->ntouched = w->head = w->len = w->pushes = w->ops = 0;
    w->stamp++;
    w->seconds = 0.0;
    w->target = target;
    w->rmax = INFINITY;
    w->r[target] = 1.0;
    touch(w, target);
    return ULAM_OK;
}

/* Push until every |r_j| <= rmax.  ULAM_OK; ULAM_EINVAL for rmax <= 0 (or not started);
 * ULAM_ENOCONV once ops exceeds max_ops (> 0), with the invariant intact (the pushes so far
 * are whole) and the queue kept, so a later call goes on from there. */
int ulam__push_run(ulam_push *w, double rmax, int64_t max_ops)
{
    if (!w || w->target < 0 || !(rmax > 0) || !isfinite(rmax) || max_ops < 0) return ULAM_EINVAL;
    double t0 = ulam_now();
    const ulam_csr *M = w->M;
    w->rmax = rmax;
    w->stamp++;
    for (int64_t q = 0; q < w->ntouched; q++) enqueue(w, w->touched[q]);
    int status = ULAM_OK;
    while (w->len > 0) {
        if (max_ops > 0 && w->ops > max_ops) {
            status = ULAM_ENOCONV;
            break;
        }
        int64_t j = w->queue[w->head];
        w->head = (w->head + 1) % w->n, w->len--;
        w->mark[j] &= (unsigned char)~2u;
        double rj = w->r[j];
        if (!(fabs(rj) > rmax)) continue; /* signed rows can shrink a queued residual */
        if (w->verify && w->verify(w->vctx, j, &w->bad)) { /* a damaged row: nothing of it read */
            status = ULAM_ESYNTAX;
            break;
        }
        w->p[j] += rj;
        w->r[j] = 0.0;
        for (int64_t k = M->rowptr[j]; k < M->rowptr[j + 1]; k++) {
            int64_t c = M->colidx[k];
            w->r[c] += M->val[k] * rj;
            touch(w, c);
            enqueue(w, c);
        }
        w->pushes++;
        w->ops += M->rowptr[j + 1] - M->rowptr[j] + 1;
    }
    w->seconds += ulam_now() - t0;
    return status;
}

/* Check each row with verify before it is first pushed (see src/push.h). */
void ulam__push_set_verify(ulam_push *w, int (*verify)(const void *ctx, int64_t j, int64_t *bad), const void *ctx)
{
    w->verify = verify, w->vctx = ctx, w->bad = -1;
}

/* The row whose check failed the last run (-1: none). */
int64_t ulam__push_bad_row(const ulam_push *w)
{
    return w->bad;
}

/* The estimates p (dense, n entries). */
const double *ulam__push_estimates(const ulam_push *w)
{
    return w ? w->p : NULL;
}

/* The residuals r (dense, n entries). */
const double *ulam__push_residuals(const ulam_push *w)
{
    return w ? w->r : NULL;
}

/* What the pushes since the last start did. */
void ulam__push_report(const ulam_push *w, ulam_push_info *info)
{
    *info = (ulam_push_info){.target = -1};
    if (!w) return;
    info->target = w->target;
    info->rmax = w->rmax;
    info->pushes = w->pushes;
    info->ops = w->ops;
    info->touched = w->ntouched;
    info->seconds = w->seconds;
    for (int64_t q = 0; q < w->ntouched; q++) {
        double a = fabs(w->r[w->touched[q]]);
        info->r_sum += a;
        info->r_max = fmax(info->r_max, a);
        info->support += a > 0;
    }
}

/* The states whose p or r may be nonzero (*count of them). */
const int32_t *ulam__push_touched(const ulam_push *w, int64_t *count)
{
    *count = w->ntouched;
    return w->touched;
}

/* The matrix a workspace pushes on. */
const ulam_csr *ulam__push_matrix(const ulam_push *w)
{
    return w->M;
}

/* A count that changes whenever the workspace's state does (ulam__push_start, ulam__push_run). */
uint64_t ulam__push_stamp(const ulam_push *w)
{
    return w->stamp;
}

