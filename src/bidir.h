/* The bidirectional estimator's memory across queries (internal; src/bidir.c): the last plan
 * made on a push workspace, the pilot's scores and guards, and an analysis of M' (src/analysis.c)
 * that hands out every walk of the estimator and keeps what later walks share: the bounds over
 * every state of M' (reach_all), the kept kernels (keep_kernel) and the reach a pilot found.  Its
 * owner is the analysis of M (ulam__analysis_keep: one with its transpose and push workspace, for
 * queries made through it), or a bare push workspace for ulam_bidir_plan and ulam_bidir_solve
 * (kept with it: ulam__push_keep). */
#ifndef ULAM_BIDIR_H
#define ULAM_BIDIR_H

#include "internal.h"

typedef struct ulam__bidir ulam__bidir;

/* An empty memo (NULL: no memory). */
ulam__bidir *ulam__bidir_alloc(void);

/* Free a memo and what it keeps; accepts and returns NULL. */
ulam__bidir *ulam__bidir_free(ulam__bidir *m);

#endif
