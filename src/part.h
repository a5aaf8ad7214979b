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
    double *b;
    int64_t *split; /* nranks + 1 row boundaries: position r of a set owns rows [split[r], split[r + 1]) */
    int nranks, rank, shift; /* ranks in this rank's set and its position there */
    int set, sets;           /* this rank's set (world rank set * nranks + rank) of sets */
};

/* The position in a set owning row s. */
int ulam__part_owner(const ulam_part *p, int64_t s);

/* Every rank's slice of a vector (its rows) into all[0 .. n) on every rank of its set
 * (src/part.c); nonzero on a failed exchange. */
int ulam__dist_gather(const ulam_part *p, const ulam_comm *c, const double *mine, double *all);

/* The largest of every rank's nonnegative *x, into *x on every rank; nonzero on a failed sum. */
int ulam__dist_largest(const ulam_comm *c, double *x);

/* What bounds an adjoint walk's length on a partition: every row sum of |M| at most 1 (so the
 * analog kernel's weights stay +-1 and a walk from i is alive after k steps with probability
 * (|M|^k 1)_i) and a positive v with |M| v <= u v (a Collatz-Wielandt vector of ulam_dist_radius's
 * power iteration, certified by one product rounded up): alive with probability at most
 * u^k v_i / min v = u^k c[k] for query k.  bmax = max |b_i|: a walk of T steps scores at most
 * bmax (T + 1).  u INFINITY: no certificate. */
typedef struct {
    double u, bmax;
    double *c; /* per query, malloc'd */
} ulam__dist_cert;

/* The certificate above for walks from index[0 .. nq) (src/dist_radius.c), at most iters products. */
int ulam__dist_tail(const ulam_part *p, const ulam_comm *comm, int iters, const int64_t *index, int64_t nq,
                    ulam__dist_cert *cert, ulam_error *err);

/* As ulam_dist_forward with the sources drawn from b (this rank's rows [first, last) of it) in
 * place of the system's b: the walks of MCSA's correction and of single source's residual. */
int ulam__dist_forward_b(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, const double *b, double *x,
                        double *se, ulam_dist_result *res, ulam_error *err);

#endif
