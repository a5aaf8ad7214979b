/* The bound on the chance a walk scores at all (src/hit.c).  Internal. */
#ifndef ULAM_HIT_H
#define ULAM_HIT_H

#include "internal.h"

/* The bound on the probability that a walk scores at all (src/hit.c): Gauss-Seidel sweeps of
 * v <- a + c P v over the `count` states listed in ascending order (the walks' reachable set:
 * closed under their moves), K the walks' kernel (continuation continue_q, exponent alpha),
 * target the states where a walk scores (absorb: by ending there; else by a visit), v 1 there on
 * entry and an upper bound on each listed state's probability after every sweep; at most
 * `sweeps` sweeps (*sweep counts them, alternating ascending and descending order) or until
 * converged (*done); the entries read (and one a state). */
int64_t ulam__hit_sweeps(const ulam_csr *K, const int64_t *states, int64_t count, double continue_q, double alpha,
                         const char *target, int absorb, double *v, int sweeps, int *sweep, int *done);

#endif
