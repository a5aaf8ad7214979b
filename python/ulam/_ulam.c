/* ulam's Python binding, the C half (python/ulam/__init__.py is the other): a System holds M
 * as an ulam_csr over NumPy arrays (borrowed, referenced), and a query runs the library's method
 * table (ulam_auto_start, ulam_run_finish) with the GIL released during the guards, pilots and
 * walks.  Ctrl-C sets the walks' interrupt flag (a SIGINT handler installed for the query in the
 * main thread); the run stops at the next block and the query returns what it has, marked
 * interrupted, for the Python half to raise KeyboardInterrupt with.  Errors come back as the
 * library's status and message in the result (the Python half raises its exceptions); this file
 * raises only for bad arguments and memory. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "ulam.h"
#include "ulam_options.h"
#include "ulam_report.h"
#include "ulam_study.h"

/* The interrupt flag of the query running in the main thread (the SIGINT handler's only way in). */
static volatile int *sigint_flag;

/* SIGINT during a query: ask the walks to stop at the next block. */
static void on_sigint(int sig)
{
    (void)sig;
    if (sigint_flag) *sigint_flag = 1;
}

/* A system (I - M) x = b's matrix, with what the queries reuse. */
typedef struct {
    PyObject_HEAD
    ulam_csr M;          /* over the arrays below (never freed by ulam_csr_free) */
    PyArrayObject *rowptr, *colidx, *val;
    ulam_guard guard;    /* the analog kernel's guards at exponent 1, computed by the first query
                            that reuses them (see system_analysis) */
    int have_guard;
    ulam_analysis *an;   /* the library's analysis of M (analog, exponent 1): bounds over every
                            state, kept kernel rows, made by the first query that reuses them */
    ulam_csr *Mt;        /* M's transpose, made by the first single-source query */
} SystemObject;

/* An int64 / int32 / float64 C-contiguous 1-d array from obj (a new reference), or NULL with a
 * TypeError: the Python half converts, so anything else is a caller's mistake. */
static PyArrayObject *array_of(PyObject *obj, int type, const char *what)
{
    if (!PyArray_Check(obj) || PyArray_TYPE((PyArrayObject *)obj) != type || PyArray_NDIM((PyArrayObject *)obj) != 1 ||
        !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)obj)) {
        PyErr_Format(PyExc_TypeError, "%s: expected a C-contiguous 1-d array of the library's type", what);
        return NULL;
    }
    Py_INCREF(obj);
    return (PyArrayObject *)obj;
}

/* Free a system. */
static void System_dealloc(SystemObject *self)
{
    ulam_analysis_free(self->an);
    ulam_csr_free(self->Mt);
    Py_XDECREF(self->rowptr);
    Py_XDECREF(self->colidx);
    Py_XDECREF(self->val);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* System(indptr int64, indices int32, data float64, n): M borrowed from the arrays, checked
 * (ulam_csr_check) once; a breach is a ValueError naming the status. */
static int System_init(SystemObject *self, PyObject *args, PyObject *kw)
{
    PyObject *rp, *ci, *va;
    long long n;
    (void)kw;
    if (!PyArg_ParseTuple(args, "OOOL", &rp, &ci, &va, &n)) return -1;
    if (!(self->rowptr = array_of(rp, NPY_INT64, "indptr")) || !(self->colidx = array_of(ci, NPY_INT32, "indices")) ||
        !(self->val = array_of(va, NPY_FLOAT64, "data")))
        return -1;
    if (n < 1 || n > ULAM_MAX_DIM || PyArray_SIZE(self->rowptr) != n + 1 ||
        PyArray_SIZE(self->colidx) != PyArray_SIZE(self->val)) {
        PyErr_SetString(PyExc_ValueError, "indptr must have n + 1 entries and indices as many as data");
        return -1;
    }
    self->M = (ulam_csr){.nrows = n, .ncols = n, .rowptr = PyArray_DATA(self->rowptr),
                         .colidx = PyArray_DATA(self->colidx), .val = PyArray_DATA(self->val)};
    int status = ulam_csr_check(&self->M);
    if (status) {
        PyErr_Format(PyExc_ValueError, "%d: %s", status, ulam_strerror(status));
        return -1;
    }
    return 0;
}

/* The reusable analysis a query of this system takes instead of its own passes over M: the
 * library's analysis object (ulam_analysis_start races the walks on its bounds over every
 * state) and the guards of the analog kernel at exponent 1 (ulam_auto_opts.guard). */
static int system_analysis(SystemObject *self, ulam_auto_opts *ao, ulam_error *err)
{
    if (!self->an) {
        ulam_analysis_opts ao = ulam_analysis_defaults();
        ao.shared_bounds = 1; /* one pass over M for every query's walks */
        int status = ulam_analysis_alloc(&self->M, &ao, &self->an, err);
        if (status) return status;
    }
    if (!self->have_guard) {
        int status;
        Py_BEGIN_ALLOW_THREADS
        status = ulam_guard_check(&self->M, 0.0, NULL, &self->guard, err);
        Py_END_ALLOW_THREADS
        if (status) return status;
        self->have_guard = 1;
    }
    ao->guard = &self->guard;
    return ULAM_OK;
}

/* d[key] as a double / an integer (def when absent); -1 with an exception set on a bad value. */
static int get_double(PyObject *d, const char *key, double *v)
{
    PyObject *o = PyDict_GetItemString(d, key);
    if (!o || o == Py_None) return 0;
    *v = PyFloat_AsDouble(o);
    return *v == -1.0 && PyErr_Occurred() ? -1 : 0;
}

static int get_int64(PyObject *d, const char *key, int64_t *v)
{
    PyObject *o = PyDict_GetItemString(d, key);
    if (!o || o == Py_None) return 0;
    long long x = PyLong_AsLongLong(o);
    if (x == -1 && PyErr_Occurred()) return -1;
    *v = x;
    return 0;
}

static int get_int(PyObject *d, const char *key, int *v)
{
    int64_t x = *v;
    if (get_int64(d, key, &x)) return -1;
    *v = (int)x;
    return 0;
}

/* The walk and choice options from the Python half's dict (its keys: the fields' names; its
 * "set", a dict of option name to text, through the library's options table, ulam_options_set):
 * 0, -1 with an exception set, or 1 with err the library's refusal of a value. */
static int read_opts(PyObject *d, ulam_walk_opts *o, ulam_auto_opts *ao, ulam_method_opts *mo, int *reuse,
                     int *catch_sigint, ulam_error *err)
{
    int64_t seed = (int64_t)o->exec.seed;
    if (get_int(d, "mode", &o->mode) || get_int(d, "estimator", &o->estimator) ||
        get_double(d, "continue_q", &o->kernel.continue_q) || get_double(d, "kernel_alpha", &o->kernel.kernel_alpha) ||
        get_int64(d, "max_walks", &o->stop.max_walks) || get_double(d, "rel_err", &o->stop.rel_err) ||
        get_double(d, "max_seconds", &o->stop.max_seconds) || get_int64(d, "max_steps", &o->stop.max_steps) ||
        get_double(d, "roulette", &o->kernel.roulette) || get_double(d, "split", &o->kernel.split) || get_int64(d, "seed", &seed) ||
        get_int(d, "threads", &o->exec.threads) || get_int(d, "force", &o->policy.force) ||
        get_int(d, "assume_finite", &o->policy.assume_finite) || get_int(d, "whole_kernel", &o->kernel.whole_kernel) ||
        get_int(d, "method", &mo->method) || get_int(d, "pin_mode", &ao->pin_mode) ||
        get_int(d, "pin_estimator", &ao->pin_estimator) || get_int(d, "pin_continue", &ao->pin_continue) ||
        get_int(d, "pin_alpha", &ao->pin_alpha) || get_int(d, "reuse", reuse) ||
        get_int(d, "catch_sigint", catch_sigint))
        return -1;
    o->exec.seed = (uint64_t)seed;
    int exclude = 0;
    if (get_int(d, "exclude", &exclude)) return -1;
    mo->exclude = (unsigned)exclude;
    PyObject *set = PyDict_GetItemString(d, "set"), *key, *value;
    Py_ssize_t pos = 0;
    while (set && PyDict_Check(set) && PyDict_Next(set, &pos, &key, &value)) {
        const char *name = PyUnicode_AsUTF8(key), *text = PyUnicode_AsUTF8(value);
        if (!name || !text) return -1;
        int status = ulam_options_set(ULAM_OPTIONS_WALK, o, name, text, err);
        if (status) return err->status = status, 1;
    }
    return 0;
}

/* The dict of a refused option (read_opts's 1). */
static PyObject *refusal(const ulam_error *err)
{
    return Py_BuildValue("{s:i,s:s,s:L,s:O}", "status", err->status, "message", err->msg, "error_index", -1LL,
                         "interrupted", Py_False);
}

/* Set d[key] = v (a new reference, stolen); -1 on failure. */
static int put(PyObject *d, const char *key, PyObject *v)
{
    if (!v) return -1;
    int rc = PyDict_SetItemString(d, key, v);
    Py_DECREF(v);
    return rc;
}

/* A radius as a dict: rho, lower, upper, converged, iterations. */
static PyObject *radius(const ulam_power *p)
{
    return Py_BuildValue("{s:d,s:d,s:d,s:i,s:i}", "rho", p->rho, "lower", p->lower, "upper", p->upper, "converged",
                         p->converged, "iterations", p->iterations);
}

/* The walks row's candidates as a list of dicts (the CLI's "auto" keys, names as numbers). */
static PyObject *candidates(const ulam_auto_result *res)
{
    PyObject *l = PyList_New(res->ncand);
    for (int k = 0; l && k < res->ncand; k++) {
        const ulam_auto_candidate *c = &res->cand[k];
        PyObject *d = Py_BuildValue(
            "{s:i,s:i,s:d,s:d,s:d,s:d,s:O,s:i,s:i,s:L,s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:d}", "mode", c->mode, "estimator",
            c->estimator, "continue_q", c->continue_q, "kernel_alpha", c->kernel_alpha, "rho_hat", c->hat.rho,
            "rho_hat_upper", c->hat.upper, "certified", c->certified ? Py_True : Py_False, "state", c->state, "status",
            c->status, "pilot_walks", (long long)c->pilot_walks, "variance", c->variance, "variance_rel_error",
            c->variance_rel_error, "steps_per_walk", c->steps_per_walk, "work_per_walk", c->work_per_walk, "cost",
            c->cost, "predicted_walks", c->predicted_walks, "predicted_work", c->predicted_work, "predicted_seconds",
            c->predicted_seconds);
        if (!d) {
            Py_CLEAR(l);
            break;
        }
        PyList_SET_ITEM(l, k, d);
    }
    return l;
}

/* The choice as a dict: chosen row, pinned, every row's verdict, the walks' race, bidirectional's plan. */
static PyObject *choice(const ulam_choice *ch)
{
    PyObject *rows = PyList_New(ULAM_NMETHODS);
    for (int k = 0; rows && k < ULAM_NMETHODS; k++) {
        const ulam_method_verdict *v = &ch->method[k];
        PyObject *d = Py_BuildValue("{s:s,s:i,s:d,s:s}", "name", ulam_method_name(k), "state", v->state,
                                    "predicted_work", v->predicted_work, "why", v->why);
        if (!d) {
            Py_CLEAR(rows);
            break;
        }
        PyList_SET_ITEM(rows, k, d);
    }
    const ulam_auto_result *w = &ch->walks;
    const ulam_bidir_plan_info *p = &ch->bidir;
    return Py_BuildValue("{s:i,s:O,s:N,s:d,s:{s:i,s:i,s:i,s:i,s:d,s:d,s:d,s:d,s:N,s:N},s:{s:d,s:L,s:L,s:L,s:d,s:d}}",
                         "chosen", ch->chosen, "pinned", ch->pinned ? Py_True : Py_False, "rows", rows, "leader_work",
                         ch->leader_work, "walks", "chosen", w->chosen, "closest", w->closest, "by_work", w->by_work,
                         "stages", w->stages, "pilot_work", w->pilot_work, "reused_work", w->reused_work, "seconds",
                         w->seconds, "abs_upper", w->abs.upper, "candidates", candidates(w), "abs", radius(&w->abs),
                         "bidirectional", "rmax", p->rmax, "push_ops", (long long)p->push.ops, "push_krylov",
                         (long long)p->push.krylov, "pilot_walks", (long long)p->pilot_walks, "predicted_walks",
                         p->predicted_walks, "mean_visits", p->mean_visits);
}

/* A walk result as a dict (the library's field names). */
static PyObject *walk_result(const ulam_walk_result *r)
{
    return Py_BuildValue("{s:d,s:d,s:d,s:L,s:L,s:L,s:L,s:d,s:i,s:d,s:d,s:d,s:d,s:i,s:d,s:i,s:i,s:L,s:d,s:i,s:i,s:N,s:i,s:i,s:L,s:d}",
                         "estimate", r->estimate, "std_error", r->std_error, "variance", r->variance, "walks",
                         (long long)r->walks, "steps", (long long)r->steps, "cut", (long long)r->cut, "rows",
                         (long long)r->rows, "max_share", r->max_share, "variance_finite", r->variance_finite,
                         "score_bound", r->score_bound, "tail_bound", r->tail_bound, "min_walks", r->min_walks,
                         "variance_rel_error", r->variance_rel_error, "rel_err_met", r->rel_err_met, "cut_bound",
                         r->cut_bound, "cut_stop", r->cut_stop, "out_of_reach", r->out_of_reach, "unreached",
                         (long long)r->unreached, "seconds", r->seconds, "threads", r->threads, "interrupted",
                         r->interrupted, "rho4", radius(&r->rho4), "fourth_finite", r->fourth_finite, "push_sweeps",
                         r->push_sweeps, "push_ops", (long long)r->push_ops, "push_residual", r->push_residual);
}

/* The kinds of JSON json_text writes: a walk result's members, the choice's "auto", a
 * bidirectional run's whole report. */
enum { JSON_WALK, JSON_AUTO, JSON_BIDIR };

/* What writer(f, ...) writes, as a Python str (open_memstream around the library's FILE *
 * writers): the library's JSON, parsed by the Python half. */
static PyObject *json_text(const ulam_walk_opts *o, const ulam_answer *a, const ulam_choice *ch, int kind, int interrupted)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) return PyErr_NoMemory();
    if (kind == JSON_BIDIR) { /* the report ulam solve --json prints (no guards: the CLI computes them beside) */
        ulam_bidir_opts bo = ch->bidir_opts;
        bo.walk = *o, bo.b_index = NULL, bo.b_value = NULL; /* the run that owned b's arrays is freed */
        ulam_bidir_report rep = {.opts = &bo, .result = &a->bidir, .dense = ch->bidir_route == 1, .node_base = 1};
        ulam_report_fprint(f, ULAM_REPORT_BIDIR, &rep, ULAM_REPORT_JSON);
    } else {
        fputc('{', f);
        if (kind == JSON_WALK) ulam_walk_result_json(f, o, &a->walks, &a->guard);
        else ulam_choice_fprint(f, ch, 1, ULAM_REPORT_JSON);
        fprintf(f, "\"interrupted\": %s}", interrupted ? "true" : "false");
    }
    if (fclose(f)) {
        free(buf);
        return PyErr_NoMemory();
    }
    PyObject *s = PyUnicode_FromStringAndSize(buf, (Py_ssize_t)len);
    free(buf);
    return s;
}

/* The answer, the choice and the status as one dict. */
static PyObject *answer(int status, const ulam_error *err, const ulam_choice *ch, int started, const ulam_answer *a,
                        int ran, int interrupted)
{
    PyObject *d = PyDict_New();
    if (!d) return NULL;
    const ulam_walk_opts *o = &a->opts;
    if (put(d, "status", PyLong_FromLong(status)) || put(d, "message", PyUnicode_FromString(err->msg)) ||
        put(d, "error_index", PyLong_FromLongLong((long long)err->index)) ||
        put(d, "interrupted", PyBool_FromLong(interrupted)) ||
        (started && put(d, "choice", choice(ch))))
        goto fail;
    if (!ran) return d;
    if (put(d, "method", PyUnicode_FromString(ulam_method_name(a->method))) ||
        put(d, "estimate", PyFloat_FromDouble(a->estimate)) || put(d, "std_error", PyFloat_FromDouble(a->std_error)) ||
        put(d, "ci95", Py_BuildValue("(dd)", a->ci95[0], a->ci95[1])) || put(d, "walk", walk_result(&a->walks)) ||
        put(d, "opts", Py_BuildValue("{s:i,s:i,s:d,s:d,s:K,s:L}", "mode", o->mode, "estimator", o->estimator,
                                     "continue_q", o->kernel.continue_q, "kernel_alpha", o->kernel.kernel_alpha, "seed",
                                     (unsigned long long)o->exec.seed, "index", (long long)o->query.index)) ||
        put(d, "rho_abs", radius(&a->guard.abs)) || put(d, "rho_hat", radius(&a->guard.hat[o->mode == 1])) ||
        put(d, "iterations", PyLong_FromLong(a->iterations)) || put(d, "residual", PyFloat_FromDouble(a->residual)))
        goto fail;
    int stopped = interrupted || a->walks.interrupted;
    if (a->method == ULAM_METHOD_WALKS && put(d, "report_json", json_text(o, a, ch, JSON_WALK, stopped))) goto fail;
    if (started && !ch->pinned && put(d, "auto_json", json_text(o, a, ch, JSON_AUTO, stopped))) goto fail;
    if (a->method == ULAM_METHOD_BIDIRECTIONAL && started &&
        put(d, "report_json", json_text(o, a, ch, JSON_BIDIR, stopped)))
        goto fail;
    return d;
fail:
    Py_DECREF(d);
    return NULL;
}

/* Install the SIGINT handler for flag (main thread only); *old gets the one to restore. */
static void catch_sigint(volatile int *flag, struct sigaction *old)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigint_flag = flag;
    sigaction(SIGINT, &sa, old);
}

/* Restore the SIGINT handler. */
static void release_sigint(const struct sigaction *old)
{
    sigaction(SIGINT, old, NULL);
    sigint_flag = NULL;
}

/* Walk the solver round by round, the GIL released during each; progress (callable or None) is
 * called with (walks, estimate, std_error) after each round; an exception it raises stops the
 * walks (returned as -1 with the exception set, *status the walks'). */
static int walk_rounds(ulam_solver *sv, PyObject *progress, volatile int *flag, int *status)
{
    while (!*status && !ulam_solver_done(sv)) {
        Py_BEGIN_ALLOW_THREADS
        *status = ulam_solver_iterate(sv);
        Py_END_ALLOW_THREADS
        if (progress == Py_None || *status) continue;
        ulam_walk_result r;
        ulam_solver_result(sv, &r);
        PyObject *v = PyObject_CallFunction(progress, "Ldd", (long long)r.walks, r.estimate, r.std_error);
        if (!v) {
            *flag = 1;
            return -1;
        }
        Py_DECREF(v);
    }
    return 0;
}

/* Forward walks' (x, std_error) of every component as a tuple of two NumPy arrays of n (a new
 * reference), or NULL with an exception set. */
static PyObject *forward_vectors(const ulam_solver *sv, int64_t n)
{
    npy_intp dn = (npy_intp)n;
    PyObject *x = PyArray_SimpleNew(1, &dn, NPY_FLOAT64), *se = PyArray_SimpleNew(1, &dn, NPY_FLOAT64);
    if (!x || !se) {
        Py_XDECREF(x), Py_XDECREF(se);
        return NULL;
    }
    int st = ulam_solver_vectors(sv, PyArray_DATA((PyArrayObject *)x), PyArray_DATA((PyArrayObject *)se));
    return Py_BuildValue("(NNi)", x, se, st);
}

/* System.query(b, index, opts, progress): run the library's `ulam solve` for x_index. */
static PyObject *System_query(SystemObject *self, PyObject *args)
{
    PyObject *bobj, *od, *progress;
    long long index;
    if (!PyArg_ParseTuple(args, "OLO!O", &bobj, &index, &PyDict_Type, &od, &progress)) return NULL;
    PyArrayObject *barr = array_of(bobj, NPY_FLOAT64, "b");
    if (!barr) return NULL;
    if (PyArray_SIZE(barr) != self->M.nrows) {
        Py_DECREF(barr);
        return PyErr_Format(PyExc_ValueError, "b has %lld entries, M has %lld rows", (long long)PyArray_SIZE(barr),
                            (long long)self->M.nrows);
    }
    ulam_walk_opts o = ulam_walk_defaults();
    ulam_auto_opts ao = ulam_auto_defaults();
    ulam_method_opts mo = ulam_method_defaults();
    int reuse = 0, catch = 0, vectors = 0;
    ulam_error oerr = {0};
    int rc = read_opts(od, &o, &ao, &mo, &reuse, &catch, &oerr);
    if (rc || get_int(od, "vectors", &vectors)) {
        Py_DECREF(barr);
        return rc > 0 ? refusal(&oerr) : NULL;
    }
    volatile int flag = 0;
    o.query.index = index, o.stop.interrupt = &flag;
    ulam_choice *ch = malloc(sizeof *ch);
    ulam_answer *a = calloc(1, sizeof *a);
    if (!ch || !a) {
        free(ch), free(a);
        Py_DECREF(barr);
        return PyErr_NoMemory();
    }
    ulam_error err = {0};
    ulam_run *run = NULL;
    const double *b = PyArray_DATA(barr);
    int status = reuse ? system_analysis(self, &ao, &err) : ULAM_OK, started = 0, ran = 0, cb = 0;
    struct sigaction old;
    if (catch) catch_sigint(&flag, &old);
    if (!status) {
        Py_BEGIN_ALLOW_THREADS
        status = reuse ? ulam_analysis_start(self->an, b, &o, &ao, &mo, ch, &run, &err)
                       : ulam_auto_start(&self->M, b, &o, &ao, &mo, ch, &run, &err);
        Py_END_ALLOW_THREADS
        started = 1;
    }
    ulam_solver *sv = ulam_run_solver(run);
    if (!status && sv) cb = walk_rounds(sv, progress, &flag, &status);
    PyObject *xs = NULL; /* forward walks: (x, std_error) of every component, when asked */
    if (!cb && vectors && sv && (!status || flag) && !(xs = forward_vectors(sv, self->M.nrows))) cb = 1;
    if (run && (!status || sv)) {
        int st;
        Py_BEGIN_ALLOW_THREADS
        st = ulam_run_finish(run, a, status ? NULL : &err);
        Py_END_ALLOW_THREADS
        if (status && sv) ulam_solver_error(sv, &err);
        else status = st;
        ran = 1;
    }
    if (catch) release_sigint(&old);
    ulam_run_free(run);
    PyObject *d = cb ? NULL : answer(status, &err, ch, started, a, ran, flag && !cb);
    if (d && xs && put(d, "vectors", xs)) Py_CLEAR(d);
    else if (!d) Py_XDECREF(xs);
    free(ch), free(a);
    Py_DECREF(barr);
    return d;
}

/* A study run as a dict. */
static PyObject *study_run(const ulam_study_run *u)
{
    return Py_BuildValue("{s:s,s:d,s:i,s:K,s:i,s:d,s:d,s:d,s:L,s:L,s:d,s:O}", "method",
                         ulam_study_method_get(u->method)->name, "budget", u->budget_value, "repeat", u->repeat, "seed",
                         (unsigned long long)u->seed, "status", u->status, "estimate", u->estimate, "std_error",
                         u->std_error, "abs_error", u->abs_error, "walks", (long long)u->walks, "steps",
                         (long long)u->steps, "seconds", u->seconds, "covered", u->covered ? Py_True : Py_False);
}

/* A study's cell as a dict. */
static PyObject *study_cell(int m, double budget, const ulam_study_cell *c)
{
    return Py_BuildValue("{s:s,s:d,s:i,s:i,s:d,s:d,s:d,s:d,s:d,s:d}", "method", ulam_study_method_get(m)->name, "budget",
                         budget, "runs", c->runs, "failed", c->failed, "rmse", c->rmse, "mean_stderr", c->mean_stderr,
                         "honesty", c->honesty, "coverage", c->coverage, "seconds", c->seconds, "work", c->work);
}

/* Append o (a new reference, stolen) to list; nonzero on failure. */
static int append(PyObject *list, PyObject *o)
{
    int rc = !o || PyList_Append(list, o);
    Py_XDECREF(o);
    return rc;
}

/* d with what a study holds as lists of dicts: runs, cells, screens (the chosen methods'); d, or
 * NULL with d released. */
static PyObject *study_lists(const ulam_study *st, const double *budgets, int nb, int repeats, PyObject *d)
{
    PyObject *runs = PyList_New(0), *cells = PyList_New(0), *screens = PyList_New(0);
    int bad = !runs || !cells || !screens || PyDict_SetItemString(d, "runs", runs) ||
              PyDict_SetItemString(d, "cells", cells) || PyDict_SetItemString(d, "screens", screens);
    for (int k = 0; !bad && k < ULAM_STUDY_METHODS; k++) {
        ulam_study_screen sc;
        ulam_study_screen_get(st, k, &sc);
        if (!sc.on) continue;
        bad = append(screens, Py_BuildValue("{s:s,s:O,s:s}", "method", ulam_study_method_get(k)->name, "infinite",
                                            sc.infinite ? Py_True : Py_False, "refused", sc.why));
        for (int b = 0; !bad && b < nb; b++) {
            ulam_study_cell c;
            if (ulam_study_cell_get(st, k, b, &c)) bad = append(cells, study_cell(k, budgets[b], &c));
            for (int r = 0; !bad && r < repeats; r++) {
                ulam_study_run u;
                if (ulam_study_run_get(st, k, b, r, &u)) bad = append(runs, study_run(&u));
            }
        }
    }
    Py_XDECREF(runs), Py_XDECREF(cells), Py_XDECREF(screens);
    if (bad) Py_CLEAR(d);
    return d;
}

/* System.study(b, index, methods, budgets, time_budgets, repeats, seed, threads): a variance study
 * of x_index (ulam_study_*; methods: grid indices or None for all 18) as a dict: status, message,
 * exact, direct, done, runs, cells, screens (lists of dicts). */
static PyObject *System_study(SystemObject *self, PyObject *args)
{
    PyObject *bobj, *mobj, *bud;
    long long index;
    int time_budgets, repeats, threads;
    unsigned long long seed;
    if (!PyArg_ParseTuple(args, "OLOOiiKi", &bobj, &index, &mobj, &bud, &time_budgets, &repeats, &seed, &threads))
        return NULL;
    PyArrayObject *barr = array_of(bobj, NPY_FLOAT64, "b");
    if (!barr) return NULL;
    int methods[ULAM_STUDY_METHODS], nm = 0, nb = 0;
    double budgets[16];
    PyObject *ms = mobj == Py_None ? NULL : PySequence_Fast(mobj, "methods"), *bs = PySequence_Fast(bud, "budgets");
    int bad = (mobj != Py_None && !ms) || !bs || PyArray_SIZE(barr) != self->M.nrows;
    for (Py_ssize_t k = 0; !bad && ms && k < PySequence_Fast_GET_SIZE(ms) && nm < ULAM_STUDY_METHODS; k++)
        methods[nm++] = (int)PyLong_AsLong(PySequence_Fast_GET_ITEM(ms, k));
    for (Py_ssize_t k = 0; !bad && k < PySequence_Fast_GET_SIZE(bs) && nb < 16; k++)
        budgets[nb++] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(bs, k));
    Py_XDECREF(ms), Py_XDECREF(bs);
    if (bad || PyErr_Occurred()) {
        Py_DECREF(barr);
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "b has not n entries");
        return NULL;
    }
    ulam_study_params p = ulam_study_defaults();
    volatile int flag = 0;
    p.methods = ms ? methods : NULL, p.nmethods = nm, p.budgets = budgets, p.nbudgets = nb;
    p.time_budgets = time_budgets, p.repeats = repeats, p.seed = seed, p.threads = threads, p.interrupt = &flag;
    ulam_study *st = NULL;
    ulam_error err = {0};
    int status;
    struct sigaction old;
    catch_sigint(&flag, &old);
    Py_BEGIN_ALLOW_THREADS
    status = ulam_study_alloc(&self->M, PyArray_DATA(barr), index, &p, &st, &err);
    if (!status) status = ulam_study_run_all(st, NULL, NULL, &err);
    Py_END_ALLOW_THREADS
    release_sigint(&old);
    Py_DECREF(barr);
    const ulam_study_ref *ref = ulam_study_exact(st);
    PyObject *d = Py_BuildValue("{s:i,s:s,s:d,s:O,s:O,s:O}", "status", status, "message", status ? err.msg : "",
                                "exact", ref ? ref->exact : NAN, "direct", ref && ref->direct ? Py_True : Py_False,
                                "done", st && ulam_study_done(st) ? Py_True : Py_False, "interrupted",
                                flag ? Py_True : Py_False);
    if (d && st) d = study_lists(st, budgets, nb, repeats, d);
    ulam_study_free(st);
    return d;
}

/* System.fpush(source, opts): every x_i of (I - M) x = e_source (ulam_fpush_solve: a forward push
 * and walks from its residual) as a dict: status, message, error_index, x, std_error, lo, hi (NumPy
 * arrays of n), walks, steps, rmax, push_ops, interrupted, seconds. */
static PyObject *System_fpush(SystemObject *self, PyObject *args)
{
    PyObject *od;
    long long source;
    if (!PyArg_ParseTuple(args, "LO!", &source, &PyDict_Type, &od)) return NULL;
    ulam_fpush_opts o = ulam_fpush_defaults();
    ulam_auto_opts ao = ulam_auto_defaults();
    ulam_method_opts mo = ulam_method_defaults();
    int reuse = 0, catch = 0;
    ulam_error oerr = {0};
    int rc = read_opts(od, &o.walk, &ao, &mo, &reuse, &catch, &oerr);
    if (rc > 0) return refusal(&oerr);
    if (rc || get_double(od, "fpush_rel_err", &o.rel_err) || get_int64(od, "fpush_walks", &o.walks))
        return NULL;
    o.walk.mode = ULAM_FORWARD, o.source = source;
    npy_intp n = (npy_intp)self->M.nrows;
    PyObject *x = PyArray_SimpleNew(1, &n, NPY_FLOAT64), *se = PyArray_SimpleNew(1, &n, NPY_FLOAT64),
             *lo = PyArray_SimpleNew(1, &n, NPY_FLOAT64), *hi = PyArray_SimpleNew(1, &n, NPY_FLOAT64);
    PyObject *d = x && se && lo && hi ? PyDict_New() : NULL;
    if (!d) goto fail;
    volatile int flag = 0;
    o.walk.stop.interrupt = &flag;
    ulam_error err = {0};
    ulam_fpush_info info = {0};
    int status = ULAM_OK;
    struct sigaction old;
    if (catch) catch_sigint(&flag, &old);
    Py_BEGIN_ALLOW_THREADS
    if (!self->Mt) status = ulam_csr_transpose(&self->M, &self->Mt);
    if (status) err = (ulam_error){.status = status, .msg = "memory for M's transpose"};
    else status = ulam_fpush_solve(&self->M, self->Mt, &o, PyArray_DATA((PyArrayObject *)x),
                                   PyArray_DATA((PyArrayObject *)se), PyArray_DATA((PyArrayObject *)lo),
                                   PyArray_DATA((PyArrayObject *)hi), &info, &err);
    Py_END_ALLOW_THREADS
    if (catch) release_sigint(&old);
    if (put(d, "status", PyLong_FromLong(status)) || put(d, "message", PyUnicode_FromString(err.msg)) ||
        put(d, "error_index", PyLong_FromLongLong((long long)err.index)) || put(d, "x", x) ||
        put(d, "std_error", se) || put(d, "lo", lo) || put(d, "hi", hi))
        goto fail_d;
    if (put(d, "walks", PyLong_FromLongLong((long long)info.walks)) ||
        put(d, "steps", PyLong_FromLongLong((long long)info.steps)) || put(d, "rmax", PyFloat_FromDouble(info.rmax)) ||
        put(d, "push_ops", PyLong_FromLongLong((long long)info.push.ops)) ||
        put(d, "residual_bound", PyFloat_FromDouble(info.residual_bound)) ||
        put(d, "dense", PyBool_FromLong(info.dense)) || put(d, "interrupted", PyBool_FromLong(info.interrupted == 1 || flag)) ||
        put(d, "stopped_at_time", PyBool_FromLong(info.interrupted == 2)) ||
        put(d, "seconds", PyFloat_FromDouble(info.seconds)))
        goto fail_d;
    return d;
fail:
    Py_XDECREF(x), Py_XDECREF(se), Py_XDECREF(lo), Py_XDECREF(hi);
    return PyErr_Occurred() ? NULL : PyErr_NoMemory();
fail_d:
    Py_DECREF(d);
    return NULL;
}

/* jacobi(indptr, indices, data, n, b, omega): M = I - omega D^-1 A and omega D^-1 b (the
 * library's ulam_jacobi) as (status, message, error_index, indptr, indices, data, bp). */
static PyObject *py_jacobi(PyObject *mod, PyObject *args)
{
    (void)mod;
    PyObject *rp, *ci, *va, *bo;
    long long n;
    double omega;
    if (!PyArg_ParseTuple(args, "OOOLOd", &rp, &ci, &va, &n, &bo, &omega)) return NULL;
    PyArrayObject *r = array_of(rp, NPY_INT64, "indptr"), *c = r ? array_of(ci, NPY_INT32, "indices") : NULL,
                  *v = c ? array_of(va, NPY_FLOAT64, "data") : NULL, *b = v ? array_of(bo, NPY_FLOAT64, "b") : NULL;
    PyObject *out = NULL;
    if (!b) goto done;
    if (PyArray_SIZE(r) != n + 1 || PyArray_SIZE(b) != n || PyArray_SIZE(c) != PyArray_SIZE(v)) {
        PyErr_SetString(PyExc_ValueError, "indptr must have n + 1 entries, b n, and indices as many as data");
        goto done;
    }
    ulam_csr A = {.nrows = n, .ncols = n, .rowptr = PyArray_DATA(r), .colidx = PyArray_DATA(c), .val = PyArray_DATA(v)};
    ulam_error err = {0};
    ulam_csr *M = NULL;
    npy_intp dn = (npy_intp)n;
    PyArrayObject *bp = (PyArrayObject *)PyArray_SimpleNew(1, &dn, NPY_FLOAT64);
    if (!bp) goto done;
    int status = ulam_csr_check(&A);
    if (status) err.status = status, snprintf(err.msg, sizeof err.msg, "a valid CSR matrix A");
    else status = ulam_jacobi(&A, PyArray_DATA(b), omega, &M, PyArray_DATA(bp), &err);
    if (status) {
        out = Py_BuildValue("(isL)", status, err.msg, (long long)err.index);
        Py_DECREF(bp);
        goto done;
    }
    npy_intp rn = (npy_intp)n + 1, nz = (npy_intp)ulam_csr_nnz(M);
    PyArrayObject *R = (PyArrayObject *)PyArray_SimpleNew(1, &rn, NPY_INT64),
                  *C = (PyArrayObject *)PyArray_SimpleNew(1, &nz, NPY_INT32),
                  *V = (PyArrayObject *)PyArray_SimpleNew(1, &nz, NPY_FLOAT64);
    if (R && C && V) {
        memcpy(PyArray_DATA(R), M->rowptr, (size_t)rn * sizeof *M->rowptr);
        memcpy(PyArray_DATA(C), M->colidx, (size_t)nz * sizeof *M->colidx);
        memcpy(PyArray_DATA(V), M->val, (size_t)nz * sizeof *M->val);
        out = Py_BuildValue("(isLNNNN)", 0, "", -1LL, R, C, V, bp);
    } else {
        Py_XDECREF(R), Py_XDECREF(C), Py_XDECREF(V), Py_DECREF(bp);
    }
    ulam_csr_free(M);
done:
    Py_XDECREF(r), Py_XDECREF(c), Py_XDECREF(v), Py_XDECREF(b);
    return out;
}

/* methods(): the library's method table as a list of (name, answers) (answers: 1 one entry with
 * an error bar, 2 every unknown to a residual). */
static PyObject *py_methods(PyObject *mod, PyObject *args)
{
    (void)mod, (void)args;
    PyObject *l = PyList_New(ULAM_NMETHODS);
    for (int k = 0; l && k < ULAM_NMETHODS; k++) {
        PyObject *t = Py_BuildValue("(si)", ulam_method_name(k), ulam_method_answers(k));
        if (!t) {
            Py_CLEAR(l);
            break;
        }
        PyList_SET_ITEM(l, k, t);
    }
    return l;
}

/* study_methods(): the study's method grid as (name, mode, estimator, window) tuples. */
static PyObject *py_study_methods(PyObject *mod, PyObject *args)
{
    (void)mod, (void)args;
    PyObject *l = PyList_New(0);
    for (int k = 0; l && k < ULAM_STUDY_METHODS; k++) {
        const ulam_study_method *m = ulam_study_method_get(k);
        if (append(l, Py_BuildValue("(siii)", m->name, m->mode, m->estimator, m->window))) Py_CLEAR(l);
    }
    return l;
}

/* strerror(status): the library's description of a status. */
static PyObject *py_strerror(PyObject *mod, PyObject *args)
{
    (void)mod;
    int status;
    if (!PyArg_ParseTuple(args, "i", &status)) return NULL;
    return PyUnicode_FromString(ulam_strerror(status));
}

static PyMethodDef System_methods[] = {
    {"query", (PyCFunction)System_query, METH_VARARGS, "query(b, index, opts, progress) -> dict (internal)"},
    {"fpush", (PyCFunction)System_fpush, METH_VARARGS, "fpush(source, opts) -> dict (internal)"},
    {"study", (PyCFunction)System_study, METH_VARARGS,
     "study(b, index, methods, budgets, time_budgets, repeats, seed, threads) -> dict (internal)"},
    {NULL, NULL, 0, NULL}};

static PyTypeObject SystemType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ulam._ulam.System",
    .tp_basicsize = sizeof(SystemObject),
    .tp_dealloc = (destructor)System_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "System(indptr, indices, data, n): M of (I - M) x = b over the library's CSR (internal)",
    .tp_methods = System_methods,
    .tp_init = (initproc)System_init,
    .tp_new = PyType_GenericNew,
};

static PyMethodDef module_methods[] = {
    {"jacobi", py_jacobi, METH_VARARGS, "jacobi(indptr, indices, data, n, b, omega) (internal)"},
    {"study_methods", py_study_methods, METH_NOARGS, "study_methods() -> [(name, mode, estimator, window)]: the study's grid"},
    {"methods", py_methods, METH_NOARGS, "methods() -> [(name, answers)]: the library's method table"},
    {"strerror", py_strerror, METH_VARARGS, "strerror(status) -> str"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_ulam", "ulam's C library (internal: use ulam)", -1,
                                    module_methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__ulam(void)
{
    import_array();
    if (PyType_Ready(&SystemType) < 0) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    Py_INCREF(&SystemType);
    if (PyModule_AddObject(m, "System", (PyObject *)&SystemType) < 0 ||
        PyModule_AddStringConstant(m, "version", ULAM_VERSION) < 0) {
        Py_DECREF(&SystemType);
        Py_DECREF(m);
        return NULL;
    }
    static const struct {
        const char *name;
        int value;
    } consts[] = {{"OK", ULAM_OK}, {"EINVAL", ULAM_EINVAL}, {"ENOMEM", ULAM_ENOMEM}, {"EDIVERGE", ULAM_EDIVERGE},
                  {"EINFVAR", ULAM_EINFVAR}, {"ENOCONV", ULAM_ENOCONV}, {"ESTALL", ULAM_ESTALL},
                  {"EUNDEFINED", ULAM_EUNDEFINED}, {"EZERODIAG", ULAM_EZERODIAG}, {"ENONFINITE", ULAM_ENONFINITE},
                  {"NSTATUS", ULAM_NSTATUS}};
    for (size_t k = 0; k < sizeof consts / sizeof consts[0]; k++)
        if (PyModule_AddIntConstant(m, consts[k].name, consts[k].value) < 0) {
            Py_DECREF(m);
            return NULL;
        }
    return m;
}
