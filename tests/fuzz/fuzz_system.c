/* libFuzzer target: the prepared-system reader on arbitrary bytes, and the walks on whatever it
 * accepts, checked or not (the kernel must refuse a corrupt row it reaches, never crash).
 * Built with -Dfuzz=true (clang); the same entry point replays the committed corpus in the
 * normal test suite (replay.c). */
#include "ulam.h"

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A few short adjoint walks from state 0 of the mapped system (and forward ones once the
 * arrays passed the check). */
static void walk(const ulam_system *s, int checked)
{
    const ulam_csr *M = ulam_system_matrix(s);
    if (!M || M->nrows != M->ncols || M->nrows == 0 || M->nrows > 100000) return;
    int64_t n = M->nrows;
    const double *b = ulam_system_rhs(s, NULL);
    double *ones = b ? NULL : malloc((size_t)n * sizeof *ones);
    if (!b && !ones) return;
    for (int64_t i = 0; !b && i < n; i++) ones[i] = 1.0;
    ulam_walk_opts o = ulam_walk_defaults();
    o.max_walks = 200, o.max_steps = 200, o.threads = 1;
    ulam_walk_result r;
    for (int e = 0; e < 3; e++) {
        o.estimator = e;
        ulam_solve(M, b ? b : ones, &o, &r, NULL);
    }
    if (checked) {
        o.mode = ULAM_FORWARD, o.estimator = ULAM_COLLISION;
        ulam_solve(M, b ? b : ones, &o, &r, NULL);
    }
    free(ones);
}

/* Open the bytes at p (aligned) and walk on what is accepted. */
static void one(void *p, size_t size)
{
    ulam_system *s = NULL;
    if (ulam_system_from_memory(p, size, NULL, &s, NULL) == ULAM_OK) {
        int checked = ulam_system_check(s, NULL) == ULAM_OK;
        walk(s, checked);
        ulam_guard g;
        ulam_certificate_guard(ulam_system_certificate(s), 0.0, NULL, &g);
        ulam_system_free(s);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    void *p = NULL;
    if (posix_memalign(&p, 4096, size ? size : 1)) return 0;
    if (size) memcpy(p, data, size);
    one(p, size);
    if (size >= 1024) { /* again with the header's checksum made right, so mutations reach past it */
        uint64_t h = 0xcbf29ce484222325u;
        for (size_t i = 0; i < 1016; i++) h = (h ^ ((unsigned char *)p)[i]) * 0x100000001b3u;
        memcpy((unsigned char *)p + 1016, &h, 8);
        one(p, size);
    }
    free(p);
    return 0;
}
