/* The analysis' internal walks (src/analysis.c, ulam__analysis_walks): what an analysis lends
 * walks -- the bounds over every state, the kept kernel rows (rescored to each b, or fixed for
 * one b), the reach earlier walks found -- changes how much set-up they do, never what they
 * walk.  Each run handed out by an analysis equals, bit for bit, the run of a solver built
 * directly with the same options (ulam_solve_walks); a kernel made for another estimator or b is
 * not lent; an analysis refuses walks of another kernel.  A unit test built with the module
 * (tests/meson.build's module units): it includes internal.h beside it for the internal entry
 * points; the tests in tests/ include public headers only. */
#include <math.h>
#include <stdarg.h>
#include <setjmp.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "internal.h"
#include "analysis.h"
#include "solve.h"
#include "testutil.h"

/* Fail unless two runs are the same, bit for bit (the kernel rows built aside). */
static void assert_same_run(const ulam_walk_result *a, const ulam_walk_result *b, int step)
{
    if (a->estimate != b->estimate || a->walks != b->walks || a->std_error != b->std_error)
        print_error("step %d: lent %.17g (%lld walks, stderr %.3g), direct %.17g (%lld, %.3g)\n", step, a->estimate,
                    (long long)a->walks, a->std_error, b->estimate, (long long)b->walks, b->std_error);
    assert_memory_equal(&a->estimate, &b->estimate, sizeof a->estimate);
    assert_memory_equal(&a->std_error, &b->std_error, sizeof a->std_error);
    assert_memory_equal(a->ci95, b->ci95, sizeof a->ci95);
    assert_true(a->walks == b->walks && a->steps == b->steps && a->rel_err_met == b->rel_err_met);
}

/* The walks of a solver built directly (ulam__solver_alloc_reached, no kernel kept): under a
 * fresh pass's bounds over every state (ULAM__WALKS_ALL), else its own search (where the
 * analysis lends ULAM__WALKS_FOUND walks the reach a ULAM__WALKS_FIND run found); *reads: the
 * entries its set-up read (reachability searches, bound passes). */
static int direct_walks(const ulam_csr *M, const double *b, const ulam_walk_opts *o, int how, ulam_walk_result *res,
                        int64_t *reads)
{
    ulam__reach R = {0};
    char *seen = NULL;
    int status = ULAM_OK;
    if (how & ULAM__WALKS_ALL) {
        seen = malloc((size_t)M->nrows);
        assert_int_equal(ulam__reach_all(M, o->kernel.continue_q, o->kernel.kernel_alpha, seen, &R), ULAM_OK);
    }
    ulam_solver *s = NULL;
    ulam_error err;
    status = ulam__solver_alloc_reached(M, b, o, how & ULAM__WALKS_ALL ? &R : NULL, NULL, &s, &err);
    while (!status && !ulam_solver_done(s)) status = ulam_solver_iterate(s);
    int64_t units;
    if (s) ulam_solver_result(s, res), ulam__solver_setup(s, &units, reads);
    ulam_solver_free(s);
    free(seen);
    return status;
}

/* On a random M, for three kernels (analog, exponent 2, continuation 0.9): a sequence of walks through
 * one analysis -- b's that change (a kept kernel rescored), the same b again (a fixed kernel),
 * estimators that change (the kept kernel dropped), starts that change, the reach a first run
 * found lent to the next from the same start -- each equal to a solver built directly with the
 * same options and reach (direct_walks), and the last to ulam_solve_walks too; a kept kernel is lent (its rows count what earlier runs built) only where it was made
 * for the run, and walks of another kernel are refused. */
static void test_walks_lent_equal_direct(void **state)
{
    (void)state;
    static const struct {
        double q, alpha;
    } kernels[] = {{0.0, 1.0}, {0.0, 2.0}, {0.9, 1.0}};
    ulam_csr *M = test_random_system(10000, 5, 1, 0.8, 29);
    int64_t n = M->nrows;
    double *ones = malloc((size_t)n * sizeof *ones), *r = malloc((size_t)n * sizeof *r);
    for (int64_t i = 0; i < n; i++) ones[i] = 1.0;
    ulam_rng g;
    ulam_rng_seed(&g, 5, 0);
    for (int kk = 0; kk < 3; kk++) {
        if (!test_case(kk)) continue;
        ulam_analysis_opts ao = ulam_analysis_defaults();
        ao.continue_q = kernels[kk].q, ao.kernel_alpha = kernels[kk].alpha;
        ulam_analysis *a = NULL;
        ulam_error err;
        assert_int_equal(ulam_analysis_alloc(M, &ao, &a, &err), ULAM_OK);
        static const struct {
            int how, est, fixed_b, walks; /* walks 0: rel_err 0.1 (analog kernel; else 2000 walks) */
        } steps[] = {
            {ULAM__WALKS_ALL | ULAM__WALKS_KEEP, ULAM_COLLISION, 0, 0},   /* builds rows, keeps them */
            {ULAM__WALKS_ALL | ULAM__WALKS_KEEP, ULAM_COLLISION, 0, 2000},   /* another b: lent, rescored */
            {ULAM__WALKS_KEEP, ULAM_COLLISION, 0, 0},                      /* the same, searching its reach */
            {ULAM__WALKS_ALL | ULAM__WALKS_KEEP, ULAM_ABSORPTION, 0, 2000},  /* another estimator: dropped */
            {ULAM__WALKS_FIND | ULAM__WALKS_FIXED | ULAM__WALKS_KEEP, ULAM_COLLISION, 1, 0}, /* ones, kept fixed */
            {ULAM__WALKS_FOUND | ULAM__WALKS_FIXED | ULAM__WALKS_KEEP, ULAM_COLLISION, 1, 2000}, /* both lent */
            {ULAM__WALKS_FOUND | ULAM__WALKS_KEEP, ULAM_EXPECTED, 0, 0},  /* the found reach; absorption's dropped */
            {ULAM__WALKS_ALL | ULAM__WALKS_KEEP, ULAM_ABSORPTION, 0, 2000},  /* built, kept */
            {ULAM__WALKS_ALL, ULAM_ABSORPTION, 0, 2000},                     /* not kept: dropped */
            {ULAM__WALKS_ALL | ULAM__WALKS_KEEP, ULAM_ABSORPTION, 0, 2000},  /* so built afresh */
        };
        int64_t rows_before = 0;
        for (int st = 0; st < (int)(sizeof steps / sizeof *steps); st++) {
            const double *b = steps[st].fixed_b ? ones : r;
            if (!steps[st].fixed_b)
                for (int64_t i = 0; i < n; i++) r[i] = ulam_rng_uniform(&g) < 0.2 ? ulam_rng_uniform(&g) - 0.3 : 0.0;
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = steps[st].est;
            o.kernel.continue_q = kernels[kk].q, o.kernel.kernel_alpha = kernels[kk].alpha;
            o.query.index = st >= 4 && st <= 6 ? 7 : (int64_t)(st * 17 + kk) % n; /* 5 and 6 from 4's start */
            int rel = !steps[st].walks && kk == 0;
            o.stop.max_walks = rel ? 0 : steps[st].walks ? steps[st].walks : 2000, o.stop.rel_err = rel ? 0.1 : 0;
            o.exec.threads = 1, o.exec.seed = (uint64_t)(100 * kk + st + 1);
            ulam_walk_result lent, direct;
            ulam_solver *s = NULL;
            int s1 = ulam__analysis_walks(a, b, &o, steps[st].how, &lent, NULL, &s, &err);
            if (s1) print_error("kernel %d step %d: %s: %s\n", kk, st, ulam_strerror(s1), err.msg);
            assert_int_equal(s1, ULAM_OK);
            int64_t units, reads, direct_reads;
            ulam__solver_setup(s, &units, &reads);
            ulam_solver_free(s);
            assert_int_equal(direct_walks(M, b, &o, steps[st].how, &direct, &direct_reads), ULAM_OK);
            /* the found reach lent: no search (a search from 7 reads its reach's entries) */
            if (steps[st].how & ULAM__WALKS_FOUND) assert_true(reads < direct_reads);
            assert_same_run(&lent, &direct, st);
            /* a kernel lent holds what earlier runs built: at least as many rows; one made here as
               many as the direct run's (expected: never kept, nor lent) */
            int lent_kernel = st == 1 || st == 2 || st == 5;
            if (lent_kernel) assert_true(lent.rows >= direct.rows && lent.rows >= rows_before);
            else assert_int_equal(lent.rows, direct.rows);
            if (getenv("ULAM_TEST_VERBOSE")) print_message("kernel %d step %d: rows %lld direct %lld walks %lld\n", kk, st, (long long)lent.rows, (long long)direct.rows, (long long)lent.walks);
            rows_before = lent.rows;
        }
        /* a solver kept by the caller: the same walks, freed by the caller */
        ulam_walk_opts o = ulam_walk_defaults();
        o.kernel.continue_q = kernels[kk].q, o.kernel.kernel_alpha = kernels[kk].alpha;
        o.query.index = 3, o.stop.max_walks = 2000, o.stop.rel_err = 0, o.exec.threads = 1;
        ulam_solver *s = NULL;
        ulam_walk_result lent, direct;
        assert_int_equal(ulam__analysis_walks(a, r, &o, ULAM__WALKS_ALL | ULAM__WALKS_KEEP, NULL, NULL, &s, &err), ULAM_OK);
        assert_non_null(s);
        assert_true(ulam_solver_done(s));
        ulam_solver_result(s, &lent);
        ulam_solver_free(s);
        assert_int_equal(ulam_solve_walks(M, r, &o, &direct, &err), ULAM_OK);
        assert_same_run(&lent, &direct, -1);
        /* one analysis, one kernel */
        o.kernel.kernel_alpha = kernels[kk].alpha + 1.0;
        assert_int_equal(ulam__analysis_walks(a, r, &o, 0, &lent, NULL, &s, &err), ULAM_EINVAL);
        assert_null(s);
        ulam_analysis_free(a);
    }
    test_case_done();
    free(ones), free(r);
    ulam_csr_free(M);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_walks_lent_equal_direct)};
    return test_run(tests);
}
