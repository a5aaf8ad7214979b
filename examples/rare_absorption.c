/* Experiment 4, absorption with rare termination: a random nonnegative M (n = 200, row sums
 * 0.9) whose row 1 is rescaled to sum 1 - eps, and b = e_1, so only state 1 scores.  Adjoint
 * walks from state 1: the collision estimator counts visits to state 1 and stays bounded as
 * eps -> 0; the absorption estimator scores 1/eps on the rare walks that end at state 1, so
 * its per-walk variance grows like 1/eps (its second moment carries b o b / p*).  The guards'
 * rho(M^) stays below 1 throughout: this failure is the 1/p* term, not the kernel.
 *
 *   rare_absorption [OUTDIR]    writes OUTDIR/rare_absorption.csv and .png */
#include <stdio.h>

#include "chart.h"
#include "systems.h"

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "docs";
    const int64_t n = 200;
    const double eps[] = {0.1, 0.03, 0.01, 0.003, 0.001, 3e-4, 1e-4};
    out_file o;
    out_open(&o, dir, "rare_absorption.csv");
    fprintf(o.f, "eps,rho_hat,x1,var_collision,var_absorption,rel_se_collision,rel_se_absorption\n");
    double *b = calloc((size_t)n, sizeof *b);
    b[0] = 1.0;
    for (size_t k = 0; k < sizeof eps / sizeof *eps; k++) {
        ulam_csr *M = random_sparse(n, 8, 0.9, 0, 404);
        for (int64_t q = M->rowptr[0]; q < M->rowptr[1]; q++) M->val[q] *= (1 - eps[k]) / 0.9;
        ulam_guard g;
        ulam_guard_check(M, 0.0, NULL, &g, NULL);
        double *x = direct(M, b, NULL);
        fprintf(o.f, "%g,%g,%g", eps[k], g.hat[ULAM_ADJOINT].rho, x[0]);
        ulam_walk_result r[2];
        for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
            ulam_walk_opts wo = ulam_walk_defaults();
            wo.estimator = est;
            wo.stop.max_walks = 1000000;
            wo.exec.seed = 3 + k;
            r[est] = walk(M, b, &wo);
            fprintf(o.f, ",%g", r[est].variance);
        }
        fprintf(o.f, ",%g,%g\n", r[0].std_error / x[0], r[1].std_error / x[0]);
        fprintf(stderr, "eps = %-7g rho(M^) = %.4f  x_1 = %.4f  variance: collision %.4g, absorption %.4g\n",
                eps[k], g.hat[ULAM_ADJOINT].rho, x[0], r[0].variance, r[1].variance);
        free(x);
        ulam_csr_free(M);
    }
    out_commit(&o);
    chart_draw(dir, "rare_absorption", 700, 480,
               "set title 'Absorption with rare termination: p* = ε at the only scoring state (10^6 walks each)'\n"
               "set logscale xy\nset format y '10^{%%L}'\nset format x '10^{%%L}'\nset xlabel '1/ε'\nset ylabel 'per-walk variance'\n"
               "plot 'rare_absorption.csv' every ::1 u (1/$1):4 w lp pt 7 t 'collision', "
               "'' every ::1 u (1/$1):5 w lp pt 5 t 'absorption', x dt 2 t '1/ε slope'\n");
    free(b);
    return 0;
}
