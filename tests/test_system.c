/* Prepared systems: written and mapped back exactly, stale and corrupt files refused at open
 * (a table of damaged headers), corrupt arrays refused by the check and by the walk kernel
 * when a walk reaches them, and a query that reads no page of rows its walks do not reach. */
#include "testutil.h"

#include <math.h>
#include <pthread.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>
#include <xxhash.h>

/* The bytes of a prepared file of M and b in *len, malloc'd (via a temporary file). */
/* The walks o names on analysis a's kept kernel, to their end (ulam_analysis_solver), r filled. */
static int walks_on(ulam_analysis *a, const double *b, const ulam_walk_opts *o, ulam_walk_result *r, ulam_error *err)
{
    ulam_solver *sv = NULL;
    int status = ulam_analysis_solver(a, b, o, &sv, err);
    while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
    if (sv) ulam_solver_result(sv, r);
    ulam_solver_free(sv);
    return status;
}

static unsigned char *file_bytes(const ulam_system_desc *d, size_t *len)
{
    FILE *f = tmpfile();
    assert_non_null(f);
    assert_int_equal(ulam_system_write_file(f, d), ULAM_OK);
    long n = ftell(f);
    rewind(f);
    unsigned char *p = malloc((size_t)n + 8);
    assert_non_null(p);
    assert_int_equal(fread(p, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *len = (size_t)n;
    return p;
}

/* The header word k. */
static uint64_t word(const unsigned char *p, int k)
{
    uint64_t w;
    memcpy(&w, p + 8 * k, 8);
    return w;
}

/* Set header word k and recompute the checksum (XXH3-64 of bytes 0 .. 1015), as a writer
 * with other intentions would. */
static void set_word(unsigned char *p, int k, uint64_t w)
{
    memcpy(p + 8 * k, &w, 8);
    uint64_t h = XXH3_64bits(p, 1016);
    memcpy(p + 1016, &h, 8);
}

/* Open bytes p[0 .. len) copied to aligned memory; the status. */
static int open_copy(const unsigned char *p, size_t len, const uint64_t *tag, ulam_system **s)
{
    void *q = NULL;
    assert_int_equal(posix_memalign(&q, 4096, len ? len : 1), 0);
    memcpy(q, p, len);
    ulam_error err;
    int status = ulam_system_from_memory(q, len, tag, s, &err);
    if (status) {
        assert_true(err.msg[0] != '\0');
        free(q);
    } else {
        ulam_system_free(*s); /* the memory is borrowed: free it after */
        *s = NULL;
        free(q);
    }
    return status;
}

/* matrices/NAME.mtx and NAME_b.mtx, and the certificate of the analog guards. */
static void load_certified(const char *name, ulam_csr **A, double **b, int64_t *n, ulam_certificate *c)
{
    char path[128];
    snprintf(path, sizeof path, "matrices/%s.mtx", name);
    assert_int_equal(ulam_mm_read_matrix(path, A, NULL), ULAM_OK);
    snprintf(path, sizeof path, "matrices/%s_b.mtx", name);
    assert_int_equal(ulam_mm_read_vector(path, b, n, NULL), ULAM_OK);
    assert_int_equal(ulam_certificate_compute(*A, 0.0, NULL, c, NULL), ULAM_OK);
}

/* A file round trip: matrix, b, tag, omega and certificate come back as written. */
static void test_roundtrip(void **state)
{
    (void)state;
    ulam_csr *A = NULL;
    double *b = NULL;
    int64_t n = 0;
    ulam_certificate c;
    load_certified("signed200", &A, &b, &n, &c);
    assert_true(c.rowsum_max >= c.guard.abs.lower && c.colsum_max >= c.guard.abs.lower);
    char path[] = "/tmp/ulam_system_testXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    ulam_system_desc d = {.M = A, .b = b, .n = n, .tag = {12345, 678}, .omega = 0.75, .cert = &c};
    assert_int_equal(ulam_system_write(path, &d), ULAM_OK);
    assert_int_equal(ulam_system_is_file(path), 1);
    assert_int_equal(ulam_system_is_file("matrices/signed200.mtx"), 0);
    ulam_system *s = NULL;
    ulam_error err;
    const uint64_t tag[2] = {12345, 678}, other[2] = {12345, 679};
    assert_int_equal(ulam_system_open(path, other, &s, &err), ULAM_ENOTFOUND); /* source changed */
    assert_null(s);
    assert_int_equal(ulam_system_open(path, tag, &s, &err), ULAM_OK);
    assert_int_equal(ulam_system_check(s, &err), ULAM_OK);
    assert_csr_same(ulam_system_matrix(s), A);
    int64_t nb = 0;
    assert_memory_equal(ulam_system_rhs(s, &nb), b, (size_t)n * sizeof *b);
    assert_int_equal(nb, n);
    ulam_system_info si;
    ulam_system_get_info(s, &si);
    assert_close(si.omega, 0.75, 0);
    const ulam_certificate *r = system_cert(s);
    assert_non_null(r);
    assert_memory_equal(&r->guard.abs, &c.guard.abs, sizeof c.guard.abs);
    assert_memory_equal(r->guard.hat, c.guard.hat, sizeof c.guard.hat);
    assert_int_equal(r->guard.verdict_abs, c.guard.verdict_abs);
    assert_close(r->colsum_max, c.colsum_max, 0);
    /* the certificate serves the analog guards and nothing else */
    ulam_guard g, h;
    assert_int_equal(ulam_certificate_guard(r, 0.0, NULL, &g), ULAM_OK);
    assert_int_equal(ulam_guard_check(A, 0.0, NULL, &h, NULL), ULAM_OK);
    assert_close(g.abs.rho, h.abs.rho, 0);
    assert_close(g.hat[1].upper, h.hat[1].upper, 0);
    assert_close(g.abs.seconds, 0, 0);
    assert_int_equal(ulam_certificate_guard(r, 0.5, NULL, &g), ULAM_ENOTFOUND);
    ulam_guard_opts po = ulam_guard_defaults();
    po.power.tol = 1e-8;
    assert_int_equal(ulam_certificate_guard(r, 0.0, &po, &g), ULAM_ENOTFOUND);
    assert_int_equal(ulam_certificate_guard(NULL, 0.0, NULL, &g), ULAM_ENOTFOUND);
    s = ulam_system_free(s);
    /* a vector alone */
    d = (ulam_system_desc){.b = b, .n = n};
    assert_int_equal(ulam_system_write(path, &d), ULAM_OK);
    assert_int_equal(ulam_system_open(path, NULL, &s, &err), ULAM_OK);
    assert_null(ulam_system_matrix(s));
    assert_null(system_cert(s));
    assert_memory_equal(ulam_system_rhs(s, &nb), b, (size_t)n * sizeof *b);
    s = ulam_system_free(s);
    assert_int_equal(ulam_system_open("/nonexistent/x", NULL, &s, &err), ULAM_EIO);
    assert_int_equal(truncate(path, 0), 0);
    assert_int_equal(ulam_system_open(path, NULL, &s, &err), ULAM_EBANNER);
    remove(path);
    ulam_csr_free(A);
    free(b);
}

/* Damaged headers: each is refused at open with its status (the failing case prints its index). */
static void test_damaged(void **state)
{
    (void)state;
    ulam_csr *A = NULL;
    double *b = NULL;
    int64_t n = 0;
    ulam_certificate c;
    load_certified("chain4", &A, &b, &n, &c);
    ulam_system_desc d = {.M = A, .b = b, .n = n, .cert = &c};
    size_t len;
    unsigned char *good = file_bytes(&d, &len);
    enum { NCASE = 18 };
    static const int want[NCASE] = {ULAM_EBANNER, ULAM_ESYNTAX, ULAM_ESYNTAX, ULAM_ESYNTAX, ULAM_ESYNTAX,
                                    ULAM_EUNSUPPORTED, ULAM_EOVERFLOW, ULAM_ESYNTAX, ULAM_ESYNTAX, ULAM_ESYNTAX,
                                    ULAM_EOVERFLOW, ULAM_ESYNTAX, ULAM_EBANNER, ULAM_ESYNTAX, ULAM_ESYNTAX,
                                    ULAM_EOVERFLOW, ULAM_EBANNER, ULAM_ESYNTAX};
    for (int k = 0; k < NCASE; k++) {
        if (!test_case(k)) continue;
        unsigned char *p = malloc(len + 8);
        memcpy(p, good, len);
        size_t l = len;
        switch (k) {
        case 0: p[3] ^= 1; break;                              /* wrong magic */
        case 1: l = len - 1; break;                            /* truncated by a byte */
        case 2: l = 600; break;                                /* truncated inside the header */
        case 3: p[len] = 0, l = len + 1; break;                /* a byte appended */
        case 4: p[8 * 5] ^= 1; break;                          /* nnz changed: the checksum disagrees */
        case 5: set_word(p, 1, 1 | (uint64_t)1024 << 32); break; /* format version 1 (no block checksums) */
        case 6: set_word(p, 3, (uint64_t)1 << 40); break;      /* n past 2^31 */
        case 7: set_word(p, 7, word(p, 7) + 8); break;         /* colidx off its boundary */
        case 8: set_word(p, 8, word(p, 10)); break;            /* val past the end of the file */
        case 9: set_word(p, 5, word(p, 5) - 1); break;         /* rowptr[n] disagrees with nnz */
        case 10: set_word(p, 2, word(p, 2) | 64); break;       /* an unknown flag */
        case 11: set_word(p, 10, word(p, 10) + 4096); break;   /* stated length past the file */
        case 12: l = 4; break;                                 /* shorter than the magic */
        case 13: p[word(p, 15) + 3] ^= 4; break;               /* the checksum table damaged */
        case 14: set_word(p, 33, word(p, 33) ^ 1); break;      /* a certificate of other arrays */
        case 15: set_word(p, 14, 3); break;                    /* blocks of 8 rows: not a size written */
        case 16: l = 0; break;                                 /* empty */
        case 17: set_word(p, 16, word(p, 16) + 1); break;      /* the table's checksum disagrees */
        }
        ulam_system *s = NULL;
        int st = open_copy(p, l, NULL, &s);
        if (st != want[k]) fail_msg("damaged case %d: status %d, expected %d", k, st, want[k]);
        free(p);
    }
    test_case_done();
    /* a certificate section of an earlier version is ignored, not trusted; one of a later version
     * (longer, its extra fields appended) is read for the fields this reader knows */
    for (int v = 2; v <= 4; v += 2) {
        unsigned char *p = malloc(len);
        memcpy(p, good, len);
        set_word(p, 32, (uint64_t)v | ((word(p, 32) >> 32) + 8 * (v == 4)) << 32);
        void *q = NULL;
        assert_int_equal(posix_memalign(&q, 4096, len), 0);
        memcpy(q, p, len);
        ulam_system *s = NULL;
        assert_int_equal(ulam_system_from_memory(q, len, NULL, &s, NULL), ULAM_OK);
        if (v == 2) assert_null(system_cert(s));
        else assert_memory_equal(&system_cert(s)->guard.abs, &c.guard.abs, sizeof c.guard.abs);
        ulam_system_free(s);
        free(q), free(p);
    }
    free(good);
    ulam_csr_free(A);
    free(b);
}

/* A block-diagonal system: rows 0..B-1 move only among themselves (a ring, 4 a row), the rest
 * likewise among rows B..n-1; every row sums to 0.8. */
static ulam_csr *two_blocks(int64_t n, int64_t B)
{
    ulam_csr *M = ulam_csr_alloc(n, n, 4 * n);
    for (int64_t i = 0; i < n; i++) {
        int64_t lo = i < B ? 0 : B, m = i < B ? B : n - B, c[4];
        for (int k = 0; k < 4; k++) c[k] = lo + (i - lo + 1 + k) % m;
        for (int a = 0; a < 4; a++) /* sorted */
            for (int z = a + 1; z < 4; z++)
                if (c[z] < c[a]) {
                    int64_t t = c[a];
                    c[a] = c[z], c[z] = t;
                }
        for (int k = 0; k < 4; k++) M->colidx[4 * i + k] = (int32_t)c[k], M->val[4 * i + k] = 0.2;
        M->rowptr[i + 1] = 4 * (i + 1);
    }
    return M;
}

/* Protect the whole pages of [lo, hi) bytes at p from any access. */
static void protect(unsigned char *p, size_t lo, size_t hi)
{
    lo = (lo + 4095) / 4096 * 4096, hi = hi / 4096 * 4096;
    if (hi > lo) assert_int_equal(mprotect(p + lo, hi - lo, PROT_NONE), 0);
}

/* The bytes of a prepared file of d in page-aligned memory (munmap it), *len bytes. */
static unsigned char *mapped_bytes(const ulam_system_desc *d, size_t *len)
{
    unsigned char *bytes = file_bytes(d, len);
    unsigned char *p = mmap(NULL, *len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    assert_true(p != MAP_FAILED);
    memcpy(p, bytes, *len);
    free(bytes);
    return p;
}

/* A query on a mapped file reads no page of the rows its walks cannot reach: those pages are
 * made unreadable, and an adjoint run from block 0 still completes (a read would fault).  Its
 * estimate is that of the parsed matrix, bit for bit. */
static void test_lazy_pages(void **state)
{
    (void)state;
    const int64_t n = 8192, B = 64, far = 2048;
    ulam_csr *M = two_blocks(n, B);
    double *b = malloc((size_t)n * sizeof *b);
    for (int64_t i = 0; i < n; i++) b[i] = 1.0 + (double)(i % 7);
    ulam_system_desc d = {.M = M, .b = b, .n = n};
    size_t len;
    unsigned char *p = mapped_bytes(&d, &len);
    size_t off[4] = {word(p, 6), word(p, 7), word(p, 8), word(p, 9)}, sz[4] = {8, 16, 32, 8};
    for (int k = 0; k < 4; k++) /* rows far .. n-1, keeping rowptr[n] */
        protect(p, off[k] + (size_t)far * sz[k], off[k] + (size_t)(n - (k == 0)) * sz[k]);
    ulam_system *s = NULL;
    assert_int_equal(ulam_system_from_memory(p, len, NULL, &s, NULL), ULAM_OK);
    ulam_guard g; /* the verdicts a prepared file's certificate would carry: no pass over M */
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 3, o.stop.max_walks = 20000, o.exec.threads = 2, o.policy.guard = &g;
    ulam_walk_result r1, r2;
    ulam_error err;
    const ulam_csr *lm;
    const double *lb;
    assert_int_equal(ulam_system_lazy(s, &lm, &lb), ULAM_OK);
    o.policy.system = s; /* each block verified as the walks reach it: blocks 0 .. far hold what they read */
    assert_int_equal(ulam_solve_walks(lm, lb, &o, &r1, &err), ULAM_OK);
    o.policy.system = NULL;
    assert_int_equal(ulam_solve_walks(M, b, &o, &r2, &err), ULAM_OK);
    assert_memory_equal(&r1.estimate, &r2.estimate, sizeof r1.estimate);
    assert_int_equal(r1.rows, B);
    o.policy.system = s;
    o.estimator = ULAM_ABSORPTION; /* the reachability check too reads only what it reaches */
    assert_int_equal(ulam_solve_walks(lm, lb, &o, &r1, &err), ULAM_OK);
    o.estimator = ULAM_EXPECTED; /* and the expected estimator's b at the rows' columns */
    assert_int_equal(ulam_solve_walks(lm, lb, &o, &r1, &err), ULAM_OK);
    o.policy.system = NULL; /* the arrays of another system's solver: refused */
    ulam_system *t = NULL;
    assert_int_equal(ulam_system_from_memory(p, len, NULL, &t, NULL), ULAM_OK);
    o.policy.system = t;
    assert_int_equal(ulam_solve_walks(lm, lb, &o, &r1, &err), ULAM_EINVAL);
    ulam_system_free(t);
    ulam_system_free(s);
    munmap(p, len);
    ulam_csr_free(M);
    free(b);
}

/* KiB of the process's pages resident in mappings of the file at path (Linux: /proc/self/smaps);
 * -1 when it cannot be read. */
static long mapped_kib(const char *path)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f) return -1;
    char line[512];
    long kib = 0, v;
    int in = 0;
    while (fgets(line, sizeof line, f)) {
        if (strchr(line, '-') && strchr(line, ' ') && strchr(line, '-') < strchr(line, ' ')) in = strstr(line, path) != NULL;
        else if (in && sscanf(line, "Rss: %ld kB", &v) == 1) kib += v;
    }
    fclose(f);
    return kib;
}

/* A one-row query on a random system (8 entries a row at uniform columns, n = 2^17: the kernel
 * keeps its index of built rows sparse, two threads racing to make its leaves) from a
 * prepared file verifies at most 16 rows of M for each row its walks build (blocks of about 128
 * entries: with 1024-entry blocks each random row read verified its 127 neighbours too), and
 * answers as the parsed system does, bit for bit, within 4 standard errors of x_i.  It reads
 * those rows from the file, not through its mapping: the mapping keeps resident only what the
 * open touched (header, checksum table, the ends of rowptr), not the pages of the rows built,
 * which the kernel's fault-around (64 KiB a fault) spread over all of the 14 MiB file before. */
static void test_random_rows_checked(void **state)
{
    (void)state;
    const int64_t n = 1 << 17, k = 8;
    int32_t *ri = malloc((size_t)(n * k) * sizeof *ri), *ci = malloc((size_t)(n * k) * sizeof *ci);
    double *v = malloc((size_t)(n * k) * sizeof *v), *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
    ulam_rng r;
    ulam_rng_seed(&r, 29, 0);
    for (int64_t i = 0; i < n; i++) {
        double sum = 0;
        for (int64_t q = 0; q < k; q++)
            ri[i * k + q] = (int32_t)i, ci[i * k + q] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n),
                       sum += v[i * k + q] = 0.1 + ulam_rng_uniform(&r);
        for (int64_t q = 0; q < k; q++) v[i * k + q] *= 0.9 / sum;
        b[i] = x[i] = 0.5 + ulam_rng_uniform(&r);
    }
    ulam_csr *M = NULL;
    assert_int_equal(ulam_csr_from_triplets(n, n, n * k, ri, ci, v, &M), ULAM_OK);
    for (int it = 0; it < 240; it++) /* x = b + M x: 0.9^240 of the answer is left */
        for (int64_t i = 0; i < n; i++) {
            double t = b[i];
            for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) t += M->val[q] * x[M->colidx[q]];
            x[i] = t;
        }
    char path[] = "/tmp/ulam_test_randomXXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    ulam_certificate cert; /* with the stored bounds: no pass over what the start reaches */
    assert_int_equal(ulam_certificate_compute(M, 0.0, NULL, &cert, NULL), ULAM_OK);
    ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = &cert};
    assert_int_equal(ulam_system_write(path, &d), ULAM_OK);
    ulam_system *s = NULL;
    assert_int_equal(ulam_system_open(path, NULL, &s, NULL), ULAM_OK);
    unlink(path);
    const ulam_csr *lm;
    const double *lb;
    assert_int_equal(ulam_system_lazy(s, &lm, &lb), ULAM_OK);
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.b = lb, ao.system = s;
    ulam_analysis *af = NULL, *ap = NULL;
    assert_int_equal(ulam_analysis_alloc(lm, &ao, &af, NULL), ULAM_OK);
    ao.b = b, ao.system = NULL;
    assert_int_equal(ulam_analysis_alloc(M, &ao, &ap, NULL), ULAM_OK);
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 5, o.stop.max_walks = 60, o.exec.threads = 2;
    ulam_walk_result r1, r2;
    assert_int_equal(walks_on(af, lb, &o, &r1, NULL), ULAM_OK);
    o.exec.threads = 1; /* the parsed system's run below: one thread, the same estimate */
    ulam_system_info si;
    ulam_system_get_info(s, &si);
    int64_t rows = si.rows_checked, blocks = si.blocks_checked;
    if (!(r1.rows > 100 && rows >= r1.rows && rows <= 16 * r1.rows && blocks > 0))
        fail_msg("%lld rows built, %lld rows of M verified in %lld blocks", (long long)r1.rows, (long long)rows,
                 (long long)blocks);
    long kib = mapped_kib(path); /* of a 14 MiB file: the checksum table is 128 KiB, a fault maps up to 64
                                    KiB (264 KiB here, 1288 under valgrind); through the mapping 14472 KiB,
                                    all of it: an eighth of the file separates the two */
    if (kib >= 0 && kib > 14472 / 8) fail_msg("%ld KiB of the file resident after building %lld rows", kib, (long long)r1.rows);
    assert_int_equal(walks_on(ap, b, &o, &r2, NULL), ULAM_OK);
    assert_memory_equal(&r1.estimate, &r2.estimate, sizeof r1.estimate);
    assert_true(fabs(r1.estimate - x[5]) < 4 * r1.std_error);
    ulam_analysis_free(af), ulam_analysis_free(ap);
    ulam_system_free(s);
    ulam_csr_free(M);
    free(ri), free(ci), free(v), free(b), free(x);
}

/* Corrupt arrays behind a sound header: the check refuses them, and so does a walk that reaches
 * them (at set-up when the start row is bad, else at the round that reaches one); a walk that
 * does not reach them never sees them.  Each case prints its index when it fails. */
static void test_corrupt_rows(void **state)
{
    (void)state;
    const int64_t n = 1024, B = 32; /* blocks of 32 rows (128 entries): the walks from 3 read block 0 alone */
    ulam_csr *M = two_blocks(n, B);
    double *b = malloc((size_t)n * sizeof *b);
    for (int64_t i = 0; i < n; i++) b[i] = 1.0;
    ulam_system_desc d = {.M = M, .b = b, .n = n};
    size_t len;
    unsigned char *good = file_bytes(&d, &len);
    ulam_guard g; /* the verdicts of the sound M, as a certificate would carry them */
    assert_int_equal(ulam_guard_check(M, 0.0, NULL, &g, NULL), ULAM_OK);
    enum { NCASE = 7 };
    for (int k = 0; k < NCASE; k++) {
        if (!test_case(k)) continue;
        void *q = NULL;
        assert_int_equal(posix_memalign(&q, 4096, len), 0);
        unsigned char *p = q;
        memcpy(p, good, len);
        int64_t *rowptr = (int64_t *)(void *)(p + word(p, 6));
        int32_t *col = (int32_t *)(void *)(p + word(p, 7));
        double *val = (double *)(void *)(p + word(p, 8)), *rhs = (double *)(void *)(p + word(p, 9));
        int64_t row = B + 5; /* in block 1, reached from index B */
        switch (k) {
        case 0: col[4 * row + 1] = (int32_t)n; break;       /* column out of range */
        case 1: col[4 * row] = -7; break;                    /* negative column */
        case 2: val[4 * row + 2] = NAN; break;               /* non-finite value */
        case 3: val[4 * row + 3] = 0.0; break;               /* stored zero */
        case 4: rowptr[row + 1] = 4 * n + 100; break;        /* a range past the entries */
        case 5: rowptr[row] = rowptr[row + 1] + 4; break;    /* a range running backwards */
        case 6: rhs[row] = INFINITY; break;                  /* non-finite b */
        }
        ulam_system *s = NULL;
        ulam_error err;
        assert_int_equal(ulam_system_from_memory(p, len, NULL, &s, &err), ULAM_OK);
        const ulam_csr *lm;
        const double *lb;
        ulam_system_lazy(s, &lm, &lb);
        for (int start = 0; start < 3; start++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.query.index = start == 0 ? B : start == 1 ? row : 3, o.stop.max_walks = 5000, o.exec.threads = 1, o.policy.guard = &g;
            o.policy.system = s;
            ulam_walk_result r;
            int st = ulam_solve_walks(lm, lb, &o, &r, &err);
            if (start < 2 && (st != ULAM_ESYNTAX || !strstr(err.msg, "block 1 of")))
                fail_msg("corrupt case %d, start %lld: status %d (%s)", k, (long long)o.query.index, st, err.msg);
            if (start == 2 && st != ULAM_OK) fail_msg("corrupt case %d: the other block failed (%d)", k, st);
        }
        if (ulam_system_check(s, &err) == ULAM_OK) fail_msg("corrupt case %d: passed the check", k);
        assert_int_equal(err.index, B);
        if (k < 6) assert_null(ulam_system_matrix(s));
        else assert_null(ulam_system_rhs(s, NULL));
        ulam_system_free(s);
        free(q);
    }
    test_case_done();
    free(good);
    ulam_csr_free(M);
    free(b);
}

/* A chain of n states, M_{i,i-1} = M_{i,i+1} = 0.25 (ends: one neighbour): every state reaches
 * every other, while a walk (mean length under 2) rarely goes 30 states from its start. */
static ulam_csr *chain(int64_t n)
{
    ulam_csr *M = ulam_csr_alloc(n, n, 2 * n);
    int64_t q = 0;
    for (int64_t i = 0; i < n; i++) {
        if (i > 0) M->colidx[q] = (int32_t)(i - 1), M->val[q++] = 0.25;
        if (i + 1 < n) M->colidx[q] = (int32_t)(i + 1), M->val[q++] = 0.25;
        M->rowptr[i + 1] = q;
    }
    return M;
}

/* Issue 29, point 1: a rel_err query (and absorption's) from a prepared file reads only the rows
 * its walks reach, though the start reaches every state: the file's stored bounds serve the rule
 * (rows far from the start made unreadable: a pass over the reach would fault).  Through an
 * analysis on the file, the same seed gives the same walks as one on the parsed system (whose
 * bounds a pass computes: the stored ones round-trip), the estimate is within 4 standard errors
 * of the exact one, and later queries reuse the kept kernel, bit for bit a fresh analysis' answer. */
static void test_analysis_local(void **state)
{
    (void)state;
    const int64_t n = 8192, far = 2048;
    ulam_csr *M = chain(n);
    double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
    for (int64_t i = 0; i < n; i++) b[i] = 1.0 + (double)(i % 7);
    ulam_certificate cert;
    assert_int_equal(ulam_certificate_compute(M, 0.0, NULL, &cert, NULL), ULAM_OK);
    ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = &cert};
    size_t len;
    unsigned char *p = mapped_bytes(&d, &len);
    size_t off[4] = {word(p, 6), word(p, 7), word(p, 8), word(p, 9)}, sz[4] = {8, 8, 16, 8};
    for (int k = 0; k < 4; k++) /* rows far .. n-1 (entries 2 a row), keeping rowptr[n] */
        protect(p, off[k] + (size_t)far * sz[k], off[k] + (size_t)(n - (k == 0)) * sz[k]);
    ulam_system *s = NULL;
    assert_int_equal(ulam_system_from_memory(p, len, NULL, &s, NULL), ULAM_OK);
    const ulam_csr *Ms = NULL; /* unverified: the walks verify the blocks they reach */
    const double *bs = NULL;
    ulam_system_lazy(s, &Ms, &bs);
    for (int64_t i = 0; i < n; i++) x[i] = b[i];
    for (int it = 0; it < 80; it++) /* x = b + M x: rows sum to at most 0.5, so 0.5^80 of the answer is left */
        for (int64_t i = 0; i < n; i++) {
            double t = b[i];
            for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) t += M->val[q] * x[M->colidx[q]];
            x[i] = t;
        }
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.b = bs, ao.system = s, ao.shared_bounds = 1; /* the auto choice below walks on the file's bounds */
    ulam_analysis *af = NULL, *ap = NULL;
    assert_int_equal(ulam_analysis_alloc(Ms, &ao, &af, NULL), ULAM_OK);
    ao.b = b, ao.system = NULL;
    assert_int_equal(ulam_analysis_alloc(M, &ao, &ap, NULL), ULAM_OK);
    for (int e = ULAM_COLLISION; e <= ULAM_EXPECTED; e++)
        for (int64_t idx = 3; idx < 40; idx += 17) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.query.index = idx, o.estimator = e, o.stop.max_walks = 0, o.stop.rel_err = 0.02, o.exec.threads = 2, o.exec.seed = (uint64_t)idx;
            ulam_walk_result r1, r2;
            ulam_error err;
            assert_int_equal(walks_on(af, bs, &o, &r1, &err), ULAM_OK);
            assert_int_equal(walks_on(ap, b, &o, &r2, &err), ULAM_OK);
            assert_true(r1.rel_err_met);
            assert_int_equal(r1.walks, r2.walks);
            assert_memory_equal(&r1.estimate, &r2.estimate, sizeof r1.estimate);
            if (!(fabs(r1.estimate - x[idx]) < 4 * r1.std_error))
                fail_msg("estimator %d, x[%lld] = %.8g +- %.3g, exact %.8g", e, (long long)idx, r1.estimate,
                         r1.std_error, x[idx]);
        }
    for (int e = ULAM_COLLISION; e <= ULAM_EXPECTED; e++) { /* a fixed budget reads no more (the file's bounds) */
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 20, o.estimator = e, o.stop.max_walks = 3000, o.exec.threads = 2, o.exec.seed = 20;
        ulam_walk_result r1, r2;
        assert_int_equal(walks_on(af, bs, &o, &r1, NULL), ULAM_OK);
        assert_int_equal(walks_on(ap, b, &o, &r2, NULL), ULAM_OK);
        assert_memory_equal(&r1.estimate, &r2.estimate, sizeof r1.estimate);
        assert_true(isfinite(r1.ci95[0]) && fabs(r1.estimate - x[20]) < 4 * r1.std_error);
    }
    { /* auto's choice on the lazily read file reads no more either (it checked all of M's rows first) */
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 20, o.stop.max_walks = 0, o.stop.rel_err = 0.02, o.exec.threads = 2, o.exec.seed = 21;
        o.policy.system = s;
        ulam_choice *ch = malloc(sizeof *ch);
        ulam_answer *ans = malloc(sizeof *ans);
        ulam_error err;
        assert_true(ch && ans);
        ulam_auto_opts aop = ulam_auto_defaults(); /* the analysis' kernel: its guards from the certificate */
        aop.pin_continue = aop.pin_alpha = aop.pin_mode = 1;
        ulam_method_opts mo = ulam_method_defaults();
        mo.exclude = ~0u; /* the walks row alone (its race on the analysis' bounds) */
        assert_int_equal(ulam_analysis_solve(af, bs, &o, &aop, &mo, ch, ans, &err), ULAM_OK);
        assert_int_equal(ans->method, ULAM_METHOD_WALKS);
        assert_true(ans->walks.rel_err_met && fabs(ans->estimate - x[20]) < 4 * ans->std_error);
        free(ch), free(ans);
    }
    ulam_analysis_info info;
    ulam_analysis_get_info(af, &info);
    assert_int_equal(info.bounds, 1), assert_int_equal(info.b_scores, 1), assert_int_equal(info.guard, 1);
    assert_true(info.kernel_rows > 0 && info.kernel_rows < far);
    ulam_analysis_get_info(ap, &info);
    assert_int_equal(info.bounds, 2), assert_int_equal(info.b_scores, 2), assert_int_equal(info.guard, 2);
    ulam_analysis *fresh = NULL; /* a kept kernel walks as a new one: a late query, alone */
    ao.b = bs, ao.system = s;
    assert_int_equal(ulam_analysis_alloc(Ms, &ao, &fresh, NULL), ULAM_OK);
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 37, o.stop.max_walks = 0, o.stop.rel_err = 0.02, o.exec.threads = 1, o.exec.seed = 37;
    ulam_walk_result r1, r2;
    assert_int_equal(walks_on(fresh, bs, &o, &r1, NULL), ULAM_OK);
    assert_int_equal(walks_on(af, bs, &o, &r2, NULL), ULAM_OK);
    assert_int_equal(r1.walks, r2.walks);
    assert_memory_equal(&r1.estimate, &r2.estimate, sizeof r1.estimate);
    ulam_analysis_free(fresh), ulam_analysis_free(af), ulam_analysis_free(ap);
    ulam_system_free(s);
    munmap(p, len);
    ulam_csr_free(M);
    free(b), free(x);
}

/* A system with a certificate and M^T, rows of 3 to 6 entries of both signs (row sums of |M|
 * 0.75), b of varied entries: n rows in reach of one another. */
static ulam_csr *mixed(int64_t n)
{
    ulam_csr *M = ulam_csr_alloc(n, n, 6 * n);
    int64_t q = 0;
    for (int64_t i = 0; i < n; i++) {
        int len = 3 + (int)(i % 4);
        for (int k = 0; k < len; k++) {
            M->colidx[q] = (int32_t)((i * 7 + 13 * k * k + k) % n);
            int dup = 0;
            for (int64_t z = M->rowptr[i]; z < q; z++) dup |= M->colidx[z] == M->colidx[q];
            if (dup) continue;
            M->val[q++] = (k % 2 ? -0.75 : 0.75) / len;
        }
        M->rowptr[i + 1] = q;
        for (int64_t a = M->rowptr[i]; a < q; a++) /* sort the row */
            for (int64_t z = a + 1; z < q; z++)
                if (M->colidx[z] < M->colidx[a]) {
                    int32_t c = M->colidx[a];
                    double v = M->val[a];
                    M->colidx[a] = M->colidx[z], M->val[a] = M->val[z], M->colidx[z] = c, M->val[z] = v;
                }
    }
    for (int64_t i = 0; i < n; i++) /* rescale each row to |sum| 0.75 */
        for (int64_t z = M->rowptr[i]; z < M->rowptr[i + 1]; z++) M->val[z] *= (double)(3 + i % 4) / (double)(M->rowptr[i + 1] - M->rowptr[i]);
    return M;
}

/* One query of a damaged copy: lazily (o.system), through the verified accessors, and M^T: each
 * refused with a message, or answered as the intact file answers, bit for bit.  *refused counts
 * the refusals. */
static void query_copy(const unsigned char *p, size_t len, const double want[3], const ulam_csr *T, int label,
                       int *refused)
{
    void *q = NULL;
    assert_int_equal(posix_memalign(&q, 4096, len), 0);
    memcpy(q, p, len);
    ulam_system *s = NULL;
    ulam_error err;
    int st = ulam_system_from_memory(q, len, NULL, &s, &err);
    if (st) {
        if (!err.msg[0]) fail_msg("case %d: refused at open with no message", label);
        ++*refused;
        free(q);
        return;
    }
    const ulam_certificate *c = system_cert(s);
    if (!c) fail_msg("case %d: opened without its certificate", label);
    ulam_guard g;
    assert_int_equal(ulam_certificate_guard(c, 0.0, NULL, &g), ULAM_OK);
    const ulam_csr *lm;
    const double *lb;
    ulam_system_lazy(s, &lm, &lb);
    for (int e = 0; e < 3; e++) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 3, o.stop.max_walks = 2000, o.exec.threads = 1, o.policy.guard = &g, o.policy.system = s, o.estimator = e;
        ulam_walk_result r;
        st = ulam_solve_walks(lm, lb, &o, &r, &err);
        if (st == ULAM_OK && memcmp(&r.estimate, &want[e], sizeof r.estimate))
            fail_msg("case %d, estimator %d: a wrong answer %.17g (intact %.17g) with ULAM_OK", label, e, r.estimate, want[e]);
        if (st && (!err.msg[0] || st != ULAM_ESYNTAX)) fail_msg("case %d: status %d, '%s'", label, st, err.msg);
        *refused += st != ULAM_OK;
    }
    const ulam_csr *M = ulam_system_matrix(s); /* verified whole: NULL, or the intact answer */
    const double *b = ulam_system_rhs(s, NULL);
    if (M && b) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 3, o.stop.max_walks = 2000, o.exec.threads = 1;
        ulam_walk_result r;
        st = ulam_solve_walks(M, b, &o, &r, &err);
        if (st || memcmp(&r.estimate, &want[0], sizeof r.estimate)) fail_msg("case %d: verified M answered %d", label, st);
    } else if (ulam_system_check(s, &err) != ULAM_ESYNTAX || !strstr(err.msg, "block")) {
        fail_msg("case %d: an accessor refused what the check passes", label);
    }
    const ulam_csr *t = ulam_system_transpose(s);
    if (t) assert_csr_same(t, T);
    else if (ulam_system_check(s, &err) != ULAM_ESYNTAX || !strstr(err.msg, "M^T")) fail_msg("case %d: M^T refused", label);
    *refused += !t;
    ulam_system_free(s);
    free(q);
}

/* The corrupted-file table: in every byte class of a small prepared file (header words, the
 * certificate, the header's checksum, padding, rowptr, colidx, val, b, M^T's arrays, the checksum
 * table) bytes are flipped one at a time, spread over the class; every copy is refused with a
 * message or answers as the intact file does, never a wrong answer with ULAM_OK. */
static void test_flip_table(void **state)
{
    (void)state;
    const int64_t n = 700;
    ulam_csr *M = mixed(n), *T = NULL;
    assert_int_equal(ulam_csr_check(M), ULAM_OK);
    assert_int_equal(ulam_csr_transpose(M, &T), ULAM_OK);
    double *b = malloc((size_t)n * sizeof *b);
    for (int64_t i = 0; i < n; i++) b[i] = (double)(i % 5) - 1.5;
    ulam_certificate c;
    assert_int_equal(ulam_certificate_compute(M, 0.0, NULL, &c, NULL), ULAM_OK);
    ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = &c, .transpose = 1};
    size_t len;
    unsigned char *good = file_bytes(&d, &len);
    double want[3];
    for (int e = 0; e < 3; e++) {
        ulam_walk_opts o = ulam_walk_defaults();
        o.query.index = 3, o.stop.max_walks = 2000, o.exec.threads = 1, o.estimator = e;
        ulam_walk_result r;
        assert_int_equal(ulam_solve_walks(M, b, &o, &r, NULL), ULAM_OK);
        want[e] = r.estimate;
    }
    int refused = 0, dummy = 0;
    query_copy(good, len, want, T, -1, &dummy);
    assert_int_equal(dummy, 0);
    enum { CLASSES = 13, PER = 24 };
    uint64_t lo[CLASSES] = {0, 8 * 32, 8 * 69, 1016, 1024, word(good, 6), word(good, 7), word(good, 8), word(good, 9),
                            word(good, 17), word(good, 18), word(good, 19), word(good, 15)};
    uint64_t hi[CLASSES] = {8 * 32, 8 * 69, 1016, 1024, word(good, 6), lo[5] + 8 * (uint64_t)(n + 1),
                            lo[6] + 4 * (uint64_t)M->rowptr[n], lo[7] + 8 * (uint64_t)M->rowptr[n], lo[8] + 8 * (uint64_t)n,
                            lo[9] + 8 * (uint64_t)(n + 1), lo[10] + 4 * (uint64_t)M->rowptr[n],
                            lo[11] + 8 * (uint64_t)M->rowptr[n], len};
    unsigned char *p = malloc(len);
    for (int k = 0; k < CLASSES; k++) {
        if (!test_case(k)) continue;
        int before = refused;
        for (int j = 0; j < PER; j++) {
            uint64_t at = lo[k] + (hi[k] - lo[k]) * (uint64_t)j / PER + (uint64_t)j % 3;
            if (at >= hi[k]) continue;
            memcpy(p, good, len);
            p[at] ^= (unsigned char)(1u << (j % 8));
            query_copy(p, len, want, T, k * 100 + j, &refused);
        }
        if (k != 4 && refused == before) fail_msg("byte class %d: no flip was noticed", k); /* 4: padding */
    }
    test_case_done();
    free(p);
    free(good);
    ulam_csr_free(M);
    ulam_csr_free(T);
    free(b);
}

/* The prepared file of mixed(n), b_i = i mod 5 - 1.5 and its certificate (*c), in aligned
 * memory of *len bytes (free() it). */
static void *mixed_file(int64_t n, size_t *len, ulam_certificate *c)
{
    ulam_csr *M = mixed(n);
    double *b = malloc((size_t)n * sizeof *b);
    for (int64_t i = 0; i < n; i++) b[i] = (double)(i % 5) - 1.5;
    assert_int_equal(ulam_certificate_compute(M, 0.0, NULL, c, NULL), ULAM_OK);
    ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = c};
    unsigned char *bytes = file_bytes(&d, len);
    void *q = NULL;
    assert_int_equal(posix_memalign(&q, 4096, *len), 0);
    memcpy(q, bytes, *len);
    free(bytes), free(b);
    ulam_csr_free(M);
    return q;
}

/* Auto's run on a system: the choice (ulam_auto_solver, adjoint analog walks at exponent 1: the
 * three estimators on one shared kernel, rescored at each change) and the chosen run to the end:
 * the solver's status, its result in *r and the candidates in *res. */
static int auto_run(const ulam_csr *M, const double *b, const ulam_system *s, const ulam_guard *g,
                    ulam_auto_result *res, ulam_walk_result *r, ulam_error *err)
{
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = 3, o.stop.max_walks = 3000, o.exec.threads = 2, o.exec.seed = 5, o.policy.system = s;
    ulam_auto_opts ao = ulam_auto_defaults();
    ao.pin_mode = ao.pin_continue = ao.pin_alpha = 1, ao.guard = g;
    ulam_solver *sv = NULL;
    int st = ulam_auto_solver(M, b, &o, &ao, res, &sv, err);
    while (!st && !ulam_solver_done(sv))
        if ((st = ulam_solver_iterate(sv))) ulam_solver_error(sv, err);
    if (!st) ulam_solver_result(sv, r);
    ulam_solver_free(sv);
    return st;
}

/* Issue 29: on a prepared file read by pread, a kernel rescored for another estimator rescores its
 * rows from what it kept when it built them (only the expected estimator's (M b)_i reads a row and
 * its b_j again), and a thread keeps the last block of M and of b it read.  Auto's pilots (three
 * estimators on one kernel) and its chosen run answer from the file bit for bit as on the parsed
 * system, whose rows are read in place; a copy of the file with a byte of rowptr, colidx, val or b
 * flipped (spread over each array) is refused with ULAM_ESYNTAX and a message, or answers the same. */
static void test_rescore_file(void **state)
{
    (void)state;
    const int64_t n = 5000;
    ulam_csr *M = mixed(n);
    double *b = malloc((size_t)n * sizeof *b);
    for (int64_t i = 0; i < n; i++) b[i] = (double)(i % 5) - 1.5;
    ulam_certificate c;
    assert_int_equal(ulam_certificate_compute(M, 0.0, NULL, &c, NULL), ULAM_OK);
    ulam_guard g;
    assert_int_equal(ulam_certificate_guard(&c, 0.0, NULL, &g), ULAM_OK);
    ulam_system_desc d = {.M = M, .b = b, .n = n, .cert = &c};
    size_t len;
    unsigned char *good = file_bytes(&d, &len), *p = malloc(len);
    ulam_auto_result *want = malloc(sizeof *want), *res = malloc(sizeof *res);
    ulam_walk_result rw, r;
    ulam_error err;
    assert_int_equal(auto_run(M, b, NULL, &g, want, &rw, &err), ULAM_OK);
    int piloted = 0;
    for (int k = 0; k < want->ncand; k++) piloted += want->cand[k].pilot_walks > 0;
    assert_int_equal(piloted, 3);
    enum { CLASSES = 4, PER = 12 };
    uint64_t lo[CLASSES] = {word(good, 6), word(good, 7), word(good, 8), word(good, 9)};
    uint64_t hi[CLASSES] = {lo[0] + 8 * (uint64_t)(n + 1), lo[1] + 4 * (uint64_t)M->rowptr[n],
                            lo[2] + 8 * (uint64_t)M->rowptr[n], lo[3] + 8 * (uint64_t)n};
    int refused[CLASSES] = {0};
    for (int k = -1; k < CLASSES * PER; k++) { /* -1: the intact file */
        if (!test_case(k)) continue;
        memcpy(p, good, len);
        if (k >= 0) {
            int cl = k / PER, j = k % PER;
            uint64_t at = lo[cl] + (hi[cl] - lo[cl]) * (uint64_t)j / PER + (uint64_t)j % 3; /* spread over the array */
            p[at] ^= (unsigned char)(1u << (j % 8));
        }
        char path[] = "/tmp/ulam_test_rescoreXXXXXX";
        int fd = mkstemp(path);
        assert_true(fd >= 0);
        assert_int_equal(write(fd, p, len), (ssize_t)len);
        close(fd);
        ulam_system *s = NULL;
        int st = ulam_system_open(path, NULL, &s, &err); /* reads rowptr[0] and rowptr[n] alone of the arrays */
        unlink(path);
        if (st) {
            if (k < 0 || !err.msg[0]) fail_msg("case %d: refused at open (%d, '%s')", k, st, err.msg);
            refused[k / PER]++;
            continue;
        }
        const ulam_csr *lm;
        const double *lb;
        ulam_system_lazy(s, &lm, &lb);
        st = auto_run(lm, lb, s, &g, res, &r, &err);
        if (st) {
            if (k < 0 || st != ULAM_ESYNTAX || !strstr(err.msg, "block")) fail_msg("case %d: status %d, '%s'", k, st, err.msg);
            refused[k / PER]++;
        } else {
            if (res->chosen != want->chosen || memcmp(&r.estimate, &rw.estimate, sizeof r.estimate))
                fail_msg("case %d: chose %d, %.17g (the parsed system: %d, %.17g)", k, res->chosen, r.estimate,
                         want->chosen, rw.estimate);
            for (int q = 0; q < want->ncand; q++)
                if (memcmp(&res->cand[q].estimate, &want->cand[q].estimate, sizeof(double)) ||
                    memcmp(&res->cand[q].variance, &want->cand[q].variance, sizeof(double)))
                    fail_msg("case %d: candidate %d's pilot %.17g, variance %.17g (the parsed system: %.17g, %.17g)", k, q,
                             res->cand[q].estimate, res->cand[q].variance, want->cand[q].estimate, want->cand[q].variance);
        }
        ulam_system_free(s);
    }
    test_case_done();
    for (int cl = 0; cl < CLASSES; cl++)
        if (!refused[cl]) fail_msg("array %d: no flip was noticed", cl);
    free(want), free(res), free(p), free(good), free(b);
    ulam_csr_free(M);
}

/* Two solvers in two threads (each with two threads of walks) on one system opened fresh, its
 * blocks verified by whichever thread reaches them first: both answer as one solver alone does. */
typedef struct {
    const ulam_system *s;
    const ulam_guard *g;
    int index, status;
    double estimate;
} solve_job;

/* Run one job. */
static void *run_job(void *arg)
{
    solve_job *j = arg;
    const ulam_csr *M;
    const double *b;
    ulam_system_lazy(j->s, &M, &b);
    ulam_walk_opts o = ulam_walk_defaults();
    o.query.index = j->index, o.stop.max_walks = 20000, o.exec.threads = 2, o.policy.guard = j->g, o.policy.system = j->s, o.kernel.whole_kernel = j->index == 5;
    ulam_walk_result r;
    j->status = ulam_solve_walks(M, b, &o, &r, NULL);
    j->estimate = r.estimate;
    return NULL;
}

/* See solve_job. */
static void test_threads(void **state)
{
    (void)state;
    size_t len;
    ulam_certificate c;
    void *q = mixed_file(5000, &len, &c);
    ulam_guard g;
    assert_int_equal(ulam_certificate_guard(&c, 0.0, NULL, &g), ULAM_OK);
    double alone[2];
    for (int k = 0; k < 2; k++) {
        ulam_system *s = NULL;
        assert_int_equal(ulam_system_from_memory(q, len, NULL, &s, NULL), ULAM_OK);
        solve_job j = {.s = s, .g = &g, .index = k ? 5 : 3};
        run_job(&j);
        assert_int_equal(j.status, ULAM_OK);
        alone[k] = j.estimate;
        ulam_system_free(s);
    }
    ulam_system *s = NULL;
    assert_int_equal(ulam_system_from_memory(q, len, NULL, &s, NULL), ULAM_OK);
    solve_job jobs[2] = {{.s = s, .g = &g, .index = 3}, {.s = s, .g = &g, .index = 5}};
    pthread_t th[2];
    for (int k = 0; k < 2; k++) assert_int_equal(pthread_create(&th[k], NULL, run_job, &jobs[k]), 0);
    for (int k = 0; k < 2; k++) assert_int_equal(pthread_join(th[k], NULL), 0);
    for (int k = 0; k < 2; k++) {
        assert_int_equal(jobs[k].status, ULAM_OK);
        assert_memory_equal(&jobs[k].estimate, &alone[k], sizeof alone[k]);
    }
    assert_int_equal(ulam_system_check(s, NULL), ULAM_OK);
    ulam_system_free(s);
    free(q);
}

/* Recompute the checksums of M's blocks of the file at p (its arrays F, changed in place), the
 * table's, the certificate's content hash and the header's, as a forger would (rows of block k:
 * rowptr[k B .. min(n, (k+1) B)], then their colidx and val; a row range past the entries is
 * hashed up to nnz, what a forger's tool would do). */
static void reseal(void *p, const ulam_csr *F)
{
    unsigned char *u = p;
    int64_t B = (int64_t)1 << word(u, 14), n = F->nrows, nnz = (int64_t)word(u, 5), nb = (n + B - 1) / B;
    uint64_t *sums = (uint64_t *)(void *)(u + word(u, 15));
    for (int64_t k = 0; k < nb; k++) {
        int64_t r0 = k * B, r1 = r0 + B < n ? r0 + B : n;
        int64_t a = F->rowptr[r0] < nnz ? F->rowptr[r0] : nnz, e = F->rowptr[r1] < nnz ? F->rowptr[r1] : nnz;
        XXH3_state_t *st = XXH3_createState();
        XXH3_64bits_reset(st);
        XXH3_64bits_update(st, F->rowptr + r0, (size_t)(r1 - r0 + 1) * 8);
        if (e > a) {
            XXH3_64bits_update(st, F->colidx + a, (size_t)(e - a) * 4);
            XXH3_64bits_update(st, F->val + a, (size_t)(e - a) * 8);
        }
        sums[k] = XXH3_64bits_digest(st);
        XXH3_freeState(st);
    }
    int64_t total = nb * ((word(u, 2) & 2) ? 2 : 1);
    uint64_t th = XXH3_64bits(sums, (size_t)total * 8), content = XXH3_64bits(sums, (size_t)nb * 8);
    memcpy(u + 8 * 16, &th, 8);
    set_word(u, 33, content);
}

/* Arrays written with their checksums right but a column out of range, a row range running past
 * the entries, or a NaN (a writer's bug, or a forger): open, then what a user does with no check
 * of their own (the verified matrix; the lazy arrays with opts.system, guards computed or given,
 * adjoint and forward) is refused with ULAM_ESYNTAX naming the fault, never read out of bounds
 * (the guards' sum pass once read colidx[q] = 10^6 here). */
static void test_sound_sums_bad_arrays(void **state)
{
    (void)state;
    const int64_t n = 300;
    for (int k = 0; k < 3; k++) {
        if (!test_case(k)) continue;
        size_t len;
        ulam_certificate c;
        void *q = mixed_file(n, &len, &c);
        ulam_csr F = {.nrows = n, .ncols = n, .rowptr = (int64_t *)(void *)((unsigned char *)q + word(q, 6)),
                      .colidx = (int32_t *)(void *)((unsigned char *)q + word(q, 7)),
                      .val = (double *)(void *)((unsigned char *)q + word(q, 8))};
        if (k == 0) F.colidx[F.rowptr[7] + 1] = 1000000;
        if (k == 1) F.rowptr[9] = F.rowptr[n] + 50;
        if (k == 2) F.val[F.rowptr[11]] = NAN;
        reseal(q, &F);
        ulam_system *s = NULL;
        ulam_error err;
        assert_int_equal(ulam_system_from_memory(q, len, NULL, &s, &err), ULAM_OK);
        assert_null(ulam_system_matrix(s));
        const ulam_csr *lm;
        const double *lb;
        ulam_system_lazy(s, &lm, &lb);
        ulam_guard g;
        assert_int_equal(ulam_certificate_guard(system_cert(s), 0.0, NULL, &g), ULAM_OK);
        static const char *const why[3] = {"column", "row pointers", "value"};
        for (int run = 0; run < 3; run++) {
            ulam_walk_opts o = ulam_walk_defaults();
            o.query.index = 3, o.stop.max_walks = 2000, o.exec.threads = 1, o.policy.system = s;
            o.policy.guard = run == 1 ? &g : NULL;
            o.mode = run == 2 ? ULAM_FORWARD : ULAM_ADJOINT;
            ulam_walk_result r;
            int st = ulam_solve_walks(lm, lb, &o, &r, &err);
            if (st != ULAM_ESYNTAX || !strstr(err.msg, why[k]))
                fail_msg("case %d, run %d: status %d, '%s'", k, run, st, err.msg);
        }
        ulam_system_free(s);
        free(q);
    }
    test_case_done();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roundtrip),
        cmocka_unit_test(test_damaged),
        cmocka_unit_test(test_lazy_pages),
        cmocka_unit_test(test_random_rows_checked),
        cmocka_unit_test(test_corrupt_rows),
        cmocka_unit_test(test_flip_table),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_sound_sums_bad_arrays),
        cmocka_unit_test(test_analysis_local),
        cmocka_unit_test(test_rescore_file),
    };
    return test_run(tests);
}
