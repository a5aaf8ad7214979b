/* Shared pieces of the command-line tool. */
#include "cli.h"

#include <errno.h>
#include <signal.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

volatile int cli_interrupted;
const ulam_share *cli_share;
int cli_rank;

/* SIGINT: the first asks the walks to stop, the second exits at once. */
static void on_sigint(int sig)
{
    (void)sig;
    if (cli_interrupted) _exit(EXIT_INTERRUPTED);
    cli_interrupted = 1;
}

/* Catch SIGINT; a write blocked on a full pipe is restarted after the first. */
void cli_catch_sigint(void)
{
    struct sigaction sa = {.sa_handler = on_sigint, .sa_flags = SA_RESTART};
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
}

/* Restore the default SIGINT. */
void cli_release_sigint(void)
{
    signal(SIGINT, SIG_DFL);
}

/* Index of word in names[0..n), or -1. */
int cli_lookup(const char *word, const char *const *names, int n)
{
    for (int k = 0; k < n; k++)
        if (!strcmp(word, names[k])) return k;
    return -1;
}

/* The exit code for a library status. */
int cli_exit_code(int status)
{
    return status == ULAM_OK ? 0 : EXIT_STATUS_BASE + status;
}

/* Print a located error and return its exit code. */
int cli_report(const char *file, const ulam_error *err)
{
    fprintf(stderr, "ulam: ");
    if (err->file[0]) file = err->file;
    if (file && err->line > 0) fprintf(stderr, "%s:%ld: ", file, err->line);
    else if (file) fprintf(stderr, "%s: ", file);
    fprintf(stderr, "error: %s", ulam_strerror(err->status));
    if (err->msg[0]) fprintf(stderr, ": expected %s", err->msg);
    fputc('\n', stderr);
    return cli_exit_code(err->status);
}

/* Print a usage error and return EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "ulam %s: ", command);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, " (see 'ulam %s --help')\n", command);
    va_end(ap);
    return EXIT_USAGE;
}

/* Parse an integer option value in [lo, hi]. */
int cli_parse_int(const char *command, const char *opt, const char *s, int64_t lo, int64_t hi,
                  int64_t *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno == ERANGE || v < lo || v > hi)
        return cli_usage_error(command, "%s expects an integer from %lld to %lld, got '%s'", opt,
                               (long long)lo, (long long)hi, s);
    *out = v;
    return 0;
}

/* Parse a finite real option value in [lo, hi]. */
int cli_parse_real(const char *command, const char *opt, const char *s, double lo, double hi,
                   double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v) || v < lo || v > hi)
        return cli_usage_error(command, "%s expects a number from %g to %g, got '%s'", opt, lo, hi, s);
    *out = v;
    return 0;
}

/* Parse a byte count with an optional K, M, G or T suffix. */
int cli_parse_bytes(const char *command, const char *opt, const char *s, size_t *out)
{
    char *end;
    double v = strtod(s, &end);
    double scale = 1.0;
    if (*end && !end[1]) {
        const char *units = "KMGT";
        const char *u = strchr(units, *end == 'k' ? 'K' : *end);
        if (u) {
            scale = pow(1024.0, (double)(u - units + 1));
            end++;
        }
    }
    if (end == s || *end || !isfinite(v) || v <= 0 || v * scale > (double)SIZE_MAX / 2)
        return cli_usage_error(command, "%s expects a size such as 4G, 512M or 1000000, got '%s'",
                               opt, s);
    *out = (size_t)(v * scale);
    return 0;
}

/* The identity of a source file for its cache: size and modification time (ns). */
static int file_tag(const char *path, uint64_t tag[2])
{
    struct stat st;
    if (stat(path, &st)) return -1;
    tag[0] = (uint64_t)st.st_size;
    tag[1] = (uint64_t)st.st_mtim.tv_sec * 1000000000u + (uint64_t)st.st_mtim.tv_nsec;
    return 0;
}

/* Read a matrix (vec == NULL) or vector through its cache PATH.ulamcache when cache is set: a
 * cache for the file as it is now is read, else the file is parsed and the cache written
 * (a failure to write it is only a warning).  A library status, err filled. */
static int read_cached(const char *path, int cache, ulam_csr **A, double **vec, int64_t *n, ulam_error *err)
{
    char cpath[4200];
    uint64_t tag[2];
    double t0 = ulam_now();
    int use = cache && strlen(path) < 4096 && !file_tag(path, tag);
    if (use) {
        snprintf(cpath, sizeof cpath, "%s.ulamcache", path);
        int st = vec ? ulam_cache_read_vector(cpath, tag, vec, n, err) : ulam_cache_read_csr(cpath, tag, A, err);
        if (!st) {
            fprintf(stderr, "ulam: %s: loaded from its cache in %.3f s\n", path, ulam_now() - t0);
            return ULAM_OK;
        }
    }
    int status = vec ? ulam_mm_read_vector(path, vec, n, err) : ulam_mm_read_matrix(path, A, err);
    if (status || !use) return status;
    double parsed = ulam_now() - t0;
    int st = vec ? ulam_cache_write_vector(cpath, *vec, *n, tag) : ulam_cache_write_csr(cpath, *A, tag);
    if (st) fprintf(stderr, "ulam: %s: warning: cache not written: %s\n", cpath, ulam_strerror(st));
    else fprintf(stderr, "ulam: %s: parsed in %.3f s, cache written to %s\n", path, parsed, cpath);
    return ULAM_OK;
}

/* Load M (and b); 0 or an exit code. */
int cli_load_system(cli_system *s)
{
    ulam_error err;
    ulam_csr *A = NULL;
    int status = read_cached(s->matrix_path, s->cache, &A, NULL, NULL, &err);
    if (status) return cli_report(s->matrix_path, &err);
    if (A->nrows != A->ncols) {
        fprintf(stderr, "ulam: %s: error: %s: expected a square matrix, got %lld x %lld\n",
                s->matrix_path, ulam_strerror(ULAM_ENOTSQUARE), (long long)A->nrows,
                (long long)A->ncols);
        ulam_csr_free(A);
        return cli_exit_code(ULAM_ENOTSQUARE);
    }
    int64_t n = A->nrows, nb = n;
    double *b = NULL;
    if (s->rhs_path) {
        status = read_cached(s->rhs_path, s->cache, NULL, &b, &nb, &err);
        if (status) {
            ulam_csr_free(A);
            return cli_report(s->rhs_path, &err);
        }
        if (nb != n) {
            fprintf(stderr, "ulam: %s: error: %s: expected %lld entries to match %s, got %lld\n",
                    s->rhs_path, ulam_strerror(ULAM_EDIM), (long long)n, s->matrix_path,
                    (long long)nb);
            ulam_csr_free(A);
            free(b);
            return cli_exit_code(ULAM_EDIM);
        }
    } else if (s->jacobi) {
        b = calloc((size_t)n, sizeof *b);
    }
    if (s->jacobi) {
        ulam_csr *M = NULL;
        double *bp = malloc((size_t)n * sizeof *bp);
        status = b && bp ? ulam_jacobi(A, b, s->omega > 0 ? s->omega : 1.0, &M, bp, &err) : ULAM_ENOMEM;
        ulam_csr_free(A);
        free(b);
        if (status) {
            free(bp);
            if (status == ULAM_ENOMEM) err.status = status, err.line = 0, err.msg[0] = '\0';
            return cli_report(s->matrix_path, &err);
        }
        A = M;
        b = s->rhs_path ? bp : (free(bp), (double *)NULL);
    }
    s->M = A;
    s->b = b;
    if (s->index > A->nrows) {
        int rc = cli_usage_error(s->command, "--index %lld is out of range 1..%lld",
                                 (long long)s->index, (long long)A->nrows);
        cli_system_free(s);
        return rc;
    }
    return 0;
}

/* Free what cli_load_system loaded. */
void cli_system_free(cli_system *s)
{
    s->M = ulam_csr_free(s->M);
    free(s->b);
    s->b = NULL;
}

/* Solve the loaded system densely into a new *x; 0 or an exit code. */
int cli_direct_solve(const cli_system *s, size_t max_mem, double **x, ulam_direct_info *info)
{
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the solution"};
    *x = malloc((size_t)s->M->nrows * sizeof **x);
    int status = *x ? ulam_direct_solve(s->M, s->b, *x, max_mem, info, &err) : ULAM_ENOMEM;
    if (!status) return 0;
    free(*x);
    *x = NULL;
    return cli_report(s->matrix_path, &err);
}

/* Print a bare JSON number (null when not finite). */
void cli_json_value(double v)
{
    if (isfinite(v)) printf("%.17g", v);
    else printf("null");
}

/* Print a JSON number (null when not finite). */
void cli_json_number(const char *key, double v, int last)
{
    printf("\"%s\": ", key);
    cli_json_value(v);
    printf("%s", last ? "" : ", ");
}

/* Print a JSON string (escaped). */
void cli_json_string(const char *key, const char *v, int last)
{
    printf("\"%s\": \"", key);
    for (const unsigned char *c = (const unsigned char *)v; *c; c++) {
        if (*c == '"' || *c == '\\') printf("\\%c", *c);
        else if (*c < 0x20) printf("\\u%04x", *c);
        else putchar(*c);
    }
    printf("\"%s", last ? "" : ", ");
}
