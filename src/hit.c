/* A certified upper bound on the probability that a walk scores at all, for a run whose walks
 * have not scored yet.
 *
 * A walk scores only where it can: at a visit to a scoring state (collision, expected), or by
 * ending there (absorption).  Let h_i be the probability that a walk now at i ever scores: with
 * the walk's continuation q_i and moves p_ij (|K_ij|^alpha over the row's sum),
 *     h_i = a_i + c_i sum_j p_ij h_j,
 * a_i = 1, c_i = 0 at a scoring state for collision (it scores there), a_i = 1 - q_i, c_i = q_i
 * there for absorption, and a_i = 0, c_i = q_i elsewhere.  The map F(v) = a + c P v is monotone
 * and F(1) <= 1, so iterating it from v = 1 (here Gauss-Seidel, in place) keeps v >= h at every
 * step (h = F(h) <= F(v) whenever h <= v, and min(v, F(v)) too) while v falls: every iterate is a certified bound, the
 * number of steps only decides how tight.  (It is value iteration from above; the walks'
 * reachable states suffice, since their rows lead nowhere else.)
 *
 * Why it matters (src/solve.c): a score X that is nonzero with probability p has
 * Var X / (E X)^2 >= 1 / p - 1 (Cauchy-Schwarz: (E X)^2 = (E X 1{X != 0})^2 <= E X^2 p), so the
 * rel_err rule, which asks stderr <= E |x|, needs at least (1 / p - 1) / E^2 walks at the true
 * variance.  A run that has seen no score cannot meet its target before a walk scores; with
 * p <= v at its start, it can say so as soon as that count passes its budget or the cap, instead
 * of walking on to the cap. */
#include "hit.h"

#include <math.h>

/* Gauss-Seidel sweeps of v <- a + c P v over the states listed (ascending; v: 1 there on entry,
 * kept between calls), in ascending and descending order by turns (*sweep counts them), at most
 * `sweeps` of them or until one lowers no entry by more than a millionth of itself (then *done);
 * the entries read. */
int64_t ulam__hit_sweeps(const ulam_csr *K, const int64_t *states, int64_t count, double continue_q, double alpha,
                         const char *target, int absorb, double *v, int sweeps, int *sweep, int *done)
{
    int64_t reads = 0;
    for (int it = 0; it < sweeps && !*done; it++, (*sweep)++) {
        double worst = 0.0;
        int down = *sweep & 1;
        for (int64_t t = 0; t < count; t++) {
            int64_t i = states[down ? count - 1 - t : t];
            if (target[i] && !absorb) continue; /* collision: a scoring state scores, v = 1 */
            int64_t a = K->rowptr[i], e = K->rowptr[i + 1];
            double S = 0.0, Sa = 0.0, acc = 0.0;
            for (int64_t k = a; k < e; k++) {
                double w = fabs(K->val[k]), wa = alpha == 1.0 ? w : pow(w, alpha);
                S += w, Sa += wa, acc += wa * v[K->colidx[k]];
            }
            reads += 1 + e - a;
            double q = ulam__continuation(S, continue_q);
            double nv = fmin(v[i], (target[i] ? 1.0 - q : 0.0) + (Sa > 0 ? q * acc / Sa : 0.0)); /* both >= h */
            if (v[i] > 0) worst = fmax(worst, (v[i] - nv) / v[i]);
            v[i] = nv;
        }
        if (!(worst > 1e-6)) *done = 1;
    }
    return reads;
}
