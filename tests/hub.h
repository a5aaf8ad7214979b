/* k "ranks" as k threads of one process sharing an in-memory exchange (ulam_comm of
 * ulam_dist.h), for the partitioned walks' tests and benchmark: each posts its send buffer, all
 * meet, each copies what is addressed to it, all meet again. */
#ifndef ULAM_TEST_HUB_H
#define ULAM_TEST_HUB_H

#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "ulam_dist.h"

enum { HUB_MAX = 64 };

/* The in-memory exchange of k thread-ranks: each posts its send buffer, all meet, each copies
 * what is addressed to it, all meet again. */
typedef struct {
    int k;
    pthread_barrier_t bar;
    const char *send[HUB_MAX];
    const size_t *counts[HUB_MAX];
    int64_t *sums[HUB_MAX];
} hub;

typedef struct {
    hub *h;
    int rank;
} port;

/* The exchange (ulam_comm.exchange) between the hub's threads. */
static inline int hub_exchange(void *ctx, const void *send, const size_t *sendcounts, void **recv, size_t *recvcounts)
{
    port *p = ctx;
    hub *h = p->h;
    h->send[p->rank] = send, h->counts[p->rank] = sendcounts;
    pthread_barrier_wait(&h->bar);
    size_t total = 0;
    for (int r = 0; r < h->k; r++) recvcounts[r] = h->counts[r][p->rank], total += recvcounts[r];
    char *buf = malloc(total ? total : 1);
    size_t at = 0;
    for (int r = 0; r < h->k; r++) {
        size_t off = 0;
        for (int q = 0; q < p->rank; q++) off += h->counts[r][q];
        memcpy(buf + at, h->send[r] + off, recvcounts[r]);
        at += recvcounts[r];
    }
    pthread_barrier_wait(&h->bar);
    *recv = buf;
    return 0;
}

/* The sum over the hub's threads (ulam_comm.sum). */
static inline int hub_sum(void *ctx, int64_t *v, int n)
{
    port *p = ctx;
    hub *h = p->h;
    int64_t *mine = malloc((size_t)n * sizeof *mine);
    memcpy(mine, v, (size_t)n * sizeof *v);
    h->sums[p->rank] = mine;
    pthread_barrier_wait(&h->bar);
    for (int i = 0; i < n; i++) {
        int64_t s = 0;
        for (int r = 0; r < h->k; r++) s += h->sums[r][i];
        v[i] = s;
    }
    pthread_barrier_wait(&h->bar);
    free(mine);
    return 0;
}

/* Ready h for k thread-ranks. */
static inline void hub_init(hub *h, int k)
{
    memset(h, 0, sizeof *h);
    h->k = k;
    pthread_barrier_init(&h->bar, NULL, (unsigned)k);
}

/* The comm of port p. */
static inline ulam_comm hub_comm(port *p)
{
    return (ulam_comm){.rank = p->rank, .nranks = p->h->k, .ctx = p, .exchange = hub_exchange, .sum = hub_sum};
}

#endif
