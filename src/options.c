/* The options by name (include/ulam_options.h): one table of rows, option name -> field, type,
 * range and help line, read by the command line's parser and by Python's keyword arguments.
 * Adding an option is a row here. */
#include "ulam_options.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* What a row's field holds. */
enum { T_I64, T_SEED, T_INT, T_REAL, T_OPEN, T_ENUM };

static const char *const estimator_names[] = {"collision", "absorption", "expected"};
static const char *const mode_names[] = {"adjoint", "forward"};

/* One option: its name, the struct and field it sets, the field's type, its range (T_OPEN: the
 * open interval (lo, hi)), an enum's names and what a bad value should have been, its help line
 * (NULL: an old spelling, not listed). */
typedef struct {
    const char *name;
    int type, kind;
    size_t offset;
    double lo, hi; /* a real's range; an integer's is [ilo, ihi] */
    const char *const *names;
    int nnames;
    const char *what;
    const char *help;
    int64_t ilo, ihi;
} row;

#define W(f) ULAM_OPTIONS_WALK, offsetof(ulam_walk_opts, f)
#define O(f) ULAM_OPTIONS_OUTER, offsetof(ulam_outer_opts, f)
#define B(f) ULAM_OPTIONS_BIDIR, offsetof(ulam_bidir_opts, f)

static const row rows[] = {
    {"walks", T_I64, W(stop.max_walks), 0, 0, NULL, 0, NULL, "stop after N walks", 1, 1000000000000000},
    {"rel-err", T_REAL, W(stop.rel_err), 1e-12, 1.0, NULL, 0, NULL,
     "stop once the 95% interval's half-width is at most E |estimate|", 0, 0},
    {"time", T_REAL, W(stop.max_seconds), 1e-6, 1e9, NULL, 0, NULL, "stop after S seconds", 0, 0},
    {"seed", T_SEED, W(exec.seed), 0, 0, NULL, 0, NULL, "block q of walks uses stream (S, q)", 0, INT64_MAX},
    {"threads", T_INT, W(exec.threads), 0, 0, NULL, 0, NULL, "threads (default: all cores)", 1, 1024},
    {"continue", T_REAL, W(kernel.continue_q), 1e-9, 1 - 1e-12, NULL, 0, NULL,
     "continue with probability Q in every state ('analog': min(1, sum_j |M_ij|), the default)", 0, 0},
    {"kernel-exponent", T_REAL, W(kernel.kernel_alpha), 0.0, 1000.0, NULL, 0, NULL,
     "move to j with probability proportional to |M_ij|^A (default 1)", 0, 0},
    {"alpha", T_REAL, W(kernel.kernel_alpha), 0.0, 1000.0, NULL, 0, NULL, NULL, 0, 0},
    {"roulette", T_REAL, W(kernel.roulette), 1e-300, 1e300, NULL, 0, NULL, "Russian roulette below weight W", 0, 0},
    {"split", T_REAL, W(kernel.split), 1e-300, 1e300, NULL, 0, NULL, "split particles above weight W", 0, 0},
    {"max-steps", T_I64, W(stop.max_steps), 0, 0, NULL, 0, NULL, "cut walks longer than K steps", 1, INT64_MAX / 2},
    {"estimator", T_ENUM, W(estimator), 0, 0, estimator_names, 3, "collision, absorption or expected",
     "collision, absorption or expected", 0, 0},
    {"mode", T_ENUM, W(mode), 0, 0, mode_names, 2, "adjoint or forward",
     "adjoint (one unknown) or forward (every unknown)", 0, 0},
    {"tol", T_OPEN, O(tol), 0, 1, NULL, 0, "a residual reduction strictly between 0 and 1 (such as 1e-8)",
     "stop once the residual fell by this factor", 0, 0},
    {"max-iter", T_INT, O(max_iter), 0, 0, NULL, 0, NULL, "iteration cap", 1, 100000000},
    {"eps1", T_OPEN, O(eps1), 0, 1, NULL, 0, "a relative standard deviation strictly between 0 and 1 (such as 0.1)",
     "a correction's walks stop at this ||stderr||_1 / ||delta||_1", 0, 0},
    {"max-histories", T_I64, O(max_histories), 0, 0, NULL, 0, NULL, "walks a correction at most", 1, INT64_MAX / 2},
    {"stall", T_INT, O(stall), 0, 0, NULL, 0, NULL, "stop after this many iterations without progress", 1, 1000000},
    {"rmax", T_REAL, B(rmax), 1e-300, 1e300, NULL, 0, NULL, "push threshold (default: balanced against the walks)", 0, 0},
    {"min-value", T_REAL, B(min_value), 1e-300, 1e300, NULL, 0, NULL, "the smallest |x_t| the balance plans for", 0, 0},
    {"step-cost", T_REAL, B(step_cost), 1e-3, 1e6, NULL, 0, NULL, "a walk step's cost in push operations", 0, 0},
};
enum { NROWS = sizeof rows / sizeof rows[0] };

/* Fill err with status ULAM_EINVAL and the sentence fmt; ULAM_EINVAL. */
__attribute__((format(printf, 2, 3))) static int bad(ulam_error *err, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    *err = (ulam_error){.status = ULAM_EINVAL, .index = -1};
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return ULAM_EINVAL;
}

/* Parse an integer option value in [lo, hi]. */
int ulam_options_parse_int(const char *opt, const char *s, int64_t lo, int64_t hi, int64_t *out, ulam_error *err)
{
    if (!opt || !s || !out || !err) return ULAM_EINVAL;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end != s && (*end == 'e' || *end == 'E' || *end == '.')) { /* 1e12, 2.5e6: whole numbers */
        double d = strtod(s, &end);
        int whole = !*end && d == floor(d) && fabs(d) <= 9007199254740992.0; /* 2^53: exact */
        v = whole ? (long long)d : v, errno = whole ? 0 : ERANGE;
    }
    if (end == s || *end || errno == ERANGE || v < lo || v > hi)
        return bad(err, "%s expects an integer from %lld to %lld%s, got '%s'", opt, (long long)lo, (long long)hi,
                   lo == 1 && v == 0 && (strstr(opt, "index") || strstr(opt, "source") || strstr(opt, "patch"))
                       ? " (1-based, as in Matrix Market files)" : "", s);
    *out = v;
    return ULAM_OK;
}

/* Parse a finite real option value in [lo, hi]. */
int ulam_options_parse_real(const char *opt, const char *s, double lo, double hi, double *out, ulam_error *err)
{
    if (!opt || !s || !out || !err) return ULAM_EINVAL;
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v) || v < lo || v > hi)
        return bad(err, "%s expects a number from %g to %g, got '%s'", opt, lo, hi, s);
    *out = v;
    return ULAM_OK;
}

/* Levenshtein distance of a and b (both short), capped at 99. */
static int distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 60 || lb > 60) return 99;
    int d[61][61];
    for (size_t i = 0; i <= la; i++) d[i][0] = (int)i;
    for (size_t j = 0; j <= lb; j++) d[0][j] = (int)j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            int sub = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]), del = d[i - 1][j] + 1, ins = d[i][j - 1] + 1;
            d[i][j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
        }
    return d[la][lb];
}

/* The closest of names to word, or NULL. */
const char *ulam_options_suggest(const char *word, const char *const *names, int n)
{
    if (!word || !names) return NULL;
    const char *best = NULL;
    int bd = 99, len = (int)strlen(word);
    for (int k = 0; k < n; k++) {
        int d = len >= 3 && !strncmp(names[k], word, (size_t)len) ? 0 : distance(word, names[k]);
        if (d < bd) bd = d, best = names[k];
    }
    return best && bd <= (len + 2) / 3 ? best : NULL;
}

/* Set the field of row r in the struct at base from value; ULAM_OK or ULAM_EINVAL (err). */
static int set(const row *r, char *base, const char *value, ulam_error *err)
{
    char opt[80];
    snprintf(opt, sizeof opt, "--%s", r->name);
    void *f = base + r->offset;
    int64_t v;
    double x;
    int status = ULAM_OK;
    switch (r->type) {
    case T_I64:
    case T_SEED:
    case T_INT:
        if (r->type == T_I64 && !strcmp(r->name, "walks") && (x = strtod(value, NULL)) > 1e15 && isfinite(x))
            return bad(err, "--walks %s: more than 10^15 walks would take years (at 10^7 walks a second, about %.3g "
                       "years): bound the run with --rel-err E or --time S", value, x / 1e7 / 31557600);
        if ((status = ulam_options_parse_int(opt, value, r->ilo, r->ihi, &v, err))) return status;
        if (r->type == T_I64) *(int64_t *)f = v;
        else if (r->type == T_SEED) *(uint64_t *)f = (uint64_t)v;
        else *(int *)f = (int)v;
        return ULAM_OK;
    case T_REAL:
        if (!strcmp(r->name, "continue") && !strcmp(value, "analog"))
            return *(double *)f = 0.0, ULAM_OK; /* min(1, S_i) */
        if ((status = ulam_options_parse_real(opt, value, r->lo, r->hi, &x, err))) return status;
        *(double *)f = x;
        return ULAM_OK;
    case T_OPEN: {
        char *end;
        x = strtod(value, &end);
        if (end == value || *end || !(x > r->lo && x < r->hi)) return bad(err, "%s expects %s, got '%s'", opt, r->what, value);
        *(double *)f = x;
        return ULAM_OK;
    }
    default: /* T_ENUM */
        for (int k = 0; k < r->nnames; k++)
            if (!strcmp(value, r->names[k])) return *(int *)f = k, ULAM_OK;
        const char *near = ulam_options_suggest(value, r->names, r->nnames);
        if (near) return bad(err, "%s expects %s, got '%s' (did you mean '%s'?)", opt, r->what, value, near);
        return bad(err, "%s expects %s, got '%s'", opt, r->what, value);
    }
}

/* Set option name of opts (kind's struct); see ulam_options.h. */
int ulam_options_set(int kind, void *opts, const char *name, const char *value, ulam_error *err)
{
    if (!opts || !name || !value || !err || kind < ULAM_OPTIONS_WALK || kind > ULAM_OPTIONS_BIDIR) {
        if (err) *err = (ulam_error){.status = ULAM_EINVAL, .index = -1, .msg = "options, a name and a value"};
        return ULAM_EINVAL;
    }
    ulam_walk_opts *walk = kind == ULAM_OPTIONS_OUTER   ? &((ulam_outer_opts *)opts)->walk
                           : kind == ULAM_OPTIONS_BIDIR ? &((ulam_bidir_opts *)opts)->walk
                                                        : (ulam_walk_opts *)opts;
    char key[64];
    size_t len = strlen(name);
    if (len >= sizeof key) len = sizeof key - 1;
    for (size_t k = 0; k < len; k++) key[k] = name[k] == '_' ? '-' : name[k];
    key[len] = '\0';
    for (int pass = kind == ULAM_OPTIONS_WALK; pass < 2; pass++) { /* the kind's own rows, then the walks' */
        int want = pass ? ULAM_OPTIONS_WALK : kind;
        const char *k = want == ULAM_OPTIONS_WALK && !strcmp(key, "tol") ? "rel-err" : key; /* the iterations' spelling */
        for (int i = 0; i < NROWS; i++)
            if (rows[i].kind == want && !strcmp(rows[i].name, k)) return set(&rows[i], pass ? (char *)walk : opts, value, err);
    }
    *err = (ulam_error){.status = ULAM_ENOTFOUND, .index = -1};
    snprintf(err->msg, sizeof err->msg, "an option's name, got '%s'", name);
    return ULAM_ENOTFOUND;
}

