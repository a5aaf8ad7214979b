/* ulam_load.h: load a system (I - M) x = b from the files a front end names: a Matrix Market
 * matrix, an edge list or a prepared file for M, a vector or prepared file for b; with a cache,
 * a prepared copy PATH.ulamcache beside each parsed file; Jacobi's splitting of A x = b or
 * PageRank's matrix built from what was read.  The command line (ulam solve, bidir, info, ...)
 * and any other front end load through it.  Nothing is printed except the cache's notes to a
 * caller's FILE *. */
#ifndef ULAM_LOAD_H
#define ULAM_LOAD_H

#include <stdio.h>

#include "ulam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What to load (set by the caller) and what was loaded (set by ulam_load_open and _finish). */
typedef struct ulam_load {
    const char *matrix_path, *rhs_path; /* rhs_path NULL: b from a prepared matrix_path, or none */
    int jacobi;      /* the file holds A of A x = b: M = I - omega D^-1 A */
    double omega;    /* damping of the Jacobi splitting (<= 0: 1, plain Jacobi) */
    double pagerank; /* > 0: the file is an adjacency matrix; M = alpha P^T at this damping */
    int cache;       /* read and write prepared copies PATH.ulamcache beside parsed files */
    int lazy;        /* M is read only where walks reach: a mapped M is not verified by _finish */
    /* the writer of a cache copy (NULL: ulam_system_write_file through a ulam_outfile) */
    int (*write)(const char *path, const ulam_system_desc *d);
    ulam_csr *preloaded; /* matrix_path's edge list read ahead (taken over when used, else left) */
    int64_t node_base;   /* the first node id of an edge list read (1 otherwise; left as given) */
    const ulam_csr *M;   /* the iteration matrix (owned, or mapped from a prepared file) */
    const double *b;     /* the right-hand side (NULL if none) */
    const ulam_certificate *cert; /* the guards a prepared file certified (NULL: none) */
    int verified;        /* M and b checked whole (parsed, or ulam_system_check passed) */
    int b_pagerank;      /* b was made (1 - alpha) / n: x is PageRank itself */
    ulam_csr *own_M;     /* what M and b point to when this owns them */
    double *own_b;
    ulam_system *sys_M, *sys_b; /* mappings behind M and b */
} ulam_load;

/* Read M and b as L names them (prepared files mapped, not yet verified; a square M and a b of
 * its size); a status, err filled (err->file the file at fault); nothing held on failure. */
int ulam_load_open(ulam_load *L, FILE *log, ulam_error *err);

/* After ulam_load_open: Jacobi's splitting or PageRank's matrix as L asks, then verify M and b
 * whole unless lazy (lazy: a b of its own file still whole); a status; nothing held on failure. */
int ulam_load_finish(ulam_load *L, ulam_error *err);

/* Check a mapped M and b whole if not yet done; a status; nothing held on failure. */
int ulam_load_verify(ulam_load *L, ulam_error *err);

/* Free what L holds (its inputs stay); L NULL is allowed. */
void ulam_load_free(ulam_load *L);

#ifdef __cplusplus
}
#endif

#endif
