/* Outer iterations on a partition (ulam_dist.h): MCSA, whose residual is a product with M over
 * the ranks' rows, and single source, a push of e_s by products with M then forward walks from
 * what is left.  Both need the part's rows of M and of M' (ULAM_PART_BOTH).  Every norm that
 * decides a stop is a largest |entry|, the same bits whatever the split. */
#include "part.h"
#include "stop.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The halo of this rank's rows of M and room gv for a vector there, made on every rank together;
 * nonzero (on every rank) on failure. */
static int halo_open(const ulam_part *p, const ulam_comm *c, ulam__halo *h, double **gv)
{
    int64_t bad = ulam__halo_make(p, c, &p->m, h);
    *gv = malloc(((size_t)h->nghost + 1) * sizeof **gv);
    bad |= !*gv;
    if (c->nranks > 1 && c->sum(c->ctx, &bad, 1)) bad = 1; /* all stop together */
    return bad != 0;
}

/* y = M v on this rank's rows, v at its rows (own) and at their halo (gv, swapped first): the
 * same doubles, in the same order, as a product with the whole v; nonzero on a failed exchange. */
static int matvec(const ulam_part *p, const ulam_comm *c, const ulam__halo *h, const double *own, double *gv, double *y)
{
    if (ulam__halo_swap(p, c, h, own, gv)) return 1;
    const ulam__rows *A = &p->m;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        double s = 0.0;
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) s += A->val[q] * ulam__halo_at(p, A, h, own, gv, q);
        y[i] = s;
    }
    return 0;
}

/* r = b - (I - M) x on this rank's rows (gv: room for x's halo); the largest |r_i| over the
 * ranks into *rmax; nonzero on a failed exchange. */
static int residual(const ulam_part *p, const ulam_comm *c, const ulam__halo *h, const double *x, double *gv, double *r,
                    double *rmax)
{
    if (matvec(p, c, h, x, gv, r)) return 1;
    *rmax = 0.0;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        r[i] = p->b[i] - x[i] + r[i];
        if (fabs(r[i]) > *rmax) *rmax = fabs(r[i]);
    }
    return ulam__dist_largest(c, rmax);
}

/* The largest |b_i| over the ranks. */
static int largest_abs(const ulam_part *p, const ulam_comm *c, const double *v, double *out)
{
    *out = 0.0;
    for (int64_t i = 0; i < p->last - p->first; i++)
        if (fabs(v[i]) > *out) *out = fabs(v[i]);
    return ulam__dist_largest(c, out);
}

/* Set 0's values v at this rank's rows to the ranks holding the same rows in the other sets
 * (forward walks in sets leave their answer on set 0); nonzero on a failed exchange. */
static int from_set0(const ulam_part *p, const ulam_comm *c, double *v)
{
    if (p->sets <= 1) return 0;
    int64_t rows = p->last - p->first;
    size_t *cnt = calloc((size_t)c->nranks * 2, sizeof *cnt), bytes = (size_t)rows * sizeof *v;
    double *send = p->set == 0 ? malloc((size_t)(p->sets - 1) * bytes + 1) : NULL;
    void *got = NULL;
    int bad = !cnt || (p->set == 0 && !send);
    for (int s = 1; !bad && p->set == 0 && s < p->sets; s++) {
        cnt[s * p->nranks + p->rank] = bytes;
        memcpy((char *)send + (size_t)(s - 1) * bytes, v, bytes);
    }
    if (!bad) bad = c->exchange(c->ctx, send ? send : (void *)v, cnt, &got, cnt + c->nranks);
    size_t total = 0;
    for (int r = 0; !bad && r < c->nranks; r++) total += cnt[c->nranks + r];
    if (!bad && p->set > 0 && total == bytes && cnt[c->nranks + p->rank] == bytes) memcpy(v, got, bytes);
    else if (!bad && total != (p->set > 0 ? bytes : 0)) bad = 1;
    free(cnt), free(send), free(got);
    return bad;
}

/* x of (I - M) x = b by MCSA on the partition. */
int ulam_dist_mcsa(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, double tol, int max_iter,
                   double *x, ulam_dist_mcsa_info *info, ulam_error *err)
{
    ulam_dist_result all;
    return ulam__dist_mcsa(p, comm, o, tol, max_iter, x, info, &all, err);
}

/* As ulam_dist_mcsa, every correction's walks' counts summed into *all (bytes and rounds too). */
int ulam__dist_mcsa(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, double tol, int max_iter,
                    double *x, ulam_dist_mcsa_info *info, ulam_dist_result *all, ulam_error *err)
{
    ulam__clear(err);
    *all = (ulam_dist_result){0};
    if (!p || !comm || !x || !info || !(tol > 0) || max_iter < 1)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part, a comm, x, info, tol > 0 and max_iter >= 1");
    if (!p->m.rowptr || !p->t.rowptr) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part holding M and M' (ULAM_PART_BOTH)");
    if (!p->b) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a b in the prepared file (ulam prepare M.mtx --rhs b.mtx)");
    *info = (ulam_dist_mcsa_info){0};
    int64_t rows = p->last - p->first;
    double *gv = NULL, *r = malloc(((size_t)rows + 1) * sizeof *r), *d = malloc(((size_t)rows + 1) * sizeof *d);
    ulam__halo h = {0};
    int status = halo_open(p, comm, &h, &gv) ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the halo and an exchange that succeeds")
                 : r && d ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for MCSA's vectors");
    double bmax = 0.0, rmax = 0.0;
    if (!status && largest_abs(p, comm, p->b, &bmax)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks");
    memset(x, 0, (size_t)rows * sizeof *x);
    ulam_dist_opts w = o ? *o : ulam_dist_defaults();
    for (int it = 0; !status; it++) {
        if (residual(p, comm, &h, x, gv, r, &rmax)) {
            status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
            break;
        }
        info->residual = bmax > 0 ? rmax / bmax : rmax;
        if (!(info->residual > tol) || it == max_iter) break;
        for (int64_t i = 0; i < rows; i++) x[i] += r[i]; /* the Richardson step */
        if (residual(p, comm, &h, x, gv, r, &rmax)) {
            status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
            break;
        }
        ulam_dist_result res;
        w.seed = ulam_rng_substream(o ? o->seed : 1, ULAM_STREAM_ITERATION, (uint64_t)it); /* docs/streams.md */
        status = ulam__dist_forward_b(p, comm, &w, r, d, NULL, &res, err);
        if (!status && from_set0(p, comm, d)) status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange that succeeds");
        for (int64_t i = 0; !status && i < rows; i++) x[i] += d[i]; /* the Monte Carlo correction */
        info->iterations = it + 1, info->walks += res.walks, info->steps += res.steps, info->crossings += res.crossings;
        info->cut += res.cut;
        all->walks += res.walks, all->steps += res.steps, all->crossings += res.crossings, all->cut += res.cut;
        all->bytes += res.bytes, all->rounds += res.rounds;
    }
    ulam__halo_free(&h);
    free(gv), free(r), free(d);
    return status;
}

/* x = (I - M)^-1 e_source on the partition: push, then walks from the rest. */
int ulam_dist_source(const ulam_part *p, const ulam_comm *comm, int64_t source, const ulam_dist_opts *o, double tol,
                     int max_rounds, double *x, double *se, ulam_dist_source_info *info, ulam_error *err)
{
    ulam_dist_result walks;
    return ulam__dist_source(p, comm, source, o, tol, max_rounds, 0, x, se, NULL, NULL, NULL, info, &walks, err);
}

/* Whether terminal walks from r apply to the part (M >= 0, r >= 0 and every column sum of M below
 * 1, over every rank): then each walk scores 0 or one value at each row.  -1 on a failed exchange. */
static int ends_apply(const ulam_part *p, const ulam_comm *c, const double *r)
{
    double cmax = 0.0, neg = 0.0;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        cmax = fmax(cmax, p->t.rowsum[i]), neg = r[i] < 0 ? 1.0 : neg;
        for (int64_t q = p->t.rowptr[i]; q < p->t.rowptr[i + 1]; q++) neg = p->t.val[q] < 0 ? 1.0 : neg;
    }
    if (ulam__dist_largest(c, &cmax) || ulam__dist_largest(c, &neg)) return -1;
    return neg == 0.0 && cmax < 1.0;
}

/* The 95% interval of x_i = p_i + y_i from h of N walks ending at row i (column sum S of M),
 * each end worth R = mass / (1 - S): p_i + R [a, b], b from the KL interval of a count fixed in
 * advance, a from the one at the lower index of K chosen of n by estimate
 * (ulam__stop_lower_index); widened to hold the printed estimate x (the collision walks' y_i, from
 * the same walks: a superset keeps the coverage). */
static void ends_interval(double p, double x, double h, int64_t N, double mass, double S, int64_t K, int64_t n,
                          double *lo, double *hi)
{
    double R = mass / (1.0 - S), a, b, a2, b2;
    ulam__stop_kl_interval(N, h / (double)N, 0, &a, &b);
    ulam__stop_kl_interval(N, h / (double)N, ulam__stop_lower_index(0, K, n), &a2, &b2);
    *lo = fmin(p + R * a2, x), *hi = fmax(p + R * b, x);
}

/* As ulam_dist_source (source -1: from the system's b, max_rounds 0 for no push), the walks' counts
 * (bytes and rounds too) into *walks; lo and hi (or NULL)
 * each x_i's 95% interval from terminal walks where they apply (ends_apply; K the components
 * a top table lists; *terminal, when given, 1 then), else -INFINITY and INFINITY. */
int ulam__dist_source(const ulam_part *p, const ulam_comm *comm, int64_t source, const ulam_dist_opts *o, double tol,
                      int max_rounds, int64_t K, double *x, double *se, double *lo, double *hi, int *terminal,
                      ulam_dist_source_info *info, ulam_dist_result *walks, ulam_error *err)
{
    ulam__clear(err);
    *walks = (ulam_dist_result){0};
    if (!p || !comm || !x || !se || !info || !(tol >= 0) || max_rounds < 0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part, a comm, x, se, info, tol >= 0 and max_rounds >= 0");
    if (!p->m.rowptr || !p->t.rowptr) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part holding M and M' (ULAM_PART_BOTH)");
    if (source < -1 || source >= p->n) return ulam__fail(err, ULAM_EINVAL, 0, source, "a source in 1 .. %lld", (long long)p->n);
    if (source < 0 && !p->b) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a b in the prepared file (ulam prepare M.mtx --rhs b.mtx)");
    *info = (ulam_dist_source_info){0};
    int64_t rows = p->last - p->first;
    double *gv = NULL, *r = calloc((size_t)rows + 1, sizeof *r), *y = malloc(((size_t)rows + 1) * sizeof *y), mass = 0.0;
    double *h = lo && hi ? malloc(((size_t)rows + 1) * sizeof *h) : NULL;
    ulam__halo h0 = {0};
    int status = halo_open(p, comm, &h0, &gv) ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the halo and an exchange that succeeds")
                 : r && y && (h || !lo || !hi) ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the push's vectors");
    memset(x, 0, (size_t)rows * sizeof *x);
    if (!status && source >= p->first && source < p->last) r[source - p->first] = 1.0;
    if (!status && source < 0) memcpy(r, p->b, (size_t)rows * sizeof *r);
    double rmax = 1.0;
    if (!status && source < 0 && largest_abs(p, comm, r, &rmax)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks");
    int ends = status ? 0 : h ? ends_apply(p, comm, r) : 0;
    if (ends < 0) status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange that succeeds");
    for (int k = 0; !status && k < max_rounds && rmax > tol; k++) { /* x += r, r <- M r */
        for (int64_t i = 0; i < rows; i++) x[i] += r[i];
        memcpy(y, r, (size_t)rows * sizeof *y);
        if (matvec(p, comm, &h0, y, gv, r)) status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange that succeeds");
        if (!status && largest_abs(p, comm, r, &rmax)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks");
        info->rounds = k + 1;
    }
    info->residual = rmax;
    ulam_dist_result res = {0};
    if (!status) /* (I - M)^-1 r by walks, their ends counted when that applies (r >= 0 too: M >= 0 and e_s) */
        status = ends > 0 ? ulam__dist_forward_ends(p, comm, o, r, y, se, h, &mass, &res, err)
                          : ulam__dist_forward_b(p, comm, o, r, y, se, &res, err);
    if (!status && (from_set0(p, comm, y) || from_set0(p, comm, se) || (ends > 0 && from_set0(p, comm, h))))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange that succeeds");
    int64_t N = o ? o->walks : ulam_dist_defaults().walks;
    if (!status && ends > 0 && res.cut > 0) ends = 0; /* a walk cut at max_steps ended nowhere: no count holds x */
    for (int64_t i = 0; !status && i < rows; i++) {
        if (lo && hi && ends > 0 && rmax > 0.0)
            ends_interval(x[i], x[i] + y[i], h[i], N, mass, fmin(1.0, p->t.rowsum[i]), K, p->n, &lo[i], &hi[i]);
        else if (lo && hi)
            lo[i] = rmax == 0.0 ? x[i] : -INFINITY, hi[i] = rmax == 0.0 ? x[i] : INFINITY;
        x[i] += y[i];
        if (rmax == 0.0) se[i] = 0.0; /* nothing left to walk: the push is the answer */
    }
    info->walks = res.walks, info->steps = res.steps, info->crossings = res.crossings, info->cut = res.cut;
    *walks = res;
    if (terminal) *terminal = !status && ends > 0 && rmax > 0.0;
    ulam__halo_free(&h0);
    free(gv), free(r), free(y), free(h);
    return status;
}

/* The residual r = b - (I - M) x at this rank's rows with each entry's rounding bound e (x's halo
 * in gv): the largest r + e and e - r over the ranks into up[0], up[1] (both >= 0), and up[2] 1
 * when every entry of M is nonnegative, else 0; nonzero on a failed exchange. */
static int residual_bounds(const ulam_part *p, const ulam_comm *c, const ulam__halo *h, const double *b, const double *x,
                           double *gv, double up[3], double *pos, double *neg_part)
{
    if (ulam__halo_swap(p, c, h, x, gv)) return 1;
    const ulam__rows *A = &p->m;
    double neg = 0.0;
    up[0] = up[1] = 0.0;
    for (int64_t i = 0; i < p->last - p->first; i++) {
        double s = 0.0, a = 0.0;
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) {
            double xj = ulam__halo_at(p, A, h, x, gv, q);
            s += A->val[q] * xj, a += fabs(A->val[q] * xj);
            if (A->val[q] < 0) neg = 1.0;
        }
        double r = b[i] - x[i] + s; /* (len + 3) roundings, each at most DBL_EPSILON / 2 of the sizes summed */
        double e = (double)(A->rowptr[i + 1] - A->rowptr[i] + 4) * DBL_EPSILON * (fabs(b[i]) + fabs(x[i]) + a);
        up[0] = fmax(up[0], (r + e) * (1.0 + DBL_EPSILON)), up[1] = fmax(up[1], (e - r) * (1.0 + DBL_EPSILON));
        pos[i] = fmax(r + e, 0.0) * (1.0 + DBL_EPSILON), neg_part[i] = fmax(e - r, 0.0) * (1.0 + DBL_EPSILON);
    }
    int bad = ulam__dist_largest(c, &up[0]) || ulam__dist_largest(c, &up[1]) || ulam__dist_largest(c, &neg);
    up[2] = neg == 0.0;
    return bad;
}

/* An upper bound on the sum of the rows' v_i >= 0 (this rank's rows; top: their largest over every
 * rank) the same bits at any split: each v_i / top rounded up to a multiple of 2^-30 and counted
 * as an integer, so the sum over the ranks (set 0's: every row once) is exact; nonzero on a failed sum. */
static int sum_up(const ulam_part *p, const ulam_comm *c, const double *v, double top, double *out)
{
    int64_t k = 0;
    for (int64_t i = 0; top > 0 && p->set == 0 && i < p->last - p->first; i++) /* one set's rows: each once */
        k += (int64_t)ceil(v[i] / top * 1073741824.0) + 1;
    if (c->nranks > 1 && c->sum(c->ctx, &k, 1)) return 1;
    *out = top > 0 ? top * ((double)k / 1073741824.0) * (1.0 + 4.0 * DBL_EPSILON) : 0.0;
    return 0;
}

/* A certified range of the exact solution around x (see ulam_dist.h). */
int ulam_dist_bound(const ulam_part *p, const ulam_comm *comm, const double *b, const double *x, int iters, double *lo,
                    double *hi, double *worst, ulam_error *err)
{
    ulam__clear(err);
    if (!p || !comm || !x || !lo || !hi || !worst || iters < 1)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part, a comm, x, lo, hi, worst and iters >= 1");
    if (!p->m.rowptr) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part holding the rows of M");
    if (!b && !p->b) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a b in the prepared file (ulam prepare M.mtx --rhs b.mtx)");
    int64_t rows = p->last - p->first;
    for (int64_t i = 0; i < rows; i++)
        if (!isfinite(x[i])) return ulam__fail(err, ULAM_EINVAL, 0, p->first + i, "a finite x");
    double *gv = NULL, *cv = malloc(((size_t)rows + 1) * sizeof *cv), u = INFINITY, up[3] = {0, 0, 0};
    double *rp = malloc(((size_t)rows + 1) * sizeof *rp), *rn = malloc(((size_t)rows + 1) * sizeof *rn);
    ulam__halo h = {0};
    int status = halo_open(p, comm, &h, &gv) ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the halo and an exchange that succeeds")
                 : cv && rp && rn ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld doubles", (long long)rows);
    if (!status) status = ulam__dist_cw(p, comm, iters, &u, cv, err);
    if (!status && residual_bounds(p, comm, &h, b ? b : p->b, x, gv, up, rp, rn))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    /* With M' held and ||M||_1 = c < 1 (its largest column sum of |M|: a row sum of M'), also
     * |(I - M)^-1 r|_i <= ||(I - M)^-1 r||_1 <= ||r||_1 / (1 - c), r's parts summed the same bits at
     * any split (sum_up); each end the nearer of the two ranges.  R-MAT PageRank (M = 0.85 P'):
     * the power iteration certifies no u < 1 within iters products, c = 0.85 exactly. */
    double cmax = INFINITY, l1p = INFINITY, l1n = INFINITY;
    if (!status && p->t.rowptr) {
        cmax = 0.0;
        for (int64_t i = 0; i < rows; i++) cmax = fmax(cmax, p->t.rowsum[i] * (1.0 + (double)(p->t.rowptr[i + 1] - p->t.rowptr[i]) * DBL_EPSILON));
        double sp = 0.0, sn = 0.0;
        if (ulam__dist_largest(comm, &cmax) || sum_up(p, comm, rp, up[0], &sp) || sum_up(p, comm, rn, up[1], &sn))
            status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
        if (cmax < 1.0) {
            double k1 = (1.0 + 8.0 * DBL_EPSILON) / (1.0 - cmax);
            l1p = (up[2] ? sp : sp + sn) * k1, l1n = (up[2] ? sn : sp + sn) * k1;
        }
    }
    /* x* - x = (I - M)^-1 r = sum_k M^k r; |r| <= rho 1 <= rho v / min v, so |M|^k |r| <= rho u^k v / min v.
     * With M >= 0 the sum keeps r's signs: above by r's positive part, below by its negative part. */
    double k = (1.0 + 8.0 * DBL_EPSILON) / (1.0 - u), above = up[2] ? up[0] : fmax(up[0], up[1]), below = up[2] ? up[1] : above;
    int certified = u < 1.0 || isfinite(l1p);
    *worst = 0.0;
    for (int64_t i = 0; !status && i < rows; i++) {
        double slack = 2.0 * DBL_EPSILON * fabs(x[i]);
        double dn = u < 1.0 ? fmin(below * cv[i] * k, l1n) : l1n, dp = u < 1.0 ? fmin(above * cv[i] * k, l1p) : l1p;
        lo[i] = certified ? x[i] - (dn + slack) : NAN;
        hi[i] = certified ? x[i] + (dp + slack) : NAN;
        *worst = certified ? fmax(*worst, (hi[i] - lo[i]) / 2.0) : INFINITY;
    }
    if (!status && certified && ulam__dist_largest(comm, worst)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks");
    ulam__halo_free(&h);
    free(gv), free(cv), free(rp), free(rn);
    return status;
}
