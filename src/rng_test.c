/* A unit test of src/rng.c built with the module (tests/meson.build's module units): the
 * counter-based numbers (ulam__rng_counter) the distributed walks draw, which no public call
 * shows one by one.  It includes internal.h, where the module declares them; the tests in tests/
 * include public headers only. */
#include "internal.h"
#include "testutil.h"

/* Counter-based numbers: keyed by (seed, walk, step, k), in [0, 1), and not all alike. */
static void test_dist_counter(void **state)
{
    (void)state;
    assert_true(ulam__rng_counter(1, 2, 3, 0) == ulam__rng_counter(1, 2, 3, 0));
    double s = 0, s2 = 0;
    int N = 100000;
    for (int i = 0; i < N; i++) {
        double u = ulam__rng_counter(5, (uint64_t)i / 10, (uint64_t)i % 10, (unsigned)i % 3);
        assert_true(u >= 0 && u < 1);
        s += u, s2 += u * u;
    }
    double mean = s / N, var = s2 / N - mean * mean;
    assert_true(fabs(mean - 0.5) < 4 * sqrt(1.0 / 12 / N)); /* 4 standard errors */
    assert_true(fabs(var - 1.0 / 12) < 0.002);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_dist_counter)};
    return test_run(tests);
}
