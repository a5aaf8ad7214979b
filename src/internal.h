/* Internal helpers shared by the library's source files (not installed). */
#ifndef ULAM_INTERNAL_H
#define ULAM_INTERNAL_H

#include "ulam.h"

#include <stdarg.h>
#include <stdlib.h>

/* xoshiro256** step, inline for the walkers (ulam_rng_next is this). */
static inline uint64_t ulam__rng_next(ulam_rng *r)
{
    uint64_t *s = r->s;
    const uint64_t x = s[1] * 5, result = ((x << 7) | (x >> 57)) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = (s[3] << 45) | (s[3] >> 19);
    return result;
}

/* An index in [0, len) by Lemire's unbiased multiply-and-reject draw ("Fast random integer
 * generation in an interval", ACM TOMACS 29(1), 2019); *frac gets the low half of the same
 * product, uniform on a lattice of spacing len / 2^64 (the walkers use it as a coin). */
static inline uint64_t ulam__rng_index(ulam_rng *r, uint64_t len, uint64_t *frac)
{
    __uint128_t m = (__uint128_t)ulam__rng_next(r) * len;
    if ((uint64_t)m < len) {
        uint64_t floor = (0 - len) % len;
        while ((uint64_t)m < floor) m = (__uint128_t)ulam__rng_next(r) * len;
    }
    *frac = (uint64_t)m;
    return (uint64_t)(m >> 64);
}

/* The continuation probability of a state whose row of |K| sums to S: fixed continue_q when
 * given (> 0), else analog min(1, S); 0 for an empty row. */
static inline double ulam__continuation(double S, double continue_q)
{
    return S == 0.0 ? 0.0 : continue_q > 0 ? continue_q : (S < 1.0 ? S : 1.0);
}

/* The weight factor S / q of a state whose row of |K| sums to S (0 for an empty row). */
static inline double ulam__factor(double S, double continue_q)
{
    double q = ulam__continuation(S, continue_q);
    return q > 0 ? S / q : 0.0;
}

/* Uniform double in [0, 1) from the top 53 bits. */
static inline double ulam__rng_uniform(ulam_rng *r)
{
    return (double)(ulam__rng_next(r) >> 11) * 0x1.0p-53;
}

/* Threads a run uses: requested when > 0, else all cores (1 without OpenMP). */
int ulam__threads(int requested);

/* The calling thread's number in the enclosing OpenMP team (0 outside one or without OpenMP). */
int ulam__thread_num(void);

/* Restart a forward solver on right-hand side b (borrowed) with seed: the kernel is kept,
 * tallies, counts and stopping state are reset (src/solve.c; used by the outer iterations). */
int ulam__solver_restart(ulam_solver *s, const double *b, uint64_t seed, ulam_error *err);

/* Walk again with options o that differ from the solver's only in the estimator, the seed, the
 * stopping rules (max_walks, rel_err, max_seconds), interrupt, share, force, assume_finite and
 * rel_err_offset (else ULAM_EINVAL): the kernel rows built (rescored for a new estimator), the
 * reachable set, the score bounds met before, the guards and the workspace are kept; every tally,
 * count and stopping state is reset, so the walks that follow are those of a solver allocated with
 * o, bit for bit (src/solve.c; used by the method choice, src/auto.c).  Refusals as
 * ulam_solver_alloc's. */
int ulam__solver_rerun(ulam_solver *s, const ulam_walk_opts *o, ulam_error *err);

/* The walk solver's internal interface (src/solve.c).  Queries on a solver (ulam__solver_setup,
 * ulam__solver_range_walks) and its restarts (ulam__solver_restart, _rerun) are for any file
 * downstream of it; its construction and caching on what earlier solvers made
 * (ulam__solver_alloc_reached, ulam__solver_keep_kernel, _keep_kernel_fixed, ulam__solver_reached,
 * ulam__reach_all below) are called from the analysis (src/analysis.c, the one home of "reach
 * once, keep the kernel, hand out solvers"), and besides it only from the method choice's
 * pilots (src/auto.c: ulam__solver_alloc_reached with the analysis' bounds). */

/* The deterministic set-up work of a solver so far: kernel units built (*units, 16 bytes each: a
 * row's nonzeros + 3) and matrix entries read by reachability checks and score-bound passes
 * (*reads). */
void ulam__solver_setup(const ulam_solver *s, int64_t *units, int64_t *reads);

/* Nonzero when [lower, upper] decides a radius' verdict and its warning: wholly below 0.99,
 * wholly at or above 1, or wholly in [0.99, 1) (src/spectral.c; the guards use it). */
int ulam__power_certain(double lower, double upper);

/* Power iteration on diag(left) |A| diag(right) (left, right may be NULL) from the bounds
 * already in *out (the guards' one-pass sums), with out->iterations and out->seconds added
 * to; out keeps the tighter bounds of both (src/spectral.c; ulam_spectral_power starts it
 * from [0, INFINITY]). */
int ulam__power_from(const ulam_csr *A, const double *left, const double *right, const ulam_power_opts *o,
                     ulam_power *out, ulam_error *err);

/* A Collatz-Wielandt certificate |K| v <= u v over the rows in seen (closed under K's moves)
 * from the expected lengths h = (I - |K|)^-1 1, solved roughly by CG or GMRES in at most
 * max_iter products: *u (1: none), *kappa = max h / min h; *matvecs added to (src/spectral.c). */
int ulam__length_certificate(const ulam_csr *K, const char *seen, int max_iter, double *u, double *kappa,
                             int64_t *matvecs);

/* rho(M4), M4_ij = |K_ij|^4 / (q_i p_ij)^3, of the walk kernel of K (M adjoint, M' forward) at
 * continuation continue_q and exponent alpha, with certified bounds (stopped once they decide
 * against 1 like the guards' radii): the walk's score has a finite fourth moment when it is
 * below 1.  abs: rho(|M|) when known (NULL: not), which it is when every weight factor is 1
 * (src/guard.c). */
int ulam__guard_fourth(const ulam_csr *K, double continue_q, double alpha, const ulam_power *abs, ulam_power *out,
                       ulam_error *err);

/* Whether a caller's guard g (may be NULL) was computed for continuation q (<= 0: analog),
 * kernel exponent alpha and holds every verdict in need (ULAM_GUARD_* bits), so a solver may
 * take it instead of computing its own (src/guard.c). */
int ulam__guard_fits(const ulam_guard *g, double continue_q, double alpha, int need);

/* The walks the rel_err rule's range term would need at estimate m and target E were every visit
 * to score at most per_visit (times the walk's weight), both signs when signs, under the
 * reachability bounds of a solver made with rel_err > 0 and b = 1 (src/solve.c; INFINITY
 * without a bound). */
double ulam__solver_range_walks(const ulam_solver *s, double per_visit, int signs, double m, double E);

/* The forward push on b (src/bpush.c): push r (q alongside; x = q + (I - M)^-1 r holds before and
 * after) on Mt, M's transpose, until every |r_j| <= rmax or *ops (nonzeros read, plus one a push)
 * passes max_ops.  ULAM_OK or ULAM_ENOMEM. */
int ulam__bpush(const ulam_csr *Mt, double rmax, int64_t max_ops, double *q, double *r, int64_t *ops);

/* max_j |r_j| over n entries. */
double ulam__bpush_max(const double *r, int64_t n);

/* The forward walks' predicted work (units of ULAM_AUTO_*) on a residual of l1 norm r_sum, the
 * push part q_i of the watched x_i taken as its scale (src/fpush_b.c's cost model). */
typedef double (*ulam__fpush_b_cost)(double r_sum, double q_i, void *ctx);

/* What the push on b for forward walks did: sweeps, operations (a state read a sweep, a push its
 * column's entries + 1), ||r||_1 before and after, the walks' predicted work before and after. */
typedef struct {
    int sweeps;
    int64_t ops;
    double r_sum0, r_sum, work0, work;
} ulam__fpush_b_info;
#define ULAM__FPUSH_B_SWEEPS 1000 /* the most sweeps (the cost model stops them long before) */

/* The push on b for forward walks (src/fpush_b.c): Gauss-Seidel sweeps of the forward push on Mt,
 * M's transpose, r (b on entry) into q (zero on entry), x = q + (I - M)^-1 r holding throughout,
 * while the walks' work cost(||r||_1, q[index]) falls by more than a sweep costs; the first sweep
 * when its reads cost at most `first` units.  ULAM_OK. */
int ulam__fpush_b(const ulam_csr *Mt, int64_t index, ulam__fpush_b_cost cost, void *ctx, double first, double *q,
                  double *r, ulam__fpush_b_info *info);

/* The bound on the probability that a walk scores at all (src/hit.c): Gauss-Seidel sweeps of
 * v <- a + c P v over the `count` states listed in ascending order (the walks' reachable set:
 * closed under their moves), K the walks' kernel (continuation continue_q, exponent alpha),
 * target the states where a walk scores (absorb: by ending there; else by a visit), v 1 there on
 * entry and an upper bound on each listed state's probability after every sweep; at most
 * `sweeps` sweeps (*sweep counts them, alternating ascending and descending order) or until
 * converged (*done); the entries read (and one a state). */
int64_t ulam__hit_sweeps(const ulam_csr *K, const int64_t *states, int64_t count, double continue_q, double alpha,
                         const char *target, int absorb, double *v, int sweeps, int *sweep, int *done);

struct ulam_kernel; /* src/kernel.h */

/* A set of states adjoint walks on K can reach (seen: n flags, closed under the walk's moves,
 * rows checked) and, when bounds is set, what check_reach computes over it from K alone
 * (src/solve.c): the largest weight factor S / q (fbig), continuation (qmax), whether K has a
 * negative entry (neg), the weight growth along paths, and (tail) the length tail's
 * certificate.  ulam__reach_all makes it over every state: a superset of any start's reach, so
 * its bounds hold for every start and b (looser where a start reaches less), computed once. */
typedef struct ulam__reach {
    const char *seen;
    int bounds;
    const ulam_csr *K;
    double continue_q, alpha;
    double fbig, qmax, growth;
    int neg, tail;
    double tail_u, kappa;
    /* the scores of one b over every state (ulam__reach_b; b NULL: none): the largest |b_i|
       (bmax), |(K b)_i| (kbmax), absorption's |b_i| / p*_i and b_i^2 / p*_i where b_i != 0
       (gabs, g2abs; INFINITY where p*_i = 0), its first such state with p*_i = 0 (bad, -1:
       none), and b's signs (bpos, bneg) */
    const double *b;
    double bmax, kbmax, gabs, g2abs;
    int64_t bad;
    int bpos, bneg;
} ulam__reach;

/* The reach of every state of K at continuation continue_q and exponent alpha with its bounds;
 * seen: n bytes of room, set to all ones (borrowed by R).  ULAM_OK, ULAM_ENOMEM, ULAM_ESYNTAX
 * (a corrupt row), ULAM_ERANGE (alpha's probabilities underflow). */
int ulam__reach_all(const ulam_csr *K, double continue_q, double alpha, char *seen, ulam__reach *R);

/* Add to R (made by ulam__reach_all for K, or read from a prepared file) the scores of b (n
 * entries, borrowed by R) over every state, so that a solver given R and this b reads neither K
 * nor b before walking: one pass over K and b.  ULAM_OK, or ULAM_EINVAL when R is not K's. */
int ulam__reach_b(const ulam_csr *K, const double *b, ulam__reach *R);

/* As ulam_solver_alloc (adjoint) with reach (borrowed until the solver is freed; NULL: search)
 * and kernel (NULL, or one of ulam__solver_keep_kernel, borrowed likewise)
 * the states walks can reach, from an earlier solver on the same M, start states and
 * continuation (ulam__solver_reached) or from ulam__reach_all: its rows were checked then, the
 * search is not made again, and with reach->bounds (for this M, continuation and exponent)
 * neither are the bounds of M alone. */
int ulam__solver_alloc_reached(const ulam_csr *M, const double *b, const ulam_walk_opts *opts,
                               const ulam__reach *reach, struct ulam_kernel *kernel, ulam_solver **out,
                               ulam_error *err);

/* The kernel of an adjoint collision or absorption solver, kept for later solvers on the same M,
 * continuation, exponent and estimator with any b (ulam__solver_alloc_reached's kernel, rescored
 * to its b: rows already built are not built again, and walks take exactly the moves a new
 * kernel's would); the caller owns it from here (ulam__kernel_free, after this solver is freed).
 * NULL when it cannot be kept (forward, expected, a failed kernel, no memory, a borrowed one). */
struct ulam_kernel *ulam__solver_keep_kernel(ulam_solver *s);

/* As ulam__solver_keep_kernel for a b whose values the caller keeps as they are, passed again to
 * every later solver on the kernel: rescoring is then nothing at all, nothing is recorded (O(1)),
 * and the expected estimator's kernel keeps too. */
struct ulam_kernel *ulam__solver_keep_kernel_fixed(ulam_solver *s);

/* The states a solver's walks can reach (n flags; NULL unless its reachability check ran). */
const char *ulam__solver_reached(const ulam_solver *s);

/* The walk solver builds the rest of its kernel at once when walks have built 1 / ULAM__COMPLETE
 * of it row by row (src/solve.c: the rent-or-buy rule); the choice's work models predict it. */
enum { ULAM__COMPLETE = 4 };

/* The bounds a prepared system stores for its matrix (ulam__reach_all's, with b's scores when
 * the file holds b) when made for continuation continue_q and exponent alpha: 1 and R filled
 * (R->K its matrix, R->seen NULL: the caller gives n flags of ones), else 0 (src/cache.c). */
int ulam__system_bounds(const ulam_system *s, double continue_q, double alpha, ulam__reach *R);

/* As ulam_auto_solver, with reach (NULL: none; borrowed until the solver is freed) the bounds
 * over every state of M (ulam__reach_all's, with b's scores when they are this b's) that the
 * candidates of its kernel (adjoint, its continuation and exponent) walk under instead of each
 * searching its start's reach (src/auto.c; ulam_analysis_auto). */
int ulam__auto_solver_reach(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                            const ulam__reach *reach, ulam_auto_result *res, ulam_solver **out, ulam_error *err);

/* Iterate s until a stopping rule holds, fill result (may be NULL) and, on failure, err; free s.
 * The status (src/solve.c: the rest of ulam_solve_walks). */
int ulam__solver_finish(ulam_solver *s, ulam_walk_result *result, ulam_error *err);

/* The walks' pins o (the caller's, or ulam_auto_defaults()) given a's guards when they pin a's own
 * kernel (adjoint, a's continuation and exponent, no guard of their own): ULAM_OK, or the guards'
 * status (src/analysis.c; ulam_analysis_auto, ulam_analysis_auto_start). */
int ulam__analysis_pin_guard(ulam_analysis *a, const ulam_walk_opts *base, ulam_auto_opts *o, ulam_error *err);

/* The analysis' transpose (ulam_analysis_transpose), with *seconds (may be NULL) the time this
 * call spent making it: 0 when the analysis had it (src/analysis.c). */
const ulam_csr *ulam__analysis_transpose(ulam_analysis *a, double *seconds, ulam_error *err);

/* The matrix and the kernel (continuation, 0 analog, and exponent) an analysis is made for. */
const ulam_csr *ulam__analysis_matrix(const ulam_analysis *a);
void ulam__analysis_kernel(const ulam_analysis *a, double *continue_q, double *alpha);

/* What a caller (the bidirectional planner: its memo, src/bidir.h) keeps with an analysis: NULL
 * until ulam__analysis_keep; m is dropped with drop when the analysis is freed (or another is
 * kept), before the rest of the analysis. */
void *ulam__analysis_kept(const ulam_analysis *a);
void ulam__analysis_keep(ulam_analysis *a, void *m, void (*drop)(void *));

/* What an analysis lends an internal caller's walks and keeps from them (ulam__analysis_walks). */
enum {
    ULAM__WALKS_ALL = 1,   /* walk under the bounds over every state (ulam__analysis_bounds_all) */
    ULAM__WALKS_FOUND = 2, /* else under the states the last ULAM__WALKS_FIND walks found they reach (the
                              caller's to pass only for walks from the same starts; none kept: search) */
    ULAM__WALKS_FIND = 4,  /* keep the states these walks find they reach, in place of the last ones */
    ULAM__WALKS_KEEP = 8,  /* walk on the kept kernel made for these walks (matrix, continuation, exponent,
                              estimator) and keep theirs when none was: rescored to each walks' b (not
                              the expected estimator's); without it the kept kernel is dropped */
    ULAM__WALKS_FIXED = 16 /* the kept kernel is the one for this b alone, whose values its owner keeps as
                              they are (one an estimator, ulam_analysis_solver's for the shared b) */
};

/* An analysis' bounds over every state with its shared b's scores (R->b: the analysis' b, NULL
 * when they could not be made), as its queries walk under them: a prepared file's, else one pass
 * over M (made once, kept); NULL when they cannot be made (no memory, a corrupt row, a damaged
 * file).  Borrowed from the analysis (src/cache.c stores them in a prepared file). */
const ulam__reach *ulam__analysis_bounds(ulam_analysis *a);

/* The bounds over every state of an analysis' matrix (a prepared file's, else one pass,
 * ulam__reach_all; made once and kept): ULAM_OK, or the status and err (no memory, a corrupt
 * row, alpha's probabilities underflowing, a damaged file). */
int ulam__analysis_bounds_all(ulam_analysis *a, ulam_error *err);

/* Adjoint walks on a's matrix for b (borrowed until the solver is freed) under o (its kernel's
 * continuation and exponent a's, else ULAM_EINVAL; nothing else changed) run until a stopping
 * rule holds, with what how (ULAM__WALKS_*) says a lends them and keeps from them; the result and
 * guards (either may be NULL) filled, err on failure; the finished solver in *out (the caller
 * frees it; after a failure it may only free it), or freed here when out is NULL.  The walks
 * are those of ulam_solver_alloc with o, bit for bit, whatever a lends (src/analysis.c: the
 * bidirectional planner walks on M^T through an analysis of M^T). */
int ulam__analysis_walks(ulam_analysis *a, const double *b, const ulam_walk_opts *o, int how, ulam_walk_result *result,
                         ulam_guard *guard, ulam_solver **out, ulam_error *err);

/* ulam_bidir_plan and ulam_bidir_solve on an analysis' transpose, push workspace and planner's
 * memo (made at the first call and kept), for any kernel: the memo reuses a plan only for the
 * same options, continuation and exponent among them (src/bidir.c). */
int ulam__bidir_plan_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_plan_info *plan, ulam_error *err);
int ulam__bidir_solve_on(ulam_analysis *a, const ulam_bidir_opts *o, ulam_bidir_result *res, ulam_error *err);

/* A row read from a file: its len columns and values (and b_i); and a thread's cache of one block
 * of M (its row pointers, columns and values at blk) and one of b (at bblk), each kept once
 * verified, so the next row or b_j in the same block is read from memory; grown as rows need.
 * All zero: empty. */
typedef struct ulam__rowbuf {
    int32_t *col;
    double *val;
    int64_t len, cap;
    double b;
    unsigned char *blk;
    int64_t blkcap;
    int64_t blk_at, blk_cols, blk_vals; /* the block at blk + 1 (0: none), its columns' and values' offsets */
    double *bblk;
    int64_t bblkcap, bblk_at;           /* the block of b at bblk + 1 (0: none) */
} ulam__rowbuf;

/* Free r's buffers and empty it. */
static inline void ulam__rowbuf_free(ulam__rowbuf *r)
{
    free(r->col), free(r->val), free(r->blk), free(r->bblk);
    *r = (ulam__rowbuf){0};
}

/* A check of rows [first, last) of a borrowed matrix (and, with with_b, of b at those rows) made
 * before anything reads them: ULAM_OK, or ULAM_ESYNTAX with *bad (may be NULL) the first row of the
 * damaged block.  Thread-safe.  fn NULL: nothing to check.  A prepared system's (src/cache.c): a
 * solver given ulam_walk_opts.policy.system calls it on each row before building it, on every row
 * reached by a reachability search, and on all of them before a pass over all of M. */
typedef struct ulam__rows_check {
    int (*fn)(const void *ctx, int64_t first, int64_t last, int with_b, int64_t *bad);
    const void *ctx;
    int with_b;
    /* A prepared file read by pread (src/cache.c; NULL: rows are read in place): row i of
       fetch_of into r, its block verified first (and with b_of's b_i in r->b when with_b);
       b_at: b_of's j-th entry, its block verified first (r: the thread's buffer, or NULL).
       ULAM_OK, or ULAM_ESYNTAX (ULAM_EIO) with *bad (may be NULL) the first row of the damaged
       block.  Thread-safe (r: the thread's). */
    int (*fetch)(const void *ctx, int64_t i, int with_b, ulam__rowbuf *r, int64_t *bad);
    int (*b_at)(const void *ctx, int64_t j, ulam__rowbuf *r, double *v, int64_t *bad);
    const ulam_csr *fetch_of;
    const double *b_of;
} ulam__rows_check;


/* Run rc on rows [first, last) (ULAM_OK when rc or its fn is NULL). */
static inline int ulam__rows_verify(const ulam__rows_check *rc, int64_t first, int64_t last, int64_t *bad)
{
    return rc && rc->fn ? rc->fn(rc->ctx, first, last, rc->with_b, bad) : 0;
}

/* The check of a solver given opts->policy.system: *rc, when M is that system's matrix (b is checked
 * with it when it is the system's b; another b was verified by whoever gave it); else ULAM_EINVAL. */
int ulam__system_rows_check(const ulam_system *s, const ulam_csr *M, const double *b, ulam__rows_check *rc,
                            ulam_error *err);

/* What a prepared system is written from checked (ulam_system_write_file's refusals: ULAM_EINVAL),
 * and its bytes written to f with the bounds R (an analysis' of d->M at the certificate's
 * continuation and exponent 1, with d->b's scores; NULL: none stored) once checked (src/cache.c;
 * the writer, src/prepare.c, makes R). */
int ulam__system_desc_check(FILE *f, const ulam_system_desc *d);
int ulam__system_write_checked(FILE *f, const ulam_system_desc *d, const ulam__reach *R);

/* Why the block holding row i of s failed: ULAM_ESYNTAX with err naming the block and the fault. */
int ulam__system_row_error(const ulam_system *s, int64_t i, ulam_error *err);

/* What a valid prepared file's header states (src/cache.c): sizes, which arrays it holds, block
 * size 2^shift rows, the byte offsets of rowptr, colidx, val, b, M^T's three and the checksum
 * table (0 for an absent array), each part's blocks and first checksum, the table's own hash. */
typedef struct {
    int64_t n, ncols, nnz, nblocks[3], first[3];
    int shift, has_matrix, has_rhs, has_tr;
    uint64_t off[8], sums_hash, tag[2];
    double omega;
} ulam__layout;

/* Check the header at p (its first 1024 bytes; the file is len bytes) and give its layout. */
int ulam__system_header(const unsigned char *p, uint64_t len, ulam__layout *L, ulam_error *err);

/* 1 when a block (row pointers rp[0 .. rows], entries col, val) has checksum want and holds the
 * CSR invariants (columns below ncols, rising; values finite and nonzero). */
int ulam__system_block_ok(const int64_t *rp, int64_t rows, const int32_t *col, const double *val, int64_t ncols,
                          uint64_t want);

/* XXH3-64 of n bytes (the prepared format's checksum of a b block and of the checksum table). */
uint64_t ulam__system_hash(const void *p, size_t n);

/* Record a failure in err (which may be NULL) and return status. */
int ulam__fail(ulam_error *err, int status, long line, int64_t index, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Reset err (which may be NULL) to "no error". */
void ulam__clear(ulam_error *err);

/* malloc of n items of size sz, NULL on overflow or failure (n == 0 allocates one byte). */
void *ulam__malloc(size_t n, size_t sz);

/* calloc of n items of size sz, NULL on failure (n == 0 allocates one byte). */
void *ulam__calloc(size_t n, size_t sz);


/* Make room for need items of size sz in a growable array: pp is the address of its pointer
 * (a T **), *cap its capacity (doubling from 16; both are updated); ULAM_OK, or ULAM_ENOMEM
 * leaving the array as it was. */
int ulam__grow(void *pp, int64_t *cap, int64_t need, size_t sz);


/* Sort every row of A by column (with `threads` threads), sum duplicates and drop zeros,
 * compacting A in place. */
int ulam__csr_canonicalize(ulam_csr *A, int threads);

/* ||b - (I - M) x||_inf / ||b||_inf from the sparse M (src/direct.c). */
double ulam__direct_residual(const ulam_csr *M, const double *b, const double *x);


/* The arguments of a direct solve checked: M, b, x given, M square and a sound CSR (src/direct.c). */
int ulam__direct_args(const ulam_csr *M, const double *b, const double *x, ulam_error *err);
/* Argument checks (src/check.c): ULAM_OK, or ULAM_EINVAL with err naming the field and what was
 * expected.  Every finite-valued option must be finite and in its range; walk options also have
 * their counts checked (max_walks, max_steps, threads). */
int ulam__walk_opts_check(const ulam_walk_opts *o, ulam_error *err);
int ulam__power_opts_check(const ulam_power_opts *o, ulam_error *err);
int ulam__guard_opts_check(const ulam_guard_opts *o, ulam_error *err);
int ulam__spectral_opts_check(const ulam_spectral_opts *o, ulam_error *err);

/* A real argument: finite and lo <= v <= hi, else ULAM_EINVAL naming it and its range in words. */
int ulam__real_check(double v, double lo, double hi, const char *name, const char *range, ulam_error *err);

/* A vector x of len entries where a call reads n: ULAM_EINVAL (NULL) or ULAM_EDIM. */
int ulam__length_check(const double *x, int64_t len, int64_t n, const char *name, ulam_error *err);

/* The structure of A, so that reading every row stays in bounds: sizes, rowptr[0] = 0, row
 * pointers rising to nnz, column indices in [0, ncols) (values are not read).  ULAM_OK,
 * ULAM_EINVAL (sizes, missing arrays), ULAM_ESYNTAX (row pointers) or ULAM_EINDEX (a column),
 * err->index naming the row.  One O(n + nnz) pass: every function that reads all of a matrix it
 * is given calls it first; a lazy reader (the walk kernel, a prepared file's blocks) checks the
 * rows it touches with ulam__csr_check_rows instead. */
int ulam__csr_check_structure(const ulam_csr *A, ulam_error *err);

/* As ulam__csr_check_structure for rows [lo, hi) of A only (A's sizes and rowptr[nrows] trusted). */
int ulam__csr_check_rows(const ulam_csr *A, int64_t lo, int64_t hi, ulam_error *err);

/* Scaling of b (src/util.c): a solver works on b 2^-e when b's largest |entry| is far from 1, so
 * that scores, sums and squares neither overflow nor underflow, and multiplies what it finds by
 * 2^e (both exact: powers of 2).  ulam__b_exponent gives e (0: no scaling; b's largest |entry|
 * outside [2^-256, 2^256] is brought into [0.5, 1)); ulam__b_scaled a malloc'd copy of b 2^-e. */
int ulam__b_exponent(const double *b, int64_t n);
double *ulam__b_scaled(const double *b, int64_t n, int e);

/* As ulam_mm_read_matrix_opts with reals by the C library's strtod (the same doubles, slower: the
 * reader as it was), for the reader's benchmark and tests to compare (src/mmio.c). */
int ulam__mm_read_matrix_libc(FILE *f, const char *name, const ulam_mm_opts *o, ulam_csr **A, ulam_error *err);

/* What a sweep push did (src/sweep.c): rounds over a list of states or whole sweeps (sweeps of
 * them), pushes, operations (a push costs its row's entries + 1, a sweep n more), the residual's
 * sum of |r| and the states it is on. */
typedef struct {
    int64_t rounds, sweeps, pushes, ops, support;
    double r_sum;
    int64_t pulls; /* sweeps made by pulling (ulam__sweep_push_pull) */
    int nonneg;    /* 1: M was read whole and has no negative entry (r >= 0 then); 0: not known */
    double r_neg;  /* the mass of r's negative entries after pull sweeps (over-relaxed ones overshoot; roundings) */
} ulam__sweep_info;

/* The walks' work (push operations) a residual of mass r_sum would leave. */
typedef double (*ulam__sweep_cost)(double r_sum, void *ctx);

/* Forward push of x = (I - M)^-1 e_s on M given as its transpose Mt, into p and r (n entries
 * each, zero on entry; x = p + (I - M)^-1 r after): rounds over the states holding residual, then
 * whole sweeps in order once n / 16 hold it, pushing every |r_j| > rmax, until none is left or
 * (cost given) one more round would save less walk work than it costs.  ULAM_OK, ULAM_ENOMEM,
 * ULAM_ENOCONV past max_ops (> 0) operations (p and r still valid). */
int ulam__sweep_push(const ulam_csr *Mt, int64_t s, double rmax, ulam__sweep_cost cost, void *ctx, int64_t max_ops,
                     double *p, double *r, ulam__sweep_info *info);

/* One push sweep of Mt's states in order: every |r_j| > thr pushed (p_j += r_j, r_j = 0, and
 * M_kj r_j added to r_k); the operations (n, and each push's row entries + 1), the pushes in
 * *pushed. */
int64_t ulam__sweep_once(const ulam_csr *Mt, double thr, double *p, double *r, int64_t *pushed);

/* ulam__sweep_push given M too (NULL: as ulam__sweep_push): when M >= 0 the whole sweeps pull
 * along M's rows (the same Gauss-Seidel sweeps, read like a matrix-vector product), r formed once
 * at the end; then (info->nonneg) csum and cmax (n entries each, or NULL) hold the sum and the
 * largest entry of each row of Mt. */
int ulam__sweep_push_pull(const ulam_csr *M, const ulam_csr *Mt, int64_t s, double rmax, ulam__sweep_cost cost,
                          void *ctx, int64_t max_ops, double *p, double *r, double *csum, double *cmax,
                          ulam__sweep_info *info);

/* ulam_fpush_solve with the sweep push's counts in sw (may be NULL; zero when ||M||_1 >= 1 and
 * the queue push ran) (src/fpush.c). */
int ulam__fpush_solve(const ulam_csr *M, const ulam_csr *Mt, const ulam_fpush_opts *opts, double *x, double *std_error,
                      double *lo, double *hi, ulam_fpush_info *info, ulam__sweep_info *sw, ulam_error *err);

#endif
