/* vwalls/module.h - the generic module: how a user plugs a geometric problem into vwalls.
 *
 * A module is a table of callbacks. The runtime never knows what a ray or a patch is:
 * it places objects into cells by their bounds, builds each cell's local state, and
 * delivers fixed-size messages to handlers. A cell is only ever touched by the one
 * worker thread that hosts it, so a cell's state needs no locking. Output handlers run
 * on the output process (rank 0), one call at a time.
 *
 * Duplicated cells (the balancer's "duplicate" strategy, vw_world_set_replicas): a cell
 * may have copies on other workers, each with its own state built by cell_build from the
 * same objects. The original is the master (replica 0). Messages of kinds flagged
 * VW_MSG_INDEPENDENT sent to the cell are spread over the master and its copies; every
 * other kind goes to the master only. step() runs on every copy (so a copy can flush
 * what it buffers), so work that must happen once per cell (primary rays, a shot)
 * belongs to the master: test vw_ctx_replica(ctx) == 0. Counters and measurements of
 * the copies add up to the cell's.
 */
#ifndef VWALLS_MODULE_H
#define VWALLS_MODULE_H

#include "vwalls/common.h"
#include "vwalls/decomp.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VW_MODULE_ABI 1
#define VW_MAX_MSG_BYTES 4096
#define VW_MAX_KINDS 64
#define VW_MAX_COUNTERS 32

/* vw_msg_kind.flags. INDEPENDENT: a message of this kind can be handled by any copy of
   its destination cell with the same result (it reads only the cell's objects, writes
   nothing a later message of the cell reads, and sends what it sends from the cell), so
   a duplicated cell may share such messages with its copies (rays of a ray tracer). */
#define VW_MSG_INDEPENDENT 1u

/* Handed to every callback that runs for a cell: who am I, and how to send. */
typedef struct vw_ctx vw_ctx;

/* vw_world_create refuses a kind without a name (one the table's initialiser left out
   is all zeros), one with neither handle nor output, and unknown flags. */
typedef struct vw_msg_kind {
    const char *name;
    size_t size;    /* bytes of one message record, at most VW_MAX_MSG_BYTES: every send
                       copies this many bytes from the pointer it is given, so it must be
                       sizeof the record sent: vw_send_cell and the others cannot check
                       that; the sized sends (VW_SEND_CELL, ... below) do */
    /* Runs on the worker hosting the destination cell. May send messages. */
    void (*handle)(vw_ctx *ctx, void *cell_state, const void *msg);
    /* For kinds sent with vw_send_output: runs on the output process. */
    void (*output)(void *user, const void *msg);
    /* VW_MSG_* flags; 0 (also when an initialiser omits it) = handled by the master. */
    unsigned flags;
} vw_msg_kind;

typedef struct vw_module {
    unsigned abi;            /* VW_MODULE_ABI */
    const char *name;

    /* Objects are plain records of object_size bytes, copied into every cell their
       bounds overlap (so they must not hold pointers that differ between processes).
       Each cell's box is widened for this by a margin of 1e-9 of the world's largest
       extent (docs/runtime.md), so an object on a wall, or near one within the margin,
       goes to the cells on both sides: cell_build may get objects just outside
       vw_ctx_cell_box. To count something once, give it one owner (vw_decomp_locate). */
    size_t object_size;
    void (*object_bounds)(const void *object, vw_box *out, void *user);

    const vw_msg_kind *kinds;
    int nkinds;

    /* Named per-cell counters the module adds to with vw_count(); summed over cells
       (and processes) into the stats. */
    const char *const *counters;
    int ncounters;

    /* Build the local state of a cell from its objects (in the order they were added;
       they stay unchanged until the call returns, and only until then: they may be the
       world's own records). Runs once per cell at commit, on the worker that hosts the
       cell. Optional: without it every callback gets state NULL. It may not send
       (there is no run to deliver in; post with vw_world_post instead): a send here
       stops the process, as in load(). A constructor: on VW_OK *state is the cell's,
       freed with cell_free when the cell is rebuilt or goes; on failure the build
       frees whatever it made itself, and the runtime ignores *state (cell_free is
       never called for a build that failed). The commit then fails (on every process,
       under MPI), and a later commit builds the cell again. */
    vw_status (*cell_build)(vw_ctx *ctx, const void *objects, size_t nobjects, void **state);
    void (*cell_free)(void *state, void *user);
    /* Optional: local work that needs no message (generate primary rays, shoot a patch).
       Every run calls it on every cell (and copy) at its start, also a run with nothing
       posted, so a cell that has nothing to do must return 0 at once (keep a flag in
       the state). "At its start" is no order: a cell's handlers may run before its
       first step() of the run (a neighbour's message can arrive first, even with one
       worker), so what step() and a handler may both do once (report a result) needs
       a flag in the state too. Return nonzero when it did some work; it is called
       again until it returns 0, and again after the cell receives messages (not in a
       run that a callback failed: vw_ctx_fail). A worker goes idle only after a pass
       in which step() of every cell (and copy) it hosts returned 0, so a cell may keep
       tallies or partial buffers between calls and hand them over here. */
    int (*step)(vw_ctx *ctx, void *state);
    /* Optional load estimate of a cell; otherwise measured busy time is used. */
    double (*load)(vw_ctx *ctx, void *state);
    /* Optional local convergence test: nonzero when the cell has converged. The runtime
       never calls it by itself; vw_world_done (world.h) asks every cell between runs,
       on the process that hosts it (the master of a duplicated cell), and agrees on the
       answer, for an outer loop of runs ("run until done"). Like load() it may not send
       or fail the run. */
    int (*done)(vw_ctx *ctx, void *state);
} vw_module;

/* Who am I. */
VW_API int vw_ctx_cell(const vw_ctx *ctx);
VW_API int vw_ctx_worker(const vw_ctx *ctx);
VW_API int vw_ctx_process(const vw_ctx *ctx);
VW_API const vw_decomp *vw_ctx_decomp(const vw_ctx *ctx);
VW_API vw_box vw_ctx_cell_box(const vw_ctx *ctx);
VW_API void *vw_ctx_user(const vw_ctx *ctx);
/* Which copy of a duplicated cell runs this callback (0 = the master, or no copies),
   and how many copies besides the master the cell has. */
VW_API int vw_ctx_replica(const vw_ctx *ctx);
VW_API int vw_ctx_replicas(const vw_ctx *ctx);
/* Farming a cell's own work (what step() creates) among its copies: the work is cut
   into nbatches batches numbered 0, 1, ..., nbatches - 1, and each call returns the
   number of a batch this copy is to make, or nbatches when none is left for it. Within
   one run every number is returned exactly once. Of k copies, copy r (the master is 0)
   takes its turns r, r + k, r + 2k, ... first, an equal share as the balancer plans (with
   vw_config.worker_speeds: a share in proportion to its worker's speed, its slots spread
   evenly over the batch numbers),
   with no message; a copy whose turns are used up then takes the turns not yet taken
   by the other copies (vw_config.steal), so a copy slowed down (a busy core, a slower
   machine) leaves its rest to the others: in its process one at a time, on another
   process by asking it, which the call then waits for. Counting restarts at every
   run; a cell without copies gets
   0, 1, 2, ... Call it from step() until it returns nbatches, with the same nbatches
   in every copy; small batches spread the work evenly when its cost varies along the
   batch numbers. */
VW_API uint64_t vw_ctx_next_batch(vw_ctx *ctx, uint64_t nbatches);

/* Sending. A message is copied when sent; the caller keeps its buffer (which may be NULL
   for a kind of size 0, a signal that carries nothing). A send that cannot be meant is
   a bug in the module and stops the process with a message on stderr: an unknown cell,
   face or kind, a kind without handle sent to a cell, a kind without
   output handler sent to the output, msg NULL for a kind of size > 0 (also when the
   send reaches no cell: a point outside, a face on the world's wall); so is an
   unknown counter given to vw_count.
   Messages are batched per destination into packets, flushed when full or when the
   worker has nothing else to do. To a duplicated cell, a message of an independent kind
   goes to the master or one of its copies in turn (round-robin per sending worker),
   also when a cell sends to itself: that is how a master shares work it creates. */
VW_API void vw_send_cell(vw_ctx *ctx, int cell, int kind, const void *msg);
/* To the cell owning world point p (dir decides points on walls). Returns the cell, or
   -1 (message dropped) when p lies outside the world. */
VW_API int vw_send_point(vw_ctx *ctx, const double p[3], const double dir[3], int kind,
                         const void *msg);
/* To every neighbour across one face (0..5, see decomp.h). Returns how many. */
VW_API int vw_send_face(vw_ctx *ctx, int face, int kind, const void *msg);
/* To every face neighbour. Returns how many. */
VW_API int vw_send_neighbours(vw_ctx *ctx, int kind, const void *msg);
/* To the output process, where the kind's output handler receives it. */
VW_API void vw_send_output(vw_ctx *ctx, int kind, const void *msg);

/* Sized sends: the same five, told the size of the record they are given, which must be
   the kind's size. The sends above copy the kind's size from msg whatever msg points
   to: a kind whose size is smaller than the record truncates every message silently,
   one whose size is larger reads past the sender's variable. A sized send whose size
   differs stops the process with a message on stderr, like the misuses above, naming
   the call, the kind, the size given and the kind's size ("vwalls: module 'M' gave
   vw_send_cell_sized a record of 12 bytes for message kind 0 ('count'), whose size is 8
   bytes (worker W, in cell C)"), also when the send reaches no cell. The check is one
   comparison per send, and only here: vw_send_cell, a hot path (a ray tracer's rays),
   stays as it was. A signal (a kind of size 0) is sent with msg NULL and size 0. */
VW_API void vw_send_cell_sized(vw_ctx *ctx, int cell, int kind, const void *msg, size_t size);
VW_API int vw_send_point_sized(vw_ctx *ctx, const double p[3], const double dir[3], int kind,
                               const void *msg, size_t size);
VW_API int vw_send_face_sized(vw_ctx *ctx, int face, int kind, const void *msg, size_t size);
VW_API int vw_send_neighbours_sized(vw_ctx *ctx, int kind, const void *msg, size_t size);
VW_API void vw_send_output_sized(vw_ctx *ctx, int kind, const void *msg, size_t size);

/* The sized sends of a record variable (an lvalue: a variable, a struct member, *ptr),
   written once: VW_SEND_CELL(ctx, cell, MSG_RAY, ray) passes &(ray) and sizeof(ray).
   Give the record, not a pointer to it (a pointer p is sent as *p: with p itself the
   size is that of the pointer, which the check catches unless the kind is as small).
   Each returns what its function returns. */
#define VW_SEND_CELL(ctx, cell, kind, rec) \
    vw_send_cell_sized((ctx), (cell), (kind), &(rec), sizeof(rec))
#define VW_SEND_POINT(ctx, p, dir, kind, rec) \
    vw_send_point_sized((ctx), (p), (dir), (kind), &(rec), sizeof(rec))
#define VW_SEND_FACE(ctx, face, kind, rec) \
    vw_send_face_sized((ctx), (face), (kind), &(rec), sizeof(rec))
#define VW_SEND_NEIGHBOURS(ctx, kind, rec) \
    vw_send_neighbours_sized((ctx), (kind), &(rec), sizeof(rec))
#define VW_SEND_OUTPUT(ctx, kind, rec) \
    vw_send_output_sized((ctx), (kind), &(rec), sizeof(rec))

/* Inline hand-off, "a message of kind `kind` delivered by a function call": when this
   worker hosts `cell` (or, if the kind is independent and every worker of the process
   holds a copy of the cell, when farming, its own copy), switches ctx to it and returns
   its state; otherwise NULL, and the caller sends the message instead. The caller then
   does for that cell exactly what the message's handler would do (vw_count, sends, and
   time are charged to it), and must go back with vw_ctx_restore(ctx, cell, replica)
   using the values vw_ctx_cell() and vw_ctx_replica() had before, before it returns or
   uses the first cell's state again. Messages are the model; this only skips the packet
   for the common case of a neighbour on the same worker (a ray crossing a wall). Only
   in handlers and step(): cell_build and load get NULL (there is no run to hand off in).
   An unknown cell or kind, or a kind without handle, stops the process as vw_send_cell
   does. The common case (a cell of this worker without copies) is a few compares and
   the meter's note. */
VW_API void *vw_ctx_enter(vw_ctx *ctx, int cell, int kind);
VW_API void vw_ctx_restore(vw_ctx *ctx, int cell, int replica);

/* Add n to the module's counter idx for this cell. */
VW_API void vw_count(vw_ctx *ctx, int idx, int64_t n);

/* A handler or step() that cannot go on (memory it needs and cannot get) fails the run:
   from then on the run drops the module's work on every worker (and, under MPI, on
   every process, from the next termination wave): handlers are no longer called for
   the messages still arriving, step() is not called, output handlers get nothing. The
   messages are still counted, so the run ends as always, and vw_world_run returns
   status (VW_OK is taken as VW_E_STATE) on every process, vw_world_errmsg saying
   "cell C: <the message, printf-style>" (under MPI "rank R: cell C: ..." of the lowest
   failing rank). The first failure of a run is kept. What the dropped work would have
   done is lost: a module whose state it leaves half-updated should not be run again.
   The caller returns as usual after it. Only in handlers and step(): cell_build returns
   its status, and a call from it or from load() stops the process as a misuse.
   Output handlers, which get no context, keep their own failure flag for the caller
   to check after the run. No callback may change its world (vw_world_run, _post,
   _add_objects, _commit, vw_world_free, ...: world.h, Misuse): that too stops the
   process, naming the call. The runtime fails a run the same way when it cannot
   allocate a packet for a message being sent. */
VW_API void vw_ctx_fail(vw_ctx *ctx, vw_status status, const char *fmt, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#ifdef __cplusplus
}
#endif
#endif
