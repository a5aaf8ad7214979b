/* A bidirectional solve's report to a caller's stream (include/ulam_report.h): the one home of
 * what ulam solve --source/--rhs --method bidirectional prints (text and JSON), and of the
 * single-source table (--source S without --index, PageRank's top K). */
#include "ulam_report.h"
#include "report.h"

#include <math.h>
#include <string.h>

/* The 1-based number a 0-based state is shown as. */
static long long node(const ulam_bidir_report *p, int64_t i)
{
    return (long long)(i + p->node_base);
}

/* --check's method, "LU" when not named. */
static const char *direct_method(const ulam_bidir_report *p)
{
    return p->direct_method ? p->direct_method : "LU";
}

/* PageRank's line: what pi is of x and what the personalisation is (source: 1-based, 0 none). */
static void pagerank_line(FILE *f, const ulam_bidir_report *p, int64_t source)
{
    double a = p->pagerank;
    char who[200];
    if (p->seeds) snprintf(who, sizeof who, "the seeds %.120s", p->seeds);
    else if (source) snprintf(who, sizeof who, "e_%lld (source %lld)", node(p, source - 1), node(p, source - 1));
    else snprintf(who, sizeof who, "uniform (global PageRank)");
    fprintf(f, "pagerank        pi = (1 - %.10g) x, x of (I - %.10g P^T) x = s, s %s; dangling nodes' rank leaks (no "
               "teleport): pi sums to 1 - the leak\n", a, a, who); /* 0.9999999 shown, not 1 */
}

/* --check's line: the direct value, its method and seconds, and z. */
static void check_line(FILE *f, const ulam_bidir_report *p)
{
    const ulam_bidir_result *r = p->result;
    fprintf(f, "direct          %.10g (%s, %.3g s), ", p->direct, direct_method(p), p->direct_seconds);
    ulam__report_z_fprint(f, r->estimate, p->direct, r->std_error, r->ci95[0], r->ci95[1]);
}

/* The answer line: x[t] = estimate +- stderr and its interval, or why there is none. */
static void answer_line(FILE *f, const ulam_bidir_report *p)
{
    const ulam_bidir_opts *o = p->opts;
    const ulam_bidir_result *r = p->result;
    const char *name = p->answer_name ? p->answer_name : "x";
    const char *stop = r->walks.interrupted ? "  [INTERRUPTED]" : "";
    long long t = node(p, o->target);
    int pad = ulam__report_pad(name, t, 16);
    if (isfinite(r->ci95[0]) && isfinite(r->ci95[1])) {
        fprintf(f, "%s[%lld]%*s%.10g", name, t, pad, "", r->estimate);
        ulam__report_pm_fprint(f, r->estimate, r->std_error, r->ci95[0], r->ci95[1]);
        fprintf(f, "%s\n", stop);
    } else {
        fprintf(f, "%s[%lld]%*s%.10g +- %.3g (no confidence interval: %s)%s\n", name, t, pad, "", r->estimate,
                r->std_error, r->walks.variance > 0 ? "no certified range of the walk part's score"
                                                    : "no walk scored, and no bound certifies the part they missed",
                stop);
    }
}

/* The push on b's lines (the library pushed b and walked from t: src/bpush.c). */
static void dense_text(FILE *f, const ulam_bidir_report *p)
{
    const ulam_bidir_opts *o = p->opts;
    const ulam_bidir_result *r = p->result;
    const ulam_walk_result *w = &r->walks;
    fprintf(f, "method          bidirectional, the push on b: then %s walks from %lld scoring its residual\n",
            ulam__report_estimator_name(o->walk.estimator), node(p, o->target));
    if (r->push.krylov > 0) /* a Krylov start (src/bkrylov.c): q from CG, then the push */
        fprintf(f, "push            q from %lld conjugate-gradient products, then rmax %.3g: %lld operations; q_%lld = "
                   "%.10g exact; residual max %.3g (b's was %.3g)\n",
                (long long)r->push.krylov, r->push.rmax, (long long)r->push.ops, node(p, o->target), r->push_part,
                r->push.r_max, r->plan.rmax > 0 ? p->bmax : NAN);
    else
        fprintf(f, "push            rmax %.3g: %lld operations; q_%lld = %.10g exact; residual max %.3g (b's was %.3g)\n",
                r->push.rmax, (long long)r->push.ops, node(p, o->target), r->push_part, r->push.r_max,
                r->plan.rmax > 0 ? p->bmax : NAN);
    fprintf(f, "walks           %lld (%lld cut, %lld steps, %d threads); a pilot of %lld walks predicted %.3g\n",
            (long long)w->walks, (long long)w->cut, (long long)w->steps, w->threads, (long long)r->plan.pilot_walks,
            r->plan.predicted_walks);
    fprintf(f, "seconds         %.4f (push and pilot %.4f, walks %.4f, seed %llu); transpose %.3f s\n", r->seconds,
            r->plan.seconds, w->seconds, (unsigned long long)o->walk.exec.seed, p->transpose_seconds);
    fprintf(f, "load            %.3f s inputs\n", p->load_seconds);
}

/* The reverse push's lines (walks from b's states). */
static void reverse_text(FILE *f, const ulam_bidir_report *p)
{
    const ulam_bidir_opts *o = p->opts;
    const ulam_bidir_result *r = p->result;
    const ulam_walk_result *w = &r->walks;
    const char *rmax = o->rmax > 0 ? "given" : "balanced";
    if (o->nb > 0)
        fprintf(f, "method          bidirectional: reverse push from %lld, walks from b's %lld nonzeros (%s rmax)\n",
                node(p, o->target), (long long)o->nb, rmax);
    else
        fprintf(f, "method          bidirectional: reverse push from %lld, walks from source %lld (%s rmax)\n",
                node(p, o->target), node(p, o->source), rmax);
    fprintf(f, "push            rmax %.3g: %lld pushes, %lld operations, %.4f s; <p, b> = %.10g; residual on %lld "
               "states, sum %.3g\n", r->push.rmax, (long long)r->push.pushes, (long long)r->push.ops, r->push.seconds,
            r->push_part, (long long)r->push.support, r->push.r_sum);
    if (r->push.support == 0)
        fprintf(f, "walks           none: the push left no residual, the value is exact (to rounding)\n");
    else
        fprintf(f, "walks           %lld (%lld cut, %lld steps, %d threads)\n", (long long)w->walks, (long long)w->cut,
                (long long)w->steps, w->threads);
    if (o->rmax <= 0)
        fprintf(f, "balance         pilot %lld walks, %.3g visits a walk; %.3g walks predicted at this rmax, "
                   "work %.3g operations predicted in all (a visit %.3g operations; probe's |x| >= %.3g)\n",
                (long long)r->plan.pilot_walks, r->plan.mean_visits, r->plan.predicted_walks, r->plan.predicted_work,
                r->plan.step_cost, r->plan.probe);
    fprintf(f, "seconds         %.4f (push %.4f, walks %.4f, seed %llu); transpose %.3f s\n", r->seconds,
            r->push.seconds, w->seconds, (unsigned long long)o->walk.exec.seed, p->transpose_seconds);
    if (p->guard)
        fprintf(f, "guards          rho(|M|) %.6g (%s), rho(M^) %.6g (%s, forward kernel)\n", p->guard->abs.rho,
                ulam_verdict_word(p->guard->verdict_abs), p->guard->hat[ULAM_FORWARD].rho,
                ulam_verdict_word(p->guard->verdict_hat[ULAM_FORWARD]));
    fprintf(f, "load            %.3f s inputs, %.3f s guards\n", p->load_seconds, p->guard_seconds);
}

/* The point query as text: the answer line, then (not QUIET) the rel_err outcome, the route's
 * lines, the choice, PageRank's line and --check's. */
static void point_text(FILE *f, const ulam_bidir_report *p, int format)
{
    const ulam_bidir_opts *o = p->opts;
    answer_line(f, p);
    if (format == ULAM_REPORT_QUIET) return;
    ulam__report_rel_err_fprint(f, &o->walk, &p->result->walks, 0);
    if (p->dense) dense_text(f, p);
    else reverse_text(f, p);
    if (p->choice) ulam_choice_fprint(f, p->choice, 1, format == ULAM_REPORT_VERBOSE);
    if (p->pagerank > 0) pagerank_line(f, p, o->nb ? 0 : o->source + 1);
    if (p->check) check_line(f, p);
}

/* The point query as one JSON object. */
static void point_json(FILE *f, const ulam_bidir_report *p)
{
    const ulam_bidir_opts *o = p->opts;
    const ulam_bidir_result *r = p->result;
    const ulam_walk_result *w = &r->walks;
    const ulam_guard *g = p->guard;
    int finite = g ? g->verdict_hat[ULAM_FORWARD] != ULAM_VERDICT_FAIL : isfinite(r->ci95[0]) && isfinite(r->ci95[1]);
    fprintf(f, "{\"index\": %lld, ", node(p, o->target));
    if (p->answer_name && strcmp(p->answer_name, "x")) fprintf(f, "\"quantity\": \"%s\", ", p->answer_name);
    if (o->nb > 0) fprintf(f, "\"source\": null, \"b_nonzeros\": %lld, ", (long long)o->nb);
    else fprintf(f, "\"source\": %lld, \"b_nonzeros\": 1, ", node(p, o->source));
    ulam_json_string(f, "method", "bidirectional", 0);
    ulam_json_number(f, "estimate", r->estimate, 0);
    ulam_json_number(f, "stderr", r->std_error, 0);
    fputs("\"ci95\": ", f);
    if (finite) {
        fputc('[', f), ulam_json_number(f, NULL, r->ci95[0], 1), fputs(", ", f);
        ulam_json_number(f, NULL, r->ci95[1], 1), fputs("], ", f);
    } else {
        fputs("null, ", f);
    }
    fprintf(f, "\"variance_finite\": %s, ", finite ? "true" : "false");
    ulam_json_number(f, "rho_abs", g ? g->abs.rho : NAN, 0);
    ulam_json_number(f, "rho_hat", g ? g->hat[ULAM_FORWARD].rho : NAN, 0);
    ulam_json_number(f, "rmax", r->push.rmax, 0);
    fprintf(f, "\"rmax_balanced\": %s, ", o->rmax > 0 ? "false" : "true");
    ulam_json_number(f, "push_part", r->push_part, 0);
    fprintf(f, "\"pushes\": %lld, \"push_ops\": %lld, \"residual_support\": %lld, ", (long long)r->push.pushes,
            (long long)r->push.ops, (long long)r->push.support);
    ulam_json_number(f, "residual_sum", r->push.r_sum, 0);
    ulam_json_number(f, "push_seconds", r->push.seconds, 0);
    fprintf(f, "\"walks\": %lld, \"steps\": %lld, \"cut\": %lld, \"pilot_walks\": %lld, ", (long long)w->walks,
            (long long)w->steps, (long long)w->cut, (long long)r->plan.pilot_walks);
    ulam_json_number(f, "variance", w->variance, 0);
    ulam_json_number(f, "mean_visits", r->plan.mean_visits, 0);
    ulam_json_number(f, "predicted_walks", r->plan.predicted_walks, 0);
    ulam_json_number(f, "predicted_work", r->plan.predicted_work, 0);
    ulam_json_number(f, "walk_seconds", w->seconds, 0);
    ulam_json_number(f, "seconds", r->seconds, 0);
    ulam_json_number(f, "transpose_seconds", p->transpose_seconds, 0);
    ulam_json_number(f, "load_seconds", p->load_seconds, 0);
    ulam_json_number(f, "guard_seconds", p->guard_seconds, 0);
    ulam_json_string(f, "estimator", ulam__report_estimator_name(o->walk.estimator), 0);
    fprintf(f, "\"seed\": %llu, \"threads\": %d, \"ranks\": %d, ", (unsigned long long)o->walk.exec.seed, w->threads,
            p->ranks > 0 ? p->ranks : 1);
    if (p->check) {
        ulam_json_string(f, "direct_method", direct_method(p), 0);
        ulam_json_number(f, "direct", p->direct, 0);
        ulam_json_number(f, "z", ulam__report_z(r->estimate, p->direct, r->std_error), 0);
    }
    if (o->walk.stop.rel_err > 0) fprintf(f, "\"rel_err_met\": %s, ", w->rel_err_met ? "true" : "false");
    if (p->choice) ulam_choice_fprint(f, p->choice, 1, ULAM_REPORT_JSON);
    fprintf(f, "\"interrupted\": %s}\n", w->interrupted ? "true" : "false");
}

/* The single-source table's details (not QUIET), below its rows: the method, the push, the walks,
 * the seconds. */
static void table_head(FILE *f, const ulam_bidir_report *p)
{
    const ulam_fpush_info *t = p->top;
    if (t->dense)
        fprintf(f, "method          single source: dense LU of I - M (n = %lld: cheaper than the push's 1 / (1 - ||M||_1) = "
                   "%.3g sweeps per e-fold of its residual, or walks of as many steps)\n", (long long)p->n, t->mean_visits);
    else if (p->source)
        fprintf(f, "method          single source: forward push from %lld, forward walks on its residual (FORA)\n",
                node(p, p->source - 1));
    else
        fprintf(f, "method          single source: forward push from a virtual state feeding %s, forward walks on its "
                   "residual (FORA)\n", p->seeds ? "the seeds" : "every node");
    if (p->pagerank > 0) pagerank_line(f, p, p->source);
    if (t->dense)
        fprintf(f, "residual        ||b - (I - M) x||_1 = %.3g as computed, so every %s is within %.3g of the one printed "
                   "(rounding included; no walks)\n", t->push.r_sum, p->pagerank > 0 ? "pi_i" : "x_i", t->residual_bound);
    else
        fprintf(f, "push            rmax %.3g: %lld operations, residual on %lld states, sum %.3g (walk part of any %s at "
                   "most %.3g)\n", t->rmax, (long long)t->push.ops, (long long)t->push.support, t->push.r_sum,
                p->pagerank > 0 ? "pi_i" : "x_i", t->residual_bound);
    if (!t->dense)
        fprintf(f, "walks           %lld (%lld steps)%s\n", (long long)t->walks, (long long)t->steps,
                t->interrupted == 1 ? "  [INTERRUPTED]" : t->interrupted ? "  (stopped at --time)" : "");
    if (t->min_value > 0 && !t->dense)
        fprintf(f, "target          every 95%% interval honest; planned for relative error %.3g at values >= %.3g%s\n",
                t->rel_err, t->min_value, t->interrupted == 2 ? " (--time ended the walks first: the intervals are wider)" : "");
    if (t->push.support > 0 && !isfinite(t->residual_bound)) /* the queue path (src/fpush.c) */
        fprintf(f, "intervals       the source's alone: with ||M||_1 >= 1 the other components' walk parts have no "
                   "certified range (none printed)\n");
    if (t->dense) fprintf(f, "seconds         %.4f (the LU; CPU %.4f)\n", t->seconds, p->cpu_seconds);
    else fprintf(f, "seconds         %.4f (push %.4f, walks %.4f; CPU %.4f)\n", t->seconds, t->push_seconds, t->walk_seconds,
                 p->cpu_seconds);
    if (p->direct_x)
        fprintf(f, "direct          %s, %.3g s (the column direct)\n", direct_method(p), p->direct_seconds);
}

/* The single-source table as text: the answer first (the columns' names, not QUIET, then a row for
 * each of the largest with its interval), then its details (not QUIET). */
static void table_text(FILE *f, const ulam_bidir_report *p, int format)
{
    const double *xd = p->direct_x;
    if (format != ULAM_REPORT_QUIET)
        fprintf(f, "%-6s %-10s %-14s %-11s %s\n", "rank", p->node_base ? "index" : "node",
                p->pagerank > 0 ? "pi" : "estimate", "stderr", xd ? "95% CI                    direct" : "95% CI");
    for (int64_t k = 0; k < p->rows; k++) {
        int64_t i = p->order[k];
        fprintf(f, "%-6lld %-10lld %-14.8g %-11.3g ", (long long)k + 1, node(p, i), p->x[i], p->se[k]);
        int none = isnan(p->lo[k]) || isnan(p->hi[k]); /* no certified interval (an infinite variance) */
        if (none) fprintf(f, xd ? "%-25s" : "%s", "none");
        else fprintf(f, "%-12.6g %.6g", p->lo[k], p->hi[k]);
        if (xd) fprintf(f, "%*s%.8g", none ? 0 : 13 - (int)snprintf(NULL, 0, "%.6g", p->hi[k]), "", xd[i]);
        if (k == 0 && format == ULAM_REPORT_QUIET && p->top->interrupted == 1) fputs("  [INTERRUPTED]", f); /* the head's mark */
        fputc('\n', f);
    }
    if (format != ULAM_REPORT_QUIET) table_head(f, p);
}

/* The single-source table as one JSON object. */
static void table_json(FILE *f, const ulam_bidir_report *p)
{
    const ulam_fpush_info *t = p->top;
    fputc('{', f);
    ulam_json_string(f, "method", "single-source", 0);
    if (p->source) fprintf(f, "\"source\": %lld, ", node(p, p->source - 1));
    else fputs("\"source\": null, ", f);
    if (p->pagerank > 0) ulam_json_number(f, "damping", p->pagerank, 0), ulam_json_string(f, "quantity", "pi", 0);
    fprintf(f, "\"n\": %lld, ", (long long)p->n);
    ulam_json_number(f, "rmax", t->rmax, 0);
    fprintf(f, "\"push_ops\": %lld, \"walks\": %lld, \"steps\": %lld, ", (long long)t->push.ops, (long long)t->walks,
            (long long)t->steps);
    ulam_json_number(f, "residual_bound", t->residual_bound, 0);
    if (t->min_value > 0) ulam_json_number(f, "rel_err", t->rel_err, 0), ulam_json_number(f, "min_value", t->min_value, 0);
    ulam_json_number(f, "seconds", t->seconds, 0);
    ulam_json_number(f, "push_seconds", t->push_seconds, 0);
    ulam_json_number(f, "walk_seconds", t->walk_seconds, 0);
    ulam_json_number(f, "cpu_seconds", p->cpu_seconds, 0);
    fputs("\"top\": [", f);
    for (int64_t k = 0; k < p->rows; k++) {
        int64_t i = p->order[k];
        fprintf(f, "%s{\"index\": %lld, ", k ? ", " : "", node(p, i));
        ulam_json_number(f, "estimate", p->x[i], 0);
        ulam_json_number(f, "stderr", p->se[k], 0);
        fputs("\"ci95\": [", f);
        ulam_json_number(f, NULL, p->lo[k], 1), fputs(", ", f), ulam_json_number(f, NULL, p->hi[k], 1);
        fprintf(f, "]%s", p->direct_x ? ", " : "");
        if (p->direct_x) ulam_json_number(f, "direct", p->direct_x[i], 1);
        fputc('}', f);
    }
    fprintf(f, "], \"dense\": %s, \"interrupted\": %s, \"stopped_at_time\": %s}\n", t->dense ? "true" : "false",
            t->interrupted == 1 ? "true" : "false", t->interrupted == 2 ? "true" : "false");
}

/* ulam_report_fprint's ULAM_REPORT_BIDIR (src/report.h). */
int ulam__report_bidir_fprint(FILE *f, const void *report, int format)
{
    const ulam_bidir_report *r = report;
    if (r->opts && r->result) {
        if (format == ULAM_REPORT_JSON) point_json(f, r);
        else if (format == ULAM_REPORT_CHECK) check_line(f, r);
        else point_text(f, r, format);
    } else if (r->top && r->order && r->x && r->se && r->lo && r->hi) {
        if (format == ULAM_REPORT_JSON) table_json(f, r);
        else if (format != ULAM_REPORT_CHECK) table_text(f, r, format);
    } else return ULAM_EINVAL;
    return ULAM_OK;
}
