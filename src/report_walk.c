/* A walk run's report to a caller's stream (include/ulam_report.h): the answer line, the brief and
 * verbose blocks, the JSON object, the --check line and a first round's warnings of ulam solve's
 * walks row. */
#include "ulam_report.h"
#include "report.h"
#include "internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Peak resident memory of this process so far, in MiB (ulam__peak_rss_kib; 0 when unknown). */
static double peak_rss_mib(void)
{
    double kib = ulam__peak_rss_kib();
    return kib >= 0 ? kib / 1024.0 : 0.0;
}

/* The unknown's name ("x" unless the caller names it). */
static const char *name(const ulam_walk_report *p)
{
    return p->answer_name ? p->answer_name : "x";
}

/* Write the answer line: x[I] with its interval, or why there is none (quiet: no PageRank line). */
static void answer(FILE *f, const ulam_walk_report *p, int quiet)
{
    const ulam_walk_opts *o = p->opts;
    const ulam_walk_result *r = p->result;
    long long i = (long long)(o->query.index + p->node_base);
    int pad = ulam__report_pad(name(p), i, 16);
    const char *stop = r->interrupted ? "  [INTERRUPTED]" : "";
    if (o->mode == ULAM_FORWARD && isnan(r->std_error) && r->ci95[0] == 0 && r->ci95[1] == 0)
        fprintf(f, "%s[%lld]%*s0 exactly (95%% CI 0 .. 0: no walk from where b is nonzero can reach it)%s\n",
                name(p), i, pad, "", stop);
    else if (o->mode == ULAM_FORWARD && isnan(r->std_error))
        fprintf(f, "%s[%lld]%*sunreached (no walk tallied it: no estimate)%s\n", name(p), i, pad, "", stop);
    else if (r->variance_finite == 1 && isnan(r->ci95[0]))
        fprintf(f, "%s[%lld]%*s%.10g +- %.3g (no confidence interval: %s)%s\n", name(p), i, pad, "", r->estimate,
                r->std_error,
                !isfinite(r->cut_bound) ? "walks cut at --max-steps may have moved it by any amount"
                : ulam__report_score_too_small(r) ? "scores too small to square in doubles, so no variance: scale b up "
                                                    "(a prepared file's b is not rescaled)"
                : !isfinite(r->tail_bound) && r->estimate != 0 ? "no certified range of a single walk's score"
                : "no certified range yet, or a score past the certified one", stop);
    else if (r->variance_finite == 1) {
        fprintf(f, "%s[%lld]%*s%.10g", name(p), i, pad, "", r->estimate);
        ulam__report_pm_fprint(f, r->estimate, r->std_error, r->ci95[0], r->ci95[1]);
        fprintf(f, "%s\n", stop);
    } else
        fprintf(f, "%s[%lld]%*s%.10g (no confidence interval: the variance is %s; the sample stderr %.3g "
                   "means nothing)%s\n", name(p), i, pad, "", r->estimate,
                r->variance_finite == 0 ? "infinite, rho(M^) >= 1" : "not certified finite, rho(M^) straddles 1",
                r->std_error, stop);
    if (strcmp(name(p), "x") && !quiet) /* PageRank's pi */
        fprintf(f, "pagerank        pi = x of (I - alpha P^T) x = (1 - alpha) / n: global PageRank, uniform teleport; "
                   "dangling nodes' rank leaks (pi sums to 1 - the leak)\n");
}

/* Write the default block: the answer, the method in words, the cost, the target (about 5 lines). */
static void brief(FILE *f, const ulam_walk_report *p)
{
    const ulam_walk_opts *o = p->opts;
    const ulam_walk_result *r = p->result;
    answer(f, p, 0);
    fprintf(f, "method          %s random walks, %s estimator", ulam__report_mode_name(o->mode),
            ulam__report_estimator_name(o->estimator));
    if (o->mode == ULAM_ADJOINT) fputs(" (walks start at the unknown)\n", f);
    else if (r->push_sweeps > 0)
        fprintf(f, " (b pushed first, %d sweeps to ||r||_1 / ||b||_1 = %.3g; walks start from r: every unknown at "
                   "once)\n", r->push_sweeps, r->push_residual);
    else fputs(" (walks start from b: every unknown at once)\n", f);
    if (p->choice) ulam_choice_fprint(f, p->choice, 1, ULAM_REPORT_BRIEF);
    if (r->cut)
        fprintf(f, "walks           %lld (%lld cut at %lld steps: the estimate is biased by the cut)\n",
                (long long)r->walks, (long long)r->cut, (long long)o->stop.max_steps);
    else
        fprintf(f, "walks           %lld (mean length %.3g steps)\n", (long long)r->walks,
                r->walks ? (double)r->steps / (double)r->walks : 0.0);
    fprintf(f, "seconds         %.3g walking on %d threads; %.3g in all (inputs, guards, set-up)\n", r->seconds,
            r->threads, p->total_seconds);
    ulam__report_rel_err_fprint(f, o, r, 0);
    if (o->mode == ULAM_FORWARD && r->unreached)
        fprintf(f, "unreached       %lld of %lld components (no walk tallied them: no estimate)\n",
                (long long)r->unreached, (long long)p->n);
}

/* Write the guards' line: the radii of rho(|M|) and of the mode's rho(M^) with their verdicts. */
static void guards(FILE *f, const ulam_walk_report *p)
{
    const ulam_walk_opts *o = p->opts;
    const ulam_guard *g = p->guard;
    fprintf(f, "guards          rho(|M|) in [%.6g, %.6g] (%s), rho(M^) in [%.6g, %.6g] (%s)", g->abs.lower,
            g->abs.upper, ulam_verdict_word(g->verdict_abs), g->hat[o->mode].lower, g->hat[o->mode].upper,
            ulam_verdict_word(g->verdict_hat[o->mode]));
    if (o->kernel.kernel_alpha != 1.0) fprintf(f, " at kernel exponent alpha = %g", o->kernel.kernel_alpha);
    fputc('\n', f);
}

/* Write the whole human-readable block (verbose). */
static void verbose(FILE *f, const ulam_walk_report *p)
{
    const ulam_walk_opts *o = p->opts;
    const ulam_walk_result *r = p->result;
    double mean_len = r->walks ? (double)r->steps / (double)r->walks : 0.0;
    double rel = r->estimate != 0 ? r->std_error / fabs(r->estimate) : INFINITY;
    answer(f, p, 0);
    fprintf(f, "method          %s walks, %s estimator\n", ulam__report_mode_name(o->mode),
            ulam__report_estimator_name(o->estimator));
    if (r->push_sweeps > 0)
        fprintf(f, "push on b       %d Gauss-Seidel sweeps, %lld operations: ||r||_1 / ||b||_1 = %.3g (the walks start "
                   "from the residual r; each estimate adds the pushed part)\n", r->push_sweeps, (long long)r->push_ops,
                r->push_residual);
    fprintf(f, "walks           %lld (%lld cut at %lld steps%s)\n", (long long)r->walks, (long long)r->cut,
            (long long)o->stop.max_steps, r->cut ? ": the estimate is biased by the cut" : "");
    fprintf(f, "steps           %lld (mean walk length %.4g; kernel rows built %lld)\n", (long long)r->steps, mean_len,
            (long long)r->rows);
    fprintf(f, "variance        %.6g per walk (relative error %.3g)\n", r->variance, rel);
    fprintf(f, "seconds         %.4f (%.3g M steps/s, %d threads, seed %llu)\n", r->seconds,
            r->seconds > 0 ? (double)r->steps / r->seconds / 1e6 : 0.0, r->threads, (unsigned long long)o->exec.seed);
    fprintf(f, "figure of merit %.4g (1 / (relative variance x seconds))\n",
            r->seconds > 0 && rel > 0 ? 1.0 / (rel * rel * r->seconds) : INFINITY);
    if (p->guard) guards(f, p);
    if (isfinite(r->score_bound))
        fprintf(f, "tail            a single score is at most %.4g: one more walk could move the estimate by at "
                   "most %.3g%%\n", r->score_bound, 100 * r->tail_bound);
    else if (isfinite(r->tail_bound))
        fprintf(f, "tail            scores grow with the walk's length; walks short enough to matter (the rest add "
                   "under %.3g%% of the answer) could move it by at most %.3g%% more\n",
                100 * (o->stop.rel_err > 0 ? o->stop.rel_err : 0.01), 100 * r->tail_bound);
    else
        fprintf(f, "tail            scores are unbounded (walk length, weights): no walk count rules out an unseen "
                   "large score; the variance's own relative error is %.3g\n", r->variance_rel_error);
    if (o->mode == ULAM_FORWARD)
        fprintf(f, "unreached       %lld of %lld components (no walk tallied them: no estimate)\n",
                (long long)r->unreached, (long long)p->n);
    ulam__report_rel_err_fprint(f, o, r, 1);
    fprintf(f, "load            %.3f s inputs, %.3f s guards, %.3f s %s; peak memory %.0f MiB\n", p->load_seconds,
            p->guard_seconds, p->kernel_seconds,
            p->choice ? "choice and solver set-up (auto's guards, pilots, set-up)" : "solver set-up", peak_rss_mib());
    if (p->choice) ulam_choice_fprint(f, p->choice, 1, ULAM_REPORT_VERBOSE);
}

/* Write the JSON object and a newline. */
static void json(FILE *f, const ulam_walk_report *p)
{
    const ulam_walk_result *r = p->result;
    fprintf(f, "{\"index\": %lld, ", (long long)(p->opts->query.index + p->node_base));
    if (strcmp(name(p), "x")) fprintf(f, "\"quantity\": \"%s\", ", name(p));
    ulam_walk_result_json(f, p->opts, r, p->guard); /* the result's members: the library's schema */
    fprintf(f, "\"ranks\": %d, ", p->ranks > 0 ? p->ranks : 1);
    ulam_json_number(f, "load_seconds", p->load_seconds, 0);
    ulam_json_number(f, "guard_seconds", p->guard_seconds, 0);
    ulam_json_number(f, "kernel_seconds", p->kernel_seconds, 0);
    fprintf(f, "\"kernel_rows\": %lld, ", (long long)r->rows);
    ulam_json_number(f, "peak_rss_mib", peak_rss_mib(), 0);
    if (p->check) {
        ulam_json_number(f, "direct", p->direct, 0);
        ulam_json_number(f, "direct_seconds", p->direct_seconds, 0);
        ulam_json_string(f, "direct_method", p->direct_method, 0);
        ulam_json_number(f, "z", ulam__report_z(r->estimate, p->direct, r->std_error), 0);
    }
    if (p->choice) ulam_choice_fprint(f, p->choice, 1, ULAM_REPORT_JSON);
    fprintf(f, "\"interrupted\": %s}\n", r->interrupted ? "true" : "false");
}

/* A duration in words: seconds, minutes, hours, days or years. */
static void say_duration(char *out, size_t size, double t)
{
    if (t < 120) snprintf(out, size, "%.0f seconds", t);
    else if (t < 7200) snprintf(out, size, "%.0f minutes", t / 60);
    else if (t < 172800) snprintf(out, size, "%.1f hours", t / 3600);
    else if (t < 63115200) snprintf(out, size, "%.0f days", t / 86400);
    else snprintf(out, size, "%.3g years", t / 31557600);
}

/* After the first round of a run bounded only by a walk count: when that count at this round's
 * pace would take over an hour, say how long (issue 42: --walks 1e12 started with no word of it). */
static void walks_warning(FILE *f, const char *pre, const ulam_walk_opts *o, const ulam_walk_result *r)
{
    if (!(o->stop.max_walks > 0) || o->stop.max_seconds > 0 || !(r->walks > 0) || !(r->seconds > 0)) return;
    double t = r->seconds / (double)r->walks * (double)(o->stop.max_walks - r->walks);
    if (t < 3600) return;
    char d[64];
    say_duration(d, sizeof d, t);
    fprintf(f, "%swarning: --walks %lld at the pace of the first %lld (%.3g s) takes %sabout %s more; Ctrl-C stops "
               "and prints the estimate so far, --time S bounds the run\n", pre, (long long)o->stop.max_walks,
            (long long)r->walks, r->seconds, o->stop.rel_err > 0 ? "up to " : "", d);
}

/* After the first round: say so when the rel-err rule's minimum walk count (from the bound on a
 * single score) is out of reach, and name the estimators without that tail. */
static void rel_err_warning(FILE *f, const char *pre, const ulam_walk_opts *o, const ulam_walk_result *r)
{
    double limit = o->stop.max_walks > 0 ? (double)o->stop.max_walks : 1e8;
    if (!(o->stop.rel_err > 0)) return;
    if (!isfinite(r->tail_bound) && r->walks > 0 && r->estimate != 0) { /* (at 0 the tail is infinite too) */
        fprintf(f, "%swarning: --rel-err %g: no bound on a single walk's score holds (weights can grow without "
                   "bound, or the walk's length tail is not certified): the rule cannot be met; the run ends by "
                   "--walks or --time\n", pre, o->stop.rel_err);
        return;
    }
    if (!(r->min_walks > limit)) return;
    if (isfinite(r->score_bound))
        fprintf(f, "%swarning: --rel-err %g: a single %sscore can reach %.4g, so the rule needs about %.3g walks at "
                   "this estimate before it may stop (%s)%s\n", pre, o->stop.rel_err,
                o->estimator == ULAM_ABSORPTION ? "absorption " : "", r->score_bound, r->min_walks,
                o->stop.max_walks > 0 ? "more than --walks" : "out of reach in practice",
                o->estimator == ULAM_ABSORPTION ? "; the collision and expected estimators score b directly and "
                                                  "have no such tail" : "");
    else
        fprintf(f, "%swarning: --rel-err %g: scores grow with the walk's length, so the rule needs about %.3g walks "
                   "at this estimate before it may stop (%s)\n", pre, o->stop.rel_err, r->min_walks,
                o->stop.max_walks > 0 ? "more than --walks" : "out of reach in practice");
}

/* ulam_report_fprint's ULAM_REPORT_WALK (src/report.h). */
int ulam__report_walk_fprint(FILE *f, const void *report, int format)
{
    const ulam_walk_report *r = report;
    if (!r->opts || !r->result || (r->opts->mode != ULAM_ADJOINT && r->opts->mode != ULAM_FORWARD) ||
        r->opts->estimator < 0 || r->opts->estimator > 2)
        return ULAM_EINVAL;
    const ulam_walk_result *w = r->result;
    switch (format) {
    case ULAM_REPORT_QUIET: answer(f, r, 1); break;
    case ULAM_REPORT_BRIEF: brief(f, r); break;
    case ULAM_REPORT_VERBOSE: verbose(f, r); break;
    case ULAM_REPORT_JSON: json(f, r); break;
    case ULAM_REPORT_CHECK:
        if (!r->check) break;
        fprintf(f, "direct          %.10g (%s, %.3g s), ", r->direct, r->direct_method ? r->direct_method : "LU",
                r->direct_seconds);
        ulam__report_z_fprint(f, w->estimate, r->direct, w->std_error, w->ci95[0], w->ci95[1]);
        break;
    case ULAM_REPORT_WARN:
        rel_err_warning(f, r->prefix ? r->prefix : "", r->opts, w);
        walks_warning(f, r->prefix ? r->prefix : "", r->opts, w);
        break;
    default: break;
    }
    return ULAM_OK;
}
