/* raytrace.h - the distributed ray tracer: a vwalls module (Menzel et al. 1994, sec. 3).
 *
 * Rays travel through the cells as messages. Invariants that keep images bit-identical
 * for every decomposition, worker count and engine:
 *  - a ray is owned by exactly one cell at a time; crossing a wall transfers ownership,
 *    and the ray keeps its ORIGINAL origin and direction for its whole life (it is never
 *    re-originated at a wall), so every cell computes the same hit for it;
 *  - the t-interval a cell searches is the ray-walk segment, run past its far wall by
 *    rt_shared.overlap (Embree's float tests do not split a hit on a wall exactly),
 *    and the segments of one ray are contiguous (decomp.h); objects are placed with
 *    bounds widened by bpad >= 2 overlap, so "first hit over all cells" is the global
 *    first hit (docs/raytrace.md, "The overlap");
 *  - nothing in the shading depends on the cell: it reads only the ray, the hit object's
 *    record (material copied in) and the lights;
 *  - every contribution goes to the output process in 64-bit fixed point, where integer
 *    addition makes the sum independent of arrival order.
 */
#ifndef RT_RAYTRACE_H
#define RT_RAYTRACE_H

#include <stdatomic.h>
#include <stdint.h>
#include "vwalls/vwalls.h"

/* ---- objects ---------------------------------------------------------------------- */

typedef enum rt_kind { RT_SPHERE = 0, RT_TRIANGLE = 1, RT_CONE = 2 } rt_kind;

#define RT_SMOOTH 1 /* triangle with vertex normals (NFF pp, OBJ vn) */
#define RT_INSIDE 2 /* sphere or cone given with negative radii: normals point inward */

/* One primitive as copied into every cell it overlaps: plain data, material included,
   so a cell needs nothing but its records to shade a hit. */
typedef struct rt_object {
    int32_t kind;  /* rt_kind */
    int32_t id;    /* the scene's global id (a polygon's id for each of its triangles) */
    int32_t flags; /* RT_SMOOTH, RT_INSIDE */
    int32_t pad;
    vw_material mat;
    union {
        struct { double c[3], r; } sphere;
        struct { double base[3], r0, apex[3], r1; } cone; /* radii >= 0 */
        struct { double v[3][3], n[3][3]; } tri;
    } g;
} rt_object;

/* The scene's primitives as records (polygons by vw_polygon_triangulate, degenerate triangles
   dropped). *out is malloc'ed; returns VW_E_NOMEM on failure. */
vw_status rt_objects_from_scene(const vw_scene *s, rt_object **out, size_t *n);
/* The same records a part at a time, so that a large scene's records need not all exist
   beside the world's copy: rt_objects_count is the scene's objects (spheres, cones,
   polygons); rt_objects_room the records they make at most, and *widest (if not NULL) the
   most one polygon makes. rt_objects_next writes the records of objects *next, *next + 1,
   ... into out while they fit its room (which must hold widest at least), sets *n to the
   records written and *next past the last object done; done when *next is the count. */
size_t rt_objects_count(const vw_scene *s);
size_t rt_objects_room(const vw_scene *s, size_t *widest);
vw_status rt_objects_next(const vw_scene *s, size_t *next, rt_object *out, size_t room, size_t *n);
/* Bounds of one record, widened by pad on every side. */
void rt_object_bounds(const rt_object *o, double pad, vw_box *out);

/* ---- camera ------------------------------------------------------------------------- */

typedef struct rt_view {
    double eye[3];
    double right[3], up[3], fwd[3]; /* orthonormal; screen x grows along right */
    double tan_half;                /* tan(vertical angle / 2) */
    double aspect;                  /* width / height */
    int width, height;
} rt_view;

void rt_view_init(rt_view *v, const vw_camera *cam, int width, int height);
/* The unit direction of the eye ray through the centre of pixel (px, py), row 0 on top. */
void rt_view_ray(const rt_view *v, int px, int py, double dir[3]);
/* Screen position (pixel units, may be fractional or off-screen) of world point p;
   returns 0 when p is not in front of the eye. */
int rt_view_project(const rt_view *v, const double p[3], double *sx, double *sy);
/* The screen rectangle [lo, hi] (pixel units, as rt_view_project) that holds the
   outline of box b, given in the frame coordinates of decomposition d; returns 0 when
   part of the box is not in front of the eye (no rectangle). */
int rt_view_outline(const rt_view *v, const vw_box *b, const vw_decomp *d, double lo[2],
                    double hi[2]);

/* ---- the module ------------------------------------------------------------------------ */

/* Fixed point of the pixel sums: a contribution c is added as llround(c * 2^32). */
#define RT_FIX_ONE 4294967296.0

/* Module counters, in this order. */
enum {
    RT_C_EYE = 0, RT_C_REFLECT, RT_C_REFRACT, RT_C_SHADOW, /* rays created, by kind */
    RT_C_ENDED,                                            /* rays ended, any kind */
    RT_C_PIXELS,                                           /* primary pixels of a cell */
    RT_C_SEGMENTS,                                         /* cell visits of all rays */
    RT_C_SEARCHES, /* the visits that searched the cell's objects (Embree), not passed over
                      by the reach test: the work the cell's objects make */
    RT_NCOUNTERS
};

typedef struct rt_light {
    double pos[3], color[3];
} rt_light;

/* Where Embree's float coordinates come from: x_embree = (x - origin) * scale, the same
   for every cell of a job (rt_float_frame_of), so that a hit never depends on the layout.
   Floats keep 24 bits: measured from an origin inside a scene far from (0, 0, 0), and
   brought near unit size by a power of two, the coordinates lose the least of them. */
typedef struct rt_float_frame {
    double origin[3];
    double scale;     /* a power of two (rt_embree_scale) */
    double inv_scale; /* 1 / scale, exact */
    int moved;        /* origin or scale not the identity's: the queries convert */
} rt_float_frame;

/* What every cell and the output handler of one process share (the module's user
   pointer). Read-only while the world runs, except the output side (accum, done),
   which only the output handler writes, one call at a time. */
typedef struct rt_shared {
    rt_view view;
    rt_light *lights;
    int nlights;
    double background[3];
    int max_depth;   /* an eye ray has depth 1; rays of depth max_depth spawn no others */
    double eps;      /* float error across a surface: a secondary ray's searches start
                        at eps / cos of its angle to the surface, up to 64 eps (job.c) */
    double bpad;     /* objects' bounds are widened by this before placement */
    double overlap;  /* a cell searches this far past its far wall (<= bpad / 2) */
    void *device;    /* RTCDevice, one per process, shared by every cell */
    rt_float_frame ff; /* where Embree's float coordinates come from */
    struct rt_geo_cache *geo_cache; /* the built cells of this process, shared by the
                                       copies of a cell (geometry.h) */
    int sample;      /* primary pixels: every sample-th row and column only (the load
                        balancer's cheap pre-pass); 0 or 1 = every pixel */
    /* The cell of each pixel's eye ray (-1: misses the world) on decomposition
       owner_decomp; cell_build uses it when that is the world's decomposition, and
       walks the pixels itself otherwise. NULL when not computed. */
    const int *owner;
    const vw_decomp *owner_decomp;
    /* The same map sorted by cell: cell c's pixels, in increasing order, are
       owner_pixels[owner_first[c] .. owner_first[c + 1]) (set with owner). A cell
       built on owner_decomp reads its slice in place while it lives: the arrays are
       rewritten only for another decomposition, whose cells are all built anew. */
    const int *owner_first, *owner_pixels;
    /* Every process: record which worker makes each eye ray (rt_job_record_eye_workers):
       the cell sends it to the output process with the pixel's contributions. */
    int record_eye_workers;
    /* Every process: send the cell where each eye ray hits (rt_job_record_hit_cells)
       with the pixel's contributions. */
    int record_hit_cells;
    /* Output process only: */
    int64_t (*accum)[3];        /* width*height fixed-point sums */
    int *eye_worker;            /* width*height, when recorded: the worker that made the
                                   pixel's eye ray in the last run, -1 = none */
    int *hit_cell;              /* width*height, when recorded: the cell where the pixel's
                                   eye ray hit in the last run, -1 = none (it left the
                                   world, or missed it) */
    /* The counters below are written while every worker reads the fields above for
       every ray: each gets a cache line of its own, or the writes would bounce the
       read-mostly line between cores. */
    _Alignas(64) atomic_llong pixels_done; /* eye rays that have ended (progress) */
    _Alignas(64) atomic_llong entries;     /* contributions received */
    /* Every process: rays created so far, published by the cells in batches (for the
       progress bar's rays/s; the exact counts are the module counters). */
    _Alignas(64) atomic_llong rays;
    char pad_end[64 - sizeof(atomic_llong)];
    /* Bumped by every rt_job_run(): a cell not rebuilt since the last run (dynamic
       scenes rebuild only touched cells) sees a new frame and restarts its eye rays. */
    _Alignas(64) unsigned frame;
} rt_shared;

/* Eye rays per farmed batch (vw_ctx_next_batch): copies of a duplicated cell take
   every k-th run of this many pixels of the cell's row-major list, fine enough that
   each copy's share samples the whole cell (batches of 256 pixels, a quarter row at
   1024 wide, left one copy the image's heavy middle columns: busy 0.98 s against
   0.80 s). rt_job_overlay_workers draws who made them. */
#define RT_SHARE 16

extern const vw_module rt_module;

/* ---- a whole render (what the command line and the tests drive) ------------------------- */

/* Farming within a process: the workers of a process share its cells by holding copies
   of them (vw_world_set_replicas). A ray then moves to another worker only when it
   crosses into a cell of another process, and every copy takes eye-ray batches in
   turns, then the turns a slower copy has not taken (vw_ctx_next_batch), so the
   workers stay evenly loaded. The copies of a cell share one built Embree scene
   (rt_geo_acquire). */
typedef enum rt_farm {
    RT_FARM_IDLE = 0, /* only workers that host no cell get copies (of all their
                         process's cells): --cells 1 on 2 workers uses both */
    RT_FARM_ALL,      /* every worker hosts every cell of its process */
                      /* (a process that hosts no cell at all farms every cell) */
    RT_FARM_NONE      /* no copies besides those a balancer made */
} rt_farm;

typedef struct rt_params {
    int width, height;   /* 0: the camera's resolution, else 512x512 */
    int depth;           /* 0: 5 */
    int dims[3];         /* grid layout; 0s mean 1 */
    int workers;         /* per process; 0 = cores */
    const vw_camera *camera; /* NULL: the scene's (or a default framing for OBJ) */
    vw_config *config;   /* NULL: vw_config_init() defaults (incl. VW_STRESS) */
    /* Dynamic scenes (vwalls animate) fix these for a whole animation, so that a frame
       depends only on where the objects are, not on where they were at the start: */
    const vw_box *world;       /* NULL: the scene bounds, padded */
    /* NULL, or a box the world box is grown to cover (vwalls render --world): the space
       the scene is meant to fill, which its objects may not reach (the paper's clustered
       load cases cut the whole scene space, not the cluster's bounds). Not with world. */
    const vw_box *world_min;
    double scale;              /* 0: the scene's diagonal; sets the epsilons */
    const rt_object *objects;  /* NULL: rt_objects_from_scene(); else these records, */
    size_t nobjects;           /* in this order (world object ids = their index) */
    /* Nonzero: the cells' copies of mode `farm` (rt_job_farm) are made before the objects
       are added, so that under MPI each process keeps the records its copies will be
       built from as they come, instead of fetching them from the others at the commit
       (docs/runtime.md, "Object records"). For a caller that farms the initial mapping
       (no balancing, no new mapping first); rt_job_farm_copies tells how many. */
    int farm_first;
    rt_farm farm;
} rt_params;

/* The records of one scene object into out[0..n) (n = 1, or count-2 for a polygon),
   the same as rt_objects_from_scene() makes, except that a degenerate triangle becomes
   an empty record (rt_object_empty) instead of being dropped, so every object keeps a
   fixed number of records. Returns n. */
size_t rt_object_records(const vw_scene *s, vw_prim_kind kind, size_t index, rt_object *out);
/* A record that no cell holds: its bounds lie beyond any world box. */
void rt_object_empty(rt_object *o);

typedef struct rt_job rt_job;

/* The scenes the ray tracer takes, refused by rt_job_create (VW_E_INVAL) beyond: the eye
   and the world box within RT_MAX_COORD of the origin on every axis, and a scene at least
   RT_MIN_SIZE across (a scene that is a single point is allowed: it shows nothing).
   Embree sees the scene in a float frame, measured from an origin inside it and brought
   near unit size by a power of two (rt_float_frame, geometry.h), so its floats neither
   overflow nor vanish; the limits keep the shading's double products of four lengths (a
   triangle's normal) from doing so, by a wide margin: tests/raytrace renders the same
   image, byte for byte, from the same scene scaled by 2^100 and 2^-190. */
#define RT_MAX_COORD 1e36
#define RT_MIN_SIZE 1e-60

/* Phases, each timed by the caller if it wishes: create (objects, decomposition, world,
   objects added), commit (cells built), run (rays traced). err gets a message.
   Under MPI every process calls each of these (and rt_job_reset, rt_job_map, rt_job_farm,
   rt_job_balance) alike, and each fails on every process or on none: what a process
   does alone (checking its own copy of the scene against the coordinate limits, the
   decomposition, the Embree device, memory; the image sums rank 0 alone keeps) ends in
   agreement before the next collective step, vw_config_agree before the world exists
   and vw_world_agree after, so every process returns the lowest failing rank's status
   and err says "rank R: <its message>" on every process. */
vw_status rt_job_create(const vw_scene *s, const rt_params *p, rt_job **out, char *err,
                        size_t errlen);
/* The runtime configuration a job with these parameters runs with: p->config (or the
   defaults) with p->workers when given. */
vw_config rt_job_config(const rt_params *p);
vw_status rt_job_commit(rt_job *j, char *err, size_t errlen);
vw_status rt_job_run(rt_job *j, char *err, size_t errlen);
void rt_job_free(rt_job *j);

vw_world *rt_job_world(rt_job *j);
const rt_shared *rt_job_shared(const rt_job *j);
int rt_job_is_output(const rt_job *j);
/* Pixels whose eye ray enters the world (progress denominator; output process). */
int64_t rt_job_primary_pixels(const rt_job *j);
/* Thread-safe progress: eye rays ended so far (output process), rays created so far
   (this process). */
void rt_job_progress(const rt_job *j, int64_t *pixels_done, int64_t *rays);
/* The balancer's pre-pass: from the next commit on, cells generate eye rays for every
   stride-th row and column only (1 = all). Takes effect when cells are (re)built. */
void rt_job_set_sample(rt_job *j, int stride);
/* Forget the last run's image and measurements, and recompute which cell owns each
   pixel from the world's current decomposition (after the balancer changed it), so
   the next run renders from scratch. The world's cells are rebuilt at the next commit. */
vw_status rt_job_reset(rt_job *j);
/* Record which worker makes each eye ray in the runs that follow (for
   rt_job_eye_workers; costs one package entry per pixel). Before rt_job_run; on every
   process. */
vw_status rt_job_record_eye_workers(rt_job *j);
/* The global worker that made each pixel's eye ray in the last run (width*height
   entries, -1 where the ray misses the world): the cell's worker, or with copies the
   one that took the pixel's batch (vw_ctx_next_batch: its own turn, or another copy's
   it took). Output process; 0 if not recorded. */
int rt_job_eye_workers(const rt_job *j, int *worker);
/* The overlay variant that tints each pixel by that worker. */
void rt_job_overlay_workers(const rt_job *j, uint8_t *out);
/* Record the cell where each eye ray hits in the runs that follow (for rt_job_overlay:
   its tint then follows the visible surfaces' cells). Before rt_job_run; on every
   process. VW_E_NOMEM when the output process has no room for the map. */
vw_status rt_job_record_hit_cells(rt_job *j);
/* ---- load balancing (apps/raytrace/balance.c) ---------------------------------------- */

typedef struct rt_balance {
    vw_balance_strategy strategy;
    vw_map_kind map;          /* how balanced cells go onto workers */
    const double *speeds;     /* per global worker, or NULL */
    vw_load_spec load;        /* what a cell's load is */
    int rounds;               /* pre-pass / balance rounds (>= 1) */
    int stride;               /* the pre-pass traces every stride-th row and column;
                                 0: rt_prepass_stride() */
} rt_balance;

/* Eye rays per cell the automatic pre-pass aims at. */
#define RT_PREPASS_RAYS 256
/* The pre-pass stride for an image and a cell count: about RT_PREPASS_RAYS eye rays per
   cell, between 1 (every pixel) and 8. */
int rt_prepass_stride(int width, int height, int cells);

typedef struct rt_balance_result {
    vw_balance_report rep;    /* the first round's "before", the last round's prediction */
    uint64_t migrated, bytes; /* over all rounds */
    int rounds;
    double prepass_s;
    int stride;               /* the pre-pass stride used */
    int reverted;             /* 1: the last balance was refuted by its pre-pass, undone */
    double measured;          /* lambda the pre-pass measured on the layout kept */
} rt_balance_result;

/* Single image: a cheap sparse pre-pass measures where the work lies, the balancer
   builds the load field and moves the walls (repeated b->rounds times, each pre-pass
   re-calibrating the field on the new layout, and each balance checked by the next
   pre-pass: one that does not lower the slowest worker's measured load per sampled
   pixel is undone and ends the rounds; lambda alone cannot see a balance that adds
   work, as rotate's larger world box and divide's extra walls do);
   then the job is reset for the full render (commit + run). Strategy none with map
   greedy/weighted maps by the measured loads instead. Collective under MPI: what each
   process does alone between the collective steps (its loads, field and saved layout,
   a rebuild's arrays) is agreed on before the next one (once after the loads, once a
   rebuild, once a pre-pass round), so memory one process lacks fails the balance on
   every process with "rank R: ..." in err. */
vw_status rt_job_balance(rt_job *j, const rt_balance *b, rt_balance_result *out, char *err,
                         size_t errlen);
/* Re-maps the cells (kind, loads or NULL, speeds or NULL) before or between runs. */
vw_status rt_job_map(rt_job *j, vw_map_kind kind, const double *load, const double *speeds,
                     char *err, size_t errlen);
/* Parses "idle" | "all" | "none"; -1 if none of them. */
int rt_farm_parse(const char *s);
const char *rt_farm_name(rt_farm f);
/* Adds the copies of mode f to the current mapping (after balancing, before commit).
   *copies gets the number of copies added (may be NULL). */
vw_status rt_job_farm(rt_job *j, rt_farm f, int *copies, char *err, size_t errlen);
/* The copies rt_job_create made (rt_params.farm_first), or 0. */
int rt_job_farm_copies(const rt_job *j);

/* lambda of the deterministic work (ray-cell visits, RT_C_SEGMENTS) over workers. */
double rt_job_work_imbalance(const rt_job *j, const double *speeds);

/* After run, output process: the fixed-point sums (background of pixels that miss the
   world included), width*height*3, row-major from the top row. */
const int64_t *rt_job_sums(const rt_job *j);
/* 8-bit RGB (clamp(sum / 2^32) * 255, rounded half up) and float RGB (sum / 2^32). */
void rt_job_rgb8(const rt_job *j, uint8_t *out);
void rt_job_rgbf(const rt_job *j, float *out);
/* The overlay picture: the image with the cell walls drawn and each pixel tinted by
   the measured load of a cell (green = lightest, red = heaviest): the cell where its
   eye ray hit, when recorded (rt_job_record_hit_cells; a pixel whose ray hit nothing
   is not tinted), else the cell where its eye ray entered the world (its primary
   pixels, the viewport's projection onto the cells). */
void rt_job_overlay(const rt_job *j, uint8_t *out);
/* The "rays" and per-cell pixel members for the stats JSON (malloc'ed string). */
char *rt_job_stats_json(const rt_job *j);

/* Where a ray leaving a surface in direction d (unit; ng the surface's unit geometric
   normal) starts its searches, as a factor of rt_shared.eps (Embree's and the doubles'
   error in the hit point across the surface): 1 over the cosine of d to ng (a ray that
   leaves at a grazing angle needs that much farther to get as far off the surface), up
   to 64. A surface nearer than that to a ray's origin is not seen by it; features of
   any size above the float error cast their shadows and show in mirrors. Shared with
   bench/embree_raw.c, which must cast the same rays. */
static inline float rt_ray_eps(const double d[3], const double ng[3])
{
    double c = d[0] * ng[0] + d[1] * ng[1] + d[2] * ng[2];
    c = c < 0 ? -c : c;
    return (float)(1.0 / (c > 1.0 / 64 ? c : 1.0 / 64));
}

/* The fixed-point -> 8-bit rule, shared with the tests. */
static inline uint8_t rt_fix_to_u8(int64_t q)
{
    if (q <= 0) return 0;
    if (q >= (int64_t)1 << 32) return 255;
    return (uint8_t)((q * 255 + ((int64_t)1 << 31)) >> 32);
}

#endif
