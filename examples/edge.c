/* Experiment 1, approaching the edge: M = s P for a fixed random stochastic P (n = 1000, 8 per
 * row), s from 0.5 to 0.999.  For adjoint collision and absorption walks: mean walk length
 * against 1/(1 - s), per-walk variance, and the time to 1% relative error (per-walk variance
 * x seconds per walk / (0.01 x)^2, from a run of 2 10^5 walks); beside them LAPACK's time,
 * its relative error (against one step of iterative refinement with a long double residual)
 * and rcond.
 *
 *   edge [OUTDIR]    writes OUTDIR/edge.csv and OUTDIR/edge.png (default OUTDIR: docs) */
#include <math.h>
#include <stdio.h>

#include "chart.h"
#include "systems.h"

/* The relative error of x: one refinement step d solves (I - M) d = b - (I - M) x. */
static double lapack_error(const ulam_csr *M, const double *b, const double *x)
{
    int64_t n = M->nrows;
    double *r = malloc((size_t)n * sizeof *r), dn = 0, xn = 0;
    for (int64_t i = 0; i < n; i++) {
        long double s = (long double)b[i] - x[i];
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += (long double)M->val[q] * x[M->colidx[q]];
        r[i] = (double)s;
    }
    double *d = direct(M, r, NULL);
    for (int64_t i = 0; i < n; i++) dn = fmax(dn, fabs(d[i])), xn = fmax(xn, fabs(x[i]));
    free(r), free(d);
    return dn / xn;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "docs";
    const double ss[] = {0.5, 0.7, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 0.999};
    const int64_t n = 1000;
    ulam_csr *P = random_sparse(n, 8, 1.0, 0, 2024);
    double *b = random_vector(n, 0.0, 1.0, 2024);
    out_file o;
    out_open(&o, dir, "edge.csv");
    fprintf(o.f, "s,inv_gap,len_collision,var_collision,t1_collision,len_absorption,var_absorption,"
                 "t1_absorption,lapack_seconds,lapack_relerr,rcond\n");
    for (size_t k = 0; k < sizeof ss / sizeof *ss; k++) {
        ulam_csr *M = scaled_copy(P, ss[k]);
        ulam_direct_info info;
        double *x = direct(M, b, &info);
        fprintf(o.f, "%g,%g", ss[k], 1 / (1 - ss[k]));
        for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
            ulam_walk_opts wo = ulam_walk_defaults();
            wo.estimator = est;
            wo.stop.max_walks = 200000;
            wo.exec.seed = 11 + k;
            ulam_walk_result r = walk(M, b, &wo);
            double t1 = r.variance / pow(0.01 * x[0], 2) * r.seconds / (double)r.walks;
            fprintf(o.f, ",%g,%g,%g", (double)r.steps / (double)r.walks, r.variance, t1);
            fprintf(stderr, "s = %-6g %-10s mean length %8.2f  variance %10.4g  time to 1%% %.3g s  (z = %.2f)\n",
                    ss[k], est ? "absorption" : "collision", (double)r.steps / (double)r.walks, r.variance, t1,
                    (r.estimate - x[0]) / r.std_error);
        }
        fprintf(o.f, ",%g,%g,%g\n", info.seconds, lapack_error(M, b, x), info.rcond);
        free(x);
        ulam_csr_free(M);
    }
    out_commit(&o);
    chart_draw(dir, "edge", 1100, 800,
               "set multiplot layout 2,2 title 'Approaching the edge: M = s P, P stochastic (n = 1000, 8 per row), x_1 by adjoint walks'\n"
               "set logscale xy\nset format y '10^{%%L}'\nset xlabel '1/(1 - s)'\n"
               "set title 'mean walk length'\n"
               "plot 'edge.csv' every ::1 u 2:3 w lp pt 7 t 'collision', '' every ::1 u 2:6 w lp pt 5 t 'absorption', x - 1 t 's/(1-s) (expected)' dt 2\n"
               "set title 'per-walk variance'\n"
               "plot 'edge.csv' every ::1 u 2:4 w lp pt 7 t 'collision', '' every ::1 u 2:7 w lp pt 5 t 'absorption'\n"
               "set title 'seconds to 1%% relative error (walks) and to solve (LAPACK dgesv)'\nset ylabel 'seconds'\n"
               "plot 'edge.csv' every ::1 u 2:5 w lp pt 7 t 'collision', '' every ::1 u 2:8 w lp pt 5 t 'absorption', '' every ::1 u 2:9 w lp pt 9 t 'LAPACK (whole vector)'\n"
               "set title 'LAPACK: relative error, and its bound eps/rcond'\nset ylabel ''\nset key bottom right\n"
               "plot 'edge.csv' every ::1 u 2:10 w lp pt 7 t 'relative error (vs refined)', '' every ::1 u 2:(2.2e-16/$11) w lp pt 5 t 'eps / rcond'\n"
               "unset multiplot\n");
    free(b);
    ulam_csr_free(P);
    return 0;
}
