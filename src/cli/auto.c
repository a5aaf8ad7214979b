/* ulam solve --method auto: choose mode x estimator x continuation for the user (opt-in). */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <string.h>


/* Choose for s (loaded) under o (what ao pins stays; an: the walks on its bounds, NULL: none)
 * through the library's method table, make the run *run and set o's mode, estimator and
 * continuation to the walks' choice; *status gets the refusal (err filled) for the caller to
 * report as a plain run's.  0, or an exit code (message printed) when the library fails or when
 * no candidate is certified and o asks for a --rel-err target (the closest is named). */
int cli_auto_choose(const cli_system *s, ulam_analysis *an, ulam_walk_opts *o, const ulam_auto_opts *ao,
                    const char *excluded_why, ulam_choice *ch, ulam_run **run, int *status, ulam_error *err)
{
    ulam_method_opts mo = ulam_method_defaults();
    if (excluded_why) mo.exclude |= 1u << ULAM_METHOD_BIDIRECTIONAL;
    ch->walks.chosen = ch->walks.closest = -1;
    *status = an ? ulam_analysis_start(an, s->b, o, ao, &mo, ch, run, err)
                 : ulam_auto_start(s->M, s->b, o, ao, &mo, ch, run, err);
    ulam_method_verdict *v = &ch->method[ULAM_METHOD_BIDIRECTIONAL];
    if (excluded_why && v->state == ULAM_METHOD_NOT_CONSIDERED && !strcmp(v->why, "not considered: excluded"))
        snprintf(v->why, sizeof v->why, "not considered: %s", excluded_why);
    const ulam_auto_result *res = &ch->walks;
    int k = res->chosen >= 0 ? res->chosen : res->closest;
    if (k < 0 && !*status) /* no walk candidate and no refusal: never run (nor label) another row's answer */
        *status = err->status = ULAM_EINVAL, snprintf(err->msg, sizeof err->msg, "a walk candidate to run");
    if (k < 0) {
        int rc = cli_report(s->matrix_path, err);
        return *status == ULAM_EDIVERGE ? EXIT_DIVERGE : *status == ULAM_EINFVAR ? EXIT_INFVAR : rc;
    }
    const ulam_auto_candidate *c = &res->cand[k];
    if (res->chosen < 0) {
        int diverge = !(res->abs.upper < 1);
        if (diverge && !o->policy.force) { /* the guards' refusal says why; no candidate is run */
            cli_guard_diverge(s, &res->guard, 0);
            *run = ulam_run_free(*run);
            return EXIT_DIVERGE;
        }
        const char *hint = s->jacobi || s->pagerank > 0 ? "" : cli_system_hint(s->M);
        char q[32] = "analog";
        if (c->continue_q > 0) snprintf(q, sizeof q, "Q = %.3g", c->continue_q);
        fprintf(stderr, "ulam: %s: %s: --method auto: no candidate has a certified finite variance%s; the closest is "
                        "%s %s (continuation %s, kernel exponent %g) with rho(M^) = %.6g (upper bound %.6g)%s.%s\n",
                s->matrix_path, o->stop.rel_err > 0 ? "error" : "warning",
                !diverge ? "" : res->abs.lower >= 1 ? " (rho(|M|) >= 1, certified)" : " (rho(|M|) is not certified below 1)",
                cli_mode_names[c->mode], cli_estimator_names[c->estimator], q, c->kernel_alpha, c->hat.rho, c->hat.upper,
                o->stop.rel_err > 0 ? ": a --rel-err target cannot be met honestly" : "; running it", hint);
        if (o->stop.rel_err > 0) {
            *run = ulam_run_free(*run);
            return diverge ? EXIT_DIVERGE : EXIT_INFVAR;
        }
    }
    o->mode = c->mode, o->estimator = c->estimator, o->kernel.continue_q = c->continue_q, o->kernel.kernel_alpha = c->kernel_alpha;
    return 0;
}

/* A continuation in words. */
static void print_q(double q)
{
    if (q > 0) printf("Q = %-6.3g", q);
    else printf("analog    ");
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

/* The candidates and the choice, as text. */
void cli_auto_print_text(const ulam_choice *ch, int bidir)
{
    const ulam_auto_result *res = &ch->walks;
    const ulam_method_verdict *v = &ch->method[ULAM_METHOD_BIDIRECTIONAL];
    int bstate = bidir ? v->state : 0;
    if (cli_verbosity < 1) { /* one line: what was chosen among how many; --verbose lists them */
        if (bstate == ULAM_METHOD_CHOSEN)
            printf("auto            chose bidirectional over %d walk candidates (--verbose lists them)\n", res->ncand);
        else if (res->chosen >= 0)
            printf("auto            chose it among %d candidates by predicted cost (--verbose lists them)\n", res->ncand);
        else
            printf("auto            no certified candidate among %d: ran the closest (--verbose lists them)\n",
                   res->ncand);
        return;
    }
    if (bstate == ULAM_METHOD_CHOSEN)
        printf("auto            chose bidirectional: its predicted work %.3g units is below the walk leader's %.3g "
               "(%d walk candidates after %d pilot stages; guards and pilots %.3f s)\n", v->predicted_work, ch->leader_work,
               res->ncand, res->stages, res->seconds);
    else if (res->chosen >= 0) {
        char share[96] = "no predicted work to compare the pilots with"; /* a chosen run that predicts nothing */
        if (isfinite(pilot_share(res)))
            snprintf(share, sizeof share, "the pilots' overhead is %.3g%% of the predicted work", 100 * pilot_share(res));
        printf("auto            chose the least predicted %s of %d candidates after %d pilot stages; %s (guards and "
               "pilots %.3f s); the estimate is from fresh walks\n", res->by_work ? "work" : "variance x work a walk",
               res->ncand, res->stages, share, res->seconds);
    }
    else
        printf("auto            no certified candidate among %d: ran the closest\n", res->ncand);
    for (int k = 0; k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        printf("  %c %-8s %-10s ", k == res->chosen && !(bstate == ULAM_METHOD_CHOSEN) ? '*' : ' ', cli_mode_names[c->mode], cli_estimator_names[c->estimator]);
        print_q(c->continue_q);
        printf(" alpha %-3.3g", c->kernel_alpha);
        if (isfinite(c->hat.upper)) printf(" rho(M^) %-9.4g ", c->hat.rho);
        else printf(" rho(M^) %-9s ", "-");
        if (c->state == ULAM_AUTO_SKIPPED) printf("not piloted: starting its kernel would pass the pilot budget\n");
        else if (!c->certified) printf("not certified finite (upper bound %.4g)\n", c->hat.upper);
        else if (c->state == ULAM_AUTO_REFUSED) printf("refused: %s\n", ulam_strerror(c->status));
        else
            printf("pilots %lld walks  variance %-9.4g (+-%.0f%%) %.3g steps/walk  predicted %s%.4g walks, %.3g units "
                   "(%.2g s)%s\n", (long long)c->pilot_walks, c->variance, 100 * fmin(c->variance_rel_error, 99.99),
                   c->steps_per_walk, c->predicted_lower ? ">= " : "", c->predicted_walks,
                   c->predicted_work, c->predicted_seconds,
                   c->state == ULAM_AUTO_DROPPED ? "  dropped" : "");
    }
    if (!bidir) return;
    printf("  %c bidirectional (reverse push, walks from b) ", bstate == ULAM_METHOD_CHOSEN ? '*' : ' ');
    if (bstate)
        printf("rmax %.3g  push %lld ops  pilot %lld walks  predicted %.4g walks, %.3g units%s%s\n", ch->bidir.rmax,
               (long long)ch->bidir.push.ops, (long long)ch->bidir.pilot_walks, ch->bidir.predicted_walks, v->predicted_work,
               bstate == ULAM_METHOD_CHOSEN ? "" : "  ", bstate == ULAM_METHOD_CHOSEN ? "" : v->why);
    else
        printf("%s\n", v->why);
}

/* The candidates and the choice, as the JSON key "auto" (followed by a comma). */
void cli_auto_print_json(const ulam_choice *ch, int bidir)
{
    const ulam_auto_result *res = &ch->walks;
    const ulam_method_verdict *v = &ch->method[ULAM_METHOD_BIDIRECTIONAL];
    int bstate = bidir ? v->state : 0;
    /* 1-based positions in "candidates", as every index a user sees (0: none) */
    printf("\"auto\": {\"chosen\": %d, \"closest\": %d, \"stages\": %d, ",
           (bstate == ULAM_METHOD_CHOSEN ? res->ncand : res->chosen) + 1, res->closest + 1, res->stages);
    cli_json_number("seconds", res->seconds, 0);
    cli_json_number("pilot_work", res->pilot_work, 0);
    cli_json_number("reused_work", res->reused_work, 0);
    cli_json_number("pilot_share", pilot_share(res), 0);
    printf("\"candidates\": [");
    for (int k = 0; k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        printf("%s{", k ? ", " : "");
        cli_json_string("mode", cli_mode_names[c->mode], 0);
        cli_json_string("estimator", cli_estimator_names[c->estimator], 0);
        cli_json_number("continue", c->continue_q > 0 ? c->continue_q : NAN, 0);
        cli_json_number("kernel_alpha", c->kernel_alpha, 0);
        cli_json_number("rho_hat", isfinite(c->hat.upper) ? c->hat.rho : NAN, 0);
        cli_json_number("rho_hat_upper", c->hat.upper, 0);
        printf("\"certified\": %s, ", c->certified ? "true" : "false");
        cli_json_string("state", state_names[c->state == ULAM_AUTO_CHOSEN && bstate == ULAM_METHOD_CHOSEN ? ULAM_AUTO_FINALIST : c->state], 0);
        cli_json_string("status", c->status ? ulam_strerror(c->status) : "ok", 0);
        printf("\"pilot_walks\": %lld, ", (long long)c->pilot_walks);
        cli_json_number("variance", c->pilot_walks ? c->variance : NAN, 0);
        cli_json_number("variance_rel_error", c->pilot_walks ? c->variance_rel_error : NAN, 0);
        cli_json_number("steps_per_walk", c->pilot_walks ? c->steps_per_walk : NAN, 0);
        cli_json_number("work_per_walk", c->pilot_walks ? c->work_per_walk : NAN, 0);
        cli_json_number("cost", c->cost, 0);
        cli_json_number("predicted_walks", c->predicted_walks, 0);
        printf("\"predicted_is\": \"%s\", ", c->predicted_lower ? "lower bound" : "estimate");
        cli_json_number("predicted_work", c->predicted_work, 0);
        cli_json_number("predicted_seconds", c->predicted_seconds, 1);
        printf("}");
    }
    if (bstate) { /* planned: the last entry (chosen: index ncand) */
        printf("%s{", res->ncand ? ", " : "");
        cli_json_string("mode", "bidirectional", 0);
        cli_json_string("state", bstate == ULAM_METHOD_CHOSEN ? "chosen" : bstate == 1 ? "planned" : "not_considered", 0);
        cli_json_number("rmax", bstate ? ch->bidir.rmax : NAN, 0);
        printf("\"push_ops\": %lld, \"pilot_walks\": %lld, ", (long long)(bstate ? ch->bidir.push.ops : 0),
               (long long)(bstate ? ch->bidir.pilot_walks : 0));
        cli_json_number("predicted_walks", bstate ? ch->bidir.predicted_walks : NAN, 0);
        cli_json_number("predicted_work", v->predicted_work, 0);
        cli_json_number("leader_work", ch->leader_work, 1);
        printf("}");
    }
    printf("]");
    if (bidir) { /* why bidirectional was not chosen, in one line (null: it was) */
        printf(", ");
        if (bstate == ULAM_METHOD_CHOSEN) printf("\"bidirectional\": null");
        else cli_json_string("bidirectional", v->why, 1);
    }
    printf("}, ");
}
