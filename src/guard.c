/* Stability guards: the spectral radii that say whether a walk's answer means anything.
 *
 * A walk on K (K = M for adjoint walks, M' for forward walks) continues from i with
 * probability q_i, moves to j with probability p_ij and multiplies its weight by
 * K_ij / (q_i p_ij).  Its expected score is the Neumann series sum_k K^k b, which the walks
 * reproduce term by term only if sum_k |K|^k |b| converges: rho(|M|) < 1 (the same for M').
 * Its second moment v solves (I - M^) v = r with M^_ij = K_ij^2 / (q_i p_ij) and
 *   collision:  r = b o b + 2 b o (x - b)
 *   absorption: r = b o b / p*      (a state that scores needs p* > 0: checked by the solver)
 *   expected:   r = c o c + 2 c o (y - c), c = M b
 * (o: elementwise; derived in tests/test_walk.c), so every estimator's variance is finite iff
 * the series sum_k M^^k r converges: rho(M^) < 1.  For the analog kernel (p_ij = |K_ij| / S_i)
 * M^ = diag(S / q) |K|; a fixed q = Q gives diag(S / Q) |K|.  With K = M', rho(diag(c) |M'|)
 * = rho(|M| diag(c)), c the column factors, so no transpose is formed.  At a kernel exponent
 * alpha != 1 (p_ij = |K_ij|^alpha / T_i given a move) the factor differs from entry to entry,
 * M^_ij = |K_ij| |K_ij| T_i / (q_i |K_ij|^alpha), so M^ is formed entry by entry (on M' for
 * forward walks) and its radius bounded the same way; rho(|M|) does not depend on alpha.
 *
 * The fourth moment (what the rel_err rule's check on the variance's own error bar needs) is
 * the same with fourth powers: E[|w_k|^4 at j] = w0^4 (M4^k)_{start j}, M4_ij = |K_ij|^4 /
 * (q_i p_ij)^3, and a score sum_k w_k g_k (collision g = b, expected g = M b plus the start's
 * b; absorption one score w_k b_j / p*_j, i.e. g_j^4 = b_j^4 / p*_j^3 against M4^k) has, by
 * Minkowski, ||X||_4 <= sum_k ((M4^k |g|^4)_start)^(1/4) w0: finite when rho(M4) < 1.  The
 * entries of the moment matrices of order r are P_ij f_ij^r (P_ij = q_i p_ij), log-linear in
 * r, so log rho is convex in r (Kingman): with rho(P) <= 1 at r = 0, rho(M4) < 1 gives rho(M^)
 * < 1 and rho(|M|) < 1 too, and rho(M4) >= rho(M^)^2 / rho(P) >= rho(M^)^2.
 * The solver computes it for rel_err runs (ulam__guard_fourth); it matters only where no
 * bound on a single score holds (a bounded score has every moment finite).
 *
 * The radii of these nonnegative matrices come from power iteration with Collatz-Wielandt
 * bounds (spectral.c), which certify a verdict whenever the bracket lies on one side of 1. */
#include "guard.h"
#include "defaults.h"
#include "check.h"
#include "kernel.h"
#include "spectral.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

/* The default guard options: all three radii, stopped once certified. */
ulam_guard_opts ulam__guard_defaults(void)
{
    return (ulam_guard_opts){.need = ULAM_GUARD_ALL, .power = ulam_power_defaults(), .kernel_alpha = 1.0};
}

/* Certified bounds alone decide: below 0.99 fine, below 1 near the edge, from 1 up failing,
 * straddling 1 unknown. */
int ulam_verdict_of(const ulam_power *p)
{
    if (p->upper < 0.99) return ULAM_VERDICT_OK;
    if (p->upper < 1.0) return ULAM_VERDICT_EDGE;
    if (p->lower >= 1.0) return ULAM_VERDICT_FAIL;
    return ULAM_VERDICT_UNKNOWN;
}

/* 1 finite, 0 infinite, -1 unknown: the variance of walks in mode by g. */
int ulam_guard_variance(const ulam_guard *g, int mode)
{
    int v = g->verdict_hat[mode == ULAM_FORWARD];
    return v == ULAM_VERDICT_OK || v == ULAM_VERDICT_EDGE ? 1 : v == ULAM_VERDICT_FAIL ? 0 : -1;
}

/* The one-pass sums of a nonnegative matrix A: min and max of its row sums r and column sums c
 * bound its radius (min r <= rho <= max r, the same for c, as rho(A) = rho(A')). */
typedef struct {
    double rmin, rmax, cmin, cmax, total;
} sums;

/* Bounds from the sums into a fresh radius (estimate: the first power step's sum(A1)/n). */
static ulam_power from_sums(const sums *s, int64_t n)
{
    ulam_power p = {.lower = fmax(s->rmin, s->cmin), .upper = fmin(s->rmax, s->cmax), .rowsum_max = s->rmax,
                    .colsum_max = s->cmax};
    if (n == 0) p.lower = p.upper = 0.0;
    p.rho = fmin(fmax(n > 0 ? s->total / (double)n : 0.0, p.lower), p.upper);
    p.converged = isfinite(p.upper) && p.upper - p.lower <= 1e-12 * p.upper;
    return p;
}

/* min and max of the n entries of v into *lo, *hi. */
static void range(const double *v, int64_t n, double *lo, double *hi)
{
    *lo = n ? INFINITY : 0.0, *hi = 0.0;
    for (int64_t i = 0; i < n; i++) *lo = fmin(*lo, v[i]), *hi = fmax(*hi, v[i]);
}

/* Nonzero when all n factors are 1: diag(f) |M| is then |M|, and so is its radius. */
static int all_ones(const double *f, int64_t n)
{
    for (int64_t i = 0; i < n; i++)
        if (f[i] != 1.0) return 0;
    return 1;
}

/* Scratch of the guard check: per-state sums and factors. */
typedef struct {
    double *S, *C;   /* row and column sums of |M| */
    double *fr, *fc; /* kernel factors S_i / q_i of rows (adjoint) and columns (forward) */
    double *ca;      /* column sums of diag(fr) |M| */
    double *rf;      /* row sums of |M| diag(fc) */
} guard_work;

/* Free the scratch. */
static void work_free(guard_work *w)
{
    free(w->S), free(w->C), free(w->fr), free(w->fc), free(w->ca), free(w->rf);
}

/* The pass over M's rows: S and fr, reading M in order; with cols, also C, fc and the column
 * sums of diag(fr) |M| (a scatter to random columns, each row read twice while in cache),
 * made only when the row sums alone do not settle the run's verdicts. */
static int sum_pass(const ulam_csr *M, double continue_q, int cols, guard_work *w)
{
    int64_t n = M->nrows;
    if (!w->S) {
        w->S = ulam__malloc((size_t)n, sizeof(double)), w->fr = ulam__malloc((size_t)n, sizeof(double));
        if (!w->S || !w->fr) return ULAM_ENOMEM;
        for (int64_t i = 0; i < n; i++) {
            double s = 0.0;
            for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += fabs(M->val[q]);
            w->S[i] = s;
            w->fr[i] = ulam__factor(s, continue_q);
        }
    }
    if (!cols) return ULAM_OK;
    w->C = ulam__calloc((size_t)n, sizeof(double)), w->ca = ulam__calloc((size_t)n, sizeof(double));
    w->fc = ulam__malloc((size_t)n, sizeof(double));
    if (!w->C || !w->ca || !w->fc) return ULAM_ENOMEM;
    for (int64_t i = 0; i < n; i++)
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) {
            w->C[M->colidx[q]] += fabs(M->val[q]);
            w->ca[M->colidx[q]] += w->fr[i] * fabs(M->val[q]);
        }
    for (int64_t j = 0; j < n; j++) w->fc[j] = ulam__factor(w->C[j], continue_q);
    return ULAM_OK;
}

/* The row sums of |M| diag(fc), which need every fc first: a second pass. */
static int forward_rows(const ulam_csr *M, guard_work *w)
{
    int64_t n = M->nrows;
    if (!(w->rf = ulam__malloc((size_t)n, sizeof(double)))) return ULAM_ENOMEM;
    for (int64_t i = 0; i < n; i++) {
        double s = 0.0;
        for (int64_t q = M->rowptr[i]; q < M->rowptr[i + 1]; q++) s += fabs(M->val[q]) * w->fc[M->colidx[q]];
        w->rf[i] = s;
    }
    return ULAM_OK;
}

/* The sums of diag(f) |M| (rows = f o S, columns ca) or of |M| diag(f) (rows rf, columns
 * f o C); rf may be NULL (not computed: the row bound is then infinite). */
static sums hat_sums(const guard_work *w, int64_t n, int forward)
{
    sums s = {0};
    const double *f = forward ? w->fc : w->fr, *base = forward ? w->C : w->S;
    s.rmin = n ? INFINITY : 0.0, s.cmin = s.rmin;
    for (int64_t i = 0; i < n; i++) {
        double scaled = f[i] * base[i]; /* adjoint: row i of diag(f)|M|; forward: column i of |M|diag(f) */
        double other = forward ? (w->rf ? w->rf[i] : INFINITY) : w->ca ? w->ca[i] : INFINITY;
        double r = forward ? other : scaled, c = forward ? scaled : other;
        s.rmin = fmin(s.rmin, r), s.rmax = fmax(s.rmax, r);
        s.cmin = fmin(s.cmin, c), s.cmax = fmax(s.cmax, c);
        s.total += c; /* the sum of all entries: the column sums add up to it */
    }
    if (forward && !w->rf) s.rmin = 0.0;
    if (!forward && !w->ca) s.cmin = 0.0;
    return s;
}

/* Nonzero when every state is reachable in the graph of G (i -> j for G_ij != 0) from a
 * state marked deficient (-1: out of memory). */
static int all_reached(const ulam_csr *G, char *seen)
{
    int64_t n = G->nrows, head = 0, tail = 0;
    int32_t *queue = ulam__malloc((size_t)n, sizeof *queue);
    if (!queue) return -1;
    for (int64_t j = 0; j < n; j++)
        if (seen[j]) queue[tail++] = (int32_t)j;
    while (head < tail) {
        int32_t i = queue[head++];
        for (int64_t q = G->rowptr[i]; q < G->rowptr[i + 1]; q++)
            if (!seen[G->colidx[q]]) seen[G->colidx[q]] = 1, queue[tail++] = G->colidx[q];
    }
    free(queue);
    return tail == n;
}

/* The walk kernel's own certificate of rho < 1.  Rows (adjoint walks on M): every row sum S_i
 * of |M| is at most 1, as the kernel computes it in floating point, so every weight factor is
 * exactly 1 and the kernel is a substochastic chain whose row probabilities sum to exactly 1;
 * if from every state a state with S_i < 1 (where walks may end) can be reached, the chain is
 * transient, some power of it has every row sum below 1, and its radius is below 1 (strictly:
 * by how much, unknown).  Columns (forward walks on M') the same with the column sums C.
 * 1 certified, 0 not, -1 out of memory. */
static int kernel_transient(const ulam_csr *M, const double *sums, int rows)
{
    int64_t n = M->nrows;
    for (int64_t i = 0; i < n; i++)
        if (sums[i] > 1.0) return 0;
    char *seen = ulam__calloc((size_t)n, 1);
    ulam_csr *T = NULL;
    if (!seen || (rows && ulam_csr_transpose(M, &T))) {
        free(seen);
        return -1;
    }
    for (int64_t i = 0; i < n; i++) seen[i] = sums[i] < 1.0;
    int r = all_reached(rows ? T : M, seen); /* rows: states that reach a deficient one in M */
    ulam_csr_free(T);
    free(seen);
    return r;
}

/* One radius: the sums' bounds (and for rho(|M|) itself, when S and C are given, the kernels'
 * certificate of rho < 1: rows if reach & 1, columns if reach & 2, all those asked must hold),
 * then power iteration unless they certify (or o->tight). */
static int radius(const ulam_csr *M, const double *left, const double *right, const sums *sm, const double *S,
                  const double *C, int reach, const ulam_guard_opts *o, ulam_power *out, ulam_error *err)
{
    double t0 = ulam_now();
    *out = from_sums(sm, M->nrows);
    out->seconds = 0.0;
    int status = ULAM_OK;
    if (reach && !ulam__power_certain(out->lower, out->upper) && out->upper >= 1.0) {
        int r = 1;
        for (int v = 0; v < 2 && r > 0; v++)
            if (reach & (1 << v)) r = (v ? C : S) ? kernel_transient(M, v ? C : S, v == 0) : 0;
        if (r < 0) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a reachability check");
        if (r) out->upper = nextafter(1.0, 0.0), out->lower = fmin(out->lower, out->upper);
        if (r && !o->tight) { /* certain: below 1; the 0.99 margin is left open (at sums of 1 power
                                 * iteration would seldom settle it) */
            out->seconds = ulam_now() - t0;
            return ULAM_OK;
        }
    }
    if (!out->converged && (o->tight || !ulam__power_certain(out->lower, out->upper))) {
        ulam_power_opts po = o->power;
        po.certify = !o->tight;
        status = ulam__power_from(M, left, right, &po, out, err);
    }
    out->seconds = ulam_now() - t0;
    return status;
}

/* The one-pass sums of the nonnegative matrix A (its entries as they are). */
static sums matrix_sums(const ulam_csr *A, double *col)
{
    int64_t n = A->nrows;
    sums s = {.rmin = n ? INFINITY : 0.0, .cmin = n ? INFINITY : 0.0};
    for (int64_t j = 0; j < n; j++) col[j] = 0.0;
    for (int64_t i = 0; i < n; i++) {
        double r = 0.0;
        for (int64_t q = A->rowptr[i]; q < A->rowptr[i + 1]; q++) r += A->val[q], col[A->colidx[q]] += A->val[q];
        s.rmin = fmin(s.rmin, r), s.rmax = fmax(s.rmax, r), s.total += r;
    }
    range(col, n, &s.cmin, &s.cmax);
    return s;
}

/* The radius of the walk's moment matrix of order power + 1 on K (M adjoint, M' forward):
 * entries |K_ij| f_ij^power, f_ij = |K_ij| / (q_i p_ij) the moves' weight factors (S_i / q_i
 * at alpha = 1, else ulam__kernel_moves), formed in K's pattern: power 1 is M^, power 3 the
 * fourth-moment matrix M4_ij = |K_ij|^4 / (q_i p_ij)^3.  An entry whose probability underflows
 * (the walk kernel refuses its row) leaves the radius unknown: bounds [0, INFINITY], nothing
 * certified. */
static int moment_radius(const ulam_csr *K, double continue_q, double alpha, int power, const ulam_guard_opts *o,
                         ulam_power *out, ulam_error *err)
{
    int64_t n = K->nrows, nnz = K->rowptr[n];
    double *val = ulam__malloc((size_t)nnz, sizeof *val), *f = ulam__malloc((size_t)nnz, sizeof *f);
    double *col = ulam__malloc((size_t)n, sizeof *col);
    if (!val || !f || !col) {
        free(val), free(f), free(col);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for a moment matrix");
    }
    int finite = 1;
    for (int64_t i = 0; i < n; i++) {
        double q = ulam__kernel_q(K, i, continue_q), S = 0.0;
        int64_t a = K->rowptr[i];
        for (int64_t k = a; alpha == 1.0 && k < K->rowptr[i + 1]; k++) S += fabs(K->val[k]);
        if (q > 0 && alpha != 1.0) (void)ulam__kernel_moves(K, i, q, alpha, val + a, f + a);
        for (int64_t k = a; k < K->rowptr[i + 1]; k++) {
            double fk = alpha == 1.0 ? ulam__factor(S, continue_q) : f[k];
            val[k] = q > 0 ? fabs(K->val[k]) * pow(fk, power) : 0.0;
            finite &= isfinite(val[k]);
        }
    }
    ulam_csr H = {.nrows = n, .ncols = n, .rowptr = K->rowptr, .colidx = K->colidx, .val = val};
    int status = ULAM_OK;
    if (finite) {
        sums sm = matrix_sums(&H, col);
        status = radius(&H, NULL, NULL, &sm, NULL, NULL, 0, o, out, err);
    } else {
        *out = (ulam_power){.rho = INFINITY, .lower = 0.0, .upper = INFINITY, .rowsum_max = INFINITY,
                            .colsum_max = INFINITY};
    }
    free(val), free(f), free(col);
    return status;
}

/* rho(M4) of the walk kernel of K (internal.h).  Every factor 1 (alpha = 1, no row of |K|
 * above 1, analog continuation q_i = S_i): then q_i p_ij = |K_ij|, M4_ij = |K_ij|^4 / |K_ij|^3
 * = |K_ij|, M4 = |K| itself and rho(M4) = rho(|M|), taken from abs when given (the guards'
 * radius, which the solver has certified below 1 or refused). */
int ulam__guard_fourth(const ulam_csr *K, double continue_q, double alpha, const ulam_power *abs, ulam_power *out,
                       ulam_error *err)
{
    int ones = alpha == 1.0 && abs;
    for (int64_t i = 0; ones && i < K->nrows; i++) {
        double S = 0.0;
        for (int64_t k = K->rowptr[i]; k < K->rowptr[i + 1]; k++) S += fabs(K->val[k]);
        ones = S == 0.0 || ulam__factor(S, continue_q) == 1.0;
    }
    if (ones) {
        *out = *abs;
        out->seconds = 0.0;
        return ULAM_OK;
    }
    ulam_guard_opts o = ulam_guard_defaults();
    return moment_radius(K, continue_q, alpha, 3, &o, out, err);
}

/* The radii asked for and their verdicts. */
int ulam_guard_check(const ulam_csr *M, double continue_q, const ulam_guard_opts *opts,
                     ulam_guard *g, ulam_error *err)
{
    ulam__clear(err);
    if (!M || !g) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix and an output");
    if (M->nrows != M->ncols) return ulam__fail(err, ULAM_ENOTSQUARE, 0, -1, "a square matrix M");
    ulam_guard_opts o = opts ? *opts : ulam_guard_defaults();
    if (!o.need) o.need = ULAM_GUARD_ALL;
    int bad = ulam__guard_opts_check(&o, err); /* src/check.c: the options, then M's structure */
    if (!bad) bad = ulam__real_check(continue_q, -DBL_MAX, nextafter(1.0, 0.0), "continue_q",
                                     "finite and below 1 (<= 0: analog)", err);
    if (bad || (bad = ulam__csr_check_structure(M, err))) return bad;
    int64_t n = M->nrows;
    int alpha1 = o.kernel_alpha == 1.0; /* else rho(M^) comes from moment_radius */
    double t0 = ulam_now();
    ulam_power none = {.upper = INFINITY, .rowsum_max = INFINITY, .colsum_max = INFINITY};
    *g = (ulam_guard){.continue_q = continue_q, .kernel_alpha = o.kernel_alpha, .abs = none, .hat = {none, none}};
    guard_work w = {0};
    int status = sum_pass(M, continue_q, 0, &w), cols = o.tight || (alpha1 && (o.need & ULAM_GUARD_FORWARD));
    if (!status && !cols) { /* the column sums only when the row sums do not certify */
        double lo, hi;
        range(w.S, n, &lo, &hi);
        cols = !ulam__power_certain(lo, hi);
        if (alpha1 && (o.need & ULAM_GUARD_ADJOINT) && !all_ones(w.fr, n)) {
            sums h = hat_sums(&w, n, 0);
            cols |= !ulam__power_certain(h.rmin, h.rmax);
        }
    }
    if (!status && cols) status = sum_pass(M, continue_q, 1, &w);
    if (!status && alpha1 && (o.need & ULAM_GUARD_FORWARD)) { /* the second pass only when the column sums do not certify */
        sums f = hat_sums(&w, n, 1);
        if (o.tight || !ulam__power_certain(fmax(f.cmin, 0.0), f.cmax)) status = forward_rows(M, &w);
    }
    if (status) {
        work_free(&w);
        return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the kernel factors");
    }
    double pass = ulam_now() - t0;
    sums a = {.cmin = 0.0, .cmax = INFINITY};
    range(w.S, n, &a.rmin, &a.rmax);
    if (w.C) range(w.C, n, &a.cmin, &a.cmax);
    for (int64_t i = 0; i < n; i++) a.total += w.S[i];
    int ones[2] = {alpha1 && all_ones(w.fr, n), alpha1 && w.fc && all_ones(w.fc, n)}, need = o.need;
    for (int m = 0; m < 2; m++)
        if ((o.need & ULAM_GUARD_HAT(m)) && ones[m]) need |= ULAM_GUARD_ABS; /* M^ is |M| itself */
    int reach = (need & ULAM_GUARD_ADJOINT ? 1 : 0) | (need & ULAM_GUARD_FORWARD ? 2 : 0);
    if (need & ULAM_GUARD_ABS) status = radius(M, NULL, NULL, &a, w.S, w.C, reach ? reach : 3, &o, &g->abs, err);
    for (int m = 0; m < 2 && !status; m++) {
        if (!(need & ULAM_GUARD_HAT(m))) continue;
        if (!alpha1) {
            ulam_csr *T = NULL;
            if (m == ULAM_FORWARD && ulam_csr_transpose(M, &T)) status = ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for M'");
            else status = moment_radius(T ? T : M, continue_q, o.kernel_alpha, 1, &o, &g->hat[m], err);
            ulam_csr_free(T);
            continue;
        }
        if (ones[m]) {
            g->hat[m] = g->abs;
            g->hat[m].seconds = 0.0;
            continue;
        }
        sums h = hat_sums(&w, n, m == ULAM_FORWARD);
        const double *f = m == ULAM_FORWARD ? w.fc : w.fr;
        status = radius(M, m == ULAM_FORWARD ? NULL : f, m == ULAM_FORWARD ? f : NULL, &h, NULL, NULL, 0, &o, &g->hat[m],
                        err);
    }
    work_free(&w);
    if (status) return status;
    g->computed = need;
    g->abs.seconds += pass; /* the one pass is charged to rho(|M|) */
    g->verdict_abs = need & ULAM_GUARD_ABS ? ulam_verdict_of(&g->abs) : ULAM_VERDICT_UNKNOWN;
    for (int m = 0; m < 2; m++)
        g->verdict_hat[m] = need & ULAM_GUARD_HAT(m) ? ulam_verdict_of(&g->hat[m]) : ULAM_VERDICT_UNKNOWN;
    return ULAM_OK;
}

/* Whether a caller's guard fits a solver's continuation, exponent and needs. */
int ulam__guard_fits(const ulam_guard *g, double continue_q, double alpha, int need)
{
    double q = continue_q > 0 ? continue_q : 0.0;
    return g && (g->continue_q > 0 ? g->continue_q : 0.0) == q && g->kernel_alpha == alpha &&
           (g->computed & need) == need;
}
