/* The method table's walks row: adjoint or forward von Neumann-Ulam walks, the candidate (mode,
 * estimator, continuation, kernel exponent) chosen by the pilots' race (src/auto.c), run by the
 * walk solver (src/solve.c). */
#include "auto.h"
#include "method_row.h"

#include <math.h>

/* Walks answer every entry query (their own guards refuse what they cannot do). */
static int applies(const ulam__query *q, int k, char *why, size_t len)
{
    (void)q, (void)k, (void)why, (void)len;
    return 1;
}

/* The race (ulam_auto_solver): its chosen candidate's predicted work, its solver kept. */
static int predict(ulam__query *q, int k, ulam_error *err)
{
    ulam_choice *ch = q->ch;
    int status = ulam__auto_solver_reach(q->M, q->b, q->o, q->ao, q->reach, &ch->walks, &q->run->sv, err);
    const ulam_auto_result *au = &ch->walks;
    if (au->chosen >= 0) {
        double w = au->cand[au->chosen].predicted_work;
        const ulam_stop_opts *st = &q->o->stop;
        if (isnan(w) && !(st->rel_err > 0) && st->max_walks == 0 && st->max_seconds > 0)
            w = exp2(floor(log2(st->max_seconds / ULAM_AUTO_UNIT_SECONDS))); /* --time alone: the work the time
                buys at the work model's rate (a constant, not this machine's), rounded down to a power of 2 so that
                the time a caller has left after its set-up (the CLI's) seldom changes a plan made on it */
        /* with a target, a leader whose pilot saw no score predicts nothing: the cap at max_walks bounds its work
           (the other rows' plans are capped by it) but is no prediction of meeting the target, so it does not
           beat a row that has one (a PageRank point query chose walks that stopped out of reach, interval 1000
           times |x|, on 6 of 40 seeds) */
        const ulam_auto_candidate *c = &au->cand[au->chosen];
        int blind = st->rel_err > 0 && c->estimate + st->rel_err_offset == 0 && !(c->variance > 0);
        ch->leader_work = w, ch->method[k].predicted_work = blind ? INFINITY : w;
    }
    int c = au->chosen >= 0 ? au->chosen : au->closest;
    if (!status && c < 0) /* no candidate to run, not even the closest: refused, never another row's answer */
        return ulam__fail(err, au->abs.upper < 1 ? ULAM_EINFVAR : ULAM_EDIVERGE, 0, -1,
                          "a walk candidate with a finite bound on rho(M^) (none of %d has one; rho(|M|) in [%.3g, "
                          "%.3g]): M's entries may span too many orders of magnitude; scale its rows and columns, or "
                          "use 'ulam direct'",
                          au->ncand, au->abs.lower, au->abs.upper);
    if (c >= 0) {
        ulam_walk_opts *o = &q->run->o;
        o->mode = au->cand[c].mode, o->estimator = au->cand[c].estimator;
        o->kernel.continue_q = au->cand[c].continue_q, o->kernel.kernel_alpha = au->cand[c].kernel_alpha;
        o->policy.guard = NULL; /* the solver holds its own copy */
    }
    return status;
}

/* Pinned: a solver on the options as given (ulam_solve_walks's run). */
static int pin(ulam__query *q, int k, ulam_error *err)
{
    (void)k;
    return ulam_solver_alloc(q->M, q->b, q->o, &q->run->sv, err);
}

/* Iterate until done (a solver that has failed stays failed: its status). */
static int finish(ulam_run *r, ulam_answer *a, ulam_error *err)
{
    int status = ulam_solver_error(r->sv, NULL);
    while (!status && !ulam_solver_done(r->sv)) status = ulam_solver_iterate(r->sv);
    ulam_solver_result(r->sv, &a->walks);
    ulam__solver_guard(r->sv, &a->guard);
    if (status) ulam_solver_error(r->sv, err);
    a->estimate = a->walks.estimate;
    a->std_error = a->walks.std_error;
    a->ci95[0] = a->walks.ci95[0], a->ci95[1] = a->walks.ci95[1]; /* NaN unless the variance is certified finite */
    a->opts.policy.guard = NULL;
    return status;
}

/* Free the solver. */
static void release(ulam_run *r)
{
    r->sv = ulam_solver_free(r->sv);
}

const ulam__method_type ulam__method_walks = {"walks", ULAM_ANSWERS_ENTRY, applies, predict, pin, finish, release};
