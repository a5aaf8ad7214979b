/* Writing a prepared system (docs/prepared.md): the walk kernel's bounds over every state (and
 * b's scores) from an analysis of M at the certificate's continuation and exponent 1, the very
 * bounds an analysis of the mapped file then walks under; the bytes and their checksums by
 * src/cache.c, which reads and verifies files and knows nothing of analyses. */
#include "analysis.h"
#include "cache.h"
#include "solve.h"

/* Write a prepared system to f. */
int ulam_system_write_file(FILE *f, const ulam_system_desc *d)
{
    int status = ulam__system_desc_check(f, d);
    if (status) return status;
    if (!d->cert || d->M->nrows != d->M->ncols) return ulam__system_write_checked(f, d, NULL);
    ulam_analysis_opts o = ulam_analysis_defaults();
    o.continue_q = d->cert->continue_q, o.kernel_alpha = 1.0, o.b = d->b;
    ulam_analysis *a = NULL;
    const ulam__reach *R = ulam_analysis_alloc(d->M, &o, &a, NULL) ? NULL : ulam__analysis_bounds(a);
    status = ulam__system_write_checked(f, d, R && (!d->b || R->b == d->b) ? R : NULL); /* none when not made */
    ulam_analysis_free(a);
    return status;
}

/* Write a prepared system to path atomically. */
int ulam_system_write(const char *path, const ulam_system_desc *d)
{
    if (!path || !d) return ULAM_EINVAL;
    ulam_outfile o;
    int status = ulam_outfile_open(&o, path);
    if (status) return status;
    status = ulam_system_write_file(o.f, d);
    if (status) {
        ulam_outfile_abort(&o);
        return status;
    }
    return ulam_outfile_commit(&o);
}
