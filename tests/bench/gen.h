/* Shared by the benchmark programs: reproducible test systems and memory readings. */
#ifndef ULAM_BENCH_GEN_H
#define ULAM_BENCH_GEN_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ulam.h"

/* The reference solve by the library's Gauss-Seidel iteration (ulam_outer_*, ULAM_GAUSS_SEIDEL:
 * sweeps on x = M x + b from x = 0, each also computing its residual) into x (n entries), until
 * the sweep moves x by at most tol -- index < 0: every entry, by at most tol absolutely (old: n
 * entries of scratch); else x_index, by at most tol |x_index| (old unused) -- or max_sweeps;
 * the sweeps made, -1 when the iteration could not start (b = 0, no memory). */
static inline int bench_gauss_seidel(const ulam_csr *M, const double *b, int64_t index, double tol, int max_sweeps,
                                     double *x, double *old)
{
    ulam_outer_opts o = ulam_outer_defaults();
    o.method = ULAM_GAUSS_SEIDEL, o.tol = 1e-300, o.max_iter = max_sweeps; /* stopped here, not by the residual */
    ulam_outer *s = NULL;
    ulam_outer_info info;
    if (ulam_outer_alloc(M, b, &o, &s, NULL)) return -1;
    ulam_outer_get_info(s, &info);
    int64_t n = M->nrows;
    int sweeps = 0;
    for (int settled = 0; !settled && sweeps < max_sweeps && !ulam_outer_done(s); sweeps++) {
        double was = info.x[index < 0 ? 0 : index], change = 0;
        if (index < 0) memcpy(old, info.x, (size_t)n * sizeof *old);
        ulam_outer_iterate(s, NULL);
        if (index >= 0) {
            settled = fabs(info.x[index] - was) <= tol * fabs(info.x[index]);
            continue;
        }
        for (int64_t i = 0; i < n; i++) change = fmax(change, fabs(info.x[i] - old[i]));
        settled = change <= tol;
    }
    memcpy(x, info.x, (size_t)n * sizeof *x);
    ulam_outer_free(s);
    return sweeps;
}

/* Radiosity-like M: n x n, 8 nonzeros a row at columns drawn uniformly (stream (n, 0)),
 * values 0.1 + U(0, 1) scaled so every row sums to 0.9, so rho(|M|) = rho(M) = 0.9 exactly
 * (the Perron root of a matrix with constant row sums). */
static inline ulam_csr *bench_random_csr(int64_t n)
{
    const int k = 8;
    ulam_csr *M = ulam_csr_alloc(n, n, n * k);
    if (!M) return NULL;
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)n, 0);
    for (int64_t i = 0; i < n; i++) {
        M->rowptr[i + 1] = (i + 1) * k;
        double sum = 0;
        for (int q = 0; q < k; q++) {
            M->colidx[i * k + q] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n);
            sum += M->val[i * k + q] = 0.1 + ulam_rng_uniform(&r);
        }
        for (int q = 0; q < k; q++) M->val[i * k + q] *= 0.9 / sum;
    }
    return M; /* a column drawn twice in a row is harmless for walking and solving */
}

/* Screened diffusion on an L x L grid (n = L^2): one implicit step of diffusion with
 * absorption, M_ii = 0.1 and 0.2 to each of the 4 neighbours (5 nonzeros a row inside, fewer
 * on the edge), so rows sum to at most 0.9 and M is symmetric: (I - M) is positive definite
 * (CG applies), and a walk stays near its start. */
static inline ulam_csr *bench_screened_csr(int64_t L)
{
    int64_t n = L * L, nz = 0;
    ulam_csr *M = ulam_csr_alloc(n, n, 5 * n);
    if (!M) return NULL;
    for (int64_t i = 0; i < L; i++)
        for (int64_t j = 0; j < L; j++) {
            const int64_t at[5][2] = {{i - 1, j}, {i, j - 1}, {i, j}, {i, j + 1}, {i + 1, j}}; /* column order */
            for (int k = 0; k < 5; k++) {
                if (at[k][0] < 0 || at[k][0] >= L || at[k][1] < 0 || at[k][1] >= L) continue;
                M->colidx[nz] = (int32_t)(at[k][0] * L + at[k][1]);
                M->val[nz++] = k == 2 ? 0.1 : 0.2;
            }
            M->rowptr[i * L + j + 1] = nz;
        }
    return M;
}

/* b_i = 0.5 + U(0, 1) from stream (n, 1). */
static inline double *bench_random_rhs(int64_t n)
{
    double *b = malloc((size_t)n * sizeof *b);
    if (!b) return NULL;
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)n, 1);
    for (int64_t i = 0; i < n; i++) b[i] = 0.5 + ulam_rng_uniform(&r);
    return b;
}

/* M with each row's columns sorted and repeated ones summed (the form a parse gives and
 * ulam_csr_check wants), in place of M (freed); NULL when out of memory. */
static inline ulam_csr *bench_canonical(ulam_csr *M)
{
    int64_t nz = M->rowptr[M->nrows];
    int32_t *ti = malloc((size_t)nz * sizeof *ti);
    ulam_csr *C = NULL;
    if (ti) {
        for (int64_t i = 0; i < M->nrows; i++)
            for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) ti[q] = (int32_t)i;
        if (ulam_csr_from_triplets(M->nrows, M->ncols, nz, ti, M->colidx, M->val, &C)) C = NULL;
    }
    free(ti);
    ulam_csr_free(M);
    return C;
}

/* Resident set size of this process now, in bytes (/proc/self/statm); 0 if unreadable. */
static inline double bench_rss(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2) res = 0;
        fclose(f);
    }
    return (double)res * (double)sysconf(_SC_PAGESIZE);
}

/* Peak resident set size of this process so far, in bytes (VmHWM); 0 if unreadable. */
static inline double bench_peak_rss(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) kb = atof(line + 6);
    if (f) fclose(f);
    return kb * 1024.0;
}

/* Bytes of a CSR matrix's three arrays. */
static inline double bench_csr_bytes(const ulam_csr *M)
{
    return (double)(M->nrows + 1) * 8.0 + (double)M->rowptr[M->nrows] * 12.0;
}

/* The number after "key": in a JSON text, or NAN. */
static inline double bench_json_number(const char *text, const char *key)
{
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *p = strstr(text, pat);
    return p ? atof(p + strlen(pat)) : NAN;
}

/* Run argv with stdout captured into out (stderr to /dev/null when quiet); wall seconds into
 * *wall, its CPU seconds (user + system) into *cpu, its peak RSS in MiB into *rss (which counts
 * what this process had resident when it forked: free big arrays first).  The exit status, or -1. */
static inline int bench_run(char *const argv[], char *out, size_t cap, int quiet, double *wall, double *cpu,
                            double *rss)
{
    int fd[2];
    if (pipe(fd)) return -1;
    double t0 = ulam_now();
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fd[1], 1);
        if (quiet && !freopen("/dev/null", "w", stderr)) _exit(126);
        close(fd[0]), close(fd[1]);
        execv(argv[0], argv);
        _exit(127);
    }
    close(fd[1]);
    size_t len = 0;
    ssize_t got;
    while (len + 1 < cap && (got = read(fd[0], out + len, cap - 1 - len)) > 0) len += (size_t)got;
    out[len] = '\0';
    close(fd[0]);
    int status = 0;
    struct rusage ru;
    wait4(pid, &status, 0, &ru);
    *wall = ulam_now() - t0;
    *cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
           1e-6 * (double)ru.ru_stime.tv_usec;
    *rss = (double)ru.ru_maxrss / 1024.0;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* A uniform random permutation of 0 .. n-1 into perm from r (Fisher-Yates). */
static inline void bench_permutation(int32_t *perm, int64_t n, ulam_rng *r)
{
    for (int64_t i = 0; i < n; i++) perm[i] = (int32_t)i;
    for (int64_t i = n - 1; i > 0; i--) {
        int64_t j = (int64_t)ulam_rng_bounded(r, (uint64_t)i + 1);
        int32_t t = perm[i];
        perm[i] = perm[j], perm[j] = t;
    }
}

/* One R-MAT edge (a = 0.57, b = c = 0.19, d = 0.05) of a 2^L-node graph from r: tail *u, head *v
 * (before any relabelling). */
static inline void bench_rmat_edge(ulam_rng *r, int L, int64_t *u, int64_t *v)
{
    *u = *v = 0;
    for (int l = 0; l < L; l++) {
        double q = ulam_rng_uniform(r);
        int down = q >= 0.57 + 0.19, right = (q >= 0.57 && q < 0.76) || q >= 0.95;
        *u = 2 * *u + down, *v = 2 * *v + right;
    }
}

/* The R-MAT graph (Chakrabarti, Zhan, Faloutsos 2004; a = 0.57, b = c = 0.19, d = 0.05; states
 * relabelled by a random permutation; stream (L, 0)) as M = alpha P' (n = 2^L, 8 n edges, P the
 * random-walk matrix of the out-edges); *dangling counts states without out-edges (bench_bidir,
 * bench_queries). */
static inline ulam_csr *bench_rmat(int L, double alpha, int64_t *dangling, int64_t *maxin, int64_t *maxout)
{
    int64_t n = (int64_t)1 << L, m = 8 * n;
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)L, 0);
    int32_t *perm = malloc((size_t)n * sizeof *perm), *src = malloc((size_t)m * sizeof *src);
    int32_t *dst = malloc((size_t)m * sizeof *dst);
    int64_t *outdeg = calloc((size_t)n, sizeof *outdeg), *indeg = calloc((size_t)n, sizeof *indeg);
    double *val = malloc((size_t)m * sizeof *val);
    ulam_csr *M = NULL;
    if (!perm || !src || !dst || !outdeg || !indeg || !val) goto done;
    bench_permutation(perm, n, &r);
    for (int64_t e = 0; e < m; e++) {
        int64_t u, v;
        bench_rmat_edge(&r, L, &u, &v);
        src[e] = perm[u], dst[e] = perm[v];
        outdeg[perm[u]]++, indeg[perm[v]]++;
    }
    *dangling = *maxin = *maxout = 0;
    for (int64_t i = 0; i < n; i++) {
        *dangling += outdeg[i] == 0;
        if (indeg[i] > *maxin) *maxin = indeg[i];
        if (outdeg[i] > *maxout) *maxout = outdeg[i];
    }
    for (int64_t e = 0; e < m; e++) val[e] = alpha / (double)outdeg[src[e]];
    /* M_vu = alpha P_uv: row v of M holds v's in-neighbours u */
    if (ulam_csr_from_triplets(n, n, m, dst, src, val, &M)) M = NULL;
done:
    free(perm), free(src), free(dst), free(outdeg), free(indeg), free(val);
    return M;
}

/* The metastable chain of issue 25 (tests/test_stop.c): 40 states; cluster A (states 0..19,
 * b = 1) has rows of M summing to exactly 0.95, state 0 leaking `leak` into cluster B (states
 * 20..39, b = 10, rows summing to 0.9995).  M and b (40 entries, malloc'd); nonzero when out of
 * memory. */
static inline int bench_metastable(double leak, ulam_csr **M, double **b)
{
    int32_t ti[200], tj[200];
    double tx[200];
    int nz = 0;
    static const int hop[4] = {1, 3, 7, 12};
    for (int c = 0; c < 2; c++)
        for (int i = 0; i < 20; i++) {
            double sum = c ? 0.9995 : 0.95 - (i == 0 ? leak : 0.0);
            for (int h = 0; h < 4; h++) ti[nz] = 20 * c + i, tj[nz] = 20 * c + (i + hop[h]) % 20, tx[nz++] = sum / 4;
        }
    ti[nz] = 0, tj[nz] = 20, tx[nz++] = leak;
    *b = malloc(40 * sizeof **b);
    if (!*b || ulam_csr_from_triplets(40, 40, nz, ti, tj, tx, M)) return free(*b), *b = NULL, -1;
    for (int i = 0; i < 40; i++) (*b)[i] = i < 20 ? 1.0 : 10.0;
    return 0;
}

/* Issue 25's cost case 6: a power-law system with one large, nearly unreachable entry of b.
 * n states; row i of M has 1 + Zipf(2.1) entries (at most 1000) at uniform columns, signs
 * random, |M| rows summing to 0.5; the column of state n - 1 is emptied but for one entry eps
 * at a random row k, so walks from state 0 reach n - 1 with (adjoint) weight
 * ((I - M)^-1)_{0k} eps; b = +-0.1 at random, b_{n-1} = big.  Stream (seed, 25).  Nonzero when
 * out of memory. */
static inline int bench_case6(int64_t n, double eps, double big, uint64_t seed, ulam_csr **M, double **b)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 25);
    double cum[1000];
    for (int k = 0; k < 1000; k++) cum[k] = (k ? cum[k - 1] : 0) + pow(k + 1.0, -2.1);
    int64_t cap = 0, nz = 0;
    int *d = malloc((size_t)n * sizeof *d);
    if (!d) return -1;
    for (int64_t i = 0; i < n; i++) {
        double u = ulam_rng_uniform(&r) * cum[999];
        int k = 0;
        while (cum[k] <= u && k < 999) k++;
        cap += d[i] = 1 + (k + 1 < 999 ? k + 1 : 999);
    }
    int32_t *ti = malloc((size_t)(cap + 1) * sizeof *ti), *tj = malloc((size_t)(cap + 1) * sizeof *tj);
    double *tx = malloc((size_t)(cap + 1) * sizeof *tx);
    *b = malloc((size_t)n * sizeof **b);
    int status = -1;
    if (ti && tj && tx && *b) {
        for (int64_t i = 0; i < n; i++) {
            int64_t at = nz;
            double sum = 0;
            for (int q = 0; q < d[i]; q++) {
                int32_t j = (int32_t)ulam_rng_bounded(&r, (uint64_t)(n - 1)); /* never n - 1 */
                double v = 0.2 + ulam_rng_uniform(&r);
                ti[nz] = (int32_t)i, tj[nz] = j, tx[nz++] = ulam_rng_uniform(&r) < 0.5 ? -v : v, sum += v;
            }
            for (int64_t e = at; e < nz; e++) tx[e] *= 0.5 / sum;
            (*b)[i] = ulam_rng_uniform(&r) < 0.5 ? -0.1 : 0.1;
        }
        ti[nz] = (int32_t)ulam_rng_bounded(&r, (uint64_t)(n - 1)), tj[nz] = (int32_t)(n - 1), tx[nz++] = eps;
        (*b)[n - 1] = big;
        status = ulam_csr_from_triplets(n, n, nz, ti, tj, tx, M) ? -1 : 0; /* repeated entries summed */
    }
    free(d), free(ti), free(tj), free(tx);
    if (status) free(*b), *b = NULL;
    return status;
}

/* Upwind convection-diffusion on an L x L grid (Dirichlet), h^2 times: 4 + 2 c on the diagonal,
 * -1 - c to the west and south neighbours (upwind for a flow towards north-east at c = v h), -1 to
 * the east and north; the A that --jacobi splits.  NULL when out of memory. */
static inline ulam_csr *bench_convdiff(int64_t L, double c)
{
    int64_t n = L * L, nz = 0;
    int32_t *ti = malloc((size_t)(5 * n) * sizeof *ti), *tj = malloc((size_t)(5 * n) * sizeof *tj);
    double *tx = malloc((size_t)(5 * n) * sizeof *tx);
    ulam_csr *A = NULL;
    if (ti && tj && tx) {
        for (int64_t i = 0; i < L; i++)
            for (int64_t j = 0; j < L; j++) {
                int32_t row = (int32_t)(i * L + j);
                const int64_t at[4][2] = {{i - 1, j}, {i, j - 1}, {i + 1, j}, {i, j + 1}};
                ti[nz] = row, tj[nz] = row, tx[nz++] = 4.0 + 2.0 * c;
                for (int k = 0; k < 4; k++) {
                    if (at[k][0] < 0 || at[k][0] >= L || at[k][1] < 0 || at[k][1] >= L) continue;
                    ti[nz] = row, tj[nz] = (int32_t)(at[k][0] * L + at[k][1]), tx[nz++] = k < 2 ? -1.0 - c : -1.0;
                }
            }
        if (ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A)) A = NULL;
    }
    free(ti), free(tj), free(tx);
    return A;
}

/* Issue 38 point 8's systems.  signed: n states, row i of M has 8 entries at uniform columns,
 * magnitudes 0.1 + U(0, 1) with random signs, rows of |M| scaled to sum to 0.8; b = U(-0.5, 1).
 * Stream (seed, 38).  Nonzero when out of memory. */
static inline int bench_signed(int64_t n, uint64_t seed, ulam_csr **M, double **b)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 38);
    int64_t nz = 8 * n;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    *b = malloc((size_t)n * sizeof **b);
    int bad = !ti || !tj || !tx || !*b;
    for (int64_t i = 0; !bad && i < n; i++) {
        double sum = 0;
        for (int k = 0; k < 8; k++) {
            int64_t e = 8 * i + k;
            ti[e] = (int32_t)i, tj[e] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n);
            tx[e] = (0.1 + ulam_rng_uniform(&r)) * (ulam_rng_uniform(&r) < 0.5 ? -1.0 : 1.0), sum += fabs(tx[e]);
        }
        for (int k = 0; k < 8; k++) tx[8 * i + k] *= 0.8 / sum;
        (*b)[i] = 1.5 * ulam_rng_uniform(&r) - 0.5;
    }
    bad = bad || ulam_csr_from_triplets(n, n, nz, ti, tj, tx, M);
    free(ti), free(tj), free(tx);
    if (bad) free(*b), *b = NULL;
    return bad ? -1 : 0;
}

/* A hub of damping alpha: state 0 moves to each of states 1 .. n-1 with probability alpha / (n - 1);
 * state i >= 1 to the hub and to state i + 1 (wrapping to 1) with alpha / 2 each (M = alpha P,
 * P a random walk's transition matrix: walks last 1 / (1 - alpha) steps); b = U(0, 1), stream
 * (seed, 39).  The unknown: the hub.  Nonzero when out of memory. */
static inline int bench_hub(int64_t n, double alpha, uint64_t seed, ulam_csr **M, double **b)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 39);
    int64_t nz = 3 * n;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    *b = malloc((size_t)n * sizeof **b);
    int bad = !ti || !tj || !tx || !*b;
    nz = 0;
    for (int64_t i = 0; !bad && i < n; i++) {
        (*b)[i] = ulam_rng_uniform(&r);
        if (i == 0)
            for (int64_t j = 1; j < n; j++) ti[nz] = 0, tj[nz] = (int32_t)j, tx[nz++] = alpha / (double)(n - 1);
        else {
            ti[nz] = (int32_t)i, tj[nz] = 0, tx[nz++] = alpha / 2;
            ti[nz] = (int32_t)i, tj[nz] = (int32_t)(i + 1 < n ? i + 1 : 1), tx[nz++] = alpha / 2;
        }
    }
    bad = bad || ulam_csr_from_triplets(n, n, nz, ti, tj, tx, M);
    free(ti), free(tj), free(tx);
    if (bad) free(*b), *b = NULL;
    return bad ? -1 : 0;
}

/* Issue 38's three clusters (tests/cli_test.py's three_clusters at leak 1e-4): 60 states, three
 * clusters of 20 with rows of |M| summing to 0.99; cluster c's first state (its hub) moves to
 * states +1, +3, +7, +12 of its cluster with a quarter each, every other state half to the hub
 * and a sixth to each of +1, +3, +7; the hubs of the first two clusters move `leak` (taken
 * from their own rows) to the next cluster's hub.  b = 1 on the last cluster, 0 elsewhere: x_0
 * is reached only through both leaks.  Nonzero when out of memory. */
static inline int bench_clusters(double leak, ulam_csr **M, double **b)
{
    int32_t ti[242], tj[242];
    double tx[242];
    int nz = 0;
    static const int hop[4] = {1, 3, 7, 12};
    for (int c = 0; c < 3; c++) {
        int32_t hub = 20 * c;
        for (int32_t i = 0; i < 20; i++) {
            double rs = 0.99 - (i == 0 && c < 2 ? leak : 0.0);
            if (i == 0)
                for (int h = 0; h < 4; h++) ti[nz] = hub, tj[nz] = hub + hop[h], tx[nz++] = rs / 4;
            else {
                ti[nz] = hub + i, tj[nz] = hub, tx[nz++] = rs / 2;
                for (int h = 0; h < 3; h++) ti[nz] = hub + i, tj[nz] = hub + (i + hop[h]) % 20, tx[nz++] = rs / 6;
            }
        }
        if (c < 2) ti[nz] = hub, tj[nz] = hub + 20, tx[nz++] = leak;
    }
    *b = malloc(60 * sizeof **b);
    if (!*b || ulam_csr_from_triplets(60, 60, nz, ti, tj, tx, M)) return free(*b), *b = NULL, -1;
    for (int i = 0; i < 60; i++) (*b)[i] = i < 40 ? 0.0 : 1.0;
    return 0;
}

/* Upwind convection-diffusion on an L x L grid with cell Peclet numbers cx (along j) and cy
 * (along i): h^2 times, 4 + cx + cy on the diagonal, -1 - cx and -1 - cy to the upstream
 * neighbours, -1 downstream; by its Jacobi splitting, b = 30 entries U(0, 1) at random states
 * plus 1 at the last (stream (seed, 40)).  Nonzero when out of memory. */
static inline int bench_convdiff_b(int64_t L, double cx, double cy, uint64_t seed, ulam_csr **M, double **b)
{
    int64_t n = L * L, nz = 0;
    int32_t *ti = malloc((size_t)(5 * n) * sizeof *ti), *tj = malloc((size_t)(5 * n) * sizeof *tj);
    double *tx = malloc((size_t)(5 * n) * sizeof *tx), *rhs = calloc((size_t)n, sizeof *rhs);
    *b = malloc((size_t)n * sizeof **b);
    ulam_csr *A = NULL;
    int bad = !ti || !tj || !tx || !rhs || !*b;
    for (int64_t i = 0; !bad && i < L; i++)
        for (int64_t j = 0; j < L; j++) {
            int32_t row = (int32_t)(i * L + j);
            const int64_t at[4][2] = {{i - 1, j}, {i, j - 1}, {i + 1, j}, {i, j + 1}};
            const double up[4] = {cy, cx, 0, 0};
            ti[nz] = row, tj[nz] = row, tx[nz++] = 4.0 + cx + cy;
            for (int k = 0; k < 4; k++) {
                if (at[k][0] < 0 || at[k][0] >= L || at[k][1] < 0 || at[k][1] >= L) continue;
                ti[nz] = row, tj[nz] = (int32_t)(at[k][0] * L + at[k][1]), tx[nz++] = -1.0 - up[k];
            }
        }
    ulam_rng r;
    ulam_rng_seed(&r, seed, 40);
    for (int k = 0; !bad && k < 30; k++) rhs[ulam_rng_bounded(&r, (uint64_t)n)] = ulam_rng_uniform(&r);
    if (!bad) rhs[n - 1] = 1.0;
    bad = bad || ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A) || ulam_jacobi(A, rhs, 1.0, M, *b, NULL);
    ulam_csr_free(A), free(ti), free(tj), free(tx), free(rhs);
    if (bad) free(*b), *b = NULL;
    return bad ? -1 : 0;
}

/* x = (I - M)^-1 b by x <- b + M x to a change below 1e-15 ||x||_1 or 10^5 products; a new array
 * (NULL when out of memory). */
static inline double *bench_neumann(const ulam_csr *M, const double *b)
{
    int64_t n = M->nrows;
    double *x = calloc((size_t)n, sizeof *x), *y = malloc((size_t)n * sizeof *y);
    for (int it = 0; x && y && it < 100000; it++) {
        ulam_csr_matvec(M, 0, x, y);
        double dif = 0, tot = 0;
        for (int64_t i = 0; i < n; i++) y[i] += b[i], dif += fabs(y[i] - x[i]), tot += fabs(y[i]), x[i] = y[i];
        if (dif <= 1e-15 * tot) break;
    }
    if (!y) free(x), x = NULL;
    free(y);
    return x;
}

#endif
