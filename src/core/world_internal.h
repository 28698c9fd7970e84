/* world_internal.h - the runtime's representation: world, cells, workers, packets.
 *
 * Ownership rules that must stay true:
 *  - a cell's state is touched only by the worker hosting it (cell->worker);
 *  - a packet is owned by exactly one party at a time: the sending worker while it is
 *    open, the destination's inbox, then the worker handling it (which frees it);
 *  - w->active counts busy workers plus packets sent and not yet handled; it reaches
 *    zero exactly once per run, at global quiescence, and only then does run() end.
 *    With MPI the communication thread holds one count of its own for the whole run
 *    and gives it back only when the processes have agreed on global quiescence, so
 *    local quiescence alone never ends a run;
 *  - a cell's measurements (messages_in, busy_s, counters) are written only by the
 *    process hosting it; after every run the other processes receive copies;
 *  - a duplicated cell's copies (vw__replica) follow the same rules each: one worker
 *    touches a copy's state and figures, and a worker hosts at most one copy of a cell
 *    (the master counts as one), so (cell, worker) names the copy a message is for.
 */
#ifndef VW_WORLD_INTERNAL_H
#define VW_WORLD_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "vwalls/world.h"

#define VW__OUTPUT (-1) /* destination "the output process" */

/* One message inside a packet: header then payload, padded to 8 bytes. */
typedef struct vw__msg_header {
    int32_t cell;   /* destination cell; unused for output messages */
    uint16_t kind;
    uint16_t size;
} vw__msg_header;

typedef struct vw__packet {
    struct vw__packet *next;
    int dest;          /* global worker id, or VW__OUTPUT */
    int src;           /* global worker that filled it, -1 for posted messages */
    uint32_t nmsgs;
    size_t used, cap;  /* bytes of data */
    unsigned char data[];
} vw__packet;
/* The largest vw_config.packet_bytes (vw_world_create refuses more). */
#define VW__MAX_PACKET_BYTES ((size_t)1 << 30)

/* Cache-line alignment of what one worker writes on its hot path (a cell's figures and
   counters, a worker's own state): two workers never write the same line. Arrays of
   these types come from vw__calloc_lines. */
#define VW__LINE 64

/* A copy of a duplicated cell on another worker (balance strategy "duplicate"): its
   own module state built from the cell's objects, and its own figures, which add up
   with the master's to the cell's. */
/* Imbalance lambda of the workers' work t[g] (time on a worker of speed 1) given their
   relative speeds (NULL: all equal): the slowest worker's time max t[g] / speed[g]
   against the ideal, the time of a split by speed, sum t / sum speed. With equal
   speeds that is max / mean of t, DESIGN's definition. 1 with no work; INFINITY when a
   speed is not positive and finite or a t is negative, NaN or infinite. */
double vw__lambda(const double *t, const double *speeds, int n);
/* What the host at `root` ("" for this one: a test lays out /proc and /sys in a
   directory) gives this process (host.c): the CPU quota of its control groups in cores
   (0: none), the least room left under their memory limits and /proc/meminfo's
   MemAvailable, in bytes (0: not said). A NULL pointer skips what it would read. */
void vw__host_probe(const char *root, double *quota_cores, uint64_t *cgroup_mem, uint64_t *meminfo_mem);

/* A unit's (a cell's, or a copy's) measured busy time, and the inline hand-offs into it
   (vw_ctx_enter) that the meter (runtime.c) noted since its worker last read the clock. */
typedef struct vw__busy {
    double s;
    unsigned notes;
} vw__busy;

/* Turns a unit took from a copy in another process (vw_ctx_next_batch): slots [at, end)
   of copy `unit`'s counter, its part of what that copy had left in one round trip. Only
   the unit's own worker touches it. */
typedef struct vw__stash {
    int unit;
    uint64_t at, end;
} vw__stash;

typedef struct vw__replica {
    _Alignas(VW__LINE) int worker; /* global worker id, never the master's */
    void *state;
    int built;
    unsigned built_version;  /* the cell's version it was built from */
    int64_t *counters;       /* module counters, ncounters */
    double load;             /* load() of the hosting process at the last run's end */
    /* Written by the hosting worker per message; other workers read `worker` above
       (vw__cell_rep_of), so these get a line of their own. */
    _Alignas(VW__LINE) uint64_t messages_in;
    vw__busy busy;
    _Atomic uint64_t batches; /* turns taken in this run (vw_ctx_next_batch; other
                                 workers of the process take them too at the end) */
    atomic_int spent;         /* a copy in another process: its process answered that
                                 its turns are used up (this run) */
    vw__stash stash;          /* turns taken from a copy in another process, to make */
} vw__replica;

typedef struct vw__cell {
    /* Read by every worker that sends to or enters the cell: */
    _Alignas(VW__LINE) int worker; /* global worker id */
    int nreps;
    vw__replica *reps;       /* copies besides the master, nreps of them */
    int farmed;              /* every worker of this process holds a copy (set per run) */
    int solo;                /* the worker vw_ctx_enter's fast path enters it on: `worker`
                                without copies, -1 with them (set per run) */
    unsigned *rr;            /* duplicated cells: per local worker, the next copy to send to
                                (one counter per sender and cell, so each cell's copies get
                                their shares whatever else the sender sends), at
                                rr[local * VW__RR_STRIDE]: a cache line per sender */
    /* A duplicated cell's work shared among its units (0 = the master, r = copy
       reps[r - 1]) in proportion to their workers' speeds (vw_config.worker_speeds;
       equal without them): a pattern of share_len slots repeated for ever, share_seq[j]
       the unit of slot j. Unit u's slots, ascending, are share_pos[share_first[u] ..
       share_first[u + 1]): its i-th turn (vw_ctx_next_batch) is the batch of its i-th
       slot, and messages sent to the cell go to the units slot after slot
       (vw_send_cell). All NULL / 0 without copies (make_shares, world.c). */
    int share_len;
    int *share_seq, *share_pos, *share_first;
    void *state;             /* the module's cell state */
    int built, dirty;
    size_t *objs;            /* ids of the objects overlapping the cell */
    size_t nobjs, capobjs;
    int64_t *counters;       /* module counters, ncounters */
    double load;             /* load() of the hosting process at the last run's end */
    unsigned version;        /* bumped whenever the cell's objects change (copies rebuild) */
    /* Written by the hosting worker per message or hand-off: a line of their own, or
       every other worker's reads of the fields above would bounce it between cores. */
    _Alignas(VW__LINE) uint64_t messages_in;
    vw__busy busy;
    _Atomic uint64_t batches; /* the master's turns taken in this run (as above) */
    atomic_int spent;         /* (as above) */
    vw__stash stash;
} vw__cell;

/* Stride of vw__cell.rr: one cache line per sending worker. */
#define VW__RR_STRIDE (VW__LINE / sizeof(unsigned))

/* Units noted (inline hand-offs, vw_ctx_enter) before the meter reads the clock again. */
#define VW__METER_N 64

typedef struct vw__worker {
    _Alignas(VW__LINE) struct vw_world *w;
    int local, global;
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    vw__packet *head, *tail;   /* the inbox, guarded by mu */
    int busy;
    atomic_size_t outstanding; /* bytes this worker sent that are not yet handled
                                  (vw__packet_charge each packet) */
    vw__packet **out;          /* open packet per destination: [0..G) workers, [G] output */
    int *cells, ncells;        /* the cells this worker hosts (masters and copies) */
    int *cell_rep;             /* per entry of cells: 0 = the master, r = copy reps[r-1] */
    int step_cursor;
    uint64_t rng;              /* stress switch */
    double busy_s;
    double yielded;            /* when the worker last gave its core away (share_core) */
    /* The meter (runtime.c): the units (cell, copy) that ran since the clock was last
       read at `mark`, each once, with how often it was noted (its notes); that time is
       shared among the nnotes notes when it is next read. `idle` stands for no unit. */
    vw__busy *metered[VW__METER_N];
    int nmetered, nnotes;
    vw__busy idle;
    double mark;
    uint64_t msgs_sent, bytes_sent, packets_sent;
    uint64_t msgs_remote, bytes_remote; /* to other processes */
    uint64_t turns_remote;     /* turns made of copies on other processes (stash) */
    /* Cell-to-cell traffic by destination, for the mapping's locality figures
       (vw_world_traffic, src/map): messages and bytes to this same worker, and per
       destination process [2p] messages, [2p+1] bytes (nprocs pairs). */
    uint64_t tr_self_msgs, tr_self_bytes;
    uint64_t *tr_proc;
    vw_status build_status;
    int build_cell, build_rep; /* the unit whose build failed (build_status not VW_OK) */
} vw__worker;

/* Per-worker figures of all processes (index: global worker), gathered after each run
   so that every process, and the stats JSON at rank 0, sees the whole job. */
typedef struct vw__worker_stats {
    double busy_s;
    uint64_t msgs_sent, bytes_sent, packets_sent;
    uint64_t msgs_remote, bytes_remote; /* that crossed a process boundary */
    uint64_t turns_remote;              /* turns made of copies on other processes */
    uint64_t peak_rss;                  /* of the worker's process */
    uint64_t records;                   /* object records its process keeps (vw_world.nslots) */
    uint64_t fetched;                   /* and got from others (vw_world.fetched) */
} vw__worker_stats;

/* How packets leave this process (the MPI engine); NULL for the threads engine.
   A table of functions, like SQLite's VFS: one contract, one implementation per engine. */
typedef struct vw__transport {
    const char *name;
    /* Takes ownership of a packet for a worker of another process (or the output
       process); must keep the termination protocol's counts. Called by workers. */
    void (*send)(struct vw_world *w, struct vw__worker *from, struct vw__packet *p);
    /* Drives the exchange while the workers run, on the thread that called run(), and
       returns at global quiescence (after giving back its count in w->active). */
    vw_status (*run)(struct vw_world *w);
    /* After a run, collectively: makes every process's cell and worker figures global. */
    vw_status (*sync)(struct vw_world *w);
    /* Called by worker `thief` when its own turns are used up: takes some of unit
       `unit`'s turns of `cell` (vw__take_turns on the unit's process): returns how many
       (0: none left), the first at *first; waits for the answer. */
    uint64_t (*take_turns)(struct vw_world *w, int cell, int unit, int thief,
                           uint64_t nbatches, uint64_t *first);
    void (*free)(struct vw_world *w);
    void *impl;
} vw__transport;

struct vw_world {
    const vw_module *m;
    void *user;
    vw_decomp *decomp;
    vw_config cfg;
    int rank, nprocs;          /* process rank and count (1 without MPI) */
    int nworkers;              /* per process */
    int gworkers;              /* all processes */
    int steal;                 /* cfg.steal decided (vw_ctx_next_batch) */
    int share_core;            /* busy workers yield now and then (runtime.c share_core) */
    double *speeds;            /* cfg.worker_speeds copied (gworkers), or NULL */
    double *slowdown;          /* cfg.worker_slowdown copied (gworkers), or NULL */
    int ncells;
    vw__cell *cells;
    int *cell_worker;          /* cell -> global worker */
    vw__worker *workers;       /* this process's workers */
    /* The objects. Ids 0 .. nobjects-1, in the order added. On one process every
       record is kept, record id at objects + id * object_size (slot and bounds NULL).
       Under MPI (nprocs > 1) a process keeps only its share (DESIGN.md: "a worker holds
       only its cells' share"): the records of the objects its cells and copies hold
       (an object no cell holds, by its home process id % nprocs, so that every record
       is kept somewhere); slot[id] is the record's place in objects, or VW__NO_SLOT,
       and bounds[id] every object's bounds, which the placement reads. The commit
       fetches what a process lacks from a process that keeps it and then drops what it
       no longer needs (share_records, world.c). */
    unsigned char *objects;
    size_t nobjects;           /* objects added */
    size_t nslots, capslots;   /* records in objects, and room for */
    size_t *slot;
    vw_box *bounds;
    uint64_t fetched;          /* records this process got from others, since created */
    double pad;                /* placement padding (world units) */
    int committed;
    /* The workers' unit lists (vw__worker.cells) lag the copies of duplicated cells:
       vw_world_set_replicas only marks them, and the commit lists them once, so setting
       copies on every cell costs cells + units, not cells x units. Never set while
       committed (set_replicas uncommits), so a run always finds them current. */
    int units_stale;
    vw__packet *posted;        /* messages posted before run */
    atomic_long active;
    atomic_int finished;
    /* A failed run (vw_ctx_fail, or a packet the runtime could not allocate). From the
       first failure on the run drops the module's work: handlers, steps and output
       handlers are no longer called, while the messages are still counted, so the run
       reaches quiescence as before. `dropping` says so to the workers (the MPI
       transport also sets it when a wave reports another process dropping); the first
       failure of this process writes run_err and run_msg (run_failed 0 -> 1), which
       vw_world_run returns, agreed between processes. Reset at every run. */
    atomic_int dropping;
    atomic_int run_failed;
    vw_status run_err;
    char run_msg[400];
    /* The worker threads, started at the first build or run and kept until the world
       is freed (an iterative solver runs hundreds of times): under pool_mu, run_gen
       counts the jobs dispatched, pool_left the workers still in the current one. */
    pthread_mutex_t pool_mu;
    pthread_cond_t pool_cv;
    unsigned run_gen;
    int pool_started, pool_left, pool_quit;
    void (*pool_job)(struct vw__worker *); /* the current job: a run or a build */
    pthread_mutex_t output_mu; /* output handlers run one at a time */
    /* Non-NULL while the module's callbacks may run (a run, a build, load() or done()
       called between runs): what runs them, for the message. A call that changes the
       world then comes from a callback (or from another thread) and would hang in
       pool_wait or change cells under the workers: vw__world_guard stops the process. */
    _Atomic(const char *) in_callbacks;
    vw__transport *transport;
    vw__worker_stats *wstats;  /* gworkers entries, valid after a run */
    char errmsg[512];
    vw_status err;
    /* stats */
    struct vw__phase {         /* vw_world_add_time, in the order first added */
        char *name;
        double s;
    } *phases;
    int nphases, capphases;
    char balance_strategy[32];
    double imbalance_before, imbalance_after;
    uint64_t migrated;
    uint64_t runs;
};

/* world.c */
/* The fraction of a cell's work that its unit u (0 = the master, r = copy r) takes: 1
   without copies. */
double vw__unit_share(const vw__cell *c, int u);
/* Records the first error of the current step (a public call: create, add, update, set
   copies, redecompose or remap, commit, post, run, balance, write stats) as the world's
   error with its message; later ones within the step (wrappers of the same failure)
   keep it. */
vw_status vw__world_error(vw_world *w, vw_status st, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* A failed query (a call that reads the world and changes nothing of what it computes:
   vw_world_cell_stats, vw_world_traffic, vw_world_machines) says why like a failed step,
   replacing any older message; called from a callback, where the workers share the
   world, it leaves the message alone and only returns st. */
vw_status vw__world_query_error(const vw_world *w, vw_status st, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* The most worker threads a process may run (vw_config.workers): VW_E_LIMIT above. */
#define VW__MAX_WORKERS 1024
/* Stops the process (world.h: "Between runs only"): `call` was made while the world's
   callbacks run (w->in_callbacks). */
void vw__world_reentered(const vw_world *w, const char *call) __attribute__((noreturn, cold));
static inline void vw__world_guard(const vw_world *w, const char *call)
{
    if (atomic_load_explicit(&w->in_callbacks, memory_order_relaxed)) vw__world_reentered(w, call);
}
/* A public step begins: the last step's error is no longer the world's (vw_world_errmsg
   tells the last failed step's, not the world's first). Every call that changes the
   world begins so, which refuses it from inside a callback, naming the caller. */
static inline void vw__world_begin_step_(vw_world *w, const char *call)
{
    vw__world_guard(w, call);
    w->err = VW_OK;
}
#define vw__world_begin_step(w) vw__world_begin_step_((w), __func__)
int vw__worker_process(const vw_world *w, int global_worker);
/* Ends a collective step in agreement (see world.c): st is this process's outcome, step
   its name for a failure without a message. */
vw_status vw__world_step_agreed(vw_world *w, vw_status st, const char *step);
/* calloc for n items of `size`, aligned to and padded to whole cache lines. */
void *vw__calloc_lines(size_t n, size_t size);
vw_status vw__world_build_cell(vw_world *w, int cell, vw__worker *wk);
vw_status vw__world_build_replica(vw_world *w, int cell, int rep, vw__worker *wk);
/* Which copy of cell this global worker hosts: 0 = the master, r >= 1 = reps[r-1],
   -1 = none. */
int vw__cell_rep_of(const vw_world *w, int cell, int worker);
/* Copies over all cells. */
int vw__replica_total(const vw_world *w);

/* runtime.c */
vw_status vw__runtime_run(vw_world *w);
/* Ends and joins the worker threads (before the world is freed). */
void vw__runtime_stop(vw_world *w);
/* Builds every unit (cell or copy) of this process that needs it. On failure *cell and
   *rep name the failing unit (rep 0: the master): the lowest (cell, then copy) of the
   units that failed, whatever the thread timing, as a worker stops at its first
   failure and builds its units in that order. */
vw_status vw__runtime_build(vw_world *w, int *cell, int *rep);
/* What a packet in flight counts against its sender's cap (vw_config.cap_bytes): its
   bytes and a fixed charge, so the cap bounds the packets too. Without the charge, a
   worker that flushed one small message at a time (a step that sends one and returns
   1) had up to a few hundred thousand packets in flight under MPI, each a request the
   communication thread tests on every pass (mpi_local_fail_handler took over 30 s). */
#define VW__PACKET_CHARGE 4096
static inline size_t vw__packet_charge(const vw__packet *p) { return p->used + VW__PACKET_CHARGE; }
/* A packet of cap bytes, or NULL when out of memory. */
vw__packet *vw__packet_new(int dest, int src, size_t cap);
/* Fails the current run of this process (the first call of the run sets its status and
   message; see vw_world.dropping). Any thread, during a run. */
void vw__run_fail(vw_world *w, vw_status st, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
void vw__deliver(vw_world *w, vw__worker *from, vw__packet *p);
/* Queues a packet for a worker of this process, counting it in w->active; rng (may be
   NULL) drives the stress switch's reordering. */
void vw__deliver_local(vw_world *w, vw__packet *p, uint64_t *rng);
void vw__run_output(vw_world *w, const vw__packet *p);
/* What is wrong with a packet from another process, or NULL: a message header past its
   end, a kind the module does not have or a size not its kind's, a cell that does not
   exist, messages that do not fill it exactly (written into buf). The workers index the
   cells and kinds with these fields unchecked; the MPI transport checks every packet it
   receives once, on its own thread, so a corrupt or mismatched peer stops the job with
   a message instead of making them read and write out of bounds. */
const char *vw__packet_problem(const vw_world *w, const vw__packet *p, char *buf, size_t len);
void vw__uncount(vw_world *w);
/* Worker `thief` of another process asks for turns of unit `unit` of `cell` (a unit
   this process hosts): takes the thief's part of those it has left (half with equal
   speeds, by the two workers' speeds otherwise) with one add on the unit's counter.
   Returns how many (0: none left), the first counter value at *first, or UINT64_MAX
   when no such unit or worker exists here (a malformed request). The communication
   thread, during a run. */
uint64_t vw__take_turns(vw_world *w, int cell, int unit, int thief, uint64_t nbatches,
                        uint64_t *first);
uint64_t vw__rng_next(uint64_t *s);
double vw__cell_load(vw_world *w, int cell);
/* done() of a cell this process hosts (its master), between runs. */
int vw__cell_done(vw_world *w, int cell);
/* load() of copy rep (>= 1) of cell, hosted by this process. */
double vw__replica_load(vw_world *w, int cell, int rep);
/* Fills w->wstats from this process's workers (the other processes' entries zero). */
void vw__stats_local(vw_world *w);
uint64_t vw__peak_rss(void);

/* Whether VW_CORES gives this process's cores (host.c): then they are not shared with
   other processes of the host (vw__mpi_core_share). */
int vw__host_cores_given(void);

/* The records a process keeps (vw_world.objects): NULL for one it does not. */
#define VW__NO_SLOT SIZE_MAX
static inline const unsigned char *vw__world_record(const vw_world *w, size_t id)
{
    size_t s = w->slot ? w->slot[id] : id;
    return s == VW__NO_SLOT ? NULL : w->objects + s * w->m->object_size;
}

/* transport/mpi.c (stubs in world.c without MPI). vw__mpi_attach decides the engine at
   create: it sets rank, nprocs and w->transport when the world runs under MPI. */
vw_status vw__mpi_attach(vw_world *w);
/* Collective over the world's processes: the lowest rank whose v differs from rank 0's,
   or -1 when all agree (always -1 without MPI). */
int vw__mpi_first_differing(vw_world *w, uint64_t v);
/* The same for n values at once (n at most 256): the lowest rank r any of whose v[i]
   differs from rank 0's, or -1; then *part is the first such i on rank r, *theirs its
   v[i] there and *first rank 0's, on every process. */
int vw__mpi_first_differing_n(vw_world *w, const uint64_t *v, int n, int *part, uint64_t *theirs,
                              uint64_t *first);
/* Collective: the records a process lacks (share_records, world.c). First agrees on
   `local` (msg: why it failed); then, unless no process asks for any, finds the lowest
   process that keeps each record (one MPI_Allreduce of an int an object), and each
   process asks its records of those (vw__world_record answers). On VW_OK *got
   holds the nask records whose ids are ask[], in that order (the caller frees it).
   Every failure is agreed, with its message in msg. */
vw_status vw__mpi_fetch_records(vw_world *w, vw_status local, const uint64_t *ask,
                                size_t nask, unsigned char **got, char *msg, size_t len);
/* vw_world_agree without its guard (engine.h): the runtime's own agreements, one of
   which (the end of a run) is made while w->in_callbacks still says a run. The public
   vw_world_agree (world.c) refuses a call from a callback, then calls this: the MPI
   engine's (transport/mpi_engine.c), or world.c's, which returns local. w not NULL. */
vw_status vw__world_agree(vw_world *w, vw_status local, char *msg, size_t len);

double vw__now(void);

#endif
