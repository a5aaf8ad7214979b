/* Graphs on the command line: --pagerank ALPHA (--damping) reads the file (an adjacency matrix in
 * Matrix Market, or an edge list: src/edgelist.c) as a graph and solves PageRank's
 * (I - alpha P^T) x = (1 - alpha) / n (b from --rhs if given); a seed set (--source 3,7,9 or a
 * file) is a personalisation vector; a single-source or seed-set answer is reported as
 * pi = (1 - alpha) x, as PPR tools report it. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* True when spec is a list of node ids ("3,7,9": digits and commas, at least one comma). */
int cli_seeds_is_list(const char *spec)
{
    return strspn(spec, "0123456789,") == strlen(spec) && strchr(spec, ',');
}

/* See cli.h. */
int cli_parse_damping(const char *command, const char *s, double *alpha)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !(v >= 1e-6 && v <= 1 - 1e-9))
        return cli_usage_error(command, "--pagerank expects a damping factor alpha with 0 < alpha < 1 (from 1e-06 to "
                               "1 - 1e-09; at 1 no rank is ever teleported and I - alpha P^T is singular), got '%s'", s);
    *alpha = v;
    return 0;
}

/* Node id v of the command line (cli_node_base) as a 0-based state < n into *i; 0 or a usage
 * error naming where it came from. */
static int seed_state(const char *where, long line, int64_t v, int64_t n, int64_t *i)
{
    if (v >= cli_node_base && v - cli_node_base < n) return *i = v - cli_node_base, 0;
    if (line) return cli_usage_error("solve", "%s:%ld: seed node %lld is out of range %lld..%lld", where, line,
                                     (long long)v, (long long)cli_node_base, (long long)(n - 1 + cli_node_base));
    return cli_usage_error("solve", "--source %s: seed node %lld is out of range %lld..%lld", where, (long long)v,
                           (long long)cli_node_base, (long long)(n - 1 + cli_node_base));
}

/* See cli.h. */
int cli_seeds_parse(const char *spec, int64_t n, double *w)
{
    int64_t i = 0;
    int rc;
    for (int64_t k = 0; k < n; k++) w[k] = 0.0;
    if (cli_seeds_is_list(spec)) {
        for (const char *p = spec; *p;) {
            char *end;
            errno = 0;
            long long v = strtoll(p, &end, 10);
            if (end == p || errno) return cli_usage_error("solve", "--source expects node ids separated by commas "
                                                          "(3,7,9), got '%s'", spec);
            if ((rc = seed_state(spec, 0, v, n, &i))) return rc;
            w[i] += 1.0;
            p = *end == ',' ? end + 1 : end;
        }
    } else {
        FILE *f = fopen(spec, "r");
        if (!f) /* not a node id, nor a list: a file of seeds, missing (exit 13, as a missing matrix) */
            return cli_report_read(spec, "--source seeds file (or a node id, or ids separated by commas: 3,7,9)",
                                   errno);
        char line[512];
        long ln = 0;
        rc = 0;
        errno = 0;
        while (!rc && fgets(line, sizeof line, f)) {
            ln++;
            char *p = line, *end;
            while (*p == ' ' || *p == '\t') p++;
            if (!*p || *p == '#' || *p == '%' || *p == '\n' || *p == '\r') continue;
            errno = 0;
            long long v = strtoll(p, &end, 10);
            double x = 1.0;
            int ok = end != p && !errno && *p != '-' && *p != '+';
            p = end;
            if (ok && (*p == ' ' || *p == '\t' || *p == ',')) {
                p += strspn(p, " \t,");
                if (*p && *p != '\n' && *p != '\r' && *p != '#') {
                    x = strtod(p, &end);
                    ok = end != p && isfinite(x) && x >= 0.0;
                    p = end;
                }
            }
            p += strspn(p, " \t\r\n");
            if (!ok || (*p && *p != '#'))
                rc = cli_usage_error("solve", "%s:%ld: expected a seed 'id' or 'id weight' (weight finite and >= 0)",
                                     spec, ln);
            else if (!(rc = seed_state(spec, ln, v, n, &i)))
                w[i] += x;
        }
        if (!rc && ferror(f)) rc = cli_report_read(spec, "--source seeds file", errno); /* a directory: EISDIR */
        fclose(f);
        if (rc) return rc;
    }
    double sum = 0.0;
    for (int64_t k = 0; k < n; k++) sum += w[k];
    if (!(sum > 0.0 && isfinite(sum)))
        return cli_usage_error("solve", "--source %s: expected seeds of positive total weight", spec);
    for (int64_t k = 0; k < n; k++) w[k] /= sum;
    return 0;
}

/* See cli.h. */
int cli_graph_augment(const ulam_csr *M, const double *w, double alpha, ulam_csr **out)
{
    int64_t n = M->nrows, k = 0;
    for (int64_t i = 0; i < n; i++) k += w[i] != 0.0;
    ulam_csr *A = ulam_csr_alloc(n + 1, n + 1, M->rowptr[n] + k);
    if (!A) return ULAM_ENOMEM;
    int64_t at = 0;
    for (int64_t i = 0; i < n; i++) {
        A->rowptr[i] = at;
        for (int64_t p = M->rowptr[i]; p < M->rowptr[i + 1]; p++) A->colidx[at] = M->colidx[p], A->val[at++] = M->val[p];
        if (w[i] != 0.0) A->colidx[at] = (int32_t)n, A->val[at++] = alpha * w[i]; /* column n is the last */
    }
    A->rowptr[n] = A->rowptr[n + 1] = at;
    *out = A;
    return ULAM_OK;
}
