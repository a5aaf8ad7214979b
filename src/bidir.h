/* The bidirectional estimator's memory across queries (internal; src/bidir.c): the last plan
 * made on a push workspace, the pilot's scores, guards and reach, the bounds over every state of
 * M' (reach_all) and the kept kernels (keep_kernel).  Its owner is the analysis (src/analysis.c:
 * one with its transpose and push workspace, for queries made through it), or a bare push
 * workspace for ulam_bidir_plan and ulam_bidir_solve (kept with it: ulam__push_keep). */
#ifndef ULAM_BIDIR_H
#define ULAM_BIDIR_H

#include "internal.h"

typedef struct ulam__bidir ulam__bidir;

/* An empty memo (NULL: no memory). */
ulam__bidir *ulam__bidir_alloc(void);

/* Free a memo and what it keeps; accepts and returns NULL. */
ulam__bidir *ulam__bidir_free(ulam__bidir *m);

/* ulam_bidir_plan and ulam_bidir_solve with push workspace w on M, Mt M's transpose, and memo m:
 * a plan m holds is reused only for w's state as the plan left it and the same options (among
 * them the continuation, the kernel exponent and the estimator). */
int ulam__bidir_plan(const ulam_csr *M, const ulam_csr *Mt, ulam_push *w, ulam__bidir *m, const ulam_bidir_opts *o,
                     ulam_bidir_plan_info *plan, ulam_error *err);
int ulam__bidir_solve(const ulam_csr *M, const ulam_csr *Mt, ulam_push *w, ulam__bidir *m, const ulam_bidir_opts *o,
                      ulam_bidir_result *res, ulam_error *err);

#endif
