/* Reverse push and the bidirectional estimator for point sources, against LAPACK.
 *
 * The push's invariant x_t = <p, b> + <r, x> is checked to rounding for several b; the
 * bidirectional estimate of x_t of (I - M) x = e_s within 4 sigma of LAPACK over a seeded table
 * of systems (case k draws from stream (k, 0): a failure prints k and reruns exactly); coverage
 * of its 95% interval over 200 seeds with a binomial bound.  A unit test built with the module
 * (tests/meson.build's module units): the push workspace and the bidirectional estimator on it
 * (ulam__push_*, ulam__bidir_solve, _plan) are the library's own, reached by its callers through
 * the method table (ulam_analysis_solve) and ulam_analysis_bidir. */
#include "analysis.h"
#include "bidir.h"
#include "bkrylov.h"
#include "push.h"
#include "stats.h"
#include "testutil.h"
#include "zipf_graph.h"

#include <string.h>

/* x = (I - M)^-1 e_s by LAPACK (a new array). */
static double *exact_column(const ulam_csr *M, int64_t s)
{
    int64_t n = M->nrows;
    double *b = calloc((size_t)n, sizeof *b), *x = malloc((size_t)n * sizeof *x);
    b[s] = 1.0;
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    free(b);
    return x;
}

/* Fail unless x_t = <p, b> + <r, x> to rounding for the workspace's state. */
static void assert_invariant(const ulam_push *w, const ulam_csr *M, int64_t t, const double *b, const double *x,
                             int k)
{
    const double *p = ulam__push_estimates(w), *r = ulam__push_residuals(w);
    double sum = 0, scale = fabs(x[t]);
    for (int64_t j = 0; j < M->nrows; j++) {
        sum += p[j] * b[j] + r[j] * x[j];
        scale += fabs(p[j] * b[j]) + fabs(r[j] * x[j]);
    }
    if (!(fabs(sum - x[t]) <= 1e-13 * scale + 1e-300))
        print_error("case %d: <p, b> + <r, x> = %.17g, x_t = %.17g\n", k, sum, x[t]);
    assert_close(sum, x[t], 1e-13 * scale + 1e-300);
}

/* The seeded table of systems: n, entries a row, signed, largest row sum of |M|. */
static const struct { int64_t n; int k, signed_; double rowsum; } systems[] = {
    {12, 3, 0, 0.9}, {40, 4, 1, 0.9}, {60, 2, 0, 0.95}, {80, 6, 1, 0.8}, {150, 5, 0, 0.85}, {30, 8, 1, 0.7},
    {50, 4, 0, 0.9995}, /* rows of |M| up to 1 - 5e-4: long walks, a push that converges slowly */
};
enum { NSYS = sizeof systems / sizeof systems[0] };

/* The invariant holds after every run of pushes, for three right-hand sides, at thresholds
 * falling from 0.5 to 1e-6; every residual is then at most rmax; a cap stops the push with
 * ULAM_ENOCONV and the invariant intact. */
static void test_push_invariant(void **state)
{
    (void)state;
    for (int k = 0; k < NSYS; k++) {
        if (!test_case(k)) continue;
        ulam_csr *M = test_random_system(systems[k].n, systems[k].k, systems[k].signed_, systems[k].rowsum, (uint64_t)k);
        int64_t n = M->nrows;
        ulam_rng rg;
        ulam_rng_seed(&rg, (uint64_t)k, 1);
        double *b[3], *x[3];
        for (int q = 0; q < 3; q++) {
            b[q] = malloc((size_t)n * sizeof *b[q]);
            x[q] = malloc((size_t)n * sizeof *x[q]);
            for (int64_t j = 0; j < n; j++) b[q][j] = q == 0 ? (j == 1) : ulam_rng_uniform(&rg) - (q == 2 ? 0.5 : 0);
            assert_int_equal(ulam_direct_solve(M, b[q], x[q], 0, NULL, NULL), ULAM_OK);
        }
        ulam_push *w = NULL;
        assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
        ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
        for (int64_t t = 0; t < n; t += n / 4) {
            assert_int_equal(ulam__push_start(w, t), ULAM_OK);
            for (int q = 0; q < 3; q++) assert_invariant(w, M, t, b[q], x[q], k);
            for (double rmax = 0.5; rmax >= 1e-6; rmax /= 7) {
                assert_int_equal(ulam__push_run(w, rmax, 0), ULAM_OK);
                ulam_push_info pi;
                ulam__push_report(w, &pi);
                assert_true(pi.r_max <= rmax);
                assert_true(pi.rmax == rmax && pi.target == t && pi.pushes > 0);
                for (int q = 0; q < 3; q++) assert_invariant(w, M, t, b[q], x[q], k);
            }
            assert_int_equal(ulam__push_start(w, t), ULAM_OK); /* a cap cuts a deep push short */
            assert_int_equal(ulam__push_run(w, 1e-12, 5), ULAM_ENOCONV);
            for (int q = 0; q < 3; q++) assert_invariant(w, M, t, b[q], x[q], k);
            assert_int_equal(ulam__push_run(w, 1e-12, 0), ULAM_OK); /* and goes on from there */
            for (int q = 0; q < 3; q++) assert_invariant(w, M, t, b[q], x[q], k);
        }
        for (int q = 0; q < 3; q++) free(b[q]), free(x[q]);
        ulam__push_free(w), ulam__bidir_free(w_memo);
        ulam_csr_free(M);
    }
    test_case_done();
}

/* Bad arguments are refused. */
static void test_push_bad_input(void **state)
{
    (void)state;
    ulam_csr *M = test_random_system(10, 2, 0, 0.9, 99), *R = ulam_csr_alloc(3, 4, 0);
    ulam_push *w = NULL;
    assert_int_equal(ulam__push_alloc(R, &w), ULAM_ENOTSQUARE);
    assert_null(w);
    assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
    ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
    assert_int_equal(ulam__push_run(w, 0.1, 0), ULAM_EINVAL); /* not started */
    assert_int_equal(ulam__push_start(w, 10), ULAM_EINVAL);
    assert_int_equal(ulam__push_start(w, -1), ULAM_EINVAL);
    assert_int_equal(ulam__push_start(w, 3), ULAM_OK);
    assert_int_equal(ulam__push_run(w, 0.0, 0), ULAM_EINVAL);
    assert_int_equal(ulam__push_run(w, -1.0, 0), ULAM_EINVAL);
    assert_int_equal(ulam__push_run(w, NAN, 0), ULAM_EINVAL);
    ulam_csr *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    ulam_bidir_opts o = ulam_bidir_defaults();
    ulam_bidir_result res;
    ulam_error err;
    o.source = 10;
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_EINVAL);
    assert_non_null(strstr(err.msg, "source"));
    o.source = 0, o.target = -1;
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_EINVAL);
    o.target = 0, o.rmax = INFINITY;
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_EINVAL);
    o.rmax = 0;
    assert_int_equal(ulam__bidir_solve(w, w_memo, R, &o, &res, &err), ULAM_EINVAL); /* not M's transpose */
    assert_null(ulam__push_free(NULL));
    ulam__push_free(w), ulam__bidir_free(w_memo);
    ulam_csr_free(M), ulam_csr_free(Mt), ulam_csr_free(R);
}

/* Run a bidirectional estimate; must succeed. */
static ulam_bidir_result bidir(const ulam_csr *M, const ulam_csr *Mt, const ulam_bidir_opts *o)
{
    ulam_push *w = NULL;
    assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
    ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
    ulam_bidir_result res;
    ulam_error err;
    int st = ulam__bidir_solve(w, w_memo, Mt, o, &res, &err);
    if (st) print_error("ulam__bidir_solve: %s: %s\n", ulam_strerror(st), err.msg);
    assert_int_equal(st, ULAM_OK);
    ulam__push_free(w), ulam__bidir_free(w_memo);
    return res;
}

/* Within 4 sigma of LAPACK on every system of the table, for a fixed rmax and the balanced one,
 * with the collision and expected estimators; the walks do part of the work (r != 0). */
static void test_bidir_unbiased(void **state)
{
    (void)state;
    static const double rmaxes[] = {0.3, 0.05, 0};
    for (int k = 0; k < NSYS; k++) {
        ulam_csr *M = test_random_system(systems[k].n, systems[k].k, systems[k].signed_, systems[k].rowsum, (uint64_t)k), *Mt = NULL;
        assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
        int64_t n = M->nrows, s = (k * 7 + 1) % n, t = (k * 3 + 2) % n;
        double *x = exact_column(M, s);
        for (int q = 0; q < 3; q++)
            for (int est = ULAM_COLLISION; est <= ULAM_EXPECTED; est += 2) {
                if (!test_case(1000L * k + 10 * q + est)) continue;
                ulam_bidir_opts o = ulam_bidir_defaults();
                o.source = s, o.target = t, o.rmax = rmaxes[q];
                o.walk.stop.max_walks = 20000, o.walk.estimator = est, o.walk.exec.seed = (uint64_t)(k * 10 + q);
                ulam_bidir_result res = bidir(M, Mt, &o);
                if (res.std_error == 0) { /* no residual left, or none the walks reach: exact */
                    assert_true(q == 2 || res.push.support > 0);
                    assert_close(res.estimate, x[t], 1e-12 * fabs(x[t]) + 1e-300);
                    continue;
                }
                double z = (res.estimate - x[t]) / (res.std_error + 1e-13 * fabs(x[t])); /* + LAPACK's rounding */
                if (!(fabs(z) < 4))
                    print_error("case %d rmax %g est %d: estimate %.10g, LAPACK %.10g, stderr %.3g (z = %.2f)\n", k,
                                rmaxes[q], est, res.estimate, x[t], res.std_error, z);
                assert_true(res.walks.walks == 20000);
                assert_true(fabs(z) < 4);
                assert_close(res.estimate - res.push_part, res.walks.estimate, 1e-15 * (fabs(res.estimate) + 1));
                /* the walks' interval (src/stop.h) about the estimate, never narrower than the CLT's, or
                   withheld (NaN: no certified range for the residual's scores) */
                assert_true(isnan(res.ci95[0]) ||
                            (res.ci95[0] <= res.estimate && res.estimate <= res.ci95[1] &&
                             res.ci95[1] - res.ci95[0] >= 2 * ULAM_Z95 * res.std_error * (1 - 1e-12)));
                assert_true(res.seconds >= res.push.seconds);
                if (q == 2) assert_true(res.plan.pilot_walks == 256 && res.plan.mean_visits >= 1);
            }
        free(x);
        ulam_csr_free(M), ulam_csr_free(Mt);
    }
    test_case_done();
}

/* The plan: the balance's rmax and push, the pilot, the predicted walks and work; a solve with
 * the same options reuses it (no push again, the same answer as a solve on a fresh workspace);
 * other options, or a push since, make the solve plan again; the plan is the same for any
 * thread count. */
static void test_bidir_plan(void **state)
{
    (void)state;
    ulam_csr *M = test_random_system(150, 5, 0, 0.85, 4), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.source = 3, o.target = 10, o.walk.stop.max_walks = 0, o.walk.stop.rel_err = 0.05, o.walk.exec.threads = 1;
    ulam_push *w = NULL, *fresh = NULL;
    assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
    ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
    assert_int_equal(ulam__push_alloc(M, &fresh), ULAM_OK);
    ulam__bidir *fresh_memo = ulam__bidir_alloc(); /* its plan memo */
    ulam_bidir_plan_info plan, again;
    ulam_error err;
    assert_int_equal(ulam__bidir_plan(w, w_memo, Mt, &o, &plan, &err), ULAM_OK);
    ulam_push_info pi;
    ulam__push_report(w, &pi);
    assert_true(plan.balanced && plan.target == 10 && plan.rmax == pi.rmax && plan.push.ops == pi.ops && pi.ops > 0);
    assert_true(pi.r_max <= plan.rmax && plan.push_part == ulam__push_estimates(w)[3]);
    assert_true(plan.pilot_walks == 256 && plan.mean_visits == 1.0 + (double)plan.pilot_steps / 256.0);
    assert_true(plan.predicted_walks >= ULAM__REL_FIRST && isfinite(plan.predicted_walks)); /* the rule's first check */
    assert_close(plan.predicted_work, (double)plan.push.ops + plan.step_cost * ((double)(256 + plan.pilot_steps) +
                                      plan.predicted_walks * plan.mean_visits), 1e-9 * plan.predicted_work);
    ulam_bidir_result res, ref;
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_OK);
    print_message("plan: rmax %g, %lld push operations, %g walks predicted; the solve ran %lld\n", plan.rmax,
                  (long long)plan.push.ops, plan.predicted_walks, (long long)res.walks.walks);
    assert_true(res.plan_reused && res.push.ops == plan.push.ops && res.push.pushes == plan.push.pushes);
    assert_memory_equal(&res.plan.predicted_work, &plan.predicted_work, sizeof plan.predicted_work);
    assert_int_equal(ulam__bidir_solve(fresh, fresh_memo, Mt, &o, &ref, &err), ULAM_OK); /* plans inside */
    assert_false(ref.plan_reused);
    assert_memory_equal(&res.estimate, &ref.estimate, sizeof res.estimate);
    assert_memory_equal(&res.std_error, &ref.std_error, sizeof res.std_error);
    assert_true(ref.plan.rmax == plan.rmax && ref.plan.push.ops == plan.push.ops && ref.walks.walks == res.walks.walks);
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_OK); /* still the plan in place */
    assert_true(res.plan_reused);
    o.walk.kernel.kernel_alpha = 2.0; /* another kernel exponent: its walks' plan is another (issue 29) */
    int st = ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err);
    assert_true(st != ULAM_OK || !res.plan_reused);
    o.walk.kernel.kernel_alpha = 1.0;
    o.walk.exec.seed = 2; /* another pilot: plan again */
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_OK);
    assert_false(res.plan_reused);
    assert_int_equal(ulam__bidir_plan(w, w_memo, Mt, &o, &plan, &err), ULAM_OK);
    assert_int_equal(ulam__push_run(w, plan.rmax / 2, 0), ULAM_OK); /* the push moved on: plan again */
    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_OK);
    assert_false(res.plan_reused);
    assert_true(res.push.rmax == plan.rmax && res.push.ops == plan.push.ops);
    o.walk.exec.threads = 2;
    assert_int_equal(ulam__bidir_plan(w, w_memo, Mt, &o, &again, &err), ULAM_OK);
    assert_true(again.rmax == plan.rmax && again.push.ops == plan.push.ops && again.pilot_steps == plan.pilot_steps);
    assert_memory_equal(&again.predicted_work, &plan.predicted_work, sizeof plan.predicted_work);
    o.rmax = 0.01, o.walk.stop.rel_err = 0, o.walk.stop.max_walks = 5000; /* given rmax: no pilot, walks known */
    assert_int_equal(ulam__bidir_plan(w, w_memo, Mt, &o, &plan, &err), ULAM_OK);
    assert_true(!plan.balanced && plan.pilot_walks == 0 && plan.rmax == 0.01 && plan.predicted_walks == 5000);
    assert_true(isnan(plan.predicted_work)); /* V unknown */
    o.walk.stop.rel_err = 0.05, o.walk.stop.max_walks = 0;
    assert_int_equal(ulam__bidir_plan(w, w_memo, Mt, &o, &plan, &err), ULAM_OK);
    assert_true(isnan(plan.predicted_walks) && isnan(plan.predicted_work)); /* no pilot measured V */
    o.source = 150;
    assert_int_equal(ulam__bidir_plan(w, w_memo, Mt, &o, &plan, &err), ULAM_EINVAL);
    assert_int_equal(ulam__bidir_plan(NULL, NULL, Mt, &o, &plan, &err), ULAM_EINVAL);
    ulam__push_free(w), ulam__bidir_free(w_memo), ulam__push_free(fresh), ulam__bidir_free(fresh_memo);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* Two kernel exponents through one analysis must not share a plan (issue 29: the plan memo
 * once ignored the exponent, so a plan made for alpha 1 -- its pilot, rmax and the pilot's
 * guards -- served alpha 2's walks).  On an analysis' transpose and push workspace a plan made
 * for alpha 1 is reused by the same options and not by alpha 2, whose estimate is bit for bit a
 * fresh workspace's at alpha 2. */
static void test_analysis_bidir_exponent(void **state)
{
    (void)state;
    ulam_csr *M = test_random_system(150, 5, 0, 0.85, 4), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    ulam_analysis *a = NULL;
    ulam_error err;
    assert_int_equal(ulam_analysis_alloc(M, NULL, &a, &err), ULAM_OK);
    const ulam_csr *T = ulam_analysis_transpose(a, &err);
    ulam_push *w = ulam__analysis_push(a, &err);
    assert_non_null(T);
    assert_non_null(w);
    ulam__bidir *w_memo = ulam__bidir_alloc(); /* a plan memo of its own on the analysis' workspace */
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.source = 3, o.target = 10, o.walk.stop.max_walks = 4000, o.walk.stop.rel_err = 0, o.walk.exec.threads = 1;
    ulam_bidir_plan_info plan;
    ulam_bidir_result one, two, ref;
    assert_int_equal(ulam__bidir_plan(w, w_memo, T, &o, &plan, &err), ULAM_OK);
    assert_int_equal(ulam__bidir_solve(w, w_memo, T, &o, &one, &err), ULAM_OK);
    assert_true(one.plan_reused); /* the same options: the plan in place */
    ulam_bidir_opts o2 = o;
    o2.walk.kernel.kernel_alpha = 2.0;
    assert_int_equal(ulam__bidir_solve(w, w_memo, T, &o2, &two, &err), ULAM_OK);
    assert_false(two.plan_reused); /* another exponent: another plan */
    ulam_push *fresh = NULL;
    assert_int_equal(ulam__push_alloc(M, &fresh), ULAM_OK);
    ulam__bidir *fresh_memo = ulam__bidir_alloc(); /* its plan memo */
    assert_int_equal(ulam__bidir_solve(fresh, fresh_memo, Mt, &o2, &ref, &err), ULAM_OK);
    assert_memory_equal(&two.estimate, &ref.estimate, sizeof ref.estimate);
    assert_memory_equal(&two.std_error, &ref.std_error, sizeof ref.std_error);
    assert_true(two.plan.rmax == ref.plan.rmax && two.plan.pilot_steps == ref.plan.pilot_steps);
    /* ulam_analysis_bidir: its own memo on the analysis' transpose and push; the analysis' kernel only */
    assert_int_equal(ulam_analysis_bidir(a, &o2, &two, &err), ULAM_EINVAL); /* alpha 2 on alpha 1's analysis */
    ulam_bidir_result three, four;
    assert_int_equal(ulam_analysis_bidir(a, &o, &three, &err), ULAM_OK);
    assert_false(three.plan_reused); /* the analysis' memo held no plan: planned (the same plan) */
    assert_int_equal(ulam_analysis_bidir(a, &o, &four, &err), ULAM_OK);
    assert_true(four.plan_reused);
    assert_memory_equal(&three.estimate, &one.estimate, sizeof one.estimate); /* a fresh plan's walks */
    assert_memory_equal(&four.estimate, &one.estimate, sizeof one.estimate);
    assert_ptr_equal(ulam_analysis_transpose(a, &err), T); /* made once */
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.kernel_alpha = 2.0;
    ulam_analysis *a2 = NULL;
    assert_int_equal(ulam_analysis_alloc(M, &ao, &a2, &err), ULAM_OK);
    assert_int_equal(ulam_analysis_bidir(a2, &o2, &three, &err), ULAM_OK);
    assert_false(three.plan_reused);
    assert_memory_equal(&three.estimate, &ref.estimate, sizeof ref.estimate);
    assert_memory_equal(&three.std_error, &ref.std_error, sizeof ref.std_error);
    ulam_analysis_free(a2);
    /* the method table's bidirectional row on an analysis (ulam_analysis_start): its
       transpose, made by the first query, serves the second (no time spent making it), and the
       answers are those of a run without an analysis (bit for bit) */
    double *bv = calloc(150, sizeof *bv);
    bv[3] = 1.0, bv[40] = -0.5;
    ulam_walk_opts wo = ulam_walk_defaults();
    wo.query.index = 10, wo.stop.max_walks = 0, wo.stop.rel_err = 0.05, wo.exec.threads = 1;
    ulam_method_opts mo = ulam_method_defaults();
    mo.method = ULAM_METHOD_BIDIRECTIONAL;
    ulam_analysis *a3 = NULL;
    assert_int_equal(ulam_analysis_alloc(M, NULL, &a3, &err), ULAM_OK);
    for (int k = 0; k < 2; k++) {
        ulam_choice ch, cref;
        ulam_run *run = NULL;
        ulam_answer ans, aref;
        wo.exec.seed = (uint64_t)k + 1;
        assert_int_equal(ulam_analysis_start(a3, bv, &wo, NULL, &mo, &ch, &run, &err), ULAM_OK);
        assert_int_equal(ulam_run_finish(run, &ans, &err), ULAM_OK);
        ulam_run_free(run);
        assert_int_equal(ulam_auto(M, bv, &wo, NULL, &mo, &cref, &aref, &err), ULAM_OK);
        assert_true(ans.method == ULAM_METHOD_BIDIRECTIONAL && aref.method == ULAM_METHOD_BIDIRECTIONAL);
        assert_memory_equal(&ans.estimate, &aref.estimate, sizeof ans.estimate);
        assert_memory_equal(&ans.std_error, &aref.std_error, sizeof ans.std_error);
        if (k == 1) assert_true(ch.transpose_seconds == 0.0 && cref.transpose_seconds > 0.0);
    }
    ulam_analysis_free(a3);
    ulam__bidir_free(w_memo);
    free(bv);
    ulam__push_free(fresh), ulam__bidir_free(fresh_memo);
    ulam_analysis_free(a);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* The walk solver's start distribution (ulam_walk_opts.starts, what the sparse-b walks use):
 * <c, x> within 4 sigma of LAPACK for the three estimators and under a rel_err rule (which
 * must stop), and refused in forward mode, with a state out of range or all-zero weights. */
static void test_solver_starts(void **state)
{
    (void)state;
    ulam_csr *M = test_random_system(60, 4, 1, 0.85, 7);
    int64_t n = M->nrows, st[3] = {5, 17, 5};
    double c[3] = {0.5, -2.0, 0.25}, *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
    for (int64_t i = 0; i < n; i++) b[i] = 1.0 + (double)(i % 5) / 4.0;
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    double exact = 0.75 * x[5] - 2.0 * x[17];
    for (int k = 0; k < 4; k++) { /* case k: estimators 0..2, then collision with rel_err 0.02 */
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.nstarts = 3, o.query.starts = st, o.query.start_weights = c, o.exec.seed = (uint64_t)k + 1;
        o.estimator = k < 3 ? k : ULAM_COLLISION, o.stop.max_walks = k < 3 ? 40000 : 0, o.stop.rel_err = k < 3 ? 0 : 0.02;
        ulam_walk_result r;
        ulam_error err;
        int st_ = ulam_solve_walks(M, b, &o, &r, &err);
        if (st_ || !(fabs(r.estimate - exact) < 4 * r.std_error))
            print_error("case %d: %s, %.8g +- %.3g, exact %.8g\n", k, ulam_strerror(st_), r.estimate, r.std_error, exact);
        assert_int_equal(st_, ULAM_OK);
        assert_true(fabs(r.estimate - exact) < 4 * r.std_error);
        if (k == 3) assert_true(r.rel_err_met && r.std_error <= 0.02 * fabs(r.estimate));
    }
    ulam_walk_opts o = ulam_walk_defaults();
    ulam_walk_result r;
    ulam_error err;
    double zeros[3] = {0, 0, 0};
    int64_t bad[3] = {5, 60, 1};
    o.query.nstarts = 3, o.query.starts = st, o.query.start_weights = c, o.mode = ULAM_FORWARD;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_EINVAL);
    o.mode = ULAM_ADJOINT, o.query.starts = bad;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_EINVAL);
    o.query.starts = st, o.query.start_weights = zeros;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_EINVAL);
    free(b), free(x);
    ulam_csr_free(M);
}

/* A sparse b of 3 entries with mixed signs: x_t = <p, b> + <r, x> with walks started at b's
 * states in proportion to |b_j|, signed weights ||b||_1: within 4 sigma of LAPACK on systems of
 * the table (fixed and balanced rmax, collision and expected), the push's invariant exact for
 * that b, the result the same for any thread count, bad entries refused. */
static void test_bidir_sparse_b(void **state)
{
    (void)state;
    static const double rmaxes[] = {0.05, 0};
    for (int k = 0; k < NSYS - 1; k++) { /* the long walks of the last system: test_bidir_unbiased */
        ulam_csr *M = test_random_system(systems[k].n, systems[k].k, systems[k].signed_, systems[k].rowsum, (uint64_t)k), *Mt = NULL;
        assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
        int64_t n = M->nrows, t = (k * 3 + 2) % n;
        int64_t idx[3] = {(k * 7 + 1) % n, (k * 5 + 4) % n, (k * 11 + 6) % n};
        double val[3] = {0.7, -1.3, 0.4};
        double *b = calloc((size_t)n, sizeof *b), *x = malloc((size_t)n * sizeof *x);
        for (int j = 0; j < 3; j++) b[idx[j]] += val[j];
        assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
        ulam_push *w = NULL;
        assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
        ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
        for (int q = 0; q < 2; q++)
            for (int est = ULAM_COLLISION; est <= ULAM_EXPECTED; est += 2) {
                ulam_bidir_opts o = ulam_bidir_defaults();
                o.target = t, o.nb = 3, o.b_index = idx, o.b_value = val, o.rmax = rmaxes[q];
                o.walk.stop.max_walks = 20000, o.walk.estimator = est, o.walk.exec.seed = (uint64_t)(k * 10 + q + 100);
                ulam_bidir_result res;
                ulam_error err;
                int st = ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err);
                if (st) print_error("case %d: %s: %s\n", k, ulam_strerror(st), err.msg);
                assert_int_equal(st, ULAM_OK);
                assert_invariant(w, M, t, b, x, k);
                assert_close(res.push_part, 0.7 * ulam__push_estimates(w)[idx[0]] - 1.3 * ulam__push_estimates(w)[idx[1]] +
                             0.4 * ulam__push_estimates(w)[idx[2]], 1e-15);
                if (res.std_error == 0) { /* no residual the walks reach: exact */
                    assert_close(res.estimate, x[t], 1e-12 * fabs(x[t]) + 1e-300);
                    continue;
                }
                double z = (res.estimate - x[t]) / (res.std_error + 1e-13 * fabs(x[t]));
                if (!(fabs(z) < 4))
                    print_error("case %d rmax %g est %d: estimate %.10g, LAPACK %.10g, stderr %.3g (z = %.2f)\n", k,
                                rmaxes[q], est, res.estimate, x[t], res.std_error, z);
                assert_true(fabs(z) < 4 && res.walks.walks == 20000);
                if (k == 1 && q == 1 && est == ULAM_COLLISION) { /* any thread count, the same answer */
                    ulam_bidir_result two;
                    o.walk.exec.threads = 2;
                    assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &two, &err), ULAM_OK);
                    assert_memory_equal(&two.estimate, &res.estimate, sizeof res.estimate);
                    assert_memory_equal(&two.std_error, &res.std_error, sizeof res.std_error);
                }
            }
        ulam_bidir_opts o = ulam_bidir_defaults();
        ulam_bidir_result res;
        ulam_error err;
        int64_t bad_idx[2] = {0, n};
        double zeros[2] = {0, 0}, nan_val[2] = {1, NAN};
        o.target = t, o.nb = 2, o.b_index = bad_idx, o.b_value = val;
        assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_EINVAL); /* index n */
        o.b_index = idx, o.b_value = zeros;
        assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_EINVAL); /* ||b||_1 = 0 */
        o.b_value = nan_val;
        assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_EINVAL);
        ulam__push_free(w), ulam__bidir_free(w_memo);
        free(b), free(x);
        ulam_csr_free(M), ulam_csr_free(Mt);
    }
}

/* Over 200 seeds the 95% interval covers the LAPACK value 180 to 198 times (Bin(200, 0.95) falls
 * outside with probability about 0.002), with a threshold that leaves most of the value to the walks. */
static void test_bidir_coverage(void **state)
{
    (void)state;
    ulam_csr *M = test_random_system(40, 4, 1, 0.9, 1), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = exact_column(M, 5);
    int covered = 0, printed = 0;
    double push_part = 0;
    for (int seed = 0; seed < 200; seed++) { /* case seed: reruns exactly */
        if (!test_case(seed)) continue;
        ulam_bidir_opts o = ulam_bidir_defaults();
        o.source = 5, o.target = 17, o.rmax = 0.2;
        o.walk.stop.max_walks = 2000, o.walk.exec.seed = (uint64_t)seed;
        ulam_bidir_result res = bidir(M, Mt, &o);
        covered += fabs(res.estimate - x[17]) <= ULAM_Z95 * res.std_error; /* the walks' own check */
        printed += res.ci95[0] <= x[17] && x[17] <= res.ci95[1]; /* src/stop.h's interval: conservative */
        push_part = res.push_part;
    }
    test_case_done();
    if (test_case_all()) { /* the count over seeds (one case alone: none) */
        print_message("-+ 1.96 stderr covered the LAPACK value %d / 200 times, the printed interval %d (x = %.6g, push "
                      "part %.6g)\n", covered, printed, x[17], push_part);
        assert_true(fabs(push_part - x[17]) > 0.1 * fabs(x[17]));
        assert_in_range(covered, 180, 198);
        assert_true(printed >= 180);
    }
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* M_ij = 0.3 for j = i + 1, i + 2 over 7 states: nilpotent, so every push ends with r = 0. */
static ulam_csr *nilpotent(void)
{
    int32_t ti[] = {0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5}, tj[] = {1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6};
    double tx[] = {0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3};
    ulam_csr *N = NULL;
    assert_int_equal(ulam_csr_from_triplets(7, 7, 11, ti, tj, tx, &N), ULAM_OK);
    return N;
}

/* A push that leaves no residual is exact (no walks, zero stderr); a --rel-err rule stops on the
 * whole estimate p_s + <r, x>; the result does not depend on the thread count. */
static void test_bidir_rules(void **state)
{
    (void)state;
    ulam_csr *N = nilpotent(), *Nt = NULL; /* the push from 1 ends with r = 0 */
    assert_int_equal(ulam_csr_transpose(N, &Nt), ULAM_OK);
    double *xn = exact_column(N, 5);
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.source = 5, o.target = 1, o.rmax = 1e-3;
    ulam_bidir_result res = bidir(N, Nt, &o);
    assert_true(res.push.support == 0 && res.walks.walks == 0 && res.std_error == 0);
    assert_close(res.estimate, xn[1], 1e-15);
    assert_true(xn[1] > 0.1);
    free(xn);
    ulam_csr_free(N), ulam_csr_free(Nt);
    /* M' has rows summing to 0.9, so the walks on it carry weights that never grow and the
     * rel_err rule has a bound on a single score (with M's rows at 0.9 instead, M' has column
     * sums above 1 on cycles: no score bound, and rel_err alone stops as out of reach) */
    ulam_csr *Mt = test_random_system(80, 6, 0, 0.9, 3), *M = NULL;
    assert_int_equal(ulam_csr_transpose(Mt, &M), ULAM_OK);
    double *x = exact_column(M, 3);
    o = ulam_bidir_defaults();
    o.source = 3, o.target = 10, o.rmax = 0.05, o.walk.stop.max_walks = 0, o.walk.stop.rel_err = 0.01;
    res = bidir(M, Mt, &o);
    print_message("rel-err 0.01: %lld walks, relative error %.3g\n", (long long)res.walks.walks,
                  res.std_error / fabs(res.estimate));
    assert_true(res.walks.walks >= 1000 && res.std_error <= 0.01 * fabs(res.estimate));
    /* stopped by the rule: its range-term minimum (here above what the standard error needs) */
    assert_true(res.walks.rel_err_met && res.walks.walks >= res.walks.min_walks && res.walks.min_walks > 1024);
    assert_true(fabs(res.estimate - x[10]) < 4 * res.std_error);
    o.rmax = 0, o.walk.stop.rel_err = 0, o.walk.stop.max_walks = 5000, o.walk.exec.threads = 1;
    ulam_bidir_result one = bidir(M, Mt, &o);
    o.walk.exec.threads = 2;
    ulam_bidir_result two = bidir(M, Mt, &o);
    assert_memory_equal(&one.estimate, &two.estimate, sizeof one.estimate);
    assert_memory_equal(&one.std_error, &two.std_error, sizeof one.std_error);
    assert_true(one.push.rmax == two.push.rmax && one.push.pushes == two.push.pushes);
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* A --rel-err run ends when the walks cannot score anything but one value: no residual state
 * reachable from the source (the walk part is exactly 0), or a source without moves whose own
 * residual is all a walk scores.  Before, every walk scored the same forever and the run never
 * stopped (a zero sample variance no longer stops it, test_bidir_rare_score). */
static void test_bidir_deterministic_walks(void **state)
{
    (void)state;
    ulam_csr *N = nilpotent(), *Nt = NULL; /* x_t = 0 for t > s; N' has no moves from 0 */
    assert_int_equal(ulam_csr_transpose(N, &Nt), ULAM_OK);
    static const struct { int64_t s, t; double rmax; int est; } cases[] = {
        {1, 5, 2, ULAM_COLLISION}, /* no push; walks from 1 on N' never reach 5: x = 0 exactly */
        {1, 5, 2, ULAM_EXPECTED},  {1, 5, 2, ULAM_ABSORPTION},
        {0, 0, 2, ULAM_COLLISION}, /* walks from 0 on N' have no moves and score r_0 = 1: x = 1 */
    };
    for (int k = 0; k < 4; k++) { /* case k */
        if (!test_case(k)) continue;
        double *x = exact_column(N, cases[k].s);
        ulam_bidir_opts o = ulam_bidir_defaults();
        o.source = cases[k].s, o.target = cases[k].t, o.rmax = cases[k].rmax, o.walk.estimator = cases[k].est;
        o.walk.stop.max_walks = 0, o.walk.stop.rel_err = 0.1;
        ulam_bidir_result res = bidir(N, Nt, &o);
        if (!(res.std_error == 0 && res.estimate == x[cases[k].t]))
            print_error("case %d: %.6g +- %.3g, exact %.6g\n", k, res.estimate, res.std_error, x[cases[k].t]);
        assert_true(res.std_error == 0 && res.estimate == x[cases[k].t] && res.walks.walks >= 256); /* a first round */
        free(x);
    }
    test_case_done();
    ulam_csr_free(N), ulam_csr_free(Nt);
}

/* A push taken down to rounding (rmax 1e-19 on a 600-state Zipf PageRank graph: <p, b> is x_t
 * but for the roundings of ~10^5 operations, the residual ~1e-17, the walks' interval ~1e-22
 * wide): every interval still holds LAPACK's x_t, with the allowance for the arithmetic's error,
 * and is at most 1e-8 |x_t| wide either side.  Before, 0.2200611274 +- 3.85e-22 missed the
 * exact value by 1.3 ulp (z = -144216) on such a graph. */
static void test_bidir_rounding(void **state)
{
    (void)state;
    int64_t n = 600, s = 3;
    ulam_csr *M = zipf_graph(n, 2.1, 0.75, 0.85, 7), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = exact_column(M, s);
    int tried = 0;
    for (int64_t t = 0; t < n && tried < 40; t++) {
        if (!(x[t] > 1e-6)) continue;
        tried++;
        if (!test_case(tried)) continue;
        ulam_bidir_opts o = ulam_bidir_defaults();
        o.source = s, o.target = t, o.rmax = 1e-19, o.walk.exec.seed = (uint64_t)t + 1;
        o.walk.stop.max_walks = 0, o.walk.stop.rel_err = 0.1;
        ulam_bidir_result res = bidir(M, Mt, &o);
        if (!(res.ci95[0] <= x[t] && x[t] <= res.ci95[1]))
            print_error("case %d (t %lld): %.17g in [%.17g, %.17g]? exact %.17g\n", tried, (long long)t, res.estimate,
                        res.ci95[0], res.ci95[1], x[t]);
        assert_true(res.ci95[0] <= x[t] && x[t] <= res.ci95[1]);
        assert_true(res.ci95[1] - res.estimate <= 1e-8 * x[t] && res.estimate - res.ci95[0] <= 1e-8 * x[t]);
    }
    test_case_done();
    assert_true(tried >= 20);
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* The time rule stops a run with no walk cap (its first block whole), and a run of a handful of
 * walks reports what it has: an estimate within 4 sigma when the walks scored differently. */
static void test_bidir_small_budgets(void **state)
{
    (void)state;
    ulam_csr *M = test_random_system(80, 6, 0, 0.9, 3), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = exact_column(M, 3);
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.source = 3, o.target = 10, o.rmax = 0.05, o.walk.stop.max_walks = 0, o.walk.stop.max_seconds = 1e-6;
    ulam_bidir_result res = bidir(M, Mt, &o);
    assert_true(res.walks.walks >= 1 && res.walks.walks <= 1024 && isfinite(res.estimate));
    assert_true(fabs(res.estimate - x[10]) < 4 * res.std_error);
    for (int64_t walks = 1; walks <= 16; walks *= 4) {
        if (!test_case(walks)) continue;
        o.walk.stop.max_seconds = 0, o.walk.stop.max_walks = walks;
        res = bidir(M, Mt, &o);
        assert_true(res.walks.walks == walks && isfinite(res.estimate));
        if (walks > 1 && res.std_error > 0) assert_true(fabs(res.estimate - x[10]) < 4 * res.std_error);
    }
    test_case_done();
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* A rare score does not stop a --rel-err run at 0 +- 0: walks from 1 reach the target 0 with
 * probability 0.001, so the first 1024 often all score 0 (zero sample variance). */
static void test_bidir_rare_score(void **state)
{
    (void)state;
    int32_t ti[] = {0, 1}, tj[] = {1, 1};
    double tx[] = {0.001, 0.5};
    ulam_csr *M = NULL, *Mt = NULL;
    assert_int_equal(ulam_csr_from_triplets(2, 2, 2, ti, tj, tx, &M), ULAM_OK);
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = exact_column(M, 1);
    for (int seed = 0; seed < 10; seed++) { /* case seed */
        if (!test_case(seed)) continue;
        ulam_bidir_opts o = ulam_bidir_defaults();
        o.source = 1, o.target = 0, o.rmax = 2; /* no push: every score is a walk's */
        o.walk.stop.max_walks = 0, o.walk.stop.rel_err = 0.1, o.walk.exec.seed = (uint64_t)seed;
        ulam_bidir_result res = bidir(M, Mt, &o);
        if (!(res.std_error > 0 && fabs(res.estimate - x[0]) < 4 * res.std_error))
            print_error("seed %d: %.6g +- %.3g after %lld walks, exact %.6g\n", seed, res.estimate, res.std_error,
                        (long long)res.walks.walks, x[0]);
        assert_true(res.std_error > 0 && res.std_error <= 0.1 * res.estimate);
        assert_true(fabs(res.estimate - x[0]) < 4 * res.std_error);
    }
    test_case_done();
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* reach_all: bounds over every state, made once in the workspace and shared by later queries;
 * keep_kernel: the walks' kernel rows kept there and rescored to each query's residual (the
 * expected estimator keeps none).
 * Queries (several targets and sources, balanced rmax, rel_err 0.1, the three estimators) on
 * one shared workspace
 * are within 4 sigma of LAPACK, and where the bounds over the source's reach equal those over
 * every state (the table's systems: random rows reach every state) they are bit for bit the
 * run with a search a query on a fresh workspace (case 202 too, where x_t = 0 and the push finds
 * nothing: the solver searches once its estimate is still 0, and stops at once, certified); on a block-diagonal M (the source's block reaches half of
 * the states, the other block's rows sum higher, so the bounds are looser and the balance may
 * choose another rmax) still within 4 sigma and the rule met. */
static void test_bidir_reach_all(void **state)
{
    (void)state;
    for (int k = 0; k < NSYS + 1; k++) {
        ulam_csr *M = NULL, *Mt = NULL;
        int block = k == NSYS;
        if (!block) M = test_random_system(systems[k].n, systems[k].k, systems[k].signed_, systems[k].rowsum, (uint64_t)k);
        else { /* two random blocks of 30 states, the second's rows summing up to 0.95 */
            ulam_csr *A = test_random_system(30, 4, 0, 0.6, 7), *B = test_random_system(30, 4, 0, 0.95, 8);
            int64_t nz = ulam_csr_nnz(A) + ulam_csr_nnz(B), e = 0;
            int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
            double *tx = malloc((size_t)nz * sizeof *tx);
            for (int h = 0; h < 2; h++)
                for (int64_t i = 0; i < 30; i++) {
                    const ulam_csr *C = h ? B : A;
                    for (int64_t q = C->rowptr[i]; q < C->rowptr[i + 1]; q++, e++)
                        ti[e] = (int32_t)(i + 30 * h), tj[e] = C->colidx[q] + 30 * h, tx[e] = C->val[q];
                }
            assert_int_equal(ulam_csr_from_triplets(60, 60, nz, ti, tj, tx, &M), ULAM_OK);
            free(ti), free(tj), free(tx);
            ulam_csr_free(A), ulam_csr_free(B);
        }
        assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
        int64_t n = M->nrows;
        ulam_push *shared = NULL;
        assert_int_equal(ulam__push_alloc(M, &shared), ULAM_OK);
        ulam__bidir *shared_memo = ulam__bidir_alloc(); /* its plan memo */
        for (int qe = 0; qe < 12; qe++) { /* collision, absorption, expected: 4 queries each (a kernel kept 4) */
            int q = qe % 4, est = qe < 4 ? ULAM_COLLISION : qe < 8 ? ULAM_ABSORPTION : ULAM_EXPECTED;
            if (!test_case(100L * k + qe)) continue;
            int64_t s = (k * 7 + 5 * q + 1) % (block ? 30 : n), t = (k * 3 + 11 * q + 2) % (block ? 30 : n);
            double *x = exact_column(M, s);
            ulam_bidir_opts o = ulam_bidir_defaults();
            o.source = s, o.target = t;
            o.walk.stop.max_walks = 0, o.walk.stop.rel_err = 0.1, o.walk.exec.seed = (uint64_t)(k * 10 + q + 1);
            o.walk.estimator = est, o.reach_all = 1, o.keep_kernel = 1;
            if (est == ULAM_ABSORPTION) o.walk.kernel.continue_q = 0.9; /* rows of M' may sum past 1: p* = 0.1 */
            ulam_bidir_result res;
            ulam_error err;
            int st = ulam__bidir_solve(shared, shared_memo, Mt, &o, &res, &err);
            if (st) print_error("case %d: %s: %s\n", 100 * k + qe, ulam_strerror(st), err.msg);
            assert_int_equal(st, ULAM_OK);
            double z = (res.estimate - x[t]) / (res.std_error + 1e-13 * fabs(x[t]) + 1e-300);
            if (!(fabs(z) < 4))
                print_error("case %d: estimate %.10g, LAPACK %.10g, stderr %.3g (z = %.2f), %lld walks, push support %lld\n",
                            100 * k + qe, res.estimate, x[t], res.std_error, z, (long long)res.walks.walks,
                            (long long)res.push.support);
            /* walks that all scored alike (stderr 0; case 204 at rmax 0.5: 256 walks of absorption that
             * never scored): the interval, on the certified range, must hold x_t */
            int zero = res.std_error == 0.0 && res.ci95[0] <= x[t] && x[t] <= res.ci95[1];
            if (!(fabs(z) < 4)) print_error("case %d: ci %.10g .. %.10g\n", 100 * k + qe, res.ci95[0], res.ci95[1]);
            assert_true(fabs(z) < 4 || zero);
            if (!(res.push.support == 0 || res.walks.rel_err_met))
                print_error("case %d: %lld walks, stderr %.3g, estimate %.6g, out of reach %d, cut stop %d\n",
                            100 * k + qe, (long long)res.walks.walks, res.std_error, res.estimate, res.walks.out_of_reach,
                            res.walks.cut_stop);
            assert_true(res.push.support == 0 || res.walks.rel_err_met);
            o.reach_all = o.keep_kernel = 0;
            ulam_bidir_result one = bidir(M, Mt, &o); /* a search a query, fresh workspace */
            if (!block) {
                if (res.estimate != one.estimate || res.walks.walks != one.walks.walks)
                    print_error("case %d: shared %.17g (%lld walks), one query %.17g (%lld)\n", 100 * k + qe,
                                res.estimate, (long long)res.walks.walks, one.estimate, (long long)one.walks.walks);
                assert_true(res.estimate == one.estimate && res.std_error == one.std_error);
                assert_true(res.walks.walks == one.walks.walks);
            }
            free(x);
        }
        ulam__push_free(shared), ulam__bidir_free(shared_memo);
        ulam_csr_free(M), ulam_csr_free(Mt);
    }
    test_case_done();
}

/* Issue 25 case 3: M = 0.85 P' of a 5000-node heavy-tailed digraph (zipf_graph.h), source 2, the
 * target whose x_t is nearest 0.0028, 100 walks.  The balance used to stop at rmax = 1 (no push:
 * the 1000-walk floor of the rel_err rule, which a fixed walk count does not have), and a run
 * whose walks missed the target printed 0 +- 0: 18/100 covered.  Now the push spends what the
 * walks do (rmax 1/64), and over 200 seeds at least 180 collision intervals cover (Bin(200,
 * 0.95) falls below 180 with probability about 0.002; we measured 184), none zero-width; the
 * absorption walks' scores have a certified range (score_bound), so theirs is the
 * empirical-Bernstein interval (valid at any n): at least 95 of 100 cover.  With the push
 * forbidden (rmax 2), a sample that saw nothing gets the certified bound of the walk part, never
 * a zero-width interval. */
static void test_bidir_fixed_walks_honest(void **state)
{
    (void)state;
    ulam_csr *M = zipf_graph(5000, 2.1, 0.75, 0.85, 1), *Mt = NULL;
    assert_non_null(M);
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = zipf_graph_column(M, 2), best = INFINITY;
    int64_t t = -1;
    for (int64_t i = 0; i < 5000; i++)
        if (i != 2 && x[i] > 0 && fabs(log(x[i] / 0.0028)) < best) best = fabs(log(x[i] / 0.0028)), t = i;
    assert_true(x[t] > 0.002 && x[t] < 0.004);
    ulam_push *w = NULL;
    assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
    ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
    static const struct { int est, seeds, need; double rmax; } cases[] = {
        {ULAM_COLLISION, 200, 180, 0}, {ULAM_ABSORPTION, 100, 95, 0}, {ULAM_COLLISION, 100, 90, 2}};
    for (int c = 0; c < 3; c++) {
        if (!test_case(c)) continue;
        int covered = 0, zero = 0, blind = 0;
        double rmax = 0;
        for (int seed = 0; seed < cases[c].seeds; seed++) {
            ulam_bidir_opts o = ulam_bidir_defaults();
            o.source = 2, o.target = t, o.rmax = cases[c].rmax;
            o.walk.stop.max_walks = 100, o.walk.exec.seed = (uint64_t)seed, o.walk.estimator = cases[c].est;
            ulam_bidir_result res;
            ulam_error err;
            assert_int_equal(ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err), ULAM_OK);
            covered += res.ci95[0] <= x[t] && x[t] <= res.ci95[1];
            zero += !(res.ci95[1] > res.ci95[0]);
            blind += res.walks.variance == 0;
            rmax = res.plan.rmax;
        }
        print_message("case %d: x_t = %.5g, rmax %.3g: %d / %d covered, %d zero-width, %d saw one score\n", c, x[t], rmax,
                      covered, cases[c].seeds, zero, blind);
        assert_int_equal(zero, 0);
        assert_true(covered >= cases[c].need);
        if (cases[c].rmax == 0) assert_true(rmax < 0.05); /* pushed: 1/64 at step_cost 1.3 */
        else assert_true(blind > 0); /* some samples saw nothing: the case the bound is for */
    }
    test_case_done();
    ulam__push_free(w), ulam__bidir_free(w_memo);
    free(x);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* Single source, every target (src/fpush.c, issue 29 point 4): on the 5000-node Zipf graph from
 * source 2 at rel_err 0.1, every component with pi = 0.15 x >= 1/n: the 95% intervals cover the
 * exact value for at least 90% of them, and the estimates are within 10% for at least 90%; no
 * interval is zero-width.  Two seeds. */
static void test_fpush_all_targets(void **state)
{
    (void)state;
    int64_t n = 5000;
    ulam_csr *M = zipf_graph(n, 2.1, 0.75, 0.85, 1), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    double *x = zipf_graph_column(M, 2), *est = malloc((size_t)n * sizeof *est), *se = malloc((size_t)n * sizeof *se);
    double *lo = malloc((size_t)n * sizeof *lo), *hi = malloc((size_t)n * sizeof *hi);
    for (int seed = 1; seed <= 2; seed++) {
        if (!test_case(seed)) continue;
        ulam_fpush_opts o = ulam_fpush_defaults();
        o.source = 2, o.walk.exec.seed = (uint64_t)seed;
        ulam_fpush_info info;
        ulam_error err;
        assert_int_equal(ulam_fpush_solve(M, Mt, &o, est, se, lo, hi, &info, &err), ULAM_OK);
        int big = 0, covered = 0, close = 0, zero = 0;
        for (int64_t i = 0; i < n; i++) {
            zero += !(hi[i] > lo[i]);
            if (0.15 * x[i] < 1.0 / (double)n) continue;
            big++;
            covered += lo[i] <= x[i] && x[i] <= hi[i];
            close += fabs(est[i] - x[i]) <= 0.1 * x[i];
        }
        print_message("seed %d: rmax %.3g, %lld push ops, %lld walks: %d components with pi >= 1/n, %d covered, %d "
                      "within 10%%, %d zero-width\n", seed, info.rmax, (long long)info.push.ops, (long long)info.walks, big,
                      covered, close, zero);
        assert_true(big >= 20);
        assert_true(covered >= 0.9 * big && close >= 0.9 * big);
        assert_int_equal(zero, 0);
    }
    test_case_done();
    free(x), free(est), free(se), free(lo), free(hi);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* Three clusters of 20 states (rows of |M| summing to 0.99, half of each row to its cluster's
 * first state, a hub whose column sums to about 10), each hub leaking 1e-4 into the next
 * cluster's: the adjoint rho(M^) is 0.99, the forward one above 1 (tests/cli_test.py's). */
static ulam_csr *three_clusters(void)
{
    int32_t ti[300], tj[300];
    double tx[300];
    int64_t nz = 0;
    for (int c = 0; c < 3; c++) {
        int hub = 20 * c;
        for (int i = 0; i < 20; i++) {
            int r = hub + i;
            double rs = 0.99 - (i == 0 && c < 2 ? 1e-4 : 0.0);
            static const int h[4] = {1, 3, 7, 12};
            for (int q = 0; q < (i == 0 ? 4 : 3); q++)
                ti[nz] = r, tj[nz] = hub + (i + h[q]) % 20, tx[nz++] = i == 0 ? rs / 4 : 0.5 * rs / 3;
            if (i > 0) ti[nz] = r, tj[nz] = hub, tx[nz++] = 0.5 * rs;
        }
        if (c < 2) ti[nz] = hub, tj[nz] = hub + 20, tx[nz++] = 1e-4;
    }
    ulam_csr *M;
    assert_int_equal(ulam_csr_from_triplets(60, 60, nz, ti, tj, tx, &M), ULAM_OK);
    return M;
}

/* Walks from a sparse b on the three clusters are forward walks on M (adjoint on M'), whose
 * variance is infinite: a --rel-err target is refused (ULAM_EINFVAR), and the message names
 * them as forward walks on M with the forward rho(M^) (above 1), not as adjoint walks (before:
 * "rho(M^) of the adjoint kernel is in [1.087, 1.336]", the mode as the walk solver saw it on M',
 * while on M the adjoint rho(M^) is 0.99). */
static void test_bidir_refusal_names_mode(void **state)
{
    (void)state;
    ulam_csr *M = three_clusters(), *Mt;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    ulam_push *w = NULL;
    assert_int_equal(ulam__push_alloc(M, &w), ULAM_OK);
    ulam__bidir *w_memo = ulam__bidir_alloc(); /* its plan memo */
    int64_t idx[3] = {44, 50, 55};
    double val[3] = {1.0, 1.0, 1.0};
    ulam_bidir_opts o = ulam_bidir_defaults();
    o.target = 21, o.nb = 3, o.b_index = idx, o.b_value = val;
    o.walk.stop.rel_err = 0.1, o.walk.stop.max_walks = 0;
    ulam_bidir_result res;
    ulam_error err;
    int st = ulam__bidir_solve(w, w_memo, Mt, &o, &res, &err);
    print_message("status %d: %s\n", st, err.msg);
    assert_int_equal(st, ULAM_EINFVAR);
    assert_non_null(strstr(err.msg, "forward walks on M"));
    assert_null(strstr(err.msg, "adjoint kernel"));
    double lo = 0, hi = 0;
    const char *at = strstr(err.msg, "rho(M^)");
    assert_non_null(at);
    assert_int_equal(sscanf(strstr(at, "["), "[%lf, %lf]", &lo, &hi), 2);
    assert_true(hi > 1.0 && lo <= hi); /* the forward radius, not the adjoint 0.99 */
    ulam__push_free(w), ulam__bidir_free(w_memo);
    ulam_csr_free(M), ulam_csr_free(Mt);
}

/* The Krylov start's residual (src/bkrylov.c): on a symmetric M (a ring of 200 states, 0.49 to
 * each neighbour) and a b spread over six decades, CG stopped early (20 products) gives a q whose
 * r = b - (I - M) q, as computed, is within the stated delta of the same sums in long double at
 * every state; and x_i = q_i + [(I - M)^-1 r]_i within delta times the visits' bound (LAPACK on
 * both), the bound the interval is widened by. */
static void test_bkrylov_rounding(void **state)
{
    (void)state;
    enum { N = 200 };
    int32_t ti[2 * N], tj[2 * N];
    double tx[2 * N], b[N], q[N], r[N], x[N], y[N], delta;
    for (int i = 0; i < N; i++) {
        ti[2 * i] = i, tj[2 * i] = (i + 1) % N, tx[2 * i] = 0.49;
        ti[2 * i + 1] = i, tj[2 * i + 1] = (i + N - 1) % N, tx[2 * i + 1] = 0.49;
        b[i] = pow(10.0, -3.0 + 6.0 * (double)((i * 37) % N) / N) * (i % 3 ? 1.0 : -1.0);
    }
    ulam_csr *M;
    assert_int_equal(ulam_csr_from_triplets(N, N, 2 * N, ti, tj, tx, &M), ULAM_OK);
    int it;
    assert_int_equal(ulam__bkrylov(M, b, 1e-12, 20, q, r, &delta, &it), ULAM_OK);
    assert_int_equal(it, 20);
    double worst = 0.0;
    for (int j = 0; j < N; j++) {
        long double s = (long double)b[j] - q[j];
        for (int64_t p = M->rowptr[j]; p < M->rowptr[j + 1]; p++) s += (long double)M->val[p] * q[M->colidx[p]];
        worst = fmax(worst, fabs((double)(s - r[j])));
    }
    double visits = ulam__bkrylov_visits(M); /* 1 / (1 - 0.98) = 50 */
    assert_true(visits >= 50.0 && visits < 50.1);
    assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
    assert_int_equal(ulam_direct_solve(M, r, y, 0, NULL, NULL), ULAM_OK);
    double gap = 0.0, xmax = 0.0;
    for (int j = 0; j < N; j++) gap = fmax(gap, fabs(x[j] - q[j] - y[j])), xmax = fmax(xmax, fabs(x[j]));
    print_message("delta %.3g, largest rounding seen %.3g; |x - q - (I - M)^-1 r| %.3g against delta x visits %.3g\n",
                  delta, worst, gap, delta * visits);
    assert_true(worst <= delta && delta > 0);
    assert_true(gap <= delta * visits + 1e-12 * xmax); /* LAPACK's own rounding beside it */
    ulam_csr_free(M);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_push_invariant), cmocka_unit_test(test_push_bad_input),
        cmocka_unit_test(test_bidir_unbiased), cmocka_unit_test(test_bidir_plan), cmocka_unit_test(test_analysis_bidir_exponent),
        cmocka_unit_test(test_solver_starts), cmocka_unit_test(test_bidir_sparse_b),  cmocka_unit_test(test_bidir_coverage),
        cmocka_unit_test(test_bidir_rules),    cmocka_unit_test(test_bidir_rare_score),
        cmocka_unit_test(test_bidir_small_budgets), cmocka_unit_test(test_bidir_deterministic_walks),
        cmocka_unit_test(test_bidir_reach_all),  cmocka_unit_test(test_bidir_fixed_walks_honest),
        cmocka_unit_test(test_fpush_all_targets), cmocka_unit_test(test_bidir_rounding),
        cmocka_unit_test(test_bidir_refusal_names_mode), cmocka_unit_test(test_bkrylov_rounding),
    };
    return test_run(tests);
}
