/* The report module's core (its private header src/report.h, which every writer includes): the
 * answer line's column, an interval's digits, a radius in words, --check's z and the rel_err rule's
 * outcome, one home for each; the writers stand above it (report_json.c, report_walk.c, report_bidir.c,
 * report_info.c, report_prepare.c, report_direct.c, report_query.c, report_kind.c's table). */
#include "report.h"

#include <math.h>
#include <string.h>

/* The significant digits that print an interval's ends lo < hi apart: 10, or up to 17 (every
 * double prints as itself) for an interval narrower than 10 digits show (a push taken down to
 * rounding): its ends then do not print as one number. */
int ulam__report_ci_digits(double lo, double hi)
{
    char a[40], b[40];
    int p = 10;
    for (; p < 17 && lo < hi; p++) {
        snprintf(a, sizeof a, "%.*g", p, lo), snprintf(b, sizeof b, "%.*g", p, hi);
        if (strcmp(a, b)) break;
    }
    return p;
}

/* Write " +- H (95% CI lo .. hi)": H the standard error se, or, where a side of the interval is
 * over ULAM__REPORT_PM_WIDE standard errors (a range term leads it: a push's certified residual, a
 * score bound at few walks), that side's width, the standard error then named inside the
 * parentheses: the first line's +- is never far narrower than the interval it stands beside. */
void ulam__report_pm_fprint(FILE *f, double est, double se, double lo, double hi)
{
    int d = ulam__report_ci_digits(lo, hi);
    double h = fmax(hi - est, est - lo);
    if (h > ULAM__REPORT_PM_WIDE * se)
        fprintf(f, " +- %.3g (95%% CI %.*g .. %.*g; standard error %.3g)", h, d, lo, d, hi, se);
    else
        fprintf(f, " +- %.3g (95%% CI %.*g .. %.*g)", se, d, lo, d, hi);
}

/* A radius in words: six decimals from 1e-4 to 1e6 (and 0, inf), six significant digits past them
 * (1e-23 is not 0.000000, 1e99 not a hundred digits); buf holds 32 characters. */
const char *ulam__report_radius_str(char *buf, double x)
{
    double a = fabs(x);
    snprintf(buf, 32, a == 0 || !isfinite(a) || (a >= 1e-4 && a < 1e6) ? "%.6f" : "%.6g", x);
    return buf;
}

/* Write a radius as "0.900000 (bounds [lo, hi], k iterations, s, converged or a bound)". */
void ulam__report_power_fprint(FILE *f, const ulam_power *p)
{
    /* an upper bound below 1 that 6 decimals round to 1.000000 gets the digits that show it
     * (issue 42: "bounds [0.990002, 1.000000]" stood beside "below 1") */
    char r[32], lo[32], hi[40];
    if (p->upper < 1.0 && p->upper >= 0.9999995) snprintf(hi, sizeof hi, "%.17g", p->upper);
    else ulam__report_radius_str(hi, p->upper);
    fprintf(f, "%s (bounds [%s, %s], %d iterations, %.3f s%s)", ulam__report_radius_str(r, p->rho),
            ulam__report_radius_str(lo, p->lower), hi, p->iterations, p->seconds,
            p->converged ? "" : p->iterations == 0 ? ", certified by row/column sums; the value is not an estimate"
                                                   : ", NOT converged: only the bounds are certain");
}

/* The spaces after "x[index]" (1-based) that put the value at the given column, the one of the
 * lines below it (16 under "method          "); at least 1. */
int ulam__report_pad(const char *name, int64_t index, int column)
{
    char label[64];
    int len = snprintf(label, sizeof label, "%.40s[%lld]", name, (long long)index);
    return len < column ? column - len : 1;
}

/* --check's z = (estimate - direct) / stderr: 0 when they are equal, +-inf when only the stderr
 * is 0. */
double ulam__report_z(double estimate, double direct, double std_error)
{
    double d = estimate - direct;
    return std_error > 0 ? d / std_error : d == 0 ? 0.0 : copysign(INFINITY, d);
}

/* The --check line's tail: "z = Z" (ulam__report_z), and when |z| > 4 whether direct is inside [lo, hi]
 * (an interval wider than the stderr says: a range term, or the allowance for rounding). */
void ulam__report_z_fprint(FILE *f, double estimate, double direct, double std_error, double lo, double hi)
{
    double z = ulam__report_z(estimate, direct, std_error);
    fprintf(f, "z = %.3f", z);
    if (fabs(z) > 4.0 && lo <= direct && direct <= hi) /* newuser18: z = 17043 beside a push's certified range */
        fprintf(f, " (direct inside the 95%% interval: z counts the standard error alone, the interval also its range terms)");
    else if (fabs(z) > 4.0) fprintf(f, " (direct OUTSIDE the 95%% interval)");
    fputc('\n', f);
}

/* An estimator's name, as the options table spells it. */
const char *ulam__report_estimator_name(int estimator)
{
    static const char *const names[] = {"collision", "absorption", "expected"};
    return estimator >= 0 && estimator < 3 ? names[estimator] : "?";
}

/* A walk mode's name. */
const char *ulam__report_mode_name(int mode)
{
    return mode == ULAM_FORWARD ? "forward" : "adjoint";
}

/* Nonzero when the interval was withheld because the scores are too small to square (a b far
 * below 1 that the solver could not rescale: a prepared file's, read lazily; src/stop.h). */
int ulam__report_score_too_small(const ulam_walk_result *r)
{
    return r->estimate != 0 && fabs(r->estimate) < ULAM_SCORE_TINY && r->std_error == 0 && isnan(r->ci95[0]);
}

/* Print whether the --rel-err target was met, and when not why (one line; nothing without a target). */
void ulam__report_rel_err_fprint(FILE *f, const ulam_walk_opts *o, const ulam_walk_result *r, int verbose)
{
    if (o->stop.rel_err > 0 && r->cut_stop)
        fprintf(f, "rel-err         NOT met (target %.3g): %lld walks were cut at %lld steps and the cut's bias may be "
               "%.3g, more than a tenth of the target error: unreachable by more walks (raise --max-steps)\n",
               o->stop.rel_err, (long long)r->cut, (long long)o->stop.max_steps, r->cut_bound);
    else if (o->stop.rel_err > 0 && !isfinite(r->tail_bound) && r->estimate != 0)
        fprintf(f, "rel-err         NOT met (target %.3g; no bound on a single score: no walk count can certify it)\n",
               o->stop.rel_err);
    else if (o->stop.rel_err > 0 && r->out_of_reach && !isfinite(r->ci95[0]) &&
             !(r->min_walks > (o->stop.max_walks > 0 ? (double)o->stop.max_walks : (double)ULAM_REL_ERR_CAP)))
        fprintf(f, "rel-err         NOT met (target %.3g): %s, so no interval can be "
               "printed; stopped after %lld walks, over 1024 times the %.4g the rule asked for\n", o->stop.rel_err,
               ulam__report_score_too_small(r) ? "the scores are too small to square in doubles (scale b up)" : "a score passed the certified range",
               (long long)r->walks, r->min_walks);
    else if (o->stop.rel_err > 0 && r->estimate == 0 && r->out_of_reach && r->min_walks > 0 && isfinite(r->min_walks))
        fprintf(f, "rel-err         NOT met (target %.3g): no walk has scored in %lld; a walk scores at all with probability "
               "at most %.3g (certified from where it can go), so the rule asks for at least %.4g walks, %s: stopped "
               "early, %s\n", o->stop.rel_err, (long long)r->walks,
               1.0 / (1.0 + r->min_walks * o->stop.rel_err * o->stop.rel_err), r->min_walks,
               o->stop.max_walks > 0 ? "more than --walks" : "beyond the 1e9 cap",
               isfinite(r->ci95[0]) ? "the interval above" : "the estimate so far above");
    else if (o->stop.rel_err > 0 && r->fourth_finite != 1 && (verbose || !r->rel_err_met))
        fprintf(f, "rel-err         %s (target %.3g; the certified second moment asks for %.4g walks at this estimate): "
               "scores are unbounded and rho(M4) is in [%.4g, %.4g], so the fourth moment is %s and the rule does "
               "not use the variance's own error bar\n", r->rel_err_met ? "met" : "NOT met", o->stop.rel_err, r->min_walks,
               r->rho4.lower, r->rho4.upper, r->fourth_finite == 0 ? "infinite" : "not certified finite");
    else if (o->stop.rel_err > 0 && r->min_walks > 0 && (verbose || !r->rel_err_met))
        fprintf(f, "rel-err         %s (target %.3g; the rule asks for %.4g walks at this estimate and variance%s)\n",
               r->rel_err_met ? "met" : "NOT met", o->stop.rel_err, r->min_walks,
               !r->out_of_reach ? (o->stop.max_walks > 0 && !r->rel_err_met && r->min_walks > (double)o->stop.max_walks
                                       ? ", more than --walks: the interval above is the budget's" : "")
               : o->stop.max_walks > 0 ? ", more than --walks: stopped early, the estimate so far above"
                                                        : ", beyond the 1e9 cap: stopped early, the estimate so far above");
    else if (o->stop.rel_err > 0)
        fprintf(f, "rel-err         %s (target %.3g)\n", r->rel_err_met ? "met" : "NOT met", o->stop.rel_err);
}
