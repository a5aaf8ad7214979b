/* The stopping rule and the printed interval: the stitched empirical-Bernstein bound (see
 * stop.h), one formula for every budget (walks, time, rel_err) and every solver. */
#include "stop.h"

#include <math.h>

/* The epoch of n walks. */
int ulam__stop_epoch(int64_t n)
{
    if (n <= ULAM__STOP_N0) return 1;
    return 1 + (int)ceil(2.0 * log2((double)n / ULAM__STOP_N0) - 1e-12);
}

/* ln(3 / delta_k): delta_k = delta / (k (k + 1)) at checkpoint k >= 1, delta itself at k = 0. */
double ulam__stop_log(int k)
{
    return log(3.0 / ULAM__STOP_DELTA) + (k >= 1 ? log((double)k * ((double)k + 1.0)) : 0.0);
}

/* The interval of n scores. */
void ulam__stop_interval(int64_t n, double mean, double var, double R, double bias, double maxabs, double limit, int k,
                         ulam__stop_ci *ci)
{
    *ci = (ulam__stop_ci){.lo = NAN, .hi = NAN, .half = INFINITY, .var_term = INFINITY, .range_term = INFINITY,
                          .bias = bias, .L = ulam__stop_log(k), .k = k, .kind = ULAM__STOP_NONE};
    if (R == 0.0) { /* nothing that scores is reachable: x is 0, certified */
        ci->lo = ci->hi = mean, ci->half = ci->var_term = ci->range_term = 0.0, ci->kind = ULAM__STOP_EXACT;
        return;
    }
    if (n < 2 || !isfinite(R) || !(R > 0) || !isfinite(mean) || !(bias >= 0) || !isfinite(bias)) return;
    if (maxabs > limit * (1.0 + ULAM__STOP_ROUNDING)) { /* past the range: not the clipped sample R describes */
        ci->kind = ULAM__STOP_BEYOND;
        return;
    }
    double N = (double)n, L = ci->L;
    ci->var_term = sqrt(2.0 * fmax(var, 0.0) * L / N);
    ci->range_term = 7.0 * R * L / (3.0 * (N - 1.0));
    ci->half = ci->var_term + ci->range_term + bias;
    ci->lo = mean - ci->half, ci->hi = mean + ci->half;
    ci->kind = ULAM__STOP_EB;
}

/* Whether an interval meets a relative-error target. */
int ulam__stop_rel_met(const ulam__stop_ci *ci, double m, double E)
{
    if (!(E > 0)) return 0;
    if (ci->kind == ULAM__STOP_EXACT) return 1;
    double w = sqrt(2.0 * ci->L) * E * fabs(m);
    return ci->kind == ULAM__STOP_EB && w > 0 && ci->var_term <= w && ci->half <= 2.0 * w;
}

/* The walk count that would meet target E. */
double ulam__stop_walks_needed(double m, double var, double R, double bias, double E, int k)
{
    if (!(E > 0)) return 0.0;
    if (R == 0.0) return 0.0;
    double L = ulam__stop_log(k), w = sqrt(2.0 * L) * E * fabs(m), C = 2.0 * w - bias;
    if (!(fabs(m) > 0) || !isfinite(R) || !(C > 0)) return INFINITY;
    /* var_term(n) = a / sqrt(n) <= w, and a / sqrt(n) + c / (n - 1) <= C (both fall with n) */
    double a = sqrt(2.0 * fmax(var, 0.0) * L), c = 7.0 * R * L / 3.0, nv = fmax(var, 0.0) / (E * m * E * m);
    double lo = fmax(nv, 1.0), hi = fmax(lo, fmax(4.0 * a * a / (C * C), 2.0 * c / C + 1.0)) + 1.0;
    if (a / sqrt(lo) + c / (lo - 1.0) <= C) return ceil(fmax(lo, 2.0));
    for (int it = 0; it < 200 && hi - lo > 0.5; it++) { /* lo fails, hi holds */
        double mid = 0.5 * (lo + hi);
        if (a / sqrt(mid) + c / (mid - 1.0) <= C) hi = mid;
        else lo = mid;
    }
    return ceil(hi);
}

/* The walks' share of a target E beside an independent relative error f. */
double ulam__stop_combined_target(double E, double f)
{
    if (!(E > 0)) return E;
    return f < E ? sqrt(E * E - f * f) : 0.0;
}

/* kl(a || b) between Bernoulli laws (0 ln 0 = 0). */
static double kl_bernoulli(double a, double b)
{
    double s = 0.0;
    if (a > 0) s += a * log(a / b);
    if (a < 1) s += (1.0 - a) * log((1.0 - a) / (1.0 - b));
    return s;
}

/* The KL interval of n scores in [0, 1]. */
void ulam__stop_kl_interval(int64_t n, double m, int k, double *lo, double *hi)
{
    double c = log(2.0 / ULAM__STOP_DELTA) + (k >= 1 ? log((double)k * ((double)k + 1.0)) : 0.0), N = (double)n;
    m = fmin(1.0, fmax(0.0, m));
    double in = m, out = 1.0; /* kl(m || q) is 0 at q = m, rises to infinity at 0 and 1: bisect each side */
    for (int it = 0; it < 64 && m < 1.0; it++) {
        double q = 0.5 * (in + out);
        if (N * kl_bernoulli(m, q) <= c) in = q;
        else out = q;
    }
    *hi = out; /* outside the set: the conservative end */
    in = m, out = 0.0;
    for (int it = 0; it < 64 && m > 0.0; it++) {
        double q = 0.5 * (in + out);
        if (N * kl_bernoulli(m, q) <= c) in = q;
        else out = q;
    }
    *lo = out;
}

/* psi_E(l) = -ln(1 - l) - l, the exponential-inequality penalty of a bet l in [0, 1). */
static double cs_psi(double l)
{
    return -log1p(-l) - l;
}

/* ln(2 / delta): each side of the sequence takes delta / 2. */
static double cs_log(void)
{
    return log(2.0 / ULAM__STOP_DELTA);
}

/* Plan the next block. */
void ulam__cs_plan(ulam__cs *cs, int64_t n, double mean, double var, double A, double b, double h, double nplan)
{
    cs->limit = A, cs->bias = b, cs->lam = 0.0, cs->c = 0.0, cs->s = INFINITY;
    if (!(A > 0) || !isfinite(A) || !(b >= 0) || !isfinite(b)) return; /* no range: the block weighs nothing */
    double c = n > 0 && isfinite(mean) ? fmax(-A, fmin(A, mean)) : 0.0, s = A + fabs(c), N = (double)n;
    /* the variance in xi units, with one prior observation at the largest, 1/4 (as Waudby-Smith and
       Ramdas): a sample that has not yet seen its rare large scores bets small */
    double v = ((n > 1 && isfinite(var) ? fmax(var, 0.0) * (N - 1.0) : 0.0) / s / s + 0.25) / (N + 1.0);
    double lam = h > 0 ? (h / s) / (v + h / s) /* the lambda that reaches h soonest: h_xi = psi'(l) v */
                       : sqrt(2.0 * cs_log() / (v * fmax(nplan, 2.0)));
    cs->lam = isfinite(lam) && lam > 0 ? fmin(lam, ULAM__CS_LMAX) : 0.0, cs->c = c, cs->s = s;
}

/* psi4(u) / u^4 = sum over k >= 4 of u^(k - 4) / k, u in [0, 1): the quartic's coefficient. */
static double cs_psi4_u4(double u)
{
    if (u >= 0.25) return (-log1p(-u) - u - u * u / 2.0 - u * u * u / 3.0) / (u * u * u * u);
    double sum = 0.0, p = 1.0;
    for (int k = 4; k < 40; k++, p *= u) sum += p / k; /* 0.25^36: past the double's precision */
    return sum;
}

/* The two ends' mean quartic penalty a score at bet l (plan: centre c, scale s, limit A), for
 * scores of second and fourth moments v2, v4 about c in xi units. */
static double cs_pen(const ulam__cs *cs, double l, double v2, double v4)
{
    double alo = fmin(1.0, (cs->c + cs->limit) / cs->s), ahi = fmin(1.0, (cs->limit - cs->c) / cs->s);
    double c4 = 0.5 * (cs_psi4_u4(l * fmax(alo, 0.0)) + cs_psi4_u4(l * fmax(ahi, 0.0)));
    return fmin(l * l / 2.0 * v2 + l * l * l * l * c4 * v4, cs_psi(l) * v2);
}

/* Plan the next block with the scores' higher moments. */
void ulam__cs_plan4(ulam__cs *cs, int64_t n, double mean, double var, double m3, double m4, double A, double b, double h,
                    double nplan)
{
    ulam__cs_plan(cs, n, mean, var, A, b, h, nplan); /* the limit, centre, scale and Fan's bet */
    if (!(cs->lam > 0)) return;
    double s = cs->s, N = (double)n, d = n > 0 && isfinite(mean) ? (mean - cs->c) / s : 0.0;
    double M2 = n > 1 && isfinite(var) ? fmax(var, 0.0) * (N - 1.0) / (s * s) : 0.0;
    double M3 = n > 1 && isfinite(m3) ? m3 / (s * s * s) : 0.0, M4 = n > 1 && isfinite(m4) ? fmax(m4, 0.0) / (s * s * s * s) : 0.0;
    double v2 = (M2 + N * d * d + 0.25) / (N + 1.0); /* about c, with the prior observation */
    double v4 = fmax((M4 + 4.0 * d * M3 + 6.0 * d * d * M2 + N * d * d * d * d + 0.0625) / (N + 1.0), v2 * v2);
    double lo = 1e-9, hi = ULAM__CS_LMAX4, g = 0.5 * (sqrt(5.0) - 1.0); /* golden-section: the objective is unimodal */
    for (int it = 0; it < 60; it++) {
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1, f2;
        if (h > 0) f1 = -(x1 * h / s - cs_pen(cs, x1, v2, v4)), f2 = -(x2 * h / s - cs_pen(cs, x2, v2, v4));
        else f1 = (cs_log() / fmax(nplan, 2.0) + cs_pen(cs, x1, v2, v4)) / x1, f2 = (cs_log() / fmax(nplan, 2.0) + cs_pen(cs, x2, v2, v4)) / x2;
        if (f1 <= f2) hi = x2;
        else lo = x1;
    }
    double lam = 0.5 * (lo + hi);
    if (isfinite(lam) && lam > 0) cs->lam = fmin(lam, ULAM__CS_LMAX4);
}

/* Add a block under the current plan: its scores' moments about the block's centre c in xi units
 * (S2, S3, S4: sums of xi^2, xi^3, xi^4; S3 = S4 = NAN when not known: Fan's psi both ends). */
static void cs_add_sums(ulam__cs *cs, int64_t n, double mean, double S2, double S3, double S4, double maxabs)
{
    if (n <= 0) return;
    if (maxabs > cs->limit * (1.0 + ULAM__STOP_ROUNDING) || !isfinite(mean)) cs->beyond = 1;
    double N = (double)n, eta = cs->lam / cs->s, l = cs->lam;
    if (eta > 0 && isfinite(eta) && !cs->beyond) {
        cs->eta += eta * N, cs->etax += eta * N * mean, cs->etab += eta * N * cs->bias;
        double fan = cs_psi(l) * S2, lo = fan, hi = fan;
        if (isfinite(S3) && isfinite(S4)) { /* the quartic, each end at its own range end (stop.h) */
            double alo = fmin(1.0, (cs->c + cs->limit) / cs->s), ahi = fmin(1.0, (cs->limit - cs->c) / cs->s);
            double l4 = l * l * l * l, q = l * l / 2.0 * S2, t = l * l * l / 3.0 * S3;
            lo = fmin(fan, q - t + l4 * cs_psi4_u4(l * fmax(alo, 0.0)) * S4);
            hi = fmin(fan, q + t + l4 * cs_psi4_u4(l * fmax(ahi, 0.0)) * S4);
        }
        cs->v += fan, cs->vlo += lo, cs->vhi += hi;
    }
    cs->n += n;
}

/* Add a block under the current plan. */
void ulam__cs_add(ulam__cs *cs, int64_t n, double mean, double m2, double maxabs)
{
    double d = (mean - cs->c) / cs->s, N = (double)n;
    cs_add_sums(cs, n, mean, (fmax(m2, 0.0) / cs->s / cs->s + N * d * d), NAN, NAN, maxabs);
}

/* Add a block with its third and fourth moments under the current plan. */
void ulam__cs_add4(ulam__cs *cs, int64_t n, double mean, double m2, double m3, double m4, double maxabs)
{
    double s = cs->s, d = (mean - cs->c) / s, N = (double)n, M2 = fmax(m2, 0.0) / (s * s), M3 = m3 / (s * s * s);
    double M4 = fmax(m4, 0.0) / (s * s * s * s); /* about the block's mean, then shifted to c: sum (y + d)^k */
    double S2 = M2 + N * d * d, S3 = M3 + 3.0 * d * M2 + N * d * d * d;
    double S4 = M4 + 4.0 * d * M3 + 6.0 * d * d * M2 + N * d * d * d * d;
    cs_add_sums(cs, n, mean, S2, S3, fmax(S4, 0.0), maxabs);
}

/* The sequence's interval. */
void ulam__cs_interval(const ulam__cs *cs, double m, double extra, ulam__stop_ci *ci)
{
    ulam__cs_interval_sides(cs, m, extra, cs_log(), cs_log(), ci);
}

/* The sequence's interval, each side at its own ln(1 / delta_side). */
void ulam__cs_interval_sides(const ulam__cs *cs, double m, double extra, double llo, double lhi, ulam__stop_ci *ci)
{
    *ci = (ulam__stop_ci){.lo = NAN, .hi = NAN, .half = INFINITY, .var_term = INFINITY, .range_term = INFINITY,
                          .bias = extra, .L = fmax(llo, lhi), .k = 0, .kind = ULAM__STOP_NONE};
    if (cs->beyond) {
        ci->kind = ULAM__STOP_BEYOND;
        return;
    }
    if (cs->n < 2 || !(cs->eta > 0) || !isfinite(m) || !(extra >= 0) || !isfinite(extra)) return;
    double c = cs->etax / cs->eta, b = cs->etab / cs->eta + extra;
    ci->var_term = 0.5 * (cs->vlo + cs->vhi) / cs->eta, ci->range_term = ci->L / cs->eta, ci->bias = b;
    ci->lo = fmin(c - (llo + cs->vlo) / cs->eta - b, m), ci->hi = fmax(c + (lhi + cs->vhi) / cs->eta + b, m); /* holding m */
    ci->half = 0.5 * (ci->hi - ci->lo);
    ci->kind = ULAM__STOP_EB;
}

/* The half-width's range term at a bet at its largest. */
double ulam__cs_range_width(double A, double n)
{
    return cs_log() * A / (ULAM__CS_LMAX * n);
}

/* The walks a sequence tuned to target E needs. */
double ulam__cs_walks_needed(double m, double var, double A, double b, double E)
{
    if (!(E > 0)) return 0.0;
    if (A == 0.0) return 0.0;
    double h = E * fabs(m) - b, s = A + fabs(m);
    if (!(fabs(m) > 0) || !isfinite(A) || !(h > 0)) return INFINITY;
    double hx = h / s, vx = fmax(var, 0.0) / s / s, lam = fmin(ULAM__CS_LMAX, hx / (vx + hx));
    double den = lam * hx - cs_psi(lam) * vx;
    return den > 0 ? ceil(fmax(cs_log() / den, 2.0)) : INFINITY;
}

/* The least walks a sequence tuned to E needs at variance var, whatever its range. */
double ulam__cs_var_walks(double m, double var, double E)
{
    if (!(E > 0) || !(var > 0)) return 0.0;
    return fabs(m) > 0 ? 2.0 * cs_log() * var / (E * m * E * m) : INFINITY;
}

/* The further walks that take the half-width to h. */
double ulam__cs_walks_left(const ulam__cs *cs, double mean, double var, double extra, double h)
{
    double L = cs_log(), eta = cs->lam / cs->s, d = (mean - cs->c) / cs->s;
    if (!(h > 0) || cs->beyond || !(eta > 0) || !isfinite(eta)) return INFINITY;
    double b = cs->eta > 0 ? cs->etab / cs->eta : cs->bias, hb = h - fmax(b, cs->bias) - extra;
    if (!(hb > 0)) return INFINITY;
    double v = 0.5 * (cs->vlo + cs->vhi), f = cs->v > 0 ? v / cs->v : 1.0; /* the ends' penalty over Fan's so far */
    if (cs->eta > 0 && (L + v) / cs->eta <= hb) return 0.0;
    double a = f * cs_psi(cs->lam) * (fmax(var, 0.0) / cs->s / cs->s + d * d), den = hb * eta - a; /* per walk */
    return den > 0 ? ceil((L + v - hb * cs->eta) / den) : INFINITY;
}

/* The stitching index j whose delta, delta / (j (j + 1)), is at most K / n times index k's
 * (delta itself at k = 0): the lower ends of the K components ulam_fpush_top (and the partitioned top table) prints (k itself
 * when K >= n, every component).  They are the K largest estimates, chosen after the walks: a
 * component whose true walk part is tiny ranks among them because a walk or two ended at it, and
 * its lower end, valid for a component named in advance, then excludes x_i (the 72.8%
 * coverage at 100 walks, every miss below).  At n K / n the expected number of printed lower
 * ends that miss is at most the sum over all n components of K delta / (2 n), K delta / 2, under
 * any dependence and any selection (Benjamini and Yekutieli's false coverage rate, JASA 2005,
 * for a selection of fixed size K), so the share of printed intervals that miss below is at most
 * delta / 2.  The upper ends keep index k: ranking by a larger estimate only makes a component
 * whose walks ended at it too rarely less likely to be printed (at a fixed count, P(printed | h
 * walks ended at i) rises with h). */
int ulam__stop_lower_index(int k, int64_t K, int64_t n)
{
    if (K >= n) return k;
    double t = (k >= 1 ? (double)k * ((double)k + 1.0) : 1.0) * (double)n / (double)(K > 0 ? K : 1);
    double j = ceil(0.5 * (sqrt(1.0 + 4.0 * t) - 1.0));
    while (j * (j + 1.0) < t) j++;
    return j < 1 ? 1 : (int)j;
}

/* Whether a printed interval meets relative error E. */
int ulam__stop_printed_met(double lo, double hi, double est, double E)
{
    double half = 0.5 * (hi - lo);
    return isfinite(half) && half <= E * fabs(est);
}
