/* ulam prepare: a prepared system file (M, b and the guards' certificate) for fast queries. */
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ulam prepare. */
int cli_prepare(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"rhs", required_argument, 0, 'b'},      {"jacobi", no_argument, 0, 'j'},
        {"omega", required_argument, 0, 'w'},    {"continue", required_argument, 0, 'q'},
        {"output", required_argument, 0, 'o'},   {"help", no_argument, 0, 'h'},
        {"transpose", no_argument, 0, 't'},
        {0, 0, 0, 0}};
    cli_system s = {.command = "prepare", .omega = 1.0};
    const char *out = NULL;
    double continue_q = 0.0;
    int c, rc, transpose = 0;
    if (cli_check_options("prepare", argc, argv, longopts)) return EXIT_USAGE;
    optind = 0;
    while ((c = getopt_long(argc, argv, "ho:", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': s.rhs_path = optarg; break;
        case 'j': s.jacobi = 1; break;
        case 'w': if ((rc = cli_parse_real("prepare", "--omega", optarg, 1e-6, 2.0, &s.omega))) return rc; break;
        case 'q': if ((rc = cli_parse_real("prepare", "--continue", optarg, 1e-9, 1 - 1e-12, &continue_q))) return rc; break;
        case 'o': out = optarg; break;
        case 't': transpose = 1; break;
        case 'h': ulam_options_help(stdout, "prepare"); return 0;
        default: return cli_usage_error("prepare", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("prepare", "expects exactly one matrix file");
    if (!out) return cli_usage_error("prepare", "needs -o SYSTEM.ulam");
    s.matrix_path = argv[optind];
    const cli_file outs[] = {{"-o", out}}, ins[] = {{"the matrix", s.matrix_path}, {"--rhs", s.rhs_path}};
    if ((rc = cli_check_outputs("prepare", outs, 1, ins, 2))) return rc;
    ulam_outfile o;
    ulam_error err = {.msg = "a writable output file"};
    int status = cli_outfile_open(&o, out); /* checked before the work */
    if (status) {
        err.status = status;
        return cli_report(out, &err);
    }
    double t0 = ulam_now();
    if ((rc = cli_load_system(&s))) {
        cli_outfile_abort(&o);
        return rc;
    }
    double load = ulam_now() - t0;
    ulam_certificate cert;
    t0 = ulam_now();
    status = ulam_certificate_compute(s.M, continue_q, NULL, &cert, &err);
    double guards = ulam_now() - t0;
    if (status) {
        cli_outfile_abort(&o);
        rc = cli_report(s.matrix_path, &err);
        cli_system_free(&s);
        return rc;
    }
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = s.M, d.b = s.b, d.n = s.M->nrows, d.omega = s.jacobi ? s.omega : 0.0, d.cert = &cert;
    d.transpose = transpose;
    status = ulam_system_write_file(o.f, &d);
    if (status) cli_outfile_abort(&o);
    else status = cli_outfile_commit(&o);
    if (status) {
        err = (ulam_error){.status = status, .msg = "a writable output file"};
        rc = cli_report(out, &err);
    } else {
        ulam_prepare_report pr = {.path = out, .n = s.M->nrows, .nnz = ulam_csr_nnz(s.M), .with_b = s.b != NULL,
                                  .jacobi = s.jacobi, .transpose = transpose, .cert = &cert,
                                  .load_seconds = load, .guard_seconds = guards};
        ulam_report_fprint(stdout, ULAM_REPORT_PREPARE, &pr, ULAM_REPORT_BRIEF);
    }
    cli_system_free(&s);
    return rc;
}
