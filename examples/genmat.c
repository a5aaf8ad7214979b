/* genmat: make the systems in matrices/ reproducibly (fixed seeds, public API only).
 *
 *   genmat OUTDIR            write every generated system into OUTDIR
 *   genmat --radiosity N OUT.mtx OUT_b.mtx
 *                            a radiosity-like dense n x n M = diag(rho) F and emissions b
 *   genmat --sparse N K S OUT.mtx OUT_b.mtx
 *                            a random nonnegative n x n matrix with K nonzeros per row
 *                            (random columns) and every row sum equal to S
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "systems.h"

/* Write M and b as DIR/NAME.mtx and DIR/NAME_b.mtx; exit on failure (a tool, not a library). */
static void save(const char *dir, const char *name, const ulam_csr *M, const double *b,
                 const char *comment)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.mtx", dir, name);
    int s = ulam_mm_write_matrix(path, M, comment);
    snprintf(path, sizeof path, "%s/%s_b.mtx", dir, name);
    if (!s) s = ulam_mm_write_vector(path, b, M->nrows, "right-hand side b");
    if (s) {
        fprintf(stderr, "genmat: %s: %s\n", path, ulam_strerror(s));
        exit(1);
    }
}

/* The 5-point Laplacian on a g x g grid (A form, diagonal 4). */
static ulam_csr *poisson2d(int g)
{
    int64_t n = (int64_t)g * g, nz = 5 * n, k = 0;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    for (int y = 0; y < g; y++)
        for (int x = 0; x < g; x++) {
            int32_t i = y * g + x;
            int32_t nb[4] = {x > 0 ? i - 1 : -1, x < g - 1 ? i + 1 : -1, y > 0 ? i - g : -1,
                             y < g - 1 ? i + g : -1};
            ti[k] = i, tj[k] = i, tx[k++] = 4.0;
            for (int q = 0; q < 4; q++)
                if (nb[q] >= 0) ti[k] = i, tj[k] = nb[q], tx[k++] = -1.0;
        }
    return build(n, k, ti, tj, tx);
}

/* Write every system of matrices/ that is generated rather than written by hand. */
static void all(const char *dir)
{
    char comment[256];
    ulam_csr *M = poisson2d(20);
    double *b = random_vector(400, 1.0, 1.0, 0); /* all ones */
    save(dir, "poisson20", M, b,
         "2-D Poisson 5-point matrix A on a 20 x 20 grid (n = 400); use --jacobi");
    ulam_csr_free(M), free(b);

    M = poisson2d(30); /* Benzi et al. 2017: 32 nodes a direction, h = 1/31, f = sin(pi x) sin(pi y) */
    b = malloc(900 * sizeof *b);
    for (int y = 0; y < 30; y++)
        for (int x = 0; x < 30; x++)
            b[y * 30 + x] = sin(M_PI * (x + 1) / 31.0) * sin(M_PI * (y + 1) / 31.0) / (31.0 * 31.0);
    save(dir, "poisson900", M, b,
         "-Laplace u = sin(pi x) sin(pi y) on the unit square, u = 0 on its boundary: 5-point A = h^2 "
         "(-Laplace_h), h = 1/31 (30 x 30 unknowns; b = h^2 f); use --jacobi (Benzi et al. 2017)");
    ulam_csr_free(M), free(b);

    M = random_doubly(1000, 8, 0.9, 1000);
    b = random_vector(1000, 0.0, 1.0, 1000);
    save(dir, "randsub1000", M, b,
         "random sparse doubly substochastic M (8 weighted random permutations), n = 1000, every "
         "row and column sum 0.9");
    ulam_csr_free(M), free(b);

    M = radiosity_like(100, 100);
    b = emitters(100);
    save(dir, "radiosity100", M, b,
         "radiosity-like dense substochastic M = diag(rho) F, n = 100, rho in [0.3, 0.8]");
    ulam_csr_free(M), free(b);

    M = random_sparse(200, 8, 0.8, 1, 200);
    b = random_vector(200, -1.0, 1.0, 200);
    save(dir, "signed200", M, b,
         "random signed sparse M, n = 200, 8 nonzeros/row, row sums of |M| 0.8: rho(|M|) < 1");
    ulam_csr_free(M), free(b);

    M = random_sparse(200, 8, 1.3, 1, 201);
    b = random_vector(200, -1.0, 1.0, 201);
    snprintf(comment, sizeof comment, "random signed sparse M, n = 200, 8 nonzeros/row, row "
             "sums of |M| 1.3: rho(M) < 1 < rho(|M|), Neumann converges, walks do not");
    save(dir, "signed_edge200", M, b, comment);
    ulam_csr_free(M), free(b);

    M = random_sparse(200, 8, 1.1, 0, 202);
    b = random_vector(200, 0.0, 1.0, 202);
    save(dir, "divergent200", M, b,
         "random nonnegative sparse M, n = 200, every row sum 1.1: rho(M) = 1.1 > 1, divergent");
    ulam_csr_free(M), free(b);
}

int main(int argc, char **argv)
{
    if (argc == 2 && argv[1][0] != '-') { /* an option is not a folder (genmat --help wrote --help/poisson20_b.mtx) */
        all(argv[1]);
        return 0;
    }
    if (argc == 7 && !strcmp(argv[1], "--sparse")) {
        int64_t n = atoll(argv[2]);
        int k = atoi(argv[3]);
        double s = atof(argv[4]);
        if (n < 2 || k < 1 || k > n) {
            fprintf(stderr, "genmat: need N >= 2 and 1 <= K <= N\n");
            return 2;
        }
        ulam_csr *M = random_sparse(n, k, s, 0, (uint64_t)n);
        double *b = random_vector(n, 0.0, 1.0, (uint64_t)n);
        char comment[128];
        snprintf(comment, sizeof comment, "random sparse M, n = %lld, %d nonzeros/row, row sums %g",
                 (long long)n, k, s);
        int st = ulam_mm_write_matrix(argv[5], M, comment);
        if (!st) st = ulam_mm_write_vector(argv[6], b, n, "right-hand side b");
        ulam_csr_free(M), free(b);
        if (st) fprintf(stderr, "genmat: %s\n", ulam_strerror(st));
        return st ? 1 : 0;
    }
    if (argc == 5 && !strcmp(argv[1], "--radiosity") && atoll(argv[2]) >= 5) {
        int64_t n = atoll(argv[2]);
        ulam_csr *M = radiosity_like(n, (uint64_t)n);
        double *b = emitters(n);
        int st = ulam_mm_write_matrix(argv[3], M, "radiosity-like dense M = diag(rho) F, rho in [0.3, 0.8]");
        if (!st) st = ulam_mm_write_vector(argv[4], b, n, "emissions b");
        ulam_csr_free(M), free(b);
        if (st) fprintf(stderr, "genmat: %s\n", ulam_strerror(st));
        return st ? 1 : 0;
    }
    int help = argc == 2 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"));
    fprintf(help ? stdout : stderr,
            "usage: genmat OUTDIR | genmat --radiosity N OUT.mtx OUT_b.mtx | genmat --sparse N K S OUT.mtx OUT_b.mtx\n");
    return help ? 0 : 2;
}
