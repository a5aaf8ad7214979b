/* embed: the smallest program built against an installed ulam (pkg-config --cflags --libs ulam).
 * It estimates x_0 of (I - M) x = b for a 3-state chain by adjoint walks, solves the same
 * system with LAPACK, and exits 0 only when the two agree within four standard errors. */
#include <math.h>
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
    ulam_walk_result r;
    ulam_error err;
    double x[3];
    if (!st)
        st = ulam_solve(M, b, &o, &r, &err);
    if (!st)
        st = ulam_direct_solve(M, b, x, 0, NULL, &err);
    ulam_csr_free(M);
    if (st) {
        fprintf(stderr, "embed: %s\n", ulam_strerror(st));
        return 1;
    }
    double z = (r.estimate - x[0]) / r.std_error;
    printf("ulam %s: x_0 = %.6f +- %.6f by %lld walks; LAPACK %.6f; z = %.2f\n", ULAM_VERSION,
           r.estimate, r.std_error, (long long)r.walks, x[0], z);
    return fabs(z) < 4 ? 0 : 1;
}
