/* One answer of a batch of queries as ulam solve --queries reports it (ulam_query_report,
 * include/ulam_report.h): a line of text or a JSON object. */
#include "ulam_report.h"
#include "report.h"

#include <math.h>

/* Write the answer as one JSON object. */
static void query_json(FILE *f, const ulam_query_report *q)
{
    fprintf(f, "{\"query\": %lld, \"line\": %ld, \"source\": ", (long long)q->query + 1, q->line);
    if (q->source >= 0) fprintf(f, "%lld, ", (long long)(q->source + q->node_base));
    else fputs("null, ", f);
    fprintf(f, "\"index\": %lld, ", (long long)(q->index + q->node_base));
    ulam_json_number(f, "estimate", q->estimate, 0);
    ulam_json_number(f, "stderr", q->std_error, 0);
    fputs("\"ci95\": ", f);
    if (isnan(q->ci95[0])) fputs("null, ", f);
    else fprintf(f, "[%.17g, %.17g], ", q->ci95[0], q->ci95[1]);
    fprintf(f, "\"rel_err_met\": %s, \"walks\": %lld, \"seed\": %llu, ", q->rel_err_met ? "true" : "false",
            (long long)q->walks, (unsigned long long)q->seed);
    ulam_json_number(f, "seconds", q->seconds, 1);
    fputs("}\n", f);
}

/* Write the answer as one line of text. */
static void query_text(FILE *f, const ulam_query_report *q)
{
    char src[32] = "";
    if (q->source >= 0) snprintf(src, sizeof src, " (source %lld)", (long long)(q->source + q->node_base));
    fprintf(f, "%s[%lld]%s %.10g", q->answer_name, (long long)(q->index + q->node_base), src, q->estimate);
    if (!isnan(q->ci95[0])) ulam__report_pm_fprint(f, q->estimate, q->std_error, q->ci95[0], q->ci95[1]);
    else fprintf(f, " +- %.3g", q->std_error);
    fprintf(f, "  walks %lld, %.4f s, seed %llu\n", (long long)q->walks, q->seconds, (unsigned long long)q->seed);
}

/* See report.h. */
int ulam__report_query_fprint(FILE *f, const void *report, int format)
{
    const ulam_query_report *q = report;
    if (!q->answer_name) return ULAM_EINVAL;
    if (format == ULAM_REPORT_JSON) query_json(f, q);
    else query_text(f, q);
    return 0;
}
