/* ulam info: what a matrix is, and whether its Neumann series and walks converge. */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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
    ulam_info_report ir = {.matrix = s.matrix_path, .jacobi = s.jacobi, .omega = s.omega, .so = &so};
    ulam_csr *A = NULL; /* a signed J's damping table needs A: Arnoldi on each damped splitting (n <= 100000) */
    ulam_error err = {0};
    ulam_csr_stats_compute(s.M, &ir.st);
    ulam_guard_opts go = ulam_guard_defaults();
    bound_work(ir.st.nnz, &so, &go.power);
    int status = ulam_spectral_radius(s.M, 0, &so, &ir.rho);
    if (status) err = (ulam_error){.status = status, .msg = "memory for the radius estimate"};
    else {
        go.tight = 1; /* info reports the radii themselves, not only the verdicts */
        go.kernel_alpha = alpha;
        status = ulam_guard_check(s.M, continue_q, &go, &ir.g, &err);
    }
    if (!status && !json && s.jacobi && s.omega <= 1.0 && !ir.st.nonnegative && s.M->nrows <= 100000)
        status = ulam_mm_read_matrix(s.matrix_path, &A, &err);
    ir.A = A;
    if (status) rc = cli_report(s.matrix_path, &err);
    else if ((cli_json_done |= json, status = ulam_report_fprint(stdout, ULAM_REPORT_INFO, &ir, json ? ULAM_REPORT_JSON : 0)))
        rc = cli_exit_code(status); /* the damping table's Arnoldi */
    const char *hint = !rc && !json && !s.jacobi && ir.g.verdict_abs == ULAM_VERDICT_FAIL ? cli_system_hint(s.M) : "";
    if (*hint) fprintf(stderr, "ulam: %s: note:%s\n", s.matrix_path, hint); /* as solve's refusal says (newuser18) */
    ulam_csr_free(A);
    cli_system_free(&s);
    return rc;
}
