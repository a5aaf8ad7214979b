/* The reference solve (include/ulam_reference.h): sparse or dense LU; past the memory limit CG
 * (M symmetric) or GMRES(50) refined until a certified range is narrow enough. */
#include "ulam_reference.h"
#include "bound.h"
#include "csr.h"
#include "direct.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The iterative reference's default cap on products with M: about 4e10 flops' worth (CG's
 * product and 5 vector updates, nnz + 10 n; GMRES(50)'s Gram-Schmidt about 100 n more), at
 * least 1000. */
static int64_t reference_cap(const ulam_csr *M, int cg)
{
    double n = (double)M->nrows, work = (double)M->rowptr[M->nrows] + (cg ? 10.0 : 110.0) * n;
    double cap = 4e10 / fmax(work, 1.0);
    return cap < 1000.0 ? 1000 : cap > 1e9 ? (int64_t)1e9 : (int64_t)cap;
}

/* Whether the reference solve of M is the sparse LU. */
static int reference_sparse(const ulam_csr *M, int lu)
{
    if (lu >= 0 || !M) return lu > 0;
    int64_t n = M->nrows;
    return ulam__direct_sparse_available() && n > 1000 && (double)M->rowptr[n] < 0.05 * (double)n * (double)n;
}

/* What the reference solve of M will be and need, before it starts. */
int ulam_reference_plan(const ulam_csr *M, int lu, int estimate, ulam_reference_info *p, ulam_error *err)
{
    ulam__clear(err);
    if (!p) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a place for the plan");
    *p = (ulam_reference_info){.sparse = reference_sparse(M, lu), .umfpack = ulam__direct_sparse_available(),
                               .bytes = NAN, .flops = NAN};
    if (!M) return ULAM_OK;
    p->cg = ulam__csr_symmetric(M) != 0, p->products = reference_cap(M, p->cg);
    double n = (double)M->nrows;
    if (!p->sparse) {
        size_t bytes = ulam_direct_bytes(M->nrows);
        p->bytes = bytes ? (double)bytes : INFINITY, p->flops = 2.0 / 3.0 * n * n * n;
        return ULAM_OK;
    }
    return estimate ? ulam__direct_sparse_estimate(M, &p->bytes, &p->flops, err) : ULAM_OK;
}

/* The half-width the goal judges: x[index]'s (its range into g->lo, g->hi), or the widest. */
static double goal_width(const ulam_reference_goal *g, const double *x, const double *lo, const double *hi,
                         double worst, ulam_reference_goal *out)
{
    if (g->index < 0) return worst;
    int64_t i = g->index;
    out->lo = lo[i], out->hi = hi[i];
    return isnan(lo[i]) ? INFINITY : fmax(x[i] - lo[i], hi[i] - x[i]);
}

/* Past the LU's memory: CG (M symmetric) or GMRES(50) in rounds of refinement, each from the
 * residual recomputed and to a tolerance the range so far asks for, until the goal's range is
 * narrow enough, a round no longer halves it, or the cap (see ulam_reference_goal). */
static int reference_iterative(const ulam_csr *M, const double *b, double *x, ulam_reference_goal *g,
                               ulam_direct_info *info, ulam_error *err)
{
    int64_t n = M->nrows;
    ulam_reference_goal in = *g;
    if (in.index >= n) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a goal index below n = %lld", (long long)n);
    g->met = g->capped = g->rounds = 0, g->products = g->certificate = 0, g->lo = g->hi = NAN, g->reached = INFINITY;
    double *h = NULL, u = 1.0, target = in.half_width > 0 ? in.half_width : 0.0;
    double *r = ulam__malloc((size_t)n + 1, sizeof *r), *d = ulam__malloc((size_t)n + 1, sizeof *d);
    double *lo = ulam__malloc((size_t)n + 1, sizeof *lo), *hi = ulam__malloc((size_t)n + 1, sizeof *hi);
    double *keep = ulam__malloc((size_t)n + 1, sizeof *keep);
    int status = r && d && lo && hi && keep ? ulam__bound_vector(M, &h, &u, &g->certificate) : ULAM_ENOMEM, conv = 0;
    /* CG needs I - M positive definite: M symmetric with rho(|M|) <= u < 1 certified (else GMRES) */
    g->cg = !status && u < 1.0 && ulam__csr_symmetric(M) != 0;
    g->cap = in.max_products > 0 ? in.max_products : reference_cap(M, g->cg);
    double floor_tol = g->cg ? 1e-10 : 1e-8, worst, width = INFINITY;
    memset(x, 0, (size_t)n * sizeof *x);
    if (!status) {
        int c = ulam__bound_range(M, b, x, h, u, lo, hi, &worst);
        status = c == -2 ? ULAM_ENOMEM : c < 0 ? ULAM_ENONFINITE : ULAM_OK;
        g->certified = c == 1;
        if (c == 1) width = goal_width(&in, x, lo, hi, worst, g);
    }
    while (!status && g->products < g->cap && !(g->certified && width <= target)) {
        /* the correction's tolerance: the range shrinks about as the residual (a tenth more for the
           norms' difference), never below CG's 1e-10 or GMRES's 1e-8 (a round refines further) */
        double tol = g->certified && target > 0 ? fmin(0.5, fmax(floor_tol, 0.1 * target / width)) : floor_tol;
        if (ulam__residual(M, b, x, r, NULL) < 0) {
            status = ULAM_ENONFINITE;
            break;
        }
        int it = 0, budget = (int)fmin((double)(g->cap - g->products), 2e9), s;
        double res;
        s = g->cg ? ulam_cg(M, r, tol, budget, d, &it, &res) : ulam_gmres(M, r, 50, tol, budget, d, &it, &res);
        g->products += it, g->rounds++;
        if (s == ULAM_ENOMEM || s == ULAM_EINVAL) {
            status = s;
            break;
        }
        if (s == ULAM_ENONFINITE) break; /* this round's correction is lost; x stands */
        memcpy(keep, x, (size_t)n * sizeof *x);
        for (int64_t i = 0; i < n; i++) x[i] += d[i];
        if (!g->certified) { /* one solve to the floor's residual: nothing to refine against */
            conv = s == ULAM_OK;
            break;
        }
        double was = width;
        int c = ulam__bound_range(M, b, x, h, u, lo, hi, &worst);
        if (c == -2) status = ULAM_ENOMEM;
        width = c == 1 ? goal_width(&in, x, lo, hi, worst, g) : INFINITY;
        if (!(width < was)) { /* worse: the round before stands */
            memcpy(x, keep, (size_t)n * sizeof *x);
            c = ulam__bound_range(M, b, x, h, u, lo, hi, &worst);
            width = c == 1 ? goal_width(&in, x, lo, hi, worst, g) : INFINITY;
        }
        if (!(width <= 0.5 * was) && width > target) break; /* not halved: the rounding's floor */
    }
    g->capped = g->products >= g->cap && !(g->certified && width <= target);
    g->reached = g->certified ? width : INFINITY;
    g->met = g->certified && (width <= target || (target == 0 && !g->capped));
    if (!status) { /* ||r||_inf / ||b||_inf, as the LU reports it */
        double rmax = 0.0, bmax = 0.0;
        if (ulam__residual(M, b, x, r, NULL) < 0) rmax = INFINITY;
        for (int64_t i = 0; i < n; i++) rmax = fmax(rmax, fabs(r[i])), bmax = fmax(bmax, fabs(b[i]));
        info->residual = bmax > 0 ? rmax / bmax : rmax;
    }
    free(r), free(d), free(lo), free(hi), free(keep), free(h);
    const char *name = g->cg ? "CG" : "GMRES(50)";
    if (status == ULAM_ENOMEM) return ulam__fail(err, status, 0, -1, "memory for the iterative reference (n = %lld)", (long long)n);
    if (status == ULAM_EINVAL) return ulam__fail(err, status, 0, -1, "a square matrix for the %s reference", name);
    if (status) return ulam__fail(err, status, 0, -1, "a finite residual in the iterative reference (%s)", name);
    if (g->met || (!g->certified && conv)) return ULAM_OK; /* uncertified: x to the floor's residual (g->certified 0) */
    if (!g->certified)
        return ulam__fail(err, ULAM_ENOCONV, 0, -1, "a vector certifying rho(|M|) below 1 for the %s reference's range "
                          "(it ran to a relative residual of %.3g in %lld products, uncertified)", name, info->residual,
                          (long long)g->products);
    if (g->capped)
        return ulam__fail(err, ULAM_ENOCONV, 0, -1, "the %s reference within its cap of %lld products: its certified "
                          "range reached +-%.3g, not the +-%.3g wanted", name, (long long)g->cap, width, target);
    return ulam__fail(err, ULAM_ENOCONV, 0, -1, "the %s reference's certified range to narrow to +-%.3g: it stopped "
                      "at +-%.3g, the rounding's floor (a round no longer halved it)", name, target, width);
}

/* Solve (I - M) x = b for reference. */
int ulam_reference_solve(const ulam_csr *M, const double *b, int lu, size_t max_bytes, ulam_reference_goal *iterative,
                         double *x, ulam_direct_info *info, const char **how, ulam_error *err)
{
    if (!M || !b || !x || !info || !err) {
        if (err) *err = (ulam_error){.status = ULAM_EINVAL, .index = -1, .msg = "a matrix, b, x and info"};
        return ULAM_EINVAL;
    }
    int sparse = reference_sparse(M, lu);
    if (how) *how = sparse ? "sparse LU" : "dense LU";
    int status = sparse ? ulam__direct_sparse(M, b, x, max_bytes, info, err) : ulam_direct_solve(M, b, x, max_bytes, info, err);
    if (status != ULAM_EMEMLIMIT || !iterative) return status;
    double t0 = ulam_now();
    *info = (ulam_direct_info){.rcond = NAN, .residual = NAN};
    ulam__clear(err);
    status = reference_iterative(M, b, x, iterative, info, err);
    if (how) *how = iterative->cg ? "CG" : "GMRES(50)";
    info->seconds = ulam_now() - t0;
    return status;
}
