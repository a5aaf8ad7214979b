/* ulam solve --source S or --rhs b --method bidirectional: one entry x_I of (I - M) x = b for
 * b = e_S or a sparse b, by a reverse push from I and walks from b's states.  Reached from
 * cli_solve's parser (src/cli/solve_rows.c) as the table's bidirectional row. */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* What a run reports (the library's writer, ulam_report_fprint), and how. */
typedef struct {
    int json, check;
    ulam_guard g;
    double scale;       /* what the answer is x times: 1, or 1 - alpha for PageRank's pi (0: 1) */
    const char *seeds;  /* --source as a seed set (ids or a file; NULL: one source or none) */
    ulam_bidir_report rep;
} report;

/* The writer's fields the command line knows: how states are numbered, what the answer is
 * called, PageRank's alpha (when the answer is pi), the seeds, the ranks. */
static void report_fill(const cli_system *s, report *rp)
{
    ulam_bidir_report *p = &rp->rep;
    p->node_base = cli_node_base, p->answer_name = cli_answer_name, p->seeds = rp->seeds;
    p->ranks = cli_share ? cli_share->nranks : 1;
    p->pagerank = s->pagerank > 0 && (rp->scale > 0 || !p->opts) ? s->pagerank : 0;
}

/* b's nonzeros as entries of o (new arrays in *idx, *val); 0 or an exit code (refused when b is
 * zero, or when limit and denser than sparse_limit: a --rhs b; a seed set's is not limited). */
static int sparse_b(const cli_system *s, int limit, ulam_bidir_opts *o, int64_t **idx, double **val)
{
    int64_t n = s->M->nrows, k = 0;
    for (int64_t i = 0; i < n; i++) k += s->b[i] != 0.0;
    if (k == 0) return cli_usage_error("solve", "%s: b is zero, so x is 0: nothing to estimate", s->rhs_path);
    if (limit && k > ulam_method_sparse_limit(n))
        return cli_usage_error("solve", "%s: --method bidirectional is for a sparse b, and this b has %lld nonzeros of "
                               "%lld (more than max(16, n/10) = %lld): use the walks (--method auto)", s->rhs_path,
                               (long long)k, (long long)n, (long long)ulam_method_sparse_limit(n));
    *idx = malloc((size_t)k * sizeof **idx), *val = malloc((size_t)k * sizeof **val);
    if (!*idx || !*val) {
        fprintf(stderr, "ulam: %s: error: %s\n", s->rhs_path ? s->rhs_path : s->matrix_path, ulam_strerror(ULAM_ENOMEM));
        return cli_exit_code(ULAM_ENOMEM);
    }
    for (int64_t i = 0, j = 0; i < n; i++)
        if (s->b[i] != 0.0) (*idx)[j] = i, (*val)[j++] = s->b[i];
    o->nb = k, o->b_index = *idx, o->b_value = *val;
    return 0;
}

/* prepare's answer when b = e_S, a --rel-err target, and the walks from S (forward on M) have a
 * variance not certified finite: the run goes to the walks row (cli_solve_source). */
enum { ROUTE_ADJOINT = -2 };

/* Load the system with b from --rhs (sparse) or b = e_S, check S, run the guards and --check;
 * 0, ROUTE_ADJOINT or an exit code. */
static int prepare(cli_system *s, int64_t source, int force, ulam_bidir_opts *o, int64_t **idx, double **val,
                   report *rp)
{
    double t0 = ulam_now();
    int rc = cli_load_system(s);
    if (rc) return rc;
    rp->rep.load_seconds = ulam_now() - t0;
    int64_t n = s->M->nrows;
    if (source > n)
        return cli_usage_error("solve", "--source %lld is out of range %lld..%lld", (long long)(source - 1 + cli_node_base),
                               (long long)cli_node_base, (long long)(n - 1 + cli_node_base));
    if (s->rhs_path) {
        if ((rc = sparse_b(s, 1, o, idx, val))) return rc;
    } else {
        free(s->own_b); /* --pagerank's uniform b: the source or the seeds replace it */
        if (!(s->own_b = calloc((size_t)n, sizeof *s->own_b))) {
            fprintf(stderr, "ulam: %s: error: %s\n", s->matrix_path, ulam_strerror(ULAM_ENOMEM));
            return cli_exit_code(ULAM_ENOMEM);
        }
        s->b = s->own_b; /* freed by cli_system_free */
        if (rp->seeds && (rc = cli_seeds_parse(rp->seeds, n, s->own_b))) return rc;
        if (source) s->own_b[source - 1] = 1.0;
        if (!source && !rp->seeds) /* --pagerank --top K: global PageRank, s uniform */
            for (int64_t i = 0; i < n; i++) s->own_b[i] = 1.0 / (double)n;
        if (rp->seeds && idx && (rc = sparse_b(s, 0, o, idx, val))) return rc; /* a point query: the seeds as b */
    }
    double continue_q = o->walk.kernel.continue_q;
    if ((rc = cli_guard(s, continue_q, 1.0, ULAM_FORWARD, &rp->g))) return rc;
    if (rp->g.verdict_abs >= ULAM_VERDICT_FAIL) {
        cli_guard_diverge(s, &rp->g, force);
        if (!force) return EXIT_DIVERGE;
    }
    if (source && o->walk.stop.rel_err > 0 && ulam_guard_variance(&rp->g, ULAM_FORWARD) != 1)
        return ROUTE_ADJOINT; /* walks from S cannot meet the target: the push on b and walks from I may */
    cli_guard_warn(s, &rp->g, ULAM_FORWARD, 0);
    rp->rep.guard_seconds = rp->g.abs.seconds + rp->g.hat[0].seconds + rp->g.hat[1].seconds;
    return 0; /* --check runs once the estimate is printed (answer) */
}

/* Report the estimate r (scaled to PageRank's pi when rp->scale) and, with --check, the reference
 * solve after it: the text is printed and flushed first, as ulam solve's walks do (Ctrl-C or a
 * failed reference keeps it); JSON waits for the check to hold it.  0 or an exit code. */
static int answer(const cli_system *s, const ulam_bidir_opts *o, ulam_bidir_result *r, report *rp)
{
    int rc = 0, check = rp->check && !r->walks.interrupted && cli_rank == 0;
    ulam_bidir_report *p = &rp->rep;
    if (rp->scale > 0) /* PageRank's pi = (1 - alpha) x: the answer, its interval and --check's */
        r->estimate *= rp->scale, r->std_error *= rp->scale, r->ci95[0] *= rp->scale, r->ci95[1] *= rp->scale;
    p->opts = o, p->result = r, p->check = 0;
    p->guard = p->dense ? NULL : &rp->g; /* the push on b computes no guard here: none written (JSON null) */
    report_fill(s, rp);
    if (!rp->json) {
        ulam_report_fprint(stdout, ULAM_REPORT_BIDIR, p, cli_verbosity < 0 ? ULAM_REPORT_QUIET : cli_verbosity > 0 ? ULAM_REPORT_VERBOSE : ULAM_REPORT_BRIEF);
        cli_flush();
    }
    if (check) {
        double hw = 0.5 * (r->ci95[1] - r->ci95[0]) / (rp->scale > 0 ? rp->scale : 1.0); /* of x, as the reference */
        rc = cli_direct_check(s, s->index - 1, hw, &p->direct, &p->direct_seconds, &p->direct_method);
        p->direct *= rp->scale > 0 ? rp->scale : 1.0;
        p->check = !rc;
    }
    if (rc == EXIT_INTERRUPTED && !rp->json) fprintf(stderr, "ulam: --check interrupted: the estimate above stands unchecked\n");
    if (!rc && rp->json) ulam_report_fprint(stdout, ULAM_REPORT_BIDIR, p, ULAM_REPORT_JSON), cli_json_done = 1;
    else if (!rc && p->check) ulam_report_fprint(stdout, ULAM_REPORT_BIDIR, p, ULAM_REPORT_CHECK);
    if (!rc && r->walks.interrupted) rc = EXIT_INTERRUPTED;
    if (!rc && o->walk.stop.rel_err > 0 && !r->walks.rel_err_met) rc = EXIT_TARGET; /* printed "NOT met" */
    cli_flush();
    if (rc == EXIT_INTERRUPTED && check && !cli_share) { /* the reference's thread still reads the system */
        fflush(stderr);
        _exit(rc);
    }
    return rc;
}

/* The refusal of a --rel-err target the walks from b cannot meet (forward walks on M, adjoint on
 * M', whose rho(M^) is not certified below 1): exit 4, as for the walks, the radius named by the
 * forward guard g (the library's message names the mode on M'). */
static int refuse_infvar(const cli_system *s, const ulam_bidir_opts *o, const ulam_guard *g)
{
    fprintf(stderr, "ulam: %s: error: --rel-err %g can never be met: the walks from b are forward walks on M, whose "
                    "rho(M^) is in [%.4g, %.4g], not certified below 1. Bound the run with --walks N or --time S (no "
                    "confidence interval is then printed), or let --method auto choose\n",
            s->matrix_path, o->walk.stop.rel_err, g->hat[ULAM_FORWARD].lower, g->hat[ULAM_FORWARD].upper);
    return EXIT_INFVAR;
}

/* Transpose, push, walk and print, on an analysis of M (its transpose a prepared file's stored
 * one after prepare --transpose: none to build); 0 or an exit code. */
static int run(cli_system *s, ulam_bidir_opts *o, report *rp)
{
    ulam_analysis *an = NULL;
    ulam_analysis_opts ao = ulam_analysis_defaults();
    ao.continue_q = o->walk.kernel.continue_q, ao.kernel_alpha = o->walk.kernel.kernel_alpha, ao.system = s->sys_M;
    ulam_error err;
    int status = ulam_analysis_alloc(s->M, &ao, &an, &err);
    double t0 = ulam_now();
    if (!status && !ulam_analysis_transpose(an, &err)) status = err.status;
    rp->rep.transpose_seconds = ulam_now() - t0;
    ulam_bidir_result r;
    o->walk.stop.interrupt = &cli_interrupted, o->walk.exec.share = cli_share;
    cli_catch_sigint();
    if (!status) status = ulam_analysis_bidir(an, o, &r, &err); /* its push workspace and plan */
    int rc = status == ULAM_EINFVAR ? refuse_infvar(s, o, &rp->g) : status ? cli_report(s->matrix_path, &err)
                                                                    : answer(s, o, &r, rp);
    cli_release_sigint();
    ulam_analysis_free(an);
    return rc;
}

/* --source S (or seeds, or --pagerank's uniform s) without --index: every component by forward
 * push and walks (src/fpush.c), the largest K printed with their intervals; a seed set is the one
 * source of the system with a virtual state feeding it (cli_graph_augment); 0 or an exit code. */
static int run_all(cli_system *s, int64_t source, int force, const ulam_bidir_opts *bo, int64_t top, report *rp)
{
    ulam_fpush_opts o = ulam_fpush_defaults();
    o.walk = bo->walk;
    o.walk.mode = ULAM_FORWARD;
    o.walk.stop.max_walks = bo->walk.stop.max_walks > 0 ? bo->walk.stop.max_walks : 0;
    o.walks = o.walk.stop.max_walks;
    if (bo->walk.stop.rel_err > 0) o.rel_err = bo->walk.stop.rel_err;
    o.rmax = bo->rmax, o.min_value = bo->min_value, o.step_cost = bo->step_cost, o.source = source - 1;
    int check = rp->check;
    rp->check = 0; /* prepare's direct value is for one index */
    /* one source on a prepared file: read where the push and the walks go, each block verified when
     * first read (seeds and --check read all of M; ranks share nothing of it here) */
    s->lazy = source && !check && !cli_share && ulam_system_is_file(s->matrix_path);
    int rc = prepare(s, source, force, (ulam_bidir_opts *)bo, NULL, NULL, rp);
    if (rc) return rc;
    int64_t n = s->M->nrows;
    if (top > n) top = n;
    double alpha = s->pagerank, scale = alpha > 0 ? 1.0 - alpha : 1.0;
    ulam_csr *Ma = NULL, *Mt = NULL;
    const ulam_csr *W = s->M;
    int status = ULAM_OK;
    if (!source) { /* seeds: one source, the virtual state n; x' = alpha x */
        status = cli_graph_augment(s->M, s->b, alpha, &Ma);
        W = Ma, o.source = n, scale /= alpha;
        if (!(o.min_value > 0)) o.min_value = alpha / (double)n; /* 1 / n of x, as for one source */
    }
    int64_t nw = W ? W->nrows : n, want = top + (W != s->M); /* and the virtual state, the largest */
    /* x for every component, the rest for the top ones only (ulam_fpush_top: no sort of n) */
    size_t kk = (size_t)want;
    int64_t *order = malloc(kk * sizeof *order);
    double *x = malloc((size_t)nw * sizeof *x), *se = malloc(kk * sizeof *se);
    double *lo = malloc(kk * sizeof *lo), *hi = malloc(kk * sizeof *hi), *xd = NULL;
    ulam_fpush_info info;
    ulam_error err;
    int lazy = s->lazy && W == s->M && s->sys_M; /* the library takes the file's M^T (or transposes M) */
    const ulam_csr *T = W == s->M && s->sys_M && !lazy ? ulam_system_transpose(s->sys_M) : NULL; /* prepare --transpose's */
    if (T && (T->nrows != nw || ulam_csr_nnz(T) != ulam_csr_nnz(W))) T = NULL;
    if (!status) status = !order || !x || !se || !lo || !hi ? ULAM_ENOMEM : T || lazy ? ULAM_OK : ulam_csr_transpose(W, &Mt);
    if (!T) T = Mt;
    o.walk.policy.system = lazy ? s->sys_M : NULL;
    o.walk.policy.guard = &rp->g, o.walk.stop.interrupt = &cli_interrupted; /* M's guards serve M': same spectrum */
    if (status) err = (ulam_error){.status = status, .msg = "memory for every component"};
    struct timespec c0, c1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    cli_catch_sigint(); /* Ctrl-C stops the walks: the table so far is printed, marked [INTERRUPTED] */
    o.walk.stop.max_seconds = cli_time_left(bo->walk.stop.max_seconds); /* --time counts the reading and guards too */
    if (!status) status = ulam_fpush_top(W, T, &o, want, x, order, se, lo, hi, &info, &err);
    cli_release_sigint();
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec); /* push and walks */
    if (status) rc = cli_report(s->matrix_path, &err);
    int crc = 0; /* --check's: a failed or interrupted reference still prints the table, without it */
    double dsec = 0.0;
    const char *dm = NULL;
    if (!rc && check && cli_rank == 0) crc = cli_direct_reference(s, -1, 0.0, &xd, &dsec, &dm);
    int64_t shown = 0; /* the top rows without the virtual state, scaled to pi */
    for (int64_t k = 0; !rc && k < want && shown < top; k++)
        if (order[k] < n) {
            int64_t i = order[k];
            order[shown] = i, se[shown] = se[k] * scale, lo[shown] = lo[k] * scale, hi[shown] = hi[k] * scale;
            x[i] *= scale;
            if (xd) xd[i] *= alpha > 0 ? 1.0 - alpha : 1.0;
            shown++;
        }
    if (!rc && cli_rank == 0) {
        ulam_bidir_report *p = &rp->rep;
        info.residual_bound *= scale, info.min_value *= scale; /* as the estimates: of pi, or of x */
        p->top = &info, p->n = n, p->source = source, p->rows = shown, p->order = order, p->x = x, p->direct_x = xd;
        p->se = se, p->lo = lo, p->hi = hi, p->cpu_seconds = cpu, p->direct_seconds = dsec, p->direct_method = dm;
        report_fill(s, rp);
        ulam_report_fprint(stdout, ULAM_REPORT_BIDIR, p, rp->json ? ULAM_REPORT_JSON : cli_verbosity < 0 ? ULAM_REPORT_QUIET
                                                                                            : ULAM_REPORT_BRIEF);
        cli_json_done |= rp->json;
    }
    if (!rc && cli_interrupted) rc = EXIT_INTERRUPTED;
    if (!rc && info.interrupted == 2 && bo->walk.stop.rel_err > 0) rc = EXIT_TARGET; /* --time ended it before --rel-err */
    if (!rc) rc = crc;
    if (crc == EXIT_INTERRUPTED && !cli_share) { /* the reference's thread still reads the system */
        cli_flush();
        fprintf(stderr, "ulam: --check interrupted: the estimates above stand unchecked\n");
        _exit(rc);
    }
    free(order), free(x), free(se), free(lo), free(hi), free(xd);
    ulam_csr_free(Mt), ulam_csr_free(Ma);
    return rc;
}

/* The bidirectional row's options (src/cli/solve_rows.c reads them). */
static const struct option longopts[] = {
    {"rhs", required_argument, 0, 'b'},       {"index", required_argument, 0, 'i'},
    {"source", required_argument, 0, 'u'},    {"method", required_argument, 0, 'M'},
    {"rmax", required_argument, 0, 'x'},      {"min-value", required_argument, 0, 'v'},
    {"step-cost", required_argument, 0, 'k'}, {"top", required_argument, 0, 'T'},
    CLI_WALK_OPTION("estimator"),             CLI_WALK_OPTION("walks"),
    CLI_WALK_OPTION("rel-err"),               CLI_WALK_OPTION("time"),
    CLI_WALK_OPTION("seed"),                  CLI_WALK_OPTION("threads"),
    CLI_WALK_OPTION("continue"),              CLI_WALK_OPTION("max-steps"),
    {"check", no_argument, 0, 'c'},           {"json", no_argument, 0, 'J'},
    {"force", no_argument, 0, 'F'},           {"cache", no_argument, 0, 'C'},
    {"pagerank", required_argument, 0, 'P'},  {"damping", required_argument, 0, 'P'},
    {"help", no_argument, 0, 'h'},            {0, 0, 0, 0}};

/* What the command line gives a bidirectional solve. */
typedef struct {
    cli_system s;
    ulam_bidir_opts o;
    report rp;
    int64_t source, top;
    int force, method;
    cli_solve_route route; /* set when the walks row solves instead (CLI_ROUTE_WALKS) */
} bidir_args;

/* The arguments before any option. */
static void init(void *p)
{
    bidir_args *a = p;
    *a = (bidir_args){.s = {.command = "solve", .omega = 1.0}, .o = ulam_bidir_defaults()};
    a->o.walk.stop.max_walks = 0;
}

/* One option (c its code in longopts) into the arguments; 0, or an exit code (-1: --help printed). */
static int option(void *p, int c, const char *name, const char *optarg)
{
    bidir_args *a = p;
    ulam_error err;
    int rc;
    switch (c) {
    case CLI_WALK: if ((rc = cli_walk_option("solve", name, optarg, &a->o.walk))) return rc; break;
    case 'b': a->s.rhs_path = optarg; break;
    case 'i': if ((rc = cli_parse_node("solve", "--index", optarg, &a->s.index))) return rc; break;
    case 'u': /* a node, or a seed set: ids with commas, or a file of them */
        if (cli_seeds_is_list(optarg) || (strspn(optarg, "0123456789") != strlen(optarg) && !strchr("+-", optarg[0])))
            a->rp.seeds = optarg, a->source = 0;
        else if ((rc = cli_parse_node("solve", "--source", optarg, &a->source))) return rc;
        else a->rp.seeds = NULL;
        break;
    case 'P': if ((rc = cli_parse_damping("solve", optarg, &a->s.pagerank))) return rc; break;
    case 'M':
        if (ulam_method_find(optarg) != ULAM_METHOD_BIDIRECTIONAL)
            return cli_usage_error("solve", "--source S and --rmax go with --method bidirectional, got '%s'", optarg);
        a->method = 1;
        break;
    case 'x': case 'v': case 'k': /* the library's table (src/options.c) */
        if (ulam_options_set(ULAM_OPTIONS_BIDIR, &a->o, name, optarg, &err)) return cli_usage_error("solve", "%s", err.msg);
        break;
    case 'T': if ((rc = cli_parse_int("solve", "--top", optarg, 1, ULAM_MAX_DIM, &a->top))) return rc; break;
    case 'c': a->rp.check = 1; break;
    case 'J': a->rp.json = 1; break;
    case 'F': a->force = 1; break;
    case 'C': a->s.cache = 1; break;
    case 'h': ulam_options_help(stdout, "bidirectional"); return -1;
    default: return cli_usage_error("solve", "unknown option for a --source solve");
    }
    return 0;
}

/* The options read (argv[optind..]: the operands): check them and run; 0 or an exit code. */
static int start_run(void *p, int argc, char **argv, int optind)
{
    bidir_args *a = p;
    cli_system s = a->s;
    ulam_bidir_opts o = a->o;
    report rp = a->rp;
    int64_t source = a->source, top = a->top, *bidx = NULL;
    int rc, force = a->force, method = a->method;
    double *bval = NULL;
    if (optind != argc - 1) return cli_operands_error("solve", argc, argv, optind);
    if (s.rhs_path && (source || rp.seeds)) return cli_usage_error("solve", "--source S sets b = e_S: it cannot go with --rhs");
    if (rp.seeds && !(s.pagerank > 0))
        return cli_usage_error("solve", "--source %s: a seed set is a personalisation vector: it needs --pagerank ALPHA "
                               "(a plain system takes b as --rhs b.mtx with --method bidirectional)", rp.seeds);
    if (s.pagerank > 0 && !s.rhs_path) rp.scale = 1.0 - s.pagerank, cli_answer_name = "pi"; /* b = s: pi = (1 - alpha) x */
    if (s.rhs_path && !method && top)
        return cli_usage_error("solve", "--top K lists the largest components of x for one source: it needs --source S "
                               "(b = e_S) or --pagerank ALPHA, not --rhs");
    if (s.rhs_path && !method)
        return cli_usage_error("solve", "--rhs b with --rmax is a bidirectional solve: say --method bidirectional");
    if (!source && !s.rhs_path && !rp.seeds && !(s.pagerank > 0 && !s.index))
        return cli_usage_error("solve", "--method bidirectional needs --source S (b = e_S) or a sparse --rhs b.mtx");
    if (top && s.index) return cli_usage_error("solve", "--top K lists the largest of every component: not with --index");
    if (!s.index && s.rhs_path) return cli_usage_error("solve", "--method bidirectional needs --index I");
    if (!s.index) { /* single source, every target */
        s.matrix_path = argv[optind];
        rc = run_all(&s, source, force, &o, top ? top : 10, &rp);
        cli_system_free(&s);
        return rc;
    }
    cli_walk_budget(&o.walk);
    o.walk.policy.force = force;
    s.matrix_path = argv[optind];
    if (!(rc = prepare(&s, source, force, &o, &bidx, &bval, &rp))) {
        o.target = s.index - 1, o.source = source ? source - 1 : 0;
        rc = run(&s, &o, &rp);
    } else if (rc == ROUTE_ADJOINT) {
        cli_system_free(&s);
        a->route = (cli_solve_route){.s = a->s, .walk = o.walk, .source = source, .json = rp.json, .check = rp.check,
                                     .force = force};
        a->route.s.matrix_path = argv[optind];
        return CLI_ROUTE_WALKS;
    }
    free(bidx), free(bval);
    cli_system_free(&s);
    return rc;
}

/* Bidirectional: --source S, --rmax or --method bidirectional. */
static const char *const claims[] = {"source", "rmax", "top", NULL};

/* --method bidirectional is this row's. */
static int serves(const char *method)
{
    return method && ulam_method_find(method) == ULAM_METHOD_BIDIRECTIONAL;
}

/* See cli.h. */
const cli_solve_route *cli_bidir_route(const void *p)
{
    return &((const bidir_args *)p)->route;
}

const cli_solve_row cli_solve_bidir_row = {"bidirectional", longopts, claims, serves, sizeof(bidir_args), init, option,
                                           start_run};

/* The push on b's b as its report names it: e_s (a single 1) as the source, else b's nonzeros
 * counted into o->nb (the report reads the count alone; b_index and b_value stay NULL). */
static void pushed_b(const cli_system *s, ulam_bidir_opts *o)
{
    int64_t nb = 0, at = 0;
    for (int64_t i = 0; i < s->M->nrows; i++)
        if (s->b[i] != 0.0) nb++, at = i;
    if (nb == 1 && s->b[at] == 1.0) o->source = at, o->nb = 0;
    else o->nb = nb;
}

/* Run the chosen bidirectional (cli.h). */
int cli_bidir_auto_run(cli_system *s, ulam_run *run, const ulam_choice *ch, int route, int json, int check,
                       double load_seconds)
{
    report rp = {.json = json, .check = check,
                 .rep = {.load_seconds = load_seconds, .transpose_seconds = ch->transpose_seconds, .choice = ch}};
    for (int64_t i = 0; i < s->M->nrows; i++) rp.rep.bmax = fmax(rp.rep.bmax, fabs(s->b[i]));
    rp.rep.dense = route; /* ulam__method_bidir_route: the push on b */
    int rc = 0;
    if (!route) { /* the dense route's walks run on M under the walks' own guards */
        if ((rc = cli_guard(s, ch->bidir_opts.walk.kernel.continue_q, 1.0, ULAM_FORWARD, &rp.g))) return rc;
        rp.rep.guard_seconds = rp.g.abs.seconds + rp.g.hat[0].seconds + rp.g.hat[1].seconds;
        cli_guard_warn(s, &rp.g, ULAM_FORWARD, 0);
    }
    ulam_answer a;
    ulam_error err;
    cli_catch_sigint();
    int status = ulam_run_finish(run, &a, &err);
    ulam_bidir_opts o = ch->bidir_opts;
    o.walk = a.opts;
    if (route) pushed_b(s, &o);
    rc = status ? cli_report(s->matrix_path, &err) : answer(s, &o, &a.bidir, &rp);
    cli_flush();
    cli_release_sigint();
    return rc;
}
