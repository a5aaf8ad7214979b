/* The kernel exponent alpha: walks that move from i to j with probability
 * p_ij = q_i |K_ij|^alpha / sum_k |K_ik|^alpha (K = M adjoint, M' forward) and multiply their
 * weight by K_ij / (q_i p_ij), tested against LAPACK and against the second-moment matrix
 * M^_ij = K_ij^2 / (q_i p_ij) = |K_ij|^(2 - alpha) sum_k |K_ik|^alpha / q_i formed here densely
 * (directly from that formula, not through the library's normalised form).  alpha = 1 is the
 * analog kernel of tests/test_walk.c, whose results it leaves bit for bit as they were. */
#include "testutil.h"

#include <string.h>

/* A signed system with uneven rows: n states, each row `per` entries (distinct random columns)
 * whose magnitudes spread over a factor `spread` and sum to `rowsum`, random signs, and one
 * explicit zero a row in the triplets (which the matrix must not keep); b uniform in [-1, 1]. */
static test_sys uneven(int32_t n, int per, double spread, double rowsum, uint64_t seed)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 5);
    int32_t *ti = malloc((size_t)n * (per + 1) * sizeof *ti), *tj = malloc((size_t)n * (per + 1) * sizeof *tj);
    double *tx = malloc((size_t)n * (per + 1) * sizeof *tx);
    test_sys s = {.n = n, .b = malloc((size_t)n * sizeof(double))};
    int64_t nz = 0;
    for (int32_t i = 0; i < n; i++) {
        double v[16], sum = 0.0;
        for (int k = 0; k < per; k++) sum += v[k] = pow(spread, ulam_rng_uniform(&r));
        for (int k = 0; k < per; k++) {
            ti[nz] = i, tj[nz] = (i + 1 + k * (n / per) + (int32_t)ulam_rng_bounded(&r, (uint64_t)(n / per - 1))) % n;
            tx[nz++] = rowsum * v[k] / sum * (ulam_rng_uniform(&r) < 0.3 ? -1.0 : 1.0);
        }
        ti[nz] = i, tj[nz] = (i + n / (2 * per)) % n, tx[nz++] = 0.0; /* a stored zero in the input */
        s.b[i] = 2.0 * ulam_rng_uniform(&r) - 1.0;
    }
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &s.M), ULAM_OK);
    for (int64_t q = 0; q < ulam_csr_nnz(s.M); q++) assert_true(s.M->val[q] != 0.0);
    free(ti), free(tj), free(tx);
    test_sys_solve(&s);
    return s;
}

/* The uneven signed system of the statistical tests: magnitudes over a factor 10 in each row,
 * rows of |M| summing to 0.5; rho(M^) 0.65 at alpha = 0 and 2, 0.50 at 1. */
#define UNEVEN uneven(40, 4, 10.0, 0.5, 1)

/* The dense k-th moment matrix (n x n, row-major), entries |K_ij|^k / (q_i p_ij)^(k - 1), of the
 * mode's kernel at exponent alpha and continuation q_fixed (0: analog), in M's orientation:
 * adjoint the matrix itself; forward the transpose of the forward one (the same radius).  k = 2
 * is M^; at k = 4 a radius below 1 makes the walk's fourth moment finite. */
static double *dense_moment(const ulam_csr *M, int mode, double alpha, double q_fixed, int kth)
{
    int64_t n = M->nrows;
    double *D = calloc((size_t)(n * n), sizeof *D), *S = calloc((size_t)n, sizeof *S), *T = calloc((size_t)n, sizeof *T);
    for (int64_t i = 0; i < n; i++)
        for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++) {
            int64_t r = mode == ULAM_ADJOINT ? i : M->colidx[k]; /* the walk's row: M's row, or its column */
            S[r] += fabs(M->val[k]);
            T[r] += pow(fabs(M->val[k]), alpha);
        }
    for (int64_t i = 0; i < n; i++)
        for (int64_t k = M->rowptr[i]; k < M->rowptr[i + 1]; k++) {
            int64_t r = mode == ULAM_ADJOINT ? i : M->colidx[k];
            double q = q_fixed > 0 ? q_fixed : fmin(1.0, S[r]), v = fabs(M->val[k]);
            double p = q * pow(v, alpha) / T[r];
            D[i * n + M->colidx[k]] = pow(v, kth) / pow(p, kth - 1);
        }
    free(S), free(T);
    return D;
}

/* The dense M^ of the mode's kernel (dense_moment, k = 2). */
static double *dense_hat(const ulam_csr *M, int mode, double alpha, double q_fixed)
{
    return dense_moment(M, mode, alpha, q_fixed, 2);
}

/* The Perron root of the nonnegative dense D (n x n) by power iteration on I + D (the shift
 * makes the root strictly dominant) until its estimate sum(y) / sum(x) has not moved by more
 * than 1e-15 relatively for 20 iterations. */
static double dense_radius(const double *D, int64_t n)
{
    double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y), lam = 0.0;
    for (int64_t i = 0; i < n; i++) x[i] = 1.0;
    for (int it = 0, still = 0; it < 1000000 && still < 20; it++) {
        double sx = 0.0, sy = 0.0, mx = 0.0;
        for (int64_t i = 0; i < n; i++) {
            double t = x[i];
            for (int64_t j = 0; j < n; j++) t += D[i * n + j] * x[j];
            y[i] = t, sx += x[i], sy += t, mx = fmax(mx, t);
        }
        still = fabs(sy / sx - lam) <= 1e-15 * lam ? still + 1 : 0;
        lam = sy / sx;
        for (int64_t i = 0; i < n; i++) x[i] = y[i] / mx;
    }
    free(x), free(y);
    return lam - 1.0;
}

/* rho(M^) of the guards at alpha in {0, 0.5, 2, 3} (and 1, today's) for both modes and two
 * continuations on the chain, the signed system and two uneven ones (the second with radii up
 * to 0.95 and 4.5): the certified bounds contain the dense computation's radius, the iterated
 * estimate (tight) agrees with it to 1e-6, and the check stopped once certified gives the
 * same verdict. */
static void test_radius(void **state)
{
    (void)state;
    test_sys sy[4] = {test_sys_load("chain4"), test_sys_load("signed200"), UNEVEN, uneven(40, 4, 30.0, 0.6, 1)};
    static const double alphas[] = {0.0, 0.5, 1.0, 2.0, 3.0}, qs[] = {0.0, 0.7};
    int c = 0;
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 5; a++)
            for (int m = ULAM_ADJOINT; m <= ULAM_FORWARD; m++)
                for (int iq = 0; iq < 2; iq++, c++) {
                    if (!test_case(c)) continue;
                    double *D = dense_hat(sy[k].M, m, alphas[a], qs[iq]), exact = dense_radius(D, sy[k].n);
                    ulam_guard_opts go = ulam_guard_defaults();
                    go.kernel_alpha = alphas[a], go.tight = 1, go.power.tol = 1e-10, go.power.max_iter = 100000;
                    ulam_guard g, gc;
                    assert_int_equal(ulam_guard_check(sy[k].M, qs[iq], &go, &g, NULL), ULAM_OK);
                    go.tight = 0; /* stopped once certified: the same verdict */
                    assert_int_equal(ulam_guard_check(sy[k].M, qs[iq], &go, &gc, NULL), ULAM_OK);
                    const ulam_power *h = &g.hat[m];
                    if (!(h->lower <= exact * (1 + 1e-9) && exact <= h->upper * (1 + 1e-9)) ||
                        fabs(h->rho - exact) > 1e-6 * exact || gc.verdict_hat[m] != g.verdict_hat[m])
                        print_error("case %d (system %d alpha %g mode %d q %g): rho(M^) %.12g in [%.12g, %.12g], dense "
                                    "%.12g, verdicts %d %d\n", c, k, alphas[a], m, qs[iq], h->rho, h->lower, h->upper,
                                    exact, g.verdict_hat[m], gc.verdict_hat[m]);
                    assert_true(h->lower <= exact * (1 + 1e-9) && exact <= h->upper * (1 + 1e-9));
                    assert_true(fabs(h->rho - exact) <= 1e-6 * exact);
                    assert_int_equal(gc.verdict_hat[m], g.verdict_hat[m]);
                    assert_true(g.kernel_alpha == alphas[a]);
                    if (iq == 0)
                        print_message("system %d alpha %.1f: %s rho(M^) %.6f\n", k, alphas[a], m ? "forward" : "adjoint", exact);
                    free(D);
                }
    test_case_done();
    for (int k = 0; k < 4; k++) test_sys_free(&sy[k]);
}

/* Every mode and estimator at alpha 0, 0.5 and 2 agrees with LAPACK within 4 sigma, on the
 * chain, the signed system and the uneven signed one (built from triplets with stored
 * zeros), wherever its variance is certified finite; the six forward cases of the signed
 * system at alpha 0 and 2 have rho(M^) 1.04 (test_radius) and report no interval.  Forward
 * absorption where a column of |M| sums past 1 is refused (p* = 0) and runs with q = 0.8. */
static void test_agreement(void **state)
{
    (void)state;
    test_sys sy[3] = {test_sys_load("chain4"), test_sys_load("signed200"), UNEVEN};
    static const int64_t index[3] = {1, 3, 5};
    static const double alphas[] = {0.0, 0.5, 2.0};
    int c = 0, skipped = 0;
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            for (int mode = ULAM_ADJOINT; mode <= ULAM_FORWARD; mode++)
                for (int est = ULAM_COLLISION; est <= ULAM_EXPECTED; est++, c++) {
                    if (!test_case(c)) continue;
                    ulam_walk_opts o = ulam_walk_defaults();
                    o.mode = mode, o.estimator = est, o.query.index = index[k], o.kernel.kernel_alpha = alphas[a];
                    o.stop.max_walks = mode == ULAM_FORWARD ? 100000 : 40000;
                    o.exec.seed = 300 + (uint64_t)c;
                    ulam_solver *sv = NULL;
                    int st = ulam_solver_alloc(sy[k].M, sy[k].b, &o, &sv, NULL);
                    ulam_solver_free(sv);
                    if (st == ULAM_EUNDEFINED) {
                        assert_true(est == ULAM_ABSORPTION && mode == ULAM_FORWARD && k > 0);
                        o.kernel.continue_q = 0.8;
                    }
                    ulam_walk_result r = test_sys_run(&sy[k], o);
                    if (r.variance_finite != 1) { /* no 4 sigma claim: and no interval either */
                        assert_true(k == 1 && alphas[a] != 0.5 && mode == ULAM_FORWARD);
                        assert_true(r.variance_finite == 0 && isnan(r.ci95[0]));
                        skipped++;
                        continue;
                    }
                    double z = (r.estimate - sy[k].x[o.query.index]) / r.std_error;
                    if (!(fabs(z) < 4) || !(r.std_error < 0.25 * (fabs(sy[k].x[o.query.index]) + 1)))
                        print_error("case %d (system %d alpha %g mode %d est %d): %.10g +- %.3g, LAPACK %.10g (z = "
                                    "%.2f)\n", c, k, alphas[a], mode, est, r.estimate, r.std_error, sy[k].x[o.query.index], z);
                    assert_true(fabs(z) < 4);
                    assert_true(r.std_error > 0 && r.std_error < 0.25 * (fabs(sy[k].x[o.query.index]) + 1));
                }
    test_case_done();
    print_message("%d of %d cases with rho(M^) >= 1 (signed200 forward at alpha 0 and 2): no interval\n", skipped, c);
    if (test_case_all()) assert_int_equal(skipped, 6);
    for (int k = 0; k < 3; k++) test_sys_free(&sy[k]);
}

/* The exact per-walk variance of the adjoint estimator at index under the kernel of exponent
 * alpha (analog continuation): (I - M^) v = r as in tests/test_walk.c, M^ from dense_hat. */
static double exact_variance(const test_sys *s, int est, int64_t index, double alpha)
{
    int64_t n = s->n;
    double *D = dense_hat(s->M, ULAM_ADJOINT, alpha, 0.0), *rhs = malloc((size_t)n * sizeof *rhs);
    double *v = malloc((size_t)n * sizeof *v), *c = malloc((size_t)n * sizeof *c);
    int32_t *ti = malloc((size_t)(n * n) * sizeof *ti), *tj = malloc((size_t)(n * n) * sizeof *tj);
    int64_t nz = 0;
    for (int64_t i = 0; i < n; i++)
        for (int64_t j = 0; j < n; j++)
            if (D[i * n + j] != 0.0) ti[nz] = (int32_t)i, tj[nz] = (int32_t)j, D[nz++] = D[i * n + j];
    ulam_csr *H = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, D, &H), ULAM_OK);
    ulam_csr_matvec(s->M, 0, s->b, c);
    for (int64_t i = 0; i < n; i++) {
        double S = 0;
        for (int64_t k = s->M->rowptr[i]; k < s->M->rowptr[i + 1]; k++) S += fabs(s->M->val[k]);
        double pstar = 1 - fmin(1.0, S), y = s->x[i] - s->b[i];
        if (est == ULAM_COLLISION) rhs[i] = s->b[i] * s->b[i] + 2 * s->b[i] * (s->x[i] - s->b[i]);
        else if (est == ULAM_ABSORPTION) rhs[i] = s->b[i] * s->b[i] / pstar;
        else rhs[i] = c[i] * c[i] + 2 * c[i] * (y - c[i]);
    }
    assert_int_equal(ulam_direct_solve(H, rhs, v, 0, NULL, NULL), ULAM_OK);
    double mean = est == ULAM_EXPECTED ? s->x[index] - s->b[index] : s->x[index], var = v[index] - mean * mean;
    free(D), free(rhs), free(v), free(c), free(ti), free(tj);
    ulam_csr_free(H);
    return var;
}

/* The per-walk sample variance at alpha 0, 0.5 and 2 matches the exact one of that kernel
 * within 4 of its own reported relative standard errors, for every adjoint estimator on an
 * uneven signed system (magnitudes over a factor 3), whose fourth-moment radius is below 1 at
 * each exponent (checked: on UNEVEN it is 1.7 at alpha = 0 and 4.2 at 2, the fourth moment is
 * infinite there and the variance's reported error bar too small, -3.3% measured at +-0.9%);
 * alpha changes the variance (so the kernel walked is the one asked for). */
static void test_exact_variance(void **state)
{
    (void)state;
    test_sys s = uneven(40, 4, 3.0, 0.5, 1);
    static const double alphas[] = {0.0, 0.5, 1.0, 2.0};
    static const char *const names[] = {"collision", "absorption", "expected"};
    for (int est = ULAM_COLLISION; est <= ULAM_EXPECTED; est++) {
        double ex[4];
        for (int a = 0; a < 4; a++) {
            ex[a] = exact_variance(&s, est, 5, alphas[a]);
            if (!test_case(1000L * est + a)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = est, o.query.index = 5, o.kernel.kernel_alpha = alphas[a], o.stop.max_walks = 400000, o.exec.seed = 11;
            ulam_walk_result r = test_sys_run(&s, o);
            double *D4 = dense_moment(s.M, ULAM_ADJOINT, alphas[a], 0.0, 4), r4 = dense_radius(D4, s.n);
            free(D4);
            assert_true(r4 < 0.9); /* a finite fourth moment: the variance's own error bar means something */
            print_message("uneven40 x[6] alpha %.1f %-10s variance: measured %.6g +- %.2g%%, exact %.6g (%+.2f%%)\n",
                          alphas[a], names[est], r.variance, 100 * r.variance_rel_error, ex[a],
                          100 * (r.variance / ex[a] - 1));
            assert_true(ex[a] > 0 && r.variance_rel_error < 0.1);
            assert_close(r.variance, ex[a], 4 * r.variance_rel_error * ex[a]);
        }
        test_case_done();
        assert_true(fabs(ex[0] / ex[2] - 1) > 0.02 && fabs(ex[2] / ex[3] - 1) > 0.02);
    }
    test_sys_free(&s);
}

/* A cycle whose rows hold 0.9 to the next state and 0.05 to the one after: rho(|M|) = 0.95 and
 * at alpha = 1 (analog, S = q) M^ = |M|, finite; at alpha = 0 every row of M^ sums to
 * 2 (0.81 + 0.0025) / 0.95 = 1.7105, certified >= 1: the variance is infinite, the solver says
 * so (no interval; a --rel-err target alone refused naming the exponent), while alpha = 2
 * gives the same sums and alpha = 0.5 a radius in between. */
static void test_verdict(void **state)
{
    (void)state;
    enum { N = 50 };
    int32_t ti[2 * N], tj[2 * N];
    double tx[2 * N], b[N];
    for (int i = 0; i < N; i++) {
        ti[2 * i] = i, tj[2 * i] = (i + 1) % N, tx[2 * i] = 0.9;
        ti[2 * i + 1] = i, tj[2 * i + 1] = (i + 2) % N, tx[2 * i + 1] = 0.05;
        b[i] = 1.0 + 0.5 * sin(i);
    }
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(N, N, 2 * N, ti, tj, tx, &M), ULAM_OK);
    static const double alphas[] = {0.0, 0.5, 1.0, 2.0};
    ulam_guard g[4];
    for (int a = 0; a < 4; a++) {
        ulam_guard_opts go = ulam_guard_defaults();
        go.kernel_alpha = alphas[a];
        assert_int_equal(ulam_guard_check(M, 0.0, &go, &g[a], NULL), ULAM_OK);
        print_message("cycle: alpha %.1f rho(M^) in [%.6f, %.6f] verdict %d\n", alphas[a], g[a].hat[0].lower,
                      g[a].hat[0].upper, g[a].verdict_hat[0]);
        assert_int_equal(g[a].verdict_abs, g[0].verdict_abs); /* rho(|M|) does not depend on alpha */
    }
    assert_int_equal(ulam_guard_variance(&g[2], ULAM_ADJOINT), 1);
    assert_int_equal(g[0].verdict_hat[0], ULAM_VERDICT_FAIL);
    assert_true(g[0].hat[0].lower >= 1.71 && g[0].hat[0].upper <= 1.711);
    assert_int_equal(g[3].verdict_hat[0], ULAM_VERDICT_FAIL);
    assert_true(g[1].hat[0].lower > g[2].hat[0].upper && g[1].hat[0].upper < g[0].hat[0].lower);
    ulam_walk_opts o = ulam_walk_defaults();
    o.stop.max_walks = 0, o.stop.rel_err = 0.01, o.kernel.kernel_alpha = 1.0;
    ulam_walk_result r;
    ulam_error err;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_OK);
    assert_true(r.rel_err_met && r.variance_finite == 1);
    o.kernel.kernel_alpha = 0.0;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_EINFVAR);
    assert_non_null(strstr(err.msg, "alpha = 0"));
    assert_non_null(strstr(err.msg, ">= 1: infinite"));
    o.policy.guard = &g[2]; /* the alpha = 1 verdicts handed in are not this kernel's: recomputed */
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_EINFVAR);
    o.stop.max_walks = 4000; /* bounded: runs, no interval, the rule never fires */
    ulam_solver *sv = NULL;
    assert_int_equal(ulam_solver_alloc(M, b, &o, &sv, &err), ULAM_OK);
    while (!ulam_solver_done(sv)) assert_int_equal(ulam_solver_iterate(sv), ULAM_OK);
    ulam_solver_result(sv, &r);
    assert_true(r.walks == 4000 && !r.rel_err_met && r.variance_finite == 0 && isnan(r.ci95[0]) && isnan(r.ci95[1]));
    ulam_solver_free(sv);
    ulam_csr_free(M);
}

/* Over 200 seeds estimate -+ 1.96 stderr of adjoint collision walks at alpha = 2 on the uneven
 * signed system (2000 walks each) covers the LAPACK value 180 to 198 times: Bin(200, 0.95) falls
 * outside that range with probability 0.0016 (a kernel with the wrong weights would be biased
 * and cover far less often); the printed interval (src/stop.h, conservative) at least 180. */
static void test_coverage(void **state)
{
    (void)state;
    test_sys s = UNEVEN;
    int covered = 0, printed = 0;
    for (int seed = 0; seed < 200; seed++) { /* case seed: reruns exactly */
        if (!test_case(seed)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 5, o.kernel.kernel_alpha = 2.0, o.stop.max_walks = 2000, o.exec.seed = (uint64_t)seed;
        ulam_walk_result r = test_sys_run(&s, o);
        assert_int_equal(r.variance_finite, 1);
        covered += fabs(r.estimate - s.x[5]) <= ULAM_Z95 * r.std_error;
        printed += r.ci95[0] <= s.x[5] && s.x[5] <= r.ci95[1];
    }
    test_case_done();
    if (!test_case_all()) { /* one case alone: no count over seeds */
        test_sys_free(&s);
        return;
    }
    print_message("alpha 2: -+ 1.96 stderr covered the LAPACK value %d / 200 times, the printed interval %d\n", covered,
                  printed);
    assert_in_range(covered, 180, 198);
    assert_true(printed >= 180);
    test_sys_free(&s);
}

/* The rel_err rule where the fourth moment is infinite (chain4 at alpha = 2: rho(M4) >= 1.157,
 * weights grow on cycles) stands on the certified second moment: over 100 seeds every run ends
 * met, within the target, and its 95% interval covers the LAPACK value at least 88 times
 * (Bin(100, 0.95) falls below 88 with probability 0.0043). */
static void test_rel_err_fourth_coverage(void **state)
{
    (void)state;
    test_sys s = test_sys_load("chain4");
    int covered = 0;
    for (int seed = 0; seed < 100; seed++) { /* case seed: reruns exactly */
        if (!test_case(seed)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 0, o.kernel.kernel_alpha = 2.0, o.stop.max_walks = 0, o.stop.rel_err = 0.05, o.exec.seed = 500 + (uint64_t)seed;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(s.M, s.b, &o, &r, NULL), ULAM_OK);
        assert_true(r.rel_err_met && r.fourth_finite == 0 && r.variance_finite == 1);
        assert_true(r.std_error <= 0.05 * fabs(r.estimate));
        covered += r.ci95[0] <= s.x[0] && s.x[0] <= r.ci95[1];
    }
    test_case_done();
    if (test_case_all()) {
        print_message("chain4 alpha 2, --rel-err 0.05 on the second moment: %d / 100 intervals cover\n", covered);
        assert_true(covered >= 88);
    }
    test_sys_free(&s);
}

/* The weight bound follows each move's factor: state 0 moves to 1 (0.6) or 2 (0.2), 1 to 2 (0.5),
 * 2 ends; absorption scores b_2 = 1 where walks end at 2.  At alpha = 0 the move 0 -> 1 has
 * probability 0.8 / 2 and factor 0.6 / 0.4 = 1.5 (the row factor S / q is 1), so a score is
 * 1.5 and the bound must say 1.5, not 1; at alpha = 1 every factor is 1; at alpha = 3 the move
 * 0 -> 2 has probability 0.8 (1/27) / (28/27) and factor 0.2 * 28 / 0.8 = 7.  --rel-err meets
 * its target and agrees with x_0 = 0.2 + 0.6 * 0.5 = 0.5, with the absorption and the collision
 * estimator (whose range term asks for at least 12.28 R / (E x) walks, R >= that largest score). */
static void test_weight_bound(void **state)
{
    (void)state;
    int32_t ti[3] = {0, 0, 1}, tj[3] = {1, 2, 2};
    double tx[3] = {0.6, 0.2, 0.5}, b[3] = {0, 0, 1};
    test_sys s = {.n = 3, .b = b};
    assert_int_equal(ulam_csr_from_triplets(3, 3, 3, ti, tj, tx, &s.M), ULAM_OK);
    static const double alphas[] = {0.0, 1.0, 3.0}, bounds[] = {1.5, 1.0, 0.2 * 27 * (1 + 1 / 27.0) / 0.8};
    for (int a = 0; a < 3; a++) {
        if (!test_case(a)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.estimator = ULAM_ABSORPTION, o.kernel.kernel_alpha = alphas[a], o.stop.max_walks = 0, o.stop.rel_err = 0.01;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(s.M, s.b, &o, &r, NULL), ULAM_OK);
        print_message("alpha %.0f: score bound %.6g, %lld walks to 1%%, x_1 = %.6g +- %.2g\n", alphas[a], r.score_bound,
                      (long long)r.walks, r.estimate, r.std_error);
        assert_close(r.score_bound, bounds[a], 1e-12);
        assert_true(r.rel_err_met && fabs(r.estimate - 0.5) < 4 * r.std_error);
        o.estimator = ULAM_COLLISION; /* per visit at most the weight bound times max |b|: the range term holds too */
        assert_int_equal(ulam_solve_walks(s.M, s.b, &o, &r, NULL), ULAM_OK);
        assert_true(r.rel_err_met && isfinite(r.tail_bound) && fabs(r.estimate - 0.5) < 4 * r.std_error);
        assert_true(r.min_walks >= 12.28 * bounds[a] / (0.01 * r.estimate)); /* R >= the largest score */
    }
    test_case_done();
    ulam_csr_free(s.M);
}

/* Bit for bit the same result with the kernel built lazily or whole, and with 1 or 2 threads,
 * at alpha = 0.5 in both modes. */
static void test_identical(void **state)
{
    (void)state;
    test_sys s = test_sys_load("randsub1000");
    for (int mode = ULAM_ADJOINT; mode <= ULAM_FORWARD; mode++) {
        if (!test_case(mode)) continue;
        ulam_walk_opts o = ulam_walk_defaults();
        o.mode = mode, o.query.index = 5, o.stop.max_walks = 50000, o.exec.seed = 9, o.kernel.kernel_alpha = 0.5, o.exec.threads = 1;
        ulam_walk_result a = test_sys_run(&s, o);
        o.exec.threads = 2;
        ulam_walk_result b = test_sys_run(&s, o);
        o.kernel.whole_kernel = 1;
        ulam_walk_result c = test_sys_run(&s, o);
        assert_memory_equal(&a.estimate, &b.estimate, sizeof a.estimate);
        assert_memory_equal(&a.variance, &c.variance, sizeof a.variance);
        assert_true(a.steps == b.steps && a.steps == c.steps && c.rows == s.n);
        assert_true(fabs(a.estimate - s.x[5]) < 4 * a.std_error);
    }
    test_case_done();
    test_sys_free(&s);
}

/* Bad exponents are refused by the solver and the guards; certificates hold exponent 1 only
 * (computing or writing another is refused, a query at another exponent does not take one);
 * stored zeros weigh nothing at alpha = 0 (the guards' radius is the matrix's without them,
 * and walks refuse the row as corrupt rather than dividing by zero); a row whose entries are
 * too uneven for the exponent's probabilities is refused when a walk reaches it, and where a
 * probability underflows the guards certify nothing. */
static void test_options(void **state)
{
    (void)state;
    test_sys s = test_sys_load("chain4");
    ulam_walk_opts o = ulam_walk_defaults();
    ulam_guard_opts go = ulam_guard_defaults();
    ulam_solver *sv = NULL;
    ulam_guard g;
    ulam_error err;
    assert_true(o.kernel.kernel_alpha == 1.0 && go.kernel_alpha == 1.0);
    static const double bad[] = {-1.0, -1e-300, NAN, INFINITY};
    for (int k = 0; k < 4; k++) {
        o.kernel.kernel_alpha = go.kernel_alpha = bad[k];
        assert_int_equal(ulam_solver_alloc(s.M, s.b, &o, &sv, &err), ULAM_EINVAL);
        assert_non_null(strstr(err.msg, "kernel exponent"));
        assert_null(sv);
        assert_int_equal(ulam_guard_check(s.M, 0.0, &go, &g, NULL), ULAM_EINVAL);
    }
    ulam_certificate c;
    go.kernel_alpha = 2.0;
    assert_int_equal(ulam_certificate_compute(s.M, 0.0, &go, &c, &err), ULAM_EINVAL);
    assert_int_equal(ulam_certificate_compute(s.M, 0.0, NULL, &c, &err), ULAM_OK);
    assert_true(c.guard.kernel_alpha == 1.0);
    assert_int_equal(ulam_certificate_guard(&c, 0.0, &go, &g), ULAM_ENOTFOUND);
    go.kernel_alpha = 1.0;
    assert_int_equal(ulam_certificate_guard(&c, 0.0, &go, &g), ULAM_OK);
    c.guard.kernel_alpha = 2.0;
    ulam_system_desc d = {.M = s.M, .b = s.b, .n = s.n, .cert = &c};
    FILE *f = tmpfile();
    assert_int_equal(ulam_system_write_file(f, &d), ULAM_EINVAL);
    fclose(f);
    test_sys_free(&s);

    /* stored zeros: the same matrix with and without a zero in every row (at the first column
       the row lacks, kept in column order) */
    test_sys u = uneven(40, 4, 30.0, 0.6, 2);
    ulam_csr *Z = ulam_csr_alloc(40, 40, ulam_csr_nnz(u.M) + 40);
    for (int64_t i = 0, at = 0; i < 40; i++) {
        int32_t zc = 0;
        while (csr_get(u.M, i, zc) != 0.0) zc++;
        Z->rowptr[i] = at;
        for (int64_t k = u.M->rowptr[i]; k < u.M->rowptr[i + 1]; k++) {
            if (zc >= 0 && zc < u.M->colidx[k]) Z->colidx[at] = zc, Z->val[at++] = 0.0, zc = -1;
            Z->colidx[at] = u.M->colidx[k], Z->val[at++] = u.M->val[k];
        }
        if (zc >= 0) Z->colidx[at] = zc, Z->val[at++] = 0.0;
        Z->rowptr[i + 1] = at;
    }
    assert_true(ulam_csr_nnz(Z) == ulam_csr_nnz(u.M) + 40);
    for (int m = ULAM_ADJOINT; m <= ULAM_FORWARD; m++) {
        ulam_guard gz, gu;
        go = ulam_guard_defaults();
        go.kernel_alpha = 0.0, go.tight = 1, go.need = ULAM_GUARD_HAT(m);
        assert_int_equal(ulam_guard_check(Z, 0.0, &go, &gz, NULL), ULAM_OK);
        assert_int_equal(ulam_guard_check(u.M, 0.0, &go, &gu, NULL), ULAM_OK);
        assert_true(isfinite(gz.hat[m].rho));
        assert_close(gz.hat[m].rho, gu.hat[m].rho, 1e-9 * gu.hat[m].rho);
    }
    o = ulam_walk_defaults();
    o.kernel.kernel_alpha = 0.0, o.query.index = 3, o.stop.max_walks = 1000;
    ulam_walk_result r;
    assert_int_equal(ulam_solve_walks(Z, u.b, &o, &r, &err), ULAM_ESYNTAX);
    ulam_csr_free(Z);
    test_sys_free(&u);

    /* a row with entries 0.5 and 1e-30: at alpha = 2 the small move has probability 4e-60 */
    int32_t ti[3] = {0, 0, 1}, tj[3] = {1, 2, 0};
    double tx[3] = {0.5, 1e-30, 0.5}, b[3] = {1, 1, 1};
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(3, 3, 3, ti, tj, tx, &M), ULAM_OK);
    o = ulam_walk_defaults();
    o.kernel.kernel_alpha = 2.0, o.stop.max_walks = 1000, o.policy.force = 1;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_ERANGE);
    assert_int_equal(err.index, 0);
    assert_non_null(strstr(err.msg, "alpha = 2"));
    go = ulam_guard_defaults(); /* at alpha = 20 the probability (2e-30)^20 underflows: rho(M^) unknown, not certified */
    go.kernel_alpha = 20.0;
    assert_int_equal(ulam_guard_check(M, 0.0, &go, &g, NULL), ULAM_OK);
    assert_true(g.verdict_hat[ULAM_ADJOINT] == ULAM_VERDICT_UNKNOWN && g.hat[ULAM_ADJOINT].lower == 0.0);
    o.kernel.kernel_alpha = 1.0; /* the analog kernel samples it (probability 2e-30) */
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_OK);
    ulam_csr_free(M);
}

/* The fourth moment's honesty gap, reproduced: on UNEVEN (adjoint collision, x[6]) the sample
 * variance's spread over 200 seeds of 20000 walks against the relative error the solver reports
 * for it (variance_rel_error, from the sample fourth moment).  At alpha = 1 (analog, weights
 * never grow, rho(M4) = rho(|M|) = 0.5) the two agree (measured 0.0138 against 0.0134); at
 * alpha = 2, rho(M4) = 4.2 (the fourth moment infinite, the variance finite: rho(M^) 0.65),
 * the spread is 1.7 times the reported error (0.152 against 0.089), so the rule's check
 * variance_rel_error <= 0.25 trusted a number that is far too small.  The spread of 200
 * draws is itself known to within about 10% (15% allowed; heavy tails only widen the
 * alpha 2 spread, and the bound there asks for 1.3 of the 1.7 measured).  Then the rule: a
 * --rel-err target alone at alpha = 2 is refused naming rho(M4) and exponent 1, whose rho(M4)
 * is below 1; with a walk budget it runs and is never met; at alpha 1 it is met. */
static void test_fourth_moment(void **state)
{
    (void)state;
    test_sys s = UNEVEN;
    static const double alphas[] = {1.0, 2.0};
    double ratio[2];
    for (int a = 0; a < 2; a++) {
        double sv = 0.0, sv2 = 0.0, vre = 0.0;
        enum { SEEDS = 200 };
        for (int k = 0; k < SEEDS; k++) {
            if (!test_case(1000L * a + k)) continue;
            ulam_walk_opts o = ulam_walk_defaults();
            o.query.index = 5, o.kernel.kernel_alpha = alphas[a], o.stop.max_walks = 20000, o.exec.seed = 100 + (uint64_t)k;
            ulam_walk_result r = test_sys_run(&s, o);
            sv += r.variance, sv2 += r.variance * r.variance, vre += r.variance_rel_error;
        }
        test_case_done();
        if (!test_case_all()) continue;
        double mean = sv / SEEDS, spread = sqrt(fmax(0.0, sv2 / SEEDS - mean * mean)) / mean;
        ratio[a] = spread / (vre / SEEDS);
        print_message("uneven40 x[6] alpha %.0f, 200 seeds x 20000 walks: variance spread %.4g, reported "
                      "variance_rel_error %.4g (ratio %.3g)\n", alphas[a], spread, vre / SEEDS, ratio[a]);
    }
    if (test_case_all()) {
        assert_true(ratio[0] > 0.85 && ratio[0] < 1.15);
        assert_true(ratio[1] > 1.3);
    }
    double *D4 = dense_moment(s.M, ULAM_ADJOINT, 2.0, 0.0, 4), r4 = dense_radius(D4, s.n);
    free(D4);
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 5, o.kernel.kernel_alpha = 2.0, o.stop.max_walks = 0, o.stop.rel_err = 0.05;
    ulam_walk_result r;
    ulam_error err;
    /* rho(M4) >= 1 but a certified second moment: the rule skips the variance's own error and
     * stands on v2 (its range term bounds the true standard error by 0.29 E |x|) */
    assert_int_equal(ulam_solve_walks(s.M, s.b, &o, &r, &err), ULAM_OK);
    print_message("alpha 2 --rel-err 0.05 alone: %lld walks, met %d, %.6g +- %.3g (exact %.6g; dense rho(M4) %.6g, "
                  "fourth %d)\n", (long long)r.walks, r.rel_err_met, r.estimate, r.std_error, s.x[5], r4,
                  r.fourth_finite);
    assert_true(r4 >= 1.0 && r.fourth_finite == 0 && r.rel_err_met);
    assert_close(r.estimate, s.x[5], 4 * r.std_error);
    assert_true(r.std_error <= 0.05 * fabs(r.estimate));
    o.stop.max_walks = 200000; /* with a budget too: the same verdicts, and the rule may stop it earlier, or */
    assert_int_equal(ulam_solve_walks(s.M, s.b, &o, &r, &err), ULAM_OK); /* say early the budget is too small */
    assert_true(r.walks == 200000 || r.rel_err_met || (r.out_of_reach && r.min_walks > 200000));
    assert_true(r.fourth_finite == 0 && r.variance_finite == 1);
    assert_true(r.rho4.lower <= r4 * (1 + 1e-9) && r4 <= r.rho4.upper * (1 + 1e-9) && r.rho4.lower >= 1.0);
    assert_close(r.estimate, s.x[5], 4 * r.std_error);
    o.kernel.kernel_alpha = 1.0, o.stop.max_walks = 0; /* bounded scores: every moment finite, rho4 not needed */
    assert_int_equal(ulam_solve_walks(s.M, s.b, &o, &r, &err), ULAM_OK);
    assert_true(r.rel_err_met && r.fourth_finite == 1);
    assert_close(r.estimate, s.x[5], 4 * r.std_error);
    test_sys_free(&s);
}

/* rho(M4) as the solver certifies it (rel_err runs whose scores have no bound: exponents 0,
 * 0.5, 2 and, at exponent 1, a continuation Q = 0.3 below UNEVEN's row sums 0.5, whose factors
 * S / Q = 5/3 grow weights on cycles; both modes; UNEVEN and the factor-30 one): the bounds
 * contain the dense matrix's radius, fourth_finite follows them, and the rule is met within a
 * 10^6-walk budget only where it is 1 (and then within 4 sigma of LAPACK). */
static void test_fourth_radius(void **state)
{
    (void)state;
    test_sys sy[2] = {UNEVEN, uneven(40, 4, 30.0, 0.6, 1)};
    static const double alphas[] = {0.0, 0.5, 1.0, 2.0};
    int c = 0, finite = 0, infinite = 0;
    for (int k = 0; k < 2; k++)
        for (int a = 0; a < 4; a++)
            for (int m = ULAM_ADJOINT; m <= ULAM_FORWARD; m++, c++) {
                if (!test_case(c)) continue;
                double q = alphas[a] == 1.0 ? 0.3 : 0.0;
                double *D = dense_moment(sy[k].M, m, alphas[a], q, 4), exact = dense_radius(D, sy[k].n);
                free(D);
                ulam_walk_opts o = ulam_walk_defaults();
                o.mode = m, o.query.index = 5, o.kernel.kernel_alpha = alphas[a], o.kernel.continue_q = q, o.stop.rel_err = 0.05;
                o.stop.max_walks = 1000000, o.exec.seed = 3;
                ulam_walk_result r;
                ulam_error err;
                int st = ulam_solve_walks(sy[k].M, sy[k].b, &o, &r, &err);
                print_message("system %d alpha %.1f Q %.1f %s: rho(M4) dense %.6g, certified [%.6g, %.6g], fourth %d, "
                              "met %d (%s)\n", k, alphas[a], q, m ? "forward" : "adjoint", exact, r.rho4.lower,
                              r.rho4.upper, r.fourth_finite, r.rel_err_met, st ? err.msg : "ran");
                if (st == ULAM_EINFVAR) continue; /* rho(M^) >= 1: the variance itself is infinite */
                assert_int_equal(st, ULAM_OK);
                assert_true(r.rho4.lower <= exact * (1 + 1e-9) && exact <= r.rho4.upper * (1 + 1e-9));
                assert_int_equal(r.fourth_finite, r.rho4.upper < 1.0 ? 1 : r.rho4.lower >= 1.0 ? 0 : -1);
                if (r.rel_err_met) assert_close(r.estimate, sy[k].x[5], 4 * r.std_error);
                finite += r.fourth_finite == 1, infinite += r.fourth_finite == 0;
            }
    test_case_done();
    if (test_case_all()) assert_true(finite >= 2 && infinite >= 2); /* both sides exercised */
    test_sys_free(&sy[0]), test_sys_free(&sy[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_radius),       cmocka_unit_test(test_agreement), cmocka_unit_test(test_exact_variance),
        cmocka_unit_test(test_verdict),      cmocka_unit_test(test_coverage), cmocka_unit_test(test_rel_err_fourth_coverage),  cmocka_unit_test(test_weight_bound),
        cmocka_unit_test(test_identical),    cmocka_unit_test(test_options), cmocka_unit_test(test_fourth_moment),
        cmocka_unit_test(test_fourth_radius),
    };
    return test_run(tests);
}
