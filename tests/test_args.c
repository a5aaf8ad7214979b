/* The library validates what it is given (issue 26, points 3 and 4): every finite-valued option
 * of every public entry point is checked (NaN, +-inf, out of range) and refused with ULAM_EINVAL
 * and a message naming it, never accepted, hung on or crashed on; vectors passed with their
 * length are refused when short (ULAM_EDIM); a matrix built by hand with row pointers or column
 * indices out of range is refused by every solver entry point, never read out of bounds. */
#include "testutil.h"
#include "ulam_reference.h"

/* The 4-state chain M_{i,i+1} = 0.5 and b = 1 (x = 2 - 2^(i-3) ...: every call below succeeds
 * on it with good options). */
static ulam_csr *chain(void)
{
    int32_t ti[3] = {0, 1, 2}, tj[3] = {1, 2, 3};
    double tx[3] = {0.5, 0.5, 0.5};
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(4, 4, 3, ti, tj, tx, &M), ULAM_OK);
    return M;
}

static const double ones[4] = {1, 1, 1, 1};

/* One bad value of a walk option. */
typedef struct bad_walk {
    const char *field;
    size_t off;
    double v;
} bad_walk;

#define W(f, v) {#f, offsetof(ulam_walk_opts, f), v}
static const bad_walk walk_table[] = {
    W(kernel.continue_q, NAN), W(kernel.continue_q, INFINITY), W(kernel.continue_q, 1.0), W(kernel.continue_q, -INFINITY),
    W(kernel.roulette, NAN), W(kernel.roulette, INFINITY), W(kernel.roulette, -1.0),
    W(kernel.split, NAN), W(kernel.split, INFINITY), W(kernel.split, -1.0),
    W(stop.rel_err, NAN), W(stop.rel_err, INFINITY), W(stop.rel_err, -0.1),
    W(stop.max_seconds, NAN), W(stop.max_seconds, INFINITY), W(stop.max_seconds, -1.0),
    W(stop.rel_err_offset, NAN), W(stop.rel_err_offset, INFINITY),
    W(kernel.kernel_alpha, NAN), W(kernel.kernel_alpha, INFINITY), W(kernel.kernel_alpha, -1.0),
};
#undef W
enum { NWALK = sizeof walk_table / sizeof *walk_table };

/* o with row k of walk_table set; max_walks 0 when the bad field is max_seconds, so a NaN time
 * limit is the only rule (it never returned). */
static ulam_walk_opts bad_opts(int k, int mode)
{
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = mode, o.stop.max_walks = 1000, o.exec.threads = 1;
    if (!strcmp(walk_table[k].field, "stop.max_seconds")) o.stop.max_walks = 0;
    memcpy((char *)&o + walk_table[k].off, &walk_table[k].v, sizeof(double));
    return o;
}

/* err says which field it refused. */
static void assert_names(const ulam_error *err, const char *field)
{
    if (!strstr(err->msg, field)) {
        print_error("message \"%s\" does not name %s\n", err->msg, field);
        fail();
    }
}

/* Every bad walk option, both modes, through ulam_solver_alloc: ULAM_EINVAL naming
 * the field. */
static void test_walk_options(void **state)
{
    (void)state;
    ulam_csr *M = chain();
    for (int k = 0; k < NWALK; k++) {
        for (int mode = 0; mode < 2; mode++) {
            if (!test_case(k * 2 + mode)) continue;
            ulam_walk_opts o = bad_opts(k, mode);
            ulam_walk_result r;
            ulam_error err;
            assert_int_equal(ulam_solve_walks(M, ones, &o, &r, &err), ULAM_EINVAL);
            assert_int_equal(err.status, ULAM_EINVAL);
            assert_names(&err, walk_table[k].field);
            ulam_solver *s = NULL;
            assert_int_equal(ulam_solver_alloc(M, ones, &o, &s, &err), ULAM_EINVAL);
            assert_null(s);
        }
    }
    test_case_done();
    ulam_csr_free(M);
}

/* The walk options inside other entry points' options: outer iterations, bidirectional, the method
 * choice. */
static void test_nested_walk_options(void **state)
{
    (void)state;
    ulam_csr *M = chain(), *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    ulam_analysis *an = NULL;
    assert_int_equal(ulam_analysis_alloc(M, NULL, &an, NULL), ULAM_OK);
    for (int k = 0; k < NWALK; k++) {
        if (!test_case(k)) continue;
        ulam_error err;
        ulam_outer_opts oo = ulam_outer_defaults();
        oo.method = ULAM_SEQUENTIAL, oo.walk = bad_opts(k, ULAM_FORWARD);
        oo.walk.estimator = ULAM_COLLISION;
        double x[4];
        assert_int_equal(ulam_outer_solve(M, ones, &oo, x, NULL, 0, NULL, &err), ULAM_EINVAL);
        assert_names(&err, walk_table[k].field);
        ulam_bidir_opts bo = ulam_bidir_defaults();
        bo.walk = bad_opts(k, ULAM_ADJOINT), bo.target = 0, bo.source = 3, bo.rmax = 0.1;
        ulam_bidir_result br;
        assert_int_equal(ulam_analysis_bidir(an, &bo, &br, &err), ULAM_EINVAL);
        if (strncmp(walk_table[k].field, "kernel.continue_q", 17) && strncmp(walk_table[k].field, "kernel.kernel_alpha", 19))
            assert_names(&err, walk_table[k].field); /* else the analysis' own kernel refuses it first */
        ulam_fpush_opts fo = ulam_fpush_defaults();
        fo.walk = bad_opts(k, ULAM_FORWARD), fo.source = 0;
        ulam_fpush_info fi;
        assert_int_equal(ulam_fpush_solve(M, Mt, &fo, x, NULL, NULL, NULL, &fi, &err), ULAM_EINVAL);
        assert_names(&err, walk_table[k].field);
        ulam_walk_opts base = bad_opts(k, ULAM_ADJOINT);
        ulam_auto_opts ao = ulam_auto_defaults();
        ulam_auto_result *ar = malloc(sizeof *ar);
        assert_non_null(ar);
        assert_int_equal(ulam_auto_solver(M, ones, &base, &ao, ar, NULL, &err), ULAM_EINVAL);
        assert_names(&err, walk_table[k].field);
        free(ar);
    }
    test_case_done();
    ulam_analysis_free(an);
    ulam_csr_free(Mt);
    ulam_csr_free(M);
}

/* The other options structs and real arguments: guards, power iteration, Arnoldi, outer
 * iterations, the method choice, bidirectional, Krylov, Jacobi, push. */
static void test_other_options(void **state)
{
    (void)state;
    ulam_csr *M = chain(), *J = NULL, *Mt = NULL;
    assert_int_equal(ulam_csr_transpose(M, &Mt), ULAM_OK);
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        if (!test_case(k)) continue;
        double v = bad[k];
        ulam_error err;
        ulam_guard g;
        ulam_guard_opts go = ulam_guard_defaults();
        go.power.tol = v;
        assert_int_equal(ulam_guard_check(M, 0.0, &go, &g, &err), ULAM_EINVAL);
        assert_names(&err, "tol");
        go = ulam_guard_defaults(), go.kernel_alpha = v;
        assert_int_equal(ulam_guard_check(M, 0.0, &go, &g, &err), ULAM_EINVAL);
        assert_names(&err, "kernel_alpha");
        assert_int_equal(ulam_guard_check(M, v, NULL, &g, &err), ULAM_EINVAL);
        assert_names(&err, "continue_q");
        ulam_spectral_opts so = ulam_spectral_defaults();
        so.tol = v;
        ulam_radius rad;
        assert_int_equal(ulam_spectral_radius(M, 1, &so, &rad), ULAM_EINVAL);
        ulam_outer_opts oo = ulam_outer_defaults();
        oo.tol = v;
        double x[4], bp[4], res;
        assert_int_equal(ulam_outer_solve(M, ones, &oo, x, NULL, 0, NULL, &err), ULAM_EINVAL);
        oo = ulam_outer_defaults(), oo.eps1 = v;
        assert_int_equal(ulam_outer_solve(M, ones, &oo, x, NULL, 0, NULL, &err), ULAM_EINVAL);
        ulam_walk_opts base = ulam_walk_defaults();
        ulam_auto_opts ao = ulam_auto_defaults();
        ulam_auto_result *ar = malloc(sizeof *ar);
        assert_non_null(ar);
        ao.continue_q = v;
        assert_int_equal(ulam_auto_solver(M, ones, &base, &ao, ar, NULL, &err), ULAM_EINVAL);
        ao = ulam_auto_defaults(), ao.pilot_share = v;
        assert_int_equal(ulam_auto_solver(M, ones, &base, &ao, ar, NULL, &err), ULAM_EINVAL);
        free(ar);
        int it;
        assert_int_equal(ulam_cg(M, ones, v, 100, x, &it, &res), ULAM_EINVAL);
        assert_int_equal(ulam_gmres(M, ones, 10, v, 100, x, &it, &res), ULAM_EINVAL);
        assert_int_equal(ulam_jacobi(M, ones, v, &J, bp, &err), ULAM_EINVAL);
        assert_null(J);
        ulam_bidir_opts bo = ulam_bidir_defaults();
        bo.walk.stop.max_walks = 1000, bo.target = 0, bo.source = 3, bo.min_value = v;
        ulam_analysis *an = NULL;
        assert_int_equal(ulam_analysis_alloc(M, NULL, &an, NULL), ULAM_OK);
        ulam_bidir_result br;
        assert_int_equal(ulam_analysis_bidir(an, &bo, &br, &err), ULAM_EINVAL);
        ulam_analysis_free(an);
        ulam_fpush_opts fo = ulam_fpush_defaults();
        ulam_fpush_info fi;
        fo.min_value = v;
        assert_int_equal(ulam_fpush_solve(M, Mt, &fo, x, NULL, NULL, NULL, &fi, &err), ULAM_EINVAL);
        fo = ulam_fpush_defaults(), fo.rmax = v;
        assert_int_equal(ulam_fpush_solve(M, Mt, &fo, x, NULL, NULL, NULL, &fi, &err), ULAM_EINVAL);
        fo = ulam_fpush_defaults(), fo.step_cost = v;
        assert_int_equal(ulam_fpush_solve(M, Mt, &fo, x, NULL, NULL, NULL, &fi, &err), ULAM_EINVAL);
    }
    test_case_done();
    ulam_csr_free(Mt);
    ulam_csr_free(M);
}

/* A damaged copy of the chain: kind 0 rowptr[0] != 0, 1 a row pointer far past nnz, 2 falling
 * row pointers, 3 a negative one, 4 a column index past n, 5 a negative column, 6 rowptr[n]
 * negative, 7 more rows than ULAM_MAX_DIM. */
static ulam_csr *damaged(int kind)
{
    ulam_csr *M = chain();
    switch (kind) {
    case 0: M->rowptr[0] = 1; break;
    case 1: M->rowptr[2] = (int64_t)1 << 40; break;
    case 2: M->rowptr[2] = 0, M->rowptr[1] = 2; break;
    case 3: M->rowptr[1] = INT64_MIN / 2; break;
    case 4: M->colidx[1] = 1 << 30; break;
    case 5: M->colidx[0] = INT32_MIN; break;
    case 6: M->rowptr[4] = -5; break;
    }
    return M;
}
enum { NDAMAGED = 7 };

/* Every solver entry point refuses a structurally damaged matrix built by hand (it would read
 * out of bounds: a segfault or, under ASan, a report), with the status of ulam_csr_check's kind. */
static void test_damaged_matrix(void **state)
{
    (void)state;
    for (int kind = 0; kind < NDAMAGED; kind++) {
        if (!test_case(kind)) continue;
        ulam_csr *M = damaged(kind), *T = NULL, *J = NULL;
        ulam_error err;
        assert_int_not_equal(ulam_csr_check(M), ULAM_OK);
        for (int mode = 0; mode < 2; mode++)
            for (int est = 0; est < 3; est++) {
                ulam_walk_opts o = ulam_walk_defaults();
                o.mode = mode, o.estimator = est, o.stop.max_walks = 1000, o.exec.threads = 1;
                ulam_walk_result r;
                int st = ulam_solve_walks(M, ones, &o, &r, &err);
                assert_true(st == ULAM_ESYNTAX || st == ULAM_EINDEX);
                assert_int_equal(err.status, st);
            }
        ulam_guard g;
        ulam_csr *good = chain(); /* the guards given (a certificate): the walks read rows lazily */
        assert_int_equal(ulam_guard_check(good, 0.0, NULL, &g, &err), ULAM_OK);
        ulam_csr_free(good);
        for (int est = 0; est < 3; est++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.estimator = est, o.stop.max_walks = 1000, o.exec.threads = 1, o.policy.guard = &g;
            for (o.query.index = 0; o.query.index < 4; o.query.index++) {
                ulam_walk_result r;
                int st = ulam_solve_walks(M, ones, &o, &r, &err); /* refused or answered, never out of bounds */
                assert_true(st == ULAM_OK || st == ULAM_ESYNTAX || st == ULAM_EINDEX);
            }
        }
        assert_int_not_equal(ulam_guard_check(M, 0.0, NULL, &g, &err), ULAM_OK);
        ulam_radius rad;
        assert_int_not_equal(ulam_spectral_radius(M, 0, NULL, &rad), ULAM_OK);
        assert_int_not_equal(ulam_csr_transpose(M, &T), ULAM_OK);
        assert_null(T);
        double x[4], bp[4], res;
        int it;
        assert_int_not_equal(ulam_direct_solve(M, ones, x, 0, NULL, &err), ULAM_OK);
        ulam_direct_info di;
        assert_int_not_equal(ulam_reference_solve(M, ones, 1, 0, 0, x, &di, NULL, &err), ULAM_OK);
        assert_int_not_equal(ulam_cg(M, ones, 1e-8, 100, x, &it, &res), ULAM_OK);
        assert_int_not_equal(ulam_gmres(M, ones, 10, 1e-8, 100, x, &it, &res), ULAM_OK);
        assert_int_not_equal(ulam_jacobi(M, ones, 1.0, &J, bp, &err), ULAM_OK);
        assert_int_not_equal(ulam_outer_solve(M, ones, NULL, x, NULL, 0, NULL, &err), ULAM_OK);
        ulam_certificate c;
        assert_int_not_equal(ulam_certificate_compute(M, 0.0, NULL, &c, &err), ULAM_OK);
        ulam_csr_stats st;
        assert_int_not_equal(ulam_csr_stats_compute(M, &st), ULAM_OK);
        ulam_walk_opts base = ulam_walk_defaults();
        base.stop.max_walks = 1000;
        ulam_auto_opts ao = ulam_auto_defaults();
        ulam_auto_result *ar = malloc(sizeof *ar);
        assert_non_null(ar);
        assert_int_not_equal(ulam_auto_solver(M, ones, &base, &ao, ar, NULL, &err), ULAM_OK);
        free(ar);
        ulam_csr_free(M);
    }
    test_case_done();
}

/* The 3-state path M_{12} = M_{21} = M_{23} = M_{32} = a. */
static ulam_csr *path3(double a)
{
    int32_t ti[4] = {0, 1, 1, 2}, tj[4] = {1, 0, 2, 1};
    double tx[4] = {a, a, a, a};
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(3, 3, 4, ti, tj, tx, &M), ULAM_OK);
    return M;
}

/* Point 5: b = (1, 1e308, 1).  With a = 0.25 x_2 = 1.1428e308 is a double: walks (both modes,
 * every estimator) and Krylov answer it (walks within 4 standard errors of LAPACK's, finite
 * errors); with a = 0.49 x_2 = 1.92e308 is not: ULAM_ENONFINITE with a message, never inf +- 0. */
static void test_overflow(void **state)
{
    (void)state;
    const double b[3] = {1, 1e308, 1};
    ulam_csr *M = path3(0.25), *H = path3(0.49);
    double exact[3], x[3];
    ulam_error err;
    assert_int_equal(ulam_direct_solve(M, b, exact, 0, NULL, &err), ULAM_OK);
    for (int mode = 0; mode < 2; mode++)
        for (int est = 0; est < 3; est++) {
            test_case(mode * 3 + est);
            ulam_walk_opts o = ulam_walk_defaults();
            o.mode = mode, o.estimator = est, o.query.index = 1, o.stop.max_walks = 20000, o.exec.threads = 1;
            ulam_walk_result r;
            assert_int_equal(ulam_solve_walks(M, b, &o, &r, &err), ULAM_OK);
            assert_true(isfinite(r.estimate) && isfinite(r.std_error) && r.std_error > 0);
            assert_true(fabs(r.estimate - exact[1]) < 4 * r.std_error);
            int st = ulam_solve_walks(H, b, &o, &r, &err);
            assert_int_equal(st, ULAM_ENONFINITE);
            assert_non_null(strstr(err.msg, "double"));
        }
    test_case_done();
    int it;
    double res;
    assert_int_equal(ulam_gmres(M, b, 10, 1e-10, 100, x, &it, &res), ULAM_OK);
    assert_close(x[1] / exact[1], 1.0, 1e-9);
    assert_int_equal(ulam_cg(M, b, 1e-10, 100, x, &it, &res), ULAM_OK);
    assert_close(x[1] / exact[1], 1.0, 1e-9);
    assert_int_equal(ulam_gmres(H, b, 10, 1e-10, 100, x, &it, &res), ULAM_ENONFINITE);
    assert_int_equal(ulam_cg(H, b, 1e-10, 100, x, &it, &res), ULAM_ENONFINITE);
    ulam_csr_free(M);
    ulam_csr_free(H);
}

/* The scaling is exact: b 2^600 and b 2^-600 give the estimates of b times 2^600 and 2^-600, bit
 * for bit (and the same walks). */
static void test_scaling_exact(void **state)
{
    (void)state;
    ulam_csr *M = path3(0.3);
    const double b[3] = {1, -0.5, 2};
    for (int mode = 0; mode < 2; mode++) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.mode = mode, o.query.index = 1, o.stop.max_walks = 5000, o.exec.threads = 1;
        ulam_walk_result r0, r1;
        ulam_error err;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r0, &err), ULAM_OK);
        for (int k = -1; k <= 1; k += 2) {
            double bb[3];
            for (int i = 0; i < 3; i++) bb[i] = ldexp(b[i], 600 * k);
            assert_int_equal(ulam_solve_walks(M, bb, &o, &r1, &err), ULAM_OK);
            assert_true(r1.estimate == ldexp(r0.estimate, 600 * k));
            assert_true(r1.std_error == ldexp(r0.std_error, 600 * k));
            assert_int_equal(r1.walks, r0.walks);
            assert_int_equal(r1.steps, r0.steps);
        }
    }
    ulam_csr_free(M);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walk_options),   cmocka_unit_test(test_nested_walk_options),
        cmocka_unit_test(test_other_options),
        cmocka_unit_test(test_damaged_matrix), cmocka_unit_test(test_overflow),
        cmocka_unit_test(test_scaling_exact),
    };
    return test_run(tests);
}
