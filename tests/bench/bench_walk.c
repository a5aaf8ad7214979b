/* Benchmark: walk throughput (steps per second) of adjoint collision walks on random
 * sparse systems with 8 nonzeros per row and row sums 0.9, in cache (n = 1000) and out of
 * cache (n = 10^7), with 1 and 2 threads.  Targets (issue 3): >= 100 M steps/s in cache and
 * >= 15 M steps/s at n = 10^7 on one core; two threads >= 1.8x one.  The kernel is built whole
 * before the clock starts (whole_kernel), so these are steps on built rows; what a first visit
 * costs is in bench_scale.  This machine is a shared virtual one whose speed drifts by +-20%
 * from run to run, so each figure is the best of three one-second runs. */
#include <stdio.h>
#include <stdlib.h>

#include "gen.h"

int main(void)
{
    const int64_t sizes[2] = {1000, 10000000};
    printf("%-12s %8s %14s %12s %10s\n", "n", "threads", "steps", "seconds", "M steps/s");
    for (int s = 0; s < 2; s++) {
        ulam_csr *M = bench_random_csr(sizes[s]);
        double *b = M ? malloc((size_t)sizes[s] * sizeof *b) : NULL;
        if (!b) {
            fprintf(stderr, "out of memory for n = %lld\n", (long long)sizes[s]);
            return 1;
        }
        for (int64_t i = 0; i < sizes[s]; i++) b[i] = 1.0;
        ulam_walk_result best[2] = {{0}};
        for (int rep = 0; rep < 3; rep++) /* alternate 1 and 2 threads: drift hits both */
            for (int t = 1; t <= 2; t++) {
                ulam_walk_opts o = ulam_walk_defaults();
                o.stop.max_walks = 0;
                o.stop.max_seconds = 1.0;
                o.exec.threads = t;
                o.kernel.whole_kernel = 1;
                o.query.index = sizes[s] / 2;
                o.exec.seed = (uint64_t)rep + 1;
                ulam_walk_result r;
                if (ulam_solve_walks(M, b, &o, &r, NULL)) return 1;
                if (rep == 0 || r.steps / r.seconds > best[t - 1].steps / best[t - 1].seconds) best[t - 1] = r;
            }
        for (int t = 1; t <= 2; t++)
            printf("%-12lld %8d %14lld %12.3f %10.1f\n", (long long)sizes[s], t, (long long)best[t - 1].steps,
                   best[t - 1].seconds, (double)best[t - 1].steps / best[t - 1].seconds / 1e6);
        printf("%-12s %8s two threads / one = %.2fx\n", "", "",
               (best[1].steps / best[1].seconds) / (best[0].steps / best[0].seconds));
        free(b);
        ulam_csr_free(M);
    }
    return 0;
}
