/* --method auto against every single method, in one process (issue 20's target: auto within 1.5x
 * of the best single method at --rel-err 0.01 on the study's two default systems).
 *
 * The systems are genmat's (examples/systems.h): the dense radiosity-like r500 (genmat --radiosity
 * 500) and the sparse s100k (genmat --sparse 100000 8 0.9), x_1 at rel_err 0.01, 2 threads.  Each
 * single method (adjoint / forward x collision / absorption / expected x analog / Q = 0.9, kernel
 * exponent 1) times its whole estimate as `ulam solve --method walks` makes it: the guards, the
 * solver's set-up and the walks; auto times ulam_auto_solver (guards, pilots, the chosen solver)
 * and its walks.  Median of 5 repetitions, each running every method once (so a busy spell of
 * the machine slows them alike); the ratio is to the best single method's median.
 *
 *   bench_auto [REPS]    prints the table */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "systems.h"

enum { SINGLE = 12, REPS_MAX = 15 };

/* One timed estimate. */
typedef struct {
    int status;
    double seconds, estimate, std_error;
    int64_t walks;
    int chosen_mode, chosen_estimator;
    double chosen_q, chosen_alpha;
} run;

/* The median of n values (sorted in place). */
static double median(double *v, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && v[j - 1] > v[j]; j--) {
            double t = v[j];
            v[j] = v[j - 1], v[j - 1] = t;
        }
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Iterate s until done; fill r from it. */
static void finish(ulam_solver *s, run *r)
{
    int status = ULAM_OK;
    while (!status && !ulam_solver_done(s)) status = ulam_solver_iterate(s);
    ulam_walk_result w;
    ulam_solver_result(s, &w);
    r->status = status, r->estimate = w.estimate, r->std_error = w.std_error, r->walks = w.walks;
}

/* A single method k (mode = k / 6, estimator = k / 2 % 3, continuation k % 2) as ulam solve
 * --method walks runs it: guards, set-up, walks. */
static run single(const ulam_csr *M, const double *b, int k)
{
    run r = {0};
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = k / 6, o.estimator = k / 2 % 3, o.kernel.continue_q = k % 2 ? 0.9 : 0.0;
    o.query.index = 0, o.stop.rel_err = 0.01, o.stop.max_walks = 0, o.exec.threads = 2;
    double t0 = ulam_now();
    ulam_guard g;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_HAT(o.mode);
    ulam_solver *s = NULL;
    r.status = ulam_guard_check(M, o.kernel.continue_q, &go, &g, NULL);
    o.policy.guard = &g;
    if (!r.status) r.status = ulam_solver_alloc(M, b, &o, &s, NULL);
    if (!r.status) finish(s, &r);
    r.seconds = ulam_now() - t0;
    ulam_solver_free(s);
    return r;
}

/* --method auto: guards, pilots, the chosen solver and its walks. */
static run automatic(const ulam_csr *M, const double *b)
{
    run r = {0};
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 0, o.stop.rel_err = 0.01, o.stop.max_walks = 0, o.exec.threads = 2;
    double t0 = ulam_now();
    ulam_auto_result res;
    ulam_solver *s = NULL;
    r.status = ulam_auto_solver(M, b, &o, NULL, &res, &s, NULL);
    if (!r.status) finish(s, &r);
    r.seconds = ulam_now() - t0;
    int k = res.chosen >= 0 ? res.chosen : 0;
    r.chosen_mode = res.cand[k].mode, r.chosen_estimator = res.cand[k].estimator;
    r.chosen_q = res.cand[k].continue_q, r.chosen_alpha = res.cand[k].kernel_alpha;
    ulam_solver_free(s);
    return r;
}

/* A method's name. */
static void name(char *buf, size_t n, int mode, int est, double q)
{
    static const char *const modes[] = {"adjoint", "forward"}, *const ests[] = {"collision", "absorption", "expected"};
    if (q > 0) snprintf(buf, n, "%s %s Q=%g", modes[mode], ests[est], q);
    else snprintf(buf, n, "%s %s analog", modes[mode], ests[est]);
}

/* Time every method on one system and print its rows; 1 when auto meets 1.5x. */
static int bench(const char *sys, const ulam_csr *M, const double *b, int reps)
{
    double med[SINGLE + 1], t[SINGLE + 1][REPS_MAX];
    run last[SINGLE + 1];
    for (int r = 0; r < reps; r++) /* every method once a repetition: a busy spell slows them all */
        for (int k = 0; k <= SINGLE; k++) {
            last[k] = k < SINGLE ? single(M, b, k) : automatic(M, b);
            t[k][r] = last[k].seconds;
        }
    for (int k = 0; k <= SINGLE; k++) med[k] = last[k].status ? NAN : median(t[k], reps);
    int best = -1;
    for (int k = 0; k < SINGLE; k++)
        if (!isnan(med[k]) && (best < 0 || med[k] < med[best])) best = k;
    char nm[64];
    for (int k = 0; k <= SINGLE; k++) {
        const run *r = &last[k];
        if (k < SINGLE) name(nm, sizeof nm, k / 6, k / 2 % 3, k % 2 ? 0.9 : 0.0);
        else snprintf(nm, sizeof nm, "auto");
        printf("%-6s %-28s", sys, nm);
        if (r->status) {
            printf(" refused: %s\n", ulam_strerror(r->status));
            continue;
        }
        printf(" %10.4f %9lld %13.7g %10.3g %7.2f", med[k], (long long)r->walks, r->estimate, r->std_error,
               best >= 0 ? med[k] / med[best] : NAN);
        if (k == best) printf("  best single");
        if (k == SINGLE) {
            name(nm, sizeof nm, r->chosen_mode, r->chosen_estimator, r->chosen_q);
            printf("  chose %s alpha %g: %s", nm, r->chosen_alpha, med[k] <= 1.5 * med[best] ? "meets 1.5x" : "MISSES 1.5x");
        }
        printf("\n");
    }
    return best >= 0 && !last[SINGLE].status && med[SINGLE] <= 1.5 * med[best];
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? atoi(argv[1]) : 5;
    if (reps < 1 || reps > REPS_MAX) {
        fprintf(stderr, "usage: bench_auto [REPS 1..%d]\n", REPS_MAX);
        return 2;
    }
    printf("x_1 at --rel-err 0.01, 2 threads; whole estimate (guards + set-up or pilots + walks), median of %d\n", reps);
    printf("%-6s %-28s %10s %9s %13s %10s %7s\n", "system", "method", "seconds", "walks", "estimate", "stderr", "ratio");
    ulam_csr *M = radiosity_like(500, 500);
    double *b = emitters(500);
    int ok = bench("r500", M, b, reps);
    ulam_csr_free(M), free(b);
    M = random_sparse(100000, 8, 0.9, 0, 100000);
    b = random_vector(100000, 0.0, 1.0, 100000);
    ok &= bench("s100k", M, b, reps);
    ulam_csr_free(M), free(b);
    printf("auto within 1.5x of the best single method on both: %s\n", ok ? "yes" : "no");
    return 0;
}
