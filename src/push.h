/* The push workspace's internal accessors (src/push.c): facts about the push itself, nothing of
 * what is built on it. */
#ifndef ULAM_PUSH_H
#define ULAM_PUSH_H

#include "internal.h"

/* The matrix a workspace pushes on. */
const ulam_csr *ulam__push_matrix(const ulam_push *w);

/* A count that changes whenever the workspace's state changes (ulam_push_start, ulam_push_run):
 * a plan that recorded it describes the push in place while it is unchanged. */
uint64_t ulam__push_stamp(const ulam_push *w);

/* What a caller keeps with the workspace for the workspace's lifetime (src/bidir.c keeps the
 * plan memo of ulam_bidir_plan and ulam_bidir_solve there): push.c neither reads it nor knows its
 * type, and frees it with drop(data) in ulam_push_free.  Set once; NULL until set. */
void *ulam__push_kept(const ulam_push *w);
void ulam__push_keep(ulam_push *w, void *data, void (*drop)(void *));

#endif
