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
 * position, so a step touches one row's memory and nothing else.
 *
 * The kernel exponent alpha generalises the move probabilities to p_ij = |K_ij|^alpha / T_i,
 * T_i = sum_k |K_ik|^alpha (0: uniform over the row's nonzeros, 2: Alea's transition factor);
 * the weight factor K_ij / (q_i p_ij) then differs from move to move, so each slot's two
 * outcomes get their own factor in a table beside the arena (fac, at the slot's unit), read
 * only at alpha != 1: at alpha = 1 the rows are built by exactly the code they always were.
 *
 * Rows are built lazily.  The first walk to reach state j builds its row from the borrowed K at
 * the next free place of an arena (so rows a run visits are packed densely, and the rest of
 * the reservation is never touched), its moves naming target states not yet placed.  The first
 * walk to take such a move looks the target's place up (building that row if need be) and
 * rewrites the outcome to name it, so later steps cost what they cost in a kernel built whole.
 * A query for one x_i visits a small part of a large system: it pays for, and keeps in memory,
 * only the rows its walks reach.
 *
 * K may be a prepared file mapped in place and not verified beyond its header, so every row
 * is checked as it is built (its rowptr range, columns, values and score finite): a corrupt
 * row, or a row that would overflow the arena, is replaced by the dead row at the arena's end
 * (which terminates at once and scores nothing) and recorded in k->status, which the solver
 * turns into a failed run.  The per-thread scratch grows to the longest row built, so nothing
 * reads all of K before the walks.
 *
 * With k->rc (a prepared file's verification, src/cache.c) every row's block is verified before
 * the row is first read, and all of K before the kernel is completed; a damaged block fails the
 * kernel as a corrupt row does.  Rows read from a file are dear (a system call each part), so
 * such a kernel keeps what rescoring a row for another estimator needs (ulam__rowrec) and reads a
 * row again only for the expected estimator's (K b)_i, when a walk first reaches it. */
#include "kernel.h"
#include "cache.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Free a kernel; accepts NULL. */
ulam_kernel *ulam__kernel_free(ulam_kernel *k)
{
    if (!k) return NULL;
    free(k->mem);
    free(k->fac);
    free(k->scored);
    free(k->rec);
    free((void *)k->where);
    free((void *)k->dir);
    free((void *)k->leaves);
    free(k);
    return NULL;
}

/* Keep a new kernel's places in leaves: the directory and the leaves' storage, zero and untouched. */
static int make_sparse(ulam_kernel *k)
{
    int64_t groups = k->n / ULAM__LEAF + 1;
    /* calloc: zero pages never touched, so a leaf costs memory once it is handed out */
    k->dir = ulam__calloc((size_t)groups, sizeof *k->dir);
    k->leaves = ulam__calloc((size_t)groups * ULAM__LEAF, sizeof *k->leaves);
    return k->dir && k->leaves ? ULAM_OK : ULAM_ENOMEM;
}

/* A leaf being made (the directory's mark while one thread takes it). */
#define LEAF_CLAIMED ((_Atomic int32_t *)(uintptr_t)1)

/* State j's place (0: no row, -1: being built, else its unit + 1), or NULL when its leaf is not
 * made and make is 0 (no row).  make: the leaf is made if need be (racing threads agree: the first
 * claims the group, the others wait for its leaf). */
static _Atomic int32_t *place(ulam_kernel *k, int64_t j, int make)
{
    if (k->where) return &k->where[j];
    _Atomic(_Atomic int32_t *) *d = &k->dir[j / ULAM__LEAF];
    _Atomic int32_t *leaf = atomic_load_explicit(d, memory_order_acquire), *none = NULL;
    if (leaf && leaf != LEAF_CLAIMED) return leaf + j % ULAM__LEAF;
    if (!make) return NULL;
    if (!leaf && atomic_compare_exchange_strong_explicit(d, &none, LEAF_CLAIMED, memory_order_acq_rel,
                                                         memory_order_acquire)) {
        leaf = k->leaves + atomic_fetch_add_explicit(&k->nleaves, 1, memory_order_relaxed) * ULAM__LEAF;
        atomic_store_explicit(d, leaf, memory_order_release);
        return leaf + j % ULAM__LEAF;
    }
    while ((leaf = atomic_load_explicit(d, memory_order_acquire)) == LEAF_CLAIMED) continue;
    return leaf + j % ULAM__LEAF;
}

/* State j's place value (0 when its leaf is not made). */
static int32_t place_of(ulam_kernel *k, int64_t j, memory_order mo)
{
    _Atomic int32_t *p = place(k, j, 0);
    return p ? atomic_load_explicit(p, mo) : 0;
}

/* The 64-bit threshold of an alias fraction f in [0, 1]. */
static uint64_t threshold(double f)
{
    return f >= 1.0 ? UINT64_MAX : f <= 0.0 ? 0 : (uint64_t)(f * 0x1.0p64);
}

/* Write slot s: take a below threshold t, else b. */
static void set_slot(ulam__slot *s, uint64_t t, int32_t a, int32_t b)
{
    s->thresh = t;
    atomic_store_explicit(&s->a, a, memory_order_relaxed);
    atomic_store_explicit(&s->b, b, memory_order_relaxed);
}

/* A row at h that terminates at once and scores nothing (state i). */
static void dead_row(ulam__row *h, int64_t i)
{
    *h = (ulam__row){.len = 1, .state = (int32_t)i};
    set_slot((ulam__slot *)(void *)h + ULAM__HEAD, UINT64_MAX, ULAM__TERMINATE, ULAM__TERMINATE);
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
        set_slot(&s[a], threshold(scaled[a]), out[a], out[g]);
        scaled[g] = (scaled[g] + scaled[a]) - 1.0;
        if (scaled[g] < 1.0) {
            nl--;
            small[ns++] = g;
        }
    }
    while (nl > 0) { /* leftovers are 1 up to rounding */
        int64_t g = large[--nl];
        set_slot(&s[g], UINT64_MAX, out[g], out[g]);
    }
    while (ns > 0) {
        int64_t a = small[--ns];
        set_slot(&s[a], UINT64_MAX, out[a], out[a]);
    }
}

/* The outcomes of row i: its moves and termination. */
static int64_t row_outcomes(const ulam_csr *K, int64_t i)
{
    return K->rowptr[i + 1] - K->rowptr[i] + 1;
}

/* The kernel of K: its size is reserved (not touched) and no row is built. */
int ulam__kernel_alloc(const ulam_csr *K, double continue_q, double alpha, ulam__scores scores, ulam_kernel **out)
{
    *out = NULL;
    int64_t n = K->nrows, nnz = K->rowptr[n];
    if (n >= ULAM__UNRESOLVED || nnz > ULAM__UNRESOLVED - (ULAM__HEAD + 1) * (n + 1)) return ULAM_EOVERFLOW;
    ulam_kernel *k = calloc(1, sizeof *k);
    if (!k) return ULAM_ENOMEM;
    k->n = n, k->cap = nnz + (ULAM__HEAD + 1) * n;
    k->K = K, k->continue_q = continue_q, k->alpha = alpha, k->scores = scores;
    atomic_init(&k->top, 0);
    atomic_init(&k->built, 0);
    atomic_init(&k->status, ULAM_OK);
    atomic_init(&k->bad, -1);
    atomic_init(&k->nleaves, 0);
    atomic_init(&k->nrec, 0);
    int dense = n <= ULAM__DENSE_MAX;
    if (dense) k->where = ulam__calloc((size_t)n, sizeof *k->where); /* zero: no row built */
    k->mem = ulam__alloc_big((size_t)(k->cap + ULAM__HEAD + 1), sizeof *k->mem);
    if (alpha != 1.0) k->fac = ulam__alloc_big((size_t)(k->cap + ULAM__HEAD + 1), sizeof *k->fac);
    if ((dense ? !k->where : make_sparse(k) != ULAM_OK) || !k->mem || (alpha != 1.0 && !k->fac)) {
        ulam__kernel_free(k);
        return ULAM_ENOMEM;
    }
    dead_row(ulam__kernel_row(k, k->cap), -1);
    *out = k;
    return ULAM_OK;
}

/* Give k its check (see kernel.h). */
int ulam__kernel_set_check(ulam_kernel *k, const ulam__rows_check *rc)
{
    k->rc = *rc;
    if (!rc->fetch || rc->fetch_of != k->K || k->rec) return ULAM_OK;
    /* reserved for every state, touched as rows are built: a query pays for the rows it builds */
    k->rec = ulam__malloc((size_t)k->n, sizeof *k->rec);
    return k->rec ? ULAM_OK : ULAM_ENOMEM;
}

/* Room in scratch w for rows of m outcomes (grown to at least twice what it had). */
static int kscratch_fit(ulam__kscratch *w, int64_t m)
{
    if (m <= w->cap) return ULAM_OK;
    int64_t c = w->cap;
    if (ulam__grow(&w->p, &c, m, sizeof *w->p)) return ULAM_ENOMEM;
    c = w->cap;
    if (ulam__grow(&w->scaled, &c, m, sizeof *w->scaled)) return ULAM_ENOMEM;
    c = w->cap;
    if (ulam__grow(&w->f, &c, m, sizeof *w->f)) return ULAM_ENOMEM;
    c = w->cap;
    if (ulam__grow(&w->o, &c, m, sizeof *w->o)) return ULAM_ENOMEM;
    c = w->cap;
    if (ulam__grow(&w->small, &c, m, sizeof *w->small)) return ULAM_ENOMEM;
    c = w->cap;
    if (ulam__grow(&w->large, &c, m, sizeof *w->large)) return ULAM_ENOMEM;
    w->cap = c;
    return ULAM_OK;
}

/* Scratch for building rows, sized for short ones (it grows when a longer row is built). */
int ulam__kscratch_alloc(const ulam_kernel *k, ulam__kscratch *w)
{
    (void)k;
    *w = (ulam__kscratch){0};
    return kscratch_fit(w, 64);
}

/* Free scratch. */
void ulam__kscratch_free(ulam__kscratch *w)
{
    free(w->p), free(w->scaled), free(w->f), free(w->o), free(w->small), free(w->large);
    ulam__rowbuf_free(&w->rb);
    *w = (ulam__kscratch){0};
}

/* The sum S_i of row i of |K|. */
static double row_sum(const ulam_csr *K, int64_t i)
{
    double S = 0.0;
    for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) S += fabs(K->val[q]);
    return S;
}

/* A row as the kernel reads it: its len columns and values, and b_i (1 without b). */
typedef struct {
    const int32_t *col;
    const double *val;
    int64_t len;
    double g;
} row_view;

/* The sum of |values| of a row (as row_sum, in the same order). */
static double view_sum(const row_view *v)
{
    double S = 0.0;
    for (int64_t q = 0; q < v->len; q++) S += fabs(v->val[q]);
    return S;
}

/* Nonzero when k reads K's rows from a file (pread) rather than in place. */
static int fetching(const ulam_kernel *k)
{
    return k->rc.fetch && k->rc.fetch_of == k->K;
}

/* Nonzero when row i's range in rowptr lies within K's entries (a prepared file is trusted no
 * further than its header). */
static int range_ok(const ulam_csr *K, int64_t i)
{
    int64_t a = K->rowptr[i], b = K->rowptr[i + 1];
    return a >= 0 && a <= b && b <= K->rowptr[K->nrows];
}

/* Row i of K into *v: read from the file into w's buffer (its block verified), or in place (its
 * block verified first unless inplace: all of K was); ULAM_OK or ULAM_ESYNTAX (a damaged block
 * or range). */
static int get_row(ulam_kernel *k, int64_t i, ulam__kscratch *w, int inplace, row_view *v)
{
    const double *b = k->scores.b;
    if (!inplace && fetching(k)) {
        int with_b = b && b == k->rc.b_of;
        if (k->rc.fetch(k->rc.ctx, i, with_b, &w->rb, NULL)) return ULAM_ESYNTAX;
        *v = (row_view){w->rb.col, w->rb.val, w->rb.len, with_b ? w->rb.b : b ? b[i] : 1.0};
        return ULAM_OK;
    }
    if ((!inplace && ulam__rows_verify(&k->rc, i, i + 1, NULL)) || !range_ok(k->K, i)) return ULAM_ESYNTAX;
    int64_t a = k->K->rowptr[i];
    *v = (row_view){k->K->colidx + a, k->K->val + a, k->K->rowptr[i + 1] - a, b ? b[i] : 1.0};
    return ULAM_OK;
}

/* b_j for the expected estimator's score: from the file when k reads rows there (r: the
 * thread's buffer, or NULL); NAN when its block is damaged (the row then fails). */
static double b_entry(const ulam_kernel *k, int64_t j, ulam__rowbuf *r)
{
    double v;
    if (fetching(k) && k->scores.b == k->rc.b_of) return k->rc.b_at(k->rc.ctx, j, r, &v, NULL) ? NAN : v;
    return k->scores.b[j];
}

/* The expected estimator's score (K b)_i of row v (r: as b_entry's). */
static double expected_score(const ulam_kernel *k, const row_view *v, ulam__rowbuf *r)
{
    double mb = 0.0;
    for (int64_t q = 0; q < v->len; q++) mb += v->val[q] * b_entry(k, v->col[q], r);
    return mb;
}

/* The continuation probability q_i of row i. */
double ulam__kernel_q(const ulam_csr *K, int64_t i, double continue_q)
{
    return ulam__continuation(row_sum(K, i), continue_q);
}

/* The moves of the len values val of a row (see ulam__kernel_moves). */
static int moves_of(const double *val, int64_t len, double q, double alpha, double *pm, double *f)
{
    double m = 0.0, T = 0.0;
    for (int64_t k = 0; k < len; k++) m = fmax(m, fabs(val[k]));
    for (int64_t k = 0; k < len; k++) T += pm[k] = val[k] != 0.0 ? pow(fabs(val[k]) / m, alpha) : 0.0;
    int status = ULAM_OK;
    for (int64_t k = 0; k < len; k++) {
        double v = fabs(val[k]);
        f[k] = v != 0.0 ? v * T / (q * pm[k]) : 0.0; /* |K_ij| / (q p_ij), with p_ij = pm T: no division by p */
        pm[k] /= T;
        if (v != 0.0 && !(pm[k] * (double)len >= 0x1p-40)) status = ULAM_ERANGE;
    }
    return status;
}

/* The moves of row i at kernel exponent alpha != 1 (see kernel.h). */
int ulam__kernel_moves(const ulam_csr *K, int64_t i, double q, double alpha, double *pm, double *f)
{
    int64_t a = K->rowptr[i];
    return moves_of(K->val + a, K->rowptr[i + 1] - a, q, alpha, pm, f);
}

/* Nonzero when k's estimator scores (K b)_i. */
static int scores_mb(const ulam_kernel *k)
{
    return k->scores.estimator == ULAM_EXPECTED && k->scores.b;
}

/* What a visit to and a termination at a row score from its g_i, p*_i and (K b)_i (read only
 * when scores_mb; see ulam__scores). */
static void scores_of(const ulam_kernel *k, double g, double pstar, double mb, double *visit, double *end)
{
    *visit = k->scores.estimator == ULAM_COLLISION ? g : scores_mb(k) ? mb : 0.0;
    *end = k->scores.estimator == ULAM_ABSORPTION && pstar > 0 ? g / pstar : 0.0;
}

/* What a visit to and a termination at row v score (r: as b_entry's). */
static void row_scores(const ulam_kernel *k, const row_view *v, double pstar, ulam__rowbuf *r, double *visit,
                       double *end)
{
    scores_of(k, v->g, pstar, scores_mb(k) ? expected_score(k, v, r) : 0.0, visit, end);
}

/* Record the first failure of the kernel (status, at row i). */
static void fail(ulam_kernel *k, int status, int64_t i)
{
    int ok = ULAM_OK;
    if (atomic_compare_exchange_strong(&k->status, &ok, status)) atomic_store(&k->bad, i);
}

/* A row left stale by rescore_records: its place holds -(record + 2) until a walk reaches it. */
#define STALE(o) (-(int32_t)(o) - 2)

/* Give row r of k (state i, at header h) its (M b)_i read again with its b_j (w: scratch) and
 * its scores; a failure is recorded and the row scores nothing. */
static void rescore_mb(ulam_kernel *k, ulam__rowrec *r, int64_t i, ulam__row *h, ulam__kscratch *w)
{
    if (k->rc.fetch(k->rc.ctx, i, 0, &w->rb, NULL)) { /* read before, so intact unless the file changed */
        h->visit = h->end = 0.0, fail(k, ULAM_ESYNTAX, i);
        return;
    }
    row_view v = {w->rb.col, w->rb.val, w->rb.len, r->g};
    r->mb = expected_score(k, &v, &w->rb);
    scores_of(k, r->g, r->pstar, r->mb, &h->visit, &h->end);
    if (!isfinite(h->visit) || !isfinite(h->end)) h->visit = h->end = 0.0, fail(k, ULAM_ENONFINITE, i);
}

/* Rescore the rows k's records hold (every built row) from the records alone.  A row whose
 * (M b)_i the expected estimator needs and no record holds is left stale instead of read now:
 * its place marks it, every move into it is unresolved again, so the first walk to reach it
 * rescores it (ulam__kernel_unit) and a row no walk reaches is never read; rescoring for
 * another estimator makes every row current again. */
static int rescore_records(ulam_kernel *k)
{
    int64_t nrec = atomic_load(&k->nrec), stale = 0;
    for (int64_t o = 0; o < nrec; o++) {
        ulam__rowrec *r = &k->rec[o];
        ulam__row *h = ulam__kernel_row(k, r->u);
        _Atomic int32_t *at = place(k, h->state, 0);
        if (scores_mb(k) && isnan(r->mb)) {
            atomic_store_explicit(at, STALE(o), memory_order_relaxed);
            h->visit = h->end = 0.0, stale++;
            continue;
        }
        atomic_store_explicit(at, (int32_t)r->u + 1, memory_order_relaxed); /* current (it may have been stale) */
        scores_of(k, r->g, r->pstar, r->mb, &h->visit, &h->end);
        if (!isfinite(h->visit) || !isfinite(h->end)) {
            fail(k, ULAM_ENONFINITE, h->state);
            break;
        }
    }
    for (int64_t o = 0; stale && o < nrec; o++) { /* moves into stale rows: unresolved, as before they were built */
        ulam__row *h = ulam__kernel_row(k, k->rec[o].u);
        ulam__slot *sl = (ulam__slot *)(void *)h + ULAM__HEAD;
        for (int32_t q = 0; q < h->len; q++)
            for (int side = 0; side < 2; side++) {
                _Atomic int32_t *x = side ? &sl[q].b : &sl[q].a;
                int32_t out = atomic_load_explicit(x, memory_order_relaxed), t = ulam__outcome_target(out);
                if (out == ULAM__TERMINATE || t >= ULAM__UNRESOLVED) continue;
                int64_t j = ulam__kernel_row(k, t)->state;
                if (atomic_load_explicit(place(k, j, 0), memory_order_relaxed) > -2) continue;
                t = ULAM__UNRESOLVED + (int32_t)j;
                atomic_store_explicit(x, out < 0 ? ~t : t, memory_order_relaxed);
            }
    }
    return atomic_load(&k->status);
}

/* Rescore every built row for another estimator. */
int ulam__kernel_rescore(ulam_kernel *k, int estimator)
{
    int status = atomic_load(&k->status);
    if (status) return status;
    k->scores.estimator = estimator;
    if (k->rec && !k->rec_stale) return rescore_records(k);
    int64_t top = atomic_load(&k->top);
    ulam__kscratch w = {0};
    row_view v;
    for (int64_t u = 0; u < top; u += ULAM__HEAD + v.len + 1) {
        /* the built rows one after another in the arena (not where[]: its n entries, untouched pages
           too, would cost a query O(n)); a failed build ended the loop above through k->status */
        ulam__row *h = ulam__kernel_row(k, u);
        int64_t i = h->state;
        if (get_row(k, i, &w, 0, &v)) { /* read before, so intact unless the file changed */
            fail(k, ULAM_ESYNTAX, i);
            break;
        }
        row_scores(k, &v, 1.0 - ulam__continuation(view_sum(&v), k->continue_q), &w.rb, &h->visit, &h->end);
        if (!isfinite(h->visit) || !isfinite(h->end)) {
            fail(k, ULAM_ENONFINITE, i);
            break;
        }
    }
    ulam__kscratch_free(&w);
    return atomic_load(&k->status);
}

/* Nonzero when the entries of row v are columns in range (ncols) with finite, nonzero values. */
static int view_ok(const row_view *v, int64_t ncols)
{
    for (int64_t q = 0; q < v->len; q++)
        if (v->col[q] < 0 || v->col[q] >= ncols || !isfinite(v->val[q]) || v->val[q] == 0.0) return 0;
    return 1;
}

/* Nonzero when the entries of row i (range checked) are columns in range with finite, nonzero
 * values. */
static int entries_ok(const ulam_csr *K, int64_t i)
{
    int64_t a = K->rowptr[i];
    row_view v = {K->colidx + a, K->val + a, K->rowptr[i + 1] - a, 1.0};
    return view_ok(&v, K->ncols);
}

/* Ask for what building state j's row reads first: its place and its range in rowptr. */
static void prefetch_state(const ulam_kernel *k, int64_t j)
{
#if defined(__GNUC__)
    if (k->where) __builtin_prefetch((const void *)&k->where[j]);
    else __builtin_prefetch((const void *)&k->dir[j / ULAM__LEAF]);
    __builtin_prefetch((const void *)&k->K->rowptr[j]);
#else
    (void)k, (void)j;
#endif
}

/* The outcome of a move to state j along an entry of sign given by v: the target row's unit when
 * placed, else the state to resolve; negative (flipping the weight) for v < 0. */
static int32_t move_outcome(ulam_kernel *k, int64_t j, double v, int placed)
{
    if (!placed) prefetch_state(k, j); /* a walk here moves to one of these next */
    int32_t t = placed ? place_of(k, j, memory_order_relaxed) - 1 : ULAM__UNRESOLVED + (int32_t)j;
    return v < 0 ? ~t : t;
}

/* The alias table of row i (header h built, continuation qi) at kernel exponent alpha != 1:
 * the table is built on the outcomes' numbers, then each slot gets its two outcomes and their
 * weight factors.  A probability too small for the table records ULAM_ERANGE (the dead row
 * instead); a factor that is not finite, ULAM_ENONFINITE. */
static void build_moves(ulam_kernel *k, const row_view *v, int64_t i, ulam__row *h, double qi, int placed,
                        ulam__kscratch *w)
{
    int64_t len = h->len - 1;
    int status = len > 0 ? moves_of(v->val, len, qi, k->alpha, w->p, w->f) : ULAM_OK;
    for (int64_t q = 0; !status && q < len; q++)
        if (!isfinite(w->f[q])) status = ULAM_ENONFINITE;
    if (status) {
        dead_row(h, i);
        fail(k, status, i);
        return;
    }
    for (int64_t q = 0; q <= len; q++) {
        if (q < len) w->p[q] *= qi;
        w->o[q] = (int32_t)q;
    }
    w->p[len] = 1.0 - qi;
    w->f[len] = 0.0; /* termination: never read */
    ulam__slot *s = (ulam__slot *)(void *)h + ULAM__HEAD;
    ulam__alias_build(w->p, w->o, len + 1, s, w->scaled, w->small, w->large);
    for (int64_t q = 0; q < len; q++) w->large[q] = move_outcome(k, v->col[q], v->val[q], placed);
    w->large[len] = ULAM__TERMINATE; /* the table is built: large is free scratch again */
    int64_t u = s - k->mem;
    for (int64_t q = 0; q <= len; q++) {
        int32_t a = atomic_load_explicit(&s[q].a, memory_order_relaxed), c = atomic_load_explicit(&s[q].b, memory_order_relaxed);
        k->fac[u + q][0] = w->f[a], k->fac[u + q][1] = w->f[c];
        set_slot(&s[q], s[q].thresh, (int32_t)w->large[a], (int32_t)w->large[c]);
    }
}

/* Build row i at header h: factor, scores and the alias table of its moves and termination.
 * Moves name their target rows' units when `placed` (every row has its place), else target
 * states still to be resolved.  A corrupt row (or no memory for its scratch) builds the dead
 * row instead and is recorded. */
static void build_row(ulam_kernel *k, const row_view *v, int64_t i, ulam__row *h, int placed, ulam__kscratch *w)
{
    int ok = view_ok(v, k->K->ncols);
    double mb = NAN; /* (K b)_i once its b_j are read from the file */
    if (ok && k->rc.with_b && k->scores.estimator == ULAM_EXPECTED) { /* its score reads b at its columns */
        double bj;
        int fromfile = fetching(k) && k->scores.b == k->rc.b_of;
        if (fromfile) mb = 0.0; /* summed as expected_score sums it */
        for (int64_t q = 0; ok && q < v->len; q++)
            if (!fromfile) ok = !ulam__rows_verify(&k->rc, v->col[q], v->col[q] + 1, NULL);
            else if ((ok = !k->rc.b_at(k->rc.ctx, v->col[q], &w->rb, &bj, NULL))) mb += v->val[q] * bj;
    }
    if (!ok) {
        dead_row(h, i);
        fail(k, ULAM_ESYNTAX, i);
        return;
    }
    int64_t len = v->len;
    if (kscratch_fit(w, len + 1)) {
        dead_row(h, i);
        fail(k, ULAM_ENOMEM, i);
        return;
    }
    double S = view_sum(v), qi = ulam__continuation(S, k->continue_q);
    *h = (ulam__row){.factor = qi > 0 && !k->fac ? S / qi : 0.0, .len = (int32_t)(len + 1), .state = (int32_t)i};
    if (scores_mb(k) && isnan(mb)) mb = expected_score(k, v, &w->rb);
    scores_of(k, v->g, 1.0 - qi, mb, &h->visit, &h->end);
    if (!isfinite(h->factor) || !isfinite(h->visit) || !isfinite(h->end)) {
        dead_row(h, i);
        fail(k, ULAM_ENONFINITE, i);
        return;
    }
    if (k->rec && !placed) { /* what rescoring it needs (claimed once: fewer records than states) */
        int64_t o = atomic_fetch_add_explicit(&k->nrec, 1, memory_order_relaxed);
        k->rec[o] = (ulam__rowrec){(ulam__slot *)(void *)h - k->mem, v->g, 1.0 - qi, scores_mb(k) ? mb : NAN};
    }
    if (k->fac) {
        build_moves(k, v, i, h, qi, placed, w);
        return;
    }
    for (int64_t q = 0; q < len; q++) {
        w->p[q] = qi * fabs(v->val[q]) / S;
        w->o[q] = move_outcome(k, v->col[q], v->val[q], placed);
    }
    w->p[len] = 1.0 - qi;
    w->o[len] = ULAM__TERMINATE;
    ulam__alias_build(w->p, w->o, len + 1, (ulam__slot *)(void *)h + ULAM__HEAD, w->scaled, w->small, w->large);
}

/* State j's row: the thread that claims it (where 0 -> -1) takes the next units of the arena,
 * builds the row there and publishes its place; any other thread waits for that. */
int32_t ulam__kernel_unit(ulam_kernel *k, int64_t j, ulam__kscratch *w)
{
    _Atomic int32_t *at = place(k, j, 1);
    int32_t v = atomic_load_explicit(at, memory_order_acquire), expect = 0;
    if (v > 0) return v - 1;
    if (atomic_compare_exchange_strong_explicit(at, &expect, -1, memory_order_acquire,
                                                memory_order_acquire)) {
        row_view rv;
        int ok = !get_row(k, j, w, 0, &rv);
        int64_t len = ok ? ULAM__HEAD + rv.len + 1 : 0;
        int64_t u = len ? atomic_fetch_add_explicit(&k->top, len, memory_order_relaxed) : k->cap;
        if (len && u + len > k->cap) u = k->cap; /* rowptr's ranges overlap: the file is corrupt */
        if (u < k->cap) build_row(k, &rv, j, ulam__kernel_row(k, u), 0, w);
        else fail(k, ULAM_ESYNTAX, j);
        atomic_store_explicit(at, (int32_t)u + 1, memory_order_release);
        atomic_fetch_add_explicit(&k->built, 1, memory_order_relaxed);
        return (int32_t)u;
    }
    while ((v = atomic_load_explicit(at, memory_order_acquire)) < 0)
        if (v <= -2 && atomic_compare_exchange_strong_explicit(at, &v, -1, memory_order_acquire, memory_order_acquire)) {
            ulam__rowrec *r = &k->rec[-(int64_t)v - 2]; /* stale (rescore_records): rescored by the thread that claims it */
            rescore_mb(k, r, j, ulam__kernel_row(k, r->u), w);
            atomic_store_explicit(at, (int32_t)r->u + 1, memory_order_release);
            return (int32_t)r->u;
        }
    return v - 1;
}

/* The row an unresolved outcome leads to; the outcome is rewritten to name it directly
 * (racing walkers write the same value). */
int32_t ulam__kernel_resolve(ulam_kernel *k, ulam__slot *s, uint64_t frac, int32_t o, ulam__kscratch *w)
{
    int32_t u = ulam__kernel_unit(k, ulam__outcome_target(o) - ULAM__UNRESOLVED, w);
    atomic_store_explicit(frac < s->thresh ? &s->a : &s->b, o < 0 ? ~u : u, memory_order_release);
    return u;
}

/* Prefetch the places of the targets of row i (random reads). */
static void prefetch_targets(const ulam_kernel *k, int64_t i)
{
#if defined(__GNUC__)
    if (i < k->n)
        for (int64_t q = k->K->rowptr[i]; q < k->K->rowptr[i + 1]; q++)
            if (k->where) __builtin_prefetch((const void *)&k->where[k->K->colidx[q]]);
#else
    (void)k, (void)i;
#endif
}

/* Build every row not built yet: place them all after the built ones, then build them in
 * parallel, streaming K once, with their moves resolved. */
void ulam__kernel_complete(ulam_kernel *k, int threads, ulam__kscratch *w)
{
    const ulam_csr *K = k->K;
    int64_t from = atomic_load(&k->top), u = from, bad = -1;
    for (int64_t o = 0; k->rec && !k->rec_stale && o < atomic_load(&k->nrec); o++) { /* stale rows current first: */
        ulam__rowrec *r = &k->rec[o]; /* the rows built below name their targets' places */
        int64_t i = ulam__kernel_row(k, r->u)->state;
        if (atomic_load_explicit(place(k, i, 0), memory_order_relaxed) > -2) continue;
        rescore_mb(k, r, i, ulam__kernel_row(k, r->u), &w[0]);
        atomic_store_explicit(place(k, i, 0), (int32_t)r->u + 1, memory_order_relaxed);
    }
    k->rec_stale = 1; /* the rows built here keep no record */
    if (ulam__rows_verify(&k->rc, 0, k->n, &bad)) { /* every row is read below: every block verified first */
        fail(k, ULAM_ESYNTAX, bad);
        return;
    }
    for (int64_t i = 0; i < k->n; i++)
        if (atomic_load_explicit(place(k, i, 1), memory_order_relaxed) == 0) {
            int64_t len = range_ok(K, i) ? ULAM__HEAD + row_outcomes(K, i) : 0;
            if (!len || u + len > k->cap) {
                fail(k, ULAM_ESYNTAX, i);
                len = 0;
            }
            atomic_store_explicit(place(k, i, 1), (int32_t)(len ? u : k->cap) + 1, memory_order_relaxed);
            u += len;
        }
    atomic_store(&k->top, u);
    atomic_store(&k->built, k->n);
    /* static chunks of 4096 rows: a kernel of fewer rows is one thread's work, so no team */
#pragma omp parallel for schedule(static, 4096) num_threads(threads) if (k->n > 4096)
    for (int64_t i = 0; i < k->n; i++) {
        int64_t at = place_of(k, i, memory_order_relaxed) - 1;
        prefetch_targets(k, i + 16);
        row_view rv;
        if (at >= from && at < k->cap && !get_row(k, i, NULL, 1, &rv)) /* verified whole above: read in place */
            build_row(k, &rv, i, ulam__kernel_row(k, at), 1, &w[ulam__thread_num()]);
    }
}

/* States reachable from the start set (marked in seen[]) along the walk's moves. */
int ulam__kernel_reach(const ulam_csr *K, double continue_q, char *seen, const ulam__rows_check *rc, int64_t *bad)
{
    int64_t n = K->nrows, *stack = ulam__malloc((size_t)n, sizeof *stack), top = 0;
    if (!stack) return ULAM_ENOMEM;
    for (int64_t i = 0; i < n; i++)
        if (seen[i]) stack[top++] = i;
    while (top > 0) {
        int64_t i = stack[--top];
        if (ulam__rows_verify(rc, i, i + 1, NULL) || !range_ok(K, i) || !entries_ok(K, i)) {
            free(stack);
            if (bad) *bad = i;
            return ULAM_ESYNTAX;
        }
        if (ulam__kernel_q(K, i, continue_q) <= 0) continue;
        for (int64_t q = K->rowptr[i]; q < K->rowptr[i + 1]; q++) {
            int64_t j = K->colidx[q];
            if (!seen[j]) {
                seen[j] = 1;
                stack[top++] = j;
            }
        }
    }
    free(stack);
    return ULAM_OK;
}

/* Rescore row i, when built, from k's scores. */
static void rescore_row(ulam_kernel *k, int64_t i)
{
    int32_t u = place_of(k, i, memory_order_relaxed);
    if (u <= 0) return;
    ulam__row *h = ulam__kernel_row(k, u - 1);
    ulam__kscratch w = {0};
    row_view v;
    if (get_row(k, i, &w, 0, &v)) {
        ulam__kscratch_free(&w);
        h->visit = h->end = 0.0, fail(k, ULAM_ESYNTAX, i);
        return;
    }
    double pstar = k->scores.estimator == ULAM_ABSORPTION ? 1.0 - ulam__continuation(view_sum(&v), k->continue_q) : 0.0;
    row_scores(k, &v, pstar, &w.rb, &h->visit, &h->end); /* p* is read by absorption alone */
    ulam__kscratch_free(&w);
    if (!isfinite(h->visit) || !isfinite(h->end)) h->visit = h->end = 0.0, fail(k, ULAM_ENONFINITE, i);
}

/* Keep k for later right-hand sides (see kernel.h). */
int ulam__kernel_keep(ulam_kernel *k)
{
    if (k->scores.estimator == ULAM_EXPECTED || !k->scores.b || atomic_load(&k->status)) return ULAM_EINVAL;
    if (!k->scored && !(k->scored = ulam__malloc((size_t)k->n, sizeof *k->scored))) return ULAM_ENOMEM;
    k->nscored = 0;
    for (int64_t i = 0; i < k->n; i++)
        if (k->scores.b[i] != 0.0) k->scored[k->nscored++] = i;
    return ULAM_OK;
}

/* Give a kept kernel's rows the scores of b (see kernel.h). */
int ulam__kernel_rescore_b(ulam_kernel *k, const double *b)
{
    if ((!k->scored && !k->fixed) || atomic_load(&k->status)) return ULAM_EINVAL;
    if (b == k->scores.b && k->fixed) return ULAM_OK; /* the same scores: nothing to do */
    if (k->fixed) return ULAM_EINVAL;
    k->scores.b = b;
    k->rec_stale = 1; /* the records hold the old b's g_i */
    for (int64_t j = 0; j < k->nscored; j++) rescore_row(k, k->scored[j]); /* now b's (0 off its support) */
    int status = atomic_load(&k->status) ? atomic_load(&k->status) : ulam__kernel_keep(k);
    for (int64_t j = 0; !status && j < k->nscored; j++) rescore_row(k, k->scored[j]);
    return status ? status : atomic_load(&k->status);
}
