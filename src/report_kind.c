/* ulam_report_fprint (include/ulam_report.h): a table of the report kinds and their writers. */
#include "ulam_report.h"
#include "report.h"

/* The writers by kind (enum ulam_report_kind). */
static int (*const writers[])(FILE *, const void *, int) = {
    [ULAM_REPORT_INFO] = ulam__report_info_fprint,
    [ULAM_REPORT_DIRECT] = ulam__report_direct_fprint,
    [ULAM_REPORT_QUERY] = ulam__report_query_fprint,
    [ULAM_REPORT_BIDIR] = ulam__report_bidir_fprint,
    [ULAM_REPORT_WALK] = ulam__report_walk_fprint,
    [ULAM_REPORT_PREPARE] = ulam__report_prepare_fprint,
};

/* See ulam_report.h. */
int ulam_report_fprint(FILE *f, int kind, const void *report, int format)
{
    if (!f || !report || kind < 0 || kind >= (int)(sizeof writers / sizeof *writers) || !writers[kind])
        return ULAM_EINVAL;
    return writers[kind](f, report, format);
}
