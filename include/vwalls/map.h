/* vwalls/map.h - mapping cells onto workers and processes (the paper's "mapping"):
 * which worker thread of which process hosts each cell.
 *
 * A mapping is a table cell -> global worker (process * workers_per_process + local
 * worker), the form vw_config.cell_worker and vw_world_redecompose take. Invariant of
 * every mapper: each cell is mapped exactly once, to a worker in [0, gworkers).
 *
 * Errors. The mappers and parsers (vw_map_*) take no world and have no message to set:
 * their status (VW_E_INVAL for a bad argument, VW_E_NOMEM) is all they say. The calls
 * on a world (vw_world_remap, vw_world_traffic, vw_world_machines) follow world.h:
 * VW_E_INVAL without a message for a NULL world, otherwise every failure sets the
 * message vw_world_errmsg(w) returns. All three are collective under MPI, and like the
 * calls that change the world, they stop the process with a message naming the call
 * when a module's callback makes them (world.h, Misuse).
 */
#ifndef VWALLS_MAP_H
#define VWALLS_MAP_H

#include "vwalls/common.h"
#include "vwalls/decomp.h"
#include "vwalls/world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vw_map_kind {
    VW_MAP_BLOCK = 0, /* contiguous blocks of the cell grid per process, then per worker */
    VW_MAP_GREEDY,    /* by load, longest first, neighbours together where loads allow */
    VW_MAP_WEIGHTED   /* like greedy, load in proportion to each worker's speed */
} vw_map_kind;

VW_API const char *vw_map_kind_name(vw_map_kind k);
VW_API vw_status vw_map_kind_parse(const char *s, vw_map_kind *out);

/* Factor n into dims[0]*dims[1]*dims[2] matched to the cell grid cells[3] (as
   MPI_Dims_create does, but preferring factors that divide the cell counts), so that
   each part is a compact block: of the factorisations that leave no part empty and
   divide the most sides evenly, the one whose cuts have the least area (within 5 %),
   then the fewest cell faces. Without sizes the cells are taken as cubes (so the area
   is the faces cut: the cuts go across the axes of most cells); vw_map_block scores
   the same way with the grid's real walls. VW_E_INVAL for n < 1 or cells or dims
   NULL, with dims (if given) 1x1x1 (n < 1 gave {0, 1, 1}). */
VW_API vw_status vw_map_dims(int n, const int cells[3], int dims[3]);

/* Block mapping: a grid decomposition is cut into nprocs blocks (process grid matched
   to the cell grid) and each block into wpp worker blocks, so that most neighbour
   traffic stays inside a worker, then inside a process: of the even cuts, the one of
   least wall area between blocks, from the grid's walls where they are (within 5 %,
   then the fewest cell faces; the count of faces alone cut 2x2x2 cells of a flat world
   at its broad horizontal wall). Non-grid decompositions are
   mapped in kd-tree leaf order (cells close in the tree are close in space). No worker
   gets more than ceil(cells / workers) cells, no process more than ceil(cells /
   nprocs), and every worker gets one when there are as many cells as workers: where
   no blocks are that even, runs of the grid's leaf order instead. */
VW_API vw_status vw_map_block(const vw_decomp *d, int nprocs, int wpp, int *cell_worker);

/* Greedy (over-decomposition): cells sorted by load, longest first, each to the worker
   that finishes it first (load / speed); among workers within `slack` (relative) of the
   best, one already hosting a face neighbour is preferred. speeds NULL = all equal;
   VW_E_INVAL for a speed that is not positive and finite, or a negative slack. A load
   that is not a positive number (0, negative, NaN) counts as none; cell_load NULL, or
   no cell with a load, counts every cell alike (1 each). A load of +infinity ranks
   above every finite one: such cells go one to a worker before any gets a second (in
   order of cell id, each among the workers with fewest of them as above: neighbours,
   then the lowest worker id), and the finite cells only to the workers with fewest. */
VW_API vw_status vw_map_greedy(const vw_decomp *d, const double *cell_load, int gworkers,
                               const double *speeds, double slack, int *cell_worker);

/* Weighted (unequal workers): greedy with speeds and no neighbour preference beyond 2%:
   each worker's load ends near its share speed / sum(speeds). */
VW_API vw_status vw_map_weighted(const vw_decomp *d, const double *cell_load, int gworkers,
                                 const double *speeds, int *cell_worker);

/* One entry point for the command line: kind, loads (NULL: the cells' volumes ... 1 each). */
VW_API vw_status vw_map_compute(vw_map_kind kind, const vw_decomp *d, const double *cell_load,
                                int nprocs, int wpp, const double *speeds, int *cell_worker);

/* "1,1,2,4" -> speeds (exactly n entries separated by commas, each > 0 and finite,
   decimal with or without an exponent); VW_E_INVAL otherwise (an empty list, an empty
   entry, a trailing comma, a bad number, a hexadecimal one such as "0x2", white space
   or '+' before a number: vw_strtod_decimal). */
VW_API vw_status vw_map_parse_speeds(const char *s, double *speeds, int n);

/* Re-maps the world's cells onto workers between runs (cells move with their objects
   and are rebuilt on their new worker). Before the first commit nothing has been built,
   so nothing counts as migrated. A step of the world's life (world.h): VW_E_INVAL for
   no mapping (cell_worker NULL) or a worker that does not exist, and the world stays
   as it was. */
VW_API vw_status vw_world_remap(vw_world *w, const int *cell_worker);

/* Share of neighbour traffic that stayed inside the sending worker, inside its process
   and inside its machine (messages and bytes, from the runtime's counters by
   destination class) since the last vw_world_reset_stats. Only messages sent count:
   work a module does in a cell of its own worker through vw_ctx_enter is no message
   (the ray tracer hands every ray on that way, one crossing a wall and one whose walk
   starts in the next cell, so its msgs_worker stays 0 unless VW_STRESS refuses
   hand-offs). VW_E_INVAL when out is
   NULL, VW_E_NOMEM for the table of machines, VW_E_MPI as vw_world_machines. Collective under MPI, and ends in
   agreement like a step of the world's life (world.h): a failure on one process only
   (out NULL there, no memory there) fails the call on every process with the lowest
   failing one's status, vw_world_errmsg saying "rank R: <its message>" everywhere, and
   no process is left waiting for another. */
typedef struct vw_traffic {
    uint64_t msgs, bytes;                 /* cell-to-cell messages */
    uint64_t msgs_worker, bytes_worker;   /* ... whose destination is the same worker */
    uint64_t msgs_process, bytes_process; /* ... the same process */
    uint64_t msgs_machine, bytes_machine; /* ... the same machine */
} vw_traffic;
VW_API vw_status vw_world_traffic(vw_world *w, vw_traffic *out);
/* The machine of every process (machine_of[vw_world_processes()]): the lowest rank that
   shares memory with it (MPI_Comm_split_type(MPI_COMM_TYPE_SHARED)); without MPI, 0.
   Collective under MPI, and ends in agreement as vw_world_traffic does (machine_of
   NULL on one process only fails the call on all). VW_E_INVAL when machine_of is NULL,
   VW_E_MPI when MPI cannot group the processes. */
VW_API vw_status vw_world_machines(vw_world *w, int *machine_of);

#ifdef __cplusplus
}
#endif
#endif
