/* ulam: the command-line entry point; dispatches to one file per subcommand. */
#include "cli.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Run the subcommand. */
static int dispatch(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        ulam_options_help(argc < 2 ? stderr : stdout, "ulam");
        return argc < 2 ? EXIT_USAGE : 0;
    }
    if (!strcmp(argv[1], "help")) { /* ulam help [COMMAND]: COMMAND --help */
        static char help[] = "--help";
        char *sub[] = {argv[0], argc > 2 ? argv[2] : help, help, NULL};
        return dispatch(argc > 2 ? 3 : 2, sub);
    }
    if (!strcmp(argv[1], "--version")) {
        printf("ulam %s\n", ULAM_VERSION);
        return 0;
    }
    if (cli_output_conflict(argv[1])) return EXIT_USAGE;
    if (!strcmp(argv[1], "info")) return cli_info(argc - 1, argv + 1);
    if (!strcmp(argv[1], "direct")) return cli_direct(argc - 1, argv + 1);
    if (!strcmp(argv[1], "solve")) return cli_solve(argc - 1, argv + 1);
    if (!strcmp(argv[1], "study")) return cli_study(argc - 1, argv + 1);
#ifdef ULAM_RADIOSITY
    if (!strcmp(argv[1], "radiosity")) return cli_radiosity(argc - 1, argv + 1);
#else
    if (!strcmp(argv[1], "radiosity")) {
        fprintf(stderr, "ulam: radiosity: this ulam was built without the radiosity front end (meson "
                        "-Dradiosity=enabled needs Embree 3 and libpng: libembree-dev, libpng-dev)\n");
        return EXIT_USAGE;
    }
#endif
    if (!strcmp(argv[1], "prepare")) return cli_prepare(argc - 1, argv + 1);
    static const char *const commands[] = {"info", "solve", "direct", "study", "radiosity", "prepare", "help"};
    const char *near = ulam_options_suggest(argv[1], commands, (int)(sizeof commands / sizeof commands[0]));
    if (near) fprintf(stderr, "ulam: unknown command '%s' (did you mean '%s'?)\n", argv[1], near);
    else fprintf(stderr, "ulam: unknown command '%s'\n", argv[1]);
    ulam_options_help(stderr, "ulam");
    return EXIT_USAGE;
}

int main(int argc, char **argv)
{
    cli_started = ulam_now();
#ifdef ULAM_MPI
    cli_mpi_init(&argc, &argv);
#endif
#ifndef ULAM_MPI
    { /* started by mpirun, built without MPI: each process runs the whole command alone; say so once (newuser18) */
        const char *size = getenv("OMPI_COMM_WORLD_SIZE"), *rank = getenv("OMPI_COMM_WORLD_RANK");
        if (!size) size = getenv("PMI_SIZE"), rank = getenv("PMI_RANK");
        if (size && atoi(size) > 1 && (!rank || atoi(rank) == 0))
            fprintf(stderr, "ulam: warning: started as one of %d processes (mpirun), but this ulam was built without MPI "
                            "(meson setup -Dmpi=enabled, docs/distributed.md): each runs the whole command alone\n", atoi(size));
    }
#endif
    cli_signals_init(); /* temporary files removed on SIGINT, SIGTERM, SIGHUP */
    cli_output_begin(&argc, argv);
    int rc = cli_output_finish(dispatch(argc, argv));
    int e = cli_flush();
    if (e && cli_rank == 0) { /* a full disk or a closed pipe: say so */
        fprintf(stderr, "ulam: error: cannot write the answer to standard output (%s)\n", strerror(e));
        if (!rc) rc = cli_exit_code(ULAM_EIO);
    }
#ifdef ULAM_MPI
    cli_mpi_finalize();
#endif
    return rc;
}
