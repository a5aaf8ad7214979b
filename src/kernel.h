/* The walk kernel (internal): an arena of rows, each a header and its alias slots, built the
 * first time a walk reaches the row. */
#ifndef ULAM_KERNEL_H
#define ULAM_KERNEL_H

#include "internal.h"
#include "cache.h"

#include <stdatomic.h>

/* Outcome code for "the walk terminates here". */
#define ULAM__TERMINATE INT32_MIN

/* Outcome targets from here up name the state t - ULAM__UNRESOLVED, whose row's place is not
 * yet known; below it they name the row's unit. */
#define ULAM__UNRESOLVED (INT32_C(1) << 30)

/* One alias slot: with the 64-bit fraction u of the draw that picked it, take a when
 * u < thresh, else b.  An outcome r >= 0 moves to target r keeping the weight's sign; ~r (< 0)
 * moves there flipping it; ULAM__TERMINATE ends the walk.  A walk that follows an unresolved
 * target rewrites it to the row's unit (the only write to a built row). */
typedef struct {
    uint64_t thresh;
    _Atomic int32_t a, b;
} ulam__slot;

/* A row's header, two units long, followed by its len alias slots: everything a step from
 * this state reads sits in one contiguous run of memory. */
typedef struct {
    double factor; /* S_i / q_i: the weight's factor on every move (kernel exponent 1; else 0,
                      each move's own factor sitting in the kernel's fac) */
    double visit;  /* scored (times the weight) on every visit */
    double end;    /* scored (times the weight) when the walk terminates here */
    int32_t len;   /* alias slots (nonzeros + 1 for termination) */
    int32_t state; /* i */
} ulam__row;

#define ULAM__HEAD 2 /* units in a header */

/* A kernel of more states keeps its places (where) in leaves of ULAM__LEAF states made when a
 * walk first reaches one of their states, so a query that builds rows scattered over a large
 * system keeps 8 bytes a group of ULAM__LEAF states and a leaf a group reached, not 4 bytes a
 * state (40 MB at 10^7, nearly all of it touched by 10^5 scattered rows). */
#define ULAM__DENSE_MAX (INT64_C(1) << 16)
#define ULAM__LEAF 16

/* What visits and terminations score, with g_i = b[i] (1 when b is NULL): collision g_i per
 * visit, absorption g_i / p*_i per termination, expected (K b)_i per visit (0 without b). */
typedef struct {
    const double *b;
    int estimator;
} ulam__scores;

/* What rescoring a built row needs without reading it again (a kernel that reads its rows from a
 * file keeps one a row it builds lazily, in the order the rows were claimed): the row's unit,
 * g_i, p*_i = 1 - q_i and (K b)_i, the expected estimator's score (NAN until computed). */
typedef struct {
    int64_t u;
    double g, pstar, mb;
} ulam__rowrec;

/* The kernel of a borrowed matrix K.  Rows are built when first reached and placed one after
 * another in an arena of 16-byte units, so the memory a run touches is the rows it visits,
 * densely packed; where[i] is 0 until row i is built, -1 while a thread builds it, then its
 * unit + 1.  Units and states are below 2^30 (a 16 GB kernel). */
typedef struct ulam_kernel {
    int64_t n, cap;         /* cap: units reserved (all rows); the dead row sits at unit cap */
    _Atomic int64_t top;    /* units handed out */
    _Atomic int64_t built;  /* rows built */
    _Atomic int status;     /* ULAM_OK, or the first row's failure: ULAM_ESYNTAX (corrupt),
                               ULAM_ENONFINITE (a non-finite score) or ULAM_ENOMEM (scratch) */
    _Atomic int64_t bad;    /* the row of that failure (-1: none) */
    ulam__slot *mem;
    _Atomic int32_t *where;   /* the places, one a state (n <= ULAM__DENSE_MAX), else NULL and: */
    _Atomic(_Atomic int32_t *) *dir; /* one leaf of ULAM__LEAF places a group of states, made
                                        the first time a state of the group is placed */
    _Atomic int32_t *leaves;  /* their storage, handed out in order (touched as they are made) */
    _Atomic int64_t nleaves;  /* leaves handed out */
    const ulam_csr *K;
    double continue_q;
    double alpha;       /* the kernel exponent: p_ij = q_i |K_ij|^alpha / sum_k |K_ik|^alpha */
    double (*fac)[2];   /* alpha != 1: the weight factors |K_ij| / (q_i p_ij) of the two outcomes
                           of the slot at each unit (a, b); NULL at alpha = 1 (the row's factor) */
    ulam__scores scores;
    int64_t *scored, nscored; /* kept (ulam__kernel_keep): the states b scores at */
    int fixed;                /* kept with b's values fixed: only the same b rescores, as a no-op */
    ulam__rows_check rc;      /* made before a row of K (and of b) is first read (a prepared file's
                                 verification; fn NULL: none) */
    ulam__rowrec *rec;        /* rows read from a file (rc.fetch): one record a lazily built row,
                                 reserved for every state, touched as rows are built (NULL: none) */
    _Atomic int64_t nrec;     /* records written */
    int rec_stale;            /* the records no longer hold every built row's g (ulam__kernel_complete,
                                 ulam__kernel_rescore_b): rescoring reads the rows again */
} ulam_kernel;

/* Per-thread scratch for building rows of up to cap outcomes (grown as rows need). */
typedef struct {
    double *p, *scaled, *f; /* f: the moves' factors (kernel exponent != 1) */
    int32_t *o;
    int64_t *small, *large;
    int64_t cap;
    ulam__rowbuf rb; /* the row being built, read from a file (k->rc.fetch) */
} ulam__kscratch;

/* Vose's alias table of m outcomes out[] with probabilities p[] (sum 1) into s[0..m-1];
 * scaled, small and large are scratch arrays of m entries. */
void ulam__alias_build(const double *p, const int32_t *out, int64_t m, ulam__slot *s, double *scaled,
                       int64_t *small, int64_t *large);

/* The kernel of K (which must outlive it; continue_q <= 0: analog) with exponent alpha, no row
 * built yet: O(n) time, 4 bytes a state up to ULAM__DENSE_MAX states and 0.5 beyond (alpha != 1:
 * room for two factors a slot, reserved like the slots).  ULAM_OK, ULAM_ENOMEM, or ULAM_EOVERFLOW past 2^30 units. */
int ulam__kernel_alloc(const ulam_csr *K, double continue_q, double alpha, ulam__scores scores, ulam_kernel **out);

/* The moves of row i of K at kernel exponent alpha != 1 with continuation q > 0: pm[k] the
 * probability of the move along the row's k-th entry given that the walk moves,
 * (|K_ij| / m)^alpha / sum (m the row's largest |entry|, a stored zero weighing nothing), and
 * f[k] its weight factor |K_ij| / (q pm[k]) (the sign is the entry's).  ULAM_OK, or ULAM_ERANGE
 * when a probability is below 2^-40 / len (the alias table's 64-bit thresholds would bias it;
 * such an f may be infinite). */
int ulam__kernel_moves(const ulam_csr *K, int64_t i, double q, double alpha, double *pm, double *f);

/* Keep k for later right-hand sides: record the states its b scores at (b still as the rows were
 * built with it).  Collision or absorption only (a row's scores are its own b_i's; expected
 * reads its neighbours').  ULAM_OK, ULAM_EINVAL (expected, no b, or a failed kernel),
 * ULAM_ENOMEM. */
int ulam__kernel_keep(ulam_kernel *k);

/* Give a kept kernel's rows the scores of b (n entries, borrowed like the first; with k->fixed
 * only the b it was kept with, whose values its owner keeps unchanged: nothing to do): the rows that
 * scored and those b scores at are rescored, as a row built now would be, the rest score 0 as
 * before, and rows built later read b; the alias tables are unchanged (they do not depend on b).
 * ULAM_OK, ULAM_EINVAL (not kept), ULAM_ENONFINITE (a non-finite score, recorded). */
int ulam__kernel_rescore_b(ulam_kernel *k, const double *b);

/* Give k the check *rc made before its rows are read (after ulam__kernel_alloc, before any row is
 * built); when rc reads rows from a file, k keeps what rescoring needs (ulam__rowrec) so that a
 * change of estimator reads no row again but the expected estimator's new ones.  ULAM_OK or
 * ULAM_ENOMEM. */
int ulam__kernel_set_check(ulam_kernel *k, const ulam__rows_check *rc);

/* Free a kernel; accepts NULL. */
ulam_kernel *ulam__kernel_free(ulam_kernel *k);

/* Scratch for building k's rows; ULAM_OK or ULAM_ENOMEM (free it with ulam__kscratch_free). */
int ulam__kscratch_alloc(const ulam_kernel *k, ulam__kscratch *w);

/* Free scratch (its arrays may be NULL). */
void ulam__kscratch_free(ulam__kscratch *w);

/* The unit of state j's row, building it first if no walk has; safe when threads race. */
int32_t ulam__kernel_unit(ulam_kernel *k, int64_t j, ulam__kscratch *w);

/* Resolve the unresolved outcome o that fraction frac took from slot s: the target row's unit,
 * written back into the slot. */
int32_t ulam__kernel_resolve(ulam_kernel *k, ulam__slot *s, uint64_t frac, int32_t o, ulam__kscratch *w);

/* Build every row no walk has built yet, with `threads` threads (w[t]: thread t's scratch),
 * while no walk runs: for a run that visits most states, streaming K once beats building row
 * by row at first visits (random reads). */
void ulam__kernel_complete(ulam_kernel *k, int threads, ulam__kscratch *w);

/* Rewrite the scores (visit, end) of every built row for estimator `estimator` (the moves and
 * factors do not depend on it), while no walk runs; ULAM_OK, the kernel's failure, or
 * ULAM_ENONFINITE when a new score is not finite (the kernel is then failed). */
int ulam__kernel_rescore(ulam_kernel *k, int estimator);

/* The continuation probability q_i of row i of K. */
double ulam__kernel_q(const ulam_csr *K, int64_t i, double continue_q);

/* Mark in seen[] every state of K reachable from those already marked by the walk's moves
 * (the nonzeros of rows with q_i > 0); ULAM_OK, ULAM_ENOMEM, or ULAM_ESYNTAX when a row it
 * reaches is corrupt (rows are checked as the kernel checks them, after rc, which may be NULL),
 * *bad (may be NULL) that row. */
int ulam__kernel_reach(const ulam_csr *K, double continue_q, char *seen, const ulam__rows_check *rc, int64_t *bad);

/* The header of the row at unit u. */
static inline ulam__row *ulam__kernel_row(const ulam_kernel *k, int64_t u)
{
    return (ulam__row *)(void *)(k->mem + u);
}

/* Draw a slot of row h; *frac is to be compared with its threshold. */
static inline ulam__slot *ulam__kernel_pick(ulam__row *h, ulam_rng *r, uint64_t *frac)
{
    return (ulam__slot *)(void *)h + ULAM__HEAD + ulam__rng_index(r, (uint64_t)h->len, frac);
}

/* The target (row unit, unresolved state code or source state) of an outcome other than
 * ULAM__TERMINATE; o < 0 also flips the weight's sign. */
static inline int32_t ulam__outcome_target(int32_t o)
{
    return o < 0 ? ~o : o;
}

/* The outcome of slot s for fraction frac.  Both are read and one is selected without a
 * branch (the coin is unpredictable: a branch here costs a third of the in-cache speed). */
static inline int32_t ulam__slot_outcome(ulam__slot *s, uint64_t frac)
{
    int32_t a = atomic_load_explicit(&s->a, memory_order_acquire);
    int32_t b = atomic_load_explicit(&s->b, memory_order_acquire);
    return frac < s->thresh ? a : b;
}

/* The weight factor (without sign) of the move that fraction frac takes from slot s of row h:
 * the row's at kernel exponent 1 (fac NULL), else the move's own (mem: the arena). */
static inline double ulam__move_weight(double (*fac)[2], const ulam__slot *mem, const ulam__row *h,
                                       const ulam__slot *s, uint64_t frac)
{
    return fac ? fac[s - mem][!(frac < s->thresh)] : h->factor;
}

/* The row unit a move with outcome o (taken by frac from slot s) reaches. */
static inline int32_t ulam__kernel_target(ulam_kernel *k, ulam__slot *s, uint64_t frac, int32_t o, ulam__kscratch *w)
{
    int32_t t = ulam__outcome_target(o);
    return t < ULAM__UNRESOLVED ? t : ulam__kernel_resolve(k, s, frac, o, w);
}

#endif
