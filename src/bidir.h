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

#endif
