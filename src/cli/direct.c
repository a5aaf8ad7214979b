/* ulam direct: the reference solve of (I - M) x = b, sparse (UMFPACK) or dense (LAPACK); and the
 * interruptible reference of solve --check. */
#include "cli.h"

#include <getopt.h>
#include <pthread.h>
#include <stdatomic.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The iterative reference's plan in words (past the LU's memory limit): which solver, to what, its cap. */
static void iterative_words(char *buf, size_t size, const ulam_reference_info *p, int64_t index, double half_width)
{
    char what[160];
    if (index >= 0 && half_width > 0)
        snprintf(what, sizeof what, "until x[%lld]'s certified range is within +-%.3g (a thousandth of the walks' "
                 "half-width)", (long long)(index + cli_node_base), half_width); /* x: PageRank's too (pi scaled) */
    else snprintf(what, sizeof what, "until its certified range no longer narrows");
    snprintf(buf, size, "%s %s, at most %lld products", p->cg ? "CG (M symmetric)" : "GMRES(50)", what,
             (long long)p->products);
}

/* Before a reference solve that may take long: what it needs, on stderr (nothing when it is quick). */
static void announce(const cli_system *s, int sparse, int64_t index, double half_width)
{
    int64_t n = s->M->nrows, nnz = s->M->rowptr[n];
    double flops = 2.0 / 3.0 * (double)n * (double)n * (double)n, gib = (double)ulam_direct_bytes(n) / 1073741824.0;
    ulam_reference_info p;
    ulam_error err;
    int est = !ulam_reference_plan(s->M, sparse, sparse && nnz + n > 200000, &p, &err);
    double bytes = p.bytes, lu_flops = p.flops;
    char it[400];
    iterative_words(it, sizeof it, &p, index, half_width);
    if (sparse && nnz + n > 200000 && est && bytes > (double)CLI_MAX_MEM)
        fprintf(stderr, "ulam: --check: sparse LU (UMFPACK) of n = %lld, %lld nonzeros: at most %.3g GiB (UMFPACK's "
                        "bound), over 4 GiB, so %s instead; Ctrl-C keeps the estimate\n",
                (long long)n, (long long)nnz, bytes / 1073741824.0, it);
    else if (sparse && nnz + n > 200000 && est)
        fprintf(stderr, "ulam: --check: sparse LU (UMFPACK) of n = %lld, %lld nonzeros: at most %.3g GiB and %.2g flops "
                        "(UMFPACK's bounds; at most about %.0f s at 10 Gflop/s); Ctrl-C keeps the estimate\n",
                (long long)n, (long long)nnz, bytes / 1073741824.0, lu_flops, lu_flops / 1e10);
    else if (!sparse && !(gib * 1073741824.0 <= (double)CLI_MAX_MEM))
        fprintf(stderr, "ulam: --check: dense LU (LAPACK) of n = %lld: %.3g GiB, over 4 GiB%s, so %s instead; Ctrl-C "
                        "keeps the estimate\n", (long long)n, gib, p.umfpack ? "" : " (this ulam has no UMFPACK for a sparse LU)", it);
    else if (!sparse && flops > 2e10)
        fprintf(stderr, "ulam: --check: dense LU (LAPACK) of n = %lld: %.3g GiB and 2/3 n^3 = %.2g flops (about %.0f s "
                        "at 10 Gflop/s)%s; Ctrl-C keeps the estimate\n", (long long)n, gib, flops, flops / 1e10,
                p.umfpack ? "" : " (this ulam has no UMFPACK for a sparse LU)");
}

/* The reference solve in a thread, so that Ctrl-C can leave it. */
typedef struct {
    const cli_system *s;
    int sparse;   /* sparse LU first (else dense) */
    int krylov;   /* the LU would pass the memory limit: CG or GMRES(50) to the goal instead */
    ulam_reference_goal goal;
    double *x;
    ulam_direct_info info;
    int rc;
    atomic_int done;
} check_job;

/* Run the job (thread body): the LU, or CG / GMRES(50) when the LU's memory passes the limit. */
static void *check_run(void *p)
{
    check_job *j = p;
    const ulam_csr *M = j->s->M;
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the solution"};
    int status = ULAM_ENOMEM;
    const char *how = "";
    if ((j->x = malloc((size_t)M->nrows * sizeof *j->x))) /* CG or GMRES when the LU would pass the limit */
        status = ulam_reference_solve(M, j->s->b, cli_direct_force, CLI_MAX_MEM, &j->goal, j->x, &j->info, &how, &err);
    j->krylov = !strcmp(how, "CG") || !strcmp(how, "GMRES(50)");
    if (j->krylov && status == ULAM_ENOCONV && j->goal.certified) { /* the range it reached is said, not hidden */
        fprintf(stderr, "ulam: %s: warning: --check: %s\n", j->s->matrix_path, err.msg);
        status = ULAM_OK;
    }
    j->rc = status ? cli_report(j->s->matrix_path, &err) : 0;
    atomic_store(&j->done, 1);
    return NULL;
}

/* What the iterative reference reached, for --check's line (one check a process: a static buffer). */
static const char *iterative_method(const check_job *j)
{
    static char buf[400];
    const ulam_reference_goal *g = &j->goal;
    const char *name = g->cg ? "CG" : "GMRES(50)";
    if (!g->certified)
        snprintf(buf, sizeof buf, "%s to a relative residual of %.3g, %lld products, uncertified (no vector shows rho(|M|) "
                 "below 1); the LU would pass 4 GiB", name, j->info.residual, (long long)g->products);
    else if (g->met && g->half_width > 0)
        snprintf(buf, sizeof buf, "%s to a certified range of +-%.3g, wanted +-%.3g, %lld products; the LU would "
                 "pass 4 GiB", name, g->reached, g->half_width, (long long)g->products);
    else if (g->met)
        snprintf(buf, sizeof buf, "%s to a certified range of +-%.3g, as narrow as it got, %lld products; the LU "
                 "would pass 4 GiB", name, g->reached, (long long)g->products);
    else if (g->half_width > 0)
        snprintf(buf, sizeof buf, "%s %s: certified only to +-%.3g, NOT the +-%.3g wanted; the LU would pass 4 GiB",
                 name, g->capped ? "stopped at its cap of products" : "stopped at the rounding's floor", g->reached,
                 g->half_width);
    else
        snprintf(buf, sizeof buf, "%s %s: certified to +-%.3g; the LU would pass 4 GiB", name,
                 g->capped ? "stopped at its cap of products" : "stopped at the rounding's floor", g->reached);
    return buf;
}

/* The reference solve of s for --check into a new *x (all of it), *method "sparse LU", "dense LU"
 * or what CG / GMRES(50) reached (when the LU would pass the memory limit); the needs announced
 * first when large; 0, an exit code (reported), or EXIT_INTERRUPTED on Ctrl-C (cli_interrupted)
 * while the solve still runs in its thread (s must then stay loaded until exit). */
int cli_direct_reference(const cli_system *s, int64_t index, double half_width, double **x, double *seconds,
                         const char **method)
{
    *x = NULL;
    check_job *j = calloc(1, sizeof *j);
    if (!j) return cli_exit_code(ULAM_ENOMEM);
    double t0 = ulam_now(); /* the whole check's wall time: a sparse LU's symbolic step refused for memory then
                               GMRES(50) printed 0.253 s after 36 s (newuser18, n = 200000) */
    ulam_reference_info p;
    ulam_reference_plan(s->M, cli_direct_force, 0, &p, NULL);
    double want = isfinite(half_width) && half_width > 0 ? 1e-3 * half_width : 0.0; /* enough to judge the walks */
    j->s = s, j->sparse = p.sparse, j->goal = (ulam_reference_goal){.index = index, .half_width = want};
    announce(s, j->sparse, index, want);
    pthread_t t;
    if (pthread_create(&t, NULL, check_run, j)) {
        check_run(j);
    } else {
        while (!atomic_load(&j->done) && !cli_interrupted) nanosleep(&(struct timespec){0, 20000000}, NULL);
        if (!atomic_load(&j->done)) {
            pthread_detach(t);
            *method = "interrupted";
            return EXIT_INTERRUPTED;
        }
        pthread_join(t, NULL);
    }
    *method = j->krylov ? iterative_method(j) : j->sparse ? "sparse LU" : "dense LU";
    int rc = j->rc;
    if (!rc) *x = j->x, *seconds = ulam_now() - t0;
    else free(j->x);
    free(j);
    return rc;
}

/* x_index of the reference solve of s for --check (cli_direct_reference). */
int cli_direct_check(const cli_system *s, int64_t index, double half_width, double *value, double *seconds,
                     const char **method)
{
    double *x;
    int rc = cli_direct_reference(s, index, half_width, &x, seconds, method);
    if (!rc) *value = x[index];
    free(x);
    return rc;
}


/* ulam direct. */
int cli_direct(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"rhs", required_argument, 0, 'b'},     {"index", required_argument, 0, 'i'},
        {"out", required_argument, 0, 'o'},     {"max-mem", required_argument, 0, 'm'},
        {"jacobi", no_argument, 0, 'j'},        {"omega", required_argument, 0, 'w'},
        {"json", no_argument, 0, 'J'},          {"help", no_argument, 0, 'h'},
        {"lu", required_argument, 0, 'L'},      {"pagerank", required_argument, 0, 'P'},
        {"damping", required_argument, 0, 'P'}, {0, 0, 0, 0}};
    static const char *const lu_names[] = {"dense", "sparse", "auto"};
    cli_system s = {.command = "direct", .omega = 1.0};
    const char *out = NULL, *index = NULL;
    size_t max_mem = CLI_MAX_MEM;
    int json = 0, c, rc;
    ulam_reference_info plan;
    if (cli_check_options("direct", argc, argv, longopts)) return EXIT_USAGE;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': s.rhs_path = optarg; break;
        case 'i': index = optarg; break; /* parsed once the file's node numbering is known */
        case 'o': out = optarg; break;
        case 'm': if ((rc = cli_parse_bytes("direct", "--max-mem", optarg, &max_mem))) return rc; break;
        case 'j': s.jacobi = 1; break;
        case 'w': if ((rc = cli_parse_real("direct", "--omega", optarg, 1e-6, 2.0, &s.omega))) return rc; break;
        case 'J': json = 1; break;
        case 'P': if ((rc = cli_parse_damping("direct", optarg, &s.pagerank))) return rc; break;
        case 'L':
            if ((cli_direct_force = cli_choose("direct", "--lu", optarg, lu_names, 3, "auto, sparse or dense")) < 0)
                return EXIT_USAGE;
            if (cli_direct_force == 2) cli_direct_force = -1;
            if (cli_direct_force == 1 && (ulam_reference_plan(NULL, 1, 0, &plan, NULL), !plan.umfpack))
                return cli_usage_error("direct", "--lu sparse: this ulam was built without UMFPACK (libsuitesparse-dev)");
            break;
        case 'h': ulam_options_help(stdout, "direct"); return 0;
        default: return cli_usage_error("direct", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_operands_error("direct", argc, argv, optind);
    ulam_error err;
    if (ulam_edgelist_is_file(argv[optind]) && cli_graph_preload(argv[optind], NULL, &err))
        return cli_report(argv[optind], &err); /* an edge list's ids number the states */
    if (index && (rc = cli_parse_node("direct", "--index", index, &s.index))) return rc;
    if (!s.rhs_path && !s.pagerank && !ulam_system_is_file(argv[optind])) return cli_need_rhs("direct", argv[optind]);
    s.matrix_path = argv[optind];
    const cli_file outs[] = {{"--out", out}}, ins[] = {{"the matrix", s.matrix_path}, {"--rhs", s.rhs_path}};
    if ((rc = cli_check_outputs("direct", outs, 1, ins, 2))) return rc;
    if ((rc = cli_load_system(&s))) return rc;
    if (!s.b) {
        cli_system_free(&s);
        return cli_usage_error("direct", "needs --rhs b.mtx (%s holds no b)", s.matrix_path);
    }
    double *x = NULL;
    ulam_direct_info info;
    int status;
    if ((rc = cli_direct_solve(&s, max_mem, &x, &info))) {
        /* reported */
    } else { /* the answer first: a failed write of --out below cannot lose it */
        ulam_reference_plan(s.M, cli_direct_force, 0, &plan, NULL);
        ulam_direct_report d = {.n = s.M->nrows, .x = x, .index = s.index, .list = !out, .sparse = plan.sparse,
                                .info = info, .answer_name = cli_answer_name, .node_base = cli_node_base};
        cli_json_done |= json;
        ulam_report_fprint(stdout, ULAM_REPORT_DIRECT, &d, json ? ULAM_REPORT_JSON
                                                           : cli_verbosity < 0 ? ULAM_REPORT_QUIET : ULAM_REPORT_BRIEF);
        cli_flush();
        const char *hint = s.jacobi || json ? "" : cli_system_hint(s.M); /* the answer is (I - M)'s: say what M looks like */
        if (*hint) fprintf(stderr, "ulam: %s: note: this solves (I - M) x = b for M as read.%s\n", s.matrix_path, hint);
        if (out && (status = cli_write_vector(out, x, s.M->nrows, "solution of (I - M) x = b by ulam direct")))
            rc = cli_report_write(out, status, errno);
        else if (out && !json && cli_verbosity >= 0) printf("written    %s\n", out); /* --quiet: the file is the answer */
    }
    free(x);
    cli_system_free(&s);
    return rc;
}
