/* ulam solve: one unknown (adjoint) or every unknown (forward) by random walks. */
#include "cli.h"

#include <getopt.h>
#include <sys/resource.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage =
    "usage: ulam solve M.mtx --rhs b.mtx --index I [--mode adjoint|forward]\n"
    "                  [--estimator collision|absorption|expected] [--walks N] [--rel-err E]\n"
    "                  [--time S] [--seed S] [--threads T] [--continue Q] [--roulette W]\n"
    "                  [--split W] [--max-steps K] [--jacobi [--omega W]] [--check] [--json]\n"
    "                  [--out x.mtx] [--errors e.mtx] [--force] [--cache] [--whole-kernel]\n"
    "\n"
    "Estimate x_I of (I - M) x = b by von Neumann-Ulam random walks, with an error bar.\n"
    "Indices are 1-based, as in Matrix Market files.\n"
    "M.mtx may be a prepared system (ulam prepare): it is mapped and read only where the walks\n"
    "go, its certificate serves the guards, and it holds b unless --rhs is given.\n"
    "\n"
    "  --mode adjoint     start walks at I and gather b (default): one unknown, cheaply\n"
    "  --mode forward     start walks from the source b and tally where they go: every unknown\n"
    "                     (--out x.mtx, --errors e.mtx write all estimates and standard errors)\n"
    "  --estimator E      collision (score at every visit, default), absorption (score where\n"
    "                     the walk ends, / p*), expected (score the exact next-step expectation)\n"
    "  --walks N          stop after N walks (default 100000 when no rule is given)\n"
    "  --rel-err E        stop once stderr / |estimate| <= E (after at least 1000 walks)\n"
    "  --time S           stop after S seconds; the first rule reached wins\n"
    "  --seed S           block q of walks uses stream (S, q): identical results for any --threads\n"
    "  --threads T        threads (default: all cores)\n"
    "  --continue Q       continue with probability Q in every state (default: analog,\n"
    "                     q_i = min(1, sum_j |M_ij|)); weights keep the estimate unbiased\n"
    "  --roulette W       Russian roulette below weight W (survive with |w|/W, weight W)\n"
    "  --split W          split particles above weight W into ceil(|w|/W) copies\n"
    "  --max-steps K      cut walks longer than K steps and count them (default 1000000)\n"
    "  --jacobi           the file holds A of A x = b; walk on M = I - omega D^-1 A\n"
    "  --omega W          damping of the Jacobi splitting (default 1)\n"
    "  --check            also solve with LAPACK: adds direct, direct_seconds and\n"
    "                     z = (estimate - direct) / stderr\n"
    "  --json             print one JSON object\n"
    "  --force            walk even when rho(|M|) >= 1 (otherwise refused with exit 3)\n"
    "  --cache            keep a binary copy of each input beside it (FILE.ulamcache) and read\n"
    "                     that instead of parsing while the file is unchanged (size, mtime)\n"
    "  --whole-kernel     build the walk kernel's every row before walking (default: a row\n"
    "                     is built when a walk first reaches it, so one unknown of a large\n"
    "                     system reads and keeps only the rows its walks visit)\n"
    "\n"
    "Before walking, the guards estimate rho(|M|) (the walks converge iff < 1) and rho(M^) of\n"
    "the kernel's second-moment matrix (the variance is finite iff < 1); with rho(M^) >= 1 the\n"
    "run goes on but reports no confidence interval.\n"
    "\n"
    "Ctrl-C stops the walks and prints the estimate so far (exit 130); a second Ctrl-C\n"
    "exits at once.\n";

static const char *const mode_names[] = {"adjoint", "forward"};
static const char *const est_names[] = {"collision", "absorption", "expected"};

typedef struct {
    int check, json;
    double direct, direct_seconds;
    uint64_t seed;
    ulam_guard g;
    int variance_finite;
    double load_seconds, guard_seconds, kernel_seconds; /* reading the inputs; the guards; the solver set-up */
} report_opts;

/* Peak resident memory of this process so far, in MiB. */
static double peak_rss_mib(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) ? 0.0 : (double)ru.ru_maxrss / 1024.0;
}

/* Nonzero when one walk dominates the sum of squares: a heavy tail. */
static int heavy(const ulam_walk_result *r)
{
    return r->walks >= 1000 && r->max_share > CLI_HEAVY_SHARE;
}

/* Print the human-readable block. */
static void print_text(const ulam_walk_opts *o, const ulam_walk_result *r, const report_opts *ro)
{
    double mean_len = r->walks ? (double)r->steps / (double)r->walks : 0.0;
    double rel = r->estimate != 0 ? r->std_error / fabs(r->estimate) : INFINITY;
    if (ro->variance_finite)
        printf("x[%lld]%*s%.10g +- %.3g (95%% CI %.10g .. %.10g)%s\n", (long long)o->index + 1,
               o->index < 9 ? 10 : 9, "", r->estimate, r->std_error, r->ci95[0], r->ci95[1],
               r->interrupted ? "  [INTERRUPTED]" : "");
    else
        printf("x[%lld]%*s%.10g (no confidence interval: the variance is infinite, rho(M^) >= 1; the "
               "sample stderr %.3g means nothing)%s\n", (long long)o->index + 1, o->index < 9 ? 10 : 9, "",
               r->estimate, r->std_error, r->interrupted ? "  [INTERRUPTED]" : "");
    printf("method          %s walks, %s estimator\n", mode_names[o->mode], est_names[o->estimator]);
    printf("walks           %lld (%lld cut at %lld steps%s)\n", (long long)r->walks, (long long)r->cut,
           (long long)o->max_steps, r->cut ? ": the estimate is biased by the cut" : "");
    printf("steps           %lld (mean walk length %.4g; kernel rows built %lld)\n", (long long)r->steps, mean_len,
           (long long)r->rows);
    printf("variance        %.6g per walk (relative error %.3g)\n", r->variance, rel);
    printf("seconds         %.4f (%.3g M steps/s, %d threads, seed %llu)\n", r->seconds,
           r->seconds > 0 ? (double)r->steps / r->seconds / 1e6 : 0.0, r->threads,
           (unsigned long long)ro->seed);
    printf("figure of merit %.4g (1 / (relative variance x seconds))\n",
           r->seconds > 0 && rel > 0 ? 1.0 / (rel * rel * r->seconds) : INFINITY);
    printf("guards          rho(|M|) %.6g (%s), rho(M^) %.6g (%s)\n", ro->g.abs.rho,
           cli_verdict_word(ro->g.verdict_abs), ro->g.hat[o->mode].rho, cli_verdict_word(ro->g.verdict_hat[o->mode]));
    if (heavy(r))
        printf("heavy tail      one walk holds %.1f%% of the sum of squared scores: the error bar is "
               "not to be trusted\n", 100 * r->max_share);
    printf("load            %.3f s inputs, %.3f s guards, %.3f s solver set-up; peak memory %.0f MiB\n",
           ro->load_seconds, ro->guard_seconds, ro->kernel_seconds, peak_rss_mib());
    if (ro->check)
        printf("direct          %.10g (LAPACK, %.4f s), z = %.3f\n", ro->direct, ro->direct_seconds,
               (r->estimate - ro->direct) / r->std_error);
}

/* Print the JSON object. */
static void print_json(const ulam_walk_opts *o, const ulam_walk_result *r, const report_opts *ro)
{
    double rel = r->estimate != 0 ? r->std_error / fabs(r->estimate) : INFINITY;
    printf("{\"index\": %lld, ", (long long)o->index + 1);
    cli_json_number("estimate", r->estimate, 0);
    cli_json_number("stderr", r->std_error, 0);
    if (ro->variance_finite) {
        printf("\"ci95\": [");
        cli_json_value(r->ci95[0]);
        printf(", ");
        cli_json_value(r->ci95[1]);
        printf("], ");
    } else {
        printf("\"ci95\": null, ");
    }
    printf("\"variance_finite\": %s, ", ro->variance_finite ? "true" : "false");
    cli_json_number("rho_abs", ro->g.abs.rho, 0);
    cli_json_number("rho_hat", ro->g.hat[o->mode].rho, 0);
    cli_json_number("max_share", r->max_share, 0);
    printf("\"heavy_tail\": %s, ", heavy(r) ? "true" : "false");
    cli_json_number("variance", r->variance, 0);
    printf("\"walks\": %lld, \"steps\": %lld, \"cut\": %lld, ", (long long)r->walks, (long long)r->steps,
           (long long)r->cut);
    cli_json_number("mean_length", r->walks ? (double)r->steps / (double)r->walks : 0.0, 0);
    cli_json_number("seconds", r->seconds, 0);
    cli_json_number("steps_per_second", r->seconds > 0 ? (double)r->steps / r->seconds : 0.0, 0);
    cli_json_number("figure_of_merit", r->seconds > 0 && rel > 0 ? 1.0 / (rel * rel * r->seconds) : NAN, 0);
    cli_json_string("mode", mode_names[o->mode], 0);
    cli_json_string("estimator", est_names[o->estimator], 0);
    printf("\"seed\": %llu, \"threads\": %d, \"ranks\": %d, ", (unsigned long long)ro->seed, r->threads,
           cli_share ? cli_share->nranks : 1);
    cli_json_number("load_seconds", ro->load_seconds, 0);
    cli_json_number("guard_seconds", ro->guard_seconds, 0);
    cli_json_number("kernel_seconds", ro->kernel_seconds, 0);
    printf("\"kernel_rows\": %lld, ", (long long)r->rows);
    cli_json_number("peak_rss_mib", peak_rss_mib(), 0);
    if (ro->check) {
        cli_json_number("direct", ro->direct, 0);
        cli_json_number("direct_seconds", ro->direct_seconds, 0);
        cli_json_number("z", (r->estimate - ro->direct) / r->std_error, 0);
    }
    printf("\"interrupted\": %s}\n", r->interrupted ? "true" : "false");
}

/* LAPACK value of x_index for --check; 0 or an exit code. */
static int direct_check(const cli_system *s, int64_t index, report_opts *ro)
{
    double *x;
    ulam_direct_info info;
    int rc = cli_direct_solve(s, (size_t)4 << 30, &x, &info);
    if (rc) return rc;
    ro->direct = x[index];
    ro->direct_seconds = info.seconds;
    free(x);
    return 0;
}

/* Write the forward vectors; 0 or an exit code. */
static int write_vectors(const ulam_solver *sv, int64_t n, const char *out, const char *errors)
{
    double *x = malloc((size_t)n * sizeof *x), *e = malloc((size_t)n * sizeof *e);
    int status = x && e ? ulam_solver_vectors(sv, x, e) : ULAM_ENOMEM;
    const char *path = out;
    if (!status && out) status = ulam_mm_write_vector(out, x, n, "forward random-walk estimates of x");
    if (!status && errors) {
        path = errors;
        status = ulam_mm_write_vector(errors, e, n, "standard errors of the forward estimates");
    }
    free(x), free(e);
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable output file and finite values"};
    return cli_report(path, &err);
}

/* ulam solve. */
int cli_solve(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"rhs", required_argument, 0, 'b'},       {"index", required_argument, 0, 'i'},
        {"mode", required_argument, 0, 'm'},      {"estimator", required_argument, 0, 'e'},
        {"walks", required_argument, 0, 'n'},     {"rel-err", required_argument, 0, 'r'},
        {"time", required_argument, 0, 't'},      {"seed", required_argument, 0, 's'},
        {"threads", required_argument, 0, 'T'},   {"continue", required_argument, 0, 'q'},
        {"roulette", required_argument, 0, 'R'},  {"split", required_argument, 0, 'S'},
        {"max-steps", required_argument, 0, 'K'}, {"jacobi", no_argument, 0, 'j'},
        {"omega", required_argument, 0, 'w'},     {"check", no_argument, 0, 'c'},
        {"json", no_argument, 0, 'J'},            {"out", required_argument, 0, 'o'},
        {"errors", required_argument, 0, 'E'},    {"help", no_argument, 0, 'h'},
        {"force", no_argument, 0, 'F'},           {"cache", no_argument, 0, 'C'},
        {"whole-kernel", no_argument, 0, 'W'},    {0, 0, 0, 0}};
    cli_system s = {.command = "solve", .omega = 1.0};
    ulam_walk_opts o = ulam_walk_defaults();
    report_opts ro = {.seed = 1};
    const char *out = NULL, *errors = NULL;
    int64_t v;
    int c, rc, any_rule = 0, force = 0;
    o.max_walks = 0;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': s.rhs_path = optarg; break;
        case 'i': if ((rc = cli_parse_int("solve", "--index", optarg, 1, ULAM_MAX_DIM, &s.index))) return rc; break;
        case 'm':
            if ((o.mode = cli_lookup(optarg, mode_names, 2)) < 0)
                return cli_usage_error("solve", "--mode expects adjoint or forward, got '%s'", optarg);
            break;
        case 'e':
            if ((o.estimator = cli_lookup(optarg, est_names, 3)) < 0)
                return cli_usage_error("solve", "--estimator expects collision, absorption or expected, got '%s'", optarg);
            break;
        case 'n': if ((rc = cli_parse_int("solve", "--walks", optarg, 1, INT64_MAX / 2, &o.max_walks))) return rc; any_rule = 1; break;
        case 'r': if ((rc = cli_parse_real("solve", "--rel-err", optarg, 1e-12, 1.0, &o.rel_err))) return rc; any_rule = 1; break;
        case 't': if ((rc = cli_parse_real("solve", "--time", optarg, 1e-6, 1e9, &o.max_seconds))) return rc; any_rule = 1; break;
        case 's': if ((rc = cli_parse_int("solve", "--seed", optarg, 0, INT64_MAX, &v))) return rc; o.seed = ro.seed = (uint64_t)v; break;
        case 'T': if ((rc = cli_parse_int("solve", "--threads", optarg, 1, 1024, &v))) return rc; o.threads = (int)v; break;
        case 'q': if ((rc = cli_parse_real("solve", "--continue", optarg, 1e-9, 1 - 1e-12, &o.continue_q))) return rc; break;
        case 'R': if ((rc = cli_parse_real("solve", "--roulette", optarg, 1e-300, 1e300, &o.roulette))) return rc; break;
        case 'S': if ((rc = cli_parse_real("solve", "--split", optarg, 1e-300, 1e300, &o.split))) return rc; break;
        case 'K': if ((rc = cli_parse_int("solve", "--max-steps", optarg, 1, INT64_MAX / 2, &o.max_steps))) return rc; break;
        case 'j': s.jacobi = 1; break;
        case 'C': s.cache = 1; break;
        case 'W': o.whole_kernel = 1; break;
        case 'w': if ((rc = cli_parse_real("solve", "--omega", optarg, 1e-6, 2.0, &s.omega))) return rc; break;
        case 'c': ro.check = 1; break;
        case 'J': ro.json = 1; break;
        case 'F': force = 1; break;
        case 'o': out = optarg; break;
        case 'E': errors = optarg; break;
        case 'h': fputs(usage, stdout); return 0;
        default: return cli_usage_error("solve", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("solve", "expects exactly one matrix file");
    if (!s.rhs_path && !ulam_system_is_file(argv[optind])) return cli_usage_error("solve", "needs --rhs b.mtx");
    if (!s.index && o.mode == ULAM_ADJOINT) return cli_usage_error("solve", "adjoint walks need --index I");
    if ((out || errors) && o.mode != ULAM_FORWARD)
        return cli_usage_error("solve", "--out and --errors need --mode forward");
    if (o.roulette > 0 && o.split > 0 && o.split <= o.roulette)
        return cli_usage_error("solve", "--split W must exceed --roulette W");
    if (!any_rule) o.max_walks = 100000;
    s.matrix_path = argv[optind];
    s.lazy = o.mode == ULAM_ADJOINT && !ro.check && !cli_share; /* read only the rows walks reach */
    double t0 = ulam_now();
    if ((rc = cli_load_system(&s))) return rc;
    if (!s.b) {
        cli_system_free(&s);
        return cli_usage_error("solve", "needs --rhs b.mtx (%s holds no b)", s.matrix_path);
    }
    ro.load_seconds = ulam_now() - t0;
    o.index = s.index ? s.index - 1 : 0;
    if ((rc = cli_guard(&s, o.continue_q, o.mode, force, &ro.g))) {
        cli_system_free(&s);
        return rc;
    }
    ro.guard_seconds = ro.g.abs.seconds + ro.g.hat[0].seconds + ro.g.hat[1].seconds;
    ro.variance_finite = ro.g.verdict_hat[o.mode] != ULAM_VERDICT_FAIL;
    if (ro.check && (rc = direct_check(&s, o.index, &ro))) {
        cli_system_free(&s);
        return rc;
    }
    ulam_solver *sv = NULL;
    ulam_error err;
    o.interrupt = &cli_interrupted, o.share = cli_share;
    t0 = ulam_now();
    int status = ulam_solver_alloc(s.M, s.b, &o, &sv, &err);
    ro.kernel_seconds = ulam_now() - t0;
    int64_t n = s.M->nrows;
    if (status) {
        cli_system_free(&s);
        return cli_report(s.matrix_path, &err);
    }
    cli_catch_sigint();
    while (!status && !ulam_solver_done(sv)) status = ulam_solver_iterate(sv);
    ulam_walk_result r;
    ulam_solver_result(sv, &r);
    rc = 0;
    if (status == ULAM_ENOMEM) {
        fprintf(stderr, "ulam: %s: error: %s: expected memory to build the walk kernel's rows\n", s.matrix_path,
                ulam_strerror(status));
        rc = cli_exit_code(status);
    } else if (status && status != ULAM_ENONFINITE) {
        fprintf(stderr, "ulam: %s: error: %s: expected rows the walks reach to be consistent (row data of "
                        "the mapped file is corrupt: prepare it again)\n", s.matrix_path, ulam_strerror(status));
        rc = cli_exit_code(status);
    } else if (status) {
        fprintf(stderr, "ulam: %s: error: %s: a walk produced a non-finite weight or score after %lld "
                        "walks; nothing was averaged in from it (is rho(|M|) < 1? see 'ulam info')\n",
                s.matrix_path, ulam_strerror(status), (long long)r.walks);
        rc = cli_exit_code(status);
    } else if (o.mode == ULAM_FORWARD && (out || errors) && !r.interrupted && cli_rank == 0) {
        rc = write_vectors(sv, n, out, errors);
    }
    if (!status && !rc) {
        if (ro.json) print_json(&o, &r, &ro);
        else print_text(&o, &r, &ro);
        if (r.interrupted) rc = EXIT_INTERRUPTED;
    }
    fflush(stdout); /* still caught: a second Ctrl-C ends a write blocked on a full pipe */
    cli_release_sigint();
    ulam_solver_free(sv);
    cli_system_free(&s);
    return rc;
}
