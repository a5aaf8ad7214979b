/* Spectral radius of M, |M| or any linear operator.
 *
 * Plain power iteration never settles on a signed matrix whose dominant eigenvalues are
 * a complex pair, and an explicitly restarted Arnoldi stagnates on clustered spectra.
 * So: ARPACK-NG's implicitly restarted Arnoldi (dnaupd/dneupd, which = "LM"), stopped when
 * the dominant Ritz pair has ||A u - lambda u|| <= tol |lambda|; the residual reported is
 * recomputed from the returned eigenvector.  Small operators (n <= DENSE_MAX, where ARPACK's
 * nev < n - 1 constraint bites) are formed densely from n products and solved by dgeev. */
#include "internal.h"

#include <arpack.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { DENSE_MAX = 128, NEV = 2 };

/* The default options. */
ulam_spectral_opts ulam_spectral_defaults(void)
{
    return (ulam_spectral_opts){.tol = 1e-6, .max_restarts = 300, .krylov_dim = 20, .seed = 1};
}

typedef struct {
    const ulam_csr *A;
    int use_abs;
} csr_op_ctx;

/* y = A x or |A| x as an operator. */
static void csr_op(const void *ctx, const double *x, double *y)
{
    const csr_op_ctx *c = ctx;
    ulam_csr_matvec(c->A, c->use_abs, x, y);
}

/* Small n: form the matrix column by column from op(e_j), take all eigenvalues. */
static int radius_dense(int64_t n, void (*op)(const void *, const double *, double *),
                        const void *ctx, ulam_radius *out)
{
    double *a = ulam__malloc((size_t)(n * n), sizeof *a);
    double *e = ulam__calloc((size_t)n, sizeof *e);
    double *wr = ulam__malloc((size_t)n, sizeof *wr), *wi = ulam__malloc((size_t)n, sizeof *wi);
    int status = ULAM_ENOMEM;
    if (!a || !e || !wr || !wi) goto done;
    for (int64_t j = 0; j < n; j++) {
        e[j] = 1.0;
        op(ctx, e, a + j * n); /* column j, column-major */
        e[j] = 0.0;
        out->matvecs++;
    }
    status = ULAM_ENOCONV;
    if (LAPACKE_dgeev(LAPACK_COL_MAJOR, 'N', 'N', (lapack_int)n, a, (lapack_int)n, wr, wi, NULL, 1,
                      NULL, 1) != 0)
        goto done;
    out->rho = 0.0;
    for (int64_t j = 0; j < n; j++) out->rho = fmax(out->rho, hypot(wr[j], wi[j]));
    out->residual = 0.0;
    out->converged = 1;
    status = ULAM_OK;
done:
    free(a), free(e), free(wr), free(wi);
    return status;
}

/* ||A u - lambda u|| / (|lambda| ||u||) for u = xr + i xi (xi NULL when real). */
static double ritz_residual(int64_t n, void (*op)(const void *, const double *, double *),
                            const void *ctx, double lr, double li, const double *xr,
                            const double *xi, double *work, ulam_radius *out)
{
    double rr = 0.0, uu = 0.0;
    op(ctx, xr, work);
    out->matvecs++;
    for (int64_t k = 0; k < n; k++) {
        double d = work[k] - lr * xr[k] + (xi ? li * xi[k] : 0.0);
        rr += d * d;
        uu += xr[k] * xr[k];
    }
    if (xi) {
        op(ctx, xi, work);
        out->matvecs++;
        for (int64_t k = 0; k < n; k++) {
            double d = work[k] - li * xr[k] - lr * xi[k];
            rr += d * d;
            uu += xi[k] * xi[k];
        }
    }
    double lam = hypot(lr, li);
    return lam > 0 && uu > 0 ? sqrt(rr / uu) / lam : (rr == 0 ? 0.0 : INFINITY);
}

typedef struct {
    a_int n, ncv, lworkl;
    double *resid, *v, *workd, *workl, *dr, *di, *z, *workev;
    a_int *select;
} arpack_ws;

/* Free the ARPACK workspace. */
static void ws_free(arpack_ws *w)
{
    free(w->resid), free(w->v), free(w->workd), free(w->workl), free(w->dr), free(w->di);
    free(w->z), free(w->workev), free(w->select);
}

/* Allocate the ARPACK workspace for n and ncv. */
static int ws_alloc(arpack_ws *w, a_int n, a_int ncv)
{
    memset(w, 0, sizeof *w);
    w->n = n;
    w->ncv = ncv;
    w->lworkl = 3 * ncv * ncv + 6 * ncv;
    w->resid = ulam__malloc((size_t)n, sizeof(double));
    w->v = ulam__malloc((size_t)n * (size_t)ncv, sizeof(double));
    w->workd = ulam__malloc(3 * (size_t)n, sizeof(double));
    w->workl = ulam__malloc((size_t)w->lworkl, sizeof(double));
    w->dr = ulam__malloc((size_t)ncv + 1, sizeof(double));
    w->di = ulam__malloc((size_t)ncv + 1, sizeof(double));
    w->z = ulam__malloc((size_t)n * (NEV + 1), sizeof(double));
    w->workev = ulam__malloc(3 * (size_t)ncv, sizeof(double));
    w->select = ulam__calloc((size_t)ncv, sizeof(a_int));
    int ok = w->resid && w->v && w->workd && w->workl && w->dr && w->di && w->z && w->workev && w->select;
    if (!ok) ws_free(w);
    return ok ? ULAM_OK : ULAM_ENOMEM;
}

/* Largest-modulus Ritz value of the last Arnoldi factorisation (when not converged). */
static void last_ritz(const arpack_ws *w, const a_int *ipntr, ulam_radius *out)
{
    const double *rr = w->workl + ipntr[5] - 1, *ri = w->workl + ipntr[6] - 1,
                 *bd = w->workl + ipntr[7] - 1;
    for (a_int k = 0; k < w->ncv; k++) {
        double lam = hypot(rr[k], ri[k]);
        if (lam > out->rho) {
            out->rho = lam;
            out->residual = lam > 0 ? bd[k] / lam : INFINITY;
        }
    }
}

/* Dominant eigenvalue from dneupd, and its recomputed residual. */
static int extract(arpack_ws *w, a_int *iparam, a_int *ipntr, double tol,
                   void (*op)(const void *, const double *, double *), const void *ctx,
                   ulam_radius *out)
{
    a_int ierr = 0;
    dneupd_c(1, "A", w->select, w->dr, w->di, w->z, w->n, 0.0, 0.0, w->workev, "I", w->n, "LM", NEV,
             tol, w->resid, w->ncv, w->v, w->n, iparam, ipntr, w->workd, w->workl, w->lworkl, &ierr);
    if (ierr != 0) return ULAM_ENOCONV;
    a_int nconv = iparam[4], best = 0;
    for (a_int k = 1; k < nconv; k++)
        if (hypot(w->dr[k], w->di[k]) > hypot(w->dr[best], w->di[best])) best = k;
    /* a complex pair occupies two columns of z: (re, im) at the first of the pair */
    a_int col = best;
    if (w->di[best] != 0.0 && best > 0 && w->di[best] < 0 && w->dr[best - 1] == w->dr[best]) col = best - 1;
    const double *xr = w->z + (size_t)col * (size_t)w->n;
    const double *xi = w->di[best] != 0.0 && col + 1 <= NEV ? xr + w->n : NULL;
    out->rho = hypot(w->dr[best], w->di[best]);
    out->residual = ritz_residual(w->n, op, ctx, w->dr[col], fabs(w->di[col]), xr, xi, w->workd, out);
    out->converged = out->residual <= 10 * tol;
    return ULAM_OK;
}

/* Spectral radius of a linear operator. */
int ulam_spectral_radius_op(int64_t n, void (*op)(const void *ctx, const double *x, double *y),
                            const void *ctx, int positive_start, const ulam_spectral_opts *opts,
                            ulam_radius *out)
{
    if (n < 1 || !op || !out) return ULAM_EINVAL;
    ulam_spectral_opts o = opts ? *opts : ulam_spectral_defaults();
    if (!(o.tol > 0) || o.max_restarts < 1 || o.krylov_dim < 1) return ULAM_EINVAL;
    memset(out, 0, sizeof *out);
    if (n <= DENSE_MAX) return radius_dense(n, op, ctx, out);
    if (n > INT32_MAX) return ULAM_EOVERFLOW;
    a_int ncv = o.krylov_dim < 2 * NEV + 1 ? 2 * NEV + 1 : o.krylov_dim;
    arpack_ws w;
    if (ws_alloc(&w, (a_int)n, ncv)) return ULAM_ENOMEM;
    ulam_rng rng;
    ulam_rng_seed(&rng, o.seed, 0x5eed);
    for (int64_t i = 0; i < n; i++) w.resid[i] = positive_start ? 1.0 : ulam_rng_uniform(&rng) - 0.5;
    a_int iparam[11] = {0}, ipntr[14] = {0}, ido = 0, info = 1; /* info = 1: use resid */
    iparam[0] = 1;                                            /* exact shifts */
    iparam[2] = o.max_restarts;
    iparam[6] = 1; /* mode 1: A x = lambda x */
    for (;;) {
        dnaupd_c(&ido, "I", w.n, "LM", NEV, o.tol, w.resid, w.ncv, w.v, w.n, iparam, ipntr, w.workd,
                 w.workl, w.lworkl, &info);
        if (ido != -1 && ido != 1) break;
        op(ctx, w.workd + ipntr[0] - 1, w.workd + ipntr[1] - 1);
        out->matvecs++;
    }
    int status = ULAM_OK;
    if (info == 0 && iparam[4] >= 1) status = extract(&w, iparam, ipntr, o.tol, op, ctx, out);
    else if (info == 1 || info == 3 || (info == 0 && iparam[4] < 1)) last_ritz(&w, ipntr, out);
    else status = ULAM_ENOCONV;
    ws_free(&w);
    return status;
}

/* Spectral radius of A or |A|. */
int ulam_spectral_radius(const ulam_csr *A, int use_abs, const ulam_spectral_opts *opts,
                         ulam_radius *out)
{
    if (!A || !out) return ULAM_EINVAL;
    if (A->nrows != A->ncols) return ULAM_ENOTSQUARE;
    csr_op_ctx ctx = {A, use_abs};
    return ulam_spectral_radius_op(A->nrows, csr_op, &ctx, use_abs, opts, out);
}
