/* A unit test of src/stop.c built with the module (tests/meson.build's module units): the
 * stitching's confidence levels and the confidence sequence's quartic penalty (ulam__cs_add4),
 * which no public call shows one by one.  It includes stop.h, its
 * module's private header, beside it; the tests in tests/ include public headers only. */
#include "stop.h"
#include "stats.h"
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

/* The quartic penalty of ulam__cs_add4 keeps each end's factor below the bet's own wealth: for
 * one score X anywhere in [-A, A], exp(lambda xi - vlo) <= 1 + lambda xi and
 * exp(-lambda xi - vhi) <= 1 - lambda xi (xi = (X - c) / s), over bets up to the cap, centres
 * across the range and scales s = A + |c| (the solver's); and it is never above Fan's
 * psi(lambda) xi^2, nor far above lambda^2 xi^2 / 2 for a score near the centre. */
static void test_quartic_penalty_bounds_wealth(void **state)
{
    (void)state;
    const double A = 3.0;
    for (int il = 1; il <= 15; il++)
        for (int ic = -10; ic <= 10; ic++)
            for (int ix = 0; ix <= 400; ix++) {
                double lam = ULAM__CS_LMAX4 * il / 15.0, c = A * ic / 10.0, X = -A + 2.0 * A * ix / 400.0;
                ulam__cs cs = {.lam = lam, .c = c, .s = A + fabs(c), .limit = A};
                ulam__cs_add4(&cs, 1, X, 0.0, 0.0, 0.0, 0.0);
                double xi = (X - c) / cs.s, tol = 1e-12;
                assert_true(lam * xi - cs.vlo <= log1p(lam * xi) + tol);
                assert_true(-lam * xi - cs.vhi <= log1p(-lam * xi) + tol);
                assert_true(cs.vlo <= cs.v + tol && cs.vhi <= cs.v + tol); /* at most Fan's */
                if (fabs(xi) < 0.01) assert_true(cs.vlo + cs.vhi <= lam * lam * xi * xi * 1.02 + tol);
            }
}

/* The sequence with the quartic penalty (ulam__cs_add4) covers at every count at once: scores in
 * [0, 1] that are 1 with probability 0.01 and else U(0, 0.1) (skewed, the range far above the
 * spread, as a walk score's), and signed ones (+-1 with probability 0.01 each, else U(-0.1, 0.1)),
 * bets planned (ulam__cs_plan4) before each block of 64 from the blocks so far, at a target half-width (rel_err)
 * and at a planned count (a fixed budget), 300 runs of 16384 scores each: a run misses when the
 * interval fails to hold the mean at any block's end.  At most 0.05 of the runs may (binomial,
 * 300 runs: mean 15, sd 3.8): at most 30. */
static void test_quartic_sequence_covers_at_every_count(void **state)
{
    (void)state;
    for (int law = 0; law < 2; law++)
        for (int plan = 0; plan < 2; plan++) {
            double mu = law ? 0.0 : 0.01 + 0.99 * 0.05;
            int missed = 0;
            for (int seed = 0; seed < 300; seed++) {
                ulam_rng r;
                ulam_rng_seed(&r, 1000 + (uint64_t)seed, (uint64_t)(law * 2 + plan));
                ulam__cs cs = {0};
                ulam__moments run = {0};
                int miss = 0;
                for (int q = 0; q < 256; q++) {
                    double h = plan ? 0.0 : 0.1 * fmax(fabs(run.mean), 0.01);
                    ulam__cs_plan4(&cs, run.n, run.mean, ulam__moments_variance(&run), run.m3, run.m4, 1.0, 0.0, h,
                                   16384.0);
                    ulam__moments blk = {0};
                    for (int k = 0; k < 64; k++) {
                        double u = ulam_rng_uniform(&r), v = ulam_rng_uniform(&r), x;
                        if (law == 0) x = u < 0.01 ? 1.0 : 0.1 * v;
                        else x = u < 0.01 ? 1.0 : u < 0.02 ? -1.0 : 0.2 * v - 0.1;
                        ulam__moments_add(&blk, x);
                    }
                    ulam__cs_add4(&cs, blk.n, blk.mean, blk.m2, blk.m3, blk.m4, 0.0);
                    ulam__moments_merge(&run, &blk);
                    ulam__stop_ci ci;
                    ulam__cs_interval(&cs, run.mean, 0.0, &ci);
                    miss |= ci.kind == ULAM__STOP_EB && !(ci.lo <= mu && mu <= ci.hi);
                }
                missed += miss;
            }
            print_message("law %d, plan %d: %d of 300 runs missed at some count\n", law, plan, missed);
            assert_true(missed <= 30);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_stitching_spends_delta),
                                       cmocka_unit_test(test_quartic_penalty_bounds_wealth),
                                       cmocka_unit_test(test_quartic_sequence_covers_at_every_count)};
    return test_run(tests);
}
