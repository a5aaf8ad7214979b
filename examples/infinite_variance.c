/* Experiment 3, infinite variance: one doubly substochastic system (n = 1000, rows and columns
 * of |M| sum to 0.9, so rho(|M|) = 0.9) walked with two kernels:
 *   analog (q_i = 0.9):   rho(M^) = 0.9, finite variance;
 *   fixed q = 0.5:        M^ = diag(S / q) |M|, rho(M^) = 0.81 / 0.5 = 1.62, infinite variance.
 * Both estimates are unbiased, but only the first error bar means anything: the running
 * estimate with its claimed interval, and the claimed standard error against walks.
 *
 *   infinite_variance [OUTDIR]    writes OUTDIR/infinite_variance.csv and .png */
#include <stdio.h>

#include "chart.h"
#include "systems.h"

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "docs";
    const int64_t n = 1000;
    ulam_csr *M = random_doubly(n, 8, 0.9, 91);
    double *b = random_vector(n, 0.0, 1.0, 91), *x = direct(M, b, NULL);
    const double qs[2] = {0.0, 0.5};
    out_file o;
    out_open(&o, dir, "infinite_variance.csv");
    fprintf(o.f, "case,walks,estimate,stderr,direct\n");
    double hat[2];
    for (int c = 0; c < 2; c++) {
        ulam_guard g;
        ulam_guard_check(M, qs[c], NULL, &g, NULL);
        hat[c] = g.hat[ULAM_ADJOINT].rho;
        fprintf(stderr, "case %d: q = %s, rho(|M|) = %.3f, rho(M^) = %.3f\n", c, c ? "0.5" : "analog", g.abs.rho, hat[c]);
        ulam_walk_opts wo = ulam_walk_defaults();
        wo.kernel.continue_q = qs[c];
        wo.exec.seed = 9;
        running(M, b, wo, 12, x[0], o.f, c);
    }
    out_commit(&o);
    chart_draw(dir, "infinite_variance", 1100, 450,
               "set multiplot layout 1,2 title 'Infinite variance: x_1 of one system (ρ(|M|) = 0.9), two kernels'\n"
               "set key top left\nset logscale x\nset xlabel 'walks'\nset format x '10^{%%L}'\n"
               "set title 'running estimate and claimed 95%% interval'\nset key bottom right\n"
               "plot 'infinite_variance.csv' u ($1==0?$2:1/0):3:($4*1.96) w yerrorlines pt 7 t 'analog kernel, ρ(M̂) = %.2f', "
               "'' u ($1==1?$2*1.15:1/0):3:($4*1.96) w yerrorlines pt 5 t 'q = 0.5, ρ(M̂) = %.2f', '' u 2:5 w l lw 2 t 'LAPACK'\n"
               "set logscale y\nset format y '10^{%%L}'\nset key bottom left\n"
               "set title 'claimed standard error and actual error'\n"
               "plot 'infinite_variance.csv' u ($1==0?$2:1/0):4 w lp pt 7 t 'analog: claimed stderr', "
               "'' u ($1==0?$2:1/0):(abs($3-$5)) w p pt 6 t 'analog: |error|', "
               "'' u ($1==1?$2:1/0):4 w lp pt 5 t 'q = 0.5: claimed stderr', '' u ($1==1?$2:1/0):(abs($3-$5)) w p pt 4 t 'q = 0.5: |error|', "
               "4.8/sqrt(x) dt 2 t '1/√N slope'\n"
               "unset multiplot\n",
               hat[0], hat[1]);
    free(b), free(x);
    ulam_csr_free(M);
    return 0;
}
