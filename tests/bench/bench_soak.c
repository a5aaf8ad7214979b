/* Soak (issue 7): 10^9 walk steps on two threads on the large system (n = 10^7, 8 nonzeros a
 * row, rho = 0.9), the resident set sampled after every round of blocks.  Passes when the RSS
 * does not grow after warm-up (the first 5% of the steps) by more than 1 MiB and the estimate
 * is within 4 standard errors of the reference: Gauss-Seidel on the whole vector, swept until
 * x_I changes by less than 1e-13 relative (its error is then below 10 x that: rho / (1 - rho)
 * times the last change).  LAPACK cannot hold n = 10^7 (800 TB dense). */
#include <math.h>

#include "gen.h"

int main(void)
{
    const int64_t n = 10000000, I = n / 2, target = 1000000000;
    ulam_csr *M = bench_random_csr(n);
    double *b = bench_random_rhs(n), *x = calloc((size_t)n, sizeof *x);
    if (!M || !b || !x) {
        fprintf(stderr, "soak: out of memory\n");
        return 1;
    }
    double t0 = ulam_now();
    int sweeps = bench_gauss_seidel(M, b, I, 1e-13, 1000, x, NULL);
    double ref = x[I];
    printf("reference x[%lld] = %.15g (Gauss-Seidel, %d sweeps, %.1f s, settled to 1e-13 unless 1000)\n",
           (long long)I + 1, ref, sweeps, ulam_now() - t0);
    free(x);

    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = I, o.exec.threads = 2, o.stop.max_walks = INT64_MAX / 4, o.exec.seed = 7; /* stopped by steps below */
    ulam_solver *sv = NULL;
    ulam_error err;
    if (ulam_solver_alloc(M, b, &o, &sv, &err)) {
        fprintf(stderr, "soak: %s: %s\n", ulam_strerror(err.status), err.msg);
        return 1;
    }
    ulam_walk_result r = {0};
    double rss0 = 0, rss_max = 0, rss_min = INFINITY, next = 0.1 * (double)target;
    int samples = 0;
    printf("%14s %12s %9s %10s %18s %10s\n", "steps", "walks", "seconds", "RSS MiB", "estimate", "z");
    while (r.steps < target) {
        if (ulam_solver_iterate(sv)) return 1;
        ulam_solver_result(sv, &r);
        double rss = bench_rss();
        if (r.steps >= target / 20) { /* after warm-up */
            if (rss0 == 0) rss0 = rss;
            rss_max = fmax(rss_max, rss), rss_min = fmin(rss_min, rss), samples++;
        }
        if ((double)r.steps >= next || r.steps >= target) {
            printf("%14lld %12lld %9.1f %10.1f %18.12g %10.2f\n", (long long)r.steps, (long long)r.walks, r.seconds,
                   rss / 1048576.0, r.estimate, (r.estimate - ref) / r.std_error);
            next += 0.1 * (double)target;
        }
    }
    double z = (r.estimate - ref) / r.std_error, growth = rss_max - rss0;
    printf("RSS after warm-up %.1f MiB, min %.1f, max %.1f over %d samples: growth %.3f MiB (limit 1)\n",
           rss0 / 1048576.0, rss_min / 1048576.0, rss_max / 1048576.0, samples, growth / 1048576.0);
    printf("CSR %.1f MiB; %.1f M steps/s on %d threads; estimate %.12g +- %.3g, reference %.12g, z = %.2f (limit 4)\n",
           bench_csr_bytes(M) / 1048576.0, (double)r.steps / r.seconds / 1e6, r.threads, r.estimate, r.std_error, ref,
           z);
    int ok = growth <= 1048576.0 && fabs(z) <= 4.0;
    printf("soak %s\n", ok ? "PASS" : "FAIL");
    ulam_solver_free(sv);
    ulam_csr_free(M);
    free(b);
    return ok ? 0 : 1;
}
