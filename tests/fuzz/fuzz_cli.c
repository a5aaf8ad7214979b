/* libFuzzer target: the command line end to end.  Each input makes a system of 2 to 50 states
 * (its entries, signs, row sums and magnitudes from the input: mostly convergent, sometimes
 * not, sometimes entries spanning hundreds of orders of magnitude) and a set of options for
 * `ulam solve` or `ulam info` (modes, estimators, methods, budgets, kernels, windows, and now and
 * then a malformed value or an unknown option), runs the ulam executable on them, and demands
 *   - a normal exit: no signal death, no hang (every run is bounded by --time);
 *   - a refusal to be clear: a known exit code (2, 3, 4, 10 + a status), a message on stderr
 *     that is not "error: success", and --json's error object with that exit code;
 *   - an answer (exit 0) to be about the unknown asked (its index) and, when it prints an
 *     interval, to hold the direct solve's x_I within 6 standard errors (an honest run misses
 *     one time in 5e8: a miss is a wrong answer, not bad luck) -- unless the options asked for
 *     an interval the guards do not certify (--assume-finite-variance, --force).
 * The executable's path is ULAM_CLI (the build's, compiled in).  Built with -Dfuzz=true (clang);
 * the same entry point replays the committed corpus in the normal test suite (replay.c). */
#include "ulam.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef ULAM_CLI
#define ULAM_CLI "ulam"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The input as a stream of bytes (zeros past its end). */
typedef struct {
    const uint8_t *p;
    size_t n, at;
} bytes;

/* The next byte. */
static unsigned next(bytes *in)
{
    return in->at < in->n ? in->p[in->at++] : 0u;
}

/* A number in [0, 1) from two bytes. */
static double unit(bytes *in)
{
    unsigned hi = next(in), lo = next(in);
    return (double)(hi << 8 | lo) / 65536.0;
}

/* Write M (n x n, nnz entries) and b as Matrix Market files in dir; 0 on success. */
static int write_system(const char *dir, int n, int nnz, const int *row, const int *col, const double *val,
                        const double *b)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/m.mtx", dir);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fprintf(f, "%%%%MatrixMarket matrix coordinate real general\n%d %d %d\n", n, n, nnz);
    for (int k = 0; k < nnz; k++) fprintf(f, "%d %d %.17g\n", row[k] + 1, col[k] + 1, val[k]);
    if (fclose(f)) return -1;
    snprintf(path, sizeof path, "%s/b.mtx", dir);
    if (!(f = fopen(path, "w"))) return -1;
    fprintf(f, "%%%%MatrixMarket matrix array real general\n%d 1\n", n);
    for (int i = 0; i < n; i++) fprintf(f, "%.17g\n", b[i]);
    return fclose(f) ? -1 : 0;
}

/* Run ulam with argv, stdout into out (cap bytes, NUL-terminated), stderr into err; the wait
 * status, or -1 when it could not be run. */
static int run(char *const *argv, char *out, size_t cap, char *err, size_t ecap)
{
    int po[2], pe[2];
    if (pipe(po)) return -1;
    if (pipe(pe)) {
        close(po[0]), close(po[1]);
        return -1;
    }
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        dup2(po[1], 1), dup2(pe[1], 2);
        close(po[0]), close(po[1]), close(pe[0]), close(pe[1]);
        execv(argv[0], argv);
        _exit(127);
    }
    close(po[1]), close(pe[1]);
    size_t len[2] = {0, 0}, caps[2] = {cap, ecap};
    char *buf[2] = {out, err}, sink[4096];
    struct pollfd fds[2] = {{.fd = po[0], .events = POLLIN}, {.fd = pe[0], .events = POLLIN}};
    while (fds[0].fd >= 0 || fds[1].fd >= 0) { /* both pipes to their end: a full one would block the child */
        if (poll(fds, 2, -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        for (int k = 0; k < 2; k++) {
            if (fds[k].fd < 0 || !fds[k].revents) continue;
            int room = len[k] + 1 < caps[k];
            ssize_t got = room ? read(fds[k].fd, buf[k] + len[k], caps[k] - 1 - len[k]) : read(fds[k].fd, sink, sizeof sink);
            if (got > 0 && room) len[k] += (size_t)got;
            if (got == 0 || (got < 0 && errno != EINTR)) close(fds[k].fd), fds[k].fd = -1;
        }
    }
    size_t no = len[0], ne = len[1];
    out[no] = '\0', err[ne] = '\0';
    int st;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR) return -1;
    return st;
}

/* The number after "key": in JSON text (NAN when absent or null). */
static double json_number(const char *json, const char *key)
{
    char k[64];
    snprintf(k, sizeof k, "\"%s\": ", key);
    const char *p = strstr(json, k);
    if (!p) return NAN;
    p += strlen(k);
    if (*p == '[') p++;
    char *end;
    double v = strtod(p, &end);
    return end == p ? NAN : v;
}

/* The second number of "key": [a, b] (NAN when absent or null). */
static double json_second(const char *json, const char *key)
{
    char k[64];
    snprintf(k, sizeof k, "\"%s\": [", key);
    const char *p = strstr(json, k);
    if (!p || !(p = strchr(p + strlen(k), ','))) return NAN;
    char *end;
    double v = strtod(p + 1, &end);
    return end == p + 1 ? NAN : v;
}

/* Stop the fuzzer with what failed (libFuzzer keeps the input). */
static void fail(const char *what, char *const *argv, const char *out, const char *err)
{
    fprintf(stderr, "fuzz_cli: %s\n  ulam", what);
    for (int k = 1; argv[k]; k++) fprintf(stderr, " %s", argv[k]);
    fprintf(stderr, "\n  stdout: %.600s\n  stderr: %.600s\n", out, err);
    abort();
}

/* One option, chosen and valued from the input, onto argv (args' storage); 1 when it asks for an
 * interval the guards do not certify. */
static int option(bytes *in, int n, char **argv, int *argc, char (*store)[32], int *ns)
{
    static const char *const modes[] = {"adjoint", "forward"};
    static const char *const estimators[] = {"collision", "absorption", "expected", "bogus"};
    static const char *const methods[] = {"auto", "walks", "walks", "auto"};
    unsigned k = next(in) % 18;
    char *v = store[(*ns)++];
    switch (k) {
    case 0: argv[(*argc)++] = "--mode", argv[(*argc)++] = (char *)modes[next(in) % 2]; break;
    case 1: argv[(*argc)++] = "--estimator", argv[(*argc)++] = (char *)estimators[next(in) % 4]; break;
    case 2: snprintf(v, 32, "%u", 1u + (next(in) << 8 | next(in)) % 20000u), argv[(*argc)++] = "--walks", argv[(*argc)++] = v; break;
    case 3: snprintf(v, 32, "%.3g", 0.01 + unit(in)), argv[(*argc)++] = "--rel-err", argv[(*argc)++] = v; break;
    case 4: snprintf(v, 32, "%.3g", unit(in)), argv[(*argc)++] = "--continue", argv[(*argc)++] = v; break;
    case 5: snprintf(v, 32, "%.3g", 3.0 * unit(in)), argv[(*argc)++] = "--kernel-exponent", argv[(*argc)++] = v; break;
    case 6: snprintf(v, 32, "%.3g", 2.0 * unit(in)), argv[(*argc)++] = "--roulette", argv[(*argc)++] = v; break;
    case 7: snprintf(v, 32, "%.3g", 0.5 + 4.0 * unit(in)), argv[(*argc)++] = "--split", argv[(*argc)++] = v; break;
    case 8: snprintf(v, 32, "%u", 1u + next(in)), argv[(*argc)++] = "--max-steps", argv[(*argc)++] = v; break;
    case 9: snprintf(v, 32, "%u", next(in)), argv[(*argc)++] = "--seed", argv[(*argc)++] = v; break;
    case 10: argv[(*argc)++] = "--threads", argv[(*argc)++] = next(in) & 1 ? "2" : "1"; break;
    case 11: argv[(*argc)++] = "--method", argv[(*argc)++] = (char *)methods[next(in) % 4]; break;
    case 12: argv[(*argc)++] = "--assume-finite-variance"; return 1;
    case 13: argv[(*argc)++] = "--force"; return 1;
    case 14: argv[(*argc)++] = "--check"; break;
    case 15: /* a malformed value: must be a usage error */
        snprintf(v, 32, "%s", (const char *[]){"-1", "nan", "1e999", "", "0x", "12abc"}[next(in) % 6]);
        argv[(*argc)++] = (char *)(const char *[]){"--walks", "--rel-err", "--continue", "--seed"}[next(in) % 4];
        argv[(*argc)++] = v;
        break;
    case 16: argv[(*argc)++] = (char *)(const char *[]){"--frobnicate", "--walk", "-x", "--index"}[next(in) % 4]; break;
    default: snprintf(v, 32, "%d", 1 + (int)(next(in) % (unsigned)n)), argv[(*argc)++] = "--index", argv[(*argc)++] = v; break;
    }
    return 0;
}

/* The folder the systems are written to (made once, removed at exit). */
static char dir[4096];

/* Remove the folder and its two files. */
static void cleanup(void)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/m.mtx", dir), remove(path);
    snprintf(path, sizeof path, "%s/b.mtx", dir), remove(path);
    rmdir(dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!dir[0]) {
        const char *tmp = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/ulam-fuzz-cli-XXXXXX", tmp && *tmp ? tmp : P_tmpdir);
        if (!mkdtemp(dir)) return dir[0] = 0, 0;
        atexit(cleanup);
    }
    bytes in = {data, size, 0};
    int n = 2 + (int)(next(&in) % 49u);
    unsigned shape = next(&in);
    double target = 0.2 + 0.85 * unit(&in); /* row sums of |M|: past 1 now and then */
    int signed_m = shape & 1, wild = (shape & 6) == 6;  /* wild: magnitudes from 1e-200 to 1e200 */
    int per = 1 + (int)(next(&in) % 6u);
    int *row = malloc((size_t)(n * per) * sizeof *row), *col = malloc((size_t)(n * per) * sizeof *col);
    double *val = malloc((size_t)(n * per) * sizeof *val), *b = malloc((size_t)n * sizeof *b);
    double *x = malloc((size_t)n * sizeof *x);
    char *out = malloc(1 << 20), *err = malloc(1 << 16);
    if (!row || !col || !val || !b || !x || !out || !err) goto done;
    int nnz = 0;
    for (int i = 0; i < n; i++) {
        double sum = 0;
        int first = nnz;
        for (int k = 0; k < per; k++) {
            int j = (int)((unsigned)(i + 1 + k * 7 + (int)next(&in)) % (unsigned)n);
            int dup = 0;
            for (int q = first; q < nnz; q++) dup |= col[q] == j;
            if (dup) continue;
            double w = 0.05 + unit(&in);
            if (signed_m && (next(&in) & 1)) w = -w;
            row[nnz] = i, col[nnz] = j, val[nnz++] = w, sum += fabs(w);
        }
        for (int q = first; q < nnz; q++) val[q] *= target / sum;
        if (wild && nnz > first) val[first] *= pow(10.0, (double)((int)(next(&in) % 41u) - 20) * 10.0);
        b[i] = (next(&in) & 3) ? 1.0 + unit(&in) : 0.0;
    }
    if (write_system(dir, n, nnz, row, col, val, b)) goto done;
    char mpath[128], bpath[128];
    snprintf(mpath, sizeof mpath, "%s/m.mtx", dir), snprintf(bpath, sizeof bpath, "%s/b.mtx", dir);
    ulam_csr *M = NULL;
    int exact = !ulam_mm_read_matrix(mpath, &M, NULL) && !ulam_direct_solve(M, b, x, 0, NULL, NULL);
    ulam_csr_free(M);
    char *argv[64], store[24][32];
    int argc = 0, ns = 0, uncertified = 0, info = (shape & 0x30) == 0x30;
    argv[argc++] = ULAM_CLI, argv[argc++] = info ? "info" : "solve", argv[argc++] = mpath;
    if (!info) argv[argc++] = "--rhs", argv[argc++] = bpath;
    int index = 1 + (int)(next(&in) % (unsigned)n);
    snprintf(store[ns], 32, "%d", index);
    if (!info) argv[argc++] = "--index", argv[argc++] = store[ns++];
    if (!info) argv[argc++] = "--walks", argv[argc++] = "20000"; /* a budget the options may change */
    for (int k = 0, nopt = (int)(next(&in) % 6u); k < nopt && argc < 52 && ns < 20; k++) {
        int before = argc;
        uncertified |= option(&in, n, argv, &argc, store, &ns);
        if (argc - before == 2 && !strcmp(argv[before], "--index")) index = atoi(argv[before + 1]); /* the last counts */
    }
    argv[argc++] = "--json", argv[argc++] = "--time", argv[argc++] = "2"; /* no run is longer */
    argv[argc] = NULL;
    if (getenv("ULAM_FUZZ_CLI_VERBOSE")) { /* what each input runs */
        for (int k = 1; argv[k]; k++) fprintf(stderr, "%s%s", k > 1 ? " " : "fuzz_cli: ulam ", argv[k]);
        fputc('\n', stderr);
    }
    int st = run(argv, out, 1 << 20, err, 1 << 16);
    if (st < 0) goto done;
    if (WIFSIGNALED(st)) fail("killed by a signal", argv, out, err);
    int rc = WEXITSTATUS(st);
    if (strstr(err, "error: success")) fail("'error: success'", argv, out, err);
    if (strstr(err, "Sanitizer") || strstr(err, "runtime error:")) /* an instrumented ulam's report */
        fail("a sanitizer report", argv, out, err);
    int rel_err = 0; /* a well-formed --rel-err asked: exit 5 (target not met) is then an answer */
    for (int k = 1; argv[k] && argv[k + 1]; k++)
        if (!strcmp(argv[k], "--rel-err") && strtod(argv[k + 1], NULL) > 0) rel_err = 1;
    if (rc == 5 && !rel_err) fail("exit 5 (target not met) with no --rel-err asked", argv, out, err);
    if (rc == 5 && !strstr(out, "\"rel_err_met\": false")) fail("exit 5 with no \"rel_err_met\": false", argv, out, err);
    if (rc != 0 && rc != 5) {
        int known = rc == 2 || rc == 3 || rc == 4 || (rc >= 11 && rc <= 37);
        if (!known) fail("an unknown exit code", argv, out, err);
        char want[32];
        snprintf(want, sizeof want, "\"exit\": %d}", rc);
        if (!strstr(err, "ulam") || strncmp(out, "{\"error\": \"", 11) || !strstr(out, want))
            fail("a refusal with no message (on stderr and as --json's error object)", argv, out, err);
        goto done;
    }
    if (info) goto done;
    double idx = json_number(out, "index"), est = json_number(out, "estimate"), se = json_number(out, "stderr");
    double lo = json_number(out, "ci95"), hi = json_second(out, "ci95");
    if (idx != index) fail("an answer about another unknown", argv, out, err);
    if (exact && !uncertified && isfinite(lo) && isfinite(hi)) {
        double tol = 1e-9 * (fabs(x[index - 1]) + 1.0), half = isfinite(se) ? 6.0 * se : 0.0;
        if (!(x[index - 1] >= fmin(lo, est - half) - tol && x[index - 1] <= fmax(hi, est + half) + tol))
            fail("an interval (widened to 6 standard errors) that misses the direct solve", argv, out, err);
    }
done:
    free(row), free(col), free(val), free(b), free(x), free(out), free(err);
    return 0;
}
