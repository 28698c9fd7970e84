/* solver_internal.h - what module.c (the cells) and solve.c (the rounds) share: the
 * solver record, the message records and the kinds and counters of the module.
 * Message records are plain data of fixed size, so they cross processes unchanged.
 */
#ifndef RAD_SOLVER_INTERNAL_H
#define RAD_SOLVER_INTERNAL_H

#include "radiosity/radiosity.h"

enum {
    RAD_K_GO,            /* round start: report state, set the shot budget */
    RAD_K_SHOT,          /* a shot with its merged coverage bitmap */
    RAD_K_FULL,          /* a shot whose bitmap is full: only completes dependencies */
    RAD_K_COLLECT,       /* send results to the output process */
    RAD_K_RESTORE_PATCH, /* resume: a patch's unshot power */
    RAD_K_RESTORE_ELEM,  /* resume: an element's radiosity (splitting as needed) */
    RAD_K_REPORT,        /* output: one cell's ledger and largest unshot power */
    RAD_K_PATCH_OUT,     /* output: one patch */
    RAD_K_ELEM_OUT,      /* output: one element */
    RAD_NKINDS
};

enum { RAD_C_SHOTS, RAD_C_SHOT_MSGS, RAD_C_SHOT_BYTES, RAD_C_FULL_MSGS, RAD_C_RASTER,
       RAD_C_SPLITS, RAD_C_BACK_HITS, RAD_NCOUNTERS };

typedef struct rad_go_msg {
    int32_t round, budget;
    double thr;          /* shoot only patches with more unshot power (r+g+b) */
    double sub_rel;      /* > 0: split elements differing from a neighbour by this much */
    double sub_floor;    /* ... and by at least this absolute radiosity */
    int32_t max_level, pad;
} rad_go_msg;

typedef struct rad_shot_hdr {
    double p[3], n[3];   /* shooter centroid and normal (world) */
    double u[3];         /* hemicube orientation: x axis; y = n x u */
    double power[3];     /* unshot power shot */
    uint64_t id;         /* unique: (source cell << 40) | sequence */
    int64_t piece;       /* the shooter piece (skipped by its own cell) */
    int32_t src_cell, round;
} rad_shot_hdr;

typedef struct rad_collect_msg {
    int32_t what, pad;
} rad_collect_msg;

typedef struct rad_report_msg {
    int32_t round, cell;
    int64_t nshots;
    double max_unshot;   /* the largest patch_unshot (module.c) of the cell's pieces */
    double unshot[3], absorbed[3], shot[3], won[3];
} rad_report_msg;

/* Per worker (global id): how many shots its cells hold ready to rasterise (module.c,
   step), and the scratch a shot is rasterised in (z-buffer, pixel classes), allocated
   by the worker at its first shot. A worker rasterises one shot at a time and nothing
   of it outlives process_shot, so one scratch a worker does for all its cells: one a
   cell, 196 KB at res 64, was 80 % of the memory of the Cornell box on 12x12x12 cells
   and took 0.8 GB on 32x32x32. Only that worker's thread touches its slot; slots are
   cache-line aligned, so two workers never write one line. */
typedef struct rad_worker_slot {
    _Alignas(64) int ready;
    rad_zbuf z;          /* z.written: the pixels the current shot wrote */
    int *pcls;           /* with subdivision: see rad_cell.pcls */
} rad_worker_slot;

struct rad_solver {
    const rad_mesh *mesh;
    const vw_decomp *d;
    rad_options opt;
    rad_hemicube hc;
    size_t bitmap_bytes;
    vw_msg_kind kinds[RAD_NKINDS];
    vw_module mod;
    vw_world *w;
    double emitted_sum;  /* r+g+b of the emitted power */
    double thr;
    double near_eps;
    int round;
    rad_worker_slot *slots;
    size_t nslots;
    /* Per cell: 1 when step() may find work (module.c, note_work). step() reads this
       dense array before the cell's state: the runtime asks every cell of a worker each
       time the worker's inbox runs dry, and reading each cell's own state (a cache miss
       a cell) was 58 % of the Cornell box's first round on 24x24x24 cells. Each entry is
       written by the worker hosting its cell only. */
    unsigned char *stepwork;
    /* The output process's view, rebuilt by the REPORT messages of every run. */
    rad_report_msg rep;
    int nreports;
    double base_absorbed[3], base_escaped[3];  /* from a resumed checkpoint */
    int64_t base_shots;
    int64_t shots;
    /* The stall rule (solve.c, stall_check): the shots and the power lost (absorbed +
       escaped, r+g+b, output process) at the last check, and what stopped the run. */
    int64_t stall_at, stall_at_reported;
    double stall_lost_at;
    int stalled;
    int64_t stall_span;
    double stall_lost;
    double ratio;
    rad_ledger ledger;
    rad_elem_result *elems;
    size_t nelems, capelems;
    rad_patch_result *patches;
    size_t npatches, cappatches;
    /* The bytes a collect's output handlers could not get (0: none): they have no
       context to fail the run with, so rad_solver_collect fails it after. */
    size_t collect_nomem;
    /* Test switches (VW_FAULT): every allocation of the solve fails (solve-nomem), or
       the collect's (collect-nomem). */
    int fault_solve_nomem, fault_collect_nomem;
    rad_round_fn on_round;
    void *on_round_user;
};

extern const char *const rad_counter_names[RAD_NCOUNTERS];
/* Fills s->kinds and s->mod (module.c). */
void rad_module_setup(rad_solver *s);

#endif
