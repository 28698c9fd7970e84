/* anim.h - the ray tracer over a dynamic scene (vwalls animate / edit): a render job
 * whose object records follow a vw_dynscene edit by edit. Only the records of objects
 * an accepted edit changed are replaced (vw_world_update_object), so only the cells
 * they left or joined rebuild their Embree scene at the next frame.
 *
 * Record slots: object id k owns a fixed run of records, in id order (one for a sphere
 * or cone, count-2 for a polygon), the same runs as the dynscene's collision shapes, so
 * record index == collider slot.
 */
#ifndef RT_ANIM_H
#define RT_ANIM_H

#include "raytrace/raytrace.h"
#include "vwalls/dynamic.h"

typedef struct rt_anim rt_anim;

typedef struct rt_anim_params {
    int width, height, depth;   /* 0: defaults as in rt_params */
    int dims[3];                /* grid layout */
    int workers;                /* per process; 0 = cores */
    double margin;              /* the world box: scene bounds grown by margin * diagonal
                                   on every side (objects cannot leave it); 0: 0.25 */
    const vw_box *world_min;    /* the world box covers this box too (the space the scene
                                   is meant to fill, as rt_params.world_min); may be NULL */
    int brute_force;            /* decide collisions with the O(n^2) reference */
    int full_rebuild;           /* benchmark: re-place every object and rebuild every
                                   cell at every frame instead of the touched ones */
    rt_farm farm;               /* how the workers of a process share its cells at every
                                   frame (rt_job_farm); 0 = RT_FARM_IDLE */
    vw_config *config;          /* may be NULL */
} rt_anim_params;

/* What the last apply / render did. */
typedef struct rt_anim_stats {
    size_t accepted, collisions, sweeps, invalid;
    size_t records_updated;     /* records replaced in the render world */
    size_t cells_touched;       /* apply: cells a changed record left or joined that no
                                   earlier batch since the last frame touched */
    size_t cells_rebuilt;       /* render: the cells this frame's commit built: every
                                   cell on the first frame, with full_rebuild and after
                                   a rebalance, else those the edits since the last
                                   frame touched (each once, however many batches) */
    double apply_s, update_s;   /* deciding (distributed query), updating the worlds */
    double build_s, render_s;   /* the last frame: commit (rebuild of dirty cells), run */
} rt_anim_stats;

/* Takes ownership of s (also on failure). */
vw_status rt_anim_create(vw_scene *s, const rt_anim_params *p, rt_anim **out, char *err,
                         size_t errlen);
void rt_anim_free(rt_anim *a);
rt_job *rt_anim_job(rt_anim *a);
vw_dynscene *rt_anim_dynscene(rt_anim *a);
/* The camera and world box used for every frame (for rendering an edited scene from
   scratch identically: pass these in rt_params.camera, .world and .scale). */
const vw_camera *rt_anim_camera(const rt_anim *a);
const vw_box *rt_anim_world(const rt_anim *a);
double rt_anim_scale(const rt_anim *a);

/* Decides a batch of object edits and brings the render world up to date. err gets a
   message. Collective under MPI, like the rest of this file: the batch's bookkeeping
   (the touched cells' marks, room for the records) is each process's own and is agreed
   on before the render world's first update, so memory one process lacks fails the
   batch on every process with "rank R: ..." in err (and no process waits for it). */
vw_status rt_anim_apply(rt_anim *a, const vw_edit *edits, size_t n, int check, int sweep,
                        vw_result *results, rt_anim_stats *st, char *err, size_t errlen);
/* Renders the current scene (rebuilding the dirty cells first). The image is then
   rt_job_rgb8(rt_anim_job(a)) on the output process. */
vw_status rt_anim_render(rt_anim *a, rt_anim_stats *st, char *err, size_t errlen);
/* Rebalances the render world with the given strategy from the last frame's measured
   loads (VW_E_UNSUPPORTED when the build has no balancer); the collider follows. When
   no load has been measured on the current walls (no frame rendered yet, or none since
   the last rebalance reset the counters), nothing is done and both lambdas are 0.
   Collective under MPI: its loads and field are agreed on before the balance, so memory
   one process lacks fails it on every process with "rank R: ..." in err. */
vw_status rt_anim_balance(rt_anim *a, const char *strategy, double *lambda_before,
                          double *lambda_predicted, char *err, size_t errlen);
/* Lambda (max/mean worker busy time) of the last frame. */
double rt_anim_imbalance(rt_anim *a);
/* Lambda of the last frame's counted work (ray segments per worker): the same on every
   run and every machine, where busy time varies with the machine's load. */
double rt_anim_work_imbalance(rt_anim *a);

#endif
