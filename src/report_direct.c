/* A direct solve as ulam direct reports it (ulam_direct_report, include/ulam_report.h), as text
 * or JSON. */
#include "ulam_report.h"
#include "report.h"

/* Write "name[i]" and x_i at column 11 (i 0-based). */
static void entry(FILE *f, const ulam_direct_report *d, int64_t i)
{
    int64_t shown = i + d->node_base;
    fprintf(f, "%s[%lld]%*s%.17g\n", d->answer_name, (long long)shown, ulam__report_pad(d->answer_name, shown, 11), "",
            d->x[i]);
}

/* Write the report as text (quiet: the answer lines alone, as solve --quiet). */
static void direct_text(FILE *f, const ulam_direct_report *d, int quiet)
{
    if (d->index > 0) { /* the answer first */
        entry(f, d, d->index - 1);
    } else if (d->list) {
        for (int64_t i = 0; i < d->n && i < 10; i++) entry(f, d, i);
        if (d->n > 10) fprintf(f, "...        (%lld more: use --out or --index)\n", (long long)(d->n - 10));
    }
    if (quiet) return;
    fprintf(f, "n          %lld\n", (long long)d->n);
    fprintf(f, "method     %s\n", d->sparse ? "sparse LU (UMFPACK)" : "dense LU (LAPACK)");
    fprintf(f, "rcond      %.3e\n", d->info.rcond);
    fprintf(f, "residual   %.3e\n", d->info.residual);
    fprintf(f, "seconds    %.6f\n", d->info.seconds);
}

/* Write the report as one JSON object. */
static void direct_json(FILE *f, const ulam_direct_report *d)
{
    fprintf(f, "{\"n\": %lld, ", (long long)d->n);
    if (d->index > 0) {
        fprintf(f, "\"index\": %lld, ", (long long)(d->index - 1 + d->node_base));
        ulam_json_number(f, "estimate", d->x[d->index - 1], 0);
        ulam_json_number(f, "value", d->x[d->index - 1], 0); /* deprecated: "estimate", as in every command */
    }
    ulam_json_string(f, "method", d->sparse ? "sparse LU" : "dense LU", 0);
    ulam_json_number(f, "rcond", d->info.rcond, 0);
    ulam_json_number(f, "residual", d->info.residual, 0);
    ulam_json_number(f, "seconds", d->info.seconds, 1);
    fputs("}\n", f);
}

/* See report.h. */
int ulam__report_direct_fprint(FILE *f, const void *report, int format)
{
    const ulam_direct_report *d = report;
    if (!d->x || !d->answer_name || d->n < 0 || d->index > d->n) return ULAM_EINVAL;
    if (format == ULAM_REPORT_JSON) direct_json(f, d);
    else direct_text(f, d, format == ULAM_REPORT_QUIET);
    return 0;
}
