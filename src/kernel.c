/* The transition kernel of a walk on the rows of a matrix K (M for adjoint walks, M' for
 * forward walks).
 *
 * From state i the walk continues with probability q_i and then moves to j with probability
 * p_ij = |K_ij| / S_i (S_i = sum_j |K_ij|); it terminates with p*_i = 1 - q_i.  The weight is
 * multiplied by K_ij / (q_i p_ij) = sign(K_ij) S_i / q_i: a per-row factor and a sign.  The
 * L_i + 1 outcomes of row i (L_i moves and termination) share one Walker alias table built by
 * Vose's method (M. D. Vose, "A linear algorithm for generating random numbers with a given
 * distribution", IEEE TSE 17(9), 1991), so a step costs one 64-bit draw.  Each row's header
 * (factor, scores, length) sits just before its slots, and outcomes name the target row's
 * position, so a step touches one row's memory and nothing else. */
#include "kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Free a kernel; accepts NULL. */
ulam_kernel *ulam__kernel_free(ulam_kernel *k)
{
    if (!k) return NULL;
    free(k->mem);
    free(k->at);
    free(k->pstar);
    free(k);
    return NULL;
}

/* The 64-bit threshold of an alias fraction f in [0, 1]. */
static uint64_t threshold(double f)
{
    return f >= 1.0 ? UINT64_MAX : f <= 0.0 ? 0 : (uint64_t)(f * 0x1.0p64);
}

/* Vose's alias table for the m outcomes with probabilities p (summing to 1) into s. */
void ulam__alias_build(const double *p, const int32_t *out, int64_t m, ulam__slot *s, double *scaled,
                        int64_t *small, int64_t *large)
{
    int64_t ns = 0, nl = 0;
    for (int64_t k = 0; k < m; k++) {
        scaled[k] = p[k] * (double)m;
        if (scaled[k] < 1.0) small[ns++] = k;
        else large[nl++] = k;
    }
    while (ns > 0 && nl > 0) {
        int64_t a = small[--ns], g = large[nl - 1];
        s[a] = (ulam__slot){threshold(scaled[a]), out[a], out[g]};
        scaled[g] = (scaled[g] + scaled[a]) - 1.0;
        if (scaled[g] < 1.0) {
            nl--;
            small[ns++] = g;
        }
    }
    while (nl > 0) { /* leftovers are 1 up to rounding */
        int64_t g = large[--nl];
        s[g] = (ulam__slot){UINT64_MAX, out[g], out[g]};
    }
    while (ns > 0) {
        int64_t a = small[--ns];
        s[a] = (ulam__slot){UINT64_MAX, out[a], out[a]};
    }
}

/* Encode moving to the row at unit u with the sign of v. */
static int32_t encode(int64_t u, double v)
{
    return v < 0 ? ~(int32_t)u : (int32_t)u;
}

/* Lay out the rows: at[i] is row i's first unit; returns the total, or -1 past int32. */
static int64_t layout(const ulam_csr *K, int64_t *at)
{
    int64_t u = 0;
    for (int64_t i = 0; i < K->nrows; i++) {
        at[i] = u;
        u += ULAM__HEAD + (K->rowptr[i + 1] - K->rowptr[i]) + 1;
        if (u >= INT32_MAX) return -1;
    }
    return u;
}

/* Scratch for building alias tables of up to m outcomes. */
typedef struct {
    double *p, *scaled;
    int32_t *o;
    int64_t *small, *large;
} scratch;

/* Allocate scratch for m outcomes; 0 on failure (what was allocated is freed by drop). */
static int scratch_get(scratch *w, int64_t m)
{
    w->p = ulam__malloc((size_t)m, sizeof *w->p);
    w->scaled = ulam__malloc((size_t)m, sizeof *w->scaled);
    w->o = ulam__malloc((size_t)m, sizeof *w->o);
    w->small = ulam__malloc((size_t)m, sizeof *w->small);
    w->large = ulam__malloc((size_t)m, sizeof *w->large);
    return w->p && w->scaled && w->o && w->small && w->large;
}

/* Free scratch. */
static void scratch_drop(scratch *w)
{
    free(w->p), free(w->scaled), free(w->o), free(w->small), free(w->large);
}

/* Fill row i: header, then the alias table of its moves and termination. */
static void build_row(const ulam_csr *K, int64_t i, double continue_q, ulam_kernel *k, scratch *w)
{
    int64_t b = K->rowptr[i], len = K->rowptr[i + 1] - b;
    double S = 0.0;
    for (int64_t q = b; q < b + len; q++) S += fabs(K->val[q]);
    double qi = ulam__continuation(S, continue_q);
    ulam__row *h = ulam__kernel_row(k, k->at[i]);
    *h = (ulam__row){.factor = qi > 0 ? S / qi : 0.0, .len = (int32_t)(len + 1), .state = (int32_t)i};
    k->pstar[i] = 1.0 - qi;
    for (int64_t q = 0; q < len; q++) {
        w->p[q] = qi * fabs(K->val[b + q]) / S;
        w->o[q] = encode(k->at[K->colidx[b + q]], K->val[b + q]);
    }
    w->p[len] = k->pstar[i];
    w->o[len] = ULAM__TERMINATE;
    ulam__alias_build(w->p, w->o, len + 1, k->mem + k->at[i] + ULAM__HEAD, w->scaled, w->small, w->large);
}

/* Prefetch the row positions that row i's outcomes will look up (random reads). */
static void prefetch_targets(const ulam_csr *K, const int64_t *at, int64_t i)
{
#if defined(__GNUC__)
    if (i < K->nrows)
        for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) __builtin_prefetch(at + K->colidx[q]);
#else
    (void)K, (void)at, (void)i;
#endif
}

/* Build the kernel of K; continue_q <= 0 means analog q_i = min(1, S_i).  Rows are built in
 * parallel; the positions of rows a few ahead are prefetched. */
int ulam__kernel_build(const ulam_csr *K, double continue_q, ulam_kernel **out)
{
    *out = NULL;
    int64_t n = K->nrows, maxlen = 0;
    for (int64_t i = 0; i < n; i++)
        if (K->rowptr[i + 1] - K->rowptr[i] > maxlen) maxlen = K->rowptr[i + 1] - K->rowptr[i];
    ulam_kernel *k = calloc(1, sizeof *k);
    if (!k) return ULAM_ENOMEM;
    k->n = n;
    k->at = ulam__alloc_big((size_t)n, sizeof *k->at);
    k->pstar = ulam__malloc((size_t)n, sizeof *k->pstar);
    if (!k->at || !k->pstar || (k->units = layout(K, k->at)) < 0 ||
        !(k->mem = ulam__alloc_big((size_t)k->units, sizeof *k->mem))) {
        ulam__kernel_free(k);
        return ULAM_ENOMEM;
    }
    int failed = 0;
#pragma omp parallel reduction(| : failed) if (n > 50000)
    {
        scratch w;
        if (!scratch_get(&w, maxlen + 1)) failed = 1;
#pragma omp for schedule(static, 4096)
        for (int64_t i = 0; i < n; i++) {
            if (failed) continue;
            prefetch_targets(K, k->at, i + 16);
            build_row(K, i, continue_q, k, &w);
        }
        scratch_drop(&w);
    }
    if (failed) {
        ulam__kernel_free(k);
        return ULAM_ENOMEM;
    }
    *out = k;
    return ULAM_OK;
}

/* States reachable from the start set (marked in seen[]) along the kernel's moves. */
int ulam__kernel_reach(const ulam_kernel *k, char *seen)
{
    int64_t *stack = ulam__malloc((size_t)k->n, sizeof *stack), top = 0;
    if (!stack) return ULAM_ENOMEM;
    for (int64_t i = 0; i < k->n; i++)
        if (seen[i]) stack[top++] = i;
    while (top > 0) {
        const ulam__row *h = ulam__kernel_row(k, k->at[stack[--top]]);
        const ulam__slot *s = (const ulam__slot *)(const void *)h + ULAM__HEAD;
        for (int32_t q = 0; q < h->len; q++) {
            int32_t outs[2] = {s[q].a, s[q].b};
            for (int t = 0; t < 2; t++) {
                if (outs[t] == ULAM__TERMINATE) continue;
                int32_t j = ulam__kernel_row(k, ulam__outcome_target(outs[t]))->state;
                if (!seen[j]) {
                    seen[j] = 1;
                    stack[top++] = j;
                }
            }
        }
    }
    free(stack);
    return ULAM_OK;
}
