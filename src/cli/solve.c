/* ulam solve: one unknown (adjoint) or every unknown (forward) by random walks. */
#include "cli.h"

#include <errno.h>

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>


typedef struct {
    int check, json;
    double direct, direct_seconds;
    ulam_guard g;
    int assume_finite;
    int64_t n;
    double load_seconds, guard_seconds, kernel_seconds; /* reading the inputs; the guards; the solver set-up */
    const ulam_choice *ch;      /* --method auto: the rows, the candidates and the choice (else NULL) */
    double t_start;             /* when the command started (ulam_now) */
    const char *direct_method;  /* --check: "dense LU", "sparse LU" or "interrupted" */
} report_opts;

/* The reference value of x_index for --check (sparse or dense LU, src/cli/direct.c), interruptible:
 * 0, EXIT_INTERRUPTED (the solve still runs: the caller must leave s alone) or an exit code. */
static int direct_check(const cli_system *s, int64_t index, const ulam_walk_result *r, report_opts *ro)
{
    double value = NAN, seconds = NAN;
    int rc = cli_direct_check(s, index, 0.5 * (r->ci95[1] - r->ci95[0]), &value, &seconds, &ro->direct_method);
    ro->direct = value, ro->direct_seconds = seconds;
    return rc;
}

/* The standard errors as a Matrix Market array to f: NaN for a component no walk reached
 * (ulam_mm_write_vector refuses non-finite values), with the comments saying so and whether the
 * variance is finite. */
static void write_errors(FILE *f, const double *e, int64_t n, const ulam_walk_result *r)
{
    fprintf(f, "%%%%MatrixMarket matrix array real general\n%% standard errors of the forward estimates\n");
    if (r->variance_finite != 1)
        fprintf(f, "%% VARIANCE %s (rho(M^) of the forward kernel %s): these standard errors mean nothing\n",
                r->variance_finite == 0 ? "INFINITE" : "NOT CERTIFIED FINITE",
                r->variance_finite == 0 ? ">= 1" : "straddles 1");
    if (r->unreached)
        fprintf(f, "%% %lld components unreached (no walk tallied them): their error is nan, they have no estimate\n",
                (long long)r->unreached);
    fprintf(f, "%lld 1\n", (long long)n);
    for (int64_t k = 0; k < n; k++) fprintf(f, isnan(e[k]) ? "nan\n" : "%.17g\n", e[k]);
}

/* Write the forward vectors, --out and --errors committed together or neither (both written to
 * temporary files, renamed into place only when both are whole); 0 or an exit code. */
static int write_vectors(const ulam_solver *sv, int64_t n, const char *out, const char *errors,
                         const ulam_walk_result *r)
{
    double *x = malloc((size_t)n * sizeof *x), *e = malloc((size_t)n * sizeof *e);
    int status = x && e ? ulam_solver_vectors(sv, x, e) : ULAM_ENOMEM, k = 0, errnum = 0;
    ulam_outfile o[2] = {{0}};
    char both[1100];
    const char *fail = NULL;
    if (!status && out) {
        if ((status = cli_outfile_open(&o[k], out)) ||
            (status = ulam_mm_write_vector_file(o[k].f, x, n, r->unreached ? "forward random-walk estimates of x "
                                                "(unreached components: 0, no estimate; see the errors)"
                                                : "forward random-walk estimates of x")))
            fail = out, errnum = errno;
        k++;
    }
    if (!status && errors) {
        if ((status = cli_outfile_open(&o[k], errors))) fail = errors, errnum = errno;
        else write_errors(o[k].f, e, n, r);
        k++;
    }
    if (!status) {
        status = cli_outfile_commit_all(o, k);
        errnum = errno;
        if (out && errors) snprintf(both, sizeof both, "%s and %s", out, errors), fail = both;
    }
    cli_outfile_abort(&o[0]), cli_outfile_abort(&o[1]); /* whatever is left: nothing is replaced */
    free(x), free(e);
    if (!fail) fail = out ? out : errors;
    return status ? cli_report_write(fail, status, errnum) : 0;
}

/* Everything ulam solve was asked: parse fills it from argv, run does it. */
typedef struct {
    cli_system s;         /* the files (rhs_path, index, jacobi, omega, cache, matrix_path) */
    ulam_walk_opts o;     /* how to walk and when to stop */
    const char *out, *errors; /* --out, --errors (NULL: none) */
    int check, json, force, assume_finite;
    int autom;            /* --method auto (the default): choose what is not pinned */
    ulam_auto_opts ao;    /* what the command line pins (--mode, --estimator, --continue) */
    ulam_analysis *an;    /* what queries on M share (a prepared system read lazily; NULL: none) */
    double max_seconds;   /* --time as given (o.max_seconds: what is left of it for the walks) */
    const char *queries;  /* --queries FILE ("-": stdin; NULL: one query) */
    int walks_given;      /* --walks or --time given */
    int64_t source;       /* > 0: b = e_source, 1-based (cli_solve_source; 0: b from the files) */
} solve_args;

/* The walks row's options (src/cli/solve_rows.c reads them; the walk options go to cli_walk_option). */
static const struct option longopts[] = {
    {"rhs", required_argument, 0, 'b'},      {"index", required_argument, 0, 'i'},
    CLI_WALK_OPTION("mode"),                 CLI_WALK_OPTION("estimator"),
    CLI_WALK_OPTION("walks"),                CLI_WALK_OPTION("rel-err"),
    CLI_WALK_OPTION("time"),                 CLI_WALK_OPTION("seed"),
    CLI_WALK_OPTION("threads"),              CLI_WALK_OPTION("continue"),
    CLI_WALK_OPTION("roulette"),             CLI_WALK_OPTION("split"),
    CLI_WALK_OPTION("max-steps"),            CLI_WALK_OPTION("alpha"),
    CLI_WALK_OPTION("kernel-exponent"),      CLI_WALK_OPTION("tol"),
    {"jacobi", no_argument, 0, 'j'},
    {"omega", required_argument, 0, 'w'},    {"check", no_argument, 0, 'c'},
    {"json", no_argument, 0, 'J'},           {"out", required_argument, 0, 'o'},
    {"errors", required_argument, 0, 'E'},   {"help", no_argument, 0, 'h'},
    {"force", no_argument, 0, 'F'},          {"cache", no_argument, 0, 'C'},
    {"whole-kernel", no_argument, 0, 'W'},   {"assume-finite-variance", no_argument, 0, 'A'},
    {"method", required_argument, 0, 'U'},   {"pagerank", required_argument, 0, 'P'},
    {"damping", required_argument, 0, 'P'},  {"queries", required_argument, 0, 'Q'},
    {0, 0, 0, 0}};

/* The arguments before any option. */
static void init(void *p)
{
    solve_args *a = p;
    *a = (solve_args){.s = {.command = "solve", .omega = 1.0}, .o = ulam_walk_defaults(), .autom = 1,
                      .ao = ulam_auto_defaults()};
    a->o.stop.max_walks = 0; /* set by cli_walk_budget unless a rule is given */
}

/* One option (c its code in longopts, name its long name) into the arguments; 0, or an exit code
 * (-1: --help printed). */
static int option(void *p, int c, const char *name, const char *optarg)
{
    solve_args *a = p;
    int rc;
    switch (c) {
    case CLI_WALK:
        if ((rc = cli_walk_option("solve", name, optarg, &a->o))) return rc;
        a->ao.pin_mode |= !strcmp(name, "mode");
        a->ao.pin_estimator |= !strcmp(name, "estimator");
        a->ao.pin_continue |= !strcmp(name, "continue");
        a->ao.pin_alpha |= !strcmp(name, "alpha") || !strcmp(name, "kernel-exponent");
        break;
    case 'b': a->s.rhs_path = optarg; break;
    case 'i': if ((rc = cli_parse_node("solve", "--index", optarg, &a->s.index))) return rc; break;
    case 'j': a->s.jacobi = 1; break;
    case 'C': a->s.cache = 1; break;
    case 'W': a->o.kernel.whole_kernel = 1; break;
    case 'U':
        if (!strcmp(optarg, "bidirectional")) return cli_usage_error("solve", "--method bidirectional needs --source S (b = e_S)");
        if (strcmp(optarg, "auto") && ulam_method_find(optarg) != ULAM_METHOD_WALKS) return cli_method_error(optarg);
        a->autom = !strcmp(optarg, "auto");
        break;
    case 'w': if ((rc = cli_parse_real("solve", "--omega", optarg, 1e-6, 2.0, &a->s.omega))) return rc; break;
    case 'P': if ((rc = cli_parse_damping("solve", optarg, &a->s.pagerank))) return rc; break;
    case 'c': a->check = 1; break;
    case 'J': a->json = 1; break;
    case 'F': a->force = 1; break;
    case 'A': a->assume_finite = 1; break;
    case 'o': a->out = optarg; break;
    case 'E': a->errors = optarg; break;
    case 'Q': a->queries = optarg; break;
    case 'h': ulam_options_help(stdout, "solve"); return -1;
    default: return cli_usage_error("solve", "unknown option");
    }
    return 0;
}

/* The checks once every option is read (argv[first..]: the operands); 0 or an exit code. */
static int finish_parse(solve_args *a, int argc, char **argv, int optind)
{
    if (optind != argc - 1) return cli_operands_error("solve", argc, argv, optind);
    if (a->queries && (a->s.index || a->o.mode != ULAM_ADJOINT || a->out || a->errors || a->check || a->s.jacobi))
        return cli_usage_error("solve", "--queries takes the indices from its file, in adjoint mode (no --index, "
                                        "--mode forward, --out, --errors, --check or --jacobi)");
    a->walks_given = a->o.stop.max_walks > 0 || a->o.stop.max_seconds > 0;
    if (!a->queries && !a->s.rhs_path && !a->s.pagerank && !ulam_system_is_file(argv[optind]))
        return cli_need_rhs("solve", argv[optind]);
    if (a->s.pagerank > 0 && a->s.jacobi) return cli_usage_error("solve", "--pagerank and --jacobi exclude each other");
    if (!a->s.index && a->o.mode == ULAM_ADJOINT && !a->queries) return cli_usage_error("solve", "adjoint walks need --index I");
    if ((a->out || a->errors) && a->o.mode != ULAM_FORWARD)
        return cli_usage_error("solve", "--out and --errors need --mode forward");
    if (a->o.kernel.roulette > 0 && a->o.kernel.split > 0 && a->o.kernel.split <= a->o.kernel.roulette)
        return cli_usage_error("solve", "--split W must exceed --roulette W");
    cli_walk_budget(&a->o);
    a->s.matrix_path = argv[optind];
    if (a->ao.pin_mode && a->ao.pin_estimator && a->ao.pin_continue && a->ao.pin_alpha) a->autom = 0; /* nothing to choose */
    return 0;
}

/* A lazily read prepared system under auto: with a certificate that serves the adjoint guards,
 * auto chooses the estimator on the certificate's kernel (continuation, exponent 1, adjoint: what
 * is not pinned is set so), whose guards need no pass over M, so the query still reads only the
 * rows its walks reach; otherwise the file is verified whole first (the guards read all of M). */
static int certified_auto(solve_args *a, ulam_guard *g)
{
    cli_system *s = &a->s;
    if (!s->lazy) return 0;
    ulam_walk_opts *o = &a->o;
    ulam_guard_opts go = ulam_guard_defaults();
    go.need = ULAM_GUARD_ABS | ULAM_GUARD_ADJOINT;
    double q = a->ao.pin_continue ? o->kernel.continue_q : s->cert ? s->cert->continue_q : 0.0;
    if ((a->ao.pin_alpha && o->kernel.kernel_alpha != 1.0) || (a->ao.pin_mode && o->mode != ULAM_ADJOINT) ||
        ulam_certificate_guard(s->cert, q, &go, g))
        return cli_system_verify(s);
    o->kernel.continue_q = q, o->kernel.kernel_alpha = 1.0, o->mode = ULAM_ADJOINT;
    a->ao.pin_continue = a->ao.pin_alpha = a->ao.pin_mode = 1;
    a->ao.guard = g;
    return 0;
}

/* For a prepared system read only where walks go (s->lazy): the analysis its queries share
 * (a->an), at the options' continuation and exponent, on the file's stored bounds and b; 0 or
 * an exit code (no memory). */
static int lazy_analysis(solve_args *a)
{
    cli_system *s = &a->s;
    if (!s->lazy || !s->sys_M || a->an) return 0;
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.continue_q = a->o.kernel.continue_q, ao.kernel_alpha = a->o.kernel.kernel_alpha, ao.b = s->b, ao.system = s->sys_M;
    ao.shared_bounds = 1; /* the file's stored bounds: no pass over what each start can reach */
    ulam_error err;
    return ulam_analysis_alloc(s->M, &ao, &a->an, &err) ? cli_report(s->matrix_path, &err) : 0;
}

/* What the command line rules out for bidirectional beyond what the library tests (the options it
 * cannot honour), in words (NULL: nothing). */
static const char *bidir_excluded(const solve_args *a)
{
    if (a->s.lazy) return "a prepared system read only where walks go (bidirectional transposes all of M)";
    return NULL;
}

enum { CLI_FIRST_ROUND = 1024 }; /* the walks of a solver's first round (src/solve.c's block) */

/* The seconds the chosen walks' first round is predicted to take: its walks at the pilots' work a
 * walk, at the work model's rate (a quiet machine's), over the threads, slowed by the load past
 * the cores (a 500 x 500 Poisson grid's centre: 1.2 s predicted quiet, 3.5 s taken at load 10 on
 * 2 cores); 0 when no pilot chose them. */
static double first_round(const solve_args *a, const ulam_choice *ch, const ulam_solver *sv)
{
    if (!a->autom || !sv || !ch || ch->walks.chosen < 0) return 0.0;
    const ulam_auto_candidate *c = &ch->walks.cand[ch->walks.chosen];
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double load[1] = {0.0}, busy = cores > 0 && getloadavg(load, 1) == 1 ? fmax(1.0, load[0] / (double)cores) : 1.0;
    int threads = a->o.exec.threads > 0 ? a->o.exec.threads : cores > 0 ? (int)cores : 1;
    double t = CLI_FIRST_ROUND * c->work_per_walk * ULAM_AUTO_UNIT_SECONDS * busy / fmin(threads, CLI_FIRST_ROUND);
    return c->pilot_walks > 0 && isfinite(t) ? t : 0.0;
}

/* Load the system, choose (--method auto: the library's table, ch) or guard, and make the run
 * *run (walks: *sv, borrowed from it; none when bidirectional is chosen); print the refusals and
 * the warnings, then run --check; 0 or an exit code (nothing kept on failure). */
static int start(solve_args *a, report_opts *ro, ulam_choice *ch, ulam_run **run, ulam_solver **sv)
{
    cli_system *s = &a->s;
    ulam_walk_opts *o = &a->o;
    int rc;
    /* read only the rows walks reach; auto does on a prepared system (see certified_auto) */
    s->lazy = o->mode == ULAM_ADJOINT && !cli_share && (!a->autom || ulam_system_is_file(s->matrix_path));
    const cli_file outs[] = {{"--out", a->out}, {"--errors", a->errors}}, ins[] = {{"the matrix", s->matrix_path}, {"--rhs", s->rhs_path}};
    if ((rc = cli_check_outputs("solve", outs, 2, ins, 2))) return rc;
    double t0 = ulam_now();
    if ((rc = cli_load_system(s))) return rc;
    if (a->source > 0 && !s->b && (s->own_b = calloc((size_t)s->M->nrows, sizeof *s->own_b)))
        s->own_b[a->source - 1] = 1.0, s->b = s->own_b; /* freed by cli_system_free */
    if (!s->b) {
        cli_system_free(s);
        return cli_usage_error("solve", "needs --rhs b.mtx (%s holds no b)", s->matrix_path);
    }
    ro->load_seconds = ulam_now() - t0;
    int said = a->o.stop.max_seconds > 0 && ulam_now() - cli_started >= a->o.stop.max_seconds;
    if (said) /* --time counts the whole run: said at the start when reading alone is past it */
        fprintf(stderr, "ulam: %s: note: --time %g cannot be met: reading M (%lld nonzeros) took %.3g s; the guards, the "
                        "set-up and one round of walks follow\n",
                s->matrix_path, a->o.stop.max_seconds, (long long)ulam_csr_nnz(s->M), ulam_now() - cli_started);
    o->query.index = s->index ? s->index - 1 : 0;
    o->stop.interrupt = &cli_interrupted, o->exec.share = cli_share, o->policy.force = a->force;
    o->policy.system = s->lazy ? s->sys_M : NULL; /* a mapped M read lazily: its blocks verified as walks reach them */
    o->policy.assume_finite = ro->assume_finite;
    ro->n = s->M->nrows;
    ulam_error err;
    int status;
    a->max_seconds = o->stop.max_seconds;
    o->stop.max_seconds = cli_time_left(a->max_seconds); /* --time counts the reading before it too */
    if (a->autom) { /* guards, pilots, the rows of the table and the run, its set-up kept from the choice */
        t0 = ulam_now();
        ulam_guard cg;
        const char *excluded = bidir_excluded(a);
        if ((rc = certified_auto(a, &cg)) || (rc = lazy_analysis(a)) ||
            (rc = cli_auto_choose(s, a->an, o, &a->ao, excluded, ch, run, &status, &err))) {
            cli_system_free(s);
            return rc;
        }
        ro->ch = ch;
        ro->g = ch->walks.guard;
        ro->kernel_seconds = ulam_now() - t0; /* the choice's guards, pilots and set-up: all of it */
        *sv = ulam_run_solver(*run);
    } else {
        if ((rc = cli_guard(s, o->kernel.continue_q, o->kernel.kernel_alpha, o->mode, &ro->g))) {
            cli_system_free(s);
            return rc;
        }
        o->policy.guard = &ro->g;
        o->stop.max_seconds = cli_time_left(a->max_seconds); /* and the guards */
        t0 = ulam_now();
        if ((rc = lazy_analysis(a))) {
            cli_system_free(s);
            return rc;
        }
        if (a->an) { /* the file's stored bounds: no pass over what the start can reach */
            status = ulam_analysis_solver(a->an, s->b, o, sv, &err);
            if (status) a->an = ulam_analysis_free(a->an);
        } else {
            status = ulam_solver_alloc(s->M, s->b, o, sv, &err); /* refuses what the guards refuse */
        }
        ro->kernel_seconds = ulam_now() - t0;
    }
    ro->guard_seconds = ro->g.abs.seconds + ro->g.hat[0].seconds + ro->g.hat[1].seconds;
    double first = first_round(a, ch, *sv), el = ulam_now() - cli_started, S = a->max_seconds;
    if (!status && !said && S > 0 && (el > S || el + first > fmax(1.2 * S, S + 0.1))) { /* --time counts the whole run */
        char more[160] = "";
        if (first > 0)
            snprintf(more, sizeof more, "; one round of walks (%d of about %.3g steps, by the pilots) needs about %.2g s "
                                        "more", CLI_FIRST_ROUND, ch->walks.cand[ch->walks.chosen].steps_per_walk, first);
        fprintf(stderr, "ulam: %s: note: --time %g cannot be met: reading (%.3g s), the guards, the choice and the set-up "
                        "(%.3g s) took %.3g s before any walk%s: the walks get their first round only\n",
                s->matrix_path, S, ro->load_seconds, ro->kernel_seconds, el, more);
    }
    if (status == ULAM_EINVAL && o->kernel.split > 0 && strstr(err.msg, "split weight")) {
        rc = cli_usage_error("solve", "--split W: %s", err.msg);
    } else if (status == ULAM_EDIVERGE) {
        cli_guard_diverge(s, &ro->g, 0);
        rc = EXIT_DIVERGE;
    } else if (status == ULAM_EINFVAR) {
        fprintf(stderr, "ulam: %s: error: --rel-err %g can never be met: it needs %s. Bound the run with --walks N "
                        "or --time S (%s)\n", s->matrix_path, o->stop.rel_err, err.msg,
                strstr(err.msg, "rho(M^)") ? "no confidence interval is then printed" : "the rule is then never met");
        rc = EXIT_INFVAR;
    } else if (status) {
        rc = cli_report(s->matrix_path, &err);
    }
    if (status) {
        *run = ulam_run_free(*run);
        cli_system_free(s);
        return rc;
    }
    int walks = *sv != NULL;
    if (walks && ro->g.verdict_abs >= ULAM_VERDICT_FAIL) cli_guard_diverge(s, &ro->g, 1);
    if (walks) cli_guard_warn(s, &ro->g, o->mode, ro->assume_finite);
    return 0; /* bidirectional: --check once its estimate is printed (cli_bidir_auto_run) */
}

/* The report of walks r run with o (the library writes it: ulam_report_fprint). */
static ulam_walk_report walk_report(const ulam_walk_opts *o, const ulam_walk_result *r, const report_opts *ro)
{
    return (ulam_walk_report){.opts = o, .result = r, .guard = &ro->g, .choice = ro->ch, .n = ro->n,
                              .node_base = cli_node_base, .answer_name = cli_answer_name,
                              .ranks = cli_share ? cli_share->nranks : 1, .load_seconds = ro->load_seconds,
                              .guard_seconds = ro->guard_seconds, .kernel_seconds = ro->kernel_seconds,
                              .total_seconds = ulam_now() - ro->t_start, .check = ro->check, .direct = ro->direct,
                              .direct_seconds = ro->direct_seconds, .direct_method = ro->direct_method};
}

/* Walk until a stopping rule holds (a progress line on a terminal), then write and print the
 * results; 0 or an exit code. */
static int run(solve_args *a)
{
    const cli_system *s = &a->s;
    const ulam_walk_opts *o = &a->o;
    report_opts ro = {.check = a->check, .json = a->json, .assume_finite = a->assume_finite, .t_start = ulam_now()};
    ulam_choice ch;
    ulam_run *rn = NULL;
    ulam_solver *sv = NULL;
    int rc = start(a, &ro, &ch, &rn, &sv), status = ULAM_OK;
    if (rc) {
        a->an = ulam_analysis_free(a->an);
        return rc;
    }
    if (!sv && ch.chosen != ULAM_METHOD_BIDIRECTIONAL) { /* no solver and not bidirectional: nothing to label */
        fprintf(stderr, "ulam: %s: error: --method auto chose no method it can run\n", s->matrix_path);
        ulam_run_free(rn);
        a->an = ulam_analysis_free(a->an);
        cli_system_free(&a->s);
        return cli_exit_code(ULAM_EINVAL);
    }
    if (!sv) { /* auto chose bidirectional: its own report, with the choice */
        rc = cli_bidir_auto_run(&a->s, rn, &ch, ch.bidir_route == 1, ro.json, ro.check, ro.load_seconds);
        ulam_run_free(rn);
        a->an = ulam_analysis_free(a->an);
        cli_system_free(&a->s);
        return rc;
    }
    cli_catch_sigint();
    ulam_walk_result r;
    cli_progress pg;
    cli_progress_start(&pg, ro.json);
    for (int first = 1; !status && !ulam_solver_done(sv); first = 0) {
        status = ulam_solver_iterate(sv);
        ulam_solver_result(sv, &r);
        if (first && !status) { /* what the first round warns of */
            char pre[1100];
            snprintf(pre, sizeof pre, "ulam: %s: ", s->matrix_path);
            ulam_walk_report w = walk_report(o, &r, &ro);
            w.prefix = pre;
            ulam_report_fprint(stderr, ULAM_REPORT_WALK, &w, ULAM_REPORT_WARN);
        }
        cli_progress_show(&pg, r.walks, r.estimate, r.std_error, o);
    }
    cli_progress_end(&pg);
    ulam_error ferr;
    ulam_solver_result(sv, &r);
    if (r.cut_stop)
        fprintf(stderr, "ulam: %s: warning: --rel-err %g is unreachable: %lld walks were cut at --max-steps %lld and "
                        "the cut's bias may be up to %.3g, more than a tenth of the target error; stopped after %lld "
                        "walks (raise --max-steps)\n", s->matrix_path, o->stop.rel_err, (long long)r.cut,
                (long long)o->stop.max_steps, r.cut_bound, (long long)r.walks);
    if (status == ULAM_ENOMEM) {
        fprintf(stderr, "ulam: %s: error: %s: expected memory to build the walk kernel's rows\n", s->matrix_path,
                ulam_strerror(status));
        rc = cli_exit_code(status);
    } else if (status && status != ULAM_ENONFINITE) {
        fprintf(stderr, "ulam: %s: error: %s: expected rows the walks reach to be consistent (row data of "
                        "the mapped file is corrupt: prepare it again)\n", s->matrix_path, ulam_strerror(status));
        rc = cli_exit_code(status);
    } else if (status && ulam_solver_error(sv, &ferr) && ferr.index >= 0) { /* the estimate overflowed */
        fprintf(stderr, "ulam: %s: error: %s: expected %s; no estimate after %lld walks\n", s->matrix_path,
                ulam_strerror(status), ferr.msg, (long long)r.walks);
        rc = cli_exit_code(status);
    } else if (status) {
        fprintf(stderr, "ulam: %s: error: %s: a walk produced a non-finite weight or score after %lld "
                        "walks; nothing was averaged in from it (is rho(|M|) < 1? see 'ulam info')\n",
                s->matrix_path, ulam_strerror(status), (long long)r.walks);
        rc = cli_exit_code(status);
    }
    int left = 0; /* a check still running when Ctrl-C came: leave the system to it */
    if (!status && !rc) {
        ulam_walk_report w = walk_report(o, &r, &ro);
        if (!ro.json)
            ulam_report_fprint(stdout, ULAM_REPORT_WALK, &w, cli_verbosity < 0 ? ULAM_REPORT_QUIET : cli_verbosity ? ULAM_REPORT_VERBOSE
                                                                                                        : ULAM_REPORT_BRIEF);
        cli_flush(); /* the estimate first: a check may take long, a failed write of the files below cannot lose it, and Ctrl-C keeps what is printed */
        if (ro.check && !r.interrupted && cli_rank == 0) {
            rc = cli_system_verify(&a->s);
            rc = rc ? rc : direct_check(s, o->query.index, &r, &ro);
            left = rc == EXIT_INTERRUPTED;
            w = walk_report(o, &r, &ro);
            if (!ro.json && !rc) ulam_report_fprint(stdout, ULAM_REPORT_WALK, &w, ULAM_REPORT_CHECK);
            if (left && !ro.json) fprintf(stderr, "ulam: --check interrupted: the estimate above stands unchecked\n");
        }
        if (ro.json && (!rc || left)) {
            w = walk_report(o, &r, &ro);
            ulam_report_fprint(stdout, ULAM_REPORT_WALK, &w, ULAM_REPORT_JSON);
            cli_json_done = 1;
        }
        if (r.interrupted && o->stop.max_walks > 4 * r.walks && r.walks > 0 && !(o->stop.rel_err > 0) &&
            !(o->stop.max_seconds > 0) && r.std_error > 0 && isfinite(r.ci95[1] - r.ci95[0])) /* newuser15 pt 7 */
            fprintf(stderr, "ulam: %s: note: the interval above is %.3g standard errors wide each side: its bets were "
                            "planned for all %lld walks and the run stopped at %lld; a run of --walks %lld would "
                            "print a narrower one (the sequence holds at every count, so it is valid, only wide)\n",
                    s->matrix_path, 0.5 * (r.ci95[1] - r.ci95[0]) / r.std_error, (long long)o->stop.max_walks,
                    (long long)r.walks, (long long)r.walks);
        if (r.interrupted) rc = EXIT_INTERRUPTED;
        else if (o->mode == ULAM_FORWARD && (a->out || a->errors) && cli_rank == 0)
            rc = write_vectors(sv, ro.n, a->out, a->errors, &r);
        if (!rc && o->stop.rel_err > 0 && !r.rel_err_met) rc = EXIT_TARGET; /* printed "NOT met": say so */
    }
    cli_flush(); /* still caught: a second Ctrl-C ends a write blocked on a full pipe */
    if (left && !cli_share) { /* the reference solve's thread still reads the system: end here */
        fflush(stderr);
        _exit(rc);
    }
    if (left) return rc; /* under MPI the ranks end together (main); the system stays to the thread */
    cli_release_sigint();
    if (rn) ulam_run_free(rn); /* its solver with it (before the analysis it may borrow) */
    else ulam_solver_free(sv);
    a->an = ulam_analysis_free(a->an);
    cli_system_free(&a->s);
    return rc;
}

/* x_I for b = e_source by the walks row under auto (cli.h). */
int cli_solve_source(const cli_system *s, const ulam_walk_opts *o, int64_t source, int json, int check, int force)
{
    solve_args a;
    init(&a);
    a.s.matrix_path = s->matrix_path, a.s.index = s->index, a.s.cache = s->cache;
    a.o = *o, a.o.mode = ULAM_ADJOINT;
    a.json = json, a.check = check, a.force = force, a.source = source;
    a.walks_given = o->stop.max_walks > 0 || o->stop.max_seconds > 0;
    return run(&a);
}

/* The options read: check them and run (many queries: src/cli/queries.c); 0 or an exit code. */
static int start_run(void *p, int argc, char **argv, int first)
{
    solve_args *a = p;
    int rc = finish_parse(a, argc, argv, first);
    if (!rc && a->queries) return cli_queries(&a->s, &a->o, a->queries, a->json, a->walks_given);
    return rc ? rc : run(a);
}

/* The walks row of ulam solve (auto, or --method walks): the default, the last row of the table. */
static int serves(const char *method)
{
    (void)method;
    return 1;
}

const cli_solve_row cli_solve_walks_row = {"walks", longopts, NULL, serves, sizeof(solve_args), init, option, start_run};
