/* vwalls/engine.h - the process-level engine: MPI start-up and shutdown, and agreement
 * between processes (every rank learns whether every other rank is fine, and if not,
 * which rank failed and why), so that no rank computes on input another rank rejected.
 *
 * All functions work in a build without MPI and in a process started without a launcher:
 * there they describe a single process and agree with nobody but themselves.
 */
#ifndef VWALLS_ENGINE_H
#define VWALLS_ENGINE_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vw_world vw_world;
typedef struct vw_config vw_config;

/* Nonzero when the build has MPI and the process is part of an MPI job: MPI is already
   initialised, or an MPI launcher (mpirun, mpiexec, srun) started it. */
VW_API int vw_engine_launched(void);

/* Initialises MPI when launched and not yet initialised, requesting the thread level the
   engine needs (MPI_THREAD_FUNNELED: only the thread that calls vw_world_run and the
   collective calls below makes MPI calls). Fails with VW_E_MPI and a message when MPI
   offers less. Without a launcher it does nothing and returns VW_OK. */
VW_API vw_status vw_engine_init(int *argc, char ***argv, char *msg, size_t len);
/* Finalises MPI if vw_engine_init initialised it (a second call does nothing). Call it
   last, after vw_world_free of every world: any call on a world after it (a run, an
   agreement) makes MPI calls after MPI_Finalize, which MPI forbids (the job aborts or
   hangs), and a world freed after it cannot free its communicator. */
VW_API void vw_engine_finish(void);
/* Ends the whole job at once with this status (MPI_Abort when launched, exit otherwise),
   after printing msg; for failures the other ranks cannot learn about otherwise. */
VW_API void vw_engine_abort(int status, const char *msg);

/* Rank and size on MPI_COMM_WORLD (0 and 1 without MPI). */
VW_API int vw_engine_rank(void);
VW_API int vw_engine_size(void);

/* Agreement (collective: every rank must call it). `local` is this rank's status and
   msg its message. Returns VW_OK on every rank when every rank passed VW_OK; otherwise
   every rank returns the status of the lowest failing rank, and msg (of size len) holds
   "rank R: <its message>" on every rank. vw_engine_agree runs on MPI_COMM_WORLD (usable
   before a world exists), vw_world_agree on the world's communicator (VW_E_INVAL for a
   NULL world, with MPI or without). vw_config_agree runs on the communicator a world
   made with config c would run on (c->mpi_comm, or MPI_COMM_WORLD when c or its
   mpi_comm is NULL), before that world exists: a program that prepares rank-local
   input for vw_world_create (reads, checks, allocates) calls it once with that
   preparation's status before vw_world_create, so a rank that failed alone does not
   return while the others wait in vw_world_create; after the world exists,
   vw_world_agree does the same before the next collective step. Like vw_world_create
   it initialises MPI when the process was started by a launcher and nobody did; where
   the world would run on the threads engine alone (or on one process) it returns
   local and leaves msg as it is. The agreed message is in msg only: vw_world_agree
   leaves vw_world_errmsg as it was. vw_world_agree is made between runs, from the
   thread that runs the world: called from a module's callback (with either engine) it
   stops the process with a message naming it, as the calls that change the world do
   (world.h, Misuse). */
VW_API vw_status vw_engine_agree(vw_status local, char *msg, size_t len);
VW_API vw_status vw_world_agree(vw_world *w, vw_status local, char *msg, size_t len);
VW_API vw_status vw_config_agree(const vw_config *c, vw_status local, char *msg, size_t len);
/* "what: msg" into dst (len bytes), keeping an agreed message's leading "rank R: " in
   front: "rank 1: cell 2: no room" wrapped in "applying edits" is "rank 1: applying
   edits: cell 2: no room", so the rank that failed leads every message alike. dst must
   not overlap msg. */
VW_API void vw_errmsg_wrap(char *dst, size_t len, const char *what, const char *msg);

/* Broadcast (collective on MPI_COMM_WORLD: every rank must call it with the same n): the
   n bytes at buf on rank 0 replace those at buf on every other rank. For input only rank
   0 can read, such as standard input, which MPI launchers forward to rank 0 alone. Does
   nothing without MPI or with one process. */
VW_API void vw_engine_broadcast(void *buf, size_t n);

/* Workers per process of a world created on MPI_COMM_WORLD with vw_config.workers =
   workers: workers when positive; 0: one per core (vw_host_cores), and under MPI each
   process's share of its host's cores (processes on one host that may run on the same
   cores split them), the fewest of any process, which every process of the world then
   runs (global worker = rank * W + local); -1 for a count vw_world_create refuses
   (negative: VW_E_INVAL, above 1024: VW_E_LIMIT), which makes no world. So a tool can
   size per-worker options (speeds) before the world exists, the same on every host.
   Collective under MPI: every rank must call it, whatever its count. */
VW_API int vw_engine_workers(int workers);
/* The cores each process of a world on MPI_COMM_WORLD may count on, the fewest of any
   process: vw_host_cores alone, and under MPI each process's share of its host's cores
   as a fraction (three unbound processes on two cores have 2/3 of a core each), which
   vw_engine_workers(0) rounds down to whole workers, at least one. More workers than
   this is a crowded host: a worker's busy time is then partly time spent waiting for a
   core. The same on every process; collective under MPI, as vw_engine_workers. */
VW_API double vw_engine_core_share(void);
/* What this host gives the process (not collective). vw_host_cores: the cores it may
   run on, the default worker count: its CPU affinity (taskset, a container's cpuset, an
   MPI launcher's binding), or fewer when a control group it belongs to, or one above,
   has a CPU quota (cgroup v2 cpu.max, v1 cpu.cfs_quota_us), rounded up to whole cores.
   vw_host_memory: the bytes it may still allocate, /proc/meminfo's MemAvailable or the
   least room left under a memory limit of those groups (v2 memory.max, v1
   memory.limit_in_bytes), if lower; 0 when nothing says. VW_CORES=N (1 to 1024) and
   VW_MEM_AVAILABLE=BYTES replace the readings, so one machine can play hosts of other
   sizes; another VW_CORES is ignored with a warning on stderr (once a process, from
   the first MPI process only). */
VW_API int vw_host_cores(void);
VW_API uint64_t vw_host_memory(void);

#ifdef __cplusplus
}
#endif
#endif
