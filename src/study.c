/* Pieces of variance studies an embedding program needs to repeat one: the method grid (what
 * each of the study's method names means as walk options) and the exact value a study scores
 * against (LAPACK, or Gauss-Seidel run until x_I settles). */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The grid, k = 9 mode + 3 estimator + window. */
static const ulam_study_method methods[ULAM_STUDY_METHODS] = {
    {"adjoint-collision-plain", ULAM_ADJOINT, ULAM_COLLISION, ULAM_WINDOW_PLAIN},
    {"adjoint-collision-roulette", ULAM_ADJOINT, ULAM_COLLISION, ULAM_WINDOW_ROULETTE},
    {"adjoint-collision-split", ULAM_ADJOINT, ULAM_COLLISION, ULAM_WINDOW_SPLIT},
    {"adjoint-absorption-plain", ULAM_ADJOINT, ULAM_ABSORPTION, ULAM_WINDOW_PLAIN},
    {"adjoint-absorption-roulette", ULAM_ADJOINT, ULAM_ABSORPTION, ULAM_WINDOW_ROULETTE},
    {"adjoint-absorption-split", ULAM_ADJOINT, ULAM_ABSORPTION, ULAM_WINDOW_SPLIT},
    {"adjoint-expected-plain", ULAM_ADJOINT, ULAM_EXPECTED, ULAM_WINDOW_PLAIN},
    {"adjoint-expected-roulette", ULAM_ADJOINT, ULAM_EXPECTED, ULAM_WINDOW_ROULETTE},
    {"adjoint-expected-split", ULAM_ADJOINT, ULAM_EXPECTED, ULAM_WINDOW_SPLIT},
    {"forward-collision-plain", ULAM_FORWARD, ULAM_COLLISION, ULAM_WINDOW_PLAIN},
    {"forward-collision-roulette", ULAM_FORWARD, ULAM_COLLISION, ULAM_WINDOW_ROULETTE},
    {"forward-collision-split", ULAM_FORWARD, ULAM_COLLISION, ULAM_WINDOW_SPLIT},
    {"forward-absorption-plain", ULAM_FORWARD, ULAM_ABSORPTION, ULAM_WINDOW_PLAIN},
    {"forward-absorption-roulette", ULAM_FORWARD, ULAM_ABSORPTION, ULAM_WINDOW_ROULETTE},
    {"forward-absorption-split", ULAM_FORWARD, ULAM_ABSORPTION, ULAM_WINDOW_SPLIT},
    {"forward-expected-plain", ULAM_FORWARD, ULAM_EXPECTED, ULAM_WINDOW_PLAIN},
    {"forward-expected-roulette", ULAM_FORWARD, ULAM_EXPECTED, ULAM_WINDOW_ROULETTE},
    {"forward-expected-split", ULAM_FORWARD, ULAM_EXPECTED, ULAM_WINDOW_SPLIT},
};

/* Method k of the grid, or NULL out of range. */
const ulam_study_method *ulam_study_method_get(int k)
{
    return k >= 0 && k < ULAM_STUDY_METHODS ? &methods[k] : NULL;
}

/* The index of the method named name, or -1. */
int ulam_study_method_find(const char *name)
{
    for (int k = 0; name && k < ULAM_STUDY_METHODS; k++)
        if (!strcmp(name, methods[k].name)) return k;
    return -1;
}

/* Set o's mode, estimator and weight window for method k on b. */
int ulam_study_method_opts(int k, const double *b, int64_t n, ulam_walk_opts *o)
{
    const ulam_study_method *m = ulam_study_method_get(k);
    if (!m || !o || (m->mode == ULAM_FORWARD && (!b || n < 0))) return ULAM_EINVAL;
    double w0 = m->mode == ULAM_FORWARD ? 0.0 : 1.0; /* forward particles start at ||b||_1 */
    if (m->mode == ULAM_FORWARD)
        for (int64_t i = 0; i < n; i++) w0 += fabs(b[i]);
    o->mode = m->mode, o->estimator = m->estimator;
    o->kernel.roulette = m->window >= ULAM_WINDOW_ROULETTE ? 0.5 * w0 : 0.0;
    o->kernel.split = m->window == ULAM_WINDOW_SPLIT ? 2.0 * w0 : 0.0;
    return ULAM_OK;
}

/* One Gauss-Seidel sweep on x = M x + b. */
void ulam_gauss_seidel_sweep(const ulam_csr *M, const double *b, double *x)
{
    for (int64_t i = 0; i < M->nrows; i++) {
        double s = b[i];
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += M->val[q] * x[M->colidx[q]];
        x[i] = s;
    }
}

/* Gauss-Seidel sweeps on x until x_index settles; the sweeps made. */
int ulam_gauss_seidel_settle(const ulam_csr *M, const double *b, double *x, int64_t index, double rel_tol,
                             int min_sweeps, int max_sweeps)
{
    int k = 0;
    while (k < max_sweeps) {
        double old = x[index];
        ulam_gauss_seidel_sweep(M, b, x);
        k++;
        if (k >= min_sweeps && fabs(x[index] - old) <= rel_tol * fabs(x[index])) break;
    }
    return k;
}

/* The exact x_index a study scores against. */
int ulam_study_reference(const ulam_csr *M, const double *b, int64_t index, ulam_study_ref *ref, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !b || !ref || M->nrows != M->ncols || index < 0 || index >= M->nrows)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a square matrix, b and an index in range");
    int64_t n = M->nrows;
    double *x = ulam__calloc((size_t)n, sizeof *x), *xd = NULL;
    if (!x) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the reference solve");
    *ref = (ulam_study_ref){0};
    ref->sweeps = ulam_gauss_seidel_settle(M, b, x, index, 1e-16, 12, 100000);
    ref->exact = ref->settled = x[index];
    ulam_direct_info info;
    if (n <= ULAM_STUDY_DIRECT_MAX && (xd = ulam__malloc((size_t)n, sizeof *xd)) &&
        !ulam_direct_solve(M, b, xd, 0, &info, NULL)) { /* LAPACK failing leaves Gauss-Seidel's */
        ref->direct = 1, ref->direct_seconds = info.seconds, ref->exact = xd[index];
    }
    free(x), free(xd);
    return ULAM_OK;
}

/* The 95% Wilson score interval of covered / runs. */
void ulam_study_coverage_interval(int covered, int runs, double *lo, double *hi)
{
    if (runs <= 0) {
        *lo = 0.0, *hi = 1.0;
        return;
    }
    double n = runs, p = covered / n, z = ULAM_Z95, z2 = z * z;
    double mid = (p + z2 / (2 * n)) / (1 + z2 / n), half = z * sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n);
    *lo = covered <= 0 ? 0.0 : fmax(0.0, mid - half), *hi = covered >= runs ? 1.0 : fmin(1.0, mid + half); /* exact ends */
}
