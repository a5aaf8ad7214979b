/* Binary caches of a parsed matrix or vector: the arrays as they sit in memory behind a
 * header, so a second run loads by reading, not parsing.  Layout (native byte order, checked
 * by a marker): char magic[8] ("ulamCSR1" or "ulamVEC1"), uint64 order marker, int64 nrows,
 * ncols, nnz, uint64 tag[2] (the caller's identity of the source: size and mtime), then
 * rowptr int64[nrows + 1], colidx int32[nnz], val double[nnz] (a vector: val double[nrows]). */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { HEADER_WORDS = 6 };
static const uint64_t ORDER = 0x0102030405060708u;

/* Write the header and arrays to an atomic output file. */
static int cache_write(const char *path, const char magic[8], const int64_t dims[3], const uint64_t tag[2],
                       const void *const parts[3], const size_t bytes[3])
{
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    uint64_t head[HEADER_WORDS] = {ORDER, (uint64_t)dims[0], (uint64_t)dims[1], (uint64_t)dims[2], tag[0], tag[1]};
    int ok = fwrite(magic, 1, 8, o.f) == 8 && fwrite(head, sizeof head, 1, o.f) == 1;
    for (int k = 0; k < 3 && ok; k++) ok = bytes[k] == 0 || fwrite(parts[k], 1, bytes[k], o.f) == bytes[k];
    if (!ok) {
        ulam_outfile_abort(&o);
        return ULAM_EIO;
    }
    return ulam_outfile_commit(&o);
}

/* Open a cache and check its magic, byte order, tag and the sizes it states (its length is
 * checked by reading: read_all). */
static int cache_open(const char *path, const char magic[8], const uint64_t tag[2], int64_t dims[3], FILE **fp,
                      ulam_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return ulam__fail(err, ULAM_EIO, 0, -1, "a readable cache file");
    char m[8];
    uint64_t h[HEADER_WORDS];
    if (fread(m, 1, 8, f) != 8 || memcmp(m, magic, 8) || fread(h, sizeof h, 1, f) != 1 || h[0] != ORDER) {
        fclose(f);
        return ulam__fail(err, ULAM_EBANNER, 0, -1, "an ulam cache written on this kind of machine");
    }
    if (h[4] != tag[0] || h[5] != tag[1]) {
        fclose(f);
        return ulam__fail(err, ULAM_ENOTFOUND, 0, -1, "a cache of the current source file (it changed)");
    }
    for (int k = 0; k < 3; k++) dims[k] = (int64_t)h[k + 1];
    if (dims[0] < 0 || dims[1] < 0 || dims[2] < 0 || dims[0] > ULAM_MAX_DIM || dims[1] > ULAM_MAX_DIM ||
        dims[2] > INT64_MAX / 32) {
        fclose(f);
        return ulam__fail(err, ULAM_EOVERFLOW, 0, -1, "sizes that fit (got %lld x %lld, %lld entries)",
                          (long long)dims[0], (long long)dims[1], (long long)dims[2]);
    }
    *fp = f;
    return ULAM_OK;
}

/* Read exactly bytes into p, and then find the end of the file. */
static int read_all(FILE *f, void *p, size_t bytes, int last)
{
    if (bytes && fread(p, 1, bytes, f) != bytes) return 0;
    return !last || fgetc(f) == EOF;
}

/* Write A to a binary cache at path, tagged with the identity of its source. */
int ulam_cache_write_csr(const char *path, const ulam_csr *A, const uint64_t tag[2])
{
    if (!path || !A || !tag) return ULAM_EINVAL;
    int64_t nnz = A->rowptr[A->nrows], dims[3] = {A->nrows, A->ncols, nnz};
    const void *parts[3] = {A->rowptr, A->colidx, A->val};
    size_t bytes[3] = {((size_t)A->nrows + 1) * sizeof *A->rowptr, (size_t)nnz * sizeof *A->colidx,
                       (size_t)nnz * sizeof *A->val};
    return cache_write(path, "ulamCSR1", dims, tag, parts, bytes);
}

/* Read a matrix cache written for the same tag; its structure is checked as a parse would. */
int ulam_cache_read_csr(const char *path, const uint64_t tag[2], ulam_csr **A, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !tag || !A) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path, a tag and a result");
    *A = NULL;
    int64_t d[3];
    FILE *f = NULL;
    int status = cache_open(path, "ulamCSR1", tag, d, &f, err);
    if (status) return status;
    ulam_csr *B = ulam_csr_alloc(d[0], d[1], d[2]);
    if (!B) {
        fclose(f);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld entries", (long long)d[2]);
    }
    int ok = read_all(f, B->rowptr, ((size_t)d[0] + 1) * sizeof *B->rowptr, 0) &&
             read_all(f, B->colidx, (size_t)d[2] * sizeof *B->colidx, 0) &&
             read_all(f, B->val, (size_t)d[2] * sizeof *B->val, 1);
    fclose(f);
    if (!ok || B->rowptr[d[0]] != d[2] || ulam_csr_check(B) != ULAM_OK) { /* nnz first: the check reads that far */
        ulam_csr_free(B);
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a complete, consistent cache (truncated or corrupt)");
    }
    *A = B;
    return ULAM_OK;
}

/* Write x (n values) to a binary cache at path, tagged with the identity of its source. */
int ulam_cache_write_vector(const char *path, const double *x, int64_t n, const uint64_t tag[2])
{
    if (!path || !x || n < 0 || !tag) return ULAM_EINVAL;
    int64_t dims[3] = {n, 1, n};
    const void *parts[3] = {x, NULL, NULL};
    size_t bytes[3] = {(size_t)n * sizeof *x, 0, 0};
    return cache_write(path, "ulamVEC1", dims, tag, parts, bytes);
}

/* Read a vector cache written for the same tag into a new *x of *n values. */
int ulam_cache_read_vector(const char *path, const uint64_t tag[2], double **x, int64_t *n, ulam_error *err)
{
    ulam__clear(err);
    if (!path || !tag || !x || !n) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a path, a tag and a result");
    *x = NULL;
    int64_t d[3];
    FILE *f = NULL;
    int status = cache_open(path, "ulamVEC1", tag, d, &f, err);
    if (status) return status;
    double *v = d[1] == 1 && d[2] == d[0] ? ulam__malloc((size_t)d[0], sizeof *v) : NULL;
    int ok = v && read_all(f, v, (size_t)d[0] * sizeof *v, 1);
    fclose(f);
    for (int64_t i = 0; ok && i < d[0]; i++) ok = isfinite(v[i]);
    if (!ok) {
        free(v);
        return ulam__fail(err, ULAM_ESYNTAX, 0, -1, "a complete, consistent cache (truncated or corrupt)");
    }
    *x = v, *n = d[0];
    return ULAM_OK;
}
