/* The options by name (include/ulam_options.h): one table for the command line and Python sets
 * each field in range, refuses a bad value with a sentence naming the option and what it
 * expected (o untouched), and says ULAM_ENOTFOUND for a name that is no option. */
#include "testutil.h"
#include "ulam_options.h"

/* Good values land in their fields, whatever the spelling (rel_err, rel-err, tol). */
static void test_walk_set(void **state)
{
    (void)state;
    ulam_walk_opts o = ulam_walk_defaults();
    ulam_error err;
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "rel-err", "0.1", &err), ULAM_OK);
    assert_true(o.stop.rel_err == 0.1);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "rel_err", "0.25", &err), ULAM_OK);
    assert_true(o.stop.rel_err == 0.25);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "tol", "0.5", &err), ULAM_OK);
    assert_true(o.stop.rel_err == 0.5);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "walks", "2.5e3", &err), ULAM_OK);
    assert_int_equal(o.stop.max_walks, 2500);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "seed", "9223372036854775807", &err), ULAM_OK);
    assert_true(o.exec.seed == 9223372036854775807ULL);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "estimator", "expected", &err), ULAM_OK);
    assert_int_equal(o.estimator, ULAM_EXPECTED);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "mode", "forward", &err), ULAM_OK);
    assert_int_equal(o.mode, ULAM_FORWARD);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "continue", "0.5", &err), ULAM_OK);
    assert_true(o.kernel.continue_q == 0.5);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "continue", "analog", &err), ULAM_OK);
    assert_true(o.kernel.continue_q == 0.0);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "threads", "3", &err), ULAM_OK);
    assert_int_equal(o.exec.threads, 3);
}

/* A bad value is refused with the option's name and its range; o is untouched. */
static void test_walk_refuse(void **state)
{
    (void)state;
    ulam_walk_opts o = ulam_walk_defaults(), before = o;
    ulam_error err;
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "rel-err", "2", &err), ULAM_EINVAL);
    assert_string_equal(err.msg, "--rel-err expects a number from 1e-12 to 1, got '2'");
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "walks", "0", &err), ULAM_EINVAL);
    assert_string_equal(err.msg, "--walks expects an integer from 1 to 1000000000000000, got '0'");
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "walks", "1e16", &err), ULAM_EINVAL);
    assert_non_null(strstr(err.msg, "would take years"));
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "threads", "nan", &err), ULAM_EINVAL);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "time", "inf", &err), ULAM_EINVAL);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "estimator", "colision", &err), ULAM_EINVAL);
    assert_string_equal(err.msg, "--estimator expects collision, absorption or expected, got 'colision' "
                                 "(did you mean 'collision'?)");
    assert_memory_equal(&o, &before, sizeof o);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &o, "rmax", "1", &err), ULAM_ENOTFOUND); /* bidirectional's */
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, NULL, "walks", "1", &err), ULAM_EINVAL);
    assert_int_equal(ulam_options_set(7, &o, "walks", "1", &err), ULAM_EINVAL);
}

/* The outer iteration's and bidirectional's own rows first, then their walks'. */
static void test_outer_bidir(void **state)
{
    (void)state;
    ulam_outer_opts o = ulam_outer_defaults();
    ulam_bidir_opts b = ulam_bidir_defaults();
    ulam_error err;
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_OUTER, &o, "tol", "1e-6", &err), ULAM_OK);
    assert_true(o.tol == 1e-6 && o.walk.stop.rel_err == ulam_outer_defaults().walk.stop.rel_err);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_OUTER, &o, "tol", "1", &err), ULAM_EINVAL);
    assert_string_equal(err.msg, "--tol expects a residual reduction strictly between 0 and 1 (such as 1e-8), got '1'");
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_OUTER, &o, "max_iter", "7", &err), ULAM_OK);
    assert_int_equal(o.max_iter, 7);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_OUTER, &o, "seed", "5", &err), ULAM_OK);
    assert_true(o.walk.exec.seed == 5);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_BIDIR, &b, "rmax", "1e-4", &err), ULAM_OK);
    assert_true(b.rmax == 1e-4);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_BIDIR, &b, "step-cost", "0", &err), ULAM_EINVAL);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_BIDIR, &b, "walks", "10", &err), ULAM_OK);
    assert_int_equal(b.walk.stop.max_walks, 10);
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_BIDIR, &b, "stall", "10", &err), ULAM_ENOTFOUND); /* the outer's */
}

/* Every option ulam_options.h names for an outer iteration (its own, then the walks' it hands
 * on) can be set by name, and an outer option is not a walk option. */
static void test_list(void **state)
{
    (void)state;
    static const char *const names[] = {"tol", "max-iter", "eps1", "max-histories", "stall", "walks", "rel-err",
                                        "time", "seed", "threads", "continue", "kernel-exponent", "roulette",
                                        "split", "max-steps", "estimator", "mode"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        ulam_outer_opts o = ulam_outer_defaults();
        ulam_error err;
        assert_int_not_equal(ulam_options_set(ULAM_OPTIONS_OUTER, &o, names[k], "x", &err), ULAM_ENOTFOUND);
    }
    ulam_walk_opts w = ulam_walk_defaults();
    ulam_error err;
    assert_int_equal(ulam_options_set(ULAM_OPTIONS_WALK, &w, "max-iter", "10", &err), ULAM_ENOTFOUND);
    const char *modes[] = {"adjoint", "forward"};
    assert_string_equal(ulam_options_suggest("forwrd", modes, 2), "forward");
    assert_null(ulam_options_suggest("zzzzzz", modes, 2));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walk_set),
        cmocka_unit_test(test_walk_refuse),
        cmocka_unit_test(test_outer_bidir),
        cmocka_unit_test(test_list),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
