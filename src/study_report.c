/* A study's reports (ulam_study_fprint): runs.csv, summary.csv, bars.csv, the question's
 * fingerprint, the winners' table and the charts' gnuplot scripts, each written to a caller's
 * FILE *; and runs.csv read back (ulam_study_runs_read), so a rerun resumes.  No non-finite number
 * is written: an undefined statistic is an empty field. */
#include "study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* v as %.6g in buf, or an empty field when it is not finite (an undefined statistic). */
static const char *num(char buf[32], double v)
{
    if (isfinite(v)) snprintf(buf, 32, "%.6g", v);
    else buf[0] = '\0';
    return buf;
}

/* Nonzero when method m was chosen and not refused. */
static int runs_on(const ulam_study *s, int m)
{
    return s->screen[m].on && !s->screen[m].why[0];
}

/* The fields of a runs.csv line: name, budget, repeat, estimate, stderr, walks, steps and seconds;
 * a run with no estimate (both fields empty) gives NaN for them.  1 when the line is whole. */
static int run_fields(const char *line, char name[64], double *budget, ulam_study_run *u)
{
    char est[64], err[64];
    long long w, st;
    if (sscanf(line, "%63[^,],%lf,%d,%*u,%63[^,],%63[^,],%*[^,],%lld,%lld,%lf", name, budget, &u->repeat, est, err,
               &w, &st, &u->seconds) == 8) {
        char *end1, *end2;
        u->estimate = strtod(est, &end1), u->std_error = strtod(err, &end2), u->walks = w, u->steps = st;
        return *end1 == '\0' && *end2 == '\0' && isfinite(u->estimate) && isfinite(u->std_error) &&
               isfinite(u->seconds);
    }
    /* a failed run: ",," where the estimate and stderr (and the error) would be */
    if (sscanf(line, "%63[^,],%lf,%d,%*u,,,,%lld,%lld,%lf", name, budget, &u->repeat, &w, &st, &u->seconds) == 6 &&
        isfinite(u->seconds)) {
        u->estimate = u->std_error = NAN, u->walks = w, u->steps = st;
        return 1;
    }
    return 0;
}

/* See ulam_study.h.  A torn line (left by an older version that appended) ends the reading. */
int ulam_study_runs_read(ulam_study *s, FILE *f)
{
    if (!s || !f) return 0;
    char line[1024], name[64];
    int rows = 0;
    while (fgets(line, sizeof line, f)) {
        size_t len = strlen(line);
        if (len == 0 || line[len - 1] != '\n') break;
        double budget;
        ulam_study_run u = {0};
        if (!run_fields(line, name, &budget, &u)) continue;
        int m = ulam_study_method_find(name);
        for (int b = 0; m >= 0 && b < s->p.nbudgets; b++)
            if (s->budget[b] == budget && u.repeat >= 0 && u.repeat < s->p.repeats) {
                u.method = m, u.budget = b, u.has_estimate = !isnan(u.estimate);
                rows += ulam_study_restore(s, &u) == ULAM_OK;
            }
    }
    return rows;
}

/* runs.csv: a row per finished run (a run with no estimate: its fields empty). */
static void runs_csv(FILE *f, const ulam_study *s)
{
    fputs("method,budget,repeat,seed,estimate,stderr,abs_error,walks,steps,seconds,covered\n", f);
    for (int m = 0; m < ULAM_STUDY_METHODS; m++)
        for (int b = 0; b < s->p.nbudgets; b++)
            for (int r = 0; r < s->p.repeats; r++) {
                ulam_study_run u;
                if (!ulam_study_run_get(s, m, b, r, &u)) continue;
                const char *name = ulam_study_method_get(m)->name;
                if (!u.has_estimate)
                    fprintf(f, "%s,%.17g,%d,%llu,,,,%lld,%lld,%.6g,0\n", name, u.budget_value, u.repeat,
                            (unsigned long long)u.seed, (long long)u.walks, (long long)u.steps, u.seconds);
                else
                    fprintf(f, "%s,%.17g,%d,%llu,%.17g,%.17g,%.17g,%lld,%lld,%.6g,%d\n", name, u.budget_value,
                            u.repeat, (unsigned long long)u.seed, u.estimate, u.std_error, u.abs_error,
                            (long long)u.walks, (long long)u.steps, u.seconds, u.covered);
            }
}

/* FNV-1a 64 of n bytes, continuing from h. */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *c = p;
    for (size_t k = 0; k < n; k++) h = (h ^ c[k]) * 0x100000001b3ULL;
    return h;
}

/* The question a study answers, one "field value" line each. */
static void question(FILE *f, const ulam_study *s, const ulam_study_report_opts *ro)
{
    const ulam_csr *M = s->M;
    int64_t n = M->nrows, nz = ulam_csr_nnz(M);
    uint64_t hm = fnv(0xcbf29ce484222325ULL, M->rowptr, (size_t)(n + 1) * sizeof *M->rowptr);
    hm = fnv(fnv(hm, M->colidx, (size_t)nz * sizeof *M->colidx), M->val, (size_t)nz * sizeof *M->val);
    uint64_t hb = fnv(0xcbf29ce484222325ULL, s->b, (size_t)n * sizeof *s->b);
    fprintf(f, "n %lld\nmatrix %016llx\nrhs %016llx\nindex %lld\njacobi %d\nomega %.17g\nseed %llu\nmethods ",
            (long long)n, (unsigned long long)hm, (unsigned long long)hb, (long long)s->index + 1, ro->jacobi,
            ro->jacobi ? ro->omega : 1.0, (unsigned long long)s->p.seed);
    for (int m = 0, first = 1; m < ULAM_STUDY_METHODS; m++)
        if (s->screen[m].on) fprintf(f, "%s%s", first ? "" : ",", ulam_study_method_get(m)->name), first = 0;
    fprintf(f, "\nbudgets %s\n", s->p.time_budgets ? "seconds" : "walks");
}

/* summary.csv: a row per cell. */
static void summary_csv(FILE *f, const ulam_study *s)
{
    char v[6][32];
    fprintf(f, "method,budget,runs,rmse,mean_stderr,honesty,coverage,seconds,work,variance_finite,failed\n");
    for (int m = 0; m < ULAM_STUDY_METHODS; m++)
        for (int b = 0; runs_on(s, m) && b < s->p.nbudgets; b++) {
            ulam_study_cell c;
            if (!ulam_study_cell_get(s, m, b, &c)) continue;
            fprintf(f, "%s,%.17g,%d,%s,%s,%s,%s,%s,%s,%s,%d\n", ulam_study_method_get(m)->name, s->budget[b], c.runs,
                    num(v[0], c.rmse), num(v[1], c.mean_stderr), num(v[2], c.honesty), num(v[3], c.coverage),
                    num(v[4], c.seconds), num(v[5], c.work), s->screen[m].infinite ? "false" : "true", c.failed);
        }
}

/* Method m's bar: its cell at the largest budget with runs into *last; 0 when it has none. */
static int bar_cell(const ulam_study *s, int m, ulam_study_cell *last)
{
    ulam_study_cell c;
    *last = (ulam_study_cell){0};
    for (int b = 0; runs_on(s, m) && b < s->p.nbudgets; b++)
        if (ulam_study_cell_get(s, m, b, &c)) *last = c;
    return last->runs > 0;
}

/* bars.csv: per method, its largest budget with runs, with the coverage's Wilson interval. */
static void bars_csv(FILE *f, const ulam_study *s)
{
    char v[5][32];
    fprintf(f, "method,work,coverage,honesty,coverage_lo,coverage_hi,covered,runs\n");
    for (int m = 0; m < ULAM_STUDY_METHODS; m++) {
        ulam_study_cell last;
        if (!bar_cell(s, m, &last)) continue;
        double lo, hi;
        int covered = (int)lround(last.coverage * last.runs);
        ulam_study_coverage_interval(covered, last.runs, &lo, &hi);
        fprintf(f, "%s,%s,%s,%s,%s,%s,%d,%d\n", ulam_study_method_get(m)->name, num(v[0], last.work),
                num(v[1], last.coverage), num(v[2], last.honesty), num(v[3], lo), num(v[4], hi), covered, last.runs);
    }
}

/* The winner at each budget (least RMSE^2 x seconds among the methods with a certified finite
 * variance) with its RMSE, seconds and coverage (k/N and the 95% Wilson interval), then the
 * failures and the refused methods; "PARTIAL" when interrupted. */
static void text(FILE *f, const ulam_study *s, const ulam_study_report_opts *ro)
{
    fprintf(f, "study of x[%lld]: exact %.10g; %d runs a cell%s\n", (long long)s->index + 1, s->ref.exact,
            s->p.repeats, ro->partial ? "; PARTIAL (interrupted): the cells below hold the runs finished" : "");
    fprintf(f, "%-12s %-28s %-10s %-10s %s\n", s->p.time_budgets ? "seconds" : "walks", "winner (least RMSE^2 x s)",
            "RMSE", "s a run", "coverage (95% interval)");
    for (int b = 0; b < s->p.nbudgets; b++) {
        ulam_study_cell bc;
        int best = ulam_study_winner(s, b, &bc);
        if (best < 0 || !isfinite(bc.work)) { /* none, or every cell has runs with no estimate */
            fprintf(f, "%-12g %s\n", s->budget[b],
                    best < 0 ? "(no finished runs)" : "(no winner: every method has runs with no estimate)");
            continue;
        }
        double lo, hi;
        int covered = (int)lround(bc.coverage * bc.runs);
        ulam_study_coverage_interval(covered, bc.runs, &lo, &hi);
        fprintf(f, "%-12g %-28s %-10.3g %-10.3g %d/%d (%.2f .. %.2f)\n", s->budget[b],
                ulam_study_method_get(best)->name, bc.rmse, bc.seconds, covered, bc.runs, lo, hi);
    }
    for (int m = 0; m < ULAM_STUDY_METHODS; m++) /* the failures, each cell where a run gave no estimate */
        for (int b = 0; b < s->p.nbudgets; b++) {
            ulam_study_cell c;
            if (runs_on(s, m) && ulam_study_cell_get(s, m, b, &c) && c.failed)
                fprintf(f, "no estimate: %s at %g: %d of %d runs (a failure: this cell cannot win)\n",
                        ulam_study_method_get(m)->name, s->budget[b], c.failed, c.runs);
        }
    for (int m = 0; m < ULAM_STUDY_METHODS; m++)
        if (s->screen[m].on && s->screen[m].why[0])
            fprintf(f, "refused: %s: %s\n", ulam_study_method_get(m)->name, s->screen[m].why);
}

/* LAPACK's point on the RMSE chart, kept inside the axes the other lines set: marked at the edge
 * it would stretch past, with its values and an arrow toward them (gnuplot, after X0, X1, Y0). */
static void lapack_mark(FILE *f, const ulam_study *s)
{
    if (!s->ref.direct) {
        fprintf(f, "lx = 1/0\nly = 1/0\n");
        return;
    }
    double error = fabs(s->ref.exact - s->ref.settled) + 1e-300;
    char err[32]; /* the error as a label: 0 when LAPACK and Gauss-Seidel agree to the last bit */
    if (error > 1e-299) snprintf(err, sizeof err, "%.2g", error);
    else snprintf(err, sizeof err, "0");
    fprintf(f,
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
            s->ref.direct_seconds, error, err, s->ref.direct_seconds);
}

/* Why summary.csv's cells cannot be fitted by f(x) = a / sqrt(x) (gnuplot's fit of column 4 on
 * column 8, from a = 0), or NULL when they can: it needs two cells with a finite RMSE (one point:
 * gnuplot's "No data to fit" fails the script), seconds above 0, and an RMSE above 0 (all 0: the
 * fit creeps from a = 0 toward 0 for seconds). */
static const char *no_fit(const ulam_study *s)
{
    int points = 0, above = 0;
    for (int m = 0; m < ULAM_STUDY_METHODS; m++)
        for (int b = 0; runs_on(s, m) && b < s->p.nbudgets; b++) {
            ulam_study_cell c;
            if (!ulam_study_cell_get(s, m, b, &c) || !isfinite(c.rmse) || !isfinite(c.seconds)) continue;
            if (!(c.seconds > 0)) return "a cell ran in 0 s";
            points++, above += c.rmse > 0;
        }
    if (points < 2) return "fewer than two cells";
    return above ? NULL : "every RMSE is 0 (every run exact)";
}

/* The RMSE chart of estimator e's methods (at most 6, each its own colour and dash); nothing when
 * none runs.  Its 1/sqrt(t) line is fitted to every cell (no_fit: else a note in its place). */
static void rmse_chart(FILE *f, const ulam_study *s, int e, const ulam_study_report_opts *ro)
{
    static const char *const est[3] = {"collision", "absorption", "expected"};
    char names[ULAM_STUDY_METHODS * 40] = "", budgets[MAXBUDGET * 32] = "";
    for (int m = 0; m < ULAM_STUDY_METHODS; m++)
        if (runs_on(s, m) && ulam_study_method_get(m)->estimator == ULAM_COLLISION + e)
            strcat(strcat(names, ulam_study_method_get(m)->name), " ");
    if (!names[0]) return;
    for (int b = 0; b < s->p.nbudgets; b++)
        snprintf(budgets + strlen(budgets), sizeof budgets - strlen(budgets), "%.17g ", s->budget[b]);
    double y0 = s->ref.exact != 0 ? 1e-9 * fabs(s->ref.exact) : 1e-12;
    const char *why = no_fit(s);
    char fit[200] = "set fit quiet\nset fit logfile '/dev/null'\nf(x) = a / sqrt(x)\na = 0\nfit f(x) 'summary.csv' u 8:4 via a\n";
    if (why)
        snprintf(fit, sizeof fit, "set label 2 'no 1/sqrt(t) fit: %s' at graph 0.02, graph 0.96 left font ',9'\n", why);
    fprintf(f,
            "set title 'ulam study: RMSE of x_{%lld} against seconds per run, %s estimator%s'\n"
            "set logscale xy\nset format x '10^{%%L}'\nset format y '10^{%%L}'\nset xlabel 'seconds per run'\n"
            "set ylabel 'RMSE (reference lines: the error of one run)'\nset key outside bottom center horizontal "
            "maxrows 4 font ',8'\n"
            "Y0 = %g\nset yrange [Y0:*]\n"
            "%s"
            "M = \"%s\"\n" /* at most 6 methods: 6 colours, 6 dashes */
            "C = \"#1b9e77 #d95f02 #7570b3 #e7298a #66a61e #a6761d\"\n"
            "B = \"%s\"\n" /* one point shape per budget, in the method's colour */
            "P = \"7 5 9 11 13 6 4 8 10 12 1 2 3 14 15 16\"\n"
            "stats 'summary.csv' u ($8 > 0 ? $8 : 1/0) nooutput\nX0 = STATS_min\nX1 = STATS_max\n"
            "stats 'reference.csv' u (strcol(1) ne 'lapack' && $2 > 0 ? $2 : 1/0) nooutput\n"
            "X0 = 10**floor(log10(STATS_min < X0 ? STATS_min : X0))\nX1 = 10**ceil(log10(STATS_max > X1 ? STATS_max : X1))\n"
            "set xrange [X0:X1]\n",
            (long long)s->index + 1, est[e], ro->partial ? " (PARTIAL: interrupted)" : "", y0, fit, names, budgets);
    lapack_mark(f, s);
    fprintf(f,
            "plot for [i=1:words(M)] 'summary.csv' u (strcol(1) eq word(M, i) && $11 == 0 ? $8 : 1/0):4 w l lw 2 "
            "linecolor rgb word(C, i) dashtype i title word(M, i), "
            "for [i=1:words(M)] for [j=1:words(B)] 'summary.csv' u (strcol(1) eq word(M, i) && $2 == word(B, j) + 0 && $11 == 0 ? "
            "$8 : 1/0):4 w p linecolor rgb word(C, i) pointtype (word(P, j) + 0) notitle, "
            "for [j=1:words(B)] NaN w p lc 'black' pointtype (word(P, j) + 0) title sprintf('%s', word(B, j) + 0), "
            "'reference.csv' u (strcol(1) eq 'gs' ? $2 : 1/0):3 w l lw 3 lc 'gray50' t 'Gauss-Seidel, whole vector', "
            "'' u (strcol(1) eq 'lapack' ? lx : 1/0):(ly) w p pt 9 ps 2 lc 'web-green' t 'LAPACK dgesv', "
            "%s"
            "'' u (strcol(1) eq 'cg' || strcol(1) eq 'gmres' ? $2 : 1/0):3 w lp lw 1 pt 3 lc 'dark-cyan' t 'Krylov', "
            "%s\n",
            s->p.time_budgets ? "%g s a run" : "%.0f walks",
            ulam_study_forward_walks(s) && ro->reference_time > 0 /* the one-run lines exist: else no legend */
                ? "'' u (strcol(1) eq 'sequential' ? $2 : 1/0):3 w lp lw 1 pt 5 lc 'brown' t 'sequential MC (one run)', "
                  "'' u (strcol(1) eq 'mcsa' ? $2 : 1/0):3 w lp lw 1 pt 7 lc 'dark-magenta' t 'MCSA (one run)', "
                : "",
            why ? "NaN notitle" : "f(x) dt 4 lc 'gray30' t '1/sqrt(t)'");
}

/* The work chart (RMSE^2 x seconds at the largest budget, on a log scale: nothing when no bar is
 * above 0, as when every run is exact) or the coverage chart (with its binomial interval), from
 * bars.csv. */
static void bars_chart(FILE *f, const ulam_study *s, int coverage, const ulam_study_report_opts *ro)
{
    const char *partial = ro->partial ? " (PARTIAL: interrupted)" : "";
    int above = 0;
    for (int m = 0; m < ULAM_STUDY_METHODS; m++) {
        ulam_study_cell last;
        above += bar_cell(s, m, &last) && isfinite(last.work) && last.work > 0;
    }
    if (!coverage && !above) return;
    if (!coverage)
        fprintf(f, "set title 'work-normalised variance RMSE^2 x seconds at the largest budget (lower wins)%s'\n"
                   "set style data histograms\nset style fill solid 0.6\nset logscale y\nset format y '10^{%%L}'\n"
                   "set ylabel 'RMSE^2 x seconds per run'\nset xtics rotate by 35 right font ',8'\nset bmargin 10\n"
                   "set key off\nplot 'bars.csv' skip 1 u 2:xtic(1)\n", partial);
    else
        fprintf(f, "set title 'coverage of the 95%% interval at the largest budget, with its 95%% binomial interval%s'\n"
                   "set style data histograms\nset style histogram errorbars gap 1 lw 1\n"
                   "set style fill solid 0.6\nset yrange [0:1.05]\nset ylabel 'share of runs whose 95%% interval holds x_I'\n"
                   "set xtics rotate by 35 right font ',8'\nset bmargin 10\nset rmargin 7\nset key off\n"
                   "set label 1 '0.95' at graph 1, first 0.95 offset 0.5, 0 left font ',8'\n"
                   "plot 'bars.csv' skip 1 u 3:5:6:xtic(1), 0.95 dt 2 lc 'black'\n", partial);
}

/* See ulam_study.h. */
int ulam_study_fprint(FILE *f, const ulam_study *s, int kind, const ulam_study_report_opts *ro)
{
    static const ulam_study_report_opts none = {.omega = 1.0};
    if (!f || !s) return ULAM_EINVAL;
    if (!ro) ro = &none;
    switch (kind) {
    case ULAM_STUDY_RUNS_CSV: runs_csv(f, s); break;
    case ULAM_STUDY_SUMMARY_CSV: summary_csv(f, s); break;
    case ULAM_STUDY_BARS_CSV: bars_csv(f, s); break;
    case ULAM_STUDY_QUESTION: question(f, s, ro); break;
    case ULAM_STUDY_TEXT: text(f, s, ro); break;
    case ULAM_STUDY_CHART_COLLISION:
    case ULAM_STUDY_CHART_ABSORPTION:
    case ULAM_STUDY_CHART_EXPECTED: rmse_chart(f, s, kind - ULAM_STUDY_CHART_COLLISION, ro); break;
    case ULAM_STUDY_CHART_WORK:
    case ULAM_STUDY_CHART_COVERAGE: bars_chart(f, s, kind == ULAM_STUDY_CHART_COVERAGE, ro); break;
    default: return ULAM_EINVAL;
    }
    return ferror(f) ? ULAM_EIO : ULAM_OK;
}
