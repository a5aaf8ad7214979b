/* Allocation failure, as CSparse's coverage suite tests it: every allocation of an operation
 * fails in turn (the k-th, for k = 1, 2, ... until the operation no longer allocates that
 * many), and each failure must come back as an error status with nothing leaked.
 *
 * The library's calls to malloc, calloc, realloc, aligned_alloc and free are redirected here at
 * link time (-Wl,--wrap=...; see tests/meson.build), so the library itself is unchanged.  Live
 * blocks are tracked in a hash set: memory that libc allocates itself (getline's buffer) and
 * the library frees is not counted. */
#include "testutil.h"
#ifdef ULAM_RADIOSITY
#include "ulam_radiosity.h"
#endif

#include <execinfo.h>
#include <pthread.h>
#include <string.h>

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t sz);
void *__real_realloc(void *p, size_t n);
void *__real_aligned_alloc(size_t a, size_t n);
void __real_free(void *p);
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t sz);
void *__wrap_realloc(void *p, size_t n);
void *__wrap_aligned_alloc(size_t a, size_t n);
void __wrap_free(void *p);

enum { SLOTS = 1 << 20 };
static void *live[SLOTS]; /* open addressing; (void *)1 marks a deleted slot */
static long nlive, calls, fail_at;
static int armed, failed;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;

/* Slot of pointer p (for insertion: the first free one). */
static size_t slot_of(const void *p, int insert)
{
    size_t h = ((uintptr_t)p >> 4) * 0x9E3779B97F4A7C15ull >> 44;
    for (;; h = (h + 1) & (SLOTS - 1)) {
        if (live[h] == p) return h;
        if (!live[h] || (insert && live[h] == (void *)1)) return h;
    }
}

/* Count an allocation attempt; nonzero when this one must fail. */
static int must_fail(void)
{
    if (!armed) return 0;
    pthread_mutex_lock(&lock);
    int f = ++calls == fail_at;
    if (f) failed = 1;
    pthread_mutex_unlock(&lock);
    if (f && getenv("ULAM_ALLOC_TRACE")) { /* where the failing allocation is made */
        void *bt[8];
        backtrace_symbols_fd(bt, backtrace(bt, 8), 2);
    }
    return f;
}

/* Remember a new live block. */
static void *track(void *p)
{
    if (!p || !armed) return p;
    pthread_mutex_lock(&lock);
    live[slot_of(p, 1)] = p;
    nlive++;
    pthread_mutex_unlock(&lock);
    return p;
}

/* Forget a block being freed (if it was tracked). */
static void untrack(void *p)
{
    if (!p) return;
    pthread_mutex_lock(&lock);
    size_t h = slot_of(p, 0);
    if (live[h] == p) {
        live[h] = (void *)1;
        nlive--;
    }
    pthread_mutex_unlock(&lock);
}

void *__wrap_malloc(size_t n) { return must_fail() ? NULL : track(__real_malloc(n)); }
void *__wrap_calloc(size_t n, size_t sz) { return must_fail() ? NULL : track(__real_calloc(n, sz)); }
void *__wrap_aligned_alloc(size_t a, size_t n) { return must_fail() ? NULL : track(__real_aligned_alloc(a, n)); }
void __wrap_free(void *p)
{
    untrack(p);
    __real_free(p);
}
void *__wrap_realloc(void *p, size_t n)
{
    if (must_fail()) return NULL;
    untrack(p);
    void *q = __real_realloc(p, n);
    if (!q && p) return track(p), NULL;
    return track(q);
}

/* An operation under test: returns its status, freeing everything it made. */
typedef int (*operation)(void);

/* Fail allocation k = 1, 2, ... of op in turn; every failure must return ULAM_ENOMEM with no
 * tracked block left, or, for an allocation that is only an optimisation (the Matrix Market
 * reader's bigger buffer), succeed all the same.  Returns the number of allocations op makes;
 * *optional counts the failures op got through. */
static long countdown(operation op, const char *name, long *optional)
{
    *optional = 0;
    long k;
    for (k = 1; k < 100000; k++) {
        memset(live, 0, sizeof live);
        nlive = calls = 0, failed = 0, fail_at = k, armed = 1;
        int status = op();
        armed = 0;
        if (nlive != 0) print_error("%s: allocation %ld failed, %ld blocks leaked (status %d)\n", name, k, nlive, status);
        assert_int_equal(nlive, 0);
        if (!failed) {
            assert_int_equal(status, ULAM_OK);
            return k - 1;
        }
        if (status != ULAM_OK && status != ULAM_ENOMEM)
            print_error("%s: allocation %ld failed, status %d (%s)\n", name, k, status, ulam_strerror(status));
        assert_true(status == ULAM_OK || status == ULAM_ENOMEM);
        *optional += status == ULAM_OK;
        if (status == ULAM_OK && getenv("ULAM_ALLOC_TRACE")) fprintf(stderr, "OPTIONAL %s %ld\n", name, k);
    }
    fail();
    return k;
}

/* The Matrix Market reader and the CSR build. */
static int op_read(void)
{
    ulam_csr *A = NULL, *T = NULL;
    double *x = NULL;
    int64_t n;
    int s = ulam_mm_read_matrix("matrices/chain4.mtx", &A, NULL);
    if (!s) s = ulam_mm_read_vector("matrices/chain4_b.mtx", &x, &n, NULL);
    if (!s) s = ulam_csr_transpose(A, &T);
    ulam_csr_free(A), ulam_csr_free(T), free(x);
    return s;
}

/* A walk run: kernel (alias tables), source, workspace and the walks, in one mode. */
static int walk_run(int mode, int est)
{
    ulam_csr *M = NULL;
    double *b = NULL;
    int64_t n;
    int s = ulam_mm_read_matrix("matrices/chain4.mtx", &M, NULL);
    if (!s) s = ulam_mm_read_vector("matrices/chain4_b.mtx", &b, &n, NULL);
    ulam_walk_opts o = ulam_walk_defaults();
    double w0 = mode == ULAM_ADJOINT ? 1.0 : 0.0; /* the start weight: 1 adjoint, ||b||_1 forward (a split weight below it is refused) */
    for (int64_t i = 0; !s && mode == ULAM_FORWARD && i < n; i++) w0 += fabs(b[i]);
    o.mode = mode, o.estimator = est, o.stop.max_walks = 3000, o.exec.threads = 2, o.kernel.roulette = 0.1 * w0, o.kernel.split = 2 * w0;
    ulam_walk_result r;
    if (!s) s = ulam_solve_walks(M, b, &o, &r, NULL);
    ulam_csr_free(M), free(b);
    return s;
}
static int op_walk_adjoint(void) { return walk_run(ULAM_ADJOINT, ULAM_COLLISION); }
static int op_walk_forward(void) { return walk_run(ULAM_FORWARD, ULAM_ABSORPTION); }

/* Sequential MC and MCSA (the walk solver built once and restarted on each residual), CG and
 * GMRES. */
static int op_outer(void)
{
    ulam_csr *M = NULL;
    double *b = NULL, x[4];
    int64_t n;
    int s = ulam_mm_read_matrix("matrices/chain4.mtx", &M, NULL);
    if (!s) s = ulam_mm_read_vector("matrices/chain4_b.mtx", &b, &n, NULL);
    for (int m = ULAM_SEQUENTIAL; m <= ULAM_MCSA && !s; m++) {
        ulam_outer_opts o = ulam_outer_defaults();
        o.method = m, o.tol = 1e-3, o.walk.exec.threads = 2;
        s = ulam_outer_solve(M, b, &o, x, NULL, 0, NULL, NULL);
    }
    int its;
    double res;
    if (!s) s = ulam_gmres(M, b, 2, 1e-8, 100, x, &its, &res);
    ulam_csr_free(M), free(b);
    return s;
}

/* The guards and the direct solve. */
static int op_guard_direct(void)
{
    ulam_csr *M = NULL;
    int s = ulam_mm_read_matrix("matrices/chain4.mtx", &M, NULL);
    ulam_guard g;
    if (!s) s = ulam_guard_check(M, 0, NULL, &g, NULL);
    double b[4] = {1, 1, 1, 1}, x[4];
    if (!s) s = ulam_direct_solve(M, b, x, 0, NULL, NULL);
    ulam_csr_free(M);
    return s;
}

#ifdef ULAM_RADIOSITY
/* The OBJ reader, subdivision, tracer, form factors, both patch walks and a point query. */
static int op_radiosity(void)
{
    ulam_scene *s0 = NULL, *s = NULL;
    ulam_tracer *t = NULL;
    ulam_csr *F = NULL;
    ulam_rad_solver *sv = NULL;
    int st = ulam_scene_read_obj("examples/scenes/cube.obj", &s0, NULL);
    if (!st) st = ulam_scene_subdivide(s0, 0.5, &s);
    if (!st) st = ulam_tracer_alloc(s, &t, NULL);
    if (!st) st = ulam_ff_estimate(t, 50, 1, 2, &F, NULL);
    for (int mode = 0; mode < 2 && !st; mode++) {
        ulam_rad_opts o = ulam_rad_defaults();
        o.mode = mode, o.stop.max_walks = 600, o.exec.threads = 2;
        o.estimator = mode ? ULAM_RAD_COLLISION : ULAM_RAD_NEXT_EVENT; /* shooting has no next event */
        if (!(st = ulam_rad_solver_alloc(t, &o, &sv, NULL)))
            while (!st && !ulam_rad_solver_done(sv)) st = ulam_rad_solver_iterate(sv);
        sv = ulam_rad_solver_free(sv);
    }
    if (!st) { /* a point query on the continuous surfaces */
        ulam_rad_opts o = ulam_rad_defaults();
        o.stop.max_walks = 600, o.exec.threads = 2;
        ulam_rad_point pt;
        st = ulam_rad_point_query(t, &o, (const double[3]){0.5, 0, 0.5}, NULL, &pt, NULL);
    }
    ulam_csr_free(F);
    ulam_tracer_free(t);
    ulam_scene_free(s), ulam_scene_free(s0);
    return st;
}
#endif

/* Each operation survives the failure of each of its allocations. */
static void test_countdown(void **state)
{
    (void)state;
    static const struct {
        operation op;
        const char *name;
    } ops[] = {{op_read, "Matrix Market reader and CSR"},
               {op_walk_adjoint, "adjoint walks"},
               {op_walk_forward, "forward walks"},
               {op_guard_direct, "guards and direct solve"},
               {op_outer, "sequential MC, MCSA, GMRES"},
#ifdef ULAM_RADIOSITY
               {op_radiosity, "OBJ reader, tracer, form factors, patch walks"},
#endif
    };
    for (size_t k = 0; k < sizeof ops / sizeof *ops; k++) {
        if (!test_case((long)k)) continue;
        long optional, n = countdown(ops[k].op, ops[k].name, &optional);
        print_message("%-48s %4ld allocations failed in turn: %ld ENOMEM, %ld optional\n", ops[k].name, n,
                      n - optional, optional);
        assert_true(n > 3 && optional <= 2);
    }
    test_case_done();
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_countdown)};
    return test_run(tests);
}
