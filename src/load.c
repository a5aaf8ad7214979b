/* Loading a system from the files a front end names (include/ulam_load.h). */
#include "ulam_load.h"

#include <stdlib.h>
#include <string.h>

/* Name path as the file at fault in err unless the library named one already; status. */
static int at(ulam_error *err, const char *path, int status)
{
    if (status && !err->file[0] && path) snprintf(err->file, sizeof err->file, "%s", path);
    return status;
}

/* Fill err with status and the expectation msg (no line); status. */
static int fail(ulam_error *err, int status, const char *msg)
{
    *err = (ulam_error){.status = status, .index = -1};
    snprintf(err->msg, sizeof err->msg, "%s", msg);
    return status;
}

/* The matrix (vec == NULL) or b a prepared system holds, unverified (NULL: none). */
static const void *held(const ulam_system *sys, const double **vec)
{
    const ulam_csr *M = NULL;
    const double *b = NULL;
    ulam_system_lazy(sys, &M, &b);
    return vec ? (const void *)b : (const void *)M;
}

/* Write a cache copy through an outfile; a status. */
static int write_copy(const char *path, const ulam_system_desc *d)
{
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (!status && (status = ulam_system_write_file(o.f, d))) ulam_outfile_abort(&o);
    return status ? status : ulam_outfile_commit(&o);
}

/* Read a matrix (vec == NULL) or vector.  A prepared file is mapped (*sys); with L's cache, its
 * copy PATH.ulamcache (a prepared file) is mapped when it was made from the file as it is now,
 * else the file is parsed (*A or *vec) and the copy written (a failure to write it is only a
 * note to log).  A status, err filled. */
static int read_input(ulam_load *L, const char *path, FILE *log, ulam_system **sys, ulam_csr **A, double **vec,
                      int64_t *n, ulam_error *err)
{
    char cpath[4200];
    uint64_t tag[2];
    double t0 = ulam_now();
    if (ulam_system_is_file(path)) {
        int status = ulam_system_open(path, NULL, sys, err);
        if (!status && !held(*sys, (const double **)vec)) {
            *sys = ulam_system_free(*sys);
            status = fail(err, ULAM_ENOTFOUND, vec ? "a prepared system holding b (prepare it with --rhs)"
                                                   : "a prepared system holding a matrix (this one holds only b)");
        }
        return status;
    }
    int use = L->cache && strlen(path) < 4096 && !ulam_file_tag(path, tag, NULL); /* the source's content hash */
    if (use) {
        snprintf(cpath, sizeof cpath, "%s.ulamcache", path);
        if (!ulam_system_open(cpath, tag, sys, err) && held(*sys, (const double **)vec)) {
            if (log) fprintf(log, "ulam: %s: loaded from its cache in %.3f s\n", path, ulam_now() - t0);
            return ULAM_OK;
        }
        *sys = ulam_system_free(*sys);
    }
    if (!vec && ulam_edgelist_is_file(path)) { /* a graph's edge list: no cache (its ids' base is not kept) */
        if (L->preloaded) return *A = L->preloaded, L->preloaded = NULL, ULAM_OK;
        int64_t base = 1;
        int status = ulam_edgelist_read(path, A, &base, err);
        if (!status) L->node_base = base;
        return status;
    }
    int status = vec ? ulam_mm_read_vector(path, vec, n, err) : ulam_mm_read_matrix(path, A, err);
    if (status || !use) return status;
    double parsed = ulam_now() - t0;
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = vec ? NULL : *A, d.b = vec ? *vec : NULL, d.n = vec ? *n : (*A)->nrows;
    d.tag[0] = tag[0], d.tag[1] = tag[1];
    int st = (L->write ? L->write : write_copy)(cpath, &d);
    if (log && st) fprintf(log, "ulam: %s: warning: cache not written: %s\n", cpath, ulam_strerror(st));
    else if (log) fprintf(log, "ulam: %s: parsed in %.3f s, cache written to %s\n", path, parsed, cpath);
    return ULAM_OK;
}

/* See ulam_load.h. */
void ulam_load_free(ulam_load *L)
{
    if (!L) return;
    L->own_M = ulam_csr_free(L->own_M);
    free(L->own_b);
    L->own_b = NULL;
    L->sys_M = ulam_system_free(L->sys_M);
    L->sys_b = ulam_system_free(L->sys_b);
    L->M = NULL, L->b = NULL, L->cert = NULL;
}

/* See ulam_load.h. */
int ulam_load_open(ulam_load *L, FILE *log, ulam_error *err)
{
    *err = (ulam_error){.status = ULAM_OK, .index = -1};
    if (!L || !L->matrix_path) return fail(err, ULAM_EINVAL, "a matrix file to load");
    int prepared = ulam_system_is_file(L->matrix_path);
    int status = read_input(L, L->matrix_path, log, &L->sys_M, &L->own_M, NULL, NULL, err);
    if (status) return ulam_load_free(L), at(err, L->matrix_path, status);
    const ulam_csr *mapped = NULL;
    const double *mapped_b = NULL;
    ulam_system_lazy(L->sys_M, &mapped, &mapped_b); /* verified later, or as walks read it (lazy) */
    L->M = L->own_M ? L->own_M : mapped;
    ulam_system_info si;
    ulam_system_get_info(L->sys_M, &si);
    if (prepared) L->cert = si.cert;
    if (L->M->nrows != L->M->ncols) {
        char msg[128];
        snprintf(msg, sizeof msg, "a square matrix, got %lld x %lld", (long long)L->M->nrows, (long long)L->M->ncols);
        ulam_load_free(L);
        return at(err, L->matrix_path, fail(err, ULAM_ENOTSQUARE, msg));
    }
    int64_t n = L->M->nrows, nb = n;
    if (L->rhs_path) {
        status = read_input(L, L->rhs_path, log, &L->sys_b, NULL, &L->own_b, &nb, err);
        if (status) return ulam_load_free(L), at(err, L->rhs_path, status);
        const double *vb = NULL;
        ulam_system_lazy(L->sys_b, NULL, &vb);
        if (L->sys_b) ulam_system_rhs(L->sys_b, &nb);
        L->b = L->own_b ? L->own_b : vb;
        if (nb != n) {
            fail(err, ULAM_EDIM, "");
            snprintf(err->msg, sizeof err->msg, "%lld entries to match %s, got %lld", (long long)n, L->matrix_path,
                     (long long)nb);
            ulam_load_free(L);
            return at(err, L->rhs_path, ULAM_EDIM);
        }
    } else if (prepared) {
        L->b = mapped_b;
    }
    L->verified = !L->sys_M && !L->sys_b;
    return ULAM_OK;
}

/* See ulam_load.h. */
int ulam_load_verify(ulam_load *L, ulam_error *err)
{
    if (L->verified) return ULAM_OK;
    int status = L->sys_M ? ulam_system_check(L->sys_M, err) : ULAM_OK;
    const char *path = L->matrix_path;
    if (!status && L->sys_b && (status = ulam_system_check(L->sys_b, err))) path = L->rhs_path;
    if (status) return ulam_load_free(L), at(err, path, status);
    L->verified = 1;
    return ULAM_OK;
}

/* Replace M and b by the Jacobi splitting of the loaded A (b zeros without one); a status. */
static int load_jacobi(ulam_load *L, ulam_error *err)
{
    int status = ulam_load_verify(L, err); /* a mapped copy is checked before the splitting reads it all */
    if (status) return status;
    int64_t n = L->M->nrows;
    ulam_csr *M = NULL;
    double *zeros = L->b ? NULL : calloc((size_t)n, sizeof *zeros), *bp = malloc((size_t)n * sizeof *bp);
    const double *b = L->b ? L->b : zeros;
    status = b && bp ? ulam_jacobi(L->M, b, L->omega > 0 ? L->omega : 1.0, &M, bp, err) : ULAM_ENOMEM;
    free(zeros);
    int with_b = L->b != NULL;
    if (status) {
        free(bp);
        if (status == ULAM_ENOMEM) err->status = status, err->line = 0, err->msg[0] = '\0';
        ulam_load_free(L);
        return at(err, L->matrix_path, status);
    }
    ulam_load_free(L);
    L->M = L->own_M = M;
    if (with_b) L->b = L->own_b = bp;
    else free(bp);
    L->verified = 1;
    return ULAM_OK;
}

/* Replace the loaded adjacency matrix by alpha P^T (ulam_pagerank_matrix) and, without a b, b by
 * (1 - alpha) / n; a status (nothing held on failure). */
static int load_pagerank(ulam_load *L, ulam_error *err)
{
    int status = ulam_load_verify(L, err);
    if (status) return status;
    ulam_csr *M = NULL;
    int64_t n = L->M->nrows;
    status = ulam_pagerank_matrix(L->M, L->pagerank, &M, err);
    double *b = status || L->b ? NULL : malloc((size_t)n * sizeof *b);
    if (!status && !L->b && !b) status = fail(err, ULAM_ENOMEM, "memory for b");
    double *keep_b = NULL;
    if (!status && !b && L->own_b) keep_b = L->own_b, L->own_b = NULL; /* a parsed b: keep it */
    else if (!status && !b) { /* a mapped b: copy it before the mapping goes */
        if (!(keep_b = malloc((size_t)n * sizeof *keep_b))) status = fail(err, ULAM_ENOMEM, "memory for b");
        for (int64_t i = 0; keep_b && i < n; i++) keep_b[i] = L->b[i];
    }
    if (status) {
        ulam_csr_free(M);
        ulam_load_free(L);
        return at(err, L->matrix_path, status);
    }
    for (int64_t i = 0; b && i < n; i++) b[i] = (1.0 - L->pagerank) / (double)n;
    ulam_load_free(L);
    L->M = L->own_M = M;
    L->b = L->own_b = b ? b : keep_b;
    L->verified = 1;
    L->b_pagerank = b != NULL;
    return ULAM_OK;
}

/* See ulam_load.h. */
int ulam_load_finish(ulam_load *L, ulam_error *err)
{
    *err = (ulam_error){.status = ULAM_OK, .index = -1};
    if (!L || !L->M) return fail(err, ULAM_EINVAL, "a system loaded by ulam_load_open");
    int status = L->jacobi ? load_jacobi(L, err) : ULAM_OK;
    if (!status && L->pagerank > 0) status = load_pagerank(L, err);
    if (!status && !L->lazy) status = ulam_load_verify(L, err);
    if (!status && L->lazy && L->sys_b && (status = ulam_system_check(L->sys_b, err))) { /* b's own file: whole */
        ulam_load_free(L);
        return at(err, L->rhs_path, status);
    }
    return status;
}
