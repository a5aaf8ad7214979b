/* Walks that migrate between ranks that each hold a range of rows (see ulam_dist.h).
 *
 * Histories run in batches of o->batch walk ids.  A round advances every particle a rank holds
 * until it ends or steps onto another rank's row; the particles that left travel in one exchange
 * (batched per destination), and the batch ends when a round sends none anywhere (the sum of the
 * counts sent: no rank polls another).  A step's random numbers come from (seed, walk, step), so
 * the path does not depend on who runs it.  Adjoint scores travel with their walk and reach rank
 * 0 at the walk's end; forward tallies stay where they happen (the row's owner) and are summed,
 * per state, in (walk, step) order: both are combined in walk-id order whatever the ranks. */
#include "part.h"
#include "defaults.h"
#include "stop.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A walk in flight: its id, steps taken, row, weight and (adjoint) score so far. */
typedef struct {
    int64_t w, t, s;
    double wt, score;
} particle;

/* A forward tally: walk w at step t added v at row s. */
typedef struct {
    int64_t s, w, t;
    double v;
} tally;

/* A finished adjoint history: its id and score. */
typedef struct {
    int64_t w;
    double score;
} ended;

/* A growable array of items of size sz. */
typedef struct {
    void *a;
    int64_t len, cap;
} vec;

/* The state of one run on this rank. */
typedef struct {
    const ulam_part *p;
    const ulam_comm *c;
    ulam_dist_opts o;
    vec *out;           /* per destination rank: particles leaving */
    vec here;           /* particles to advance this round */
    vec ends, tallies;  /* finished adjoint histories; forward tallies of this batch */
    const double *b;    /* forward: the sources' b at this rank's rows */
    int64_t steps, crossings, bytes, rounds, cut;
    int many;           /* a batch of two or more queries: query k walks on seed ulam_rng_substream(seed, QUERY, k) */
    int terminal;       /* forward: each walk also tallies where it ends, at row -1 - s (an end count, settle) */
    double *ends_at;    /* terminal: the walks that ended at each of this rank's rows (exact integers) */
} run;

/* The defaults. */
ulam_dist_opts ulam__dist_defaults(void)
{
    return (ulam_dist_opts){.seed = 1, .walks = 100000, .max_steps = 1000000, .batch = 65536};
}

/* Append one item (sz bytes at x) to v; ULAM_OK or ULAM_ENOMEM. */
static int push(vec *v, const void *x, size_t sz)
{
    if (v->len == v->cap && ulam__grow(&v->a, &v->cap, v->len + 1, sz)) return ULAM_ENOMEM;
    memcpy((char *)v->a + (size_t)v->len++ * sz, x, sz);
    return ULAM_OK;
}

/* Move x one step from its row (owned here): 0 when the walk ends, 1 with x at its new row (walk
 * id k o->walks + w is walk w of query k; in a batch of two or more queries query k is keyed by
 * its QUERY substream, a lone query by seed: docs/streams.md).  It
 * leaves with probability min(1, S) (S the row's sum of |entries|) to entry q with probability
 * |val_q| / S, the weight times sign(val_q) S / min(1, S). */
static int move(const ulam_part *p, const ulam__rows *A, const ulam_dist_opts *o, int many, particle *x)
{
    int64_t i = x->s - p->first, t = x->t + 1;
    uint64_t k = (uint64_t)(x->w / o->walks), w = (uint64_t)(x->w % o->walks);
    uint64_t seed = many ? ulam_rng_substream(o->seed, ULAM_STREAM_QUERY, k) : o->seed;
    double S = A->rowsum[i], c = S < 1.0 ? S : 1.0;
    if (S == 0.0 || ulam__rng_counter(seed, w, (uint64_t)t, 0) >= c) return 0;
    double u = ulam__rng_counter(seed, w, (uint64_t)t, 1) * S, acc = 0.0;
    int64_t q = A->rowptr[i], e = A->rowptr[i + 1] - 1;
    for (; q < e; q++) {
        acc += fabs(A->val[q]);
        if (u < acc) break;
    }
    x->wt *= (A->val[q] < 0 ? -S : S) / c;
    x->s = A->col[q], x->t = t;
    return 1;
}

/* Advance x from its arrival at a row of this rank until it ends or leaves (forward: tallying its
 * weight at every row it is at; adjoint: adding weight x b there to its score). */
static int advance(run *R, particle x, int forward)
{
    const ulam_part *p = R->p;
    for (;;) {
        if (forward) {
            tally e = {x.s, x.w, x.t, x.wt};
            if (push(&R->tallies, &e, sizeof e)) return ULAM_ENOMEM;
        } else {
            x.score += x.wt * p->b[x.s - p->first];
        }
        if (!move(p, forward ? &p->t : &p->m, &R->o, R->many, &x)) {
            tally e = {-1 - x.s, x.w, x.t, 1.0}; /* ended here (with probability 1 - min(1, S) at each visit) */
            if (forward && R->terminal && push(&R->tallies, &e, sizeof e)) return ULAM_ENOMEM;
            break;
        }
        if (x.t > R->o.max_steps && ++R->cut) break;
        R->steps++;
        int own = p->nranks > 1 ? ulam__part_owner(p, x.s) : 0;
        if (own != p->rank) { /* to the rank of this set that owns the row */
            R->crossings++;
            return push(&R->out[p->set * p->nranks + own], &x, sizeof x);
        }
    }
    if (forward) return ULAM_OK;
    ended e = {x.w, x.score};
    return push(&R->ends, &e, sizeof e);
}

/* Send each outbox vec[r] (items of sz bytes) to rank r; the items received, in rank order,
 * replace *in.  *sent: the items this rank sent. */
static int exchange(run *R, vec *box, size_t sz, vec *in, int64_t *sent, ulam_error *err)
{
    int k = R->c->nranks;
    size_t *counts = calloc((size_t)k * 2, sizeof *counts), total = 0;
    if (!counts) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an exchange");
    for (int r = 0; r < k; r++) counts[r] = (size_t)box[r].len * sz, total += counts[r];
    char *send = calloc(total ? total : 1, 1);
    if (!send) {
        free(counts);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an exchange");
    }
    size_t at = 0;
    for (int r = 0; r < k; r++) memcpy(send + at, box[r].a ? box[r].a : send, counts[r]), at += counts[r], box[r].len = 0;
    void *recv = NULL;
    int bad = R->c->exchange(R->c->ctx, send, counts, &recv, counts + k);
    free(send);
    size_t got = 0;
    for (int r = 0; !bad && r < k; r++) got += counts[k + r];
    free(counts);
    if (bad || got % sz) {
        free(recv);
        return ulam__fail(err, ULAM_EIO, 0, -1, "an exchange between ranks that succeeds");
    }
    free(in->a);
    in->a = recv, in->len = in->cap = (int64_t)(got / sz);
    *sent = (int64_t)(total / sz);
    R->bytes += (int64_t)total;
    return ULAM_OK;
}

/* Run the particles in R->here to their ends, round by round, until no rank sends any. */
static int rounds(run *R, int forward, ulam_error *err)
{
    for (;;) {
        const particle *x = R->here.a;
        for (int64_t q = 0; q < R->here.len; q++)
            if (advance(R, x[q], forward)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for walks in flight");
        R->here.len = 0;
        if (R->c->nranks == 1) return ULAM_OK;
        int64_t sent = 0;
        int status = exchange(R, R->out, sizeof(particle), &R->here, &sent, err);
        if (status) return status;
        R->rounds++;
        if (R->c->sum(R->c->ctx, &sent, 1)) return ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
        if (sent == 0) return ULAM_OK;
    }
}

/* Order of finished histories: by walk id. */
static int by_walk(const void *a, const void *b)
{
    int64_t x = ((const ended *)a)->w, y = ((const ended *)b)->w;
    return (x > y) - (x < y);
}

/* Order of tallies: by row, then walk, then step. */
static int by_row_walk(const void *a, const void *b)
{
    const tally *x = a, *y = b;
    if (x->s != y->s) return (x->s > y->s) - (x->s < y->s);
    if (x->w != y->w) return (x->w > y->w) - (x->w < y->w);
    return (x->t > y->t) - (x->t < y->t);
}

/* Set up R for a run on p. */
static int start(run *R, const ulam_part *p, const ulam_comm *c, const ulam_dist_opts *o, int forward, ulam_error *err)
{
    if (!(forward ? p->t.rowptr : p->m.rowptr))
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part holding the rows of %s", forward ? "M' (forward walks)" : "M (adjoint walks)");
    *R = (run){.p = p, .c = c, .o = o ? *o : ulam_dist_defaults()};
    if (R->o.walks < 1 || R->o.max_steps < 1 || R->o.batch < 1)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "walks, max_steps and batch of at least 1");
    if (c->nranks != p->nranks * p->sets || c->rank != p->set * p->nranks + p->rank || (c->sets > 1 ? c->sets : 1) != p->sets)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "the comm the part was opened with");
    R->out = calloc((size_t)c->nranks, sizeof *R->out);
    return R->out ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for outboxes");
}

/* Free R's arrays. */
static void finish(run *R)
{
    for (int r = 0; R->out && r < R->c->nranks; r++) free(R->out[r].a);
    free(R->out), free(R->here.a), free(R->ends.a), free(R->tallies.a);
}

/* The run's counts summed over ranks into res (the same on every rank). */
static int counts(run *R, ulam_dist_result *res, ulam_error *err)
{
    int64_t v[3] = {R->steps, R->crossings, R->bytes};
    if (R->c->nranks > 1 && R->c->sum(R->c->ctx, v, 3))
        return ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    res->walks = R->o.walks, res->steps = v[0], res->crossings = v[1], res->bytes = v[2], res->rounds = R->rounds;
    return ULAM_OK;
}

/* The certified interval of adjoint runs (rank 0's): the tail certificate, each query's
 * confidence sequence over its clipped scores (stop.h), which queries met rel_err. */
typedef struct {
    ulam__dist_cert cert;
    ulam__cs *cs;
    char *done;
    double E; /* rel_err (0: none) */
} seq;

/* Query k's bound on E X^2 of one score when the weights grow (cert.second): each step's
 * E (w_t b_s)^2 <= bmax^2 c u^t, so by Minkowski sqrt(E X^2) <= bmax sqrt(c) / (1 - sqrt u),
 * rounded up; or the bound aimed at the query's start (cert.v2, adjoint), the smaller. */
static double second_moment(const seq *S, int64_t k)
{
    double r = 1.0 - sqrt(S->cert.u), v2 = S->cert.bmax * S->cert.bmax * S->cert.c[k] / (r * r) * (1.0 + 1e-9);
    return S->cert.v2 ? fmin(v2, S->cert.v2[k]) : v2;
}

/* The clip of the next block of query k (mk: its n, mean and M2 so far): *A the limit of |score|,
 * *b the most clipping at A moves the mean (stop.h), *h the target half-width, *nplan the walks
 * planned.  A walk of T steps scores at most bmax (T + 1), so past A = bmax K only walks of K
 * steps or more, and E (|X| - A)_+ <= bmax sum_{j >= K} P(T >= j) <= bmax c u^K / (1 - u); K the
 * least with that at most t, t as the single-machine plan takes it (src/solve.c plan_terms): an
 * eighth of the target half-width, at most a hundredth of |x| (or of its bound bmax c / (1 - u)).
 * With growing weights (cert.second) the second moment bounds the clipping instead, and t is
 * raised to where the clipping's bias and the range it leaves balance. */
static void clip_plan(const seq *S, int64_t k, const double *mk, int64_t walks, double *A, double *b, double *h,
                      double *nplan)
{
    double u = S->cert.u, c = S->cert.c[k], bm = S->cert.bmax, N = mk[0], var = N > 1 ? mk[2] / (N - 1.0) : 0.0;
    double v2 = second_moment(S, k), xb = S->cert.second ? sqrt(v2) : bm * c / (1.0 - u);
    double mabs = fabs(mk[1]), m = N > 0 && mabs > 0 ? fmin(mabs, xb) : xb;
    if (S->cert.second && N < 2) var = v2; /* no walks yet: the certified second moment plans the first block */
    *nplan = S->E > 0 ? fmax(4.0 * N, 4096.0) : (double)walks;
    *h = S->E > 0 && mabs > 0 ? S->E * mabs : 0.0;
    double hp = *h > 0 ? *h : 2.7 * sqrt(var / *nplan), t = fmin(fmax(ULAM__STOP_TAIL, S->E / 4.0) * m, fmax(hp / 8.0, 1e-6 * m));
    if (S->cert.second) { /* (|X| - A)_+ <= X^2 / (4 A): past A = v2 / (4 t) clipping moves the mean at most t */
        /* the range then adds about R / t (R: the range term of limit v2 / 4), so t + R / t is least
           at t = sqrt R: taken when larger (at a --rel-err target, at most a quarter of it) */
        double tb = sqrt(ulam__cs_range_width(v2 / 4.0, *nplan));
        t = fmax(t, S->E > 0 ? fmin(tb, S->E / 4.0 * m) : tb);
        *A = v2 / (4.0 * t), *b = t * (1.0 + 1e-9);
        return;
    }
    double K = u > 0 ? ceil(log(t * (1.0 - u) / (bm * c)) / log(u)) : 1.0;
    K = K >= 1.0 ? fmin(K, 1e15) : 1.0;
    *A = bm * K, *b = bm * c * pow(u, K) / (1.0 - u) * (1.0 + 1e-9);
}

/* The bias of walks cut at max_steps in query k: bmax c u^max_steps / (1 - u) (growing weights:
 * the steps' root second moments past max_steps, bmax sqrt(c) u^((max_steps + 1) / 2) / (1 - sqrt u)). */
static double cut_bias(const seq *S, int64_t k, int64_t max_steps)
{
    if (S->cert.second)
        return S->cert.bmax * sqrt(S->cert.c[k]) * pow(S->cert.u, 0.5 * (double)(max_steps + 1)) / (1.0 - sqrt(S->cert.u)) *
               (1.0 + 1e-9);
    return S->cert.bmax * S->cert.c[k] * pow(S->cert.u, (double)max_steps) / (1.0 - S->cert.u) * (1.0 + 1e-9);
}

/* Whether S certifies intervals (a length tail, or b = 0). */
static int seq_on(const seq *S)
{
    return S && (S->cert.u < 1.0 || S->cert.bmax == 0.0);
}

/* Query k's interval so far (mk: n, mean, M2) into ci[0 .. 5): lo, hi, limit, bias, met. */
static void seq_interval(const seq *S, int64_t k, const double *mk, int64_t max_steps, double *ci)
{
    ci[0] = ci[1] = NAN, ci[2] = ci[3] = INFINITY, ci[4] = 0.0;
    if (S->cert.bmax == 0.0) { /* nothing scores: x = 0, exactly */
        ci[0] = ci[1] = ci[2] = ci[3] = 0.0, ci[4] = 1.0;
        return;
    }
    if (!(S->cert.u < 1.0)) return;
    ulam__stop_ci c;
    ulam__cs_interval(&S->cs[k], mk[1], cut_bias(S, k, max_steps), &c);
    if (c.kind != ULAM__STOP_EB) return;
    ci[0] = c.lo, ci[1] = c.hi, ci[2] = S->cs[k].limit, ci[3] = c.bias;
    ci[4] = S->E > 0 && c.half <= S->E * fabs(mk[1]);
}

/* Add one block of query k's histories e[0 .. nb) (walk-id order) to its sequence, clipped at
 * the limit planned from the blocks before it. */
static void seq_block(seq *S, int64_t k, const double *mk, const ended *e, int64_t nb, const ulam_dist_opts *o)
{
    if (!(S->cert.u < 1.0)) return;
    double A, b, h, nplan, N = mk[0];
    clip_plan(S, k, mk, o->walks, &A, &b, &h, &nplan);
    ulam__cs_plan(&S->cs[k], (int64_t)N, mk[1], N > 1 ? mk[2] / (N - 1.0) : 0.0, A, b, h > b ? h - b : 0.0, nplan);
    double n = 0.0, mean = 0.0, m2 = 0.0, top = 0.0;
    for (int64_t q = 0; q < nb; q++) {
        double x = fmax(-A, fmin(A, e[q].score)), d = x - mean;
        n += 1.0, mean += d / n, m2 += d * (x - mean), top = fmax(top, fabs(x));
    }
    ulam__cs_add(&S->cs[k], nb, mean, m2, top);
}

/* Rank 0's histories of one batch, sorted by walk id, into the running moments m[3 k ..] (n,
 * mean, M2) of their query k, block by block of o.batch walk ids (and with S, into the query's
 * sequence: a query that met its target takes no more); the other ranks send theirs to rank 0. */
static int gather_ends(run *R, double *mm, seq *S, ulam_error *err)
{
    if (R->c->nranks > 1) {
        vec *box = calloc((size_t)R->c->nranks, sizeof *box);
        if (!box) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an exchange");
        box[0] = R->ends, R->ends = (vec){0};
        int64_t sent, before = R->bytes;
        int status = exchange(R, box, sizeof(ended), &R->ends, &sent, err);
        R->bytes = before; /* results, not walks */
        free(box[0].a), free(box);
        if (status) return status;
    }
    ended *e = R->ends.a;
    if (R->ends.len) qsort(e, (size_t)R->ends.len, sizeof *e, by_walk);
    for (int64_t q = 0, q1; q < R->ends.len; q = q1) {
        int64_t k = e[q].w / R->o.walks, blk = e[q].w / R->o.batch;
        for (q1 = q; q1 < R->ends.len && e[q1].w / R->o.walks == k && e[q1].w / R->o.batch == blk; q1++) {
        }
        double *m = mm + 3 * k;
        if (S && S->done[k]) continue;
        if (S) seq_block(S, k, m, e + q, q1 - q, &R->o);
        for (int64_t i = q; i < q1; i++) { /* Welford's update, in walk-id order */
            double d = e[i].score - m[1];
            m[0] += 1.0, m[1] += d / m[0], m[2] += d * (e[i].score - m[1]);
        }
        double ci[5];
        if (S && S->E > 0 && seq_on(S)) seq_interval(S, k, m, R->o.max_steps, ci), S->done[k] = ci[4] > 0;
    }
    R->ends.len = 0;
    return ULAM_OK;
}

/* Rank 0's doubles v[0 .. k) to every rank (as an exchange). */
static int broadcast(run *R, double *v, int k, ulam_error *err)
{
    if (R->c->nranks == 1) return ULAM_OK;
    vec *box = calloc((size_t)R->c->nranks, sizeof *box), got = {0};
    int status = box ? ULAM_OK : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an exchange");
    for (int r = 0; !status && R->c->rank == 0 && r < R->c->nranks; r++)
        for (int q = 0; !status && q < k; q++)
            if (push(&box[r], &v[q], sizeof *v)) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an exchange");
    int64_t sent, before = R->bytes;
    if (!status) status = exchange(R, box, sizeof *v, &got, &sent, err);
    R->bytes = before; /* results, not walks */
    if (!status && got.len != k) status = ulam__fail(err, ULAM_EIO, 0, -1, "rank 0's result");
    if (!status) memcpy(v, got.a, (size_t)k * sizeof *v);
    for (int r = 0; box && r < R->c->nranks; r++) free(box[r].a);
    free(box), free(got.a);
    return status;
}

/* The walks of the batch from walk id a (up to o.batch; none past the last walk). */
static int64_t my_batch(const run *R, int64_t a)
{
    return a >= R->o.walks ? 0 : R->o.walks - a < R->o.batch ? R->o.walks - a : R->o.batch;
}

/* Whether every query of the batch of walk ids [a, a + B) is done. */
static int all_done(const seq *S, int64_t a, int64_t B, int64_t walks)
{
    for (int64_t k = a / walks; S && S->done && k <= (a + B - 1) / walks; k++)
        if (!S->done[k]) return 0;
    return S && S->done;
}

/* x_index[k] for k < nq by adjoint walks on the partitioned rows; with ci (5 nq doubles), each
 * query's certified interval (ulam_dist_adjoint_ci), and with rel_err > 0 the run ends once
 * every query met it. */
static int adjoint(const ulam_part *p, const ulam_comm *comm, const int64_t *index, int64_t nq, const ulam_dist_opts *o,
                   double rel_err, ulam_dist_result *res, double *ci, ulam_error *err)
{
    ulam__clear(err);
    if (!p || !comm || !res || !index || nq < 1) return ulam__fail(err, ULAM_EINVAL, 0, -1, "parts, indices and results");
    if (!p->b) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a b in the prepared file (ulam prepare M.mtx --rhs b.mtx)");
    if (!(rel_err >= 0) || !isfinite(rel_err)) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a relative error >= 0, got %g", rel_err);
    for (int64_t k = 0; k < nq; k++) {
        res[k] = (ulam_dist_result){0};
        if (index[k] < 0 || index[k] >= p->n)
            return ulam__fail(err, ULAM_EINVAL, 0, index[k], "an index in 1 .. %lld", (long long)p->n);
    }
    run R;
    int status = start(&R, p, comm, o, 0, err);
    R.many = nq > 1;
    if (!status && R.o.walks > INT64_MAX / nq) status = ulam__fail(err, ULAM_EINVAL, 0, -1, "walks times queries below 2^63");
    int64_t total = status ? 0 : R.o.walks * nq;
    double *m = calloc((size_t)nq * 9, sizeof *m); /* n, mean, M2 of each query (rank 0); then stderr; then ci */
    if (!status && !m) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld queries", (long long)nq);
    seq S0 = {.E = rel_err}, *S = ci ? &S0 : NULL;
    if (!status && S) status = ulam__dist_tail(p, comm, 200, index, nq, -1.0, &S->cert, err);
    if (!status && S && (!(S->cs = calloc((size_t)nq, sizeof *S->cs)) || !(S->done = calloc((size_t)nq, 1))))
        status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld queries", (long long)nq);
    int stops = S && rel_err > 0 && seq_on(S); /* the run may end early: rank 0 says which queries are done */
    int64_t nblocks = status ? 0 : (total + R.o.batch - 1) / R.o.batch;
    for (int64_t j = 0; !status && j < nblocks;) { /* a batch a set: the next blocks of walk ids with a query not done */
        int64_t a = -1;
        for (int s = 0; j < nblocks && s < p->sets; j++) {
            int64_t aj = j * R.o.batch;
            if (all_done(S, aj, total - aj < R.o.batch ? total - aj : R.o.batch, R.o.walks)) continue;
            if (s++ == p->set) a = aj;
        }
        int64_t B = a < 0 ? 0 : total - a < R.o.batch ? total - a : R.o.batch;
        for (int64_t g = a; !status && g < a + B; g++) {
            int64_t i = index[g / R.o.walks];
            particle x = {g, 0, i, 1.0, 0.0};
            if (ulam__part_owner(p, i) == p->rank && push(&R.here, &x, sizeof x))
                status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for walks");
        }
        if (!status) status = rounds(&R, 0, err);
        if (!status) status = gather_ends(&R, m, S, err);
        for (int64_t k = 0; !status && stops && k < nq; k++) m[4 * nq + k] = S->done[k];
        if (!status && stops) status = broadcast(&R, m + 4 * nq, (int)nq, err);
        for (int64_t k = 0; !status && stops && k < nq; k++) S->done[k] = m[4 * nq + k] > 0;
    }
    int64_t cut = R.cut;
    if (!status && R.c->nranks > 1 && R.c->sum(R.c->ctx, &cut, 1))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    for (int64_t k = 0; !status && R.c->rank == 0 && k < nq; k++) { /* estimate, stderr; n checked below */
        double *q = m + 3 * k;
        m[3 * nq + k] = q[0] > 1 ? sqrt(q[2] / (q[0] - 1.0) / q[0]) : NAN;
        if (S) seq_interval(S, k, q, R.o.max_steps, m + 4 * nq + 5 * k);
        if (q[0] != (double)R.o.walks && !(stops && S->done[k] && q[0] >= 1))
            status = ulam__fail(err, ULAM_EIO, 0, -1, "every history back at rank 0");
    }
    if (!status) status = broadcast(&R, m, (int)(nq * (S ? 9 : 4)), err);
    ulam_dist_result c = {0};
    if (!status) status = counts(&R, &c, err);
    for (int64_t k = 0; !status && k < nq; k++) {
        res[k] = c, res[k].estimate = m[3 * k + 1], res[k].std_error = m[3 * nq + k], res[k].cut = cut;
        res[k].walks = (int64_t)m[3 * k];
        if (ci) memcpy(ci + 5 * k, m + 4 * nq + 5 * k, 5 * sizeof *ci);
    }
    free(m);
    if (S) free(S->cert.c), free(S->cert.v2), free(S->cs), free(S->done);
    finish(&R);
    return status;
}

/* As ulam_dist_adjoint_many with each query's certified 95% interval. */
int ulam_dist_adjoint_ci(const ulam_part *p, const ulam_comm *comm, const int64_t *index, int64_t nq,
                         const ulam_dist_opts *o, double rel_err, ulam_dist_result *res, ulam_dist_ci *ci, ulam_error *err)
{
    if (!ci) /* no interval: the walks alone (ulam_dist_adjoint_many) */
        return rel_err == 0 ? adjoint(p, comm, index, nq, o, 0.0, res, NULL, err)
                            : ulam__fail(err, ULAM_EINVAL, 0, -1, "intervals with a relative error target");
    double *v = nq > 0 ? calloc((size_t)nq * 5, sizeof *v) : NULL;
    if (nq < 1) return ulam__fail(err, ULAM_EINVAL, 0, -1, "at least one query");
    if (!v) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld intervals", (long long)nq);
    int status = adjoint(p, comm, index, nq, o, rel_err, res, v, err);
    for (int64_t k = 0; k < nq; k++)
        ci[k] = status ? (ulam_dist_ci){NAN, NAN, INFINITY, INFINITY, 0}
                       : (ulam_dist_ci){v[5 * k], v[5 * k + 1], v[5 * k + 2], v[5 * k + 3], v[5 * k + 4] > 0};
    free(v);
    return status;
}

/* The blocks' sums of |b| (blocks of 2^shift rows, the same whatever the split) in every rank's
 * hands, and their running sums P[0 .. nb] in block order. */
static int block_prefix(run *R, double **P, int64_t *nb, ulam_error *err)
{
    const ulam_part *p = R->p;
    *nb = (p->n + ((int64_t)1 << p->shift) - 1) >> p->shift;
    int64_t *bits = calloc((size_t)*nb + 1, sizeof *bits);
    *P = malloc(((size_t)*nb + 1) * sizeof **P);
    if (!bits || !*P) {
        free(bits);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld block sums", (long long)*nb);
    }
    for (int64_t k = p->first >> p->shift; p->set == 0 && p->first < p->last && (k << p->shift) < p->last; k++) { /* one set's; none on a rank without rows */
        double s = 0.0;
        int64_t r1 = (k + 1) << p->shift < p->last ? (k + 1) << p->shift : p->last;
        for (int64_t i = k << p->shift; i < r1; i++) s += fabs(R->b[i - p->first]);
        memcpy(&bits[k], &s, 8);
    }
    if (R->c->nranks > 1 && R->c->sum(R->c->ctx, bits, (int)*nb)) { /* one owner a block: the sum is exact */
        free(bits);
        return ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    }
    (*P)[0] = 0.0;
    for (int64_t k = 0; k < *nb; k++) {
        double s;
        memcpy(&s, &bits[k], 8);
        (*P)[k + 1] = (*P)[k] + s;
    }
    free(bits);
    return ULAM_OK;
}

/* Start this rank's forward walks of ids [w0, w0 + B): each draws its block by P, then its row in
 * the block by |b|. */
static int forward_starts(run *R, const double *P, int64_t nb, int64_t w0, int64_t B, ulam_error *err)
{
    const ulam_part *p = R->p;
    double total = P[nb];
    for (int64_t w = w0; w < w0 + B; w++) {
        double u = ulam__rng_counter(R->o.seed, (uint64_t)w, 0, 2) * total;
        int64_t lo = 0, hi = nb - 1; /* the last block k with P[k] <= u and a positive sum */
        while (lo < hi) {
            int64_t mid = (lo + hi + 1) / 2;
            if (P[mid] <= u) lo = mid;
            else hi = mid - 1;
        }
        while (lo > 0 && P[lo + 1] == P[lo]) lo--;
        int64_t r0 = lo << p->shift;
        if (r0 < p->first || r0 >= p->last) continue;
        int64_t r1 = (lo + 1) << p->shift < p->last ? (lo + 1) << p->shift : p->last, s = -1;
        double acc = P[lo];
        for (int64_t i = r0; i < r1; i++) {
            double a = fabs(R->b[i - p->first]);
            if (a == 0.0) continue;
            s = i, acc += a;
            if (u < acc) break;
        }
        if (s < 0) continue; /* no b in the block: P would not have chosen it */
        particle x = {w, 0, s, R->b[s - p->first] < 0 ? -total : total, 0.0};
        if (push(&R->here, &x, sizeof x)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for walks");
    }
    return ULAM_OK;
}

/* Each history's total at each row of the batch's tallies, in (row, walk) order, in place. */
static void totals(run *R)
{
    tally *t = R->tallies.a;
    if (R->tallies.len) qsort(t, (size_t)R->tallies.len, sizeof *t, by_row_walk);
    int64_t m = 0;
    for (int64_t q = 0; q < R->tallies.len;) {
        tally e = {t[q].s, t[q].w, 0, 0.0};
        for (; q < R->tallies.len && t[q].s == e.s && t[q].w == e.w; q++) e.v += t[q].v; /* in step order */
        t[m++] = e;
    }
    R->tallies.len = m;
}

/* Add the batches' tallies to the per-row sums of set 0's ranks, each history's total at a row
 * once, in (row, walk) order: with sets, each rank's totals go to the rank of set 0 that holds
 * the same rows. */
static int settle(run *R, double *sum, double *sumsq, int64_t watch, int64_t w0, int64_t w1, ulam_error *err)
{
    const ulam_part *p = R->p;
    totals(R);
    if (p->sets > 1) {
        vec *box = calloc((size_t)R->c->nranks, sizeof *box);
        if (!box) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an exchange");
        box[p->rank] = R->tallies, R->tallies = (vec){0};
        int64_t sent, before = R->bytes;
        int status = exchange(R, box, sizeof(tally), &R->tallies, &sent, err);
        R->bytes = before; /* results, not walks */
        free(box[p->rank].a), free(box);
        if (status) return status;
        tally *t = R->tallies.a;
        if (R->tallies.len) qsort(t, (size_t)R->tallies.len, sizeof *t, by_row_walk); /* walks differ across sets */
    }
    const tally *t = R->tallies.a;
    int64_t at = -1; /* the watched row's first total (its walks in order) */
    for (int64_t q = 0; p->set == 0 && q < R->tallies.len; q++) {
        if (t[q].s < 0) { /* an end count (terminal: ends sorted first, rows -1 - s) */
            R->ends_at[-1 - t[q].s - p->first] += t[q].v;
            continue;
        }
        sum[t[q].s - p->first] += t[q].v;
        sumsq[t[q].s - p->first] += t[q].v * t[q].v;
        if (t[q].s == watch && at < 0) at = q;
    }
    if (watch >= p->first && watch < p->last && p->set == 0) /* every history of walk ids [w0, w1), 0 where none tallied */
        for (int64_t w = w0, q = at; w < w1; w++) {
            ended e = {w, 0.0};
            if (q >= 0 && q < R->tallies.len && t[q].s == watch && t[q].w == w) e.score = t[q++].v;
            if (push(&R->ends, &e, sizeof e)) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the watched row's histories");
        }
    R->tallies.len = 0;
    return ULAM_OK;
}

/* Every x_i by forward walks on the partitioned rows of M'. */
int ulam_dist_forward(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, double *x, double *se,
                      ulam_dist_result *res, ulam_error *err)
{
    return ulam__dist_forward_ci(p, comm, o, -1, x, se, res, NULL, err);
}

/* Forward walks from b (this rank's rows of it); with S, component watch's histories into S and
 * its moments m (n, mean, M2) at rank 0. */
static int forward(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, const double *b, int64_t watch,
                   seq *S, double *m, double *x, double *se, double *hits, double *mass, ulam_dist_result *res,
                   ulam_error *err)
{
    ulam__clear(err);
    if (p && comm && res && !b) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a b in the prepared file (ulam prepare M.mtx --rhs b.mtx)");
    if (!p || !comm || !res) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a part, a comm, b and a result");
    *res = (ulam_dist_result){0};
    for (int64_t i = 0; i < p->last - p->first; i++)
        if (!isfinite(b[i])) return ulam__fail(err, ULAM_EINVAL, 0, p->first + i, "a finite b");
    run R;
    int status = start(&R, p, comm, o, 1, err);
    R.b = b, R.terminal = hits != NULL, R.ends_at = hits;
    if (hits) memset(hits, 0, (size_t)(p->last - p->first) * sizeof *hits);
    int64_t rows = p->last - p->first, nb = 0;
    double *sum = calloc((size_t)rows + 1, sizeof *sum), *sumsq = calloc((size_t)rows + 1, sizeof *sumsq), *P = NULL;
    if (!status && (!sum || !sumsq)) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for %lld sums", (long long)rows);
    if (!status) status = block_prefix(&R, &P, &nb, err);
    if (!status && S) status = ulam__dist_tail(p, comm, 200, &watch, 1, P[nb], &S->cert, err);
    for (int64_t w0 = 0; !status && P[nb] > 0 && w0 < R.o.walks; w0 += R.o.batch * p->sets) { /* a batch a set */
        int64_t a = w0 + p->set * R.o.batch, w1 = w0 + R.o.batch * p->sets;
        status = forward_starts(&R, P, nb, a, my_batch(&R, a), err);
        if (!status) status = rounds(&R, 1, err);
        if (!status) status = settle(&R, sum, sumsq, S ? watch : -1, w0, w1 < R.o.walks ? w1 : R.o.walks, err);
        if (!status && S) status = gather_ends(&R, m, S, err);
    }
    int64_t cut = R.cut;
    if (!status && R.c->nranks > 1 && R.c->sum(R.c->ctx, &cut, 1))
        status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
    if (!status) status = counts(&R, res, err);
    double N = (double)R.o.walks, zero_b = P && P[nb] == 0;
    for (int64_t i = 0; !status && p->set == 0 && i < rows; i++) {
        double mean = sum[i] / N, var = (sumsq[i] - sum[i] * mean) / (N - 1.0);
        if (x) x[i] = mean;
        if (se) se[i] = zero_b ? 0.0 : sumsq[i] == 0.0 ? NAN : N > 1 ? sqrt(fmax(var, 0.0) / N) : NAN;
    }
    if (mass) *mass = P ? P[nb] : 0.0;
    if (!status && S && zero_b) m[0] = N; /* b = 0: x = 0, every history 0 */
    res->cut = cut;
    free(sum), free(sumsq), free(P);
    finish(&R);
    return status;
}

/* As ulam_dist_forward with the sources' b given at this rank's rows. */
int ulam__dist_forward_b(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, const double *b, double *x,
                        double *se, ulam_dist_result *res, ulam_error *err)
{
    return forward(p, comm, o, b, -1, NULL, NULL, x, se, NULL, NULL, res, err);
}

/* Forward walks from b scoring where they end (part.h). */
int ulam__dist_forward_ends(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, const double *b,
                            double *x, double *se, double *hits, double *mass, ulam_dist_result *res, ulam_error *err)
{
    if (!hits || !mass) return ulam__fail(err, ULAM_EINVAL, 0, -1, "room for the hit counts and the mass");
    return forward(p, comm, o, b, -1, NULL, NULL, x, se, hits, mass, res, err);
}

/* Forward walks with component watch's certified interval (part.h). */
int ulam__dist_forward_ci(const ulam_part *p, const ulam_comm *comm, const ulam_dist_opts *o, int64_t watch, double *x,
                          double *se, ulam_dist_result *res, ulam_dist_ci *ci, ulam_error *err)
{
    if (!ci || watch < 0) return forward(p, comm, o, p ? p->b : NULL, -1, NULL, NULL, x, se, NULL, NULL, res, err);
    if (!p || watch >= p->n) return ulam__fail(err, ULAM_EINVAL, 0, watch, "a part and an index in 1 .. %lld", p ? (long long)p->n : 0LL);
    seq S0 = {.E = 0.0};
    double m[9] = {0}, mk[3] = {0};
    S0.cs = calloc(1, sizeof *S0.cs), S0.done = calloc(1, 1);
    int status = S0.cs && S0.done ? forward(p, comm, o, p->b, watch, &S0, mk, x, se, NULL, NULL, res, err)
                                  : ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for an interval");
    if (!status && comm->rank == 0) {
        m[0] = mk[1], m[1] = mk[0] > 1 ? sqrt(mk[2] / (mk[0] - 1.0) / mk[0]) : NAN;
        if (S0.cert.bmax == 0.0) m[1] = 0.0;
        seq_interval(&S0, 0, mk, o ? o->max_steps : ulam_dist_defaults().max_steps, m + 2);
        if (mk[0] != (double)res->walks) status = ulam__fail(err, ULAM_EIO, 0, -1, "every history back at rank 0");
    }
    if (!status && comm->nranks > 1) { /* rank 0's to all (a sum: the others add zeros) */
        int64_t bits[7] = {0};
        if (comm->rank == 0) memcpy(bits, m, sizeof bits);
        if (comm->sum(comm->ctx, bits, 7)) status = ulam__fail(err, ULAM_EIO, 0, -1, "a sum over ranks that succeeds");
        memcpy(m, bits, sizeof bits);
    }
    if (!status) {
        res->estimate = m[0], res->std_error = m[1];
        *ci = (ulam_dist_ci){m[2], m[3], m[4], m[5], m[6] > 0};
    }
    free(S0.cert.c), free(S0.cert.v2), free(S0.cs), free(S0.done);
    return status;
}
