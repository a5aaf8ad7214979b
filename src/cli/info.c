/* ulam info: what a matrix is, and whether its Neumann series and walks converge. */
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

static const char *const usage =
    "usage: ulam info M.mtx [--jacobi [--omega W]] [--tol T] [--json]\n"
    "\n"
    "Describe the iteration matrix M of (I - M) x = b: size, nonzeros per row, signs,\n"
    "row sums of |M| (the continuation probabilities of an analog walk), the spectral\n"
    "radii of M and |M| (restarted Arnoldi, relative residual tolerance T, default 1e-6),\n"
    "and whether the Neumann series sum M^k b converges (rho(M) < 1) and whether its\n"
    "random-walk estimate does (rho(|M|) < 1).\n"
    "\n"
    "  --jacobi     the file holds A of A x = b; describe M = I - omega D^-1 A\n"
    "  --omega W    damping of the Jacobi splitting (default 1)\n"
    "  --tol T      relative residual tolerance of the radius estimates\n"
    "  --json       print one JSON object\n";

/* Print the human-readable report. */
static void print_text(const cli_system *s, const ulam_csr_stats *st, const ulam_radius *r,
                       const ulam_radius *ra)
{
    printf("matrix           %s%s\n", s->matrix_path, s->jacobi ? " (Jacobi splitting of A)" : "");
    printf("n                %lld\n", (long long)st->n);
    printf("nnz              %lld\n", (long long)st->nnz);
    printf("nonzeros/row     min %lld, mean %.3g, max %lld\n", (long long)st->row_nnz_min,
           st->row_nnz_mean, (long long)st->row_nnz_max);
    printf("signs            %s\n", st->nonnegative ? "nonnegative" : "mixed (weights carry signs)");
    printf("row sums of |M|  min %.6g, max %.6g\n", st->abs_rowsum_min, st->abs_rowsum_max);
    printf("substochastic    %s\n", st->substochastic ? "yes" : "no");
    printf("rho(M)           %.6f (residual %.1e, %d matvecs%s)\n", r->rho, r->residual,
           r->matvecs, r->converged ? "" : ", NOT converged");
    printf("rho(|M|)         %.6f (residual %.1e, %d matvecs%s)\n", ra->rho, ra->residual,
           ra->matvecs, ra->converged ? "" : ", NOT converged");
    const char *unsure = " [estimate not converged: verdict uncertain]";
    printf("Neumann series   %s%s\n", r->rho < 1 ? "converges (rho(M) < 1)" : "diverges (rho(M) >= 1)",
           r->converged ? "" : unsure);
    printf("walks            %s%s\n",
           ra->rho < 1 ? "converge (rho(|M|) < 1)" : "diverge (rho(|M|) >= 1): use 'ulam direct'",
           ra->converged ? "" : unsure);
}

/* Print the JSON object. */
static void print_json(const cli_system *s, const ulam_csr_stats *st, const ulam_radius *r,
                       const ulam_radius *ra)
{
    printf("{");
    cli_json_string("matrix", s->matrix_path, 0);
    printf("\"jacobi\": %s, ", s->jacobi ? "true" : "false");
    printf("\"n\": %lld, \"nnz\": %lld, ", (long long)st->n, (long long)st->nnz);
    printf("\"row_nnz_min\": %lld, \"row_nnz_max\": %lld, ", (long long)st->row_nnz_min,
           (long long)st->row_nnz_max);
    cli_json_number("row_nnz_mean", st->row_nnz_mean, 0);
    printf("\"nonnegative\": %s, ", st->nonnegative ? "true" : "false");
    cli_json_number("abs_rowsum_min", st->abs_rowsum_min, 0);
    cli_json_number("abs_rowsum_max", st->abs_rowsum_max, 0);
    printf("\"substochastic\": %s, ", st->substochastic ? "true" : "false");
    cli_json_number("rho", r->rho, 0);
    cli_json_number("rho_residual", r->residual, 0);
    printf("\"rho_converged\": %s, ", r->converged ? "true" : "false");
    cli_json_number("rho_abs", ra->rho, 0);
    cli_json_number("rho_abs_residual", ra->residual, 0);
    printf("\"rho_abs_converged\": %s, ", ra->converged ? "true" : "false");
    printf("\"neumann_converges\": %s, ", r->rho < 1 ? "true" : "false");
    printf("\"walks_converge\": %s}\n", ra->rho < 1 ? "true" : "false");
}

/* ulam info. */
int cli_info(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"jacobi", no_argument, 0, 'j'}, {"omega", required_argument, 0, 'w'},
        {"tol", required_argument, 0, 't'}, {"json", no_argument, 0, 'J'},
        {"help", no_argument, 0, 'h'},   {0, 0, 0, 0}};
    cli_system s = {.command = "info", .omega = 1.0};
    ulam_spectral_opts so = ulam_spectral_defaults();
    int json = 0, c, rc;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'j': s.jacobi = 1; break;
        case 'w': if ((rc = cli_parse_real("info", "--omega", optarg, 1e-6, 2.0, &s.omega))) return rc; break;
        case 't': if ((rc = cli_parse_real("info", "--tol", optarg, 1e-14, 0.5, &so.tol))) return rc; break;
        case 'J': json = 1; break;
        case 'h': fputs(usage, stdout); return 0;
        default: return cli_usage_error("info", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("info", "expects exactly one matrix file");
    s.matrix_path = argv[optind];
    if ((rc = cli_load_system(&s))) return rc;
    ulam_csr_stats st;
    ulam_radius r, ra;
    ulam_csr_stats_compute(s.M, &st);
    int status = ulam_spectral_radius(s.M, 0, &so, &r);
    if (!status) status = ulam_spectral_radius(s.M, 1, &so, &ra);
    if (status) {
        ulam_error e = {.status = status, .msg = "memory for the radius estimate"};
        cli_system_free(&s);
        return cli_report(s.matrix_path, &e);
    }
    if (json) print_json(&s, &st, &r, &ra);
    else print_text(&s, &st, &r, &ra);
    cli_system_free(&s);
    return 0;
}
