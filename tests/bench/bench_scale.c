/* Scale (issue 8): the time to get ONE component of (I - M) x = b to 1% relative error, by
 *   walks      adjoint collision walks (2 threads), stopped when the reported standard error
 *              is 1% of the estimate, as a user's one query runs them: solver set-up and the
 *              walks, which build the kernel rows they reach ("rows" of them);
 *   prebuilt   the same walks with the kernel built whole first, walk time only (the cost of
 *              a query once the rows are built; the whole build is timed apart, "build");
 *   dgesv      dense LAPACK (OpenBLAS, 2 threads) while the matrix fits in 2 GB;
 *   umfpack    UMFPACK (SuiteSparse) LU of I - M, symbolic + numeric + solve, in a child
 *              process limited to 16 GB of address space and 600 s;
 *   gs         Gauss-Seidel on the whole vector from x = 0, stopped when x_I is within 1% of
 *              the reference (capped at 300 s; past the cap the time is projected from the
 *              observed geometric decay of the error);
 * on two families at n = 10^3 .. 10^7:
 *   random     radiosity-like nonnegative M, 8 nonzeros a row at uniform columns, row sums
 *              0.9 (rho(|M|) = 0.9 exactly), b = 0.5 + U(0, 1);
 *   poisson    the 9-point 2-D Poisson matrix (20 on the diagonal, -4 to the edge and -1 to
 *              the corner neighbours, Dirichlet boundary, 8 off-diagonal nonzeros a row) on a
 *              sqrt(n) x sqrt(n) grid through Jacobi (ulam_jacobi), f = 1; rho(M) -> 1 as n grows.
 * The component is the middle one.  The reference is dgesv, else UMFPACK, else Gauss-Seidel
 * converged to 1e-13.  Writes docs/scale.csv and docs/scale.png (run from the source root). */
#include <math.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include "gen.h"
#include "../../src/internal.h" /* ulam__gauss_seidel_sweep: the Gauss-Seidel peer, timed sweep by sweep (the public ulam_outer_* iteration adds a residual product to each) */
#include "gnuplot.h"

#ifdef HAVE_UMFPACK
#include <suitesparse/umfpack.h>
#endif

enum { RANDOM, POISSON, NFAM };
enum { WALK, BUILT, DGESV, UMF, GS, NMETH };
static const char *const fam_names[NFAM] = {"random", "poisson"};
static const char *const meth_names[NMETH] = {"walks", "prebuilt", "dgesv", "umfpack", "gs"};
static const double GS_CAP = 300.0, WALK_CAP = 300.0;

typedef struct {
    double seconds;  /* to 1% on x_I; < 0: not run */
    int projected;   /* seconds is a projection past a cap */
    char note[96];   /* why not run, or what was reached */
} outcome;

/* The 9-point Poisson system on an L x L grid through Jacobi: M and b. */
static ulam_csr *poisson(int64_t L, double **bp)
{
    int64_t n = L * L, nz = 0;
    ulam_csr *A = ulam_csr_alloc(n, n, 9 * n);
    double *f = malloc((size_t)n * sizeof *f);
    *bp = malloc((size_t)n * sizeof **bp);
    if (!A || !f || !*bp) return NULL;
    double h = 1.0 / (double)(L + 1);
    for (int64_t i = 0; i < L; i++)
        for (int64_t j = 0; j < L; j++) {
            for (int di = -1; di <= 1; di++)
                for (int dj = -1; dj <= 1; dj++) {
                    int64_t a = i + di, c = j + dj;
                    if (a < 0 || a >= L || c < 0 || c >= L) continue;
                    A->colidx[nz] = (int32_t)(a * L + c);
                    A->val[nz++] = di == 0 && dj == 0 ? 20.0 : di == 0 || dj == 0 ? -4.0 : -1.0;
                }
            A->rowptr[i * L + j + 1] = nz;
            f[i * L + j] = 6.0 * h * h; /* Mehrstellen: (20u - 4 sum edges - sum corners) = 6 h^2 f */
        }
    ulam_csr *M = NULL;
    int st = ulam_jacobi(A, f, 1.0, &M, *bp, NULL);
    ulam_csr_free(A);
    free(f);
    return st ? NULL : M;
}

/* Run fn in a child process with an address-space limit and a time limit; the child writes
 * two doubles (seconds, x_I) to a pipe.  0 on success. */
static int in_child(void (*fn)(const ulam_csr *, const double *, int64_t, double *), const ulam_csr *M,
                    const double *b, int64_t I, double limit_bytes, unsigned limit_s, double out[2], char *why)
{
    int fd[2];
    if (pipe(fd)) return -1;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        struct rlimit rl = {(rlim_t)limit_bytes, (rlim_t)limit_bytes};
        setrlimit(RLIMIT_AS, &rl);
        alarm(limit_s);
        double r[2] = {-1, 0};
        fn(M, b, I, r);
        ssize_t w = write(fd[1], r, sizeof r);
        _exit(w == sizeof r ? 0 : 1);
    }
    close(fd[1]);
    double r[2] = {-1, 0};
    ssize_t got = read(fd[0], r, sizeof r);
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) sprintf(why, "> %u s", limit_s);
    else if (got != sizeof r || r[0] < 0) sprintf(why, "failed (out of memory at %.0f GB?)", limit_bytes / 1e9);
    else {
        out[0] = r[0], out[1] = r[1];
        return 0;
    }
    return 1;
}

#ifdef HAVE_UMFPACK
/* UMFPACK on I - M: CSR of I - M read as the CSC of its transpose, solved with UMFPACK_At. */
static void umfpack_run(const ulam_csr *M, const double *b, int64_t I, double r[2])
{
    int64_t n = M->nrows, nz = M->rowptr[n] + n;
    SuiteSparse_long *Ap = malloc((size_t)(n + 1) * sizeof *Ap), *Ai = malloc((size_t)nz * sizeof *Ai);
    double *Ax = malloc((size_t)nz * sizeof *Ax), *x = malloc((size_t)n * sizeof *x);
    if (!Ap || !Ai || !Ax || !x) return;
    double t0 = ulam_now();
    int64_t k = 0;
    for (int64_t i = 0; i < n; i++) { /* I - M, the diagonal merged in */
        Ap[i] = k;
        int diag = 0;
        for (int64_t p = M->rowptr[i]; p < M->rowptr[i + 1]; p++) {
            Ai[k] = M->colidx[p], Ax[k] = -M->val[p];
            if (M->colidx[p] == i) Ax[k] += 1.0, diag = 1;
            k++;
        }
        if (!diag) Ai[k] = i, Ax[k++] = 1.0;
    }
    Ap[n] = k;
    /* UMFPACK wants sorted indices without duplicates: sort and merge each column */
    for (int64_t i = 0; i < n; i++)
        for (int64_t p = Ap[i] + 1; p < Ap[i + 1]; p++)
            for (int64_t q = p; q > Ap[i] && Ai[q - 1] > Ai[q]; q--) {
                SuiteSparse_long ti = Ai[q]; Ai[q] = Ai[q - 1]; Ai[q - 1] = ti;
                double tx = Ax[q]; Ax[q] = Ax[q - 1]; Ax[q - 1] = tx;
            }
    k = 0;
    for (int64_t i = 0; i < n; i++) {
        int64_t start = k;
        for (int64_t p = Ap[i]; p < Ap[i + 1]; p++)
            if (k > start && Ai[k - 1] == Ai[p]) Ax[k - 1] += Ax[p];
            else Ai[k] = Ai[p], Ax[k++] = Ax[p];
        Ap[i] = start;
    }
    Ap[n] = k;
    void *sym = NULL, *num = NULL;
    if (umfpack_dl_symbolic(n, n, Ap, Ai, Ax, &sym, NULL, NULL) != UMFPACK_OK) return;
    if (umfpack_dl_numeric(Ap, Ai, Ax, sym, &num, NULL, NULL) != UMFPACK_OK) return;
    if (umfpack_dl_solve(UMFPACK_At, Ap, Ai, Ax, x, b, num, NULL, NULL) != UMFPACK_OK) return;
    r[0] = ulam_now() - t0, r[1] = x[I];
}
#endif

/* Dense LAPACK through ulam_direct_solve. */
static void dgesv_run(const ulam_csr *M, const double *b, int64_t I, double r[2])
{
    double *x = malloc((size_t)M->nrows * sizeof *x);
    ulam_direct_info info;
    double t0 = ulam_now();
    if (x && !ulam_direct_solve(M, b, x, (size_t)2 << 30, &info, NULL)) r[0] = ulam_now() - t0, r[1] = x[I];
    free(x);
}

/* Gauss-Seidel from 0: the time until x_I is within 1% of *ref.  With *ref unknown (NaN) it
 * sweeps to convergence (x_I moving by <= 1e-13 relative), which sets *ref, and finds the 1%
 * time in the trace of x_I it kept on the way. */
static outcome gs_run(const ulam_csr *M, const double *b, int64_t I, double *ref)
{
    int64_t n = M->nrows;
    outcome o = {.seconds = -1};
    int known = !isnan(*ref), k = 0, cap = 0;
    double *x = calloc((size_t)n, sizeof *x), t = 0, e_prev = 0, rate = 0, old = 0;
    double *xs = NULL, *ts = NULL; /* the trace: x_I and seconds after each sweep (ref unknown) */
    while (x && t < GS_CAP) {
        double t0 = ulam_now();
        ulam__gauss_seidel_sweep(M, b, x);
        t += ulam_now() - t0, k++;
        if (known) {
            double e = fabs(x[I] - *ref);
            if (k > 1 && e_prev > 0) rate = 0.9 * rate + 0.1 * (e / e_prev);
            e_prev = e;
            if (e <= 0.01 * fabs(*ref)) {
                o.seconds = t;
                break;
            }
            continue;
        }
        if (k > cap) {
            cap = cap ? 2 * cap : 256;
            double *nx = realloc(xs, (size_t)cap * sizeof *xs), *nt = nx ? realloc(ts, (size_t)cap * sizeof *ts) : NULL;
            if (nx) xs = nx;
            if (nt) ts = nt;
            if (!nx || !nt) break;
        }
        xs[k - 1] = x[I], ts[k - 1] = t;
        if (k > 10 && fabs(x[I] - old) <= 1e-13 * fabs(x[I])) { /* converged: the reference */
            *ref = x[I];
            for (int j = 0; j < k && o.seconds < 0; j++)
                if (fabs(xs[j] - *ref) <= 0.01 * fabs(*ref)) o.seconds = ts[j];
            break;
        }
        old = x[I];
    }
    if (known && o.seconds < 0 && x && rate > 0 && rate < 1) { /* project: e_prev * rate^m = 1% |ref| */
        double m = log(0.01 * fabs(*ref) / e_prev) / log(rate);
        o.seconds = t * (1.0 + m / k), o.projected = 1;
        snprintf(o.note, sizeof o.note, "%d sweeps in %.0f s, error %.2g%%, rate %.6f", k, t,
                 100 * e_prev / fabs(*ref), rate);
    }
    free(x), free(xs), free(ts);
    return o;
}

/* Walks to 1% with the kernel built as they go (whole = 0: set-up and walk seconds) or built
 * whole first (walk seconds; *setup gets the build); the estimate, its error, steps/s and the
 * kernel rows built. */
static outcome walk_run(const ulam_csr *M, const double *b, int64_t I, int whole, double *setup, double *est,
                        double *se, double *steps_s, int64_t *rows)
{
    outcome o = {.seconds = -1};
    ulam_walk_opts w = ulam_walk_defaults();
    w.query.index = I, w.exec.threads = 2, w.stop.max_walks = 0, w.stop.rel_err = 0.01, w.stop.max_seconds = WALK_CAP, w.exec.seed = 3;
    w.stop.max_steps = INT64_MAX / 4, w.kernel.whole_kernel = whole;
    ulam_solver *sv = NULL;
    double t0 = ulam_now();
    if (ulam_solver_alloc(M, b, &w, &sv, NULL)) return o;
    *setup = ulam_now() - t0;
    while (!ulam_solver_done(sv))
        if (ulam_solver_iterate(sv)) break;
    ulam_walk_result r;
    ulam_solver_result(sv, &r);
    ulam_solver_free(sv);
    *est = r.estimate, *se = r.std_error, *steps_s = (double)r.steps / r.seconds, *rows = r.rows;
    double rel = r.std_error / fabs(r.estimate), pre = whole ? 0.0 : *setup;
    o.seconds = pre + r.seconds;
    if (rel > 0.0101) { /* capped: 1% needs (rel / 1%)^2 times the walks */
        o.seconds = pre + r.seconds * (rel / 0.01) * (rel / 0.01), o.projected = 1;
        snprintf(o.note, sizeof o.note, "%lld walks in %.0f s reached %.2g%%", (long long)r.walks, r.seconds,
                 100 * rel);
    }
    return o;
}

/* The chart from docs/scale.csv: one line per method (each series picked out by grep, so
 * the rows of other series do not break its line), projections as open circles. */
static int chart(void)
{
    return gnuplot_draw("docs", "scale", 1100, 520,
                        "set multiplot layout 1,2\nset logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
                        "set xlabel 'n'\nset ylabel 'seconds to x_I at 1%'\nset key top left font ',9'\nset grid\n"
                        "set datafile separator ','\nset xrange [500:2e7]\n"
                        "do for [f in 'random poisson'] {\n"
                        "  set title f eq 'random' ? 'radiosity-like M, 8 nonzeros a row, rho = 0.9' : "
                        "'2-D Poisson (9-point) through Jacobi'\n"
                        "  plot for [m in 'walks prebuilt dgesv umfpack gs'] "
                        "sprintf(\"< grep '^%s,[0-9]*,%s,' scale.csv\", f, m) u 2:4 w lp lw 2 t m, "
                        "'scale.csv' u ((strcol(1) eq f && $5 == 1) ? $2 : 1/0):4 w p pt 6 ps 2.5 lc 'black' "
                        "t 'projected'\n}\n"
                        "unset multiplot\n");
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--chart")) return chart() ? 1 : 0; /* redraw only */
    const int64_t sizes[] = {1000, 10000, 100000, 1000000, 10000000};
    const double nmax = argc > 1 ? atof(argv[1]) : 1e7; /* bench_scale 1e4: a quick look */
    ulam_csr *W = bench_random_csr(1000); /* start the OpenMP threads before anything is timed */
    double *wb = bench_random_rhs(1000), t, w1, w2, w3;
    int64_t wr;
    if (W && wb) walk_run(W, wb, 500, 0, &t, &w1, &w2, &w3, &wr);
    ulam_csr_free(W), free(wb);
    FILE *csv = fopen("docs/scale.csv", "w");
    if (csv) fprintf(csv, "family,n,method,seconds,projected\n");
    printf("%-8s %9s | %10s %8s %10s %8s | %10s %12s %12s | %9s %9s | %9s %9s %s\n", "family", "n", "walks",
           "rows", "prebuilt", "build", "dgesv", "umfpack", "gs", "walk/best", "pre/best", "M steps/s", "z(walk)",
           "notes");
    for (int fam = 0; fam < NFAM; fam++) {
        int failed[NMETH] = {0};
        for (int s = 0; s < 5 && sizes[s] <= nmax; s++) {
            int64_t n = sizes[s];
            double *b = NULL;
            ulam_csr *M = NULL;
            if (fam == RANDOM) M = bench_random_csr(n), b = bench_random_rhs(n);
            else M = poisson((int64_t)llround(sqrt((double)n)), &b);
            if (!M || !b) return 1;
            n = M->nrows;
            int64_t L = (int64_t)llround(sqrt((double)n)), I = fam == RANDOM ? n / 2 : L / 2 * L + L / 2;
            outcome out[NMETH];
            for (int m = 0; m < NMETH; m++) out[m] = (outcome){.seconds = -1};
            char notes[512] = "";
            double ref = NAN, r2[2];
            char why[96];
            /* dense */
            if (ulam_direct_bytes(n) <= ((size_t)2 << 30)) {
                if (!in_child(dgesv_run, M, b, I, 24e9, 600, r2, why)) out[DGESV].seconds = r2[0], ref = r2[1];
                else snprintf(out[DGESV].note, sizeof out[DGESV].note, "%s", why);
            } else {
                snprintf(out[DGESV].note, sizeof out[DGESV].note, "%.0f GB dense", (double)ulam_direct_bytes(n) / 1e9);
            }
#ifdef HAVE_UMFPACK
            if (failed[UMF]) {
                snprintf(out[UMF].note, sizeof out[UMF].note, "not run: failed at a smaller n");
            } else if (!in_child(umfpack_run, M, b, I, 16e9, 600, r2, why)) {
                out[UMF].seconds = r2[0];
                if (isnan(ref)) ref = r2[1];
            } else {
                snprintf(out[UMF].note, sizeof out[UMF].note, "%s", why);
                failed[UMF] = 1;
            }
#else
            snprintf(out[UMF].note, sizeof out[UMF].note, "not built (no libsuitesparse-dev)");
#endif
            if (failed[GS]) snprintf(out[GS].note, sizeof out[GS].note, "not run: capped at a smaller n");
            else {
                out[GS] = gs_run(M, b, I, &ref);
                if (out[GS].projected) failed[GS] = 1;
            }
            double setup = 0, build = 0, est = 0, se = 0, sps = 0, e2, s2, sps2;
            int64_t rows = 0, rows2;
            if (failed[WALK]) {
                snprintf(out[WALK].note, sizeof out[WALK].note, "not run: capped at a smaller n");
            } else {
                out[WALK] = walk_run(M, b, I, 0, &setup, &est, &se, &sps, &rows);
                out[BUILT] = walk_run(M, b, I, 1, &build, &e2, &s2, &sps2, &rows2);
                if (out[WALK].projected) failed[WALK] = 1;
            }
            double best = INFINITY;
            for (int m = DGESV; m < NMETH; m++)
                if (out[m].seconds > 0) best = fmin(best, out[m].seconds);
            char cell[NMETH][32];
            for (int m = 0; m < NMETH; m++) {
                if (out[m].seconds < 0) snprintf(cell[m], 32, "-");
                else snprintf(cell[m], 32, "%s%.3g", out[m].projected ? "~" : "", out[m].seconds);
                if (out[m].note[0])
                    snprintf(notes + strlen(notes), sizeof notes - strlen(notes), "%s%s: %s",
                             notes[0] ? "; " : "", meth_names[m], out[m].note);
                if (csv && out[m].seconds > 0)
                    fprintf(csv, "%s,%lld,%s,%.6g,%d\n", fam_names[fam], (long long)n, meth_names[m], out[m].seconds,
                            out[m].projected);
            }
            printf("%-8s %9lld | %10s %8lld %10s %8.3f | %10s %12s %12s | %9.3g %9.3g | %9.1f %9.2f %s\n",
                   fam_names[fam], (long long)n, cell[WALK], (long long)rows, cell[BUILT], build, cell[DGESV], cell[UMF],
                   cell[GS], isinf(best) ? NAN : out[WALK].seconds / best,
                   isinf(best) ? NAN : out[BUILT].seconds / best, sps2 / 1e6, isnan(ref) ? NAN : (est - ref) / se,
                   notes);
            fflush(stdout);
            ulam_csr_free(M);
            free(b);
        }
    }
    if (csv) fclose(csv);
    if (chart())
        fprintf(stderr, "bench_scale: gnuplot failed: no chart\n");
    return 0;
}
