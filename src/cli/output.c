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

/* How --verbose and --quiet were spelt (NULL: not given): both is a usage error (cli_output_conflict). */
static const char *verbose_flag, *quiet_flag;

/* See cli.h. */
int cli_output_conflict(const char *command)
{
    if (!verbose_flag || !quiet_flag) return 0;
    return cli_usage_error(command, "%s and %s contradict each other: give one", verbose_flag, quiet_flag);
}

/* Strip --verbose (-v) and --quiet (-q) from argv (the options of every command), note --json, and
 * under --json keep the last error line written to stderr for cli_output_finish. */
void cli_output_begin(int *argc, char **argv)
{
    int k = 1, j = 1;
    for (; k < *argc && strcmp(argv[k], "--"); k++) {
        if (!strcmp(argv[k], "--verbose") || !strcmp(argv[k], "-v")) cli_verbosity = 1, verbose_flag = argv[k];
        else if (!strcmp(argv[k], "--quiet") || !strcmp(argv[k], "-q")) cli_verbosity = -1, quiet_flag = argv[k];
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

/* Options that may be given more than once (each adds one: points, luminaires). */
static const char *const repeatable[] = {"at", "luminaire"};

/* Spellings of one option (--damping is --pagerank). */
static const char *const aliases[][2] = {{"pagerank", "damping"}, {"kernel-exponent", "alpha"}};

/* The index among names[0..n) that stands for option i (its first spelling), or -1 when it may repeat. */
static int single_valued(const char *const *names, int n, int i)
{
    if (cli_lookup(names[i], repeatable, (int)(sizeof repeatable / sizeof *repeatable)) >= 0) return -1;
    for (size_t a = 0; a < sizeof aliases / sizeof *aliases; a++)
        for (int s = 0; s < 2; s++)
            if (!strcmp(names[i], aliases[a][s])) {
                int k = cli_lookup(aliases[a][0], names, n);
                return k >= 0 ? k : i;
            }
    return i;
}

/* Check every --name in argv against longopts before getopt_long sees them (it would take an
 * abbreviation silently): an unknown one is a usage error naming the closest option, and so is a
 * single-valued one given twice (getopt would keep the last silently: --index 7 --index 9).  0 or
 * EXIT_USAGE. */
int cli_check_options(const char *command, int argc, char **argv, const struct option *longopts)
{
    const char *names[256], *given[256] = {0}, *spelt[256]; /* given[i]: option i's first value, spelt as spelt[i] */
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
            if (longopts[i].has_arg != required_argument) continue;
            if (!eq && k + 1 >= argc) /* getopt would print its own line, then ours: one line instead (newuser18) */
                return cli_usage_error(command, "--%s needs a value (--%s VALUE)", names[i], names[i]);
            const char *value = eq ? strchr(argv[k], '=') + 1 : k + 1 < argc ? argv[k + 1] : "";
            k += !eq; /* its value may start with "--" */
            int first = single_valued(names, n, i);
            if (first < 0) continue;
            if (given[first])
                return cli_usage_error(command, "--%s given twice (--%s %s and --%s %s): it takes one value, give it once",
                                       names[first], spelt[first], given[first], name, value);
            given[first] = value, spelt[first] = names[i];
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

