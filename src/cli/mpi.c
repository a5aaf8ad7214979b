/* Walks across MPI ranks (built with -Dmpi=enabled): the exchange the library's ulam_share asks
 * for, as MPI_Allgatherv.  MPI starts only under a launcher (mpirun sets OMPI_COMM_WORLD_SIZE
 * or PMIX_RANK), so the same binary still runs alone without one. */
#include "cli.h"

#include <mpi.h>
#include "ulam_dist.h"
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

static ulam_share share;
static int started;

/* Concatenate every rank's bytes in rank order (the ulam_share contract). */
static int allgather(void *ctx, const void *mine, size_t bytes, void **all, size_t *total)
{
    (void)ctx;
    int k = share.nranks;
    int *counts = malloc((size_t)k * sizeof *counts), *displs = malloc((size_t)k * sizeof *displs);
    int mine_n = bytes > (size_t)INT32_MAX ? -1 : (int)bytes, bad = 0;
    if (!counts || !displs || MPI_Allgather(&mine_n, 1, MPI_INT, counts, 1, MPI_INT, MPI_COMM_WORLD) != MPI_SUCCESS)
        bad = 1;
    size_t sum = 0;
    for (int r = 0; r < k && !bad; r++) {
        if (counts[r] < 0 || sum + (size_t)counts[r] > (size_t)INT32_MAX) bad = 1;
        else displs[r] = (int)sum, sum += (size_t)counts[r];
    }
    char *buf = bad ? NULL : malloc(sum ? sum : 1);
    if (!bad && (!buf || MPI_Allgatherv(mine, mine_n, MPI_BYTE, buf, counts, displs, MPI_BYTE, MPI_COMM_WORLD) !=
                             MPI_SUCCESS))
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

/* Read ULAM_TEST_PARTITION_KILL once, for this rank (share.rank set). */
static void kill_arm(void)
{
    const char *e = getenv("ULAM_TEST_PARTITION_KILL");
    int r;
    long at;
    if (e && sscanf(e, "%d:%ld", &r, &at) == 2 && r == share.rank && at > 0) kill_at = at;
}

/* Count this rank's exchanges; die at the armed one. */
static void test_kill(void)
{
    static long calls;
    if (kill_at && ++calls == kill_at) raise(SIGKILL);
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
    kill_arm();
    if (share.nranks > 1) cli_share = &share;
    cli_rank = share.rank;
    if (cli_rank && !freopen("/dev/null", "w", stdout)) fclose(stdout);
}

/* End MPI if it was started. */
void cli_mpi_finalize(void)
{
    if (started) MPI_Finalize();
}


/* The exchange of ulam_comm as MPI_Alltoall of the counts and MPI_Alltoallv of the bytes. */
static int alltoallv(void *ctx, const void *send, const size_t *sendcounts, void **recv, size_t *recvcounts)
{
    (void)ctx;
    test_kill();
    int k = share.nranks, bad = 0;
    int *sc = calloc((size_t)k * 4, sizeof *sc);
    if (!sc) return 1;
    int *sd = sc + k, *rc = sc + 2 * k, *rd = sc + 3 * k;
    size_t at = 0, total = 0;
    for (int r = 0; r < k; r++) {
        if (sendcounts[r] > (size_t)INT32_MAX || at > (size_t)INT32_MAX) bad = 1;
        sc[r] = (int)sendcounts[r], sd[r] = (int)at, at += sendcounts[r];
    }
    if (MPI_Alltoall(sc, 1, MPI_INT, rc, 1, MPI_INT, MPI_COMM_WORLD) != MPI_SUCCESS) bad = 1;
    for (int r = 0; r < k && !bad; r++) {
        if (rc[r] < 0 || total > (size_t)INT32_MAX) bad = 1;
        rd[r] = (int)total, total += (size_t)rc[r], recvcounts[r] = (size_t)rc[r];
    }
    char *buf = bad ? NULL : malloc(total ? total : 1);
    if (!bad && (!buf || MPI_Alltoallv(send, sc, sd, MPI_BYTE, buf, rc, rd, MPI_BYTE, MPI_COMM_WORLD) != MPI_SUCCESS))
        bad = 1; /* (a rank past 2^31 bytes or out of memory ends the job through MPI's error handler) */
    free(sc);
    if (bad) {
        free(buf);
        return 1;
    }
    *recv = buf;
    return 0;
}

/* The sum of ulam_comm as MPI_Allreduce. */
static int allreduce(void *ctx, int64_t *v, int n)
{
    (void)ctx;
    return MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD) != MPI_SUCCESS;
}

/* This process's rank and the exchange, for a partitioned run (one rank without mpirun). */
void cli_mpi_comm(ulam_comm *c)
{
    if (!started) return;
    c->rank = share.rank, c->nranks = share.nranks, c->exchange = alltoallv, c->sum = allreduce;
}
