/* Prepared systems' privates (src/cache.c): the stored bounds, the writer's check and
 * bytes, row buffers and block checks, the header's layout and checksums.  Internal. */
#ifndef ULAM_CACHE_H
#define ULAM_CACHE_H

#include "internal.h"
#include "reach.h"

#include <stdio.h>

/* The bounds a prepared system stores for its matrix (ulam__reach_all's, with b's scores when
 * the file holds b) when made for continuation continue_q and exponent alpha: 1 and R filled
 * (R->K its matrix, R->seen NULL: the caller gives n flags of ones), else 0 (src/cache.c). */
int ulam__system_bounds(const ulam_system *s, double continue_q, double alpha, ulam__reach *R);

/* A row read from a file: its len columns and values (and b_i); and a thread's cache of one block
 * of M (its row pointers, columns and values at blk) and one of b (at bblk), each kept once
 * verified, so the next row or b_j in the same block is read from memory; grown as rows need.
 * All zero: empty. */
typedef struct ulam__rowbuf {
    int32_t *col;
    double *val;
    int64_t len, cap;
    double b;
    unsigned char *blk;
    int64_t blkcap;
    int64_t blk_at, blk_cols, blk_vals; /* the block at blk + 1 (0: none), its columns' and values' offsets */
    double *bblk;
    int64_t bblkcap, bblk_at;           /* the block of b at bblk + 1 (0: none) */
} ulam__rowbuf;

/* Free r's buffers and empty it. */
static inline void ulam__rowbuf_free(ulam__rowbuf *r)
{
    free(r->col), free(r->val), free(r->blk), free(r->bblk);
    *r = (ulam__rowbuf){0};
}

/* A check of rows [first, last) of a borrowed matrix (and, with with_b, of b at those rows) made
 * before anything reads them: ULAM_OK, or ULAM_ESYNTAX with *bad (may be NULL) the first row of the
 * damaged block.  Thread-safe.  fn NULL: nothing to check.  A prepared system's (src/cache.c): a
 * solver given ulam_walk_opts.policy.system calls it on each row before building it, on every row
 * reached by a reachability search, and on all of them before a pass over all of M. */
typedef struct ulam__rows_check {
    int (*fn)(const void *ctx, int64_t first, int64_t last, int with_b, int64_t *bad);
    const void *ctx;
    int with_b;
    /* A prepared file read by pread (src/cache.c; NULL: rows are read in place): row i of
       fetch_of into r, its block verified first (and with b_of's b_i in r->b when with_b);
       b_at: b_of's j-th entry, its block verified first (r: the thread's buffer, or NULL).
       ULAM_OK, or ULAM_ESYNTAX (ULAM_EIO) with *bad (may be NULL) the first row of the damaged
       block.  Thread-safe (r: the thread's). */
    int (*fetch)(const void *ctx, int64_t i, int with_b, ulam__rowbuf *r, int64_t *bad);
    int (*b_at)(const void *ctx, int64_t j, ulam__rowbuf *r, double *v, int64_t *bad);
    const ulam_csr *fetch_of;
    const double *b_of;
} ulam__rows_check;


/* Run rc on rows [first, last) (ULAM_OK when rc or its fn is NULL). */
static inline int ulam__rows_verify(const ulam__rows_check *rc, int64_t first, int64_t last, int64_t *bad)
{
    return rc && rc->fn ? rc->fn(rc->ctx, first, last, rc->with_b, bad) : 0;
}

/* The check of a solver given opts->policy.system: *rc, when M is that system's matrix (b is checked
 * with it when it is the system's b; another b was verified by whoever gave it); else ULAM_EINVAL. */
int ulam__system_rows_check(const ulam_system *s, const ulam_csr *M, const double *b, ulam__rows_check *rc,
                            ulam_error *err);

/* A single-source query on a lazily read system (src/fpush.c): rows [first, last) of s's stored
 * M^T verified, each block once (ULAM_OK, ULAM_ESYNTAX with err naming the block, ULAM_EINVAL when
 * s holds no M^T); the stored M^T as it is, not verified (NULL: none); and whether M's values are
 * all >= 0 (1), one is negative (0) or the file cannot be read (-1): a scan of the value array by
 * pread, so no page of it stays mapped, and not verified -- a damaged block read later still
 * fails its query, and a sign decides only which interval the walks' scores get. */
int ulam__system_tr_verify(const ulam_system *s, int64_t first, int64_t last, ulam_error *err);
const ulam_csr *ulam__system_tr(const ulam_system *s);
int ulam__system_nonneg(const ulam_system *s);

/* A mapping larger than this many bytes is given back as passes over it go, so a query's
 * resident set stays well under the file (issue 43: 2^24 nodes, a 6.5 GB file, within 2 GiB); a
 * smaller one stays mapped whole, as read (R-MAT 2^22, a 1.6 GB file: given back, the query took
 * 1.6x the CPU).  And the file-backed resident bytes past which a pass that reads at random gives
 * all of it back (ulam__system_trim). */
#define ULAM__SYSTEM_KEEP ((size_t)2 << 30)
#define ULAM__SYSTEM_TRIM ((size_t)512 << 20)

/* Passes over a prepared system's arrays (src/cache.c): whether s's mapping is released as they go
 * (a mapped file of more than its keep bytes, ULAM__SYSTEM_KEEP unless set); rows [r0, r1) of A (s's
 * M or stored M^T; else nothing) given back to the page cache (madvise: the pages leave the
 * resident set, a later read maps them again) -- a block verified is given back so; and entries
 * [e0, e0 + cnt) of row j of the stored M^T read by pread into col and val (room for cnt entries;
 * either NULL: not read), 0 or -1 on a failed read.
 * ulam__system_trim: for passes that read at random (a queue push, walks), called now and then:
 * all of the mapping given back once the process's file-backed resident set passes ULAM__SYSTEM_TRIM. */
int ulam__system_releases(const ulam_system *s);
void ulam__system_set_keep(ulam_system *s, size_t bytes);
void ulam__system_release(const ulam_system *s, const ulam_csr *A, int64_t r0, int64_t r1);
int ulam__system_tr_read(const ulam_system *s, int64_t j, int64_t e0, int64_t cnt, int32_t *col, double *val);
void ulam__system_trim(const ulam_system *s);

/* What a prepared system is written from checked (ulam_system_write_file's refusals: ULAM_EINVAL),
 * and its bytes written to f with the bounds R (an analysis' of d->M at the certificate's
 * continuation and exponent 1, with d->b's scores; NULL: none stored) once checked (src/cache.c;
 * the writer, src/prepare.c, makes R). */
int ulam__system_desc_check(FILE *f, const ulam_system_desc *d);
int ulam__system_write_checked(FILE *f, const ulam_system_desc *d, const ulam__reach *R);

/* Why the block holding row i of s failed: ULAM_ESYNTAX with err naming the block and the fault. */
int ulam__system_row_error(const ulam_system *s, int64_t i, ulam_error *err);

/* What a valid prepared file's header states (src/cache.c): sizes, which arrays it holds, block
 * size 2^shift rows, the byte offsets of rowptr, colidx, val, b, M^T's three and the checksum
 * table (0 for an absent array), each part's blocks and first checksum, the table's own hash. */
typedef struct {
    int64_t n, ncols, nnz, nblocks[3], first[3];
    int shift, has_matrix, has_rhs, has_tr;
    uint64_t off[8], sums_hash, tag[2];
    double omega;
} ulam__layout;

/* Check the header at p (its first 1024 bytes; the file is len bytes) and give its layout. */
int ulam__system_header(const unsigned char *p, uint64_t len, ulam__layout *L, ulam_error *err);

/* 1 when a block (row pointers rp[0 .. rows], entries col, val) has checksum want and holds the
 * CSR invariants (columns below ncols, rising; values finite and nonzero). */
int ulam__system_block_ok(const int64_t *rp, int64_t rows, const int32_t *col, const double *val, int64_t ncols,
                          uint64_t want);

/* XXH3-64 of n bytes (the prepared format's checksum of a b block and of the checksum table). */
uint64_t ulam__system_hash(const void *p, size_t n);

/* log2 of a prepared file's block of rows for an n-row M with nnz entries (src/cache.c). */
int ulam__system_block_shift(int64_t n, int64_t nnz);

#endif
