/* A unit test of src/study.c built with the module (tests/meson.build's module units): a study's
 * reference value (ulam__study_reference) and the options of its method grid
 * (ulam__study_method_opts), which the public study calls use inside.  It includes internal.h,
 * where the module declares them; the tests in tests/ include public headers only. */
#include "study.h"
#include "testutil.h"

#include <stdio.h>

/* The study's exact value: the hand-checked x_2 = 4 by LAPACK (n <= ULAM_STUDY_DIRECT_MAX) and
 * by Gauss-Seidel settled, which agree to rounding; a bad index is refused. */
static void test_study_reference(void **state)
{
    (void)state;
    int32_t i[4] = {0, 1, 1, 2}, j[4] = {1, 0, 2, 1};
    double v[4] = {0.5, 0.25, 0.25, 0.5}, b[3] = {1, 2, 3};
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(3, 3, 4, i, j, v, &M), ULAM_OK);
    ulam_study_ref ref;
    assert_int_equal(ulam__study_reference(M, b, 1, &ref, NULL), ULAM_OK);
    assert_int_equal(ref.direct, 1);
    assert_close(ref.exact, 4.0, 1e-14);
    assert_close(ref.settled, 4.0, 1e-13);
    assert_true(ref.sweeps >= 12 && ref.sweeps < 100000);
    ulam_error err;
    assert_int_equal(ulam__study_reference(M, b, 3, &ref, &err), ULAM_EINVAL);
    ulam_csr_free(M);
}

/* The method grid: 18 distinct names "mode-estimator-window" found back by name, k = 9 mode +
 * 3 estimator + window; the windows at 0.5 and 2 times the starting weight (1 adjoint, ||b||_1
 * forward); out of range refused. */
static void test_study_methods(void **state)
{
    (void)state;
    static const char *const modes[] = {"adjoint", "forward"}, *const ests[] = {"collision", "absorption", "expected"},
                             *const wins[] = {"plain", "roulette", "split"};
    double b[3] = {1, -2, 3};
    char name[64];
    for (int k = 0; k < ULAM_STUDY_METHODS; k++) {
        const ulam_study_method *m = ulam_study_method_get(k);
        assert_non_null(m);
        assert_int_equal(m->mode, k / 9);
        assert_int_equal(m->estimator, k / 3 % 3);
        assert_int_equal(m->window, k % 3);
        snprintf(name, sizeof name, "%s-%s-%s", modes[m->mode], ests[m->estimator], wins[m->window]);
        assert_string_equal(m->name, name);
        assert_int_equal(ulam_study_method_find(name), k);
        ulam_walk_opts o = ulam_walk_defaults();
        assert_int_equal(ulam__study_method_opts(k, b, 3, &o), ULAM_OK);
        double w0 = m->mode == ULAM_FORWARD ? 6.0 : 1.0;
        assert_int_equal(o.mode, m->mode);
        assert_int_equal(o.estimator, m->estimator);
        assert_close(o.kernel.roulette, m->window ? 0.5 * w0 : 0.0, 0.0);
        assert_close(o.kernel.split, m->window == ULAM_WINDOW_SPLIT ? 2.0 * w0 : 0.0, 0.0);
    }
    assert_null(ulam_study_method_get(ULAM_STUDY_METHODS));
    assert_null(ulam_study_method_get(-1));
    assert_int_equal(ulam_study_method_find("adjoint-collision"), -1);
    ulam_walk_opts o = ulam_walk_defaults();
    assert_int_equal(ulam__study_method_opts(ULAM_STUDY_METHODS, b, 3, &o), ULAM_EINVAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_study_reference), cmocka_unit_test(test_study_methods)};
    return test_run(tests);
}
