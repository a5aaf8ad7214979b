/* Two solvers at once on one shared read-only system (issue 26, Checks): pthreads each running
 * ulam_solve_walks on the same mapped prepared system (its matrix, b and certificate shared, nothing
 * copied) must give, bit for bit, what the same runs give one after the other; the library holds
 * no global state.  CI runs this test under ThreadSanitizer (.ci/run). */
#include "testutil.h"

#include <pthread.h>

/* One run: its options, its result and status. */
typedef struct job {
    const ulam_csr *M;
    const double *b;
    ulam_walk_opts o;
    ulam_walk_result r;
    int status;
} job;

/* Run job j (a thread's body). */
static void *run(void *p)
{
    job *j = p;
    ulam_error err;
    j->status = ulam_solve_walks(j->M, j->b, &j->o, &j->r, &err);
    return NULL;
}

/* A random sparse substochastic M (n states, about 6 entries a row, row sums <= 0.8) and b. */
static ulam_csr *random_system(int64_t n, double *b)
{
    ulam_rng g;
    ulam_rng_seed(&g, 7, 0);
    int64_t nz = n * 6;
    int32_t *ti = malloc((size_t)nz * sizeof *ti), *tj = malloc((size_t)nz * sizeof *tj);
    double *tx = malloc((size_t)nz * sizeof *tx);
    for (int64_t k = 0; k < nz; k++) {
        ti[k] = (int32_t)(k / 6), tj[k] = (int32_t)ulam_rng_bounded(&g, (uint64_t)n);
        tx[k] = (ulam_rng_uniform(&g) < 0.3 ? -1 : 1) * 0.8 / 6 * ulam_rng_uniform(&g);
    }
    for (int64_t i = 0; i < n; i++) b[i] = ulam_rng_uniform(&g) - 0.3;
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, nz, ti, tj, tx, &M), ULAM_OK);
    free(ti), free(tj), free(tx);
    return M;
}

static void assert_same(const ulam_walk_result *a, const ulam_walk_result *b)
{
    assert_true(memcmp(&a->estimate, &b->estimate, sizeof a->estimate) == 0);
    assert_true(memcmp(&a->std_error, &b->std_error, sizeof a->std_error) == 0);
    assert_true(memcmp(&a->variance, &b->variance, sizeof a->variance) == 0);
    assert_int_equal(a->walks, b->walks);
    assert_int_equal(a->steps, b->steps);
    assert_int_equal(a->cut, b->cut);
}

/* Four solvers (adjoint at two states, forward, a rel_err run), on the mapped system with its
 * certificate, twice at once in pairs, against the sequential runs. */
static void test_two_solvers(void **state)
{
    (void)state;
    enum { N = 300 };
    double b[N];
    ulam_csr *A = random_system(N, b);
    ulam_certificate cert;
    ulam_error err;
    assert_int_equal(ulam_certificate_compute(A, 0.0, NULL, &cert, &err), ULAM_OK);
    FILE *f = tmpfile();
    assert_non_null(f);
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = A, d.b = b, d.n = N, d.cert = &cert;
    assert_int_equal(ulam_system_write_file(f, &d), ULAM_OK);
    fflush(f);
    char path[64];
    snprintf(path, sizeof path, "/proc/self/fd/%d", fileno(f));
    ulam_system *sys = NULL;
    assert_int_equal(ulam_system_open(path, NULL, &sys, &err), ULAM_OK);
    const ulam_csr *M = ulam_system_matrix(sys);
    const double *mb = ulam_system_rhs(sys, NULL);
    ulam_guard g;
    assert_int_equal(ulam_certificate_guard(system_cert(sys), 0.0, NULL, &g), ULAM_OK);
    job jobs[4];
    for (int k = 0; k < 4; k++) {
        jobs[k] = (job){.M = M, .b = mb, .o = ulam_walk_defaults()};
        jobs[k].o.exec.threads = 2, jobs[k].o.stop.max_walks = 20000, jobs[k].o.exec.seed = 11 + (uint64_t)k;
        jobs[k].o.policy.guard = k == 1 ? NULL : &g; /* one computes its own guards over the shared M */
    }
    jobs[0].o.query.index = 3, jobs[1].o.query.index = 250, jobs[1].o.estimator = ULAM_ABSORPTION;
    jobs[2].o.mode = ULAM_FORWARD, jobs[2].o.query.index = 17;
    jobs[3].o.query.index = 42, jobs[3].o.stop.max_walks = 0, jobs[3].o.stop.rel_err = 0.05;
    ulam_walk_result seq[4];
    for (int k = 0; k < 4; k++) {
        run(&jobs[k]);
        assert_int_equal(jobs[k].status, ULAM_OK);
        seq[k] = jobs[k].r;
    }
    for (int pair = 0; pair < 2; pair++) { /* (0, 1) and (2, 3) at once, then (0, 2) and (1, 3) */
        int a[2][2] = {{0, 1}, {2, 3}}, c[2][2] = {{0, 2}, {1, 3}};
        for (int h = 0; h < 2; h++) {
            int *q = pair ? c[h] : a[h];
            pthread_t t[2];
            for (int u = 0; u < 2; u++) assert_int_equal(pthread_create(&t[u], NULL, run, &jobs[q[u]]), 0);
            for (int u = 0; u < 2; u++) assert_int_equal(pthread_join(t[u], NULL), 0);
            for (int u = 0; u < 2; u++) {
                assert_int_equal(jobs[q[u]].status, ULAM_OK);
                assert_same(&jobs[q[u]].r, &seq[q[u]]);
            }
        }
    }
    ulam_system_free(sys);
    fclose(f);
    ulam_csr_free(A);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_two_solvers)};
    return test_run(tests);
}
