/* The stability guards as the commands report them: refusal messages, warnings, verdict words. */
#include "cli.h"

#include <math.h>
#include <stdio.h>

/* A hint naming the option that fits how M looks: a diagonal of magnitude >= 1 in at least half
 * the rows is A of A x = b (--jacobi); nonnegative whole-number weights off an empty diagonal with
 * some row sum above 1 are a graph's adjacency matrix (--pagerank); else "". */
const char *cli_system_hint(const ulam_csr *M)
{
    int64_t n = M->nrows, big_diag = 0, diag = 0, heavy = 0;
    int whole = 1;
    for (int64_t i = 0; i < n; i++) {
        double sum = 0.0;
        for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++) {
            double v = M->val[k];
            if (M->colidx[k] == i) diag += v != 0.0, big_diag += fabs(v) >= 1.0;
            whole &= v >= 0.0 && v == floor(v);
            sum += fabs(v);
        }
        heavy += sum > 1.0;
    }
    if (n > 0 && 2 * big_diag >= n)
        return " The diagonal is large (|M_ii| >= 1 in most rows): if the file holds A of A x = b, add --jacobi to "
               "walk on M = I - D^-1 A.";
    if (whole && !diag && heavy)
        return " It looks like a graph's adjacency matrix (whole-number weights, empty diagonal): for PageRank add "
               "--pagerank 0.85 (M = 0.85 P^T).";
    return "";
}

/* The guards' radii for a walk in mode on s (rho(|M|) and that mode's rho(M^), stopped once
 * certified); 0 or an exit code (error reported). */
int cli_guard(cli_system *s, double continue_q, double alpha, int mode, ulam_guard *g)
{
    ulam_error err;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(mode);
    go.kernel_alpha = alpha;
    if (!ulam_certificate_guard(s->cert, continue_q, &go, g)) return 0;
    int rc = cli_system_verify(s);
    if (rc) return rc;
    int status = ulam_guard_check(s->M, continue_q, &go, g, &err);
    return status ? cli_report(s->matrix_path, &err) : 0;
}

/* The refusal of walks whose rho(|M|) is not certified below 1 (or its warning under --force). */
void cli_guard_diverge(const cli_system *s, const ulam_guard *g, int force)
{
    const ulam_power *a = &g->abs;
    const char *kind = force ? "warning" : "error";
    if (g->verdict_abs == ULAM_VERDICT_FAIL)
        fprintf(stderr, "ulam: %s: %s: rho(|M|) is >= 1 (certified: bounds [%.6g, %.6g]), so the walks' expected "
                        "score is a divergent series and any estimate with an error bar would be garbage. ",
                s->matrix_path, kind, a->lower, a->upper);
    else
        fprintf(stderr, "ulam: %s: %s: rho(|M|) is in [%.6g, %.6g] after %d iterations: the bounds straddle 1, so "
                        "whether the walks converge is unknown, and unknown is treated as divergent. ",
                s->matrix_path, kind, a->lower, a->upper, a->iterations);
    const char *hint = s->jacobi || s->pagerank > 0 ? "" : cli_system_hint(s->M);
    fprintf(stderr, "%s%s with 'ulam direct'%s.%s\n", hint[0] ? hint + 1 : "", hint[0] ? " Or solve M as it is" : "Solve it",
            hint[0] ? "" :
            s->jacobi ? " (damping with --omega cannot help: rho(|I - w D^-1 A|) = 1 - w + w rho(|J|))"
                      : ", or if the file holds A of A x = b, try --jacobi",
            force ? " Running anyway (--force)." : " --force runs the walks anyway.");
}

/* Warnings for radii near or past 1 that do not stop the run. */
void cli_guard_warn(const cli_system *s, const ulam_guard *g, int mode, int assume_finite)
{
    if (g->verdict_abs == ULAM_VERDICT_EDGE && cli_verbosity > 0) /* nothing to do about it: --verbose */
        fprintf(stderr, "ulam: %s: warning: rho(|M|) is certified below 1 but not below 0.99 (bounds [%.6g, %.6g)): "
                        "walks may be long (mean length about 1 / (1 - rho))\n", s->matrix_path, g->abs.lower,
                g->abs.upper);
    const ulam_power *h = &g->hat[mode];
    char kernel[96] = "", alpha[48] = ""; /* the kernel named by mode, and by its exponent when not 1 */
    if (g->kernel_alpha != 1.0) snprintf(alpha, sizeof alpha, " of exponent alpha = %g", g->kernel_alpha);
    snprintf(kernel, sizeof kernel, "%s kernel%s", cli_mode_names[mode], alpha);
    if (g->verdict_hat[mode] == ULAM_VERDICT_FAIL)
        fprintf(stderr, "ulam: %s: warning: rho(M^) >= 1 (bounds [%.6g, %.6g]) for the %s: the estimator's "
                        "variance is infinite, so no error bar it reports can be trusted\n",
                s->matrix_path, h->lower, h->upper, kernel);
    else if (g->verdict_hat[mode] == ULAM_VERDICT_UNKNOWN)
        fprintf(stderr, "ulam: %s: warning: rho(M^) of the %s is in [%.6g, %.6g] after %d iterations: "
                        "whether the variance is finite is unknown%s\n", s->matrix_path, kernel, h->lower,
                h->upper, h->iterations,
                assume_finite ? "; --assume-finite-variance: the interval is printed anyway"
                              : ", so it is treated as infinite: no confidence interval (--assume-finite-variance "
                                "prints one anyway)");
    else if (g->verdict_hat[mode] == ULAM_VERDICT_EDGE && cli_verbosity > 0)
        fprintf(stderr, "ulam: %s: warning: rho(M^) is certified below 1 but not below 0.99 (bounds [%.6g, %.6g)): "
                        "the variance is finite but may be huge, and the error bar converges slowly\n",
                s->matrix_path, h->lower, h->upper);
}
