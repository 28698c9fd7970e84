/* vwalls/balance.h - dynamic load balancing: the four Virtual Walls strategies of Menzel
 * et al. 1994 (moving walls = the tensor balancer, rotating the frame, optimising the
 * cell shape = staggered cells, dividing and duplicating cells) and the load model.
 *
 * The balancer works on a *load field*: weighted points in world coordinates saying
 * where work lies. It is made from measured per-cell loads (the load assumed uniform
 * inside each cell) and may be re-calibrated by later measurements on other
 * decompositions, so every new measurement sharpens the picture instead of replacing
 * it. A balancer turns a field and a target layout into a new decomposition (and, for
 * divide, a cell -> worker mapping); vw_balance_world applies one to a running world.
 *
 * Invariants: every decomposition a balancer returns tiles the same world box (rotated
 * frames: the bounds of the rotated world box), so no object is lost; walls never cross
 * and keep at least min_width apart (one double apart where min_width is finer than the
 * doubles there; where fewer doubles fit than walls, the balancer returns the current
 * decomposition: no gain, no error); every process computes the same result from the
 * same (globally synchronised) measurements, so MPI ranks agree without talking.
 */
#ifndef VWALLS_BALANCE_H
#define VWALLS_BALANCE_H

#include "vwalls/common.h"
#include "vwalls/decomp.h"
#include "vwalls/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- strategies --------------------------------------------------------------------- */

typedef enum vw_balance_strategy {
    VW_BALANCE_NONE = 0,
    VW_BALANCE_TENSOR,    /* move whole hyperplanes, axis by axis (grid stays a grid) */
    VW_BALANCE_ROTATE,    /* principal axis of the load -> rotated frame, then tensor; the
                             frame is the best predicted of the axis assignments and turns
                             about the principal axis (15-degree steps), or none */
    VW_BALANCE_STAGGERED, /* x slabs, y cuts per slab, z cuts per column */
    VW_BALANCE_DIVIDE,    /* overloaded cells split into sub-cells for idle workers */
    VW_BALANCE_DUPLICATE  /* overloaded cells copied to idle workers (see world.h) */
} vw_balance_strategy;

VW_API const char *vw_balance_strategy_name(vw_balance_strategy s);
/* "none", "tensor", ... -> strategy; VW_E_INVAL for an unknown name. */
VW_API vw_status vw_balance_strategy_parse(const char *s, vw_balance_strategy *out);

/* ---- the load model ----------------------------------------------------------------- */

typedef enum vw_load_model {
    VW_LOAD_BUSY = 0, /* measured busy time per cell (the default) */
    VW_LOAD_COUNTER,  /* a module counter per cell: deterministic work (ray segments) */
    VW_LOAD_MODEL     /* a*objects + b*pixels counter + c*messages received */
} vw_load_model;

typedef struct vw_load_spec {
    vw_load_model model;
    int counter;                /* VW_LOAD_COUNTER: the module counter; MODEL: the
                                   "pixels" counter (-1 = none) */
    double w_objects, w_pixels, w_messages; /* VW_LOAD_MODEL weights */
} vw_load_spec;

/* Busy time, counter -1, model weights 1, 1, 1. */
VW_API void vw_load_spec_init(vw_load_spec *s);
/* Per-cell loads of the last run(s) under the model: out has vw_decomp_cell_count()
   entries. Valid on every process after run() (the figures are global then). */
VW_API vw_status vw_balance_cell_loads(const vw_world *w, const vw_load_spec *s, double *out);
/* lambda = the slowest worker's time, max over workers of sum(cell load) / speed,
   against the time of a split in proportion to the speeds, sum(load) / sum(speed)
   (speeds NULL = all 1: max / mean of the workers' loads):
   at least 1; 1 when no worker has load (nothing measured), and for no worker.
   Never NaN: INFINITY when a speed is not positive and finite (such a worker never
   finishes; the mappers, vw_balance_world, vw_config.worker_speeds and
   vw_map_parse_speeds refuse such speeds with VW_E_INVAL) or when a load is negative,
   NaN or infinite; 0 only when out of memory. cell_worker NULL: cell c on worker
   c % gworkers; a cell mapped outside [0, gworkers) is not counted. */
VW_API double vw_balance_imbalance(const double *cell_load, const int *cell_worker, int ncells,
                                   int gworkers, const double *speeds);

/* ---- the load field ----------------------------------------------------------------- */

typedef struct vw_load_field vw_load_field;

VW_API vw_status vw_load_field_create(vw_load_field **out);
VW_API void vw_load_field_free(vw_load_field *f);
/* A point mass of load w at world point p (modules may add their own samples).
   VW_E_INVAL for a weight that is negative or not finite, or a point that is not. */
VW_API vw_status vw_load_field_add_point(vw_load_field *f, const double p[3], double w);
/* Adds each cell's load spread uniformly over its box (k^3 points per cell, k >= 1). */
VW_API vw_status vw_load_field_add_cells(vw_load_field *f, const vw_decomp *d,
                                         const double *cell_load, int k);
/* Re-calibration by a new measurement on decomposition d: inside every cell the
   field's points are scaled so that they sum to cell_load[c]; a cell with load but
   no points gets k^3 uniform points. Keeps the old field's detail below the cells.
   A load that is not positive counts as 0; an infinite one is VW_E_INVAL (the field
   is then unchanged). */
VW_API vw_status vw_load_field_calibrate(vw_load_field *f, const vw_decomp *d,
                                         const double *cell_load, int k);
/* The field's load per cell of d (predicted loads), out[vw_decomp_cell_count(d)]. */
VW_API void vw_load_field_cell_loads(const vw_load_field *f, const vw_decomp *d, double *out);
VW_API double vw_load_field_total(const vw_load_field *f);
VW_API size_t vw_load_field_points(const vw_load_field *f);

/* ---- balancers ---------------------------------------------------------------------- */

typedef struct vw_balance_params {
    vw_balance_strategy strategy;
    int dims[3];        /* target layout (tensor, rotate, staggered); 0s: the current
                           one's (a grid's dims; a staggered tree's slabs, columns a slab
                           and cells a column; any other kind {cells, 1, 1}) */
    double min_width;   /* walls keep at least this fraction of the world extent apart
                           (default 1e-3) */
    int gworkers;       /* divide / duplicate, and rotate with speeds: all workers of the
                           job (0: ncells) */
    const double *speeds; /* relative worker speeds (gworkers entries) or NULL; rotate
                           judges its frames by the lambda of their cells mapped by speed */
    double tolerance;   /* divide / duplicate: stop at lambda <= 1 + tolerance (0.03) */
    int max_extra;      /* divide: at most this many extra cells (0: 4 * gworkers),
                           over a run of divides each on the last one's result: a
                           VW_DECOMP_DIVIDED decomposition (divide's) may grow to
                           gworkers + max_extra cells in all, no further;
                           duplicate: at most this many copies (0: 4 * gworkers, or one
                           a cell where the cells are more, up to 1024) */
} vw_balance_params;

VW_API void vw_balance_params_init(vw_balance_params *p);

/* The new decomposition for the strategy (tensor, rotate, staggered, divide), from the
   current one and the load field. cell_worker (may be NULL) receives, for divide only, a
   mapping of the new cells onto gworkers workers (longest processing time first);
   it must hold VW_MAX_CELLS entries. Others leave it untouched. VW_E_INVAL for an
   unknown strategy, a min_width outside [0, 1) or NaN, or negative dims. */
VW_API vw_status vw_balance_decompose(const vw_decomp *current, const vw_load_field *f,
                                      const vw_balance_params *p, vw_decomp **out,
                                      int *cell_worker);

/* ---- applying a balancer to a world ------------------------------------------------- */

typedef struct vw_balance_report {
    vw_balance_strategy strategy;
    int applied;               /* 0: skipped (no gain, or the gain would not pay) */
    double imbalance_before;   /* lambda of the measured loads on the old layout */
    double imbalance_predicted;/* lambda of the field's loads on the new layout */
    uint64_t migrated_objects; /* (object, worker) pairs that are new */
    uint64_t bytes_moved;      /* migrated_objects * object size */
    int cells, max_neighbours, duplicates;
    double seconds;            /* balancing itself (not the measurement) */
} vw_balance_report;

/* Mapping of the balanced cells onto workers (map.h's kinds): VW_MAP_BLOCK unless told. */
typedef struct vw_balance_apply {
    int map;                   /* a vw_map_kind (map.h) */
    const double *speeds;      /* per global worker, or NULL */
    double last_compute_s;     /* > 0: rebalance only when the expected gain, */
    double rebuild_s;          /* (1 - predicted/before) * last_compute_s, exceeds this */
} vw_balance_apply;

/* Balances world w between runs: decomposition from the field, mapping, re-placement
   and migration of objects, rebuild at the next commit/run; records the balance info
   for the stats JSON. Collective under MPI (every process calls it with the same field):
   each process plans alone, and the plans agree (vw_world_agree) before the
   redecomposition or the copies, so memory one process lacks fails the balance on every
   process, with "rank R: vw_balance_world: ..." as the world's error. */
VW_API vw_status vw_balance_world(vw_world *w, const vw_load_field *f, const vw_balance_params *p,
                                  const vw_balance_apply *a, vw_balance_report *rep);

#ifdef __cplusplus
}
#endif
#endif
