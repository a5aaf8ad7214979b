/* ulam solve SYSTEM.ulam --partition: the system's rows split across the ranks of mpirun, walks
 * that migrate (ulam_dist.h).  Alone (no mpirun, or a build without MPI) it is one rank. */
#include "cli.h"

#include <getopt.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ulam_dist.h"

static const char *const help =
    "usage: ulam solve (SYSTEM.ulam | M.mtx --rhs B.mtx) --partition (--index I | --queries FILE\n"
    "                  | --mode forward [--top K] [--out X.mtx]\n"
    "                  | --method mcsa [--tol T] [--out X.mtx] | --source S [--top K] [--out X.mtx])\n"
    "                  [--walks N | --rel-err E] [--seed S] [--max-steps N] [--batch N] [--sets K]\n"
    "\n"
    "The prepared system's rows are split across the ranks of mpirun (balanced by entries; each rank\n"
    "reads only its rows' blocks of SYSTEM.ulam, prepared with --rhs, and --transpose for forward).\n"
    "A walk that steps onto another rank's row travels there; random numbers are keyed by (seed,\n"
    "walk, step), so 1, 2, 3 or 64 ranks print the same answer bit for bit.  Collision estimator,\n"
    "analog kernel (p_ij = |M_ij| / row sum, leaving with min(1, row sum)).  Answers carry their\n"
    "standard error; --index and --queries (and --mode forward --index I) also a certified 95%\n"
    "interval when power iteration certifies a Collatz-Wielandt vector below 1 (the walk's length\n"
    "tail, or with a row sum above 1 its weights' second moment, so a score's range after clipping;\n"
    "docs/distributed.md).\n"
    "  --bound         (--mode forward) a certified range of every x_i from x's residual (needs M in the\n"
    "                  part too); MCSA and --source always print theirs\n"
    "  --rhs B.mtx     M.mtx is a coordinate Matrix Market file read by byte ranges: each rank parses\n"
    "                  its share of the lines, and the entries travel to their rows' ranks (the same\n"
    "                  rows and answer as the prepared file; b is read whole by each rank)\n"
    "  --index I       x_I by adjoint walks from I (1-based)\n"
    "  --queries FILE  x_I of each line 'I' of FILE (docs/queries.md), all walking together, each on\n"
    "                  a seed of its own, printed: a line answers what --index I --seed SEED answers\n"
    "  --mode forward  every x_i by forward walks; --out writes x as a Matrix Market vector, --errors\n"
    "                  their standard errors (also with --source); --index I prints x_I's line with its\n"
    "                  interval (its histories' tallies in a confidence sequence); --top K the K largest\n"
    "                  components, each with its range from x's residual (as --bound; M in the part too)\n"
    "  --method mcsa   every x_i by MCSA: Richardson steps (products with M across ranks) and forward\n"
    "                  walks' corrections (--walks each) to --tol (default 1e-8) of max|b|, --max-iter\n"
    "  --source S      x = (I - M)^-1 e_S: a push (products with M) to 1e-4, then forward walks; prints\n"
    "                  the --top K (default 10) components.  mcsa and --source need M' in the file\n"
    "  --walks N       histories (default 100000)       --seed S   the streams' key (default 1)\n"
    "  --rel-err E     (--index, --queries) stop a query at the first block of --batch walks whose\n"
    "                  interval's half-width is at most E |estimate|; --walks is then its most\n"
    "                  (default 2^30).  --mode forward --index I: no stop rule; it needs --walks N\n"
    "                  and judges x_I's interval after them (met, or NOT met: exit 5)\n"
    "  --max-steps N   cut a walk longer (default 1e6)  --batch N  walks a round starts (default 65536)\n"
    "  --sets K        the ranks in K sets, each a whole partition running its own batches (more\n"
    "                  memory a rank, no message between sets while walking; the same answer)\n"
    "docs/distributed.md says more.\n";

/* The parsed command line. */
typedef struct {
    const char *path, *out, *errors, *queries, *rhs;
    int64_t index; /* 1-based; 0 none */
    int forward, mcsa;
    int64_t sets, source, top, max_iter;
    double tol, rel_err;
    int walks_given, bound, top_given;
    ulam_dist_opts o;
} args;

static const struct option longopts[] = {
    {"partition", no_argument, 0, 'P'}, {"index", required_argument, 0, 'i'}, {"mode", required_argument, 0, 'm'},
    {"out", required_argument, 0, 'o'}, {"walks", required_argument, 0, 'w'}, {"seed", required_argument, 0, 's'},
    {"max-steps", required_argument, 0, 'x'}, {"batch", required_argument, 0, 'b'}, {"sets", required_argument, 0, 'S'}, {"queries", required_argument, 0, 'Q'}, {"errors", required_argument, 0, 'E'},
    {"method", required_argument, 0, 'M'}, {"tol", required_argument, 0, 'T'}, {"max-iter", required_argument, 0, 'I'},
    {"source", required_argument, 0, 'R'}, {"top", required_argument, 0, 'K'}, {"rel-err", required_argument, 0, 'e'},
    {"rhs", required_argument, 0, 'r'}, {"bound", no_argument, 0, 'B'}, {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};

/* The defaults. */
static void init(void *p)
{
    *(args *)p = (args){.o = ulam_dist_defaults(), .tol = 1e-8, .max_iter = 100, .top = 10};
}

/* One option (see cli_solve_row.option). */
static int option(void *p, int val, const char *name, const char *value)
{
    args *a = p;
    int64_t v = 0;
    int bad = 0;
    switch (val) {
    case 'P': return 0;
    case 'i': return cli_parse_int("solve", "--index", value, 1, INT32_MAX, &a->index);
    case 'm':
        if (!strcmp(value, "forward")) a->forward = 1;
        else if (strcmp(value, "adjoint"))
            return cli_usage_error("solve", "--mode with --partition is adjoint or forward, got '%s'", value);
        return 0;
    case 'o': a->out = value; return 0;
    case 'w': a->walks_given = 1; return cli_parse_int("solve", "--walks", value, 1, (int64_t)1 << 40, &a->o.walks);
    case 'e': return cli_parse_real("solve", "--rel-err", value, 1e-12, 1.0, &a->rel_err);
    case 's': bad = cli_parse_int("solve", "--seed", value, 0, INT64_MAX, &v), a->o.seed = (uint64_t)v; return bad;
    case 'x': return cli_parse_int("solve", "--max-steps", value, 1, INT64_MAX, &a->o.max_steps);
    case 'b': return cli_parse_int("solve", "--batch", value, 1, (int64_t)1 << 30, &a->o.batch);
    case 'Q': a->queries = value; return 0;
    case 'r': a->rhs = value; return 0;
    case 'B': a->bound = 1; return 0;
    case 'E': a->errors = value; return 0;
    case 'M':
        if (!strcmp(value, "mcsa")) a->mcsa = 1;
        else if (strcmp(value, "walks"))
            return cli_usage_error("solve", "--method with --partition is walks or mcsa, got '%s'", value);
        return 0;
    case 'T': return cli_parse_real("solve", "--tol", value, 1e-300, 1.0, &a->tol);
    case 'I': return cli_parse_int("solve", "--max-iter", value, 1, 1000000, &a->max_iter);
    case 'R': return cli_parse_int("solve", "--source", value, 1, INT32_MAX, &a->source);
    case 'K': a->top_given = 1; return cli_parse_int("solve", "--top", value, 1, 1000000, &a->top);
    case 'S': return cli_parse_int("solve", "--sets", value, 1, 1 << 20, &a->sets);
    case 'h': fputs(help, stdout); return -1;
    default:
        return cli_usage_error("solve", "--%s is not an option of a --partition run (ulam solve --partition --help)",
                               name ? name : "?");
    }
}

/* Check the operands and options read. */
static int check(args *a, int argc, char **argv, int first)
{
    if (first != argc - 1) return cli_usage_error("solve", "one prepared system file (or M.mtx --rhs B.mtx) with --partition");
    a->path = argv[first];
    if (!!a->forward + !!(a->index && !a->forward) + !!a->queries + a->mcsa + !!a->source != 1) /* forward: --index watches one */
        return cli_usage_error("solve", "one of --index I, --queries FILE, --mode forward, --method mcsa and --source S "
                                        "with --partition");
    if ((a->out || a->errors) && ((a->index && !a->forward) || a->queries))
        return cli_usage_error("solve", "--out and --errors with --partition write a whole x");
    if (a->bound && (!a->forward || a->mcsa || a->sets > 1))
        return cli_usage_error("solve", "--bound with --mode forward in one set (MCSA and --source print theirs)");
    if (a->errors && a->mcsa) return cli_usage_error("solve", "--errors with --mode forward or --source");
    if (a->top_given && !a->source && !(a->forward && !a->index && !a->mcsa))
        return cli_usage_error("solve", "--top K with --partition lists the largest components of --source S or of "
                                        "--mode forward (not with --index, --queries or MCSA)");
    if (a->top_given && a->forward && a->sets > 1)
        return cli_usage_error("solve", "--top K with --mode forward in one set (its ranges come from x's residual, as "
                                        "--bound's)");
    if (a->top_given && a->forward) a->bound = 1; /* each top line's range: x's residual */
    const cli_file outs[] = {{"--out", a->out}, {"--errors", a->errors}},
                   ins[] = {{"the system", a->path}, {"--queries", a->queries}, {"--rhs", a->rhs}};
    int rc = cli_check_outputs("solve", outs, 2, ins, 3);
    if (rc) return rc;
    if (a->rel_err > 0 && !a->index && !a->queries)
        return cli_usage_error("solve", "--rel-err with --partition and --index or --queries (forward mode, MCSA and "
                                        "--source give standard errors only)");
    if (a->rel_err > 0 && a->forward && !a->walks_given) /* 2^30 walks (hours) for a verdict, no stop */
        return cli_usage_error("solve", "--rel-err with --mode forward needs --walks N: forward walks on a partition have "
                                        "no stop rule, so the target is only judged on x_I's interval after the N walks; "
                                        "--index I without --mode forward (adjoint walks, the same x_I) stops at it");
    if (a->rel_err > 0 && !a->walks_given) a->o.walks = (int64_t)1 << 30;
    return 0;
}

/* Every rank's count of rows, in rank order, into rows[0 .. nranks). */
static int all_rows(const ulam_comm *c, int64_t mine, int64_t *rows)
{
    memset(rows, 0, (size_t)c->nranks * sizeof *rows);
    rows[c->rank] = mine;
    return c->nranks > 1 && c->sum(c->ctx, rows, c->nranks);
}

/* Write x (this rank's rows x[0 .. mine)) to path on rank 0, the other ranks' rows sent to it in
 * rank order through the exchange, a chunk a round; 0 or an exit code (on every rank). */
static int write_x(const ulam_comm *c, const char *path, const double *x, int64_t mine, int64_t n, const char *what)
{
    int64_t *rows = calloc((size_t)c->nranks, sizeof *rows), failed = 0;
    ulam_outfile o = {0};
    if (!rows || all_rows(c, mine, rows)) failed = 1;
    if (!failed && c->rank == 0) {
        int status = cli_outfile_open(&o, path);
        if (status || fprintf(o.f, "%%%%MatrixMarket matrix array real general\n%% %s by ulam solve --partition\n%lld 1\n",
                              what, (long long)n) < 0) failed = status ? status : 1;
        for (int64_t i = 0; !failed && i < mine; i++) failed = fprintf(o.f, "%.17g\n", x[i]) < 0;
    }
    enum { CHUNK = 1 << 16 };
    size_t *cnt = calloc((size_t)c->nranks * 2, sizeof *cnt);
    if (!cnt) failed = 1;
    for (int r = 1; r < c->nranks && rows; r++)
        for (int64_t at = 0; at < rows[r]; at += CHUNK) {
            int64_t k = rows[r] - at < CHUNK ? rows[r] - at : CHUNK;
            for (int q = 0; cnt && q < c->nranks; q++) cnt[q] = 0;
            if (cnt && c->rank == r) cnt[0] = (size_t)k * sizeof *x;
            void *got = NULL;
            if (!cnt || c->exchange(c->ctx, x + at, cnt, &got, cnt + c->nranks)) failed = 1;
            for (int64_t i = 0; !failed && c->rank == 0 && i < k; i++) failed = fprintf(o.f, "%.17g\n", ((double *)got)[i]) < 0;
            free(got);
        }
    if (c->rank == 0 && o.f) {
        if (failed) cli_outfile_abort(&o);
        else failed = cli_outfile_commit(&o);
        if (failed) cli_report_write(path, ULAM_EIO, 0);
    }
    free(rows), free(cnt);
    int64_t any = failed != 0;
    if (c->nranks > 1 && c->sum(c->ctx, &any, 1)) any = 1;
    return any ? cli_exit_code(ULAM_EIO) : 0;
}

/* Read the query file at path: 'I' lines only (no point source, no target: walks are fixed on a
 * partition), indices below n; 0 or an exit code (reported). */
static int load_queries(const char *path, int64_t n, cli_query **q, int64_t *nq)
{
    int rc = cli_read_queries(path, q, nq);
    for (int64_t k = 0; !rc && k < *nq; k++) {
        const cli_query *x = &(*q)[k];
        const char *why = x->source >= 0 ? "an 'I' line (a point source 'S I' is not run on a partition)"
                          : x->target > 0 ? "an 'I' line without a target (a partition runs a fixed --walks)"
                          : x->index >= n ? "an index within the system" : NULL;
        if (why) {
            fprintf(stderr, "ulam: %s:%ld: error: expected %s\n", path, x->line, why);
            rc = EXIT_USAGE;
        }
    }
    if (!rc && *nq == 0) {
        fprintf(stderr, "ulam: %s: error: expected at least one query\n", path);
        rc = EXIT_USAGE;
    }
    if (rc) free(*q), *q = NULL, *nq = 0;
    return rc;
}

/* The first nonzero status of the ranks, in rank order, on every rank (ULAM_EIO when the sum
 * itself fails): the exit code does not depend on which rank read the damaged block. */
static int first_status(const ulam_comm *c, int status)
{
    if (c->nranks == 1) return status;
    int64_t *v = calloc((size_t)c->nranks, sizeof *v);
    if (!v) return ULAM_ENOMEM;
    v[c->rank] = status;
    int bad = c->sum(c->ctx, v, c->nranks), first = 0;
    for (int r = 0; !bad && !first && r < c->nranks; r++) first = (int)v[r];
    free(v);
    return bad ? ULAM_EIO : first;
}

/* Run the parsed command on this rank. */
static int run(const args *a, const ulam_comm *c)
{
    ulam_part *p = NULL;
    ulam_error err;
    int what = a->mcsa || a->source || a->bound ? ULAM_PART_BOTH : a->forward ? ULAM_PART_MT : ULAM_PART_M;
    int status = a->rhs ? ulam_part_open_mtx(a->path, a->rhs, c, what, &p, &err) : ulam_part_open(a->path, c, what, &p, &err);
    int shared = first_status(c, status); /* every rank ends together, with the same code, when one cannot read its rows */
    if (shared) {
        if (status && (!a->rhs || c->rank == 0)) cli_report(a->path, &err); /* Matrix Market: every rank holds the first failure */
        ulam_part_free(p);
        return cli_exit_code(shared);
    }
    const char *die = getenv("ULAM_TEST_PARTITION_DIE"); /* tests: this rank dies before its walks */
    if (die && atoi(die) == c->rank && c->nranks > 1) _exit(9);
    int64_t first, last, n = ulam_part_rows(p, &first, &last, NULL), rows = last - first;
    int rc = 0;
    if (a->index > n || a->source > n) {
        ulam_part_free(p);
        return cli_usage_error("solve", "%s in 1 .. %lld, got %lld", a->index ? "--index" : "--source", (long long)n,
                               (long long)(a->index ? a->index : a->source));
    }
    cli_query *q = NULL;
    int64_t nq = 1, one = a->index - 1;
    if (a->queries && (rc = load_queries(a->queries, n, &q, &nq))) {
        ulam_part_free(p);
        return rc;
    }
    ulam_dist_ask ask = {.mode = a->mcsa ? ULAM_DIST_MCSA : a->source ? ULAM_DIST_SOURCE : a->forward ? ULAM_DIST_FORWARD : ULAM_DIST_ADJOINT,
                         .nq = nq, .rel_err = a->rel_err, .bound = a->bound, .tol = a->tol, .max_iter = (int)a->max_iter,
                         .source = a->source - 1, .top = a->top, .o = a->o};
    int64_t *idx = malloc((size_t)nq * sizeof *idx);
    long *lines = malloc((size_t)nq * sizeof *lines);
    for (int64_t k = 0; idx && lines && k < nq; k++) idx[k] = q ? q[k].index : one, lines[k] = q ? q[k].line : 0;
    ask.index = ask.mode == ULAM_DIST_FORWARD && !a->index ? NULL : idx; /* forward: a watched row, or none */
    int walks_forward = ask.mode != ULAM_DIST_ADJOINT;
    ulam_dist_answer s = {.ranks = malloc((size_t)c->nranks * 2 * sizeof(int64_t))};
    if (walks_forward) s.x = malloc(((size_t)rows + 1) * sizeof *s.x), s.se = malloc(((size_t)rows + 1) * sizeof *s.se);
    if (a->source || (a->forward && a->top_given)) s.tops = malloc(((size_t)a->top + 1) * sizeof *s.tops);
    if (!walks_forward || ask.index) s.res = malloc((size_t)nq * sizeof *s.res), s.ci = malloc((size_t)nq * sizeof *s.ci);
    if (!idx || !lines || !s.ranks || (walks_forward ? !s.x || !s.se || ((a->source || a->top_given) && !s.tops) : !s.res || !s.ci) ||
        (ask.index && (!s.res || !s.ci)))
        status = ULAM_ENOMEM, err.status = status, snprintf(err.msg, sizeof err.msg, "memory for the answer");
    else status = ulam_dist_run(p, c, &ask, &s, &err);
    ulam_part_free(p);
    rc = status ? (cli_report(a->path, &err), cli_exit_code(status)) : 0;
    int in_set0 = c->sets <= 1 || c->rank < c->nranks / c->sets; /* set 0's ranks hold x */
    if (!rc && a->out) rc = write_x(c, a->out, s.x, in_set0 ? rows : 0, n, "x");
    if (!rc && a->errors) rc = write_x(c, a->errors, s.se, in_set0 ? rows : 0, n, "standard errors of x");
    if (!rc && c->rank == 0)
        ulam_dist_fprint(stdout, &ask, &s, c, a->queries, lines, a->out, ulam_now() - cli_started, cli_verbosity);
    if (!rc && c->rank == 0 && s.r.cut)
        fprintf(stderr, "ulam: %s: warning: %lld walks were cut at --max-steps %lld: the estimates and their standard "
                        "errors leave out what those walks would have scored\n", a->path, (long long)s.r.cut,
                (long long)a->o.max_steps);
    if (!rc && c->rank == 0 && a->rel_err > 0) { /* "NOT met" printed (the report's count): exit 5 */
        int64_t met = 0, nq_met = ask.mode == ULAM_DIST_ADJOINT ? nq : 1;
        for (int64_t k = 0; s.ci && k < nq_met; k++) met += s.ci[k].met; /* forward: x_I's, judged after the walks */
        if (met < nq_met) rc = EXIT_TARGET;
    }
    if (!rc && a->mcsa && s.residual > a->tol) {
        if (c->rank == 0) fprintf(stderr, "ulam: %s: error: MCSA stopped at --max-iter %lld with residual %.3g above --tol %.3g\n",
                                  a->path, (long long)a->max_iter, s.residual, a->tol);
        rc = cli_exit_code(ULAM_ENOCONV);
    }
    free(s.x), free(s.se), free(s.tops), free(s.res), free(s.ci), free(s.ranks), free(idx), free(lines), free(q);
    return rc;
}

/* Check and run (see cli_solve_row.run). */
static int start_run(void *p, int argc, char **argv, int first)
{
    args *a = p;
    int rc = check(a, argc, argv, first);
    if (rc) return rc;
    ulam_comm c = {.rank = 0, .nranks = 1};
#ifdef ULAM_MPI
    cli_mpi_comm(&c);
#endif
    c.sets = (int)a->sets;
    return run(a, &c);
}

/* --partition selects this row whatever else is given. */
static const char *const claims[] = {"partition", NULL};

/* No --method value is this row's. */
static int serves(const char *method)
{
    (void)method;
    return 0;
}

const cli_solve_row cli_solve_partition_row = {"partition", longopts, claims, serves, sizeof(args), init, option, start_run};
