/* A unit test of src/stop.c built with the module (tests/meson.build's module units): the
 * stitching's confidence levels, which no public call shows one by one.  It includes stop.h, its
 * module's private header, beside it; the tests in tests/ include public headers only. */
#include "stop.h"
#include "testutil.h"

/* The stitching spends delta once: a run that may stop at any checkpoint k >= 1 has confidence
 * levels delta_k = 3 exp(-L(k)) summing to at most delta (checkpoint 1 took delta itself, so the
 * sum was 1.5 delta), and a count fixed in advance (k = 0) takes delta. */
static void test_stitching_spends_delta(void **state)
{
    (void)state;
    double sum = 0.0;
    for (int k = 1; k <= 100000; k++) sum += 3.0 * exp(-ulam__stop_log(k));
    assert_true(sum <= ULAM__STOP_DELTA && sum > 0.9999 * ULAM__STOP_DELTA);
    assert_close(3.0 * exp(-ulam__stop_log(0)), ULAM__STOP_DELTA, 1e-12);
    assert_close(3.0 * exp(-ulam__stop_log(1)), ULAM__STOP_DELTA / 2.0, 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_stitching_spends_delta)};
    return test_run(tests);
}
