/* Why --method auto does not reuse the chosen pilot's walks: a measured bias.
 *
 * The system of the rare-absorption experiment (n = 200, row sums 0.9, row 1 rescaled to sum
 * 1 - eps) with b = e_T (default T = 200): x_1 is the weighted chance that a walk from state 1
 * reaches T, so every estimator's score is skewed (mostly 0, rarely large), and a pilot's sample
 * variance is small exactly when it missed the rare large scores, that is when its mean is low.
 * For each of R seeds, ulam_auto_solver chooses among the adjoint analog estimators (collision,
 * absorption, expected) by their pilots; then N fresh walks with the choice give the answer.
 * "Reused" merges the chosen candidate's pilot walks into those N (the pooled mean), as a
 * scheme that wastes no walk would.  Over the seeds the fresh answer's mean agrees with the
 * exact x_1 (LAPACK) and the reused one's does not: the choice looked at the pilot's variance,
 * which is correlated with its mean.  "reused - fresh" is their paired difference (the pilots'
 * share of it alone).
 *
 *   pilot_reuse [EPS [R [N [ESTIMATOR [T]]]]]  defaults 0.01, 2000 seeds, 1024 walks, none pinned
 *                                              (0 collision, 1 absorption, 2 expected), 200 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "chart.h"
#include "systems.h"

/* Mean and standard error of n values. */
static void mean_se(const double *v, int n, double *m, double *se)
{
    double s = 0, s2 = 0;
    for (int k = 0; k < n; k++) s += v[k];
    *m = s / n;
    for (int k = 0; k < n; k++) s2 += (v[k] - *m) * (v[k] - *m);
    *se = sqrt(s2 / (n - 1) / n);
}

int main(int argc, char **argv)
{
    double eps = argc > 1 ? atof(argv[1]) : 0.01;
    int R = argc > 2 ? atoi(argv[2]) : 2000;
    int64_t N = argc > 3 ? atoll(argv[3]) : 1024;
    int pin = argc > 4 ? atoi(argv[4]) : -1, target = argc > 5 ? atoi(argv[5]) : 200;
    const int64_t n = 200;
    if (!(eps > 0 && eps < 1) || R < 2 || N < 1 || pin > 2 || target < 1 || target > n) {
        fprintf(stderr, "usage: pilot_reuse [EPS in (0, 1) [SEEDS >= 2 [WALKS >= 1 [ESTIMATOR -1..2 [T 1..200]]]]]\n");
        return 2;
    }
    ulam_csr *M = random_sparse(n, 8, 0.9, 0, 404);
    for (int64_t q = M->rowptr[0]; q < M->rowptr[1]; q++) M->val[q] *= (1 - eps) / 0.9;
    double *b = calloc((size_t)n, sizeof *b), *fresh = malloc((size_t)R * sizeof *fresh);
    double *reused = malloc((size_t)R * sizeof *reused), *diff = malloc((size_t)R * sizeof *diff);
    b[target - 1] = 1.0;
    double *x = direct(M, b, NULL), exact = x[0], pilot = 0, chosen[3] = {0}, reused_by[3] = {0};
    for (int s = 0; s < R; s++) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.stop.max_walks = N, o.exec.seed = (uint64_t)s + 1, o.exec.threads = 1;
        ulam_auto_opts ao = ulam_auto_defaults();
        ao.pin_mode = 1; /* adjoint */
        if (pin >= 0) o.estimator = pin, ao.pin_estimator = 1;
        else ao.pin_continue = 1; /* analog: the three estimators race */
        ulam_auto_result res;
        ulam_solver *sv = NULL;
        int status = ulam_auto_solver(M, b, &o, &ao, &res, &sv, NULL);
        while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
        if (status || res.chosen < 0) {
            fprintf(stderr, "pilot_reuse: seed %d: %s\n", s + 1, ulam_strerror(status));
            return 1;
        }
        ulam_walk_result r;
        ulam_solver_result(sv, &r);
        ulam_solver_free(sv);
        const ulam_auto_candidate *c = &res.cand[res.chosen];
        double np = (double)c->pilot_walks;
        fresh[s] = r.estimate;
        reused[s] = (np * c->estimate + (double)r.walks * r.estimate) / (np + (double)r.walks);
        diff[s] = reused[s] - fresh[s];
        pilot += np / (np + (double)r.walks) / R;
        chosen[c->estimator] += 1.0 / R;
        reused_by[c->estimator] += reused[s] - exact;
    }
    double mf, sf, mr, sr, md, sd;
    mean_se(fresh, R, &mf, &sf);
    mean_se(reused, R, &mr, &sr);
    mean_se(diff, R, &md, &sd);
    printf("pilot reuse on the rare-absorption system (eps %g, b = e_%d, x_1 = %.10g, LAPACK), %d seeds, %lld fresh "
           "walks a seed\n", eps, target, exact, R, (long long)N);
    printf("chosen: collision %.1f%%, absorption %.1f%%, expected %.1f%%; the pilots' walks are %.1f%% of a reused run's\n",
           100 * chosen[0], 100 * chosen[1], 100 * chosen[2], 100 * pilot);
    printf("%-8s %14s %12s %8s\n", "answer", "mean - exact", "std error", "z");
    printf("%-8s %14.4e %12.4e %8.2f\n", "fresh", mf - exact, sf, (mf - exact) / sf);
    printf("%-8s %14.4e %12.4e %8.2f\n", "reused", mr - exact, sr, (mr - exact) / sr);
    printf("%-8s %14.4e %12.4e %8.2f  (reused - fresh, paired)\n", "pilots", md, sd, md / sd);
    for (int e = 0; e < 3; e++)
        if (chosen[e] > 0)
            printf("  reused, when %-10s was chosen: mean - exact %.4e\n", e == 0 ? "collision" : e == 1 ? "absorption" : "expected",
                   reused_by[e] / (chosen[e] * R));
    free(x), free(b), free(fresh), free(reused), free(diff);
    ulam_csr_free(M);
    return 0;
}
