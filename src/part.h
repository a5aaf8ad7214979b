/* Private to the partitioned walks (part.c, dist.c): a rank's rows of a prepared system. */
#ifndef ULAM_PART_H
#define ULAM_PART_H

#include "internal.h"
#include "ulam_dist.h"

/* Rows [first, last) of one array (M or M'): 0-based row pointers into col and val, each row's
 * sum of |entries|; rowptr NULL when the part does not hold that array. */
typedef struct {
    int64_t nnz;
    int64_t *rowptr;
    int32_t *col;
    double *val, *rowsum;
} ulam__rows;

/* This rank's rows [first, last) of M and/or M', b at those rows, and the split every rank
 * shares. */
struct ulam_part {
    int64_t n, first, last;
    ulam__rows m, t;
    double *b; /* NULL when the file holds no b (single source needs none) */
    int64_t *split; /* nranks + 1 row boundaries: position r of a set owns rows [split[r], split[r + 1]) */
    int nranks, rank, shift; /* ranks in this rank's set and its position there */
    int set, sets;           /* this rank's set (world rank set * nranks + rank) of sets */
};

/* Check ulam_part_open's comm, what and out (*out set to NULL); a status (src/part.c). */
int ulam__part_args(const ulam_comm *comm, int what, ulam_part **out, ulam_error *err);

/* Each of p's rows' sum of |entries| of A into A->rowsum (src/part.c). */
int ulam__part_sums(const ulam_part *p, ulam__rows *A, ulam_error *err);

/* The position in a set owning row s. */
int ulam__part_owner(const ulam_part *p, int64_t s);

/* The largest of every rank's nonnegative *x, into *x on every rank; nonzero on a failed sum. */
int ulam__dist_largest(const ulam_comm *c, double *x);

/* The same for x[0 .. n) entry by entry, in one sum (src/part.c). */
int ulam__dist_largest_n(const ulam_comm *c, double *x, int n);

/* The halo of this rank's rows of A: the columns they reference that other ranks of its set own
 * (ghost, sorted), and what this rank sends each product: the offsets (into its rows) others
 * asked for, at[r] .. at[r + 1) of idx for world rank r.  A product then needs the vector at the
 * halo only, not the whole O(n) vector (src/dist_halo.c). */
typedef struct {
    int64_t nghost, *ghost;
    int64_t *idx, *at; /* at: nranks + 1 */
    int64_t rows;      /* this rank's rows */
    int32_t *loc;      /* per entry q of A: its column's place, own row (< rows) or rows + ghost; NULL with one rank */
} ulam__halo;

/* Find the halo of A's rows (one exchange); nonzero on failure (memory or the exchange). */
int ulam__halo_make(const ulam_part *p, const ulam_comm *c, const ulam__rows *A, ulam__halo *h);

/* A vector's halo values into gv (h->ghost order) from every rank's rows mine; nonzero on failure. */
int ulam__halo_swap(const ulam_part *p, const ulam_comm *c, const ulam__halo *h, const double *mine, double *gv);

/* The vector at the column of entry q of the rows the halo was made for (h->loc, found once: no
 * search a product): this rank's own rows own, else its halo gv. */
static inline double ulam__halo_at(const ulam_part *p, const ulam__rows *A, const ulam__halo *h, const double *own,
                                   const double *gv, int64_t q)
{
    if (!h->loc) return own[A->col[q] - p->first];
    int64_t l = h->loc[q];
    return l < h->rows ? own[l] : gv[l - h->rows];
}

/* Free h's arrays. */
void ulam__halo_free(ulam__halo *h);

/* What bounds an adjoint walk's length on a partition: every row sum of |M| at most 1 (so the
 * analog kernel's weights stay +-1 and a walk from i is alive after k steps with probability
 * (|M|^k 1)_i) and a positive v with |M| v <= u v (a Collatz-Wielandt vector of ulam_dist_radius's
 * power iteration, certified by one product rounded up): alive with probability at most
 * u^k v_i / min v = u^k c[k] for query k.  bmax = max |b_i|: a walk of T steps scores at most
 * bmax (T + 1).  With a row sum above 1 (second) the same power iteration's u certifies the
 * weights' second moment instead, and bmax^2 c[k] >= v_k max_i b_i^2 / v_i.  u INFINITY: no
 * certificate. */
typedef struct {
    double u, bmax;
    double *c;  /* per query, malloc'd */
    double *v2; /* second: per query, E X^2 <= v2 aimed at its start (adjoint, ulam__dist_moment) or at the row
                   watched (forward, ulam__dist_moment_forward), malloc'd;
                   NULL otherwise */
    int second; /* a row sums above 1: u certifies M^ = diag(max(1, S)) |M| (the weights' second moment),
                   and a score's E X^2 <= bmax^2 c / (1 - sqrt u)^2 (Minkowski over the steps) bounds
                   the clipping in place of the length */
} ulam__dist_cert;

/* The certificate above for walks from index[0 .. nq) (src/dist_radius.c), at most iters products.
 * total >= 0: forward walks' tallies at index[k] instead (on M', from the system's b, every weight
 * +-total = ||b||_1 while rows are <= 1): bmax is total and c[k] bounds max_{b_j != 0} v_j / min v
 * (second: / v at index[k]). */
int ulam__dist_tail(const ulam_part *p, const ulam_comm *comm, int iters, const int64_t *index, int64_t nq, double total,
                    ulam__dist_cert *cert, ulam_error *err);

/* Each adjoint query's certified E X^2 of one collision score (analog kernel, walks from
 * index[k]) aimed at its start, into v2[k] on every rank (INFINITY: none held): src/solve.c's
 * second_moment_aimed on the part's rows of M, products through the halo (src/dist_moment.c). */
int ulam__dist_moment(const ulam_part *p, const ulam_comm *comm, const int64_t *index, int64_t nq, double *v2,
                      ulam_error *err);

/* Forward mode's watched row: the certified E X^2 of one history's tally there (analog kernel
 * on M', starts by |b|) into *v2, the same on every rank; INFINITY where none held
 * (src/dist_moment.c). */
int ulam__dist_moment_forward(const ulam_part *p, const ulam_comm *comm, int64_t watch, double *v2, ulam_error *err);

/* ulam_dist_forward with, for watch >= 0 (0-based), that component's estimate and standard error
 * in res and its certified 95% interval in *ci: its histories' tallies, block by block of walk ids
 * at rank 0, feed the confidence sequence adjoint queries use (src/dist.c). */
int ulam__dist_forward_ci(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, int64_t watch, double *x,
                          double *se, ulam_dist_result *res, ulam_dist_ci *ci, ulam_error *err);

/* A Collatz-Wielandt certificate |M| v <= u v of the part's rows of M (u INFINITY: none) and
 * c[i] >= v_i / min v at this rank's rows (src/dist_radius.c), at most iters products. */
int ulam__dist_cw(const ulam_part *p, const ulam_comm *comm, int iters, double *u, double *c, ulam_error *err);

/* As ulam_dist_forward with the sources drawn from b (this rank's rows [first, last) of it) in
 * place of the system's b: the walks of MCSA's correction and of single source's residual. */
int ulam__dist_forward_b(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, const double *b, double *x,
                        double *se, ulam_dist_result *res, ulam_error *err);

/* As ulam__dist_forward_b (x and se from the same collision tallies), with hits[i] the walks that
 * ended at each of this rank's rows, counted exactly: with M >= 0, b >= 0 and every column sum S
 * of M below 1, a walk ends at i with probability x_i (1 - S_i) / ||b||_1, so hits[i] is a binomial
 * count whose KL interval, times ||b||_1 / (1 - S_i), holds x_i; *mass: ||b||_1 over every rank
 * (the same bits at any split). */
int ulam__dist_forward_ends(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, const double *b,
                            double *x, double *se, double *hits, double *mass, ulam_dist_result *res, ulam_error *err);

/* ulam_dist_mcsa with its corrections' walk counts summed into *all (src/dist_outer.c). */
int ulam__dist_mcsa(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, double tol, int max_iter,
                    double *x, ulam_dist_mcsa_info *info, ulam_dist_result *all, ulam_error *err);

/* ulam_dist_source (source -1: from the system's b) with its walks' counts in *walks and, lo and hi given, each x_i's 95% interval
 * where terminal walks apply (M >= 0, column sums of M below 1; the lower ends for K components
 * chosen by estimate; *terminal 1 then), else -INFINITY .. INFINITY (src/dist_outer.c). */
int ulam__dist_source(const ulam_part *p, const ulam_comm *comm, int64_t source, const ulam_dist_opts *o, double tol,
                      int max_rounds, int64_t K, double *x, double *se, double *lo, double *hi, int *terminal,
                      ulam_dist_source_info *info, ulam_dist_result *walks, ulam_error *err);

#endif
