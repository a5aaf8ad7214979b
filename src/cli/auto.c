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
    if (*status == ULAM_ESYNTAX || *status == ULAM_EIO) { /* a damaged or unreadable file: its error alone, no
                                                             verdict on candidates the damage cut short */
        *run = ulam_run_free(*run);
        return cli_report(s->matrix_path, err);
    }
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
