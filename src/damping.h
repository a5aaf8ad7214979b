/* The damping sweep of a Jacobi splitting (src/damping.c): rho(M) and rho(|M|) of
 * M_w = (1 - w) I + w J at several dampings w, for ulam info --jacobi.  Internal. */
#ifndef ULAM_DAMPING_H
#define ULAM_DAMPING_H

#include "internal.h"

/* One damping's row. */
typedef struct ulam__damping_row {
    double omega;
    double rho, rho_abs; /* rho(M_w) (Arnoldi, or J's moved) and rho(|M_w|)'s estimate */
    int neumann;         /* the Neumann series: 1 converges, 0 diverges, -1 unknown */
    int walks;           /* rho(|M_w|)'s verdict (ULAM_VERDICT_*) */
} ulam__damping_row;

/* The dampings of the sweep: 1, 0.9, ..., 0.5. */
#define ULAM__DAMPING_ROWS 6

/* The rows of the sweep into rows (*done of them: all unless a status) from the radii r (Arnoldi)
 * and p (|M|) of M = I - omega D^-1 A, nonneg when M >= 0, A the splitting's matrix (a signed M
 * needs it: Arnoldi on each M_w); 0 or a status. */
int ulam__damping_sweep(const ulam_csr *A, const ulam_spectral_opts *so, double omega, int nonneg,
                        const ulam_radius *r, const ulam_power *p, ulam__damping_row *rows, int *done);

#endif
