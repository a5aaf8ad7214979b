/* ulam direct: the LAPACK reference solve of (I - M) x = b. */
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>

static const char *const usage =
    "usage: ulam direct M.mtx --rhs b.mtx [--index I] [--out x.mtx] [--max-mem SIZE]\n"
    "                   [--jacobi [--omega W]] [--json]\n"
    "\n"
    "Solve (I - M) x = b with a dense LU factorisation (LAPACKE_dgesv, OpenBLAS) and report\n"
    "the reciprocal condition number (LAPACKE_dgecon, 1-norm), the relative residual\n"
    "||b - (I - M) x||_inf / ||b||_inf and the time.\n"
    "\n"
    "  --rhs b.mtx     right-hand side, a Matrix Market n x 1 vector (required)\n"
    "  --index I       report x_I; indices are 1-based, as in Matrix Market files\n"
    "  --out x.mtx     write the whole solution (array format)\n"
    "  --max-mem SIZE  refuse when the dense matrix needs more (default 4G)\n"
    "  --jacobi        the file holds A of A x = b; solve with M = I - omega D^-1 A\n"
    "  --omega W       damping of the Jacobi splitting (default 1)\n"
    "  --json          print one JSON object\n";

/* Print the human-readable report. */
static void print_text(const cli_system *s, const double *x, int64_t index,
                       const ulam_direct_info *info, const char *out)
{
    int64_t n = s->M->nrows;
    printf("n          %lld\n", (long long)n);
    if (index > 0) {
        printf("x[%lld]%*s%.17g\n", (long long)index, index < 10 ? 6 : index < 100 ? 5 : 1, "",
               x[index - 1]);
    } else if (!out) {
        for (int64_t i = 0; i < n && i < 10; i++) printf("x[%lld]%*s%.17g\n", (long long)i + 1, i < 9 ? 6 : 5, "", x[i]);
        if (n > 10) printf("...        (%lld more: use --out or --index)\n", (long long)(n - 10));
    }
    printf("rcond      %.3e\n", info->rcond);
    printf("residual   %.3e\n", info->residual);
    printf("seconds    %.6f\n", info->seconds);
    if (out) printf("written    %s\n", out);
}

/* Print the JSON object. */
static void print_json(const cli_system *s, const double *x, int64_t index,
                       const ulam_direct_info *info)
{
    printf("{\"n\": %lld, ", (long long)s->M->nrows);
    if (index > 0) {
        printf("\"index\": %lld, ", (long long)index);
        cli_json_number("value", x[index - 1], 0);
    }
    cli_json_number("rcond", info->rcond, 0);
    cli_json_number("residual", info->residual, 0);
    cli_json_number("seconds", info->seconds, 1);
    printf("}\n");
}

/* ulam direct. */
int cli_direct(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"rhs", required_argument, 0, 'b'},     {"index", required_argument, 0, 'i'},
        {"out", required_argument, 0, 'o'},     {"max-mem", required_argument, 0, 'm'},
        {"jacobi", no_argument, 0, 'j'},        {"omega", required_argument, 0, 'w'},
        {"json", no_argument, 0, 'J'},          {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0}};
    cli_system s = {.command = "direct", .omega = 1.0};
    const char *out = NULL;
    size_t max_mem = CLI_MAX_MEM;
    int json = 0, c, rc;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': s.rhs_path = optarg; break;
        case 'i': if ((rc = cli_parse_int("direct", "--index", optarg, 1, ULAM_MAX_DIM, &s.index))) return rc; break;
        case 'o': out = optarg; break;
        case 'm': if ((rc = cli_parse_bytes("direct", "--max-mem", optarg, &max_mem))) return rc; break;
        case 'j': s.jacobi = 1; break;
        case 'w': if ((rc = cli_parse_real("direct", "--omega", optarg, 1e-6, 2.0, &s.omega))) return rc; break;
        case 'J': json = 1; break;
        case 'h': fputs(usage, stdout); return 0;
        default: return cli_usage_error("direct", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("direct", "expects exactly one matrix file");
    if (!s.rhs_path && !ulam_system_is_file(argv[optind])) return cli_need_rhs("direct", argv[optind]);
    s.matrix_path = argv[optind];
    if (out && (rc = cli_check_output(out))) return rc;
    if ((rc = cli_load_system(&s))) return rc;
    if (!s.b) {
        cli_system_free(&s);
        return cli_usage_error("direct", "needs --rhs b.mtx (%s holds no b)", s.matrix_path);
    }
    double *x = NULL;
    ulam_direct_info info;
    int status;
    if ((rc = cli_direct_solve(&s, max_mem, &x, &info))) {
        /* reported */
    } else if (out && (status = ulam_mm_write_vector(out, x, s.M->nrows, "solution of (I - M) x = b by ulam direct"))) {
        ulam_error err = {.status = status, .msg = "a writable output file"};
        rc = cli_report(out, &err);
    } else if (json) {
        print_json(&s, x, s.index, &info);
    } else {
        print_text(&s, x, s.index, &info, out);
    }
    free(x);
    cli_system_free(&s);
    return rc;
}
