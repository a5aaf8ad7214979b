/* One rank's rows of a prepared system, read by its blocks alone (see ulam_dist.h).
 *
 * The split is by blocks of the prepared file (2^shift rows each), so it is the same on every
 * rank and every block is verified whole against its checksum: rank r owns the blocks from the
 * first whose entries start at or past r/nranks of all entries.  Nothing else of the file is
 * read but the header, the checksum table and one row pointer a step of the split's searches. */
#include "part.h"
#include "cache.h"

#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { HEADER_BYTES = 1024 };

/* Read len bytes at off of fd into p; 0, or -1 on a short read or an error. */
static int read_at(int fd, void *p, size_t len, uint64_t off)
{
    for (size_t got = 0; got < len;) {
        ssize_t r = pread(fd, (char *)p + got, len - got, (off_t)(off + got));
        if (r <= 0) return -1;
        got += (size_t)r;
    }
    return 0;
}

/* rowptr[i] of the part's array (byte offset at) read from the file into *v. */
static int rowptr_at(int fd, uint64_t at, int64_t i, int64_t *v)
{
    return read_at(fd, v, 8, at + (uint64_t)i * 8);
}

/* The first block k in [0, nb] whose first row's entries start at or past want (nb when none). */
static int first_block_from(int fd, uint64_t at, int shift, int64_t n, int64_t nb, int64_t want, int64_t *k)
{
    int64_t lo = 0, hi = nb;
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2, row = mid << shift, v;
        if (rowptr_at(fd, at, row < n ? row : n, &v)) return -1;
        if (v >= want) hi = mid;
        else lo = mid + 1;
    }
    *k = lo;
    return 0;
}

/* The split of nb blocks among nranks ranks by entries: block boundaries kb[0 .. nranks]. */
static int split_blocks(int fd, uint64_t at, int shift, int64_t n, int64_t nb, int64_t nnz, int nranks, int64_t *kb)
{
    kb[0] = 0, kb[nranks] = nb;
    for (int r = 1; r < nranks; r++) {
        int64_t want = nnz / nranks * r + nnz % nranks * r / nranks;
        if (first_block_from(fd, at, shift, n, nb, want, &kb[r])) return -1;
        if (kb[r] < kb[r - 1]) kb[r] = kb[r - 1];
    }
    return 0;
}

/* Read and verify rows [p->first, p->last) of the array at offsets off[0..2] (rowptr, colidx, val),
 * their checksums from sums[k0 ..]. */
static int read_rows(int fd, const ulam__layout *L, const uint64_t *off, const uint64_t *sums, int64_t k0, ulam_part *p,
                     ulam__rows *A, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    A->rowptr = ulam__malloc((size_t)rows + 1, sizeof *A->rowptr);
    if (!A->rowptr) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld row pointers", (long long)rows + 1);
    if (read_at(fd, A->rowptr, (size_t)(rows + 1) * 8, off[0] + (uint64_t)p->first * 8))
        return ulam__fail(err, ULAM_EIO, 0, p->first, "row pointers readable from the file");
    int64_t a = A->rowptr[0], e = A->rowptr[rows];
    for (int64_t i = 0; i < rows; i++)
        if (!(A->rowptr[i] >= 0 && A->rowptr[i] <= A->rowptr[i + 1] && A->rowptr[i + 1] <= L->nnz))
            return ulam__fail(err, ULAM_ESYNTAX, 0, p->first + i, "row pointers rising within the %lld entries",
                              (long long)L->nnz);
    A->nnz = e - a;
    A->col = ulam__malloc((size_t)A->nnz, sizeof *A->col);
    A->val = ulam__malloc((size_t)A->nnz, sizeof *A->val);
    if (!A->col || !A->val) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld entries", (long long)A->nnz);
    if (read_at(fd, A->col, (size_t)A->nnz * 4, off[1] + (uint64_t)a * 4) ||
        read_at(fd, A->val, (size_t)A->nnz * 8, off[2] + (uint64_t)a * 8))
        return ulam__fail(err, ULAM_EIO, 0, p->first, "entries readable from the file");
    for (int64_t r0 = p->first; r0 < p->last; r0 += (int64_t)1 << L->shift) {
        int64_t r1 = r0 + ((int64_t)1 << L->shift) < p->last ? r0 + ((int64_t)1 << L->shift) : p->last;
        const int64_t *rp = A->rowptr + (r0 - p->first);
        if (!ulam__system_block_ok(rp, r1 - r0, A->col + (rp[0] - a), A->val + (rp[0] - a), L->ncols,
                                   sums[k0 + (r0 >> L->shift)]))
            return ulam__fail(err, ULAM_ESYNTAX, 0, r0,
                              "a block matching its checksum with columns in range, rising, and finite nonzero "
                              "values (rows %lld .. %lld are damaged)", (long long)r0 + 1, (long long)r1);
    }
    for (int64_t i = 0; i <= rows; i++) A->rowptr[i] -= a;
    return ULAM_OK;
}

/* Read and verify b's entries at rows [p->first, p->last) (block checksums from sums[k0 ..]). */
static int read_rhs(int fd, const ulam__layout *L, const uint64_t *sums, int64_t k0, ulam_part *p, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    p->b = ulam__malloc((size_t)rows, sizeof *p->b);
    if (!p->b) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld entries of b", (long long)rows);
    if (read_at(fd, p->b, (size_t)rows * 8, L->off[3] + (uint64_t)p->first * 8))
        return ulam__fail(err, ULAM_EIO, 0, p->first, "b readable from the file");
    for (int64_t r0 = p->first; r0 < p->last; r0 += (int64_t)1 << L->shift) {
        int64_t r1 = r0 + ((int64_t)1 << L->shift) < p->last ? r0 + ((int64_t)1 << L->shift) : p->last;
        int ok = ulam__system_hash(p->b + (r0 - p->first), (size_t)(r1 - r0) * 8) == sums[k0 + (r0 >> L->shift)];
        for (int64_t i = r0; ok && i < r1; i++) ok = isfinite(p->b[i - p->first]);
        if (!ok)
            return ulam__fail(err, ULAM_ESYNTAX, 0, r0, "a block of b matching its checksum, finite (rows %lld .. %lld)",
                              (long long)r0 + 1, (long long)r1);
    }
    return ULAM_OK;
}

/* Each of this rank's rows' sum of |entries| in A. */
int ulam__part_sums(const ulam_part *p, ulam__rows *A, ulam_error *err)
{
    int64_t rows = p->last - p->first;
    A->rowsum = ulam__malloc((size_t)rows, sizeof *A->rowsum);
    if (!A->rowsum) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld row sums", (long long)rows);
    for (int64_t i = 0; i < rows; i++) {
        double s = 0.0;
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) s += fabs(A->val[q]);
        if (!isfinite(s)) return ulam__fail(err, ULAM_EOVERFLOW, 0, p->first + i, "a row whose |entries| sum to a finite number");
        A->rowsum[i] = s;
    }
    return ULAM_OK;
}

/* Read the header and checksum table of fd (a file of len bytes) into L and *sums (malloc'd). */
static int read_layout(int fd, uint64_t len, int what, ulam__layout *L, uint64_t **sums, ulam_error *err)
{
    unsigned char h[HEADER_BYTES];
    if (len < HEADER_BYTES || read_at(fd, h, sizeof h, 0)) {
        if (len >= 8 && !read_at(fd, h, 8, 0) && memcmp(h, "ulamSYS1", 8))
            return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam prepared system (magic 'ulamSYS1')");
        return ulam__fail(err, len ? ULAM_ESYNTAX : ULAM_EBANNER, 0, -1,
                          len ? "a header of 1024 bytes (truncated)" : "an ulam prepared system (the file is empty)");
    }
    int status = ulam__system_header(h, len, L, err);
    if (status) return status;
    if (!L->has_matrix || L->n != L->ncols) /* b may be absent: single source needs none (p->b NULL) */
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a prepared square system (ulam prepare M.mtx [--rhs b.mtx])");
    if (what != ULAM_PART_M && !L->has_tr)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "M' in the file for forward walks (ulam prepare --transpose)");
    int64_t nsums = L->nblocks[0] + L->nblocks[1] + L->nblocks[2];
    *sums = ulam__malloc((size_t)nsums, 8);
    if (!*sums) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld checksums", (long long)nsums);
    if (read_at(fd, *sums, (size_t)nsums * 8, L->off[7]) || ulam__system_hash(*sums, (size_t)nsums * 8) != L->sums_hash)
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a checksum table matching its checksum (the table is damaged)");
    return ULAM_OK;
}

/* Split and read this rank's rows of fd (see ulam_part_open). */
static int open_part(int fd, uint64_t len, const ulam_comm *c, int what, ulam_part *p, ulam_error *err)
{
    ulam__layout L;
    uint64_t *sums = NULL;
    int status = read_layout(fd, len, what, &L, &sums, err);
    int part = what == ULAM_PART_MT ? 2 : 0; /* the array the split balances */
    const uint64_t off[2][3] = {{L.off[0], L.off[1], L.off[2]}, {L.off[4], L.off[5], L.off[6]}};
    p->sets = c->sets > 1 ? c->sets : 1, p->nranks = c->nranks / p->sets;
    p->set = c->rank / p->nranks, p->rank = c->rank % p->nranks, p->n = L.n, p->shift = L.shift;
    p->split = ulam__malloc((size_t)p->nranks + 1, sizeof *p->split);
    if (!status && !p->split) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the split");
    if (!status && split_blocks(fd, off[part == 2][0], L.shift, L.n, L.nblocks[part], L.nnz, p->nranks, p->split))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "row pointers readable from the file");
    if (!status) {
        for (int r = 0; r <= p->nranks; r++) p->split[r] = p->split[r] << L.shift < L.n ? p->split[r] << L.shift : L.n;
        p->first = p->split[p->rank], p->last = p->split[p->rank + 1];
        if (what != ULAM_PART_MT) status = read_rows(fd, &L, off[0], sums, L.first[0], p, &p->m, err);
        if (!status && what != ULAM_PART_M) status = read_rows(fd, &L, off[1], sums, L.first[2], p, &p->t, err);
    }
    if (!status && L.has_rhs) status = read_rhs(fd, &L, sums, L.first[1], p, err);
    if (!status && p->m.rowptr) status = ulam__part_sums(p, &p->m, err);
    if (!status && p->t.rowptr) status = ulam__part_sums(p, &p->t, err);
    free(sums);
    return status;
}

/* Open this rank's rows of the prepared system at path. */
int ulam_part_open(const char *path, const ulam_comm *comm, int what, ulam_part **out, ulam_error *err)
{
    ulam__clear(err);
    if (!path) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path, a comm and a result");
    int status = ulam__part_args(comm, what, out, err);
    if (status) return status;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        if (fd >= 0) close(fd);
        return ulam__fail(err, ULAM_EIO, 0, -1, "a readable prepared system file");
    }
    ulam_part *p = calloc(1, sizeof *p);
    status = p ? open_part(fd, (uint64_t)st.st_size, comm, what, p, err)
               : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a part");
    close(fd);
    if (status) {
        ulam_part_free(p);
        return status;
    }
    *out = p;
    return ULAM_OK;
}

/* Check a comm, what and out of ulam_part_open (*out set to NULL). */
int ulam__part_args(const ulam_comm *comm, int what, ulam_part **out, ulam_error *err)
{
    if (!comm || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path, a comm and a result");
    *out = NULL;
    if (comm->nranks < 1 || comm->rank < 0 || comm->rank >= comm->nranks ||
        (comm->nranks > 1 && (!comm->exchange || !comm->sum)))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "0 <= rank < nranks, and an exchange and a sum with more than one rank");
    if (what < ULAM_PART_M || what > ULAM_PART_BOTH)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "ULAM_PART_M, ULAM_PART_MT or ULAM_PART_BOTH, got %d", what);
    if (comm->sets < 0 || (comm->sets > 1 && comm->nranks % comm->sets))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "sets dividing the %d ranks, got %d", comm->nranks, comm->sets);
    return ULAM_OK;
}

/* Free a part. */
ulam_part *ulam_part_free(ulam_part *p)
{
    if (!p) return NULL;
    const ulam__rows *A[2] = {&p->m, &p->t};
    for (int k = 0; k < 2; k++) free(A[k]->rowptr), free(A[k]->col), free(A[k]->val), free(A[k]->rowsum);
    free(p->b), free(p->split);
    free(p);
    return NULL;
}

/* The order and this rank's rows. */
int64_t ulam_part_rows(const ulam_part *p, int64_t *first, int64_t *last, int64_t *nnz)
{
    if (!p) return -1;
    if (first) *first = p->first;
    if (last) *last = p->last;
    if (nnz) *nnz = p->m.rowptr ? p->m.nnz : p->t.nnz;
    return p->n;
}

/* The rank owning row s (binary search of the split). */
int ulam__part_owner(const ulam_part *p, int64_t s)
{
    int lo = 0, hi = p->nranks - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (p->split[mid] <= s) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* The largest of every rank's nonnegative x[0 .. n), entry by entry (each rank's bits in its own
 * slot of one sum, so exact). */
int ulam__dist_largest_n(const ulam_comm *c, double *x, int n)
{
    if (c->nranks == 1) return 0;
    int64_t *v = calloc((size_t)c->nranks * (size_t)n, sizeof *v);
    if (!v) return 1;
    memcpy(&v[(size_t)c->rank * (size_t)n], x, (size_t)n * sizeof *x);
    int bad = c->sum(c->ctx, v, c->nranks * n);
    for (int r = 0; !bad && r < c->nranks; r++)
        for (int k = 0; k < n; k++) {
            double y;
            memcpy(&y, &v[(size_t)r * (size_t)n + (size_t)k], 8);
            if (y > x[k]) x[k] = y;
        }
    free(v);
    return bad;
}

/* The largest of every rank's nonnegative x. */
int ulam__dist_largest(const ulam_comm *c, double *x)
{
    return ulam__dist_largest_n(c, x, 1);
}
