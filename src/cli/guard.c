/* The stability guards as the commands report them: refusal, warnings, verdict words. */
#include "cli.h"

#include <stdio.h>

/* A verdict in words. */
const char *cli_verdict_word(int verdict)
{
    return verdict == ULAM_VERDICT_OK ? "below 1" : verdict == ULAM_VERDICT_EDGE ? "within 1% of 1" : "at or above 1";
}

/* Print a radius as "0.900000 (certified in [lo, hi], k iterations)". */
void cli_print_power(const ulam_power *p)
{
    printf("%.6f (bounds [%.6f, %.6f], %d iterations, %.3f s%s)", p->rho, p->lower, p->upper,
           p->iterations, p->seconds, p->converged ? "" : ", NOT converged");
}

/* Run the guards for a walk in mode on s; 0 to go on, EXIT_DIVERGE (message printed) to stop.
 * A prepared file's certificate made for this continuation serves instead of a pass over M
 * (ulam_certificate_guard); otherwise a mapped M is verified whole first. */
int cli_guard(cli_system *s, double continue_q, int mode, int force, ulam_guard *g)
{
    ulam_error err;
    if (ulam_certificate_guard(s->cert, continue_q, NULL, g)) {
        int rc = cli_system_verify(s);
        if (rc) return rc;
        int status = ulam_guard_check(s->M, continue_q, NULL, g, &err);
        if (status) return cli_report(s->matrix_path, &err);
    }
    if (g->verdict_abs == ULAM_VERDICT_FAIL) {
        fprintf(stderr,
                "ulam: %s: %s: rho(|M|) = %.6g (bounds [%.6g, %.6g]) is >= 1, so the walks' expected "
                "score is a divergent series and any estimate with an error bar would be garbage. "
                "Solve it with 'ulam direct'%s.%s\n",
                s->matrix_path, force ? "warning" : "error", g->abs.rho, g->abs.lower, g->abs.upper,
                s->jacobi ? " (damping with --omega cannot help: rho(|I - w D^-1 A|) = 1 - w + w rho(|J|))"
                          : ", or if the file holds A of A x = b, try --jacobi",
                force ? " Running anyway (--force)." : " --force runs the walks anyway.");
        if (!force) return EXIT_DIVERGE;
    } else if (g->verdict_abs == ULAM_VERDICT_EDGE) {
        fprintf(stderr, "ulam: %s: warning: rho(|M|) = %.6g is within 1%% of 1: walks will be long "
                        "(mean length about 1 / (1 - rho))\n", s->matrix_path, g->abs.rho);
    }
    const ulam_power *h = &g->hat[mode];
    if (g->verdict_hat[mode] == ULAM_VERDICT_FAIL)
        fprintf(stderr, "ulam: %s: warning: rho(M^) = %.6g >= 1 for the %s kernel: the estimator's "
                        "variance is infinite, so no error bar it reports can be trusted\n",
                s->matrix_path, h->rho, mode == ULAM_ADJOINT ? "adjoint" : "forward");
    else if (g->verdict_hat[mode] == ULAM_VERDICT_EDGE)
        fprintf(stderr, "ulam: %s: warning: rho(M^) = %.6g is within 1%% of 1: the variance is finite "
                        "but huge, and the error bar converges slowly\n", s->matrix_path, h->rho);
    return 0;
}
