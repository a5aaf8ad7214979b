/* Walks across MPI ranks (built with -Dmpi=enabled): the exchange the library's ulam_share asks
 * for, as MPI_Iallgatherv waited for with a timeout.  MPI starts only under a launcher (mpirun sets OMPI_COMM_WORLD_SIZE
 * or PMIX_RANK), so the same binary still runs alone without one. */
#include "cli.h"

#include <mpi.h>
#include "ulam_dist.h"
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

static ulam_share share;
static int started;

static int wait_for(MPI_Request *req, const char *what);

/* A collective started by call (its MPI status) on *req, waited for (wait_for); 1: failed. */
static int finish(int call, MPI_Request *req, const char *what)
{
    return call != MPI_SUCCESS || wait_for(req, what);
}

/* Concatenate every rank's bytes in rank order (the ulam_share contract). */
static int allgather(void *ctx, const void *mine, size_t bytes, void **all, size_t *total)
{
    (void)ctx;
    int k = share.nranks;
    int *counts = malloc((size_t)k * sizeof *counts), *displs = malloc((size_t)k * sizeof *displs);
    int mine_n = bytes > (size_t)INT32_MAX ? -1 : (int)bytes, bad = 0;
    MPI_Request req;
    if (!counts || !displs || finish(MPI_Iallgather(&mine_n, 1, MPI_INT, counts, 1, MPI_INT, MPI_COMM_WORLD, &req), &req, "sizes"))
        bad = 1;
    size_t sum = 0;
    for (int r = 0; r < k && !bad; r++) {
        if (counts[r] < 0 || sum + (size_t)counts[r] > (size_t)INT32_MAX) bad = 1;
        else displs[r] = (int)sum, sum += (size_t)counts[r];
    }
    char *buf = bad ? NULL : malloc(sum ? sum : 1);
    if (!bad && (!buf || finish(MPI_Iallgatherv(mine, mine_n, MPI_BYTE, buf, counts, displs, MPI_BYTE, MPI_COMM_WORLD, &req),
                                    &req, "tallies")))
        bad = 1; /* (a failed malloc here leaves the others waiting: MPI's error handler ends the job) */
    free(counts), free(displs);
    if (bad) {
        free(buf);
        return 1;
    }
    *all = buf, *total = sum;
    return 0;
}

/* Tests: ULAM_TEST_PARTITION_KILL=R:N kills rank R (SIGKILL, no word to the others) as it enters
 * its Nth exchange, while the other ranks wait in it: the job must end with an error, not hang.
 * kill_at is this rank's N (0: never), read once at start-up (kill_arm), not at every exchange. */
static long kill_at;

/* Tests: ULAM_TEST_PARTITION_STALL=R:N stops rank R at its Nth exchange for good (alive, silent:
 * a message delayed without end), while the others wait for it: they must end the job with an
 * error once ULAM_EXCHANGE_TIMEOUT has passed, not hang.  Read once at start-up. */
static long stall_at;

/* Seconds an exchange waits for the other ranks before it ends the job (ULAM_EXCHANGE_TIMEOUT,
 * default 600: longer than any step between two exchanges; 0 < value <= 1e6). */
static double exchange_timeout = 600.0;

/* Read the test hooks and the timeout once, for this rank (share.rank set). */
static void hooks_arm(void)
{
    const char *e = getenv("ULAM_TEST_PARTITION_KILL"), *s = getenv("ULAM_TEST_PARTITION_STALL");
    const char *t = getenv("ULAM_EXCHANGE_TIMEOUT");
    int r;
    long at;
    double v;
    char c;
    if (e && sscanf(e, "%d:%ld", &r, &at) == 2 && r == share.rank && at > 0) kill_at = at;
    if (s && sscanf(s, "%d:%ld", &r, &at) == 2 && r == share.rank && at > 0) stall_at = at;
    if (t && sscanf(t, "%lf%c", &v, &c) == 1 && v > 0 && v <= 1e6) exchange_timeout = v;
    else if (t && !share.rank)
        fprintf(stderr, "ulam: ULAM_EXCHANGE_TIMEOUT=%s is not a number of seconds in (0, 1e6]; waiting %g s\n", t,
                exchange_timeout);
}

/* Count this rank's exchanges; die, or stop for good, at the armed one. */
static void test_hooks(void)
{
    static long calls;
    ++calls;
    if (kill_at && calls == kill_at) raise(SIGKILL);
    while (stall_at && calls == stall_at) pause(); /* until mpirun ends the job */
}

/* Wait for a started collective; past exchange_timeout, say which rank waited for what and end
 * the job (a rank that stalled or a message that never came must not hang it); 1: MPI failed. */
static int wait_for(MPI_Request *req, const char *what)
{
    double t0 = MPI_Wtime();
    for (;;) {
        int done = 0;
        if (MPI_Test(req, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS) return 1;
        if (done) return 0;
        double t = MPI_Wtime() - t0;
        if (t > exchange_timeout) {
            fprintf(stderr, "ulam: rank %d of %d: no %s from the other ranks in %g s (a rank stalled or a message was "
                            "lost); ending the job (ULAM_EXCHANGE_TIMEOUT sets the wait)\n",
                    share.rank, share.nranks, what, exchange_timeout);
            fflush(stderr);
            MPI_Abort(MPI_COMM_WORLD, EXIT_STATUS_BASE + ULAM_EIO);
        }
        struct timespec nap = {0, t < 0.01 ? 0 : 1000000}; /* poll at once, then every millisecond */
        nanosleep(&nap, NULL);
    }
}

/* Start MPI when launched by mpirun; ranks other than 0 print nothing on stdout. */
void cli_mpi_init(int *argc, char ***argv)
{
    if (!getenv("OMPI_COMM_WORLD_SIZE") && !getenv("PMIX_RANK") && !getenv("PMI_SIZE")) return;
    if (MPI_Init(argc, argv) != MPI_SUCCESS) return;
    started = 1;
    share = ulam_share_defaults();
    MPI_Comm_rank(MPI_COMM_WORLD, &share.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &share.nranks);
    share.allgather = allgather;
    hooks_arm();
    if (share.nranks > 1) cli_share = &share;
    cli_rank = share.rank;
    if (cli_rank && !freopen("/dev/null", "w", stdout)) fclose(stdout);
}

/* End MPI if it was started. */
void cli_mpi_finalize(void)
{
    if (started) MPI_Finalize();
}


/* The exchange of ulam_comm as MPI_Ialltoall of the counts and MPI_Ialltoallv of the bytes. */
static int alltoallv(void *ctx, const void *send, const size_t *sendcounts, void **recv, size_t *recvcounts)
{
    (void)ctx;
    test_hooks();
    int k = share.nranks, bad = 0;
    MPI_Request req;
    int *sc = calloc((size_t)k * 4, sizeof *sc);
    if (!sc) return 1;
    int *sd = sc + k, *rc = sc + 2 * k, *rd = sc + 3 * k;
    size_t at = 0, total = 0;
    for (int r = 0; r < k; r++) {
        if (sendcounts[r] > (size_t)INT32_MAX || at > (size_t)INT32_MAX) bad = 1;
        sc[r] = (int)sendcounts[r], sd[r] = (int)at, at += sendcounts[r];
    }
    if (finish(MPI_Ialltoall(sc, 1, MPI_INT, rc, 1, MPI_INT, MPI_COMM_WORLD, &req), &req, "message sizes")) bad = 1;
    for (int r = 0; r < k && !bad; r++) {
        if (rc[r] < 0 || total > (size_t)INT32_MAX) bad = 1;
        rd[r] = (int)total, total += (size_t)rc[r], recvcounts[r] = (size_t)rc[r];
    }
    char *buf = bad ? NULL : malloc(total ? total : 1);
    if (!bad && (!buf || finish(MPI_Ialltoallv(send, sc, sd, MPI_BYTE, buf, rc, rd, MPI_BYTE, MPI_COMM_WORLD, &req), &req,
                                    "walks or values")))
        bad = 1; /* (a rank past 2^31 bytes or out of memory ends the job through MPI's error handler) */
    free(sc);
    if (bad) {
        free(buf);
        return 1;
    }
    *recv = buf;
    return 0;
}

/* The sum of ulam_comm as MPI_Iallreduce. */
static int allreduce(void *ctx, int64_t *v, int n)
{
    (void)ctx;
    MPI_Request req;
    return finish(MPI_Iallreduce(MPI_IN_PLACE, v, n, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD, &req), &req, "sum");
}

/* This process's rank and the exchange, for a partitioned run (one rank without mpirun). */
void cli_mpi_comm(ulam_comm *c)
{
    if (!started) return;
    c->rank = share.rank, c->nranks = share.nranks, c->exchange = alltoallv, c->sum = allreduce;
}
