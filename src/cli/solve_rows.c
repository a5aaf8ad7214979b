/* ulam solve's one option parser over its table of rows (cli.h's cli_solve_row): argv is read
 * once against every row's options, the row is picked from what was given (--method, or an
 * option only one row takes), and the options go to that row in the order given. */
#include "cli.h"

#include <getopt.h>
#include <stdlib.h>
#include <string.h>

/* The rows in the order they are tried; the last is the default. */
static const cli_solve_row *const rows[] = {&cli_solve_partition_row, &cli_solve_bidir_row, &cli_solve_outer_row,
                                            &cli_solve_walks_row};

enum { NROWS = sizeof rows / sizeof rows[0], MAXOPTS = 128, BASE = 0x200 };

/* One option as given: its place in the union (-1: none), its value (NULL: none or refused). */
typedef struct {
    int opt, refused;
    const char *value;
} given;

/* Every row's options once into u (val: the place + BASE); their count. */
static int union_opts(struct option *u)
{
    int n = 0;
    for (int r = 0; r < NROWS; r++)
        for (const struct option *o = rows[r]->longopts; o->name; o++) {
            int k = 0;
            while (k < n && strcmp(u[k].name, o->name)) k++;
            if (k == n && n < MAXOPTS - 1) u[n] = (struct option){o->name, o->has_arg, 0, BASE + n}, n++;
        }
    u[n] = (struct option){0, 0, 0, 0};
    return n;
}

/* The first row that a --method value or an option it claims selects (that option in *by), else
 * the last (*by NULL). */
static const cli_solve_row *pick(const struct option *u, const given *g, int ng, const given **by)
{
    for (int r = 0; r < NROWS - 1; r++)
        for (int k = 0; k < ng; k++) {
            const char *name = g[k].opt >= 0 ? u[g[k].opt].name : "";
            if (!strcmp(name, "method") && rows[r]->serves(g[k].value)) return *by = &g[k], rows[r];
            for (const char *const *c = rows[r]->claims; c && *c; c++)
                if (!strcmp(name, *c)) return *by = &g[k], rows[r];
        }
    return *by = NULL, rows[NROWS - 1];
}

/* name's code in the row's options, or '?'. */
static int row_code(const cli_solve_row *row, const char *name)
{
    for (const struct option *o = row->longopts; name && o->name; o++)
        if (!strcmp(o->name, name)) return o->val;
    return '?';
}

/* A usage error for the first option given that the chosen row does not take (another row's):
 * named with the option that chose the row.  0 or EXIT_USAGE. */
static int foreign(const struct option *u, const given *g, int ng, const cli_solve_row *row, const given *by)
{
    for (int k = 0; k < ng && by; k++) {
        const char *name = g[k].opt >= 0 ? u[g[k].opt].name : NULL;
        if (name && row_code(row, name) == '?')
            return cli_usage_error("solve", "--%s does not apply with --%s%s%s (the %s route)", name, u[by->opt].name,
                                   by->value ? " " : "", by->value ? by->value : "", row->name);
    }
    return 0;
}

/* ulam solve. */
int cli_solve(int argc, char **argv)
{
    struct option u[MAXOPTS];
    union_opts(u);
    if (cli_check_options("solve", argc, argv, u)) return EXIT_USAGE;
    given *g = malloc((size_t)(argc + 1) * sizeof *g);
    if (!g) return cli_exit_code(ULAM_ENOMEM);
    int ng = 0, c, idx;
    optind = 0;
    while ((c = getopt_long(argc, argv, "h", u, &idx)) != -1) {
        if (c == 'h') /* -h: --help */
            for (idx = 0; u[idx].name && strcmp(u[idx].name, "help"); idx++) continue;
        if (c == '?') g[ng++] = (given){.opt = optopt >= BASE ? optopt - BASE : -1, .refused = 1};
        else g[ng++] = (given){.opt = c == 'h' ? (u[idx].name ? idx : -1) : c - BASE, .value = optarg};
    }
    const given *by;
    const cli_solve_row *row = pick(u, g, ng, &by);
    int rc = foreign(u, g, ng, row, by) || cli_check_options("solve", argc, argv, row->longopts) ? EXIT_USAGE : 0;
    ulam_error err;
    if (!rc && optind == argc - 1 && ulam_edgelist_is_file(argv[optind]) && cli_graph_preload(argv[optind], NULL, &err))
        rc = cli_report(argv[optind], &err); /* an edge list's ids number the states: read before the options */
    void *args = rc ? NULL : calloc(1, row->size);
    if (!rc && !args) rc = cli_exit_code(ULAM_ENOMEM);
    if (args) row->init(args);
    for (int k = 0; !rc && k < ng; k++) {
        const char *name = g[k].opt >= 0 ? u[g[k].opt].name : NULL;
        rc = row->option(args, g[k].refused ? '?' : row_code(row, name), name, g[k].value);
    }
    if (!rc) rc = row->run(args, argc, argv, optind);
    const cli_solve_route *to = rc == CLI_ROUTE_WALKS && row == &cli_solve_bidir_row ? cli_bidir_route(args) : NULL;
    if (to) rc = cli_solve_source(&to->s, &to->walk, to->source, to->json, to->check, to->force);
    free(args), free(g);
    return rc < 0 ? 0 : rc;
}
