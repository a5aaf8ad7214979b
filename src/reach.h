/* reach.h: the reach of walks on K and the bounds a pass over it certifies, as a record: the walk
 * solver makes and reads it (src/solve.c, solve.h's ulam__reach_all, _reach_b), a prepared file
 * stores and returns it (src/cache.c), an analysis shares it.  A type alone, below both. */
#ifndef ULAM_REACH_H
#define ULAM_REACH_H

#include "internal.h"

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
    int shared; /* an analysis' bounds every query shares (ulam_analysis_opts.shared_bounds): the
                   solver reads no more of K for its own start (no tail_len) */
} ulam__reach;

#endif
