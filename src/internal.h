/* What every library source file shares (not installed): errors, allocation, threads, the b
 * scaling, the random stream's inline steps and the kernel's continuation.  Each module's
 * privates are in its own header (src/solve.h, src/analysis.h, src/cache.h, ...), included by
 * its friends only. */
#ifndef ULAM_INTERNAL_H
#define ULAM_INTERNAL_H

#include "ulam.h"

#include <float.h>
#include <stdarg.h>
#include <stdlib.h>

/* xoshiro256** step, inline for the walkers (ulam_rng_bounded(r, 0) is this). */
static inline uint64_t ulam__rng_next(ulam_rng *r)
{
    uint64_t *s = r->s;
    const uint64_t x = s[1] * 5, result = ((x << 7) | (x >> 57)) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = (s[3] << 45) | (s[3] >> 19);
    return result;
}

/* An index in [0, len) by Lemire's unbiased multiply-and-reject draw ("Fast random integer
 * generation in an interval", ACM TOMACS 29(1), 2019); *frac gets the low half of the same
 * product, uniform on a lattice of spacing len / 2^64 (the walkers use it as a coin). */
static inline uint64_t ulam__rng_index(ulam_rng *r, uint64_t len, uint64_t *frac)
{
    __uint128_t m = (__uint128_t)ulam__rng_next(r) * len;
    if ((uint64_t)m < len) {
        uint64_t floor = (0 - len) % len;
        while ((uint64_t)m < floor) m = (__uint128_t)ulam__rng_next(r) * len;
    }
    *frac = (uint64_t)m;
    return (uint64_t)(m >> 64);
}

/* The continuation probability of a state whose row of |K| sums to S: fixed continue_q when
 * given (> 0), else analog min(1, S); 0 for an empty row. */
static inline double ulam__continuation(double S, double continue_q)
{
    return S == 0.0 ? 0.0 : continue_q > 0 ? continue_q : (S < 1.0 ? S : 1.0);
}

/* The weight factor S / q of a state whose row of |K| sums to S (0 for an empty row). */
static inline double ulam__factor(double S, double continue_q)
{
    double q = ulam__continuation(S, continue_q);
    return q > 0 ? S / q : 0.0;
}

/* Uniform double in [0, 1) from the top 53 bits. */
/* The rounding a push's arithmetic may leave in a value of size `size` after `count` roundings
 * (its operations, plus the sums after it): each is at most DBL_EPSILON / 2 of what it adds (one
 * home for the push allowances of src/bidir.c, src/method_bidir.c and src/solve.c). */
static inline double ulam__push_rounding(double count, double size)
{
    return count * (DBL_EPSILON / 2.0) * size;
}

static inline double ulam__rng_uniform(ulam_rng *r)
{
    return (double)(ulam__rng_next(r) >> 11) * 0x1.0p-53;
}

/* Threads a run uses: requested when > 0, else all cores (1 without OpenMP). */
int ulam__threads(int requested);

/* The calling thread's number in the enclosing OpenMP team (0 outside one or without OpenMP). */
int ulam__thread_num(void);

/* This process's peak resident memory so far, in KiB (VmHWM, else ru_maxrss; -1: unknown): the one
 * measure of ulam solve's peak_rss_mib and a partitioned run's per-rank memory (src/util.c). */
double ulam__peak_rss_kib(void);

/* Record a failure in err (which may be NULL) and return status. */
int ulam__fail(ulam_error *err, int status, long line, int64_t index, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Reset err (which may be NULL) to "no error". */
void ulam__clear(ulam_error *err);

/* malloc of n items of size sz, NULL on overflow or failure (n == 0 allocates one byte). */
void *ulam__malloc(size_t n, size_t sz);

/* calloc of n items of size sz, NULL on failure (n == 0 allocates one byte). */
void *ulam__calloc(size_t n, size_t sz);

/* Uninitialised memory for n items of size sz, for a large array read at random (a matrix's
 * arrays, a push's vectors): cache-line aligned, and from 2 MiB on, 2 MiB aligned with
 * transparent huge pages asked for (a first touch and a TLB miss cost less); freed with free();
 * NULL on overflow or failure (src/util.c). */
void *ulam__alloc_big(size_t n, size_t sz);

/* Make room for need items of size sz in a growable array: pp is the address of its pointer
 * (a T **), *cap its capacity (doubling from 16; both are updated); ULAM_OK, or ULAM_ENOMEM
 * leaving the array as it was. */
int ulam__grow(void *pp, int64_t *cap, int64_t need, size_t sz);

/* Scaling of b (src/util.c): a solver works on b 2^-e when b's largest |entry| is far from 1, so
 * that scores, sums and squares neither overflow nor underflow, and multiplies what it finds by
 * 2^e (both exact: powers of 2).  ulam__b_exponent gives e (0: no scaling; b's largest |entry|
 * outside [2^-256, 2^256] is brought into [0.5, 1)); ulam__b_scaled a malloc'd copy of b 2^-e. */
int ulam__b_exponent(const double *b, int64_t n);
double *ulam__b_scaled(const double *b, int64_t n, int e);

/* One Gauss-Seidel sweep on x = M x + b, in place (rows in order, new values used at once). */
void ulam__gauss_seidel_sweep(const ulam_csr *M, const double *b, double *x);

/* Gauss-Seidel sweeps on x (in place, from what it holds) until, after at least min_sweeps, one
 * sweep changes x[index] by at most rel_tol |x[index]|, or max_sweeps are made; returns the
 * sweeps made. */
int ulam__gauss_seidel_settle(const ulam_csr *M, const double *b, double *x, int64_t index, double rel_tol,
                             int min_sweeps, int max_sweeps);

/* The k-th (k < 4) uniform double in [0, 1) of step t of walk w under seed: a counter-based
 * stream (splitmix64's finalizer chained over the key), the same on every rank and thread, so a
 * walk that migrates between ranks (ulam_dist.h) takes the same path. */
double ulam__rng_counter(uint64_t seed, uint64_t w, uint64_t t, unsigned k);

#endif