/* Spectral radius of M, |M| or any linear operator.
 *
 * Plain power iteration never settles on a signed matrix whose dominant eigenvalues are
 * a complex pair, and an explicitly restarted Arnoldi stagnates on clustered spectra.
 * So: ARPACK-NG's implicitly restarted Arnoldi (dnaupd/dneupd, which = "LM"), stopped when
 * the dominant Ritz pair has ||A u - lambda u|| <= tol |lambda|; the residual reported is
 * recomputed from the returned eigenvector.  Small operators (n <= DENSE_MAX, where ARPACK's
 * nev < n - 1 constraint bites) are formed densely from n products and solved by dgeev.
 *
 * The radius of a nonnegative operator diag(left) |A| diag(right) (ulam__spectral_power, which
 * the guards use) comes instead from shifted power iteration with Collatz-Wielandt bounds: for
 * any positive x, min_i (Ax)_i / x_i <= rho <= max_i (Ax)_i / x_i, so each iterate certifies a
 * bracket. */
#include "spectral.h"
#include "csr.h"
#include "defaults.h"
#include "check.h"
#include "dynload.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { DENSE_MAX = 128, NEV = 2 };

/* The default options. */
ulam_spectral_opts ulam__spectral_defaults(void)
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

/* Balance a (n x n, column-major) by a diagonal similarity D^-1 a D in powers of 2 (Parlett and
 * Reinsch, as LAPACK's dgebal): the eigenvalues stay, but entries spanning 1e-201 to 1e299 come
 * within range of each other, where dgeev's own scaling by the largest would flush the smallest to
 * zero (rho 0 for a radius of 1e49). */
static void balance(int64_t n, double *a)
{
    for (int sweep = 0, changed = 1; changed && sweep < 100; sweep++) {
        changed = 0;
        for (int64_t i = 0; i < n; i++) {
            double c = 0.0, r = 0.0;
            for (int64_t k = 0; k < n; k++)
                if (k != i) c += fabs(a[i * n + k]), r += fabs(a[k * n + i]); /* column i, row i */
            if (c == 0.0 || r == 0.0) continue;
            int ec, er;
            frexp(c, &ec), frexp(r, &er);
            int e = (er - ec) / 2; /* c 2^e and r 2^-e meet halfway */
            if (abs(e) < 2) continue; /* within a factor 4: balanced enough */
            double f = ldexp(1.0, e);
            for (int64_t k = 0; k < n; k++) a[i * n + k] *= f, a[k * n + i] /= f;
            changed = 1;
        }
    }
}

/* Small n: form the matrix column by column from op(e_j), take all eigenvalues. */
static int radius_dense(int64_t n, void (*op)(const void *, const double *, double *),
                        const void *ctx, ulam_radius *out)
{
    const ulam__lapacke_api *L = ulam__lapacke(NULL); /* src/dynload.c: opened on first use */
    if (!L) return ULAM_EIO;
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
    balance(n, a);
    status = ULAM_ENOCONV;
    if (L->dgeev(LAPACK_COL_MAJOR, 'N', 'N', (lapack_int)n, a, (lapack_int)n, wr, wi, NULL, 1,
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
    ulam__arpack(NULL)->dneupd(1, "A", w->select, w->dr, w->di, w->z, w->n, 0.0, 0.0, w->workev, "I", w->n, "LM", NEV,
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
int ulam__spectral_radius_op(int64_t n, void (*op)(const void *ctx, const double *x, double *y),
                            const void *ctx, int positive_start, const ulam_spectral_opts *opts,
                            ulam_radius *out)
{
    if (n < 1 || !op || !out) return ULAM_EINVAL;
    ulam_spectral_opts o = opts ? *opts : ulam_spectral_defaults();
    if (ulam__spectral_opts_check(&o, NULL)) return ULAM_EINVAL; /* src/check.c */
    memset(out, 0, sizeof *out);
    if (n <= DENSE_MAX) return radius_dense(n, op, ctx, out);
    if (n > INT32_MAX) return ULAM_EOVERFLOW;
    const ulam__arpack_api *A = ulam__arpack(NULL); /* src/dynload.c: opened on first use */
    if (!A) return ULAM_EIO;
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
        A->dnaupd(&ido, "I", w.n, "LM", NEV, o.tol, w.resid, w.ncv, w.v, w.n, iparam, ipntr, w.workd,
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
    int bad = ulam__csr_check_structure(A, NULL); /* src/check.c */
    if (bad) return bad;
    csr_op_ctx ctx = {A, use_abs};
    return ulam__spectral_radius_op(A->nrows, csr_op, &ctx, use_abs, opts, out);
}

/* ---- power iteration on nonnegative operators, with Collatz-Wielandt bounds (the guards' radii) */

/* Iterations spent, once a radius is certified below 1, on settling whether it is below 0.99
 * (the warning's margin). */
enum { MARGIN_TRIES = 20, SUPPORT_EVERY = 10 };
#define SUPPORT_CUT 1e-10 /* the support of an iterate for support_lower */

/* The default power-iteration options. */
ulam_power_opts ulam__power_defaults(void)
{
    return (ulam_power_opts){.tol = 1e-4, .max_iter = 1000};
}

/* y = diag(left) |A| xr (threaded only where the product is big enough to pay for it). */
static void apply(const ulam_csr *A, const double *left, const double *xr, double *y)
{
#pragma omp parallel for schedule(static) if (ulam_csr_nnz(A) > 200000)
    for (int64_t i = 0; i < A->nrows; i++) {
        double s = 0.0;
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) s += fabs(A->val[q]) * xr[A->colidx[q]];
        y[i] = left ? left[i] * s : s;
    }
}

/* One power step's bookkeeping: the bounds and estimate from x and y = A x, then x <- the
 * shifted, normalised iterate y + rho x (the shift damps eigenvalues on the circle |z| = rho
 * other than rho itself, such as the -rho of bipartite matrices). */
static double step(int64_t n, double *x, const double *y, double *lo, double *hi)
{
    double sx = 0.0, sy = 0.0, mx = 0.0;
    *lo = INFINITY, *hi = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double r = y[i] / x[i];
        *lo = fmin(*lo, r), *hi = fmax(*hi, r);
        sx += x[i], sy += y[i];
    }
    double est = sy / sx;
    for (int64_t i = 0; i < n; i++) mx = fmax(mx, x[i] = y[i] + est * x[i]);
    for (int64_t i = 0; i < n; i++) x[i] = mx > 0 ? fmax(x[i] / mx, 1e-200) : 1.0;
    return est;
}

/* Nonzero when [lower, upper] decides a verdict and its warning (internal.h). */
int ulam__power_certain(double lower, double upper)
{
    return upper < 0.99 || lower >= 1.0 || (lower >= 0.99 && upper < 1.0);
}

/* A lower bound on the radius from the iterate x restricted to its support (entries below
 * SUPPORT_CUT of the largest set to 0): for nonnegative A, x >= 0, x != 0 and A x >= lambda x
 * give rho(A) >= lambda (Collatz-Wielandt), and outside the support A x >= 0 = lambda x holds
 * anyway, so states that cannot reach the dominant class (a dangling row, say, whose ratio is 0)
 * no longer pin the bound at 0.  xt and yt are scratch of n. */
static double support_lower(const ulam_csr *A, const double *left, const double *right, const double *x, double *xt,
                            double *yt)
{
    int64_t n = A->nrows;
    double mx = 0.0, lam = INFINITY;
    for (int64_t i = 0; i < n; i++) mx = fmax(mx, x[i]);
    for (int64_t i = 0; i < n; i++) xt[i] = x[i] >= SUPPORT_CUT * mx ? x[i] * (right ? right[i] : 1.0) : 0.0;
    apply(A, left, xt, yt);
    for (int64_t i = 0; i < n; i++)
        if (xt[i] > 0) lam = fmin(lam, yt[i] / (xt[i] / (right ? right[i] : 1.0)));
    return isfinite(lam) ? lam : 0.0;
}

/* Power iteration from bounds already known (internal.h). */
int ulam__power_from(const ulam_csr *A, const double *left, const double *right, const ulam_power_opts *o,
                     ulam_power *out, ulam_error *err)
{
    int64_t n = A->nrows;
    double t0 = ulam_now();
    double *x = ulam__malloc((size_t)n, sizeof *x), *y = ulam__malloc((size_t)n, sizeof *y);
    double *xr = right ? ulam__malloc((size_t)n, sizeof *xr) : x;
    double *xt = ulam__malloc((size_t)n, sizeof *xt), *yt = ulam__malloc((size_t)n, sizeof *yt);
    if (!x || !y || !xr || !xt || !yt) {
        free(x), free(y), free(xt), free(yt);
        if (right) free(xr);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for five vectors of %lld", (long long)n);
    }
    for (int64_t i = 0; i < n; i++) x[i] = 1.0;
    int stable = 0;
    double prev = -1.0, change = INFINITY;
    /* an estimate that has converged while the bounds still straddle a threshold goes on (the
     * bounds close in later); certifying, once the radius is certified below 1, at most
     * MARGIN_TRIES more iterations try to settle the warning's 0.99 */
    int extra = 0;
    while (out->iterations < o->max_iter && n > 0 &&
           !(ulam__power_certain(out->lower, out->upper) && (o->certify || out->converged)) &&
           !(o->certify && out->upper < 1.0 && extra++ >= MARGIN_TRIES)) {
        if (right)
            for (int64_t i = 0; i < n; i++) xr[i] = right[i] * x[i];
        apply(A, left, xr, y);
        double lo, hi;
        out->rho = step(n, x, y, &lo, &hi);
        out->iterations++;
        out->lower = fmax(out->lower, lo), out->upper = fmin(out->upper, hi);
        /* the changes shrink geometrically at about `ratio`: the ones still to come add up to ahead */
        double c = fabs(out->rho - prev), ratio = c / change;
        double ahead = prev >= 0 && isfinite(change) && ratio < 1 ? c * ratio / (1 - ratio) : INFINITY;
        stable = ahead <= o->tol * out->rho ? stable + 1 : 0;
        prev = out->rho, change = c;
        out->converged = out->upper - out->lower <= o->tol * out->upper || stable >= 5 || out->upper <= o->tol;
        if ((out->converged || out->iterations % SUPPORT_EVERY == 0) && out->lower < out->upper)
            out->lower = fmin(fmax(out->lower, support_lower(A, left, right, x, xt, yt)), out->upper);
    }
    if (n == 0) out->lower = out->upper = 0.0, out->converged = 1;
    out->rho = fmin(fmax(out->rho, out->lower), out->upper);
    out->seconds += ulam_now() - t0;
    free(x), free(y), free(xt), free(yt);
    if (right) free(xr);
    return ULAM_OK;
}

/* rho(diag(left) |A| diag(right)) by shifted power iteration with Collatz-Wielandt bounds. */
int ulam__spectral_power(const ulam_csr *A, const double *left, const double *right,
                        const ulam_power_opts *opts, ulam_power *out, ulam_error *err)
{
    ulam__clear(err);
    if (!A || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix and an output");
    if (A->nrows != A->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix");
    ulam_power_opts o = opts ? *opts : ulam_power_defaults();
    int bad = ulam__power_opts_check(&o, err); /* src/check.c: the options, then A's structure */
    if (bad || (bad = ulam__csr_check_structure(A, err))) return bad;
    *out = (ulam_power){.lower = 0.0, .upper = INFINITY, .rowsum_max = INFINITY, .colsum_max = INFINITY};
    return ulam__power_from(A, left, right, &o, out, err);
}

/* ---- a Collatz-Wielandt vector of the walk's length tail from its expected lengths */

enum { GMRES_MAX = 1 << 20, GMRES_ITER = 1000 }; /* the most states the certificate's GMRES runs on, and
                                                     its products (restarted, it may stall) */

/* A positive v with |K| v <= u v over the rows in seen (closed under K's moves), from the
 * expected lengths h = (I - |K|)^-1 1 of walks that move by |K|: h - |K| h = 1 gives
 * |K| h <= (1 - 1 / max h) h, a certificate as close to rho(|K|) as 1 - 1 / max h, where power
 * iteration from 1 needs about (1 - rho)^-1 steps to shape its iterate (a 200 x 200 Poisson
 * grid: 10^4).  h is solved only roughly, by conjugate gradients when |K| restricted to seen is
 * symmetric and restarted GMRES otherwise, to an infinity-norm residual below 1/4 (any
 * residual below 1 keeps the bound below 1), floored at 1 (h >= 1 exactly); the certificate
 * is then one product with |K| in floating point, each ratio raised by a rounding allowance.
 * *u (1 when none holds) and *kappa = max h / min h; *matvecs gets the products spent. */
int ulam__length_certificate(const ulam_csr *K, const char *seen, int max_iter, double *u, double *kappa,
                             int64_t *matvecs, double *hout)
{
    *u = 1.0, *kappa = INFINITY;
    int64_t n = K->nrows, m = 0, nnz = 0;
    int64_t *at = ulam__malloc((size_t)n + 1, sizeof *at);
    if (!at) return ULAM_ENOMEM;
    for (int64_t i = 0; i < n; i++) {
        at[i] = seen[i] ? m++ : -1;
        if (seen[i]) nnz += K->rowptr[i + 1] - K->rowptr[i];
    }
    ulam_csr *A = m > 0 ? ulam_csr_alloc(m, m, nnz) : NULL;
    double *one = ulam__malloc((size_t)m + 1, sizeof *one), *h = ulam__malloc((size_t)m + 1, sizeof *h);
    int status = A && one && h ? ULAM_OK : m > 0 ? ULAM_ENOMEM : ULAM_EINVAL;
    int64_t q = 0;
    for (int64_t i = 0; !status && i < n; i++) {
        if (!seen[i]) continue;
        for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) {
            if (K->val[k] == 0.0) continue;
            if (at[K->colidx[k]] < 0) { /* a move out of seen: not closed, no certificate */
                status = ULAM_EINVAL;
                break;
            }
            A->colidx[q] = (int32_t)at[K->colidx[k]], A->val[q++] = fabs(K->val[k]);
        }
        A->rowptr[at[i] + 1] = q;
    }
    int it = 0;
    if (!status) {
        for (int64_t i = 0; i < m; i++) one[i] = 1.0;
        double tol = 0.25 / sqrt((double)m); /* ||r||_inf <= ||r||_2 <= 1/4 */
        int sym = ulam__csr_symmetric(A);
        status = sym               ? ulam_cg(A, one, tol, max_iter, h, &it, NULL)
                 : m <= GMRES_MAX ? ulam_gmres(A, one, 30, tol, max_iter < GMRES_ITER ? max_iter : GMRES_ITER, h, &it, NULL)
                                   : ULAM_ENOCONV; /* 31 Krylov vectors would not be small */
        if (status == ULAM_ENOCONV && !sym && m > GMRES_MAX) {
            free(at), free(one), free(h), ulam_csr_free(A);
            return status;
        }
        if (status == ULAM_ENOCONV) status = ULAM_OK; /* the product below decides */
        *matvecs += it + 1;
    }
    if (!status) {
        double ratio = 0.0, hmin = INFINITY, hmax = 0.0;
        for (int64_t i = 0; i < m; i++) h[i] = isfinite(h[i]) ? fmax(h[i], 1.0) : INFINITY;
        for (int64_t i = 0; i < m && isfinite(ratio); i++) {
            double t = 0.0;
            for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) t += A->val[k] * h[A->colidx[k]];
            /* a sum of nonnegative terms is within (len + 1) eps of the exact one */
            t *= 1.0 + (double)(A->rowptr[i + 1] - A->rowptr[i] + 2) * DBL_EPSILON;
            ratio = fmax(ratio, t / h[i]), hmin = fmin(hmin, h[i]), hmax = fmax(hmax, h[i]);
        }
        if (ratio < 1.0) *u = ratio, *kappa = hmax / hmin;
        else status = ULAM_ENOCONV;
        for (int64_t i = 0; hout && !status && i < n; i++) hout[i] = seen[i] ? h[at[i]] : NAN;
    }
    free(at), free(one), free(h), ulam_csr_free(A);
    return status;
}
