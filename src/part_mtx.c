/* One rank's rows of a Matrix Market system read by byte ranges (see ulam_part_open_mtx).
 *
 * Position q of P in a set reads the entry lines that start in the q-th P-th of the bytes after
 * the size line (each edge moved to the next line start), with the sequential reader's parser
 * (src/mmio.c).  Every rank's count of lines, summed in rank order, turns a line of its range into
 * the file's line.  The entries then travel to the rank owning their row in rounds of at most
 * ROUND entries a rank (a first split by raw entries), where each row's entries, placed in file
 * order, are sorted and summed as the single-machine reader sums them.  The split the part keeps is
 * the prepared file's: blocks of 2^shift rows (ulam__system_block_shift of the summed entries)
 * balanced by the entries of M (or M'); rows move once more only when it differs from the first.
 * M' comes from M's summed entries sent to their column's owner, in row order.  So a part is the
 * one `ulam prepare --transpose` would give, bit for bit, and no rank holds more than its share of
 * entries (and b, which every rank reads whole and keeps its rows of). */
#include "part.h"
#include "cache.h"
#include "csr.h"
#include "mmio.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Entries a rank sends in one round of the redistribution (16 MiB). */
enum { ROUND = 1 << 20 };

typedef ulam__mm_entry entry;

/* The first failing rank's status and error on every rank (ULAM_EIO when the exchange fails):
 * the message and exit code do not depend on the rank count. */
static int agree(const ulam_comm *c, int status, ulam_error *err)
{
    if (c->nranks == 1) return status;
    int64_t *v = calloc((size_t)c->nranks, sizeof *v);
    size_t *cnt = calloc((size_t)c->nranks * 2, sizeof *cnt);
    ulam_error *send = malloc((size_t)c->nranks * sizeof *send);
    void *got = NULL;
    int bad = !v || !cnt || !send, first = -1;
    if (!bad) v[c->rank] = status, bad = c->sum(c->ctx, v, c->nranks);
    for (int r = 0; !bad && first < 0 && r < c->nranks; r++)
        if (v[r]) first = r;
    if (!bad && first >= 0) {
        for (int r = 0; r < c->nranks; r++) send[r] = *err, cnt[r] = c->rank == first ? sizeof *err : 0;
        bad = c->exchange(c->ctx, send, cnt, &got, cnt + c->nranks);
        if (!bad && cnt[c->nranks + first] == sizeof *err) memcpy(err, (char *)got, sizeof *err);
        else bad = 1;
    }
    int out = bad ? ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds") : first >= 0 ? (int)v[first] : 0;
    free(v), free(cnt), free(send), free(got);
    return out;
}

/* Row boundaries split[0 .. P] of nb blocks of 2^shift rows by their counts cnt: position r's first
 * block is the first whose preceding entries reach r/P of all (as src/part.c splits a file). */
static void split_counts(const int64_t *cnt, int64_t nb, int shift, int64_t n, int P, int64_t *split)
{
    int64_t total = 0, acc = 0, k = 0;
    for (int64_t b = 0; b < nb; b++) total += cnt[b];
    split[0] = 0, split[P] = n;
    for (int r = 1; r < P; r++) {
        int64_t want = total / P * r + total % P * r / P;
        while (k < nb && acc < want) acc += cnt[k++];
        split[r] = k << shift < n ? k << shift : n;
    }
}

/* The position owning row s under split[0 .. P]. */
static int owner(const int64_t *split, int P, int64_t s)
{
    int lo = 0, hi = P - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (split[mid] <= s) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* The rows split[q] .. split[q + 1] of position q in this rank's set, from every rank's entries e
 * (row i, column j; with transpose row j, column i), as a CSR *A whose rows hold their entries in
 * the senders' rank order, each sender's in its order (unsorted, unsummed).  e is freed. */
static int gather_rows(const ulam_part *p, const ulam_comm *c, const int64_t *split, entry *e, int64_t len,
                       int transpose, ulam_csr **A, ulam_error *err)
{
    int W = c->nranks, P = p->nranks, base = p->set * P;
    int64_t first = split[p->rank], rows = split[p->rank + 1] - first, rounds = (len + ROUND - 1) / ROUND;
    int64_t *most = calloc((size_t)W, sizeof *most); /* every rank's rounds */
    int bad = !most;
    if (!bad) most[c->rank] = rounds, bad = W > 1 && c->sum(c->ctx, most, W);
    for (int r = 0; !bad && r < W; r++)
        if (most[r] > rounds) rounds = most[r];
    free(most);
    entry **buf = calloc((size_t)rounds + 1, sizeof *buf), *send = malloc((size_t)(len < ROUND ? len : ROUND) * sizeof *send + 1);
    size_t *cnt = calloc((size_t)(rounds + 1) * (size_t)W * 2, sizeof *cnt); /* round k: send counts, then received */
    int64_t *at = calloc((size_t)W + 1, sizeof *at), total = 0;
    int refused = agree(c, bad || !buf || !send || !cnt || !at ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a round of entries") : 0, err);
    if (refused) bad = 1, rounds = 0;
    for (int64_t k = 0; !bad && k < rounds; k++) {
        int64_t a = k * ROUND < len ? k * ROUND : len, b = a + ROUND < len ? a + ROUND : len;
        size_t *sc = cnt + (size_t)k * W * 2;
        memset(at, 0, ((size_t)W + 1) * sizeof *at);
        for (int64_t x = a; x < b; x++) at[base + owner(split, P, transpose ? e[x].j : e[x].i) + 1]++;
        for (int r = 0; r < W; r++) sc[r] = (size_t)at[r + 1] * sizeof *send, at[r + 1] += at[r];
        for (int64_t x = a; x < b; x++) {
            int r = base + owner(split, P, transpose ? e[x].j : e[x].i);
            send[at[r]++] = transpose ? (entry){e[x].j, e[x].i, e[x].x} : e[x];
        }
        if (W > 1) bad = c->exchange(c->ctx, send, sc, (void **)&buf[k], sc + W);
        else buf[k] = send, send = malloc((size_t)ROUND * sizeof *send), sc[W] = sc[0], bad = !send;
        for (int r = 0; !bad && r < W; r++) total += (int64_t)(sc[W + r] / sizeof *send);
    }
    free(e), free(send), free(at);
    ulam_csr *C = bad ? NULL : ulam_csr_alloc(rows, p->n, total);
    int64_t *next = C ? ulam__malloc((size_t)rows + 1, sizeof *next) : NULL;
    int status = bad ? ULAM_EIO : !C || !next ? ULAM_ENOMEM : ULAM_OK;
    for (int pass = 0; !status && pass < 2; pass++) { /* counts, then entries placed in (sender, round) order */
        for (int r = 0; r < W; r++)
            for (int64_t k = 0; k < rounds; k++) {
                const size_t *rc = cnt + (size_t)k * W * 2 + W;
                size_t off = 0;
                for (int q = 0; q < r; q++) off += rc[q] / sizeof *send;
                const entry *g = buf[k] + off;
                for (size_t x = 0; x < rc[r] / sizeof *send; x++) {
                    int64_t i = g[x].i - first;
                    if (!pass) C->rowptr[i + 1]++;
                    else C->colidx[next[i]] = g[x].j, C->val[next[i]++] = g[x].x;
                }
            }
        if (!pass) {
            for (int64_t i = 0; i < rows; i++) C->rowptr[i + 1] += C->rowptr[i];
            memcpy(next, C->rowptr, ((size_t)rows + 1) * sizeof *next);
        }
    }
    for (int64_t k = 0; buf && k < rounds; k++) free(buf[k]);
    free(buf), free(cnt), free(next);
    if (status) {
        ulam_csr_free(C);
        return refused ? refused : status == ULAM_EIO ? ulam__fail(err, status, 0, -1, "an exchange of entries between ranks that succeeds")
                                  : ulam__fail(err, status, 0, -1, "memory for %lld entries", (long long)total);
    }
    *A = C;
    return ULAM_OK;
}

/* A's entries (rows from first) as an array in row order; NULL when out of memory. */
static entry *entries_of(const ulam_csr *A, int64_t first, int64_t *len)
{
    *len = A->rowptr[A->nrows];
    entry *e = malloc((size_t)*len * sizeof *e + 1);
    for (int64_t i = 0; e && i < A->nrows; i++)
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) e[q] = (entry){(int32_t)(first + i), A->colidx[q], A->val[q]};
    return e;
}

/* A's arrays moved into R (A freed). */
static void take(ulam_csr *A, ulam__rows *R)
{
    R->rowptr = A->rowptr, R->col = A->colidx, R->val = A->val, R->nnz = A->rowptr[A->nrows];
    A->rowptr = NULL, A->colidx = NULL, A->val = NULL;
    ulam_csr_free(A);
}

/* Read this position's byte range of fd's entries into *e, the errors located at the file's
 * lines and the count checked: the same status and error on every rank. */
static int read_range(int fd, const ulam__mm_coord *h, const ulam_part *p, const ulam_comm *c, entry **e, int64_t *len,
                      ulam_error *err)
{
    int P = p->nranks, q = p->rank, W = c->nranks;
    int64_t bytes = h->end - h->data, entries = 0;
    int64_t from = q ? ulam__mm_line_start(fd, h, h->data + bytes / P * q + bytes % P * q / P) : h->data;
    int64_t to = q < P - 1 ? ulam__mm_line_start(fd, h, h->data + bytes / P * (q + 1) + bytes % P * (q + 1) / P) : h->end;
    long lines = 0;
    int status = ulam__mm_read_range(fd, h, from, to, h->nnz, e, len, &entries, &lines, err);
    entry *fit = status || !*len ? NULL : realloc(*e, (size_t)*len * sizeof **e); /* the growth's slack back */
    if (fit) *e = fit;
    int64_t *v = calloc((size_t)W * 3, sizeof *v);
    if (!v) return agree(c, ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the ranks' counts"), err);
    v[3 * c->rank] = status, v[3 * c->rank + 1] = lines, v[3 * c->rank + 2] = entries;
    if (W > 1 && c->sum(c->ctx, v, 3 * W)) {
        free(v);
        return agree(c, ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds"), err);
    }
    const int64_t *s = v + 3 * p->set * P; /* this set's positions */
    int64_t before = h->lines, seen = 0, line0 = 0, seen0 = 0;
    int trouble = -1;
    for (int r = 0; r < P && trouble < 0; r++) {
        if (r == q) line0 = before, seen0 = seen;
        if (s[3 * r] || seen + s[3 * r + 2] > h->nnz) trouble = r;
        before += s[3 * r + 1], seen += s[3 * r + 2];
    }
    int mine = 0;
    if (trouble == q) {
        if (seen0 + entries > h->nnz) { /* the first entry past the count is here, before any bad line */
            free(*e);
            status = ulam__mm_read_range(fd, h, from, to, h->nnz - seen0, e, len, &entries, &lines, err);
        }
        err->line += err->line > 0 ? line0 : 0;
        mine = status;
    }
    free(v);
    if (trouble < 0 && seen < h->nnz)
        mine = ulam__fail(err, ULAM_ETOOFEW, before, -1, "%lld entries as the size line says, found %lld before the end of file",
                          (long long)h->nnz, (long long)seen);
    return agree(c, mine, err);
}

/* The prepared file's shift and split of this set's rows (summed entries in A, rows split0[q] ..)
 * by M's entries, or by M''s (by_t), into p. */
static int final_split(ulam_part *p, const ulam_comm *c, const ulam_csr *A, int64_t first, int by_t, ulam_error *err)
{
    int64_t nnz = p->set == 0 ? A->rowptr[A->nrows] : 0;
    if (c->nranks > 1 && c->sum(c->ctx, &nnz, 1)) return ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    p->shift = ulam__system_block_shift(p->n, nnz);
    int64_t nb = (p->n + ((int64_t)1 << p->shift) - 1) >> p->shift;
    int64_t *cnt = calloc((size_t)nb + 1, sizeof *cnt);
    if (!cnt) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld block counts", (long long)nb);
    for (int64_t i = 0; p->set == 0 && i < A->nrows; i++) /* one set's */
        for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++) cnt[(by_t ? A->colidx[k] : first + i) >> p->shift]++;
    int bad = c->nranks > 1 && c->sum(c->ctx, cnt, (int)nb);
    if (!bad) split_counts(cnt, nb, p->shift, p->n, p->nranks, p->split);
    free(cnt);
    if (bad) return ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    p->first = p->split[p->rank], p->last = p->split[p->rank + 1];
    return ULAM_OK;
}

/* The first split: blocks of raw entries by row (a sum over ranks), into split0. */
static int first_split(const ulam_part *p, const ulam_comm *c, const entry *e, int64_t len, int64_t *split0, ulam_error *err)
{
    int64_t raw = p->set == 0 ? len : 0; /* one set's */
    if (c->nranks > 1 && c->sum(c->ctx, &raw, 1)) return ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    int shift0 = ulam__system_block_shift(p->n, raw);
    int64_t nb = (p->n + ((int64_t)1 << shift0) - 1) >> shift0, *cnt = calloc((size_t)nb + 1, sizeof *cnt);
    if (agree(c, cnt ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld block counts", (long long)nb), err)) {
        free(cnt);
        return err->status;
    }
    for (int64_t x = 0; p->set == 0 && x < len; x++) cnt[e[x].i >> shift0]++;
    int bad = c->nranks > 1 && c->sum(c->ctx, cnt, (int)nb);
    if (!bad) split_counts(cnt, nb, shift0, p->n, p->nranks, split0);
    free(cnt);
    return bad ? ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds") : ULAM_OK;
}

/* The rows of M and M' that `what` names into p from this rank's entries e (freed): gathered
 * by a first split of raw entries, summed, then moved to the final split. */
static int build(ulam_part *p, const ulam_comm *c, int what, entry *e, int64_t len, ulam_error *err)
{
    int P = p->nranks;
    int64_t *split0 = calloc((size_t)P + 1, sizeof *split0), n2 = 0;
    int status = agree(c, split0 ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a split"), err);
    if (!status) status = agree(c, first_split(p, c, e, len, split0, err), err);
    ulam_csr *A = NULL, *B = NULL, *T = NULL;
    if (!status) status = agree(c, gather_rows(p, c, split0, e, len, 0, &A, err), err); /* frees e */
    else free(e);
    if (!status) status = agree(c, ulam__csr_canonicalize(A, 1) ? ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory to sort a row") : 0, err);
    if (!status) status = agree(c, final_split(p, c, A, split0[p->rank], what == ULAM_PART_MT, err), err);
    if (!status && what != ULAM_PART_MT && memcmp(split0, p->split, ((size_t)P + 1) * sizeof *split0)) {
        entry *f = entries_of(A, split0[p->rank], &n2); /* M's summed rows to the final split */
        status = agree(c, f ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for entries"), err);
        if (!status) status = agree(c, gather_rows(p, c, p->split, f, n2, 0, &B, err), err);
        else free(f);
        if (!status) ulam_csr_free(A), A = B, B = NULL;
        split0[p->rank] = p->first;
    }
    if (!status && what != ULAM_PART_M) { /* M' from M's summed entries, in row order */
        entry *f = entries_of(A, split0[p->rank], &n2);
        if (what == ULAM_PART_MT) A = ulam_csr_free(A);
        status = agree(c, f ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for entries"), err);
        if (!status) status = agree(c, gather_rows(p, c, p->split, f, n2, 1, &T, err), err);
        else free(f);
        if (!status) take(T, &p->t);
    }
    if (!status && what != ULAM_PART_MT) take(A, &p->m), A = NULL;
    ulam_csr_free(A), ulam_csr_free(B);
    free(split0);
    return status;
}

/* b's entries at this rank's rows from the vector file rhs (every rank reads it whole). */
static int read_b(ulam_part *p, const char *rhs, ulam_error *err)
{
    double *b = NULL;
    int64_t n = 0;
    int status = ulam_mm_read_vector(rhs, &b, &n, err);
    if (!status && n != p->n)
        status = ulam__fail(err, ULAM_EDIM, 0, -1, "b of %lld entries (the order of M), got %lld", (long long)p->n, (long long)n);
    if (status) snprintf(err->file, sizeof err->file, "%s", rhs);
    int64_t rows = p->last - p->first;
    if (!status && !(p->b = ulam__malloc((size_t)rows + 1, sizeof *p->b)))
        status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld entries of b", (long long)rows);
    if (!status) memcpy(p->b, b + p->first, (size_t)rows * sizeof *b);
    free(b);
    return status;
}

/* Open this rank's rows of the Matrix Market system at path with b from rhs. */
int ulam_part_open_mtx(const char *path, const char *rhs, const ulam_comm *comm, int what, ulam_part **out, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !rhs) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix path and a b path");
    int status = ulam__part_args(comm, what, out, err);
    if (status) return status;
    ulam_part *p = calloc(1, sizeof *p);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    ulam__mm_coord h;
    entry *e = NULL;
    int64_t len = 0;
    if (!p) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a part");
    else if (fd < 0 || fstat(fd, &st) || !S_ISREG(st.st_mode)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a readable Matrix Market file");
    else status = ulam__mm_coord_header(fd, path, &h, err);
    if (p) {
        p->sets = comm->sets > 1 ? comm->sets : 1, p->nranks = comm->nranks / p->sets;
        p->set = comm->rank / p->nranks, p->rank = comm->rank % p->nranks;
        p->split = ulam__malloc((size_t)p->nranks + 1, sizeof *p->split);
        if (!status && !p->split) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the split");
    }
    if (!(status = agree(comm, status, err))) {
        p->n = h.n;
        status = read_range(fd, &h, p, comm, &e, &len, err);
    }
    if (fd >= 0) close(fd);
    if (!status) status = build(p, comm, what, e, len, err); /* frees e */
    else free(e);
    if (!status) status = read_b(p, rhs, err);
    if (!status && p->m.rowptr) status = ulam__part_sums(p, &p->m, err);
    if (!status && p->t.rowptr) status = ulam__part_sums(p, &p->t, err);
    status = agree(comm, status, err);
    if (status) {
        ulam_part_free(p);
        return status;
    }
    *out = p;
    return ULAM_OK;
}
