/* The method table (GSL's gsl_root_fsolver_type, Lua's luaL_Reg): every way ulam answers
 * (I - M) x = b is a row with its name, its applicability test, its cost prediction and its run;
 * ulam_analysis_start (ulam_auto_start on M alone) chooses among the rows, or starts the one
 * pinned.  A new method is a row here and its own file (src/method_*.c). */
#include "method_row.h"
#include "defaults.h"
#include "analysis.h"
#include "check.h"
#include "round.h"
#include "solve.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The rows, in enum ulam_method_row's order (the walks first: the others compare with its leader). */
static const ulam__method_type *const table[ULAM_NMETHODS] = {
    &ulam__method_walks, &ulam__method_bidir,      &ulam__method_richardson, &ulam__method_gauss_seidel,
    &ulam__method_sequential, &ulam__method_mcsa, &ulam__method_cg,          &ulam__method_gmres};

/* Row k's name, or NULL. */
const char *ulam_method_name(int k)
{
    return k >= 0 && k < ULAM_NMETHODS ? table[k]->name : NULL;
}

/* The row named name, or -1. */
int ulam_method_find(const char *name)
{
    for (int k = 0; name && k < ULAM_NMETHODS; k++)
        if (!strcmp(name, table[k]->name)) return k;
    return -1;
}

/* What row k answers (0 out of range). */
int ulam_method_answers(int k)
{
    return k >= 0 && k < ULAM_NMETHODS ? table[k]->answers : 0;
}

/* The default row options: none pinned, none excluded. */
ulam_method_opts ulam__method_defaults(void)
{
    return (ulam_method_opts){.method = -1, .exclude = 0};
}

/* Check the inputs. */
static int check(const ulam_csr *M, const double *b, const ulam_walk_opts *o, const ulam_method_opts *mo,
                 const ulam_choice *ch, ulam_run **out, ulam_error *err)
{
    if (!M || !b || !o || !ch || !out) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a matrix, b, options, a choice and a run");
    if (mo->method < -1 || mo->method >= ULAM_NMETHODS)
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "a pinned method from -1 (none) to %d", ULAM_NMETHODS - 1);
    return ULAM_OK;
}

/* "lost" to the row named by: its predicted work and the winner's ("the walks' ", "mcsa's "). */
static void lost(char *why, size_t len, double work, const char *by, double by_work)
{
    size_t n = strlen(by);
    snprintf(why, len, "lost: predicted work %.3g units, %s%s%s %.3g", work, by[n - 1] == 's' ? "the " : "", by,
             by[n - 1] == 's' ? "'" : "'s", by_work);
}

/* Every row in order: the applicability test, the prediction, the leader kept (ties to the earlier). */
static int choose(ulam__query *q, ulam_error *err)
{
    ulam_choice *ch = q->ch;
    int leader = -1;
    for (int k = 0; k < ULAM_NMETHODS; k++) {
        ulam_method_verdict *v = &ch->method[k];
        if (!table[k]->applies(q, k, v->why, sizeof v->why)) continue;
        int status = table[k]->predict(q, k, err);
        if (status) return status;
        v->state = ULAM_METHOD_PLANNED;
        if (leader < 0) {
            leader = k;
        } else if (v->predicted_work < ch->method[leader].predicted_work) {
            table[leader]->release(q->run);
            lost(ch->method[leader].why, sizeof ch->method[leader].why, ch->method[leader].predicted_work, table[k]->name,
                 v->predicted_work);
            leader = k;
        } else {
            table[k]->release(q->run);
            if (!v->why[0])
                lost(v->why, sizeof v->why, v->predicted_work, table[leader]->name, ch->method[leader].predicted_work);
        }
    }
    ch->chosen = leader;
    return ULAM_OK;
}

/* As ulam_auto_start, with reach (NULL: none; borrowed until the run is freed) the bounds over
 * every state the walks row's candidates of its kernel walk under (ulam__auto_solver_reach), and
 * an (NULL: none; borrowed likewise) the analysis of M whose transpose, push workspace and plan
 * memo the bidirectional row uses (without one the row makes its own). */
static int start_reach(const ulam_csr *M, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                           const ulam_method_opts *mo, const ulam__reach *reach, ulam_analysis *an, ulam_choice *ch,
                           ulam_run **out, ulam_error *err)
{
    ulam__clear(err);
    if (out) *out = NULL;
    ulam_auto_opts a = ao ? *ao : ulam_auto_defaults();
    ulam_method_opts m = mo ? *mo : ulam_method_defaults();
    int status = check(M, b, o, &m, ch, out, err);
    if (status) return status;
    memset(ch, 0, sizeof *ch);
    ch->chosen = -1, ch->leader_work = NAN;
    ch->walks.chosen = ch->walks.closest = -1;
    for (int k = 0; k < ULAM_NMETHODS; k++) ch->method[k].predicted_work = NAN;
    ulam_run *r = calloc(1, sizeof *r);
    if (!r) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the run");
    r->method = -1, r->M = M, r->b = b, r->o = *o;
    ulam__query q = {.M = M, .b = b, .o = o, .ao = &a, .mo = &m, .ch = ch, .run = r, .reach = reach, .an = an};
    if (m.method >= 0) {
        ch->pinned = 1;
        status = table[m.method]->pin(&q, m.method, err);
        if (!status) ch->chosen = m.method;
    } else {
        status = choose(&q, err);
    }
    if (!status && ch->chosen < 0) status = ulam__fail(err, ULAM_EINVAL, 0, -1, "a method that applies to this query");
    if (status) {
        ulam_run_free(r);
        return status;
    }
    ch->method[ch->chosen].state = ULAM_METHOD_CHOSEN;
    ch->method[ch->chosen].why[0] = 0;
    r->method = ch->chosen;
    ch->bidir_route = r->method == ULAM_METHOD_BIDIRECTIONAL ? r->br != NULL : -1;
    *out = r;
    return ULAM_OK;
}

/* Choose (or start the pinned row) and hand out the run. */
int ulam_auto_start(const ulam_csr *M, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                    const ulam_method_opts *mo, ulam_choice *ch, ulam_run **out, ulam_error *err)
{
    return start_reach(M, b, o, ao, mo, NULL, NULL, ch, out, err);
}

/* The method table's choice on an analysis: its walks row on the analysis' bounds over every
 * state when it shares them (ulam_analysis_opts.shared_bounds), else on each start's reach as on
 * M alone; the bidirectional row on its transpose and plans either way. */
int ulam_analysis_start(ulam_analysis *a, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                        const ulam_method_opts *mo, ulam_choice *ch, ulam_run **out, ulam_error *err)
{
    if (!a) {
        ulam__clear(err);
        if (out) *out = NULL;
        return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis");
    }
    if (!ulam__analysis_shares_bounds(a)) /* its transpose and plans still serve the bidirectional row */
        return start_reach(ulam__analysis_matrix(a), b, o, ao, mo, NULL, a, ch, out, err);
    ulam_auto_opts p = ao ? *ao : ulam_auto_defaults();
    int status = ulam__analysis_pin_guard(a, o, &p, err);
    return status ? status
                  : start_reach(ulam__analysis_matrix(a), b, o, &p, mo, ulam__analysis_bounds(a), a, ch, out, err);
}

/* The walk solver of a walks run (borrowed), or NULL. */
ulam_solver *ulam_run_solver(ulam_run *r)
{
    return r && r->method == ULAM_METHOD_WALKS ? r->sv : NULL;
}

/* Run to the end and fill *a. */
int ulam_run_finish(ulam_run *r, ulam_answer *a, ulam_error *err)
{
    ulam__clear(err);
    if (!r || !a || r->method < 0) return ulam__fail(err, ULAM_EINVAL, 0, -1, "a started run and an answer");
    memset(a, 0, sizeof *a);
    a->method = r->method, a->opts = r->o;
    a->estimate = a->std_error = a->residual = NAN;
    a->ci95[0] = a->ci95[1] = NAN;
    int status = table[r->method]->finish(r, a, err);
    a->status = status;
    return status;
}

/* Free a run. */
ulam_run *ulam_run_free(ulam_run *r)
{
    if (!r) return NULL;
    for (int k = 0; k < ULAM_NMETHODS; k++) table[k]->release(r);
    free(r);
    return NULL;
}

/* Choose, run and free in one call. */
int ulam_auto(const ulam_csr *M, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
              const ulam_method_opts *mo, ulam_choice *ch, ulam_answer *a, ulam_error *err)
{
    ulam_choice *own = ch ? NULL : malloc(sizeof *own);
    if (!ch && !own) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the choice");
    ulam_run *r = NULL;
    int status = ulam_auto_start(M, b, o, ao, mo, ch ? ch : own, &r, err);
    if (!status) status = ulam_run_finish(r, a, err);
    ulam_run_free(r);
    free(own);
    return status;
}

/* The pins ulam_solve takes from o, as `ulam solve` pins what its command line gives: a walk
 * option that differs from ulam_walk_defaults() (mode, estimator, continuation, exponent) pins
 * that part of the walks' race; all four, or weighted starts, pin the walks row itself. */
static void solve_pins(const ulam_walk_opts *o, ulam_auto_opts *ao, ulam_method_opts *mo)
{
    ulam_walk_opts d = ulam_walk_defaults();
    *ao = ulam_auto_defaults(), *mo = ulam_method_defaults();
    ao->pin_mode = o->mode != d.mode;
    ao->pin_estimator = o->estimator != d.estimator;
    ao->pin_continue = o->kernel.continue_q != d.kernel.continue_q && (o->kernel.continue_q > 0 || d.kernel.continue_q > 0);
    ao->pin_alpha = o->kernel.kernel_alpha != d.kernel.kernel_alpha;
    ao->guard = o->policy.guard;
    if ((ao->pin_mode && ao->pin_estimator && ao->pin_continue && ao->pin_alpha) || o->query.nstarts > 0)
        mo->method = ULAM_METHOD_WALKS;
}

/* One unknown on an analysis, as `ulam solve`: pins from o when ao is NULL, the default walk
 * budget lifted under a rel_err target; choose (or start mo's row), run to the end, free. */
int ulam_analysis_solve(ulam_analysis *a, const double *b, const ulam_walk_opts *o, const ulam_auto_opts *ao,
                        const ulam_method_opts *mo, ulam_choice *ch, ulam_answer *ans, ulam_error *err)
{
    ulam__clear(err);
    if (!a || !b || !o || !ans) return ulam__fail(err, ULAM_EINVAL, 0, -1, "an analysis, b, options and an answer");
    ulam_walk_opts lifted = ulam__lift_default_cap(o);
    ulam_auto_opts pa;
    ulam_method_opts pm;
    solve_pins(&lifted, &pa, &pm);
    if (ao) pa = *ao;
    if (mo) pm = *mo;
    ulam_choice *own = ch ? NULL : malloc(sizeof *own);
    if (!ch && !own) return ulam__fail(err, ULAM_ENOMEM, 0, -1, "memory for the choice");
    ulam_run *r = NULL;
    int status = ulam_analysis_start(a, b, &lifted, &pa, &pm, ch ? ch : own, &r, err);
    if (!status) status = ulam_run_finish(r, ans, err);
    ulam_run_free(r);
    free(own);
    return status;
}
