/* The collision-absorption law of the lecture notes: for a forward analog walk counting
 * particles at state j, collision has no larger variance than absorption iff
 * p*_j <= s / (2 - s), s the probability that a walk at j never returns to j.
 *
 * The chains: j = state 1 is the source (b = e_1); from j a walk ends with probability p*,
 * else moves to one of 3 other states, each of which returns to j with probability c and
 * ends otherwise, so s = p* + (1 - p*)(1 - c).  Visits to j are geometric, hence the exact
 * variances (law_variances in law.h)
 *     Var(collision) = (1 - s) / s^2,      Var(absorption) = 1 / (p* s) - 1 / s^2,
 * and s itself is also computed from hitting probabilities by a linear solve
 * (law_noreturn) as a check.  For s = 0.2, 0.5, 0.8, p* sweeps (0, s) across the
 * boundary; each point is measured with 2 10^5 forward walks of each estimator.
 *
 *   law [OUTDIR]    writes OUTDIR/law.csv and OUTDIR/law.png */
#include <math.h>
#include <stdio.h>

#include "chart.h"
#include "law.h"
#include "systems.h"

/* M = P' for the chain above (forward walks step on the rows of M' = P). */
static ulam_csr *law_chain(double pstar, double c)
{
    int32_t i[6], j[6];
    double x[6];
    for (int k = 0; k < 3; k++) {
        i[k] = k + 1, j[k] = 0, x[k] = (1 - pstar) / 3; /* P_{0,k+1}, stored transposed */
        i[3 + k] = 0, j[3 + k] = k + 1, x[3 + k] = c;   /* P_{k+1,0} */
    }
    ulam_csr *M = NULL;
    ulam_csr_from_triplets(4, 4, 6, i, j, x, &M);
    return M;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "docs";
    const double ss[3] = {0.2, 0.5, 0.8}, fr[] = {0.15, 0.3, 0.5, 0.7, 0.85, 1.0, 1.15, 1.3, 1.5, 1.7, 1.9};
    double b[4] = {1, 0, 0, 0};
    out_file o;
    out_open(&o, dir, "law.csv");
    fprintf(o.f, "s,pstar,boundary,x,exact_collision,exact_absorption,measured_collision,measured_absorption,s_solved\n");
    for (int a = 0; a < 3; a++)
        for (size_t k = 0; k < sizeof fr / sizeof *fr; k++) {
            double s = ss[a], bnd = s / (2 - s), ps = fr[k] * bnd;
            if (ps >= s) continue;
            double c = 1 - (s - ps) / (1 - ps), vc, va, s2 = NAN, ps2 = NAN, v[2];
            ulam_csr *M = law_chain(ps, c);
            law_variances(ps, s, &vc, &va);
            law_noreturn(M, 0, &s2, &ps2);
            for (int est = ULAM_COLLISION; est <= ULAM_ABSORPTION; est++) {
                ulam_walk_opts wo = ulam_walk_defaults();
                wo.mode = ULAM_FORWARD, wo.estimator = est, wo.stop.max_walks = 200000, wo.exec.seed = 17 + k;
                v[est] = walk(M, b, &wo).variance;
            }
            fprintf(o.f, "%g,%g,%g,%g,%g,%g,%g,%g,%.15g\n", s, ps, bnd, fr[k], vc, va, v[0], v[1], s2);
            ulam_csr_free(M);
        }
    out_commit(&o);
    chart_draw(dir, "law", 800, 520,
               "set title 'Collision vs absorption (forward walk counting at its start state j)'\n"
               "set logscale y\nset xlabel 'p*_j / (s/(2 - s))   (the law predicts the crossover at 1)'\n"
               "set ylabel 'Var(collision) / Var(absorption)'\nset key top right\nset arrow from 1, graph 0 to 1, graph 1 nohead dt 2\n"
               "S = '0.2 0.5 0.8'\n"
               "plot for [i = 1:3] 'law.csv' u ($1 == word(S, i) ? $4 : 1/0):($5/$6) w l lw 2 lc i t 'exact, s = '.word(S, i), "
               "for [i = 1:3] '' u ($1 == word(S, i) ? $4 : 1/0):($7/$8) w p pt 7 ps 1.2 lc i t 'measured, s = '.word(S, i), "
               "1 dt 3 lc 'black' t ''\n");
    return 0;
}
