/* ulam solve SYSTEM.ulam --partition: the system's rows split across the ranks of mpirun, walks
 * that migrate (ulam_dist.h).  Alone (no mpirun, or a build without MPI) it is one rank. */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "ulam_dist.h"

static const char *const help =
    "usage: ulam solve (SYSTEM.ulam | M.mtx --rhs B.mtx) --partition (--index I | --queries FILE | --mode forward [--out X.mtx]\n"
    "                  | --method mcsa [--tol T] [--out X.mtx] | --source S [--top K] [--out X.mtx])\n"
    "                  [--walks N | --rel-err E] [--seed S] [--max-steps N] [--batch N] [--sets K]\n"
    "\n"
    "The prepared system's rows are split across the ranks of mpirun (balanced by entries; each rank\n"
    "reads only its rows' blocks of SYSTEM.ulam, prepared with --rhs, and --transpose for forward).\n"
    "A walk that steps onto another rank's row travels there; random numbers are keyed by (seed,\n"
    "walk, step), so 1, 2, 3 or 64 ranks print the same answer bit for bit.  Collision estimator,\n"
    "analog kernel (p_ij = |M_ij| / row sum, leaving with min(1, row sum)).  Answers carry their\n"
    "standard error; --index and --queries also a certified 95% interval when every row sum of |M| is\n"
    "at most 1 and power iteration certifies a Collatz-Wielandt vector below 1 (the walk's length\n"
    "tail, so a score's range after clipping; docs/distributed.md).\n"
    "  --bound         (--mode forward) a certified range of every x_i from x's residual (needs M in the\n"
    "                  part too); MCSA and --source always print theirs\n"
    "  --rhs B.mtx     M.mtx is a coordinate Matrix Market file read by byte ranges: each rank parses\n"
    "                  its share of the lines, and the entries travel to their rows' ranks (the same\n"
    "                  rows and answer as the prepared file; b is read whole by each rank)\n"
    "  --index I       x_I by adjoint walks from I (1-based)\n"
    "  --queries FILE  x_I of each line 'I' of FILE (docs/queries.md), all walking together, each on\n"
    "                  a seed of its own, printed: a line answers what --index I --seed SEED answers\n"
    "  --mode forward  every x_i by forward walks; --out writes x as a Matrix Market vector, --errors\n"
    "                  their standard errors (also with --source)\n"
    "  --method mcsa   every x_i by MCSA: Richardson steps (products with M across ranks) and forward\n"
    "                  walks' corrections (--walks each) to --tol (default 1e-8) of max|b|, --max-iter\n"
    "  --source S      x = (I - M)^-1 e_S: a push (products with M) to 1e-4, then forward walks; prints\n"
    "                  the --top K (default 10) components.  mcsa and --source need M' in the file\n"
    "  --walks N       histories (default 100000)       --seed S   the streams' key (default 1)\n"
    "  --rel-err E     (--index, --queries) stop a query at the first block of --batch walks whose\n"
    "                  interval's half-width is at most E |estimate|; --walks is then its most\n"
    "                  (default 2^30)\n"
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
    int walks_given, bound;
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
    case 'K': return cli_parse_int("solve", "--top", value, 1, 1000000, &a->top);
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
    if (!!a->forward + !!a->index + !!a->queries + a->mcsa + !!a->source != 1)
        return cli_usage_error("solve", "one of --index I, --queries FILE, --mode forward, --method mcsa and --source S "
                                        "with --partition");
    if ((a->out || a->errors) && (a->index || a->queries))
        return cli_usage_error("solve", "--out and --errors with --partition write a whole x");
    if (a->bound && (!a->forward || a->mcsa || a->sets > 1))
        return cli_usage_error("solve", "--bound with --mode forward in one set (MCSA and --source print theirs)");
    if (a->errors && a->mcsa) return cli_usage_error("solve", "--errors with --mode forward or --source");
    const cli_file outs[] = {{"--out", a->out}, {"--errors", a->errors}},
                   ins[] = {{"the system", a->path}, {"--queries", a->queries}, {"--rhs", a->rhs}};
    int rc = cli_check_outputs("solve", outs, 2, ins, 3);
    if (rc) return rc;
    if (a->rel_err > 0 && !a->index && !a->queries)
        return cli_usage_error("solve", "--rel-err with --partition and --index or --queries (forward mode, MCSA and "
                                        "--source give standard errors only)");
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

/* Each rank's rows and peak resident memory (KiB), in rank order, into v[0 .. 2 nranks) on every
 * rank; nonzero when the sum fails. */
static int per_rank(const ulam_comm *c, int64_t rows, int64_t *v)
{
    struct rusage u;
    memset(v, 0, (size_t)c->nranks * 2 * sizeof *v);
    v[c->rank] = rows;
    v[c->nranks + c->rank] = getrusage(RUSAGE_SELF, &u) ? -1 : (int64_t)u.ru_maxrss;
    return c->nranks > 1 && c->sum(c->ctx, v, 2 * c->nranks);
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

/* "x[i]  estimate +- stderr (95% CI lo .. hi)" without a newline (ci NULL: forward walks, whose
 * components have no certified range on a partition; the variance is certified finite, rho < 1). */
static void print_estimate(int64_t i, double est, double se, double rho, const ulam_dist_ci *ci)
{
    printf("x[%lld]%*s%.10g", (long long)i, cli_answer_pad(i, 16), "", est);
    if (ci && ci->lo == ci->hi && ci->lo == est) printf(" +- 0 (95%% CI %.10g .. %.10g: b is 0, x is exactly 0)", ci->lo, ci->hi);
    else if (!(rho < 1.0)) printf(" (no standard error: rho(M^) is not certified below 1)");
    else if (isnan(se) && ci && isfinite(ci->lo))
        printf(" (95%% CI %.*g .. %.*g; no walk reached it: the push's part alone)", cli_ci_digits(ci->lo, ci->hi), ci->lo,
               cli_ci_digits(ci->lo, ci->hi), ci->hi);
    else if (isnan(se)) printf(" (no walk reached it: the push's part alone)");
    else if (ci && isfinite(ci->lo))
        printf(" +- %.3g (95%% CI %.*g .. %.*g)", se, cli_ci_digits(ci->lo, ci->hi), ci->lo, cli_ci_digits(ci->lo, ci->hi),
               ci->hi);
    else if (ci) printf(" +- %.3g (standard error; no certified interval: a row of |M| sums above 1 or no length tail)", se);
    else printf(" +- %.3g (standard error; no certified interval for forward walks on a partition)", se);
}

/* One query's answer line (rank 0): x[I] estimate +- stderr and its seed. */
static void print_query(const cli_query *q, int64_t k, int64_t nq, const ulam_dist_result *r, uint64_t seed, double rho,
                        const ulam_dist_ci *ci)
{
    print_estimate(q->index + 1, r->estimate, r->std_error, rho, ci);
    uint64_t own = nq > 1 ? ulam_rng_substream(seed, ULAM_STREAM_QUERY, (uint64_t)k) : seed; /* docs/streams.md */
    if (ci->met) printf("  %lld walks,", (long long)r->walks);
    printf("  line %ld, seed %llu\n", q->line, (unsigned long long)own);
}

/* A component for the top-K table: its index and estimate, its standard error. */
typedef struct {
    int64_t i;
    double x, se, lo, hi;
} entry;

/* Larger estimate first, then the smaller index (NaN last). */
static int by_estimate(const void *a, const void *b)
{
    const entry *p = a, *q = b;
    if (p->x != q->x) return isnan(p->x) ? 1 : isnan(q->x) ? -1 : p->x < q->x ? 1 : -1;
    return (p->i > q->i) - (p->i < q->i);
}

/* Each rank's K largest components to rank 0, which prints the K largest of all with their
 * standard errors; 0 or an exit code. */
static int print_top(const ulam_comm *c, const double *x, const double *se, const double *lo, const double *hi, int64_t first,
                     int64_t rows, int64_t K, double rho)
{
    entry *e = malloc(((size_t)rows + 1) * sizeof *e);
    size_t *cnt = calloc((size_t)c->nranks * 2, sizeof *cnt);
    void *got = NULL;
    int bad = !e || !cnt;
    for (int64_t i = 0; !bad && i < rows; i++) e[i] = (entry){first + i, x[i], se[i], lo[i], hi[i]};
    if (!bad) qsort(e, (size_t)rows, sizeof *e, by_estimate);
    int64_t k = rows < K ? rows : K, all = k;
    if (!bad && c->nranks > 1) {
        cnt[0] = (size_t)k * sizeof *e;
        bad = c->exchange(c->ctx, e, cnt, &got, cnt + c->nranks);
        all = 0;
        for (int r = 0; !bad && r < c->nranks; r++) all += (int64_t)(cnt[c->nranks + r] / sizeof *e);
        if (!bad && c->rank == 0) qsort(got, (size_t)all, sizeof *e, by_estimate);
    }
    const entry *t = c->nranks > 1 ? got : e;
    for (int64_t j = 0; !bad && c->rank == 0 && j < all && j < K; j++) {
        ulam_dist_ci ci = {t[j].lo, t[j].hi, INFINITY, 0.0, 0};
        print_estimate(t[j].i + 1, t[j].x, t[j].se, rho, isfinite(ci.lo) ? &ci : NULL), printf("\n");
    }
    free(e), free(cnt), free(got);
    return bad ? cli_exit_code(ULAM_EIO) : 0;
}

/* Print the run's summary (rank 0; v: per_rank's figures). */
static void summary(const args *a, const ulam_dist_result *r, int nranks, int64_t n, double seconds, const int64_t *v,
                    double rho, const ulam_dist_ci *ci, int64_t nq)
{
    if (a->queries) {
        if (cli_verbosity >= 0) printf("queries         %s, each above (walks below: each query's)\n", a->queries);
    } else if (a->mcsa || a->source) { /* their answer is above */
    }
    else if (!a->forward) print_estimate(a->index, r->estimate, r->std_error, rho, ci), printf("\n");
    int64_t met = 0;
    for (int64_t k = 0; ci && k < nq; k++) met += ci[k].met;
    if (a->rel_err > 0 && met == nq)
        printf("rel-err         met (target %.3g)%s\n", a->rel_err, a->queries ? " by every query" : "");
    else if (a->rel_err > 0)
        printf("rel-err         NOT met (target %.3g) by %lld of %lld quer%s in --walks %lld%s\n", a->rel_err,
               (long long)(nq - met), (long long)nq, nq == 1 ? "y" : "ies", (long long)a->o.walks,
               ci && isfinite(ci[0].lo) ? "" : " (no certified interval: a row of |M| sums above 1, or no length tail)");
    else if (a->forward && !a->mcsa) printf("x               %lld components by forward walks%s%s\n", (long long)n, a->out ? ", written to " : "",
                a->out ? a->out : "");
    if (cli_verbosity < 0) return;
    printf("method          %s%s collision walks on %d rank%s, rows split by entries", a->mcsa ? "MCSA with " : a->source ? "push and " : "",
           a->forward || a->mcsa || a->source ? "forward" : "adjoint", nranks, nranks == 1 ? "" : "s");
    if (a->sets > 1) printf(" within each of %lld sets", (long long)a->sets);
    printf("\n");
    if (rho < 1.0) printf("variance        finite (rho(M^) <= %.6g, certified)\n", rho);
    else if (a->forward || a->mcsa || a->source) printf("variance        not certified finite (rho(M^) bound %.4g): no error bar can be trusted\n", rho);
    printf("walks           %lld (%lld steps; %lld cut at --max-steps)\n", (long long)r->walks, (long long)r->steps,
           (long long)r->cut);
    printf("migration       %.4g of steps crossed ranks, %.3g bytes a step, %lld rounds\n",
           r->steps ? (double)r->crossings / (double)r->steps : 0.0, r->steps ? (double)r->bytes / (double)r->steps : 0.0,
           (long long)r->rounds);
    printf("seconds         %.3g in all\n", seconds);
    if (cli_verbosity < 1) return;
    printf("ranks           rows");
    for (int k = 0; k < nranks; k++) printf(" %lld", (long long)v[k]);
    printf("; peak RSS MiB");
    for (int k = 0; k < nranks; k++) printf(" %.1f", (double)v[nranks + k] / 1024.0);
    printf("\n");
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

/* The certified range [lo, hi] of every x_i at this rank's rows (ulam_dist_bound; single source's
 * b is e_source) and its largest half-width *worst. */
static int bound(const ulam_part *p, const ulam_comm *c, int64_t source, const double *x, double **lo, double **hi,
                 double *worst, ulam_error *err)
{
    int64_t first, last;
    ulam_part_rows(p, &first, &last, NULL);
    size_t rows = (size_t)(last - first) + 1;
    double *e = source ? calloc(rows, sizeof *e) : NULL;
    *lo = malloc(rows * sizeof **lo), *hi = malloc(rows * sizeof **hi);
    if (e && source - 1 >= first && source - 1 < last) e[source - 1 - first] = 1.0;
    int status = !*lo || !*hi || (source && !e) ? ULAM_ENOMEM : ulam_dist_bound(p, c, e, x, 200, *lo, *hi, worst, err);
    if (status == ULAM_ENOMEM) err->status = status, snprintf(err->msg, sizeof err->msg, "memory for the bounds");
    free(e);
    return status;
}

/* Run the parsed command on this rank. */
static int run(const args *a, const ulam_comm *c)
{
    ulam_part *p = NULL;
    ulam_error err;
    int walks_forward = a->forward || a->mcsa || a->source; /* the walks run on M' */
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
    int64_t first, last, n = ulam_part_rows(p, &first, &last, NULL);
    int rc0;
    if (a->index > n || a->source > n) {
        ulam_part_free(p);
        return cli_usage_error("solve", "%s in 1 .. %lld, got %lld", a->index ? "--index" : "--source", (long long)n,
                               (long long)(a->index ? a->index : a->source));
    }
    cli_query *q = NULL;
    int64_t nq = 0;
    if (a->queries && (rc0 = load_queries(a->queries, n, &q, &nq))) {
        ulam_part_free(p);
        return rc0;
    }
    double rho = INFINITY; /* the variance guard: the interval is printed only when it is below 1 */
    status = ulam_dist_radius(p, c, walks_forward, 200, &rho, &err);
    ulam_dist_result r = {0};
    ulam_dist_mcsa_info mi = {0};
    ulam_dist_source_info si = {0};
    double *x = NULL, *se = NULL, *lo = NULL, *hi = NULL, worst = INFINITY;
    ulam_dist_result *many = NULL;
    ulam_dist_ci *ci = NULL, one = {NAN, NAN, INFINITY, INFINITY, 0};
    if (status) {
    } else if (q) {
        int64_t *idx = malloc((size_t)nq * sizeof *idx);
        many = malloc((size_t)nq * sizeof *many);
        ci = malloc((size_t)nq * sizeof *ci);
        for (int64_t k = 0; idx && many && k < nq; k++) idx[k] = q[k].index;
        status = idx && many && ci ? ulam_dist_adjoint_ci(p, c, idx, nq, &a->o, a->rel_err, many, ci, &err) : ULAM_ENOMEM;
        if (!status) r = many[0];
        free(idx);
    } else if (a->forward || a->mcsa || a->source) {
        x = malloc(((size_t)(last - first) + 1) * sizeof *x);
        se = malloc(((size_t)(last - first) + 1) * sizeof *se);
        if (!x || !se) status = ULAM_ENOMEM;
        else if (a->mcsa) status = ulam_dist_mcsa(p, c, &a->o, a->tol, (int)a->max_iter, x, &mi, &err);
        else if (a->source) status = ulam_dist_source(p, c, a->source - 1, &a->o, 1e-4, 1000, x, se, &si, &err);
        else status = ulam_dist_forward(p, c, &a->o, x, se, &r, &err);
        if (!status && a->mcsa) r.walks = mi.walks, r.steps = mi.steps, r.crossings = mi.crossings, r.cut = mi.cut;
        if (!status && a->source) r.walks = si.walks, r.steps = si.steps, r.crossings = si.crossings, r.cut = si.cut;
        if (!status && (a->mcsa || a->source || a->bound)) status = bound(p, c, a->source, x, &lo, &hi, &worst, &err);
    } else {
        int64_t i = a->index - 1;
        status = ulam_dist_adjoint_ci(p, c, &i, 1, &a->o, a->rel_err, &r, &one, &err);
    }
    ulam_part_free(p);
    int rc = status ? (cli_report(a->path, &err), cli_exit_code(status)) : 0;
    int in_set0 = c->sets <= 1 || c->rank < c->nranks / c->sets; /* set 0's ranks hold x */
    if (!rc && a->out) rc = write_x(c, a->out, x, in_set0 ? last - first : 0, n, "x");
    if (!rc && a->errors) rc = write_x(c, a->errors, se, in_set0 ? last - first : 0, n, "standard errors of x");
    int64_t *v = rc ? NULL : malloc((size_t)c->nranks * 2 * sizeof *v);
    if (!rc && (!v || per_rank(c, last - first, v))) rc = cli_exit_code(v ? ULAM_EIO : ULAM_ENOMEM);
    for (int64_t k = 0; !rc && c->rank == 0 && k < nq; k++) print_query(&q[k], k, nq, &many[k], a->o.seed, rho, &ci[k]);
    if (!rc && a->source) rc = print_top(c, x, se, lo, hi, first, in_set0 ? last - first : 0, a->top, rho); /* set 0's rows */
    if (!rc && c->rank == 0 && a->mcsa)
        printf("x               %lld components by MCSA%s%s\nmcsa            %d iterations, residual %.3g of max |b| "
               "(target %.3g)\n", (long long)n, a->out ? ", written to " : "", a->out ? a->out : "", mi.iterations,
               mi.residual, a->tol);
    if (!rc && c->rank == 0 && a->source && cli_verbosity >= 0)
        printf("push            %d products with M, max |r| %.3g left to the walks\n", si.rounds, si.residual);
    if (!rc && c->rank == 0 && (a->mcsa || a->bound)) {
        if (isfinite(worst)) printf("bound           every |x_i - x*_i| <= %.3g (certified from x's residual and rho(|M|) < 1)\n", worst);
        else printf("bound           none certified (power iteration did not certify rho(|M|) below 1)\n");
    }
    if (!rc && c->rank == 0 && r.cut)
        fprintf(stderr, "ulam: %s: warning: %lld walks were cut at --max-steps %lld: the estimates and their standard "
                        "errors leave out what those walks would have scored\n", a->path, (long long)r.cut,
                (long long)a->o.max_steps);
    if (!rc && c->rank == 0) summary(a, &r, c->nranks, n, ulam_now() - cli_started, v, rho, q ? ci : a->index ? &one : NULL, q ? nq : 1);
    if (!rc && a->mcsa && mi.residual > a->tol) {
        if (c->rank == 0) fprintf(stderr, "ulam: %s: error: MCSA stopped at --max-iter %lld with residual %.3g above --tol %.3g\n",
                                  a->path, (long long)a->max_iter, mi.residual, a->tol);
        rc = cli_exit_code(ULAM_ENOCONV);
    }
    free(x), free(se), free(lo), free(hi), free(v), free(q), free(many), free(ci);
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
