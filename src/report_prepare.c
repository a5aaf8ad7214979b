/* What ulam prepare reports on the system file it wrote (ulam_prepare_report,
 * include/ulam_report.h): its sizes, rho(|M|) with its verdict, the sums of |M|, the seconds. */
#include "ulam_report.h"
#include "report.h"

/* See report.h. */
int ulam__report_prepare_fprint(FILE *f, const void *report, int format)
{
    const ulam_prepare_report *r = report;
    if (!r->path || !r->cert || (format != ULAM_REPORT_BRIEF && format != ULAM_REPORT_VERBOSE)) return ULAM_EINVAL;
    const ulam_certificate *c = r->cert;
    fprintf(f, "prepared       %s: n %lld, nnz %lld%s%s%s\n", r->path, (long long)r->n, (long long)r->nnz,
            r->with_b ? ", with b" : ", no b", r->jacobi ? ", Jacobi splitting" : "", r->transpose ? ", with M^T" : "");
    fputs("rho(|M|)       ", f);
    ulam__report_power_fprint(f, &c->guard.abs);
    fprintf(f, "  (%s)\nrow sums |M|   %.6g .. %.6g; column sums %.6g .. %.6g\n", ulam_verdict_word(c->guard.verdict_abs),
            c->rowsum_min, c->rowsum_max, c->colsum_min, c->colsum_max);
    fprintf(f, "seconds        %.3f load, %.3f guards\n", r->load_seconds, r->guard_seconds);
    return 0;
}
