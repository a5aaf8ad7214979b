/* Form factors: estimated by ray casting, checked by reciprocity, row sums and Howell's exact
 * formulas; the radiosity system M = diag(rho_c) F and its LAPACK solve. */
#include "rad.h"
#include "../csr.h"
#include "../dynload.h"
#include "../stop.h"

#include <stdlib.h>
#include <string.h>

/* Order of two int32_t for qsort. */
static int cmp_int32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Cast rays from patch i and write its row (sorted columns, counts / rays) at cols, vals;
 * the row length.  count and touched are scratch of npatches (count zero on entry and exit). */
static int64_t ff_row(const ulam_tracer *t, int64_t i, int64_t rays, uint64_t seed, int64_t *count,
                      int32_t *touched, int32_t *cols, double *vals)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, (uint64_t)i);
    int64_t nt = 0;
    for (int64_t k = 0; k < rays; k++) {
        int64_t j = ulam_tracer_shoot(t, i, &r);
        if (j < 0) continue;
        if (count[j]++ == 0) touched[nt++] = (int32_t)j;
    }
    qsort(touched, (size_t)nt, sizeof *touched, cmp_int32);
    for (int64_t a = 0; a < nt; a++) {
        cols[a] = touched[a];
        vals[a] = (double)count[touched[a]] / (double)rays;
        count[touched[a]] = 0;
    }
    return nt;
}

/* F by ray casting, rows in parallel. */
int ulam_ff_estimate(const ulam_tracer *t, int64_t rays, uint64_t seed, int threads, ulam_csr **F,
                     ulam_error *err)
{
    ulam__clear(err);
    if (!t || !F || rays < 1) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a tracer and rays >= 1");
    *F = NULL;
    const ulam_scene *s = ulam__tracer_scene(t);
    int64_t n = s->npatches, w = rays < n ? rays : n; /* a row has at most w entries */
    int nth = ulam__threads(threads);
    int32_t *cols = ulam__malloc((size_t)n, (size_t)w * sizeof(int32_t));
    double *vals = ulam__malloc((size_t)n, (size_t)w * sizeof(double));
    int64_t *len = ulam__malloc((size_t)n, sizeof *len);
    int64_t *count = ulam__calloc((size_t)n * (size_t)nth, sizeof *count);
    int32_t *touched = ulam__malloc((size_t)n * (size_t)nth, sizeof *touched);
    int status = cols && vals && len && count && touched ? ULAM_OK : ULAM_ENOMEM;
    if (!status) {
#pragma omp parallel for schedule(dynamic, 16) num_threads(nth)
        for (int64_t i = 0; i < n; i++) {
            int th = ulam__thread_num();
            len[i] = ff_row(t, i, rays, seed, count + (size_t)th * (size_t)n, touched + (size_t)th * (size_t)n,
                            cols + (size_t)i * (size_t)w, vals + (size_t)i * (size_t)w);
        }
        int64_t nnz = 0;
        for (int64_t i = 0; i < n; i++) nnz += len[i];
        ulam_csr *A = ulam_csr_alloc(n, n, nnz);
        if (!A) status = ULAM_ENOMEM;
        for (int64_t i = 0; A && i < n; i++) {
            A->rowptr[i + 1] = A->rowptr[i] + len[i];
            memcpy(A->colidx + A->rowptr[i], cols + (size_t)i * (size_t)w, (size_t)len[i] * sizeof(int32_t));
            memcpy(A->val + A->rowptr[i], vals + (size_t)i * (size_t)w, (size_t)len[i] * sizeof(double));
        }
        *F = A;
    }
    free(cols), free(vals), free(len), free(count), free(touched);
    return status ? ulam__fail(err, status, 0, -1, "memory for %lld x %lld form factors", (long long)n,
                               (long long)w)
                  : ULAM_OK;
}

/* Reciprocity and row sums of F. */
int ulam_ff_report_compute(const ulam_scene *s, const ulam_csr *F, ulam_ff_report *r)
{
    if (!s || !F || !r || F->nrows != s->npatches || F->ncols != s->npatches) return ULAM_EINVAL;
    ulam_csr *G = NULL, *Gt = NULL;
    if (ulam__csr_copy(F, &G)) return ULAM_ENOMEM;
    memset(r, 0, sizeof *r);
    r->rowsum_min = INFINITY;
    for (int64_t i = 0; i < F->nrows; i++) {
        double sum = 0.0;
        for (int64_t q = F->rowptr[i]; q < F->rowptr[i + 1]; q++) {
            sum += F->val[q];
            G->val[q] *= s->area[i];
        }
        r->rowsum_min = fmin(r->rowsum_min, sum);
        r->rowsum_max = fmax(r->rowsum_max, sum);
        r->rowsum_mean += sum / (double)F->nrows;
    }
    if (ulam_csr_transpose(G, &Gt)) {
        ulam_csr_free(G);
        return ULAM_ENOMEM;
    }
    /* sum |G - G'| over the union of both patterns, by merging sorted rows */
    double diff = 0.0, total = 0.0;
    for (int64_t i = 0; i < G->nrows; i++) {
        int64_t a = G->rowptr[i], b = Gt->rowptr[i];
        while (a < G->rowptr[i + 1] || b < Gt->rowptr[i + 1]) {
            int32_t ca = a < G->rowptr[i + 1] ? G->colidx[a] : INT32_MAX;
            int32_t cb = b < Gt->rowptr[i + 1] ? Gt->colidx[b] : INT32_MAX;
            double x = ca <= cb ? G->val[a++] : 0.0, y = cb <= ca ? Gt->val[b++] : 0.0;
            diff += fabs(x - y);
            total += x;
        }
    }
    r->reciprocity = total > 0 ? diff / total : 0.0;
    r->nnz = ulam_csr_nnz(F);
    ulam_csr_free(G);
    ulam_csr_free(Gt);
    return ULAM_OK;
}

/* Parallel directly opposed a x b rectangles at distance c (Howell C-11). */
double ulam_ff_parallel_rectangles(double a, double b, double c)
{
    double X = a / c, Y = b / c, X2 = X * X, Y2 = Y * Y;
    double t = 0.5 * log((1 + X2) * (1 + Y2) / (1 + X2 + Y2)) + X * sqrt(1 + Y2) * atan(X / sqrt(1 + Y2)) +
               Y * sqrt(1 + X2) * atan(Y / sqrt(1 + X2)) - X * atan(X) - Y * atan(Y);
    return 2.0 / (M_PI * X * Y) * t;
}

/* From a w x l rectangle to a perpendicular h x l rectangle sharing the edge l (Howell C-14). */
double ulam_ff_perpendicular_rectangles(double w, double h, double l)
{
    double H = h / l, W = w / l, H2 = H * H, W2 = W * W, S = H2 + W2;
    double lg = log((1 + W2) * (1 + H2) / (1 + S)) + W2 * log(W2 * (1 + S) / ((1 + W2) * S)) +
                H2 * log(H2 * (1 + S) / ((1 + H2) * S));
    return (W * atan(1 / W) + H * atan(1 / H) - sqrt(S) * atan(1 / sqrt(S)) + 0.25 * lg) / (M_PI * W);
}

/* M = diag(rho_c) F and b = E_c. */
int ulam_rad_system(const ulam_scene *s, const ulam_csr *F, int channel, ulam_csr **M, double *b)
{
    if (!s || !F || !M || !b || channel < 0 || channel > 2 || F->nrows != s->npatches) return ULAM_EINVAL;
    ulam_csr *A = NULL;
    int64_t nnz = 0;
    for (int64_t i = 0; i < F->nrows; i++)
        if (s->rho[3 * i + channel] > 0) nnz += F->rowptr[i + 1] - F->rowptr[i];
    if (!(A = ulam_csr_alloc(F->nrows, F->ncols, nnz))) return ULAM_ENOMEM;
    for (int64_t i = 0; i < F->nrows; i++) {
        double rho = s->rho[3 * i + channel];
        int64_t q0 = A->rowptr[i];
        if (rho > 0)
            for (int64_t q = F->rowptr[i]; q < F->rowptr[i + 1]; q++, q0++) {
                A->colidx[q0] = F->colidx[q];
                A->val[q0] = rho * F->val[q];
            }
        A->rowptr[i + 1] = q0;
        b[i] = s->emit[3 * i + channel];
    }
    *M = A;
    return ULAM_OK;
}

/* The three channels by LAPACK. */
int ulam_rad_direct(const ulam_scene *s, const ulam_csr *F, size_t max_bytes, double *B,
                    ulam_direct_info *info, ulam_error *err)
{
    ulam__clear(err);
    if (!s || !F || !B) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a scene, F and an output");
    int64_t n = s->npatches;
    double *b = ulam__malloc((size_t)n, sizeof *b), *x = ulam__malloc((size_t)n, sizeof *x);
    ulam_direct_info sum = {0};
    int status = b && x ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the right-hand sides");
    for (int c = 0; c < 3 && !status; c++) {
        ulam_csr *M = NULL;
        ulam_direct_info one;
        if ((status = ulam_rad_system(s, F, c, &M, b))) {
            ulam__fail(err, status, 0, -1, "memory for the radiosity system");
            break;
        }
        status = ulam_direct_solve(M, b, x, max_bytes, &one, err);
        ulam_csr_free(M);
        if (status) break;
        for (int64_t i = 0; i < n; i++) B[3 * i + c] = x[i];
        sum.seconds += one.seconds;
        sum.bytes = one.bytes;
        sum.rcond = c == 0 ? one.rcond : fmin(sum.rcond, one.rcond);
        sum.residual = fmax(sum.residual, one.residual);
    }
    if (info) *info = sum;
    free(b), free(x);
    return status;
}

/* What row_noise reads besides F: its transpose and the emitters (em[0..nem), none when the
 * pairs n * nem would pass NOISE_PAIRS: the unseen-lamp term is then skipped). */
typedef struct {
    ulam_csr *Ft;
    int64_t *em, nem;
} noise_src;

enum { NOISE_PAIRS = 100000000 };

/* Free a noise_src's arrays. */
static void noise_src_free(noise_src *ns)
{
    ulam_csr_free(ns->Ft);
    free(ns->em);
}

/* F's transpose and the emitters of s; ULAM_OK or ULAM_ENOMEM (ns freed). */
static int noise_src_make(const ulam_scene *s, const ulam_csr *F, noise_src *ns)
{
    *ns = (noise_src){0};
    if (ulam_csr_transpose(F, &ns->Ft)) return ULAM_ENOMEM;
    int64_t n = s->npatches, m = 0;
    for (int64_t k = 0; k < n; k++) m += ulam__max3(s->emit + 3 * k) > 0;
    if ((double)m * (double)n > NOISE_PAIRS || m == 0) return ULAM_OK;
    if (!(ns->em = ulam__malloc((size_t)m, sizeof *ns->em))) {
        noise_src_free(ns);
        return ULAM_ENOMEM;
    }
    for (int64_t k = 0; k < n; k++)
        if (ulam__max3(s->emit + 3 * k) > 0) ns->em[ns->nem++] = k;
    return ULAM_OK;
}

/* Nonzero when column j is in row k of A (columns sorted). */
static int in_row(const ulam_csr *A, int64_t k, int64_t j)
{
    int64_t lo = A->rowptr[k], hi = A->rowptr[k + 1];
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (A->colidx[mid] < j) lo = mid + 1;
        else hi = mid;
    }
    return lo < A->rowptr[k + 1] && A->colidx[lo] == j;
}

/* Nonzero when some vertex of patch a lies in front of patch b's plane (beyond rounding). */
static int in_front(const ulam_scene *s, int64_t a, int64_t b)
{
    const double *v0 = s->vert + 3 * s->vidx[s->start[b]], *nb = s->normal + 3 * b;
    double tol = 1e-9 * (sqrt(s->area[a]) + sqrt(s->area[b])), d[3];
    for (int64_t q = s->start[a]; q < s->start[a + 1]; q++) {
        ulam__sub3(s->vert + 3 * s->vidx[q], v0, d);
        if (ulam__dot3(d, nb) > tol) return 1;
    }
    return 0;
}

/* rho_kc^2 v_k / rays: the variance that row k's multinomial noise puts on (M B)_k, channel c,
 * with v_k = sum_j F_kj B_j^2 - (sum_j F_kj B_j)^2 the variance of the B_j a ray of row k lands
 * on, plus what the row's rays never saw.  A patch j whose own rays say by reciprocity that F_kj
 * is larger than row k saw (ns->Ft) adds (A_j F_jk / A_k - F_kj) (B_j - mean)^2.  An emitter l
 * facing k that neither's rays met adds F~ (B_l - mean)^2 with F~ = 0.5 / (rays (1 + A_k / A_l)),
 * the Jeffreys estimate of F_kl after no hit in rays trials at F_kl and rays at F_lk = F_kl A_k /
 * A_l.  Without these a patch none of whose 1000 rays hit a small bright lamp had a bar from
 * the rest alone: in an open box of 80 patches (a lamp one wall patch), 751 of 800 were within
 * 1.96 sigma of a 40000-ray solve, |z| up to 9.96. */
static double row_noise(const ulam_scene *s, const ulam_csr *F, const noise_src *ns, int64_t rays, const double *B,
                        int64_t k, int c)
{
    const ulam_csr *Ft = ns->Ft;
    double m1 = 0.0, m2 = 0.0, unseen = 0.0;
    for (int64_t q = F->rowptr[k]; q < F->rowptr[k + 1]; q++) {
        double x = B[3 * F->colidx[q] + c];
        m1 += F->val[q] * x;
        m2 += F->val[q] * x * x;
    }
    int64_t q = F->rowptr[k], qe = F->rowptr[k + 1]; /* both rows' columns are sorted: a merge */
    for (int64_t t = Ft->rowptr[k]; t < Ft->rowptr[k + 1]; t++) {
        int64_t j = Ft->colidx[t];
        while (q < qe && F->colidx[q] < j) q++;
        double seen = q < qe && F->colidx[q] == j ? F->val[q] : 0.0, d = B[3 * j + c] - m1;
        unseen += fmax(0.0, s->area[j] * Ft->val[t] / s->area[k] - seen) * d * d;
    }
    for (int64_t e = 0; e < ns->nem; e++) {
        int64_t l = ns->em[e];
        if (l == k || in_row(F, k, l) || in_row(Ft, k, l) || !in_front(s, l, k) || !in_front(s, k, l)) continue;
        double d = B[3 * l + c] - m1;
        unseen += 0.5 / ((double)rays * (1.0 + s->area[k] / s->area[l])) * d * d;
    }
    double r = s->rho[3 * k + c];
    return r * r * (fmax(0.0, m2 - m1 * m1) + unseen) / (double)rays;
}

/* Standard error of the direct B at patch p from the noise of F. */
int ulam_rad_direct_error(const ulam_scene *s, const ulam_csr *F, int64_t rays, const double *B,
                          int64_t p, size_t max_bytes, double se[3], ulam_error *err)
{
    ulam__clear(err);
    if (!s || !F || !B || !se || rays < 1 || p < 0 || p >= s->npatches)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a scene, F, B, rays >= 1 and a patch");
    int64_t n = s->npatches;
    double *e = ulam__calloc((size_t)n, sizeof *e), *g = ulam__malloc((size_t)n, sizeof *g);
    noise_src ns = {0};
    int status = e && g && !noise_src_make(s, F, &ns) ? ULAM_OK
                                                       : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a transposed solve");
    if (!status) e[p] = 1.0;
    for (int c = 0; c < 3 && !status; c++) {
        ulam_csr *M = NULL, *Mt = NULL;
        double *b = g; /* ulam_rad_system writes E_c here; overwritten by the solve */
        if ((status = ulam_rad_system(s, F, c, &M, b)) || (status = ulam_csr_transpose(M, &Mt))) {
            ulam__fail(err, status, 0, -1, "memory for the transposed system");
        } else if (!(status = ulam_direct_solve(Mt, e, g, max_bytes, NULL, err))) {
            double var = 0.0; /* g = row p of (I - M)^-1 */
            for (int64_t k = 0; k < n; k++) var += g[k] * g[k] * row_noise(s, F, &ns, rays, B, k, c);
            se[c] = sqrt(var);
        }
        ulam_csr_free(M);
        ulam_csr_free(Mt);
    }
    free(e), free(g);
    noise_src_free(&ns);
    return status;
}

/* Standard errors of the direct B at every patch from the noise of F: G = (I - M)^-1 whole
 * (LAPACKE_dgesv of (I - M)' with the identity: X = G'), se_p^2 = sum_k G_pk^2 noise_k. */
int ulam_rad_direct_errors(const ulam_scene *s, const ulam_csr *F, int64_t rays, const double *B,
                           size_t max_bytes, double *se, ulam_error *err)
{
    ulam__clear(err);
    if (!s || !F || !B || !se || rays < 1 || F->nrows != s->npatches || F->ncols != s->npatches)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a scene, its F, B, rays >= 1 and an output");
    int64_t n = s->npatches;
    size_t bytes = ulam_direct_bytes(n);
    if (bytes == 0 || n > (int64_t)INT32_MAX || bytes > SIZE_MAX / 2)
        return ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "two dense matrices whose size fits in memory");
    if (max_bytes && 2 * bytes > max_bytes)
        return ulam__fail(err, ULAM_EMEMLIMIT, 0, -1, "at most %.3g GiB for two dense matrices; n = %lld needs %.3g GiB",
                          (double)max_bytes / 1073741824.0, (long long)n, 2.0 * (double)bytes / 1073741824.0);
    const ulam__lapacke_api *L = ulam__lapacke(err); /* src/dynload.c: opened on first use */
    if (!L) return err ? err->status : ULAM_EIO;
    double *a = ulam__malloc((size_t)n * (size_t)n, sizeof *a), *x = ulam__malloc((size_t)n * (size_t)n, sizeof *x);
    double *noise = ulam__malloc((size_t)n, sizeof *noise);
    lapack_int *ipiv = ulam__malloc((size_t)n, sizeof *ipiv);
    noise_src ns = {0};
    int status = a && x && noise && ipiv && !noise_src_make(s, F, &ns)
                     ? ULAM_OK
                     : ulam__fail(err, ULAM_ENOMEM, 0, -1, "two dense %lld x %lld matrices", (long long)n, (long long)n);
    for (int c = 0; c < 3 && !status; c++) {
        memset(a, 0, (size_t)n * (size_t)n * sizeof *a);
        memset(x, 0, (size_t)n * (size_t)n * sizeof *x);
        for (int64_t k = 0; k < n; k++) { /* column k of (I - M)' is row k of I - M, column-major */
            a[k + k * n] = 1.0, x[k + k * n] = 1.0;
            for (int64_t q = F->rowptr[k]; q < F->rowptr[k + 1]; q++) a[F->colidx[q] + k * n] -= s->rho[3 * k + c] * F->val[q];
            noise[k] = row_noise(s, F, &ns, rays, B, k, c);
        }
        lapack_int info = L->dgesv(LAPACK_COL_MAJOR, (lapack_int)n, (lapack_int)n, a, (lapack_int)n, ipiv, x, (lapack_int)n);
        if (info) {
            status = ulam__fail(err, info > 0 ? ULAM_ESINGULAR : ULAM_EINVAL, 0, -1, "a nonsingular I - M");
            break;
        }
        for (int64_t p = 0; p < n; p++) { /* X = G': column p of X is row p of G */
            double var = 0.0;
            for (int64_t k = 0; k < n; k++) var += x[k + p * n] * x[k + p * n] * noise[k];
            se[3 * p + c] = sqrt(var);
        }
    }
    free(a), free(x), free(noise), free(ipiv);
    noise_src_free(&ns);
    return status;
}

/* The walks' relative target beside F's error at a patch (stop.c). */
double ulam_rad_walk_target(double rel_err, double ff_se, double B, int ff_known)
{
    if (!(rel_err > 0) || !ff_known) return rel_err;
    return ulam__stop_combined_target(rel_err, B != 0 ? ff_se / fabs(B) : (ff_se > 0 ? INFINITY : 0.0));
}
