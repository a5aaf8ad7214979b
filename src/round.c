/* The round driver shared by matrix walks (solve.c) and patch walks (radiosity/patchwalk.c):
 * rounds of blocks of walks spread over threads and, through ulam_share, over processes, whose
 * results every process then holds in block order (so any thread or rank count gives the same
 * totals); and the after-round step both solvers take (ulam__round_step: merge in block order,
 * failures, interrupt, budget and time), so those stopping rules are written once. */
#include "round.h"
#include "defaults.h"
#include "check.h"

#include <stdlib.h>
#include <string.h>

enum { TEAM_BLOCKS = 4 }; /* blocks a thread a round must have before a round takes a team */

/* The stopping defaults: 10^5 walks, 10^6 steps a walk. */
ulam_stop_opts ulam__stop_defaults(void)
{
    return (ulam_stop_opts){.max_walks = 100000, .max_steps = 1000000};
}

/* One process. */
ulam_share ulam__share_defaults(void)
{
    return (ulam_share){.rank = 0, .nranks = 1, .allgather = NULL, .ctx = NULL};
}

/* Nonzero when a block starting at walk first may start. */
int ulam__block_may_start(const ulam_walk_opts *o, double t0, int64_t first)
{
    if (o->stop.interrupt && *o->stop.interrupt) return 0;
    return first == 0 || !(o->stop.max_seconds > 0 && ulam_now() - t0 >= o->stop.max_seconds);
}

/* Nonzero when this process runs block q. */
int ulam__mine(const ulam_share *sh, int64_t q)
{
    return !sh || sh->nranks <= 1 || q % sh->nranks == sh->rank;
}

/* Nonzero when the walk budget is spent after `walks` walks or the stop flags say time is up. */
static int budget_spent(const ulam_walk_opts *o, int stop, int64_t walks)
{
    return (stop & 1) || (o->stop.max_walks > 0 && walks >= o->stop.max_walks);
}

/* This process's stop flags: 1 time is up, 2 interrupted. */
static int local_stop(const ulam_walk_opts *o, double t0)
{
    int f = o->stop.max_seconds > 0 && ulam_now() - t0 >= o->stop.max_seconds ? 1 : 0;
    return f | (o->stop.interrupt && *o->stop.interrupt ? 2 : 0);
}

/* Append n bytes to the buffer *buf of length *len and capacity *cap. */
static int put(unsigned char **buf, int64_t *len, int64_t *cap, const void *p, size_t n)
{
    if (ulam__grow(buf, cap, *len + (int64_t)n, 1)) return ULAM_ENOMEM;
    if (n) memcpy(*buf + *len, p, n);
    *len += (int64_t)n;
    return ULAM_OK;
}

/* This process's message: its length and stop flags, then for each block it ran, its index,
 * struct and tallies. */
static int pack(const void *blocks, const ulam__blocks *L, int nb, int64_t q0, const ulam_share *sh,
                int stop, unsigned char **buf, int64_t *len)
{
    int64_t cap = 0, tlen, head[2] = {0, stop};
    int status = put(buf, len, &cap, head, sizeof head);
    for (int64_t k = 0; k < nb && !status; k++) {
        if (!ulam__mine(sh, q0 + k)) continue;
        const unsigned char *b = (const unsigned char *)blocks + (size_t)k * L->size;
        const ulam__block_head *h = (const ulam__block_head *)b;
        tlen = h->len;
        if (!(status = put(buf, len, &cap, &k, sizeof k)) && !(status = put(buf, len, &cap, b, L->size)))
            status = put(buf, len, &cap, h->tally, (size_t)tlen * L->tally_size);
    }
    if (!status) memcpy(*buf, len, sizeof *len);
    return status;
}

/* Read one process's message (n bytes at p) into blocks[], each block keeping its own tally
 * storage; *stop |= its flags. */
static int unpack(const unsigned char *p, size_t n, void *blocks, const ulam__blocks *L, int nb, int *stop)
{
    int64_t head[2];
    memcpy(head, p, sizeof head);
    *stop |= (int)head[1];
    for (size_t at = sizeof head; at < n;) {
        int64_t k, tlen;
        if (n - at < sizeof k + L->size) return ULAM_EIO;
        memcpy(&k, p + at, sizeof k);
        if (k < 0 || k >= nb) return ULAM_EIO;
        unsigned char *b = (unsigned char *)blocks + (size_t)k * L->size;
        ulam__block_head *h = (ulam__block_head *)b;
        void *t = h->tally; /* the block keeps its own tally storage */
        int64_t cap = h->cap;
        memcpy(b, p + at + sizeof k, L->size);
        at += sizeof k + L->size;
        tlen = h->len;
        h->tally = t, h->cap = cap;
        if (tlen < 0 || (uint64_t)tlen > (n - at) / L->tally_size) return ULAM_EIO;
        if (ulam__grow(&h->tally, &h->cap, tlen, L->tally_size)) return ULAM_ENOMEM;
        if (tlen) memcpy(h->tally, p + at, (size_t)tlen * L->tally_size);
        at += (size_t)tlen * L->tally_size;
    }
    return ULAM_OK;
}

/* Exchange a round's nb blocks (from block q0) between the processes of o->share; *stop gets
 * the stop flags or'ed over them (this process's alone without a share). */
static int exchange(const ulam_walk_opts *o, double t0, void *blocks, const ulam__blocks *L, int nb, int64_t q0,
                    int *stop)
{
    const ulam_share *sh = o->exec.share;
    *stop = local_stop(o, t0);
    if (!sh || sh->nranks <= 1) return ULAM_OK;
    unsigned char *mine = NULL;
    int64_t len = 0, head[2] = {sizeof head, *stop | 4}; /* 4: this process failed */
    int status = pack(blocks, L, nb, q0, sh, *stop, &mine, &len);
    void *all = NULL;
    size_t total = 0; /* every process takes part, even one that failed to pack */
    if (sh->allgather(sh->ctx, status ? (void *)head : mine, status ? sizeof head : (size_t)len, &all, &total))
        status = ULAM_EIO;
    free(mine);
    for (size_t at = 0; !status && at < total;) {
        int64_t n;
        if (total - at < 2 * sizeof n) status = ULAM_EIO;
        else memcpy(&n, (const unsigned char *)all + at, sizeof n);
        if (!status && (n < (int64_t)(2 * sizeof n) || (uint64_t)n > total - at)) status = ULAM_EIO;
        if (!status) status = unpack((const unsigned char *)all + at, (size_t)n, blocks, L, nb, stop);
        at += status ? 0 : (size_t)n;
    }
    if (!status && (*stop & 4)) status = ULAM_ENOMEM; /* another process could not pack */
    free(all);
    return status;
}

/* One round of blocks, in parallel, then the exchange between processes.  Rounds grow 1, 2,
 * 4, ... blocks up to B->round (a round is as long as all before it), so a --rel-err or time
 * rule is checked often while little has run, and the schedule depends on walks done only,
 * never on the thread count. */
static int ulam__round(const ulam__blocks *B, const ulam_walk_opts *o, double t0, int64_t next, int64_t skip, int64_t want,
                int threads, void *ctx, void *results, int *nb, int *stop)
{
    int64_t left = o->stop.max_walks > 0 ? o->stop.max_walks - next : INT64_MAX, done = (next + skip) / B->block;
    int round = done + 1 < B->round ? (int)(done + 1) : B->round, n = 0;
    if (want > 0 && want / B->block + 1 < round) round = (int)(want / B->block + 1); /* a rule's stop is near */
    if (B->partial && want > 0 && want < left) left = want; /* exactly the walks asked: the last block cut short */
    while (n < round && left > (int64_t)n * B->block) n++;
    next += skip; /* the walks' place in the streams */
    /* A team only for rounds of at least TEAM_BLOCKS blocks a thread: a small round (the first
       ones, a small query) runs on the calling thread, which would otherwise wait at the round's
       end for a worker to be scheduled: on a busy machine a time slice or more, 40-100x the walks
       of a 4096-walk query (issue 29 point 5; the results do not depend on the team) */
    int team = n >= TEAM_BLOCKS * threads ? threads : 1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(team) if (team > 1)
    for (int k = 0; k < n; k++) {
        int64_t rest = left - (int64_t)k * B->block;
        B->run(ctx, k, next + (int64_t)k * B->block, rest < B->block ? rest : B->block, ulam__thread_num());
    }
    int status = exchange(o, t0, results, B, n, done, stop);
    *nb = status ? 0 : n;
    return status;
}


/* A run not yet started. */
void ulam__run_reset(ulam__run *run)
{
    *run = (ulam__run){.t0 = -1};
}

/* Block k's head in results. */
static const ulam__block_head *head(const ulam__blocks *B, const void *results, int k)
{
    return (const ulam__block_head *)((const unsigned char *)results + (size_t)k * B->size);
}

/* One round, its merge and the stopping rules but the relative error. */
int ulam__round_step(const ulam__blocks *B, const ulam_walk_opts *o, int threads, void *ctx, void *results,
                     ulam__run *run)
{
    double start = ulam_now();
    if (run->t0 < 0) run->t0 = start;
    if (B->begin) B->begin(ctx);
    int nb, stop, st = ulam__round(B, o, run->t0, run->walks, run->skip, run->want, threads, ctx, results, &nb, &stop);
    if (st) run->status = st;
    for (int k = 0; k < nb; k++) {
        const ulam__block_head *h = head(B, results, k);
        if (h->nomem) run->status = ULAM_ENOMEM;
        if (!h->complete) { /* interrupted or out of time: keep what came before */
            run->done = 1;
            break;
        }
        B->merge(ctx, k);
        run->walks += h->walks;
        if (B->partial && h->walks < B->block) run->skip += B->block - h->walks; /* the rest of its stream unrun */
        run->nonfinite += h->nonfinite;
    }
    run->seconds += ulam_now() - start;
    if (stop & 2) run->interrupted = run->done = 1;
    if (B->failure && (st = B->failure(ctx))) run->status = st, run->done = 1;
    if (run->nonfinite && !run->status) run->status = ULAM_ENONFINITE;
    if (run->status) run->done = 1;
    if (budget_spent(o, stop, run->walks)) run->done = 1;
    return run->status;
}

/* The budgets both solvers check first. */
int ulam__budgets_check(const ulam_walk_opts *o, ulam_error *err)
{
    int status = ulam__walk_opts_check(o, err); /* src/check.c: NaN, +-inf, out of range */
    if (status) return status;
    if (o->stop.max_walks < 0 || o->stop.rel_err < 0 || o->stop.max_seconds < 0 || o->stop.max_steps < 1 || o->exec.threads < 0)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "nonnegative budgets and max_steps >= 1");
    if (o->stop.max_walks == 0 && o->stop.rel_err == 0 && o->stop.max_seconds == 0 && !o->stop.interrupt)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a stopping rule: walks, rel_err or time");
    return ULAM_OK;
}

/* A rel_err target with the default walk budget runs to the target. */
ulam_walk_opts ulam__lift_default_cap(const ulam_walk_opts *o)
{
    ulam_walk_opts w = *o;
    if (w.stop.rel_err > 0 && w.stop.max_walks == ulam__stop_defaults().max_walks && !(w.stop.max_seconds > 0))
        w.stop.max_walks = 0;
    return w;
}

/* The walk cap: ULAM_REL_ERR_CAP with rel_err alone, else max_walks. */
int64_t ulam__walk_cap(const ulam_walk_opts *o)
{
    return o->stop.rel_err > 0 && o->stop.max_walks == 0 && o->stop.max_seconds == 0 ? ULAM_REL_ERR_CAP : o->stop.max_walks;
}
