/* A walk result as JSON to a caller's stream (include/ulam_report.h): the one home of the
 * schema ulam solve --json prints. */
#include "ulam_report.h"

#include <math.h>

/* Write v, or null when it is not finite. */
static void value(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.17g", v);
    else fputs("null", f);
}

/* Write a member "key": v. */
void ulam_json_number(FILE *f, const char *key, double v, int last)
{
    if (!f) return;
    if (key) fprintf(f, "\"%s\": ", key);
    value(f, v);
    if (key && !last) fputs(", ", f);
}

/* Write a member "key": "v", escaped. */
void ulam_json_string(FILE *f, const char *key, const char *v, int last)
{
    if (!f || !key || !v) return;
    fprintf(f, "\"%s\": \"", key);
    for (const unsigned char *c = (const unsigned char *)v; *c; c++) {
        if (*c == '"' || *c == '\\') fprintf(f, "\\%c", *c);
        else if (*c < 0x20) fprintf(f, "\\u%04x", *c);
        else fputc(*c, f);
    }
    fprintf(f, "\"%s", last ? "" : ", ");
}

/* A verdict on a variance: true, false or null (unknown). */
static void verdict(FILE *f, const char *key, int finite)
{
    fprintf(f, "\"%s\": %s, ", key, finite == 1 ? "true" : finite == 0 ? "false" : "null");
}

/* A radius as prefix (the estimate when converged, else the upper bound), prefix_is,
 * prefix_lower, prefix_upper, prefix_converged. */
static void radius(FILE *f, const char *prefix, const ulam_power *p)
{
    fprintf(f, "\"%s\": ", prefix);
    value(f, p->converged ? p->rho : p->upper);
    fprintf(f, ", \"%s_is\": \"%s\", \"%s_lower\": ", prefix, p->converged ? "estimate" : "upper bound", prefix);
    value(f, p->lower);
    fprintf(f, ", \"%s_upper\": ", prefix);
    value(f, p->upper);
    fprintf(f, ", \"%s_converged\": %s, ", prefix, p->converged ? "true" : "false");
}

/* Why a rel_err run stopped short of its target, as JSON (null: met, or stopped otherwise). */
static const char *rel_err_stop(const ulam_walk_result *r)
{
    return r->cut_stop ? "\"cuts\"" : r->out_of_reach ? "\"out_of_reach\""
           : !isfinite(r->tail_bound) && r->estimate != 0 ? "\"no_bound\""
           : !r->rel_err_met && r->fourth_finite != 1 ? "\"fourth_moment\"" : "null";
}

/* Write the members of a walk result. */
void ulam_walk_result_json(FILE *f, const ulam_walk_opts *o, const ulam_walk_result *r, const ulam_guard *g)
{
    static const char *const modes[] = {"adjoint", "forward"}, *const estimators[] = {"collision", "absorption", "expected"};
    if (!f || !o || !r) return;
    int mode = o->mode == ULAM_FORWARD, est = o->estimator >= 0 && o->estimator < 3 ? o->estimator : 0;
    double rel = r->estimate != 0 ? r->std_error / fabs(r->estimate) : INFINITY;
    ulam_json_number(f, "estimate", r->estimate, 0);
    ulam_json_number(f, "stderr", r->std_error, 0);
    fputs("\"ci95\": ", f);
    if (r->variance_finite == 1) {
        fputc('[', f), value(f, r->ci95[0]), fputs(", ", f), value(f, r->ci95[1]), fputs("], ", f);
    } else {
        fputs("null, ", f);
    }
    verdict(f, "variance_finite", r->variance_finite);
    if (g) radius(f, "rho_abs", &g->abs), radius(f, "rho_hat", &g->hat[mode]);
    ulam_json_number(f, "kernel_alpha", o->kernel.kernel_alpha, 0);
    ulam_json_number(f, "max_share", r->max_share, 0);
    ulam_json_number(f, "score_bound", r->score_bound, 0);
    ulam_json_number(f, "tail_bound", r->tail_bound, 0);
    ulam_json_number(f, "variance_rel_error", r->variance_rel_error, 0);
    if (o->stop.rel_err > 0) {
        ulam_json_number(f, "min_walks", r->min_walks, 0);
        fprintf(f, "\"rel_err_met\": %s, ", r->rel_err_met ? "true" : "false");
        ulam_json_number(f, "cut_bound", r->cut_bound, 0);
        fprintf(f, "\"rel_err_stop\": %s, ", rel_err_stop(r));
        verdict(f, "fourth_finite", r->fourth_finite);
        radius(f, "rho4", &r->rho4);
    }
    if (mode) fprintf(f, "\"unreached\": %lld, ", (long long)r->unreached);
    ulam_json_number(f, "variance", r->variance, 0);
    fprintf(f, "\"walks\": %lld, \"steps\": %lld, \"cut\": %lld, ", (long long)r->walks, (long long)r->steps,
            (long long)r->cut);
    ulam_json_number(f, "mean_length", r->walks ? (double)r->steps / (double)r->walks : 0.0, 0);
    ulam_json_number(f, "seconds", r->seconds, 0);
    ulam_json_number(f, "steps_per_second", r->seconds > 0 ? (double)r->steps / r->seconds : 0.0, 0);
    ulam_json_number(f, "figure_of_merit", r->seconds > 0 && rel > 0 ? 1.0 / (rel * rel * r->seconds) : NAN, 0);
    fprintf(f, "\"method\": \"walks\", \"mode\": \"%s\", \"estimator\": \"%s\", ", modes[mode], estimators[est]);
    fprintf(f, "\"seed\": %llu, \"threads\": %d, ", (unsigned long long)o->exec.seed, r->threads);
}
