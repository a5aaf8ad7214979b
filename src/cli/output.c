/* How every command talks to its user: verbosity (--quiet, --verbose), errors as JSON under --json,
 * "did you mean" for options and option values, JSON fields and the shared lines of an answer.
 * The commands print through these; this file calls no other of the tool. */
#define _GNU_SOURCE /* fopencookie: stderr is teed to keep the last error line for --json */
#include "cli.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int cli_verbosity;
int cli_json_mode;
int cli_json_done;
int cli_rank;
/* See cli.h. */
const char *cli_answer_name = "x";

/* The last line written to stderr that is not a warning or progress (for the JSON error). */
static char last_error[1024], line_buf[1024];
static size_t line_len;

/* The stderr tee: write through to fd 2, and keep the last complete line that is an error. */
static ssize_t tee_write(void *cookie, const char *buf, size_t size)
{
    (void)cookie;
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(2, buf + done, size - done);
        if (w <= 0) break;
        done += (size_t)w;
    }
    for (size_t k = 0; k < size; k++) {
        char c = buf[k];
        if (c == '\r') line_len = 0;
        else if (c != '\n' && line_len + 1 < sizeof line_buf) line_buf[line_len++] = c;
        else if (c == '\n') {
            line_buf[line_len] = '\0';
            if (line_len && !strstr(line_buf, ": warning: ") && !strstr(line_buf, "deprecated"))
                memcpy(last_error, line_buf, line_len + 1);
            line_len = 0;
        }
    }
    return (ssize_t)size;
}

/* Strip --verbose (-v) and --quiet (-q) from argv (the options of every command), note --json, and
 * under --json keep the last error line written to stderr for cli_output_finish. */
void cli_output_begin(int *argc, char **argv)
{
    int k = 1, j = 1;
    for (; k < *argc && strcmp(argv[k], "--"); k++) {
        if (!strcmp(argv[k], "--verbose") || !strcmp(argv[k], "-v")) cli_verbosity = 1;
        else if (!strcmp(argv[k], "--quiet") || !strcmp(argv[k], "-q")) cli_verbosity = -1;
        else {
            cli_json_mode |= !strcmp(argv[k], "--json");
            argv[j++] = argv[k];
        }
    }
    while (k < *argc) argv[j++] = argv[k++];
    argv[j] = NULL;
    *argc = j;
    if (!cli_json_mode) return;
    cookie_io_functions_t io = {.write = tee_write};
    FILE *f = fopencookie(NULL, "w", io);
    if (!f) return;
    setvbuf(f, NULL, _IONBF, 0);
    stderr = f;
}

/* Under --json, a failure that printed no JSON prints {"error": its last message, "exit": rc}. */
int cli_output_finish(int rc)
{
    if (!cli_json_mode || !rc || rc == EXIT_INTERRUPTED || cli_json_done || cli_rank) return rc;
    const char *msg = last_error[0] ? last_error : "failed (no message)";
    if (!strncmp(msg, "ulam: ", 6)) msg += 6;
    printf("{");
    cli_json_string("error", msg, 0);
    printf("\"exit\": %d}\n", rc);
    fflush(stdout);
    return rc;
}

/* Check every --name in argv against longopts before getopt_long sees them (it would take an
 * abbreviation silently): an unknown one is a usage error naming the closest option.  0 or
 * EXIT_USAGE. */
int cli_check_options(const char *command, int argc, char **argv, const struct option *longopts)
{
    const char *names[256];
    int n = 0;
    for (; longopts[n].name && n < 256; n++) names[n] = longopts[n].name;
    for (int k = 1; k < argc && strcmp(argv[k], "--"); k++) {
        if (strncmp(argv[k], "--", 2)) continue;
        char name[128];
        snprintf(name, sizeof name, "%s", argv[k] + 2);
        char *eq = strchr(name, '=');
        if (eq) *eq = '\0';
        int i = cli_lookup(name, names, n);
        if (i >= 0) {
            k += longopts[i].has_arg == required_argument && !eq; /* its value may start with "--" */
            continue;
        }
        const char *s = ulam_options_suggest(name, names, n);
        return s ? cli_usage_error(command, "unknown option '--%s' (did you mean '--%s'?)", name, s)
                 : cli_usage_error(command, "unknown option '--%s'", name);
    }
    return 0;
}

/* Look value up among names[0..n) for option opt: its index, or -1 after a usage error that lists
 * the names (what) and the closest. */
int cli_choose(const char *command, const char *opt, const char *value, const char *const *names, int n,
               const char *what)
{
    int k = cli_lookup(value, names, n);
    if (k >= 0) return k;
    const char *s = ulam_options_suggest(value, names, n);
    if (s) cli_usage_error(command, "%s expects %s, got '%s' (did you mean '%s'?)", opt, what, value, s);
    else cli_usage_error(command, "%s expects %s, got '%s'", opt, what, value);
    return -1;
}

/* Index of word in names[0..n), or -1. */
int cli_lookup(const char *word, const char *const *names, int n)
{
    for (int k = 0; k < n; k++)
        if (!strcmp(word, names[k])) return k;
    return -1;
}

/* Print a usage error and return EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "ulam %s: ", command);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, " (see 'ulam %s --help')\n", command);
    va_end(ap);
    return EXIT_USAGE;
}

/* Print a bare JSON number (null when not finite). */
void cli_json_value(double v)
{
    ulam_json_number(stdout, NULL, v, 1);
}

/* Print a JSON member (ulam_json_number), noting that JSON was printed. */
void cli_json_number(const char *key, double v, int last)
{
    cli_json_done = 1;
    ulam_json_number(stdout, key, v, last);
}

/* Print a JSON string member (ulam_json_string), noting that JSON was printed. */
void cli_json_string(const char *key, const char *v, int last)
{
    cli_json_done = 1;
    ulam_json_string(stdout, key, v, last);
}

/* Nonzero when the interval was withheld because the scores are too small to square (a b far
 * below 1 that the solver could not rescale: a prepared file's, read lazily; src/stop.h). */
int cli_score_too_small(const ulam_walk_result *r)
{
    return r->estimate != 0 && fabs(r->estimate) < ULAM_SCORE_TINY && r->std_error == 0 && isnan(r->ci95[0]);
}

/* Print whether the --rel-err target was met, and when not why (one line; nothing without a target). */
void cli_print_rel_err(const ulam_walk_opts *o, const ulam_walk_result *r, int verbose)
{
    if (o->stop.rel_err > 0 && r->cut_stop)
        printf("rel-err         NOT met (target %.3g): %lld walks were cut at %lld steps and the cut's bias may be "
               "%.3g, more than a tenth of the target error: unreachable by more walks (raise --max-steps)\n",
               o->stop.rel_err, (long long)r->cut, (long long)o->stop.max_steps, r->cut_bound);
    else if (o->stop.rel_err > 0 && !isfinite(r->tail_bound) && r->estimate != 0)
        printf("rel-err         NOT met (target %.3g; no bound on a single score: no walk count can certify it)\n",
               o->stop.rel_err);
    else if (o->stop.rel_err > 0 && r->out_of_reach && !isfinite(r->ci95[0]) &&
             !(r->min_walks > (o->stop.max_walks > 0 ? (double)o->stop.max_walks : (double)ULAM_REL_ERR_CAP)))
        printf("rel-err         NOT met (target %.3g): %s, so no interval can be "
               "printed; stopped after %lld walks, over 1024 times the %.4g the rule asked for\n", o->stop.rel_err,
               cli_score_too_small(r) ? "the scores are too small to square in doubles (scale b up)" : "a score passed the certified range",
               (long long)r->walks, r->min_walks);
    else if (o->stop.rel_err > 0 && r->estimate == 0 && r->out_of_reach && r->min_walks > 0 && isfinite(r->min_walks))
        printf("rel-err         NOT met (target %.3g): no walk has scored in %lld; a walk scores at all with probability "
               "at most %.3g (certified from where it can go), so the rule asks for at least %.4g walks, %s: stopped "
               "early, %s\n", o->stop.rel_err, (long long)r->walks,
               1.0 / (1.0 + r->min_walks * o->stop.rel_err * o->stop.rel_err), r->min_walks,
               o->stop.max_walks > 0 ? "more than --walks" : "beyond the 1e9 cap",
               isfinite(r->ci95[0]) ? "the interval above" : "the estimate so far above");
    else if (o->stop.rel_err > 0 && r->fourth_finite != 1 && (verbose || !r->rel_err_met))
        printf("rel-err         %s (target %.3g; the certified second moment asks for %.4g walks at this estimate): "
               "scores are unbounded and rho(M4) is in [%.4g, %.4g], so the fourth moment is %s and the rule does "
               "not use the variance's own error bar\n", r->rel_err_met ? "met" : "NOT met", o->stop.rel_err, r->min_walks,
               r->rho4.lower, r->rho4.upper, r->fourth_finite == 0 ? "infinite" : "not certified finite");
    else if (o->stop.rel_err > 0 && r->min_walks > 0 && (verbose || !r->rel_err_met))
        printf("rel-err         %s (target %.3g; the rule asks for %.4g walks at this estimate and variance%s)\n",
               r->rel_err_met ? "met" : "NOT met", o->stop.rel_err, r->min_walks,
               !r->out_of_reach ? "" : o->stop.max_walks > 0 ? ", more than --walks: stopped early, the estimate so far above"
                                                        : ", beyond the 1e9 cap: stopped early, the estimate so far above");
    else if (o->stop.rel_err > 0)
        printf("rel-err         %s (target %.3g)\n", r->rel_err_met ? "met" : "NOT met", o->stop.rel_err);
}
