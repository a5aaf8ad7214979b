/* The push workspace as the bidirectional estimator sees it (internal). */
#ifndef ULAM_PUSH_H
#define ULAM_PUSH_H

#include "ulam.h"

/* The matrix a workspace pushes on. */
const ulam_csr *ulam__push_matrix(const ulam_push *w);

#endif
