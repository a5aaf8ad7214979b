/* Shared pieces of the command-line tool. */
#include "cli.h"
#include "ulam_load.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>

const char *const cli_mode_names[2] = {"adjoint", "forward"};
const char *const cli_estimator_names[3] = {"collision", "absorption", "expected"};

volatile int cli_interrupted;
const ulam_share *cli_share;
double cli_started;
int cli_direct_force = -1;

/* The walks' share of a --time budget. */
double cli_time_left(double budget)
{
    if (!(budget > 0)) return budget;
    double left = budget - (ulam_now() - cli_started);
    return left > 1e-6 ? left : 1e-6;
}

/* Whether envp holds a variable called name. */
static int env_has(char **envp, const char *name)
{
    size_t len = strlen(name);
    for (char **e = envp; e && *e; e++)
        if (!strncmp(*e, name, len) && (*e)[len] == '=') return 1;
    return 0;
}

/* Passive waiting for OpenMP's and OpenBLAS's threads unless the user chose (see cli.h).  Both
 * libraries read the environment in their initializers, before main, and a setenv here would be
 * undone (libc's own initializer, which runs after .preinit_array, sets environ back to envp), so
 * the process runs itself again once with the variables added.  From .preinit_array, before any
 * shared library's initializer, that first image starts no thread and costs only its mapping: a
 * re-exec from main cost a second full start (ulam --version 43.6 ms of CPU). */
static void passive_threads(int argc, char **argv, char **envp)
{
    (void)argc;
    int omp = !env_has(envp, "OMP_WAIT_POLICY") && !env_has(envp, "GOMP_SPINCOUNT");
    int blas = !env_has(envp, "OPENBLAS_THREAD_TIMEOUT") && !env_has(envp, "GOTO_THREAD_TIMEOUT");
    if (!omp && !blas) return;
    size_t n = 0;
    while (envp && envp[n]) n++;
    char *env[n + 3];
    for (size_t k = 0; k < n; k++) env[k] = envp[k];
    /* OpenBLAS's server threads spin 2^28 cycles (about 0.1 s) after they start and after each call
     * before they sleep; 2^4 makes them sleep at once (a dense solve wakes them as before). */
    if (omp) env[n++] = "OMP_WAIT_POLICY=PASSIVE";
    if (blas) env[n++] = "OPENBLAS_THREAD_TIMEOUT=4";
    env[n] = NULL;
    /* the file itself, not /proc/self/exe: the process keeps its name ("ulam", not "exe") */
    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0 || len >= (ssize_t)sizeof self - 1) return;
    self[len] = '\0';
    execve(self, argv, env); /* returns only on failure (the file moved or deleted): run on as we are */
}
__attribute__((section(".preinit_array"), used)) static void (*const cli_preinit)(int, char **, char **) =
    passive_threads;

/* The temporary files of the outputs being written (ulam_outfile's NAME.tmp.XXXXXX), removed by
 * the signal handlers: one registry for every command.  Entries are set and cleared with the
 * signals blocked, so a handler sees each whole. */
enum { CLI_TMP_MAX = 8 };
static const char *volatile cli_tmps[CLI_TMP_MAX];

/* Remove every registered temporary file (async-signal-safe: unlink only). */
static void remove_tmps(void)
{
    for (int k = 0; k < CLI_TMP_MAX; k++)
        if (cli_tmps[k]) unlink(cli_tmps[k]);
}

/* The thread that blocks the signals around the registry's updates (the main thread).  A signal
 * the kernel delivers to another thread (OpenMP's workers, --check's) is sent on to it, so a
 * handler never reads the registry while the main thread is between forgetting a temporary file
 * and renaming it (found by check_signals: a study left question.txt.tmp 1 run in 4).  The
 * walks' first SIGINT only sets a flag and is taken where it lands: sent on, it could merge
 * with a second one pending on the main thread and be lost (check_second_interrupt hung). */
static pthread_t cli_main_thread;

/* 1 when sig was sent on to the main thread (the caller returns), 0 on the main thread. */
static int forwarded(int sig)
{
    if (pthread_equal(pthread_self(), cli_main_thread)) return 0;
    pthread_kill(cli_main_thread, sig); /* async-signal-safe (POSIX.1-2008) */
    return 1;
}

/* SIGINT, SIGTERM, SIGHUP outside the walks: remove the temporary files, then die of the signal
 * as the default action would (the exit status says which). */
static void on_fatal(int sig)
{
    if (forwarded(sig)) return;
    remove_tmps();
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Install sig's handler h (SA_RESTART: a write blocked on a full pipe is restarted). */
static void catch(int sig, void (*h)(int))
{
    struct sigaction sa = {.sa_handler = h, .sa_flags = SA_RESTART};
    sigemptyset(&sa.sa_mask);
    sigaction(sig, &sa, NULL);
}

/* The mapped prepared files (cli_map_register): a SIGBUS inside one is that file shrinking. */
enum { CLI_MAPS = 8 };
static struct {
    const char *path;
    const char *addr;
    size_t bytes;
} cli_maps[CLI_MAPS];

/* Write s to stderr from a signal handler (async-signal-safe). */
static void say(const char *s)
{
    for (size_t n = strlen(s); n;) {
        ssize_t w = write(2, s, n);
        if (w <= 0) return;
        s += w, n -= (size_t)w;
    }
}

/* SIGBUS: a read of a mapped prepared file past its end, which shrank under ulam (truncated, or
 * replaced in place by cp): say which file, remove the temporary files and exit with ULAM_EIO's
 * code, nothing printed from it.  Any other SIGBUS dies as the default action would. */
static void on_bus(int sig, siginfo_t *si, void *ctx)
{
    (void)ctx;
    const char *a = si ? (const char *)si->si_addr : NULL;
    for (int k = 0; a && k < CLI_MAPS; k++)
        if (cli_maps[k].path && a >= cli_maps[k].addr && a < cli_maps[k].addr + cli_maps[k].bytes) {
            say("ulam: "), say(cli_maps[k].path);
            say(": error: file cannot be opened, read or written: expected a prepared file that stays whole while "
                "in use (it shrank under ulam: truncated, or replaced in place; replace it by renaming a new file "
                "over it)\n");
            remove_tmps();
            _exit(cli_exit_code(ULAM_EIO));
        }
    signal(sig, SIG_DFL);
}

/* Remember (on 1) or forget (on 0) the mapping of s, read from path, for on_bus. */
void cli_map_register(const ulam_system *s, const char *path, int on)
{
    ulam_system_info si;
    ulam_system_get_info(s, &si);
    const void *addr = si.map;
    size_t bytes = si.map_bytes;
    if (!addr) return;
    for (int k = 0; k < CLI_MAPS; k++)
        if (on ? !cli_maps[k].path : cli_maps[k].addr == addr) {
            cli_maps[k].addr = addr, cli_maps[k].bytes = bytes;
            cli_maps[k].path = on ? path : NULL;
            return;
        }
}

/* Remove the temporary files on SIGINT, SIGTERM and SIGHUP, in every phase; report SIGBUS in a
 * mapped prepared file. */
void cli_signals_init(void)
{
    cli_main_thread = pthread_self();
    catch(SIGINT, on_fatal), catch(SIGTERM, on_fatal), catch(SIGHUP, on_fatal);
    struct sigaction sa = {.sa_sigaction = on_bus, .sa_flags = SA_SIGINFO};
    sigemptyset(&sa.sa_mask);
    sigaction(SIGBUS, &sa, NULL);
}

/* SIGINT (and SIGTERM under MPI, which mpirun sends every rank on Ctrl-C): the first asks the
 * walks to stop (every rank stops at the same round), the second removes the temporary files and
 * exits at once. */
static void on_sigint(int sig)
{
    if (!cli_interrupted) { /* the first, on whichever thread took it: only a flag */
        cli_interrupted = 1;
        return;
    }
    if (forwarded(sig)) return; /* the second reads the registry: on the main thread */
    remove_tmps();
    _exit(EXIT_INTERRUPTED);
}

/* Catch SIGINT (and SIGTERM under MPI) for the walks; a write blocked on a full pipe is restarted
 * after the first. */
void cli_catch_sigint(void)
{
    catch(SIGINT, on_sigint);
    if (cli_share) catch(SIGTERM, on_sigint);
    /* test hook (tests/cli_test.py, interrupt_when_ready): ULAM_TEST_STOP_AT_WALKS=1 stops the
       process with SIGSTOP the first time the walks' handler is in force */
    static int armed;
    if (getenv("ULAM_TEST_STOP_AT_WALKS") && !armed++) raise(SIGSTOP);
}

/* Back to the handlers of cli_signals_init. */
void cli_release_sigint(void)
{
    catch(SIGINT, on_fatal), catch(SIGTERM, on_fatal);
}

/* Block (how SIG_BLOCK) or restore the signals whose handlers read the registry. */
static void block_signals(sigset_t *old)
{
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, SIGINT), sigaddset(&s, SIGTERM), sigaddset(&s, SIGHUP);
    sigprocmask(SIG_BLOCK, &s, old);
}

/* Register (on 1) or forget (on 0) the temporary name tmp. */
static void registry(const char *tmp, int on)
{
    for (int k = 0; tmp && k < CLI_TMP_MAX; k++)
        if (on ? !cli_tmps[k] : cli_tmps[k] == tmp) {
            cli_tmps[k] = on ? tmp : NULL;
            return;
        }
}

/* ulam_outfile_open, its temporary file registered for removal on a signal. */
int cli_outfile_open(ulam_outfile *o, const char *path)
{
    sigset_t old;
    block_signals(&old);
    int status = ulam_outfile_open(o, path);
    if (!status) registry(o->tmp, 1);
    sigprocmask(SIG_SETMASK, &old, NULL);
    /* test hook (tests/cli_test.py, check_signals): ULAM_TEST_STOP_AT_TMP=k stops the process with
       SIGSTOP once its k-th temporary file exists, so a test signals it in that phase without
       waiting on a clock */
    static int opened;
    const char *stop = getenv("ULAM_TEST_STOP_AT_TMP");
    if (!status && stop && atoi(stop) == ++opened) raise(SIGSTOP);
    return status;
}

/* ulam_outfile_commit_all of k files, their temporary files forgotten (errno kept). */
int cli_outfile_commit_all(ulam_outfile *o, int k)
{
    sigset_t old;
    block_signals(&old);
    for (int j = 0; j < k; j++) registry(o[j].tmp, 0);
    int status = ulam_outfile_commit_all(o, k), e = errno;
    sigprocmask(SIG_SETMASK, &old, NULL);
    errno = e;
    return status;
}

/* ulam_outfile_commit, its temporary file forgotten (errno kept). */
int cli_outfile_commit(ulam_outfile *o)
{
    return cli_outfile_commit_all(o, 1);
}

/* ulam_outfile_abort, its temporary file forgotten. */
void cli_outfile_abort(ulam_outfile *o)
{
    sigset_t old;
    block_signals(&old);
    registry(o->tmp, 0);
    ulam_outfile_abort(o);
    sigprocmask(SIG_SETMASK, &old, NULL);
}

/* Hold (on 1) SIGINT, SIGTERM and SIGHUP until released (on 0): around a short write whose
 * temporary file the library makes itself (a PNG), so a signal ends the process after it. */
void cli_hold_signals(int on)
{
    static sigset_t old;
    if (on) block_signals(&old);
    else sigprocmask(SIG_SETMASK, &old, NULL);
}

/* ulam_system_write through a registered temporary file; a status. */
int cli_system_write(const char *path, const ulam_system_desc *d)
{
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status && (status = ulam_system_write_file(o.f, d))) cli_outfile_abort(&o);
    return status ? status : cli_outfile_commit(&o);
}

/* ulam_mm_write_vector through a registered temporary file; a status (errno says why for EIO). */
int cli_write_vector(const char *path, const double *x, int64_t n, const char *comment)
{
    ulam_outfile o;
    int status = cli_outfile_open(&o, path);
    if (!status && (status = ulam_mm_write_vector_file(o.f, x, n, comment))) {
        int e = errno;
        cli_outfile_abort(&o);
        errno = e;
        return status;
    }
    return status ? status : cli_outfile_commit(&o);
}

/* The exit code for a library status. */
int cli_exit_code(int status)
{
    return status == ULAM_OK ? 0 : EXIT_STATUS_BASE + status;
}

/* Print a located error and return its exit code. */
int cli_report(const char *file, const ulam_error *err)
{
    fprintf(stderr, "ulam: ");
    if (err->file[0]) file = err->file;
    if (file && err->line > 0) fprintf(stderr, "%s:%ld: ", file, err->line);
    else if (file) fprintf(stderr, "%s: ", file);
    fprintf(stderr, "error: %s", ulam_strerror(err->status));
    if (err->msg[0]) fprintf(stderr, ": expected %s", err->msg);
    fputc('\n', stderr);
    return cli_exit_code(err->status);
}

/* The usage error for an unknown --method, its names from the library's table (cli.h). */
int cli_method_error(const char *got)
{
    char list[512] = "auto";
    for (int k = 0; k < ULAM_NMETHODS; k++) {
        size_t n = strlen(list);
        snprintf(list + n, sizeof list - n, "%s%s%s", k == ULAM_NMETHODS - 1 ? " or " : ", ", ulam_method_name(k),
                 k == ULAM_METHOD_BIDIRECTIONAL ? " (with --source or a sparse b)" : "");
    }
    const char *names[ULAM_NMETHODS + 1] = {"auto"};
    for (int k = 0; k < ULAM_NMETHODS; k++) names[k + 1] = ulam_method_name(k);
    cli_choose("solve", "--method", got, names, ULAM_NMETHODS + 1, list); /* prints the error, did you mean */
    return EXIT_USAGE;
}

/* Report a failed write of path with errno's message. */
int cli_report_write(const char *path, int status, int errnum)
{
    ulam_error err = {.status = status, .line = 0, .index = -1};
    if (status == ULAM_EIO && errnum)
        snprintf(err.msg, sizeof err.msg, "a writable output file (%s)", strerror(errnum));
    else if (status == ULAM_ENONFINITE)
        snprintf(err.msg, sizeof err.msg, "finite values to write (nothing was written)");
    else
        snprintf(err.msg, sizeof err.msg, "a writable output file");
    return cli_report(path, &err);
}

/* Report an input file that cannot be opened or read (errno's message errnum): exit 13, as a missing matrix. */
int cli_report_read(const char *path, const char *what, int errnum)
{
    ulam_error err = {.status = ULAM_EIO, .line = 0, .index = -1};
    snprintf(err.msg, sizeof err.msg, "a readable %s (%s)", what, strerror(errnum ? errnum : EIO));
    return cli_report(path, &err);
}

static int stdout_errno; /* errno's value when a flush of stdout first failed */

/* Flush stdout, remembering why it first failed. */
int cli_flush(void)
{
    errno = 0;
    if ((fflush(stdout) != 0 || ferror(stdout)) && !stdout_errno) stdout_errno = errno ? errno : EIO;
    return stdout_errno;
}

/* Parse an integer option value in [lo, hi] (the library's parser, src/options.c). */
int cli_parse_int(const char *command, const char *opt, const char *s, int64_t lo, int64_t hi,
                  int64_t *out)
{
    ulam_error err;
    return ulam_options_parse_int(opt, s, lo, hi, out, &err) ? cli_usage_error(command, "%s", err.msg) : 0;
}

/* Parse a finite real option value in [lo, hi]. */
int cli_parse_real(const char *command, const char *opt, const char *s, double lo, double hi,
                   double *out)
{
    ulam_error err;
    return ulam_options_parse_real(opt, s, lo, hi, out, &err) ? cli_usage_error(command, "%s", err.msg) : 0;
}

/* Parse n comma-separated finite numbers of s (n of them exactly); 0 or -1. */
int cli_parse_numbers(const char *s, int n, double *x)
{
    for (int k = 0; k < n; k++) {
        char *end;
        x[k] = strtod(s, &end);
        if (end == s || !isfinite(x[k]) || (k < n - 1 ? *end != ',' : *end != 0)) return -1;
        s = end + (k < n - 1);
    }
    return 0;
}

/* Parse a byte count with an optional K, M, G or T suffix. */
int cli_parse_bytes(const char *command, const char *opt, const char *s, size_t *out)
{
    char *end;
    double v = strtod(s, &end);
    double scale = 1.0;
    if (*end && !end[1]) {
        const char *units = "KMGT";
        const char *u = strchr(units, *end == 'k' ? 'K' : *end);
        if (u) {
            scale = pow(1024.0, (double)(u - units + 1));
            end++;
        }
    }
    if (end == s || *end || !isfinite(v) || v <= 0 || v * scale > (double)SIZE_MAX / 2)
        return cli_usage_error(command, "%s expects a size such as 4G, 512M or 1000000, got '%s'",
                               opt, s);
    *out = (size_t)(v * scale);
    return 0;
}

/* See cli.h. */
int cli_need_rhs(const char *command, const char *path)
{
    size_t len = strlen(path);
    if ((len > 5 && !strcmp(path + len - 5, ".ulam")) || (len > 10 && !strcmp(path + len - 10, ".ulamcache"))) {
        ulam_system *sys = NULL;
        ulam_error err;
        int status = ulam_system_open(path, NULL, &sys, &err); /* says why it is not one */
        ulam_system_free(sys);
        if (status) return cli_report(path, &err);
    }
    if (ulam_edgelist_is_file(path)) /* a graph: its system is PageRank's unless b is given */
        return cli_usage_error(command, "needs --rhs b.mtx or, as %s is an edge list (a graph), --pagerank ALPHA "
                               "(0.85, say) to solve its PageRank", path);
    return cli_usage_error(command, "needs --rhs b.mtx");
}

/* See cli.h. */
int cli_operands_error(const char *command, int argc, char **argv, int first)
{
    if (argc - first == 2) /* M.mtx b.mtx: b is an option's */
        return cli_usage_error(command, "expects exactly one matrix file, got two: '%s' and '%s' (is the second b? "
                               "give it as --rhs %s)", argv[first], argv[first + 1], argv[first + 1]);
    if (argc - first > 2) return cli_usage_error(command, "expects exactly one matrix file, got %d", argc - first);
    return cli_usage_error(command, "expects exactly one matrix file");
}

/* See cli.h. */
int64_t cli_node_base = 1;

/* See cli.h: the edge list read ahead (its path's copy and matrix), handed over once. */
static char *ahead_path;
static ulam_csr *ahead;

/* See cli.h. */
int cli_graph_preload(const char *path, ulam_csr **A, ulam_error *err)
{
    if (A && ahead && !strcmp(ahead_path, path)) { /* read before the options: hand it over */
        *A = ahead, ahead = NULL;
        free(ahead_path), ahead_path = NULL;
        return ULAM_OK;
    }
    ulam_csr *G = NULL;
    int64_t base = 1;
    int status = ulam_edgelist_read(path, &G, &base, err);
    if (status) return status;
    cli_node_base = base;
    if (A) return *A = G, ULAM_OK;
    ulam_csr_free(ahead), free(ahead_path);
    ahead = G, ahead_path = strdup(path);
    if (!ahead_path) ahead = ulam_csr_free(ahead);
    return ULAM_OK;
}

/* See cli.h. */
int cli_parse_node(const char *command, const char *opt, const char *value, int64_t *out)
{
    int64_t v;
    if (cli_node_base == 1) return cli_parse_int(command, opt, value, 1, ULAM_MAX_DIM, out);
    int rc = cli_parse_int(command, opt, value, 0, ULAM_MAX_DIM - 1, &v);
    if (!rc) *out = v + 1; /* 0-based ids of an edge list: state v */
    return rc;
}

/* The mapping address of sys (NULL: none). */
static const void *map_of(const ulam_system *sys)
{
    ulam_system_info si;
    if (!sys) return NULL;
    ulam_system_get_info(sys, &si);
    return si.map;
}

/* s's request and state as the library's loader holds them; maps[] its mapping addresses. */
static ulam_load to_load(const cli_system *s, const void *maps[2])
{
    maps[0] = map_of(s->sys_M), maps[1] = map_of(s->sys_b);
    return (ulam_load){.matrix_path = s->matrix_path, .rhs_path = s->rhs_path, .jacobi = s->jacobi, .omega = s->omega,
                       .pagerank = s->pagerank, .cache = s->cache, .lazy = s->lazy, .write = cli_system_write,
                       .node_base = cli_node_base, .M = s->M, .b = s->b, .cert = s->cert, .verified = s->verified,
                       .own_M = s->own_M, .own_b = s->own_b, .sys_M = s->sys_M, .sys_b = s->sys_b};
}

/* Forget the mapping at addr (it is gone). */
static void forget_map(const void *addr)
{
    for (int k = 0; addr && k < CLI_MAPS; k++)
        if (cli_maps[k].addr == addr) cli_maps[k].path = NULL, cli_maps[k].addr = NULL;
}

/* Take back what the loader L holds into s, forgetting the mappings it let go; status's exit
 * code (the error reported). */
static int from_load(cli_system *s, const ulam_load *L, const void *const maps[2], int status, const ulam_error *err)
{
    if (L->sys_M != s->sys_M) forget_map(maps[0]);
    if (L->sys_b != s->sys_b) forget_map(maps[1]);
    s->M = L->M, s->b = L->b, s->cert = L->cert, s->verified = L->verified;
    s->own_M = L->own_M, s->own_b = L->own_b, s->sys_M = L->sys_M, s->sys_b = L->sys_b;
    cli_node_base = L->node_base;
    return status ? cli_report(NULL, err) : 0;
}

/* Check a mapped M and b whole if not yet done. */
int cli_system_verify(cli_system *s)
{
    ulam_error err;
    const void *maps[2];
    ulam_load L = to_load(s, maps);
    int status = ulam_load_verify(&L, &err);
    return from_load(s, &L, maps, status, &err);
}

/* Load M (and b); 0 or an exit code. */
int cli_load_system(cli_system *s)
{
    ulam_error err;
    if (ulam_system_is_file(s->matrix_path) && (s->jacobi || s->pagerank > 0))
        return cli_usage_error(s->command, "%s is a prepared system: it holds M already (prepare it with --jacobi)",
                               s->matrix_path);
    const void *maps[2];
    ulam_load L = to_load(s, maps);
    if (ahead && !strcmp(ahead_path, s->matrix_path)) { /* read before the options: hand it over */
        L.preloaded = ahead, ahead = NULL;
        free(ahead_path), ahead_path = NULL;
    }
    int status = ulam_load_open(&L, stderr, &err);
    ulam_csr_free(L.preloaded);
    L.preloaded = NULL;
    int rc = from_load(s, &L, maps, status, &err);
    if (rc) return rc;
    cli_map_register(s->sys_M, s->matrix_path, 1), cli_map_register(s->sys_b, s->rhs_path, 1);
    /* test hook (tests/hostile_test.py): stop once the file is mapped, before its arrays are read */
    if (s->sys_M && getenv("ULAM_TEST_STOP_AT_MAP")) raise(SIGSTOP);
    maps[0] = map_of(s->sys_M), maps[1] = map_of(s->sys_b);
    status = ulam_load_finish(&L, &err);
    if ((rc = from_load(s, &L, maps, status, &err))) return rc;
    if (L.b_pagerank) cli_answer_name = "pi"; /* b = (1 - alpha) / n: x is PageRank itself */
    if (s->index > s->M->nrows) {
        rc = cli_usage_error(s->command, "--index %lld is out of range %lld..%lld", (long long)(s->index - 1 + cli_node_base),
                             (long long)cli_node_base, (long long)(s->M->nrows - 1 + cli_node_base));
        cli_system_free(s);
        return rc;
    }
    return 0;
}

/* Free what cli_load_system loaded. */
void cli_system_free(cli_system *s)
{
    cli_map_register(s->sys_M, NULL, 0), cli_map_register(s->sys_b, NULL, 0);
    const void *maps[2];
    ulam_load L = to_load(s, maps);
    ulam_load_free(&L);
    from_load(s, &L, maps, 0, NULL);
}

/* Solve the loaded system into a new *x (sparse LU or dense, as ulam_reference_plan says); 0
 * or an exit code. */
int cli_direct_solve(const cli_system *s, size_t max_mem, double **x, ulam_direct_info *info)
{
    ulam_error err = {.status = ULAM_ENOMEM, .msg = "memory for the solution"};
    *x = malloc((size_t)s->M->nrows * sizeof **x);
    int status = !*x ? ULAM_ENOMEM : ulam_reference_solve(s->M, s->b, cli_direct_force, max_mem, NULL, *x, info, NULL, &err);
    if (!status) return 0;
    free(*x);
    *x = NULL;
    return cli_report(s->matrix_path, &err);
}

/* Check before any work that path can be written (a temporary file can be made beside it and
 * it is not a directory); 0 or an exit code (reported). */
int cli_check_output(const char *path)
{
    struct stat st;
    ulam_outfile o;
    int status = stat(path, &st) == 0 && S_ISDIR(st.st_mode) ? ULAM_EIO : cli_outfile_open(&o, path);
    if (!status) cli_outfile_abort(&o);
    if (!status) return 0;
    ulam_error err = {.status = status, .msg = "a writable output file (in an existing, writable directory; not a "
                                               "directory)"};
    return cli_report(path, &err);
}

/* path's file as (device, inode) when it exists, and as its directory's real path and its own
 * name (an output not yet made); 0 when neither can be had. */
static int file_id(const char *path, struct stat *st, int *exists, char *canon, size_t len)
{
    *exists = stat(path, st) == 0;
    const char *slash = strrchr(path, '/');
    char dir[4096], real[4096];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash == path ? 1 : slash - path) : 1, slash ? path : ".");
    if (!realpath(dir, real)) return *exists;
    snprintf(canon, len, "%s/%s", real, slash ? slash + 1 : path);
    return 1;
}

/* Whether the files a and b are one (same inode, or the same canonical name). */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    int ea, eb;
    char ca[8400] = "", cb[8400] = "";
    if (!file_id(a, &sa, &ea, ca, sizeof ca) || !file_id(b, &sb, &eb, cb, sizeof cb)) return !strcmp(a, b);
    if (ea && eb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    return ca[0] && !strcmp(ca, cb);
}

int cli_check_outputs(const char *command, const cli_file *outs, int nout, const cli_file *ins, int nin)
{
    for (int k = 0; k < nout; k++) {
        if (!outs[k].path) continue;
        for (int i = 0; i < nin; i++)
            if (ins[i].path && same_file(outs[k].path, ins[i].path))
                return cli_usage_error(command, "%s %s is %s %s: writing it would replace an input; choose another path",
                                       outs[k].opt, outs[k].path, ins[i].opt, ins[i].path);
        for (int j = 0; j < k; j++)
            if (outs[j].path && same_file(outs[k].path, outs[j].path))
                return cli_usage_error(command, "%s %s is also %s %s: one would overwrite the other; choose two paths",
                                       outs[k].opt, outs[k].path, outs[j].opt, outs[j].path);
    }
    for (int k = 0; k < nout; k++) {
        int rc = outs[k].path ? cli_check_output(outs[k].path) : 0;
        if (rc) return rc;
    }
    return 0;
}

/* Start a progress line: only on a terminal, never with --json, only on rank 0. */
void cli_progress_start(cli_progress *p, int json)
{
    p->on = !json && cli_rank == 0 && isatty(2);
    p->t0 = p->last = ulam_now();
    p->shown = 0;
}

/* Show walks, the estimate +- its standard error, the time elapsed and the time left at this
 * rate: the least of what the relative-error target (the error falls as 1 / sqrt(walks)), the
 * walk budget and the time limit of o leave; at most 4 a second. */
void cli_progress_show(cli_progress *p, int64_t walks, double estimate, double se, const ulam_walk_opts *o)
{
    double now = ulam_now(), el = now - p->t0;
    if (!p->on || now - p->last < 0.25) return;
    p->last = now, p->shown = 1;
    fprintf(stderr, "\rulam: %lld walks, %.6g +- %.2g, %.1f s", (long long)walks, estimate, se, el);
    double want = o->stop.rel_err * fabs(estimate), left = INFINITY;
    if (o->stop.rel_err > 0 && want > 0 && se > want) left = el * ((se / want) * (se / want) - 1);
    if (o->stop.max_walks > 0 && walks > 0) left = fmin(left, el * ((double)o->stop.max_walks / (double)walks - 1));
    if (o->stop.max_seconds > 0) left = fmin(left, o->stop.max_seconds - el);
    if (isfinite(left)) left < 1 ? fputs(", under 1 s left", stderr) : fprintf(stderr, ", about %.0f s left", left);
    fputs("      ", stderr);
}

/* End the progress line (a newline if anything was shown). */
void cli_progress_end(cli_progress *p)
{
    if (p->on && p->shown) fputc('\n', stderr);
    p->shown = 0;
}
