/* Compressed sparse row matrices: build, transpose, multiply, summarise, split. */
#include "csr.h"
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Allocate an nrows x ncols matrix with room for nnz entries. */
ulam_csr *ulam_csr_alloc(int64_t nrows, int64_t ncols, int64_t nnz)
{
    if (nrows < 0 || ncols < 0 || nnz < 0 || nrows > ULAM_MAX_DIM || ncols > ULAM_MAX_DIM)
        return NULL;
    ulam_csr *A = calloc(1, sizeof *A);
    if (!A) return NULL;
    A->nrows = nrows;
    A->ncols = ncols;
    /* 2 MiB pages (every entry is written once built): a sweep streams them, a walk reads rows at random */
    A->rowptr = ulam__alloc_big((size_t)nrows + 1, sizeof *A->rowptr);
    A->colidx = ulam__alloc_big((size_t)nnz, sizeof *A->colidx);
    A->val = ulam__alloc_big((size_t)nnz, sizeof *A->val);
    if (!A->rowptr || !A->colidx || !A->val) return ulam_csr_free(A);
    memset(A->rowptr, 0, ((size_t)nrows + 1) * sizeof *A->rowptr);
    return A;
}

/* Free a matrix; accepts NULL and returns NULL. */
ulam_csr *ulam_csr_free(ulam_csr *A)
{
    if (!A) return NULL;
    free(A->rowptr);
    free(A->colidx);
    free(A->val);
    free(A);
    return NULL;
}

/* Number of stored entries. */
int64_t ulam_csr_nnz(const ulam_csr *A)
{
    return A ? A->rowptr[A->nrows] : 0;
}

/* Check that A holds the CSR invariants: rowptr from 0 rising to nnz, columns in range,
 * sorted and unique within each row, values finite and nonzero. */
int ulam_csr_check(const ulam_csr *A)
{
    if (!A || !A->rowptr || A->nrows < 0 || A->ncols < 0 || A->nrows > ULAM_MAX_DIM || A->ncols > ULAM_MAX_DIM)
        return ULAM_EINVAL;
    int bad = ulam__csr_check_structure(A, NULL); /* src/check.c: rows in bounds before they are read */
    if (bad) return bad;
    for (int64_t i = 0; i < A->nrows; i++) {
        if (A->rowptr[i + 1] < A->rowptr[i]) return ULAM_ESYNTAX;
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) {
            if (A->colidx[p] < 0 || A->colidx[p] >= A->ncols) return ULAM_EINDEX;
            if (p > A->rowptr[i] && A->colidx[p] <= A->colidx[p - 1]) return ULAM_ESYNTAX;
            if (!isfinite(A->val[p])) return ULAM_ENONFINITE;
            if (A->val[p] == 0.0) return ULAM_ESYNTAX;
        }
    }
    return ULAM_OK;
}

typedef struct {
    int32_t j;
    double x;
} entry;

/* qsort comparator: by column. */
static int entry_cmp(const void *a, const void *b)
{
    int32_t ja = ((const entry *)a)->j, jb = ((const entry *)b)->j;
    return (ja > jb) - (ja < jb);
}

/* Sort one row's (colidx, val) by column: insertion sort when short, qsort otherwise. */
static int sort_row(int32_t *j, double *x, int64_t len)
{
    if (len <= 32) {
        for (int64_t k = 1; k < len; k++) {
            int32_t jk = j[k];
            double xk = x[k];
            int64_t m = k;
            for (; m > 0 && j[m - 1] > jk; m--) {
                j[m] = j[m - 1];
                x[m] = x[m - 1];
            }
            j[m] = jk;
            x[m] = xk;
        }
        return ULAM_OK;
    }
    entry *e = ulam__malloc((size_t)len, sizeof *e);
    if (!e) return ULAM_ENOMEM;
    for (int64_t k = 0; k < len; k++) e[k] = (entry){j[k], x[k]};
    qsort(e, (size_t)len, sizeof *e, entry_cmp);
    for (int64_t k = 0; k < len; k++) {
        j[k] = e[k].j;
        x[k] = e[k].x;
    }
    free(e);
    return ULAM_OK;
}

/* Sort every row, sum duplicates and drop zeros, compacting A in place.  Rows are sorted in
 * parallel (threads; they are independent); the compaction, needed only when some row holds a
 * repeated column or a zero, is one sequential pass. */
int ulam__csr_canonicalize(ulam_csr *A, int threads)
{
    int nomem = 0, compact = 0;
#pragma omp parallel for schedule(dynamic, 4096) num_threads(threads) reduction(|| : nomem, compact) if (threads > 1)
    for (int64_t i = 0; i < A->nrows; i++) {
        int64_t a = A->rowptr[i], b = A->rowptr[i + 1];
        if (sort_row(A->colidx + a, A->val + a, b - a)) nomem = 1;
        for (int64_t k = a; k < b; k++) compact = compact || A->val[k] == 0.0 || (k > a && A->colidx[k] == A->colidx[k - 1]);
    }
    if (nomem) return ULAM_ENOMEM;
    if (!compact) return ULAM_OK;
    int64_t out = 0, start = 0;
    for (int64_t i = 0; i < A->nrows; i++) {
        int64_t end = A->rowptr[i + 1];
        A->rowptr[i] = out;
        for (int64_t k = start; k < end;) {
            int32_t j = A->colidx[k];
            double s = 0.0;
            for (; k < end && A->colidx[k] == j; k++) s += A->val[k];
            if (s != 0.0) {
                A->colidx[out] = j;
                A->val[out++] = s;
            }
        }
        start = end;
    }
    A->rowptr[A->nrows] = out;
    return ULAM_OK;
}

/* Build a CSR matrix from triplets; duplicates summed, zeros dropped. */
int ulam_csr_from_triplets(int64_t nrows, int64_t ncols, int64_t nz, const int32_t *ti,
                           const int32_t *tj, const double *tx, ulam_csr **out)
{
    if (!out || nz < 0 || (nz > 0 && (!ti || !tj || !tx))) return ULAM_EINVAL;
    *out = NULL;
    for (int64_t k = 0; k < nz; k++)
        if (ti[k] < 0 || ti[k] >= nrows || tj[k] < 0 || tj[k] >= ncols) return ULAM_EINVAL;
    ulam_csr *A = ulam_csr_alloc(nrows, ncols, nz);
    if (!A) return nrows > ULAM_MAX_DIM || ncols > ULAM_MAX_DIM ? ULAM_EOVERFLOW : ULAM_ENOMEM;
    for (int64_t k = 0; k < nz; k++) A->rowptr[ti[k] + 1]++;
    for (int64_t i = 0; i < nrows; i++) A->rowptr[i + 1] += A->rowptr[i];
    int64_t *next = ulam__malloc((size_t)nrows + 1, sizeof *next);
    if (!next) {
        ulam_csr_free(A);
        return ULAM_ENOMEM;
    }
    memcpy(next, A->rowptr, ((size_t)nrows + 1) * sizeof *next);
    for (int64_t k = 0; k < nz; k++) {
        int64_t p = next[ti[k]]++;
        A->colidx[p] = tj[k];
        A->val[p] = tx[k];
    }
    free(next);
    int status = ulam__csr_canonicalize(A, 1);
    if (status) {
        ulam_csr_free(A);
        return status;
    }
    *out = A;
    return ULAM_OK;
}

/* The transpose of A (counting sort on columns keeps the rows of the result sorted). */
int ulam_csr_transpose(const ulam_csr *A, ulam_csr **out)
{
    if (!A || !out) return ULAM_EINVAL;
    int bad = ulam__csr_check_structure(A, NULL); /* src/check.c */
    if (bad) return bad;
    *out = NULL;
    int64_t nz = ulam_csr_nnz(A);
    ulam_csr *T = ulam_csr_alloc(A->ncols, A->nrows, nz);
    if (!T) return ULAM_ENOMEM;
    for (int64_t k = 0; k < nz; k++) T->rowptr[A->colidx[k] + 1]++;
    for (int64_t j = 0; j < A->ncols; j++) T->rowptr[j + 1] += T->rowptr[j];
    int64_t *next = ulam__malloc((size_t)A->ncols + 1, sizeof *next);
    if (!next) {
        ulam_csr_free(T);
        return ULAM_ENOMEM;
    }
    memcpy(next, T->rowptr, ((size_t)A->ncols + 1) * sizeof *next);
    for (int64_t i = 0; i < A->nrows; i++) {
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) {
            int64_t p = next[A->colidx[k]]++;
            T->colidx[p] = (int32_t)i;
            T->val[p] = A->val[k];
        }
    }
    free(next);
    *out = T;
    return ULAM_OK;
}

/* A deep copy of A. */
int ulam__csr_copy(const ulam_csr *A, ulam_csr **out)
{
    if (!A || !out) return ULAM_EINVAL;
    int bad = ulam__csr_check_structure(A, NULL); /* src/check.c */
    if (bad) return bad;
    int64_t nz = ulam_csr_nnz(A);
    ulam_csr *C = ulam_csr_alloc(A->nrows, A->ncols, nz);
    if (!C) return ULAM_ENOMEM;
    memcpy(C->rowptr, A->rowptr, ((size_t)A->nrows + 1) * sizeof *C->rowptr);
    memcpy(C->colidx, A->colidx, (size_t)nz * sizeof *C->colidx);
    memcpy(C->val, A->val, (size_t)nz * sizeof *C->val);
    *out = C;
    return ULAM_OK;
}

/* y = A x, or y = |A| x. */
int ulam_csr_matvec(const ulam_csr *A, int use_abs, const double *x, double *y)
{
    if (!A || !x || !y) return ULAM_EINVAL;
    for (int64_t i = 0; i < A->nrows; i++) {
        double s = 0.0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            s += (use_abs ? fabs(A->val[k]) : A->val[k]) * x[A->colidx[k]];
        y[i] = s;
    }
    return ULAM_OK;
}

/* Dense row-major copy of A. */
int ulam__csr_to_dense(const ulam_csr *A, double *dense)
{
    if (!A || !dense) return ULAM_EINVAL;
    int bad = ulam__csr_check_structure(A, NULL); /* src/check.c */
    if (bad) return bad;
    memset(dense, 0, (size_t)A->nrows * (size_t)A->ncols * sizeof *dense);
    for (int64_t i = 0; i < A->nrows; i++)
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            dense[i * A->ncols + A->colidx[k]] = A->val[k];
    return ULAM_OK;
}

/* Nonzero when M equals its transpose exactly (columns sorted, as ulam_csr_check asks). */
int ulam__csr_symmetric(const ulam_csr *M)
{
    if (!M || M->nrows != M->ncols) return 0;
    for (int64_t i = 0; i < M->nrows; i++)
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) {
            int32_t j = M->colidx[q];
            int64_t lo = M->rowptr[j], hi = M->rowptr[j + 1];
            while (lo < hi) { /* binary search for i in row j (columns sorted) */
                int64_t mid = lo + (hi - lo) / 2;
                if (M->colidx[mid] < i) lo = mid + 1;
                else hi = mid;
            }
            if (lo == M->rowptr[j + 1] || M->colidx[lo] != i || M->val[lo] != M->val[q]) return 0;
        }
    return 1;
}

/* Fill *st with the statistics of A. */
int ulam_csr_stats_compute(const ulam_csr *A, ulam_csr_stats *st)
{
    if (!A || !st) return ULAM_EINVAL;
    int bad = ulam__csr_check_structure(A, NULL); /* src/check.c */
    if (bad) return bad;
    memset(st, 0, sizeof *st);
    st->n = A->nrows;
    st->nnz = ulam_csr_nnz(A);
    st->nonnegative = 1;
    st->row_nnz_min = A->nrows ? INT64_MAX : 0;
    st->abs_rowsum_min = A->nrows ? INFINITY : 0.0;
    for (int64_t i = 0; i < A->nrows; i++) {
        int64_t len = A->rowptr[i + 1] - A->rowptr[i];
        double s = 0.0;
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) {
            s += fabs(A->val[k]);
            if (A->val[k] < 0) st->nonnegative = 0;
        }
        if (len < st->row_nnz_min) st->row_nnz_min = len;
        if (len > st->row_nnz_max) st->row_nnz_max = len;
        if (s < st->abs_rowsum_min) st->abs_rowsum_min = s;
        if (s > st->abs_rowsum_max) st->abs_rowsum_max = s;
    }
    st->row_nnz_mean = A->nrows ? (double)st->nnz / (double)A->nrows : 0.0;
    st->substochastic = st->nonnegative && st->abs_rowsum_max <= 1.0;
    st->symmetric = ulam__csr_symmetric(A);
    return ULAM_OK;
}

/* The diagonal entry of row i, 0 if not stored (columns are sorted: binary search). */
static double csr_diag(const ulam_csr *A, int64_t i)
{
    int64_t lo = A->rowptr[i], hi = A->rowptr[i + 1];
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (A->colidx[mid] < i) lo = mid + 1;
        else hi = mid;
    }
    return lo < A->rowptr[i + 1] && A->colidx[lo] == i ? A->val[lo] : 0.0;
}

/* Damped Jacobi splitting: M = I - omega D^-1 A, bp = omega D^-1 b. */
int ulam_jacobi(const ulam_csr *A, const double *b, double omega, ulam_csr **M, double *bp,
                ulam_error *err)
{
    ulam__clear(err);
    if (!A || !b || !M || !bp || !(omega > 0.0) || !isfinite(omega))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, a right-hand side and omega > 0");
    *M = NULL;
    int bad = ulam__csr_check_structure(A, err); /* src/check.c */
    if (bad) return bad;
    if (A->nrows != A->ncols)
        return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1,
                          "a square matrix A for the Jacobi splitting, got %lld x %lld",
                          (long long)A->nrows, (long long)A->ncols);
    int64_t n = A->nrows, nz = ulam_csr_nnz(A);
    ulam_csr *R = ulam_csr_alloc(n, n, nz + n);
    if (!R) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the Jacobi matrix");
    int64_t out = 0;
    for (int64_t i = 0; i < n; i++) {
        double d = csr_diag(A, i);
        if (d == 0.0) {
            ulam_csr_free(R);
            return ulam__fail(err, ULAM_EZERODIAG, 0, i,
                              "a nonzero diagonal entry in row %lld for the Jacobi splitting",
                              (long long)i + 1);
        }
        double s = omega / d;
        R->rowptr[i] = out;
        int diag_done = 0;
        for (int64_t k = A->rowptr[i]; k <= A->rowptr[i + 1]; k++) {
            int32_t j = k < A->rowptr[i + 1] ? A->colidx[k] : INT32_MAX;
            if (!diag_done && j >= i) {
                diag_done = 1;
                if (1.0 - omega != 0.0) {
                    R->colidx[out] = (int32_t)i;
                    R->val[out++] = 1.0 - omega;
                }
            }
            if (k == A->rowptr[i + 1] || j == i) continue;
            double v = -s * A->val[k];
            if (v != 0.0) {
                R->colidx[out] = j;
                R->val[out++] = v;
            }
        }
        bp[i] = s * b[i];
    }
    R->rowptr[n] = out;
    *M = R;
    return ULAM_OK;
}
