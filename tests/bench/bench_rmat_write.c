/* Write the R-MAT PageRank system M = 0.85 P' straight to a prepared file (issue 43's "single
 * source at scale": 2^24 nodes, 2^28 edges), with its certificate, its bounds and M' stored, so
 * no Matrix Market text (about 10 GB at that size) is ever written or parsed.
 *
 * Graph: R-MAT (Chakrabarti, Zhan, Faloutsos 2004; a = 0.57, b = c = 0.19, d = 0.05, each level
 * drawn from 16 bits: 4 levels a 64-bit draw), 2^L nodes, E 2^L edges (default E = 16), stream
 * (L, 0), nodes relabelled by a random permutation (as tests/bench/gen.h's bench_rmat); each node without an out-edge is given one to a node
 * drawn uniformly (as tests/bench/bench_igraph.py does, so PRPACK's dangling rule does not
 * enter); multi-edges summed: M_vu = 0.85 (edges u -> v) / outdeg(u).
 *
 * The edges are bucketed by their tail and then laid into M's rows by increasing tail, so every
 * row comes out sorted with its duplicates adjacent (no sort).  The certificate is written (so a
 * query runs no guards), the bounds extension is not (see below).  Peak memory about 12 bytes an
 * edge while building, then the writer's transpose (another 12 bytes an entry).
 *
 * Usage: bench_rmat_write PATH L [E]   (prints n, nnz and the seconds of each stage) */
#include <inttypes.h>
#include <stdint.h>

#include "gen.h"
#include "../../src/cache.h" /* ulam__system_write_checked: a prepared file without the bounds extension */

int main(int argc, char **argv)
{
    if (argc < 3 || atoi(argv[2]) < 4 || atoi(argv[2]) > 30) {
        fprintf(stderr, "usage: bench_rmat_write PATH L [EDGES_PER_NODE]  (4 <= L <= 30)\n");
        return 2;
    }
    int L = atoi(argv[2]);
    int64_t E = argc > 3 ? atoll(argv[3]) : 16, n = (int64_t)1 << L, m = E * n;
    double t0 = ulam_now();
    ulam_rng r;
    ulam_rng_seed(&r, (uint64_t)L, 0);
    int32_t *perm = malloc((size_t)n * sizeof *perm), *src = malloc((size_t)(m + n) * sizeof *src);
    int32_t *dst = malloc((size_t)(m + n) * sizeof *dst);
    int64_t *outp = calloc((size_t)n + 1, sizeof *outp);
    if (!perm || !src || !dst || !outp) return fprintf(stderr, "bench_rmat_write: out of memory\n"), 1;
    bench_permutation(perm, n, &r);
    for (int64_t e = 0; e < m; e++) {
        int64_t u = 0, v = 0;
        for (int l = 0; l < L; l += 4) { /* four levels a 64-bit draw, 16 bits each (a quarter of the draws) */
            uint64_t z = ulam_rng_bounded(&r, 0);
            for (int k = 0; k < 4 && l + k < L; k++, z >>= 16) {
                uint64_t q = z & 0xffff; /* a = 37356 / 65536, a + b = 49807, a + b + c = 62259 */
                u = 2 * u + (q >= 49807), v = 2 * v + ((q >= 37356 && q < 49807) || q >= 62259);
            }
        }
        src[e] = perm[u], dst[e] = perm[v];
        outp[perm[u] + 1]++;
    }
    int64_t me = m, dangling = 0;
    for (int64_t u = 0; u < n; u++)
        if (outp[u + 1] == 0) src[me] = (int32_t)u, dst[me++] = (int32_t)ulam_rng_bounded(&r, (uint64_t)n), outp[u + 1] = 1, dangling++;
    free(perm);
    double t1 = ulam_now();
    /* heads grouped by tail (a counting sort), then laid into M's rows by increasing tail */
    for (int64_t u = 0; u < n; u++) outp[u + 1] += outp[u];
    int32_t *byu = malloc((size_t)me * sizeof *byu);
    int64_t *fill = malloc((size_t)n * sizeof *fill);
    if (!byu || !fill) return fprintf(stderr, "bench_rmat_write: out of memory\n"), 1;
    memcpy(fill, outp, (size_t)n * sizeof *fill);
    for (int64_t e = 0; e < me; e++) byu[fill[src[e]]++] = dst[e];
    free(src);
    int64_t *rp = calloc((size_t)n + 1, sizeof *rp);
    if (!rp) return fprintf(stderr, "bench_rmat_write: out of memory\n"), 1;
    for (int64_t e = 0; e < me; e++) rp[dst[e] + 1]++;
    free(dst);
    for (int64_t v = 0; v < n; v++) rp[v + 1] += rp[v];
    int32_t *col = malloc((size_t)me * sizeof *col);
    if (!col) return fprintf(stderr, "bench_rmat_write: out of memory\n"), 1;
    memcpy(fill, rp, (size_t)n * sizeof *fill);
    for (int64_t u = 0; u < n; u++)
        for (int64_t k = outp[u]; k < outp[u + 1]; k++) col[fill[byu[k]]++] = (int32_t)u;
    free(byu), free(fill);
    /* duplicates merged in place: M_vu = 0.85 count / outdeg(u) */
    double *val = malloc((size_t)me * sizeof *val);
    if (!val) return fprintf(stderr, "bench_rmat_write: out of memory\n"), 1;
    int64_t nnz = 0;
    for (int64_t v = 0; v < n; v++) {
        int64_t a = rp[v], b = rp[v + 1];
        rp[v] = nnz;
        for (int64_t k = a; k < b;) {
            int64_t u = col[k], c = 0;
            while (k < b && col[k] == u) k++, c++;
            col[nnz] = (int32_t)u, val[nnz++] = 0.85 * (double)c / (double)(outp[u + 1] - outp[u]);
        }
    }
    rp[n] = nnz;
    free(outp);
    ulam_csr M = {.nrows = n, .ncols = n, .rowptr = rp, .colidx = col, .val = val};
    double t2 = ulam_now();
    printf("R-MAT 2^%d: n = %" PRId64 ", edges = %" PRId64 " (%" PRId64 " added at dangling nodes), nnz(M) = %" PRId64
           "; drawn in %.1f s, M built in %.1f s\n", L, n, me, dangling, nnz, t1 - t0, t2 - t1);
    fflush(stdout);
    ulam_certificate cert;
    ulam_error err;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_FORWARD; /* what single source reads (an adjoint query makes its own) */
    if (ulam_certificate_compute(&M, 0.0, &go, &cert, &err))
        return fprintf(stderr, "bench_rmat_write: certificate: %s\n", err.msg), 1;
    double t3 = ulam_now();
    printf("certificate in %.1f s: rho(|M|) in [%.6g, %.6g]\n", t3 - t2, cert.guard.abs.lower, cert.guard.abs.upper);
    fflush(stdout);
    ulam_system_desc d = ulam_system_desc_defaults();
    d.M = &M, d.n = n, d.cert = &cert, d.transpose = 1;
    /* no bounds extension (ulam_system_write's analysis runs 300 power iterations over M for the
     * adjoint walks' length tail: 216 s at 2^20 and 8 edges a node, hours at 2^28; single source
     * reads none of it, and an adjoint query then makes its own) */
    FILE *f = fopen(argv[1], "wb");
    int status = !f ? ULAM_EIO : ulam__system_desc_check(f, &d) ? ULAM_EINVAL : ulam__system_write_checked(f, &d, NULL);
    if (f && fclose(f)) status = ULAM_EIO;
    printf("written %s in %.1f s (status %d)\n", argv[1], ulam_now() - t3, status);
    free(rp), free(col), free(val);
    return status ? 1 : 0;
}
