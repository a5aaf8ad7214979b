/* xoshiro256** 1.0 by David Blackman and Sebastiano Vigna (2018, public domain; see
 * "Scrambled linear pseudorandom number generators", ACM TOMS 47(4), 2021 and
 * https://prng.di.unimi.it/xoshiro256starstar.c), seeded through splitmix64. */
#include "internal.h"

/* splitmix64 step (Steele, Lea and Flood, "Fast splittable pseudorandom number
 * generators", OOPSLA 2014): advance *x and return a well-mixed 64-bit value. */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* Seed from (seed, stream): distinct pairs give unrelated 256-bit states. */
void ulam_rng_seed(ulam_rng *r, uint64_t seed, uint64_t stream)
{
    uint64_t x = seed;
    uint64_t h = splitmix64(&x);
    uint64_t y = stream ^ 0x632be59bd9b4e019ULL;
    x = h ^ splitmix64(&y);
    for (int k = 0; k < 4; k++) r->s[k] = splitmix64(&x);
    if (!(r->s[0] | r->s[1] | r->s[2] | r->s[3])) r->s[0] = 1; /* the one forbidden state */
}

/* Uniform double in [0, 1): the top 53 bits times 2^-53. */
double ulam_rng_uniform(ulam_rng *r)
{
    return ulam__rng_uniform(r);
}

/* Unbiased integer in [0, bound) (Lemire's multiply-and-reject, see internal.h); bound 0: the
 * next 64 bits, [0, 2^64). */
uint64_t ulam_rng_bounded(ulam_rng *r, uint64_t bound)
{
    uint64_t frac;
    return bound ? ulam__rng_index(r, bound, &frac) : ulam__rng_next(r);
}

/* splitmix64's finalizer: a bijective mix of 64 bits. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* Uniform double in [0, 1) keyed by (seed, w, t, k): the mix chained over the key's words. */
double ulam__rng_counter(uint64_t seed, uint64_t w, uint64_t t, unsigned k)
{
    uint64_t h = mix64(seed + 0x9e3779b97f4a7c15ULL);
    h = mix64(h ^ (w + 0x632be59bd9b4e019ULL));
    h = mix64(h + (t << 2 | (k & 3)) * 0x9e3779b97f4a7c15ULL);
    return (double)(h >> 11) * 0x1.0p-53;
}

/* The seed of sub-run k for purpose p: the mix chained over (seed, p, k), its top bit cleared
 * (a seed the CLI's --seed and Python's seed= take: 0 .. 2^63 - 1). */
uint64_t ulam_rng_substream(uint64_t seed, ulam_stream_purpose p, uint64_t k)
{
    uint64_t h = mix64(seed + 0x9e3779b97f4a7c15ULL);
    h = mix64(h ^ ((uint64_t)p * 0xd1b54a32d192ed03ULL));
    return mix64(h + (k + 1) * 0x9e3779b97f4a7c15ULL) & 0x7fffffffffffffffULL;
}
