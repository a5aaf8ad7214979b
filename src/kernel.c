/* The transition kernel of a walk on the rows of a matrix K (M for adjoint walks, M' for
 * forward walks).
 *
 * From state i the walk continues with probability q_i and then moves to j with probability
 * p_ij = |K_ij| / S_i (S_i = sum_j |K_ij|); it terminates with p*_i = 1 - q_i.  The weight is
 * multiplied by K_ij / (q_i p_ij) = sign(K_ij) S_i / q_i: a per-row factor and a sign.  The
 * L_i + 1 outcomes of row i (L_i moves and termination) share one Walker alias table built by
 * Vose's method (M. D. Vose, "A linear algorithm for generating random numbers with a given
 * distribution", IEEE TSE 17(9), 1991), so a step costs one bounded draw and one uniform. */
#include "kernel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Free a kernel; accepts NULL. */
ulam_kernel *ulam__kernel_free(ulam_kernel *k)
{
    if (!k) return NULL;
    free(k->ptr);
    free(k->slot);
    free(k->factor);
    free(k->pstar);
    free(k);
    return NULL;
}

/* Encode moving to j with the sign of v. */
static int32_t encode(int32_t j, double v)
{
    return v < 0 ? ~j : j;
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
        s[a] = (ulam__slot){scaled[a], out[a], out[g]};
        scaled[g] = (scaled[g] + scaled[a]) - 1.0;
        if (scaled[g] < 1.0) {
            nl--;
            small[ns++] = g;
        }
    }
    while (nl > 0) { /* leftovers are 1 up to rounding */
        int64_t g = large[--nl];
        s[g] = (ulam__slot){1.0, out[g], out[g]};
    }
    while (ns > 0) {
        int64_t a = small[--ns];
        s[a] = (ulam__slot){1.0, out[a], out[a]};
    }
}

/* Build the kernel of K; continue_q <= 0 means analog q_i = min(1, S_i). */
int ulam__kernel_build(const ulam_csr *K, double continue_q, ulam_kernel **out)
{
    *out = NULL;
    int64_t n = K->nrows, nz = ulam_csr_nnz(K), maxlen = 0;
    for (int64_t i = 0; i < n; i++) {
        int64_t len = K->rowptr[i + 1] - K->rowptr[i];
        if (len > maxlen) maxlen = len;
    }
    ulam_kernel *k = calloc(1, sizeof *k);
    if (!k) return ULAM_ENOMEM;
    k->n = n;
    k->ptr = ulam__malloc((size_t)n + 1, sizeof *k->ptr);
    k->slot = ulam__malloc((size_t)(nz + n), sizeof *k->slot);
    k->factor = ulam__malloc((size_t)n, sizeof *k->factor);
    k->pstar = ulam__malloc((size_t)n, sizeof *k->pstar);
    double *p = ulam__malloc((size_t)maxlen + 1, sizeof *p), *scaled = ulam__malloc((size_t)maxlen + 1, sizeof *scaled);
    int32_t *o = ulam__malloc((size_t)maxlen + 1, sizeof *o);
    int64_t *small = ulam__malloc((size_t)maxlen + 1, sizeof *small), *large = ulam__malloc((size_t)maxlen + 1, sizeof *large);
    int status = ULAM_ENOMEM;
    if (!k->ptr || !k->slot || !k->factor || !k->pstar || !p || !scaled || !o || !small || !large) goto done;
    for (int64_t i = 0; i < n; i++) {
        int64_t b = K->rowptr[i], e = K->rowptr[i + 1], len = e - b;
        double S = 0.0;
        for (int64_t q = b; q < e; q++) S += fabs(K->val[q]);
        double qi = continue_q > 0 ? continue_q : fmin(1.0, S);
        if (S == 0.0) qi = 0.0;
        k->factor[i] = qi > 0 ? S / qi : 0.0;
        k->pstar[i] = 1.0 - qi;
        k->ptr[i] = b + i;
        for (int64_t q = 0; q < len; q++) {
            p[q] = qi * fabs(K->val[b + q]) / S;
            o[q] = encode(K->colidx[b + q], K->val[b + q]);
        }
        p[len] = k->pstar[i];
        o[len] = ULAM__TERMINATE;
        ulam__alias_build(p, o, len + 1, k->slot + b + i, scaled, small, large);
    }
    k->ptr[n] = nz + n;
    status = ULAM_OK;
done:
    free(p), free(scaled), free(o), free(small), free(large);
    if (status) ulam__kernel_free(k);
    else *out = k;
    return status;
}

/* States reachable from the start set (marked in seen[]) along the kernel's moves. */
void ulam__kernel_reach(const ulam_kernel *k, char *seen)
{
    int64_t *stack = ulam__malloc((size_t)k->n, sizeof *stack), top = 0;
    if (!stack) return;
    for (int64_t i = 0; i < k->n; i++)
        if (seen[i]) stack[top++] = i;
    while (top > 0) {
        int64_t i = stack[--top];
        for (int64_t s = k->ptr[i]; s < k->ptr[i + 1]; s++) {
            int32_t outs[2] = {k->slot[s].a, k->slot[s].b};
            for (int t = 0; t < 2; t++) {
                if (outs[t] == ULAM__TERMINATE) continue;
                int32_t j = outs[t] < 0 ? ~outs[t] : outs[t];
                if (!seen[j]) {
                    seen[j] = 1;
                    stack[top++] = j;
                }
            }
        }
    }
    free(stack);
}
