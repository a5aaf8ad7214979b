/* ulam study: every method at every budget, R repeats each, against the exact value; runs.csv
 * rewritten whole (temporary file, then rename) after each cell and on Ctrl-C, so a rerun
 * resumes; then summary.csv and charts.  No output file is ever seen half written, and no
 * non-finite number is written: an undefined statistic is an empty field. */
#include "cli.h"
#include "ulam_study.h"
#include "gnuplot.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *const usage =
    "usage: ulam study M.mtx --rhs b.mtx --index I [--methods LIST] [--budgets LIST |\n"
    "                  --time-budgets LIST] [--repeats R] [--out DIR] [--seed S] [--threads T]\n"
    "                  [--jacobi [--omega W]] [--cache] [--force] [--reference-time S]\n"
    "                  [--format png|svg|pdf]\n"
    "\n"
    "Run every method (mode-estimator-window: adjoint|forward, collision|absorption|expected,\n"
    "plain|roulette|split) at every budget R times with distinct seeds, and compare each run\n"
    "with the exact x_I (LAPACK when n <= 8000, else Gauss-Seidel run to convergence).\n"
    "\n"
    "  --methods LIST       comma-separated method names (default: all 18), e.g.\n"
    "                       adjoint-collision-plain,forward-expected-split\n"
    "  --budgets LIST       walks per run (default 100,1000,10000,100000,1000000)\n"
    "  --time-budgets LIST  seconds per run instead of walk counts\n"
    "  --repeats R          runs per method and budget (default 30)\n"
    "  --out DIR            output directory (default study): runs.csv (a row per run, saved\n"
    "                       after each method and budget; rerunning resumes), summary.csv,\n"
    "                       reference.csv, rmse-*.png, work.png, coverage.png\n"
    "  --cache              binary copies of the inputs beside them, as in 'ulam solve'\n"
    "  --seed S             base seed (default 1); run r of method m at budget k has its own\n"
    "  --force              start afresh when --out holds runs of a different question\n"
    "  --threads T          threads per run (default: all cores)\n"
    "  --jacobi             the file holds A of A x = b: walk on M = I - w D^-1 A, b' = w D^-1 b\n"
    "  --omega W            the damping w of --jacobi, in (0, 2] (default 1)\n"
    "  --reference-time S   seconds for each reference line of the methods that solve for every\n"
    "                       unknown (sequential MC, MCSA; default 10); 0 leaves them out\n"
    "  --format F           png (default), svg or pdf charts; each chart's gnuplot script is kept\n"
    "                       beside it (NAME.gp: 'cd DIR && gnuplot NAME.gp' redraws it from the CSVs)\n"
    "\n"
    "On stdout: the winner at each budget (least RMSE^2 x seconds) with its coverage and the\n"
    "coverage's 95% binomial (Wilson) interval, and the refused methods.  The RMSE charts are\n"
    "one per estimator (rmse-collision, rmse-absorption, rmse-expected: at most 6 lines each).\n"
    "\n"
    "A rerun resumes only the same question: DIR/question.txt records a fingerprint of it (the\n"
    "contents of M and b, n, --index, --jacobi and --omega, --seed, the methods, walk or time\n"
    "budgets); a rerun that differs in any of them is refused, naming the field (exit 2),\n"
    "unless --force discards the old runs.\n"
    "\n"
    "Windows: roulette W = 0.5 w0, split W = 2 w0 (w0 the starting weight).  Ctrl-C keeps\n"
    "every finished row and writes the summary (exit 130); a second Ctrl-C exits at once.\n";

enum { NMETHOD = ULAM_STUDY_METHODS, MAXBUDGET = 16, MAXREPEAT = 4096 };

typedef struct {
    const char *name; /* the library's method grid: ulam_study_method_get */
    int mode, on;
    char why[320]; /* non-empty: refused */
    int infinite;  /* rho(M^) not certified below 1: runs, flagged */
} method;

typedef struct {
    cli_system s;
    method m[NMETHOD];
    double budget[MAXBUDGET];
    int nbudget, time_budgets, repeats, threads, force;
    double reference_time; /* seconds for each of sequential MC's and MCSA's reference lines (0: none) */
    const char *format;    /* png, svg or pdf */
    int partial;           /* interrupted: charts and summary say so */
    uint64_t seed;
    const char *out;
    ulam_study *lib; /* the engine: the guards' verdicts, the exact value and every run (src/study.c) */
    double exact;
    int direct; double direct_seconds, direct_error; /* LAPACK's point on the chart (n <= 8000) */
    int forward_walks; /* rho(|M|) < 1 and the forward rho(M^) < 1: the outer iterations can walk */
    char **row; /* [m][b][r]: the runs.csv line of a finished run */
} study;

static const char runs_header[] = "method,budget,repeat,seed,estimate,stderr,abs_error,walks,steps,seconds,covered\n";

/* The 18 methods, all on. */
static void methods_init(method *m)
{
    for (int k = 0; k < NMETHOD; k++) {
        const ulam_study_method *g = ulam_study_method_get(k);
        m[k] = (method){.name = g->name, .mode = g->mode, .on = 1};
    }
}

/* Keep only the listed methods; 0 or a usage error. */
static int methods_select(method *m, const char *list)
{
    for (int k = 0; k < NMETHOD; k++) m[k].on = 0;
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *save, *w = strtok_r(buf, ",", &save); w; w = strtok_r(NULL, ",", &save)) {
        int k = ulam_study_method_find(w);
        if (k < 0)
            return cli_usage_error("study", "--methods: unknown method '%s' (names like adjoint-collision-plain)", w);
        m[k].on = 1;
    }
    return 0;
}

/* Parse a comma-separated list of positive numbers; 0 or a usage error. */
static int parse_budgets(study *st, const char *opt, const char *list, int integer)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", list);
    st->nbudget = 0;
    for (char *save, *w = strtok_r(buf, ",", &save); w; w = strtok_r(NULL, ",", &save)) {
        if (st->nbudget == MAXBUDGET) return cli_usage_error("study", "%s: at most %d budgets", opt, MAXBUDGET);
        double v;
        int64_t iv;
        int rc = integer ? cli_parse_int("study", opt, w, 1, INT64_MAX / 2, &iv)
                         : cli_parse_real("study", opt, w, 1e-6, 1e6, &v);
        if (rc) return rc;
        st->budget[st->nbudget++] = integer ? (double)iv : v;
    }
    return st->nbudget ? 0 : cli_usage_error("study", "%s expects a list of numbers", opt);
}

/* The runs.csv line of run (m, b, r) (NULL: none yet). */
static char **row_at(const study *st, int m, int b, int r)
{
    return &st->row[((size_t)m * MAXBUDGET + (size_t)b) * (size_t)st->repeats + (size_t)r];
}

/* The library's study of the chosen methods (ulam_study_alloc: the guards, each method screened,
 * the exact value); each refused or flagged method said on stderr.  0 or an exit code. */
static int screen_methods(study *st)
{
    int chosen[NMETHOD], n = 0;
    for (int k = 0; k < NMETHOD; k++)
        if (st->m[k].on) chosen[n++] = k;
    if (!n) {
        fprintf(stderr, "ulam: study: every selected method is refused\n");
        return EXIT_DIVERGE;
    }
    ulam_study_params p = ulam_study_defaults();
    p.methods = chosen, p.nmethods = n, p.budgets = st->budget, p.nbudgets = st->nbudget;
    p.time_budgets = st->time_budgets, p.repeats = st->repeats, p.seed = st->seed, p.threads = st->threads;
    p.interrupt = &cli_interrupted, p.share = cli_share;
    ulam_error err;
    if (ulam_study_alloc(st->s.M, st->s.b, st->s.index - 1, &p, &st->lib, &err))
        return cli_report(st->s.matrix_path, &err);
    const ulam_guard *g = ulam_study_guard(st->lib);
    st->forward_walks = ulam_study_forward_walks(st->lib);
    int left = 0;
    for (int k = 0; k < NMETHOD; k++) {
        method *m = &st->m[k];
        if (!m->on) continue;
        ulam_study_screen sc;
        ulam_study_screen_get(st->lib, k, &sc);
        snprintf(m->why, sizeof m->why, "%s", sc.why), m->infinite = sc.infinite;
        if (m->why[0]) fprintf(stderr, "ulam: study: %s refused: %s\n", m->name, m->why);
        else if (m->infinite)
            fprintf(stderr, "ulam: study: %s runs with a variance not certified finite (rho(M^) in [%.4g, %.4g]): its "
                    "error bars mean nothing\n", m->name, g->hat[m->mode].lower, g->hat[m->mode].upper);
        left += !m->why[0];
    }
    if (!left) fprintf(stderr, "ulam: study: every selected method is refused\n");
    return left ? 0 : EXIT_DIVERGE;
}

/* v as %.6g in buf, or an empty field when it is not finite (an undefined statistic). */
static const char *num(char buf[32], double v)
{
    if (isfinite(v)) snprintf(buf, 32, "%.6g", v);
    else buf[0] = '\0';
    return buf;
}

/* The fields of a runs.csv line: name, budget, repeat, estimate, stderr and seconds; a run with
 * no estimate (both fields empty) gives NaN for them.  1 when the line is whole. */
static int run_fields(const char *line, char name[64], double *budget, int *r, double *e, double *se, double *sec)
{
    char est[64], err[64];
    if (sscanf(line, "%63[^,],%lf,%d,%*u,%63[^,],%63[^,],%*[^,],%*d,%*d,%lf", name, budget, r, est, err, sec) == 6) {
        char *end1, *end2;
        *e = strtod(est, &end1), *se = strtod(err, &end2);
        return *end1 == '\0' && *end2 == '\0' && isfinite(*e) && isfinite(*se) && isfinite(*sec);
    }
    /* a failed run: ",," where the estimate and stderr (and the error) would be */
    if (sscanf(line, "%63[^,],%lf,%d,%*u,,,,%*d,%*d,%lf", name, budget, r, sec) == 4 && isfinite(*sec)) {
        *e = *se = NAN;
        return 1;
    }
    return 0;
}

/* Keep the finished rows of an earlier run of this study (a torn line, left by an older
 * version that appended, is dropped). */
static void resume(study *st, const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) return;
    char line[1024], name[64];
    int rows = 0;
    while (fgets(line, sizeof line, f)) {
        size_t len = strlen(line);
        if (len == 0 || line[len - 1] != '\n') break;
        double budget, e, se, sec;
        int r;
        if (run_fields(line, name, &budget, &r, &e, &se, &sec))
            for (int m = 0; m < NMETHOD; m++)
                for (int b = 0; b < st->nbudget; b++)
                    if (!strcmp(st->m[m].name, name) && st->budget[b] == budget && r >= 0 && r < st->repeats) {
                        ulam_study_run u = {.method = m, .budget = b, .repeat = r, .has_estimate = !isnan(e),
                                            .estimate = e, .std_error = se, .seconds = sec};
                        if (*row_at(st, m, b, r) || ulam_study_restore(st->lib, &u)) continue;
                        if (!(*row_at(st, m, b, r) = strdup(line))) continue;
                        rows++;
                    }
    }
    fclose(f);
    if (rows) fprintf(stderr, "ulam: study: resuming: %d runs already in %s\n", rows, path);
}

/* Write every finished row to runs.csv (temporary file, then rename); 0 or an exit code. */
static int save_runs(const study *st)
{
    if (cli_rank) return 0; /* under MPI, rank 0 writes */
    char path[4096];
    snprintf(path, sizeof path, "%s/runs.csv", st->out);
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status) {
        fputs(runs_header, o.f);
        for (size_t i = 0, n = (size_t)NMETHOD * MAXBUDGET * (size_t)st->repeats; i < n; i++)
            if (st->row[i]) fputs(st->row[i], o.f);
        status = cli_outfile_commit(&o);
    }
    ulam_error e = {.status = status, .msg = "a writable output directory"};
    return status ? cli_report(path, &e) : 0;
}

/* FNV-1a 64 of n bytes, continuing from h. */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t k = 0; k < n; k++) h = (h ^ c[k]) * 0x100000001b3ULL;
    return h;
}

/* The question a study answers, one "field value" line each, into buf. */
static void fingerprint(const study *st, char *buf, size_t len)
{
    const ulam_csr *M = st->s.M;
    int64_t n = M->nrows, nz = ulam_csr_nnz(M);
    uint64_t hm = fnv(0xcbf29ce484222325ULL, M->rowptr, (size_t)(n + 1) * sizeof *M->rowptr);
    hm = fnv(fnv(hm, M->colidx, (size_t)nz * sizeof *M->colidx), M->val, (size_t)nz * sizeof *M->val);
    uint64_t hb = fnv(0xcbf29ce484222325ULL, st->s.b, (size_t)n * sizeof *st->s.b);
    char methods[NMETHOD * 40] = "";
    for (int m = 0; m < NMETHOD; m++)
        if (st->m[m].on) strcat(strcat(methods, methods[0] ? "," : ""), st->m[m].name);
    snprintf(buf, len,
             "n %lld\nmatrix %016llx\nrhs %016llx\nindex %lld\njacobi %d\nomega %.17g\nseed %llu\nmethods %s\n"
             "budgets %s\n",
             (long long)n, (unsigned long long)hm, (unsigned long long)hb, (long long)st->s.index, st->s.jacobi,
             st->s.jacobi ? st->s.omega : 1.0, (unsigned long long)st->seed, methods,
             st->time_budgets ? "seconds" : "walks");
}

/* The first line of a and b (fingerprints) that differs, its field name in field[]; 0 if none. */
static int differs(const char *a, const char *b, char field[32], char was[256], char now[256])
{
    while (*a || *b) {
        size_t la = strcspn(a, "\n"), lb = strcspn(b, "\n");
        if (la != lb || strncmp(a, b, la)) {
            size_t f = strcspn(b, " \n");
            snprintf(field, 32, "%.*s", (int)(f < 31 ? f : 31), b);
            const char *va = memchr(a, ' ', la), *vb = memchr(b, ' ', lb);
            snprintf(was, 256, "%.*s", va ? (int)(la - (size_t)(va + 1 - a)) : 0, va ? va + 1 : "");
            snprintf(now, 256, "%.*s", vb ? (int)(lb - (size_t)(vb + 1 - b)) : 0, vb ? vb + 1 : "");
            return 1;
        }
        a += la + (a[la] == '\n'), b += lb + (b[lb] == '\n');
    }
    return 0;
}

/* Resume only the same question: compare DIR/question.txt with this study's fingerprint (an
 * old runs.csv without one is a different question); a mismatch is an error naming the field,
 * or with --force the old runs are discarded.  Then write the fingerprint.  0 or an exit code. */
static int check_question(study *st)
{
    char path[4096], runs[4096], mine[2048], theirs[2048] = "", field[32], was[256], now[256];
    snprintf(path, sizeof path, "%s/question.txt", st->out);
    snprintf(runs, sizeof runs, "%s/runs.csv", st->out);
    fingerprint(st, mine, sizeof mine);
    FILE *f = fopen(path, "r");
    if (f) {
        size_t k = fread(theirs, 1, sizeof theirs - 1, f);
        theirs[k] = '\0';
        fclose(f);
    }
    int old_runs = access(runs, F_OK) == 0;
    int mismatch = f ? differs(theirs, mine, field, was, now) : old_runs;
    if (mismatch && !st->force) {
        if (f)
            fprintf(stderr, "ulam: study: %s holds the runs of a different question: %s is %s there, %s here; "
                            "--force starts afresh (discarding them), or choose another --out\n",
                    st->out, field, was, now);
        else
            fprintf(stderr, "ulam: study: %s holds runs.csv but no question.txt saying what question it answers; "
                            "--force starts afresh (discarding it), or choose another --out\n", st->out);
        return EXIT_USAGE;
    }
    if (mismatch && cli_rank == 0 && remove(runs) && errno != ENOENT) {
        ulam_error e = {.status = ULAM_EIO, .msg = "a runs.csv that can be removed (--force)"};
        return cli_report(runs, &e);
    }
    if (mismatch) fprintf(stderr, "ulam: study: --force: the old runs in %s are discarded\n", st->out);
    if (cli_rank) return 0;
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status) fputs(mine, o.f), status = cli_outfile_commit(&o);
    ulam_error e = {.status = status, .msg = "a writable output directory"};
    return status ? cli_report(path, &e) : 0;
}

/* Keep run u's runs.csv line (a run with no estimate: its fields empty); 0 or an exit code. */
static int keep_row(study *st, const ulam_study_run *u)
{
    char line[512];
    const char *name = st->m[u->method].name;
    if (!u->has_estimate)
        snprintf(line, sizeof line, "%s,%.17g,%d,%llu,,,,%lld,%lld,%.6g,0\n", name, u->budget_value, u->repeat,
                 (unsigned long long)u->seed, (long long)u->walks, (long long)u->steps, u->seconds);
    else
        snprintf(line, sizeof line, "%s,%.17g,%d,%llu,%.17g,%.17g,%.17g,%lld,%lld,%.6g,%d\n", name, u->budget_value,
                 u->repeat, (unsigned long long)u->seed, u->estimate, u->std_error, u->abs_error, (long long)u->walks,
                 (long long)u->steps, u->seconds, u->covered);
    char **row = row_at(st, u->method, u->budget, u->repeat);
    free(*row);
    return (*row = strdup(line)) ? 0 : cli_exit_code(ULAM_ENOMEM);
}

/* The cells whose every run is done. */
static int cells_done(const study *st)
{
    int cells = 0;
    ulam_study_cell c;
    for (int m = 0; m < NMETHOD; m++)
        for (int b = 0; st->m[m].on && !st->m[m].why[0] && b < st->nbudget; b++)
            cells += ulam_study_cell_get(st->lib, m, b, &c) == st->repeats;
    return cells;
}

/* Run every missing run (ulam_study_iterate), saving runs.csv after each cell (and every 10 s
 * within one) and on Ctrl-C; 0, EXIT_INTERRUPTED, or an exit code when runs.csv cannot be written. */
static int run_all(study *st)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/runs.csv", st->out);
    resume(st, path);
    int rc = save_runs(st), total = 0, tty = isatty(2);
    if (rc) return rc;
    for (int m = 0; m < NMETHOD; m++) total += st->m[m].on && !st->m[m].why[0];
    total *= st->nbudget;
    double t0 = ulam_now(), saved = t0;
    cli_catch_sigint();
    while (!rc && !cli_interrupted && !ulam_study_done(st->lib)) {
        ulam_study_run u;
        ulam_error err;
        if (ulam_study_iterate(st->lib, &u, &err)) rc = cli_report(st->s.matrix_path, &err);
        if (rc || u.interrupted) break;
        if ((rc = keep_row(st, &u))) break;
        if (u.last_in_cell || ulam_now() - saved > 10.0) rc = save_runs(st), saved = ulam_now();
        if (u.last_in_cell && tty)
            fprintf(stderr, "\rulam: study: cells %d/%d, %.1f s elapsed, about %.0f s left   ", cells_done(st), total,
                    ulam_now() - t0, ulam_study_seconds_left(st->lib));
    }
    if (!rc) rc = save_runs(st); /* the rows finished before Ctrl-C */
    cli_release_sigint();
    if (tty) fputc('\n', stderr);
    return rc ? rc : cli_interrupted ? EXIT_INTERRUPTED : 0;
}

/* One point of a reference line as a reference.csv row (the error nudged off 0 for the log axis). */
static void line_point(const char *kind, double seconds, double error, void *f)
{
    char v[2][32];
    fprintf(f, "%s,%s,%s\n", kind, num(v[0], seconds), num(v[1], error + 1e-300));
}

/* The exact x_I (the study's) and the reference lines (ulam_study_reference_lines: LAPACK's
 * point, Gauss-Seidel, sequential MC and MCSA, the Krylov peer), into reference.csv.  0 or an
 * exit code. */
static int references(study *st)
{
    const ulam_study_ref *ref = ulam_study_exact(st->lib);
    st->exact = ref->exact;
    st->direct = ref->direct, st->direct_seconds = ref->direct_seconds;
    st->direct_error = fabs(ref->exact - ref->settled) + 1e-300;
    char path[4096];
    snprintf(path, sizeof path, "%s/reference.csv", st->out);
    ulam_outfile o = {0};
    int status = cli_rank ? ULAM_OK : cli_outfile_open(&o, path); /* under MPI, rank 0 writes */
    if (status) {
        ulam_error e = {.status = status, .msg = "a writable output directory"};
        return cli_report(path, &e);
    }
    FILE *f = o.f ? o.f : fopen("/dev/null", "w");
    if (!f) return cli_exit_code(ULAM_EIO);
    fprintf(f, "kind,seconds,error\n");
    ulam_error err;
    if ((status = ulam_study_reference_lines(st->lib, st->reference_time, line_point, f, &err))) {
        if (o.f) cli_outfile_abort(&o);
        else fclose(f);
        return cli_report(st->s.matrix_path, &err);
    }
    if (!o.f) return fclose(f), 0;
    ulam_error e = {.status = cli_outfile_commit(&o), .msg = "a writable output directory"};
    return e.status ? cli_report(path, &e) : 0;
}

/* What R runs of one method at one budget say, against the exact value (src/study.c). */
typedef ulam_study_cell cell;

/* The summary c of method m's finished runs at budget b; the number of runs it summarises (0:
 * none). */
static int method_cell(const study *st, int m, int b, cell *c)
{
    return ulam_study_cell_get(st->lib, m, b, c);
}

/* summary.csv (a row per cell) and bars.csv (per method, at the largest budget). */
static int summarise(study *st)
{
    char path[2][4096], v[6][32];
    snprintf(path[0], sizeof path[0], "%s/summary.csv", st->out);
    snprintf(path[1], sizeof path[1], "%s/bars.csv", st->out);
    ulam_outfile o[2] = {{0}};
    int k = 0, status = ULAM_OK;
    for (; k < 2 && !status; k++) status = cli_outfile_open(&o[k], path[k]);
    if (status) {
        cli_outfile_abort(&o[0]);
        ulam_error err = {.status = status, .msg = "a writable output directory"};
        return cli_report(path[k - 1], &err);
    }
    FILE *f = o[0].f, *g = o[1].f;
    fprintf(f, "method,budget,runs,rmse,mean_stderr,honesty,coverage,seconds,work,variance_finite,failed\n");
    fprintf(g, "method,work,coverage,honesty,coverage_lo,coverage_hi,covered,runs\n");
    for (int m = 0; m < NMETHOD; m++) {
        if (!st->m[m].on || st->m[m].why[0]) continue;
        cell last = {0};
        for (int b = 0; b < st->nbudget; b++) {
            cell c;
            if (!method_cell(st, m, b, &c)) continue;
            fprintf(f, "%s,%.17g,%d,%s,%s,%s,%s,%s,%s,%s,%d\n", st->m[m].name, st->budget[b], c.runs,
                    num(v[0], c.rmse), num(v[1], c.mean_stderr), num(v[2], c.honesty), num(v[3], c.coverage),
                    num(v[4], c.seconds), num(v[5], c.work), st->m[m].infinite ? "false" : "true", c.failed);
            last = c;
        }
        if (last.runs) {
            double lo, hi;
            int covered = (int)lround(last.coverage * last.runs);
            ulam_study_coverage_interval(covered, last.runs, &lo, &hi);
            fprintf(g, "%s,%s,%s,%s,%s,%s,%d,%d\n", st->m[m].name, num(v[0], last.work), num(v[1], last.coverage),
                    num(v[2], last.honesty), num(v[3], lo), num(v[4], hi), covered, last.runs);
        }
    }
    for (k = 0; k < 2 && !status; k++) status = cli_outfile_commit(&o[k]);
    cli_outfile_abort(&o[0]), cli_outfile_abort(&o[1]); /* whatever was not committed */
    ulam_error err = {.status = status, .msg = "a writable output directory"};
    return status ? cli_report(path[k ? k - 1 : 0], &err) : 0;
}

/* LAPACK's point on the RMSE chart, kept inside the axes the other lines set: marked at the edge
 * it would stretch past, with its values and an arrow toward them (gnuplot, after X0, X1, Y0). */
static void lapack_mark(const study *st, char *buf, size_t len)
{
    if (!st->direct) {
        snprintf(buf, len, "lx = 1/0\nly = 1/0\n");
        return;
    }
    char err[32]; /* the error as a label: 0 when LAPACK and Gauss-Seidel agree to the last bit */
    if (st->direct_error > 1e-299) snprintf(err, sizeof err, "%.2g", st->direct_error);
    else snprintf(err, sizeof err, "0");
    snprintf(buf, len,
             "LX = %.17g\nLY = %.17g\n"
             "lx = LX < X0 ? X0 : LX > X1 ? X1 : LX\nly = LY < Y0 ? 2 * Y0 : LY\n"
             "lt = 'LAPACK: error %s in %.3g s '.(LY < Y0 ? '\342\206\223' : '').(LX > X1 ? '\342\206\222' : "
             "LX < X0 ? '\342\206\220' : '')\n"
             "if (lx != LX || ly != LY) {\n"
             "  if (lx > sqrt(X0 * X1)) {\n"
             "    set label 1 lt at lx, ly right offset character -1.5, 0 font ',9'\n"
             "  } else {\n"
             "    set label 1 lt at lx, ly left offset character 1.5, 0 font ',9'\n"
             "  }\n"
             "}\n",
             st->direct_seconds, st->direct_error, err, st->direct_seconds);
}

/* Draw DIR/NAME.FORMAT from script, and keep the script beside it as DIR/NAME.gp ('cd DIR &&
 * gnuplot NAME.gp' redraws it from the CSVs there); the chart is drawn into a temporary file that
 * ulam made (mkstemp: O_EXCL, a fresh name, never a planted symlink), which gnuplot writes through
 * the descriptor it inherits (/dev/fd/N: no name to follow), then renamed into place.  ULAM_OK or
 * ULAM_EIO (gnuplot missing or failed). */
static int draw(const study *st, const char *name, int width, int height, const char *script)
{
    char term[128], gp[4200], out[4200], cmd[4200];
    const char *fmt = st->format;
    if (!strcmp(fmt, "pdf")) snprintf(term, sizeof term, "pdfcairo size %gin,%gin font 'sans,9'", width / 100.0, height / 100.0);
    else if (!strcmp(fmt, "svg")) snprintf(term, sizeof term, "svg size %d,%d font 'sans,10' background 'white'", width, height);
    else snprintf(term, sizeof term, "pngcairo size %d,%d font 'sans,10'", width, height);
    snprintf(gp, sizeof gp, "%s/%s.gp", st->out, name);
    snprintf(out, sizeof out, "%s/%s.%s", st->out, name, fmt);
    const char *head = "set datafile separator ','\nset grid\n";
    ulam_outfile o;
    if (!ulam_outfile_open(&o, gp)) {
        fprintf(o.f, "# ulam study: %s; redraw with: cd %s && gnuplot %s.gp\nset terminal %s\nset output '%s.%s'\n%s%s\n"
                     "set output\n", name, st->out, name, term, name, fmt, head, script);
        if (ulam_outfile_commit(&o)) return ULAM_EIO;
    }
    if (strchr(st->out, '\'')) return ULAM_EINVAL;
    ulam_outfile chart;
    if (cli_outfile_open(&chart, out)) return ULAM_EIO;
    fflush(chart.f);
    snprintf(cmd, sizeof cmd, "cd '%s' && gnuplot 2>/dev/null", st->out);
    FILE *g = popen(cmd, "w");
    if (!g) {
        cli_outfile_abort(&chart);
        return ULAM_EIO;
    }
    fprintf(g, "set terminal %s\nset output '/dev/fd/%d'\n%s%s\nset output\n", term, fileno(chart.f), head, script);
    if (pclose(g) != 0) {
        cli_outfile_abort(&chart);
        return ULAM_EIO;
    }
    return cli_outfile_commit(&chart) ? ULAM_EIO : ULAM_OK;
}

/* The RMSE chart of the methods in names (one estimator's: at most 6, each its own colour and dash)
 * as NAME; nonzero when gnuplot failed. */
static int rmse_chart(const study *st, const char *name, const char *names, const char *what)
{
    char budgets[MAXBUDGET * 32] = "", lapack[1024], script[12288];
    for (int b = 0; b < st->nbudget; b++)
        snprintf(budgets + strlen(budgets), sizeof budgets - strlen(budgets), "%.17g ", st->budget[b]);
    double y0 = st->exact != 0 ? 1e-9 * fabs(st->exact) : 1e-12;
    lapack_mark(st, lapack, sizeof lapack);
    snprintf(script, sizeof script,
             "set title 'ulam study: RMSE of x_{%lld} against seconds per run, %s estimator%s'\n"
             "set logscale xy\nset format x '10^{%%L}'\nset format y '10^{%%L}'\nset xlabel 'seconds per run'\n"
             "set ylabel 'RMSE (reference lines: the error of one run)'\nset key outside bottom center horizontal "
             "maxrows 4 font ',8'\n"
             "Y0 = %g\nset yrange [Y0:*]\n"
             "set fit quiet\nset fit logfile '/dev/null'\nf(x) = a / sqrt(x)\na = 0\nfit f(x) 'summary.csv' u 8:4 via a\n"
             "M = \"%s\"\n" /* at most 6 methods: 6 colours, 6 dashes */
             "C = \"#1b9e77 #d95f02 #7570b3 #e7298a #66a61e #a6761d\"\n"
             "B = \"%s\"\n" /* one point shape per budget, in the method's colour */
             "P = \"7 5 9 11 13 6 4 8 10 12 1 2 3 14 15 16\"\n"
             "stats 'summary.csv' u ($8 > 0 ? $8 : 1/0) nooutput\nX0 = STATS_min\nX1 = STATS_max\n"
             "stats 'reference.csv' u (strcol(1) ne 'lapack' && $2 > 0 ? $2 : 1/0) nooutput\n"
             "X0 = 10**floor(log10(STATS_min < X0 ? STATS_min : X0))\nX1 = 10**ceil(log10(STATS_max > X1 ? STATS_max : X1))\n"
             "set xrange [X0:X1]\n"
             "%s"
             "plot for [i=1:words(M)] 'summary.csv' u (strcol(1) eq word(M, i) && $11 == 0 ? $8 : 1/0):4 w l lw 2 "
             "linecolor rgb word(C, i) dashtype i title word(M, i), "
             "for [i=1:words(M)] for [j=1:words(B)] 'summary.csv' u (strcol(1) eq word(M, i) && $2 == word(B, j) + 0 && $11 == 0 ? "
             "$8 : 1/0):4 w p linecolor rgb word(C, i) pointtype (word(P, j) + 0) notitle, "
             "for [j=1:words(B)] NaN w p lc 'black' pointtype (word(P, j) + 0) title sprintf('%s', word(B, j) + 0), "
             "'reference.csv' u (strcol(1) eq 'gs' ? $2 : 1/0):3 w l lw 3 lc 'gray50' t 'Gauss-Seidel, whole vector', "
             "'' u (strcol(1) eq 'lapack' ? lx : 1/0):(ly) w p pt 9 ps 2 lc 'web-green' t 'LAPACK dgesv', "
             "%s"
             "'' u (strcol(1) eq 'cg' || strcol(1) eq 'gmres' ? $2 : 1/0):3 w lp lw 1 pt 3 lc 'dark-cyan' t 'Krylov', "
             "f(x) dt 4 lc 'gray30' t '1/sqrt(t)'\n",
             (long long)st->s.index, what, st->partial ? " (PARTIAL: interrupted)" : "", y0, names, budgets, lapack,
             st->time_budgets ? "%g s a run" : "%.0f walks",
             st->forward_walks && st->reference_time > 0 /* the one-run lines exist (reference()): else no legend */
                 ? "'' u (strcol(1) eq 'sequential' ? $2 : 1/0):3 w lp lw 1 pt 5 lc 'brown' t 'sequential MC (one run)', "
                   "'' u (strcol(1) eq 'mcsa' ? $2 : 1/0):3 w lp lw 1 pt 7 lc 'dark-magenta' t 'MCSA (one run)', "
                 : "");
    return draw(st, name, 1100, 750, script);
}

/* The charts (an RMSE chart per estimator, work, coverage with its binomial interval); the names of
 * those drawn into drawn[]; nonzero when gnuplot failed. */
static int charts(const study *st, char *drawn, size_t len)
{
    static const char *const est[3] = {"collision", "absorption", "expected"};
    char script[2048], key[32], chart[64];
    drawn[0] = '\0';
    for (int e = 0; e < 3; e++) {
        char names[NMETHOD * 40] = "";
        snprintf(key, sizeof key, "-%s-", est[e]);
        for (int m = 0; m < NMETHOD; m++)
            if (st->m[m].on && !st->m[m].why[0] && strstr(st->m[m].name, key)) strcat(strcat(names, st->m[m].name), " ");
        if (!names[0]) continue;
        snprintf(chart, sizeof chart, "rmse-%s", est[e]);
        if (rmse_chart(st, chart, names, est[e])) {
            fprintf(stderr, "ulam: study: gnuplot failed (install gnuplot-nox): charts not drawn, CSVs written\n");
            return 1;
        }
        snprintf(drawn + strlen(drawn), len - strlen(drawn), ", %s.%s", chart, st->format);
    }
    const char *partial = st->partial ? " (PARTIAL: interrupted)" : "";
    snprintf(script, sizeof script,
             "set title 'work-normalised variance RMSE^2 x seconds at the largest budget (lower wins)%s'\n"
             "set style data histograms\nset style fill solid 0.6\nset logscale y\nset format y '10^{%%L}'\n"
             "set ylabel 'RMSE^2 x seconds per run'\nset xtics rotate by 35 right font ',8'\nset bmargin 10\n"
             "set key off\nplot 'bars.csv' skip 1 u 2:xtic(1)\n", partial);
    draw(st, "work", 1000, 500, script);
    snprintf(script, sizeof script,
             "set title 'coverage of the 95%% interval at the largest budget, with its 95%% binomial interval%s'\n"
             "set style data histograms\nset style histogram errorbars gap 1 lw 1\n"
             "set style fill solid 0.6\nset yrange [0:1.05]\nset ylabel 'share of runs whose 95%% interval holds x_I'\n"
             "set xtics rotate by 35 right font ',8'\nset bmargin 10\nset rmargin 7\nset key off\n"
             "set label 1 '0.95' at graph 1, first 0.95 offset 0.5, 0 left font ',8'\n"
             "plot 'bars.csv' skip 1 u 3:5:6:xtic(1), 0.95 dt 2 lc 'black'\n", partial);
    draw(st, "coverage", 1000, 500, script);
    snprintf(drawn + strlen(drawn), len - strlen(drawn), ", work.%s, coverage.%s (and their .gp scripts)", st->format,
             st->format);
    return 0;
}

/* On stdout: the winner at each budget (least RMSE^2 x seconds among the methods with a certified
 * finite variance) with its RMSE, seconds and coverage (k/N and the 95% Wilson interval), then the
 * refused methods; "PARTIAL" when interrupted. */
static void print_summary(const study *st)
{
    printf("study of x[%lld]: exact %.10g; %d runs a cell%s\n", (long long)st->s.index, st->exact, st->repeats,
           st->partial ? "; PARTIAL (interrupted): the cells below hold the runs finished" : "");
    printf("%-12s %-28s %-10s %-10s %s\n", st->time_budgets ? "seconds" : "walks", "winner (least RMSE^2 x s)", "RMSE",
           "s a run", "coverage (95% interval)");
    for (int b = 0; b < st->nbudget; b++) {
        cell bc;
        int best = ulam_study_winner(st->lib, b, &bc);
        if (best < 0 || !isfinite(bc.work)) { /* none, or every cell has runs with no estimate */
            printf("%-12g %s\n", st->budget[b], best < 0 ? "(no finished runs)" : "(no winner: every method has runs with no estimate)");
            continue;
        }
        double lo, hi;
        int covered = (int)lround(bc.coverage * bc.runs);
        ulam_study_coverage_interval(covered, bc.runs, &lo, &hi);
        printf("%-12g %-28s %-10.3g %-10.3g %d/%d (%.2f .. %.2f)\n", st->budget[b], st->m[best].name, bc.rmse,
               bc.seconds, covered, bc.runs, lo, hi);
    }
    for (int m = 0; m < NMETHOD; m++) /* the failures, each cell where a run gave no estimate */
        for (int b = 0; b < st->nbudget; b++) {
            cell c;
            if (st->m[m].on && !st->m[m].why[0] && method_cell(st, m, b, &c) && c.failed)
                printf("no estimate: %s at %g: %d of %d runs (a failure: this cell cannot win)\n", st->m[m].name,
                       st->budget[b], c.failed, c.runs);
        }
    for (int m = 0; m < NMETHOD; m++)
        if (st->m[m].on && st->m[m].why[0]) printf("refused: %s: %s\n", st->m[m].name, st->m[m].why);
}

/* ulam study. */
int cli_study(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"rhs", required_argument, 0, 'b'},     {"index", required_argument, 0, 'i'},
        {"methods", required_argument, 0, 'm'}, {"budgets", required_argument, 0, 'n'},
        {"time-budgets", required_argument, 0, 't'}, {"repeats", required_argument, 0, 'R'},
        {"out", required_argument, 0, 'o'},     {"seed", required_argument, 0, 's'},
        {"threads", required_argument, 0, 'T'}, {"jacobi", no_argument, 0, 'j'},
        {"omega", required_argument, 0, 'w'},   {"help", no_argument, 0, 'h'},
        {"cache", no_argument, 0, 'C'},         {"force", no_argument, 0, 'F'},
        {"reference-time", required_argument, 0, 'r'}, {"format", required_argument, 0, 'f'},
        {0, 0, 0, 0}};
    static const char *const formats[] = {"png", "svg", "pdf"};
    static study st;
    st = (study){.s = {.command = "study", .omega = 1.0}, .repeats = 30, .seed = 1, .out = "study",
                 .reference_time = 10, .format = "png"};
    methods_init(st.m);
    parse_budgets(&st, "--budgets", "100,1000,10000,100000,1000000", 1);
    int64_t v;
    int c, rc;
    if (cli_check_options("study", argc, argv, longopts)) return EXIT_USAGE;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'b': st.s.rhs_path = optarg; break;
        case 'i': if ((rc = cli_parse_int("study", "--index", optarg, 1, ULAM_MAX_DIM, &st.s.index))) return rc; break;
        case 'm': if ((rc = methods_select(st.m, optarg))) return rc; break;
        case 'n': if ((rc = parse_budgets(&st, "--budgets", optarg, 1))) return rc; st.time_budgets = 0; break;
        case 't': if ((rc = parse_budgets(&st, "--time-budgets", optarg, 0))) return rc; st.time_budgets = 1; break;
        case 'R': if ((rc = cli_parse_int("study", "--repeats", optarg, 2, MAXREPEAT, &v))) return rc; st.repeats = (int)v; break;
        case 'o': st.out = optarg; break;
        case 's': if ((rc = cli_parse_int("study", "--seed", optarg, 0, UINT32_MAX, &v))) return rc; st.seed = (uint64_t)v; break;
        case 'T': if ((rc = cli_parse_int("study", "--threads", optarg, 1, 1024, &v))) return rc; st.threads = (int)v; break;
        case 'j': st.s.jacobi = 1; break;
        case 'C': st.s.cache = 1; break;
        case 'F': st.force = 1; break;
        case 'r': if ((rc = cli_parse_real("study", "--reference-time", optarg, 0, 1e6, &st.reference_time))) return rc; break;
        case 'f':
            if ((rc = cli_choose("study", "--format", optarg, formats, 3, "png, svg or pdf")) < 0) return EXIT_USAGE;
            st.format = formats[rc];
            break;
        case 'w': if ((rc = cli_parse_real("study", "--omega", optarg, 1e-6, 2.0, &st.s.omega))) return rc; break;
        case 'h': fputs(usage, stdout); return 0;
        default: return cli_usage_error("study", "unknown option");
        }
    }
    if (optind != argc - 1) return cli_usage_error("study", "expects exactly one matrix file");
    if (!st.s.rhs_path && !ulam_system_is_file(argv[optind])) return cli_need_rhs("study", argv[optind]);
    if (!st.s.index) return cli_usage_error("study", "needs --index I");
    st.s.matrix_path = argv[optind];
    if (mkdir(st.out, 0777) && access(st.out, W_OK)) {
        ulam_error e = {.status = ULAM_EIO, .msg = "a directory that can be created or written"};
        return cli_report(st.out, &e);
    }
    if ((rc = cli_load_system(&st.s))) return rc;
    if (!st.s.b) {
        cli_system_free(&st.s);
        return cli_usage_error("study", "needs --rhs b.mtx (%s holds no b)", st.s.matrix_path);
    }
    size_t cells = (size_t)NMETHOD * MAXBUDGET * (size_t)st.repeats;
    st.row = calloc(cells, sizeof *st.row);
    rc = st.row ? 0 : cli_exit_code(ULAM_ENOMEM);
    if (!rc) rc = check_question(&st);
    if (!rc) rc = screen_methods(&st);
    if (!rc) rc = references(&st);
    if (!rc) rc = run_all(&st);
    if ((rc == 0 || rc == EXIT_INTERRUPTED) && cli_rank == 0) {
        st.partial = rc == EXIT_INTERRUPTED;
        int rs = summarise(&st);
        if (!rs) {
            char drawn[512];
            if (charts(&st, drawn, sizeof drawn)) drawn[0] = '\0';
            print_summary(&st);
            fprintf(stderr, "ulam: study: wrote %s/: runs.csv, summary.csv, bars.csv, reference.csv, question.txt%s\n",
                    st.out, drawn);
        } else {
            rc = rs;
        }
    }
    for (size_t i = 0; st.row && i < cells; i++) free(st.row[i]);
    free(st.row);
    st.lib = ulam_study_free(st.lib);
    cli_system_free(&st.s);
    return rc;
}
