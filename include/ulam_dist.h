/* ulam_dist.h: one system partitioned by rows across ranks, with walks that migrate.
 *
 * Each rank holds a contiguous range of rows (balanced by nonzeros, at the prepared file's block
 * boundaries) read from a prepared file by its blocks alone: no rank reads or maps the rest.  A
 * walk that steps onto a row another rank owns travels there with its state (walk id, step,
 * state, weight, score) in the next exchange.  The library stays MPI-free: the caller gives the
 * exchange as callbacks (src/cli/mpi.c gives MPI_Alltoallv and MPI_Allreduce).
 *
 * Random numbers are counter-based: the k-th number of step t of walk w is a hash of (seed, w,
 * t, k) (src/rng.c's counter-based numbers), so a walk takes the same path whichever rank runs which step, and
 * 1, 2, 3 or 64 ranks give the same answer bit for bit: walks' scores and tallies are combined
 * in walk-id order, never in arrival order.
 *
 * API, in order of use: primary ulam_part_open (ulam_part_open_mtx from Matrix Market by byte
 * ranges), ulam_dist_run (one run as `ulam solve --partition` makes it) and ulam_dist_fprint (its
 * answer in words), ulam_part_free; the pieces ulam_dist_run calls: ulam_dist_radius (the variance
 * guard), ulam_dist_adjoint_ci (ulam_dist_adjoint and _many without an interval), ulam_dist_forward,
 * ulam_dist_mcsa, ulam_dist_source, ulam_dist_bound (a certified range from the residual);
 * secondary ulam_dist_defaults, ulam_part_rows. */
#ifndef ULAM_DIST_H
#define ULAM_DIST_H

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The exchange between ranks.  rank and nranks as MPI gives them; with nranks 1 the callbacks
 * may be NULL.  exchange: every rank sends sendcounts[r] bytes (consecutive in send, in rank
 * order) to rank r and receives, in *recv (malloc'd by the callback, freed by the library),
 * recvcounts[r] bytes from each rank r in rank order; sum: the element-wise sum of v[0 .. n)
 * over all ranks, in place.  Each returns 0, or nonzero on failure (the run then ends with
 * ULAM_EIO on every rank that sees it).  The answer is the same bits whatever nranks and sets. */
typedef struct ulam_comm {
    int rank, nranks;
    int sets; /* 0 or 1: one partition; k > 1 (dividing nranks): k sets of nranks / k consecutive
                 ranks, each set a whole partition of the rows running its own batches of walks
                 (memory per rank times k, and no message leaves a set while walks run) */
    void *ctx;
    int (*exchange)(void *ctx, const void *send, const size_t *sendcounts, void **recv, size_t *recvcounts);
    int (*sum)(void *ctx, int64_t *v, int n);
} ulam_comm;

/* One rank's rows of a prepared system. */
typedef struct ulam_part ulam_part;

/* Which arrays a part holds: M's rows (adjoint walks), M''s (forward walks; the file prepared with
 * --transpose), or both (single source and MCSA: products with M, walks on M'). */
enum { ULAM_PART_M = 0, ULAM_PART_MT = 1, ULAM_PART_BOTH = 2 };

/* Open this rank's rows of the prepared system at path (split among the ranks of its set, by the
 * entries of M' for ULAM_PART_MT, else of M): rows [first, last) of the arrays `what` names and b's
 * entries there, every block read verified against its checksum.  The split is the same on every
 * rank (computed from the file alone).  Needs b in the file. */
int ulam_part_open(const char *path, const ulam_comm *comm, int what, ulam_part **out, ulam_error *err);

/* As ulam_part_open from a coordinate Matrix Market file of M (square; general, symmetric or
 * skew-symmetric; real, integer or pattern) and a vector file of b, read by byte ranges: each rank
 * of a set parses the entry lines in its share of the file's bytes, a failure located at its line
 * of the file (the same error, from the first failing rank, on every rank), and the entries travel
 * to their rows' owners, where duplicates are summed in file order and zeros dropped.  The part
 * is the one ulam_part_open gives on the file `ulam prepare path --rhs rhs --transpose` writes,
 * bit for bit (the same split, blocks and rows); no rank holds more than its rows' entries (each
 * reads b whole, once, and keeps its rows). */
int ulam_part_open_mtx(const char *path, const char *rhs, const ulam_comm *comm, int what, ulam_part **out,
                       ulam_error *err);

/* Free a part (NULL is fine); returns NULL. */
ulam_part *ulam_part_free(ulam_part *p);

/* The system's order; this rank's rows [*first, *last) and their nonzeros (any pointer may be NULL). */
int64_t ulam_part_rows(const ulam_part *p, int64_t *first, int64_t *last, int64_t *nnz);

/* Options of a partitioned run. */
typedef struct ulam_dist_opts {
    uint64_t seed;     /* the streams' key (default 1) */
    int64_t walks;     /* histories (default 100000) */
    int64_t max_steps; /* a walk longer than this is cut and counted (default 1000000) */
    int64_t batch;     /* histories a round starts on all ranks together (default 65536) */
} ulam_dist_opts;

/* The defaults above. */
static inline ulam_dist_opts ulam_dist_defaults(void)
{
    ulam_dist_opts o;
    ulam_defaults(ULAM_KIND_DIST, &o, sizeof o);
    return o;
}

/* What a partitioned run did (the same on every rank). */
typedef struct ulam_dist_result {
    double estimate, std_error; /* adjoint: x_index and its standard error; forward: 0 */
    int64_t walks, steps;       /* histories run and steps taken in all */
    int64_t crossings;          /* steps that moved a walk to another rank's rows */
    int64_t bytes;              /* bytes of walks sent between ranks in all */
    int64_t rounds;             /* exchanges */
    int64_t cut;                /* histories cut at max_steps */
} ulam_dist_result;

/* x_index of (I - M) x = b by adjoint collision walks from index on rows of M: each step leaves
 * row s with probability min(1, S_s) (S_s = sum_j |M_sj|) to j with probability |M_sj| / S_s,
 * the weight times sign(M_sj) S_s / min(1, S_s), the score the sum of weight x b over every state
 * visited.  Every rank gets the same result: the mean of the histories' scores in walk-id order
 * and its standard error (ulam_dist_adjoint_ci adds a certified 95% interval). */

/* x_index[k] for each k < nq at once (the queries' walks share the rounds): res[k] as
 * ulam_dist_adjoint gives for index[k] with seed ulam_rng_substream(o->seed, ULAM_STREAM_QUERY, k),
 * bit for bit (the counts of walks, steps and messages are the whole run's in each). */

/* A certified 95% interval of a partitioned adjoint query (ulam_dist_adjoint_ci). */
typedef struct ulam_dist_ci {
    double lo, hi;     /* NaN when none is certified */
    double limit;      /* the last block's clip of |score| (INFINITY: none) */
    double bias;       /* the most clipping and cuts at max_steps move the mean (in [lo, hi]) */
    int met;           /* rel_err > 0: the half-width reached rel_err |estimate| */
} ulam_dist_ci;

/* As ulam_dist_adjoint_many, with each query's 95% interval in ci[k]: when every row sum of |M|
 * is at most 1 (the walks' weights stay +-1) and power iteration certifies a Collatz-Wielandt
 * vector v with |M| v <= u v, u < 1 (so a walk from i lives k steps with probability at most
 * u^k v_i / min v, and a walk of T steps scores at most max|b| (T + 1)), the scores clipped at a
 * limit whose bias that tail bounds feed a predictable plug-in empirical-Bernstein confidence
 * sequence, block by block of o->batch walk ids in walk-id order (the single-machine solver's,
 * src/stop.h): valid at every block, so under rel_err > 0 too, which ends a query's walks (and
 * the run, once all met) at the first block whose half-width is at most rel_err |estimate|,
 * o->walks then the most a query takes (res[k].walks: the walks it took).  With a row sum above
 * 1 the same iteration on M^ = diag(max(1, S)) |M| bounds the score's second moment instead
 * (E X^2 <= max_j (b_j^2 / v_j) v_i / (1 - sqrt u)^2), and that bounds the clipping's bias
 * (docs/distributed.md).  Else ci[k] has NaN ends.  ci NULL (rel_err 0): the walks alone, no interval.  The same bits at any rank count and
 * any number of sets. */
int ulam_dist_adjoint_ci(const ulam_part *p, const ulam_comm *comm, const int64_t *index, int64_t nq,
                         const ulam_dist_opts *o, double rel_err, ulam_dist_result *res, ulam_dist_ci *ci, ulam_error *err);

/* ulam_dist_adjoint_many and ulam_dist_adjoint (above): ulam_dist_adjoint_ci without intervals
 * (ci NULL, rel_err 0), the same bits. */
static inline int ulam_dist_adjoint_many(const ulam_part *p, const ulam_comm *comm, const int64_t *index, int64_t nq,
                                         const ulam_dist_opts *o, ulam_dist_result *res, ulam_error *err)
{
    return ulam_dist_adjoint_ci(p, comm, index, nq, o, 0.0, res, NULL, err);
}

/* One query: ulam_dist_adjoint_many with nq 1. */
static inline int ulam_dist_adjoint(const ulam_part *p, const ulam_comm *comm, int64_t index, const ulam_dist_opts *o,
                                    ulam_dist_result *res, ulam_error *err)
{
    return ulam_dist_adjoint_many(p, comm, &index, 1, o, res, err);
}

/* Every x_i of (I - M) x = b by forward collision walks on rows of M' (the part opened with
 * transpose): a source j ~ |b_j| / ||b||_1 with weight ||b||_1 sign(b_j), moves as above on M',
 * and each history's tallies at each state it visits.  x and se (this rank's rows [first, last),
 * may be NULL) get each component's mean over the histories and its standard error; a component
 * no walk tallied gets x 0 and se NaN.  With sets, the ranks of set 0 get them (the others' x and
 * se are left as they were). */
int ulam_dist_forward(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, double *x, double *se,
                      ulam_dist_result *r, ulam_error *err);

/* What MCSA on a partition did. */
typedef struct ulam_dist_mcsa_info {
    int iterations;                  /* Richardson step + Monte Carlo correction, each */
    double residual;                 /* max |b - (I - M) x| / max |b| at the end */
    int64_t walks, steps, crossings; /* of every correction */
    int64_t cut;                     /* walks cut at max_steps */
} ulam_dist_mcsa_info;

/* x of (I - M) x = b by MCSA (Evans, Slattery, Wilson): x <- x + r (r = b - (I - M) x, a product
 * with M over the ranks' rows), then x <- x + d, d forward walks (o->walks of them, seed o->seed +
 * iteration) from the new residual; until max |r| <= tol max |b| or max_iter iterations.  x: this
 * rank's rows (in sets, every set's ranks get them).  Needs ULAM_PART_BOTH.  The same bits at any rank
 * count and any number of sets. */
int ulam_dist_mcsa(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, double tol, int max_iter,
                   double *x, ulam_dist_mcsa_info *info, ulam_error *err);

/* What single source on a partition did. */
typedef struct ulam_dist_source_info {
    int rounds;                      /* products of the push */
    double residual;                 /* max |r| left to the walks */
    int64_t walks, steps, crossings; /* of the walks from r */
    int64_t cut;                     /* walks cut at max_steps */
} ulam_dist_source_info;

/* x = (I - M)^-1 e_source: a push x = sum_{k<K} M^k e_s (products with M over the ranks' rows)
 * until max |M^K e_s| <= tol or K = max_rounds, then forward walks (o) from r = M^K e_s add
 * (I - M)^-1 r with its standard errors se (NaN where no walk tallied; 0 everywhere when r = 0).
 * x, se: this rank's rows (in sets, every set's ranks get them).  Needs ULAM_PART_BOTH.  The same bits at
 * any rank count and any number of sets. */
int ulam_dist_source(const ulam_part *p, const ulam_comm *comm, int64_t source, const ulam_dist_opts *o, double tol,
                     int max_rounds, double *x, double *se, ulam_dist_source_info *info, ulam_error *err);

/* A certified range [lo[i], hi[i]] of the exact x*_i of (I - M) x* = b around any x (this rank's
 * rows; b NULL: the system's, else this rank's rows of another), from x's residual: r = b - (I - M) x
 * computed with each row's rounding bounded (rho = its largest |entry| over the ranks), and a
 * Collatz-Wielandt vector v > 0 with |M| v <= u v, u < 1, by at most iters products of power
 * iteration over the ranks' rows, give |x*_i - x_i| <= rho v_i / (min v (1 - u)); with M >= 0 the
 * range takes r's signs (above by its positive part, below by its negative part).  With M' in the
 * part and ||M||_1 = c < 1, also |x*_i - x_i| <= ||r||_1 / (1 - c) (each end the nearer; ||r||_1
 * summed in fixed point, the same bits at any split).  No sampling:
 * the range is certain, for MCSA's x, single source's or forward walks' alike.  NaN ends (and
 * *worst INFINITY) when neither u < 1 nor c < 1 is certified; else *worst is the largest half-width over the
 * ranks.  Needs the part's rows of M.  The same bits at any rank count. */
int ulam_dist_bound(const ulam_part *p, const ulam_comm *comm, const double *b, const double *x, int iters, double *lo,
                    double *hi, double *worst, ulam_error *err);

/* A certified upper bound *upper on rho(M^), M^_ij = M_ij^2 / p_ij of the walks above on the part's
 * rows of M (forward 0: adjoint walks) or M' (forward 1) (M^_ij = |M_ij| S_i / min(1, S_i)): below 1, the walks' scores have finite variance.  Power
 * iteration on the rows each rank holds, the iterate shared through the exchange, each step's
 * Collatz-Wielandt bound max_i (M^ v)_i / v_i rounded up; it stops when that is below 1 or after
 * iters steps (the smallest bound seen).  The same bits on every rank and at any rank count. */
int ulam_dist_radius(const ulam_part *p, const ulam_comm *comm, int forward, int iters, double *upper, ulam_error *err);

/* What one partitioned run asks (ulam_dist_run): the mode and its inputs. */
enum { ULAM_DIST_ADJOINT = 0, ULAM_DIST_FORWARD = 1, ULAM_DIST_MCSA = 2, ULAM_DIST_SOURCE = 3 };
typedef struct ulam_dist_ask {
    int mode;             /* ULAM_DIST_ADJOINT, _FORWARD, _MCSA or _SOURCE */
    const int64_t *index; /* adjoint: the nq queries' 0-based rows (ulam_dist_adjoint_ci); forward:
                             NULL, or one row whose certified interval goes to ci[0] */
    int64_t nq;
    double rel_err;       /* adjoint: the queries' stop (0: o.walks each); forward with index: no
                             stop (o.walks run), ci[0].met says whether the interval after them
                             is within rel_err |estimate| */
    int bound;            /* forward: also x's certified range from its residual (ulam_dist_bound) */
    double tol;           /* MCSA: the residual's target, of max |b| */
    int max_iter;         /* MCSA: its most iterations */
    int64_t source, top;  /* single source: its 0-based row; the top components gathered to rank 0
                             (single source, and forward when ans->tops is given) */
    ulam_dist_opts o;
} ulam_dist_ask;

/* A component of single source's top table: its 0-based row, estimate, standard error, range. */
typedef struct ulam_dist_top {
    int64_t i;
    double x, se, lo, hi;
} ulam_dist_top;

/* What one partitioned run found.  The caller gives the arrays (ulam_dist_run says which modes
 * fill which); the rest the run fills, the same on every rank unless said. */
typedef struct ulam_dist_answer {
    double *x, *se;            /* forward, MCSA, single source: this rank's rows (se not for MCSA); the
                                  ranks of set 0 hold them (a rank of another set: its rows, or 0 rows) */
    ulam_dist_result *res;     /* adjoint: nq of them */
    ulam_dist_ci *ci;          /* adjoint: nq of them; forward with an index: one */
    ulam_dist_top *tops;       /* single source, forward (NULL: no table): top of them; rank 0 gets the
                                  ntop largest of all (forward: lo, hi infinite without ask->bound
                                  unless terminal) */
    int64_t *ranks;            /* 2 nranks: every rank's rows, then its peak resident memory (KiB) */
    int64_t n, ntop;           /* the system's order; the top table's rows (rank 0) */
    ulam_dist_result r;        /* the whole run's walks, steps, crossings, bytes, rounds and cuts
                                  (adjoint, forward with an index: also that row's estimate) */
    double rho;                /* the variance guard: certified bound on rho(M^), INFINITY when none */
    double worst;              /* MCSA, single source, forward with bound: the largest certified half-width */
    int iterations;            /* MCSA: iterations; single source: the push's products with M */
    double residual;           /* MCSA: max |r| / max |b| at the end; single source: max |r| left to the walks */
    int terminal;              /* single source, forward's top table: 1 when the walks also counted where
                                  they end (M >= 0, b >= 0, column sums of M below 1, no walk cut): each top
                                  entry's interval is then its end count's 95% interval (overlapped with the
                                  certified range where one is made); 0: the certified range alone */
} ulam_dist_answer;

/* Run ask on the part (every rank of comm together): the variance guard (ulam_dist_radius), then
 * the mode's walks (ulam_dist_adjoint_ci, _forward, _mcsa or _source; MCSA, single source and
 * forward with ask->bound also ulam_dist_bound around x, single source's b being e_source), and
 * each rank's rows and peak memory.  ans's arrays: adjoint res and ci (nq each); forward, MCSA and
 * single source x (this rank's rows), forward and single source se, single source tops (ask->top;
 * forward: optional, the table of the ask->top largest);
 * ranks (2 nranks) always.  An MCSA run that stops at max_iter above tol is not an error here
 * (ans->residual says so).  The same answer at any rank count and any number of sets. */
int ulam_dist_run(const ulam_part *p, const ulam_comm *comm, const ulam_dist_ask *ask, ulam_dist_answer *ans,
                  ulam_error *err);

/* Write ulam_dist_run's answer to f as `ulam solve --partition` prints it (rank 0): the answer
 * lines (each query's with its file line lines[k] and seed; single source's or forward's top table; MCSA's and
 * the push's lines; the bound), then the summary (rel-err, method, variance, walks, migration,
 * seconds; verbosity 1: each rank's rows and peak memory; -1: the answers alone).  queries: the
 * query file's name (NULL: one --index), out: where x was written (NULL: nowhere).  The run's
 * nranks and sets label the method.  Nonzero when a write fails. */
int ulam_dist_fprint(FILE *f, const ulam_dist_ask *ask, const ulam_dist_answer *ans, const ulam_comm *comm,
                     const char *queries, const long *lines, const char *out, double seconds, int verbosity);

#ifdef __cplusplus
}
#endif
#endif
