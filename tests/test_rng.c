/* xoshiro256** and its seeding: reference output, streams, uniformity, unbiased bounds. */
#include "testutil.h"

/* The first outputs of xoshiro256** from state (1, 2, 3, 4), computed independently. */
static void test_reference_output(void **state)
{
    (void)state;
    ulam_rng r = {{1, 2, 3, 4}};
    assert_true(ulam_rng_bounded(&r, 0) == 11520ULL);
    assert_true(ulam_rng_bounded(&r, 0) == 0ULL);
    assert_true(ulam_rng_bounded(&r, 0) == 1509978240ULL);
    assert_true(ulam_rng_bounded(&r, 0) == 1215971899390074240ULL);
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
        uint64_t x = ulam_rng_bounded(&a, 0);
        assert_true(x == ulam_rng_bounded(&b, 0));
        assert_true(x != ulam_rng_bounded(&c, 0));
        assert_true(x != ulam_rng_bounded(&d, 0));
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

/* ulam_rng_substream: the documented formula's values (docs/streams.md, computed independently),
 * the same triple the same seed, below 2^63 (a --seed the CLI takes), and the 6 x 2000 (purpose,
 * k) of three seeds all distinct from each other and from the seeds themselves. */
/* qsort's order on uint64_t. */
static int by_value(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* ulam_rng_substream: the documented formula's values (docs/streams.md, computed independently),
 * the same triple the same seed, below 2^63 (a --seed the CLI takes), and the 6 x 2000 (purpose,
 * k) of three seeds all distinct from each other and from the seeds themselves. */
static void test_substream(void **state)
{
    (void)state;
    assert_true(ulam_rng_substream(1, ULAM_STREAM_QUERY, 0) == UINT64_C(3603747775286318917));
    assert_true(ulam_rng_substream(11, ULAM_STREAM_QUERY, 3) == UINT64_C(2099057283005048251));
    assert_true(ulam_rng_substream(42, ULAM_STREAM_PILOT, 0) == UINT64_C(6161051708188775094));
    assert_true(ulam_rng_substream(0, ULAM_STREAM_STUDY, 7) == UINT64_C(2006811855215911423));
    enum { P = 6, K = 2000, S = 3 };
    const uint64_t seeds[S] = {0, 1, 2};
    uint64_t *all_seeds = malloc((size_t)(P * K * S + S) * sizeof *all_seeds);
    assert_non_null(all_seeds);
    size_t n = 0;
    for (int s = 0; s < S; s++) {
        all_seeds[n++] = seeds[s];
        for (int p = ULAM_STREAM_QUERY; p <= ULAM_STREAM_STUDY; p++)
            for (uint64_t k = 0; k < K; k++) {
                uint64_t v = ulam_rng_substream(seeds[s], (ulam_stream_purpose)p, k);
                assert_true(v == ulam_rng_substream(seeds[s], (ulam_stream_purpose)p, k) && v < UINT64_C(1) << 63);
                all_seeds[n++] = v;
            }
    }
    qsort(all_seeds, n, sizeof *all_seeds, by_value);
    for (size_t q = 1; q < n; q++) assert_true(all_seeds[q] != all_seeds[q - 1]);
    free(all_seeds);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_output), cmocka_unit_test(test_streams),
        cmocka_unit_test(test_uniform), cmocka_unit_test(test_bounded),
        cmocka_unit_test(test_substream),
    };
    return test_run(tests);
}
