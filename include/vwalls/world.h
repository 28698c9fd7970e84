/* vwalls/world.h - the runtime: a world of cells hosted by workers, run to quiescence.
 *
 * Life cycle (Embree's commit step): create, add objects, commit (cells are built),
 * post initial messages and/or let step() callbacks create work, run. run() returns at
 * global quiescence: every worker idle and every message sent has been handled.
 * A world may be run again (next frame, next radiosity round); it may be given a new
 * decomposition between runs (objects migrate to their new cells, cells are rebuilt).
 *
 * Engines: worker threads in one process (always), and MPI between processes when the
 * library was built with MPI and the world is created inside an MPI job.
 *
 * Under MPI every process takes the steps of a world's life alike, with the same
 * arguments: vw_world_create, vw_world_add_objects, vw_world_update_object,
 * vw_world_set_replicas, vw_world_redecompose, vw_world_remap, vw_world_commit and
 * vw_world_run are collective. Each ends in agreement (vw_world_agree): a step that
 * fails on one process only (out of memory, a cell_build that fails there) fails on
 * every process with the status of the lowest failing one, and vw_world_errmsg (for
 * create: vw_world_errmsg(NULL)) says "rank R: <its message>" everywhere. So a program
 * may stop at the first failing step on every process alike, and no process is left
 * waiting for another in a collective call. vw_world_post and the queries are local.
 * What a program does on one process alone before or between these steps (reading its
 * copy of the input, allocating) needs its own agreement before the next one:
 * vw_config_agree before vw_world_create, vw_world_agree after (vwalls/engine.h).
 * vw_world_create also refuses, on every process, a process whose module differs from
 * process 0's in name, record size, message kinds or counters (another build: packets
 * cross as raw bytes), and vw_world_commit one given another world (walls, mapping,
 * copies, objects' bounds).
 *
 * Misuse. A call given a NULL world returns VW_E_INVAL (a status), 0, -1 or NULL (the
 * queries, each as said below), or does nothing (the void ones). Every other call of
 * this header, and of map.h on a world (vw_world_remap, vw_world_traffic,
 * vw_world_machines), that returns a status other than VW_OK sets the message
 * vw_world_errmsg(w) returns, queries (vw_world_cell_stats) included; a query made
 * from a callback leaves the message as it was (the workers share the world) and only
 * returns its status. vw_world_agree (engine.h) is the exception: it writes the agreed
 * message into the caller's buffer and leaves vw_world_errmsg's alone. A world changes
 * only between runs, from the thread that runs it: a module's callback (cell_build,
 * step, a handler, an output handler, load, done) that calls vw_world_add_objects,
 * _update_object, _set_replicas, _redecompose, _remap, _commit, _post, _run, _done,
 * _write_stats, _reset_stats, vw_balance_world or vw_world_free on its own world stops
 * the process with a message on stderr naming the call, as a send that cannot be meant
 * does (module.h): returning a status there would leave the run hung or the cells
 * changed under the workers. So do vw_world_agree, vw_world_traffic and
 * vw_world_machines, which change nothing but are collective under MPI: made from a
 * worker thread in the middle of a run, they would meet the run's own collectives (a
 * hang, or agreements mixed up). The other queries may be called from callbacks;
 * figures they read are those of the last run.
 */
#ifndef VWALLS_WORLD_H
#define VWALLS_WORLD_H

#include <stdio.h>
#include "vwalls/common.h"
#include "vwalls/decomp.h"
#include "vwalls/module.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vw_world vw_world;

typedef struct vw_config {
    int workers;             /* worker threads per process; 0 = number of cores (under
                                MPI its share of the host's: vw_engine_workers);
                                negative: VW_E_INVAL at create, above 1024 VW_E_LIMIT
                                (vw_engine_workers answers -1 for both) */
    size_t packet_bytes;     /* flush a packet when it holds this much (default 32 KiB;
                                at most 1 GiB, VW_E_LIMIT above) */
    size_t cap_bytes;        /* a worker whose unconsumed sent bytes exceed this drains its
                                inbox before step() creates new work (default 64 MiB; each
                                packet counts 4 KiB more than its bytes, so the cap also
                                bounds how many are in flight) */
    /* Stress switches (also from the environment: VW_STRESS=seed, VW_STRESS_SPLIT=1). */
    uint64_t stress_seed;    /* nonzero: delay and reorder deliveries at random */
    int stress_split;        /* one message per packet */
    /* Mapping: cell -> global worker id (process * workers + local worker), ncells
       entries; NULL = contiguous blocks of cells per worker. Copied at create. */
    const int *cell_worker;
    /* MPI: pointer to an MPI_Comm to run on (the library then never calls MPI_Init or
       MPI_Finalize); NULL = MPI_COMM_WORLD if MPI is initialised or the process was
       started by a launcher, else the threads engine alone. */
    const void *mpi_comm;
    /* Per-worker slow-down factor for emulating unequal machines: processes x workers
       entries, copied at create (NULL = none). */
    const double *worker_slowdown;
    /* Farmed work (vw_ctx_next_batch): a copy of a cell whose turns are used up takes
       the turns the cell's other copies have not taken: those in its process one at a
       time, those on other processes by asking their process, its part of what the
       copy has left (half with equal speeds) in one round trip. 1 = on, 0 = off
       (every copy makes exactly its equal share), -1 (the default) = on when the
       process has no more workers than cores. Then taking turns only evens out a
       machine's speed differences; with more workers than cores (emulating a larger
       machine) it would hand the work to whichever threads the system happens to run,
       and the per-worker loads and lambda would no longer mean the same on every
       machine. */
    int steal;
    /* Relative speed of every global worker (processes x workers entries, all > 0;
       copied at create), or NULL: all equal. The master and copies of a duplicated cell
       take shares of its turns (vw_ctx_next_batch) and of the messages sent to it
       (vw_send_cell) in proportion to their workers' speeds, so a copy on a machine
       three times as fast makes three times the batches, also across processes (until
       its turns are used up: see steal). */
    const double *worker_speeds;
} vw_config;

/* Defaults, then the environment's stress switches. */
VW_API void vw_config_init(vw_config *c);

VW_API vw_status vw_world_create(const vw_module *m, void *user, const vw_decomp *d,
                                 const vw_config *c, vw_world **out);
VW_API void vw_world_free(vw_world *w);
/* The message of the last step that failed, with detail (sqlite3_errmsg style: read it
   before the next step, which clears it). With w NULL: why this
   thread's last vw_world_create failed (which leaves no world to ask), e.g. "processes
   were given different worker counts (1 to 2)". */
VW_API const char *vw_world_errmsg(const vw_world *w);

/* Objects get global ids in the order added (0, 1, ...); no callback is told the id, so
   a module that needs it keeps it in its object record. An object whose bounds meet no
   cell (outside the world box) is held by no cell: that is how a removed object keeps
   its id (the dynamic scenes do so), and vw_world_cells_of_object reports 0 for it.
   Under MPI every process is given every object, and keeps the records of those its
   cells and copies hold (and of some no cell holds): each its share, fetched from the
   others at a commit that needs them (docs/runtime.md, "Object records"). */
VW_API vw_status vw_world_add_objects(vw_world *w, const void *objects, size_t n);
/* Build every cell (cell_build on the hosting worker). */
VW_API vw_status vw_world_commit(vw_world *w);
/* A message delivered to `cell` at the start of the next run, on the worker that hosts
   the cell then (after any vw_world_remap or vw_world_redecompose in between; one that
   leaves no cell `cell` is refused with VW_E_STATE while the message waits). msg may be
   NULL for a kind of size 0. An unknown cell or kind, a kind without handle, or a NULL
   msg for a kind of size > 0 is VW_E_INVAL with a message. */
VW_API vw_status vw_world_post(vw_world *w, int cell, int kind, const void *msg);
/* The same, told the size of the record msg points to (module.h, sized sends): a size
   other than the kind's is VW_E_INVAL with a message naming both, nothing posted.
   VW_WORLD_POST(w, cell, kind, rec) passes &(rec) and sizeof(rec); a signal (a kind of
   size 0) is posted with msg NULL and size 0. */
VW_API vw_status vw_world_post_sized(vw_world *w, int cell, int kind, const void *msg, size_t size);
#define VW_WORLD_POST(w, cell, kind, rec) \
    vw_world_post_sized((w), (cell), (kind), &(rec), sizeof(rec))
/* Runs every cell to quiescence (no message in flight, every step() idle); commits
   first when objects or the decomposition changed since the last commit. A run that a
   callback failed (vw_ctx_fail, module.h) or that could not allocate a packet drops
   the rest of the module's work, still ends, and returns that status (on every
   process, agreed). */
VW_API vw_status vw_world_run(vw_world *w);

/* The module's done() (its local convergence test, module.h) asked of every cell, on the
   process hosting the cell (its master; copies are not asked), between runs: *done is 1
   when every cell said nonzero, else 0. Every cell is asked each time. Collective under
   MPI: every process gets the same answer. VW_E_INVAL (and *done 0) when the module has
   no done() or done is NULL, VW_E_STATE when a cell is not built (commit or run first).
   An iterative solver's outer loop: run, then stop when vw_world_done says so. */
VW_API vw_status vw_world_done(vw_world *w, int *done);

/* Replace the decomposition (and optionally the mapping) between runs: objects are
   re-placed, moved between workers/processes, and the cells rebuilt. A mapping to a
   worker that does not exist is VW_E_INVAL, and the world stays as it was. */
VW_API vw_status vw_world_redecompose(vw_world *w, const vw_decomp *d, const int *cell_worker);
/* Replace object `id` (dynamic scenes): it leaves cells it no longer overlaps, joins
   the new ones; only the touched cells are rebuilt at the next commit/run. */
VW_API vw_status vw_world_update_object(vw_world *w, size_t id, const void *object);
/* The cells that hold object `id` now, ascending: writes at most max ids to out (may be
   NULL with max 0) and returns how many there are. The placement is known to every
   process, so this answers the same everywhere. O(objects held by all cells): for
   tests and tools that check the placement rule, not for inner loops. */
VW_API int vw_world_cells_of_object(const vw_world *w, size_t id, int *out, int max);

/* Cell duplication (the paper's fourth strategy): the cell gets copies on the given
   global workers, each built from the cell's objects at the next commit/run; messages
   of VW_MSG_INDEPENDENT kinds are then shared between the master and the copies (see
   module.h). n = 0 removes the copies. Between runs only, and with the same arguments
   on every process. VW_E_INVAL when the module has no independent kind, a worker is out
   of range, repeated, or the master's own. A copy whose worker stays keeps its state and
   figures; the figures of dropped copies are dropped (reset the stats first). A new
   decomposition or mapping (vw_world_redecompose, vw_world_remap) removes every copy;
   the neighbourhood of cells never changes. */
VW_API vw_status vw_world_set_replicas(vw_world *w, int cell, const int *workers, int n);
/* The workers of the cell's copies (not the master): writes at most max to out (may be
   NULL with max 0) and returns how many there are. */
VW_API int vw_world_replicas(const vw_world *w, int cell, int *out, int max);

/* Engine facts. A NULL world has rank -1, 0 processes and workers, is not the output,
   has decomposition NULL; an unknown cell (or a NULL world) has worker -1. */
VW_API int vw_world_process(const vw_world *w);       /* this process's rank */
VW_API int vw_world_processes(const vw_world *w);
VW_API int vw_world_workers(const vw_world *w);       /* per process */
VW_API int vw_world_is_output(const vw_world *w);     /* rank 0 */
VW_API const vw_decomp *vw_world_decomp(const vw_world *w);
VW_API int vw_world_cell_worker(const vw_world *w, int cell);

/* Measurements of the last run(s), valid on every process after run(). With a NULL
   world, an unknown cell, worker or counter: VW_E_INVAL from vw_world_cell_stats (with a
   message, but for a NULL world), 0 from the others; vw_world_imbalance(NULL) is 0 (a
   lambda is at least 1); vw_world_reset_stats(NULL) does nothing. */
typedef struct vw_cell_stats {
    int worker;
    size_t objects;
    uint64_t messages_in;
    double busy_s;      /* measured time in handlers and step() (all runs) */
    double load;        /* module's load() if given, else busy_s */
    int replicas;       /* copies besides the master (figures above include theirs) */
} vw_cell_stats;
VW_API vw_status vw_world_cell_stats(const vw_world *w, int cell, vw_cell_stats *out);
VW_API double vw_world_worker_busy(const vw_world *w, int global_worker);
/* Sum over all cells and processes of module counter idx. */
VW_API int64_t vw_world_counter(const vw_world *w, int idx);
VW_API int64_t vw_world_cell_counter(const vw_world *w, int cell, int idx);
/* Sum of module counter idx over the cells and copies that global worker g hosts. */
VW_API int64_t vw_world_worker_counter(const vw_world *w, int g, int idx);
/* Imbalance lambda = max / mean of worker busy times; with worker speeds
   (vw_config.worker_speeds), the longest busy time against the time the work would take
   split in proportion to the speeds (a worker's work: its busy time times its speed). */
VW_API double vw_world_imbalance(const vw_world *w);
VW_API void vw_world_reset_stats(vw_world *w);

/* Times of phases the application measured itself, for the stats JSON
   ("load", "build", "compute", "balance", ...). Accumulates; a phase may have any name
   (it is escaped in the JSON), and there may be any number of them. */
VW_API void vw_world_add_time(vw_world *w, const char *phase, double seconds);
/* The time accumulated for a phase (0 if none). */
VW_API double vw_world_time(const vw_world *w, const char *phase);

/* What the balancer did, for the stats JSON "balance" member. */
VW_API void vw_world_set_balance_info(vw_world *w, const char *strategy, double imbalance_before,
                                      double imbalance_after, uint64_t migrated_objects);
/* The stats JSON's balance.migrated_objects: the (object, worker) pairs that new
   decompositions and mappings (vw_world_redecompose, vw_world_remap) made since the world
   was created, none before its cells were first built; or the count last given to
   vw_world_set_balance_info, and those made since. The same on every process. */
VW_API uint64_t vw_world_migrated(const vw_world *w);

/* The stats JSON (docs/runtime.md, Statistics), written by the output process only,
   through vw_outfile (vwalls/outfile.h: complete or absent). extra_json: more
   top-level members ("\"rays\": {...}") or NULL, copied as they are: writing them as
   JSON is the caller's part. On failure vw_world_errmsg() says "path: reason". */
VW_API vw_status vw_world_write_stats(vw_world *w, const char *path, const char *command,
                                      const char *extra_json);

#ifdef __cplusplus
}
#endif
#endif
