/* Graphs on the command line: --pagerank ALPHA (--damping) reads the file as an adjacency matrix
 * and solves PageRank's (I - alpha P^T) x = (1 - alpha) / n (b from --rhs if given). */
#include "cli.h"

#include <stdio.h>
#include <stdlib.h>

/* Replace the loaded adjacency matrix by alpha P^T (ulam_pagerank_matrix) and, without --rhs, b by
 * (1 - alpha) / n; 0 or an exit code (nothing stays loaded on failure). */
int cli_load_pagerank(cli_system *s)
{
    int rc = cli_system_verify(s);
    if (rc) return rc;
    ulam_error err;
    ulam_csr *M = NULL;
    int64_t n = s->M->nrows;
    int status = ulam_pagerank_matrix(s->M, s->pagerank, &M, &err);
    double *b = status || s->b ? NULL : malloc((size_t)n * sizeof *b);
    if (!status && !s->b && !b) status = ULAM_ENOMEM, err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for b"};
    if (status) {
        cli_system_free(s);
        return cli_report(s->matrix_path, &err);
    }
    if (b)
        for (int64_t i = 0; i < n; i++) b[i] = (1.0 - s->pagerank) / (double)n;
    double *keep_b = NULL;
    if (!b && s->own_b) keep_b = s->own_b, s->own_b = NULL; /* --rhs parsed: keep it */
    else if (!b) { /* --rhs mapped: copy it before the mapping goes */
        keep_b = malloc((size_t)n * sizeof *keep_b);
        if (!keep_b) {
            ulam_csr_free(M);
            cli_system_free(s);
            err = (ulam_error){.status = ULAM_ENOMEM, .msg = "memory for b"};
            return cli_report(s->matrix_path, &err);
        }
        for (int64_t i = 0; i < n; i++) keep_b[i] = s->b[i];
    }
    cli_system_free(s);
    s->M = s->own_M = M;
    s->b = s->own_b = b ? b : keep_b;
    s->verified = 1;
    return 0;
}
