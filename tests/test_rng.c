/* xoshiro256** and its seeding: reference output, streams, uniformity, unbiased bounds. */
#include "testutil.h"

/* The first outputs of xoshiro256** from state (1, 2, 3, 4), computed independently. */
static void test_reference_output(void **state)
{
    (void)state;
    ulam_rng r = {{1, 2, 3, 4}};
    assert_true(ulam_rng_next(&r) == 11520ULL);
    assert_true(ulam_rng_next(&r) == 0ULL);
    assert_true(ulam_rng_next(&r) == 1509978240ULL);
    assert_true(ulam_rng_next(&r) == 1215971899390074240ULL);
}

/* Same (seed, stream) repeats; a different seed or stream does not. */
static void test_streams(void **state)
{
    (void)state;
    ulam_rng a, b, c, d;
    ulam_rng_seed(&a, 42, 0);
    ulam_rng_seed(&b, 42, 0);
    ulam_rng_seed(&c, 42, 1);
    ulam_rng_seed(&d, 43, 0);
    for (int k = 0; k < 100; k++) {
        uint64_t x = ulam_rng_next(&a);
        assert_true(x == ulam_rng_next(&b));
        assert_true(x != ulam_rng_next(&c));
        assert_true(x != ulam_rng_next(&d));
    }
}

/* Uniform doubles lie in [0, 1) with mean 1/2 and variance 1/12 (4 sigma bounds). */
static void test_uniform(void **state)
{
    (void)state;
    enum { N = 1000000 };
    ulam_rng r;
    ulam_rng_seed(&r, 1, 0);
    double s = 0, s2 = 0;
    for (int k = 0; k < N; k++) {
        double u = ulam_rng_uniform(&r);
        assert_true(u >= 0.0 && u < 1.0);
        s += u, s2 += u * u;
    }
    double mean = s / N, var = s2 / N - mean * mean;
    assert_close(mean, 0.5, 4 * sqrt(1.0 / 12 / N));
    assert_close(var, 1.0 / 12, 4 * sqrt(1.0 / 180 / N)); /* Var(U^2 - ...) ~ 1/180 */
}

/* Bounded draws are uniform over [0, 7): chi-square with 6 degrees of freedom below its
 * 0.1% point (22.46), and never out of range; bound 1 always gives 0. */
static void test_bounded(void **state)
{
    (void)state;
    enum { N = 700000, K = 7 };
    ulam_rng r;
    ulam_rng_seed(&r, 2, 0);
    long count[K] = {0};
    for (int k = 0; k < N; k++) {
        uint64_t v = ulam_rng_bounded(&r, K);
        assert_true(v < K);
        count[v]++;
    }
    double chi2 = 0, e = (double)N / K;
    for (int k = 0; k < K; k++) chi2 += (count[k] - e) * (count[k] - e) / e;
    assert_true(chi2 < 22.46);
    for (int k = 0; k < 100; k++) assert_true(ulam_rng_bounded(&r, 1) == 0);
    uint64_t big = (UINT64_C(1) << 63) + 1; /* rejection path: still in range */
    for (int k = 0; k < 1000; k++) assert_true(ulam_rng_bounded(&r, big) < big);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_output), cmocka_unit_test(test_streams),
        cmocka_unit_test(test_uniform), cmocka_unit_test(test_bounded),
    };
    return test_run(tests);
}
