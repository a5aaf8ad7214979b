/* ulam info: what a matrix is, and whether its Neumann series and walks converge. */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const unsure = " [the estimate did not converge]";

/* The Neumann verdict on rho(M) < 1: 1 converges, 0 diverges, -1 unknown; *certified says
 * whether bounds decide it (rho(M) <= rho(|M|) < 1 certified; a nonnegative M with rho(|M|)
 * certified >= 1), else a converged Arnoldi estimate at least 1% away from 1 decides it, never
 * an unconverged one. */
static int neumann_verdict(const ulam_csr_stats *st, const ulam_radius *r, const ulam_guard *g, int *certified)
{
    *certified = 1;
    if (g->abs.upper < 1) return 1;
    if (st->nonnegative && g->abs.lower >= 1) return 0;
    *certified = 0;
    if (r->converged && fabs(r->rho - 1) >= 0.01) return r->rho < 1;
    return -1;
}

/* Print the human-readable report. */
static void print_text(const cli_system *s, const ulam_csr_stats *st, const ulam_radius *r,
                       const ulam_guard *g)
{
    printf("matrix           %s%s\n", s->matrix_path, s->jacobi ? " (Jacobi splitting of A)" : "");
    printf("n                %lld\n", (long long)st->n);
    printf("nnz              %lld\n", (long long)st->nnz);
    printf("nonzeros/row     min %lld, mean %.3g, max %lld\n", (long long)st->row_nnz_min,
           st->row_nnz_mean, (long long)st->row_nnz_max);
    printf("signs            %s\n", st->nonnegative ? "nonnegative" : "mixed (weights carry signs)");
    printf("row sums of |M|  min %.6g, max %.6g\n", st->abs_rowsum_min, st->abs_rowsum_max);
    printf("substochastic    %s\n", st->substochastic ? "yes" : "no");
    char rho[32];
    printf("rho(M)           %s (residual %.1e, %d matvecs%s)\n", cli_radius_str(rho, r->rho), r->residual, r->matvecs,
           r->converged ? "" : ", NOT converged");
    printf("rho(|M|)         ");
    cli_print_power(&g->abs);
    printf("\nrho(M^) adjoint  ");
    cli_print_power(&g->hat[ULAM_ADJOINT]);
    if (g->kernel_alpha != 1.0) printf(" at kernel exponent alpha = %g", g->kernel_alpha);
    printf("\nrho(M^) forward  ");
    cli_print_power(&g->hat[ULAM_FORWARD]);
    if (g->kernel_alpha != 1.0) printf(" at kernel exponent alpha = %g", g->kernel_alpha);
    int cert, nv = neumann_verdict(st, r, g, &cert);
    printf("\nNeumann series   %s%s\n",
           nv == 1 ? "converges (rho(M) < 1)" : nv == 0 ? "diverges (rho(M) >= 1)" : "unknown (rho(M) not certified on either side of 1)",
           nv < 0 ? (r->converged ? " [the estimate is within 1% of 1]" : unsure)
           : cert ? (nv ? " [certified: rho(M) <= rho(|M|) < 1]" : " [certified: M >= 0 and rho(|M|) >= 1]")
                  : " [converged estimate, not certified]");
    printf("walks            %s (rho(|M|) %s)\n",
           g->verdict_abs == ULAM_VERDICT_FAIL ? "diverge: use 'ulam direct'"
           : g->verdict_abs == ULAM_VERDICT_UNKNOWN ? "unknown: refused unless --force" : "converge",
           cli_verdict_word(g->verdict_abs));
    for (int m = 0; m < 2; m++) {
        int v = ulam_guard_variance(g, m);
        printf("variance %s %s (rho(M^) %s)\n", cli_mode_names[m],
               v == 0 ? "infinite: no error bar can be trusted"
               : v < 0 ? "unknown: treated as infinite (no interval) unless --assume-finite-variance" : "finite",
               cli_verdict_word(g->verdict_hat[m]));
    }
}

/* Print the JSON object. */
static void print_json(const cli_system *s, const ulam_csr_stats *st, const ulam_radius *r,
                       const ulam_guard *g)
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
    cli_json_radius("rho_abs", &g->abs);
    cli_json_radius("rho_hat_adjoint", &g->hat[ULAM_ADJOINT]);
    cli_json_radius("rho_hat_forward", &g->hat[ULAM_FORWARD]);
    cli_json_number("kernel_alpha", g->kernel_alpha, 0);
    int cert, nv = neumann_verdict(st, r, g, &cert);
    printf("\"neumann_converges\": %s, \"neumann_certified\": %s, ", nv < 0 ? "null" : nv ? "true" : "false",
           cert ? "true" : "false");
    cli_json_variance("walks_converge", g->verdict_abs <= ULAM_VERDICT_EDGE ? 1 : g->verdict_abs == ULAM_VERDICT_FAIL ? 0 : -1);
    cli_json_variance("variance_finite_adjoint", ulam_guard_variance(g, ULAM_ADJOINT));
    cli_json_variance("variance_finite_forward", ulam_guard_variance(g, ULAM_FORWARD));
    cli_json_number("guard_seconds", g->abs.seconds + g->hat[0].seconds + g->hat[1].seconds, 1);
    printf("}\n");
}

/* x -> 1 - w + w x: an eigenvalue of J = I - D^-1 A moved to M_w = (1 - w) I + w J. */
static double damped(double w, double x)
{
    return 1.0 - w + w * x;
}

/* For --jacobi: rho(M) and rho(|M|) of the splitting M_w = (1 - w) I + w J at several dampings w,
 * from J's radii (rJ, pJ: Arnoldi and the power iteration on |J|) where they are exact: J's
 * diagonal is 0, so |M_w| = (1 - w) I + w |J| and rho(|M_w|) = 1 - w + w rho(|J|), its bounds
 * moved the same way, for 0 < w <= 1; and for J >= 0 the Perron root gives rho(M_w) likewise.  A
 * signed J's rho(M_w) needs Arnoldi on each M_w (A read again; only for n <= 100000).  Issue 42:
 * Arnoldi and the power iteration on every M_w took 81 s on a 500 x 500 Poisson. */
static int print_omegas(const cli_system *base, const ulam_spectral_opts *so, int nonneg, const ulam_radius *rJ,
                        const ulam_power *pJ)
{
    ulam_csr *A = NULL;
    ulam_error err;
    int status = 0;
    if (!nonneg && base->M->nrows > 100000) return 0; /* a signed J's Arnoldi on each M_w: too long */
    if (!nonneg && (status = ulam_mm_read_matrix(base->matrix_path, &A, &err))) return cli_report(base->matrix_path, &err);
    int64_t n = base->M->nrows;
    double *b = A ? calloc((size_t)n, sizeof *b) : NULL, *bp = A ? malloc((size_t)n * sizeof *bp) : NULL;
    if (A && (!b || !bp)) status = ULAM_ENOMEM;
    printf("damping          omega   rho(M)     rho(|M|)   Neumann    walks\n");
    for (int k = 0; k <= 5 && !status; k++) {
        double omega = 1.0 - 0.1 * k;
        ulam_radius r = *rJ;
        ulam_power pa = *pJ;
        pa.rho = damped(omega, pJ->rho), pa.lower = damped(omega, pJ->lower), pa.upper = damped(omega, pJ->upper);
        if (pJ->upper < 1.0) pa.upper = fmin(pa.upper, nextafter(1.0, 0.0)); /* below 1 iff J's is: not lost to rounding */
        if (nonneg) {
            r.rho = damped(omega, rJ->rho);
        } else {
            ulam_csr *M = NULL;
            status = ulam_jacobi(A, b, omega, &M, bp, NULL);
            if (!status) status = ulam_spectral_radius(M, 0, so, &r);
            ulam_csr_free(M);
        }
        if (!status)
            printf("                 %5.2f   %-9.6f  %-9.6f  %-9s  %s\n", omega, r.rho, pa.rho,
                   pa.upper < 1 ? "converges" : !r.converged || fabs(r.rho - 1) < 0.01 ? "unknown"
                   : r.rho < 1 ? "converges" : "diverges", ulam_verdict_of(&pa) <= ULAM_VERDICT_EDGE ? "converge" : ulam_verdict_of(&pa) == ULAM_VERDICT_FAIL ? "diverge" : "unknown");
    }
    ulam_csr_free(A);
    free(b), free(bp);
    if (status) return cli_exit_code(status);
    printf("                 (rho(|I - w D^-1 A|) = 1 - w + w rho(|J|) for 0 < w <= 1%s: damping can\n"
           "                 shrink rho(M) when J has eigenvalues near -1, but never brings the walks'\n"
           "                 rho(|M|) below plain Jacobi's)\n", nonneg ? ", as is rho(M) for J >= 0" : "");
    return 0;
}

/* A bound on each radius's work in matrix-vector products: about 2^28 nonzeros touched (a second
 * or so), at least 200 products and at most the defaults, so that info on a large M ends in
 * bounded time; a radius the cap stops says NOT converged and gives its certified bounds. */
static void bound_work(int64_t nnz, ulam_spectral_opts *so, ulam_power_opts *po)
{
    double products = fmax(200.0, (double)(1 << 28) / (double)(nnz > 0 ? nnz : 1));
    if (products < (double)po->max_iter) po->max_iter = (int)products;
    int restarts = (int)(products / (double)so->krylov_dim);
    if (restarts < so->max_restarts) so->max_restarts = restarts > 10 ? restarts : 10;
}

/* ulam info. */
int cli_info(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"jacobi", no_argument, 0, 'j'}, {"omega", required_argument, 0, 'w'},
        {"tol", required_argument, 0, 't'}, {"json", no_argument, 0, 'J'},
        {"continue", required_argument, 0, 'q'}, {"help", no_argument, 0, 'h'},
        {"alpha", required_argument, 0, 'a'},   {"kernel-exponent", required_argument, 0, 'K'},
        {0, 0, 0, 0}};
    cli_system s = {.command = "info", .omega = 1.0};
    ulam_spectral_opts so = ulam_spectral_defaults();
    double continue_q = 0.0, alpha = 1.0;
    int json = 0, c, rc;
    if (cli_check_options("info", argc, argv, longopts)) return EXIT_USAGE;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'j': s.jacobi = 1; break;
        case 'w': if ((rc = cli_parse_real("info", "--omega", optarg, 1e-6, 2.0, &s.omega))) return rc; break;
        case 't': if ((rc = cli_parse_real("info", "--tol", optarg, 1e-14, 0.5, &so.tol))) return rc; break;
        case 'q': if ((rc = cli_parse_real("info", "--continue", optarg, 1e-9, 1 - 1e-12, &continue_q))) return rc; break;
        case 'a': /* fall through: the deprecated spelling */
        case 'K':
            if (c == 'a') fprintf(stderr, "ulam info: note: --alpha is deprecated: the kernel exponent is --kernel-exponent\n");
            if ((rc = cli_parse_real("info", c == 'a' ? "--alpha" : "--kernel-exponent", optarg, 0.0, 1000.0, &alpha))) return rc;
            break;
        case 'J': json = 1; break;
        case 'h': ulam_options_help(stdout, "info"); return 0;
        default: return cli_usage_error("info", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("info", "expects exactly one matrix file");
    s.matrix_path = argv[optind];
    if ((rc = cli_load_system(&s))) return rc;
    ulam_csr_stats st;
    ulam_radius r;
    ulam_guard g;
    ulam_error err = {0};
    ulam_csr_stats_compute(s.M, &st);
    ulam_guard_opts go = ulam_guard_defaults();
    bound_work(st.nnz, &so, &go.power);
    int status = ulam_spectral_radius(s.M, 0, &so, &r);
    if (status) err = (ulam_error){.status = status, .msg = "memory for the radius estimate"};
    else {
        go.tight = 1; /* info reports the radii themselves, not only the verdicts */
        go.kernel_alpha = alpha;
        status = ulam_guard_check(s.M, continue_q, &go, &g, &err);
    }
    if (status) {
        rc = cli_report(s.matrix_path, &err);
        cli_system_free(&s);
        return rc;
    }
    if (json) print_json(&s, &st, &r, &g);
    else print_text(&s, &st, &r, &g);
    if (!json && s.jacobi && s.omega <= 1.0) { /* J's radii from M_w's: x -> (x - 1 + w) / w */
        ulam_radius rJ = r;
        ulam_power pJ = g.abs;
        double w = s.omega;
        rJ.rho = (r.rho - 1.0 + w) / w, pJ.rho = (g.abs.rho - 1.0 + w) / w;
        pJ.lower = (g.abs.lower - 1.0 + w) / w, pJ.upper = (g.abs.upper - 1.0 + w) / w;
        rc = print_omegas(&s, &so, st.nonnegative, &rJ, &pJ);
    }
    cli_system_free(&s);
    return rc;
}
