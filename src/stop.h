/* The stopping rule and the printed interval, in one place (internal): every walk solver (the
 * matrix solver src/solve.c, the patch solver src/radiosity/patchwalk.c) asks here what 95%
 * interval its scores give and whether a relative-error target is met.
 *
 * The construction: the empirical-Bernstein bound of Maurer and Pontil ("Empirical Bernstein
 * bounds and sample variance penalization", COLT 2009, Theorem 4, both sides): for n
 * independent scores in an interval of width R, with sample variance V (n - 1 denominator),
 *     |mean - E score| <= sqrt(2 V L / n) + 7 R L / (3 (n - 1)),   L = ln(3 / delta_k),
 * with probability at least 1 - delta_k (two Bernstein tails and the variance's own bound, a
 * third each).  Stitched over the checkpoints a run can stop at: walk counts are grouped in
 * epochs growing by sqrt(2) from ULAM__STOP_N0 (epoch k holds n in (N0 2^((k-2)/2),
 * N0 2^((k-1)/2)]), epoch k gets delta_k = delta / (k (k + 1)) (delta / 2 at the first), so the
 * bounds hold at every epoch at once with probability 1 - delta (sum over k >= 1 of
 * 1 / (k (k + 1)) = 1); the rel_err rule checks once per epoch.  A run with a fixed walk count and
 * no other rule stops at one count known in advance: it takes delta itself (k = 0).
 *
 * R is certified by the caller (a bound on a single score, or the range of walks cut at a
 * length past which they add at most `bias` to the mean, or a second-moment route), as is
 * `bias`, the most the scores' mean can differ from x (truncation, walks cut at max_steps),
 * which widens the interval on both sides.  R = 0 certifies x exactly (nothing that scores is
 * reachable); R infinite gives no interval. */
#ifndef ULAM_STOP_H
#define ULAM_STOP_H

#include <stdint.h>

#define ULAM__STOP_DELTA 0.05 /* 1 - the confidence of every printed interval */
#define ULAM__STOP_N0 1024    /* the first epoch's walks (one block) */
#define ULAM__STOP_TAIL 0.01  /* the largest share of |x| the truncation bias may take (fixed budgets) */
#define ULAM__STOP_TINY (ULAM_SCORE_TINY * ULAM_SCORE_TINY) /* below this largest score^2 a sample's squares are near
                                    the subnormal doubles, its variance may have underflowed to 0: no interval */
#define ULAM__STOP_ROUNDING 1e-9 /* a score at the range's edge, up to the rounding of a walk's weight
                                    products (S / q = 1 computed as 0.9 / 0.9 along many steps), is
                                    inside it: only a score past limit (1 + this) is beyond */

/* What the interval rests on. */
enum {
    ULAM__STOP_NONE = 0,  /* no interval: no certified range (or fewer than 2 walks) */
    ULAM__STOP_EB = 1,    /* the stitched empirical-Bernstein interval */
    ULAM__STOP_EXACT = 2, /* x certified exactly (nothing that scores is reachable): zero width */
    ULAM__STOP_BEYOND = 3 /* no interval: a score beyond the certified range R was seen */
};

/* A 95% interval: [lo, hi], its half-width (half = INFINITY, lo = hi = NaN when none), the
 * terms it is made of, the checkpoint it was taken at and its kind (ULAM__STOP_*). */
typedef struct {
    double lo, hi, half;
    double var_term, range_term, bias;
    double L; /* ln(3 / delta_k) */
    int k, kind;
} ulam__stop_ci;

/* The epoch of n walks (1 for n <= ULAM__STOP_N0). */
int ulam__stop_epoch(int64_t n);

/* L = ln(3 / delta_k) of epoch k >= 1; of a count fixed in advance at k = 0. */
double ulam__stop_log(int k);

/* The interval of n scores with mean `mean`, sample variance `var`, certified range R (the width
 * of an interval holding every score; INFINITY none, 0 exact) and certified bias, at epoch k
 * (0 for a run that stops at a count fixed in advance); maxabs: the largest |score| seen, with
 * half: R / 2 when the scores may take both signs (else R) as the largest |score| the range
 * allows (kind ULAM__STOP_BEYOND past it). */
void ulam__stop_interval(int64_t n, double mean, double var, double R, double bias, double maxabs, double limit, int k,
                         ulam__stop_ci *ci);

/* Whether an interval meets a relative-error target E at estimate m: its variance term at most
 * w = sqrt(2 L) E |m|, the width it has when the standard error is E |m| (so the rule asks
 * stderr <= E |m|, as a CLT rule would), and its whole half-width (variance, range and bias
 * terms) at most 2 w: the range and bias terms take the slack the variance term leaves (so the
 * sample has seen what could still matter); never at m = 0 unless exact. */
int ulam__stop_rel_met(const ulam__stop_ci *ci, double m, double E);

/* The walk count at which a run of sample variance var, range R and bias at estimate m would
 * meet target E at epoch k (the rule of ulam__stop_rel_met: the least n with the variance term
 * at most w and the half-width at most 2 w); 0 with no target, INFINITY when the bias alone
 * reaches 2 w, m = 0 or R infinite. */
double ulam__stop_walks_needed(double m, double var, double R, double bias, double E, int k);

/* The relative target E' that walks must meet so that, with an independent error of relative
 * size f beside theirs (a sampled matrix's), the two combined (in quadrature) meet E:
 * sqrt(E^2 - f^2); 0 when f >= E (no walk count can meet E). */
double ulam__stop_combined_target(double E, double f);


/* The confidence sequence of the matrix solver (src/solve.c): the predictable plug-in
 * empirical-Bernstein sequence of Waudby-Smith and Ramdas ("Estimating means of bounded random
 * variables by betting", JRSS B 2023, Theorem 2), taken a block of walks at a time.  Block q's
 * scores X all lie in [-A_q, A_q] (A_q, the block's limit, and everything below with index q is
 * fixed from blocks 0 .. q-1 alone, before block q is looked at: predictable); with a centre c_q
 * in that interval, s_q = A_q + |c_q| and xi = (X - c_q) / s_q lie in [-1, 1], and for every
 * lambda in [0, 1) (Fan, Grama and Liu 2015) exp(lambda xi - psi(lambda) xi^2) <= 1 + lambda xi,
 * psi(l) = -ln(1 - l) - l.  So for the true mean mu_q of block q's scores both
 *     prod exp(+-lambda_q (X - mu_q) / s_q - psi(lambda_q) xi^2)
 * are nonnegative supermartingales from 1, and by Ville's inequality, with probability
 * 1 - delta at every walk count at once (each side delta / 2),
 *     |sum eta_q (X - mu_q)| <= ln(2 / delta) + sum psi(lambda_q) xi^2,   eta_q = lambda_q / s_q:
 * the interval centre sum eta X / sum eta, half-width (ln(2 / delta) + V) / sum eta, plus the
 * eta-weighted bias bound of the blocks (mu_q within b_q of x: the truncation that set A_q).
 * Valid at every count, so under any stopping rule (walks, time, rel_err) without a union over
 * checkpoints.  lambda_q is tuned to the planned end: with a target half-width h (rel_err) the
 * lambda whose interval first reaches h, lambda = h s / sigma^2 (for psi(l) ~ l^2 / 2); with a
 * planned walk count n (a fixed budget, a time limit), the lambda narrowest at n,
 * sqrt(2 ln(2 / delta) / (sigma_xi^2 n)); never above ULAM__CS_LMAX.  The matrix solver adds its
 * blocks with ulam__cs_add4 (each end's quartic penalty, below Fan's) and plans them with
 * ulam__cs_plan4 (the bets that penalty pays best for).  A block with a score past
 * its A_q makes the sequence withhold the interval from then on (its clipped scores, which the
 * bound is about, are not the ones seen). */
#define ULAM__CS_LMAX 0.75
/* ulam__cs_plan4's cap: the quartic charges a large bet little where the scores sit inside the
 * range (bench_relerr at E = 0.1, 3 seeds: walks/clt 3.91 -> 3.48 on the Laplacian's corner,
 * 21.8 -> 17.1 on convection-diffusion, against 0.75); any cap below 1 keeps lambda a < 1 */
#define ULAM__CS_LMAX4 0.95

typedef struct {
    double eta, etax, v, etab; /* sum eta n, sum eta X, sum psi(lambda) xi^2, sum eta n b */
    double vlo, vhi;           /* the lower and the upper end's penalty sums (each v under ulam__cs_add) */
    int64_t n;
    int beyond;                /* a block had a score past its limit */
    double lam, c, s, limit, bias; /* the plan for the next block */
} ulam__cs;

/* Plan the next block from the blocks so far (n scores, mean, sample variance var): its limit A
 * (every score in [-A, A]), the bias bound b of its scores' mean, and either the target
 * half-width h > 0 or the planned walk count nplan. */
void ulam__cs_plan(ulam__cs *cs, int64_t n, double mean, double var, double A, double b, double h, double nplan);

/* ulam__cs_plan for blocks added by ulam__cs_add4, from the blocks so far with their sums of
 * cubed and fourth-power deviations too (m3, m4; with n, mean and var): the bet that maximises
 * lambda h_xi - pen(lambda) with a target, or minimises (ln(2 / delta) / nplan + pen(lambda)) / lambda
 * with a planned count, pen the two ends' mean quartic penalty a score (its cubes cancel between
 * the ends) at the scores' second and fourth moments about the centre, with the one prior
 * observation at xi^2 = 1/4 (xi^4 = 1/16) as ulam__cs_plan's; ulam__cs_plan's bet is the least
 * of Fan's psi, which the quartic undercuts, so it bet smaller than the quartic pays best for. */
void ulam__cs_plan4(ulam__cs *cs, int64_t n, double mean, double var, double m3, double m4, double A, double b, double h,
                    double nplan);

/* Add a block of n scores (mean, m2 = sum of squared deviations, largest |score| maxabs) under
 * the current plan. */
void ulam__cs_add(ulam__cs *cs, int64_t n, double mean, double m2, double maxabs);

/* ulam__cs_add for a block whose third and fourth central moments are known too (m3, m4: sums of
 * cubed and fourth-power deviations from mean), each end with its own penalty, a quartic in xi in
 * place of psi(lambda) xi^2: for y >= -u (u < 1), ln(1 + y) >= y - y^2 / 2 + y^3 / 3 - psi4(u) (y / u)^4,
 * psi4(u) = -ln(1 - u) - u - u^2 / 2 - u^3 / 3 (the quartic's remainder is largest at the lowest y),
 * so with the scores in [-A, A], xi >= -a_lo for the lower end's bet (a_lo = (c + A) / s) and
 * -xi >= -a_hi for the upper end's (a_hi = (A - c) / s), each end's supermartingale holds with the
 * penalty lambda^2 xi^2 / 2 -+ lambda^3 xi^3 / 3 + psi4(lambda a) xi^4 / a^4 in place of
 * psi(lambda) xi^2.  It is at most psi(lambda a) xi^2 / a^2 <= psi(lambda) xi^2 wherever xi is in
 * range (equal at its end), and near the betting sequence's own ln(1 + lambda xi) where the scores
 * sit well inside their range: Fan's psi(lambda) charged every score as if it were at the range's
 * end. */
void ulam__cs_add4(ulam__cs *cs, int64_t n, double mean, double m2, double m3, double m4, double maxabs);

/* The sequence's 95% interval at estimate m (stretched to hold m), extra bias added on both
 * sides (walks cut at max_steps); kind ULAM__STOP_EB (an interval), ULAM__STOP_BEYOND or
 * ULAM__STOP_NONE (fewer than 2 scores, nothing weighted). */
void ulam__cs_interval(const ulam__cs *cs, double m, double extra, ulam__stop_ci *ci);

/* ulam__cs_interval with the lower end at ln(1 / delta_lo) = llo and the upper at lhi in place of
 * ln(2 / delta) each (Ville's inequality on each side's supermartingale alone: the lower end
 * misses with probability at most delta_lo, the upper at most delta_hi, at every count at once). */
void ulam__cs_interval_sides(const ulam__cs *cs, double m, double extra, double llo, double lhi, ulam__stop_ci *ci);

/* The further walks that take the sequence's half-width to h under its current plan, for scores
 * of mean `mean` and variance var (extra: the bias added at the interval); 0 when it is there,
 * INFINITY when the plan cannot reach it. */
double ulam__cs_walks_left(const ulam__cs *cs, double mean, double var, double extra, double h);

/* The range term ln(2 / delta) A / (ULAM__CS_LMAX n) of the half-width of n scores in [-A, A] under
 * bets at their largest (scores of small variance; about the centre 0): what a block of n scores
 * with limit A adds to the interval at least, for planning. */
double ulam__cs_range_width(double A, double n);

/* The walks at which a sequence tuned to target E at estimate m (variance var, limit A, bias b)
 * reaches half-width E |m|; INFINITY when it cannot (bias too large, m = 0, A infinite). */
double ulam__cs_walks_needed(double m, double var, double A, double b, double E);

/* The least walks a sequence tuned to target E needs at variance var and estimate m, whatever
 * its range and bias: 2 ln(2 / delta) var / (E m)^2 (psi(l) >= l^2 / 2, so no bet does better;
 * 7.4 times the var / (E m)^2 of a rule that asks stderr <= E |m|); INFINITY at m = 0. */
double ulam__cs_var_walks(double m, double var, double E);

/* The Chernoff-Hoeffding interval for the mean of n independent scores in [0, 1] (Hoeffding 1963,
 * Theorem 1: P(mean >= mu + t) <= exp(-n kl(mu + t || mu)), Bernoulli laws being the extreme
 * case; the same below): [lo, hi] = the means q with n kl(m || q) <= ln(2 / delta_k) on each
 * side, delta_k = ULAM__STOP_DELTA / (k (k + 1)) at checkpoint k >= 1 of a run that may stop at
 * any of them (sum 1 / (k (k + 1)) = 1), ULAM__STOP_DELTA itself at k = 0 (a count fixed in
 * advance); sample mean m.  For scores that are mostly 0 with rare hits of one
 * size it is the binomial's own bound (no hit in n: hi = 1 - (delta_k / 2)^(1/n), about
 * 3.7 / n), against the empirical-Bernstein range term 7 L / (3 (n - 1)) (about 9.6 / n). */
void ulam__stop_kl_interval(int64_t n, double m, int k, double *lo, double *hi);

/* Whether a printed interval [lo, hi] meets relative error E around est: finite, and its
 * half-width within E |est| (src/stop.c). */
int ulam__stop_printed_met(double lo, double hi, double est, double E);

/* The stitching index whose delta, delta / (j (j + 1)), is at most K / n times index k's: the
 * lower ends of K components chosen of n by their estimates after the walks (src/stop.c). */
int ulam__stop_lower_index(int k, int64_t K, int64_t n);

#endif /* ULAM_STOP_H */
