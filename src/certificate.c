/* The guard certificate of a prepared system: what ulam_guard_check found, with the row and
 * column sums of |M|, kept so that a later query on the same M needs no pass over it. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>

/* The certificate of M. */
int ulam_certificate_compute(const ulam_csr *M, double continue_q, const ulam_guard_opts *opts,
                             ulam_certificate *c, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !c) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix and an output");
    ulam_guard_opts o = opts ? *opts : ulam_guard_defaults();
    if (o.kernel_alpha != 1.0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the kernel exponent 1 (a certificate holds its guards; got %g)",
                          o.kernel_alpha);
    *c = (ulam_certificate){.continue_q = continue_q > 0 ? continue_q : 0.0, .tol = o.power.tol,
                            .max_iter = o.power.max_iter};
    int status = ulam_guard_check(M, continue_q, &o, &c->guard, err);
    if (status) return status;
    ulam_csr_stats st;
    ulam_csr_stats_compute(M, &st);
    c->rowsum_min = st.abs_rowsum_min, c->rowsum_max = st.abs_rowsum_max;
    double *col = ulam__calloc((size_t)M->ncols, sizeof *col);
    if (!col) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the column sums");
    for (int64_t q = 0; q < M->rowptr[M->nrows]; q++) col[M->colidx[q]] += fabs(M->val[q]);
    c->colsum_min = M->ncols ? INFINITY : 0.0;
    for (int64_t j = 0; j < M->ncols; j++)
        c->colsum_min = fmin(c->colsum_min, col[j]), c->colsum_max = fmax(c->colsum_max, col[j]);
    free(col);
    return ULAM_OK;
}

/* The guards from certificate c when it was made for this continuation, kernel exponent and
 * these options and holds the radii they need. */
int ulam_certificate_guard(const ulam_certificate *c, double continue_q, const ulam_guard_opts *opts,
                           ulam_guard *g)
{
    if (!c || !g) return ULAM_ENOTFOUND;
    ulam_guard_opts o = opts ? *opts : ulam_guard_defaults();
    int need = o.need ? o.need : ULAM_GUARD_ALL;
    if (c->continue_q != (continue_q > 0 ? continue_q : 0.0) || c->tol != o.power.tol ||
        c->max_iter != o.power.max_iter || c->guard.kernel_alpha != o.kernel_alpha || (c->guard.computed & need) != need ||
        o.tight)
        return ULAM_ENOTFOUND;
    *g = c->guard;
    g->abs.seconds = g->hat[0].seconds = g->hat[1].seconds = 0.0;
    return ULAM_OK;
}
