/* report.h: the report module's private pieces (ulam__report_), shared by its writers
 * (src/report_*.c over src/report.c): the answer line's column, an interval's digits, --check's z, the rel_err
 * rule's outcome in words. */
#ifndef ULAM_REPORT_PRIVATE_H
#define ULAM_REPORT_PRIVATE_H

#include <stdint.h>
#include <stdio.h>

#include "ulam.h"

/* The spaces after "name[index]" that put the value at column (16: under "method          "); at least 1. */
int ulam__report_pad(const char *name, int64_t index, int column);

/* The significant digits (10 to 17) that print an interval's ends lo < hi as two numbers. */
int ulam__report_ci_digits(double lo, double hi);

/* Standard errors a side of an interval may span before the answer line's +- shows that side instead. */
#define ULAM__REPORT_PM_WIDE 10.0

/* Write " +- H (95% CI lo .. hi)" for an estimate with standard error se and a finite interval: H
 * is se, or the interval's wider side when that passes ULAM__REPORT_PM_WIDE se (then "; standard
 * error se" inside the parentheses). */
void ulam__report_pm_fprint(FILE *f, double est, double se, double lo, double hi);

/* A radius in words: six decimals from 1e-4 to 1e6 (and 0, inf), else six significant digits;
 * buf holds 32 characters, returned. */
const char *ulam__report_radius_str(char *buf, double x);

/* Write radius p as "0.900000 (bounds [lo, hi], k iterations, s, converged or a bound)" (no newline). */
void ulam__report_power_fprint(FILE *f, const ulam_power *p);

/* --check's z = (estimate - direct) / std_error: 0 when they are equal, +-inf when only the stderr is 0. */
double ulam__report_z(double estimate, double direct, double std_error);

/* Write "z = Z", when |z| > 4 whether direct is inside [lo, hi], and a newline. */
void ulam__report_z_fprint(FILE *f, double estimate, double direct, double std_error, double lo, double hi);

/* An estimator's name (enum ulam_estimator): "collision", "absorption", "expected" ("?" for another). */
const char *ulam__report_estimator_name(int estimator);

/* A walk mode's name (enum ulam_mode): "adjoint" or "forward". */
const char *ulam__report_mode_name(int mode);

/* Nonzero when r's interval was withheld because its scores are too small to square in doubles. */
int ulam__report_score_too_small(const ulam_walk_result *r);

/* Write whether o's rel_err target was met by r, and when not why (one line; nothing without a
 * target; verbose: also a met target's rule). */
void ulam__report_rel_err_fprint(FILE *f, const ulam_walk_opts *o, const ulam_walk_result *r, int verbose);

/* Write the JSON member "key": true, false or null (finite 1, 0, else) and ", ". */
void ulam__report_verdict_json(FILE *f, const char *key, int finite);

/* Write radius p as JSON members prefix (the estimate when converged, else the upper bound),
 * prefix_is, prefix_lower, prefix_upper, prefix_converged, each followed by ", ". */
void ulam__report_radius_json(FILE *f, const char *prefix, const ulam_power *p);

/* The writers of ulam_report_fprint's kinds (src/report_info.c, _direct.c, _query.c, _bidir.c, _walk.c, _prepare.c): report is
 * the kind's struct; 0 or a status. */
int ulam__report_info_fprint(FILE *f, const void *report, int format);
int ulam__report_direct_fprint(FILE *f, const void *report, int format);
int ulam__report_query_fprint(FILE *f, const void *report, int format);
int ulam__report_bidir_fprint(FILE *f, const void *report, int format);
int ulam__report_walk_fprint(FILE *f, const void *report, int format);
int ulam__report_prepare_fprint(FILE *f, const void *report, int format);

#endif
