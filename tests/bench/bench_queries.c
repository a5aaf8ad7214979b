/* Many point-source queries in one process (issue 29, point 2): `ulam solve SYSTEM --queries FILE`
 * from a prepared file of the R-MAT graph of bench_bidir (2^L states, M = 0.85 P'), against the
 * in-process figure of bench_bidir (ulam_analysis_bidir on one analysis of M, whose push workspace
 * and plan memo the queries share, with reach_all and keep_kernel, the transpose and guards made
 * before the clock), on the same pairs (bench_bidir's
 * draw: SOURCES random sources reaching at least TARGETS states of x_t >= 1/n, TARGETS of those),
 * the same seeds (pair k: seed k; the queries' --seed 1 gives query k seed k) and the same rule
 * (--rel-err 0.1, one thread, no step cap).  Per-query seconds: the CLI's JSON "seconds" (each
 * query's wall time, the first paying the transpose, guards and push workspace) against the
 * in-process ones; median and 90th percentile and the whole process.  Target: CLI per-query
 * median <= 1.5x the in-process median.  Usage: bench_queries path/to/ulam [L [SOURCES]]
 * (default 20 and 20: 100 pairs). */
#include "exact.h"

enum { SOURCES = 20, TARGETS = 5, PAIRS = SOURCES * TARGETS };
static const double REL = 0.1, ALPHA = 0.85;

/* qsort order of doubles. */
static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile (nearest rank) of v[0..n) (v is sorted). */
static double quantile(double *v, int n, double q)
{
    qsort(v, (size_t)n, sizeof *v, cmp);
    int k = (int)ceil(q * n) - 1;
    return v[k < 0 ? 0 : k];
}

int main(int argc, char **argv)
{
    int L = argc > 2 ? atoi(argv[2]) : 20, nsrc = argc > 3 ? atoi(argv[3]) : SOURCES, np = nsrc * TARGETS;
    if (argc < 2 || L < 8 || L > 24 || nsrc < 1 || nsrc > SOURCES) {
        fprintf(stderr, "usage: bench_queries path/to/ulam [L [SOURCES]], 8 <= L <= 24, 1 <= SOURCES <= %d\n", SOURCES);
        return 2;
    }
    int64_t dangling, maxin, maxout, n = (int64_t)1 << L;
    ulam_csr *M = bench_rmat(L, ALPHA, &dangling, &maxin, &maxout);
    double *x = malloc((size_t)n * sizeof *x), *old = malloc((size_t)n * sizeof *old), *b = malloc((size_t)n * sizeof *b);
    int64_t *cand = malloc((size_t)n * sizeof *cand), ps[PAIRS], pt[PAIRS];
    if (!M || !x || !old || !b || !cand) return fprintf(stderr, "queries: out of memory\n"), 1;
    ulam_rng r; /* bench_bidir's pairs */
    ulam_rng_seed(&r, (uint64_t)L, 1);
    for (int src = 0, k = 0; src < nsrc;) {
        int64_t s = (int64_t)ulam_rng_bounded(&r, (uint64_t)n), nc = 0;
        bench_exact_column(M, s, x, old, b);
        for (int64_t i = 0; i < n; i++)
            if (i != s && x[i] >= 1.0 / (double)n) cand[nc++] = i;
        if (nc < TARGETS) continue;
        for (int q = 0; q < TARGETS; q++, k++) {
            int64_t j = q + (int64_t)ulam_rng_bounded(&r, (uint64_t)(nc - q));
            int64_t t = cand[j];
            cand[j] = cand[q], cand[q] = t;
            ps[k] = s, pt[k] = t;
        }
        src++;
    }
    /* in process, as bench_bidir: one analysis of M (its transpose, push workspace and plan memo) */
    ulam_analysis *an = NULL;
    const ulam_csr *Mt = NULL;
    ulam_guard g;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(ULAM_ADJOINT);
    if (ulam_analysis_alloc(M, NULL, &an, NULL) || !(Mt = ulam_analysis_transpose(an, NULL)) ||
        ulam_guard_check(Mt, 0.0, &go, &g, NULL))
        return fprintf(stderr, "queries: set-up failed\n"), 1;
    double inproc[PAIRS], cli[PAIRS], est[PAIRS];
    for (int k = 0; k < np; k++) {
        ulam_bidir_opts o = ulam_bidir_defaults();
        o.walk.policy.guard = &g, o.reach_all = 1, o.keep_kernel = 1, o.source = ps[k], o.target = pt[k];
        o.walk.stop.max_walks = 0, o.walk.stop.rel_err = REL, o.walk.exec.threads = 1, o.walk.exec.seed = (uint64_t)k + 1;
        o.walk.stop.max_steps = INT64_MAX / 4;
        ulam_bidir_result res;
        if (ulam_analysis_bidir(an, &o, &res, NULL)) return fprintf(stderr, "queries: pair %d failed\n", k + 1), 1;
        inproc[k] = res.seconds, est[k] = res.estimate;
    }
    ulam_analysis_free(an);
    /* the CLI: a prepared file (certificate and stored bounds) and one process for every pair */
    char dir[] = "/tmp/ulam_bench_queriesXXXXXX", sysf[128], qf[128];
    if (!mkdtemp(dir)) return 1;
    snprintf(sysf, sizeof sysf, "%s/rmat.ulam", dir), snprintf(qf, sizeof qf, "%s/pairs.txt", dir);
    ulam_certificate cert;
    if (ulam_certificate_compute(M, 0.0, NULL, &cert, NULL)) return fprintf(stderr, "queries: certificate failed\n"), 1;
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = M, d.n = n, d.cert = &cert;
    FILE *f = fopen(qf, "w");
    if (ulam_system_write(sysf, &d) || !f) return fprintf(stderr, "queries: files not written\n"), 1;
    for (int k = 0; k < np; k++) fprintf(f, "%lld %lld\n", (long long)ps[k] + 1, (long long)pt[k] + 1);
    fclose(f);
    ulam_csr_free(M);
    char *args[] = {argv[1], "solve", sysf, "--queries", qf, "--rel-err", "0.1", "--threads", "1", "--seed", "1",
                    "--max-steps", "1000000000000", "--json", NULL};
    size_t cap = (size_t)np * 1024 + 4096;
    char *out = malloc(cap);
    double whole = NAN, cpu = NAN, rss = NAN;
    int rc = out ? bench_run(args, out, cap, 0, &whole, &cpu, &rss) : 1;
    int got = 0;
    int same = 0;
    for (char *line = out; !rc && line && *line && got < np; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL) {
        same += bench_json_number(line, "estimate") == est[got];
        cli[got++] = bench_json_number(line, "seconds");
    }
    if (rc || got != np) return fprintf(stderr, "queries: the CLI run failed (exit %d, %d answers)\n", rc, got), 1;
    double first = cli[0], sum = 0;
    for (int k = 0; k < np; k++) sum += cli[k];
    double im = quantile(inproc, np, 0.5), i9 = quantile(inproc, np, 0.9);
    double cm = quantile(cli, np, 0.5), c9 = quantile(cli, np, 0.9);
    printf("R-MAT 2^%d, %d point-source pairs at --rel-err %.2g, one thread; seconds per query\n", L, np, REL);
    printf("%-34s %10s %10s\n", "", "median", "p90");
    printf("%-34s %10.4f %10.4f\n", "in process (bench_bidir's figure)", im, i9);
    printf("%-34s %10.4f %10.4f\n", "ulam solve --queries (one process)", cm, c9);
    printf("%-34s %9.2fx %9.2fx   (target: median <= 1.5x)\n", "ratio", cm / im, c9 / i9);
    printf("CLI process: %.2f s wall, %.2f s CPU, peak %.0f MiB; its first query %.3f s (transpose, guards, push "
           "workspace), the queries %.2f s in all; %d of %d estimates the in-process ones to the printed digits\n", whole,
           cpu, rss, first, sum, same, np);
    free(out), free(x), free(old), free(b), free(cand);
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) ? 1 : 0;
}
