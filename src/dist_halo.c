/* The halo of a rank's rows: the outside columns they read, found once (ulam__halo_make) and
 * refreshed from their owners a product at a time (ulam__halo_swap); used by the partitioned
 * radius guard (src/dist_radius.c) and second moment (src/dist_moment.c). */
#include "part.h"

#include <stdlib.h>
#include <string.h>

/* Free h's arrays. */
void ulam__halo_free(ulam__halo *h)
{
    free(h->ghost), free(h->idx), free(h->at), free(h->loc);
}

/* Order of int64_t. */
static int by_int64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Add column j to the open-addressing set t (cap a power of 2, -1 empty, *len entries), doubling
 * it at half full; nonzero when out of memory. */
static int set_add(int32_t **t, int64_t *cap, int64_t *len, int32_t j)
{
    if (2 * (*len + 1) > *cap) {
        int64_t nc = *cap ? 2 * *cap : 1024;
        int32_t *nt = malloc((size_t)nc * sizeof *nt);
        if (!nt) return 1;
        memset(nt, 0xff, (size_t)nc * sizeof *nt);
        for (int64_t q = 0; q < *cap; q++) {
            if ((*t)[q] < 0) continue;
            uint64_t at = ((uint64_t)(*t)[q] * 0x9E3779B97F4A7C15u) >> 20 & (uint64_t)(nc - 1);
            while (nt[at] >= 0) at = (at + 1) & (uint64_t)(nc - 1);
            nt[at] = (*t)[q];
        }
        free(*t);
        *t = nt, *cap = nc;
    }
    uint64_t at = ((uint64_t)j * 0x9E3779B97F4A7C15u) >> 20 & (uint64_t)(*cap - 1);
    while ((*t)[at] >= 0 && (*t)[at] != j) at = (at + 1) & (uint64_t)(*cap - 1);
    if ((*t)[at] < 0) (*t)[at] = j, ++*len;
    return 0;
}

/* Find the halo of A's rows on this rank: its sorted distinct outside columns (gathered in a hash
 * set: memory by the halo, not by the entries or n), each asked of its owner through one
 * exchange; nonzero on failure (memory or the exchange). */
int ulam__halo_make(const ulam_part *p, const ulam_comm *c, const ulam__rows *A, ulam__halo *h)
{
    *h = (ulam__halo){0};
    int64_t rows = p->last - p->first, k = c->nranks, cap = 0, u = 0;
    int32_t *t = NULL;
    for (int64_t q = 0; q < A->rowptr[rows]; q++)
        if ((A->col[q] < p->first || A->col[q] >= p->last) && set_add(&t, &cap, &u, A->col[q])) return free(t), 1;
    h->ghost = malloc(((size_t)u + 1) * sizeof *h->ghost);
    h->at = calloc((size_t)k + 1, sizeof *h->at);
    size_t *cnt = calloc((size_t)k * 2, sizeof *cnt);
    if (!h->ghost || !h->at || !cnt) return free(t), free(cnt), 1;
    for (int64_t q = 0, m = 0; q < cap; q++)
        if (t[q] >= 0) h->ghost[m++] = t[q];
    free(t);
    h->nghost = u;
    if (u) qsort(h->ghost, (size_t)u, sizeof *h->ghost, by_int64);
    for (int64_t q = 0; q < u; q++) cnt[p->set * p->nranks + ulam__part_owner(p, h->ghost[q])] += sizeof(int64_t);
    void *got = NULL;
    int bad = k > 1 ? c->exchange(c->ctx, h->ghost, cnt, &got, cnt + k) : 0; /* ghosts sorted: in owner order */
    size_t total = 0;
    for (int r = 0; !bad && r < k; r++) h->at[r + 1] = h->at[r] + (int64_t)(cnt[k + r] / sizeof(int64_t)), total += cnt[k + r];
    h->idx = malloc(total + 1);
    if (!bad && h->idx) {
        if (total) memcpy(h->idx, got, total);
        for (int64_t q = 0; q < h->at[k]; q++) {
            h->idx[q] -= p->first;
            if (h->idx[q] < 0 || h->idx[q] >= rows) bad = 1; /* a request for a row this rank does not hold */
        }
    }
    free(got), free(cnt);
    h->rows = rows;
    if (!bad && h->idx && k > 1) { /* each entry's place, by one search now instead of one a product */
        h->loc = malloc(((size_t)A->rowptr[rows] + 1) * sizeof *h->loc);
        for (int64_t q = 0; h->loc && q < A->rowptr[rows]; q++) {
            int64_t j = A->col[q], lo = 0, hi = u - 1;
            if (j >= p->first && j < p->last) {
                h->loc[q] = (int32_t)(j - p->first);
                continue;
            }
            while (lo < hi) {
                int64_t mid = (lo + hi) / 2;
                if (h->ghost[mid] < j) lo = mid + 1;
                else hi = mid;
            }
            h->loc[q] = (int32_t)(rows + lo);
        }
        if (!h->loc) bad = 1;
    }
    return bad || !h->idx;
}

/* The iterate's halo values into gv (in h->ghost order) from every rank's rows mine; nonzero on a
 * failed exchange. */
int ulam__halo_swap(const ulam_part *p, const ulam_comm *c, const ulam__halo *h, const double *mine, double *gv)
{
    int k = c->nranks;
    if (k == 1) return 0;
    size_t *cnt = calloc((size_t)k * 2, sizeof *cnt);
    double *send = malloc(((size_t)h->at[k] + 1) * sizeof *send);
    void *got = NULL;
    int bad = !cnt || !send;
    for (int r = 0; !bad && r < k; r++) cnt[r] = (size_t)(h->at[r + 1] - h->at[r]) * sizeof *send;
    for (int64_t q = 0; !bad && q < h->at[k]; q++) send[q] = mine[h->idx[q]];
    if (!bad) bad = c->exchange(c->ctx, send, cnt, &got, cnt + k);
    size_t total = 0;
    for (int r = 0; !bad && r < k; r++) total += cnt[k + r];
    if (!bad && total == (size_t)h->nghost * sizeof *gv) {
        if (total) memcpy(gv, got, total); /* no ghosts: got may be NULL */
    } else {
        bad = 1;
    }
    (void)p;
    free(cnt), free(send), free(got);
    return bad;
}
