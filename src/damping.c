/* The damping sweep of a Jacobi splitting (src/damping.h): J's radii from M's, and at each
 * damping w of M_w = (1 - w) I + w J, rho(|M_w|) moved from rho(|J|) and rho(M_w) moved or by
 * Arnoldi.  Issue 42: Arnoldi and the power iteration on every M_w took 81 s on a 500 x 500
 * Poisson. */
#include "damping.h"

#include <math.h>
#include <stdlib.h>

/* x -> 1 - w + w x: an eigenvalue of J = I - D^-1 A moved to M_w = (1 - w) I + w J. */
static double damped(double w, double x)
{
    return 1.0 - w + w * x;
}

/* J's diagonal is 0, so |M_w| = (1 - w) I + w |J| and rho(|M_w|) = 1 - w + w rho(|J|), its bounds
 * moved the same way, for 0 < w <= 1; and for J >= 0 the Perron root gives rho(M_w) likewise.  A
 * signed J's rho(M_w) needs Arnoldi on each M_w. */
int ulam__damping_sweep(const ulam_csr *A, const ulam_spectral_opts *so, double omega, int nonneg,
                        const ulam_radius *r, const ulam_power *p, ulam__damping_row *rows, int *done)
{
    *done = 0;
    if (!nonneg && !A) return ULAM_EINVAL;
    ulam_radius rJ = *r; /* J's radii from M's: x -> (x - 1 + w) / w */
    ulam_power pJ = *p;
    rJ.rho = (r->rho - 1.0 + omega) / omega, pJ.rho = (p->rho - 1.0 + omega) / omega;
    pJ.lower = (p->lower - 1.0 + omega) / omega, pJ.upper = (p->upper - 1.0 + omega) / omega;
    int64_t n = A ? A->nrows : 0;
    double *b = A ? calloc((size_t)n, sizeof *b) : NULL, *bp = A ? malloc((size_t)n * sizeof *bp) : NULL;
    int status = A && (!b || !bp) ? ULAM_ENOMEM : ULAM_OK;
    for (int k = 0; k < ULAM__DAMPING_ROWS && !status; k++) {
        double w = 1.0 - 0.1 * k;
        ulam_radius rw = rJ;
        ulam_power pa = pJ;
        pa.rho = damped(w, pJ.rho), pa.lower = damped(w, pJ.lower), pa.upper = damped(w, pJ.upper);
        if (pJ.upper < 1.0) pa.upper = fmin(pa.upper, nextafter(1.0, 0.0)); /* below 1 iff J's is: not lost to rounding */
        if (nonneg) {
            rw.rho = damped(w, rJ.rho);
        } else {
            ulam_csr *M = NULL;
            status = ulam_jacobi(A, b, w, &M, bp, NULL);
            if (!status) status = ulam_spectral_radius(M, 0, so, &rw);
            ulam_csr_free(M);
        }
        if (status) break;
        rows[k] = (ulam__damping_row){.omega = w, .rho = rw.rho, .rho_abs = pa.rho, .walks = ulam_verdict_of(&pa),
                                      .neumann = pa.upper < 1 ? 1 : !rw.converged || fabs(rw.rho - 1) < 0.01 ? -1
                                                                                                        : rw.rho < 1};
        *done = k + 1;
    }
    free(b), free(bp);
    return status;
}
