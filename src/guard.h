/* The guards' privates (src/guard.c): the fourth moment's radius, whether a caller's guard fits.  Internal. */
#ifndef ULAM_GUARD_H
#define ULAM_GUARD_H

#include "internal.h"

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

#endif
