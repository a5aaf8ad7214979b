/* The study engine of the library (ulam_study_*): every run's seed is its substream, its
 * estimate honest against LAPACK, the same seed gives the same runs (whatever the repeats), a
 * restored study needs no run, refused and interrupted runs, and bad parameters. */
#include "testutil.h"
#include "ulam_study.h"

#include <string.h>

/* Two methods (one adjoint, one forward), walk budgets 100 and 1000, repeats runs, seed 7. */
static ulam_study_params params(const int *methods, const double *budgets, int repeats)
{
    ulam_study_params p = ulam_study_defaults();
    p.methods = methods, p.nmethods = 2, p.budgets = budgets, p.nbudgets = 2, p.repeats = repeats, p.seed = 7;
    p.threads = 1;
    return p;
}

/* A study of chain4's x_2 to its end: each run walks with ulam_rng_substream(7, STUDY, k), scores
 * within 4 of its stderr of LAPACK's x_2, and each cell summarises all its runs. */
static void test_runs_honest(void **state)
{
    (void)state;
    test_sys s = test_sys_load("chain4");
    int methods[2] = {ulam_study_method_find("adjoint-collision-plain"), ulam_study_method_find("forward-expected-split")};
    double budgets[2] = {100, 1000};
    ulam_study_params p = params(methods, budgets, 8);
    ulam_study *st = NULL;
    ulam_error err;
    assert_int_equal(ulam_study_alloc(s.M, s.b, 1, &p, &st, &err), ULAM_OK);
    assert_true(fabs(ulam_study_exact(st)->exact - s.x[1]) <= 1e-12 * fabs(s.x[1]));
    assert_int_equal(ulam_study_exact(st)->direct, 1);
    int runs = 0, cells = 0;
    while (!ulam_study_done(st)) {
        ulam_study_run u;
        assert_int_equal(ulam_study_iterate(st, &u, &err), ULAM_OK);
        assert_false(u.interrupted);
        uint64_t k = ((uint64_t)u.method << 24) + ((uint64_t)u.budget << 16) + (uint64_t)u.repeat;
        assert_true(u.seed == ulam_rng_substream(7, ULAM_STREAM_STUDY, k));
        assert_true(u.has_estimate && u.walks == (int64_t)budgets[u.budget]);
        assert_true(fabs(u.estimate - s.x[1]) < 4 * u.std_error);
        runs++, cells += u.last_in_cell;
    }
    assert_int_equal(runs, 2 * 2 * 8);
    assert_int_equal(cells, 4);
    assert_int_equal(ulam_study_iterate(st, &(ulam_study_run){0}, &err), ULAM_EINVAL); /* done */
    ulam_study_cell c;
    for (int m = 0; m < 2; m++)
        for (int b = 0; b < 2; b++) {
            assert_int_equal(ulam_study_cell_get(st, methods[m], b, &c), 8);
            assert_int_equal(c.failed, 0);
            assert_true(c.rmse > 0 && c.mean_stderr > 0 && c.coverage >= 0 && c.coverage <= 1);
        }
    assert_int_equal(ulam_study_cell_get(st, 0 == methods[0] ? 1 : 0, 0, &c), 0); /* a method not chosen */
    for (int b = 0; b < 2; b++) { /* the winner: the least RMSE^2 x seconds of the two */
        ulam_study_cell c0, c1, w;
        ulam_study_cell_get(st, methods[0], b, &c0), ulam_study_cell_get(st, methods[1], b, &c1);
        assert_int_equal(ulam_study_winner(st, b, &w), c1.work < c0.work ? methods[1] : methods[0]);
        assert_true(w.work == fmin(c0.work, c1.work));
    }
    assert_int_equal(ulam_study_winner(st, 2, &c), -1); /* no such budget */
    assert_true(ulam_study_seconds_left(st) == 0.0);
    ulam_study_free(st);
    test_sys_free(&s);
}

/* The same seed gives the same runs, and run (m, b, r) does not depend on how many repeats the
 * study has (a resumed study with more repeats keeps the rows it has); a study restored from
 * another's runs is done and summarises the same. */
static void test_same_seed_same_runs(void **state)
{
    (void)state;
    test_sys s = test_sys_load("chain4");
    int methods[2] = {0, ULAM_STUDY_METHODS - 1};
    double budgets[2] = {100, 300};
    ulam_study_params p3 = params(methods, budgets, 3), p5 = params(methods, budgets, 5);
    ulam_study *a = NULL, *b = NULL, *c = NULL;
    assert_int_equal(ulam_study_alloc(s.M, s.b, 2, &p3, &a, NULL), ULAM_OK);
    assert_int_equal(ulam_study_alloc(s.M, s.b, 2, &p5, &b, NULL), ULAM_OK);
    assert_int_equal(ulam_study_alloc(s.M, s.b, 2, &p3, &c, NULL), ULAM_OK);
    assert_int_equal(ulam_study_run_all(a, NULL, NULL, NULL), ULAM_OK);
    assert_int_equal(ulam_study_run_all(b, NULL, NULL, NULL), ULAM_OK);
    assert_true(ulam_study_done(a) && ulam_study_done(b) && !ulam_study_done(c));
    for (int m = 0; m < 2; m++)
        for (int k = 0; k < 2; k++)
            for (int r = 0; r < 3; r++) {
                ulam_study_run ua, ub;
                assert_int_equal(ulam_study_run_get(a, methods[m], k, r, &ua), 1);
                assert_int_equal(ulam_study_run_get(b, methods[m], k, r, &ub), 1);
                assert_true(ua.seed == ub.seed && ua.estimate == ub.estimate && ua.std_error == ub.std_error);
                assert_true(ua.walks == ub.walks && ua.steps == ub.steps);
                assert_int_equal(ulam_study_restore(c, &ua), ULAM_OK);
                assert_int_equal(ulam_study_restore(c, &ua), ULAM_EINVAL); /* already done */
            }
    assert_true(ulam_study_done(c));
    ulam_study_cell ca, cc;
    assert_int_equal(ulam_study_cell_get(a, methods[1], 1, &ca), 3);
    assert_int_equal(ulam_study_cell_get(c, methods[1], 1, &cc), 3);
    assert_true(ca.rmse == cc.rmse && ca.coverage == cc.coverage && ca.mean_stderr == cc.mean_stderr);
    ulam_study_free(a), ulam_study_free(b), ulam_study_free(c);
    test_sys_free(&s);
}

/* Every method is refused on a system whose rho(|M|) is not certified below 1: the study is done
 * at once, each screening saying why. */
static void test_refused(void **state)
{
    (void)state;
    test_sys s = test_sys_load("divergent200");
    ulam_study_params p = ulam_study_defaults();
    p.repeats = 2;
    ulam_study *st = NULL;
    assert_int_equal(ulam_study_alloc(s.M, s.b, 0, &p, &st, NULL), ULAM_OK);
    for (int k = 0; k < ULAM_STUDY_METHODS; k++) {
        ulam_study_screen sc;
        assert_int_equal(ulam_study_screen_get(st, k, &sc), ULAM_OK);
        assert_true(sc.on && strstr(sc.why, "rho(|M|)"));
    }
    assert_true(ulam_study_done(st));
    assert_int_equal(ulam_study_screen_get(st, ULAM_STUDY_METHODS, &(ulam_study_screen){0}), ULAM_EINVAL);
    ulam_study_free(st);
    test_sys_free(&s);
}

/* The reference lines' points, in order. */
typedef struct {
    char kind[16][16];
    double seconds[256], error[256];
    int n, kinds;
} lines;

/* Keep one point of a reference line. */
static void keep(const char *kind, double seconds, double error, void *arg)
{
    lines *l = arg;
    if (!l->kinds || strcmp(l->kind[l->kinds - 1], kind)) snprintf(l->kind[l->kinds++], 16, "%s", kind);
    if (l->n < 256) l->seconds[l->n] = seconds, l->error[l->n++] = error;
}

/* Nonzero when M equals its transpose (ulam_csr_stats' symmetric). */
static int symmetric(const ulam_csr *M)
{
    ulam_csr_stats st;
    return !ulam_csr_stats_compute(M, &st) && st.symmetric;
}

/* The reference lines on chain4 (n = 4, forward walks certified): LAPACK's point, Gauss-Seidel
 * down to 1e-9 |x_2|, sequential MC and MCSA, then the Krylov peer (GMRES: chain4 is not
 * symmetric) ending within 1e-9 of x_2; none of the walked lines at reference_time 0. */
static void test_reference_lines(void **state)
{
    (void)state;
    test_sys s = test_sys_load("chain4");
    int methods[2] = {0, 1};
    double budgets[2] = {100, 1000};
    ulam_study_params p = params(methods, budgets, 2);
    ulam_study *st = NULL;
    assert_int_equal(ulam_study_alloc(s.M, s.b, 1, &p, &st, NULL), ULAM_OK);
    assert_int_equal(ulam_study_forward_walks(st), 1);
    static lines l;
    memset(&l, 0, sizeof l);
    assert_int_equal(ulam_study_reference_lines(st, 0.01, keep, &l, NULL), ULAM_OK);
    const char *want[] = {"lapack", "gs", "sequential", "mcsa", symmetric(s.M) ? "cg" : "gmres"};
    assert_int_equal(l.kinds, 5);
    for (int k = 0; k < 5; k++) assert_string_equal(l.kind[k], want[k]);
    assert_true(l.error[l.n - 1] <= 1e-9 * fabs(s.x[1]) && l.error[0] <= 1e-12 * fabs(s.x[1]));
    memset(&l, 0, sizeof l);
    assert_int_equal(ulam_study_reference_lines(st, 0, keep, &l, NULL), ULAM_OK);
    assert_int_equal(l.kinds, 3); /* lapack, gs, the Krylov peer */
    assert_int_equal(ulam_study_reference_lines(st, 0, NULL, NULL, NULL), ULAM_EINVAL);
    ulam_study_free(st);
    test_sys_free(&s);
}

/* A run stopped by the interrupt flag is not recorded; bad parameters are ULAM_EINVAL. */
static void test_interrupt_and_bad_params(void **state)
{
    (void)state;
    test_sys s = test_sys_load("chain4");
    int methods[2] = {0, 1}, bad_method[2] = {0, ULAM_STUDY_METHODS};
    double budgets[2] = {100, 1000}, bad_budgets[2] = {100, NAN};
    volatile int stop = 1;
    ulam_study_params p = params(methods, budgets, 2);
    p.interrupt = &stop;
    ulam_study *st = NULL;
    ulam_error err;
    assert_int_equal(ulam_study_alloc(s.M, s.b, 0, &p, &st, &err), ULAM_OK);
    ulam_study_run u;
    assert_int_equal(ulam_study_iterate(st, &u, &err), ULAM_OK);
    assert_true(u.interrupted);
    assert_int_equal(ulam_study_run_get(st, 0, 0, 0, &u), 0);
    assert_int_equal(ulam_study_run_all(st, NULL, NULL, &err), ULAM_OK);
    assert_false(ulam_study_done(st));
    stop = 0;
    assert_int_equal(ulam_study_run_all(st, NULL, NULL, &err), ULAM_OK);
    assert_true(ulam_study_done(st));
    st = ulam_study_free(st);
    ulam_study_params q = params(methods, budgets, 1);
    assert_int_equal(ulam_study_alloc(s.M, s.b, 0, &q, &st, &err), ULAM_EINVAL); /* repeats < 2 */
    q = params(bad_method, budgets, 2);
    assert_int_equal(ulam_study_alloc(s.M, s.b, 0, &q, &st, &err), ULAM_EINVAL);
    q = params(methods, bad_budgets, 2);
    assert_int_equal(ulam_study_alloc(s.M, s.b, 0, &q, &st, &err), ULAM_EINVAL);
    q = params(methods, budgets, 2);
    assert_int_equal(ulam_study_alloc(s.M, s.b, s.n, &q, &st, &err), ULAM_EINVAL); /* index out of range */
    assert_null(st);
    assert_null(ulam_study_free(NULL));
    test_sys_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runs_honest), cmocka_unit_test(test_same_seed_same_runs),
        cmocka_unit_test(test_refused), cmocka_unit_test(test_interrupt_and_bad_params),
        cmocka_unit_test(test_reference_lines),
    };
    return test_run(tests);
}
