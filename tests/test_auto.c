/* --method auto's choice (ulam_auto_choose): screening by certified guards, pins, pilots, and an
 * unbiased estimate from fresh walks with the chosen method. */
#include "testutil.h"

/* Load matrices/NAME.mtx and its b. */
static ulam_csr *load(const char *name, double **b)
{
    char mp[256], bp[256];
    snprintf(mp, sizeof mp, "matrices/%s.mtx", name);
    snprintf(bp, sizeof bp, "matrices/%s_b.mtx", name);
    int64_t n;
    *b = must_read_vector(bp, &n);
    return must_read(mp);
}

/* Every candidate's certification follows its bounds, only certified ones are piloted, the
 * choice is the least finite cost, and walks with the chosen method on the caller's seed agree
 * with LAPACK within 4 sigma. */
static void test_choice(void **state)
{
    (void)state;
    static const char *const names[] = {"randsub1000", "signed200", "chain4"};
    for (int k = 0; k < 3; k++) { /* case k */
        if (!test_case(k)) continue;
        double *b;
        ulam_csr *M = load(names[k], &b);
        double *x = malloc((size_t)M->nrows * sizeof *x);
        assert_int_equal(ulam_direct_solve(M, b, x, 0, NULL, NULL), ULAM_OK);
        ulam_walk_opts o = ulam_walk_defaults();
        o.index = 1, o.rel_err = 0.02, o.seed = 11;
        ulam_auto_result res;
        ulam_auto_opts ao = ulam_auto_defaults();

        assert_int_equal(ulam_auto_choose(M, b, &o, &ao, &res, NULL), ULAM_OK);
        assert_int_equal(res.ncand, 12);
        assert_true(res.chosen >= 0);
        for (int c = 0; c < res.ncand; c++) {
            const ulam_auto_candidate *a = &res.cand[c];
            if (a->state != ULAM_AUTO_SKIPPED) assert_int_equal(a->certified, res.abs.upper < 1 && a->hat.upper < 1);
            assert_true(a->certified || a->pilot_walks == 0);
            if (a->state == ULAM_AUTO_FINALIST) assert_true(res.cand[res.chosen].predicted_work <= a->predicted_work);
        }
        const ulam_auto_candidate *ch = &res.cand[res.chosen];
        assert_true(ch->certified && ch->status == ULAM_OK && ch->state == ULAM_AUTO_CHOSEN);
        o.mode = ch->mode, o.estimator = ch->estimator, o.continue_q = ch->continue_q;
        ulam_walk_result r;
        assert_int_equal(ulam_solve(M, b, &o, &r, NULL), ULAM_OK);
        if (!(fabs(r.estimate - x[1]) < 4 * r.std_error))
            print_error("case %d: %.10g +- %.3g, LAPACK %.10g\n", k, r.estimate, r.std_error, x[1]);
        assert_true(fabs(r.estimate - x[1]) < 4 * r.std_error);
        free(x), free(b);
        ulam_csr_free(M);
    }
    test_case_done();
}

/* Pins keep the caller's values; with rho(|M|) >= 1 nothing is certified and the closest
 * candidate is named; bad options are refused. */
static void test_pins_and_none(void **state)
{
    (void)state;
    double *b;
    ulam_csr *M = load("randsub1000", &b);
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = ULAM_FORWARD, o.estimator = ULAM_EXPECTED, o.continue_q = 0.5;
    ulam_auto_opts ao = ulam_auto_defaults();
    ao.pin_mode = ao.pin_continue = 1;
    ulam_auto_result res;
    assert_int_equal(ulam_auto_choose(M, b, &o, &ao, &res, NULL), ULAM_OK);
    assert_int_equal(res.ncand, 3);
    for (int c = 0; c < 3; c++) assert_true(res.cand[c].mode == ULAM_FORWARD && res.cand[c].continue_q == 0.5);
    ao.pin_estimator = 1;
    assert_int_equal(ulam_auto_choose(M, b, &o, &ao, &res, NULL), ULAM_OK);
    assert_true(res.ncand == 1 && res.cand[0].estimator == ULAM_EXPECTED);
    ao.continue_q = 1.0;
    assert_int_equal(ulam_auto_choose(M, b, &o, &ao, &res, NULL), ULAM_EINVAL);
    free(b);
    ulam_csr_free(M);
    M = load("signed_edge200", &b);
    o = ulam_walk_defaults();
    assert_int_equal(ulam_auto_choose(M, b, &o, NULL, &res, NULL), ULAM_OK);
    assert_true(res.chosen == -1 && res.closest >= 0 && res.abs.lower >= 1);
    for (int c = 0; c < res.ncand; c++) {
        assert_true(!res.cand[c].certified && res.cand[c].pilot_walks == 0 && res.cand[c].state == ULAM_AUTO_UNCERTIFIED);
        assert_true(res.cand[res.closest].hat.rho <= res.cand[c].hat.rho);
    }
    free(b);
    ulam_csr_free(M);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_choice),
        cmocka_unit_test(test_pins_and_none),
    };
    return test_run(tests);
}
