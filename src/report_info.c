/* What ulam info reports on a matrix (ulam_info_report, include/ulam_report.h), as text or JSON:
 * its statistics, rho(M), the guards' radii, the Neumann series' verdict and a Jacobi
 * splitting's damping table. */
#include "ulam_report.h"
#include "damping.h"
#include "report.h"

#include <math.h>

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

/* Write a radius as "label0.900000 (bounds [lo, hi], k iterations, s, converged or a bound)"; at
 * kernel exponent alpha when not 1, and a newline. */
static void power_fprint(FILE *f, const char *label, const ulam_power *p, double alpha)
{
    fputs(label, f);
    ulam__report_power_fprint(f, p);
    if (alpha != 1.0) fprintf(f, " at kernel exponent alpha = %g", alpha);
    fputc('\n', f);
}

/* Write the damping table of a Jacobi splitting (ulam__damping_sweep); 0 or a status (the rows
 * made before it written). */
static int damping_fprint(FILE *f, const ulam_info_report *ir)
{
    ulam__damping_row rows[ULAM__DAMPING_ROWS];
    int done, nonneg = ir->st.nonnegative;
    ulam_spectral_opts so = ir->so ? *ir->so : ulam_spectral_defaults();
    int status = ulam__damping_sweep(ir->A, &so, ir->omega, nonneg, &ir->rho, &ir->g.abs, rows, &done);
    fprintf(f, "damping          omega   rho(M)     rho(|M|)   Neumann    walks\n");
    for (int k = 0; k < done; k++)
        fprintf(f, "                 %5.2f   %-9.6f  %-9.6f  %-9s  %s\n", rows[k].omega, rows[k].rho, rows[k].rho_abs,
                rows[k].neumann > 0 ? "converges" : rows[k].neumann < 0 ? "unknown" : "diverges",
                rows[k].walks <= ULAM_VERDICT_EDGE ? "converge" : rows[k].walks == ULAM_VERDICT_FAIL ? "diverge" : "unknown");
    if (status) return status;
    fprintf(f, "                 (rho(|I - w D^-1 A|) = 1 - w + w rho(|J|) for 0 < w <= 1%s: damping can\n"
               "                 shrink rho(M) when J has eigenvalues near -1, but never brings the walks'\n"
               "                 rho(|M|) below plain Jacobi's)\n", nonneg ? ", as is rho(M) for J >= 0" : "");
    return 0;
}

/* Write the report as text. */
static int info_text(FILE *f, const ulam_info_report *ir)
{
    const ulam_csr_stats *st = &ir->st;
    const ulam_radius *r = &ir->rho;
    const ulam_guard *g = &ir->g;
    fprintf(f, "matrix           %s%s\n", ir->matrix, ir->jacobi ? " (Jacobi splitting of A)" : "");
    fprintf(f, "n                %lld\n", (long long)st->n);
    fprintf(f, "nnz              %lld\n", (long long)st->nnz);
    fprintf(f, "nonzeros/row     min %lld, mean %.3g, max %lld\n", (long long)st->row_nnz_min, st->row_nnz_mean,
            (long long)st->row_nnz_max);
    fprintf(f, "signs            %s\n", st->nonnegative ? "nonnegative" : "mixed (weights carry signs)");
    fprintf(f, "row sums of |M|  min %.6g, max %.6g\n", st->abs_rowsum_min, st->abs_rowsum_max);
    fprintf(f, "substochastic    %s\n", st->substochastic ? "yes" : "no");
    char rho[32];
    fprintf(f, "rho(M)           %s (residual %.1e, %d matvecs%s)\n", ulam__report_radius_str(rho, r->rho), r->residual, r->matvecs,
            r->converged ? "" : ", NOT converged");
    power_fprint(f, "rho(|M|)         ", &g->abs, 1.0);
    power_fprint(f, "rho(M^) adjoint  ", &g->hat[ULAM_ADJOINT], g->kernel_alpha);
    power_fprint(f, "rho(M^) forward  ", &g->hat[ULAM_FORWARD], g->kernel_alpha);
    int cert, nv = neumann_verdict(st, r, g, &cert);
    fprintf(f, "Neumann series   %s%s\n",
            nv == 1 ? "converges (rho(M) < 1)" : nv == 0 ? "diverges (rho(M) >= 1)" : "unknown (rho(M) not certified on either side of 1)",
            nv < 0 ? (r->converged ? " [the estimate is within 1% of 1]" : unsure)
            : cert ? (nv ? " [certified: rho(M) <= rho(|M|) < 1]" : " [certified: M >= 0 and rho(|M|) >= 1]")
                   : " [converged estimate, not certified]");
    fprintf(f, "walks            %s (rho(|M|) %s)\n",
            g->verdict_abs == ULAM_VERDICT_FAIL ? "diverge: use 'ulam direct'"
            : g->verdict_abs == ULAM_VERDICT_UNKNOWN ? "unknown: refused unless --force" : "converge",
            ulam_verdict_word(g->verdict_abs));
    for (int m = 0; m < 2; m++) {
        int v = ulam_guard_variance(g, m);
        fprintf(f, "variance %s %s (rho(M^) %s)\n", ulam__report_mode_name(m),
                v == 0 ? "infinite: no error bar can be trusted"
                : v < 0 ? "unknown: treated as infinite (no interval) unless --assume-finite-variance" : "finite",
                ulam_verdict_word(g->verdict_hat[m]));
    }
    return ir->jacobi && ir->omega <= 1.0 && (st->nonnegative || ir->A) ? damping_fprint(f, ir) : 0;
}

/* Write the report as one JSON object. */
static void info_json(FILE *f, const ulam_info_report *ir)
{
    const ulam_csr_stats *st = &ir->st;
    const ulam_radius *r = &ir->rho;
    const ulam_guard *g = &ir->g;
    fputc('{', f);
    ulam_json_string(f, "matrix", ir->matrix, 0);
    fprintf(f, "\"jacobi\": %s, ", ir->jacobi ? "true" : "false");
    fprintf(f, "\"n\": %lld, \"nnz\": %lld, ", (long long)st->n, (long long)st->nnz);
    fprintf(f, "\"row_nnz_min\": %lld, \"row_nnz_max\": %lld, ", (long long)st->row_nnz_min, (long long)st->row_nnz_max);
    ulam_json_number(f, "row_nnz_mean", st->row_nnz_mean, 0);
    fprintf(f, "\"nonnegative\": %s, ", st->nonnegative ? "true" : "false");
    ulam_json_number(f, "abs_rowsum_min", st->abs_rowsum_min, 0);
    ulam_json_number(f, "abs_rowsum_max", st->abs_rowsum_max, 0);
    fprintf(f, "\"substochastic\": %s, ", st->substochastic ? "true" : "false");
    ulam_json_number(f, "rho", r->rho, 0);
    ulam_json_number(f, "rho_residual", r->residual, 0);
    fprintf(f, "\"rho_converged\": %s, ", r->converged ? "true" : "false");
    ulam__report_radius_json(f, "rho_abs", &g->abs);
    ulam__report_radius_json(f, "rho_hat_adjoint", &g->hat[ULAM_ADJOINT]);
    ulam__report_radius_json(f, "rho_hat_forward", &g->hat[ULAM_FORWARD]);
    ulam_json_number(f, "kernel_alpha", g->kernel_alpha, 0);
    int cert, nv = neumann_verdict(st, r, g, &cert);
    fprintf(f, "\"neumann_converges\": %s, \"neumann_certified\": %s, ", nv < 0 ? "null" : nv ? "true" : "false",
            cert ? "true" : "false");
    ulam__report_verdict_json(f, "walks_converge",
                              g->verdict_abs <= ULAM_VERDICT_EDGE ? 1 : g->verdict_abs == ULAM_VERDICT_FAIL ? 0 : -1);
    ulam__report_verdict_json(f, "variance_finite_adjoint", ulam_guard_variance(g, ULAM_ADJOINT));
    ulam__report_verdict_json(f, "variance_finite_forward", ulam_guard_variance(g, ULAM_FORWARD));
    ulam_json_number(f, "guard_seconds", g->abs.seconds + g->hat[0].seconds + g->hat[1].seconds, 1);
    fputs("}\n", f);
}

/* See report.h. */
int ulam__report_info_fprint(FILE *f, const void *report, int format)
{
    const ulam_info_report *ir = report;
    if (!ir->matrix) return ULAM_EINVAL;
    if (format != ULAM_REPORT_JSON) return info_text(f, ir);
    info_json(f, ir);
    return 0;
}
