/* ulam: linear systems (I - M) x = b by von Neumann-Ulam random walks.
 *
 * The core solver's public header (libulam: matrices, I/O, guards, the analysis and the method
 * table, walks, statistics, direct solves); ulam_dist.h holds the walks across processes,
 * ulam_study.h the variance studies (libulam_study) and ulam_radiosity.h the radiosity front end
 * (libulam_radiosity).  Conventions (CSparse / GSL style):
 *   - every fallible function returns an int status (ULAM_OK == 0), see ulam_strerror();
 *   - functions that read files also fill an optional ulam_error with the line and a
 *     sentence saying what was expected;
 *   - indices are 0-based in this API (the command line and Matrix Market files are 1-based);
 *   - inputs are const, outputs are caller-owned, every _free accepts and returns NULL;
 *   - the library never prints and never exits;
 *   - ABI habit: a struct the caller fills starts from its defaults function, which sets every
 *     field, and the caller then sets what it needs (ulam_walk_defaults, whose parts by concern
 *     kernel, stop, exec, query and policy are set with it; ulam_analysis_defaults,
 *     ulam_method_defaults, ulam_auto_defaults, ulam_mm_defaults, ulam_spectral_defaults,
 *     ulam_power_defaults, ulam_guard_defaults, ulam_outer_defaults, ulam_bidir_defaults,
 *     ulam_fpush_defaults, ulam_share_defaults, ulam_system_desc_defaults; in ulam_radiosity.h
 *     ulam_camera_cornell or ulam_camera_frame): a field a later version adds then takes its
 *     default there, so such a program keeps its meaning when rebuilt.  Handles (ulam_analysis,
 *     ulam_run, ulam_solver, ulam_outer, ulam_system; ulam_tracer, ulam_rad_solver) are opaque,
 *     reached only through their functions; what the library fills (answers, results, reports,
 *     the _get_info structs, ulam_guard, ulam_certificate, ulam_csr and ulam_scene from their
 *     allocators and readers) is plain data to read.
 *
 * The API by rank, as CSparse's header ranks its own (each section banner below names the
 * ranks it holds; sections follow the data flow, file -> matrix -> analysis -> method -> walks
 * -> output):
 *   primary, what most programs call: ulam_mm_read_matrix, ulam_mm_read_vector, ulam_csr_free,
 *     ulam_walk_defaults (each options struct's wrapper over ulam_defaults), and for one
 *     unknown ONE call on one reusable analysis:
 *     ulam_analysis_alloc, ulam_analysis_solve (auto by default, a method by name through
 *     ulam_method_find: what `ulam solve` runs), ulam_analysis_free; then ulam_direct_solve,
 *     ulam_mm_write_vector, ulam_strerror;
 *   secondary, more control and the other methods: ulam_analysis_start with ulam_run_solver,
 *     ulam_run_finish, ulam_run_free (the same call step by step), the walk solver by hand
 *     (ulam_solver_alloc, _iterate, _done, _result, _vectors, _error, _guard, _free;
 *     ulam_analysis_solver on an analysis' kept kernel), the guards (ulam_guard_check,
 *     ulam_guard_variance, ulam_verdict_of), building and transforming matrices (ulam_csr_alloc,
 *     _from_triplets, _check, _transpose, ulam_jacobi, ulam_pagerank_matrix), reader options
 *     and files (ulam_mm_read_matrix_opts, ulam_mm_write_matrix), spectral radii
 *     (ulam_spectral_radius), prepared systems (ulam_system_*, ulam_certificate_*), processes
 *     (ulam_share), outer iterations (ulam_outer_*), Krylov peers (ulam_cg, ulam_gmres), point
 *     sources (ulam_analysis_bidir, ulam_fpush_*), the method table (ulam_method_*),
 *     ulam_analysis_transpose, _get_info, ulam_direct_bytes, ulam_reference_plan and ulam_reference_solve (ulam_reference.h);
 *   tertiary, mirrors kept for what they pin and utilities: ulam_solve_walks (the walks o names,
 *     no choice, no analysis), ulam_auto and ulam_auto_start (the table's choice on M alone),
 *     ulam_auto_solver (the walks' race alone), ulam_csr_nnz, _matvec, _stats_compute,
 *     ulam_strtod, ulam_outfile_*, ulam_edgelist_*, random numbers (ulam_rng_*),
 *     ulam_now, ulam_file_tag.
 * ulam_dist.h, ulam_study.h and ulam_radiosity.h rank their own.
 */
#ifndef ULAM_H
#define ULAM_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "ulam_version.h" /* ULAM_VERSION, _MAJOR, _MINOR, _PATCH */

/* The standard normal's 97.5% quantile: every 95% interval is estimate -+ ULAM_Z95 stderr. */
#define ULAM_Z95 1.959963984540054

/* Scores below this in magnitude (all of a run's) are too small to square in doubles: their
 * variance may underflow to 0, so such a run prints no interval (a b far below 1 that the solver
 * cannot rescale: a prepared file's, read lazily). */
#define ULAM_SCORE_TINY 0x1p-480

/* ---------------------------------------------------------------- status codes */
/* All primary. */

enum ulam_status {
    ULAM_OK = 0,
    ULAM_EINVAL,       /* invalid argument passed to the API */
    ULAM_ENOMEM,       /* out of memory */
    ULAM_EIO,          /* file cannot be opened, read or written */
    ULAM_EEMPTY,       /* input file is empty */
    ULAM_EBANNER,      /* not the kind of file expected: a missing or malformed banner or magic */
    ULAM_EUNSUPPORTED, /* valid Matrix Market, but a kind ulam does not handle (complex, ...) */
    ULAM_ESIZELINE,    /* missing or malformed size line */
    ULAM_EOVERFLOW,    /* sizes too large to represent or allocate */
    ULAM_ETOOFEW,      /* fewer entries than the size line declares */
    ULAM_ETOOMANY,     /* more entries than the size line declares */
    ULAM_EINDEX,       /* row or column index out of range */
    ULAM_ESYNTAX,      /* malformed entry: not a number, missing or extra fields */
    ULAM_ENONFINITE,   /* NaN or infinite value */
    ULAM_ENOTSQUARE,   /* square matrix required */
    ULAM_EDIM,         /* dimensions do not agree (e.g. length of b) */
    ULAM_EZERODIAG,    /* zero diagonal entry where a Jacobi splitting needs it */
    ULAM_ESINGULAR,    /* the system matrix is singular */
    ULAM_EMEMLIMIT,    /* the dense matrix would exceed the memory limit */
    ULAM_ENOCONV,      /* an iteration did not converge within its cap */
    ULAM_EUNDEFINED,   /* the estimator is undefined for this system (p* = 0 where it scores) */
    ULAM_EGEOMETRY,    /* a degenerate, non-planar or non-convex face */
    ULAM_ENOTFOUND,    /* a named thing (material, label) is not defined */
    ULAM_ERANGE,       /* a value outside its allowed range (a reflectance outside [0, 1)) */
    ULAM_EDEVICE,      /* the ray-casting device (Embree) failed */
    ULAM_EDIVERGE,     /* rho(|M|) is not certified below 1: the walks may diverge */
    ULAM_EINFVAR,      /* a relative-error target with a variance not certified finite */
    ULAM_ESTALL,       /* an outer iteration's residual stopped decreasing */
    ULAM_NSTATUS
};

/* A short English description of a status code (never NULL). */
const char *ulam_strerror(int status);

/* Details of a failure: the status, a 1-based input line (0 if none), a 0-based row
 * or index the failure concerns (-1 if none), and a sentence saying what was expected. */
typedef struct ulam_error {
    int status;
    long line;
    int64_t index;
    char msg[256];
    char file[256]; /* the file the line is in when it is not the one the caller named (an MTL
                       file read for an OBJ file); empty otherwise */
} ulam_error;

/* ---------------------------------------------------------------- defaults */
/* Primary, through each struct's wrapper (ulam_walk_defaults() ...). */

/* The option structs the library fills with their defaults (ulam_defaults) and, the first three,
 * sets by name (ulam_options.h). */
enum ulam_kind {
    ULAM_KIND_WALK = 0,     /* ulam_walk_opts */
    ULAM_KIND_OUTER = 1,    /* ulam_outer_opts */
    ULAM_KIND_BIDIR = 2,    /* ulam_bidir_opts */
    ULAM_KIND_ANALYSIS = 3, /* ulam_analysis_opts */
    ULAM_KIND_METHOD = 4,   /* ulam_method_opts */
    ULAM_KIND_AUTO = 5,     /* ulam_auto_opts */
    ULAM_KIND_MM = 6,       /* ulam_mm_opts */
    ULAM_KIND_SPECTRAL = 7, /* ulam_spectral_opts */
    ULAM_KIND_POWER = 8,    /* ulam_power_opts */
    ULAM_KIND_GUARD = 9,    /* ulam_guard_opts */
    ULAM_KIND_FPUSH = 10,   /* ulam_fpush_opts */
    ULAM_KIND_SHARE = 11,   /* ulam_share */
    ULAM_KIND_SYSTEM_DESC = 12, /* ulam_system_desc */
    ULAM_KIND_DIST = 13     /* ulam_dist_opts (ulam_dist.h) */
};

/* Fill *opts, the struct kind names, with its defaults; size is the caller's sizeof *opts, which
 * must be this library's.  ULAM_OK, or ULAM_EINVAL (opts zeroed) for an unknown kind or another
 * size.  Each struct's wrapper below its typedef (ulam_walk_defaults() ...) is this call: the
 * values stay the library's, so a field a later version adds takes its default there. */
int ulam_defaults(int kind, void *opts, size_t size);

/* ---------------------------------------------------------------- sparse matrices */
/* Primary: the struct, ulam_csr_free.  Secondary: building, checking, transposing, ulam_jacobi.
 * Tertiary: nnz, copy, matvec, dense, stats. */

/* Compressed sparse row matrix.  Plain data: rowptr has nrows+1 entries (64-bit, so
 * nnz may exceed 2^31), colidx and val have rowptr[nrows] entries; columns are sorted
 * and unique within each row and no stored value is zero. */
typedef struct ulam_csr {
    int64_t nrows, ncols;
    int64_t *rowptr;
    int32_t *colidx;
    double *val;
} ulam_csr;

/* Largest dimension a matrix may have (column indices are 32-bit). */
#define ULAM_MAX_DIM INT32_MAX

/* Allocate an nrows x ncols matrix with room for nnz entries (rowptr zeroed). */
ulam_csr *ulam_csr_alloc(int64_t nrows, int64_t ncols, int64_t nnz);

/* Free a matrix; accepts NULL and returns NULL. */
ulam_csr *ulam_csr_free(ulam_csr *A);

/* Number of stored entries. */
int64_t ulam_csr_nnz(const ulam_csr *A);

/* ULAM_OK when A holds the invariants above (rowptr from 0 rising to nnz, columns in range,
 * sorted and unique in each row, values finite and nonzero); else the status of the first
 * breach (ULAM_ESYNTAX, ULAM_EINDEX, ULAM_ENONFINITE; ULAM_EINVAL for bad sizes). */
int ulam_csr_check(const ulam_csr *A);

/* Build a CSR matrix from triplets (0-based); duplicates are summed, zeros dropped. */
int ulam_csr_from_triplets(int64_t nrows, int64_t ncols, int64_t nz, const int32_t *ti,
                           const int32_t *tj, const double *tx, ulam_csr **out);

/* The transpose of A (new matrix in *out). */
int ulam_csr_transpose(const ulam_csr *A, ulam_csr **out);

/* y = A x (use_abs != 0: y = |A| x). */
int ulam_csr_matvec(const ulam_csr *A, int use_abs, const double *x, double *y);

/* Summary statistics of a square matrix M (the walk kernel's raw material). */
typedef struct ulam_csr_stats {
    int64_t n, nnz;
    int64_t row_nnz_min, row_nnz_max;
    double row_nnz_mean;
    int nonnegative;      /* every entry >= 0 */
    double abs_rowsum_min; /* min_i sum_j |M_ij| */
    double abs_rowsum_max; /* max_i sum_j |M_ij| */
    int substochastic;    /* nonnegative and every row sum <= 1 */
    int symmetric;        /* M equals its transpose exactly (CG's condition, with I - M positive
                             definite) */
} ulam_csr_stats;

/* Fill *st with the statistics of A. */
int ulam_csr_stats_compute(const ulam_csr *A, ulam_csr_stats *st);

/* Damped Jacobi splitting of A x = b: M = I - omega D^-1 A, bp = omega D^-1 b
 * (omega = 1 is plain Jacobi).  bp has A->nrows entries.  A zero diagonal entry
 * fails with ULAM_EZERODIAG and err->index naming the row. */
int ulam_jacobi(const ulam_csr *A, const double *b, double omega, ulam_csr **M, double *bp,
                ulam_error *err);

/* PageRank as a system: M = alpha P^T for the adjacency matrix A (edge i -> j of weight A_ij >= 0,
 * P = D^-1 A row-stochastic; a dangling row stays zero), so that (I - M) x = (1 - alpha) / n
 * gives PageRank x.  alpha in (0, 1) is the damping; *M is new (ulam_csr_free). */
int ulam_pagerank_matrix(const ulam_csr *A, double alpha, ulam_csr **M, ulam_error *err);

/* Edge lists (src/edgelist.c): one edge "u v" or "u v weight" a line (blanks, tabs or a comma
 * between; '#' and '%' lines are comments; gzip read through zlib), as SNAP and networkx write
 * them.  Node ids are used as written: 0-based when some id is 0 (n = largest id + 1), else
 * 1-based (n = largest id); *base (may be NULL) gets 0 or 1.  *A is the adjacency matrix (A_uv:
 * the summed weights of the edges u -> v, an unweighted edge 1; weights finite and >= 0).
 * ULAM_OK, or ULAM_EIO, ULAM_ESYNTAX (err->line: the line and what it should hold), ULAM_ERANGE
 * (a negative weight), ULAM_EEMPTY (no edge), ULAM_EOVERFLOW (an id past ULAM_MM_DIM_CAP of the
 * edge count, as a Matrix Market size line), ULAM_ENOMEM. */
int ulam_edgelist_read(const char *path, ulam_csr **A, int64_t *base, ulam_error *err);

/* 1 when path names an edge list rather than a Matrix Market file or a prepared system: not
 * named .mtx (.mtx.gz, .mm), and a regular file that does not start with "%%", or a file that
 * cannot be peeked at (a pipe) named .txt, .tsv, .csv, .edges, .el or .edgelist (each also .gz). */
int ulam_edgelist_is_file(const char *path);

/* ---------------------------------------------------------------- Matrix Market */
/* Primary: ulam_mm_read_matrix, _read_vector, _write_vector.  Secondary: options, FILE readers,
 * _write_matrix.  Tertiary: ulam_strtod, ulam_outfile. */

/* The most rows (and columns) a Matrix Market matrix declaring nnz entries may have: every row
 * costs memory and time in each pass over M, so a short file may not declare millions of empty
 * ones (ULAM_EOVERFLOW at the size line).  A vector (n x 1), held dense anyway: 2^24 + 64 nnz. */
#define ULAM_MM_DIM_CAP(nnz) (((int64_t)1 << 16) + 64 * (int64_t)(nnz))

/* Read a sparse matrix from path ("coordinate" real/integer/pattern, general/symmetric/
 * skew-symmetric; duplicates summed, explicit zeros dropped; symmetric files are
 * expanded). */
int ulam_mm_read_matrix(const char *path, ulam_csr **A, ulam_error *err);

/* Options of the matrix reader.  Start from ulam_mm_defaults(). */
typedef struct ulam_mm_opts {
    int threads;     /* 0: all cores; 1: the sequential streaming reader.  A regular file of
                        coordinate general kind is read by `threads` threads in chunks split at
                        line starts, straight into the CSR arrays when its rows rise through the
                        file; any error is found and located (file:line) by the sequential
                        reader, which reads on from the size line */
} ulam_mm_opts;

/* The defaults: all cores (threads 0). */
static inline ulam_mm_opts ulam_mm_defaults(void)
{
    ulam_mm_opts o;
    ulam_defaults(ULAM_KIND_MM, &o, sizeof o);
    return o;
}

/* Read a matrix as ulam_mm_read_matrix, from an open file f (name is used only in error
 * details), with options (o NULL: ulam_mm_defaults()). */
int ulam_mm_read_matrix_opts(FILE *f, const char *name, const ulam_mm_opts *o, ulam_csr **A, ulam_error *err);

/* Read a dense vector from path: "array" m x 1, or "coordinate" m x 1 (missing entries are
 * 0).  *x is malloc'd with *n entries. */
int ulam_mm_read_vector(const char *path, double **x, int64_t *n, ulam_error *err);

/* strtod(s, end) exactly (the same double and end for every input, C locale), faster for
 * decimals of up to 19 significant digits with normal results (Clinger's fast path, else the
 * Eisel-Lemire algorithm); everything else is strtod's own work.  errno is set only when
 * strtod itself runs. */
double ulam_strtod(const char *s, char **end);

/* Write A as "coordinate real general" with an optional one-line comment.  The file is
 * written to a temporary name and renamed into place only when complete. */
int ulam_mm_write_matrix(const char *path, const ulam_csr *A, const char *comment);

/* Write x as "array real general" n x 1, atomically like ulam_mm_write_matrix (ULAM_ENONFINITE
 * for a non-finite value, nothing written; ULAM_EIO with errno saying why). */
int ulam_mm_write_vector(const char *path, const double *x, int64_t n, const char *comment);

/* As ulam_mm_write_vector, to an open file f (an ulam_outfile's, say, to commit with others). */
int ulam_mm_write_vector_file(FILE *f, const double *x, int64_t n, const char *comment);

/* An output file written under a temporary name in the same directory and renamed into place
 * by ulam_outfile_commit: a reader sees the old file or the complete new one, never a part.
 * Every file the library and the CLI write goes through it.  Write to f between open and
 * commit; on any failure call ulam_outfile_abort, which leaves an old file at path intact. */
typedef struct ulam_outfile {
    FILE *f;    /* the temporary file, open for writing */
    char *path; /* the final name */
    char *tmp;  /* the temporary name (path.tmp.XXXXXX) */
} ulam_outfile;

/* Open a temporary file beside path; ULAM_OK, ULAM_ENOMEM or ULAM_EIO (o is then empty). */
int ulam_outfile_open(ulam_outfile *o, const char *path);

/* Flush, close and rename into place; ULAM_OK, or ULAM_EIO with the temporary file removed and
 * errno saying why (ENOSPC: "No space left on device"). */
int ulam_outfile_commit(ulam_outfile *o);

/* Commit k files together (an answer and its errors): flush and close every one, and only when
 * all were written whole rename each into place; else remove every temporary file, so no file
 * is replaced (ULAM_EIO, errno saying why).  Every o[j] is left empty (aborted) either way. */
int ulam_outfile_commit_all(ulam_outfile *o, int k);

/* Close and remove the temporary file; accepts an empty (zeroed or aborted) o. */
void ulam_outfile_abort(ulam_outfile *o);

/* ---------------------------------------------------------------- direct solve */
/* Primary: ulam_direct_solve.  Secondary: ulam_solution_bound (a certified range around any x), ulam_direct_bytes.  The sparse LU (UMFPACK) and the
 * choice between them: ulam_reference.h. */

/* What a LAPACK direct solve reports besides the solution. */
typedef struct ulam_direct_info {
    double rcond;    /* reciprocal 1-norm condition number of I - M (LAPACKE_dgecon) */
    double residual; /* ||b - (I - M) x||_inf / ||b||_inf */
    double seconds;  /* wall time of assembly, factorisation and solve */
    size_t bytes;    /* memory the dense matrix needed */
} ulam_direct_info;

/* Bytes the dense n x n reference solve needs, or 0 if that overflows size_t. */
size_t ulam_direct_bytes(int64_t n);

/* Solve (I - M) x = b densely with LAPACKE_dgesv.  Refuses with ULAM_EMEMLIMIT when the
 * dense matrix would exceed max_bytes (0: no limit); a singular system fails with
 * ULAM_ESINGULAR (err->index is the zero pivot).  info may be NULL. */
int ulam_direct_solve(const ulam_csr *M, const double *b, double *x, size_t max_bytes,
                      ulam_direct_info *info, ulam_error *err);

/* A certified range [lo[i], hi[i]] of the exact x*_i of (I - M) x* = b around any finite x (an
 * outer iteration's, a Krylov peer's, a direct solve's), for every i, from x's residual r = b -
 * (I - M) x computed with each row's rounding bounded: a Collatz-Wielandt vector v > 0 with
 * |M| v <= u v, u < 1 (v = 1 when the rows of |M| sum below 1, else the expected lengths
 * (I - |M|)^-1 1 solved roughly and checked by one product) gives |x*_i - x_i| <= max_j (|r_j| /
 * v_j) v_i / (1 - u); with M >= 0 the range takes r's signs.  No sampling: the range is certain.
 * *worst: the largest half-width.  ULAM_EDIVERGE (NaN ends, *worst INFINITY) when no such v is
 * certified; ULAM_EINVAL for a non-square M or a non-finite x or b (err->index: its row). */
int ulam_solution_bound(const ulam_csr *M, const double *b, const double *x, double *lo, double *hi, double *worst,
                        ulam_error *err);

/* ---------------------------------------------------------------- spectral radius */
/* Secondary. */

/* Options of the spectral radius estimate: ARPACK's implicitly restarted Arnoldi
 * (dense dgeev for n <= 128), stopped when the dominant Ritz pair reaches
 * ||A u - lambda u|| <= tol |lambda|.  Start from ulam_spectral_defaults(). */
typedef struct ulam_spectral_opts {
    double tol;       /* relative residual tolerance (default 1e-6) */
    int max_restarts; /* cap on implicit restarts (default 300) */
    int krylov_dim;   /* Arnoldi basis size, ARPACK's ncv (default 20) */
    uint64_t seed;    /* start vector seed for signed matrices (default 1) */
} ulam_spectral_opts;

/* The defaults: tol 1e-6, max_restarts 300, krylov_dim 20, seed 1. */
static inline ulam_spectral_opts ulam_spectral_defaults(void)
{
    ulam_spectral_opts o;
    ulam_defaults(ULAM_KIND_SPECTRAL, &o, sizeof o);
    return o;
}

/* Result of a spectral radius estimate. */
typedef struct ulam_radius {
    double rho;       /* |lambda| of the dominant Ritz value */
    double residual;  /* ||A u - lambda u|| / (|lambda| ||u||) of the dominant pair */
    int matvecs;      /* matrix-vector products spent */
    int converged;    /* residual <= tol */
} ulam_radius;

/* Spectral radius of A (use_abs == 0) or of |A| (use_abs != 0, the Perron root).
 * opts may be NULL for the defaults.  Not converging is reported in out->converged,
 * not as a failure. */
int ulam_spectral_radius(const ulam_csr *A, int use_abs, const ulam_spectral_opts *opts,
                         ulam_radius *out);

/* Options of the power iteration for nonnegative operators (the guards' radii).  Start from
 * ulam_power_defaults(). */
typedef struct ulam_power_opts {
    double tol;   /* stop when (upper - lower) <= tol * upper, or when for 5 iterations the
                     changes, extrapolated as a geometric series, add up to <= tol * rho,
                     or when upper <= tol (default 1e-4) */
    int max_iter; /* iteration cap (default 1000) */
    int certify;  /* nonzero: stop as soon as the bounds certify a verdict (ulam_verdict_of)
                     with its warning margin: upper < 0.99, lower >= 1, or 0.99 <= lower and
                     upper < 1 (default 0: iterate to the tolerance) */
} ulam_power_opts;

/* The defaults: tol 1e-4, max_iter 1000, certify 0. */
static inline ulam_power_opts ulam_power_defaults(void)
{
    ulam_power_opts o;
    ulam_defaults(ULAM_KIND_POWER, &o, sizeof o);
    return o;
}

/* Spectral radius of a nonnegative operator by power iteration, with Collatz-Wielandt bounds
 * from the same iterates: for any positive x, min_i (Ax)_i / x_i <= rho(A) <= max_i (Ax)_i / x_i.
 * Plain data, so a certificate can be stored and read back (a prepared system). */
typedef struct ulam_power {
    double rho;          /* the estimate, sum(Ax) / sum(x) at the last iterate: a crude one
                            unless converged (then only the bounds are certain) */
    double lower, upper; /* certified bounds: lower <= rho(A) <= upper */
    double rowsum_max, colsum_max; /* the one-pass bounds: largest row and column sums of the
                                      matrix (INFINITY when not computed) */
    int iterations;      /* matrix-vector products (0: the one-pass bounds sufficed) */
    int converged;       /* stopped by the tolerance: rho is an estimate to tol */
    double seconds;
} ulam_power;

/* ---------------------------------------------------------------- stability guards */
/* Primary: ulam_guard_check and its options.  Secondary: ulam_verdict_of, ulam_guard_variance. */

/* A radius against 1, from its certified bounds alone (never from an unconverged estimate):
 * OK when upper < 0.99; EDGE (finite, within 1% of 1) when upper < 1; FAIL when lower >= 1;
 * UNKNOWN when the bounds straddle 1, which callers treat as FAIL unless told otherwise. */
enum ulam_verdict { ULAM_VERDICT_OK = 0, ULAM_VERDICT_EDGE = 1, ULAM_VERDICT_FAIL = 2, ULAM_VERDICT_UNKNOWN = 3 };
int ulam_verdict_of(const ulam_power *p);

/* The radii a guard check computes: rho(|M|), the adjoint and the forward rho(M^). */
enum { ULAM_GUARD_ABS = 1, ULAM_GUARD_ADJOINT = 2, ULAM_GUARD_FORWARD = 4, ULAM_GUARD_ALL = 7 };

/* The bit of ULAM_GUARD_* for the rho(M^) of walks in mode (ULAM_ADJOINT, ULAM_FORWARD). */
#define ULAM_GUARD_HAT(mode) ((mode) == 1 ? ULAM_GUARD_FORWARD : ULAM_GUARD_ADJOINT)

/* What a guard check computes and how far.  Start from ulam_guard_defaults(). */
typedef struct ulam_guard_opts {
    int need;  /* ULAM_GUARD_* bits (0: all three) */
    int tight; /* nonzero: iterate every radius to the tolerance (ulam info); 0: stop as soon
                  as the bounds certify the verdict (one O(nnz) pass when row or column sums do) */
    ulam_power_opts power; /* the iteration (certify is set by tight) */
    double kernel_alpha;   /* the kernel exponent of the walks whose rho(M^) is computed (see
                              ulam_walk_opts; default 1) */
} ulam_guard_opts;

/* The defaults: all three radii (need ULAM_GUARD_ALL), tight 0 (stopped once certified), power
 * ulam_power_defaults(), kernel_alpha 1. */
static inline ulam_guard_opts ulam_guard_defaults(void)
{
    ulam_guard_opts o;
    ulam_defaults(ULAM_KIND_GUARD, &o, sizeof o);
    return o;
}

/* The guards of a walk on M with continuation continue_q (<= 0: analog) and kernel exponent
 * alpha, a plain struct (a certificate a prepared-system file can store and reload):
 *   abs:    rho(|M|) (= rho(|M'|)): the walk's expectation is a convergent series iff < 1 (for
 *           every alpha);
 *   hat[m]: rho(M^) of the mode m kernel's second-moment matrix M^_ij = K_ij^2 / (q_i p_ij),
 *           K = M (adjoint) or M' (forward), p_ij = q_i |K_ij|^alpha / sum_k |K_ik|^alpha:
 *           diag(S / q) |K| at alpha = 1, |K_ij|^(2 - alpha) sum_k |K_ik|^alpha / q_i in
 *           general; the estimators' variance is finite iff < 1.
 * Each radius carries its one-pass row/column-sum bounds, its certified bounds (the tighter of
 * those and the power iteration's), its estimate and whether it converged; verdicts come from
 * the bounds only.  A radius not computed has verdict ULAM_VERDICT_UNKNOWN and bounds
 * [0, INFINITY]. */
typedef struct ulam_guard {
    double continue_q; /* the kernel the radii describe: its continuation */
    double kernel_alpha; /* and its exponent (rho(M^) depends on it, rho(|M|) does not) */
    int computed;      /* ULAM_GUARD_* bits of the radii computed */
    ulam_power abs, hat[2];
    int verdict_abs, verdict_hat[2];
} ulam_guard;

/* Compute the radii opts->need asks for (opts may be NULL: ulam_guard_defaults()): one pass over
 * M gives every row and column sum bound; power iteration runs only for a radius those do not
 * certify (or for every radius when opts->tight).  At opts->kernel_alpha != 1, rho(M^) is that
 * of M^ formed entry by entry (nnz doubles; forward: on M', a transpose); a kernel_alpha that
 * is negative or not finite is ULAM_EINVAL. */
int ulam_guard_check(const ulam_csr *M, double continue_q, const ulam_guard_opts *opts,
                     ulam_guard *g, ulam_error *err);

/* Whether g certifies the variance of walks in mode finite: 1 finite (rho(M^) < 1), 0 infinite
 * (rho(M^) >= 1), -1 unknown (the bounds straddle 1, or that radius was not computed). */
int ulam_guard_variance(const ulam_guard *g, int mode);

/* ---------------------------------------------------------------- prepared systems */
/* Secondary, except tertiary: ulam_system_from_memory, _is_file, _omega, _certificate, _write_file. */

/* A prepared system: M (and b, and optionally M^T) of (I - M) x = b as one binary file that is
 * mapped read-only and used in place, so a query reads only the pages of the rows its walks
 * reach.  The layout is documented in docs/prepared.md (format version 2): a 1024-byte
 * little-endian header (sizes, array offsets, the file length, a certificate section, its own
 * XXH3 checksum), the arrays at 4096-byte boundaries and a table of XXH3-64 checksums, one for
 * each block of rows of M, b and M^T.  Every block is verified (checksum and CSR invariants) the
 * first time anything reads it, once.  `ulam prepare` writes one; `--cache` keeps one beside
 * each input (a vector's holds only b), tagged with the XXH3-128 hash of the source's bytes. */
typedef struct ulam_system ulam_system;

/* What the guards certified for a prepared system, so a query needs no pass over M: the
 * radii of ulam_guard_check for the kernel of continuation continue_q and exponent 1 (a
 * query at another kernel exponent computes its own) under power-iteration
 * options (tol, max_iter), and the row- and column-sum bounds of |M| (the largest of either
 * bounds rho(|M|) from above).  Stored in a versioned section of the header (version 3 holds
 * these fields and the content hash of M's blocks, which binds it to the arrays it certifies; a
 * later version appends fields and a version-3 reader reads the ones it knows; an earlier one is
 * ignored and the guards run as usual). */
typedef struct ulam_certificate {
    double continue_q; /* <= 0: the analog kernel */
    double tol;
    int max_iter;
    double rowsum_min, rowsum_max, colsum_min, colsum_max; /* of |M| */
    ulam_guard guard;
} ulam_certificate;

/* What to write: M and/or b (n entries; with M, n = M->nrows), an optional source tag (the
 * CLI's cache: ulam_file_tag of the source), the Jacobi damping omega that made M (0: M as
 * read), an optional certificate of M, and whether to store M^T too (transpose 1: the writer
 * builds it; ulam_system_transpose then serves it).  Start from ulam_system_desc_defaults(). */
typedef struct ulam_system_desc {
    const ulam_csr *M;
    const double *b;
    int64_t n;
    uint64_t tag[2];
    double omega;
    const ulam_certificate *cert;
    int transpose;
} ulam_system_desc;

/* The defaults: nothing to write yet (M, b and cert NULL, n 0, tag {0, 0}, omega 0, no
 * transpose); set M and/or b and n. */
static inline ulam_system_desc ulam_system_desc_defaults(void)
{
    ulam_system_desc o;
    ulam_defaults(ULAM_KIND_SYSTEM_DESC, &o, sizeof o);
    return o;
}

/* Write a prepared system to f (positioned at 0; the caller closes it): ULAM_OK, ULAM_EINVAL
 * (also for an M that fails ulam_csr_check, a b not finite, a certificate without M or whose
 * guards are not of kernel exponent 1), ULAM_ENOMEM or ULAM_EIO. */
int ulam_system_write_file(FILE *f, const ulam_system_desc *d);

/* Write a prepared system to path atomically (through ulam_outfile). */
int ulam_system_write(const char *path, const ulam_system_desc *d);

/* Map the prepared system at path read-only.  Checked at once, in O(blocks): magic and an empty
 * file (ULAM_EBANNER), version and byte order (ULAM_EUNSUPPORTED), the header's checksum, sizes,
 * offsets and the file's length against them, the checksum table against its checksum, the
 * certificate's content hash against the table, rowptr[0] = 0 and rowptr[nrows] = nnz
 * (ULAM_ESYNTAX; a truncated file fails here); tag, when not NULL, must match the stored one
 * (ULAM_ENOTFOUND).  The arrays are verified block by block when first read (below). */
int ulam_system_open(const char *path, const uint64_t tag[2], ulam_system **out, ulam_error *err);

/* As ulam_system_open on bytes already in memory (borrowed: they must outlive the system). */
int ulam_system_from_memory(const void *data, size_t bytes, const uint64_t tag[2], ulam_system **out,
                            ulam_error *err);

/* 1 when path starts with the prepared-system magic, 0 otherwise (unreadable included). */
int ulam_system_is_file(const char *path);

/* Verify every block of M, b and M^T (checksums and the CSR invariants of ulam_csr_check, a
 * finite b): one pass over the file, and none again (each block's verdict is kept).  ULAM_OK or
 * ULAM_ESYNTAX with err naming the damaged block (err->index its first row) and the fault. */
int ulam_system_check(const ulam_system *s, ulam_error *err);

/* The mapped matrix, verified whole on the first call (NULL when the file holds none or it is
 * damaged: ulam_system_check says where): read-only, owned by s (never pass it to
 * ulam_csr_free), valid until ulam_system_free. */
const ulam_csr *ulam_system_matrix(const ulam_system *s);

/* The mapped b, verified whole (NULL when the file holds none or it is damaged); *n (may be
 * NULL) gets its length. */
const double *ulam_system_rhs(const ulam_system *s, int64_t *n);

/* The stored M^T (`ulam prepare --transpose`), verified whole, NULL when the file holds none
 * or it is damaged: what a bidirectional or point-source query pushes on, with no transpose to
 * build. */
const ulam_csr *ulam_system_transpose(const ulam_system *s);

/* The mapped M and b (either may be NULL) as they are, NOT verified: for a solver given
 * ulam_walk_opts.policy.system = s (and this M), which verifies each block before its walks, its
 * reachability search or a pass over all of M first read it, so a query for one x_i reads only
 * the blocks of the rows it reaches.  ULAM_OK, or ULAM_EINVAL for s NULL. */
int ulam_system_lazy(const ulam_system *s, const ulam_csr **M, const double **b);

/* Unmap and free; accepts and returns NULL. */
ulam_system *ulam_system_free(ulam_system *s);

/* What a prepared system holds besides M, b and M^T, and what its queries have read. */
typedef struct ulam_system_info {
    const ulam_certificate *cert; /* the stored certificate, or NULL when there is none (or of a
                                     version this reader does not know) */
    double omega;            /* the Jacobi damping the stored M was made with (0: none) */
    int64_t blocks_checked;  /* the blocks of M, b and M^T verified so far (each once) ... */
    int64_t rows_checked;    /* ... and the rows of M they hold: what queries read of the file
                                beyond its header and checksum table */
    const void *map;         /* the file mapping behind s: its first byte and its length (NULL and
                                0 for borrowed memory).  A file that shrinks while mapped */
    size_t map_bytes;        /* (truncated, or replaced in place by `cp`) makes a read of the lost
                                pages raise SIGBUS: a program that catches SIGBUS can tell such a
                                fault (si_addr inside the mapping) from others and report the file */
} ulam_system_info;

/* Fill info (all zero for s NULL). */
void ulam_system_get_info(const ulam_system *s, ulam_system_info *info);

/* The content tag of a source file for a cache (ulam_system_desc.tag, ulam_system_open's tag):
 * the XXH3-128 hash of its bytes (low, high), so an edit that keeps the size and the modification
 * time still changes it.  ULAM_OK, ULAM_EIO or ULAM_ENOMEM. */
int ulam_file_tag(const char *path, uint64_t tag[2], ulam_error *err);

/* The certificate of M: the guards of ulam_guard_check(M, continue_q, opts) and the row and
 * column sums of |M| (one more pass); ULAM_EINVAL for opts->kernel_alpha != 1 (the file's
 * certificate holds the guards of exponent 1). */
int ulam_certificate_compute(const ulam_csr *M, double continue_q, const ulam_guard_opts *opts,
                             ulam_certificate *c, ulam_error *err);

/* The guards a query would compute, taken from certificate c when it was made for the same
 * continuation, kernel exponent and power-iteration options and holds the radii opts->need
 * asks for (opts NULL:
 * the defaults, all three; never for opts->tight): ULAM_OK with *g
 * filled (its seconds 0: no pass was made), or ULAM_ENOTFOUND when c is NULL or does not
 * apply (the caller then runs ulam_guard_check). */
int ulam_certificate_guard(const ulam_certificate *c, double continue_q, const ulam_guard_opts *opts,
                           ulam_guard *g);

/* ---------------------------------------------------------------- random walks */
/* Primary, except secondary: ulam_share. */

enum ulam_mode { ULAM_ADJOINT = 0, ULAM_FORWARD = 1 };
enum ulam_estimator { ULAM_COLLISION = 0, ULAM_ABSORPTION = 1, ULAM_EXPECTED = 2 };

/* Walks spread over processes (MPI ranks, say; the library itself knows nothing of MPI).
 * Process `rank` of `nranks` runs the blocks q with q mod nranks = rank; after every round,
 * allgather gives every process every block's result, so each merges all blocks in the same
 * order and reaches the same totals, bit for bit, and the same stopping decisions as one
 * process running them all with the same seed.  allgather must concatenate every process's
 * `bytes` bytes at `mine` in rank order into a new malloc'd *all of *total bytes, returning 0,
 * or nonzero on failure (the run then stops with ULAM_EIO).  Start from ulam_share_defaults(). */
typedef struct ulam_share {
    int rank, nranks;
    int (*allgather)(void *ctx, const void *mine, size_t bytes, void **all, size_t *total);
    void *ctx;
} ulam_share;

/* The defaults: one process (rank 0 of 1; allgather and ctx NULL, never called). */
static inline ulam_share ulam_share_defaults(void)
{
    ulam_share o;
    ulam_defaults(ULAM_KIND_SHARE, &o, sizeof o);
    return o;
}

/* The walk kernel: how a walk moves and how its weight is kept in a window.  Start from
 * ulam_walk_defaults() (its kernel). */
typedef struct ulam_kernel_opts {
    double continue_q;   /* fixed continuation probability in (0, 1); <= 0: analog min(1, S_i) */
    double kernel_alpha; /* the kernel exponent alpha, finite and >= 0: a walk that continues from
                            i moves to j with probability |K_ij|^alpha / sum_k |K_ik|^alpha over
                            the row's nonzeros (K = M adjoint, M' forward), its weight times
                            K_ij / (q_i p_ij); 1 (the default): the "almost optimal" |K_ij| / S_i,
                            0 uniform, 2 Alea's transition factor.  rho(M^) is that kernel's, so
                            policy.guard is used only when computed for the same alpha */
    int whole_kernel;    /* 1: build the walk kernel's every row before walking; 0: build each
                            row when a walk first reaches it, and the rest at once when walks
                            have reached 1/4 of them (a run that far will reach most) */
    double roulette;     /* weight window floor W: below it survive with |w|/W at weight W; 0 off */
    double split;        /* weight window ceiling: above it split into ceil(|w|/W) copies; 0 off */
} ulam_kernel_opts;

/* When a run stops: the first rule met ends it.  Start from ulam_walk_defaults() (its stop). */
typedef struct ulam_stop_opts {
    int64_t max_walks;   /* stop after this many walks (0: no limit) */
    double rel_err;      /* stop once the relative-error rule holds (see ulam_solve_walks); 0 off */
    double max_seconds;  /* stop after this much wall time (0 off); the first block always runs */
    int64_t max_steps;   /* a walk longer than this is cut and counted (default 10^6) */
    const volatile int *interrupt; /* stop at the next block when *interrupt != 0 (may be NULL) */
    double rel_err_offset; /* a known exact part c of the answer c + estimate (bidirectional's push
                              part): rel_err is then relative to |c + estimate| (0: none) */
} ulam_stop_opts;

/* Where and how the walks run.  Start from ulam_walk_defaults() (its exec). */
typedef struct ulam_exec_opts {
    uint64_t seed;       /* block q of walks uses the stream (seed, q): same result for any thread count */
    int threads;         /* 0: all cores */
    const ulam_share *share; /* NULL: this process runs every block */
} ulam_exec_opts;

/* What is asked: which x_i (or which weighted sum of them).  Start from ulam_walk_defaults() (its query). */
typedef struct ulam_query_opts {
    int64_t index;       /* 0-based component reported (the start state in adjoint mode) */
    int64_t nstarts;     /* adjoint: 0 starts every walk at index; k > 0 starts it at starts[j]
                            with probability |start_weights[j]| / S (S their sum of |.|) and
                            weight sign(start_weights[j]) S, so the estimate is of
                            sum_j start_weights[j] x_{starts[j]} (index only labels it) */
    const int64_t *starts;       /* k states (0-based), borrowed like b */
    const double *start_weights; /* k finite weights, not all 0 */
} ulam_query_opts;

/* What the run trusts: the guards' verdicts, computed before or to compute, and what to do when
 * they do not certify.  Start from ulam_walk_defaults() (its policy). */
typedef struct ulam_policy_opts {
    int force;           /* 1: walk even when rho(|M|) is not certified below 1 (else ULAM_EDIVERGE) */
    int assume_finite;   /* 1: treat a variance the guards cannot certify either way as finite */
    const ulam_guard *guard; /* the verdicts for this M and continue_q computed before (an earlier
                                ulam_guard_check, a prepared system): used instead of
                                computing them when they hold the radii this run needs; NULL:
                                the solver computes them */
    const ulam_system *system; /* the prepared system M (and b, when it is the system's) come from
                                  (ulam_system_lazy), or NULL: its blocks are verified as they are
                                  first read (each row before a walk builds it; every row before a
                                  pass over all of M), and a damaged one fails the run with
                                  ULAM_ESYNTAX naming it */
} ulam_policy_opts;

/* How to walk and when to stop, by concern.  Start from ulam_walk_defaults() (each part from its
 * own defaults function). */
typedef struct ulam_walk_opts {
    int mode;            /* ULAM_ADJOINT (one x_i) or ULAM_FORWARD (every x_i) */
    int estimator;       /* ULAM_COLLISION, ULAM_ABSORPTION or ULAM_EXPECTED */
    ulam_kernel_opts kernel; /* continuation, exponent, weight window */
    ulam_stop_opts stop;     /* walks, rel_err, time, cuts, interrupt */
    ulam_exec_opts exec;     /* seed, threads, processes */
    ulam_query_opts query;   /* index, weighted starts */
    ulam_policy_opts policy; /* force, assume_finite, guards computed before, prepared system */
} ulam_walk_opts;

/* The defaults: adjoint collision walks and each part's defaults (index 0, analog kernel with
 * exponent 1, seed 1, all cores, 10^5 walks, walk cap 10^6 steps). */
static inline ulam_walk_opts ulam_walk_defaults(void)
{
    ulam_walk_opts o;
    ulam_defaults(ULAM_KIND_WALK, &o, sizeof o);
    return o;
}

/* What a run has found so far. */
typedef struct ulam_walk_result {
    double estimate;   /* of x_index */
    double std_error;  /* standard error of the estimate */
    double ci95[2];    /* the 95% interval (docs/error-bars.md): empirical Bernstein on the certified
                          range R of a single score (tail_bound), stitched over the walk counts the
                          run could stop at, widened by the truncation's and the cuts' bias; zero
                          width only when x is certified 0; NaN when there is none (no certified
                          range, variance not certified finite, or a score past R) */
    double variance;   /* per-walk (per-history) sample variance */
    int64_t walks;     /* histories completed */
    int64_t steps;     /* transitions made */
    int64_t cut;       /* walks cut at max_steps (the estimate is biased by them) */
    int64_t rows;      /* rows of the walk kernel built: states reached, or n once built whole */
    double max_share;  /* largest single score^2 / sum of scores^2 (luck: it is large only in the
                          runs that happened to see a large score; see tail_bound) */
    int variance_finite; /* the guards' verdict on rho(M^): 1 certified finite (or assumed with
                            assume_finite), 0 infinite, -1 unknown; ci95 is NaN unless 1 */
    double score_bound;  /* the largest |score| a walk can make (absorption: W max |b_j| / p*_j over
                            reachable scoring states, W the weight bound); INFINITY: unbounded */
    double tail_bound;   /* R / (walks |estimate|), R the range ci95 uses (score_bound, or for
                            collision and expected the range of walks short enough to matter:
                            longer ones add at most a share of the estimate, counted as bias):
                            how far one more walk could move the estimate, relatively;
                            luck-independent (INFINITY: no bound) */
    double min_walks;    /* rel_err: the walks the rule predicts it needs at this estimate and
                            variance (a confidence sequence tuned to the target from the start,
                            at the range it plans; at most walks once met; INFINITY: none can,
                            0: no target) */
    double variance_rel_error; /* relative standard error of `variance` (fourth moment) */
    int rel_err_met;     /* 1: stopped by the rel_err rule */
    double cut_bound;    /* the most the walks cut at max_steps can have moved the mean (0: none
                            cut; INFINITY: no bound); the rel_err rule needs it <= 0.1 E |m|, and
                            ci95 is widened by it on both sides */
    int cut_stop;        /* 1: stopped because the cuts' bias may exceed the rel_err target
                            (raise max_steps) */
    int out_of_reach;    /* 1: stopped early, not met, because the walks the rule predicts
                            (min_walks) exceed max_walks or ULAM_REL_ERR_CAP (a finite range,
                            a nonzero estimate and a certified finite variance; rel_err_met 0) */
    int64_t unreached;   /* forward: components no walk has tallied (no estimate at all) */
    double seconds;    /* wall time spent walking */
    int threads;       /* threads used */
    int interrupted;   /* stopped by *interrupt */
    ulam_power rho4;   /* rel_err > 0: rho(M4), M4_ij = |K_ij|^4 / (q_i p_ij)^3 (the walk's fourth
                          moment is finite when it is below 1), certified bounds; [0, INFINITY]
                          when not computed (rel_err 0, or a bounded score: not needed) */
    int fourth_finite; /* rel_err > 0: 1 the score's fourth moment is finite (rho4 certified
                          below 1, or a single score is bounded: every moment finite), 0 infinite,
                          -1 unknown (also rel_err 0: not asked).  Unless 1, variance_rel_error may
                          be far too small and the rel_err rule is never met (rel_err alone is
                          refused: ULAM_EINFVAR) */
    int push_sweeps;     /* forward: Gauss-Seidel sweeps of the push on b made before the walks (the
                            walks then start from its residual r and every estimate adds the push's
                            part; a rel_err target or a fixed budget of the method choice's); 0: the
                            walks start from b */
    int64_t push_ops;    /* their operations (a state read a sweep, a push its column's entries + 1) */
    double push_residual; /* ||r||_1 / ||b||_1 after them (1: no push) */
} ulam_walk_result;

/* An opaque walk solver: the kernel, the statistics and the stopping state. */
typedef struct ulam_solver ulam_solver;

/* Prepare walks on (I - M) x = b.  M and b are borrowed: they must stay unchanged until the
 * solver is freed, for the walk kernel's rows are built from them when a walk first reaches
 * them (so a query for one x_i reads and keeps only the rows its walks visit).
 * Before any walk it takes the guards' verdicts (opts->policy.guard, or ulam_guard_check on rho(|M|)
 * and this mode's rho(M^), stopped once certified) and keeps them:
 *   - rho(|M|) not certified below 1 (>= 1, or bounds straddling 1): ULAM_EDIVERGE unless
 *     opts->policy.force;
 *   - rho(M^) not certified below 1: the variance counts as infinite (result variance_finite
 *     0 or -1, ci95 NaN; opts->policy.assume_finite makes an unknown one finite), the rel_err rule
 *     never fires, and a rel_err run with neither max_walks nor max_seconds is refused with
 *     ULAM_EINFVAR (err->msg names the radius, and the other mode when its variance is finite);
 *   - absorption where a reachable scoring state has p* = 0: ULAM_EUNDEFINED, err->index
 *     naming it. */
int ulam_solver_alloc(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                      ulam_solver **out, ulam_error *err);

/* Run one round of walks (rounds grow 1, 2, 4 ... 64 blocks of 1024 walks as walks accumulate,
 * whatever the thread count).  A b whose largest |entry| lies outside [2^-256, 2^256] is walked
 * on scaled by a power of 2 (exact) and the results scaled back, so an answer a double can hold
 * is answered; one it cannot (or a non-finite score) ends the run with ULAM_ENONFINITE.  ULAM_OK,
 * or the status that ends the run: ULAM_ENONFINITE,
 * ULAM_ENOMEM, ULAM_EIO (the share's allgather), ULAM_ESYNTAX (a corrupt row of a mapped
 * file), ULAM_ERANGE (at kernel_alpha != 1, a reached row whose entries are so uneven that a
 * move's probability is below 2^-40 / the row's length); ulam_solver_error says why. */
int ulam_solver_iterate(ulam_solver *s);

/* Why the run failed (the status ulam_solver_iterate returned), with err filled: the row of a
 * corrupt mapped file, no memory, a failed exchange, a non-finite score; ULAM_OK while it has
 * not failed. */
int ulam_solver_error(const ulam_solver *s, ulam_error *err);

/* Nonzero once a stopping rule (walks, rel_err, time, interrupt) is met. */
int ulam_solver_done(const ulam_solver *s);

/* The result so far. */
void ulam_solver_result(const ulam_solver *s, ulam_walk_result *r);

/* Forward mode: every component's estimate and standard error (arrays of n; either may be
 * NULL); a component no walk has tallied has no estimate: x 0 (expected: b_i) and standard
 * error NaN.  Adjoint mode: ULAM_EINVAL.  ULAM_ENONFINITE (the arrays filled) when an estimate
 * exceeds the largest double. */
int ulam_solver_vectors(const ulam_solver *s, double *x, double *std_error);

/* Free a solver; accepts and returns NULL. */
ulam_solver *ulam_solver_free(ulam_solver *s);

/* The walks opts name, pinned (no choice): allocate, iterate until done, report, free in one
 * call, with the refusals of ulam_solver_alloc (guards checked first).  It always ends: rel_err alone stops at 10^9
 * walks at most (ULAM_REL_ERR_CAP; rel_err_met 0).
 * The rel_err rule (opts->stop.rel_err = E, variance certified finite; docs/error-bars.md), checked
 * after every round, stops when the printed 95% interval ci95 is at most E |m| wide on each side
 * ((ci95[1] - ci95[0]) / 2 <= E |m|, m the estimate), after N >= 1000 walks, m != 0 (unless
 * nothing that scores is reachable: x = 0, certified) and, forward, the watched component
 * opts->query.index tallied.  ci95 is a confidence sequence (src/stop.h: the predictable
 * plug-in empirical-Bernstein sequence of Waudby-Smith and Ramdas, 2023), valid at every walk
 * count at once, so stopping on it keeps its 95%; it rests on R, the range of a single score
 * (score_bound; for collision and expected the range of walks short enough to matter, from the
 * continuation or a Collatz-Wielandt certificate of the length tail; with weights growing on
 * cycles, from a certified second moment; twice it when scores take both signs), the scores
 * clipped to it and the clipping's bias added.  No such R (splitting, forward expected, no
 * certificate): never met, and rel_err alone is refused with ULAM_EINFVAR (err->msg names the
 * reason);
 * with walks cut at max_steps, cut_bound <= 0.1 E |m|, else the run stops (cut_stop).
 * A run whose predicted walks (min_walks) exceed max_walks or ULAM_REL_ERR_CAP stops after
 * the round, not met (out_of_reach), with the estimate so far; a zero estimate never does.  A split weight below the start weight (1 adjoint, ||b||_1 forward)
 * is refused with ULAM_EINVAL. */
int ulam_solve_walks(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                     ulam_walk_result *result, ulam_error *err);

/* The walk cap of a run whose only rule is rel_err. */
#define ULAM_REL_ERR_CAP 1000000000

/* ---------------------------------------------------------------- analysis: many queries on one M */
/* Secondary.  An analysis is what queries on one M share, built once for (M, continuation,
 * kernel exponent) and held by the caller across queries, as CSparse's cs_sqr is across cs_lu
 * calls: the guards' verdicts (a prepared system's certificate, else computed at the first
 * query), the bounds the rel_err rule and absorption need over every state (a prepared file
 * stores them, `ulam prepare`; else one pass over M at the first query that needs them), the
 * scores of the b the queries share (opts.b), each estimator's walk kernel (the rows any earlier
 * query built, kept while queries use that b), and M's transpose (made when first asked).  A
 * query then reads only the rows its walks reach.  The bounds hold for every start, so they are
 * at most as tight as a search of one start's reach would give (the rule may ask for more
 * walks); an estimate still exactly 0 searches its start's reach as ulam_solver_alloc would. */
typedef struct ulam_analysis ulam_analysis;

/* What an analysis is made for.  Start from ulam_analysis_defaults(). */
typedef struct ulam_analysis_opts {
    size_t size;             /* sizeof (ulam_analysis_opts), set by ulam_analysis_defaults: a
                                later version reads only the fields a caller's size holds */
    double continue_q;       /* the walks' continuation (<= 0: analog) */
    double kernel_alpha;     /* the kernel exponent (1) */
    const double *b;         /* the right-hand side queries share (NULL: none); borrowed, and its
                                values unchanged while the analysis lives */
    const ulam_system *system; /* the prepared system M is mapped from (NULL: none): its
                                certificate and stored bounds serve when made for this
                                continuation and exponent */
    int shared_bounds;       /* 1: the method table's walks (ulam_analysis_start, _solve) walk
                                under the bounds over every state, made once for all queries (a
                                prepared file's, or one pass over M); 0 (the default): each query
                                searches its own start's reach, as on M alone */
} ulam_analysis_opts;

/* The defaults: analog continuation, exponent 1, no b, no system, bounds per query. */
static inline ulam_analysis_opts ulam_analysis_defaults(void)
{
    ulam_analysis_opts o;
    ulam_defaults(ULAM_KIND_ANALYSIS, &o, sizeof o);
    return o;
}

/* An analysis of square M (borrowed: it must outlive the analysis) under opts (NULL: the
 * defaults).  O(1) work and memory here; what the queries need is made at the first that needs
 * it.  ULAM_OK, ULAM_EINVAL, ULAM_ENOTSQUARE, ULAM_ENOMEM. */
int ulam_analysis_alloc(const ulam_csr *M, const ulam_analysis_opts *opts, ulam_analysis **out, ulam_error *err);

/* Free an analysis and everything it made; accepts and returns NULL.  Free every solver made on
 * it first. */
ulam_analysis *ulam_analysis_free(ulam_analysis *a);

/* A solver for one query on a's M (as ulam_solver_alloc, whose refusals it shares), using what
 * a holds: opts->kernel.continue_q and kernel_alpha must be a's (ULAM_EINVAL otherwise); opts->policy.guard,
 * when NULL, is a's.  Adjoint queries with b = a's b walk on a's kept kernel for their estimator
 * (one solver on it at a time: free it before the next); other b and forward mode get a kernel
 * of their own.  The same seed gives the same walks as ulam_solver_alloc (the bounds, and so a
 * rel_err run's length, may differ). */
int ulam_analysis_solver(ulam_analysis *a, const double *b, const ulam_walk_opts *opts, ulam_solver **out,
                         ulam_error *err);

/* M's transpose, made at the first call and kept (NULL: no memory, err filled). */
const ulam_csr *ulam_analysis_transpose(ulam_analysis *a, ulam_error *err);

/* What an analysis holds so far. */
typedef struct ulam_analysis_info {
    int bounds;          /* 0 none yet, 1 read from a prepared file, 2 computed by a pass over M */
    int b_scores;        /* the shared b's scores: 0 none, 1 stored, 2 computed */
    int guard;           /* the guards: 0 none yet, 1 from a certificate, 2 computed */
    int64_t kernel_rows; /* rows built in the kept kernels */
    double seconds;      /* spent making the bounds, b's scores, guards and transpose */
} ulam_analysis_info;

/* Fill info (see ulam_analysis_info). */
void ulam_analysis_get_info(const ulam_analysis *a, ulam_analysis_info *info);

/* ---------------------------------------------------------------- outer iterations */
/* All secondary. */

/* Iterations on (I - M) x = b from x = 0 that stop on the exact residual
 * ||b - (I - M) x||_2 / ||b||_2 <= tol:
 *   ULAM_RICHARDSON  x <- M x + b (the deterministic reference);
 *   ULAM_GAUSS_SEIDEL one Gauss-Seidel sweep;
 *   ULAM_SEQUENTIAL  Halton's sequential Monte Carlo: r = b - (I - M) x, delta ~ (I - M)^-1 r
 *                    by forward walks from r, x <- x + delta;
 *   ULAM_MCSA        Monte Carlo Synthetic Acceleration (Evans and Mosher): a Richardson step
 *                    x <- M x + b, then the residual, its walk correction and the update.
 * The walks of an iteration run in batches until the apparent relative standard deviation of
 * the correction, ||stderr||_1 / ||delta||_1, is below eps1 (Benzi et al., Numer. Linear
 * Algebra Appl. 2017, criterion for the method that estimates every component), or the
 * history cap is reached. */
enum ulam_method { ULAM_RICHARDSON = 0, ULAM_GAUSS_SEIDEL = 1, ULAM_SEQUENTIAL = 2, ULAM_MCSA = 3 };

/* Options of an outer iteration.  Start from ulam_outer_defaults(). */
typedef struct ulam_outer_opts {
    int method;            /* enum ulam_method (default ULAM_MCSA) */
    double tol;            /* residual reduction, in (0, 1) (default 1e-8) */
    int max_iter;          /* iteration cap (default 0: 1000 with walks, 100000 for the deterministic) */
    int stall;             /* end with ULAM_ESTALL after this many iterations without a new
                              smallest residual (0: 5 with walks, 100 without) */
    double eps1;           /* adaptive threshold on ||stderr||_1 / ||delta||_1, in (0, 1)
                              (default 0.1) */
    int64_t max_histories; /* history cap of one correction (default 10^8) */
    ulam_walk_opts walk;   /* the walks: estimator, seed, threads, continue_q, max_steps,
                              roulette, split, interrupt, share (mode is forced to forward; the
                              seed of iteration l is drawn from the stream (seed, l)) */
} ulam_outer_opts;

/* The defaults: MCSA, tol 1e-8, max_iter 0, stall 0, eps1 0.1, max_histories 10^8, walk
 * ulam_walk_defaults() but forward expected-value walks (seed 1). */
static inline ulam_outer_opts ulam_outer_defaults(void)
{
    ulam_outer_opts o;
    ulam_defaults(ULAM_KIND_OUTER, &o, sizeof o);
    return o;
}

/* What one iteration did. */
typedef struct ulam_outer_step {
    int iteration;        /* 1-based */
    double residual;      /* ||b - (I - M) x||_2 / ||b||_2 after it */
    int64_t histories;    /* walks of its correction (0 without walks) */
    int64_t steps, cut;   /* their transitions, and walks cut at max_steps */
    double rel_sd;        /* ||stderr||_1 / ||delta||_1 the correction reached */
    double seconds;       /* wall time of the iteration */
    double walk_seconds;  /* of which walking */
} ulam_outer_step;

/* An outer iteration's workspace (opaque). */
typedef struct ulam_outer ulam_outer;

/* Prepare the iteration on (I - M) x = b (M and b borrowed until freed).  Refuses options
 * out of range (ULAM_EINVAL), a non-square M, and b = 0 (ULAM_EINVAL: nothing to reduce); with
 * walks, also a forward rho(M^) not certified below 1 (ULAM_EINFVAR, before any walk: an
 * unknown one walks when walk.assume_finite).  The guards come from walk.guard when it holds
 * rho(|M|) and the forward rho(M^) of this kernel, else they are computed here. */
int ulam_outer_alloc(const ulam_csr *M, const double *b, const ulam_outer_opts *opts, ulam_outer **out,
                     ulam_error *err);

/* One iteration; fills *step (may be NULL).  A walk correction is applied only when it lowers
 * the residual it was fed; otherwise its walks go on to about N (ratio / 0.5)^2 histories (at
 * least 4 N) and it is tried again, and when that count exceeds 100 times what the eps1 rule
 * asked for or max_histories, the run ends with ULAM_ESTALL (step->histories counts every
 * walk, rejected ones too).  ULAM_OK while it may go on or once converged;
 * then ULAM_ENOCONV at the iteration cap, ULAM_ESTALL when the residual stopped decreasing,
 * ULAM_ENONFINITE for a non-finite residual or walk, ULAM_ENOMEM; each also ends the run. */
int ulam_outer_iterate(ulam_outer *s, ulam_outer_step *step);

/* Nonzero once converged, failed, interrupted or capped. */
int ulam_outer_done(const ulam_outer *s);

/* Where an outer iteration stands. */
typedef struct ulam_outer_info {
    const double *x; /* the current iterate (n entries, owned by the workspace) */
    int converged;   /* nonzero once ||r||_2 / ||b||_2 <= tol */
    int rejected;    /* corrections rejected so far: a walk correction that did not lower the
                        residual is never applied; its walks go on to more histories (see
                        ulam_outer_iterate) */
} ulam_outer_info;

/* Fill info (all zero for s NULL). */
void ulam_outer_get_info(const ulam_outer *s, ulam_outer_info *info);

/* Free; accepts and returns NULL. */
ulam_outer *ulam_outer_free(ulam_outer *s);

/* Why the run ended, as a sentence in err (may be NULL); returns its status (ULAM_OK while it
 * goes on or once converged). */
int ulam_outer_error(const ulam_outer *s, ulam_error *err);


/* Iterate until done into x (n entries); steps (may be NULL) gets up to max_steps records,
 * *nsteps (may be NULL) the iterations run.  Returns the last iterate's status. */
int ulam_outer_solve(const ulam_csr *M, const double *b, const ulam_outer_opts *opts, double *x,
                     ulam_outer_step *steps, int max_steps, int *nsteps, ulam_error *err);

/* ---------------------------------------------------------------- Krylov peers */
/* Secondary (CG asks a symmetric M: ulam_csr_stats_compute's symmetric). */

/* Krylov solvers for (I - M) x = b from x = 0, stopped when ||b - (I - M) x||_2 / ||b||_2 <=
 * tol (the true residual, recomputed at the end): conjugate gradients for symmetric positive
 * definite I - M (ulam_cg), restarted GMRES(restart) with modified Gram-Schmidt and Givens
 * rotations otherwise (ulam_gmres).  *iterations gets the matrix-vector products spent on
 * Krylov vectors, *residual the final relative residual.  ULAM_OK or ULAM_ENOCONV at max_iter;
 * ULAM_ENONFINITE when x or the residual is not finite (b far from 1 is scaled by a power of 2
 * first, exactly, so an x up to the largest double is answered). */
int ulam_cg(const ulam_csr *M, const double *b, double tol, int max_iter, double *x, int *iterations,
            double *residual);
int ulam_gmres(const ulam_csr *M, const double *b, int restart, double tol, int max_iter, double *x,
               int *iterations, double *residual);

/* ---------------------------------------------------------------- point sources: push and bidirectional */
/* All secondary. */

/* Reverse local push from a target t on the adjoint equation (src/push.c): estimates p and
 * residuals r with x_t = <p, b> + <r, x> for every b, where (I - M) x = b.  Pushing j moves r_j
 * into p_j and adds M_jk r_j to r_k over row j of M.  An opaque workspace, reused across
 * targets (a new start clears only the states the last one touched). */
typedef struct ulam_push ulam_push;

/* What the pushes since the last start did. */
typedef struct ulam_push_info {
    int64_t target;  /* 0-based; -1 before any start */
    double rmax;     /* every |r_j| <= rmax once a run has returned ULAM_OK */
    int64_t pushes;  /* states pushed */
    int64_t ops;     /* work: nonzeros of M read, plus one per push */
    int64_t touched; /* states whose p or r was ever set */
    int64_t support; /* states with r_j != 0 */
    double r_sum, r_max; /* sum and largest of |r_j| */
    double seconds;  /* wall time pushing */
    int64_t krylov;  /* the push on b with a symmetric M: the conjugate-gradient products that made
                        its start q (src/bkrylov.c; 0: none, the push from q = 0) */
} ulam_push_info;

/* Bidirectional estimate of x_t of (I - M) x = b for b = e_s or a sparse b (src/bidir.c; Lofgren,
 * Banerjee, Goel, "Personalized PageRank estimation and search: a bidirectional approach", WSDM
 * 2016): a reverse push from t gives x_t = <p, b> + <r, x>, and <r, x> = b' (I - M')^-1 r is
 * estimated by the adjoint walk solver on M' scoring r from walks that start at s (or at b's
 * state j with probability |b_j| / ||b||_1 and weight sign(b_j) ||b||_1: walks forward from the
 * sources).  Each score is at most rmax x the walk's weight sum, so the variance falls with rmax.  Start from
 * ulam_bidir_defaults(). */
typedef struct ulam_bidir_opts {
    int64_t target, source; /* 0-based t and s (b = e_s when nb is 0) */
    int64_t nb;               /* > 0: a sparse b instead of e_s, nb entries (indices may repeat) */
    const int64_t *b_index;   /* their 0-based states (borrowed) */
    const double *b_value;    /* their finite values, not all 0 */
    double rmax;       /* push threshold; <= 0: balance the push's work against the walks' predicted work */
    double min_value;  /* the smallest |x_t| the balance plans for (<= 0: 1 / n) */
    int64_t max_push_ops; /* cap on the push's work (0: 100 nnz(M) + 10^6); past it ULAM_ENOCONV */
    ulam_walk_opts walk;  /* the walks' kernel, seed, threads and stopping rules (mode, index and
                             starts are set here); rel_err applies to the whole estimate
                             <p, b> + <r, x> */
    int reach_all;        /* 1: the walks' reachability bounds (rel_err, absorption) taken over
                             every state of Mt, a superset of what any source reaches, so they
                             hold for every query (looser where a source reaches less); computed
                             once and kept with the push workspace (or the analysis:
                             ulam_analysis_bidir) for later queries on the same Mt, continuation
                             and exponent; 0: a search from the source each query */
    int keep_kernel;      /* 1 (collision or absorption): the walks' kernel rows of Mt kept with the
                             push workspace (or the analysis) and rescored to the next query's
                             residual, so a query builds only the rows no earlier one reached (its
                             walks are those a new kernel gives, bit for bit; walks.rows counts
                             every row kept) */
    double step_cost;     /* push operations one walk visit costs, for the balance (<= 0: the
                             default ULAM_BIDIR_STEP_COST); measure it on the machine and graph at
                             hand with bench_bidir, which prints push operations/s over walk
                             visits/s (docs/bidirectional.md) */
} ulam_bidir_opts;

/* The balance's default cost of one walk visit in push operations: the median of bench_bidir's
 * measurements, 0.74 and 1.29 on the Zipf family and 1.82 on R-MAT 2^18 (one thread, a 2-core
 * machine at load ~20, 2026-12-02, docs/bidirectional.md); not the 3 issue 29 supposed. */
#define ULAM_BIDIR_STEP_COST 1.3

/* The defaults: target and source 0, balanced rmax (0), min_value 0 (1 / n), max_push_ops 0
 * (the default cap), walk ulam_walk_defaults(), step_cost 0 (ULAM_BIDIR_STEP_COST). */
static inline ulam_bidir_opts ulam_bidir_defaults(void)
{
    ulam_bidir_opts o;
    ulam_defaults(ULAM_KIND_BIDIR, &o, sizeof o);
    return o;
}

/* A bidirectional estimate's plan: the push it runs and what the walks after it
 * are predicted to cost, in a deterministic unit of work (push operations; a walk's visits, its
 * steps + 1, count step_cost operations each), so a comparison of methods on it gives the same
 * answer on every run, thread count and MPI rank. */
typedef struct ulam_bidir_plan_info {
    int64_t target;         /* 0-based t */
    double rmax;            /* the push threshold: the balance's choice, or ulam_bidir_opts.rmax */
    int balanced;           /* 1: rmax chosen by the balance */
    ulam_push_info push;    /* the push as run to rmax (its ops are counted, not predicted) */
    double push_part;       /* <p, b>: the exact part of x_t */
    int64_t pilot_walks;    /* walks of the pilot that measured mean_visits (0: rmax given) */
    int64_t pilot_steps;    /* their steps */
    double mean_visits;     /* V: states a walk from b visits on average (pilot; 1 without one) */
    double predicted_walks; /* walks the stopping rule is predicted to need (0: no residual left,
                               the value is exact; max_walks when that is the only rule; NaN
                               when rmax is given and rel_err is set: no pilot measured V) */
    double predicted_work;  /* push.ops + step_cost (pilot visits + predicted_walks V): the whole
                               estimate's work in push operations (NaN when rmax is given and
                               walks remain: no pilot measured V) */
    double step_cost;       /* push operations a walk visit counts as */
    int64_t pilot_units;    /* kernel units (16 bytes of a row) the pilot's solver built on Mt */
    int64_t pilot_reads;    /* entries its reachability checks and score-bound passes read */
    double seconds;         /* wall time of the plan: pilot and push */
    double probe;           /* a lower bound on |x_t| from 1024 walks scoring the residual midway
                               (0: no probe ran, or it saw nothing), which the balance plans for */
} ulam_bidir_plan_info;

/* What a bidirectional estimate found. */
typedef struct ulam_bidir_result {
    double estimate, std_error, ci95[2]; /* of x_t: <p, b> plus the walks' estimate of <r, x>; the
                                            interval widened by an allowance for the push's rounding */
    double push_part;      /* <p, b>, exact given the push */
    ulam_push_info push;   /* the push (its seconds are push_seconds) */
    ulam_walk_result walks; /* the walks' estimate of <r, x> (0 walks when r = 0: exact) */
    ulam_bidir_plan_info plan; /* the plan the estimate followed */
    int plan_reused;       /* 1: the workspace held this plan (ulam_analysis_bidir), not redone */
    double seconds;        /* the whole estimate: the plan's seconds (pilot and push, also when
                              reused) plus the walks' set-up and walks */
} ulam_bidir_result;

/* Single source, every target (src/fpush.c, src/sweep.c; FORA, Wang et al., KDD 2017, with
 * SpeedPPR's sweeps, Wu et al., 2021): x = (I - M)^-1 e_s by a forward push from s (rounds over
 * the states holding residual, then whole sweeps in order once n/16 do), leaving
 * x = p + (I - M)^-1 r, and terminal walks on M from r that estimate every component of the rest
 * (||M||_1 >= 1: the queue push of ulam_push on M' and the forward walk solver).  Start from
 * ulam_fpush_defaults(). */
typedef struct ulam_fpush_opts {
    int64_t source;      /* 0-based s */
    double rel_err;      /* E: walk until every x_i whose interval reaches min_value has its 95%
                            interval within -+ E x_i (default 0.1) */
    double min_value;    /* delta (<= 0: 1 / n) */
    int64_t walks;       /* > 0: this many walks; 0: the rel_err rule */
    double rmax;         /* > 0: push every |r_j| > rmax, no balance; <= 0: push while one more
                            round saves more predicted walk work than it costs */
    double step_cost;    /* push operations a walk step costs, for the balance (<= 0: 100; the
                            queue path: ULAM_BIDIR_STEP_COST) */
    ulam_walk_opts walk; /* seed, threads, estimator, continue_q, guard, max_walks, interrupt (mode
                            forced forward) */
} ulam_fpush_opts;

/* The defaults: source 0, rel_err 0.1, min_value 0, walks 0, rmax 0, step_cost 0, walk
 * ulam_walk_defaults() in forward mode. */
static inline ulam_fpush_opts ulam_fpush_defaults(void)
{
    ulam_fpush_opts o;
    ulam_defaults(ULAM_KIND_FPUSH, &o, sizeof o);
    return o;
}

/* What a single-source estimate did. */
typedef struct ulam_fpush_info {
    double rmax;           /* the push threshold (the sweep push balanced: the largest |r_j| left) */
    ulam_push_info push;   /* the push */
    double mean_visits;    /* V the balance took: 1 / (1 - ||M||_1) */
    double residual_bound; /* ||r||_1 / (1 - ||M||_1): the most the walks' part of any x_i can be
                              (INFINITY: ||M||_1 >= 1, no bound) */
    int64_t walks, steps;  /* the walks and their transitions */
    int interrupted;       /* 1: by opts->walk.stop.interrupt; 2: walk.stop.max_seconds ended the walks (the
                              top-K target's push takes at most a quarter of it): intervals wider than planned */
    double seconds, push_seconds, walk_seconds;
    double rel_err, min_value; /* the target the walks were planned for: relative error rel_err at every x_i
                                  whose interval reaches min_value (ulam_fpush_top with min_value <= 0: the
                                  k-th largest p_i + r_i after the push, which x's k-th largest is at least
                                  when M >= 0; else min_value, or 1 / n) */
    int dense;             /* 1: x by a dense LU of I - M instead (a small system whose push would take
                              1 / (1 - ||M||_1) sweeps an e-fold): no push, no walks; residual_bound
                              certifies every x_i from the LU's residual (push.r_sum) */
} ulam_fpush_info;

/* Estimate every x_i of (I - M) x = e_source into x (n entries); std_error, lo and hi (each may
 * be NULL) get each component's standard error and 95% interval: p_i + the walks' stitched
 * empirical-Bernstein interval (src/stop.h; every walk score within -+ ||r||_1 / (1 - ||M||_1)),
 * clipped to p_i -+ residual_bound, widened by an allowance for the push's rounding, its lower end
 * at least min(x_i, 0) when M >= 0 (the queue path for ||M||_1 >= 1: the normal interval where the
 * walks scored two values, else p_i -+ residual_bound, NaN when there is none, and NaN everywhere
 * when the forward guard does not certify the walks' variance finite).  Mt is M's
 * transpose.  With o->walk.policy.system (M its ulam_system_lazy matrix) and Mt NULL, the file's
 * stored M^T (ulam prepare --transpose) is read where the push and the walks go, each block
 * verified when first read (ulam_system_info.blocks_checked counts them); sweeps of the whole
 * graph, a guard to compute, or a file with no M^T verify the file whole first (a damaged block:
 * ULAM_ESYNTAX naming it).  ULAM_OK, ULAM_EINVAL, ULAM_ENOCONV (queue push cap 100 nnz + 10^6), ULAM_ENOMEM,
 * the walk solver's statuses. */
int ulam_fpush_solve(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *o, double *x, double *std_error,
                     double *lo, double *hi, ulam_fpush_info *info, ulam_error *err);

/* ulam_fpush_solve's x (n entries), and of only the k (0 <= k <= n) components of largest
 * estimate: their indices into index (k entries; by decreasing estimate, ties by smaller index,
 * NaN last) and their standard errors and 95% intervals into std_error, lo and hi (k entries
 * each, each may be NULL), as ulam_fpush_solve gives them but for the lower ends (0 < k < n): the
 * k are chosen by their estimates after the walks, so their lower ends are taken at delta k / n
 * (at most a share delta / 2 of them miss below in expectation; docs/bidirectional.md), and the
 * relative-error rule, which checks them, may walk on, so x may differ.  For a query that reports a
 * few components: no pass writes 3 n outputs (whose first touch alone dominated the walk phase on
 * R-MAT 2^20) and no sort of n.  ulam_fpush_solve's statuses; ULAM_EINVAL for k out of range or
 * no index array. */
int ulam_fpush_top(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *o, int64_t k, double *x, int64_t *index,
                   double *std_error, double *lo, double *hi, ulam_fpush_info *info, ulam_error *err);

/* ---------------------------------------------------------------- choosing the method */
/* All secondary. */

/* What became of a candidate of ulam_auto_solver. */
enum ulam_auto_state {
    ULAM_AUTO_UNCERTIFIED = 0, /* its variance is not certified finite (or its guard was not computed) */
    ULAM_AUTO_REFUSED,         /* the solver refused it (status: absorption with p* = 0) */
    ULAM_AUTO_SKIPPED,         /* not piloted: starting its kernel would pass the pilot budget */
    ULAM_AUTO_DROPPED,         /* piloted, then dropped: its predicted work clearly the leader's worse */
    ULAM_AUTO_FINALIST,        /* piloted to the end, not chosen */
    ULAM_AUTO_CHOSEN
};

/* One candidate of ulam_auto_solver: a mode, an estimator and a continuation. */
typedef struct ulam_auto_candidate {
    int mode, estimator;
    double continue_q;    /* <= 0: analog */
    double kernel_alpha;  /* the kernel exponent: p_ij proportional to |K_ij|^alpha */
    ulam_power hat;       /* rho(M^) of this candidate's kernel (bounds [0, INFINITY]: not computed) */
    int certified;        /* hat.upper < 1 and rho(|M|)'s upper bound < 1: variance certified finite */
    int status;           /* ULAM_OK, or why the solver refused it (ULAM_EUNDEFINED: absorption with p* = 0) */
    int state;            /* enum ulam_auto_state */
    int stages;           /* pilot stages it ran (its pilots: pilot_walks, then doubling) */
    int64_t pilot_walks;  /* walks of its pilots, all stages (0: not piloted) */
    double estimate, variance, variance_rel_error; /* pooled over its pilots (never used in the answer) */
    double steps_per_walk; /* the pilots' mean steps a walk */
    double work_per_walk;  /* the work model's units a walk (see ulam_auto_solver) */
    double cost;           /* variance x work_per_walk (INFINITY when not piloted); the variance
                              compared is at least what puts the pilot's mean within 2 standard
                              errors of the most precise other pilot's (a pilot that missed a
                              skewed score's rare large values looks cheap otherwise) */
    double predicted_walks; /* walks the run would make (rel_err: the rule's variance, range and
                               variance-error terms at the pilots' values, rounded up to the rounds
                               the rule is checked at; else max_walks; NaN for time alone) */
    int predicted_lower;    /* 1: predicted_walks is only a lower bound on the walks the rule will
                               need: the pilots' mean is within 4 of its standard errors of 0
                               (base's rel_err_offset added), so it does not resolve |x| (signed
                               cancellation), and the prediction is made at the largest |x| the
                               pilots allow; such a leader's pilots grow past ao->pilot_max (up to
                               64 times) while the pilot share allows.  0 otherwise (also without
                               a rel_err race or a pilot) */
    double predicted_work;  /* units: predicted_walks x work_per_walk + the kernel still to build */
    double predicted_seconds; /* predicted_work x ULAM_AUTO_UNIT_SECONDS (for the report only) */
} ulam_auto_candidate;

/* At most 2 modes x 3 estimators x 2 continuations (x 3 kernel exponents). */
#define ULAM_AUTO_MAX 36

/* The work model's units (one unit: one step of a walk), measured once (README, "Choosing for the
 * user"): a walk's start and record, a forward tally, a kernel unit built (16 bytes of a row), a
 * matrix entry read by a guard, reachability check or score-bound pass; and the seconds a unit
 * took on the machine they were measured on.  ULAM_AUTO_UNIT_SECONDS is a tunable of the report
 * alone (docs/tunables.md): it converts predicted work to the predicted_seconds printed, and
 * nothing the choice or a run decides reads it, so the same seed gives the same answer on every
 * machine whatever its speed. */
#define ULAM_AUTO_WALK 3.0
#define ULAM_AUTO_TALLY 1.0
#define ULAM_AUTO_BUILD 2.0
#define ULAM_AUTO_READ 1.0
#define ULAM_AUTO_UNIT_SECONDS 3e-8

/* What the choice may vary and how it pilots: a pinned part keeps base's value.  Start from
 * ulam_auto_defaults(). */
typedef struct ulam_auto_opts {
    int pin_mode, pin_estimator, pin_continue, pin_alpha;
    double continue_q;    /* the fixed continuation tried beside analog (default 0.9); kernel
                             exponents tried: 1, 0 and 2 */
    int64_t pilot_walks;  /* a candidate's first pilot (default 128 walks); survivors double */
    int64_t pilot_max;    /* the largest pilot of a stage (default 1024) */
    double pilot_share;   /* stop piloting once the pilots' overhead (their work less what the
                             leader's run reuses) reaches this share of the leader's predicted
                             run (default 0.2) */
    const ulam_guard *guard; /* radii computed before (a prepared system's certificate): they serve
                                the candidates of their continuation and exponent instead of a pass
                                over M (NULL: none) */
} ulam_auto_opts;

/* The default options: nothing pinned, Q = 0.9, pilots of 128 walks doubling up to 1024, 0.2. */
static inline ulam_auto_opts ulam_auto_defaults(void)
{
    ulam_auto_opts o;
    ulam_defaults(ULAM_KIND_AUTO, &o, sizeof o);
    return o;
}

/* The candidates and the choice. */
typedef struct ulam_auto_result {
    int ncand;
    ulam_auto_candidate cand[ULAM_AUTO_MAX];
    int chosen;     /* the piloted candidate of least predicted work (rel_err) or cost; -1 when none
                       is certified */
    int closest;    /* the candidate of least rho(M^) among those screened (named when none is certified) */
    ulam_power abs; /* rho(|M|) */
    ulam_guard guard; /* the guards of the chosen (or closest) candidate's continuation */
    int by_work;    /* 1: compared by predicted work (a rel_err target); 0: by cost */
    int stages;     /* pilot stages run */
    double pilot_work;  /* units the guards and pilots spent */
    double reused_work; /* of which the chosen run reuses (its guards, reachable set, score bounds, kernel rows) */
    double seconds; /* wall time of guards and pilots (reported; the choice never looks at a clock) */
} ulam_auto_result;

/* Choose the walk method for (I - M) x = b under base's options, deterministically: the same
 * choice for any thread count, process count and machine load (no clock is read for it).
 *   - candidates: mode x estimator x continuation (analog, ao->continue_q) x kernel exponent
 *     (1, 0, 2), less what is pinned, adjoint before forward; a guard per continuation and
 *     exponent (rho(|M|), rho(M^) of each mode's kernel;
 *     the forward one only when forward candidates are started or none is certified) screens
 *     them: only certified-finite ones are piloted;
 *   - pilots race: every candidate ao->pilot_walks walks, on seeds of its own, candidates of one
 *     kernel (mode, continuation) sharing one solver (its rows, reachable set and score bounds;
 *     rescored per estimator), then the survivors' walks double; a candidate is dropped when even
 *     at its variance's lower bound (2 relative errors) its predicted work exceeds the leader's at
 *     its upper; piloting stops when one is left, at ao->pilot_max, or when the overhead reaches
 *     ao->pilot_share of the leader's predicted run (then no new kernel is started either);
 *   - predicted work: units of the work model (ULAM_AUTO_*): walks x (steps + ULAM_AUTO_WALK +
 *     forward tallies) + the kernel units still to build; with rel_err the walks are the rule's:
 *     variance, range (min_walks) and variance-error terms, at a lower bound where the pilots do
 *     not resolve |x| (ulam_auto_candidate.predicted_lower).
 * The pilots' walks are not used in the answer: it comes from fresh walks on base's seed
 * (ulam_auto_solver), which the choice, a function of the pilots alone, cannot bias. */

/* ulam_auto_solver: the choice above, and *out (NULL: the choice alone) gets the solver to run:
 * the chosen candidate's (or, when none is certified, the closest's) on base's options with that mode, estimator and continuation, its
 * kernel rows, reachable set, score bounds and guards kept from the pilots, no walk made yet:
 * iterating it gives, bit for bit, what a solver allocated with those options would (NULL with
 * a status when none is left).  Its refusals are ulam_solver_alloc's. */
int ulam_auto_solver(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                     ulam_auto_result *res, ulam_solver **out, ulam_error *err);

/* ---------------------------------------------------------------- the method table */
/* All secondary, except primary: ulam_auto. */

/* The methods, rows of one table (src/method.c; GSL's gsl_root_fsolver_type): each has a name,
 * an applicability test, a cost prediction in the work model's units (ULAM_AUTO_*) and a run.
 * Rows answer one of two questions: one entry x_i with an error bar (walks, bidirectional) or
 * every unknown to a residual tolerance (the outer iterations and the Krylov peers; asked for
 * one entry they answer x_i without an error bar).  Row k's number is stable: */
enum ulam_method_row {
    ULAM_METHOD_WALKS = 0,         /* adjoint or forward walks: mode x estimator x continuation x
                                      kernel exponent, raced by ulam_auto_solver */
    ULAM_METHOD_BIDIRECTIONAL = 1, /* reverse push from the index, walks from a sparse b */
    ULAM_METHOD_RICHARDSON = 2,    /* then ULAM_METHOD_RICHARDSON + enum ulam_method: richardson, */
    ULAM_METHOD_GAUSS_SEIDEL = 3,  /* gauss-seidel, */
    ULAM_METHOD_SEQUENTIAL = 4,    /* sequential, */
    ULAM_METHOD_MCSA = 5,          /* mcsa (ulam_outer_*), */
    ULAM_METHOD_CG = 6,            /* then the Krylov peers cg */
    ULAM_METHOD_GMRES = 7,         /* and gmres */
    ULAM_NMETHODS = 8
};

/* What a row answers. */
enum { ULAM_ANSWERS_ENTRY = 1, ULAM_ANSWERS_ALL = 2 };

/* Row k's name ("walks", "bidirectional", "richardson", "gauss-seidel", "sequential", "mcsa", "cg",
 * "gmres"), or NULL when k is out of range. */
const char *ulam_method_name(int k);

/* The row named name, or -1. */
int ulam_method_find(const char *name);

/* What row k answers: ULAM_ANSWERS_ENTRY or ULAM_ANSWERS_ALL (0 out of range). */
int ulam_method_answers(int k);

/* The densest b the bidirectional row takes by its reverse push from the index: nonzeros at most
 * max(16, n / 10) (a denser b: the push on b, see ulam_auto_start). */
int64_t ulam_method_sparse_limit(int64_t n);

/* Which rows a choice may take.  Start from ulam_method_defaults(). */
typedef struct ulam_method_opts {
    int method;       /* the row pinned (enum ulam_method_row); -1: choose among the rows */
    unsigned exclude; /* bit k set: row k (not the walks) is not considered (its why says "not
                         considered: excluded"; a caller may write its own reason there) */
} ulam_method_opts;

/* The defaults: no row pinned (method -1), none excluded. */
static inline ulam_method_opts ulam_method_defaults(void)
{
    ulam_method_opts o;
    ulam_defaults(ULAM_KIND_METHOD, &o, sizeof o);
    return o;
}

/* What became of a row in a choice. */
enum ulam_method_state {
    ULAM_METHOD_NOT_CONSIDERED = 0, /* its applicability test failed (why says which) */
    ULAM_METHOD_PLANNED = 1,        /* applicable and its cost predicted (or refused, or dropped while
                                       predicting: why says), not chosen */
    ULAM_METHOD_CHOSEN = 2          /* the row that runs */
};

/* One row's verdict. */
typedef struct ulam_method_verdict {
    int state;             /* enum ulam_method_state */
    double predicted_work; /* its predicted work in the work model's units (NaN: not predicted) */
    char why[320];         /* states 0 and 1: why not, in one line (empty when chosen) */
} ulam_method_verdict;

/* The choice among the rows for one query (ulam_auto_start). */
typedef struct ulam_choice {
    int chosen;                   /* the row that runs (enum ulam_method_row; -1: none) */
    int pinned;                   /* 1: the row was pinned (ulam_method_opts.method), not chosen */
    ulam_method_verdict method[ULAM_NMETHODS];
    ulam_auto_result walks;       /* the walks row's race (ulam_auto_solver): its candidates */
    double leader_work;           /* the walks' chosen candidate's predicted work (NaN: none) */
    ulam_bidir_plan_info bidir;   /* the bidirectional row's plan (state PLANNED or CHOSEN) */
    ulam_bidir_opts bidir_opts;   /* the options it was planned with and runs with (its b arrays
                                     are owned by the run: valid until ulam_run_free) */
    double transpose_seconds;     /* the bidirectional row's transpose of M */
    int bidir_route;              /* the route the bidirectional run takes: 1 the push on b and walks
                                     from the index, 0 the reverse push from the index and walks from
                                     b (a sparse b, or no walks from the index certified), -1 another
                                     row chosen */
} ulam_choice;

/* A chosen method ready to run (opaque): the walk solver, the bidirectional plan, or the outer
 * iteration's options. */
typedef struct ulam_run ulam_run;

/* What a run answered: x_index with an error bar (NaN without one: the rows that answer every
 * unknown to a residual), the row that ran, the options its walks ran with (the choice's mode,
 * estimator, continuation and exponent; borrowed pointers as given) and the row's own result. */
typedef struct ulam_answer {
    int method;                  /* enum ulam_method_row */
    double estimate, std_error, ci95[2];
    ulam_walk_opts opts;         /* walks: the options of the run (the choice's); else as given */
    ulam_walk_result walks;      /* walks: the run; bidirectional: its walks (on <r, x>) */
    ulam_bidir_result bidir;     /* bidirectional only */
    ulam_guard guard;            /* walks: the guards the run walked under */
    int iterations;              /* outer or Krylov rows: iterations (matrix-vector products for Krylov) */
    double residual;             /* outer or Krylov rows: the final relative residual */
    int status;                  /* the run's status (ULAM_OK; ENOCONV, ESTALL for the outer rows) */
} ulam_answer;

/* Choose the method for x_{o->query.index} of (I - M) x = b under o's options, ao's pins of the walks'
 * candidates (ao NULL: ulam_auto_defaults()) and mo's of the rows (mo NULL:
 * ulam_method_defaults(), every row considered): with mo->method >= 0 that row alone, as o says (walks: ulam_solver_alloc on o, no pilots: bit for bit what ulam_solve_walks does);
 * else every row of the table in order: the walks row races its candidates (ulam_auto_solver),
 * then each other row's applicability test and cost prediction, a row replacing the leader when
 * its predicted work is below the leader's.  Bidirectional applies to an adjoint query with a
 * rel_err target, nothing pinned it cannot honour (forward mode, the estimator, alpha other than
 * 1, roulette or split; a dense b takes the leader's estimator and exponent), a nonzero b and a
 * walk leader W above nnz(M)/4 (it needs M's transpose); its push is capped at W / 2 (pinned, a
 * b equal to e_S runs as the point source S, as `ulam solve --source S` does).  A sparse b
 * (ulam_method_sparse_limit) gets the reverse push from the index and walks from b; a dense b
 * the push on b (src/bpush.c): b's large entries are pushed down to rmax deterministically and
 * adjoint walks from the index score the residual, whose smaller range the rel_err rule pays
 * for (pinned, it needs a rel_err target and plans from a pilot round of walks on b).  The rows that answer every unknown do
 * not apply to a query for one entry with an error bar (they give no standard error; pinned, their
 * ci95 is the certified range ulam_solution_bound gives from x's residual, NaN where none holds); pinned, they run from
 * ulam_outer_defaults() and the Krylov peers to its tolerance, with o's seed, threads,
 * continuation, cut, interrupt and force, and o->stop.max_walks (when set) capping one correction.
 * ch gets every row's verdict; *out the run (NULL on failure).  Statuses: ulam_auto_solver's (the walks' refusal:
 * ch->walks says which candidate), ULAM_ENOMEM. */
int ulam_auto_start(const ulam_csr *M, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                    const ulam_method_opts *mo, ulam_choice *ch, ulam_run **out, ulam_error *err);

/* The walk solver of a run of the walks row (borrowed: iterate it, read it; freed by
 * ulam_run_free), or NULL for another row. */
ulam_solver *ulam_run_solver(ulam_run *r);

/* Run to the end (walks: iterate the solver until done) and fill *a.  The walks' statuses, the
 * bidirectional and outer rows' (ULAM_ENOCONV, ULAM_ESTALL with a filled; a->status holds it). */
int ulam_run_finish(ulam_run *r, ulam_answer *a, ulam_error *err);

/* Free a run; accepts and returns NULL. */
ulam_run *ulam_run_free(ulam_run *r);

/* The library's `ulam solve`: ulam_auto_start, ulam_run_finish, ulam_run_free in one call
 * (ch may be NULL).  With ao and mo NULL it chooses as `ulam solve` does by default (the same
 * choice and, on the same seed, the same estimate); pin a row with mo->method
 * (ULAM_METHOD_WALKS: ulam_solve_walks's run, bit for bit).  Tertiary: ulam_analysis_solve on an
 * analysis of M is the primary call. */
int ulam_auto(const ulam_csr *M, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
              const ulam_method_opts *mo, ulam_choice *ch, ulam_answer *a, ulam_error *err);

/* A bidirectional estimate (b = e_source or o's sparse b; x_target) on a's transpose (ulam_analysis_transpose: a
 * prepared file's stored M^T when it has one, else made once), push workspace and plan memo,
 * all made at the first call and kept across queries: a plan is reused for
 * the same options and the push as it left it; the walks' bounds over every state and kernel
 * rows (o->reach_all, keep_kernel) stay with the analysis.  o->walk.kernel's continuation and
 * exponent must be a's (ULAM_EINVAL otherwise: one analysis, one kernel).  The same seed gives
 * the same estimate as a fresh analysis.  ULAM_OK, ULAM_EINVAL (bad options), ULAM_ENOMEM,
 * and the walks' refusals (ulam_solver_alloc's). */
int ulam_analysis_bidir(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_result *res, ulam_error *err);

/* ---------------------------------------------------------------- one unknown: the primary call */
/* Primary: ulam_analysis_solve (with ulam_analysis_alloc, ulam_analysis_free, ulam_method_find).
 * Secondary: ulam_analysis_start and the run's ulam_run_solver, ulam_run_finish, ulam_run_free
 * (the same, step by step: iterate the walks to show progress or stop early).
 *
 * To ask for x_i of (I - M) x = b:
 *     ulam_analysis *a;  ulam_analysis_alloc(M, NULL, &a, &err);      (once per M, reused)
 *     ulam_walk_opts o = ulam_walk_defaults();  o.query.index = i;  o.stop.rel_err = 0.01;
 *     ulam_answer ans;   ulam_analysis_solve(a, b, &o, NULL, NULL, NULL, &ans, &err);
 *     ... ans.estimate, ans.ci95 ...;   ulam_analysis_free(a);
 * and a method by name: ulam_method_opts mo = ulam_method_defaults();
 *     mo.method = ulam_method_find("bidirectional");  ulam_analysis_solve(a, b, &o, NULL, &mo, ...). */

/* x_{o->query.index} of (I - M) x = b, M = a's, as `ulam solve` answers it: by the method the
 * table chooses (mo NULL, or mo->method -1: every row's applicability and predicted work, the walks
 * racing their candidates) or by the row mo->method names (ulam_method_find; ULAM_METHOD_WALKS with
 * every walk option as o says: ulam_solve_walks's run, bit for bit, when a does not share bounds).
 * ao NULL takes the walks' pins from o as the command line takes them from its options: a walk
 * option that differs from ulam_walk_defaults() (mode, estimator, continuation, exponent) pins
 * that part of the race, and all four, or weighted starts, pin the walks row (when mo is NULL);
 * o->policy.guard serves as ao's guard.  A rel_err target with max_walks left at its default runs
 * to the target (capped at ULAM_REL_ERR_CAP), as --rel-err does.  So a caller with
 * ulam_walk_defaults() and an analysis with ulam_analysis_defaults() gets what `ulam solve` gives
 * for a Matrix Market file: the same choice and, on the same seed, the same estimate.  ch (may be
 * NULL) gets every row's verdict; ans the answer: x_i with its error bar (ans->estimate,
 * std_error, ci95; NaN without one: the rows that answer every unknown to a residual), the row
 * that ran and its own result.  Statuses: the walks' refusals (ulam_solver_alloc's: ch->walks
 * says which candidate), the rows' (ULAM_ENOCONV, ULAM_ESTALL, with ans filled), ULAM_EINVAL,
 * ULAM_ENOMEM. */
int ulam_analysis_solve(ulam_analysis *a, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                        const ulam_method_opts *mo, ulam_choice *ch, ulam_answer *ans, ulam_error *err);

/* ulam_analysis_solve's first half: choose (or start mo's row) and hand out the run in *out (NULL
 * on failure), no walk made yet; ao NULL: ulam_auto_defaults(), nothing pinned (o's walk options
 * are not read as pins here), and o's budget as given.  The walks row's candidates walk under a's
 * bounds over every state when a shares them (ulam_analysis_opts.shared_bounds: a prepared
 * file's, or one pass over M), else each on its start's reach as ulam_auto_start does on M; the
 * bidirectional row on a's transpose and plans either way.  The run borrows a (free it first). */
int ulam_analysis_start(ulam_analysis *a, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                        const ulam_method_opts *mo, ulam_choice *ch, ulam_run **out, ulam_error *err);

/* ---------------------------------------------------------------- random numbers */
/* All tertiary. */

/* xoshiro256** 1.0 (Blackman & Vigna, "Scrambled linear pseudorandom number generators",
 * ACM TOMS 2021; https://prng.di.unimi.it), seeded through splitmix64.  Caller-owned. */
typedef struct ulam_rng {
    uint64_t s[4];
} ulam_rng;

/* Seed from a 64-bit seed and a stream number (e.g. a walk or block index). */
void ulam_rng_seed(ulam_rng *r, uint64_t seed, uint64_t stream);

/* Uniform double in [0, 1) with 53 random bits. */
double ulam_rng_uniform(ulam_rng *r);

/* Unbiased uniform integer in [0, bound) (Lemire's multiply-and-reject); bound 0: the next 64
 * random bits (the whole range, [0, 2^64)). */
uint64_t ulam_rng_bounded(ulam_rng *r, uint64_t bound);

/* What a derived seed is for: the one place sub-runs get their seeds (ulam_rng_substream). */
typedef enum ulam_stream_purpose {
    ULAM_STREAM_QUERY = 1,     /* query k of a batch (--queries, partition queries) */
    ULAM_STREAM_PILOT = 2,     /* pilot k of auto's choice or bidir's plan */
    ULAM_STREAM_PROBE = 3,     /* probe k of bidir's push/walk split */
    ULAM_STREAM_ITERATION = 4, /* outer iteration k of MCSA / sequential Monte Carlo */
    ULAM_STREAM_POINT = 5,     /* radiosity point, work-plane node, mesh sample or view patch k */
    ULAM_STREAM_STUDY = 6      /* run k of a variance study */
} ulam_stream_purpose;

/* The seed of sub-run k for purpose p under seed: splitmix64's finalizer chained over (seed, p,
 * k), its top bit cleared (below 2^63, so the CLI's --seed and Python take it), so distinct (p, k)
 * give unrelated seeds and the same triple gives the same seed from C, the CLI and Python.  Every
 * derived seed in ulam comes from here (docs/streams.md). */
uint64_t ulam_rng_substream(uint64_t seed, ulam_stream_purpose p, uint64_t k);

/* ---------------------------------------------------------------- utilities */
/* All tertiary. */

/* Monotonic wall clock in seconds. */
double ulam_now(void);

#ifdef __cplusplus
}
#endif

#endif /* ULAM_H */
