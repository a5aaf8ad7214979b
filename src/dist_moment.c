/* The second moment of adjoint walks' scores on a partition, aimed at their starts (the
 * single-machine construction is src/solve.c's second_moment_aimed; this is it on a rank's rows
 * with products through the halo).  Y = sum over a walk's visits of |w| a_j, a = |b|, bounds
 * |X|; h = E[Y | start j] solves h = a + |M| h and m = E[Y^2 | start j] solves m = r + M^ m with
 * r = a (2 h - a), M^ = diag(max(1, S)) |M| (the analog kernel's weight grows by max(1, S_i) a
 * step).  Both by certified supersolutions z (r + A z <= z gives z >= m by induction; no
 * spectral condition), so E X^2 <= z at the query's row.  Only exact maxima cross ranks and
 * each row's sum is taken in its own order: the same bits at any rank count. */
#include "part.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* y = r + A v on this rank's rows (A = |M|, or M^ with grow; r NULL: 0), v at its rows and its
 * halo gv, each row's sum rounded up by its length's roundings. */
static void product(const ulam_part *p, const ulam__halo *h, int grow, const double *r, const double *v, const double *gv,
                    double *y)
{
    const ulam__rows *A = &p->m;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        double t = 0.0, f = grow && A->rowsum[i] > 1.0 ? A->rowsum[i] : 1.0;
        int64_t len = A->rowptr[i + 1] - A->rowptr[i];
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) t += fabs(A->val[q]) * ulam__halo_at(p, A, h, v, gv, q);
        y[i] = ((r ? r[i] : 0.0) + t * f) * (1.0 + (double)(len + 4) * DBL_EPSILON);
    }
}

enum { ITER = 400, NF = 5 };

/* A certified z >= the solution of m = r + A m (r >= 0) on this rank's rows: lazy iterates m <-
 * (m + r + A m) / 2 from r, and every fourth one the candidates m + beta e, e = res + phi max res
 * (res = r + A m - m, turning towards A's Perron vector), beta = max res / (e - A e) (src/solve.c
 * moment_solve, whose margins it keeps).  z: the candidate of least max z (its rows here); q[k]
 * (this rank's own query rows; INFINITY elsewhere): the least a candidate gave at row idx[k].
 * Stops when 40 iterates lower max z by less than 0.1% or r + A m <= m.  *any: whether a
 * candidate held.  Nonzero on a failed exchange or memory. */
static int supersolve(const ulam_part *p, const ulam_comm *c, const ulam__halo *h, int grow, const double *r,
                      const int64_t *idx, int64_t nq, double *z, double *q, int *any)
{
    static const double phis[NF] = {0.0, 1e-12, 1e-8, 1e-4, 1e-2};
    int64_t rows = p->last - p->first;
    size_t nr = (size_t)rows + 1, ng = (size_t)h->nghost + 1;
    double *m = malloc(nr * sizeof *m), *y = malloc(nr * sizeof *y), *res = malloc(nr * sizeof *res);
    double *ar = malloc(nr * sizeof *ar), *rs = malloc(nr * sizeof *rs), *one = malloc(nr * sizeof *one);
    double *gv = malloc(ng * sizeof *gv), *g1 = malloc(ng * sizeof *g1), best = INFINITY;
    int bad = !m || !y || !res || !ar || !rs || !one || !gv || !g1;
    *any = 0;
    for (int64_t k = 0; k < nq; k++) q[k] = INFINITY;
    for (int64_t i = 0; !bad && i < rows; i++) m[i] = r[i], one[i] = 1.0, z[i] = INFINITY;
    for (int64_t g = 0; !bad && g < h->nghost; g++) g1[g] = 1.0;
    if (!bad) product(p, h, grow, NULL, one, g1, rs); /* A's row sums */
    for (int it = 0, last = 0; !bad && it < ITER && it - last < 40; it++) {
        if ((bad = ulam__halo_swap(p, c, h, m, gv))) break;
        product(p, h, grow, r, m, gv, y);
        double D = 0.0;
        for (int64_t i = 0; i < rows; i++) res[i] = fmax(y[i] * (1.0 + 1e-10) - m[i], 0.0), D = fmax(D, res[i]);
        if (it % 4 != 3) { /* a lazy step; the check every fourth iterate */
            for (int64_t i = 0; i < rows; i++) m[i] += res[i] / 2.0 / (1.0 + 1e-10);
            continue;
        }
        if ((bad = ulam__dist_largest_n(c, &D, 1)) || !isfinite(D)) break;
        if (!(D > 0)) { /* r + A m <= m already */
            double top = 0.0;
            for (int64_t i = 0; i < rows; i++) top = fmax(top, m[i]);
            if ((bad = ulam__dist_largest_n(c, &top, 1))) break;
            if (top < best)
                for (int64_t i = 0; i < rows; i++) z[i] = m[i];
            for (int64_t k = 0; k < nq; k++)
                if (idx[k] >= p->first && idx[k] < p->last) q[k] = fmin(q[k], m[idx[k] - p->first]);
            *any = 1;
            break;
        }
        if ((bad = ulam__halo_swap(p, c, h, res, gv))) break;
        product(p, h, grow, NULL, res, gv, ar);
        double beta[NF] = {0}, top[NF] = {0};
        for (int fl = 0; fl < NF; fl++) {
            double phi = phis[fl] * D;
            for (int64_t i = 0; i < rows && isfinite(beta[fl]); i++) {
                double e = res[i] + phi, gap = e - (ar[i] + phi * rs[i]) * (1.0 + 1e-10);
                if (!isfinite(m[i]) || !isfinite(e) || !isfinite(gap)) beta[fl] = INFINITY; /* overflow: none */
                else if (res[i] > 0) beta[fl] = gap > 0 ? fmax(beta[fl], res[i] / gap) : INFINITY;
                else if (gap < 0) beta[fl] = INFINITY;
            }
        }
        if ((bad = ulam__dist_largest_n(c, beta, NF))) break;
        for (int fl = 0; fl < NF; fl++)
            for (int64_t i = 0; isfinite(beta[fl]) && i < rows; i++)
                top[fl] = fmax(top[fl], (m[i] + beta[fl] * (1.0 + 1e-9) * (res[i] + phis[fl] * D)) * (1.0 + 1e-9));
        if ((bad = ulam__dist_largest_n(c, top, NF))) break;
        for (int fl = 0; fl < NF; fl++) {
            if (!isfinite(beta[fl])) continue;
            double phi = phis[fl] * D, bb = beta[fl] * (1.0 + 1e-9);
            *any = 1;
            for (int64_t k = 0; k < nq; k++)
                if (idx[k] >= p->first && idx[k] < p->last) {
                    int64_t i = idx[k] - p->first;
                    q[k] = fmin(q[k], (m[i] + bb * (res[i] + phi)) * (1.0 + 1e-9));
                }
            if (!(top[fl] < best)) continue;
            if (top[fl] < best * (1.0 - 1e-3)) last = it;
            best = top[fl];
            for (int64_t i = 0; i < rows; i++) z[i] = (m[i] + bb * (res[i] + phi)) * (1.0 + 1e-9);
        }
        for (int64_t i = 0; i < rows; i++) m[i] += res[i] / 2.0 / (1.0 + 1e-10); /* not past the solution */
    }
    free(m), free(y), free(res), free(ar), free(rs), free(one), free(gv), free(g1);
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
    if (!status && supersolve(p, comm, &h, 0, a, index, 0, hz, q, &held))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    for (int64_t i = 0; !status && held && i < rows; i++) r[i] = a[i] * (2.0 * hz[i] - a[i]) * (1.0 + 4.0 * DBL_EPSILON);
    if (!status && held && supersolve(p, comm, &h, 1, r, index, nq, hz, q, &held))
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
