/* ulam solve --method auto: choose mode x estimator x continuation for the user (opt-in). */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <string.h>


/* Nonzero when argv names option opt (as "--opt" or "--opt=..."). */
static int has_option(int argc, char **argv, const char *opt)
{
    size_t n = strlen(opt);
    for (int k = 1; k < argc; k++)
        if (!strncmp(argv[k], opt, n) && (argv[k][n] == '\0' || argv[k][n] == '=')) return 1;
    return 0;
}

/* Choose for s (loaded) and set o's mode, estimator and continuation; what the command line names
 * (--mode, --estimator, --continue) is pinned.  0, or an exit code (message printed) when the library
 * fails or when no candidate is certified and o asks for a --rel-err target. */
int cli_auto_choose(const cli_system *s, int argc, char **argv, ulam_walk_opts *o, ulam_auto_result *res)
{
    ulam_auto_opts ao = ulam_auto_defaults();
    ao.pin_mode = has_option(argc, argv, "--mode");
    ao.pin_estimator = has_option(argc, argv, "--estimator");
    ao.pin_continue = has_option(argc, argv, "--continue");
    ulam_error err;
    int status = ulam_auto_choose(s->M, s->b, o, &ao, res, &err);
    if (status) return cli_report(s->matrix_path, &err);
    int k = res->chosen >= 0 ? res->chosen : res->closest;
    if (k < 0) return cli_usage_error("solve", "--method auto has no candidate left once --mode, --estimator and --continue are pinned");
    const ulam_auto_candidate *c = &res->cand[k];
    if (res->chosen < 0) {
        fprintf(stderr, "ulam: %s: %s: --method auto: no candidate has a certified finite variance; the closest is "
                        "%s %s (continuation %s%.3g) with rho(M^) = %.6g (upper bound %.6g)%s\n",
                s->matrix_path, o->rel_err > 0 ? "error" : "warning", cli_mode_names[c->mode], cli_estimator_names[c->estimator],
                c->continue_q > 0 ? "" : "analog, ", c->continue_q > 0 ? c->continue_q : 0.0, c->hat.rho, c->hat.upper,
                o->rel_err > 0 ? ": a --rel-err target cannot be met honestly" : "; running it");
        if (o->rel_err > 0) return EXIT_DIVERGE;
    }
    o->mode = c->mode, o->estimator = c->estimator, o->continue_q = c->continue_q;
    return 0;
}

/* A continuation in words. */
static void print_q(double q)
{
    if (q > 0) printf("Q = %-6.3g", q);
    else printf("analog    ");
}

/* The candidates and the choice, as text. */
void cli_auto_print_text(const ulam_auto_result *res)
{
    printf("auto            %s from %d candidates (guards and pilots %.3f s); the estimate is from fresh walks\n",
           res->chosen >= 0 ? "chose the least variance x seconds a walk" : "no certified candidate: ran the closest",
           res->ncand, res->seconds);
    for (int k = 0; k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        printf("  %c %-8s %-10s ", k == res->chosen ? '*' : ' ', cli_mode_names[c->mode], cli_estimator_names[c->estimator]);
        print_q(c->continue_q);
        printf(" rho(M^) %-9.4g ", c->hat.rho);
        if (!c->certified) printf("not certified finite (upper bound %.4g)\n", c->hat.upper);
        else if (c->status) printf("refused: %s\n", ulam_strerror(c->status));
        else printf("variance %-10.4g %.3g s/walk  cost %-10.4g predicted %.3g s\n", c->variance, c->seconds_per_walk,
                    c->cost, c->predicted_seconds);
    }
}

/* The candidates and the choice, as the JSON key "auto" (followed by a comma). */
void cli_auto_print_json(const ulam_auto_result *res)
{
    printf("\"auto\": {\"chosen\": %d, \"closest\": %d, ", res->chosen, res->closest);
    cli_json_number("seconds", res->seconds, 0);
    printf("\"candidates\": [");
    for (int k = 0; k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        printf("%s{", k ? ", " : "");
        cli_json_string("mode", cli_mode_names[c->mode], 0);
        cli_json_string("estimator", cli_estimator_names[c->estimator], 0);
        cli_json_number("continue", c->continue_q > 0 ? c->continue_q : NAN, 0);
        cli_json_number("rho_hat", c->hat.rho, 0);
        cli_json_number("rho_hat_upper", c->hat.upper, 0);
        printf("\"certified\": %s, ", c->certified ? "true" : "false");
        cli_json_string("status", c->status ? ulam_strerror(c->status) : "ok", 0);
        printf("\"pilot_walks\": %lld, ", (long long)c->pilot_walks);
        cli_json_number("variance", c->pilot_walks ? c->variance : NAN, 0);
        cli_json_number("seconds_per_walk", c->pilot_walks ? c->seconds_per_walk : NAN, 0);
        cli_json_number("cost", c->cost, 0);
        cli_json_number("predicted_seconds", c->predicted_seconds, 1);
        printf("}");
    }
    printf("]}, ");
}
