/* mpi_engine.c - the process-level MPI engine: is this an MPI job, start-up and shutdown
 * at the thread level the transport needs, ending the job on a failure, and agreement
 * between ranks (the lowest failing rank's status and message reach every rank).
 */
#include "transport/mpi_internal.h"
#include "vwalls/engine.h"

#include <errno.h>
#include <limits.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int we_initialised; /* MPI_Init_thread was called by vw_engine_init / autoinit */

/* Variables the launchers of Open MPI, MPICH (Hydra), PMIx-based and Slurm set in every
   process they start. Without one of them (and MPI not initialised) the process runs
   the threads engine and never touches MPI, not even for a singleton init. */
int vw__mpi_launcher_env(void)
{
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMI_RANK",
                                       "PMIX_RANK", "MPI_LOCALNRANKS", "SLURM_PROCID"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++) {
        const char *v = getenv(vars[i]);
        if (v && *v) return 1;
    }
    return 0;
}

static int mpi_up(void)
{
    int init = 0, fin = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    return init && !fin;
}

int vw_engine_launched(void) { return mpi_up() || vw__mpi_launcher_env(); }

static const char *level_name(int l)
{
    switch (l) {
    case MPI_THREAD_SINGLE: return "MPI_THREAD_SINGLE";
    case MPI_THREAD_FUNNELED: return "MPI_THREAD_FUNNELED";
    case MPI_THREAD_SERIALIZED: return "MPI_THREAD_SERIALIZED";
    case MPI_THREAD_MULTIPLE: return "MPI_THREAD_MULTIPLE";
    default: return "an unknown thread level";
    }
}

static vw_status check_level(int got, char *msg, size_t len)
{
    if (got >= VW__MPI_THREAD_LEVEL) return VW_OK;
    if (msg && len)
        snprintf(msg, len, "MPI offers only %s; vwalls needs %s (worker threads run beside "
                 "the thread that makes the MPI calls)", level_name(got),
                 level_name(VW__MPI_THREAD_LEVEL));
    return VW_E_MPI;
}

vw_status vw_engine_init(int *argc, char ***argv, char *msg, size_t len)
{
    if (msg && len) msg[0] = 0;
    int init = 0;
    MPI_Initialized(&init);
    if (init) {
        int got;
        MPI_Query_thread(&got);
        return check_level(got, msg, len);
    }
    if (!vw__mpi_launcher_env()) return VW_OK;
    int got = MPI_THREAD_SINGLE;
    if (MPI_Init_thread(argc, argv, VW__MPI_THREAD_LEVEL, &got) != MPI_SUCCESS) {
        if (msg && len) snprintf(msg, len, "MPI_Init_thread failed");
        return VW_E_MPI;
    }
    we_initialised = 1;
    return check_level(got, msg, len);
}

void vw_engine_finish(void)
{
    if (we_initialised && mpi_up()) MPI_Finalize();
    we_initialised = 0;
}

static void finish_at_exit(void) { vw_engine_finish(); }

vw_status vw__mpi_autoinit(char *msg, size_t len)
{
    vw_status st = vw_engine_init(NULL, NULL, msg, len);
    if (we_initialised) atexit(finish_at_exit);
    return st;
}

/* The pause before MPI_Abort: MPICH's launcher (Hydra) tears the job down as soon as it
   hears of the abort, and under load its proxy had not yet relayed the line this process
   had written to its stderr pipe in 3 runs of 50 (tests/mpi/wire.sh, the other core
   busy). A tenth of a second lets the proxy read it first; an aborting job can afford it. */
#define VW_ABORT_PAUSE_NS 100000000L

void vw_engine_abort(int status, const char *msg)
{
    if (msg) fprintf(stderr, "%s\n", msg);
    fflush(NULL);
    if (mpi_up()) {
        struct timespec pause = {0, VW_ABORT_PAUSE_NS};
        while (nanosleep(&pause, &pause) != 0 && errno == EINTR) {
        }
        MPI_Abort(MPI_COMM_WORLD, status ? status : 1);
    }
    _exit(status ? status : 1);
}

int vw_engine_rank(void)
{
    int r = 0;
    if (mpi_up()) MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

int vw_engine_size(void)
{
    int n = 1;
    if (mpi_up()) MPI_Comm_size(MPI_COMM_WORLD, &n);
    return n;
}

/* The length of a message's leading "FILE:LINE: " (bad input, as the readers word it),
   or 0 when it has none: what comes before its first ": " must end in ':' and digits. */
static size_t file_line_length(const char *msg)
{
    const char *sep = strstr(msg, ": ");
    if (!sep) return 0;
    const char *d = sep;
    while (d > msg && d[-1] >= '0' && d[-1] <= '9') d--;
    if (d == sep || d - msg < 2 || d[-1] != ':') return 0;
    return (size_t)(sep + 2 - msg);
}

/* Two collectives: the lowest failing rank (MIN of rank-or-size), then its status and
   message broadcast from it. Costs O(log P) when everybody is fine. The message names
   that rank in front ("rank R: ..."), or after the "FILE:LINE: " of bad input, which
   then stays first on the line, as without MPI. */
vw_status vw__mpi_agree(MPI_Comm comm, vw_status local, char *msg, size_t len)
{
    int rank, size;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    int mine = local != VW_OK ? rank : size, first = size;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
    if (first == size) return VW_OK;
    struct {
        int status;
        char text[1020];
    } b;
    memset(&b, 0, sizeof b);
    if (rank == first) {
        b.status = (int)local;
        const char *text = msg && *msg ? msg : vw_status_message(local);
        size_t fl = file_line_length(text);
        snprintf(b.text, sizeof b.text, "%.*srank %d: %s", (int)fl, text, first, text + fl);
    }
    MPI_Bcast(&b, (int)sizeof b, MPI_BYTE, first, comm);
    if (msg && len) snprintf(msg, len, "%s", b.text);
    return (vw_status)b.status;
}

vw_status vw_engine_agree(vw_status local, char *msg, size_t len)
{
    if (!mpi_up()) return local;
    int size;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size == 1) return local;
    return vw__mpi_agree(MPI_COMM_WORLD, local, msg, len);
}

void vw_engine_broadcast(void *buf, size_t n)
{
    if (!mpi_up() || vw_engine_size() == 1) return;
    /* In pieces, as MPI counts in int. */
    for (size_t off = 0; off < n;) {
        size_t k = n - off < (size_t)INT_MAX ? n - off : (size_t)INT_MAX;
        MPI_Bcast((char *)buf + off, (int)k, MPI_BYTE, 0, MPI_COMM_WORLD);
        off += k;
    }
}

/* This process's share of its host's cores as a fraction, num / den: the processes of
   the host that may run on the same cores split them (three unbound processes on two
   cores have two thirds of a core each). cores: vw_host_cores, which VW_CORES replaces
   outright (a process told its cores keeps them). Collective on comm. */
static void core_share(MPI_Comm comm, int cores, long *num, long *den)
{
    *num = cores, *den = 1;
    MPI_Comm host;
    if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &host) != MPI_SUCCESS)
        return;
    int n = 1;
    MPI_Comm_size(host, &n);
    if (n > 1) {
        /* The masks' union by a bitwise or of their bytes, their sizes by a sum: two
           reductions, whatever the number of processes on the host. */
        cpu_set_t mine, any;
        CPU_ZERO(&mine);
        if (sched_getaffinity(0, sizeof mine, &mine) != 0) CPU_SET(0, &mine);
        long count = CPU_COUNT(&mine), sum = 0;
        MPI_Allreduce(&mine, &any, (int)sizeof mine, MPI_BYTE, MPI_BOR, host);
        MPI_Allreduce(&count, &sum, 1, MPI_LONG, MPI_SUM, host);
        if (sum > 0 && !vw__host_cores_given())
            *num = (long)cores * CPU_COUNT(&any), *den = sum;
    }
    MPI_Comm_free(&host);
}

int vw__mpi_core_share(MPI_Comm comm, int cores)
{
    long num, den;
    core_share(comm, cores, &num, &den);
    return num < den ? 1 : (int)(num / den); /* whole workers, at least one */
}

double vw_engine_core_share(void)
{
    double share = vw_host_cores(), fewest = share;
    if (mpi_up() && vw_engine_size() > 1) {
        long num, den;
        core_share(MPI_COMM_WORLD, (int)share, &num, &den);
        share = (double)num / (double)den;
        MPI_Allreduce(&share, &fewest, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    }
    return fewest;
}

int vw_engine_workers(int workers)
{
    /* The reductions run whatever this rank's workers, so every rank makes them. */
    double share = vw_engine_core_share();
    /* A count vw_world_create refuses has no answer (it took a negative one as one per
       core); the reductions above were still made, as the other ranks make them. */
    if (workers < 0 || workers > VW__MAX_WORKERS) return -1;
    return workers > 0 ? workers : share < 1 ? 1 : (int)share;
}

/* On the communicator vw__mpi_attach will choose for a world made with c, without making
   the world: the application's own set-up before vw_world_create can then fail on one
   rank and still meet the others in the same collective call. Where no communicator can
   be had (one was given but MPI is not initialised), vw_world_create fails alike on
   every rank, so local is all there is to say. */
vw_status vw_config_agree(const vw_config *c, vw_status local, char *msg, size_t len)
{
    int init = 0;
    MPI_Initialized(&init);
    if (!(c && c->mpi_comm) && !init && vw__mpi_launcher_env()) {
        char why[300];
        (void)vw__mpi_autoinit(why, sizeof why); /* (a low thread level: create will say) */
    }
    if (!mpi_up()) return local; /* the threads engine alone */
    MPI_Comm base = c && c->mpi_comm ? *(const MPI_Comm *)c->mpi_comm : MPI_COMM_WORLD;
    int size = 1;
    MPI_Comm_size(base, &size);
    if (size == 1) return local;
    return vw__mpi_agree(base, local, msg, len);
}

/* The public vw_world_agree (world.c) refuses a call from a callback, then comes here. */
vw_status vw__world_agree(vw_world *w, vw_status local, char *msg, size_t len)
{
    MPI_Comm c = vw__mpi_world_comm(w);
    if (c == MPI_COMM_NULL) return local;
    return vw__mpi_agree(c, local, msg, len);
}
