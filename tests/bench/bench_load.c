/* Loading at scale (issue 8): `ulam solve` on a 10^7 x 10^7 Matrix Market file (8 x 10^7
 * entries written with 17 significant digits, rho = 0.9) and its right-hand side, for x_I to
 * 1%, run twice with --cache: the first run parses and writes the binary caches, the second
 * reads them.  Prints the load (parse or cache), guard, solver set-up and walk seconds, the
 * walk kernel rows built, and the peak resident memory against the CSR size.  Targets: parsing < 10 x the walk time, or a second
 * run that loads in under a second; peak RSS <= 2.5 x the CSR.  usage: bench_load path/to/ulam */
#include <math.h>
#include <sys/stat.h>

#include "gen.h"

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_load path/to/ulam\n");
        return 2;
    }
    const int64_t n = 10000000;
    char dir[] = "/tmp/ulam_bench_loadXXXXXX", mpath[256], bpath[256], idx[32];
    if (!mkdtemp(dir)) return 1;
    snprintf(mpath, sizeof mpath, "%s/M.mtx", dir);
    snprintf(bpath, sizeof bpath, "%s/b.mtx", dir);
    snprintf(idx, sizeof idx, "%lld", (long long)n / 2 + 1);
    ulam_csr *M = bench_random_csr(n);
    double *b = bench_random_rhs(n);
    if (!M || !b) return 1;
    double t0 = ulam_now(), csr_mib = bench_csr_bytes(M) / 1048576.0;
    if (ulam_mm_write_matrix(mpath, M, "bench_load: 8 per row, rho 0.9") || ulam_mm_write_vector(bpath, b, n, NULL))
        return 1;
    struct stat st;
    stat(mpath, &st);
    printf("wrote %s: %.0f MB, %lld entries, in %.0f s; CSR in memory %.0f MiB\n", mpath, (double)st.st_size / 1e6,
           (long long)ulam_csr_nnz(M), ulam_now() - t0, csr_mib);
    ulam_csr_free(M);
    free(b);
    char *args[] = {argv[1], "solve", mpath, "--method", "walks", "--rhs", bpath, "--index", idx, "--rel-err", "0.01",
                    "--threads", "2", "--json", "--cache", NULL};
    static char out[1 << 16];
    printf("%-16s %9s %9s %9s %9s %10s %10s %9s %9s\n", "run", "load s", "guards s", "set-up s", "walk s",
           "load/walk", "rows", "peak MiB", "peak/CSR");
    int rc = 0;
    for (int k = 0; k < 2 && !rc; k++) {
        double rss = 0, wall, cpu;
        rc = bench_run(args, out, sizeof out, 0, &wall, &cpu, &rss);
        double load = bench_json_number(out, "load_seconds"), kern = bench_json_number(out, "kernel_seconds");
        double walk = bench_json_number(out, "seconds"), guard = bench_json_number(out, "guard_seconds");
        printf("%-16s %9.3f %9.3f %9.4f %9.4f %10.0f %10.0f %9.0f %9.2f\n", k ? "second (cache)" : "first (parse)", load,
               guard, kern, walk, load / walk, bench_json_number(out, "kernel_rows"), rss, rss / csr_mib);
    }
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) rc = 1;
    return rc;
}
