/* Partitioned walks (ulam_dist.h, issue 43): for 1 .. 64 ranks (threads of this process sharing
 * an in-memory exchange, tests/hub.h: the partition and the walks are those of as many MPI ranks;
 * the time is not), the share of steps that cross ranks, bytes a step, exchange rounds, each
 * rank's rows, and the same answer bit for bit; then a projection of a run's time to 64 ranks from
 * the one-rank step time and an assumed network (docs/distributed.md states it as a projection).
 *     build/tests/bench_dist [walks]
 * Systems: forward walks (all of x) on screened diffusion 300 x 300 (a grid: a walk stays near its
 * start), R-MAT 2^16 PageRank (0.85 P', b uniform: walks jump anywhere), and the 8-a-row random
 * matrix of bench_walk. */
#include "../hub.h"
#include "gen.h"

#include <stdio.h>
#include <unistd.h>

/* One thread-rank's run. */
typedef struct {
    port port;
    const char *path;
    int64_t walks;
    double *x;
    int status;
    ulam_dist_result res;
    int64_t rows;
    double seconds;
} job;

/* Open the rank's rows and run forward walks into job->x. */
static void *rank_main(void *arg)
{
    job *j = arg;
    ulam_comm c = hub_comm(&j->port);
    ulam_part *p = NULL;
    double t0 = ulam_now();
    j->status = ulam_part_open(j->path, &c, ULAM_PART_MT, &p, NULL);
    if (j->status) return NULL; /* (a failure on one rank would stall the others: the bench's files are sound) */
    int64_t first, last;
    ulam_part_rows(p, &first, &last, NULL);
    j->rows = last - first;
    ulam_dist_opts o = ulam_dist_defaults();
    o.walks = j->walks, o.batch = 16384;
    j->status = ulam_dist_forward(p, &c, &o, j->x + first, NULL, &j->res, NULL);
    j->seconds = ulam_now() - t0;
    ulam_part_free(p);
    return NULL;
}

/* Write M and b as a prepared file with M' at path. */
static int prepare(const char *path, ulam_csr *M, double *b)
{
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = M, d.b = b, d.n = M->nrows, d.transpose = 1;
    return ulam_system_write(path, &d);
}

/* Run every rank count on the file at path and print a row each. */
static void sweep(const char *name, const char *path, int64_t n, int64_t walks)
{
    static const int ks[] = {1, 2, 3, 4, 8, 16, 32, 64};
    double *ref = malloc((size_t)n * sizeof *ref), *x = malloc((size_t)n * sizeof *x), t1 = 0;
    printf("\n%s (n %lld, %lld forward walks)\n", name, (long long)n, (long long)walks);
    printf("%6s %10s %10s %8s %10s %10s %9s\n", "ranks", "crossing", "bytes/step", "rounds", "max rows", "identical",
           "seconds");
    for (size_t q = 0; q < sizeof ks / sizeof *ks; q++) {
        int k = ks[q];
        hub h;
        hub_init(&h, k);
        job jobs[HUB_MAX];
        pthread_t t[HUB_MAX];
        for (int r = 0; r < k; r++) {
            jobs[r] = (job){.port = {&h, r}, .path = path, .walks = walks, .x = q ? x : ref};
            pthread_create(&t[r], NULL, rank_main, &jobs[r]);
        }
        int64_t maxrows = 0, bad = 0;
        for (int r = 0; r < k; r++) {
            pthread_join(t[r], NULL);
            bad |= jobs[r].status != ULAM_OK;
            if (jobs[r].rows > maxrows) maxrows = jobs[r].rows;
        }
        pthread_barrier_destroy(&h.bar);
        const ulam_dist_result *res = &jobs[0].res;
        if (q == 0) t1 = jobs[0].seconds;
        int same = !bad && (q == 0 || !memcmp(x, ref, (size_t)n * sizeof *x));
        printf("%6d %10.4f %10.2f %8lld %10lld %10s %9.3f\n", k, res->steps ? (double)res->crossings / (double)res->steps : 0.0,
               res->steps ? (double)res->bytes / (double)res->steps : 0.0, (long long)res->rounds, (long long)maxrows,
               bad ? "FAILED" : same ? "yes" : "NO", jobs[0].seconds);
        if (k == 64 && res->steps) { /* the projection (docs/distributed.md) */
            double share = (double)res->crossings / (double)res->steps, ts = t1 / (double)res->steps;
            const double alpha = 5e-6, beta = 5e9; /* assumed: 5 us a collective round, 5 GB/s a rank */
            double comp = ts * (double)res->steps / 64, comm = (double)res->rounds * alpha * 6 /* log2 64 */ +
                                                            share * 40.0 * (double)res->steps / 64 / beta;
            printf("projected at 64 ranks: %.3g s compute + %.3g s exchange (1 rank: %.3g s; step %.3g us, crossing %.3f)\n",
                   comp, comm, t1, ts * 1e6, share);
        }
    }
    free(ref), free(x);
}

int main(int argc, char **argv)
{
    int64_t walks = argc > 1 ? atoll(argv[1]) : 50000;
    char dir[] = "/tmp/ulam_bench_dist_XXXXXX";
    if (!mkdtemp(dir)) return 1;
    char path[256];
    printf("bench_dist: partitioned forward walks, ranks as threads (%ld cores online)\n", sysconf(_SC_NPROCESSORS_ONLN));
    int64_t dangling, maxin, maxout;
    struct {
        const char *name;
        ulam_csr *M;
    } sys[] = {{"screened diffusion 300x300", bench_screened_csr(300)},
               {"R-MAT 2^16 PageRank 0.85", bench_rmat(16, 0.85, &dangling, &maxin, &maxout)},
               {"random 8 a row, 2^16", bench_canonical(bench_random_csr((int64_t)1 << 16))}};
    for (size_t s = 0; s < sizeof sys / sizeof *sys; s++) {
        ulam_csr *M = sys[s].M;
        double *b = bench_random_rhs(M->nrows);
        snprintf(path, sizeof path, "%s/s%zu.ulam", dir, s);
        if (!M || !b || prepare(path, M, b)) return 1;
        sweep(sys[s].name, path, M->nrows, walks);
        unlink(path);
        ulam_csr_free(M), free(b);
    }
    rmdir(dir);
    return 0;
}
