/* bench_mcsa: every unknown to 10^-8 by the outer iterations, beside their peers, in one run.
 *
 *   1. the paper's Poisson problem (Benzi et al. 2017, matrices/poisson900 with Jacobi):
 *      Richardson, Gauss-Seidel, CG, sequential MC and MCSA to 10^-8 (Richardson also to 10^-7,
 *      the tolerance its 3133 matches); fails unless the counts are within 2 of the paper's,
 *      MCSA needs at most 10 iterations and every solution is within 2e-7 of LAPACK's;
 *   2. threads: the first three MCSA iterations on one thread and on two (the same walks, bit
 *      for bit: fails otherwise), the walk seconds' ratio;
 *   3. the scale benchmark's random family (rho = 0.9, 8 nonzeros a row) at n = 10^5 and 10^6:
 *      MCSA beside Gauss-Seidel and GMRES(30), seconds to each tolerance 10^-2 .. 10^-8.  MCSA is
 *      given at most BUDGET seconds and 5 n histories an iteration.
 * Writes docs/mcsa.csv (method, problem, n, residual, seconds: every iteration of an outer
 * method, a run a tolerance of a Krylov one) and draws docs/mcsa.png.
 *
 *   bench_mcsa [--chart]     (--chart: redraw docs/mcsa.png from docs/mcsa.csv only) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"
#include "gnuplot.h"

enum { NTOL = 7, STEPS = 100000 };
/* The current iterate of outer iteration s (owned by it). */
static const double *outer_x(const ulam_outer *s)
{
    ulam_outer_info info;
    ulam_outer_get_info(s, &info);
    return info.x;
}

static const double BUDGET = 120.0; /* seconds of MCSA per random system (checked between iterations) */
enum { HIST_PER_N = 5 };             /* its history cap an iteration: 5 n */

static FILE *csv;

/* Seconds at which the residual first met 10^-1 .. 10^-8 (index k: 10^-(k+1)); NAN if never. */
static void crossings(const ulam_outer_step *st, int k, double t[8])
{
    double sum = 0;
    for (int j = 0; j < 8; j++) t[j] = NAN;
    for (int i = 0; i < k; i++) {
        sum += st[i].seconds;
        for (int j = 0; j < 8; j++)
            if (isnan(t[j]) && st[i].residual <= pow(10.0, -(j + 1))) t[j] = sum;
    }
}

/* One CSV row per tolerance 10^-2 .. 10^-8 (unreached ones are left out). */
static void put_rows(const char *method, const char *problem, int64_t n, const double t[8])
{
    for (int j = 1; j < 8; j++)
        if (!isnan(t[j])) fprintf(csv, "%s,%s,%lld,%g,%.6g\n", method, problem, (long long)n, pow(10.0, -(j + 1)), t[j]);
}

/* One CSV row per iteration of an outer method: the smallest residual reached so far and when
 * (the first 100 and then every 10th of a long run, and the last). */
static void put_steps(const char *method, const char *problem, int64_t n, const ulam_outer_step *st, int k)
{
    double t = 0, best = INFINITY;
    for (int i = 0; i < k; i++) {
        t += st[i].seconds;
        best = fmin(best, st[i].residual);
        if (i < 100 || i % 10 == 9 || i == k - 1)
            fprintf(csv, "%s,%s,%lld,%.6g,%.6g\n", method, problem, (long long)n, best, t);
    }
}

/* ||x - y||_2 / ||y||_2. */
static double rel_error(const double *x, const double *y, int64_t n)
{
    double num = 0, den = 0;
    for (int64_t i = 0; i < n; i++) num += (x[i] - y[i]) * (x[i] - y[i]), den += y[i] * y[i];
    return sqrt(num / den);
}

/* An outer iteration to tol; returns the iterations, fills steps, x and the totals. */
static int outer(const ulam_csr *M, const double *b, int method, double tol, int threads, int max_iter,
                 int64_t max_hist, double budget, ulam_outer_step *st, double *x, int *status)
{
    ulam_outer_opts o = ulam_outer_defaults();
    o.method = method, o.tol = tol, o.walk.exec.threads = threads, o.max_iter = max_iter;
    if (max_hist) o.max_histories = max_hist;
    ulam_outer *it = NULL;
    ulam_error err;
    if ((*status = ulam_outer_alloc(M, b, &o, &it, &err))) { /* refused (e.g. an infinite variance): no step */
        fprintf(stderr, "bench_mcsa: refused: %s\n", err.msg);
        memset(x, 0, (size_t)M->nrows * sizeof *x); /* the start, x0 = 0 */
        return 0;
    }
    int k = 0;
    double spent = 0;
    while (!ulam_outer_done(it) && k < STEPS) {
        *status = ulam_outer_iterate(it, &st[k]);
        spent += st[k++].seconds;
        if (budget > 0 && spent > budget && !ulam_outer_done(it)) {
            *status = -1; /* out of the benchmark's time budget */
            break;
        }
    }
    memcpy(x, outer_x(it), (size_t)M->nrows * sizeof *x);
    ulam_outer_free(it);
    return k;
}

/* Sum of the histories of k steps. */
static int64_t histories(const ulam_outer_step *st, int k)
{
    int64_t h = 0;
    for (int i = 0; i < k; i++) h += st[i].histories;
    return h;
}

/* Seconds of k steps (walk seconds when walk != 0). */
static double seconds(const ulam_outer_step *st, int k, int walk)
{
    double s = 0;
    for (int i = 0; i < k; i++) s += walk ? st[i].walk_seconds : st[i].seconds;
    return s;
}

/* Part 1: the paper's table.  Returns the number of missed targets. */
static int paper(ulam_outer_step *st)
{
    ulam_csr *A = NULL, *M = NULL;
    double *b = NULL;
    int64_t n;
    if (ulam_mm_read_matrix("matrices/poisson900.mtx", &A, NULL) ||
        ulam_mm_read_vector("matrices/poisson900_b.mtx", &b, &n, NULL) || ulam_jacobi(A, b, 1.0, &M, b, NULL)) {
        fprintf(stderr, "bench_mcsa: cannot read matrices/poisson900 (run from the source root)\n");
        exit(1);
    }
    double *x = malloc((size_t)n * sizeof *x), *xd = malloc((size_t)n * sizeof *xd), t[8];
    ulam_direct_solve(M, b, xd, 0, NULL, NULL);
    printf("Poisson n = 900 (Benzi et al. 2017), Jacobi, x0 = 0, eps1 = 0.1, expected estimator, seed 1\n");
    printf("%-22s %8s %8s %12s %14s %10s %10s\n", "method", "tol", "iters", "paper iters", "hist/iter",
           "seconds", "rel.err");
    struct {
        const char *name;
        int method;
        double tol;
        int paper; /* the paper's count when this row reproduces it, else 0 */
    } rows[] = {{"richardson", ULAM_RICHARDSON, 1e-7, 3133}, {"richardson", ULAM_RICHARDSON, 1e-8, 0},
                {"gauss-seidel", ULAM_GAUSS_SEIDEL, 1e-8, 0},  {"sequential", ULAM_SEQUENTIAL, 1e-8, 9},
                {"mcsa", ULAM_MCSA, 1e-8, 8}};
    int missed = 0, status;
    for (int r = 0; r < 5; r++) {
        int k = outer(M, b, rows[r].method, rows[r].tol, 0, 0, 0, 0, st, x, &status);
        double err = rel_error(x, xd, n), hist = (double)histories(st, k) / k;
        char pc[16] = "-";
        if (rows[r].paper) snprintf(pc, sizeof pc, "%d", rows[r].paper);
        printf("%-22s %8.0e %8d %12s %14.0f %10.3f %10.3g\n", rows[r].name, rows[r].tol, k, pc, hist,
               seconds(st, k, 0), err);
        if (status || (rows[r].paper && abs(k - rows[r].paper) > 2) || err > 2e-7 ||
            (rows[r].method == ULAM_MCSA && k > 10)) {
            printf("  MISSED: status %d, %d iterations, error %.3g\n", status, k, err);
            missed++;
        }
        if (rows[r].tol == 1e-8) put_steps(rows[r].name, "poisson", n, st, k);
    }
    for (int j = 1; j < 8; j++) { /* CG, one run a tolerance */
        int its;
        double res, t0 = ulam_now();
        ulam_cg(M, b, pow(10.0, -(j + 1)), 100000, x, &its, &res);
        t[j] = ulam_now() - t0;
        if (j == 7) printf("%-22s %8.0e %8d %12s %14s %10.3f %10.3g\n", "cg", 1e-8, its, "-", "-", t[j], rel_error(x, xd, n));
    }
    put_rows("cg", "poisson", n, t);
    free(x), free(xd), free(b);
    ulam_csr_free(A), ulam_csr_free(M);
    return missed;
}

/* Part 2: thread speed-up of the walks (the first three MCSA iterations on Poisson). */
static int threads(ulam_outer_step *st)
{
    ulam_csr *A = NULL, *M = NULL;
    double *b = NULL;
    int64_t n;
    ulam_mm_read_matrix("matrices/poisson900.mtx", &A, NULL);
    ulam_mm_read_vector("matrices/poisson900_b.mtx", &b, &n, NULL);
    ulam_jacobi(A, b, 1.0, &M, b, NULL);
    double *x1 = malloc((size_t)n * sizeof *x1), *x2 = malloc((size_t)n * sizeof *x2), w[2][2];
    ulam_outer_step *st2 = st + 16;
    int status, k1 = 0, k2 = 0, same = 1;
    for (int rep = 0; rep < 2; rep++) { /* alternate one and two threads, keep the best of two */
        k1 = outer(M, b, ULAM_MCSA, 1e-8, 1, 3, 0, 0, st, x1, &status);
        w[0][rep] = seconds(st, k1, 1);
        k2 = outer(M, b, ULAM_MCSA, 1e-8, 2, 3, 0, 0, st2, x2, &status);
        w[1][rep] = seconds(st2, k2, 1);
        same = same && k1 == k2 && !memcmp(x1, x2, (size_t)n * sizeof *x1) && histories(st, k1) == histories(st2, k2);
    }
    double one = fmin(w[0][0], w[0][1]), two = fmin(w[1][0], w[1][1]);
    printf("\nthreads: MCSA on Poisson n = 900, 3 iterations, %lld histories (best of 2)\n",
           (long long)histories(st, k1));
    printf("  1 thread %.3f s walking, 2 threads %.3f s: %.2fx; iterates %s\n", one, two, one / two,
           same ? "bit-identical" : "DIFFER");
    free(x1), free(x2), free(b);
    ulam_csr_free(A), ulam_csr_free(M);
    return !same;
}

/* Part 3: one random system: MCSA, Gauss-Seidel and GMRES(30), seconds to each tolerance. */
static void scale(int64_t n, ulam_outer_step *st)
{
    ulam_csr *M = bench_random_csr(n);
    double *b = bench_random_rhs(n), *x = malloc((size_t)n * sizeof *x), t[8], tm[8], tg[8];
    ulam_guard g;
    ulam_guard_check(M, 0.0, NULL, &g, NULL);
    int status, kg = outer(M, b, ULAM_GAUSS_SEIDEL, 1e-8, 0, 0, 0, 0, st, x, &status);
    crossings(st, kg, tg);
    put_steps("gauss-seidel", "random", n, st, kg);
    for (int j = 1; j < 8; j++) {
        int its;
        double res, t0 = ulam_now();
        ulam_gmres(M, b, 30, pow(10.0, -(j + 1)), 100000, x, &its, &res);
        t[j] = ulam_now() - t0;
    }
    put_rows("gmres", "random", n, t);
    int km = outer(M, b, ULAM_MCSA, 1e-8, 0, 0, HIST_PER_N * n, BUDGET, st, x, &status);
    crossings(st, km, tm);
    put_steps("mcsa", "random", n, st, km);
    printf("\nrandom n = %lld (rho(|M|) = 0.9; forward rho(M^) = %.4f%s): seconds to reach each tolerance\n",
           (long long)n, g.hat[ULAM_FORWARD].rho, g.verdict_hat[ULAM_FORWARD] == ULAM_VERDICT_FAIL ? ": variance infinite" : "");
    printf("%-8s %12s %12s %12s %10s %10s\n", "tol", "mcsa", "gauss-seidel", "gmres(30)", "mcsa/gs", "mcsa/gmres");
    for (int j = 1; j < 8; j++)
        printf("%-8.0e %12.4g %12.4g %12.4g %10.3g %10.3g\n", pow(10.0, -(j + 1)), tm[j], tg[j], t[j], tm[j] / tg[j],
               tm[j] / t[j]);
    double res = km ? st[km - 1].residual : 1;
    printf("mcsa (at most %d n histories an iteration): %d iterations, %lld histories, residual %.3g, %s\n",
           HIST_PER_N, km, (long long)histories(st, km), res,
           status == ULAM_OK ? "converged" : status == -1 ? "stopped at the benchmark's time budget"
                                                          : ulam_strerror(status));
    for (int i = 0; i < km; i++)
        printf("  iteration %d: residual %.3e, %lld histories, rel sd %.3f, %.2f s\n", i + 1, st[i].residual,
               (long long)st[i].histories, st[i].rel_sd, st[i].seconds);
    printf("gauss-seidel: %d sweeps\n", kg);
    free(b), free(x);
    ulam_csr_free(M);
}

/* The chart from docs/mcsa.csv: seconds against tolerance, one panel a problem. */
static int chart(void)
{
    return gnuplot_draw("docs", "mcsa", 1500, 480,
                        "set multiplot layout 1,3\nset logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
                        "set xrange [1:5e-9] reverse\nset xlabel 'smallest residual ||r||/||b|| reached'\n"
                        "set ylabel 'seconds'\nset key top left font ',9'\nset grid\nset datafile separator ','\n"
                        "set title 'Poisson n = 900 (Benzi et al. 2017), Jacobi'\n"
                        "plot for [m in 'mcsa sequential gauss-seidel richardson'] "
                        "sprintf(\"< grep '^%s,poisson,' mcsa.csv\", m) u 4:5 w l lw 2 t m, "
                        "\"< grep '^cg,poisson,' mcsa.csv\" u 4:5 w lp lw 2 t 'cg (b is an eigenvector: one step)'\n"
                        "do for [n in '100000 1000000'] {\n"
                        "  set title sprintf('random, rho = 0.9, n = %s', n)\n"
                        "  plot for [m in 'mcsa gauss-seidel gmres'] "
                        "sprintf(\"< grep '^%s,random,%s,' mcsa.csv\", m, n) u 4:5 w lp lw 2 ps 0.6 t (m eq 'gmres' ? 'gmres(30)' : m)\n"
                        "}\nunset multiplot\n");
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--chart")) return chart() ? 1 : 0;
    setvbuf(stdout, NULL, _IOLBF, 0); /* a line at a time: the run takes minutes */
    ulam_outer_step *st = malloc(STEPS * sizeof *st);
    if (argc > 1 && !strcmp(argv[1], "--paper")) { /* the test: the paper's three rows alone */
        csv = fopen("/dev/null", "w");
        int missed = !st || !csv || paper(st);
        if (csv) fclose(csv);
        free(st);
        printf("\n%s\n", missed ? "MISSED the paper's rows (see above)" : "the paper's rows reproduced");
        return missed ? 1 : 0;
    }
    ulam_outfile out;
    if (!st || ulam_outfile_open(&out, "docs/mcsa.csv")) {
        fprintf(stderr, "bench_mcsa: cannot write docs/mcsa.csv (run from the source root)\n");
        return 1;
    }
    csv = out.f;
    fprintf(csv, "method,problem,n,tol,seconds\n");
    int missed = paper(st);
    missed += threads(st);
    scale(100000, st);
    scale(1000000, st);
    free(st);
    if (ulam_outfile_commit(&out)) return 1;
    chart();
    printf("\n%s\n", missed ? "MISSED a target (see above)" : "all targets met");
    return missed ? 1 : 0;
}
