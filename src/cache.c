/* Prepared systems: M and b of (I - M) x = b as one file mapped read-only and used in place
 * (docs/prepared.md).  The header is 1024 bytes of little-endian 64-bit words:
 *
 *   word  0      magic "ulamSYS1"
 *   word  1      version (1) | header bytes (1024) << 32
 *   word  2      flags: 1 matrix, 2 b, 4 certificate
 *   words 3-5    nrows, ncols, nnz
 *   words 6-9    byte offsets of rowptr int64[nrows + 1], colidx int32[nnz], val double[nnz],
 *                b double[nrows] (0 when absent), each a multiple of 4096
 *   word  10     the file's length in bytes
 *   words 11-12  the source's tag (the CLI's cache: size and mtime; 0 from `ulam prepare`)
 *   word  13     the Jacobi damping omega that made M (double; 0: M as read)
 *   words 32-95  the certificate section: word 32 its version (2) | its bytes << 32, then
 *                version 2's fields (see put_cert)
 *   words 96-126 the bounds extension (a section of its own, versioned apart): word 96 its
 *                version (1) | its bytes << 32, then the walk kernel's bounds over every state
 *                and b's scores (see put_bounds); 0 when absent, and a reader that does not know
 *                its version ignores it
 *   word  127    FNV-1a 64 of bytes 0 .. 1015
 *
 * Opening checks the header whole but reads no array beyond rowptr[0] and rowptr[nrows]:
 * ulam_system_check verifies them, and the walk kernel checks each row it builds. */
#include "internal.h"

#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

enum {
    HEADER = 1024, WORDS = HEADER / 8, ALIGN = 4096, VERSION = 1,
    F_MATRIX = 1, F_RHS = 2, F_CERT = 4,
    W_FLAGS = 2, W_DIMS = 3, W_OFF = 6, W_LEN = 10, W_TAG = 11, W_OMEGA = 13,
    W_CERT = 32, W_SUM = WORDS - 1, CERT_VERSION = 2, CERT_WORDS = 36,
    W_BOUNDS = 96, BOUNDS_VERSION = 1, BOUNDS_WORDS = 16
};
static const char MAGIC[8] = {'u', 'l', 'a', 'm', 'S', 'Y', 'S', '1'};

struct ulam_system {
    ulam_csr csr;          /* pointers into the mapping */
    const double *b;
    int64_t n;
    int has_matrix, has_cert;
    double omega;
    ulam_certificate cert;
    int has_bounds;
    ulam__reach bounds;    /* the bounds extension (seen and K unset) */
    void *map;             /* the mapping (NULL: borrowed memory) */
    size_t map_bytes;
};

/* FNV-1a 64 of bytes p[0 .. n). */
static uint64_t fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 0xcbf29ce484222325u;
    for (size_t i = 0; i < n; i++) h = (h ^ p[i]) * 0x100000001b3u;
    return h;
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

/* Certificate version 2 from word 33: continue_q, tol, max_iter, rowsum min and max, colsum min
 * and max, then |M|, M^ adjoint, M^ forward (8 words each), the three verdicts and the guard's
 * computed bits. */
static void put_cert(uint64_t *w, const ulam_certificate *c)
{
    w[0] = (uint64_t)CERT_VERSION | (uint64_t)(CERT_WORDS * 8) << 32;
    w[1] = bits(c->continue_q), w[2] = bits(c->tol), w[3] = (uint64_t)(int64_t)c->max_iter;
    w[4] = bits(c->rowsum_min), w[5] = bits(c->rowsum_max), w[6] = bits(c->colsum_min), w[7] = bits(c->colsum_max);
    put_power(w + 8, &c->guard.abs);
    put_power(w + 16, &c->guard.hat[0]);
    put_power(w + 24, &c->guard.hat[1]);
    w[32] = (uint64_t)c->guard.verdict_abs, w[33] = (uint64_t)c->guard.verdict_hat[0];
    w[34] = (uint64_t)c->guard.verdict_hat[1], w[35] = (uint64_t)c->guard.computed;
}

/* Read certificate version 2; 0 when the section is of another version or inconsistent. */
static int get_cert(const uint64_t *w, ulam_certificate *c)
{
    if (w[0] != ((uint64_t)CERT_VERSION | (uint64_t)(CERT_WORDS * 8) << 32)) return 0;
    *c = (ulam_certificate){.continue_q = real(w[1]), .tol = real(w[2]), .max_iter = (int)(int64_t)w[3],
                            .rowsum_min = real(w[4]), .rowsum_max = real(w[5]), .colsum_min = real(w[6]),
                            .colsum_max = real(w[7])};
    get_power(w + 8, &c->guard.abs);
    get_power(w + 16, &c->guard.hat[0]);
    get_power(w + 24, &c->guard.hat[1]);
    for (int k = 0; k < 3; k++)
        if (w[32 + k] > ULAM_VERDICT_UNKNOWN) return 0;
    if (w[35] > (uint64_t)ULAM_GUARD_ALL) return 0;
    c->guard.verdict_abs = (int)w[32], c->guard.verdict_hat[0] = (int)w[33], c->guard.verdict_hat[1] = (int)w[34];
    c->guard.computed = (int)w[35];
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

/* The bounds of d's M (and scores of its b) at its certificate's continuation and exponent 1,
 * into the header words w; nothing when they cannot be made (a corrupt row, no memory). */
static void make_bounds(const ulam_system_desc *d, uint64_t *w)
{
    char *seen = ulam__malloc((size_t)d->M->nrows, 1);
    ulam__reach R;
    if (seen && !ulam__reach_all(d->M, d->cert->continue_q, 1.0, seen, &R) &&
        (!d->b || !ulam__reach_b(d->M, d->b, &R)))
        put_bounds(w, &R);
    free(seen);
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

/* An empty description. */
ulam_system_desc ulam_system_desc_defaults(void)
{
    return (ulam_system_desc){.M = NULL, .b = NULL, .n = 0, .tag = {0, 0}, .omega = 0.0, .cert = NULL};
}

/* Write a prepared system to f. */
int ulam_system_write_file(FILE *f, const ulam_system_desc *d)
{
    if (!f || !d || (!d->M && !d->b) || !little_endian()) return ULAM_EINVAL;
    const ulam_csr *M = d->M;
    int64_t n = M ? M->nrows : d->n, nnz = M ? M->rowptr[M->nrows] : 0;
    if (n < 0 || (M && d->n != M->nrows && d->b)) return ULAM_EINVAL;
    if (d->cert && d->cert->guard.kernel_alpha != 1.0) return ULAM_EINVAL; /* the section holds exponent 1's guards */
    uint64_t w[WORDS] = {0}, at = HEADER;
    size_t part[4] = {M ? ((size_t)n + 1) * 8 : 0, (size_t)nnz * 4, (size_t)nnz * 8, d->b ? (size_t)n * 8 : 0};
    memcpy(&w[0], MAGIC, 8);
    w[1] = (uint64_t)VERSION | (uint64_t)HEADER << 32;
    w[W_FLAGS] = (M ? F_MATRIX : 0) | (d->b ? F_RHS : 0) | (d->cert ? F_CERT : 0);
    w[W_DIMS] = (uint64_t)n, w[W_DIMS + 1] = (uint64_t)(M ? M->ncols : 1), w[W_DIMS + 2] = (uint64_t)nnz;
    at = aligned(at);
    for (int k = 0; k < 4; k++) {
        w[W_OFF + k] = part[k] || (k < 3 && M) || (k == 3 && d->b) ? at : 0;
        at = aligned(at + part[k]);
    }
    w[W_LEN] = at;
    w[W_TAG] = d->tag[0], w[W_TAG + 1] = d->tag[1];
    w[W_OMEGA] = bits(d->omega);
    if (d->cert) put_cert(w + W_CERT, d->cert);
    if (d->cert && M && M->nrows == M->ncols) make_bounds(d, w + W_BOUNDS);
    w[W_SUM] = fnv1a((const unsigned char *)w, (size_t)W_SUM * 8);
    const void *src[4] = {M ? (const void *)M->rowptr : NULL, M ? (const void *)M->colidx : NULL,
                          M ? (const void *)M->val : NULL, d->b};
    uint64_t pos = 0;
    int ok = put_part(f, w, HEADER, &pos);
    for (int k = 0; k < 4 && ok; k++)
        if (w[W_OFF + k]) ok = put_part(f, src[k], part[k], &pos);
    return ok && pos == at ? ULAM_OK : ULAM_EIO;
}

/* Write a prepared system to path atomically. */
int ulam_system_write(const char *path, const ulam_system_desc *d)
{
    if (!path || !d) return ULAM_EINVAL;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    status = ulam_system_write_file(o.f, d);
    if (status) {
        ulam_outfile_abort(&o);
        return status;
    }
    return ulam_outfile_commit(&o);
}

/* Nonzero when an array of bytes at offset off lies inside a file of len bytes past the header. */
static int inside(uint64_t off, uint64_t bytes, uint64_t len)
{
    return off >= HEADER && off % ALIGN == 0 && off <= len && bytes <= len - off;
}

/* Check the header of the len bytes at p and fill s (its arrays point into p). */
static int parse(const unsigned char *p, size_t len, const uint64_t tag[2], ulam_system *s, ulam_error *err)
{
    uint64_t w[WORDS];
    if (len < 8 || memcmp(p, MAGIC, 8))
        return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam prepared system (magic 'ulamSYS1')");
    if (!little_endian()) return ulam__fail(err, ULAM_EUNSUPPORTED, 0, -1, "a little-endian machine");
    if (len < HEADER)
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a header of %d bytes (the file has %zu: truncated)", HEADER, len);
    memcpy(w, p, HEADER);
    if (w[1] != ((uint64_t)VERSION | (uint64_t)HEADER << 32))
        return ulam__fail(err, ULAM_EUNSUPPORTED, 0, -1, "format version 1 (got %llu)", (unsigned long long)(w[1] & 0xffffffffu));
    if (fnv1a(p, (size_t)W_SUM * 8) != w[W_SUM])
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a header matching its checksum (the header is corrupt)");
    if (w[W_LEN] != len)
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a file of %llu bytes as its header states, got %zu (truncated?)",
                          (unsigned long long)w[W_LEN], len);
    uint64_t flags = w[W_FLAGS], n = w[W_DIMS], nc = w[W_DIMS + 1], nnz = w[W_DIMS + 2];
    int m = (flags & F_MATRIX) != 0, r = (flags & F_RHS) != 0;
    if ((flags & ~(uint64_t)(F_MATRIX | F_RHS | F_CERT)) || (!m && !r) || n > ULAM_MAX_DIM || nc > ULAM_MAX_DIM ||
        nnz > (uint64_t)INT64_MAX / 32 || (!m && (nnz || nc != 1)))
        return ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "sizes that fit (got %llu x %llu, %llu entries)",
                          (unsigned long long)n, (unsigned long long)nc, (unsigned long long)nnz);
    uint64_t bytes[4] = {m ? (n + 1) * 8 : 0, m ? nnz * 4 : 0, m ? nnz * 8 : 0, r ? n * 8 : 0};
    for (int k = 0; k < 4; k++) {
        int present = k < 3 ? m : r;
        if (present ? !inside(w[W_OFF + k], bytes[k], len) : w[W_OFF + k] != 0)
            return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "arrays inside the file at 4096-byte boundaries (array %d is not)", k);
    }
    if (tag && (w[W_TAG] != tag[0] || w[W_TAG + 1] != tag[1]))
        return ulam__fail(err, ULAM_ENOTFOUND, 0, -1, "a cache of the current source file (it changed)");
    *s = (ulam_system){.n = (int64_t)n, .has_matrix = m, .omega = real(w[W_OMEGA])};
    if (m) {
        s->csr = (ulam_csr){.nrows = (int64_t)n, .ncols = (int64_t)nc, .rowptr = (int64_t *)(uintptr_t)(p + w[W_OFF]),
                            .colidx = (int32_t *)(uintptr_t)(p + w[W_OFF + 1]),
                            .val = (double *)(uintptr_t)(p + w[W_OFF + 2])};
        if (s->csr.rowptr[0] != 0 || s->csr.rowptr[n] != (int64_t)nnz)
            return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "rowptr from 0 to the %llu entries the header states",
                              (unsigned long long)nnz);
    }
    if (r) s->b = (const double *)(const void *)(p + w[W_OFF + 3]);
    s->has_cert = (flags & F_CERT) && get_cert(w + W_CERT, &s->cert);
    s->has_bounds = m && nc == n && get_bounds(w + W_BOUNDS, s->b, (int64_t)n, &s->bounds);
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
    close(fd);
    if (map == MAP_FAILED) {
        if (len == 0) return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam prepared system (the file is empty)");
        return ulam__fail(err, ULAM_EIO, 0, -1, "a file that can be mapped");
    }
    int status = ulam_system_from_memory(map, len, tag, out, err);
    if (status) {
        munmap(map, len);
        return status;
    }
    (*out)->map = map, (*out)->map_bytes = len;
    return ULAM_OK;
}

/* 1 when path starts with the prepared-system magic. */
int ulam_system_is_file(const char *path)
{
    char m[8];
    FILE *f = path ? fopen(path, "rb") : NULL;
    int yes = f && fread(m, 1, 8, f) == 8 && !memcmp(m, MAGIC, 8);
    if (f) fclose(f);
    return yes;
}

/* Verify the arrays as a parse would. */
int ulam_system_check(const ulam_system *s, ulam_error *err)
{
    ulam__clear(err);
    if (!s) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a system");
    int status = s->has_matrix ? ulam_csr_check(&s->csr) : ULAM_OK;
    if (status) return ulam__fail(err, status, 0, -1, "a consistent matrix (the prepared file is corrupt)");
    for (int64_t i = 0; s->b && i < s->n; i++)
        if (!isfinite(s->b[i])) return ulam__fail(err, ULAM_ENONFINITE, 0, i, "finite b (the prepared file is corrupt)");
    return ULAM_OK;
}

/* The mapped matrix, or NULL. */
const ulam_csr *ulam_system_matrix(const ulam_system *s)
{
    return s && s->has_matrix ? &s->csr : NULL;
}

/* The mapped b, or NULL. */
const double *ulam_system_rhs(const ulam_system *s, int64_t *n)
{
    if (n) *n = s ? s->n : 0;
    return s ? s->b : NULL;
}

/* The stored certificate, or NULL. */
const ulam_certificate *ulam_system_certificate(const ulam_system *s)
{
    return s && s->has_cert ? &s->cert : NULL;
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

/* The Jacobi damping of the stored M. */
double ulam_system_omega(const ulam_system *s)
{
    return s ? s->omega : 0.0;
}

/* Unmap and free. */
ulam_system *ulam_system_free(ulam_system *s)
{
    if (!s) return NULL;
    if (s->map) munmap(s->map, s->map_bytes);
    free(s);
    return NULL;
}
