/* Experiment 2, past the edge: forced walks (q = 0.5 everywhere, so they end) on two systems
 * the guard refuses, the running estimate of x_1 against LAPACK's:
 *   case 0: random signs, rho(M) < 1 <= rho(|M|): the Neumann series converges, the walks'
 *           expected |score| does not;
 *   case 1: nonnegative, rho(M) = 1.1 > 1: the series itself diverges, yet I - M is regular.
 *
 *   past_edge [OUTDIR]    writes OUTDIR/past_edge.csv and OUTDIR/past_edge.png */
#include <stdio.h>

#include "chart.h"
#include "systems.h"

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "docs";
    const int64_t n = 200;
    ulam_csr *Ms[2] = {random_sparse(n, 8, 1.3, 1, 77), random_sparse(n, 8, 1.1, 0, 78)};
    double *b = random_vector(n, 0.0, 1.0, 77);
    char title[2][256];
    out_file o;
    out_open(&o, dir, "past_edge.csv");
    fprintf(o.f, "case,walks,estimate,stderr,direct\n");
    for (int c = 0; c < 2; c++) {
        ulam_radius rs;
        ulam_guard g;
        ulam_spectral_radius(Ms[c], 0, NULL, &rs);
        ulam_guard_check(Ms[c], 0.5, NULL, &g, NULL);
        snprintf(title[c], sizeof title[c], "ρ(M) = %.3f, ρ(|M|) = %.3f, ρ(M̂) = %.3f: %s", rs.rho,
                 g.abs.rho, g.hat[ULAM_ADJOINT].rho,
                 g.verdict_abs >= ULAM_VERDICT_FAIL ? "refused (exit 3) without --force" : "allowed");
        fprintf(stderr, "case %d: %s\n", c, title[c]);
        double *x = direct(Ms[c], b, NULL);
        ulam_walk_opts wo = ulam_walk_defaults();
        wo.kernel.continue_q = 0.5;
        wo.policy.force = 1; /* the point is to watch what the guard refuses */
        wo.exec.seed = 5;
        running(Ms[c], b, wo, 12, x[0], o.f, c);
        free(x);
    }
    out_commit(&o);
    chart_draw(dir, "past_edge", 1100, 450,
               "set multiplot layout 1,2 title 'Past the edge: forced adjoint walks (q = 0.5), running estimate of x_1 with its claimed 95%% interval'\n"
               "set key top left\nset logscale x\nset xlabel 'walks'\nset format x '10^{%%L}'\nset key bottom left\n"
               "set title \"%s\" font ',9'\n"
               "plot 'past_edge.csv' u ($1==0?$2:1/0):3:($4*1.96) w yerrorlines pt 7 t 'walk estimate', '' u ($1==0?$2:1/0):5 w l lw 2 t 'LAPACK'\n"
               "set title \"%s\" font ',9'\n"
               "plot 'past_edge.csv' u ($1==1?$2:1/0):3:($4*1.96) w yerrorlines pt 7 t 'walk estimate', '' u ($1==1?$2:1/0):5 w l lw 2 t 'LAPACK'\n"
               "unset multiplot\n",
               title[0], title[1]);
    free(b);
    ulam_csr_free(Ms[0]), ulam_csr_free(Ms[1]);
    return 0;
}
