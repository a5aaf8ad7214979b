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

const char *const cli_mode_names[2] = {"adjoint", "forward"};
const char *const cli_estimator_names[3] = {"collision", "absorption", "expected"};

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
    if (end != s && (*end == 'e' || *end == 'E' || *end == '.')) { /* 1e12, 2.5e6: whole numbers */
        double d = strtod(s, &end);
        int whole = !*end && d == floor(d) && fabs(d) <= 9007199254740992.0; /* 2^53: exact */
        v = whole ? (long long)d : v, errno = whole ? 0 : ERANGE;
    }
    if (end == s || *end || errno == ERANGE || v < lo || v > hi)
        return cli_usage_error(command, "%s expects an integer from %lld to %lld%s, got '%s'", opt,
                               (long long)lo, (long long)hi,
                               lo == 1 && v == 0 && (strstr(opt, "index") || strstr(opt, "source") || strstr(opt, "patch"))
                                   ? " (1-based, as in Matrix Market files)" : "", s);
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

/* The matrix (vec == NULL) or b a prepared system holds, unverified (NULL: none). */
static const void *held(const ulam_system *sys, const double **vec)
{
    const ulam_csr *M = NULL;
    const double *b = NULL;
    ulam_system_lazy(sys, &M, &b);
    return vec ? (const void *)b : (const void *)M;
}

/* Read a matrix (vec == NULL) or vector.  A prepared file is mapped (*sys); with cache, its
 * copy PATH.ulamcache (a prepared file) is mapped when it was made from the file as it is now,
 * else the file is parsed (*A or *vec) and the copy written (a failure to write it is only a
 * warning).  A library status, err filled. */
static int read_input(const char *path, int cache, ulam_system **sys, ulam_csr **A, double **vec, int64_t *n,
                      ulam_error *err)
{
    char cpath[4200];
    uint64_t tag[2];
    double t0 = ulam_now();
    if (ulam_system_is_file(path)) {
        int status = ulam_system_open(path, NULL, sys, err);
        if (!status && !held(*sys, (const double **)vec)) {
            *sys = ulam_system_free(*sys);
            *err = (ulam_error){.status = ULAM_ENOTFOUND, .index = -1};
            snprintf(err->msg, sizeof err->msg, "%s", vec ? "a prepared system holding b (prepare it with --rhs)"
                                                          : "a prepared system holding a matrix (this one holds only b)");
            status = ULAM_ENOTFOUND;
        }
        return status;
    }
    int use = cache && strlen(path) < 4096 && !ulam_file_tag(path, tag, NULL); /* the source's content hash */
    if (use) {
        snprintf(cpath, sizeof cpath, "%s.ulamcache", path);
        if (!ulam_system_open(cpath, tag, sys, err) && held(*sys, (const double **)vec)) {
            fprintf(stderr, "ulam: %s: loaded from its cache in %.3f s\n", path, ulam_now() - t0);
            return ULAM_OK;
        }
        *sys = ulam_system_free(*sys);
    }
    int status = vec ? ulam_mm_read_vector(path, vec, n, err) : ulam_mm_read_matrix(path, A, err);
    if (status || !use) return status;
    double parsed = ulam_now() - t0;
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = vec ? NULL : *A, d.b = vec ? *vec : NULL, d.n = vec ? *n : (*A)->nrows;
    d.tag[0] = tag[0], d.tag[1] = tag[1];
    int st = ulam_system_write(cpath, &d);
    if (st) fprintf(stderr, "ulam: %s: warning: cache not written: %s\n", cpath, ulam_strerror(st));
    else fprintf(stderr, "ulam: %s: parsed in %.3f s, cache written to %s\n", path, parsed, cpath);
    return ULAM_OK;
}

/* Check a mapped M and b whole if not yet done. */
int cli_system_verify(cli_system *s)
{
    ulam_error err;
    if (s->verified) return 0;
    if (s->sys_M && ulam_system_check(s->sys_M, &err)) {
        cli_system_free(s);
        return cli_report(s->matrix_path, &err);
    }
    if (s->sys_b && ulam_system_check(s->sys_b, &err)) {
        cli_system_free(s);
        return cli_report(s->rhs_path, &err);
    }
    s->verified = 1;
    return 0;
}

/* Replace M and b by the Jacobi splitting of the loaded A (b zeros without --rhs). */
static int load_jacobi(cli_system *s)
{
    int rc = cli_system_verify(s); /* a mapped copy is checked before the splitting reads it all */
    if (rc) return rc;
    ulam_error err;
    int64_t n = s->M->nrows;
    ulam_csr *M = NULL;
    double *zeros = s->b ? NULL : calloc((size_t)n, sizeof *zeros), *bp = malloc((size_t)n * sizeof *bp);
    const double *b = s->b ? s->b : zeros;
    int status = b && bp ? ulam_jacobi(s->M, b, s->omega > 0 ? s->omega : 1.0, &M, bp, &err) : ULAM_ENOMEM;
    free(zeros);
    int with_b = s->b != NULL;
    if (status) {
        free(bp);
        if (status == ULAM_ENOMEM) err.status = status, err.line = 0, err.msg[0] = '\0';
        cli_system_free(s);
        return cli_report(s->matrix_path, &err);
    }
    cli_system_free(s);
    s->M = s->own_M = M;
    if (with_b) s->b = s->own_b = bp;
    else free(bp);
    s->verified = 1;
    return 0;
}

/* See cli.h. */
int cli_need_rhs(const char *command, const char *path)
{
    size_t len = strlen(path);
    if ((len > 5 && !strcmp(path + len - 5, ".ulam")) || (len > 10 && !strcmp(path + len - 10, ".ulamcache"))) {
        ulam_system *sys = NULL;
        ulam_error err;
        int status = ulam_system_open(path, NULL, &sys, &err); /* says why it is not one */
        ulam_system_free(sys);
        if (status) return cli_report(path, &err);
    }
    return cli_usage_error(command, "needs --rhs b.mtx");
}

/* Load M (and b); 0 or an exit code. */
int cli_load_system(cli_system *s)
{
    ulam_error err;
    int prepared = ulam_system_is_file(s->matrix_path);
    if (prepared && (s->jacobi || s->pagerank > 0))
        return cli_usage_error(s->command, "%s is a prepared system: it holds M already (prepare it with --jacobi)",
                               s->matrix_path);
    int status = read_input(s->matrix_path, s->cache, &s->sys_M, &s->own_M, NULL, NULL, &err);
    if (status) return cli_report(s->matrix_path, &err);
    const ulam_csr *mapped = NULL;
    const double *mapped_b = NULL;
    ulam_system_lazy(s->sys_M, &mapped, &mapped_b); /* verified below, or as walks read it (lazy) */
    s->M = s->own_M ? s->own_M : mapped;
    if (prepared) s->cert = ulam_system_certificate(s->sys_M);
    if (s->M->nrows != s->M->ncols) {
        fprintf(stderr, "ulam: %s: error: %s: expected a square matrix, got %lld x %lld\n",
                s->matrix_path, ulam_strerror(ULAM_ENOTSQUARE), (long long)s->M->nrows,
                (long long)s->M->ncols);
        cli_system_free(s);
        return cli_exit_code(ULAM_ENOTSQUARE);
    }
    int64_t n = s->M->nrows, nb = n;
    if (s->rhs_path) {
        status = read_input(s->rhs_path, s->cache, &s->sys_b, NULL, &s->own_b, &nb, &err);
        if (status) {
            cli_system_free(s);
            return cli_report(s->rhs_path, &err);
        }
        const double *vb = NULL;
        ulam_system_lazy(s->sys_b, NULL, &vb);
        if (s->sys_b) ulam_system_rhs(s->sys_b, &nb);
        s->b = s->own_b ? s->own_b : vb;
        if (nb != n) {
            fprintf(stderr, "ulam: %s: error: %s: expected %lld entries to match %s, got %lld\n",
                    s->rhs_path, ulam_strerror(ULAM_EDIM), (long long)n, s->matrix_path,
                    (long long)nb);
            cli_system_free(s);
            return cli_exit_code(ULAM_EDIM);
        }
    } else if (prepared) {
        s->b = mapped_b;
    }
    s->verified = !s->sys_M && !s->sys_b;
    int rc = s->jacobi ? load_jacobi(s) : 0;
    if (!rc && s->pagerank > 0) rc = cli_load_pagerank(s);
    if (!rc && !s->lazy) rc = cli_system_verify(s);
    if (!rc && s->lazy && s->sys_b && ulam_system_check(s->sys_b, &err)) { /* a b of its own file: whole */
        cli_system_free(s);
        return cli_report(s->rhs_path, &err);
    }
    if (rc) return rc;
    if (s->index > s->M->nrows) {
        rc = cli_usage_error(s->command, "--index %lld is out of range 1..%lld",
                             (long long)s->index, (long long)s->M->nrows);
        cli_system_free(s);
        return rc;
    }
    return 0;
}

/* Free what cli_load_system loaded. */
void cli_system_free(cli_system *s)
{
    s->own_M = ulam_csr_free(s->own_M);
    free(s->own_b);
    s->own_b = NULL;
    s->sys_M = ulam_system_free(s->sys_M);
    s->sys_b = ulam_system_free(s->sys_b);
    s->M = NULL, s->b = NULL, s->cert = NULL;
}

/* Solve the loaded system densely into a new *x; 0 or an exit code. */
int cli_direct_solve(const cli_system *s, size_t max_mem, double **x, ulam_direct_info *info)
{
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the solution"};
    *x = malloc((size_t)s->M->nrows * sizeof **x);
    int status = !*x ? ULAM_ENOMEM : cli_direct_sparse_wanted(s->M) ? ulam_direct_sparse(s->M, s->b, *x, max_mem, info, &err)
                                                                  : ulam_direct_solve(s->M, s->b, *x, max_mem, info, &err);
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
    cli_json_done = 1;
    printf("\"%s\": ", key);
    cli_json_value(v);
    printf("%s", last ? "" : ", ");
}

/* Print a JSON string (escaped). */
void cli_json_string(const char *key, const char *v, int last)
{
    cli_json_done = 1;
    printf("\"%s\": \"", key);
    for (const unsigned char *c = (const unsigned char *)v; *c; c++) {
        if (*c == '"' || *c == '\\') printf("\\%c", *c);
        else if (*c < 0x20) printf("\\u%04x", *c);
        else putchar(*c);
    }
    printf("\"%s", last ? "" : ", ");
}

/* Check before any work that path can be written (a temporary file can be made beside it and
 * it is not a directory); 0 or an exit code (reported). */
int cli_check_output(const char *path)
{
    struct stat st;
    ulam_outfile o;
    int status = stat(path, &st) == 0 && S_ISDIR(st.st_mode) ? ULAM_EIO : ulam_outfile_open(&o, path);
    if (!status) ulam_outfile_abort(&o);
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable output file (in an existing, writable directory; not a "
                                               "directory)"};
    return cli_report(path, &err);
}

/* Start a progress line: only on a terminal, never with --json, only on rank 0. */
void cli_progress_start(cli_progress *p, int json)
{
    p->on = !json && cli_rank == 0 && isatty(2);
    p->t0 = p->last = ulam_now();
    p->shown = 0;
}

/* Show walks, the estimate +- its standard error, the time elapsed and the time left at this
 * rate: the least of what the relative-error target (the error falls as 1 / sqrt(walks)), the
 * walk budget and the time limit of o leave; at most 4 a second. */
void cli_progress_show(cli_progress *p, int64_t walks, double estimate, double se, const ulam_walk_opts *o)
{
    double now = ulam_now(), el = now - p->t0;
    if (!p->on || now - p->last < 0.25) return;
    p->last = now, p->shown = 1;
    fprintf(stderr, "\rulam: %lld walks, %.6g +- %.2g, %.1f s", (long long)walks, estimate, se, el);
    double want = o->rel_err * fabs(estimate), left = INFINITY;
    if (o->rel_err > 0 && want > 0 && se > want) left = el * ((se / want) * (se / want) - 1);
    if (o->max_walks > 0 && walks > 0) left = fmin(left, el * ((double)o->max_walks / (double)walks - 1));
    if (o->max_seconds > 0) left = fmin(left, o->max_seconds - el);
    if (isfinite(left)) left < 1 ? fputs(", under 1 s left", stderr) : fprintf(stderr, ", about %.0f s left", left);
    fputs("      ", stderr);
}

/* End the progress line (a newline if anything was shown). */
void cli_progress_end(cli_progress *p)
{
    if (p->on && p->shown) fputc('\n', stderr);
    p->shown = 0;
}
