/* libFuzzer target: a matrix built by hand from arbitrary bytes (sizes, row pointers, column
 * indices and values as given, no ulam_csr_check first) and options from the same bytes, handed
 * to the public entry points as a user would: each must refuse what is out of range with a
 * status, never read out of bounds, hang or crash.  Built with -Dfuzz=true (clang); the same
 * entry point replays the committed corpus in the normal test suite (replay.c).
 * Input: n (1 byte, 1..16), nnz (1 byte), the options byte, then rowptr (n + 1 int16), colidx
 * (nnz int16), val (nnz float), b (n float): short input is padded with zeros; rowptr[n] is cut
 * to the nnz allocated (the arrays' length, which no library can check). */
#include "ulam.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The next k bytes of the input (zeros past its end). */
static void take(const uint8_t *data, size_t size, size_t *at, void *out, size_t k)
{
    memset(out, 0, k);
    if (*at < size) memcpy(out, data + *at, size - *at < k ? size - *at : k);
    *at += k;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 3) return 0;
    size_t at = 3;
    int64_t n = 1 + data[0] % 16, nnz = data[1] % 64;
    int flags = data[2];
    ulam_csr A = {n, n, malloc((size_t)(n + 1) * sizeof(int64_t)), malloc((size_t)(nnz ? nnz : 1) * sizeof(int32_t)),
                  malloc((size_t)(nnz ? nnz : 1) * sizeof(double))};
    double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x), *bp = malloc((size_t)n * sizeof *bp);
    if (!A.rowptr || !A.colidx || !A.val || !b || !x || !bp) goto done;
    for (int64_t i = 0; i <= n; i++) {
        int16_t v;
        take(data, size, &at, &v, sizeof v);
        A.rowptr[i] = flags & 64 ? (int64_t)v * (1 << 20) : v; /* sometimes far out of range */
    }
    /* the contract a library cannot check: colidx and val hold rowptr[n] entries (here nnz are
       allocated), so a larger rowptr[n] is not a matrix at all; everything else is as given */
    if (A.rowptr[n] > nnz) A.rowptr[n] = nnz;
    for (int64_t p = 0; p < nnz; p++) {
        int16_t v;
        take(data, size, &at, &v, sizeof v);
        A.colidx[p] = v;
    }
    for (int64_t p = 0; p < nnz; p++) {
        float v;
        take(data, size, &at, &v, sizeof v);
        A.val[p] = v;
    }
    for (int64_t i = 0; i < n; i++) {
        float v;
        take(data, size, &at, &v, sizeof v);
        b[i] = v;
    }
    ulam_walk_opts o = ulam_walk_defaults();
    o.mode = flags & 1, o.estimator = (flags >> 1) % 3, o.stop.max_walks = 64, o.stop.max_steps = 64, o.exec.threads = 1;
    o.kernel.continue_q = flags & 8 ? 0.5 : 0.0, o.query.index = (flags >> 4) % n;
    o.policy.force = (flags & 128) != 0;
    ulam_error err;
    ulam_walk_result r;
    ulam_solve_walks(&A, b, &o, &r, &err);
    ulam_guard g;
    ulam_guard_check(&A, 0.0, NULL, &g, &err);
    ulam_csr *T = NULL, *J = NULL;
    if (ulam_csr_transpose(&A, &T) == ULAM_OK) ulam_csr_free(T);
    if (ulam_jacobi(&A, b, 1.0, &J, bp, &err) == ULAM_OK) ulam_csr_free(J);
    ulam_direct_solve(&A, b, x, 0, NULL, &err);
    int it;
    double res;
    ulam_gmres(&A, b, 4, 1e-8, 50, x, &it, &res);
    ulam_outer_opts oo = ulam_outer_defaults();
    oo.method = ULAM_GAUSS_SEIDEL, oo.max_iter = 50;
    ulam_outer_solve(&A, b, &oo, x, NULL, 0, NULL, &err);
done:
    free(A.rowptr), free(A.colidx), free(A.val), free(b), free(x), free(bp);
    return 0;
}
