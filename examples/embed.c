/* embed: the smallest program built against an installed ulam (pkg-config --cflags --libs ulam).
 * It estimates x_0 of (I - M) x = b for a 3-state chain by the library's primary call (an
 * analysis of M, then ulam_analysis_solve: the method `ulam solve` chooses), solves the same
 * system with LAPACK, and exits 0 only when LAPACK's x_0 lies in the printed 95% interval. */
#include <stdio.h>

#include <ulam.h>

int main(void)
{
    /* M: a substochastic chain, b = (1, 2, 3). */
    const int32_t ti[] = {0, 0, 1, 1, 2};
    const int32_t tj[] = {1, 2, 0, 2, 1};
    const double tx[] = {0.3, 0.2, 0.4, 0.1, 0.5};
    const double b[] = {1.0, 2.0, 3.0};
    ulam_csr *M = NULL;
    int st = ulam_csr_from_triplets(3, 3, 5, ti, tj, tx, &M);
    ulam_walk_opts o = ulam_walk_defaults();
    o.exec.seed = 7;
    ulam_analysis *a = NULL;
    ulam_answer ans;
    ulam_error err;
    double x[3];
    if (!st)
        st = ulam_analysis_alloc(M, NULL, &a, &err);
    if (!st)
        st = ulam_analysis_solve(a, b, &o, NULL, NULL, NULL, &ans, &err);
    if (!st)
        st = ulam_direct_solve(M, b, x, 0, NULL, &err);
    ulam_analysis_free(a);
    ulam_csr_free(M);
    if (st) {
        fprintf(stderr, "embed: %s\n", ulam_strerror(st));
        return 1;
    }
    int in = ans.ci95[0] <= x[0] && x[0] <= ans.ci95[1];
    printf("ulam %s: x_0 = %.6f (95%% CI %.6f .. %.6f) by %s (%lld walks); LAPACK %.6f, %s\n", ULAM_VERSION,
           ans.estimate, ans.ci95[0], ans.ci95[1], ulam_method_name(ans.method), (long long)ans.walks.walks, x[0],
           in ? "inside" : "OUTSIDE");
    return in ? 0 : 1;
}
