/* Argument checks: what the library verifies before it reads what a caller gives it.  Every
 * finite-valued option is checked (NaN, +-inf, out of range) with ULAM_EINVAL and a sentence
 * naming the field, and a matrix's structure (row pointers, column indices) is checked before a
 * pass reads all of it, so a matrix built by hand or mapped from a damaged file is refused, never
 * read out of bounds.  One home for these checks: the solvers call them first. */
#include "check.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

/* A real option of a struct: its name, its offset, the range it must lie in and that range in
 * words (every value must also be finite). */
typedef struct real_opt {
    const char *name;
    size_t off;
    double lo, hi; /* lo <= v <= hi */
    const char *range;
} real_opt;

#define BELOW(x) nextafter((x), -INFINITY)
#define ABOVE(x) nextafter((x), INFINITY)

/* Check the real options of the struct at p against table t of k rows. */
static int check_reals(const void *p, const real_opt *t, size_t k, const char *what, ulam_error *err)
{
    for (size_t r = 0; r < k; r++) {
        double v;
        memcpy(&v, (const char *)p + t[r].off, sizeof v);
        if (!isfinite(v) || !(v >= t[r].lo) || !(v <= t[r].hi))
            return ulam__fail(err, ULAM_EINVAL, 0, -1, "%s.%s %s, not %g", what, t[r].name, t[r].range, v);
    }
    return ULAM_OK;
}

/* Check the finite-valued options of a walk (ulam_walk_opts). */
int ulam__walk_opts_check(const ulam_walk_opts *o, ulam_error *err)
{
    const real_opt t[] = {
        {"kernel.continue_q", offsetof(ulam_walk_opts, kernel.continue_q), -DBL_MAX, BELOW(1.0), "finite and below 1 (<= 0: analog)"},
        {"kernel.roulette", offsetof(ulam_walk_opts, kernel.roulette), 0.0, DBL_MAX, "finite and >= 0 (0: off)"},
        {"kernel.split", offsetof(ulam_walk_opts, kernel.split), 0.0, DBL_MAX, "finite and >= 0 (0: off)"},
        {"stop.rel_err", offsetof(ulam_walk_opts, stop.rel_err), 0.0, DBL_MAX, "finite and >= 0 (0: off)"},
        {"stop.max_seconds", offsetof(ulam_walk_opts, stop.max_seconds), 0.0, DBL_MAX, "finite and >= 0 (0: off)"},
        {"stop.rel_err_offset", offsetof(ulam_walk_opts, stop.rel_err_offset), -DBL_MAX, DBL_MAX, "finite"},
        {"kernel.kernel_alpha", offsetof(ulam_walk_opts, kernel.kernel_alpha), 0.0, DBL_MAX, "(the kernel exponent) finite and >= 0"},
    };
    if (!o) return ulam__fail(err, ULAM_EINVAL, 0, -1, "walk options");
    int status = check_reals(o, t, sizeof t / sizeof *t, "ulam_walk_opts", err);
    if (status) return status;
    if (o->stop.max_walks < 0 || o->stop.max_steps < 1 || o->exec.threads < 0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "ulam_walk_opts with stop.max_walks >= 0, stop.max_steps >= 1 "
                                                   "and exec.threads >= 0");
    return ULAM_OK;
}

/* Check the options of a power iteration (ulam_power_opts). */
int ulam__power_opts_check(const ulam_power_opts *o, ulam_error *err)
{
    const real_opt t[] = {{"tol", offsetof(ulam_power_opts, tol), ABOVE(0.0), BELOW(1.0), "finite and in (0, 1)"}};
    int status = check_reals(o, t, 1, "ulam_power_opts", err);
    if (status) return status;
    if (o->max_iter < 1) return ulam__fail(err, ULAM_EINVAL, 0, -1, "ulam_power_opts.max_iter >= 1, not %d", o->max_iter);
    return ULAM_OK;
}

/* Check the options of a guard check (ulam_guard_opts). */
int ulam__guard_opts_check(const ulam_guard_opts *o, ulam_error *err)
{
    const real_opt t[] = {
        {"kernel_alpha", offsetof(ulam_guard_opts, kernel_alpha), 0.0, DBL_MAX, "(the kernel exponent) finite and >= 0"}};
    int status = check_reals(o, t, 1, "ulam_guard_opts", err);
    return status ? status : ulam__power_opts_check(&o->power, err);
}

/* Check the options of the Arnoldi spectral radius (ulam_spectral_opts). */
int ulam__spectral_opts_check(const ulam_spectral_opts *o, ulam_error *err)
{
    const real_opt t[] = {{"tol", offsetof(ulam_spectral_opts, tol), ABOVE(0.0), BELOW(1.0), "finite and in (0, 1)"}};
    int status = check_reals(o, t, 1, "ulam_spectral_opts", err);
    if (status) return status;
    if (o->max_restarts < 1 || o->krylov_dim < 1)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "ulam_spectral_opts with max_restarts >= 1 and krylov_dim >= 1");
    return ULAM_OK;
}

/* Check a real argument: finite and lo <= v <= hi (name and range in words for the message). */
int ulam__real_check(double v, double lo, double hi, const char *name, const char *range, ulam_error *err)
{
    if (isfinite(v) && v >= lo && v <= hi) return ULAM_OK;
    return ulam__fail(err, ULAM_EINVAL, 0, -1, "%s %s, not %g", name, range, v);
}

/* Check a vector's length against the n entries a call reads. */
int ulam__length_check(const double *x, int64_t len, int64_t n, const char *name, ulam_error *err)
{
    if (!x) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a vector %s", name);
    if (len != n)
        return ulam__fail(err, ULAM_EDIM, 0, -1, "%s with %lld entries, one a row of M, not %lld", name,
                          (long long)n, (long long)len);
    return ULAM_OK;
}

/* Check the sizes and arrays of A (not its rows). */
static int check_shape(const ulam_csr *A, ulam_error *err)
{
    if (!A || !A->rowptr)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix with its row pointers");
    if (A->nrows < 0 || A->ncols < 0 || A->nrows > ULAM_MAX_DIM || A->ncols > ULAM_MAX_DIM)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix of 0 to %d rows and columns, not %lld x %lld",
                          ULAM_MAX_DIM, (long long)A->nrows, (long long)A->ncols);
    int64_t nnz = A->rowptr[A->nrows];
    if (A->rowptr[0] != 0 || nnz < 0)
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "row pointers from rowptr[0] = 0 (got %lld) to nnz >= 0 "
                          "(got %lld)", (long long)A->rowptr[0], (long long)nnz);
    if (nnz > 0 && (!A->colidx || !A->val))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix with its column indices and values");
    return ULAM_OK;
}

/* Check rows [lo, hi) of A: row pointers rising within [0, nnz], column indices in range. */
static int ulam__csr_check_rows(const ulam_csr *A, int64_t lo, int64_t hi, ulam_error *err)
{
    int64_t nnz = A->rowptr[A->nrows];
    for (int64_t i = lo; i < hi; i++) {
        int64_t a = A->rowptr[i], b = A->rowptr[i + 1];
        if (a < 0 || b < a || b > nnz)
            return ulam__fail(err, ULAM_ESYNTAX, 0, i, "row pointers rising from 0 to nnz = %lld: row %lld "
                              "(1-based) runs from %lld to %lld", (long long)nnz, (long long)i + 1, (long long)a,
                              (long long)b);
        for (int64_t p = a; p < b; p++)
            if (A->colidx[p] < 0 || A->colidx[p] >= A->ncols)
                return ulam__fail(err, ULAM_EINDEX, 0, i, "column indices from 0 to %lld: row %lld (1-based) "
                                  "holds %ld", (long long)A->ncols - 1, (long long)i + 1, (long)A->colidx[p]);
    }
    return ULAM_OK;
}

/* Check that reading every row of A stays in bounds (sizes, rowptr, colidx): one pass over
 * rowptr and colidx, the work of a pass that reads all of A anyway. */
int ulam__csr_check_structure(const ulam_csr *A, ulam_error *err)
{
    int status = check_shape(A, err);
    return status ? status : ulam__csr_check_rows(A, 0, A->nrows, err);
}
