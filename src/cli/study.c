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
    int no_charts;         /* --no-charts: the CSVs alone, no gnuplot run */
    int partial;           /* interrupted: charts and summary say so */
    uint64_t seed;
    const char *out;
    ulam_study *lib; /* the engine: the guards' verdicts, the exact value, every run and the reports (src/study*.c) */
} study;

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

/* The library's study of the chosen methods (ulam_study_alloc: the guards, each method screened,
 * the exact value).  0 or an exit code. */
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
    return 0;
}

/* Each refused or flagged method said on stderr; 0, or EXIT_DIVERGE when none is left. */
static int refusals(study *st)
{
    const ulam_guard *g = ulam_study_guard(st->lib);
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

/* The report options of st. */
static ulam_study_report_opts report_opts(const study *st)
{
    return (ulam_study_report_opts){.jacobi = st->s.jacobi, .omega = st->s.omega,
                                    .reference_time = st->reference_time, .partial = st->partial};
}

/* Write report kind of the study as DIR/name (temporary file, then rename); 0 or an exit code. */
static int write_report(const study *st, const char *name, int kind)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", st->out, name);
    ulam_outfile o;
    ulam_study_report_opts ro = report_opts(st);
    int status = cli_outfile_open(&o, path);
    if (!status && (status = ulam_study_fprint(o.f, st->lib, kind, &ro))) cli_outfile_abort(&o);
    else if (!status) status = cli_outfile_commit(&o);
    ulam_error e = {.status = status, .msg = "a writable output directory"};
    return status ? cli_report(path, &e) : 0;
}

/* Write every finished row to runs.csv; 0 or an exit code (under MPI, rank 0 writes). */
static int save_runs(const study *st)
{
    return cli_rank ? 0 : write_report(st, "runs.csv", ULAM_STUDY_RUNS_CSV);
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
    char path[4096], runs[4096], mine[2048] = "", theirs[2048] = "", field[32], was[256], now[256];
    snprintf(path, sizeof path, "%s/question.txt", st->out);
    snprintf(runs, sizeof runs, "%s/runs.csv", st->out);
    ulam_study_report_opts ro = report_opts(st);
    FILE *q = fmemopen(mine, sizeof mine - 1, "w");
    if (!q) return cli_exit_code(ULAM_ENOMEM);
    ulam_study_fprint(q, st->lib, ULAM_STUDY_QUESTION, &ro);
    fclose(q);
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
    return cli_rank ? 0 : write_report(st, "question.txt", ULAM_STUDY_QUESTION);
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
    FILE *f = fopen(path, "r");
    int rows = f ? ulam_study_runs_read(st->lib, f) : 0;
    if (f) fclose(f);
    if (rows) fprintf(stderr, "ulam: study: resuming: %d runs already in %s\n", rows, path);
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
    fprintf(f, "%s,", kind);
    for (int k = 0; k < 2; k++) {
        double v = k ? error + 1e-300 : seconds;
        if (isfinite(v)) fprintf(f, "%.6g", v);
        fputc(k ? '\n' : ',', f);
    }
}

/* The reference lines (ulam_study_reference_lines: LAPACK's point, Gauss-Seidel, sequential MC
 * and MCSA, the Krylov peer), into reference.csv.  0 or an exit code. */
static int references(study *st)
{
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

/* Draw DIR/NAME.FORMAT from the library's script of chart kind, and keep the script beside it as
 * DIR/NAME.gp ('cd DIR && gnuplot NAME.gp' redraws it from the CSVs there); the chart is drawn
 * into a temporary file that ulam made (mkstemp: O_EXCL, a fresh name, never a planted symlink),
 * which gnuplot writes through the descriptor it inherits (/dev/fd/N: no name to follow), then
 * renamed into place.  ULAM_OK, 1 when the chart has no lines, or ULAM_EIO (gnuplot missing or
 * failed). */
static int draw(const study *st, const char *name, int width, int height, int kind)
{
    char term[128], gp[4200], out[4200], cmd[4200], *script = NULL;
    size_t size = 0;
    ulam_study_report_opts ro = report_opts(st);
    FILE *sf = open_memstream(&script, &size);
    if (!sf) return ULAM_EIO;
    ulam_study_fprint(sf, st->lib, kind, &ro);
    fclose(sf);
    int status = size ? ULAM_OK : 1;
    const char *fmt = st->format;
    if (!strcmp(fmt, "pdf")) snprintf(term, sizeof term, "pdfcairo size %gin,%gin font 'sans,9'", width / 100.0, height / 100.0);
    else if (!strcmp(fmt, "svg")) snprintf(term, sizeof term, "svg size %d,%d font 'sans,10' background 'white'", width, height);
    else snprintf(term, sizeof term, "pngcairo size %d,%d font 'sans,10'", width, height);
    snprintf(gp, sizeof gp, "%s/%s.gp", st->out, name);
    snprintf(out, sizeof out, "%s/%s.%s", st->out, name, fmt);
    const char *head = "set datafile separator ','\nset grid\n";
    ulam_outfile o, chart;
    if (!status && !ulam_outfile_open(&o, gp)) {
        fprintf(o.f, "# ulam study: %s; redraw with: cd %s && gnuplot %s.gp\nset terminal %s\nset output '%s.%s'\n%s%s\n"
                     "set output\n", name, st->out, name, term, name, fmt, head, script);
        if (ulam_outfile_commit(&o)) status = ULAM_EIO;
    }
    if (!status && strchr(st->out, '\'')) status = ULAM_EINVAL;
    if (!status && cli_outfile_open(&chart, out)) status = ULAM_EIO;
    if (!status) {
        fflush(chart.f);
        snprintf(cmd, sizeof cmd, "cd '%s' && gnuplot 2>/dev/null", st->out);
        FILE *g = popen(cmd, "w");
        if (g) fprintf(g, "set terminal %s\nset output '/dev/fd/%d'\n%s%s\nset output\n", term, fileno(chart.f), head, script);
        if (!g || pclose(g) != 0) cli_outfile_abort(&chart), status = ULAM_EIO;
        else status = cli_outfile_commit(&chart) ? ULAM_EIO : ULAM_OK;
    }
    free(script);
    return status;
}

/* The charts (an RMSE chart per estimator, work, coverage with its binomial interval); the names of
 * those drawn into drawn[]; nonzero when gnuplot failed. */
static int charts(const study *st, char *drawn, size_t len)
{
    static const char *const est[3] = {"collision", "absorption", "expected"};
    char chart[64];
    drawn[0] = '\0';
    for (int e = 0; e < 3; e++) {
        snprintf(chart, sizeof chart, "rmse-%s", est[e]);
        int status = draw(st, chart, 1100, 750, ULAM_STUDY_CHART_COLLISION + e);
        if (status == 1) continue; /* no method of this estimator runs */
        if (status) {
            fprintf(stderr, "ulam: study: gnuplot failed (install gnuplot-nox): charts not drawn, CSVs written\n");
            return 1;
        }
        snprintf(drawn + strlen(drawn), len - strlen(drawn), ", %s.%s", chart, st->format);
    }
    int work = draw(st, "work", 1000, 500, ULAM_STUDY_CHART_WORK);
    if (work == 1) fprintf(stderr, "ulam: study: work chart not drawn: no method's RMSE^2 x s is above 0 (every run exact)\n");
    else if (!work) snprintf(drawn + strlen(drawn), len - strlen(drawn), ", work.%s", st->format);
    if (!draw(st, "coverage", 1000, 500, ULAM_STUDY_CHART_COVERAGE))
        snprintf(drawn + strlen(drawn), len - strlen(drawn), ", coverage.%s", st->format);
    snprintf(drawn + strlen(drawn), len - strlen(drawn), " (and their .gp scripts)");
    return 0;
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
        {"no-charts", no_argument, 0, 'P'},     {0, 0, 0, 0}};
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
        case 'P': st.no_charts = 1; break;
        case 'r': if ((rc = cli_parse_real("study", "--reference-time", optarg, 0, 1e6, &st.reference_time))) return rc; break;
        case 'f':
            if ((rc = cli_choose("study", "--format", optarg, formats, 3, "png, svg or pdf")) < 0) return EXIT_USAGE;
            st.format = formats[rc];
            break;
        case 'w': if ((rc = cli_parse_real("study", "--omega", optarg, 1e-6, 2.0, &st.s.omega))) return rc; break;
        case 'h': ulam_options_help(stdout, "study"); return 0;
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
    rc = screen_methods(&st);
    if (!rc) rc = check_question(&st);
    if (!rc) rc = refusals(&st);
    if (!rc) rc = references(&st);
    if (!rc) rc = run_all(&st);
    if ((rc == 0 || rc == EXIT_INTERRUPTED) && cli_rank == 0) {
        st.partial = rc == EXIT_INTERRUPTED;
        int rs = write_report(&st, "summary.csv", ULAM_STUDY_SUMMARY_CSV);
        if (!rs) rs = write_report(&st, "bars.csv", ULAM_STUDY_BARS_CSV);
        if (!rs) {
            char drawn[512] = "";
            ulam_study_report_opts ro = report_opts(&st);
            if (!st.no_charts && charts(&st, drawn, sizeof drawn)) drawn[0] = '\0';
            ulam_study_fprint(stdout, st.lib, ULAM_STUDY_TEXT, &ro);
            fprintf(stderr, "ulam: study: wrote %s/: runs.csv, summary.csv, bars.csv, reference.csv, question.txt%s\n",
                    st.out, drawn);
        } else {
            rc = rs;
        }
    }
    st.lib = ulam_study_free(st.lib);
    cli_system_free(&st.s);
    return rc;
}
