/* CSV files and gnuplot charts for the example experiments: each file is written under a
 * temporary name and renamed into place when complete. */
#ifndef ULAM_EXAMPLES_CHART_H
#define ULAM_EXAMPLES_CHART_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "gnuplot.h"
#include "ulam.h"

/* An output file being written: its final path and the temporary one. */
typedef struct {
    FILE *f;
    char path[4096], tmp[4200];
} out_file;

/* Open DIR/NAME for writing under a temporary name; exit on failure (a tool, not a library). */
static inline void out_open(out_file *o, const char *dir, const char *name)
{
    snprintf(o->path, sizeof o->path, "%s/%s", dir, name);
    snprintf(o->tmp, sizeof o->tmp, "%s.tmp", o->path);
    if (!(o->f = fopen(o->tmp, "w"))) {
        perror(o->tmp);
        exit(1);
    }
}

/* Close and rename into place; exit on failure. */
static inline void out_commit(out_file *o)
{
    if (fclose(o->f) || rename(o->tmp, o->path)) {
        perror(o->path);
        remove(o->tmp);
        exit(1);
    }
    fprintf(stderr, "wrote %s\n", o->path);
}

/* Draw DIR/NAME.png with gnuplot_draw (src/cli/gnuplot.h) from a printf-style script (data files relative to
 * DIR).  Returns 0, or 1 with a message when gnuplot is missing or fails. */
static inline int chart_draw(const char *dir, const char *name, int width, int height, const char *fmt, ...)
{
    static char script[16384];
    va_list ap;
    va_start(ap, fmt);
    int len = vsnprintf(script, sizeof script, fmt, ap);
    va_end(ap);
    if (len < 0 || (size_t)len >= sizeof script || gnuplot_draw(dir, name, width, height, script)) {
        fprintf(stderr, "gnuplot failed for %s/%s.png (install gnuplot-nox); the CSV is written\n", dir, name);
        return 1;
    }
    fprintf(stderr, "wrote %s/%s.png\n", dir, name);
    return 0;
}

/* Run walks; exit with the library's message on failure. */
static inline ulam_walk_result walk(const ulam_csr *M, const double *b, const ulam_walk_opts *o)
{
    ulam_walk_result r;
    ulam_error err;
    int s = ulam_solve_walks(M, b, o, &r, &err);
    if (s) {
        fprintf(stderr, "ulam_solve_walks: %s: %s\n", ulam_strerror(s), err.msg);
        exit(1);
    }
    return r;
}

/* x from the dense LAPACK solve; exit on failure. */
static inline double *direct(const ulam_csr *M, const double *b, ulam_direct_info *info)
{
    double *x = malloc((size_t)M->nrows * sizeof *x);
    int s = x ? ulam_direct_solve(M, b, x, 0, info, NULL) : ULAM_ENOMEM;
    if (s) {
        fprintf(stderr, "ulam_direct_solve: %s\n", ulam_strerror(s));
        exit(1);
    }
    return x;
}

/* The running estimate: runs of 1024 * 2^k walks, k = 0 .. kmax, with the same seed (whole
 * blocks of 1024, so each run's walks are the previous run's plus new ones); one CSV row
 * "case,walks,estimate,stderr,direct" per run.  A run that stops on a non-finite score ends
 * the series. */
static inline void running(const ulam_csr *M, const double *b, ulam_walk_opts o, int kmax, double exact,
                           FILE *f, int tag)
{
    for (int k = 0; k <= kmax; k++) {
        o.stop.max_walks = (int64_t)1024 << k;
        ulam_walk_result r;
        int s = ulam_solve_walks(M, b, &o, &r, NULL);
        if (s) {
            fprintf(stderr, "case %d: %lld walks: %s\n", tag, (long long)o.stop.max_walks, ulam_strerror(s));
            return;
        }
        fprintf(f, "%d,%lld,%.10g,%.6g,%.10g\n", tag, (long long)r.walks, r.estimate, r.std_error, exact);
    }
}

#endif
