/* Prepared systems: M and b of (I - M) x = b as one file mapped read-only and used in place
 * (docs/prepared.md).  The header is 1024 bytes of little-endian 64-bit words:
 *
 *   word  0      magic "ulamSYS1"
 *   word  1      format version (2) | header bytes (1024) << 32
 *   word  2      flags: 1 matrix, 2 b, 4 certificate, 8 transpose
 *   words 3-5    nrows, ncols, nnz
 *   words 6-9    byte offsets of rowptr int64[nrows + 1], colidx int32[nnz], val double[nnz],
 *                b double[nrows] (0 when absent), each a multiple of 4096
 *   word  10     the file's length in bytes
 *   words 11-12  the source's tag (the CLI's cache: XXH3-128 of the source file; 0 from `ulam prepare`)
 *   word  13     the Jacobi damping omega that made M (double; 0: M as read)
 *   word  14     log2 of the rows in a block (the unit of verification)
 *   word  15     byte offset of the checksum table (XXH3-64 of each block: M's, b's, M^T's)
 *   word  16     XXH3-64 of the checksum table
 *   words 17-19  byte offsets of M^T's rowptr int64[ncols + 1], colidx int32[nnz], val double[nnz]
 *   words 32-95  the certificate section: word 32 its version (3) | its bytes << 32, then
 *                version 3's fields (see put_cert), the first the content hash of M's blocks
 *   words 96-126 the bounds extension (a section of its own, versioned apart, written and
 *                trusted only with the certificate, which binds M): word 96 its version (1) |
 *                its bytes << 32, then the walk kernel's bounds over every state and b's scores
 *                (see put_bounds); 0 when absent, and a reader that does not know its version
 *                ignores it
 *   word  127    XXH3-64 of bytes 0 .. 1015
 *
 * Opening checks the header, the checksum table and the certificate's binding, and reads no
 * array beyond rowptr[0] and rowptr[nrows].  Each block of rows is verified the first time
 * anything reads it (its checksum, its rowptr rising within the entries, its columns in range,
 * sorted and unique, its values finite and nonzero; b's block hashed and finite), once: an atomic
 * state a block, so the two walk threads may race to verify one and agree.  ulam_system_matrix,
 * _rhs and _transpose verify their arrays whole; ulam_system_lazy hands the arrays out unverified
 * for a solver given ulam_walk_opts.system, whose kernel verifies each row's block before it
 * builds the row (so a one-row query reads a few blocks). */
#include "cache.h"
#include "defaults.h"
#include "reach.h"

#include <fcntl.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#define XXH_STATIC_LINKING_ONLY /* XXH3_state_t on the stack */
#include <xxhash.h>

enum {
    HEADER = 1024, WORDS = HEADER / 8, ALIGN = 4096, VERSION = 2,
    F_MATRIX = 1, F_RHS = 2, F_CERT = 4, F_TRANSPOSE = 8,
    W_FLAGS = 2, W_DIMS = 3, W_OFF = 6, W_LEN = 10, W_TAG = 11, W_OMEGA = 13, W_SHIFT = 14, W_SUMS = 15,
    W_SUMS_HASH = 16, W_TOFF = 17,
    W_CERT = 32, W_SUM = WORDS - 1, CERT_VERSION = 3, CERT_WORDS = 37,
    W_BOUNDS = 96, BOUNDS_VERSION = 1, BOUNDS_WORDS = 16,
    BLOCK_ENTRIES = 128 /* entries a block aims at: a random row read verifies ~16 rows, not ~128 */
};
static const char MAGIC[8] = {'u', 'l', 'a', 'm', 'S', 'Y', 'S', '1'};

/* Which arrays a block belongs to. */
enum { PART_M = 0, PART_B = 1, PART_T = 2 };

/* The verification state of a block. */
enum { UNCHECKED = 0, GOOD = 1, BAD = 2 };

struct ulam_system {
    ulam_csr csr;          /* pointers into the mapping */
    ulam_csr tr;           /* M^T (prepare --transpose), or nrows 0 */
    const double *b;
    int64_t n;
    int has_matrix, has_cert, has_tr;
    double omega;
    ulam_certificate cert;
    int shift;             /* a block holds 2^shift rows */
    int64_t nblocks[3];    /* blocks of M, b, M^T (0: absent) */
    int64_t first[3];      /* each part's first entry in sums[] and state[] */
    const uint64_t *sums;  /* the checksum table */
    _Atomic unsigned char *state; /* one a block, as sums[] */
    int has_bounds;
    ulam__reach bounds;    /* the bounds extension (seen and K unset) */
    void *map;             /* the mapping (NULL: borrowed memory) */
    size_t map_bytes;
    int fd;                /* the file, for rows read by pread (-1: borrowed memory) */
    uint64_t off[4];       /* byte offsets of rowptr, colidx, val and b in the file */
    _Atomic int64_t *checked; /* [0] blocks verified, [1] rows of M they hold */
    size_t keep;           /* a mapping of more bytes is released as passes over it go (ulam__system_release) */
};

/* XXH3-64 of bytes p[0 .. n). */
static uint64_t hash(const void *p, size_t n)
{
    return (uint64_t)XXH3_64bits(p, n);
}

/* Nonzero on a little-endian machine (the only one that can use the file in place). */
static int little_endian(void)
{
    const uint16_t one = 1;
    unsigned char c;
    memcpy(&c, &one, 1);
    return c == 1;
}

/* A double's bits as a header word, and back. */
static uint64_t bits(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}
static double real(uint64_t u)
{
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* One radius as 8 words: rho, lower, upper, rowsum_max, colsum_max, iterations, converged,
 * seconds. */
static void put_power(uint64_t *w, const ulam_power *p)
{
    w[0] = bits(p->rho), w[1] = bits(p->lower), w[2] = bits(p->upper);
    w[3] = bits(p->rowsum_max), w[4] = bits(p->colsum_max);
    w[5] = (uint64_t)(int64_t)p->iterations, w[6] = (uint64_t)p->converged, w[7] = bits(p->seconds);
}
static void get_power(const uint64_t *w, ulam_power *p)
{
    *p = (ulam_power){.rho = real(w[0]), .lower = real(w[1]), .upper = real(w[2]), .rowsum_max = real(w[3]),
                      .colsum_max = real(w[4]), .iterations = (int)(int64_t)w[5], .converged = w[6] != 0,
                      .seconds = real(w[7])};
}

/* Certificate version 3 from word 33: the content hash of M's blocks (XXH3-64 of their
 * checksums: the arrays it certifies), continue_q, tol, max_iter, rowsum min and max, colsum min
 * and max, then |M|, M^ adjoint, M^ forward (8 words each), the three verdicts and the guard's
 * computed bits.  A later version appends fields: the section's bytes say how many there are. */
static void put_cert(uint64_t *w, const ulam_certificate *c, uint64_t content)
{
    w[0] = (uint64_t)CERT_VERSION | (uint64_t)(CERT_WORDS * 8) << 32;
    w[1] = content;
    w[2] = bits(c->continue_q), w[3] = bits(c->tol), w[4] = (uint64_t)(int64_t)c->max_iter;
    w[5] = bits(c->rowsum_min), w[6] = bits(c->rowsum_max), w[7] = bits(c->colsum_min), w[8] = bits(c->colsum_max);
    put_power(w + 9, &c->guard.abs);
    put_power(w + 17, &c->guard.hat[0]);
    put_power(w + 25, &c->guard.hat[1]);
    w[33] = (uint64_t)c->guard.verdict_abs, w[34] = (uint64_t)c->guard.verdict_hat[0];
    w[35] = (uint64_t)c->guard.verdict_hat[1], w[36] = (uint64_t)c->guard.computed;
}

/* Read a certificate of version 3 or later (the fields version 3 has): 1, with *content its
 * content hash; 0 when the section is of an earlier version, too short for its version, or
 * inconsistent. */
static int get_cert(const uint64_t *w, ulam_certificate *c, uint64_t *content)
{
    uint64_t version = w[0] & 0xffffffffu, bytes = w[0] >> 32;
    if (version < CERT_VERSION || bytes < CERT_WORDS * 8 || bytes > (uint64_t)(W_SUM - W_CERT) * 8) return 0;
    *content = w[1];
    *c = (ulam_certificate){.continue_q = real(w[2]), .tol = real(w[3]), .max_iter = (int)(int64_t)w[4],
                            .rowsum_min = real(w[5]), .rowsum_max = real(w[6]), .colsum_min = real(w[7]),
                            .colsum_max = real(w[8])};
    get_power(w + 9, &c->guard.abs);
    get_power(w + 17, &c->guard.hat[0]);
    get_power(w + 25, &c->guard.hat[1]);
    for (int k = 0; k < 3; k++)
        if (w[33 + k] > ULAM_VERDICT_UNKNOWN) return 0;
    if (w[36] > (uint64_t)ULAM_GUARD_ALL) return 0;
    c->guard.verdict_abs = (int)w[33], c->guard.verdict_hat[0] = (int)w[34], c->guard.verdict_hat[1] = (int)w[35];
    c->guard.computed = (int)w[36];
    c->guard.continue_q = c->continue_q;
    c->guard.kernel_alpha = 1.0; /* certificates are made at kernel exponent 1 (ulam_certificate_compute) */
    return 1;
}

/* The bounds extension, version 1, from word 96: the continuation and exponent they were made
 * for, the largest weight factor, continuation and weight growth, the length tail's u and kappa,
 * flags (1 K has a negative entry, 2 tail certified, 4 b's scores present, 8 b has a positive
 * entry, 16 a negative one), then b's bmax, kbmax, gabs, g2abs and bad (ulam__reach's fields). */
static void put_bounds(uint64_t *w, const ulam__reach *R)
{
    w[0] = (uint64_t)BOUNDS_VERSION | (uint64_t)(BOUNDS_WORDS * 8) << 32;
    w[1] = bits(R->continue_q), w[2] = bits(R->alpha), w[3] = bits(R->fbig), w[4] = bits(R->qmax);
    w[5] = bits(R->growth), w[6] = bits(R->tail_u), w[7] = bits(R->kappa);
    w[8] = (uint64_t)(R->neg ? 1 : 0) | (R->tail ? 2 : 0) | (R->b ? 4 : 0) | (R->bpos ? 8 : 0) | (R->bneg ? 16 : 0);
    w[9] = bits(R->bmax), w[10] = bits(R->kbmax), w[11] = bits(R->gabs), w[12] = bits(R->g2abs);
    w[13] = (uint64_t)R->bad;
}

/* Read the bounds extension into R (b: the file's b, which its scores are of); 0 when absent, of
 * another version or inconsistent. */
static int get_bounds(const uint64_t *w, const double *b, int64_t n, ulam__reach *R)
{
    if (w[0] != ((uint64_t)BOUNDS_VERSION | (uint64_t)(BOUNDS_WORDS * 8) << 32) || w[8] > 31) return 0;
    *R = (ulam__reach){.bounds = 1, .continue_q = real(w[1]), .alpha = real(w[2]), .fbig = real(w[3]),
                       .qmax = real(w[4]), .growth = real(w[5]), .tail_u = real(w[6]), .kappa = real(w[7]),
                       .neg = (w[8] & 1) != 0, .tail = (w[8] & 2) != 0, .bpos = (w[8] & 8) != 0,
                       .bneg = (w[8] & 16) != 0, .bmax = real(w[9]), .kbmax = real(w[10]), .gabs = real(w[11]),
                       .g2abs = real(w[12]), .bad = (int64_t)w[13]};
    if ((w[8] & 4) && b) R->b = b;
    else R->bmax = R->kbmax = R->gabs = R->g2abs = INFINITY, R->bad = -1;
    return R->continue_q >= 0 && R->qmax >= 0 && R->fbig >= 0 && R->growth >= 1 && R->bad >= -1 && R->bad < n;
}

/* Round x up to the alignment. */
static uint64_t aligned(uint64_t x)
{
    return (x + ALIGN - 1) / ALIGN * ALIGN;
}

/* Write bytes p[0 .. n) and then zeros up to the next boundary; *at advances. */
static int put_part(FILE *f, const void *p, size_t n, uint64_t *at)
{
    static const unsigned char zeros[ALIGN];
    if (n && fwrite(p, 1, n, f) != n) return 0;
    size_t pad = (size_t)(aligned(*at + n) - (*at + n));
    *at += n + pad;
    return !pad || fwrite(zeros, 1, pad, f) == pad;
}

/* log2 of the rows of a block: at most about BLOCK_ENTRIES entries of the matrix (b alone: 1024 rows),
 * from 16 to 65536 rows. */
int ulam__system_block_shift(int64_t n, int64_t nnz)
{
    double want = nnz > 0 ? (double)BLOCK_ENTRIES * (double)n / (double)nnz : 1024.0;
    int s = 4;
    while (s < 16 && (double)((int64_t)1 << (s + 1)) <= want) s++; /* at most BLOCK_ENTRIES entries on average */
    return s;
}

/* Blocks of 2^shift rows covering n rows. */
static int64_t block_count(int64_t n, int shift)
{
    return (n + ((int64_t)1 << shift) - 1) >> shift;
}

/* The checksum of a block of rows rows: their row pointers rp[0 .. rows] and the entries
 * rp[0] .. rp[rows] - 1 at col and val. */
static uint64_t block_hash(const int64_t *rp, int64_t rows, const int32_t *col, const double *val)
{
    XXH3_state_t st;
    XXH3_64bits_reset(&st);
    int64_t a = rp[0], e = rp[rows];
    XXH3_64bits_update(&st, rp, (size_t)(rows + 1) * sizeof *rp);
    if (e > a) {
        XXH3_64bits_update(&st, col, (size_t)(e - a) * sizeof *col);
        XXH3_64bits_update(&st, val, (size_t)(e - a) * sizeof *val);
    }
    return (uint64_t)XXH3_64bits_digest(&st);
}

/* The checksum of rows r0 .. r1 - 1 of A (its rowptr checked): rowptr[r0 .. r1], then the
 * columns and values of those rows. */
static uint64_t csr_block_hash(const ulam_csr *A, int64_t r0, int64_t r1)
{
    int64_t a = A->rowptr[r0];
    return block_hash(A->rowptr + r0, r1 - r0, A->colidx + a, A->val + a);
}

/* The checksums of A's blocks into sums[0 .. blocks). */
static void csr_sums(const ulam_csr *A, int shift, uint64_t *sums)
{
    int64_t nb = block_count(A->nrows, shift);
    for (int64_t k = 0; k < nb; k++) {
        int64_t r0 = k << shift, r1 = r0 + ((int64_t)1 << shift) < A->nrows ? r0 + ((int64_t)1 << shift) : A->nrows;
        sums[k] = csr_block_hash(A, r0, r1);
    }
}

/* The checksums of b's blocks into sums[0 .. blocks). */
static void vec_sums(const double *b, int64_t n, int shift, uint64_t *sums)
{
    int64_t nb = block_count(n, shift);
    for (int64_t k = 0; k < nb; k++) {
        int64_t r0 = k << shift, r1 = r0 + ((int64_t)1 << shift) < n ? r0 + ((int64_t)1 << shift) : n;
        sums[k] = hash(b + r0, (size_t)(r1 - r0) * sizeof *b);
    }
}

/* An empty description. */
ulam_system_desc ulam__system_desc_defaults(void)
{
    return (ulam_system_desc){.M = NULL, .b = NULL, .n = 0, .tag = {0, 0}, .omega = 0.0, .cert = NULL, .transpose = 0};
}

/* Check what a prepared system is written from (ulam_system_write_file's refusals). */
int ulam__system_desc_check(FILE *f, const ulam_system_desc *d)
{
    if (!f || !d || (!d->M && !d->b) || !little_endian() || (d->transpose && !d->M)) return ULAM_EINVAL;
    const ulam_csr *M = d->M;
    int64_t n = M ? M->nrows : d->n;
    if (n < 0 || (M && d->n != M->nrows && d->b)) return ULAM_EINVAL;
    if (d->cert && (d->cert->guard.kernel_alpha != 1.0 || !M)) return ULAM_EINVAL; /* exponent 1's guards, of M */
    if (M && ulam_csr_check(M)) return ULAM_EINVAL; /* never a file that fails its own verification */
    for (int64_t i = 0; d->b && i < n; i++)
        if (!isfinite(d->b[i])) return ULAM_EINVAL;
    return ULAM_OK;
}

/* Write a prepared system (d checked) to f with the bounds R (NULL: none). */
int ulam__system_write_checked(FILE *f, const ulam_system_desc *d, const ulam__reach *R)
{
    const ulam_csr *M = d->M;
    int64_t n = M ? M->nrows : d->n, nnz = M ? M->rowptr[M->nrows] : 0;
    ulam_csr *T = NULL;
    if (d->transpose && ulam_csr_transpose(M, &T)) return ULAM_ENOMEM;
    int shift = ulam__system_block_shift(n, nnz);
    int64_t nb[3] = {M ? block_count(n, shift) : 0, d->b ? block_count(n, shift) : 0, T ? block_count(T->nrows, shift) : 0};
    size_t nsums = (size_t)(nb[0] + nb[1] + nb[2]);
    uint64_t *sums = malloc((nsums ? nsums : 1) * sizeof *sums);
    if (!sums) {
        ulam_csr_free(T);
        return ULAM_ENOMEM;
    }
    if (M) csr_sums(M, shift, sums);
    if (d->b) vec_sums(d->b, n, shift, sums + nb[0]);
    if (T) csr_sums(T, shift, sums + nb[0] + nb[1]);
    uint64_t w[WORDS] = {0}, at = aligned(HEADER);
    enum { PARTS = 8 };
    size_t part[PARTS] = {M ? ((size_t)n + 1) * 8 : 0, (size_t)nnz * 4, (size_t)nnz * 8, d->b ? (size_t)n * 8 : 0,
                          T ? ((size_t)T->nrows + 1) * 8 : 0, T ? (size_t)nnz * 4 : 0, T ? (size_t)nnz * 8 : 0,
                          nsums * 8};
    const void *src[PARTS] = {M ? (const void *)M->rowptr : NULL, M ? (const void *)M->colidx : NULL,
                              M ? (const void *)M->val : NULL, d->b, T ? (const void *)T->rowptr : NULL,
                              T ? (const void *)T->colidx : NULL, T ? (const void *)T->val : NULL, sums};
    int present[PARTS] = {M != NULL, M != NULL, M != NULL, d->b != NULL, T != NULL, T != NULL, T != NULL, 1};
    const int word[PARTS] = {W_OFF, W_OFF + 1, W_OFF + 2, W_OFF + 3, W_TOFF, W_TOFF + 1, W_TOFF + 2, W_SUMS};
    memcpy(&w[0], MAGIC, 8);
    w[1] = (uint64_t)VERSION | (uint64_t)HEADER << 32;
    w[W_FLAGS] = (M ? F_MATRIX : 0) | (d->b ? F_RHS : 0) | (d->cert ? F_CERT : 0) | (T ? F_TRANSPOSE : 0);
    w[W_DIMS] = (uint64_t)n, w[W_DIMS + 1] = (uint64_t)(M ? M->ncols : 1), w[W_DIMS + 2] = (uint64_t)nnz;
    for (int k = 0; k < PARTS; k++) {
        w[word[k]] = present[k] ? at : 0;
        at = aligned(at + part[k]);
    }
    w[W_LEN] = at;
    w[W_TAG] = d->tag[0], w[W_TAG + 1] = d->tag[1];
    w[W_OMEGA] = bits(d->omega);
    w[W_SHIFT] = (uint64_t)shift;
    w[W_SUMS_HASH] = hash(sums, nsums * 8);
    if (d->cert) put_cert(w + W_CERT, d->cert, hash(sums, (size_t)nb[0] * 8));
    if (R && d->cert && M && M->nrows == M->ncols) put_bounds(w + W_BOUNDS, R);
    w[W_SUM] = hash(w, (size_t)W_SUM * 8);
    uint64_t pos = 0;
    int ok = put_part(f, w, HEADER, &pos);
    for (int k = 0; k < PARTS && ok; k++)
        if (present[k]) ok = put_part(f, src[k], part[k], &pos);
    free(sums);
    ulam_csr_free(T);
    return ok && pos == at ? ULAM_OK : ULAM_EIO;
}

/* Nonzero when an array of bytes at offset off lies inside a file of len bytes past the header. */
static int inside(uint64_t off, uint64_t bytes, uint64_t len)
{
    return off >= HEADER && off % ALIGN == 0 && off <= len && bytes <= len - off;
}

/* The CSR view of arrays at offsets off[0 .. 2] of p. */
static ulam_csr csr_at(const unsigned char *p, const uint64_t *off, uint64_t nrows, uint64_t ncols)
{
    return (ulam_csr){.nrows = (int64_t)nrows, .ncols = (int64_t)ncols, .rowptr = (int64_t *)(uintptr_t)(p + off[0]),
                      .colidx = (int32_t *)(uintptr_t)(p + off[1]), .val = (double *)(uintptr_t)(p + off[2])};
}

/* Check the header of the len bytes at p and fill s (its arrays point into p). */
/* Check a prepared file's header (its first HEADER bytes at p, the file len bytes long) and
 * give the layout it states: every array inside the file, at most 2^31 - 1 rows and columns. */
int ulam__system_header(const unsigned char *p, uint64_t len, ulam__layout *L, ulam_error *err)
{
    uint64_t w[WORDS];
    if (len == 0) return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam prepared system (the file is empty)");
    if (len < 8 || memcmp(p, MAGIC, 8))
        return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam prepared system (magic 'ulamSYS1')");
    if (!little_endian()) return ulam__fail(err, ULAM_EUNSUPPORTED, 0, -1, "a little-endian machine");
    if (len < HEADER)
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a header of %d bytes (the file has %llu: truncated)", HEADER,
                          (unsigned long long)len);
    memcpy(w, p, HEADER);
    if (hash(p, (size_t)W_SUM * 8) != w[W_SUM])
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1,
                          "a header matching its checksum (the header is damaged, or of a format before version 2)");
    if (w[1] != ((uint64_t)VERSION | (uint64_t)HEADER << 32))
        return ulam__fail(err, ULAM_EUNSUPPORTED, 0, -1, "format version %d (got %llu: prepare the file again)", VERSION,
                          (unsigned long long)(w[1] & 0xffffffffu));
    if (w[W_LEN] != len)
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a file of %llu bytes as its header states, got %llu (truncated?)",
                          (unsigned long long)w[W_LEN], (unsigned long long)len);
    uint64_t flags = w[W_FLAGS], n = w[W_DIMS], nc = w[W_DIMS + 1], nnz = w[W_DIMS + 2], shift = w[W_SHIFT];
    int m = (flags & F_MATRIX) != 0, r = (flags & F_RHS) != 0, t = (flags & F_TRANSPOSE) != 0;
    if ((flags & ~(uint64_t)(F_MATRIX | F_RHS | F_CERT | F_TRANSPOSE)) || (!m && !r) || (t && !m) || (!m && (flags & F_CERT)) ||
        n > ULAM_MAX_DIM || nc > ULAM_MAX_DIM || nnz > (uint64_t)INT64_MAX / 32 || (!m && (nnz || nc != 1)) || shift < 4 ||
        shift > 30)
        return ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "sizes that fit (got %llu x %llu, %llu entries, blocks of 2^%llu rows)",
                          (unsigned long long)n, (unsigned long long)nc, (unsigned long long)nnz, (unsigned long long)shift);
    int64_t nb[3] = {m ? block_count((int64_t)n, (int)shift) : 0, r ? block_count((int64_t)n, (int)shift) : 0,
                     t ? block_count((int64_t)nc, (int)shift) : 0};
    uint64_t nsums = (uint64_t)(nb[0] + nb[1] + nb[2]);
    const int word[8] = {W_OFF, W_OFF + 1, W_OFF + 2, W_OFF + 3, W_TOFF, W_TOFF + 1, W_TOFF + 2, W_SUMS};
    const char *name[8] = {"rowptr", "colidx", "val", "b", "rowptr of M^T", "colidx of M^T", "val of M^T", "checksums"};
    uint64_t bytes[8] = {m ? (n + 1) * 8 : 0, m ? nnz * 4 : 0, m ? nnz * 8 : 0, r ? n * 8 : 0,
                         t ? (nc + 1) * 8 : 0, t ? nnz * 4 : 0, t ? nnz * 8 : 0, nsums * 8};
    int present[8] = {m, m, m, r, t, t, t, 1};
    for (int k = 0; k < 8; k++)
        if (present[k] ? !inside(w[word[k]], bytes[k], len) : w[word[k]] != 0)
            return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "arrays inside the file at 4096-byte boundaries (%s is not)", name[k]);
    *L = (ulam__layout){.n = (int64_t)n, .ncols = (int64_t)nc, .nnz = (int64_t)nnz, .shift = (int)shift,
                        .has_matrix = m, .has_rhs = r, .has_tr = t, .sums_hash = w[W_SUMS_HASH],
                        .tag = {w[W_TAG], w[W_TAG + 1]}, .omega = real(w[W_OMEGA])};
    for (int k = 0; k < 8; k++) L->off[k] = w[word[k]];
    for (int k = 0; k < 3; k++) L->nblocks[k] = nb[k], L->first[k] = k ? L->first[k - 1] + nb[k - 1] : 0;
    return ULAM_OK;
}

/* XXH3-64 of n bytes: the prepared format's checksum of a b block or of the checksum table. */
uint64_t ulam__system_hash(const void *p, size_t n)
{
    return hash(p, n);
}

/* Parse the header at p (len bytes in all) into s, arrays used in place. */
static int parse(const unsigned char *p, size_t len, const uint64_t tag[2], ulam_system *s, ulam_error *err)
{
    uint64_t w[WORDS];
    ulam__layout L;
    int status = ulam__system_header(p, len, &L, err);
    if (status) return status;
    memcpy(w, p, HEADER);
    uint64_t flags = w[W_FLAGS], n = w[W_DIMS], nc = w[W_DIMS + 1], nnz = w[W_DIMS + 2], shift = w[W_SHIFT];
    int m = L.has_matrix, r = L.has_rhs, t = L.has_tr;
    const int64_t *nb = L.nblocks;
    uint64_t nsums = (uint64_t)(nb[0] + nb[1] + nb[2]);
    const uint64_t *sums = (const uint64_t *)(const void *)(p + w[W_SUMS]);
    if (hash(sums, (size_t)nsums * 8) != w[W_SUMS_HASH])
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a checksum table matching its checksum (the table is damaged)");
    if (tag && (w[W_TAG] != tag[0] || w[W_TAG + 1] != tag[1]))
        return ulam__fail(err, ULAM_ENOTFOUND, 0, -1, "a cache of the current source file (it changed)");
    *s = (ulam_system){.n = (int64_t)n, .has_matrix = m, .has_tr = t, .omega = real(w[W_OMEGA]), .shift = (int)shift,
                       .sums = sums, .fd = -1, .keep = ULAM__SYSTEM_KEEP, .off = {w[W_OFF], w[W_OFF + 1], w[W_OFF + 2], w[W_OFF + 3]}};
    for (int k = 0; k < 3; k++) s->nblocks[k] = nb[k], s->first[k] = k ? s->first[k - 1] + nb[k - 1] : 0;
    if (m) {
        s->csr = csr_at(p, w + W_OFF, n, nc);
        if (s->csr.rowptr[0] != 0 || s->csr.rowptr[n] != (int64_t)nnz)
            return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "rowptr from 0 to the %llu entries the header states",
                              (unsigned long long)nnz);
    }
    if (t) {
        s->tr = csr_at(p, w + W_TOFF, nc, n);
        if (s->tr.rowptr[0] != 0 || s->tr.rowptr[nc] != (int64_t)nnz)
            return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "rowptr of M^T from 0 to the %llu entries the header states",
                              (unsigned long long)nnz);
    }
    if (r) s->b = (const double *)(const void *)(p + w[W_OFF + 3]);
    uint64_t content = 0;
    s->has_cert = (flags & F_CERT) && get_cert(w + W_CERT, &s->cert, &content);
    if (s->has_cert && content != hash(sums, (size_t)nb[0] * 8))
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a certificate bound to the file's matrix (its content hash "
                          "differs: the arrays were replaced)");
    s->has_bounds = s->has_cert && m && nc == n && get_bounds(w + W_BOUNDS, s->b, (int64_t)n, &s->bounds);
    return ULAM_OK;
}

/* As ulam_system_open on bytes already in memory. */
int ulam_system_from_memory(const void *data, size_t bytes, const uint64_t tag[2], ulam_system **out, ulam_error *err)
{
    ulam__clear(err);
    if (!data || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "bytes and a result");
    *out = NULL;
    if ((uintptr_t)data % 8) return ulam__fail(err, ULAM_EINVAL, 0, -1, "bytes aligned to 8");
    ulam_system *s = malloc(sizeof *s);
    if (!s) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a system");
    int status = parse(data, bytes, tag, s, err);
    int64_t total = status ? 0 : s->nblocks[0] + s->nblocks[1] + s->nblocks[2];
    if (!status && (!(s->state = calloc((size_t)(total ? total : 1), sizeof *s->state)) ||
                    !(s->checked = calloc(2, sizeof *s->checked)))) {
        free((void *)s->state);
    free((void *)s->checked);
        status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the blocks' states");
    }
    if (status) {
        free(s);
        return status;
    }
    *out = s;
    return ULAM_OK;
}

/* Map the prepared system at path read-only. */
int ulam_system_open(const char *path, const uint64_t tag[2], ulam_system **out, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path and a result");
    *out = NULL;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        if (fd >= 0) close(fd);
        return ulam__fail(err, ULAM_EIO, 0, -1, "a readable prepared system file");
    }
    size_t len = (size_t)st.st_size;
    void *map = len ? mmap(NULL, len, PROT_READ, MAP_PRIVATE, fd, 0) : MAP_FAILED;
    if (map == MAP_FAILED) {
        close(fd);
        if (len == 0) return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam prepared system (the file is empty)");
        return ulam__fail(err, ULAM_EIO, 0, -1, "a file that can be mapped");
    }
    int status = ulam_system_from_memory(map, len, tag, out, err);
    if (status) {
        munmap(map, len);
        close(fd);
        return status;
    }
    (*out)->map = map, (*out)->map_bytes = len, (*out)->fd = fd; /* kept: a lazy query preads its rows */
    return ULAM_OK;
}

/* 1 when path is a regular file that starts with the prepared-system magic.  A pipe, FIFO or
 * device is never one (it cannot be mapped) and is not read: its first bytes stay for the parser
 * (`info /dev/stdin`, `solve <(cat m.mtx)` found an empty file when this consumed them). */
int ulam_system_is_file(const char *path)
{
    char m[8];
    struct stat st;
    int fd = path ? open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC) : -1;
    int yes = fd >= 0 && !fstat(fd, &st) && S_ISREG(st.st_mode) && pread(fd, m, 8, 0) == 8 && !memcmp(m, MAGIC, 8);
    if (fd >= 0) close(fd);
    return yes;
}

/* Why a block failed, as the state it is left in. */
enum { BAD_SUM = 2, BAD_ROWPTR = 3, BAD_COLUMN = 4, BAD_VALUE = 5 };

/* The rows [*r0, *r1) of block k of a part of rows rows. */
static void block_rows(const ulam_system *s, int64_t k, int64_t rows, int64_t *r0, int64_t *r1)
{
    *r0 = k << s->shift;
    *r1 = *r0 + ((int64_t)1 << s->shift) < rows ? *r0 + ((int64_t)1 << s->shift) : rows;
}

/* Nonzero when the row pointers rp[0 .. rows] of a block rise within [0, nnz]. */
static int rowptr_ok(const int64_t *rp, int64_t rows, int64_t nnz)
{
    for (int64_t i = 0; i < rows; i++)
        if (!(rp[i] >= 0 && rp[i] <= rp[i + 1] && rp[i + 1] <= nnz)) return 0;
    return 1;
}

/* The state a block verifies to against checksum want: its row pointers rp[0 .. rows] (risen
 * within the entries), its entries rp[0] .. at col and val (columns below ncols). */
static int block_state(const int64_t *rp, int64_t rows, const int32_t *col, const double *val, int64_t ncols,
                       uint64_t want)
{
    if (block_hash(rp, rows, col, val) != want) return BAD_SUM;
    for (int64_t i = 0; i < rows; i++)
        for (int64_t q = rp[i] - rp[0]; q < rp[i + 1] - rp[0]; q++) {
            if (col[q] < 0 || col[q] >= ncols || (q > rp[i] - rp[0] && col[q] <= col[q - 1])) return BAD_COLUMN;
            if (!isfinite(val[q]) || val[q] == 0.0) return BAD_VALUE;
        }
    return GOOD;
}

/* The checksum of a block of rows: its row pointers rp[0 .. rows] and entries col, val (the
 * prepared format's rule); 1 when it is want and the entries hold the CSR invariants. */
int ulam__system_block_ok(const int64_t *rp, int64_t rows, const int32_t *col, const double *val, int64_t ncols,
                          uint64_t want)
{
    return block_state(rp, rows, col, val, ncols, want) == GOOD;
}

/* The state block rows r0 .. r1 - 1 of A (nnz entries) verify to against checksum want. */
static int csr_block_state(const ulam_csr *A, int64_t r0, int64_t r1, uint64_t want)
{
    const int64_t *rp = A->rowptr + r0; /* rowptr[nrows] was checked at open */
    if (!rowptr_ok(rp, r1 - r0, A->rowptr[A->nrows])) return BAD_ROWPTR;
    return block_state(rp, r1 - r0, A->colidx + rp[0], A->val + rp[0], A->ncols, want);
}

/* Verify block k of a part once (any thread; racing threads compute the same state). */
static int verify_block(const ulam_system *s, int part, int64_t k)
{
    _Atomic unsigned char *st = &s->state[s->first[part] + k];
    unsigned char v = atomic_load_explicit(st, memory_order_acquire);
    if (v == UNCHECKED) {
        uint64_t want = s->sums[s->first[part] + k];
        int64_t r0, r1;
        block_rows(s, k, part == PART_T ? s->tr.nrows : s->n, &r0, &r1);
        if (part == PART_B) {
            v = hash(s->b + r0, (size_t)(r1 - r0) * sizeof *s->b) != want ? BAD_SUM : GOOD;
            for (int64_t i = r0; v == GOOD && i < r1; i++)
                if (!isfinite(s->b[i])) v = BAD_VALUE;
        } else {
            v = (unsigned char)csr_block_state(part == PART_M ? &s->csr : &s->tr, r0, r1, want);
        }
        atomic_store_explicit(st, v, memory_order_release);
        if (part == PART_M) atomic_fetch_add_explicit(&s->checked[1], r1 - r0, memory_order_relaxed);
        atomic_fetch_add_explicit(&s->checked[0], 1, memory_order_relaxed);
    }
    return v == GOOD ? ULAM_OK : ULAM_ESYNTAX;
}

/* The message of a failed block k of a part. */
static int block_error(const ulam_system *s, int part, int64_t k, ulam_error *err)
{
    static const char *const parts[3] = {"M", "b", "M^T"};
    static const char *const why[6] = {"", "", "its checksum does not match", "its row pointers do not rise within the entries",
                                       "a column out of range or out of order", "a value that is not finite and nonzero"};
    int64_t r0, r1;
    block_rows(s, k, part == PART_T ? s->tr.nrows : s->n, &r0, &r1);
    unsigned char v = atomic_load(&s->state[s->first[part] + k]);
    return ulam__fail(err, ULAM_ESYNTAX, 0, r0, "an intact prepared file: block %lld of %s (rows %lld..%lld, 1-based) "
                      "is damaged: %s", (long long)k, parts[part], (long long)r0 + 1, (long long)r1,
                      v < 6 ? why[v] : "?");
}

/* Verify blocks of a part covering rows [first, last); the first failure with err filled. */
static int verify_part(const ulam_system *s, int part, int64_t first, int64_t last, ulam_error *err)
{
    int64_t rows = part == PART_T ? s->tr.nrows : s->n;
    if (!s->nblocks[part]) return ULAM_OK;
    first = first < 0 ? 0 : first, last = last > rows ? rows : last;
    for (int64_t k = first >> s->shift; first < last && k <= (last - 1) >> s->shift; k++)
        if (verify_block(s, part, k)) return block_error(s, part, k, err);
    return ULAM_OK;
}

/* Rows a stretch of a whole check given back at once (a large file: ulam__system_releases). */
#define RELEASE_ROWS ((int64_t)1 << 16)

/* Verify every block. */
int ulam_system_check(const ulam_system *s, ulam_error *err)
{
    ulam__clear(err);
    if (!s) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a system");
    int status = ULAM_OK;
    for (int part = 0; part < 3 && !status; part++) {
        int64_t rows = part == PART_T ? s->tr.nrows : s->n, step = ulam__system_releases(s) && part != PART_B ? RELEASE_ROWS : rows;
        for (int64_t r0 = 0; r0 < rows && !status; r0 += step) { /* a large file given back a stretch at a time */
            status = verify_part(s, part, r0, r0 + step, err);
            ulam__system_release(s, part == PART_M ? &s->csr : &s->tr, r0 - (r0 & (((int64_t)1 << s->shift) - 1)),
                                 r0 + step < rows ? r0 + step : rows);
        }
    }
    return status;
}

/* The lazy check of a solver's rows (ulam__rows_check). */
static int rows_check(const void *ctx, int64_t first, int64_t last, int with_b, int64_t *bad)
{
    const ulam_system *s = ctx;
    ulam_error err;
    int status = verify_part(s, PART_M, first, last, &err);
    if (!status && with_b) status = verify_part(s, PART_B, first, last, &err);
    if (status && bad) *bad = err.index;
    return status;
}

/* Read bytes [off, off + len) of s's file into p; 0, or -1 on a short read or an error. */
static int read_at(const ulam_system *s, void *p, size_t len, uint64_t off)
{
    for (size_t got = 0; got < len;) {
        ssize_t r = pread(s->fd, (char *)p + got, len - got, (off_t)(off + got));
        if (r <= 0) return -1;
        got += (size_t)r;
    }
    return 0;
}

/* Room for need bytes in r's block buffer (8-aligned). */
static int blk_fit(ulam__rowbuf *r, int64_t need)
{
    return need <= r->blkcap ? 0 : ulam__grow(&r->blk, &r->blkcap, need, 1);
}

/* Read block k of M (rows r0 .. r1 - 1) from the file into r's block buffer: its rowptr at
 * r->blk, its columns and values at r->blk_cols and r->blk_vals (byte offsets), the row pointers
 * checked to rise within the entries; its state when unchecked, else GOOD or BAD_SUM (unread). */
static unsigned char read_block(const ulam_system *s, int64_t k, int64_t r0, int64_t r1, int unchecked, ulam__rowbuf *r)
{
    int64_t rows = r1 - r0, pb = (rows + 1) * 8, nnz = s->csr.rowptr[s->n], a, m;
    r->blk_at = 0;
    if (blk_fit(r, pb) || read_at(s, r->blk, (size_t)pb, s->off[0] + (uint64_t)r0 * 8)) return BAD_ROWPTR;
    memcpy(&a, r->blk, 8);
    memcpy(&m, r->blk + rows * 8, 8);
    if (!rowptr_ok((const int64_t *)(void *)r->blk, rows, nnz)) return BAD_ROWPTR;
    m -= a;
    r->blk_cols = pb, r->blk_vals = pb + (m * 4 + 7) / 8 * 8;
    if (blk_fit(r, r->blk_vals + m * 8) || read_at(s, r->blk + r->blk_cols, (size_t)m * 4, s->off[1] + (uint64_t)a * 4) ||
        read_at(s, r->blk + r->blk_vals, (size_t)m * 8, s->off[2] + (uint64_t)a * 8))
        return BAD_SUM;
    if (!unchecked) return GOOD; /* verified when first read: not again */
    return (unsigned char)block_state((const int64_t *)(void *)r->blk, rows, (const int32_t *)(void *)(r->blk + r->blk_cols),
                                      (const double *)(void *)(r->blk + r->blk_vals), s->csr.ncols,
                                      s->sums[s->first[PART_M] + k]);
}

/* Record block k of a part verified to v (as verify_block does). */
static void set_state(const ulam_system *s, int part, int64_t k, unsigned char v)
{
    int64_t r0, r1;
    block_rows(s, k, s->n, &r0, &r1);
    atomic_store_explicit(&s->state[s->first[part] + k], v, memory_order_release);
    if (part == PART_M) atomic_fetch_add_explicit(&s->checked[1], r1 - r0, memory_order_relaxed);
    atomic_fetch_add_explicit(&s->checked[0], 1, memory_order_relaxed);
}

/* b_j read from the file into *out, its block verified first and kept in r's b buffer (a thread's
 * next b_j in the block is read from there); ULAM_OK or ULAM_ESYNTAX with *bad the block's first row. */
static int b_value(const ulam_system *s, int64_t j, ulam__rowbuf *r, double *out, int64_t *bad)
{
    int64_t k = j >> s->shift, r0, r1;
    block_rows(s, k, s->n, &r0, &r1);
    if (r->bblk_at == k + 1) {
        *out = r->bblk[j - r0];
        return ULAM_OK;
    }
    unsigned char v = atomic_load_explicit(&s->state[s->first[PART_B] + k], memory_order_acquire);
    int fresh = v == UNCHECKED;
    r->bblk_at = 0;
    if (v == UNCHECKED || v == GOOD) {
        if (r1 - r0 > r->bblkcap && ulam__grow(&r->bblk, &r->bblkcap, r1 - r0, sizeof *r->bblk)) v = BAD_SUM;
        else if (read_at(s, r->bblk, (size_t)(r1 - r0) * 8, s->off[3] + (uint64_t)r0 * 8)) v = BAD_SUM;
        else if (fresh) { /* verified once: its checksum and finite entries */
            v = hash(r->bblk, (size_t)(r1 - r0) * 8) != s->sums[s->first[PART_B] + k] ? BAD_SUM : GOOD;
            for (int64_t i = 0; v == GOOD && i < r1 - r0; i++)
                if (!isfinite(r->bblk[i])) v = BAD_VALUE;
        }
    }
    if (fresh) set_state(s, PART_B, k, v == UNCHECKED ? BAD_SUM : v);
    if (v == GOOD) {
        r->bblk_at = k + 1;
        *out = r->bblk[j - r0];
        return ULAM_OK;
    }
    if (bad) *bad = r0;
    return ULAM_ESYNTAX;
}

/* Row i of M read from the file into r (see ulam__rows_check.fetch): its block read whole (and
 * verified the first time any thread reads it) and kept, so the thread's next row in the block
 * is copied from memory. */
static int fetch_row(const void *ctx, int64_t i, int with_b, ulam__rowbuf *r, int64_t *bad)
{
    const ulam_system *s = ctx;
    int64_t k = i >> s->shift, r0, r1;
    block_rows(s, k, s->n, &r0, &r1);
    if (r->blk_at != k + 1) {
        unsigned char v = atomic_load_explicit(&s->state[s->first[PART_M] + k], memory_order_acquire);
        int fresh = v == UNCHECKED;
        if (v == UNCHECKED || v == GOOD) v = read_block(s, k, r0, r1, fresh, r);
        if (fresh) set_state(s, PART_M, k, v);
        if (v != GOOD) {
            if (bad) *bad = r0;
            return ULAM_ESYNTAX;
        }
        r->blk_at = k + 1;
    }
    int64_t p[2], a0;
    memcpy(p, r->blk + (i - r0) * 8, 16), memcpy(&a0, r->blk, 8);
    int64_t len = p[1] - p[0], cc = r->cap, cv = r->cap;
    int nomem = ulam__grow(&r->col, &cc, len, sizeof *r->col) || ulam__grow(&r->val, &cv, len, sizeof *r->val);
    r->cap = cc < cv ? cc : cv;
    if (nomem) { /* the row fails as unreadable */
        if (bad) *bad = r0;
        return ULAM_ESYNTAX;
    }
    memcpy(r->col, r->blk + r->blk_cols + (p[0] - a0) * 4, (size_t)len * 4);
    memcpy(r->val, r->blk + r->blk_vals + (p[0] - a0) * 8, (size_t)len * 8);
    r->len = len;
    return with_b ? b_value(s, i, r, &r->b, bad) : ULAM_OK;
}

/* b_j from the file (see ulam__rows_check.b_at). */
static int b_at(const void *ctx, int64_t j, ulam__rowbuf *r, double *v, int64_t *bad)
{
    if (r) return b_value(ctx, j, r, v, bad);
    ulam__rowbuf t = {0};
    int status = b_value(ctx, j, &t, v, bad);
    ulam__rowbuf_free(&t);
    return status;
}

/* The check a solver given opts->system makes before it reads rows (see internal.h). */
int ulam__system_rows_check(const ulam_system *s, const ulam_csr *M, const double *b, ulam__rows_check *rc,
                            ulam_error *err)
{
    if (!s->has_matrix || M != &s->csr)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the matrix of opts->system (ulam_system_lazy's) as M");
    *rc = (ulam__rows_check){.fn = rows_check, .ctx = s, .with_b = b && b == s->b};
    if (s->fd >= 0) /* rows read by pread: a mapped page would bring its neighbours (docs/prepared.md) */
        rc->fetch = fetch_row, rc->b_at = b_at, rc->fetch_of = &s->csr, rc->b_of = s->b;
    return ULAM_OK;
}

/* Why row i's block failed (see internal.h). */
int ulam__system_row_error(const ulam_system *s, int64_t i, ulam_error *err)
{
    int status = verify_part(s, PART_M, i, i + 1, err);
    return status ? status : verify_part(s, PART_B, i, i + 1, err);
}

/* The mapped arrays, unverified, for a solver given opts->system. */
int ulam_system_lazy(const ulam_system *s, const ulam_csr **M, const double **b)
{
    if (!s) return ULAM_EINVAL;
    if (M) *M = s->has_matrix ? &s->csr : NULL;
    if (b) *b = s->b;
    return ULAM_OK;
}

/* The mapped matrix, verified whole, or NULL. */
const ulam_csr *ulam_system_matrix(const ulam_system *s)
{
    return s && s->has_matrix && !verify_part(s, PART_M, 0, s->n, NULL) ? &s->csr : NULL;
}

/* The mapped b, verified whole, or NULL. */
const double *ulam_system_rhs(const ulam_system *s, int64_t *n)
{
    if (n) *n = s ? s->n : 0;
    return s && s->b && !verify_part(s, PART_B, 0, s->n, NULL) ? s->b : NULL;
}

/* Rows [first, last) of s's stored M^T verified, each block once (see src/cache.h). */
int ulam__system_tr_verify(const ulam_system *s, int64_t first, int64_t last, ulam_error *err)
{
    return s && s->has_tr ? verify_part(s, PART_T, first, last, err) : ulam__fail(err, ULAM_EINVAL, 0, -1, "a stored M^T");
}

/* s's stored M^T as it is, not verified, or NULL (see src/cache.h). */
const ulam_csr *ulam__system_tr(const ulam_system *s)
{
    return s && s->has_tr ? &s->tr : NULL;
}

/* Whether s's mapping is released as passes go (see src/cache.h). */
int ulam__system_releases(const ulam_system *s)
{
    return s && s->map && s->fd >= 0 && s->map_bytes > s->keep;
}

/* Set the bytes of mapping s keeps resident (see src/cache.h). */
void ulam__system_set_keep(ulam_system *s, size_t bytes)
{
    if (s) s->keep = bytes;
}

/* Give back the pages of [p, p + bytes) of s's mapping, widened to whole pages (MADV_DONTNEED:
 * the file's pages stay in the page cache, a later read maps them again; nothing of a read-only
 * private mapping is lost). */
static void release_bytes(const ulam_system *s, const void *p, size_t bytes)
{
    const size_t page = (size_t)2 << 20; /* whole 2 MiB spans: a huge mapping is not split */
    uintptr_t a = (uintptr_t)p / page * page, e = ((uintptr_t)p + bytes + page - 1) / page * page;
    uintptr_t m0 = (uintptr_t)s->map, m1 = m0 + s->map_bytes;
    a = a < m0 ? m0 : a, e = e > m1 ? m1 : e;
    if (a < e) madvise((void *)a, e - a, MADV_DONTNEED); /* advice: a failure leaves the pages resident, no more */
}

/* Rows [r0, r1) of A (s's M or stored M^T) given back to the page cache (see src/cache.h). */
void ulam__system_release(const ulam_system *s, const ulam_csr *A, int64_t r0, int64_t r1)
{
    if (!ulam__system_releases(s) || (A != &s->csr && A != &s->tr) || r0 >= r1) return;
    int64_t a = A->rowptr[r0], b = A->rowptr[r1];
    release_bytes(s, A->colidx + a, (size_t)(b - a) * sizeof *A->colidx);
    release_bytes(s, A->val + a, (size_t)(b - a) * sizeof *A->val);
    release_bytes(s, A->rowptr + r0, (size_t)(r1 - r0) * sizeof *A->rowptr);
}

/* All of s's mapping given back once the process's file-backed resident pages pass
 * ULAM__SYSTEM_TRIM, or its keep when smaller (see src/cache.h): /proc/self/statm's third field
 * (none: nothing given back). */
void ulam__system_trim(const ulam_system *s)
{
    if (!ulam__system_releases(s)) return;
    char buf[128];
    int fd = open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
    ssize_t got = fd >= 0 ? read(fd, buf, sizeof buf - 1) : -1;
    if (fd >= 0) close(fd);
    if (got <= 0) return;
    buf[got] = 0;
    unsigned long long size = 0, res = 0, shared = 0;
    if (sscanf(buf, "%llu %llu %llu", &size, &res, &shared) == 3 &&
        shared * (unsigned long long)sysconf(_SC_PAGESIZE) > (s->keep < ULAM__SYSTEM_TRIM ? s->keep : ULAM__SYSTEM_TRIM))
        release_bytes(s, s->map, s->map_bytes);
}

/* Entries [e0, e0 + cnt) of row j of s's stored M^T read by pread into col and val (see src/cache.h). */
int ulam__system_tr_read(const ulam_system *s, int64_t j, int64_t e0, int64_t cnt, int32_t *col, double *val)
{
    const ulam_csr *T = &s->tr;
    int64_t a = T->rowptr[j] + e0;
    uint64_t oc = (uint64_t)((const unsigned char *)(const void *)(T->colidx + a) - (const unsigned char *)s->map);
    uint64_t ov = (uint64_t)((const unsigned char *)(const void *)(T->val + a) - (const unsigned char *)s->map);
    return cnt > 0 && ((col && read_at(s, col, (size_t)cnt * 4, oc)) || (val && read_at(s, val, (size_t)cnt * 8, ov))) ? -1 : 0;
}

/* Whether M's values are all >= 0, read by pread (see src/cache.h). */
int ulam__system_nonneg(const ulam_system *s)
{
    int64_t nnz = s->csr.rowptr[s->n];
    if (s->fd < 0) {
        for (int64_t e = 0; e < nnz; e++)
            if (s->csr.val[e] < 0) return 0;
        return 1;
    }
    enum { CHUNK = 1 << 17 }; /* values a read: 1 MiB */
    double *buf = malloc(CHUNK * sizeof *buf);
    int v = buf ? 1 : -1;
    for (int64_t e = 0; v == 1 && e < nnz; e += CHUNK) {
        int64_t m = nnz - e < CHUNK ? nnz - e : CHUNK;
        if (read_at(s, buf, (size_t)m * 8, s->off[2] + (uint64_t)e * 8)) v = -1;
        for (int64_t q = 0; v == 1 && q < m; q++)
            if (buf[q] < 0) v = 0;
    }
    free(buf);
    return v;
}

/* The stored M^T, verified whole, or NULL. */
const ulam_csr *ulam_system_transpose(const ulam_system *s)
{
    return s && s->has_tr && !verify_part(s, PART_T, 0, s->tr.nrows, NULL) ? &s->tr : NULL;
}

/* The bounds extension of s for its matrix at continuation continue_q and kernel exponent alpha
 * (R->seen unset: every state): 1 when the file holds them, else 0 (see internal.h). */
int ulam__system_bounds(const ulam_system *s, double continue_q, double alpha, ulam__reach *R)
{
    if (!s || !s->has_bounds || s->bounds.continue_q != fmax(continue_q, 0.0) || s->bounds.alpha != alpha) return 0;
    *R = s->bounds;
    R->K = &s->csr;
    return 1;
}

/* What s holds besides M, b and M^T, and what its queries have read. */
void ulam_system_get_info(const ulam_system *s, ulam_system_info *info)
{
    if (!info) return;
    memset(info, 0, sizeof *info);
    if (!s) return;
    info->cert = s->has_cert ? &s->cert : NULL;
    info->omega = s->omega;
    info->blocks_checked = atomic_load(&s->checked[0]), info->rows_checked = atomic_load(&s->checked[1]);
    info->map = s->map, info->map_bytes = s->map ? s->map_bytes : 0;
}

/* Unmap and free. */
ulam_system *ulam_system_free(ulam_system *s)
{
    if (!s) return NULL;
    if (s->map) munmap(s->map, s->map_bytes);
    if (s->fd >= 0) close(s->fd);
    free((void *)s->state);
    free((void *)s->checked);
    free(s);
    return NULL;
}

/* The content tag of a source file: XXH3-128 of its bytes. */
int ulam_file_tag(const char *path, uint64_t tag[2], ulam_error *err)
{
    ulam__clear(err);
    if (!path || !tag) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path and a tag");
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return ulam__fail(err, ULAM_EIO, 0, -1, "a readable file");
    struct stat sb;
    if (fstat(fd, &sb) || !S_ISREG(sb.st_mode)) { /* a pipe read here would be lost to the parser */
        close(fd);
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a regular file (a pipe or device has no lasting content to tag)");
    }
    XXH3_state_t *st = XXH3_createState();
    enum { CHUNK = 1 << 20 };
    unsigned char *buf = malloc(CHUNK);
    int status = st && buf ? ULAM_OK : ULAM_ENOMEM;
    if (!status) XXH3_128bits_reset(st);
    for (ssize_t got; !status && (got = read(fd, buf, CHUNK)) != 0;) {
        if (got < 0) status = ULAM_EIO;
        else XXH3_128bits_update(st, buf, (size_t)got);
    }
    if (!status) {
        XXH128_hash_t h = XXH3_128bits_digest(st);
        tag[0] = h.low64, tag[1] = h.high64;
    }
    close(fd);
    free(buf);
    XXH3_freeState(st);
    return status ? ulam__fail(err, status, 0, -1, status == ULAM_EIO ? "a readable file" : "memory to hash the file")
                  : ULAM_OK;
}
