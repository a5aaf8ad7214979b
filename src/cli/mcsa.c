/* ulam solve --method: every unknown to a residual tolerance by an outer iteration
 * (sequential Monte Carlo, MCSA, or the deterministic Richardson and Gauss-Seidel). */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The method's name: its row of the library's table (p->method counts from ULAM_METHOD_RICHARDSON). */
#define method_name(m) ulam_method_name(ULAM_METHOD_RICHARDSON + (m))
enum { KRYLOV_CG = ULAM_METHOD_CG - ULAM_METHOD_RICHARDSON, KRYLOV_GMRES = ULAM_METHOD_GMRES - ULAM_METHOD_RICHARDSON };

/* What the report needs besides the steps. */
typedef struct {
    const ulam_outer_opts *o;
    const cli_system *s;
    const ulam_outer_step *steps;
    int method, nsteps, iterations, restart, status, converged, json, check;
    double residual;
    int64_t index; /* 1-based, 0: none */
    const double *x;
    double err_direct, direct_seconds, seconds;
    const double *lo, *hi; /* each x_i's certified range (NULL: none) */
    double worst;
    const char *direct_method; /* --check's reference: "dense LU", "sparse LU" or what CG / GMRES(50) reached */
    ulam_guard g;
    ulam_error why; /* the library's sentence on how the run ended */
    int rejected;   /* corrections rejected and redone with more histories */
} report;

/* Nonzero when the method walks. */
static int walking(int method)
{
    return method == ULAM_SEQUENTIAL || method == ULAM_MCSA;
}

/* Print one iteration's line (the header before the first). */
static void print_step(const ulam_outer_step *s, int walks)
{
    if (s->iteration == 1) printf("%-5s %-12s %-12s %-10s %-10s\n", "iter", "residual", "histories", "rel_sd", "seconds");
    printf("%-5d %-12.4e %-12lld %-10.3g %-10.4f\n", s->iteration, s->residual, (long long)s->histories,
           walks ? s->rel_sd : 0.0, s->seconds);
    cli_flush();
}

/* Nonzero when iteration k's line is printed as it ends: the first 10, then every 500th (the
 * last is printed when the run ends). */
static int shown(int k)
{
    return k <= 10 || k % 500 == 0;
}

/* --check's line. */
static void print_check(const report *p)
{
    printf("direct          relative error ||x - x_direct||_2 / ||x_direct||_2 = %.4e (%s, %.4f s)\n", p->err_direct,
           p->direct_method ? p->direct_method : "LU", p->direct_seconds);
}

/* Print the report to stdout as the library writes it (text totals, or JSON with the history). */
static void print_report(const report *p)
{
    ulam_outer_report r = {.method = ULAM_METHOD_RICHARDSON + p->method, .estimator = p->o->walk.estimator,
                           .tol = p->o->tol, .eps1 = p->o->eps1, .seed = p->o->walk.exec.seed,
                           .threads = p->o->walk.exec.threads, .ranks = cli_share ? cli_share->nranks : 1,
                           .steps = p->steps, .nsteps = p->nsteps, .iterations = p->iterations, .restart = p->restart,
                           .status = p->status, .converged = p->converged, .rejected = p->rejected,
                           .residual = p->residual, .seconds = p->seconds, .index = p->index, .x = p->x,
                           .answer_name = cli_answer_name, .check = p->check, .err_direct = p->err_direct, .g = p->g,
                           .lo = p->lo, .hi = p->hi, .worst = p->worst};
    if (p->json) cli_json_done = 1;
    ulam_outer_report_fprint(stdout, &r, p->json ? ULAM_REPORT_JSON : cli_verbosity < 0 ? ULAM_REPORT_QUIET : ULAM_REPORT_BRIEF);
}

/* The relative 2-norm error of x against the reference solve (cli_direct_reference: LU, or CG /
 * GMRES(50) past the memory limit, as narrow as it gets; interruptible); 0 or an exit code. */
static int direct_error(const cli_system *s, const double *x, report *p)
{
    double *xd, num = 0, den = 0, seconds = 0.0;
    const char *method = NULL;
    int rc = cli_direct_reference(s, -1, 0.0, &xd, &seconds, &method);
    if (rc) return rc;
    for (int64_t i = 0; i < s->M->nrows; i++) num += (x[i] - xd[i]) * (x[i] - xd[i]), den += xd[i] * xd[i];
    p->err_direct = den > 0 ? sqrt(num / den) : sqrt(num);
    p->direct_seconds = seconds, p->direct_method = method;
    free(xd);
    return 0;
}

/* Print why the run ended early (not for a converged one). */
static void print_failure(const report *p)
{
    double res = p->residual;
    if (p->status == ULAM_ESTALL && strstr(p->why.msg, "lowers the residual"))
        fprintf(stderr, "ulam: %s: error: %s: expected %s\n", p->s->matrix_path, ulam_strerror(p->status), p->why.msg);
    else if (p->status == ULAM_ESTALL)
        fprintf(stderr, "ulam: %s: error: %s: the residual made no new low in the last %s iterations (now "
                        "%.3g after %d, tolerance %g): the corrections no longer reduce it (is rho(M^) < 1? a "
                        "smaller --eps1 walks more a correction)\n",
                p->s->matrix_path, ulam_strerror(p->status), p->o->stall ? "--stall" : "(default 5 or 100)", res,
                p->iterations, p->o->tol);
    else if (p->status == ULAM_ENOCONV)
        fprintf(stderr, "ulam: %s: error: %s: residual %.3g after --max-iter %d iterations (tolerance %g)\n",
                p->s->matrix_path, ulam_strerror(p->status), res, p->iterations, p->o->tol);
    else if (p->status == ULAM_ENONFINITE && p->method >= KRYLOV_CG)
        fprintf(stderr, "ulam: %s: error: %s: expected a solution a double can hold: x (or its residual, %.3g) "
                        "exceeds 1.8e308 after %d iterations; no output written\n",
                p->s->matrix_path, ulam_strerror(p->status), res, p->iterations);
    else
        fprintf(stderr, "ulam: %s: error: %s after %d iterations (is rho(|M|) < 1? see 'ulam info')\n",
                p->s->matrix_path, ulam_strerror(p->status), p->nsteps);
}

/* Run the iteration, printing nothing; fills p (steps malloc'd); 0 or an exit code. */
static int run(const cli_system *s, const ulam_outer_opts *o, report *p, ulam_outer_step **steps, double **x)
{
    ulam_outer *it = NULL;
    ulam_error err;
    int status = ulam_outer_alloc(s->M, s->b, o, &it, &err), cap = 0;
    if (status) return cli_report(s->matrix_path, &err);
    double t0 = ulam_now();
    /* the iterations' table, live, under --verbose only: by default the answer is the first line */
    int table = !p->json && cli_rank == 0 && cli_verbosity > 0;
    cli_catch_sigint();
    while (!ulam_outer_done(it)) {
        if (p->nsteps == cap) {
            ulam_outer_step *g = realloc(*steps, (size_t)(cap = cap ? 2 * cap : 64) * sizeof *g);
            if (!g) {
                status = ULAM_ENOMEM;
                break;
            }
            *steps = g;
        }
        status = ulam_outer_iterate(it, &(*steps)[p->nsteps]);
        p->nsteps++;
        if (table && shown(p->nsteps)) print_step(&(*steps)[p->nsteps - 1], walking(p->method));
    }
    cli_release_sigint();
    if (table && p->nsteps && !shown(p->nsteps)) {
        printf("...\n");
        print_step(&(*steps)[p->nsteps - 1], walking(p->method));
    }
    p->seconds = ulam_now() - t0;
    p->status = status;
    p->iterations = p->nsteps;
    ulam_outer_info oi;
    ulam_outer_get_info(it, &oi);
    p->converged = oi.converged;
    p->residual = p->nsteps ? (*steps)[p->nsteps - 1].residual : 1.0;
    ulam_outer_error(it, &p->why);
    p->rejected = oi.rejected;
    *x = malloc((size_t)s->M->nrows * sizeof **x);
    if (*x) memcpy(*x, oi.x, (size_t)s->M->nrows * sizeof **x);
    ulam_outer_free(it);
    return *x ? 0 : cli_exit_code(ULAM_ENOMEM);
}

/* Run a Krylov peer into a new *x; 0 or an exit code. */
static int run_krylov(const cli_system *s, const ulam_outer_opts *o, report *p, double **x)
{
    *x = malloc((size_t)s->M->nrows * sizeof **x);
    if (!*x) return cli_exit_code(ULAM_ENOMEM);
    int cap = o->max_iter ? o->max_iter : 100000;
    double t0 = ulam_now();
    ulam_csr_stats st;
    if (p->method == KRYLOV_CG && (ulam_csr_stats_compute(s->M, &st) || !st.symmetric)) {
        fprintf(stderr, "ulam: %s: error: --method cg needs a symmetric M (I - M symmetric positive definite); "
                        "use --method gmres\n", s->matrix_path);
        return EXIT_USAGE;
    }
    p->status = p->method == KRYLOV_CG ? ulam_cg(s->M, s->b, o->tol, cap, *x, &p->iterations, &p->residual)
                                       : ulam_gmres(s->M, s->b, p->restart, o->tol, cap, *x, &p->iterations, &p->residual);
    p->seconds = ulam_now() - t0;
    p->converged = p->status == ULAM_OK;
    if (p->status == ULAM_ENOMEM) return cli_exit_code(p->status);
    return 0;
}

/* The outer rows' options (src/cli/solve_rows.c reads them). */
static const struct option longopts[] = {
    {"rhs", required_argument, 0, 'b'},     {"method", required_argument, 0, 'M'},
    {"tol", required_argument, 0, 'l'},     {"rel-err", required_argument, 0, 'l'},     {"max-iter", required_argument, 0, 'k'},
    {"eps1", required_argument, 0, 'p'},    {"max-histories", required_argument, 0, 'H'},
    {"stall", required_argument, 0, 'a'},   CLI_WALK_OPTION("estimator"),
    CLI_WALK_OPTION("seed"),                CLI_WALK_OPTION("threads"),
    CLI_WALK_OPTION("continue"),            CLI_WALK_OPTION("max-steps"),
    {"jacobi", no_argument, 0, 'j'},        {"omega", required_argument, 0, 'w'},
    {"json", no_argument, 0, 'J'},          {"out", required_argument, 0, 'o'},
    {"index", required_argument, 0, 'i'},   {"check", no_argument, 0, 'c'},
    {"force", no_argument, 0, 'F'},         {"cache", no_argument, 0, 'C'},
    {"restart", required_argument, 0, 'r'}, {"help", no_argument, 0, 'h'},
    {0, 0, 0, 0}};

/* What the command line gives an outer iteration (p points at o and s). */
typedef struct {
    cli_system s;
    ulam_outer_opts o;
    report p;
    const char *out;
    int force;
} outer_args;

/* The arguments before any option. */
static void init(void *q)
{
    outer_args *a = q;
    *a = (outer_args){.s = {.command = "solve", .omega = 1.0}, .o = ulam_outer_defaults()};
    a->p = (report){.o = &a->o, .s = &a->s, .method = ULAM_MCSA, .restart = 30};
}

/* One option (c its code in longopts) into the arguments; 0, or an exit code (-1: --help printed). */
static int option(void *q, int c, const char *name, const char *optarg)
{
    outer_args *a = q;
    ulam_outer_opts *o = &a->o;
    ulam_error err;
    int64_t v;
    int rc;
    switch (c) {
    case CLI_WALK: if ((rc = cli_walk_option("solve", name, optarg, &o->walk))) return rc; break;
    case 'b': a->s.rhs_path = optarg; break;
    case 'M':
        if (ulam_method_answers(ulam_method_find(optarg)) != ULAM_ANSWERS_ALL)
            return cli_method_error(optarg);
        a->p.method = ulam_method_find(optarg) - ULAM_METHOD_RICHARDSON;
        if (a->p.method < KRYLOV_CG) o->method = a->p.method;
        break;
    case 'r':
        if ((rc = cli_parse_int("solve", "--restart", optarg, 1, 10000, &v))) return rc;
        a->p.restart = (int)v;
        break;
    case 'l': case 'k': case 'p': case 'H': case 'a': /* the library's table (src/options.c) */
        if (ulam_options_set(ULAM_OPTIONS_OUTER, o, c == 'l' ? "tol" : name, optarg, &err)) return cli_usage_error("solve", "%s", err.msg);
        break;
    case 'j': a->s.jacobi = 1; break;
    case 'w': if ((rc = cli_parse_real("solve", "--omega", optarg, 1e-6, 2.0, &a->s.omega))) return rc; break;
    case 'J': a->p.json = 1; break;
    case 'o': a->out = optarg; break;
    case 'i': if ((rc = cli_parse_int("solve", "--index", optarg, 1, ULAM_MAX_DIM, &a->s.index))) return rc; break;
    case 'c': a->p.check = 1; break;
    case 'F': a->force = 1; break;
    case 'C': a->s.cache = 1; break;
    case 'h': ulam_options_help(stdout, "mcsa"); return -1;
    default: return cli_usage_error("solve", "unknown option (for --method: see 'ulam solve --method mcsa --help')");
    }
    return 0;
}

/* The options read (argv[optind..]: the operands): check them and run; 0 or an exit code. */
static int start_run(void *q, int argc, char **argv, int optind)
{
    outer_args *a = q;
    cli_system s = a->s;
    ulam_outer_opts o = a->o;
    report p = a->p;
    p.o = &o, p.s = &s;
    const char *out = a->out;
    int rc, force = a->force;
    if (optind != argc - 1) return cli_operands_error("solve", argc, argv, optind);
    if (!s.rhs_path) return cli_usage_error("solve", "needs --rhs b.mtx");
    s.matrix_path = argv[optind];
    const cli_file outs[] = {{"--out", out}}, ins[] = {{"the matrix", s.matrix_path}, {"--rhs", s.rhs_path}};
    if ((rc = cli_check_outputs("solve", outs, 1, ins, 2))) return rc;
    if ((rc = cli_load_system(&s))) return rc;
    p.index = s.index;
    o.walk.exec.share = cli_share, o.walk.stop.interrupt = &cli_interrupted;
    if (walking(p.method) && (rc = cli_guard(&s, o.walk.kernel.continue_q, o.walk.kernel.kernel_alpha, ULAM_FORWARD, &p.g))) {
        cli_system_free(&s);
        return rc;
    }
    if (walking(p.method) && p.g.verdict_abs >= ULAM_VERDICT_FAIL) {
        cli_guard_diverge(&s, &p.g, force);
        if (!force) {
            cli_system_free(&s);
            return EXIT_DIVERGE;
        }
    }
    if (walking(p.method)) cli_guard_warn(&s, &p.g, ULAM_FORWARD, 0);
    o.walk.policy.guard = &p.g, o.walk.policy.force = force; /* the walks' solver takes these verdicts */
    ulam_outer_step *steps = NULL;
    double *x = NULL;
    rc = p.method >= KRYLOV_CG ? run_krylov(&s, &o, &p, &x) : run(&s, &o, &p, &steps, &x);
    p.steps = steps, p.x = x;
    double *lo = NULL, *hi = NULL; /* the certified range of every x_i from x's residual, where one holds */
    if (!rc && x && cli_rank == 0 && (lo = malloc((size_t)s.M->nrows * sizeof *lo)) &&
        (hi = malloc((size_t)s.M->nrows * sizeof *hi)) && ulam_solution_bound(s.M, s.b, x, lo, hi, &p.worst, NULL) == ULAM_OK)
        p.lo = lo, p.hi = hi;
    if (!rc && p.status && p.status != ULAM_ESTALL && p.status != ULAM_ENOCONV) {
        print_failure(&p);
        rc = cli_exit_code(p.status);
    } else if (!rc) {
        int want = p.check && cli_rank == 0, crc = 0; /* the answer first, then --check (its CG or GMRES past 4 GiB) */
        p.check = 0;
        if (!p.json && cli_rank == 0) print_report(&p), cli_flush(); /* a failed write of --out below cannot lose it */
        if (want) crc = direct_error(&s, x, &p);
        p.check = want && !crc;
        if (p.json && cli_rank == 0 && !crc) print_report(&p);
        else if (p.check && !p.json) print_check(&p);
        cli_flush();
        if (crc == EXIT_INTERRUPTED && !cli_share) { /* the reference's thread still reads the system */
            fprintf(stderr, "ulam: --check interrupted: the solution above stands unchecked\n");
            _exit(crc);
        }
        rc = crc;
        int ws;
        if (!rc && out && cli_rank == 0 && p.converged &&
            (ws = cli_write_vector(out, x, s.M->nrows, "outer-iteration solution x")))
            rc = cli_report_write(out, ws, errno);
        if (!rc && p.status) {
            print_failure(&p);
            rc = cli_exit_code(p.status);
        }
        if (!rc && cli_interrupted) rc = EXIT_INTERRUPTED;
    }
    cli_flush();
    free(steps), free(x), free(lo), free(hi);
    cli_system_free(&s);
    return rc;
}

/* The rows that answer every unknown (--method richardson ... gmres); a --method without a value
 * and an unknown name come here too, to be refused in this row's words. */
static int serves(const char *method)
{
    return !method || (strcmp(method, "auto") && ulam_method_answers(ulam_method_find(method)) != ULAM_ANSWERS_ENTRY);
}

const cli_solve_row cli_solve_outer_row = {"outer", longopts, NULL, serves, sizeof(outer_args), init, option, start_run};
