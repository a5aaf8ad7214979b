/* The command-line tool: a thin layer that parses options, calls libulam and prints. */
#ifndef ULAM_CLI_H
#define ULAM_CLI_H

#include "ulam.h"
#include "ulam_options.h"
#include "ulam_report.h"
#include "ulam_reference.h"

#include <getopt.h>

/* Exit codes (documented in README.md and docs/input.md): 0 success, 1 internal failure, 2 usage error,
 * 3 walks would diverge, 4 a --rel-err target with a variance not certified finite, 5 a solve's
 * --rel-err target not met when the walks stopped (--walks, --time or the cap: the estimate and its
 * interval are printed, wider than asked), 10 + status for a library status, 130 interrupted. */
enum { EXIT_USAGE = 2, EXIT_DIVERGE = 3, EXIT_INFVAR = 4, EXIT_TARGET = 5, EXIT_STATUS_BASE = 10, EXIT_INTERRUPTED = 130 };

/* The exit code for a library status. */
int cli_exit_code(int status);

/* Print "ulam: file:line: error: <status>: expected <msg>" and return the exit code. */
int cli_report(const char *file, const ulam_error *err);

/* Report a failed write of path (status ULAM_EIO: errno's message errnum, "No space left on
 * device"; ULAM_ENONFINITE: values that cannot be written) and return the exit code. */
int cli_report_write(const char *path, int status, int errnum);

/* Report the input path (what: "query file", ...) that cannot be opened or read, with errno's
 * message errnum ("No such file or directory"), as ULAM_EIO: "ulam: PATH: error: cannot open, read
 * or write file: expected a readable WHAT (REASON)"; the exit code (13, as for a missing matrix). */
int cli_report_read(const char *path, const char *what, int errnum);

/* fflush(stdout), remembering errno's value at the first failure (main reports it at exit: "No
 * space left on device"); 0 or that errno value. */
int cli_flush(void);

/* Print "ulam: <command>: <message>" for a usage error and return EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Parse an integer option value in [lo, hi]; 0 on success, else prints and returns EXIT_USAGE. */
int cli_parse_int(const char *command, const char *opt, const char *s, int64_t lo, int64_t hi,
                  int64_t *out);

/* Parse a finite real option value in [lo, hi]. */
int cli_parse_real(const char *command, const char *opt, const char *s, double lo, double hi,
                   double *out);

/* Parse n comma-separated finite numbers of s (exactly n) into x; 0 or -1 (the caller reports). */
int cli_parse_numbers(const char *s, int n, double *x);

/* Parse a byte count with an optional K, M, G or T suffix (powers of 1024). */
int cli_parse_bytes(const char *command, const char *opt, const char *s, size_t *out);

/* A walk option shared by the walking commands (src/cli/walkopts.c): in a command's longopts as
 * CLI_WALK_OPTION("walks"), getopt_long returns CLI_WALK for it and the command hands it on with
 * cli_walk_option(command, longopts[idx].name, optarg, &o).  Short letters differ per command. */
enum { CLI_WALK = 0x100 };
#define CLI_WALK_OPTION(name) {name, required_argument, 0, CLI_WALK}

/* Parse walk option --name (walks, rel-err, time, seed, threads, continue, roulette, split,
 * max-steps, estimator, mode) into o: 0 handled, 1 not a walk option, else an exit code (reported). */
int cli_walk_option(const char *command, const char *name, const char *value, ulam_walk_opts *o);

/* After parsing: 100000 walks when no stopping rule (--walks, --rel-err, --time) was given. */
void cli_walk_budget(ulam_walk_opts *o);

/* What a subcommand needs to know about the system it solves. */
typedef struct cli_system {
    const char *command;  /* subcommand name, for messages */
    const char *matrix_path, *rhs_path;
    int64_t index;        /* 1-based --index to check against n once loaded (0: none) */
    int jacobi;   /* the file holds A of A x = b: use M = I - omega D^-1 A */
    double omega; /* damping of the Jacobi splitting (1 = plain Jacobi) */
    double pagerank; /* > 0: the file is an adjacency matrix; solve PageRank at this damping */
    int cache;    /* read and write binary caches beside the files (--cache) */
    int lazy;     /* the command reads M only where walks reach (adjoint solve): a mapped
                     file is then verified only if its certificate does not serve the guards */
    const ulam_csr *M;  /* the iteration matrix (owned, or mapped from a prepared file) */
    const double *b;    /* the right-hand side (NULL if no --rhs and none needed) */
    const ulam_certificate *cert; /* the guards a prepared file certified (NULL: none) */
    int verified;       /* M and b checked whole (parsed, or ulam_system_check passed) */
    ulam_csr *own_M;    /* what M and b point to when this owns them */
    double *own_b;
    ulam_system *sys_M, *sys_b; /* mappings behind M and b */
} cli_system;

/* The usage error of a command that takes one matrix file and was given argv[first..argc) (two:
 * a hint that the second, b, goes with --rhs); EXIT_USAGE. */
int cli_operands_error(const char *command, int argc, char **argv, int first);

/* The number the command line gives the first state (--index, --source, printed indices): 1, as
 * in Matrix Market files, or 0 for an edge list whose ids are 0-based (SNAP's; src/edgelist.c):
 * node ids are then used as written. */
extern int64_t cli_node_base;

/* Read the edge list at path (ulam_edgelist_read; cli_node_base becomes its ids' base): with A
 * NULL keep it for the next call with that path (ulam solve reads it before its options, whose
 * node ids need the base), else into *A (the kept one if it is path's).  ULAM_OK or a status with
 * err filled. */
int cli_graph_preload(const char *path, ulam_csr **A, ulam_error *err);

/* Parse a node id option (--index, --source) as the command line numbers states (cli_node_base)
 * into *out, 1-based (state *out - 1); 0 or EXIT_USAGE (reported). */
int cli_parse_node(const char *command, const char *opt, const char *value, int64_t *out);

/* Load M (and b if rhs_path is set, or from a prepared file, or zeros when jacobi needs
 * one) and check index against n; a prepared file (or a --cache copy) is mapped, and checked
 * whole unless s->lazy; 0 or an exit code (nothing stays loaded on failure). */
int cli_load_system(cli_system *s);

/* The refusal of a command given no --rhs for path: a file named .ulam or .ulamcache that is
 * not a prepared system (empty, another magic) says so; an edge list is told of --pagerank; anything else needs --rhs.  An exit code. */
int cli_need_rhs(const char *command, const char *path);

/* Check a mapped M and b whole (ulam_system_check) if not yet done; 0 or an exit code. */
int cli_system_verify(cli_system *s);

/* What the answer line calls the unknown: "x", or "pi" once --pagerank made b = (1 - alpha) / n
 * (x is then PageRank itself; src/cli/graph.c). */
extern const char *cli_answer_name;

/* True when a --source value is a list of node ids ("3,7,9"). */
int cli_seeds_is_list(const char *spec);

/* --pagerank ALPHA (--damping) of command into *alpha: a number with 0 < alpha < 1 (1e-6 to
 * 1 - 1e-9); 0 or a usage error saying the range is open at 1. */
int cli_parse_damping(const char *command, const char *s, double *alpha);

/* A --source seed set (ids "3,7,9", equal weights, or a file of lines "id" or "id weight", '#'
 * comments), node ids numbered as the command line numbers them, into the personalisation vector
 * w (n entries, summing to 1); 0 or an exit code (reported, file:line for a bad line). */
int cli_seeds_parse(const char *spec, int64_t n, double *w);

/* The system (n + 1 states) whose state n is a virtual source feeding the seeds w: M with column
 * n = alpha w, row n empty, so that x' = (I - M')^-1 e_n has x'_i = alpha x_i for x = (I - M)^-1 w
 * (a single source for a seed set; column n sums to alpha < 1).  ULAM_OK or ULAM_ENOMEM. */
int cli_graph_augment(const ulam_csr *M, const double *w, double alpha, ulam_csr **out);

/* A hint naming the option that fits how M looks (--jacobi for a large diagonal, --pagerank for an
 * adjacency matrix), or "" (src/cli/guard.c). */
const char *cli_system_hint(const ulam_csr *M);

/* Free what cli_load_system loaded. */
void cli_system_free(cli_system *s);

/* The reference solve (src/cli/direct.c; the library's ulam_reference_*): --lu of ulam direct
 * sets cli_direct_force: -1 auto, 0 dense, 1 sparse. */
extern int cli_direct_force;

/* x_index (from 0) of the reference solve for --check, interruptible by Ctrl-C (EXIT_INTERRUPTED:
 * its thread still reads s); half_width is the walks' interval's: past the LU's memory limit the
 * iterative reference stops once x_index's certified range is within a thousandth of it (<= 0 or
 * NaN: as narrow as it gets).  *method "sparse LU", "dense LU" or what the iterative one reached;
 * 0 or an exit code. */
int cli_direct_check(const cli_system *s, int64_t index, double half_width, double *value, double *seconds,
                     const char **method);

/* The whole reference solve for --check into a new *x (as cli_direct_check; index -1: every
 * component judged, the widest range), interruptible; 0 or an exit code. */
int cli_direct_reference(const cli_system *s, int64_t index, double half_width, double **x, double *seconds,
                         const char **method);

/* Solve the loaded system (sparse or dense LU) into a new *x; 0 or an exit code (error reported). */
int cli_direct_solve(const cli_system *s, size_t max_mem, double **x, ulam_direct_info *info);

/* Set by the first Ctrl-C while cli_catch_sigint is in force (walks stop at their next block). */
extern volatile int cli_interrupted;

/* Walks shared across MPI ranks (NULL: this process alone) and this process's rank (0 alone).
 * Only rank 0 prints results and writes files. */
extern const ulam_share *cli_share;
extern int cli_rank;

/* When the process started (ulam_now()), set first thing in main: --time counts from here. */
extern double cli_started;

/* The walks' share of a --time budget of `budget` seconds (0: none) once what ran since the
 * process started (reading, guards, set-up) is taken off; at least one block of walks still
 * runs when nothing is left (a tiny positive budget). */
double cli_time_left(double budget);

/* OpenMP's and OpenBLAS's threads wait passively (sleep, not spin) on a busy machine unless the user
 * chose (OMP_WAIT_POLICY, GOMP_SPINCOUNT, OPENBLAS_THREAD_TIMEOUT): both read it when they load,
 * before main, so common.c's .preinit_array function runs the process again once with it set
 * (issue 29 point 5). */

/* With -Dmpi=enabled: start MPI when launched by mpirun, and end it (src/cli/mpi.c). */
void cli_mpi_init(int *argc, char ***argv);
void cli_mpi_finalize(void);

/* The exchange between mpirun's ranks for a partitioned run (src/cli/mpi.c); unchanged alone. */
struct ulam_comm;
void cli_mpi_comm(struct ulam_comm *c);

/* Signals and temporary files: every output is written to a temporary file (NAME.tmp.XXXXXX)
 * opened by cli_outfile_open, which registers it, and renamed into place by cli_outfile_commit
 * (or removed by cli_outfile_abort), which forget it; SIGINT, SIGTERM and SIGHUP remove every
 * registered file in every phase (cli_signals_init, from main), then end the process as the
 * signal would.  During walks cli_catch_sigint takes SIGINT (and, under MPI, SIGTERM: mpirun's
 * Ctrl-C) instead: the first sets cli_interrupted (the estimate so far is printed), a second
 * removes the temporary files and exits at once with EXIT_INTERRUPTED; cli_release_sigint
 * restores the handlers of cli_signals_init. */
void cli_signals_init(void);
void cli_catch_sigint(void);
void cli_release_sigint(void);
int cli_outfile_open(ulam_outfile *o, const char *path);
int cli_outfile_commit(ulam_outfile *o);
int cli_outfile_commit_all(ulam_outfile *o, int k);
void cli_outfile_abort(ulam_outfile *o);

/* ulam_mm_write_vector and ulam_system_write through cli_outfile_open: ULAM_OK or a status (errno
 * says why for EIO). */
int cli_write_vector(const char *path, const double *x, int64_t n, const char *comment);
int cli_system_write(const char *path, const ulam_system_desc *d);

/* Hold (on 1) SIGINT, SIGTERM and SIGHUP until released (on 0), around a short write whose
 * temporary file the library makes itself (ulam_png_write). */
void cli_hold_signals(int on);

/* Index of word in names[0..n), or -1. */
int cli_lookup(const char *word, const char *const *names, int n);

/* The usage error for an unknown --method: auto and the rows of the library's table; EXIT_USAGE. */
int cli_method_error(const char *got);

/* Print a JSON number (null when not finite). */
void cli_json_number(const char *key, double v, int last);

/* Print a JSON string (escaped). */
void cli_json_string(const char *key, const char *v, int last);

/* The guards' radii for a walk in mode on s with kernel exponent alpha (rho(|M|) and that mode's
 * rho(M^), stopped once certified): a prepared file's certificate made for this continuation
 * (and exponent: a certificate holds alpha = 1's) serves instead of a pass
 * over M (ulam_certificate_guard), else a mapped M is verified whole first; 0 or an exit code
 * (error reported).  The solver takes them (ulam_walk_opts.guard) and refuses what they refuse. */
int cli_guard(cli_system *s, double continue_q, double alpha, int mode, ulam_guard *g);

/* Print why walks whose rho(|M|) is not certified below 1 are refused (a warning under force). */
void cli_guard_diverge(const cli_system *s, const ulam_guard *g, int force);

/* Print the warnings of radii near 1, past it or unknown that do not stop a run. */
void cli_guard_warn(const cli_system *s, const ulam_guard *g, int mode, int assume_finite);

/* Output (src/cli/output.c).  cli_verbosity: -1 --quiet (the answer line), 0 default (a few lines),
 * 1 --verbose (everything); cli_json_mode: --json was given; cli_json_done: a JSON object was
 * printed (set by cli_json_number and cli_json_string). */
extern int cli_verbosity, cli_json_mode, cli_json_done;

/* Strip --verbose/-v and --quiet/-q from argv, note --json (then stderr keeps its last error). */
void cli_output_begin(int *argc, char **argv);

/* A usage error (EXIT_USAGE) when argv had both --verbose and --quiet (-v, -q), naming both; else 0. */
int cli_output_conflict(const char *command);

/* Under --json, a failure that printed no JSON prints {"error": message, "exit": rc}; returns rc. */
int cli_output_finish(int rc);

/* Every value of solve --method (src/cli/output.c), and them in words for messages. */

/* Refuse an unknown --name in argv (no abbreviations), naming the closest of longopts; 0 or EXIT_USAGE. */
int cli_check_options(const char *command, int argc, char **argv, const struct option *longopts);

/* value's index among names[0..n) for option opt, or -1 after a usage error (what: the names in
 * words) with a "did you mean". */
int cli_choose(const char *command, const char *opt, const char *value, const char *const *names, int n,
               const char *what);

/* Subcommands: each takes the argv that starts at its own name. */
int cli_info(int argc, char **argv);
int cli_direct(int argc, char **argv);
int cli_solve(int argc, char **argv);

/* A row of `ulam solve`'s table (src/cli/solve_rows.c): a group of the library's method rows that
 * share a report, with the options it takes.  The one parser reads argv once against the union
 * of every row's longopts, picks the first row that a --method value (serves) or an option of
 * its own (claims) selects, the last row being the default, and hands it each option in order.
 * Adding a method or an estimator touches the library's table and the row that reports it. */
typedef struct cli_solve_row {
    const char *name;
    const struct option *longopts; /* the options it takes; val: its own codes */
    const char *const *claims;     /* options that select it whatever --method says (NULL-ended), or NULL */
    int (*serves)(const char *method); /* 1 when --method METHOD (NULL: given no value) is this row's */
    size_t size;                   /* its arguments' struct */
    void (*init)(void *args);
    /* one option: val its code in longopts ('?': getopt refused it), name its long name; 0, an
     * exit code, or -1 (--help printed: exit 0) */
    int (*option)(void *args, int val, const char *name, const char *value);
    /* the options read, argv[first..] the operands: check and run; 0 or an exit code */
    int (*run)(void *args, int argc, char **argv, int first);
} cli_solve_row;

/* A row's hand-over to the walks row (cli_solve_source's arguments): x_I for b = e_source. */
typedef struct cli_solve_route {
    cli_system s;
    ulam_walk_opts walk;
    int64_t source;
    int json, check, force;
} cli_solve_route;

/* The bidirectional row's run returns this when the walks row should solve instead: cli_solve
 * then runs cli_solve_source on cli_bidir_route(args). */
enum { CLI_ROUTE_WALKS = -2 };

/* The hand-over the bidirectional row's run set when it returned CLI_ROUTE_WALKS. */
const cli_solve_route *cli_bidir_route(const void *args);

/* The rows: bidirectional (src/cli/bidir.c), the outer iterations and Krylov peers
 * (src/cli/mcsa.c), the walks with auto (src/cli/solve.c); --partition (below). */
extern const cli_solve_row cli_solve_bidir_row, cli_solve_outer_row, cli_solve_walks_row;

/* The rows split across MPI ranks, walks that migrate (--partition, src/cli/partition.c). */
extern const cli_solve_row cli_solve_partition_row;

/* x_I (s->index, 1-based) for b = e_source (1-based) by the walks row under --method auto with
 * walk options o (the push on b, then walks from I): a --source solve's route when the walks
 * from S have a variance not certified finite (bidir.c's cli_solve_route, src/cli/solve_rows.c).  0 or an
 * exit code. */
int cli_solve_source(const cli_system *s, const ulam_walk_opts *o, int64_t source, int json, int check, int force);

/* Run bidirectional, chosen by solve --method auto (run: the library's, ch: its choice), and print
 * its report with the choice; 0 or an exit code. */
int cli_bidir_auto_run(cli_system *s, ulam_run *run, const ulam_choice *ch, int route, int json, int check,
                       double load_seconds);

/* One line of a query file: source (0-based; -1: b), index (0-based), target (0: the command
 * line's), line. */
typedef struct cli_query {
    int64_t source, index;
    double target;
    long line;
} cli_query;

/* Read every query of path ("-": stdin) into *out (*nq of them, malloc'd); 0 or an exit code
 * (reported with the file and line). */
int cli_read_queries(const char *path, cli_query **out, int64_t *nq);

/* ulam solve --queries FILE (src/cli/queries.c): s (not loaded) and o from the command line
 * (adjoint), json, walks_given (--walks or --time given); 0 or an exit code. */
int cli_queries(cli_system *s, const ulam_walk_opts *o, const char *path, int json, int walks_given);

/* solve --method auto (src/cli/auto.c): choose the method for the loaded s under o (what ao pins
 * stays; ao->exclude: rows the command line rules out, their reason excluded_why) through the
 * library's table (ulam_auto_start; an: ulam_analysis_start, the walks on its bounds), make
 * the run *run and set o to the walks' choice; *status and err get the refusal.  0 or an exit
 * code.  The report prints the candidates (ulam_choice_fprint). */
int cli_auto_choose(const cli_system *s, ulam_analysis *an, ulam_walk_opts *o, const ulam_auto_opts *ao,
                    const char *excluded_why, ulam_choice *ch, ulam_run **run, int *status, ulam_error *err);
int cli_study(int argc, char **argv);

int cli_radiosity(int argc, char **argv);
int cli_prepare(int argc, char **argv);

/* Remember (on 1) or forget (on 0) the mapping of the prepared system s read from path: a SIGBUS
 * in it (the file shrank while in use) is reported as that file's error, exit 13. */
void cli_map_register(const ulam_system *s, const char *path, int on);

/* Check before any work that path can be written (a temporary file beside it, not a directory);
 * 0 or an exit code (reported). */
int cli_check_output(const char *path);

/* A file a run names: the option that names it ("--out"; the input's own name for an input)
 * and its path (NULL: not given). */
typedef struct {
    const char *opt, *path;
} cli_file;

/* Check the nout outputs (cli_check_output each), then refuse (usage error, EXIT_USAGE) an output
 * that is one of the nin inputs (the same file: same device and inode, through any path, link
 * or symlink) or another output of this run; 0 or the exit code (reported). */
int cli_check_outputs(const char *command, const cli_file *outs, int nout, const cli_file *ins, int nin);

/* A progress line on stderr for a terminal (nothing on a pipe, with --json, or off rank 0). */
typedef struct cli_progress {
    int on, shown;
    double t0, last;
} cli_progress;
void cli_progress_start(cli_progress *p, int json);
void cli_progress_show(cli_progress *p, int64_t walks, double estimate, double se, const ulam_walk_opts *o);
void cli_progress_end(cli_progress *p);

/* The walk modes and estimators by name, indexed by enum ulam_mode and enum ulam_estimator. */
extern const char *const cli_mode_names[2];
extern const char *const cli_estimator_names[3];

/* The memory a dense reference solve may take unless --max-mem says otherwise: 4 GiB. */
#define CLI_MAX_MEM ((size_t)4 << 30)

#endif
