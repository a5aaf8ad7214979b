/* What --rel-err costs against what the variance asks (issue 25's cost target: at most 3x).
 *
 * For each system (the suite's benign matrices, and two hard ones generated here: the
 * metastable chain of tests/test_stop.c and the 15^3 Laplacian's corner), x_1 (or the corner)
 * by adjoint walks with each of the collision and absorption estimators:
 *   oracle   walks the true variance needs for stderr = E x: var / (E x)^2, var the sample
 *            variance of a rich fixed run (ORACLE walks), x by LAPACK;
 *   walks    the mean walks of REPS --rel-err E runs (seeds 1..REPS), and how many met;
 *   ratio    walks / oracle (the target: <= 3), and walks / max(oracle, 1024) (a run's first
 *            round was 1024 walks; it is 256 since 2026-12-05);
 *   width    the mean printed 95% half-width over E |x| (1.96 is what a CLT interval at
 *            stderr E |x| would show);
 *   covered  how many of the runs' printed intervals hold x;
 *   seconds  the mean time of a whole --rel-err call (set-up, guards, forward mode's push on b,
 *            walks), and cpu/orc that over the time the oracle's walks take at the fixed run's
 *            rate (the push's work counted: forward walks from a pushed b may fall below the
 *            oracle's count).
 * Forward rows (fwd; the benign files only) run forward mode watching the same index.
 * A run is capped at CAP walks: one that predicts more stops early, not met (counted in walks).
 *
 * Issue 38's table (first): what the printed interval costs at a --rel-err stop on the hard
 * systems of issue 38 point 8, generated here (gen.h): signed (n = 200), the hub at alpha 0.99
 * (n = 200), the 12^3 Laplacian's corner (b = 1), upwind convection-diffusion 30 x 30 (cell Peclet 5 and
 * 0.5, b = 30 entries U(0, 1) plus 1 at the last unknown, unknown 1), adjoint walks, collision and
 * absorption, at E and E / 10; and the three clusters (b on the last, unknown 1; ulam_solve_walks is
 * --method walks) at leak 1e-3 for the 1e-4 and at E alone (the bench's budget):
 *   clt      the walks a CLT interval of half-width E |x| needs, (1.96 / E)^2 var / x^2;
 *   walks/clt  the mean walks of the --rel-err runs over it (the target: <= 3, median <= 2);
 *   half/Ex  the printed half-width over E |x| (--rel-err E now promises <= 1);
 *   half/1.96se  the printed half-width over 1.96 standard errors at the stop;
 *   cov      the runs whose interval holds x.
 * With OLD (a path to a previous build's libulam.so, opened with its own symbols first) each row
 * is printed for it too, side by side (docs/error-bars.md's What it costs: 5e702dc's stitched
 * empirical Bernstein against the plug-in sequence, then 0becb6a's sequence with Fan's penalty
 * and whole-block rounds against each end's quartic penalty and rounds of the walks predicted).
 *
 *   bench_relerr [E [REPS [ONLY [OLD]]]]  prints the tables (defaults 0.1 and 5; ONLY: the rows whose
 *                                     system name contains it, +ONLY: of case 6's table alone,
 *                                     =ONLY: of issue 38's table alone) */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"
#include "ulam.h"

enum { ORACLE = 1 << 20, CAP = 1 << 24 };

/* A system: M, b, the unknown's index and x by LAPACK. */
typedef struct {
    const char *name;
    ulam_csr *M;
    double *b, x;
    int64_t index;
} sys;

/* Read matrices/NAME.mtx and NAME_b.mtx (Jacobi splitting when jacobi). */
static int load(sys *s, const char *name, int jacobi)
{
    char mp[256], bp[256];
    int64_t n;
    snprintf(mp, sizeof mp, "matrices/%s.mtx", name);
    snprintf(bp, sizeof bp, "matrices/%s_b.mtx", name);
    ulam_csr *A;
    double *b;
    if (ulam_mm_read_matrix(mp, &A, NULL) || ulam_mm_read_vector(bp, &b, &n, NULL)) return -1;
    s->name = name, s->index = 0;
    if (jacobi) {
        s->b = malloc((size_t)n * sizeof *s->b);
        if (ulam_jacobi(A, b, 1.0, &s->M, s->b, NULL)) return -1;
        ulam_csr_free(A), free(b);
    } else {
        s->M = A, s->b = b;
    }
    return 0;
}

/* The metastable chain (gen.h) at leak 1e-4. */
static void metastable(sys *s)
{
    bench_metastable(1e-4, &s->M, &s->b);
    s->name = "metastable40", s->index = 0;
}

/* The m^3 Laplacian's Jacobi splitting, a point source at the centre, the corner unknown. */
static void laplace(sys *s, int m)
{
    int64_t n = (int64_t)m * m * m, nz = 0;
    int32_t *ti = malloc((size_t)(7 * n) * sizeof *ti), *tj = malloc((size_t)(7 * n) * sizeof *tj);
    double *tx = malloc((size_t)(7 * n) * sizeof *tx), *b = calloc((size_t)n, sizeof *b);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++)
            for (int k = 0; k < m; k++) {
                int32_t r = (int32_t)((i * m + j) * m + k);
                ti[nz] = r, tj[nz] = r, tx[nz++] = 6.0;
                const int d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
                for (int q = 0; q < 6; q++) {
                    int a = i + d[q][0], c = j + d[q][1], e = k + d[q][2];
                    if (a < 0 || c < 0 || e < 0 || a >= m || c >= m || e >= m) continue;
                    ti[nz] = r, tj[nz] = (int32_t)((a * m + c) * m + e), tx[nz++] = -1.0;
                }
            }
    b[((m / 2) * m + m / 2) * m + m / 2] = 1.0;
    ulam_csr *A;
    ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A);
    s->b = malloc((size_t)n * sizeof *s->b);
    ulam_jacobi(A, b, 1.0, &s->M, s->b, NULL);
    ulam_csr_free(A), free(ti), free(tj), free(tx), free(b);
    s->name = "laplace15^3 corner", s->index = 0;
}

/* x at the index by LAPACK. */
static void exact(sys *s)
{
    double *x = malloc((size_t)s->M->nrows * sizeof *x);
    s->x = ulam_direct_solve(s->M, s->b, x, 0, NULL, NULL) ? NAN : x[s->index];
    free(x);
}

/* One row of the table: est in mode (ULAM_ADJOINT, or ULAM_FORWARD watching the index). */
static void row(const sys *s, int mode, int est, double E, int reps)
{
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = mode, o.estimator = est, o.query.index = s->index, o.stop.max_walks = ORACLE, o.exec.seed = 12345;
    ulam_walk_result r;
    char label[32];
    snprintf(label, sizeof label, "%s%s", mode == ULAM_FORWARD ? "fwd " : "", est ? "absorption" : "collision");
    if (ulam_solve_walks(s->M, s->b, &o, &r, NULL)) {
        printf("%-20s %-14s refused\n", s->name, label);
        return;
    }
    double oracle = r.variance / (E * s->x * E * s->x), walks = 0, width = 0, secs = 0;
    double rate = r.seconds / (double)r.walks; /* the fixed run's seconds a walk: the oracle's walks cost oracle x rate */
    int met = 0, covered = 0;
    for (int k = 0; k < reps; k++) {
        o.stop.max_walks = CAP, o.stop.rel_err = E, o.exec.seed = 1 + (uint64_t)k; /* past CAP: stopped early, not met */
        double t0 = ulam_now();
        if (ulam_solve_walks(s->M, s->b, &o, &r, NULL)) continue;
        walks += (double)r.walks / reps, secs += (ulam_now() - t0) / reps, met += r.rel_err_met;
        width += (r.ci95[1] - r.ci95[0]) / 2 / (E * fabs(s->x)) / reps;
        covered += r.ci95[0] <= s->x && s->x <= r.ci95[1];
    }
    printf("%-20s %-14s %11.4g %11.4g %3d/%-3d %8.3g %8.3g %8.3g %3d/%-3d %8.3g %8.3g\n", s->name, label, oracle, walks,
           met, reps, walks / oracle, walks / fmax(oracle, 1024.0), width, covered, reps, secs, secs / (oracle * rate));
    fflush(stdout);
}

/* One row of the dense-b table: `label` runs est pinned as walks (push 0), pinned as the
 * bidirectional row, which with a dense b pushes b (push 1), or auto (est < 0); oracle[est] as
 * row()'s for each estimator (auto: the one its walks ran with). */
static void row_push(const sys *s, const char *label, int est, int push, const double *oracle, double E, int reps)
{
    double walks = 0, width = 0, secs = 0, ops = 0, orc = NAN;
    int met = 0, covered = 0, ran = 0;
    for (int k = 0; k < reps; k++) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = s->index, o.stop.max_walks = CAP, o.stop.rel_err = E, o.exec.seed = 1 + (uint64_t)k;
        if (est >= 0) o.estimator = est;
        ulam_method_opts mo = ulam_method_defaults();
        ulam_auto_opts ao = ulam_auto_defaults();
        if (est >= 0) ao.pin_estimator = 1, mo.method = push ? ULAM_METHOD_BIDIRECTIONAL : ULAM_METHOD_WALKS;
        ulam_choice ch;
        ulam_answer a;
        ulam_error err;
        double t0 = ulam_now();
        if (ulam_auto(s->M, s->b, &o, &ao, &mo, &ch, &a, &err)) {
            printf("%-20s %-22s refused: %s\n", s->name, label, err.msg);
            return;
        }
        secs += (ulam_now() - t0) / reps, ran++;
        walks += (double)a.walks.walks / reps, met += a.walks.rel_err_met;
        ops += a.method == ULAM_METHOD_BIDIRECTIONAL ? (double)a.bidir.plan.push.ops / reps : 0.0;
        width += (a.ci95[1] - a.ci95[0]) / 2 / (E * fabs(s->x)) / reps;
        covered += a.ci95[0] <= s->x && s->x <= a.ci95[1];
        orc = oracle[a.opts.estimator == ULAM_ABSORPTION];
        if (est < 0 && k == 0)
            printf("  (auto chose %s, %s)\n", ulam_method_name(a.method),
                   a.opts.estimator == ULAM_ABSORPTION ? "absorption" : a.opts.estimator ? "expected" : "collision");
    }
    printf("%-20s %-22s %11.4g %11.4g %3d/%-3d %8.3g %8.3g %3d/%-3d %10.3g %8.3g\n", s->name, label, orc, walks, met, ran,
           walks / orc, width, covered, ran, ops, secs);
    fflush(stdout);
}

/* Cost case 6's systems: the power law (n = 2e4, b = +-0.1 and one entry 1000 its walks from
 * state 0 reach with weight ~1e-15; b dense: the bidirectional row pushes b) and upwind
 * convection-diffusion 30 x 30 (--jacobi, a point source at the centre, the downstream corner
 * unknown; b sparse: the bidirectional row's reverse push from the unknown, unless the estimator
 * is pinned), and radiosity100 (b sparse, 5 emitters): walks as they are, the bidirectional row
 * with the estimator pinned (the push on b), and auto. */
static void dense_table(double E, int reps, const char *only)
{
    printf("\ncase 6: walks pinned, the bidirectional row pinned (dense b: the push on b), auto; E %g, %d runs a row\n", E, reps);
    printf("%-20s %-22s %11s %11s %7s %8s %8s %7s %10s %8s\n", "system", "route", "oracle", "walks", "met", "ratio",
           "width/Ex", "covered", "push ops", "seconds");
    for (int f = 0; f < 3; f++) {
        sys s = {0};
        if (f == 2 && load(&s, "radiosity100", 0)) continue;
        if (f == 0) {
            bench_case6(20000, 1e-6, 1000.0, 6, &s.M, &s.b);
            s.name = "case6 powerlaw2e4";
        } else if (f == 1) {
            ulam_csr *A = bench_convdiff(30, 1.0);
            double *one = malloc(900 * sizeof *one);
            for (int i = 0; i < 900; i++) one[i] = i == 15 * 30 + 15 ? 1.0 : 0.0;
            s.b = malloc(900 * sizeof *s.b);
            ulam_jacobi(A, one, 1.0, &s.M, s.b, NULL);
            ulam_csr_free(A), free(one);
            s.name = "convdiff30 jacobi", s.index = 899;
        }
        if (!strstr(s.name, only)) {
            ulam_csr_free(s.M), free(s.b);
            continue;
        }
        double *x = bench_neumann(s.M, s.b);
        s.x = x[s.index];
        free(x);
        if (f == 0) { /* the adjoint weight of the large entry: ((I - M)^-1)_{0, n-1} = [(I - M')^-1 e_0]_{n-1} */
            ulam_csr *Mt;
            ulam_csr_transpose(s.M, &Mt);
            double *e = calloc(20000, sizeof *e);
            e[0] = 1.0;
            double *y = bench_neumann(Mt, e);
            printf("  (x_0 = %.6g; the entry b = 1000 at state %d has adjoint weight %.3g)\n", s.x, 20000, y[19999]);
            free(y), free(e), ulam_csr_free(Mt);
        }
        double oracle[2];
        for (int est = 0; est < 2; est++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = est ? ULAM_ABSORPTION : ULAM_COLLISION, o.query.index = s.index, o.stop.max_walks = ORACLE, o.exec.seed = 12345;
            ulam_walk_result r;
            oracle[est] = ulam_solve_walks(s.M, s.b, &o, &r, NULL) ? NAN : r.variance / (E * s.x * E * s.x);
        }
        row_push(&s, "walks collision", ULAM_COLLISION, 0, oracle, E, reps);
        row_push(&s, "walks absorption", ULAM_ABSORPTION, 0, oracle, E, reps);
        row_push(&s, "push+walks collision", ULAM_COLLISION, 1, oracle, E, reps);
        row_push(&s, "push+walks absorption", ULAM_ABSORPTION, 1, oracle, E, reps);
        row_push(&s, "auto", -1, 0, oracle, E, reps);
        ulam_csr_free(s.M), free(s.b);
    }
}

/* The library a row runs: this build's, or a previous one opened by path. */
typedef struct {
    const char *name;
    ulam_walk_opts (*defaults)(void);
    int (*solve)(const ulam_csr *, const double *, const ulam_walk_opts *, ulam_walk_result *, ulam_error *);
} lib;

/* Issue 38's systems: k = 0 signed, 1 hub, 2 laplace corner, 3 convection-diffusion, 4 three
 * clusters (point 8's --method walks row, at leak 1e-3 for the 1e-4: x_0 is 100 times
 * less rare, the CLT count at E = 0.1 about 5e5 walks of 99 steps, not 7e7); 0 when made. */
static int hard_system(int k, sys *s)
{
    s->index = 0;
    if (k == 0) s->name = "signed200 gen", bench_signed(200, 5, &s->M, &s->b);
    if (k == 1) s->name = "hub200 a=0.99", bench_hub(200, 0.99, 5, &s->M, &s->b);
    if (k == 2) { /* b = 1 everywhere (Jacobi's b: 1/6), the corner unknown */
        laplace(s, 12), s->name = "laplace12^3 b=1 corner";
        for (int64_t i = 0; i < s->M->nrows; i++) s->b[i] = 1.0 / 6.0;
    }
    if (k == 3) s->name = "convdiff30 Pe 5/0.5", bench_convdiff_b(30, 5.0, 0.5, 5, &s->M, &s->b);
    if (k == 4) s->name = "clusters3 leak 1e-3", bench_clusters(1e-3, &s->M, &s->b);
    if (!s->M) return -1;
    exact(s);
    return 0;
}

/* One row of issue 38's table for library L: est at target E, reps seeds; the CLT oracle's
 * variance from a fixed run of ORACLE walks (this build). */
static void row38(const sys *s, const lib *L, int est, double E, int reps, double var)
{
    ulam_walk_opts o = L->defaults();
    o.estimator = est, o.query.index = s->index;
    double clt = 1.96 * 1.96 * var / (E * s->x * E * s->x), walks = 0, half = 0, hse = 0;
    int met = 0, cov = 0, ran = 0;
    double ratio[64];
    for (int k = 0; k < reps && k < 64; k++) {
        o.stop.max_walks = CAP, o.stop.rel_err = E, o.exec.seed = 1 + (uint64_t)k;
        ulam_walk_result r;
        if (L->solve(s->M, s->b, &o, &r, NULL)) continue;
        double h = (r.ci95[1] - r.ci95[0]) / 2;
        ratio[ran++] = (double)r.walks / clt;
        walks += (double)r.walks, met += r.rel_err_met, half += h / (E * fabs(s->x)), hse += h / (1.96 * r.std_error);
        cov += r.ci95[0] <= s->x && s->x <= r.ci95[1];
    }
    for (int i = 1; i < ran; i++) /* the median ratio */
        for (int j = i; j > 0 && ratio[j] < ratio[j - 1]; j--) {
            double t = ratio[j];
            ratio[j] = ratio[j - 1], ratio[j - 1] = t;
        }
    double med = ran ? (ran % 2 ? ratio[ran / 2] : 0.5 * (ratio[ran / 2 - 1] + ratio[ran / 2])) : NAN;
    printf("%-20s %-10s %-5g %-8s %10.4g %10.4g %8.3g %8.3g %8.3g %8.3g %3d/%-3d %3d/%-3d\n", s->name,
           est ? "absorption" : "collision", E, L->name, clt, ran ? walks / ran : NAN, ran ? walks / ran / clt : NAN, med,
           ran ? half / ran : NAN, ran ? hse / ran : NAN, met, ran, cov, ran);
    fflush(stdout);
}

/* Issue 38's table: this build and, with old, a previous one side by side. */
static void table38(double E, int reps, const char *only, const char *old)
{
    lib libs[2] = {{"this", ulam_walk_defaults, ulam_solve_walks}, {"previous", NULL, NULL}};
    int nlib = 1;
    if (old && *old) {
        void *h = dlopen(old, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
        if (!h) printf("cannot open %s: %s\n", old, dlerror());
        else {
            *(void **)&libs[1].defaults = dlsym(h, "ulam_walk_defaults");
            *(void **)&libs[1].solve = dlsym(h, "ulam_solve_walks");
            nlib = libs[1].defaults && libs[1].solve ? 2 : 1;
        }
    }
    printf("issue 38: --rel-err on hard systems, %d runs a row; clt = (1.96 / E)^2 var / x^2\n", reps);
    printf("%-20s %-10s %-5s %-8s %10s %10s %8s %8s %8s %8s %7s %7s\n", "system", "estimator", "E", "build", "clt",
           "walks", "walks/clt", "median", "half/Ex", "h/1.96se", "met", "cov");
    for (int k = 0; k < 5; k++) {
        sys s = {0};
        if (hard_system(k, &s)) continue;
        if (!strstr(s.name, only)) {
            ulam_csr_free(s.M), free(s.b);
            continue;
        }
        for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = est, o.query.index = s.index, o.stop.max_walks = ORACLE, o.exec.seed = 12345;
            ulam_walk_result r;
            if (ulam_solve_walks(s.M, s.b, &o, &r, NULL)) {
                printf("%-20s %-10s refused\n", s.name, est ? "absorption" : "collision");
                continue;
            }
            for (int e = 0; e < (k == 4 ? 1 : 2); e++) /* the clusters at E / 10: ~1e8 walks a run, past CAP */
                for (int l = 0; l < nlib; l++) row38(&s, &libs[l], est, e ? E / 10 : E, reps, r.variance);
        }
        ulam_csr_free(s.M), free(s.b);
    }
    printf("\n");
}

int main(int argc, char **argv)
{
    double E = argc > 1 ? atof(argv[1]) : 0.1;
    int reps = argc > 2 ? atoi(argv[2]) : 5;
    const char *only = argc > 3 ? argv[3] : "", *old = argc > 4 ? argv[4] : NULL;
    int case6_only = only[0] == '+', only38 = only[0] == '='; /* "+NAME": case 6's table alone; "=NAME": issue 38's */
    only += case6_only || only38;
    if (!case6_only) table38(E, reps, only, old);
    if (only38) return 0;
    static const struct { const char *name; int jacobi; } files[] = {
        {"chain4", 0}, {"radiosity100", 0}, {"randsub1000", 0}, {"signed200", 0}, {"poisson20", 1}};
    printf("--rel-err %g, %d runs a row; oracle = var / (E x)^2 (var from %d walks)\n", E, reps, ORACLE);
    printf("%-20s %-14s %11s %11s %7s %8s %8s %8s %7s %8s %8s\n", "system", "estimator", "oracle", "walks", "met", "ratio",
           "ratio1k", "width/Ex", "covered", "seconds", "cpu/orc");
    for (int f = 0; f < (case6_only ? 0 : 7); f++) {
        sys s = {0};
        if (f < 5 && load(&s, files[f].name, files[f].jacobi)) {
            printf("%s: cannot read (run from the source root)\n", files[f].name);
            continue;
        }
        if (f == 5) metastable(&s);
        if (f == 6) laplace(&s, 15);
        if (!strstr(s.name, only)) {
            ulam_csr_free(s.M), free(s.b);
            continue;
        }
        exact(&s);
        for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) row(&s, ULAM_ADJOINT, est, E, reps);
        for (int est = ULAM_COLLISION; f < 5 && est <= ULAM_ABSORPTION; est++) row(&s, ULAM_FORWARD, est, E, reps);
        ulam_csr_free(s.M), free(s.b);
    }
    dense_table(E, reps, only);
    return 0;
}
