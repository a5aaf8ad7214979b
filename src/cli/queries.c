/* ulam solve SYSTEM --queries FILE: many queries on one system in one process, the analysis
 * (guards, bounds, kept kernels, transpose, push workspace) made once and kept across them.
 *
 * A line is `I` (x_I of (I - M) x = b, b the system's or --rhs), or `S I` (x_I with b = e_S: a
 * point source, by the bidirectional method), then optionally a relative-error target for that
 * line alone written as a real with a point or an exponent (0.01, 1e-3); indices are 1-based
 * integers; '#' starts a comment; blank lines are skipped.  Query k (1-based, in file order)
 * walks with the seed ulam_rng_substream(--seed, ULAM_STREAM_QUERY, k - 1) it prints (docs/streams.md),
 * so it answers exactly what `ulam solve --method walks --index I --seed SEED` with that printed seed
 * answers on a prepared file (and on a Matrix Market file at fixed --walks; a
 * --rel-err run there walks under bounds over every state, which may ask for more walks than a
 * lone run's search of its start's reach).  One result a line, flushed as it is made: Ctrl-C
 * stops the query under way and keeps the answered lines (exit 130).  The whole file is read
 * and checked before the first query runs: a bad line is an error (file:line) with no output.
 * A line whose target (its own or --rel-err) was not met makes the exit EXIT_TARGET (5) once
 * every line is answered.
 * The queries themselves are the library's (ulam_analysis_query, src/queries.c); this file reads
 * the file, loads the system and prints. */
#include "cli.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef cli_query query;

/* Nonzero when token t is written as a real (a point or an exponent), not an index. */
static int real_token(const char *t)
{
    return strpbrk(t, ".eE") != NULL;
}

/* Parse one line into q: 1 a query, 0 nothing (blank or comment), -1 malformed (why set). */
static int parse_line(char *text, query *q, const char **why)
{
    char *hash = strchr(text, '#');
    if (hash) *hash = '\0';
    char *tok[4];
    int n = 0;
    for (char *t = strtok(text, " \t\r\n"); t; t = strtok(NULL, " \t\r\n")) {
        if (n == 3) return *why = "at most 'SOURCE INDEX TARGET'", -1;
        tok[n++] = t;
    }
    if (n == 0) return 0;
    int ints = n - (n > 1 && real_token(tok[n - 1]));
    if (ints < 1 || ints > 2) return *why = "'INDEX', 'SOURCE INDEX', either followed by a target like 0.01", -1;
    int64_t v[2];
    for (int k = 0; k < ints; k++) {
        char *end;
        errno = 0;
        long long x = strtoll(tok[k], &end, 10);
        if (*end || errno || x < cli_node_base || x > ULAM_MAX_DIM)
            return *why = cli_node_base ? "1-based integer indices" : "node ids (0-based, as in the edge list)", -1;
        v[k] = x - cli_node_base;
    }
    q->source = ints == 2 ? v[0] : -1, q->index = v[ints - 1], q->target = 0.0;
    if (ints < n) {
        char *end;
        q->target = strtod(tok[n - 1], &end);
        if (*end || !(q->target > 0 && q->target < 1)) return *why = "a target between 0 and 1 (exclusive)", -1;
    }
    return 1;
}

/* Read every query of path ("-": stdin) into *out (*nq of them); 0 or an exit code. */
int cli_read_queries(const char *path, query **out, int64_t *nq)
{
    FILE *f = strcmp(path, "-") ? fopen(path, "r") : stdin;
    if (!f) return cli_report_read(path, "query file", errno);
    query *q = NULL;
    int64_t cap = 0, n = 0;
    char buf[4096];
    int rc = 0;
    errno = 0;
    for (long line = 1; !rc && fgets(buf, sizeof buf, f); line++) {
        const char *why = NULL;
        query one = {.line = line};
        int got = strchr(buf, '\n') || feof(f) ? parse_line(buf, &one, &why) : (why = "lines under 4096 bytes", -1);
        if (got < 0) {
            fprintf(stderr, "ulam: %s:%ld: error: expected %s\n", path, line, why);
            rc = EXIT_USAGE;
        } else if (got && n == cap) {
            cap = cap ? 2 * cap : 64;
            query *g = realloc(q, (size_t)cap * sizeof *q);
            if (!g) rc = cli_exit_code(ULAM_ENOMEM);
            else q = g;
        }
        if (!rc && got > 0) q[n++] = one;
    }
    if (!rc && ferror(f)) rc = cli_report_read(path, "query file", errno); /* a directory: EISDIR */
    if (f != stdin) fclose(f);
    if (rc) free(q), q = NULL, n = 0;
    *out = q, *nq = n;
    return rc;
}

/* Everything the queries share. */
typedef struct {
    cli_system *s;
    ulam_analysis *an;
    const char *path;
    ulam_guard g, gt; /* the guards of M and (point sources, ulam_analysis_query's) of its transpose */
} shared;

/* Run query k with options o (its seed and target set) by ulam_analysis_query and print its line;
 * 0, an exit code, or EXIT_INTERRUPTED. */
static int run_query(shared *w, const query *q, int64_t k, const ulam_walk_opts *o, int json, int *unmet)
{
    ulam_error err;
    int interrupted;
    ulam_query_report a = {.query = k, .line = q->line, .source = q->source, .index = q->index,
                           .answer_name = cli_answer_name, .node_base = cli_node_base};
    int status = ulam_analysis_query(w->an, w->s->b, o, &w->gt, &a, &interrupted, &err);
    if (status) {
        fprintf(stderr, "ulam: %s: query %lld (line %ld): ", w->path, (long long)k + 1, q->line);
        return cli_report(w->s->matrix_path, &err);
    }
    if (interrupted) return EXIT_INTERRUPTED; /* the answered lines stay; this one is not an answer */
    double pi = q->source >= 0 && w->s->pagerank > 0 && strcmp(cli_answer_name, "x") ? 1.0 - w->s->pagerank : 1.0;
    a.estimate *= pi, a.std_error *= pi, a.ci95[0] *= pi, a.ci95[1] *= pi; /* b = e_S: pi = (1 - alpha) x */
    cli_json_done |= json;
    ulam_report_fprint(stdout, ULAM_REPORT_QUERY, &a, json ? ULAM_REPORT_JSON : ULAM_REPORT_BRIEF);
    fflush(stdout);
    *unmet += o->stop.rel_err > 0 && !a.rel_err_met;
    return 0;
}

/* ulam solve --queries (see the top of this file); s not loaded yet, o the command line's walk
 * options (adjoint), walks_given: --walks or --time was given. */
int cli_queries(cli_system *s, const ulam_walk_opts *o, const char *path, int json, int walks_given)
{
    query *q = NULL;
    int64_t nq = 0;
    int rc = cli_read_queries(path, &q, &nq), need_b = 0;
    for (int64_t k = 0; k < nq; k++) need_b |= q[k].source < 0;
    s->lazy = 1;
    if (!rc) rc = cli_load_system(s);
    if (rc) {
        free(q);
        return rc;
    }
    shared w = {.s = s, .path = path};
    const int64_t n = s->M->nrows;
    for (int64_t k = 0; !rc && k < nq; k++)
        if (q[k].index >= n || q[k].source >= n) {
            fprintf(stderr, "ulam: %s:%ld: error: expected indices from %lld to %lld\n", path, q[k].line,
                    (long long)cli_node_base, (long long)(n - 1 + cli_node_base));
            rc = EXIT_USAGE;
        }
    if (!rc && need_b && !s->b) rc = cli_usage_error("solve", "--queries with 'INDEX' lines needs b (--rhs b.mtx)");
    if (!rc) rc = cli_guard(s, o->kernel.continue_q, o->kernel.kernel_alpha, ULAM_ADJOINT, &w.g);
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.continue_q = o->kernel.continue_q, ao.kernel_alpha = o->kernel.kernel_alpha, ao.b = s->b, ao.system = s->sys_M;
    ulam_error err;
    if (!rc && ulam_analysis_alloc(s->M, &ao, &w.an, &err)) rc = cli_report(s->matrix_path, &err);
    ulam_walk_opts base = *o;
    base.policy.guard = &w.g, base.stop.interrupt = &cli_interrupted, base.mode = ULAM_ADJOINT;
    cli_catch_sigint();
    int unmet = 0; /* lines whose target was not met: exit EXIT_TARGET once every line is answered */
    for (int64_t k = 0; !rc && k < nq; k++) {
        ulam_walk_opts ok = base;
        ok.exec.seed = ulam_rng_substream(o->exec.seed, ULAM_STREAM_QUERY, (uint64_t)k); /* printed with the answer */
        if (q[k].target > 0) ok.stop.rel_err = q[k].target, ok.stop.max_walks = walks_given ? ok.stop.max_walks : 0;
        rc = run_query(&w, &q[k], k, &ok, json, &unmet);
    }
    if (!rc && unmet) {
        int64_t asked = 0;
        for (int64_t k = 0; k < nq; k++) asked += q[k].target > 0 || o->stop.rel_err > 0;
        fprintf(stderr, "ulam: %s: %d of %lld relative-error targets NOT met (JSON: rel_err_met false): the walks "
                        "stopped first (--walks, --time or the cap); exit %d\n", path, unmet, (long long)asked, EXIT_TARGET);
        rc = EXIT_TARGET;
    }
    fflush(stdout);
    cli_release_sigint();
    ulam_analysis_free(w.an);
    cli_system_free(s);
    free(q);
    return rc;
}
