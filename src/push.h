/* The push workspace as the bidirectional estimator sees it (internal). */
#ifndef ULAM_PUSH_H
#define ULAM_PUSH_H

#include "internal.h"

/* The matrix a workspace pushes on. */
const ulam_csr *ulam__push_matrix(const ulam_push *w);

/* The last bidirectional plan made on a workspace (src/bidir.c fills it): the transpose and
 * options it was made for, b's entries copied (idx, val: cap entries of room), what it found
 * and the guards its pilot computed.  valid is
 * cleared by ulam_push_start and ulam_push_run, so a valid memo describes the push in place. */
typedef struct {
    int valid;
    const ulam_csr *Mt; /* the transpose it was made with */
    ulam_bidir_opts o;
    int64_t *idx;
    double *val;
    int64_t cap;
    ulam_bidir_plan_info plan;
    ulam_guard guard; /* the pilot's guards on Mt, for the walks (have_guard 0: none) */
    int have_guard;
    double *ones; /* n ones (NULL until a pilot needs them): the pilot's scores */
    char *seen;   /* n flags: the states the pilot found its walks can reach (have_seen 0: none) */
    int have_seen;
    char *all;          /* n ones: every state (reach_all; NULL until a query asks) */
    ulam__reach reach;  /* what the walks reach: over seen (have_seen) or all (have_all) */
    int have_all;       /* 1: reach holds ulam__reach_all's bounds over all, for reach.K and continuation */
    struct ulam_kernel *kernel; /* keep_kernel: the last walks' kernel (ulam__solver_keep_kernel; NULL: none) */
    struct ulam_kernel *pilot;  /* keep_kernel: the pilot's, scoring ones (fixed; NULL: none) */
} ulam__bidir_memo;

/* The workspace's memo (owned by it, freed with it). */
ulam__bidir_memo *ulam__push_memo(ulam_push *w);

#endif
