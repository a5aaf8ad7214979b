/* A walk result as JSON to a caller's stream (include/ulam_report.h): the one home of the
 * schema ulam solve --json prints; an outer iteration's report, text or JSON. */
#include "ulam_report.h"
#include "report.h"

#include <math.h>
#include <string.h>

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

/* A verdict on a variance: true, false or null (unknown) (report.h). */
void ulam__report_verdict_json(FILE *f, const char *key, int finite)
{
    fprintf(f, "\"%s\": %s, ", key, finite == 1 ? "true" : finite == 0 ? "false" : "null");
}

/* A radius as prefix (the estimate when converged, else the upper bound), prefix_is,
 * prefix_lower, prefix_upper, prefix_converged. */
void ulam__report_radius_json(FILE *f, const char *prefix, const ulam_power *p)
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
    ulam__report_verdict_json(f, "variance_finite", r->variance_finite);
    if (g) ulam__report_radius_json(f, "rho_abs", &g->abs), ulam__report_radius_json(f, "rho_hat", &g->hat[mode]);
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
        ulam__report_verdict_json(f, "fourth_finite", r->fourth_finite);
        ulam__report_radius_json(f, "rho4", &r->rho4);
    }
    if (mode) {
        fprintf(f, "\"unreached\": %lld, \"push_sweeps\": %d, \"push_ops\": %lld, ", (long long)r->unreached,
                r->push_sweeps, (long long)r->push_ops);
        ulam_json_number(f, "push_residual", r->push_residual, 0);
    }
    ulam_json_number(f, "variance", r->variance, 0);
    fprintf(f, "\"walks\": %lld, \"steps\": %lld, \"cut\": %lld, ", (long long)r->walks, (long long)r->steps,
            (long long)r->cut);
    ulam_json_number(f, "mean_length", r->walks ? (double)r->steps / (double)r->walks : 0.0, 0);
    ulam_json_number(f, "seconds", r->seconds, 0);
    ulam_json_number(f, "steps_per_second", r->seconds > 0 ? (double)r->steps / r->seconds : 0.0, 0);
    ulam_json_number(f, "figure_of_merit", r->seconds > 0 && rel > 0 ? 1.0 / (rel * rel * r->seconds) : NAN, 0);
    fprintf(f, "\"method\": \"walks\", \"mode\": \"%s\", \"estimator\": \"%s\", ", ulam__report_mode_name(mode), ulam__report_estimator_name(est));
    fprintf(f, "\"seed\": %llu, \"threads\": %d, ", (unsigned long long)o->exec.seed, r->threads);
}

/* A continuation in words. */
static void print_q(FILE *f, double q)
{
    if (q > 0) fprintf(f, "Q = %-6.3g", q);
    else fputs("analog    ", f);
}

/* What became of a candidate, in words (JSON "state"). */
static const char *const state_names[] = {"uncertified", "refused", "skipped", "dropped", "finalist", "chosen"};

/* The pilots' share of the whole estimate's predicted work (NaN when not predicted). */
static double pilot_share(const ulam_auto_result *res)
{
    if (res->chosen < 0) return NAN;
    double run = res->cand[res->chosen].predicted_work, over = res->pilot_work - res->reused_work;
    return isfinite(run) ? over / (over + res->reused_work + run) : NAN;
}

/* The candidates and the choice, as text (verbose: every candidate). */
static void choice_text(FILE *f, const ulam_choice *ch, int bidir, int verbose)
{
    const ulam_auto_result *res = &ch->walks;
    const ulam_method_verdict *v = &ch->method[ULAM_METHOD_BIDIRECTIONAL];
    int bstate = bidir ? v->state : 0;
    if (!verbose) { /* one line: what was chosen among how many; --verbose lists them */
        if (bstate == ULAM_METHOD_CHOSEN)
            fprintf(f, "auto            chose bidirectional over %d walk candidates (--verbose lists them)\n", res->ncand);
        else if (res->chosen >= 0)
            fprintf(f, "auto            chose it among %d candidates by predicted cost (--verbose lists them)\n", res->ncand);
        else
            fprintf(f, "auto            no certified candidate among %d: ran the closest (--verbose lists them)\n",
                   res->ncand);
        return;
    }
    if (bstate == ULAM_METHOD_CHOSEN)
        fprintf(f, "auto            chose bidirectional: its predicted work %.3g units is below the walk leader's %.3g "
               "(%d walk candidates after %d pilot stage%s; guards and pilots %.3f s)\n", v->predicted_work, ch->leader_work,
               res->ncand, res->stages, res->stages == 1 ? "" : "s", res->seconds);
    else if (res->chosen >= 0) {
        char share[96] = "no predicted work to compare the pilots with"; /* a chosen run that predicts nothing */
        if (isfinite(pilot_share(res)))
            snprintf(share, sizeof share, "the pilots' overhead is %.3g%% of the predicted work", 100 * pilot_share(res));
        fprintf(f, "auto            chose the least predicted %s of %d candidates after %d pilot stage%s; %s (guards and "
               "pilots %.3f s); the estimate is from fresh walks\n", res->by_work ? "work" : "variance x work a walk",
               res->ncand, res->stages, res->stages == 1 ? "" : "s", share, res->seconds);
    }
    else
        fprintf(f, "auto            no certified candidate among %d: ran the closest\n", res->ncand);
    for (int k = 0; k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        fprintf(f, "  %c %-8s %-10s ", k == res->chosen && !(bstate == ULAM_METHOD_CHOSEN) ? '*' : ' ', ulam__report_mode_name(c->mode), ulam__report_estimator_name(c->estimator));
        print_q(f, c->continue_q);
        fprintf(f, " alpha %-3.3g", c->kernel_alpha);
        if (isfinite(c->hat.upper)) fprintf(f, " rho(M^) %-9.4g ", c->hat.rho);
        else fprintf(f, " rho(M^) %-9s ", "-");
        if (c->state == ULAM_AUTO_SKIPPED) fprintf(f, "not piloted: starting its kernel would pass the pilot budget\n");
        else if (!c->certified) fprintf(f, "not certified finite (upper bound %.4g)\n", c->hat.upper);
        else if (c->state == ULAM_AUTO_REFUSED) fprintf(f, "refused: %s\n", ulam_strerror(c->status));
        else
            fprintf(f, "pilots %lld walks  variance %-9.4g (+-%.0f%%) %.3g steps/walk  predicted %s%.4g walks, %.3g units "
                   "(%.2g s)%s\n", (long long)c->pilot_walks, c->variance, 100 * fmin(c->variance_rel_error, 99.99),
                   c->steps_per_walk, c->predicted_lower ? ">= " : "", c->predicted_walks,
                   c->predicted_work, c->predicted_seconds,
                   c->state == ULAM_AUTO_DROPPED ? "  dropped" : "");
    }
    if (!bidir) return;
    /* a plan whose pilot does not resolve |x| has no predicted work, only its plan's lower bound */
    int lower = isnan(v->predicted_work) && isfinite(ch->bidir.predicted_work);
    fprintf(f, "  %c bidirectional (reverse push, walks from b) ", bstate == ULAM_METHOD_CHOSEN ? '*' : ' ');
    if (bstate)
        fprintf(f, "rmax %.3g  push %lld ops  pilot %lld walks  predicted %s%.4g walks, %.3g units%s%s\n", ch->bidir.rmax,
               (long long)ch->bidir.push.ops, (long long)ch->bidir.pilot_walks, lower ? ">= " : "", ch->bidir.predicted_walks,
               lower ? ch->bidir.predicted_work : v->predicted_work,
               bstate == ULAM_METHOD_CHOSEN ? "" : "  ", bstate == ULAM_METHOD_CHOSEN ? "" : v->why);
    else
        fprintf(f, "%s\n", v->why);
}

/* The candidates and the choice, as the JSON member "auto" (followed by ", "). */
static void choice_json(FILE *f, const ulam_choice *ch, int bidir)
{
    const ulam_auto_result *res = &ch->walks;
    const ulam_method_verdict *v = &ch->method[ULAM_METHOD_BIDIRECTIONAL];
    int bstate = bidir ? v->state : 0;
    /* 1-based positions in "candidates", as every index a user sees (0: none) */
    fprintf(f, "\"auto\": {\"chosen\": %d, \"closest\": %d, \"stages\": %d, ",
           (bstate == ULAM_METHOD_CHOSEN ? res->ncand : res->chosen) + 1, res->closest + 1, res->stages);
    ulam_json_number(f, "seconds", res->seconds, 0);
    ulam_json_number(f, "pilot_work", res->pilot_work, 0);
    ulam_json_number(f, "reused_work", res->reused_work, 0);
    ulam_json_number(f, "pilot_share", pilot_share(res), 0);
    fprintf(f, "\"candidates\": [");
    for (int k = 0; k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        fprintf(f, "%s{", k ? ", " : "");
        ulam_json_string(f, "mode", ulam__report_mode_name(c->mode), 0);
        ulam_json_string(f, "estimator", ulam__report_estimator_name(c->estimator), 0);
        ulam_json_number(f, "continue", c->continue_q > 0 ? c->continue_q : NAN, 0);
        ulam_json_number(f, "kernel_alpha", c->kernel_alpha, 0);
        ulam_json_number(f, "rho_hat", isfinite(c->hat.upper) ? c->hat.rho : NAN, 0);
        ulam_json_number(f, "rho_hat_upper", c->hat.upper, 0);
        fprintf(f, "\"certified\": %s, ", c->certified ? "true" : "false");
        ulam_json_string(f, "state", state_names[c->state == ULAM_AUTO_CHOSEN && bstate == ULAM_METHOD_CHOSEN ? ULAM_AUTO_FINALIST : c->state], 0);
        ulam_json_string(f, "status", c->status ? ulam_strerror(c->status) : "ok", 0);
        fprintf(f, "\"pilot_walks\": %lld, ", (long long)c->pilot_walks);
        ulam_json_number(f, "variance", c->pilot_walks ? c->variance : NAN, 0);
        ulam_json_number(f, "variance_rel_error", c->pilot_walks ? c->variance_rel_error : NAN, 0);
        ulam_json_number(f, "steps_per_walk", c->pilot_walks ? c->steps_per_walk : NAN, 0);
        ulam_json_number(f, "work_per_walk", c->pilot_walks ? c->work_per_walk : NAN, 0);
        ulam_json_number(f, "cost", c->cost, 0);
        ulam_json_number(f, "predicted_walks", c->predicted_walks, 0);
        fprintf(f, "\"predicted_is\": \"%s\", ", c->predicted_lower ? "lower bound" : "estimate");
        ulam_json_number(f, "predicted_work", c->predicted_work, 0);
        ulam_json_number(f, "predicted_seconds", c->predicted_seconds, 1);
        fprintf(f, "}");
    }
    if (bstate) { /* planned: the last entry (chosen: index ncand) */
        fprintf(f, "%s{", res->ncand ? ", " : "");
        ulam_json_string(f, "mode", "bidirectional", 0);
        ulam_json_string(f, "state", bstate == ULAM_METHOD_CHOSEN ? "chosen" : bstate == 1 ? "planned" : "not_considered", 0);
        ulam_json_number(f, "rmax", bstate ? ch->bidir.rmax : NAN, 0);
        fprintf(f, "\"push_ops\": %lld, \"push_krylov\": %lld, \"pilot_walks\": %lld, ",
                (long long)(bstate ? ch->bidir.push.ops : 0), (long long)(bstate ? ch->bidir.push.krylov : 0),
                (long long)(bstate ? ch->bidir.pilot_walks : 0));
        ulam_json_number(f, "predicted_walks", bstate ? ch->bidir.predicted_walks : NAN, 0);
        ulam_json_number(f, "predicted_work", v->predicted_work, 0);
        ulam_json_number(f, "leader_work", ch->leader_work, 1);
        fprintf(f, "}");
    }
    fprintf(f, "]");
    if (bidir) { /* why bidirectional was not chosen, in one line (null: it was) */
        fprintf(f, ", ");
        if (bstate == ULAM_METHOD_CHOSEN) fprintf(f, "\"bidirectional\": null");
        else ulam_json_string(f, "bidirectional", v->why, 1);
    }
    fprintf(f, "}, ");
}

/* Print the choice as text or JSON. */
void ulam_choice_fprint(FILE *f, const ulam_choice *ch, int bidir, int format)
{
    if (!f || !ch) return;
    if (format == ULAM_REPORT_JSON) choice_json(f, ch, bidir);
    else choice_text(f, ch, bidir, format == ULAM_REPORT_VERBOSE);
}

/* See ulam_report.h. */
const char *ulam_verdict_word(int verdict)
{
    switch (verdict) {
    case ULAM_VERDICT_OK: return "below 1";
    case ULAM_VERDICT_EDGE: return "below 1, not certified below 0.99";
    case ULAM_VERDICT_FAIL: return "at or above 1";
    default: return "unknown: the bounds straddle 1";
    }
}

/* Sum of the steps' histories and walk seconds. */
static void totals(const ulam_outer_report *p, int64_t *hist, double *walk_s)
{
    *hist = 0, *walk_s = 0;
    for (int k = 0; p->steps && k < p->nsteps; k++) *hist += p->steps[k].histories, *walk_s += p->steps[k].walk_seconds;
}

/* The outcome in words. */
static const char *outcome(const ulam_outer_report *p)
{
    return p->converged ? "converged" : p->status == ULAM_ESTALL ? "stalled" : p->status == ULAM_ENOCONV ? "capped"
                                      : p->status == ULAM_OK    ? "interrupted" : "failed";
}

/* The text report's totals. */
static void print_text(FILE *f, const ulam_outer_report *p, int quiet)
{
    int walks = p->method == ULAM_METHOD_SEQUENTIAL || p->method == ULAM_METHOD_MCSA;
    int krylov = p->method == ULAM_METHOD_CG || p->method == ULAM_METHOD_GMRES;
    int64_t hist;
    double walk_s;
    totals(p, &hist, &walk_s);
    if (p->index && p->x) { /* the answer first, with its certified range */
        fprintf(f, "x[%lld]%*s%.12g", (long long)p->index, ulam__report_pad(p->answer_name ? p->answer_name : "x", p->index, 16), "", p->x[p->index - 1]);
        if (p->lo && p->hi) fprintf(f, " (certified range %.10g .. %.10g)", p->lo[p->index - 1], p->hi[p->index - 1]);
        fprintf(f, "\n");
    }
    if (quiet && p->index && p->x) return; /* --quiet: the answer line */
    fprintf(f, "method          %s%s%s, tol %g%s\n", ulam_method_name(p->method), walks ? ", " : "",
            walks ? ulam__report_estimator_name(p->estimator) : "", p->tol, walks ? "" : " (no walks)");
    if (p->method == ULAM_METHOD_GMRES) fprintf(f, "restart         %d\n", p->restart);
    fprintf(f, "outcome         %s after %d iterations%s, residual %.4e\n", outcome(p), p->iterations,
            krylov ? " (matrix-vector products)" : "", p->residual);
    if (walks)
        fprintf(f, "histories       %lld (%.4g per iteration), eps1 %g, corrections rejected %d\n", (long long)hist,
                p->nsteps ? (double)hist / p->nsteps : 0.0, p->eps1, p->rejected);
    fprintf(f, "seconds         %.4f (walks %.4f)\n", p->seconds, walk_s);
    if (walks)
        fprintf(f, "guards          rho(|M|) %.6g (%s), rho(M^) %.6g (%s)\n", p->g.abs.rho,
                ulam_verdict_word(p->g.verdict_abs), p->g.hat[ULAM_FORWARD].rho,
                ulam_verdict_word(p->g.verdict_hat[ULAM_FORWARD]));
    if (p->lo && p->hi)
        fprintf(f, "range           every x_i within %.3g of x (certified from x's residual, no sampling)\n", p->worst);
}

/* The JSON object with the history. */
static void print_json(FILE *f, const ulam_outer_report *p)
{
    int walks = p->method == ULAM_METHOD_SEQUENTIAL || p->method == ULAM_METHOD_MCSA;
    int64_t hist;
    double walk_s;
    totals(p, &hist, &walk_s);
    fprintf(f, "{");
    ulam_json_string(f, "method", ulam_method_name(p->method), 0);
    if (walks) ulam_json_string(f, "estimator", ulam__report_estimator_name(p->estimator), 0);
    ulam_json_string(f, "outcome", outcome(p), 0);
    fprintf(f, "\"converged\": %s, \"iterations\": %d, ", p->converged ? "true" : "false", p->iterations);
    if (p->method == ULAM_METHOD_GMRES) fprintf(f, "\"restart\": %d, ", p->restart);
    ulam_json_number(f, "tol", p->tol, 0);
    ulam_json_number(f, "eps1", p->eps1, 0);
    ulam_json_number(f, "residual", p->residual, 0);
    fprintf(f, "\"histories\": %lld, ", (long long)hist);
    if (walks) fprintf(f, "\"rejected\": %d, ", p->rejected);
    ulam_json_number(f, "seconds", p->seconds, 0);
    ulam_json_number(f, "walk_seconds", walk_s, 0);
    if (walks) {
        ulam_json_number(f, "rho_abs", p->g.abs.rho, 0);
        ulam_json_number(f, "rho_hat", p->g.hat[ULAM_FORWARD].rho, 0);
    }
    if (p->index && p->x) {
        fprintf(f, "\"index\": %lld, ", (long long)p->index);
        ulam_json_number(f, "estimate", p->x[p->index - 1], 0);
        if (p->lo && p->hi)
            fprintf(f, "\"certified_range\": [%.17g, %.17g], ", p->lo[p->index - 1], p->hi[p->index - 1]);
    }
    if (p->lo && p->hi) ulam_json_number(f, "certified_half_width", p->worst, 0);
    if (p->check) ulam_json_number(f, "relative_error", p->err_direct, 0);
    fprintf(f, "\"seed\": %llu, \"threads\": %d, \"ranks\": %d, \"history\": [", (unsigned long long)p->seed, p->threads,
            p->ranks);
    for (int k = 0; p->steps && k < p->nsteps; k++) {
        const ulam_outer_step *s = &p->steps[k];
        fprintf(f, "%s{\"iteration\": %d, ", k ? ", " : "", s->iteration);
        ulam_json_number(f, "residual", s->residual, 0);
        fprintf(f, "\"histories\": %lld, \"steps\": %lld, \"cut\": %lld, ", (long long)s->histories, (long long)s->steps,
                (long long)s->cut);
        ulam_json_number(f, "rel_sd", s->histories ? s->rel_sd : NAN, 0);
        ulam_json_number(f, "walk_seconds", s->walk_seconds, 0);
        ulam_json_number(f, "seconds", s->seconds, 1);
        fprintf(f, "}");
    }
    fprintf(f, "]}\n");
}

/* See ulam_report.h. */
void ulam_outer_report_fprint(FILE *f, const ulam_outer_report *r, int format)
{
    if (!f || !r || r->method < ULAM_METHOD_RICHARDSON || r->method > ULAM_METHOD_GMRES || r->estimator < 0 ||
        r->estimator > 2)
        return;
    if (format == ULAM_REPORT_JSON) print_json(f, r);
    else print_text(f, r, format == ULAM_REPORT_QUIET);
}
