/* Helpers shared by the tests; like the tests, it includes only the public header. */
#ifndef ULAM_TESTUTIL_H
#define ULAM_TESTUTIL_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <string.h>
#include <unistd.h>

#include "ulam.h"

/* Seeded test tables (pixman style).  A loop over a table of cases or over seeds calls
 * test_case(k) first in each iteration and test_case_done() after the loop; a test that fails
 * inside case k then says so (test_case_report, the teardown test_run gives every test), and
 *     ULAM_TEST_CASE=k build/tests/test_walk
 * runs case k alone in every table (the other cases are skipped, and so are the checks over the
 * whole table: a coverage count over seeds means nothing for one seed); ULAM_TEST=NAME runs only
 * the tests whose name matches NAME (* and ? wildcards), e.g.
 *     ULAM_TEST=test_adjoint_coverage ULAM_TEST_CASE=17 build/tests/test_walk
 * A case of a nested loop is numbered outer * 1000 + inner. */
static struct {
    long k;     /* the case being run */
    int active; /* inside a table's loop */
    long ran;   /* cases entered (a ULAM_TEST_CASE that no table has is an error, not a pass) */
} test_case_state;

/* The case ULAM_TEST_CASE names, or -1 (every case). */
static inline long test_case_only(void)
{
    const char *s = getenv("ULAM_TEST_CASE");
    char *end;
    long k = s && *s ? strtol(s, &end, 10) : -1;
    return s && *s && !*end && k >= 0 ? k : -1;
}

/* Nonzero when every case of the tables runs (no ULAM_TEST_CASE): checks over a whole table. */
static inline int test_case_all(void)
{
    return test_case_only() < 0;
}

/* Enter case k of a table; 0 when ULAM_TEST_CASE names another (skip it). */
static inline int test_case(long k)
{
    long only = test_case_only();
    if (only >= 0 && k != only) return 0;
    test_case_state.k = k, test_case_state.active = 1, test_case_state.ran++;
    return 1;
}

/* Leave a table's loop (every case run passed). */
static inline void test_case_done(void)
{
    test_case_state.active = 0;
}

/* Teardown of every test: name the case a test stopped in (it failed inside a table's loop) and
 * how to rerun it; *state is the test's name (test_run), the tests that loop over cases having
 * no state of their own. */
static inline int test_case_report(void **state)
{
    if (test_case_state.active)
        print_error("[  CASE    ] failed in case %ld: rerun it alone with ULAM_TEST=%s ULAM_TEST_CASE=%ld\n",
                    test_case_state.k, state && *state ? (const char *)*state : "NAME", test_case_state.k);
    test_case_state.active = 0;
    return 0;
}

/* Nonzero when the comma-separated list names holds name. */
static inline int test_listed(const char *names, const char *name)
{
    size_t len = strlen(name);
    for (const char *p = names; *p; p += strcspn(p, ",") + (p[strcspn(p, ",")] == ',')) {
        if (strcspn(p, ",") == len && !strncmp(p, name, len)) return 1;
    }
    return 0;
}

/* Keep those of the n tests t[] that ULAM_TEST_ONLY lists, or those ULAM_TEST_EXCEPT does not
 * (comma-separated names: meson runs a long program as two tests, one of each, so that both
 * cores work and every test runs once); the count kept, or -1 when the list names a test the
 * program lacks.  ULAM_TEST or ULAM_TEST_CASE (a rerun by hand) selects from all of them. */
static inline long test_shard(struct CMUnitTest *t, size_t n)
{
    const char *only = getenv("ULAM_TEST_ONLY"), *except = getenv("ULAM_TEST_EXCEPT"), *name = getenv("ULAM_TEST");
    const char *names = only && *only ? only : except && *except ? except : NULL;
    if (!names || (name && *name) || test_case_only() >= 0) return (long)n;
    for (const char *p = names; *p; p += strcspn(p, ",") + (p[strcspn(p, ",")] == ',')) {
        size_t k = 0, len = strcspn(p, ",");
        while (k < n && !(strlen(t[k].name) == len && !strncmp(p, t[k].name, len))) k++;
        if (k == n) {
            print_error("[  SHARD   ] no test '%.*s' in this program (ULAM_TEST_ONLY / ULAM_TEST_EXCEPT)\n", (int)len, p);
            return -1;
        }
    }
    size_t m = 0;
    for (size_t k = 0; k < n; k++)
        if (test_listed(names, t[k].name) == (names == only)) t[m++] = t[k];
    return (long)m;
}

/* Run a program's tests (as cmocka_run_group_tests), each with test_case_report as teardown (and
 * its name as state where it has none), filtered by ULAM_TEST and sharded by test_shard. */
#define test_run(tests) test_run_(#tests, (tests), sizeof(tests) / sizeof *(tests))

static inline int test_run_(const char *group, const struct CMUnitTest *tests, size_t n)
{
    struct CMUnitTest *t = malloc(n * sizeof *t);
    if (!t) return 1;
    memcpy(t, tests, n * sizeof *t);
    for (size_t k = 0; k < n; k++) {
        if (!t[k].teardown_func) t[k].teardown_func = test_case_report;
        if (!t[k].initial_state) t[k].initial_state = (void *)(uintptr_t)t[k].name;
    }
    long kept = test_shard(t, n);
    if (kept < 0) return free(t), 1;
    n = (size_t)kept;
    const char *only = getenv("ULAM_TEST");
    if (only && *only) cmocka_set_test_filter(only);
    int rc = _cmocka_run_group_tests(group, t, n, NULL, NULL);
    free(t);
    if (test_case_only() >= 0 && test_case_state.ran == 0) {
        print_error("[  CASE    ] no table of the tests run has case %ld (ULAM_TEST_CASE)\n", test_case_only());
        return 1;
    }
    return rc;
}

/* The order of two doubles (qsort). */
static inline int test_cmp_double(const void *a, const void *b)
{
    double u = *(const double *)a, v = *(const double *)b;
    return u < v ? -1 : u > v;
}

/* Fail unless |a - b| <= tol (cmocka 1.1 has no assert_double_equal). */
#define assert_close(a, b, tol) assert_close_((a), (b), (tol), #a, __FILE__, __LINE__)

static inline void assert_close_(double a, double b, double tol, const char *expr, const char *file,
                                 int line)
{
    if (!(fabs(a - b) <= tol)) {
        print_error("%s = %.17g, expected %.17g within %g (off by %.3g)\n", expr, a, b, tol, fabs(a - b));
        _fail(file, line);
    }
}

/* Path of a file under the source tree (tests run with the source root as cwd). */
static inline const char *src_path(const char *rel)
{
    static char buf[4][1024];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s", rel);
    return buf[k];
}

/* Read a matrix that must parse. */
static inline ulam_csr *must_read(const char *rel)
{
    ulam_csr *A = NULL;
    ulam_error err;
    int s = ulam_mm_read_matrix(src_path(rel), &A, &err);
    if (s) print_error("%s:%ld: %s: %s\n", rel, err.line, ulam_strerror(s), err.msg);
    assert_int_equal(s, ULAM_OK);
    return A;
}

/* M written with its transpose as a prepared file at path (a mkstemp template, filled in), and M's
 * forward guard in *g (what a query on the file is given, as the command line gives the file's
 * certificate). */
static inline void must_prepare(const ulam_csr *M, char *path, ulam_guard *g)
{
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_FORWARD;
    assert_int_equal(ulam_guard_check(M, 0.0, &go, g, NULL), ULAM_OK);
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = M, d.n = M->nrows, d.transpose = 1;
    assert_int_equal(ulam_system_write(path, &d), ULAM_OK);
}

/* Read a vector that must parse. */
static inline double *must_read_vector(const char *rel, int64_t *n)
{
    double *x = NULL;
    ulam_error err;
    int s = ulam_mm_read_vector(src_path(rel), &x, n, &err);
    if (s) print_error("%s:%ld: %s: %s\n", rel, err.line, ulam_strerror(s), err.msg);
    assert_int_equal(s, ULAM_OK);
    return x;
}

/* Value of A(i, j), 0 when not stored. */
static inline double csr_get(const ulam_csr *A, int64_t i, int64_t j)
{
    for (int64_t k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
        if (A->colidx[k] == j) return A->val[k];
    return 0.0;
}

/* Fail unless A and B are the same matrix, array for array. */
static inline void assert_csr_same(const ulam_csr *A, const ulam_csr *B)
{
    assert_int_equal(A->nrows, B->nrows);
    assert_int_equal(A->ncols, B->ncols);
    assert_int_equal(ulam_csr_nnz(A), ulam_csr_nnz(B));
    assert_memory_equal(A->rowptr, B->rowptr, (size_t)(A->nrows + 1) * sizeof *A->rowptr);
    assert_memory_equal(A->colidx, B->colidx, (size_t)ulam_csr_nnz(A) * sizeof *A->colidx);
    assert_memory_equal(A->val, B->val, (size_t)ulam_csr_nnz(A) * sizeof *A->val);
}

/* A system (I - M) x = b and its LAPACK solution x. */
typedef struct {
    ulam_csr *M;
    double *b, *x;
    int64_t n;
} test_sys;

/* Solve s with LAPACK into a new s->x. */
static inline void test_sys_solve(test_sys *s)
{
    s->x = malloc((size_t)s->n * sizeof *s->x);
    assert_int_equal(ulam_direct_solve(s->M, s->b, s->x, 0, NULL, NULL), ULAM_OK);
}

/* Load matrices/NAME.mtx and its b (matrices/NAME_b.mtx), with the Jacobi splitting
 * M = I - D^-1 A when jacobi (the file then holds A), solved with LAPACK. */
static inline test_sys test_sys_load_split(const char *name, int jacobi)
{
    char mp[256], bp[256];
    snprintf(mp, sizeof mp, "matrices/%s.mtx", name);
    snprintf(bp, sizeof bp, "matrices/%s_b.mtx", name);
    test_sys s;
    s.M = must_read(mp);
    s.b = must_read_vector(bp, &s.n);
    if (jacobi) {
        ulam_csr *M = NULL;
        assert_int_equal(ulam_jacobi(s.M, s.b, 1.0, &M, s.b, NULL), ULAM_OK);
        ulam_csr_free(s.M);
        s.M = M;
    }
    test_sys_solve(&s);
    return s;
}

/* Load matrices/NAME.mtx and its b (matrices/NAME_b.mtx), solved with LAPACK. */
static inline test_sys test_sys_load(const char *name)
{
    return test_sys_load_split(name, 0);
}

/* Free a loaded system. */
static inline void test_sys_free(test_sys *s)
{
    ulam_csr_free(s->M);
    free(s->b), free(s->x);
}

/* Run walks on s; they must succeed with the walks asked for. */
static inline ulam_walk_result test_sys_run(const test_sys *s, ulam_walk_opts o)
{
    ulam_walk_result r;
    ulam_error err;
    int st = ulam_solve_walks(s->M, s->b, &o, &r, &err);
    if (st) print_error("ulam_solve_walks: %s: %s\n", ulam_strerror(st), err.msg);
    assert_int_equal(st, ULAM_OK);
    assert_true(r.walks == o.stop.max_walks);
    return r;
}

/* The certificate a prepared system stores (NULL: none). */
static inline const ulam_certificate *system_cert(const ulam_system *s)
{
    ulam_system_info si;
    ulam_system_get_info(s, &si);
    return si.cert;
}

/* The primary call as `ulam solve` makes it on a Matrix Market file: a fresh analysis of M with
 * its defaults, ulam_analysis_solve with no pins but o's; *r gets the walks' result with the
 * whole answer's estimate, std_error and ci95 (bidirectional: its walks on <r, x>). */
static inline int solve_default(const ulam_csr *M, const double *b, const ulam_walk_opts *o, ulam_walk_result *r,
                                ulam_error *err)
{
    ulam_analysis *a = NULL;
    ulam_answer *ans = calloc(1, sizeof *ans);
    int status = ans ? ulam_analysis_alloc(M, NULL, &a, err) : ULAM_ENOMEM;
    if (!status) status = ulam_analysis_solve(a, b, o, NULL, NULL, NULL, ans, err);
    if (ans && (!status || ans->method >= 0)) {
        *r = ans->walks;
        r->estimate = ans->estimate, r->std_error = ans->std_error, r->ci95[0] = ans->ci95[0], r->ci95[1] = ans->ci95[1];
    }
    ulam_analysis_free(a);
    free(ans);
    return status;
}

/* A nonnegative n x n matrix whose Perron root is exactly rho but whose row and column sums
 * vary (so no one-pass bound is tight) and whose spectral gap is ~1/n^2 (so power iteration
 * converges slowly): rho / cos(pi / (n + 1)) D^-1 T D, T the path graph's tridiagonal (1/2
 * off the diagonal, radius cos(pi / (n + 1))), D = diag(exp(0.4 sin(0.05 k))). */
static inline ulam_csr *near_one_matrix(int32_t n, double rho)
{
    int32_t *ti = malloc(2 * (size_t)n * sizeof *ti), *tj = malloc(2 * (size_t)n * sizeof *tj);
    double *tx = malloc(2 * (size_t)n * sizeof *tx), c = rho / cos(M_PI / (n + 1));
    int64_t nz = 0;
    for (int32_t k = 0; k + 1 < n; k++) {
        double dk = exp(0.4 * sin(0.05 * k)), dl = exp(0.4 * sin(0.05 * (k + 1)));
        ti[nz] = k, tj[nz] = k + 1, tx[nz++] = c * 0.5 * dl / dk;
        ti[nz] = k + 1, tj[nz] = k, tx[nz++] = c * 0.5 * dk / dl;
    }
    ulam_csr *A = NULL;
    int s = ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A);
    free(ti), free(tj), free(tx);
    assert_int_equal(s, ULAM_OK);
    return A;
}

/* A system with rare high absorption scores (the kind that fools optional stopping): states 0..2
 * are rare, with p* = pstar and b = brare, their rows (1 - pstar in all) going to 4 bulk states;
 * every bulk state i >= 3 moves to 4 bulk states (row sum 0.55..0.85) and with probability eps
 * to a rare one, and has b_i ~ U(0, 1).  Walks start at a bulk state (index 3).  seed picks the
 * structure.  *b is malloc'd. */
static inline ulam_csr *rare_system(int32_t n, double pstar, double brare, double eps, uint64_t seed, double **b)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 77);
    int32_t *ti = malloc(6 * (size_t)n * sizeof *ti), *tj = malloc(6 * (size_t)n * sizeof *tj);
    double *tx = malloc(6 * (size_t)n * sizeof *tx);
    *b = malloc((size_t)n * sizeof **b);
    int64_t nz = 0;
    for (int32_t i = 0; i < n; i++) {
        int rare = i < 3;
        double w[4], sw = 0, total = rare ? 1 - pstar : 0.55 + 0.3 * ulam_rng_uniform(&r);
        for (int k = 0; k < 4; k++) sw += w[k] = 0.2 + ulam_rng_uniform(&r);
        for (int k = 0; k < 4; k++) { /* distinct bulk targets: one from each quarter of the bulk */
            int32_t q = (n - 3) / 4;
            ti[nz] = i, tj[nz] = 3 + k * q + (int32_t)ulam_rng_bounded(&r, (uint64_t)q), tx[nz++] = total * w[k] / sw;
        }
        if (!rare && eps > 0) ti[nz] = i, tj[nz] = (int32_t)ulam_rng_bounded(&r, 3), tx[nz++] = eps;
        (*b)[i] = rare ? brare : ulam_rng_uniform(&r);
    }
    ulam_csr *A = NULL;
    int s = ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &A);
    free(ti), free(tj), free(tx);
    assert_int_equal(s, ULAM_OK);
    return A;
}

/* A random n x n system with k entries a row (columns drawn with replacement, duplicates summed),
 * values U(0.2, 1) with a random sign when signed_, each row of |M| scaled to sum to U(0.3, rowsum). */
static inline ulam_csr *test_random_system(int64_t n, int k, int signed_, double rowsum, uint64_t seed)
{
    ulam_rng r;
    ulam_rng_seed(&r, seed, 0);
    int64_t nz = n * k;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    for (int64_t i = 0; i < n; i++) {
        double sum = 0, target = 0.3 + (rowsum - 0.3) * ulam_rng_uniform(&r);
        for (int q = 0; q < k; q++) {
            int64_t e = i * k + q;
            ti[e] = (int32_t)i;
            tj[e] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n);
            tx[e] = 0.2 + 0.8 * ulam_rng_uniform(&r);
            sum += tx[e];
            if (signed_ && ulam_rng_uniform(&r) < 0.4) tx[e] = -tx[e];
        }
        for (int q = 0; q < k; q++) tx[i * k + q] *= target / sum;
    }
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M), ULAM_OK);
    free(ti), free(tj), free(tx);
    return M;
}

/* A scene written by a test (radiosity): a new temporary directory dir (under $TMPDIR, else the
 * system's) holding scene.obj (path) and scene.mtl, whose text is mtl; returns the OBJ open for
 * writing, its mtllib line written. */
static inline FILE *test_scene_open(char dir[64], char path[96], const char *mtl)
{
    const char *tmp = getenv("TMPDIR");
    assert_true(snprintf(dir, 64, "%s/ulam_scene_XXXXXX", tmp && *tmp ? tmp : P_tmpdir) < 64);
    assert_non_null(mkdtemp(dir));
    char m[96];
    snprintf(path, 96, "%s/scene.obj", dir), snprintf(m, sizeof m, "%s/scene.mtl", dir);
    FILE *f = fopen(m, "w");
    assert_non_null(f);
    fputs(mtl, f);
    fclose(f);
    assert_non_null(f = fopen(path, "w"));
    fprintf(f, "mtllib scene.mtl\n");
    return f;
}

/* An open box: X x Y x Z without its top (y = Y), in unit patches (Kd 0.6): the floor y = 0, the
 * walls z = 0, z = Z, x = 0, x = X (sides 0 .. 4, in that order), one of them a lamp (Ke 10): side
 * lside's cell (li, lj). */
static inline void test_open_box_sized(char dir[64], char path[96], int X, int Y, int Z, int lside, int li, int lj)
{
    FILE *f = test_scene_open(dir, path, "newmtl g\nKd 0.6 0.6 0.6\nnewmtl lamp\nKd 0.6 0.6 0.6\nKe 10 10 10\n");
    /* each side: origin, u, v (u x v points in); its cells along u and v */
    const double side[5][3][3] = {{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                  {{0, 0, Z}, {0, 1, 0}, {1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                  {{X, 0, 0}, {0, 0, 1}, {0, 1, 0}}};
    const int cells[5][2] = {{Z, X}, {X, Y}, {Y, X}, {Y, Z}, {Z, Y}};
    int v = 0;
    for (int k = 0; k < 5; k++)
        for (int i = 0; i < cells[k][0]; i++)
            for (int j = 0; j < cells[k][1]; j++) {
                const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
                for (int q = 0; q < 4; q++) {
                    double x[3];
                    for (int d = 0; d < 3; d++)
                        x[d] = side[k][0][d] + (i + du[q]) * side[k][1][d] + (j + dv[q]) * side[k][2][d];
                    fprintf(f, "v %g %g %g\n", x[0], x[1], x[2]);
                }
                fprintf(f, "usemtl %s\nf %d %d %d %d\n", k == lside && i == li && j == lj ? "lamp" : "g", v + 1, v + 2,
                        v + 3, v + 4);
                v += 4;
            }
    fclose(f);
}

/* The open box: a 4 x 4 x 4 box without its top, 80 unit patches (Kd 0.6), one of them a lamp
 * (Ke 10) on the wall z = 0 (the radiosity tests' scene). */
static inline void test_open_box(char dir[64], char path[96])
{
    test_open_box_sized(dir, path, 4, 4, 4, 1, 3, 1);
}

/* Remove test_scene_open's directory and files. */
static inline void test_scene_rm(const char *dir)
{
    char p[96];
    snprintf(p, sizeof p, "%s/scene.obj", dir), remove(p);
    snprintf(p, sizeof p, "%s/scene.mtl", dir), remove(p);
    remove(dir);
}

#endif
