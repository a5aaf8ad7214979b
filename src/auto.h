/* The walks' choice on a reach (src/auto.c).  Internal. */
#ifndef ULAM_AUTO_H
#define ULAM_AUTO_H

#include "internal.h"
#include "solve.h"

/* As ulam_auto_solver, with reach (NULL: none; borrowed until the solver is freed) the bounds
 * over every state of M (ulam__reach_all's, with b's scores when they are this b's) that the
 * candidates of its kernel (adjoint, its continuation and exponent) walk under instead of each
 * searching its start's reach (src/auto.c; ulam_analysis_auto). */
int ulam__auto_solver_reach(const ulam_csr *M, const double *b, const ulam_walk_opts *base, const ulam_auto_opts *ao,
                            const ulam__reach *reach, ulam_auto_result *res, ulam_solver **out, ulam_error *err);

#endif
