/* libFuzzer target: the prepared-system reader on arbitrary bytes, and what a user does next
 * with no check of their own: the walks on the arrays handed out unverified with
 * ulam_walk_opts.system (each block verified as it is first read), and on the arrays the
 * verified accessors hand out, adjoint and forward.  A damaged file must be refused, never
 * crash or read out of bounds.  Built with -Dfuzz=true (clang); the same entry point replays the
 * committed corpus in the normal test suite (replay.c). */
#include "ulam.h"

#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A few short walks of each estimator from state 0 of M with b (ones where the file has none). */
static void walk(const ulam_csr *M, const double *b, const ulam_system *lazy, int forward)
{
    if (!M || M->nrows != M->ncols || M->nrows == 0 || M->nrows > 100000) return;
    int64_t n = M->nrows;
    double *ones = b ? NULL : malloc((size_t)n * sizeof *ones);
    if (!b && !ones) return;
    for (int64_t i = 0; !b && i < n; i++) ones[i] = 1.0;
    ulam_walk_opts o = ulam_walk_defaults();
    o.stop.max_walks = 200, o.stop.max_steps = 200, o.exec.threads = 1, o.policy.system = lazy;
    ulam_walk_result r;
    for (int e = 0; e < 3; e++) {
        o.estimator = e;
        ulam_solve_walks(M, b ? b : ones, &o, &r, NULL);
    }
    if (forward) {
        o.mode = ULAM_FORWARD, o.estimator = ULAM_COLLISION;
        ulam_solve_walks(M, b ? b : ones, &o, &r, NULL);
    }
    free(ones);
}

/* Open the bytes at p (aligned) and walk on what is accepted. */
static void one(void *p, size_t size)
{
    ulam_system *s = NULL;
    if (ulam_system_from_memory(p, size, NULL, &s, NULL) == ULAM_OK) {
        const ulam_csr *M = NULL;
        const double *b = NULL;
        ulam_system_lazy(s, &M, &b);
        ulam_guard g;
        ulam_walk_opts o = ulam_walk_defaults();
        ulam_system_info si;
        ulam_system_get_info(s, &si);
        if (!ulam_certificate_guard(si.cert, 0.0, NULL, &g) && M && M->nrows == M->ncols &&
            M->nrows > 0 && M->nrows <= 100000) { /* a query on the certificate: lazily read */
            o.stop.max_walks = 200, o.stop.max_steps = 200, o.exec.threads = 2, o.policy.guard = &g, o.policy.system = s;
            ulam_walk_result r;
            ulam_solve_walks(M, b, &o, &r, NULL);
        }
        walk(M, b, s, 1);                                        /* lazily, with the guards' own pass */
        walk(ulam_system_matrix(s), ulam_system_rhs(s, NULL), NULL, 1); /* verified whole */
        ulam_system_transpose(s);
        ulam_system_free(s);
    }
}

/* Make the checksums of bytes p[0 .. size) right where they can be: the checksum table's own
 * and the header's, so mutations reach the block checks behind them. */
static void fix_sums(unsigned char *p, size_t size)
{
    uint64_t w[128];
    memcpy(w, p, 1024);
    uint64_t off = w[15], n = w[3], nc = w[4], shift = w[14], flags = w[2];
    if (shift >= 4 && shift <= 30 && n < ((uint64_t)1 << 31) && nc < ((uint64_t)1 << 31)) {
        uint64_t B = (uint64_t)1 << shift, nb = (n + B - 1) / B, nsums = ((flags & 1) ? nb : 0) + ((flags & 2) ? nb : 0) +
                                                                      ((flags & 8) ? (nc + B - 1) / B : 0);
        if (off >= 1024 && off <= size && nsums <= (size - off) / 8) {
            uint64_t h = XXH3_64bits(p + off, nsums * 8);
            memcpy(p + 8 * 16, &h, 8);
        }
    }
    uint64_t h = XXH3_64bits(p, 1016);
    memcpy(p + 1016, &h, 8);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    void *p = NULL;
    if (posix_memalign(&p, 4096, size ? size : 1)) return 0;
    if (size) memcpy(p, data, size);
    one(p, size);
    if (size >= 1024) { /* again with the header's and the table's checksums made right */
        fix_sums(p, size);
        one(p, size);
    }
    free(p);
    return 0;
}
