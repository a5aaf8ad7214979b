/* The second moment of adjoint walks' scores on a partition, aimed at their starts (the
 * single-machine construction is src/solve.c's second_moment_aimed; this is it on a rank's rows
 * with products through the halo).  Y = sum over a walk's visits of |w| a_j, a = |b|, bounds
 * |X|; h = E[Y | start j] solves h = a + |M| h and m = E[Y^2 | start j] solves m = r + M^ m with
 * r = a (2 h - a), M^ = diag(max(1, S)) |M| (the analog kernel's weight grows by max(1, S_i) a
 * step).  Both by certified supersolutions z (r + A z <= z gives z >= m by induction; no
 * spectral condition), so E X^2 <= z at the query's row.  Only exact maxima cross ranks and
 * each row's sum is taken in its own order: the same bits at any rank count. */
#include "part.h"
#include "supersolve.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* y = r + B v on this rank's rows (B = |A|, or diag(max(1, S)) |A| with grow; r NULL: 0), v at
 * its rows and its halo gv, each row's sum rounded up by its length's roundings. */
static void product(const ulam_part *p, const ulam__rows *A, const ulam__halo *h, int grow, const double *r,
                    const double *v, const double *gv, double *y)
{
    for (int64_t i = 0; i < p->last - p->first; i++) {
        double t = 0.0, f = grow && A->rowsum[i] > 1.0 ? A->rowsum[i] : 1.0;
        int64_t len = A->rowptr[i + 1] - A->rowptr[i];
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) t += fabs(A->val[q]) * ulam__halo_at(p, A, h, v, gv, q);
        y[i] = ((r ? r[i] : 0.0) + t * f) * (1.0 + (double)(len + 4) * DBL_EPSILON);
    }
}

/* What the search needs on a partition: the rank's rows of A (|M|, or M^ with grow), its
 * halo and ghost values, and the queries whose rows' least certified values are kept. */
typedef struct {
    const ulam_part *p;
    const ulam_comm *c;
    const ulam__rows *A;
    const ulam__halo *h;
    int grow;
    int64_t row;       /* >= 0: a candidate is worth its value at this row (its owner's, exact) */
    const double *wt;  /* else, non-NULL: worth sum_i wt_i z_i (exact_sum, the candidate in zc), else max z */
    double *zc;
    double *gv;
    const int64_t *idx;
    int64_t nq;
    double *q;
} dist_ctx;

/* y = r + A v on this rank's rows, v's halo exchanged first (src/supersolve.h's product). */
static int dist_apply(void *ctx, const double *r, const double *v, double *y)
{
    dist_ctx *d = ctx;
    if (ulam__halo_swap(d->p, d->c, d->h, v, d->gv)) return 1;
    product(d->p, d->A, d->h, d->grow, r, v, d->gv, y);
    return 0;
}

/* x[0..k) to their largest over ranks (src/supersolve.h's largest). */
static int dist_largest(void *ctx, double *x, int k)
{
    const dist_ctx *d = ctx;
    return ulam__dist_largest_n(d->c, x, k);
}

/* sum over every row of wt_i v_i (>= 0; set 0's rows), the same bits at any rank count: each term
 * rounded up to a multiple of G = 2^-32 times a power of two above the largest term (exact over
 * ranks) and the multiples summed as integers; >= the exact sum; INFINITY past range, -1: failed. */
static double exact_sum(const ulam_part *p, const ulam_comm *c, const double *wt, const double *v)
{
    int64_t rows = p->last - p->first, q = 0;
    double big = 0.0;
    for (int64_t i = 0; p->set == 0 && i < rows; i++) big = fmax(big, wt[i] * v[i] * (1.0 + 2.0 * DBL_EPSILON));
    if (ulam__dist_largest_n(c, &big, 1)) return -1.0;
    if (!(big > 0)) return 0.0;
    if (!isfinite(big)) return INFINITY;
    int e;
    frexp(big, &e); /* big < 2^e */
    double G = ldexp(1.0, e - 32);
    for (int64_t i = 0; p->set == 0 && i < rows; i++) q += (int64_t)ceil(wt[i] * v[i] * (1.0 + 2.0 * DBL_EPSILON) / G);
    if (c->nranks > 1 && c->sum(c->ctx, &q, 1)) return -1.0;
    return (double)q * G * (1.0 + 4.0 * DBL_EPSILON);
}

/* What candidate m + bb (res + phi) is worth on this rank's rows, rounded up: its value at the
 * row d->row (0 elsewhere: the largest over ranks is the owner's), its exact_sum against d->wt,
 * or its largest entry. */
static double dist_worth(void *ctx, const double *m, const double *res, double phi, double bb)
{
    const dist_ctx *d = ctx;
    int64_t rows = d->p->last - d->p->first;
    if (d->row >= 0) {
        int64_t i = d->row - d->p->first;
        return i >= 0 && i < rows ? (m[i] + bb * (res[i] + phi)) * (1.0 + 1e-9) : 0.0;
    }
    if (d->wt) {
        for (int64_t i = 0; i < rows; i++) d->zc[i] = (m[i] + bb * (res[i] + phi)) * (1.0 + 1e-9);
        double v = exact_sum(d->p, d->c, d->wt, d->zc);
        return v < 0 ? INFINITY : v;
    }
    double top = 0.0;
    for (int64_t i = 0; i < rows; i++) top = fmax(top, (m[i] + bb * (res[i] + phi)) * (1.0 + 1e-9));
    return top;
}

/* Each query row of this rank's: the least value a candidate gave it. */
static void dist_offer(void *ctx, const double *m, const double *res, double phi, double bb)
{
    dist_ctx *d = ctx;
    for (int64_t k = 0; k < d->nq; k++)
        if (d->idx[k] >= d->p->first && d->idx[k] < d->p->last) {
            int64_t i = d->idx[k] - d->p->first;
            d->q[k] = fmin(d->q[k], (m[i] + bb * (res[i] + phi)) * (1.0 + 1e-9));
        }
}

/* A certified z >= the solution of m = r + B m (r >= 0; B from A and grow, as in product) on this
 * rank's rows (src/supersolve.c): the candidate of least worth (dist_worth: at row, against wt,
 * or max z); q[k] (this rank's own query rows; INFINITY elsewhere): the least
 * a candidate gave at row idx[k].  *any: whether a candidate held.  Nonzero on a failed
 * exchange or memory. */
static int supersolve(const ulam_part *p, const ulam_comm *c, const ulam__rows *A, const ulam__halo *h, int grow,
                      int64_t row, const double *wt, const double *r, const int64_t *idx, int64_t nq, double *z, double *q,
                      int *any)
{
    int64_t rows = p->last - p->first;
    double *gv = malloc(((size_t)h->nghost + 1) * sizeof *gv), best = INFINITY;
    double *zc = wt ? malloc(((size_t)rows + 1) * sizeof *zc) : NULL; /* worth against wt: the candidate */
    dist_ctx d = {p, c, A, h, grow, row, wt, zc, gv, idx, nq, q};
    ulam__super s = {&d, rows, NULL, INFINITY, 1.0 + 1e-9, dist_apply, dist_largest, dist_worth, dist_offer};
    for (int64_t k = 0; k < nq; k++) q[k] = INFINITY;
    for (int64_t i = 0; i < rows; i++) z[i] = INFINITY;
    int64_t nomem = !gv || (wt && !zc);
    if (c->nranks > 1 && c->sum(c->ctx, &nomem, 1)) nomem = 1; /* all stop together */
    int bad = nomem || ulam__super_solve(&s, r, z, &best, NULL);
    *any = isfinite(best);
    free(gv), free(zc);
    return bad;
}

/* Each query's certified E X^2 of one adjoint collision score (analog kernel, walks from
 * index[k]) into v2[k], the same on every rank; INFINITY where no supersolution held (part.h). */
int ulam__dist_moment(const ulam_part *p, const ulam_comm *comm, const int64_t *index, int64_t nq, double *v2,
                      ulam_error *err)
{
    int64_t rows = p->last - p->first;
    size_t nr = (size_t)rows + 1;
    double *a = calloc(nr, sizeof *a), *hz = malloc(nr * sizeof *hz), *r = malloc(nr * sizeof *r);
    double *q = malloc(((size_t)nq + 1) * sizeof *q);
    int64_t *bits = calloc((size_t)nq + 1, sizeof *bits);
    ulam__halo h = {0};
    int64_t bad = !a || !hz || !r || !q || !bits || ulam__halo_make(p, comm, &p->m, &h);
    if (comm->nranks > 1 && comm->sum(comm->ctx, &bad, 1)) bad = 1; /* all stop together */
    int status = bad ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the second moment's halo and an exchange that succeeds") : ULAM_OK;
    int held = 0;
    for (int64_t i = 0; !status && i < rows; i++) a[i] = fabs(p->b[i]);
    if (!status && supersolve(p, comm, &p->m, &h, 0, -1, NULL, a, index, 0, hz, q, &held))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    for (int64_t i = 0; !status && held && i < rows; i++) r[i] = a[i] * (2.0 * hz[i] - a[i]) * (1.0 + 4.0 * DBL_EPSILON);
    if (!status && held && supersolve(p, comm, &p->m, &h, 1, -1, NULL, r, index, nq, hz, q, &held))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    for (int64_t k = 0; !status && k < nq; k++) { /* each query's value from the rank that owns its row (set 0) */
        double x = held && index[k] >= p->first && index[k] < p->last && p->set == 0 ? q[k] : 0.0;
        memcpy(&bits[k], &x, 8);
    }
    if (!status && comm->nranks > 1 && comm->sum(comm->ctx, bits, (int)nq))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    for (int64_t k = 0; !status && k < nq; k++) {
        memcpy(&v2[k], &bits[k], 8);
        if (!held || !(v2[k] >= 0.0)) v2[k] = INFINITY;
    }
    ulam__halo_free(&h);
    free(a), free(hz), free(r), free(q), free(bits);
    return status;
}

/* The certified E X^2 of one forward collision history's tally at row watch (analog kernel on
 * M', starts by |b|, weight +-||b||_1) into *v2, the same on every rank; INFINITY where no
 * supersolution held (part.h).  Y = sum over the visits of |w| [s = watch] bounds |X|: with a =
 * e_watch, h = a + |M'| h and m = r + M'^ m, r = a (2 h - a) (only h at watch counts, so h is
 * aimed there), and E X^2 <= ||b||_1 sum_j |b_j| m_j (m aimed at that sum, taken exactly). */
int ulam__dist_moment_forward(const ulam_part *p, const ulam_comm *comm, int64_t watch, double *v2, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    size_t nr = (size_t)rows + 1;
    double *a = calloc(nr, sizeof *a), *hz = malloc(nr * sizeof *hz), *r = malloc(nr * sizeof *r);
    double *wt = malloc(nr * sizeof *wt), q = INFINITY, total = 0.0;
    ulam__halo h = {0};
    int64_t bad = !a || !hz || !r || !wt || ulam__halo_make(p, comm, &p->t, &h);
    if (comm->nranks > 1 && comm->sum(comm->ctx, &bad, 1)) bad = 1; /* all stop together */
    int status = bad ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the second moment's halo and an exchange that succeeds") : ULAM_OK;
    int held = 0;
    *v2 = INFINITY;
    for (int64_t i = 0; !status && i < rows; i++) a[i] = p->first + i == watch ? 1.0 : 0.0, wt[i] = fabs(p->b[i]);
    if (!status && supersolve(p, comm, &p->t, &h, 0, watch, NULL, a, NULL, 0, hz, &q, &held))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    for (int64_t i = 0; !status && held && i < rows; i++) r[i] = a[i] * (2.0 * hz[i] - a[i]) * (1.0 + 4.0 * DBL_EPSILON);
    if (!status && held && supersolve(p, comm, &p->t, &h, 1, -1, wt, r, NULL, 0, hz, &q, &held))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    double s = !status && held ? exact_sum(p, comm, wt, hz) : INFINITY;
    for (int64_t i = 0; !status && held && i < rows; i++) r[i] = 1.0;
    if (!status && held) total = exact_sum(p, comm, wt, r); /* ||b||_1, rounded up */
    if (!status && (s < 0 || total < 0)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    if (!status && held && s >= 0 && total >= 0) *v2 = total * s * (1.0 + 4.0 * DBL_EPSILON);
    if (!(*v2 >= 0.0)) *v2 = INFINITY;
    ulam__halo_free(&h);
    free(a), free(hz), free(r), free(wt);
    return status;
}
